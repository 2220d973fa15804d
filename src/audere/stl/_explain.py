"""Per-clause diagnostics: which top-level clause fails, by how much, and where."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
from numpy.typing import ArrayLike
from pydantic import BaseModel, ConfigDict, Field

from audere.errors import InvalidArgumentError
from audere.stl._formula import (
    Always,
    And,
    Eventually,
    Formula,
    Implies,
    Not,
    Or,
    Until,
)
from audere.stl._regions import RegionShape
from audere.stl._semantics import Evaluation, prepare, rho, truth

__all__ = ["ClauseReport", "explain"]


class ClauseReport(BaseModel):
    """Robustness and truth of one top-level clause of a specification, evaluated at step 0."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    index: int = Field(ge=0, description="Position of the clause among the top-level conjuncts.")
    text: str = Field(description="The clause in the text syntax.")
    robustness: float = Field(description="Robustness of the clause at step 0 (positive: satisfied).")
    satisfied: bool = Field(description="Whether the clause holds at step 0 (boolean semantics).")
    critical_step: int = Field(
        ge=0, description="The step whose value decides the robustness (e.g. the worst step of a G)."
    )
    critical_predicate: str = Field(
        description="The predicate, negated if it appears under a negation, whose value at critical_step "
        "is the robustness (e.g. '!in(B)')."
    )

    def summary(self) -> str:
        """One sentence describing the clause's verdict.

        Returns
        -------
        str
            E.g. ``"G[0,20] !in(B): violated, robustness -0.300 (!in(B) at step 7)"``.
        """
        verdict = "satisfied" if self.satisfied else "violated"
        return (
            f"{self.text}: {verdict}, robustness {self.robustness:.3f} "
            f"({self.critical_predicate} at step {self.critical_step})"
        )


def _critical(node: Formula, t: int, traces: dict[int, np.ndarray]) -> tuple[int, Formula]:
    """Follow the argmin/argmax choices from ``node`` at ``t`` down to the deciding predicate."""
    negated = False
    while True:
        if isinstance(node, Not):
            node, negated = node.child, not negated
        elif isinstance(node, And | Or):
            values = [traces[id(child)][t] for child in node.operands]
            pick = int(np.argmin(values) if isinstance(node, And) else np.argmax(values))
            node = node.operands[pick]
        elif isinstance(node, Implies):
            if -traces[id(node.left)][t] >= traces[id(node.right)][t]:
                node, negated = node.left, not negated
            else:
                node = node.right
        elif isinstance(node, Always | Eventually):
            window = traces[id(node.child)][t + node.lo : t + node.hi + 1]
            offset = int(np.argmin(window) if isinstance(node, Always) else np.argmax(window))
            t += node.lo + offset
            node = node.child
        elif isinstance(node, Until):
            left, right = traces[id(node.left)], traces[id(node.right)]
            left_min, best, best_k, best_left = np.inf, -np.inf, node.lo, True
            for k in range(node.hi + 1):
                if k >= node.lo:
                    value = min(right[t + k], left_min)
                    if value > best or k == node.lo:
                        best, best_k, best_left = value, k, left_min < right[t + k]
                if k < node.hi:
                    left_min = min(left_min, left[t + k])
            if best_left:
                window = left[t : t + best_k]
                node, t = node.left, t + int(np.argmin(window))
            else:
                node, t = node.right, t + best_k
        else:  # predicate or constant
            return t, (Not(node) if negated else node)


def explain(
    formula: Formula | str,
    positions: ArrayLike,
    regions: Mapping[str, RegionShape],
    *,
    max_clauses: int = 10,
) -> list[ClauseReport]:
    """Robustness, truth and critical step of each top-level clause of ``formula`` at step 0.

    The clauses are ``formula.clauses()`` (the conjuncts of a top-level ``&``). The critical step
    of a clause is found by following, from the clause down, the operand and the time step that
    attain each min or max (the worst step of a ``G``, the best of an ``F``, ...) to the predicate
    whose value is the clause's robustness; ties go to the earliest step and the first operand.

    Parameters
    ----------
    formula
        The specification, as a formula or its text.
    positions
        Array (T+1, 2) of positions ``(x, y)`` in metres, at least ``formula.horizon() + 1`` rows.
    regions
        Region name to shape; must define every name the formula uses.
    max_clauses
        Most reports returned (>= 1). When the formula has more clauses, the ``max_clauses`` with
        the lowest robustness are kept (the most violated), still in clause order.

    Returns
    -------
    list of ClauseReport
        One report per kept clause, in clause order (``index`` gives the position).

    Raises
    ------
    InvalidArgumentError
        For bad positions, missing regions, a signal shorter than the formula's horizon, or
        ``max_clauses < 1``.
    """
    if isinstance(max_clauses, bool) or not isinstance(max_clauses, int) or max_clauses < 1:
        raise InvalidArgumentError(f"max_clauses must be an integer >= 1, got {max_clauses!r}")
    ev = prepare(formula, positions, regions, t=0)
    traces: dict[int, np.ndarray] = {}
    ev = Evaluation(ev.formula, ev.positions[: ev.formula.horizon() + 1], ev.regions, traces=traces)
    reports = []
    for index, clause in enumerate(ev.formula.clauses()):
        value = float(rho(clause, ev)[0])
        step, predicate = _critical(clause, 0, traces)
        reports.append(
            ClauseReport(
                index=index,
                text=str(clause),
                robustness=value,
                satisfied=bool(truth(clause, ev)[0]),
                critical_step=step,
                critical_predicate=str(predicate),
            )
        )
    if len(reports) > max_clauses:
        kept = sorted(reports, key=lambda r: (r.robustness, r.index))[:max_clauses]
        reports = sorted(kept, key=lambda r: r.index)
    return reports
