"""controllers.mpc: LQR oracle, constraints, tracking, infeasibility, bad inputs, warm starts and reuse."""

from __future__ import annotations

import re
import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import scipy.linalg
from hypothesis import given, settings
from hypothesis import strategies as st

from audere.apis._registry import _REGISTRY
from audere.controllers import MPCResult, mpc
from audere.controllers._mpc import _Problem, _Spec, _window
from audere.dynamics import get_dynamics
from audere.errors import InvalidArgumentError
from audere.tasks import TrackingTask
from audere.world import Circle, Polygon, Rectangle, Square, segment_distance, signed_distance

DT = 0.1
Q_DI = np.diag([1.0, 1.0, 0.1, 0.1])
R_DI = 0.1 * np.eye(2)
X0_DI = np.array([1.0, -0.5, 0.3, 0.0])


def _lqr() -> tuple[np.ndarray, np.ndarray]:
    """The discrete LQR of the Euler double integrator: value matrix P and gain K (u = -K x)."""
    model = get_dynamics("double_integrator")
    a, b = model.linearize(np.zeros(4), np.zeros(2), DT)
    p = scipy.linalg.solve_discrete_are(a, b, Q_DI, R_DI)
    k = np.linalg.solve(R_DI + b.T @ p @ b, b.T @ p @ a)
    return p, k


def _lqr_rollout(k: np.ndarray, steps: int) -> tuple[np.ndarray, np.ndarray]:
    model = get_dynamics("double_integrator")
    x = [X0_DI]
    u = []
    for _ in range(steps):
        u.append(-k @ x[-1])
        x.append(model.step(x[-1], u[-1], DT))
    return np.array(x), np.array(u)


def _circle_reference(steps: int, dt: float) -> np.ndarray:
    t = dt * np.arange(steps + 1)
    return np.column_stack([3.0 * np.cos(0.1 * t), 3.0 * np.sin(0.1 * t)])


# ------------------------------------------------------------------------------------------ oracles


@pytest.mark.parametrize("solver", ["auto", "osqp", "qrqp", "ipopt"])
def test_matches_lqr_with_terminal_value_matrix(solver: str) -> None:
    # With the DARE solution as terminal weight and no active constraint, the MPC law is the LQR law
    # for any horizon, and the closed-loop cost (terminal P included) is x0' P x0 exactly.
    p, k = _lqr()
    result = mpc("double_integrator", X0_DI, steps=40, horizon=5, dt=DT, Q=Q_DI, R=R_DI, Qf=p, solver=solver)
    assert result.status == "solved", result.message
    assert result.solver == ("osqp" if solver == "auto" else solver)
    states, inputs = _lqr_rollout(k, 40)
    np.testing.assert_allclose(result.inputs, inputs, atol=1e-5)
    np.testing.assert_allclose(result.states, states, atol=1e-5)
    assert result.cost == pytest.approx(float(X0_DI @ p @ X0_DI), rel=1e-6)


@settings(max_examples=10)
@given(
    x0=st.lists(st.floats(-2.0, 2.0), min_size=4, max_size=4),
    q=st.lists(st.floats(0.01, 10.0), min_size=4, max_size=4),
    r=st.floats(0.01, 10.0),
    horizon=st.integers(1, 8),
)
def test_lqr_equivalence_holds_for_any_weights_and_start(
    x0: list[float], q: list[float], r: float, horizon: int
) -> None:
    model = get_dynamics("double_integrator")
    a, b = model.linearize(np.zeros(4), np.zeros(2), DT)
    qm, rm = np.diag(q), r * np.eye(2)
    p = scipy.linalg.solve_discrete_are(a, b, qm, rm)
    k = np.linalg.solve(rm + b.T @ p @ b, b.T @ p @ a)
    start = np.array(x0)
    result = mpc(model, start, steps=5, horizon=horizon, dt=DT, Q=q, R=r, Qf=p, solver="qrqp")
    assert result.status == "solved"
    x = start
    for u in result.inputs:
        np.testing.assert_allclose(u, -k @ x, atol=1e-6 * max(1.0, float(np.abs(k @ x).max())))
        x = model.step(x, u, DT)


