"""The MPC recipes (track-car, reach-unicycle, arm-reach) pass their task's own checker."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

from audere import recipes, scenarios
from audere.recipes._arm_reach import solve_arm_reach
from audere.recipes._reach_unicycle import solve_reach_unicycle
from audere.recipes._track_car import solve_track_car

RECIPES: dict[str, Callable[[Any], Any]] = {
    "track-car": solve_track_car,
    "reach-unicycle": solve_reach_unicycle,
    "arm-reach": solve_arm_reach,
}
FAST = [(name, seed) for name in RECIPES for seed in range(20)]
SLOW = [(name, seed) for name in RECIPES for seed in range(20, 100)]


def _check(name: str, seed: int) -> None:
    task = scenarios.make(name, seed=seed)
    solution = RECIPES[name](task)
    report = task.check(solution)
    assert report.success, f"{name} seed {seed}: {report.summary()}"
    # the states the recipe returns are exactly the checker's rollout of its inputs
    assert solution.inputs is not None
    assert solution.states is not None
    model = task.model
    assert model is not None
    rollout = model.rollout(np.asarray(task.x0), solution.inputs, task.dt, method=task.integrator)
    np.testing.assert_allclose(solution.states, rollout, rtol=0, atol=1e-12)
    assert task.u_min is not None
    assert task.u_max is not None
    assert (solution.inputs >= np.asarray(task.u_min)).all()
    assert (solution.inputs <= np.asarray(task.u_max)).all()


@pytest.mark.parametrize(("name", "seed"), FAST)
def test_mpc_recipe(name: str, seed: int) -> None:
    _check(name, seed)


@pytest.mark.slow
@pytest.mark.parametrize(("name", "seed"), SLOW)
def test_mpc_recipe_all_seeds(name: str, seed: int) -> None:
    _check(name, seed)


@pytest.mark.parametrize("name", sorted(RECIPES))
def test_registered(name: str) -> None:
    info = recipes.get_recipe(name)
    assert info.apis == ("mpc",)
    assert info.function is RECIPES[name]
