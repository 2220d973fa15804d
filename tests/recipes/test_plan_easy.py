"""The plan-easy recipe (informed RRT* through OMPL) passes the task's own checker."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("ompl")

from audere import recipes, scenarios
from audere.recipes._plan_easy import solve_plan_easy


def _check(seed: int) -> None:
    task = scenarios.make("plan-easy", seed=seed)
    solution = solve_plan_easy(task)
    report = task.check(solution)
    assert report.success, f"seed {seed}: {report.summary()}"
    assert solution.waypoints is not None
    np.testing.assert_array_equal(solution.waypoints[0], task.x0)
    assert np.hypot(*(solution.waypoints[-1] - np.asarray(task.goal))) <= task.goal_tolerance
    # independent of the checker: the exact world predicates see no collision either
    assert task.world().first_collision(solution.waypoints) is None


@pytest.mark.parametrize("seed", range(20))
def test_plan_easy_recipe(seed: int) -> None:
    _check(seed)


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(20, 100))
def test_plan_easy_recipe_all_seeds(seed: int) -> None:
    _check(seed)


def test_registered() -> None:
    info = recipes.get_recipe("plan-easy")
    assert info.apis == ("rrt",)
    assert info.function is solve_plan_easy
    assert recipes.solve(scenarios.make("plan-easy", seed=0)).waypoints is not None
