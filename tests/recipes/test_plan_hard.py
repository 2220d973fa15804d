"""The plan-hard recipe (door-graph A*, fine-grid A*, shortcut) passes the task's own checker."""

from __future__ import annotations

import numpy as np
import pytest

from audere import recipes, scenarios
from audere.planners import occupancy_grid
from audere.recipes._plan_hard import RESOLUTION, _restricted, solve_plan_hard


def _check(seed: int) -> None:
    task = scenarios.make("plan-hard", seed=seed)
    solution = solve_plan_hard(task)
    report = task.check(solution)
    assert report.success, f"seed {seed}: {report.summary()}"
    assert solution.waypoints is not None
    np.testing.assert_array_equal(solution.waypoints[0], task.x0)
    np.testing.assert_array_equal(solution.waypoints[-1], task.goal)
    # the exact world predicates agree with the checker: no waypoint or segment enters an obstacle
    assert task.world().first_collision(solution.waypoints) is None


@pytest.mark.parametrize("seed", range(20))
def test_plan_hard_recipe(seed: int) -> None:
    _check(seed)


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(20, 100))
def test_plan_hard_recipe_all_seeds(seed: int) -> None:
    _check(seed)


def test_registered() -> None:
    info = recipes.get_recipe("plan-hard")
    assert info.apis == ("astar",)
    assert info.function is solve_plan_hard


def test_corridor_keeps_only_the_route_cells() -> None:
    task = scenarios.make("plan-hard", seed=2)
    grid = occupancy_grid(task.world(inflated=False), resolution=RESOLUTION, margin=task.margin)
    route = ((0, 0), (0, 1))
    corridor = _restricted(grid, task, route)
    free = grid.to_world(np.argwhere(~corridor.blocked))
    assert {task.cell_of((float(x), float(y))) for x, y in free} <= set(route)
    assert (corridor.blocked >= grid.blocked).all()
