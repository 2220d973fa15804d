"""numpy, torch and CasADi evaluate the same definition: values agree; torch gradients are right."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest
import torch
from hypothesis import given, settings
from hypothesis import strategies as st

from audere.dynamics import Dynamics, get_dynamics, list_dynamics

from .strategies import dts, methods, model_rollout_case, model_state_input, models, vectors

TOL = {"rtol": 1e-12, "atol": 1e-12}


def _casadi_eval(expr: object) -> np.ndarray:
    return np.asarray(ca.DM(expr).full(), dtype=float).ravel()


@settings(max_examples=40)
@given(model_state_input(), dts, methods)
def test_three_backends_agree_on_f_and_step(
    case: tuple[Dynamics, np.ndarray, np.ndarray], dt: float, method: str
) -> None:
    model, x, u = case
    f_np = model.f(x, u)
    f_t = model.f_torch(torch.from_numpy(x), torch.from_numpy(u))
    f_c = _casadi_eval(model.f_casadi(ca.DM(x), ca.DM(u)))
    np.testing.assert_allclose(f_t.numpy(), f_np, **TOL)
    np.testing.assert_allclose(f_c, f_np, **TOL)

    s_np = model.step(x, u, dt, method=method)
    s_t = model.step_torch(torch.from_numpy(x), torch.from_numpy(u), dt, method=method)
    s_c = _casadi_eval(model.step_casadi(ca.DM(x), ca.DM(u), dt, method=method))
    s_fun = _casadi_eval(model.casadi_function(dt, method=method)(x, u))
    np.testing.assert_allclose(s_t.numpy(), s_np, **TOL)
    np.testing.assert_allclose(s_c, s_np, **TOL)
    np.testing.assert_allclose(s_fun, s_np, **TOL)
    # and the step is really the scheme's formula, not just consistent across backends
    if method == "euler":
        np.testing.assert_allclose(s_np, x + dt * f_np, **TOL)

    p_np = model.position(x)
    np.testing.assert_allclose(model.position_torch(torch.from_numpy(x)).numpy(), p_np, **TOL)
    np.testing.assert_allclose(_casadi_eval(model.position_casadi(ca.DM(x))), p_np, **TOL)


@settings(max_examples=25)
@given(model_rollout_case(), dts, methods)
def test_torch_rollout_matches_numpy(
    case: tuple[Dynamics, np.ndarray, np.ndarray], dt: float, method: str
) -> None:
    model, x0, inputs = case
    got = model.rollout_torch(torch.from_numpy(x0), torch.from_numpy(inputs), dt, method=method)
    np.testing.assert_allclose(got.numpy(), model.rollout(x0, inputs, dt, method=method), **TOL)


@pytest.mark.parametrize("name", list_dynamics())
def test_casadi_function_interface_and_symbolic_inputs(name: str) -> None:
    model = get_dynamics(name)
    fun = model.casadi_function(0.2, method="rk4")
    assert fun.name() == "F"
    assert fun.name_in() == ["x", "u"]
    assert fun.name_out() == ["x_next"]
    assert fun.size_in(0) == (model.n_x, 1)
    assert fun.size_in(1) == (model.n_u, 1)
    assert model.casadi_function(0.2, name="step").name() == "step"
    # SX and MX symbols both go through the same definition.
    for sym in (ca.SX, ca.MX):
        x = sym.sym("x", model.n_x)
        u = sym.sym("u", model.n_u)
        expr = model.step_casadi(x, u, 0.2, method="rk4")
        assert expr.shape == (model.n_x, 1)
        rng = np.random.default_rng(3)
        xv, uv = rng.normal(size=model.n_x), rng.normal(size=model.n_u)
        value = _casadi_eval(ca.Function("g", [x, u], [expr])(xv, uv))
        np.testing.assert_allclose(value, model.step(xv, uv, 0.2, method="rk4"), **TOL)
    # many columns at once through map
    rng = np.random.default_rng(4)
    xs, us = rng.normal(size=(6, model.n_x)), rng.normal(size=(6, model.n_u))
    mapped = np.asarray(fun.map(6)(xs.T, us.T).full()).T
    np.testing.assert_allclose(mapped, model.step(xs, us, 0.2, method="rk4"), **TOL)


def test_casadi_accepts_numpy_vectors() -> None:
    model = get_dynamics("unicycle")
    out = model.f_casadi(np.array([0.0, 0.0, 0.0, 2.0]), [0.5, 1.0])
    assert isinstance(out, ca.DM)
    np.testing.assert_allclose(_casadi_eval(out), [2.0, 0.0, 0.5, 1.0])


@pytest.mark.parametrize("dtype", [torch.float32, torch.float64])
def test_torch_keeps_dtype_and_device(dtype: torch.dtype) -> None:
    model = get_dynamics("two_link_arm")
    x = torch.zeros(3, 4, dtype=dtype)
    u = torch.ones(3, 2, dtype=dtype)
    for out in (model.f_torch(x, u), model.step_torch(x, u, 0.1, method="rk4")):
        assert out.dtype == dtype
        assert out.device == x.device
        assert out.shape == (3, 4)
    states = model.rollout_torch(x, torch.ones(3, 5, 2, dtype=dtype), 0.1)
    assert states.dtype == dtype
    assert states.shape == (3, 6, 4)
    assert model.position_torch(states).shape == (3, 6, 2)


def test_torch_converts_a_non_tensor_argument_to_the_tensor_dtype() -> None:
    model = get_dynamics("unicycle")
    inputs = torch.zeros(5, 2, dtype=torch.float32)
    states = model.rollout_torch(np.array([1.0, 2.0, 0.0, 1.0]), inputs, 1.0)
    assert states.dtype == torch.float32
    np.testing.assert_allclose(states[-1].numpy(), [6.0, 2.0, 0.0, 1.0])
    assert model.f_torch([0.0, 0.0, 0.0, 1.0], torch.zeros(2, dtype=torch.float64)).dtype == torch.float64


@given(models(), st.data())
@settings(max_examples=20)
def test_torch_broadcasts_batches_like_numpy(model: Dynamics, data: st.DataObject) -> None:
    x = data.draw(vectors(model.n_x, batch=(3, 1)))
    u = data.draw(vectors(model.n_u, batch=(2,)))
    got = model.f_torch(torch.from_numpy(x), torch.from_numpy(u))
    assert got.shape == (3, 2, model.n_x)
    np.testing.assert_allclose(got.numpy(), model.f(x, u), **TOL)


def _rollout_cost(model: Dynamics, x0: np.ndarray, inputs: np.ndarray, dt: float, method: str) -> float:
    """A smooth cost of the whole trajectory, computed with numpy (the reference for autograd)."""
    states = model.rollout(x0, inputs, dt, method=method)
    return float(np.sum(model.position(states) ** 2) + 0.1 * np.sum(np.sin(states) ** 2))


@pytest.mark.parametrize("name", list_dynamics())
@pytest.mark.parametrize("method", ["euler", "rk4"])
def test_torch_gradient_of_a_rollout_cost_matches_finite_differences(name: str, method: str) -> None:
    model = get_dynamics(name)
    rng = np.random.default_rng(11)
    x0 = rng.normal(size=model.n_x)
    inputs = rng.normal(scale=0.5, size=(6, model.n_u))
    dt = 0.2
    u_t = torch.tensor(inputs, requires_grad=True)
    states = model.rollout_torch(torch.tensor(x0), u_t, dt, method=method)
    cost = torch.sum(model.position_torch(states) ** 2) + 0.1 * torch.sum(torch.sin(states) ** 2)
    (grad,) = torch.autograd.grad(cost, u_t)
    assert torch.all(torch.isfinite(grad))
    np.testing.assert_allclose(cost.item(), _rollout_cost(model, x0, inputs, dt, method), rtol=1e-12)

    eps = 1e-6
    fd = np.zeros_like(inputs)
    for idx in np.ndindex(*inputs.shape):
        plus, minus = inputs.copy(), inputs.copy()
        plus[idx] += eps
        minus[idx] -= eps
        fd[idx] = (
            _rollout_cost(model, x0, plus, dt, method) - _rollout_cost(model, x0, minus, dt, method)
        ) / (2 * eps)
    np.testing.assert_allclose(grad.numpy(), fd, rtol=1e-5, atol=1e-6)
    # the inputs matter: a zero gradient would pass the check vacuously
    assert np.linalg.norm(fd) > 1e-3


def test_torch_gradient_flows_to_x0_and_float32_works() -> None:
    model = get_dynamics("pendulum")
    x0 = torch.tensor([0.5, 0.0], dtype=torch.float32, requires_grad=True)
    inputs = torch.zeros(10, 1, dtype=torch.float32, requires_grad=True)
    states = model.rollout_torch(x0, inputs, 0.05, method="rk4")
    states[-1, 0].backward()
    assert x0.grad is not None
    assert inputs.grad is not None
    assert x0.grad.dtype == torch.float32
    assert torch.all(torch.isfinite(x0.grad))
    assert x0.grad[0] > 0  # starting further out leaves the pendulum further out after a short time
