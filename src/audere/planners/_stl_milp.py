"""Big-M encoding of STL robustness as mixed-integer linear constraints (no solver imported here).

The formula is put in negation normal form (:func:`audere.stl.to_nnf`), constants are folded away,
and every node is encoded at every step it is needed, following stlpy's design: predicates are
affine expressions of the position, and every ``&``, ``G`` and ``in(box)`` node is a *minimum*,
every ``|``, ``F`` and ``!in(box)`` node a *maximum*, of its operands (nested minima and maxima
are flattened into one). ``l U[a,b] r`` is unrolled backwards from ``k = b``:
``u_b = r(t+b)``, ``u_k = max(r(t+k), min(l(t+k), u_{k+1}))`` for ``a <= k < b`` and
``u_k = min(l(t+k), u_{k+1})`` for ``k < a``; by distributivity ``u_0`` is the maximum over ``k`` of
``min(r(t+k), l(t), ..., l(t+k-1))``, the robustness (two binaries per step besides the operands;
it solved about twice as fast on plan-stl as the maximum over ``k`` of running minima).

A minimum ``r = min(e_1, ..., e_n)`` is encoded *exactly* (both directions):
``r <= e_i`` for every ``i``, and ``r >= e_i - M_i (1 - b_i)`` with binaries ``b`` summing to one
(a single binary for two operands). Every feasible point of the program therefore carries the
robustness of its own trajectory, not merely a bound on it; the price is one binary per operand of
every minimum (the one-sided encoding needs binaries only for the maxima). ``M_i`` is derived per
constraint from interval bounds on the operands (the variables' bounds: the reachable positions
intersected with the workspace), unless one ``big_m`` is given. Operands that can never be the
minimum (their lower bound is at least another operand's upper bound) and duplicates are dropped.

The model is plain data (:class:`LinearModel`): variables with bounds and integrality, and sparse
rows ``lo <= a @ v <= hi``; :mod:`audere.planners._milp` hands it to a solver through cvxpy.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from audere.errors import InvalidArgumentError
from audere.stl import (
    FALSE,
    TRUE,
    Always,
    And,
    Compare,
    Constant,
    Eventually,
    Formula,
    In,
    Not,
    Or,
    Until,
    to_nnf,
)
from audere.world import Rectangle, Square, Workspace

__all__ = ["Affine", "LinearModel", "StlEncoder", "box_of", "simplify"]

Box = tuple[float, float, float, float]
"""``(xmin, xmax, ymin, ymax)``."""


@dataclass(frozen=True)
class Affine:
    """``sum(coef[i] * v[index[i]]) + const``, with the interval ``[lo, hi]`` it ranges over."""

    index: tuple[int, ...]
    coef: tuple[float, ...]
    const: float
    lo: float
    hi: float

    def key(self) -> tuple[tuple[int, ...], tuple[float, ...], float]:
        """Identity of the expression (for removing duplicates)."""
        return (self.index, self.coef, self.const)


@dataclass
class LinearModel:
    """A mixed-integer linear program under construction: variables and rows ``lo <= a @ v <= hi``."""

    lb: list[float] = field(default_factory=list)
    ub: list[float] = field(default_factory=list)
    binary: list[bool] = field(default_factory=list)
    rows_index: list[tuple[int, ...]] = field(default_factory=list)
    rows_coef: list[tuple[float, ...]] = field(default_factory=list)
    rows_lo: list[float] = field(default_factory=list)
    rows_hi: list[float] = field(default_factory=list)

    @property
    def n_vars(self) -> int:
        """Number of variables."""
        return len(self.lb)

    @property
    def n_binaries(self) -> int:
        """Number of binary variables."""
        return sum(self.binary)

    @property
    def n_rows(self) -> int:
        """Number of linear constraints (rows)."""
        return len(self.rows_lo)

    def add_var(self, lb: float = -math.inf, ub: float = math.inf) -> int:
        """A continuous variable in ``[lb, ub]``; returns its index."""
        self.lb.append(lb)
        self.ub.append(ub)
        self.binary.append(False)
        return len(self.lb) - 1

    def add_binary(self) -> int:
        """A 0/1 variable; returns its index."""
        self.lb.append(0.0)
        self.ub.append(1.0)
        self.binary.append(True)
        return len(self.lb) - 1

    def var(self, index: int) -> Affine:
        """The variable ``index`` as an expression."""
        return Affine((index,), (1.0,), 0.0, self.lb[index], self.ub[index])

    def affine(self, terms: Mapping[int, float], const: float = 0.0) -> Affine:
        """An affine expression with its interval from the variable bounds."""
        items = sorted((i, float(c)) for i, c in terms.items() if c != 0.0)
        lo = hi = const
        for i, c in items:
            a, b = c * self.lb[i], c * self.ub[i]
            lo += min(a, b)
            hi += max(a, b)
        return Affine(tuple(i for i, _ in items), tuple(c for _, c in items), float(const), lo, hi)

    def add_row(self, terms: Mapping[int, float], lo: float = -math.inf, hi: float = math.inf) -> None:
        """The constraint ``lo <= sum(c * v[i]) <= hi``."""
        items = sorted((i, float(c)) for i, c in terms.items() if c != 0.0)
        self.rows_index.append(tuple(i for i, _ in items))
        self.rows_coef.append(tuple(c for _, c in items))
        self.rows_lo.append(lo)
        self.rows_hi.append(hi)

    def add_le(
        self, expr: Affine, scale: float = 1.0, extra: Mapping[int, float] | None = None, rhs: float = 0.0
    ) -> None:
        """The constraint ``scale * expr + sum(extra) <= rhs``."""
        terms: dict[int, float] = {}
        for i, c in zip(expr.index, expr.coef, strict=True):
            terms[i] = terms.get(i, 0.0) + scale * c
        for i, c in (extra or {}).items():
            terms[i] = terms.get(i, 0.0) + c
        self.add_row(terms, hi=rhs - scale * expr.const)

    def value(self, expr: Affine, v: NDArray[np.float64]) -> float:
        """Value of ``expr`` at the point ``v``."""
        return float(expr.const + sum(c * v[i] for i, c in zip(expr.index, expr.coef, strict=True)))

    def violation(self, v: NDArray[np.float64]) -> float:
        """Largest violation of a bound, a row or integrality at ``v`` (0 when feasible)."""
        lb, ub = np.asarray(self.lb), np.asarray(self.ub)
        worst = float(max(np.max(lb - v, initial=0.0), np.max(v - ub, initial=0.0)))
        binary = np.asarray(self.binary, dtype=bool)
        if binary.any():
            worst = max(worst, float(np.max(np.abs(v[binary] - np.round(v[binary])))))
        for index, coef, lo, hi in zip(
            self.rows_index, self.rows_coef, self.rows_lo, self.rows_hi, strict=True
        ):
            s = float(np.dot(coef, v[list(index)])) if index else 0.0
            worst = max(worst, lo - s, s - hi)
        return worst


def box_of(shape: object) -> Box | None:
    """``(xmin, xmax, ymin, ymax)`` of an axis-aligned box shape, ``None`` for any other shape."""
    if isinstance(shape, Square):
        (cx, cy), h = shape.center, shape.half_side
        return (cx - h, cx + h, cy - h, cy + h)
    if isinstance(shape, Rectangle | Workspace):
        return (shape.xmin, shape.xmax, shape.ymin, shape.ymax)
    return None


def simplify(node: Formula) -> Formula:
    """Fold ``true`` and ``false`` away from an NNF formula (robustness unchanged).

    Parameters
    ----------
    node
        A formula in negation normal form.

    Returns
    -------
    Formula
        ``TRUE``, ``FALSE``, or an equivalent formula without constants.
    """
    if isinstance(node, And | Or):
        absorbing, neutral = (FALSE, TRUE) if isinstance(node, And) else (TRUE, FALSE)
        parts = [simplify(child) for child in node.operands]
        if absorbing in parts:
            return absorbing
        kept = [p for p in parts if p != neutral]
        if not kept:
            return neutral
        return kept[0] if len(kept) == 1 else type(node)(tuple(kept))
    if isinstance(node, Always | Eventually):
        child = simplify(node.child)
        return child if isinstance(child, Constant) else type(node)(node.lo, node.hi, child)
    if isinstance(node, Until):
        left, right = simplify(node.left), simplify(node.right)
        if right == FALSE:
            return FALSE
        if right == TRUE:  # the best k is lo: left must hold on t .. t+lo-1
            if node.lo == 0 or left == TRUE:
                return TRUE
            return FALSE if left == FALSE else Always(0, node.lo - 1, left)
        if left == TRUE:
            return Eventually(node.lo, node.hi, right)
        if left == FALSE:  # only k = 0 (an empty prefix) can work
            return right if node.lo == 0 else FALSE
        return Until(node.lo, node.hi, left, right)
    return node


class StlEncoder:
    """Encode the robustness of STL formulas on position variables of a :class:`LinearModel`.

    Parameters
    ----------
    model
        The program to add variables and rows to.
    position
        ``position[t][j]``: index of the variable holding coordinate ``j`` (0: x, 1: y) at step ``t``.
    regions
        Region name to shape; every region a formula uses must be an axis-aligned box.
    big_m
        One big-M for every constraint, or ``None`` to derive each from the variable bounds.
    """

    def __init__(
        self,
        model: LinearModel,
        position: Sequence[tuple[int, int]],
        regions: Mapping[str, object],
        *,
        big_m: float | None,
    ) -> None:
        self.model = model
        self.position = position
        self.regions = regions
        self.big_m = big_m
        self._memo: dict[tuple[Formula, int], Affine] = {}
        self._suffix: dict[tuple[Formula, int, int], Affine] = {}

    def encode(self, formula: Formula) -> Affine | float:
        """The robustness of ``formula`` at step 0: an expression, or ``+-inf`` for a constant formula.

        Parameters
        ----------
        formula
            Any formula (put in negation normal form and simplified here).

        Returns
        -------
        Affine or float
            The expression equal to the robustness at every feasible point, or ``inf`` / ``-inf``.
        """
        node = simplify(to_nnf(formula))
        if isinstance(node, Constant):
            return math.inf if node.value else -math.inf
        return self.rho(node, 0)

    # --- predicates ------------------------------------------------------------------------------

    def _halfspaces(self, name: str, t: int, negate: bool) -> list[Affine]:
        box = box_of(self.regions[name])
        if box is None:  # pragma: no cover - the caller checks the regions first
            raise InvalidArgumentError(f"regions[{name!r}] must be an axis-aligned box")
        xmin, xmax, ymin, ymax = box
        ix, iy = self.position[t]
        s = -1.0 if negate else 1.0
        return [
            self.model.affine({ix: s}, -s * xmin),
            self.model.affine({ix: -s}, s * xmax),
            self.model.affine({iy: s}, -s * ymin),
            self.model.affine({iy: -s}, s * ymax),
        ]

    def _compare(self, node: Compare, t: int, negate: bool) -> Affine:
        ix, iy = self.position[t]
        s = 1.0 if node.op == ">=" else -1.0
        if negate:
            s = -s
        return self.model.affine({ix: s * node.a, iy: s * node.b}, -s * node.rhs)

    # --- flattening --------------------------------------------------------------------------------

    def _min_terms(self, node: Formula, t: int) -> list[Affine]:
        if isinstance(node, And):
            return [term for child in node.operands for term in self._min_terms(child, t)]
        if isinstance(node, Always):
            return [term for k in range(node.lo, node.hi + 1) for term in self._min_terms(node.child, t + k)]
        if isinstance(node, In):
            return self._halfspaces(node.name, t, negate=False)
        return [self.rho(node, t)]

    def _max_terms(self, node: Formula, t: int) -> list[Affine]:
        if isinstance(node, Or):
            return [term for child in node.operands for term in self._max_terms(child, t)]
        if isinstance(node, Eventually):
            return [term for k in range(node.lo, node.hi + 1) for term in self._max_terms(node.child, t + k)]
        if isinstance(node, Not) and isinstance(node.child, In):
            return self._halfspaces(node.child.name, t, negate=True)
        if isinstance(node, Until):
            return self._max_terms_until(node, t, 0)
        return [self.rho(node, t)]

    def _max_terms_until(self, node: Until, t: int, k: int) -> list[Affine]:
        """Operands of the maximum ``u_k``: ``u_k = max(r(t+k), min(l(t+k), u_{k+1}))`` for ``lo <= k < hi``,
        ``u_hi = r(t+hi)``, and ``u_k = min(l(t+k), u_{k+1})`` for ``k < lo``; ``u_0`` is the robustness."""
        if k == node.hi:
            return self._max_terms(node.right, t + k)
        rest = self.minimum([*self._min_terms(node.left, t + k), self._until(node, t, k + 1)])
        return [rest] if k < node.lo else [*self._max_terms(node.right, t + k), rest]

    def _until(self, node: Until, t: int, k: int) -> Affine:
        key = (node, t, k)
        cached = self._suffix.get(key)
        if cached is None:
            cached = self._suffix[key] = self.maximum(self._max_terms_until(node, t, k))
        return cached

    def rho(self, node: Formula, t: int) -> Affine:
        """The robustness of the NNF, constant-free ``node`` at step ``t``, as an expression.

        Parameters
        ----------
        node
            A formula in negation normal form without constants.
        t
            The step.

        Returns
        -------
        Affine
            An expression equal to the robustness at every feasible point of the program.
        """
        key = (node, t)
        cached = self._memo.get(key)
        if cached is not None:
            return cached
        if isinstance(node, Compare):
            out = self._compare(node, t, negate=False)
        elif isinstance(node, Not) and isinstance(node.child, Compare):
            out = self._compare(node.child, t, negate=True)
        elif isinstance(node, And | Always | In):
            out = self.minimum(self._min_terms(node, t))
        elif isinstance(node, Or | Eventually | Until) or (
            isinstance(node, Not) and isinstance(node.child, In)
        ):
            out = self.maximum(self._max_terms(node, t))
        else:  # pragma: no cover - to_nnf and simplify leave nothing else
            raise TypeError(f"cannot encode the formula node {type(node).__name__}: {node}")
        self._memo[key] = out
        return out

    # --- min / max -----------------------------------------------------------------------------------

    def maximum(self, terms: Sequence[Affine]) -> Affine:
        """An expression equal to ``max(terms)`` at every feasible point (``-min(-terms)``)."""
        return _negate(self.minimum([_negate(term) for term in terms]))

    def minimum(self, terms: Sequence[Affine]) -> Affine:
        """An expression equal to ``min(terms)`` at every feasible point (exact big-M encoding).

        Parameters
        ----------
        terms
            The operands (at least one).

        Returns
        -------
        Affine
            The operand itself when only one remains after pruning, else a new variable.
        """
        unique: dict[tuple[tuple[int, ...], tuple[float, ...], float], Affine] = {}
        for term in terms:
            unique.setdefault(term.key(), term)
        items = list(unique.values())
        lowest = min(items, key=lambda term: term.hi)
        # An operand whose lower bound is at least the smallest upper bound is never below it.
        items = [term for term in items if term is lowest or term.lo < lowest.hi]
        if len(items) == 1:
            return items[0]
        model = self.model
        lo, hi = min(term.lo for term in items), lowest.hi
        r = model.add_var(lo, hi)
        if len(items) == 2:
            b = model.add_binary()
            selectors: list[dict[int, float]] = [{b: 1.0}, {b: -1.0}]
            offsets = [0.0, 1.0]  # b_0 = b, b_1 = 1 - b
        else:
            bs = [model.add_binary() for _ in items]
            model.add_row(dict.fromkeys(bs, 1.0), lo=1.0, hi=1.0)
            selectors = [{b: 1.0} for b in bs]
            offsets = [0.0] * len(bs)
        for term, selector, offset in zip(items, selectors, offsets, strict=True):
            # r <= e_i
            model.add_le(term, scale=-1.0, extra={r: 1.0})
            # e_i - r <= M_i (1 - b_i), with b_i = offset + selector . v
            m = self.big_m if self.big_m is not None else term.hi - lo
            if not math.isfinite(m):
                raise InvalidArgumentError(
                    "big_m cannot be derived because the positions are unbounded: give a workspace, input "
                    "bounds (u_min, u_max) or big_m"
                )
            m = max(m, 0.0)
            extra = {r: -1.0}
            for i, c in selector.items():
                extra[i] = extra.get(i, 0.0) + m * c
            model.add_le(term, extra=extra, rhs=m * (1.0 - offset))
        return model.var(r)


def _negate(term: Affine) -> Affine:
    return Affine(term.index, tuple(-c for c in term.coef), -term.const, -term.hi, -term.lo)
