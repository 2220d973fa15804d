"""What a solution to a task is: inputs, states, or (timed) waypoints."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, TypeAlias

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field, model_validator

from audere._arrays import FloatArray

__all__ = ["Solution", "SolutionLike"]


class Solution(BaseModel):
    """A candidate solution. Give the fields the task asks for (see ``Task.solution_kinds``).

    - ``inputs`` (horizon, n_u): rolled out from ``x0`` through the task's dynamics;
    - ``states`` (horizon+1, n_x): accepted alone for the single integrator (inputs are recovered
      as finite differences); given together with ``inputs`` they must match the rollout;
    - ``waypoints`` (k, 2): a path for geometric tasks; with ``times`` (k,) a timed path, which
      STL tasks resample at the integer steps ``0..horizon`` by linear interpolation.
    """

    model_config = ConfigDict(frozen=True, extra="forbid")

    inputs: FloatArray | None = Field(None, description="Input sequence, shape (horizon, n_u).")
    states: FloatArray | None = Field(None, description="State sequence, shape (horizon+1, n_x).")
    waypoints: FloatArray | None = Field(None, description="Path, shape (k, 2).")
    times: FloatArray | None = Field(None, description="Time of each waypoint in seconds, shape (k,).")

    def __eq__(self, other: object) -> bool:
        # The generated equality compares ndarray fields with ``==``, which is ambiguous: compare the
        # serialized fields instead (cached properties such as ``model`` are left out).
        if type(other) is not type(self):
            return NotImplemented
        return self.model_dump(mode="json") == other.model_dump(mode="json")

    def __hash__(self) -> int:
        return hash(self.model_dump_json())

    @model_validator(mode="after")
    def _something(self) -> Solution:
        if self.inputs is None and self.states is None and self.waypoints is None:
            raise ValueError("a solution needs at least one of inputs, states or waypoints")
        if self.times is not None and self.waypoints is None:
            raise ValueError("times needs waypoints: give the waypoints the times belong to")
        return self

    def arrays(self) -> dict[str, NDArray[np.float64]]:
        """The fields that are set, as a name-to-array mapping."""
        return {k: np.asarray(v) for k, v in self if v is not None}


SolutionLike: TypeAlias = Solution | Mapping[str, Any] | NDArray[Any] | list[Any]
"""What ``Task.check`` accepts: a :class:`Solution`, a mapping of its fields, or a bare array."""
