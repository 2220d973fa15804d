"""The typed result every planning and control API returns."""

from __future__ import annotations

from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field

from audere._arrays import FloatArray

__all__ = ["Result", "Status"]

Status = Literal["solved", "infeasible", "time_limit", "failed"]
"""``solved``: a solution was found; ``infeasible``: the problem provably has none (or the solver
says so); ``time_limit``: the budget ran out before a solution; ``failed``: anything else (the
``message`` says what)."""


class Result(BaseModel):
    """Base result of an API call: status, solver message, cost, time, and the trajectory pieces.

    API-specific results subclass it and add their extras (a search tree, robustness, ...).
    Arrays follow the house vocabulary: ``states`` (horizon+1, n_x), ``inputs`` (horizon, n_u),
    ``waypoints`` (k, 2), ``times`` (matching the states or the waypoints), in SI units.
    """

    model_config = ConfigDict(
        frozen=True, extra="forbid", arbitrary_types_allowed=True, use_attribute_docstrings=True
    )

    status: Status = Field(description="solved, infeasible, time_limit or failed.")
    message: str = Field("", description="The solver's own message, or what went wrong.")
    cost: float | None = Field(None, description="Objective value of the returned solution, if any.")
    solve_time: float = Field(0.0, ge=0, description="Wall-clock time spent, in seconds.")
    states: FloatArray | None = Field(None, description="States, shape (horizon+1, n_x).")
    inputs: FloatArray | None = Field(None, description="Inputs, shape (horizon, n_u).")
    waypoints: FloatArray | None = Field(None, description="Path, shape (k, 2).")
    times: FloatArray | None = Field(None, description="Time stamps in seconds.")

    @property
    def solved(self) -> bool:
        """Whether ``status == "solved"``."""
        return self.status == "solved"

    def to_solution(self) -> Any:
        """The trajectory as an :class:`audere.tasks.Solution` (what ``Task.check`` judges).

        Returns
        -------
        audere.tasks.Solution
            With the inputs, states and waypoints this result carries.
        """
        from audere.tasks import Solution

        times = self.times if self.waypoints is not None and self.times is not None else None
        if self.waypoints is not None and times is not None and len(times) != len(self.waypoints):
            times = None
        return Solution(inputs=self.inputs, states=self.states, waypoints=self.waypoints, times=times)