def test_long_horizon_matches_lqr_cost_with_default_terminal_weight() -> None:
    p, k = _lqr()
    result = mpc("double_integrator", X0_DI, steps=30, horizon=80, dt=DT, Q=np.diag(Q_DI), R=0.1)
    assert result.status == "solved"
    states, inputs = _lqr_rollout(k, 30)
    e = states
    lqr_cost = float(
        np.einsum("ki,ij,kj->", e[:-1], Q_DI, e[:-1])
        + np.einsum("ki,ij,kj->", inputs, R_DI, inputs)
        + e[-1] @ (10 * Q_DI) @ e[-1]
    )
    assert result.cost == pytest.approx(lqr_cost, rel=1e-4)
    np.testing.assert_allclose(result.inputs, inputs, atol=1e-4)
    # and the closed-loop LQR cost from x0 is the value x0' P x0 up to the tail beyond 30 steps
    assert result.cost == pytest.approx(float(X0_DI @ p @ X0_DI), rel=0.05)


def test_cost_is_the_objective_of_the_returned_trajectory() -> None:
    ref = np.array([[1.0, 2.0], [2.0, 2.0]])
    result = mpc("single_integrator", [0.0, 0.0], reference=ref, steps=6, horizon=3, dt=0.5, Q=2.0, R=0.5)
    padded = np.vstack([ref, np.repeat(ref[-1:], 5, axis=0)])
    e = result.states - padded
    expected = 2.0 * (e[:-1] ** 2).sum() + 0.5 * (result.inputs**2).sum() + 20.0 * (e[-1] ** 2).sum()
    assert result.cost == pytest.approx(expected, rel=1e-12)


# ------------------------------------------------------------------------------------------ constraints


@pytest.mark.parametrize("solver", ["osqp", "ipopt"])
def test_input_and_state_bounds_are_respected_and_active(solver: str) -> None:
    result = mpc(
        "double_integrator",
        [0.0, 0.0, 0.0, 0.0],
        goal=[5.0, 3.0],
        steps=40,
        horizon=15,
        dt=DT,
        u_min=-0.5,
        u_max=[0.5, 0.5],
        x_min=[-np.inf, -np.inf, -0.3, -0.3],
        x_max=[np.inf, np.inf, 0.3, 0.3],
        solver=solver,
    )
    assert result.status == "solved", result.message
    assert np.abs(result.inputs).max() <= 0.5
    assert np.isclose(np.abs(result.inputs).max(), 0.5, atol=1e-4)  # the input bound is active
    assert np.abs(result.states[:, 2:]).max() <= 0.3 + 1e-6
    assert np.abs(result.states[:, 2:]).max() >= 0.3 - 1e-4  # and the speed bound too


def test_obstacles_are_avoided_with_the_margin() -> None:
    obstacles = [Circle(center=(2.5, 0.05), radius=0.6), Square(center=(5.0, 1.2), half_side=0.3)]
    result = mpc(
        "unicycle",
        [0.0, 0.0, 0.0, 0.0],
        goal=[6.5, 0.0],
        steps=30,
        horizon=30,
        dt=0.5,
        Q=0.0,
        Qf=50.0,
        u_min=[-0.8, -0.5],
        u_max=[0.8, 0.5],
        obstacles=obstacles,
        margin=0.2,
        mode="open_loop",
    )
    assert result.status == "solved", result.message
    p = result.states[:, :2]
    assert np.hypot(*(p[-1] - [6.5, 0.0])) < 0.2
    for shape in obstacles:
        assert signed_distance(shape, p).min() >= 0.2 - 1e-6
        # the segments may cut a chord, but only by a small part of the margin
        assert segment_distance(shape, p[:-1], p[1:]).min() >= 0.1


