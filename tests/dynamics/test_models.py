"""The models themselves: names, parameters, equations against independent references, positions."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from audere.dynamics import (
    DoubleIntegrator,
    Dynamics,
    Pendulum,
    SingleIntegrator,
    TwoLinkArm,
    Unicycle,
    get_dynamics,
    list_dynamics,
)

from .strategies import models, vectors

EXPECTED = {
    "single_integrator": (SingleIntegrator, ("x", "y"), ("vx", "vy")),
    "double_integrator": (DoubleIntegrator, ("x", "y", "vx", "vy"), ("ax", "ay")),
    "unicycle": (Unicycle, ("x", "y", "theta", "v"), ("omega", "a")),
    "pendulum": (Pendulum, ("theta", "omega"), ("torque",)),
    "two_link_arm": (TwoLinkArm, ("q1", "q2", "dq1", "dq2"), ("tau1", "tau2")),
}


def test_list_dynamics_names_every_model_in_order() -> None:
    assert list_dynamics() == list(EXPECTED)


@pytest.mark.parametrize("name", list(EXPECTED))
def test_model_names_sizes_and_default_bounds(name: str) -> None:
    cls, states, inputs = EXPECTED[name]
    model = get_dynamics(name)
    assert type(model) is cls
    assert model.name == name
    assert model.state_names == states
    assert model.input_names == inputs
    assert (model.n_x, model.n_u) == (len(states), len(inputs))
    assert len(model.state_units) == model.n_x == len(model.state_meanings)
    assert len(model.input_units) == model.n_u == len(model.input_meanings)
    for arr, n, sign in [
        (model.state_lower, model.n_x, -1),
        (model.state_upper, model.n_x, 1),
        (model.input_lower, model.n_u, -1),
        (model.input_upper, model.n_u, 1),
    ]:
        assert arr.shape == (n,)
        assert np.all(arr == sign * np.inf)
        assert not arr.flags.writeable


def test_default_parameters() -> None:
    assert get_dynamics("pendulum").params == {"length": 1.0, "mass": 1.0, "gravity": 9.81, "damping": 0.0}
    assert get_dynamics("two_link_arm").params == {
        "l1": 1.0,
        "l2": 1.0,
        "m1": 1.0,
        "m2": 1.0,
        "gravity": 0.0,
        "damping": 0.0,
    }
    assert get_dynamics("unicycle").params == {}


def test_params_override_and_models_are_frozen_values() -> None:
    pend = get_dynamics("pendulum", {"length": 0.5, "damping": 0.1})
    assert pend == Pendulum(length=0.5, damping=0.1)
    assert pend.length == 0.5
    assert pend.mass == 1.0
    assert hash(pend) == hash(Pendulum(length=0.5, damping=0.1))
    assert get_dynamics("pendulum", {}) == Pendulum()
    with pytest.raises(dataclasses.FrozenInstanceError):
        pend.length = 2.0  # type: ignore[misc]
    # Integer parameters are stored as floats.
    assert isinstance(get_dynamics("two_link_arm", {"l1": 2}).l1, float)


# ----------------------------------------------------------------------------- independent references


def _lagrangian_reference(
    mass_positions: Callable[..., list[tuple[object, object]]],
    masses: list[float],
    gravity: float,
    damping: float,
) -> Callable[[np.ndarray, np.ndarray], np.ndarray]:
    """xdot for a chain of point masses, derived symbolically from the Lagrangian L = T - V with sympy.

    ``mass_positions(q)`` returns the (x, y) position of each point mass as sympy expressions of the
    generalized coordinates; gravity acts along -y; generalized forces are ``tau - damping * qd``.
    """
    sp = pytest.importorskip("sympy")
    n = len(masses)
    q = sp.symbols(f"q0:{n}")
    qd = sp.symbols(f"qd0:{n}")
    positions = mass_positions(*q)
    kinetic = 0
    potential = 0
    for m, (px, py) in zip(masses, positions, strict=True):
        vx = sum(sp.diff(px, qi) * qdi for qi, qdi in zip(q, qd, strict=True))
        vy = sum(sp.diff(py, qi) * qdi for qi, qdi in zip(q, qd, strict=True))
        kinetic += sp.Rational(1, 2) * m * (vx**2 + vy**2)
        potential += m * gravity * py
    lag = kinetic - potential
    # d/dt dL/dqd_i = sum_j d2L/dqd_i dqd_j qdd_j + sum_j d2L/dqd_i dq_j qd_j
    mass_matrix = sp.Matrix(n, n, lambda i, j: sp.diff(lag, qd[i], qd[j]))
    rest = sp.Matrix(
        [sum(sp.diff(lag, qd[i], q[j]) * qd[j] for j in range(n)) - sp.diff(lag, q[i]) for i in range(n)]
    )
    m_fun = sp.lambdify([*q, *qd], mass_matrix, "numpy")
    r_fun = sp.lambdify([*q, *qd], rest, "numpy")

    def xdot(x: np.ndarray, u: np.ndarray) -> np.ndarray:
        args = [float(v) for v in x]
        mm = np.array(m_fun(*args), dtype=float)
        rr = np.array(r_fun(*args), dtype=float).ravel()
        qdd = np.linalg.solve(mm, u - damping * x[n:] - rr)
        return np.concatenate([x[n:], qdd])

    return xdot


def _reference_f(model: Dynamics) -> Callable[[np.ndarray, np.ndarray], np.ndarray]:
    if isinstance(model, SingleIntegrator):
        return lambda x, u: np.array([u[0], u[1]])
    if isinstance(model, DoubleIntegrator):
        return lambda x, u: np.array([x[2], x[3], u[0], u[1]])
    if isinstance(model, Unicycle):
        return lambda x, u: np.array([x[3] * np.cos(x[2]), x[3] * np.sin(x[2]), u[0], u[1]])
    sp = pytest.importorskip("sympy")
    if isinstance(model, Pendulum):
        length = model.length
        return _lagrangian_reference(
            lambda th: [(length * sp.sin(th), -length * sp.cos(th))],
            [model.mass],
            model.gravity,
            model.damping,
        )
    assert isinstance(model, TwoLinkArm)
    l1, l2 = model.l1, model.l2

    def arm(q1: object, q2: object) -> list[tuple[object, object]]:
        elbow = (l1 * sp.cos(q1), l1 * sp.sin(q1))
        hand = (elbow[0] + l2 * sp.cos(q1 + q2), elbow[1] + l2 * sp.sin(q1 + q2))
        return [elbow, hand]

    return _lagrangian_reference(arm, [model.m1, model.m2], model.gravity, model.damping)


@pytest.mark.parametrize(
    "model",
    [
        SingleIntegrator(),
        DoubleIntegrator(),
        Unicycle(),
        Pendulum(),
        Pendulum(length=0.7, mass=2.5, gravity=3.0, damping=0.4),
        TwoLinkArm(),
        TwoLinkArm(l1=0.6, l2=1.4, m1=2.0, m2=0.5, gravity=9.81, damping=0.3),
    ],
    ids=repr,
)
def test_vector_field_matches_independent_reference(model: Dynamics) -> None:
    reference = _reference_f(model)
    rng = np.random.default_rng(7)
    xs = rng.uniform(-3, 3, size=(20, model.n_x))
    us = rng.uniform(-3, 3, size=(20, model.n_u))
    got = model.f(xs, us)
    expected = np.array([reference(x, u) for x, u in zip(xs, us, strict=True)])
    np.testing.assert_allclose(got, expected, rtol=1e-10, atol=1e-10)


def test_pendulum_equilibria_and_holding_torque() -> None:
    pend = Pendulum(length=0.8, mass=1.3, gravity=9.81, damping=0.2)
    np.testing.assert_allclose(pend.f([0.0, 0.0], [0.0]), [0.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(pend.f([np.pi, 0.0], [0.0]), [0.0, 0.0], atol=1e-14)
    theta = 0.6
    hold = pend.mass * pend.gravity * pend.length * np.sin(theta)
    np.testing.assert_allclose(pend.f([theta, 0.0], [hold]), [0.0, 0.0], atol=1e-14)
    # A small push upward from hanging accelerates back down: restoring, not destabilizing.
    assert pend.f([0.1, 0.0], [0.0])[1] < 0


def _energy(model: Dynamics, x: np.ndarray) -> float:
    """Total mechanical energy from the point-mass positions (finite-difference velocities not needed:
    velocities come from the kinematics written out here)."""
    if isinstance(model, Pendulum):
        th, om = x
        return 0.5 * model.mass * (
            model.length * om
        ) ** 2 - model.mass * model.gravity * model.length * np.cos(th)
    assert isinstance(model, TwoLinkArm)
    q1, q2, d1, d2 = x
    v1 = model.l1 * d1 * np.array([-np.sin(q1), np.cos(q1)])
    v2 = v1 + model.l2 * (d1 + d2) * np.array([-np.sin(q1 + q2), np.cos(q1 + q2)])
    y1 = model.l1 * np.sin(q1)
    y2 = y1 + model.l2 * np.sin(q1 + q2)
    kinetic = 0.5 * model.m1 * v1 @ v1 + 0.5 * model.m2 * v2 @ v2
    return float(kinetic + model.gravity * (model.m1 * y1 + model.m2 * y2))


@pytest.mark.parametrize(
    ("model", "x0"),
    [
        (Pendulum(), np.array([2.5, 0.0])),
        (TwoLinkArm(gravity=9.81), np.array([0.3, 1.2, 0.0, 0.5])),
        (TwoLinkArm(), np.array([0.0, 0.5, 1.0, -1.0])),
    ],
    ids=["pendulum", "arm-gravity", "arm-plane"],
)
def test_undamped_unforced_motion_conserves_energy(model: Dynamics, x0: np.ndarray) -> None:
    states = model.rollout(x0, np.zeros((2000, model.n_u)), 0.001, method="rk4")
    energies = np.array([_energy(model, x) for x in states[::100]])
    scale = max(1.0, abs(energies[0]))
    assert np.max(np.abs(energies - energies[0])) < 1e-8 * scale
    # and the motion is not trivial
    assert np.ptp(states[:, 0]) > 0.1


def test_damping_dissipates_energy() -> None:
    model = TwoLinkArm(gravity=9.81, damping=0.5)
    states = model.rollout([0.3, 1.2, 0.0, 0.5], np.zeros((500, 2)), 0.01, method="rk4")
    energies = np.array([_energy(model, x) for x in states])
    assert np.all(np.diff(energies) <= 1e-12)
    assert energies[-1] < energies[0] - 0.1


# ----------------------------------------------------------------------------- positions


def test_positions_of_mobile_models_are_xy() -> None:
    states = np.array([[1.0, 2.0, 0.3, 4.0], [-1.0, 5.0, 1.0, 0.0]])
    np.testing.assert_array_equal(Unicycle().position(states), states[:, :2])
    np.testing.assert_array_equal(DoubleIntegrator().position(states), states[:, :2])
    np.testing.assert_array_equal(SingleIntegrator().position(states[:, :2]), states[:, :2])


def test_pendulum_position_is_the_bob() -> None:
    pend = Pendulum(length=2.0)
    got = pend.position([[0.0, 0.0], [np.pi / 2, 1.0], [np.pi, 0.0]])
    np.testing.assert_allclose(got, [[0.0, -2.0], [2.0, 0.0], [0.0, 2.0]], atol=1e-15)


def test_arm_position_is_the_end_effector() -> None:
    arm = TwoLinkArm(l1=1.0, l2=0.5)
    got = arm.position(
        [[0.0, 0.0, 0.0, 0.0], [np.pi / 2, 0.0, 1.0, 1.0], [0.0, np.pi / 2, 0.0, 0.0], [0.0, np.pi, 0.0, 0.0]]
    )
    np.testing.assert_allclose(got, [[1.5, 0.0], [0.0, 1.5], [1.0, 0.5], [0.5, 0.0]], atol=1e-15)


@given(models(), st.data())
def test_position_is_batched(model: Dynamics, data: st.DataObject) -> None:
    states = data.draw(vectors(model.n_x, batch=(2, 3)))
    got = model.position(states)
    assert got.shape == (2, 3, 2)
    for i in range(2):
        for j in range(3):
            np.testing.assert_array_equal(got[i, j], model.position(states[i, j]))


# ----------------------------------------------------------------------------- description


@pytest.mark.parametrize("name", list(EXPECTED))
def test_describe_states_names_units_params_and_scheme(name: str) -> None:
    model = get_dynamics(name)
    text = model.describe()
    for part in (name, *model.state_names, *model.input_names, *model.state_units, *model.input_units):
        assert part in text
    for key in model.params:
        assert f"{key} = " in text
    assert "x[k+1] = x[k] + dt * f(x[k], u[k])" in text
    assert "dt = 0.5 s" in model.describe(dt=0.5)
    assert "Runge-Kutta" in model.describe(method="rk4")


def test_describe_shows_parameter_values() -> None:
    text = get_dynamics("pendulum", {"length": 0.75, "damping": 0.25}).describe()
    assert "length = 0.75 m" in text
    assert "damping = 0.25" in text
    assert "theta = 0" in text or "from straight down" in text
