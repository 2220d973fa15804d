"""The plan-stl recipe (STL MILP) passes the task's own checker."""

from __future__ import annotations

import pytest

from audere import recipes, scenarios


def _check(seed: int) -> None:
    task = scenarios.make("plan-stl", seed=seed)
    report = task.check(recipes.solve(task))
    assert report.success, f"seed {seed}: {report.summary()}"


@pytest.mark.parametrize("seed", range(20))
def test_plan_stl_recipe(seed: int) -> None:
    _check(seed)


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(20, 100))
def test_plan_stl_recipe_all_seeds(seed: int) -> None:
    _check(seed)


def test_registered() -> None:
    info = recipes.get_recipe("plan-stl")
    assert info.apis == ("milp",)
