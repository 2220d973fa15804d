"""controllers.pid: oracle tests (geometric convergence, saturation, anti-windup), bad inputs, track-lin."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from audere import scenarios
from audere.controllers import pid
from audere.dynamics import get_dynamics
from audere.errors import InvalidArgumentError
from audere.tasks import Solution


def test_p_only_single_integrator_converges_geometrically() -> None:
    kp, dt = 0.3, 0.5
    reference = np.tile([4.0, -1.0], (16, 1))
    x0 = np.array([1.0, 1.0])
    result = pid("single_integrator", x0, reference, dt, kp=kp, feedforward=False)
    assert result.status == "solved"
    expected = np.linalg.norm(reference[0] - x0) * (1.0 - kp * dt) ** np.arange(16)
    np.testing.assert_allclose(result.errors, expected, rtol=1e-12, atol=1e-12)
    assert result.states is not None
    assert result.states.shape == (16, 2)
    assert result.inputs is not None
    assert result.inputs.shape == (15, 2)
    np.testing.assert_allclose(result.times, 0.5 * np.arange(16))
    assert result.cost == pytest.approx(float(np.mean(expected)))


def test_pd_double_integrator_matches_the_closed_loop_matrix() -> None:
    # per axis, with a constant reference: e[k+1] = A e[k], e = (position error, velocity error)
    kp, kd, dt = 0.6, 1.1, 0.4
    target = np.array([3.0, -2.0])
    reference = np.tile(target, (31, 1))
    x0 = np.array([0.5, 1.0, 0.2, -0.3])
    result = pid("double_integrator", x0, reference, dt, kp=kp, kd=kd, feedforward=False)
    a_cl = np.array([[1.0, dt], [-dt * kp, 1.0 - dt * kd]])
    e0 = np.stack([target - x0[:2], -x0[2:]])  # rows: position error, velocity error; columns: axes
    expected = np.array([np.linalg.matrix_power(a_cl, k) @ e0 for k in range(31)])
    assert result.states is not None
    np.testing.assert_allclose(target - result.states[:, :2], expected[:, 0, :], atol=1e-12)
    np.testing.assert_allclose(-result.states[:, 2:], expected[:, 1, :], atol=1e-12)


@given(
    kp=st.floats(0.0, 3.0),
    ki=st.floats(0.0, 2.0),
    kd=st.floats(0.0, 0.5),
    bound=st.floats(0.05, 2.0),
    anti_windup=st.sampled_from(["clamping", "back_calculation", "none"]),
    name=st.sampled_from(["single_integrator", "double_integrator", "unicycle"]),
)
def test_inputs_stay_in_bounds_and_states_are_their_rollout(
    kp: float, ki: float, kd: float, bound: float, anti_windup: Any, name: str
) -> None:
    model = get_dynamics(name)
    reference = np.linspace([0.0, 0.0], [3.0, 2.0], 16)
    x0 = np.zeros(model.n_x)
    x0[:2] = [0.4, -0.2]
    result = pid(
        model, x0, reference, 0.5, kp=kp, ki=ki, kd=kd, u_min=-bound, u_max=bound, anti_windup=anti_windup
    )
    assert result.status == "solved"
    assert result.inputs is not None
    assert np.all(np.abs(result.inputs) <= bound)
    np.testing.assert_allclose(result.states, model.rollout(x0, result.inputs, 0.5), rtol=0, atol=1e-9)


def test_states_are_the_rollout_of_the_inputs() -> None:
    reference = np.linspace([0.0, 0.0], [3.0, 1.0], 21)
    for name, x0 in [("single_integrator", [0.2, 0.0]), ("double_integrator", [0.0, 0.3, 0.0, 0.0])]:
        result = pid(name, x0, reference, 0.2, ki=0.1, u_min=-1.0, u_max=1.0)
        assert result.inputs is not None
        rolled = get_dynamics(name).rollout(x0, result.inputs, 0.2)
        np.testing.assert_allclose(result.states, rolled, rtol=0, atol=1e-12)


def test_feedforward_tracks_a_feasible_reference_exactly() -> None:
    reference = np.cumsum(np.vstack([[1.0, 1.0], np.full((20, 2), 0.3)]), axis=0)
    result = pid("single_integrator", reference[0], reference, 1.0, u_min=-0.5, u_max=0.5)
    assert result.max_error == pytest.approx(0.0, abs=1e-12)
    assert result.saturated_steps == 0


@pytest.mark.parametrize("name", ["single_integrator", "double_integrator", "unicycle"])
def test_saturation_is_respected(name: str) -> None:
    n_x = get_dynamics(name).n_x
    x0 = np.zeros(n_x)
    reference = np.tile([8.0, 5.0], (31, 1))
    lo, hi = np.array([-0.3, -0.2]), np.array([0.25, 0.4])
    result = pid(name, x0, reference, 0.5, kp=5.0, ki=1.0, u_min=lo, u_max=hi)
    assert result.inputs is not None
    assert np.all(result.inputs >= lo - 1e-15)
    assert np.all(result.inputs <= hi + 1e-15)
    assert result.saturated_steps > 0


def _overshoot(anti_windup: Any) -> float:
    """Largest excursion past a step target on the x axis (single integrator, tight saturation)."""
    reference = np.tile([5.0, 0.0], (121, 1))
    result = pid(
        "single_integrator",
        [0.0, 0.0],
        reference,
        0.1,
        kp=1.0,
        ki=0.8,
        u_min=-0.5,
        u_max=0.5,
        anti_windup=anti_windup,
        feedforward=False,
    )
    assert result.states is not None
    return float(result.states[:, 0].max() - 5.0)


def test_anti_windup_reduces_overshoot() -> None:
    none = _overshoot("none")
    clamping = _overshoot("clamping")
    back = _overshoot("back_calculation")
    assert none > 0.5  # the wound-up integrator carries the state far past the target
    assert clamping < 0.25 * none
    assert back < 0.25 * none


def test_integrator_limit_bounds_the_integral() -> None:
    reference = np.tile([5.0, 0.0], (60, 1))
    result = pid(
        "single_integrator",
        [0.0, 0.0],
        reference,
        0.1,
        kp=0.5,
        ki=1.0,
        integrator_limit=0.2,
        anti_windup="none",
    )
    assert result.integral is not None
    assert np.all(np.abs(result.integral) <= 0.2 + 1e-15)


def test_double_integrator_pd_converges_and_unicycle_follows_a_line() -> None:
    reference = np.tile([2.0, -1.0], (81, 1))
    result = pid("double_integrator", [0.0, 0.0, 0.0, 0.0], reference, 0.25)
    assert result.final_error is not None
    assert result.final_error < 1e-2
    line = np.linspace([0.0, 0.0], [6.0, 3.0], 41)
    car = pid("unicycle", [0.0, 0.0, 0.0, 0.0], line, 0.25, u_min=[-1.0, -1.0], u_max=[1.0, 1.0])
    assert car.mean_error is not None
    assert car.mean_error < 0.3
    assert car.final_error is not None
    assert car.final_error < 0.3


def test_divergence_is_reported_not_raised() -> None:
    reference = np.tile([1.0, 1.0], (1200, 1))
    result = pid("single_integrator", [0.0, 0.0], reference, 1.0, kp=3.0, feedforward=False)
    assert result.status == "failed"
    assert "diverged" in result.message


def test_time_limit_gives_time_limit_status() -> None:
    reference = np.tile([1.0, 1.0], (20001, 1))
    result = pid("single_integrator", [0.0, 0.0], reference, 0.01, time_limit=1e-4)
    assert result.status == "time_limit"
    assert result.states is not None
    assert result.inputs is not None
    assert len(result.states) == len(result.inputs) + 1 < 20001


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"dynamics": "pendulum"}, r"dynamics must be one of .*got 'pendulum'"),
        ({"dynamics": "boat"}, r"name must be one of"),
        ({"x0": [0.0, 0.0, 0.0]}, r"x0 must have shape \(2,\), got shape \(3,\)"),
        ({"x0": [0.0, float("nan")]}, r"x0 must be finite"),
        ({"reference": [[0.0, 0.0]]}, r"reference must have at least 2 rows"),
        ({"reference": np.zeros((5, 3))}, r"reference must have shape \(horizon\+1, 2\)"),
        ({"dt": 0.0}, r"dt must be a positive finite number"),
        ({"kp": -1.0}, r"kp must be >= 0"),
        ({"kd": [1.0, 2.0, 3.0]}, r"kd must be a number or an array of shape \(2,\)"),
        ({"u_min": 1.0, "u_max": 0.0}, r"u_min must be <= u_max"),
        ({"anti_windup": "magic"}, r"anti_windup must be"),
        ({"integrator_limit": 0.0}, r"integrator_limit must be a positive number"),
        ({"lookahead": 0}, r"lookahead must be an integer >= 1"),
        ({"time_limit": -1.0}, r"time_limit must be a positive number"),
        ({"method": "rk45"}, r"method must be 'euler' or 'rk4'"),
    ],
)
def test_bad_inputs(kwargs: dict[str, Any], match: str) -> None:
    call: dict[str, Any] = {"dynamics": "single_integrator", "x0": [0.0, 0.0], "reference": np.zeros((4, 2))}
    call["dt"] = 1.0
    call.update(kwargs)
    with pytest.raises(InvalidArgumentError, match=match):
        pid(**call)


def solve_track_lin_with_pid(task: Any) -> Solution:
    """track-lin with PID alone: P with reference feed-forward, clipped to the task's bounds."""
    result = pid(task.dynamics, task.x0, task.reference, task.dt, u_min=task.u_min, u_max=task.u_max)
    return result.to_solution()


