"""planners.cem: analytic optimum of a quadratic problem, cost factories, determinism, statuses."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from audere.dynamics import get_dynamics
from audere.errors import InvalidArgumentError
from audere.planners import (
    CEMResult,
    cem,
    effort_cost,
    goal_cost,
    obstacle_cost,
    tracking_cost,
)
from audere.world import Circle, Rectangle, signed_distance

SINGLE = get_dynamics("single_integrator")


def test_finds_the_analytic_optimum_of_a_quadratic_problem() -> None:
    # min ||x_T - g||^2 + lam * mean_k ||u_k||^2 for x_{k+1} = x_k + dt u_k: by symmetry all inputs are
    # equal, u* = dt d / (T dt^2 + lam / T) with d = g - x0 (bounds inactive).
    x0, goal, dt, horizon, lam = np.array([0.0, 0.0]), np.array([1.0, -0.5]), 0.5, 8, 0.5
    d = goal - x0
    u_star = dt * d / (horizon * dt**2 + lam / horizon)
    optimum = float(np.sum((d - horizon * dt * u_star) ** 2) + lam * np.sum(u_star**2))
    result = cem(
        SINGLE,
        x0,
        cost=[goal_cost(goal), effort_cost(weight=lam)],
        horizon=horizon,
        dt=dt,
        u_min=-1.0,
        u_max=1.0,
        population=200,
        iterations=60,
        seed=1,
    )
    assert result.status == "solved"
    assert result.cost is not None
    assert optimum <= result.cost <= optimum * 1.02 + 1e-6
    assert result.inputs is not None
    np.testing.assert_allclose(result.inputs.mean(axis=0), u_star, atol=0.02)
    # The reported cost is the cost of the returned inputs' rollout.
    states = SINGLE.rollout(x0, result.inputs, dt)
    np.testing.assert_allclose(result.states, states)
    again = goal_cost(goal)(states[None], result.inputs[None]) + effort_cost(weight=lam)(
        states[None], result.inputs[None]
    )
    assert float(again[0]) == pytest.approx(result.cost, rel=1e-12)
    history = result.cost_history
    assert np.all(np.diff(history) <= 0)  # the best cost never gets worse


def test_same_seed_same_result_and_bounds_respected() -> None:
    args = {"horizon": 10, "dt": 1.0, "u_min": [-0.3, -0.2], "u_max": [0.3, 0.1], "iterations": 5}
    cost = goal_cost([3.0, -3.0])
    a = cem("single_integrator", [0.0, 0.0], cost=cost, seed=7, **args)  # type: ignore[arg-type]
    b = cem("single_integrator", [0.0, 0.0], cost=cost, seed=7, **args)  # type: ignore[arg-type]
    c = cem("single_integrator", [0.0, 0.0], cost=cost, seed=8, **args)  # type: ignore[arg-type]
    assert a.inputs is not None
    assert b.inputs is not None
    assert c.inputs is not None
    np.testing.assert_array_equal(a.inputs, b.inputs)
    assert not np.array_equal(a.inputs, c.inputs)
    assert a.inputs[:, 0].min() >= -0.3
    assert a.inputs[:, 0].max() <= 0.3
    assert a.inputs[:, 1].min() >= -0.2
    assert a.inputs[:, 1].max() <= 0.1


def test_goal_cost_wraps_angles_and_weights_the_path() -> None:
    states = np.zeros((2, 3, 2))
    states[0, -1] = [np.pi - 0.1, 0.0]
    states[1, -1] = [-np.pi + 0.1, 0.0]  # the same distance to pi once wrapped
    cost = goal_cost([np.pi, 0.0], angle_indices=(0,))
    np.testing.assert_allclose(cost(states, np.zeros((2, 2, 1))), [0.01, 0.01], atol=1e-12)
    running = goal_cost([1.0, 0.0], weight=[2.0, 0.0], running_weight=3.0)
    x = np.zeros((1, 3, 2))
    x[0, :, 0] = [0.0, 0.5, 1.0]
    expected = 0.0 + 3.0 * np.mean([2.0 * 1.0, 2.0 * 0.25, 0.0])
    assert running(x, np.zeros((1, 2, 2)))[0] == pytest.approx(expected)


def test_tracking_and_obstacle_costs_against_direct_computation() -> None:
    rng = np.random.default_rng(0)
    states = rng.uniform(0.0, 3.0, size=(4, 6, 2))
    reference = rng.uniform(0.0, 3.0, size=(6, 2))
    track = tracking_cost(reference, weight=[1.0, 2.0])
    expected = ((states - reference) ** 2 * [1.0, 2.0]).sum(axis=-1).mean(axis=-1)
    np.testing.assert_allclose(track(states, np.zeros((4, 5, 2))), expected)
    shapes = [Circle(center=(1.5, 1.5), radius=0.7), Rectangle(xmin=0.0, xmax=1.0, ymin=2.0, ymax=3.0)]
    obstacles = obstacle_cost(shapes, margin=0.2, weight=5.0)
    manual = np.zeros(4)
    for shape in shapes:
        sd = signed_distance(shape, states.reshape(-1, 2)).reshape(4, 6)
        manual += (np.maximum(0.0, 0.2 - sd) ** 2).sum(axis=-1)
    np.testing.assert_allclose(obstacles(states, np.zeros((4, 5, 2))), 5.0 * manual)
    far = np.full((1, 3, 2), 9.0)
    assert obstacles(far, np.zeros((1, 2, 2)))[0] == 0.0


def test_avoids_an_obstacle_on_the_straight_line() -> None:
    circle = Circle(center=(1.0, 0.0), radius=0.4)
    result = cem(
        SINGLE,
        [0.0, 0.0],
        goal=[2.0, 0.0],
        goal_weight=10.0,
        obstacles=[circle],
        margin=0.05,
        obstacle_weight=1000.0,
        horizon=10,
        dt=0.5,
        u_min=-1.0,
        u_max=1.0,
        population=300,
        iterations=40,
    )
    assert result.states is not None
    assert signed_distance(circle, result.states).min() > 0.0
    assert np.linalg.norm(result.states[-1] - [2.0, 0.0]) < 0.2


def test_built_in_terms_equal_the_factories() -> None:
    pendulum = get_dynamics("pendulum")
    reference = np.zeros((6, 2))
    args = {"horizon": 5, "dt": 0.1, "u_min": -2.0, "u_max": 2.0, "iterations": 3, "seed": 4}
    built = cem(
        pendulum,
        [0.1, 0.0],
        goal=[0.0, -1.0],
        goal_on="position",
        reference=reference,
        effort_weight=0.5,
        **args,
    )  # type: ignore[arg-type]
    manual = cem(
        pendulum,
        [0.1, 0.0],
        cost=[
            goal_cost([0.0, -1.0], position_of=pendulum),
            tracking_cost(reference),
            effort_cost(weight=0.5),
        ],
        **args,
    )  # type: ignore[arg-type]
    assert built.inputs is not None
    assert manual.inputs is not None
    np.testing.assert_array_equal(built.inputs, manual.inputs)
    assert built.cost == manual.cost


def test_target_cost_stops_early_and_time_limit_status() -> None:
    early = cem(
        SINGLE, [0, 0], cost=goal_cost([0.5, 0.0]), horizon=4, dt=1.0, u_min=-1, u_max=1, target_cost=1.0
    )
    assert early.status == "solved"
    assert early.iterations == 1
    assert "target cost" in early.message
    slow = cem(
        SINGLE, [0, 0], cost=goal_cost([0.5, 0.0]), horizon=4, dt=1.0, iterations=1000, time_limit=1e-9
    )
    assert slow.status == "time_limit"
    assert slow.iterations == 1
    assert slow.inputs is not None  # the best sequence so far is still returned


def test_failed_when_no_sample_has_a_finite_cost() -> None:
    def hopeless(states: np.ndarray, inputs: np.ndarray) -> np.ndarray:
        return np.full(len(states), np.inf)

    result = cem(SINGLE, [0.0, 0.0], cost=hopeless, horizon=3, dt=1.0, iterations=3)
    assert isinstance(result, CEMResult)
    assert result.status == "failed"
    assert result.inputs is None
    assert result.samples == 3 * 256


def _bad_shape(states: np.ndarray, inputs: np.ndarray) -> np.ndarray:
    return np.zeros((len(states), 2))


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"dynamics": "submarine"}, "submarine"),
        ({"x0": [0.0]}, r"x0 must have shape \(2,\)"),
        ({"x0": [np.nan, 0.0]}, "x0 must be finite"),
        ({"cost": 3}, "cost must be a callable"),
        ({"cost": []}, "cost must be a callable"),
        ({"cost": None}, "nothing to minimize"),
        ({"goal": [1.0, 2.0, 3.0]}, r"goal must have shape \(2,\) when goal_on='state'"),
        ({"goal_on": "pose"}, "goal_on must be 'state' or 'position'"),
        ({"reference": np.zeros((4, 2))}, r"reference must have shape \(6, m\)"),
        ({"obstacles": [3]}, r"obstacles\[0\] must be a Circle"),
        ({"effort_weight": -1.0}, "effort_weight must be a finite number >= 0"),
        ({"cost": _bad_shape}, r"cost must return one number per sample, shape \(256,\)"),
        ({"horizon": 0}, "horizon must be an integer >= 1"),
        ({"horizon": 2.5}, "horizon must be an integer >= 1"),
        ({"dt": 0.0}, "dt must be a positive finite number"),
        ({"u_min": 1.0, "u_max": 0.0}, "u_min must be <= u_max"),
        ({"population": 1}, "population must be an integer >= 2"),
        ({"elite_fraction": 0.0}, r"elite_fraction must be a number in \(0, 1\]"),
        ({"iterations": 0}, "iterations must be an integer >= 1"),
        ({"smoothing": 1.0}, r"smoothing must be a number in \[0, 1\)"),
        ({"init_mean": np.zeros((3, 2))}, r"init_mean must be a scalar or have shape \(2,\) or \(5, 2\)"),
        ({"init_std": 0.0}, "init_std must be > 0"),
        ({"min_std": -1.0}, "min_std must be a finite number >= 0"),
        ({"time_limit": -1.0}, "time_limit must be a positive number"),
        ({"seed": -3}, "seed must be a non-negative integer"),
        ({"method": "leapfrog"}, "method must be one of"),
    ],
)
def test_bad_inputs(kwargs: dict[str, object], match: str) -> None:
    args: dict[str, object] = {
        "dynamics": SINGLE,
        "x0": [0.0, 0.0],
        "cost": goal_cost([1.0, 1.0]),
        "horizon": 5,
        "dt": 1.0,
        "iterations": 2,
    }
    args.update(kwargs)
    with pytest.raises(InvalidArgumentError, match=match):
        cem(**args)  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("factory", "match"),
    [
        (lambda: goal_cost([1.0, 2.0], weight=[-1.0, 1.0]), "weight must be a non-negative scalar or 2"),
        (lambda: goal_cost([1.0, 2.0], angle_indices=(2,)), r"angle_indices must be indices in \[0, 2\)"),
        (lambda: goal_cost([1.0, 2.0], running_weight=-1.0), "running_weight must be a finite number >= 0"),
        (lambda: tracking_cost(np.zeros(3)), "reference must"),
        (lambda: effort_cost(weight=-1.0), "weight must be a non-negative"),
        (lambda: obstacle_cost(["wall"]), r"obstacles\[0\] must be a Circle"),  # type: ignore[list-item]
        (lambda: obstacle_cost([], margin=-0.1), "margin must be a finite number >= 0"),
    ],
)
def test_bad_factory_inputs(factory: object, match: str) -> None:
    with pytest.raises(InvalidArgumentError, match=match):
        factory()  # type: ignore[operator]


def test_docs_page_examples_run() -> None:
    page = Path(__file__).resolve().parents[2] / "docs" / "apis" / "cem.md"
    blocks = re.findall(r"```python\n(.*?)```", page.read_text(encoding="utf-8"), re.S)
    assert blocks
    for block in blocks:
        exec(compile(block, str(page), "exec"), {"__name__": "docs_example"})


def test_start_inside_an_obstacle_is_infeasible() -> None:
    result = cem(
        SINGLE,
        [1.0, 0.0],
        goal=[3.0, 0.0],
        obstacles=[Circle(center=(1.0, 0.0), radius=0.5)],
        horizon=5,
        dt=1.0,
    )
    assert result.status == "infeasible"
    assert "inside obstacles[0]" in result.message
    assert result.inputs is None
