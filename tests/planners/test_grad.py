"""planners.grad: exact bounds, goals, obstacles, smooth STL robustness (-> exact as temperature -> 0),
the differentiable signed distance against the world's, determinism, statuses and bad inputs."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from audere import stl
from audere.dynamics import get_dynamics
from audere.errors import InvalidArgumentError
from audere.planners import GradResult, grad, smooth_robustness
from audere.world import Circle, Polygon, Rectangle, Square, Workspace, signed_distance

torch = pytest.importorskip("torch")

SINGLE = get_dynamics("single_integrator")
FAST = {"iterations": 80, "restarts": 4, "learning_rate": 0.1}


def test_bounds_are_respected_exactly_when_the_goal_is_out_of_reach() -> None:
    result = grad(
        SINGLE,
        [0.0, 0.0],
        goal=[50.0, -50.0],
        horizon=6,
        dt=1.0,
        u_min=[-0.3, -0.2],
        u_max=[0.4, 0.1],
        **FAST,
    )  # type: ignore[arg-type]
    assert isinstance(result, GradResult)
    u = result.inputs
    assert u is not None
    assert np.all(u[:, 0] <= 0.4)
    assert np.all(u[:, 1] >= -0.2)
    assert np.all(u >= [-0.3, -0.2])
    assert np.all(u <= [0.4, 0.1])
    np.testing.assert_allclose(u[:, 0], 0.4, atol=1e-2)  # pushed against the bounds
    np.testing.assert_allclose(u[:, 1], -0.2, atol=1e-2)


def test_one_sided_and_missing_bounds() -> None:
    result = grad(
        SINGLE,
        [0.0, 0.0],
        goal=[-3.0, 2.0],
        horizon=4,
        dt=1.0,
        u_min=[0.0, -np.inf],
        u_max=[np.inf, np.inf],
        **FAST,
    )  # type: ignore[arg-type]
    assert result.inputs is not None
    assert np.all(result.inputs[:, 0] >= 0.0)
    assert result.states is not None
    assert result.states[-1, 1] == pytest.approx(2.0, abs=0.05)


def test_reaches_a_goal_and_states_are_the_numpy_rollout() -> None:
    unicycle = get_dynamics("unicycle")
    x0 = np.array([0.0, 0.0, 0.0, 0.0])
    result = grad(
        unicycle,
        x0,
        goal=[2.0, 1.0],
        goal_on="position",
        horizon=20,
        dt=0.25,
        u_min=[-1.0, -1.0],
        u_max=[1.0, 1.0],
        iterations=250,
        restarts=4,
        learning_rate=0.1,
    )
    assert result.status == "solved"
    assert result.inputs is not None
    assert result.states is not None
    np.testing.assert_allclose(result.states, unicycle.rollout(x0, result.inputs, 0.25))
    assert np.linalg.norm(result.states[-1, :2] - [2.0, 1.0]) < 0.05
    assert len(result.loss_history) == result.iterations == 250
    assert result.cost == pytest.approx(float(result.restart_losses.min()))


def test_avoids_circles_and_boxes() -> None:
    obstacles = [Circle(center=(1.0, 0.0), radius=0.4), Square(center=(2.0, 0.3), half_side=0.2)]
    result = grad(
        SINGLE,
        [0.0, 0.0],
        goal=[3.0, 0.0],
        obstacles=obstacles,
        margin=0.05,
        horizon=15,
        dt=0.5,
        u_min=-1.0,
        u_max=1.0,
        iterations=200,
        restarts=4,
        learning_rate=0.1,
    )
    assert result.states is not None
    for shape in obstacles:
        assert signed_distance(shape, result.states).min() > 0.0
    assert np.linalg.norm(result.states[-1] - [3.0, 0.0]) < 0.1


def test_torch_signed_distance_matches_the_world() -> None:
    from audere.planners._grad import _torch_signed_distance

    rng = np.random.default_rng(0)
    points = rng.uniform(-2.0, 4.0, size=(500, 2))
    for shape in [
        Circle(center=(1.0, 0.5), radius=0.7),
        Square(center=(0.0, 1.0), half_side=0.5),
        Rectangle(xmin=1.0, xmax=3.0, ymin=-1.0, ymax=0.2),
    ]:
        ours = _torch_signed_distance(torch, shape, torch.as_tensor(points)).numpy()
        np.testing.assert_allclose(ours, signed_distance(shape, points), atol=1e-5)


REGIONS = {
    "A": Circle(center=(2.0, 2.0), radius=0.6),
    "B": Rectangle(xmin=0.5, xmax=1.5, ymin=-0.5, ymax=0.5),
    "C": Square(center=(3.0, 0.0), half_side=0.4),
    "W": Workspace(xmin=-1.0, xmax=5.0, ymin=-1.0, ymax=5.0),
}
SPECS = [
    "F[3,8] in(A)",
    "G[0,10] !in(B)",
    "F[0,5] in(C) | G[2,6] x >= 1",
    "(!in(B) U[2,9] in(A)) & G[0,10] in(W)",
    "G[0,4] (in(A) -> F[0,3] y <= 1.5)",
    "true & F[1,2] 2*x + y >= 3",
]


@pytest.mark.parametrize("spec", SPECS)
def test_smooth_robustness_tends_to_the_exact_robustness(spec: str) -> None:
    rng = np.random.default_rng(abs(hash(spec)) % 2**32)
    positions = np.cumsum(rng.uniform(-0.6, 0.9, size=(3, 11, 2)), axis=1)
    exact = np.array([stl.robustness(spec, p, REGIONS) for p in positions])
    errors = [
        np.abs(smooth_robustness(spec, positions, REGIONS, temperature=tau) - exact).max()
        for tau in (1.0, 0.1, 0.01, 1e-4)
    ]
    assert errors[-1] < 1e-3
    assert errors[-1] <= errors[1] <= errors[0] + 1e-12
    single = smooth_robustness(spec, positions[0], REGIONS, temperature=1e-4)
    assert single.shape == ()
    assert float(single) == pytest.approx(exact[0], abs=1e-3)


@given(
    steps=st.lists(st.tuples(st.floats(-1.0, 1.0), st.floats(-1.0, 1.0)), min_size=2, max_size=12),
    width=st.integers(0, 10),
    tau=st.sampled_from([1.0, 0.1, 0.01]),
)
def test_soft_minimum_brackets_the_exact_robustness(
    steps: list[tuple[float, float]], width: int, tau: float
) -> None:
    # For a min-only formula (G over a circle) the soft minimum is a lower bound within tau * log(n).
    positions = np.cumsum(np.array([(0.0, 0.0), *steps]), axis=0)
    hi = min(width, len(positions) - 1)
    spec = f"G[0,{hi}] in(A)"
    regions = {"A": Circle(center=(0.5, 0.5), radius=1.0)}
    exact = stl.robustness(spec, positions, regions)
    soft = float(smooth_robustness(spec, positions, regions, temperature=tau))
    assert soft <= exact + 1e-12
    assert soft >= exact - tau * np.log(hi + 1) - 1e-12


def test_satisfies_an_stl_spec() -> None:
    regions = {"A": Circle(center=(2.0, 2.0), radius=0.5), "B": Square(center=(1.0, 1.0), half_side=0.3)}
    spec = "F[6,10] in(A) & G[0,10] !in(B)"
    result = grad(
        SINGLE,
        [0.0, 0.0],
        spec=spec,
        regions=regions,
        horizon=10,
        dt=1.0,
        u_min=-0.5,
        u_max=0.5,
        stl_margin=0.1,
        iterations=200,
        restarts=4,
        learning_rate=0.1,
    )
    assert result.robustness is not None
    assert result.robustness > 0.0
    assert result.states is not None
    assert result.robustness == pytest.approx(stl.robustness(spec, result.states, regions))


def test_same_seed_same_result_and_threads_restored() -> None:
    before = torch.get_num_threads()
    args = {
        "goal": [1.0, -1.0],
        "horizon": 5,
        "dt": 1.0,
        "u_min": -0.5,
        "u_max": 0.5,
        "iterations": 10,
        "restarts": 3,
    }
    a = grad(SINGLE, [0.0, 0.0], seed=3, **args)  # type: ignore[arg-type]
    b = grad(SINGLE, [0.0, 0.0], seed=3, **args)  # type: ignore[arg-type]
    assert a.inputs is not None
    assert b.inputs is not None
    np.testing.assert_array_equal(a.inputs, b.inputs)
    np.testing.assert_array_equal(a.loss_history, b.loss_history)
    assert torch.get_num_threads() == before


def test_statuses() -> None:
    inside = grad(
        SINGLE,
        [1.0, 0.0],
        goal=[3.0, 0.0],
        obstacles=[Circle(center=(1.0, 0.0), radius=0.5)],
        horizon=5,
        dt=1.0,
    )
    assert inside.status == "infeasible"
    assert "inside obstacles[0]" in inside.message
    assert inside.inputs is None
    hurried = grad(SINGLE, [0.0, 0.0], goal=[1.0, 1.0], horizon=5, dt=1.0, iterations=10_000, time_limit=1e-6)
    assert hurried.status == "time_limit"
    assert hurried.inputs is not None
    assert hurried.iterations == 1


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"x0": [0.0, 0.0, 0.0]}, r"x0 must have shape \(2,\)"),
        ({"horizon": 0}, "horizon must be an integer >= 1"),
        ({"goal": [1.0, 2.0, 3.0]}, r"goal must have shape \(2,\) when goal_on='state'"),
        ({"goal": None, "effort_weight": 0.0}, "nothing to minimize"),
        ({"goal_on": "pose"}, "goal_on must be"),
        ({"goal_weight": -1.0}, "goal_weight must be a non-negative"),
        ({"angle_indices": (4,)}, r"angle_indices must be indices in \[0, 2\)"),
        ({"reference": np.zeros((3, 2))}, r"reference must have shape \(6, m\)"),
        (
            {"obstacles": [Polygon(vertices=((0, 5), (1, 5), (0, 6)))]},
            "must be a Circle, Square or Rectangle",
        ),
        ({"margin": -0.1}, "margin must be a finite number >= 0"),
        ({"spec": "F[0,3] in(Z)", "regions": {}}, "regions is missing 'Z'"),
        ({"spec": "F[0,30] x >= 1"}, "spec needs 30 steps"),
        (
            {"spec": "F[0,3] in(P)", "regions": {"P": Polygon(vertices=((0, 5), (1, 5), (0, 6)))}},
            r"regions\['P'\] must be a Circle",
        ),
        ({"temperature": 0.0}, "temperature must be a finite number > 0"),
        ({"u_min": 1.0, "u_max": -1.0}, "u_min must be <= u_max"),
        ({"restarts": 0}, "restarts must be an integer >= 1"),
        ({"iterations": 1.5}, "iterations must be an integer >= 1"),
        ({"learning_rate": 0.0}, "learning_rate must be a finite number > 0"),
        ({"init_inputs": np.zeros((2, 2))}, r"init_inputs must have shape \(5, 2\)"),
        ({"init_std": -1.0}, "init_std must be a finite number >= 0"),
        ({"seed": -1}, "seed must be a non-negative integer"),
        ({"time_limit": 0.0}, "time_limit must be a finite number > 0"),
        ({"dt": np.nan}, "dt must be a positive finite number"),
    ],
)
def test_bad_inputs(kwargs: dict[str, object], match: str) -> None:
    args: dict[str, object] = {
        "dynamics": SINGLE,
        "x0": [0.0, 0.0],
        "goal": [1.0, 1.0],
        "horizon": 5,
        "dt": 1.0,
    }
    args.update(kwargs)
    with pytest.raises(InvalidArgumentError, match=match):
        grad(**args)  # type: ignore[arg-type]


def test_smooth_robustness_bad_inputs() -> None:
    with pytest.raises(InvalidArgumentError, match=r"positions must have shape \(T\+1, 2\)"):
        smooth_robustness("F[0,1] x >= 0", np.zeros((3, 3)), {})
    with pytest.raises(InvalidArgumentError, match="temperature must be"):
        smooth_robustness("F[0,1] x >= 0", np.zeros((3, 2)), {}, temperature=-1.0)


def test_docs_page_examples_run() -> None:
    page = Path(__file__).resolve().parents[2] / "docs" / "apis" / "grad.md"
    blocks = re.findall(r"```python\n(.*?)```", page.read_text(encoding="utf-8"), re.S)
    assert blocks
    for block in blocks:
        exec(compile(block, str(page), "exec"), {"__name__": "docs_example"})