@pytest.mark.parametrize(
    "shape",
    [
        Rectangle(xmin=1.0, xmax=3.0, ymin=-1.0, ymax=0.5),
        Square(center=(2.0, 0.0), half_side=0.5),
        Polygon(vertices=((1.5, -0.5), (2.5, -0.5), (2.0, 0.6))),
    ],
)
def test_box_and_polygon_constraints_are_conservative(shape: Any) -> None:
    result = mpc(
        "single_integrator",
        [0.0, 0.1],
        goal=[4.0, 0.0],
        steps=20,
        horizon=20,
        dt=0.25,
        R=0.01,
        u_min=-1.0,
        u_max=1.0,
        obstacles=[shape],
        margin=0.1,
        mode="open_loop",
        initial_inputs=np.repeat([[0.8, 0.8], [0.8, -0.8]], 10, axis=0),  # over the top: no local trap
    )
    assert result.status == "solved", result.message
    assert signed_distance(shape, result.states).min() >= 0.1 - 1e-6
    assert np.hypot(*(result.states[-1] - [4.0, 0.0])) < 0.3


def test_nonlinear_unicycle_tracks_a_circle() -> None:
    ref = _circle_reference(40, 0.5)
    result = mpc(
        "unicycle",
        [3.5, -0.5, np.pi / 2, 0.0],
        reference=ref,
        steps=40,
        horizon=10,
        dt=0.5,
        u_min=[-1.0, -1.0],
        u_max=[1.0, 1.0],
    )
    assert result.status == "solved", result.message
    assert result.solver == "ipopt"
    error = np.hypot(*(result.states[:, :2] - ref).T)
    assert error[0] > 0.5
    assert error[10:-3].max() < 0.05  # after the transient; the end sees the held last row
    assert set(result.step_status) == {"Solve_Succeeded"}
    assert len(result.iterations) == len(result.solve_times) == 40


def test_returned_states_are_the_task_rollout_and_pass_a_tracking_check() -> None:
    ref = _circle_reference(20, 1.0)
    task = TrackingTask(
        dynamics="unicycle",
        x0=(6.5, 3.5, float(np.pi / 2), 0.0),
        dt=1.0,
        horizon=20,
        u_min=(-0.3, -0.5),
        u_max=(0.3, 0.5),
        reference=ref + 3.5,
        tolerance=0.5,
        workspace={"xmin": 0, "xmax": 10, "ymin": 0, "ymax": 10},
    )
    result = mpc(
        "unicycle",
        task.x0,
        reference=task.reference,
        steps=20,
        horizon=6,
        dt=1.0,
        u_min=task.u_min,
        u_max=task.u_max,
        method="rk4",
    )
    model = get_dynamics("unicycle")
    rollout = model.rollout(np.asarray(task.x0), result.inputs, 1.0, method="rk4")
    np.testing.assert_array_equal(result.states, rollout)
    rk4_task = task.model_copy(update={"integrator": "rk4"})
    assert rk4_task.check(result.to_solution()).success


def test_open_loop_plans_once_and_matches_the_first_closed_loop_solve() -> None:
    kwargs: dict[str, Any] = {"goal": [2.0, 1.0, 0.0, 0.0], "horizon": 15, "dt": 0.2, "u_min": -1, "u_max": 1}
    opened = mpc("unicycle", [0.0, 0.0, 0.0, 0.0], steps=15, mode="open_loop", **kwargs)
    closed = mpc("unicycle", [0.0, 0.0, 0.0, 0.0], steps=3, **kwargs)
    assert opened.status == closed.status == "solved"
    assert len(opened.step_status) == 1
    assert opened.predicted_inputs is not None
    assert opened.predicted_states is not None
    np.testing.assert_allclose(opened.inputs, opened.predicted_inputs, atol=1e-12)
    np.testing.assert_allclose(opened.states, opened.predicted_states, atol=1e-6)
    np.testing.assert_allclose(opened.inputs[0], closed.inputs[0], atol=1e-6)
    short = mpc("unicycle", [0.0, 0.0, 0.0, 0.0], steps=5, mode="open_loop", **kwargs)
    np.testing.assert_allclose(short.inputs, opened.inputs[:5], atol=1e-9)


