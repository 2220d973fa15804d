"""numpy rollouts: shapes, batching, the integration schemes' semantics and accuracy, speed."""

from __future__ import annotations

import time

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from audere.dynamics import Dynamics, get_dynamics, list_dynamics

from .strategies import methods, model_rollout_case


@pytest.mark.parametrize("name", list_dynamics())
def test_rollout_shapes(name: str) -> None:
    model = get_dynamics(name)
    nx, nu = model.n_x, model.n_u
    assert model.rollout(np.zeros(nx), np.zeros((7, nu)), 0.1).shape == (8, nx)
    assert model.rollout(np.zeros((5, nx)), np.zeros((5, 7, nu)), 0.1).shape == (5, 8, nx)
    # one x0 for a batch of input sequences (the sampling planners' case), and nested batches
    assert model.rollout(np.zeros(nx), np.zeros((5, 7, nu)), 0.1).shape == (5, 8, nx)
    assert model.rollout(np.zeros((3, 1, nx)), np.zeros((4, 7, nu)), 0.1).shape == (3, 4, 8, nx)
    # horizon 0: just the initial state
    np.testing.assert_array_equal(model.rollout(np.ones(nx), np.zeros((0, nu)), 0.1), np.ones((1, nx)))
    # lists are fine
    assert model.rollout([0.0] * nx, [[0.0] * nu] * 3, 0.1).shape == (4, nx)


@settings(max_examples=30)
@given(model_rollout_case(), st.floats(min_value=0.01, max_value=0.3), methods)
def test_batched_rollout_equals_looped_steps(
    case: tuple[Dynamics, np.ndarray, np.ndarray], dt: float, method: str
) -> None:
    model, x0, inputs = case
    states = model.rollout(x0, inputs, dt, method=method)
    assume(np.all(np.isfinite(states)))  # a diverging arm cannot be stepped from inf
    assert states.shape == (x0.shape[0], inputs.shape[1] + 1, model.n_x)
    for b in range(x0.shape[0]):
        single = model.rollout(x0[b], inputs[b], dt, method=method)
        np.testing.assert_array_equal(states[b], single)
        x = x0[b]
        np.testing.assert_array_equal(single[0], x)
        for k in range(inputs.shape[1]):
            x = model.step(x, inputs[b, k], dt, method=method)
            np.testing.assert_allclose(single[k + 1], x, rtol=1e-14, atol=1e-14)


def test_euler_is_the_benchmark_scheme() -> None:
    # x[k+1] = x[k] + dt * f(x[k], u[k]) written out by hand for the unicycle with dt = 1
    car = get_dynamics("unicycle")
    inputs = np.array([[0.3, 0.5], [-0.3, 0.5], [0.0, -0.2]])
    states = car.rollout([1.0, 1.0, 0.0, 0.0], inputs, 1.0)
    expected = [[1.0, 1.0, 0.0, 0.0]]
    for omega, a in inputs:
        x, y, th, v = expected[-1]
        expected.append([x + v * np.cos(th), y + v * np.sin(th), th + omega, v + a])
    np.testing.assert_allclose(states, expected, rtol=1e-15, atol=1e-15)
    # the single integrator moves by dt * u exactly
    np.testing.assert_allclose(
        get_dynamics("single_integrator").rollout([0.5, 0.5], [[0.5, 0.0], [0.0, -0.5]], 1.0),
        [[0.5, 0.5], [1.0, 0.5], [1.0, 0.0]],
    )


@pytest.mark.parametrize(("method", "order"), [("euler", 1), ("rk4", 4)])
def test_integration_error_shrinks_with_the_scheme_order(method: str, order: int) -> None:
    arm = get_dynamics("two_link_arm", {"gravity": 1.0, "damping": 0.1})
    x0 = np.array([0.4, 0.9, 0.2, -0.3])
    t_end = 1.0

    def final_state(n: int) -> np.ndarray:
        u = np.tile([0.5, -0.2], (n, 1))
        return arm.rollout(x0, u, t_end / n, method=method)[-1]

    exact = arm.rollout(x0, np.tile([0.5, -0.2], (1280, 1)), t_end / 1280, method="rk4")[-1]
    errors = [np.linalg.norm(final_state(n) - exact) for n in (40, 80, 160)]
    ratios = [errors[i] / errors[i + 1] for i in range(2)]
    # halving dt divides the error by about 2**order
    for r in ratios:
        assert 2**order * 0.85 < r < 2**order * 1.15, (errors, ratios)


def test_a_diverging_rollout_returns_non_finite_values_without_warnings() -> None:
    # pytest runs with -W error, so an overflow RuntimeWarning would fail this test
    arm = get_dynamics("two_link_arm")
    states = arm.rollout([0.0, 0.5, 50.0, -50.0], np.full((40, 2), 100.0), 1.0)
    assert not np.all(np.isfinite(states))
    assert np.all(np.isfinite(states[:2]))


def test_rollout_does_not_modify_its_arguments() -> None:
    car = get_dynamics("unicycle")
    x0 = np.array([1.0, 2.0, 0.1, 0.5])
    inputs = np.ones((4, 2))
    car.rollout(x0, inputs, 0.5, method="rk4")
    np.testing.assert_array_equal(x0, [1.0, 2.0, 0.1, 0.5])
    np.testing.assert_array_equal(inputs, np.ones((4, 2)))


def test_batched_unicycle_rollout_is_fast() -> None:
    car = get_dynamics("unicycle")
    rng = np.random.default_rng(0)
    x0 = rng.uniform(0, 1, size=(1000, 4))
    inputs = rng.uniform(-0.5, 0.5, size=(1000, 20, 2))
    car.rollout(x0, inputs, 1.0)  # warm up
    timings = []
    for _ in range(5):
        start = time.perf_counter()
        car.rollout(x0, inputs, 1.0)
        timings.append(time.perf_counter() - start)
    # a few milliseconds on an idle machine; the bound leaves room for a loaded CI box
    assert min(timings) < 0.05, timings
