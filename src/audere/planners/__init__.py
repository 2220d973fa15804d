"""Planners: A*, RRT/RRT* (OMPL), the cross-entropy method, gradient-based optimization, STL-MILP.

Each planner is a plain function returning a typed :class:`audere.apis.Result` subclass. Names
load lazily, so ``import audere.planners`` imports no heavy backend.
"""

from __future__ import annotations

import importlib
from typing import Any

# public name -> private module that defines it (one line per name; keep sorted by name)
_EXPORTS: dict[str, str] = {
    "AStarResult": "_astar",
    "CEMResult": "_cem",
    "CellGraph": "_astar",
    "CostFunction": "_cem",
    "GradResult": "_grad",
    "MILPResult": "_milp",
    "OccupancyGrid": "_astar",
    "RRTResult": "_rrt",
    "astar": "_astar",
    "astar_graph": "_astar",
    "cell_graph": "_astar",
    "cem": "_cem",
    "effort_cost": "_cem",
    "goal_cost": "_cem",
    "grad": "_grad",
    "milp": "_milp",
    "obstacle_cost": "_cem",
    "occupancy_grid": "_astar",
    "rrt": "_rrt",
    "shortcut": "_astar",
    "smooth_robustness": "_grad",
    "tracking_cost": "_cem",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name: str) -> Any:
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'audere.planners' has no attribute {name!r}")
    value = getattr(importlib.import_module(f"audere.planners.{module}"), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_EXPORTS))
