"""Expert recipes: for every benchmark scenario, a reference solution built from the registered APIs.

A recipe is what an expert would write with audere's APIs for a scenario (track-lin: LQR;
plan-easy: RRT*; plan-stl: the STL MILP; ...). Recipes prove that the APIs solve the benchmark,
serve as documentation, and are the offline expert strategist of the agent.

>>> from audere import recipes, scenarios
>>> task = scenarios.make("track-lin", seed=0)
>>> task.check(recipes.solve(task)).success  # doctest: +SKIP
True
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, TypeVar

from audere.errors import InvalidArgumentError

__all__ = ["Recipe", "get_recipe", "list_recipes", "recipe", "solve"]

F = TypeVar("F", bound=Callable[..., Any])

# private modules holding the built-in recipes (one line per module; keep sorted)
_MODULES: tuple[str, ...] = (
    "_arm_reach",
    "_pendulum_swingup",
    "_plan_easy",
    "_plan_hard",
    "_plan_stl",
    "_reach_unicycle",
    "_track_car",
    "_track_double",
    "_track_lin",
)


@dataclass(frozen=True)
class Recipe:
    """A registered recipe: the scenario it solves, the APIs it uses, and the function."""

    scenario: str
    apis: tuple[str, ...]
    function: Callable[..., Any]


_RECIPES: dict[str, Recipe] = {}
_loaded = False


def recipe(scenario: str, *, apis: Sequence[str]) -> Callable[[F], F]:
    """Register ``function(task) -> audere.tasks.Solution`` as the recipe for ``scenario``.

    Parameters
    ----------
    scenario
        Scenario name, e.g. ``"plan-easy"``.
    apis
        Names of the registered APIs the recipe calls.

    Returns
    -------
    callable
        A decorator that registers the function and returns it unchanged.
    """

    def decorator(function: F) -> F:
        _RECIPES[scenario] = Recipe(scenario=scenario, apis=tuple(apis), function=function)
        return function

    return decorator


def _load() -> None:
    global _loaded
    if not _loaded:
        for module in _MODULES:
            importlib.import_module(f"audere.recipes.{module}")
        _loaded = True


def list_recipes() -> list[Recipe]:
    """All registered recipes, sorted by scenario name.

    Returns
    -------
    list of Recipe
        One per scenario that has a recipe.
    """
    _load()
    return [_RECIPES[k] for k in sorted(_RECIPES)]


def get_recipe(scenario: str) -> Recipe:
    """The recipe registered for ``scenario``.

    Parameters
    ----------
    scenario
        Scenario name, e.g. ``"plan-easy"``.

    Returns
    -------
    Recipe
        The recipe.

    Raises
    ------
    InvalidArgumentError
        When no recipe is registered for that scenario.
    """
    _load()
    if scenario not in _RECIPES:
        known = ", ".join(sorted(_RECIPES)) or "none"
        raise InvalidArgumentError(f"no recipe for scenario {scenario!r}; recipes exist for: {known}")
    return _RECIPES[scenario]


def solve(task: Any) -> Any:
    """Solve a scenario task with its recipe.

    Parameters
    ----------
    task
        A task made by :func:`audere.scenarios.make` (its ``name`` is ``"<scenario>/seed=<n>"``).

    Returns
    -------
    audere.tasks.Solution
        The recipe's solution; judge it with ``task.check``.
    """
    scenario = str(getattr(task, "name", "")).split("/", 1)[0]
    if not scenario:
        raise InvalidArgumentError("task has no scenario name (task.name is empty): call a recipe directly")
    return get_recipe(scenario).function(task)