def test_short_reference_is_padded_with_its_last_row() -> None:
    held = mpc("single_integrator", [0.0, 0.0], reference=[[1.0, 2.0]], steps=10, horizon=5, dt=0.5)
    goal = mpc("single_integrator", [0.0, 0.0], goal=[1.0, 2.0], steps=10, horizon=5, dt=0.5)
    np.testing.assert_allclose(held.inputs, goal.inputs, atol=1e-9)
    np.testing.assert_array_equal(_window(np.array([[1.0], [2.0]]), 1, 3), [[2.0], [2.0], [2.0], [2.0]])


def test_arm_end_effector_reaches_a_position_goal() -> None:
    arm = get_dynamics("two_link_arm")
    x0 = np.array([0.3, 0.8, 0.0, 0.0])
    target = arm.position(np.array([1.2, 0.4, 0.0, 0.0]))
    result = mpc(
        arm, x0, goal=target, steps=30, horizon=30, dt=0.05, Q=0.0, R=1e-3, Qf=100.0, mode="open_loop"
    )
    assert result.status == "solved", result.message
    assert np.hypot(*(arm.position(result.states[-1]) - target)) < 0.02


def test_deterministic() -> None:
    a = mpc("unicycle", [0.0, 0.0, 0.3, 0.0], goal=[2.0, 2.0], steps=8, horizon=8, dt=0.5, u_min=-1, u_max=1)
    b = mpc("unicycle", [0.0, 0.0, 0.3, 0.0], goal=[2.0, 2.0], steps=8, horizon=8, dt=0.5, u_min=-1, u_max=1)
    np.testing.assert_array_equal(a.inputs, b.inputs)
    assert a.cost == b.cost


# ------------------------------------------------------------------------------------------ status


@pytest.mark.parametrize(
    ("solver", "solver_status"), [("osqp", "primal infeasible"), ("ipopt", "Infeasible")]
)
def test_infeasible_bounds_give_infeasible_status_with_the_solver_message(
    solver: str, solver_status: str
) -> None:
    # x may not pass 1.2, but the speed 1 m/s cannot be braked in time with |a| <= 0.1.
    result = mpc(
        "double_integrator",
        [1.0, 1.0, 1.0, 0.0],
        steps=10,
        horizon=10,
        dt=DT,
        x_max=[1.2, np.inf, np.inf, np.inf],
        u_min=-0.1,
        u_max=0.1,
        solver=solver,
    )
    assert result.status == "infeasible"
    assert result.failed_step == 0
    assert solver_status in result.message
    assert result.inputs is not None
    assert result.inputs.shape == (0, 2)
    assert not result.solved


def test_start_violating_a_state_bound_is_infeasible_without_solving() -> None:
    result = mpc("double_integrator", [1.0, 1.0, 2.0, 0.0], x_max=[np.inf, np.inf, 1.0, 1.0], steps=5)
    assert result.status == "infeasible"
    assert "x0[2] (vx) = 2 violates its bounds" in result.message
    assert result.step_status == ()


def test_start_inside_an_obstacle_is_infeasible() -> None:
    result = mpc(
        "unicycle", [1.0, 1.0, 0.0, 0.0], goal=[3.0, 3.0], obstacles=[Circle(center=(1.1, 1.0), radius=0.5)]
    )
    assert result.status == "infeasible"
    assert "inside obstacle 0" in result.message


def test_time_limit_and_iteration_limit() -> None:
    ref = _circle_reference(5, 0.5)
    kwargs: dict[str, Any] = {"reference": ref, "steps": 5, "horizon": 10, "dt": 0.5}
    slow = mpc("unicycle", [3.0, 0.0, np.pi / 2, 0.0], time_limit=1e-6, **kwargs)
    assert slow.status == "time_limit"
    assert "Maximum_WallTime_Exceeded" in slow.message
    assert slow.inputs is not None
    assert slow.inputs.shape == (5, 2)  # the loop goes on
    capped = mpc("unicycle", [3.0, 0.0, np.pi / 2, 0.0], max_iter=1, **kwargs)
    assert capped.status == "failed"
    assert capped.failed_step == 0
    assert "Maximum_Iterations_Exceeded" in capped.message
    assert capped.inputs is not None
    assert np.isfinite(capped.inputs).all()


