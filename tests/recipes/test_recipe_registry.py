"""Every scenario has a recipe, and every recipe names registered APIs."""

from __future__ import annotations

import pytest

from audere.apis import list_apis
from audere.errors import InvalidArgumentError
from audere.recipes import get_recipe, list_recipes, solve
from audere.scenarios import list_scenarios, make
from audere.tasks import ReachAvoidTask


def test_every_scenario_has_a_recipe_using_registered_apis() -> None:
    registered = {api.name for api in list_apis()}
    recipes = {r.scenario: r for r in list_recipes()}
    assert sorted(recipes) == sorted(s.name for s in list_scenarios())
    for recipe in recipes.values():
        assert recipe.apis, recipe.scenario
        assert set(recipe.apis) <= registered, recipe.scenario


def test_every_api_is_used_by_some_recipe_or_documented_as_an_alternative() -> None:
    used = {api for r in list_recipes() for api in r.apis}
    # grad and pid solve scenarios too (see docs/apis/grad.md, pid.md) but are not the experts' first choice
    assert used >= {"astar", "rrt", "milp", "lqr", "mpc", "cem"}


def test_solve_dispatches_on_the_task_name() -> None:
    task = make("track-lin", 3)
    assert task.check(solve(task)).success


def test_unknown_scenario_and_unnamed_task_are_clear_errors() -> None:
    expected = "no recipe for scenario 'nope'; recipes exist for: arm-reach"
    with pytest.raises(InvalidArgumentError, match=expected):
        get_recipe("nope")
    task = ReachAvoidTask(x0=(1.0, 1.0), goal=(9.0, 9.0))
    with pytest.raises(InvalidArgumentError, match=r"task has no scenario name \(task.name is empty\)"):
        solve(task)
