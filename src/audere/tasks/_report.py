"""The checker's verdict: success, metrics, and bounded diagnostics meant for a model."""

from __future__ import annotations

from typing import ClassVar, Literal

from pydantic import BaseModel, ConfigDict, Field

from audere._arrays import FloatArray

__all__ = ["CheckReport", "ClauseResult", "Violation", "ViolationKind"]

ViolationKind = Literal[
    "malformed",  # the solution has the wrong shape, NaN/inf, or is missing what the task needs
    "start",  # the path does not start at the start
    "workspace",  # a point leaves the workspace
    "collision",  # a point or a segment enters an (inflated) obstacle
    "input_bounds",  # an input exceeds its bounds
    "dynamics",  # given states do not match the rollout of the given inputs
    "goal",  # the end is too far from the goal
    "tracking",  # the mean tracking error is too large
    "stl",  # an STL clause is violated
]


class _Frozen(BaseModel):
    model_config = ConfigDict(frozen=True, extra="forbid")


class Violation(_Frozen):
    """One thing wrong with a solution, located as precisely as possible."""

    kind: ViolationKind
    message: str = Field(description="One sentence with the exact numbers.")
    step: int | None = Field(None, description="Time step or waypoint/segment index where it happens.")
    point: tuple[float, float] | None = Field(None, description="The offending position, if any.")
    obstacle: int | None = Field(None, description="Index of the obstacle hit (in the task's obstacle list).")
    clause: str | None = Field(None, description="The STL clause violated, in text syntax.")


class ClauseResult(_Frozen):
    """Robustness of one top-level clause of an STL specification."""

    text: str
    robustness: float
    satisfied: bool
    critical_step: int | None = Field(None, description="The step whose value decides the robustness.")
    critical_predicate: str | None = Field(
        None, description="The predicate (negated under a negation) whose value at critical_step decides it."
    )


class CheckReport(_Frozen):
    """Result of ``Task.check``: success, metrics and bounded diagnostics.

    Diagnostics are bounded so they can go back to a model as they are: at most
    :attr:`MAX_VIOLATIONS` violations (``n_violations`` counts them all), a downsampled trajectory
    preview, error statistics, and per-clause robustness for STL tasks.
    """

    MAX_VIOLATIONS: ClassVar[int] = 10

    success: bool
    metrics: dict[str, float] = Field(default_factory=dict, description="Named scalar metrics.")
    violations: tuple[Violation, ...] = Field((), description="The first violations, in order of occurrence.")
    n_violations: int = Field(0, ge=0, description="Total number of violations found.")
    violation_counts: dict[str, int] = Field(
        default_factory=dict, description="Number of violations of each kind, all of them counted."
    )
    clauses: tuple[ClauseResult, ...] = Field((), description="Per-clause robustness (STL tasks).")
    preview: FloatArray | None = Field(None, description="Downsampled positions, shape (<= 11, 2).")
    positions: FloatArray | None = Field(
        None, description="The full checked positions (for plots); never put into feedback text."
    )

    def __eq__(self, other: object) -> bool:
        # The generated equality compares ndarray fields with ``==``, which is ambiguous.
        if type(other) is not type(self):
            return NotImplemented
        return self.model_dump(mode="json") == other.model_dump(mode="json")

    def __hash__(self) -> int:
        return hash(self.model_dump_json())

    @property
    def first_violation(self) -> Violation | None:
        """The earliest violation, or ``None``."""
        return self.violations[0] if self.violations else None

    def summary(self) -> str:
        """One line: verdict and the key metrics.

        Returns
        -------
        str
            E.g. ``"success; goal_distance=0.031, min_clearance=0.412"``.
        """
        from audere.tasks._feedback import summary

        return summary(self)

    def feedback(self, *, max_chars: int = 2000) -> str:
        """Bounded text for a language model: verdict, metrics, first violations, clauses, preview.

        Parameters
        ----------
        max_chars
            Hard cap on the length of the text.

        Returns
        -------
        str
            The feedback, at most ``max_chars`` characters.
        """
        from audere.tasks._feedback import feedback

        return feedback(self, max_chars=max_chars)