def test_solvers_print_nothing(capfd: pytest.CaptureFixture[str]) -> None:
    for solver in ("osqp", "qrqp", "ipopt"):
        mpc("double_integrator", X0_DI, steps=3, horizon=5, dt=DT, u_min=-1, u_max=1, solver=solver)
    mpc("unicycle", [0, 0, 0, 0], goal=[1, 1], steps=2, obstacles=[Circle(center=(0.5, 0.6), radius=0.1)])
    mpc("double_integrator", [1.0, 1.0, 1.0, 0.0], x_max=[1.2, 9, 9, 9], u_min=-0.1, u_max=0.1, solver="qrqp")
    out, err = capfd.readouterr()
    assert out == ""
    assert err == ""


# ------------------------------------------------------------------------------------------ reuse


def _spec(horizon: int = 20) -> _Spec:
    inf = np.full(4, np.inf)
    return _Spec(
        model=get_dynamics("unicycle"),
        dt=0.2,
        method="euler",
        horizon=horizon,
        on_position=True,
        q=np.eye(2),
        r=0.1 * np.eye(2),
        qf=10 * np.eye(2),
        u_lo=np.array([-1.0, -1.0]),
        u_hi=np.array([1.0, 1.0]),
        x_lo=-inf,
        x_hi=inf,
        obstacles=(),
        margin=0.0,
        solver="ipopt",
        max_iter=200,
        time_limit=5.0,
    )


def test_warm_started_reuse_equals_a_cold_rebuild_and_is_faster() -> None:
    ref = _circle_reference(60, 0.2)
    x0 = [3.3, -0.3, np.pi / 2, 0.0]
    kwargs: dict[str, Any] = {
        "reference": ref,
        "steps": 25,
        "horizon": 20,
        "dt": 0.2,
        "u_min": -1,
        "u_max": 1,
    }
    warm = mpc("unicycle", x0, **kwargs)
    cold = mpc("unicycle", x0, warm_start=False, **kwargs)
    assert warm.status == cold.status == "solved"
    np.testing.assert_allclose(warm.inputs, cold.inputs, atol=1e-5)
    assert sum(warm.iterations[1:]) < sum(cold.iterations[1:])
    # The same solves with the problem rebuilt from scratch at every step.
    rebuilt_inputs = []
    rebuild_seconds = []
    assert warm.states is not None
    for k in range(25):
        start = time.perf_counter()
        problem = _Problem(_spec())
        state = warm.states[k]
        solve = problem.solve(state, _window(ref, k, 20), problem.cold_guess(state))
        rebuild_seconds.append(time.perf_counter() - start)
        assert solve.success
        rebuilt_inputs.append(solve.inputs[0])
    np.testing.assert_allclose(warm.inputs, np.array(rebuilt_inputs), atol=1e-5)
    assert np.median(warm.solve_times[1:]) < np.median(rebuild_seconds) / 2


# ------------------------------------------------------------------------------------------ bad inputs

