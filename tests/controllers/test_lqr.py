"""controllers.lqr: oracles (DARE gain, closed-loop cost x0' P x0, Riccati recursion vs dlqr), saturation,
feed-forward inference, angle wrapping, statuses and bad inputs."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest
import scipy.linalg

from audere.controllers import LQRResult, lqr
from audere.dynamics import get_dynamics
from audere.errors import InvalidArgumentError

DOUBLE = get_dynamics("double_integrator")
Q = np.diag([1.0, 1.0, 0.1, 0.1])
R = 0.01 * np.eye(2)
DT = 0.1


def _dare_gain(a: np.ndarray, b: np.ndarray, q: np.ndarray, r: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    p = scipy.linalg.solve_discrete_are(a, b, q, r)
    return np.linalg.solve(r + b.T @ p @ b, b.T @ p @ a), p


def test_stationary_gain_and_cost_match_the_dare() -> None:
    x0 = np.array([1.0, -0.5, 0.2, 0.1])
    result = lqr(DOUBLE, x0, np.zeros((41, 4)), dt=DT, state_weight=Q, input_weight=R)
    a, b = DOUBLE.linearize(np.zeros(4), np.zeros(2), DT)
    k, p = _dare_gain(a, b, Q, R)
    assert result.status == "solved"
    assert result.mode == "stationary"
    assert result.gains.shape == (40, 2, 4)
    np.testing.assert_allclose(result.gains, np.broadcast_to(k, (40, 2, 4)), rtol=1e-8, atol=1e-10)
    np.testing.assert_allclose(result.riccati, p, rtol=1e-8)
    # With the DARE solution as terminal weight the finite-horizon closed-loop cost telescopes to x0' P x0.
    assert result.cost == pytest.approx(float(x0 @ p @ x0), rel=1e-9)
    assert result.saturated_steps == 0


def test_time_varying_recursion_reaches_the_stationary_gain() -> None:
    x0 = np.array([0.5, 0.5, 0.0, 0.0])
    a, b = DOUBLE.linearize(np.zeros(4), np.zeros(2), DT)
    k, p = _dare_gain(a, b, Q, R)
    # Terminal weight Q: the gains far from the end converge to the stationary gain.
    result = lqr(
        DOUBLE,
        x0,
        np.zeros((201, 4)),
        dt=DT,
        state_weight=Q,
        input_weight=R,
        terminal_weight=Q,
        mode="time_varying",
    )
    assert result.mode == "time_varying"
    np.testing.assert_allclose(result.gains[0], k, rtol=1e-6)
    np.testing.assert_allclose(result.riccati, p, rtol=1e-6)
    assert not np.allclose(result.gains[-1], k, rtol=1e-3)  # the last step sees only Q
    # Default terminal weight (the DARE solution): every gain is the stationary one.
    default = lqr(DOUBLE, x0, np.zeros((21, 4)), dt=DT, state_weight=Q, input_weight=R, mode="time_varying")
    np.testing.assert_allclose(default.gains, np.broadcast_to(k, (20, 2, 4)), rtol=1e-8, atol=1e-10)


def test_cost_matches_brute_force_evaluation_of_the_closed_loop() -> None:
    x0 = np.array([0.3, -0.2, 0.0, 0.1])
    res = lqr(DOUBLE, x0, np.zeros((11, 4)), dt=DT, state_weight=Q, input_weight=R, terminal_weight=2 * Q)
    states, inputs = res.states, res.inputs
    assert states is not None
    assert inputs is not None
    np.testing.assert_allclose(states, DOUBLE.rollout(x0, inputs, DT), atol=1e-12)
    expected = sum(s @ Q @ s + u @ R @ u for s, u in zip(states[:-1], inputs, strict=True))
    expected += states[-1] @ (2 * Q) @ states[-1]
    assert res.cost == pytest.approx(expected, rel=1e-12)


def test_feedforward_is_inferred_for_a_feasible_reference() -> None:
    rng = np.random.default_rng(3)
    accel = rng.uniform(-0.2, 0.2, size=(15, 2))
    x0 = np.array([1.0, 2.0, 0.1, 0.0])
    reference = DOUBLE.rollout(x0, accel, 0.5)
    res = lqr("double_integrator", x0, reference, dt=0.5, u_min=-0.25, u_max=0.25)
    np.testing.assert_allclose(res.feedforward, accel, atol=1e-12)
    assert res.max_tracking_error < 1e-12
    # Starting off the reference, the feedback pulls the state back.
    off = lqr(
        "double_integrator", x0 + np.array([0.3, -0.3, 0.0, 0.0]), reference, dt=0.5, u_min=-0.25, u_max=0.25
    )
    assert off.tracking_error[-1] < 0.2 * off.tracking_error[0]


def test_saturation_is_respected_and_counted() -> None:
    res = lqr(DOUBLE, [5.0, -5.0, 0.0, 0.0], np.zeros((31, 4)), dt=DT, u_min=-0.5, u_max=[0.5, 0.4])
    assert res.inputs is not None
    assert res.inputs.min() >= -0.5
    assert res.inputs[:, 0].max() <= 0.5
    assert res.inputs[:, 1].max() <= 0.4
    assert res.saturated_steps > 0


def test_pendulum_upright_stabilization_wraps_the_angle() -> None:
    pend = get_dynamics("pendulum")
    goal = np.array([math.pi, 0.0])
    # Start near theta = -pi (the same upright position): without wrapping the error would be ~2 pi.
    x0 = np.array([-math.pi + 0.15, 0.2])
    res = lqr(
        pend,
        x0,
        np.tile(goal, (61, 1)),
        dt=0.05,
        reference_inputs=np.zeros((60, 1)),
        u_min=-3.5,
        u_max=3.5,
        angle_indices=(0,),
    )
    assert res.status == "solved"
    assert res.tracking_error[-1] < 1e-2
    assert np.abs(res.inputs).max() <= 3.5


def test_nonlinear_model_uses_time_varying_gains() -> None:
    pend = get_dynamics("pendulum")
    reference = pend.rollout([0.2, 0.0], np.full((30, 1), 0.5), 0.05)
    res = lqr(pend, [0.25, 0.0], reference, dt=0.05)
    assert res.mode == "time_varying"
    np.testing.assert_allclose(res.feedforward, 0.5, atol=1e-9)
    assert res.tracking_error[-1] < res.tracking_error[0]


def test_unstabilizable_linearization_fails_with_a_message() -> None:
    car = get_dynamics("unicycle")  # at rest, the position cannot be steered by the linearization
    res = lqr(car, [0.0, 0.0, 0.0, 0.0], np.zeros((11, 4)), dt=0.1, mode="stationary")
    assert res.status == "failed"
    assert "Riccati" in res.message


def test_time_limit_status() -> None:
    res = lqr(DOUBLE, [1.0, 0.0, 0.0, 0.0], np.zeros((2001, 4)), dt=DT, time_limit=1e-9)
    assert res.status == "time_limit"
    assert res.inputs is None


def test_result_is_typed_and_frozen() -> None:
    res = lqr("single_integrator", [0.0, 0.0], [[0.0, 0.0], [0.5, 0.0], [1.0, 0.0]], dt=1.0)
    assert isinstance(res, LQRResult)
    assert res.times is not None
    assert res.times.tolist() == [0.0, 1.0, 2.0]
    with pytest.raises(Exception, match="frozen"):
        res.status = "failed"  # type: ignore[misc]


REF = np.zeros((11, 4))


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"dynamics": 3}, "dynamics must be a Dynamics model"),
        ({"x0": [0.0, 0.0]}, r"x0 must have shape \(4,\)"),
        ({"x0": [np.nan, 0, 0, 0]}, "x0 must be finite"),
        ({"reference": np.zeros((11, 2))}, r"reference must have shape \(horizon\+1, 4\)"),
        ({"reference": np.zeros((1, 4))}, "horizon >= 1"),
        ({"reference": np.zeros(4)}, "reference is a single state"),
        ({"reference_inputs": np.zeros((5, 2))}, r"reference_inputs must have shape \(10, 2\)"),
        ({"state_weight": -np.eye(4)}, "state_weight must be positive semidefinite"),
        ({"state_weight": np.ones((3, 3))}, "state_weight must be a scalar, a diagonal"),
        ({"input_weight": 0.0}, "input_weight must be positive definite"),
        ({"input_weight": [[1.0, 2.0], [0.0, 1.0]]}, "input_weight must be symmetric"),
        ({"u_min": 1.0, "u_max": -1.0}, "u_min must be <= u_max"),
        ({"u_min": [0.0, 0.0, 0.0]}, r"u_min must be a scalar or have shape \(2,\)"),
        ({"mode": "fast"}, "mode must be"),
        ({"angle_indices": (7,)}, "angle_indices must be state indices"),
        ({"time_limit": 0.0}, "time_limit must be a positive number"),
        ({"dt": -1.0}, "dt must be a positive finite number"),
        ({"method": "midpoint"}, "method must be one of"),
    ],
)
def test_bad_inputs(kwargs: dict[str, object], match: str) -> None:
    args: dict[str, object] = {"dynamics": DOUBLE, "x0": [1.0, 0.0, 0.0, 0.0], "reference": REF, "dt": DT}
    args.update(kwargs)
    with pytest.raises(InvalidArgumentError, match=match):
        lqr(**args)  # type: ignore[arg-type]


def test_docs_page_examples_run() -> None:
    page = Path(__file__).resolve().parents[2] / "docs" / "apis" / "lqr.md"
    blocks = re.findall(r"```python\n(.*?)```", page.read_text(encoding="utf-8"), re.S)
    assert blocks
    for block in blocks:
        exec(compile(block, str(page), "exec"), {"__name__": "docs_example"})
