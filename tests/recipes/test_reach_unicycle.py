"""The reach-unicycle recipe (MPC) passes the task's own checker."""

from __future__ import annotations

import numpy as np
import pytest

from audere import recipes, scenarios
from audere.recipes._reach_unicycle import solve_reach_unicycle


def _check(seed: int) -> None:
    task = scenarios.make("reach-unicycle", seed=seed)
    solution = solve_reach_unicycle(task)
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
def test_reach_unicycle_recipe(seed: int) -> None:
    _check(seed)


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(20, 100))
def test_reach_unicycle_recipe_all_seeds(seed: int) -> None:
    _check(seed)


def test_registered() -> None:
    info = recipes.get_recipe("reach-unicycle")
    assert info.apis == ("mpc",)
    assert info.function is solve_reach_unicycle