BAD: list[tuple[dict[str, Any], str]] = [
    ({"dynamics": "boat"}, "name must be one of"),
    ({"dynamics": 3}, "dynamics must be a Dynamics model or a model name"),
    ({"x0": [0.0, 0.0, 0.0]}, r"x0 must have shape \(4,\)"),
    ({"x0": [0.0, np.nan, 0.0, 0.0]}, "x0 must be finite"),
    ({"steps": 0}, "steps must be a positive integer"),
    ({"steps": 2.5}, "steps must be a positive integer"),
    ({"horizon": -1}, "horizon must be a positive integer"),
    ({"dt": 0.0}, "dt must be a positive finite number"),
    ({"dt": "fast"}, "dt must be a positive finite number"),
    ({"reference": [[0.0, 0.0, 0.0]]}, r"reference must have shape \(T \+ 1, 2\) or \(T \+ 1, 4\)"),
    ({"reference": [0.0, 1.0]}, "reference must be a 2-D array"),
    ({"reference": [[0.0, np.inf]]}, "reference must be finite"),
    ({"goal": [1.0, 2.0, 3.0]}, r"goal must be a state \(4,\)"),
    ({"goal": [1.0, 2.0], "reference": [[1.0, 2.0]]}, "at most one of reference and goal"),
    ({"Q": [1.0, 2.0, 3.0]}, r"Q must be a scalar, a diagonal of shape \(4,\)"),
    ({"Q": -1.0}, "Q must be positive semidefinite"),
    ({"R": [[1.0, 2.0], [0.0, 1.0]]}, "R must be symmetric"),
    ({"Qf": [[1.0, 0.0], [0.0, -2.0]], "goal": [1.0, 1.0]}, "Qf must be positive semidefinite"),
    ({"u_min": [1.0, 0.0], "u_max": [0.0, 1.0]}, r"u_min must not exceed u_max, got u_min\[0\] = 1.0"),
    ({"u_min": [0.0, 0.0, 0.0]}, r"u_min must be a scalar or have shape \(2,\)"),
    ({"x_max": [np.nan, 1, 1, 1]}, "x_max must not contain NaN"),
    ({"obstacles": "circle"}, "obstacles must be a sequence"),
    ({"obstacles": [(1.0, 1.0, 0.5)]}, r"obstacles\[0\] must be a Circle"),
    ({"margin": -0.1}, "margin must be a finite number >= 0"),
    ({"mode": "closed"}, "mode must be one of 'closed_loop', 'open_loop'"),
    ({"solver": "gurobi"}, "solver must be one of"),
    ({"solver": "osqp"}, "solver 'osqp' solves quadratic programs and needs dynamics linear"),
    ({"method": "rk45"}, "method must be one of 'euler', 'rk4'"),
    ({"max_iter": 0}, "max_iter must be a positive integer"),
    ({"time_limit": float("nan")}, "time_limit must be a positive finite number"),
    ({"warm_start": "yes"}, "warm_start must be True or False"),
    ({"mode": "open_loop", "steps": 11, "horizon": 10}, "steps must not exceed horizon in open loop"),
    ({"initial_inputs": np.zeros((3, 2))}, r"initial_inputs must have shape \(horizon, n_u\) = \(10, 2\)"),
]


@pytest.mark.parametrize(("change", "match"), BAD)
def test_bad_inputs(change: dict[str, Any], match: str) -> None:
    kwargs: dict[str, Any] = {"dynamics": "unicycle", "x0": [0.0, 0.0, 0.0, 0.0], "steps": 2, "horizon": 10}
    kwargs.update(change)
    with pytest.raises(InvalidArgumentError, match=match):
        mpc(**kwargs)


def test_qp_solver_rejects_obstacles() -> None:
    with pytest.raises(InvalidArgumentError, match="obstacle constraints are nonconvex"):
        mpc(
            "single_integrator",
            [0, 0],
            goal=[1, 1],
            solver="qrqp",
            obstacles=[Circle(center=(5, 5), radius=1)],
        )


def test_registered_and_typed() -> None:
    info = _REGISTRY["mpc"]
    assert info.function is mpc
    assert "tracking" in info.tags
    result = mpc("single_integrator", [0.0, 0.0], goal=[1.0, 0.0], steps=3, horizon=3, dt=0.5)
    assert isinstance(result, MPCResult)
    assert result.times is not None
    np.testing.assert_allclose(result.times, [0.0, 0.5, 1.0, 1.5])
    assert result.solve_time >= result.build_time > 0
    solution = result.to_solution()
    assert solution.inputs is not None
    assert solution.inputs.shape == (3, 2)


# ------------------------------------------------------------------------------------------ docs

DOC = Path(__file__).resolve().parents[2] / "docs" / "apis" / "mpc.md"


@pytest.mark.parametrize("index", range(2))
def test_doc_examples_run(index: int) -> None:
    blocks = re.findall(r"```python\n(.*?)```", DOC.read_text(encoding="utf-8"), re.S)
    assert len(blocks) == 2
    exec(compile(blocks[index], str(DOC), "exec", dont_inherit=True), {"__name__": f"docs_mpc_{index}"})
