"""The track-car recipe (MPC) passes the task's own checker."""

from __future__ import annotations

import numpy as np
import pytest

from audere import recipes, scenarios
from audere.recipes._track_car import solve_track_car


def _check(seed: int) -> None:
    task = scenarios.make("track-car", seed=seed)
    solution = solve_track_car(task)
    report = task.check(solution)
    assert report.success, f"seed {seed}: {report.summary()}"
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


@pytest.mark.parametrize("seed", range(20))
def test_track_car_recipe(seed: int) -> None:
    _check(seed)


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(20, 100))
def test_track_car_recipe_all_seeds(seed: int) -> None:
    _check(seed)


def test_registered() -> None:
    info = recipes.get_recipe("track-car")
    assert info.apis == ("mpc",)
    assert info.function is solve_track_car
