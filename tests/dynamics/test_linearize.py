"""Linearization by complex step: against central finite differences, CasADi's jacobian, closed forms."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest
from hypothesis import given, settings

from audere.dynamics import Dynamics, get_dynamics, list_dynamics

from .strategies import dts, methods, model_state_input


def _central_differences(
    fun: object, x: np.ndarray, u: np.ndarray, eps: float = 1e-6
) -> tuple[np.ndarray, np.ndarray]:
    """Jacobians of ``fun(x, u)`` by central differences (the independent reference)."""
    call = fun  # type: ignore[assignment]
    y0 = np.asarray(call(x, u))
    a = np.zeros((y0.size, x.size))
    b = np.zeros((y0.size, u.size))
    for j in range(x.size):
        d = np.zeros_like(x)
        d[j] = eps
        a[:, j] = (call(x + d, u) - call(x - d, u)) / (2 * eps)
    for j in range(u.size):
        d = np.zeros_like(u)
        d[j] = eps
        b[:, j] = (call(x, u + d) - call(x, u - d)) / (2 * eps)
    return a, b


@settings(max_examples=40)
@given(model_state_input(bound=2.0), dts, methods)
def test_discrete_linearization_matches_central_differences(
    case: tuple[Dynamics, np.ndarray, np.ndarray], dt: float, method: str
) -> None:
    model, x, u = case
    a, b = model.linearize(x, u, dt, method=method)
    assert a.shape == (model.n_x, model.n_x)
    assert b.shape == (model.n_x, model.n_u)
    assert a.dtype == b.dtype == np.float64
    fa, fb = _central_differences(lambda xx, uu: model.step(xx, uu, dt, method=method), x, u)
    np.testing.assert_allclose(a, fa, rtol=1e-6, atol=1e-6)
    np.testing.assert_allclose(b, fb, rtol=1e-6, atol=1e-6)


@settings(max_examples=40)
@given(model_state_input(bound=2.0))
def test_continuous_linearization_matches_central_differences(
    case: tuple[Dynamics, np.ndarray, np.ndarray],
) -> None:
    model, x, u = case
    a, b = model.linearize_continuous(x, u)
    fa, fb = _central_differences(model.f, x, u)
    np.testing.assert_allclose(a, fa, rtol=1e-6, atol=1e-6)
    np.testing.assert_allclose(b, fb, rtol=1e-6, atol=1e-6)


@settings(max_examples=25)
@given(model_state_input(bound=2.0), dts, methods)
def test_linearization_matches_casadi_jacobian(
    case: tuple[Dynamics, np.ndarray, np.ndarray], dt: float, method: str
) -> None:
    model, x, u = case
    xs = ca.SX.sym("x", model.n_x)
    us = ca.SX.sym("u", model.n_u)
    nxt = model.step_casadi(xs, us, dt, method=method)
    jac = ca.Function("jacobians", [xs, us], [ca.jacobian(nxt, xs), ca.jacobian(nxt, us)])
    ja, jb = (np.asarray(m.full()) for m in jac(x, u))
    a, b = model.linearize(x, u, dt, method=method)
    np.testing.assert_allclose(a, ja, rtol=1e-11, atol=1e-11)
    np.testing.assert_allclose(b, jb, rtol=1e-11, atol=1e-11)


@settings(max_examples=25)
@given(model_state_input(bound=2.0), dts)
def test_euler_jacobians_are_identity_plus_dt_times_continuous(
    case: tuple[Dynamics, np.ndarray, np.ndarray], dt: float
) -> None:
    model, x, u = case
    a, b = model.linearize(x, u, dt)
    ac, bc = model.linearize_continuous(x, u)
    np.testing.assert_allclose(a, np.eye(model.n_x) + dt * ac, rtol=1e-13, atol=1e-13)
    np.testing.assert_allclose(b, dt * bc, rtol=1e-13, atol=1e-13)


def test_closed_form_jacobians() -> None:
    a, b = get_dynamics("double_integrator").linearize([1, 2, 3, 4], [5, 6], 0.5)
    expected_a = np.eye(4)
    expected_a[0, 2] = expected_a[1, 3] = 0.5
    np.testing.assert_array_equal(a, expected_a)
    np.testing.assert_array_equal(b, [[0, 0], [0, 0], [0.5, 0], [0, 0.5]])

    theta, v = 0.3, 2.0
    ac, bc = get_dynamics("unicycle").linearize_continuous([0, 0, theta, v], [0, 0])
    expected = np.zeros((4, 4))
    expected[0, 2], expected[0, 3] = -v * np.sin(theta), np.cos(theta)
    expected[1, 2], expected[1, 3] = v * np.cos(theta), np.sin(theta)
    np.testing.assert_allclose(ac, expected, rtol=1e-15, atol=1e-15)
    np.testing.assert_array_equal(bc, [[0, 0], [0, 0], [1, 0], [0, 1]])

    pend = get_dynamics("pendulum", {"length": 0.5, "mass": 2.0, "damping": 0.3})
    ac, bc = pend.linearize_continuous([np.pi, 0.0], [0.0])  # upright: unstable, +g/l
    np.testing.assert_allclose(ac, [[0, 1], [9.81 / 0.5, -0.3 / (2.0 * 0.25)]], rtol=1e-14)
    np.testing.assert_allclose(bc, [[0], [1 / (2.0 * 0.25)]], rtol=1e-14)


@pytest.mark.parametrize("name", list_dynamics())
def test_batched_linearization_equals_looped(name: str) -> None:
    model = get_dynamics(name)
    rng = np.random.default_rng(5)
    xs = rng.normal(size=(3, 2, model.n_x))
    us = rng.normal(size=(3, 2, model.n_u))
    a, b = model.linearize(xs, us, 0.1, method="rk4")
    assert a.shape == (3, 2, model.n_x, model.n_x)
    assert b.shape == (3, 2, model.n_x, model.n_u)
    for i in range(3):
        for j in range(2):
            aij, bij = model.linearize(xs[i, j], us[i, j], 0.1, method="rk4")
            np.testing.assert_array_equal(a[i, j], aij)
            np.testing.assert_array_equal(b[i, j], bij)
    # one input linearized along many states (broadcasting)
    a1, _ = model.linearize(xs, us[0, 0], 0.1)
    assert a1.shape == (3, 2, model.n_x, model.n_x)


def test_linearization_needs_neither_torch_nor_casadi() -> None:
    import subprocess
    import sys

    code = (
        "import sys\n"
        "sys.modules['torch'] = None; sys.modules['casadi'] = None\n"
        "from audere.dynamics import get_dynamics\n"
        "a, b = get_dynamics('two_link_arm').linearize([0.1, 0.2, 0.3, 0.4], [1.0, 2.0], 0.1, method='rk4')\n"
        "print(a.shape, b.shape)\n"
    )
    done = subprocess.run(
        [sys.executable, "-W", "error", "-c", code], capture_output=True, text=True, check=False
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "(4, 4) (4, 2)"