@pytest.mark.parametrize("seed", range(20))
def test_pid_alone_passes_track_lin(seed: int) -> None:
    task = scenarios.make("track-lin", seed=seed)
    assert task.check(solve_track_lin_with_pid(task)).success


@pytest.mark.slow
def test_pid_alone_passes_track_lin_100_seeds() -> None:
    failed = [
        s
        for s in range(100)
        if not (t := scenarios.make("track-lin", seed=s)).check(solve_track_lin_with_pid(t)).success
    ]
    assert failed == []


def test_pid_card_and_schema() -> None:
    from audere.apis import api_card, tool_schema, validate_call

    card = api_card("pid")
    assert "AntiWindup = Literal['clamping', 'back_calculation', 'none']\n" in card
    assert "def pid(\n    dynamics: Dynamics | str,\n" in card
    assert "class PIDResult(Result):" in card
    properties = tool_schema("pid")["function"]["parameters"]["properties"]
    assert properties["anti_windup"]["enum"] == ["clamping", "back_calculation", "none"]
    kwargs = validate_call(
        "pid",
        {"dynamics": "single_integrator", "x0": [0, 0], "reference": [[1, 0], [1, 0]], "dt": 0.5, "kp": [1]},
    )
    result = pid(**kwargs)
    np.testing.assert_allclose(result.states, [[0, 0], [0.5, 0]])
