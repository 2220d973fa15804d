"""Small hand-made tasks of every kind, as plain data (what a task file holds) and as tasks."""

from __future__ import annotations

import copy
from typing import Any

from audere.tasks import TaskAdapter

RA_PATH: dict[str, Any] = {
    "kind": "reach_avoid",
    "x0": [1.0, 1.0],
    "goal": [9.0, 9.0],
    "goal_tolerance": 0.1,
    "obstacles": [{"kind": "circle", "center": [5.0, 5.0], "radius": 1.0}],
}

RA_UNICYCLE: dict[str, Any] = {
    "kind": "reach_avoid",
    "dynamics": "unicycle",
    "x0": [1.0, 1.0, 0.0, 0.0],
    "horizon": 10,
    "u_min": [-0.3, -0.5],
    "u_max": [0.3, 0.5],
    "goal": [5.0, 1.0],
    "goal_tolerance": 0.5,
    "obstacles": [{"kind": "square", "center": [5.0, 6.0], "half_side": 0.5}],
}

TRACK_SI: dict[str, Any] = {
    "kind": "tracking",
    "dynamics": "single_integrator",
    "x0": [1.0, 1.0],
    "horizon": 4,
    "u_min": [-0.5, -0.5],
    "u_max": [0.5, 0.5],
    "reference": [[1.0, 1.0], [1.5, 1.0], [2.0, 1.0], [2.5, 1.0], [3.0, 1.0]],
    "tolerance": 0.5,
}

MAZE: dict[str, Any] = {
    "kind": "maze",
    "x0": [1.0, 1.0],
    "goal": [9.0, 9.0],
    "rows": 2,
    "cols": 2,
    "wall_thickness": 0.2,
    "margin": 0.1,
    "doors": [
        {"cells": [[0, 0], [0, 1]], "offset": 0.5, "width": 1.0},
        {"cells": [[0, 1], [1, 1]], "offset": 0.5, "width": 1.0},
    ],
    "obstacles": [{"kind": "circle", "center": [2.0, 2.0], "radius": 0.3}],
}

STL_SI: dict[str, Any] = {
    "kind": "stl",
    "dynamics": "single_integrator",
    "x0": [1.0, 1.0],
    "horizon": 10,
    "u_min": [-2.0, -2.0],
    "u_max": [2.0, 2.0],
    "regions": {"A": {"kind": "rectangle", "xmin": 4.0, "xmax": 6.0, "ymin": 4.0, "ymax": 6.0}},
    "spec": "F[0,10] in(A)",
}

# The key/door scenario in miniature: pick up the key A before passing the door D, never enter the
# wall B, and be in the goal E at some step between 6 and 8.
KEY_DOOR: dict[str, Any] = {
    "kind": "stl",
    "dynamics": "single_integrator",
    "x0": [1.0, 1.0],
    "horizon": 10,
    "u_min": [-3.0, -3.0],
    "u_max": [3.0, 3.0],
    "regions": {
        "A": {"kind": "rectangle", "xmin": 0.5, "xmax": 1.5, "ymin": 8.5, "ymax": 9.5},
        "B": {"kind": "rectangle", "xmin": 3.0, "xmax": 4.0, "ymin": 0.0, "ymax": 7.0},
        "D": {"kind": "rectangle", "xmin": 6.0, "xmax": 7.0, "ymin": 7.0, "ymax": 10.0},
        "E": {"kind": "square", "center": [9.0, 9.0], "half_side": 0.5},
    },
    "spec": "(!in(D)) U[0,10] in(A) & G[0,10] !in(B) & F[6,8] in(E)",
}

ALL = {
    "reach_avoid_path": RA_PATH,
    "reach_avoid_unicycle": RA_UNICYCLE,
    "tracking": TRACK_SI,
    "maze": MAZE,
    "stl": STL_SI,
    "key_door": KEY_DOOR,
}


def data(base: dict[str, Any], **changes: Any) -> dict[str, Any]:
    """A deep copy of ``base`` with top-level fields replaced (``None`` removes a field)."""
    out = copy.deepcopy(base)
    for key, value in changes.items():
        if value is None:
            out.pop(key, None)
        else:
            out[key] = value
    return out


def task(base: dict[str, Any], **changes: Any) -> Any:
    """The validated task built from ``base`` with ``changes``."""
    return TaskAdapter.validate_python(data(base, **changes))
