"""planners.rrt: exact collision checks, statuses, determinism, bad inputs, missing OMPL."""

from __future__ import annotations

import doctest
import math
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("ompl")

import itertools

from audere import scenarios
from audere.errors import InvalidArgumentError
from audere.planners import RRTResult, rrt
from audere.planners import _rrt as rrt_module
from audere.planners._ompl_adapter import ExactChecker
from audere.world import Circle, Polygon, Rectangle, Square, Workspace, World

ALGORITHMS = ("rrt", "rrt_connect", "rrt_star", "informed_rrt_star", "bit_star")


def random_world(rng: np.random.Generator, n: int = 10) -> World:
    shapes: list[Circle | Square | Rectangle | Polygon] = []
    for _ in range(n):
        cx, cy = rng.uniform(0, 10, size=2)
        size = rng.uniform(0.3, 1.5)
        kind = rng.integers(4)
        if kind == 0:
            shapes.append(Circle(center=(cx, cy), radius=size))
        elif kind == 1:
            shapes.append(Square(center=(cx, cy), half_side=size))
        elif kind == 2:
            shapes.append(Rectangle.from_center(cx, cy, 2 * size, size))
        else:
            angles = np.sort(rng.uniform(0, 2 * np.pi, size=5))
            pts = [(cx + size * np.cos(a), cy + size * np.sin(a)) for a in angles]
            shapes.append(Polygon(vertices=pts))
    return World(workspace=Workspace(), obstacles=tuple(shapes))


def free_point(world: World, rng: np.random.Generator) -> np.ndarray:
    while True:
        p = rng.uniform(0, 10, size=2)
        if world.signed_distance(p) > 0.05:
            return p


def assert_collision_free(world: World, path: np.ndarray) -> None:
    assert world.first_collision(path) is None
    assert world.in_workspace(path).all()


# ------------------------------------------------------------------------------ exact checker


def boundary_segments(world: World) -> list[tuple[tuple[float, float], tuple[float, float]]]:
    """Segments that touch, graze or run along obstacle boundaries: the hard cases."""
    out = []
    for o in world.obstacles:
        if isinstance(o, Circle):
            (cx, cy), r = o.center, o.radius
            out += [((cx - 2 * r, cy + r), (cx + 2 * r, cy + r)), ((cx + r, cy - 3), (cx + r, cy + 3))]
            out += [((cx - 2 * r, cy + r * (1 - 1e-12)), (cx + 2 * r, cy + r * (1 - 1e-12)))]
            out += [((cx - 2 * r, cy), (cx - r, cy)), ((cx - r, cy), (cx - r * 0.999, cy))]
        elif isinstance(o, Square | Rectangle):
            if isinstance(o, Square):
                x0, x1 = o.center[0] - o.half_side, o.center[0] + o.half_side
                y0, y1 = o.center[1] - o.half_side, o.center[1] + o.half_side
            else:
                x0, x1, y0, y1 = o.xmin, o.xmax, o.ymin, o.ymax
            out += [((x0 - 1, y1), (x1 + 1, y1)), ((x0, y0 - 1), (x0, y1 + 1)), ((x0 - 1, y1 + 1), (x0, y1))]
            out += [((x0 - 1, y1 + 1), (x1 + 1, y0 - 1)), ((x0, y1), ((x0 + x1) / 2, (y0 + y1) / 2))]
            out += [((x0 - 1, y0 + 1e-13), (x1 + 1, y0 + 1e-13)), ((x0 - 1, y0 - 1), (x0, y1 + 1))]
        else:
            v = o.vertices
            for a, b in zip(v, (*v[1:], v[0]), strict=True):
                out += [(a, b), (a, ((a[0] + b[0]) / 2 + 1e-3, (a[1] + b[1]) / 2))]
    return out


@pytest.mark.parametrize("seed", range(5))
def test_exact_checker_agrees_with_world(seed: int) -> None:
    rng = np.random.default_rng(seed)
    world = random_world(rng, n=12)
    checker = ExactChecker(world)
    p = rng.uniform(-1, 11, size=(1500, 2))
    q = p + rng.normal(scale=rng.choice([0.1, 1.0, 4.0], size=(1500, 1)), size=(1500, 2))
    segs = [(tuple(a), tuple(b)) for a, b in zip(p, q, strict=True)] + boundary_segments(world)
    a = np.array([s[0] for s in segs], dtype=float)
    b = np.array([s[1] for s in segs], dtype=float)
    expected = ~world.segments_in_collision(a, b)
    got = np.array([checker.segment_free(*s[0], *s[1]) for s in segs])
    np.testing.assert_array_equal(got, expected)
    pts = np.vstack([p, a, b])
    np.testing.assert_array_equal([checker.point_free(x, y) for x, y in pts], ~world.points_in_collision(pts))
    assert checker.exact_segment_calls < len(segs)  # most answers settled without the fallback


# ------------------------------------------------------------------------------ planning


@pytest.mark.parametrize("algorithm", ALGORITHMS)
def test_paths_are_collision_free_on_random_worlds(algorithm: str) -> None:
    solved = 0
    for seed in range(15):
        rng = np.random.default_rng(100 + seed)
        world = random_world(rng)
        start, goal = free_point(world, rng), free_point(world, rng)
        result = rrt(world, start, goal, algorithm=algorithm, time_limit=0.05, seed=seed, interpolate=40)
        assert isinstance(result, RRTResult)
        if result.status != "solved":
            assert result.status == "time_limit"
            continue
        solved += 1
        path = result.waypoints
        assert path is not None
        assert_collision_free(world, path)
        np.testing.assert_array_equal(path[0], start)
        assert np.hypot(*(path[-1] - goal)) <= 1e-3
        assert result.cost == pytest.approx(np.hypot(*np.diff(path, axis=0).T).sum())
        assert result.cost >= np.hypot(*(goal - start)) - 1e-3
        assert len(path) >= 40
        # the planner's tree: valid indices, every tree edge is collision-free too
        v, e = result.tree_vertices, result.tree_edges
        assert v.shape[1] == 2
        assert e.shape[1] == 2
        if len(e):
            assert e.min() >= 0
            assert e.max() < len(v)
            assert not world.segments_in_collision(v[e[:, 0]], v[e[:, 1]]).any()
    assert solved >= 10


@pytest.mark.parametrize("seed", range(10))
def test_plan_easy_paths_pass_the_task_checker(seed: int) -> None:
    task = scenarios.make("plan-easy", seed=seed)
    for algorithm in ("rrt", "rrt_star"):
        result = rrt(
            task.world(inflated=False), task.x0, task.goal, algorithm=algorithm, time_limit=0.05,
            goal_tolerance=task.goal_tolerance, seed=seed, interpolate=100,
        )  # fmt: skip
        assert result.solved, result.message
        assert task.check(result.to_solution()).success


def test_margin_keeps_clearance() -> None:
    task = scenarios.make("plan-hard", seed=0)
    world = World(workspace=task.workspace, obstacles=task.all_obstacles())
    result = rrt(world, task.x0, task.goal, margin=task.margin, time_limit=0.5, seed=0)
    assert result.solved, result.message
    assert world.clearance(result.waypoints) >= task.margin - 1e-9
    assert task.check(result.to_solution()).success


def test_rrt_star_cost_decreases_with_budget() -> None:
    task = scenarios.make("plan-easy", seed=4)
    world = task.world()
    costs = []
    for iterations in (150, 600, 2500, 10000):
        result = rrt(
            world, task.x0, task.goal, algorithm="rrt_star", time_limit=10.0, max_iterations=iterations,
            simplify=False, seed=1,
        )  # fmt: skip
        assert result.solved
        assert result.iterations is not None
        assert result.iterations >= iterations
        costs.append(result.cost)
    assert all(b <= a + 1e-12 for a, b in itertools.pairwise(costs)), costs
    assert costs[-1] < costs[0]
    assert costs[-1] >= math.dist(task.x0, task.goal)


def test_stop_at_first_stops_early() -> None:
    task = scenarios.make("plan-easy", seed=2)
    result = rrt(task.world(), task.x0, task.goal, algorithm="rrt_star", time_limit=5.0, stop_at_first=True)
    assert result.solved
    assert result.solve_time < 1.0


def test_straight_line_when_free() -> None:
    world = World(workspace=Workspace(), obstacles=(Circle(center=(5.0, 8.0), radius=1.0),))
    result = rrt(world, (1.0, 1.0), (9.0, 2.0), algorithm="informed_rrt_star", time_limit=0.2)
    assert result.solved
    assert result.cost == pytest.approx(math.dist((1.0, 1.0), (9.0, 2.0)), rel=1e-9)


@pytest.mark.parametrize(
    ("start", "goal", "margin", "match"),
    [
        ((5.0, 5.0), (9.0, 9.0), 0.0, r"start \(5, 5\) lies inside obstacle 0"),
        ((1.0, 1.0), (5.5, 5.0), 0.0, r"goal \(5.5, 5\) lies inside obstacle 0"),
        ((1.0, 1.0), (11.0, 5.0), 0.0, r"goal \(11, 5\) lies outside the workspace"),
        ((-0.5, 1.0), (9.0, 9.0), 0.0, r"start .* lies outside the workspace"),
        ((3.5, 5.0), (9.0, 9.0), 0.6, r"start \(3.5, 5\) lies inside obstacle 0 inflated by the margin 0.6"),
    ],
)
def test_infeasible_start_or_goal(
    start: tuple[float, float], goal: tuple[float, float], margin: float, match: str
) -> None:
    world = World(workspace=Workspace(), obstacles=(Circle(center=(5.0, 5.0), radius=1.0),))
    result = rrt(world, start, goal, margin=margin, time_limit=0.1)
    assert result.status == "infeasible"
    assert result.waypoints is None
    assert result.cost is None
    assert re.search(match, result.message), result.message


def test_unreachable_goal_hits_the_time_limit() -> None:
    # the goal sits in a closed box of four walls: valid, but unreachable
    walls = (
        Rectangle(xmin=7, xmax=9, ymin=7, ymax=7.2),
        Rectangle(xmin=7, xmax=9, ymin=8.8, ymax=9),
        Rectangle(xmin=7, xmax=7.2, ymin=7, ymax=9),
        Rectangle(xmin=8.8, xmax=9, ymin=7, ymax=9),
    )
    world = World(workspace=Workspace(), obstacles=walls)
    result = rrt(world, (1.0, 1.0), (8.0, 8.0), algorithm="rrt", time_limit=0.2)
    assert result.status == "time_limit"
    assert result.approximate
    assert result.solve_time < 2.0
    assert result.goal_distance is not None
    assert result.goal_distance > 0.5
    assert result.waypoints is not None
    assert_collision_free(world, result.waypoints)


def test_goal_tolerance() -> None:
    world = World(workspace=Workspace(), obstacles=(Circle(center=(5.0, 5.0), radius=2.0),))
    goal = np.array([9.0, 9.0])
    for tolerance in (1e-6, 0.5):
        for seed in range(5):
            result = rrt(world, (1.0, 1.0), goal, goal_tolerance=tolerance, algorithm="rrt", seed=seed)
            assert result.solved
            assert np.hypot(*(result.waypoints[-1] - goal)) <= tolerance
            assert np.hypot(*(result.raw_waypoints[-1] - goal)) <= tolerance


@pytest.mark.parametrize(
    ("algorithm", "options"),
    [
        ("rrt", {}),
        ("rrt_connect", {}),
        ("rrt_star", {"stop_at_first": True}),
        ("rrt_star", {"max_iterations": 800, "time_limit": 10.0}),
        ("informed_rrt_star", {"max_iterations": 800, "time_limit": 10.0}),
    ],
)
def test_seed_makes_runs_reproducible(algorithm: str, options: dict[str, object]) -> None:
    task = scenarios.make("plan-easy", seed=7)
    runs = [rrt(task.world(), task.x0, task.goal, algorithm=algorithm, seed=s, **options) for s in (3, 3, 4)]
    a, b, c = runs
    assert a.solved
    assert b.solved
    assert c.solved
    np.testing.assert_array_equal(a.waypoints, b.waypoints)
    np.testing.assert_array_equal(a.tree_vertices, b.tree_vertices)
    np.testing.assert_array_equal(a.tree_edges, b.tree_edges)
    assert not np.array_equal(a.tree_vertices, c.tree_vertices)


def test_interpolate_keeps_the_path() -> None:
    path = np.array([[0.0, 0.0], [3.0, 0.0], [3.0, 1.0]])
    dense = rrt_module._interpolate(path, 9)
    assert len(dense) == 9
    np.testing.assert_array_equal(dense[[0, -1]], path[[0, -1]])
    assert any((dense == path[1]).all(axis=1))
    assert np.hypot(*np.diff(dense, axis=0).T).sum() == pytest.approx(4.0)
    np.testing.assert_array_equal(rrt_module._interpolate(path, 2), path)


_WORLD = World(workspace=Workspace(), obstacles=(Circle(center=(5.0, 5.0), radius=1.0),))


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"world": "not a world"}, r"world must be an audere.world.World, got str"),
        ({"start": (1.0, 2.0, 3.0)}, r"start must have shape \(2,\), got shape \(3,\)"),
        ({"goal": (np.nan, 1.0)}, r"goal must be finite, got nan"),
        ({"start": "xy"}, r"start must be an array of numbers"),
        ({"algorithm": "prm"}, r"algorithm must be one of rrt, rrt_connect, .*got 'prm'"),
        ({"time_limit": 0.0}, r"time_limit must be a finite number > 0, got 0.0"),
        ({"time_limit": math.inf}, r"time_limit must be a finite number > 0, got inf"),
        ({"goal_tolerance": -1.0}, r"goal_tolerance must be a finite number > 0, got -1.0"),
        ({"margin": -0.1}, r"margin must be a finite number >= 0, got -0.1"),
        ({"margin": "big"}, r"margin must be a number, got str"),
        ({"interpolate": 1}, r"interpolate must be an integer >= 2, got 1"),
        ({"interpolate": 2.5}, r"interpolate must be an integer, got float"),
        ({"seed": -1}, r"seed must be an integer in \[0, 4294967294\], got -1"),
        ({"seed": True}, r"seed must be an integer, got bool"),
        ({"max_iterations": 0}, r"max_iterations must be an integer >= 1, got 0"),
        ({"range": 0.0}, r"range must be a finite number > 0, got 0.0"),
        (
            {"range": 1.0, "algorithm": "bit_star"},
            r"range applies to rrt, .* got range=1.0 with algorithm='bit_star'",
        ),
        ({"simplify": "yes"}, r"simplify must be True or False, got 'yes'"),
    ],
)
def test_bad_inputs(kwargs: dict[str, object], match: str) -> None:
    call: dict[str, object] = {"world": _WORLD, "start": (1.0, 1.0), "goal": (9.0, 9.0), "time_limit": 0.1}
    call.update(kwargs)
    with pytest.raises(InvalidArgumentError, match=match):
        rrt(**call)  # type: ignore[arg-type]


def test_missing_ompl_names_the_install_command() -> None:
    code = (
        "import sys; sys.modules['ompl'] = None\n"
        "from audere.planners import rrt\n"
        "from audere.world import World, Workspace\n"
        "from audere.errors import MissingDependencyError\n"
        "try:\n"
        "    rrt(World(workspace=Workspace()), (1, 1), (9, 9))\n"
        "except MissingDependencyError as exc:\n"
        "    print('MISSING', exc)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60, check=True)
    assert "MISSING" in out.stdout
    assert "pip install 'audere[ompl]'" in out.stdout


def test_importing_does_not_import_ompl() -> None:
    code = "import sys, audere.planners._rrt; print('ompl' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60, check=True)
    assert out.stdout.strip() == "False"


def test_docstring_example() -> None:
    failures, _ = doctest.testmod(rrt_module, optionflags=doctest.ELLIPSIS, verbose=False)
    assert failures == 0


DOC = Path(__file__).resolve().parents[2] / "docs" / "apis" / "rrt.md"
DOC_BLOCKS = re.findall(r"```python\n(.*?)```", DOC.read_text(encoding="utf-8"), re.S)


@pytest.mark.parametrize("source", DOC_BLOCKS, ids=[f"block{i}" for i in range(len(DOC_BLOCKS))])
def test_doc_examples_print_what_they_say(source: str, capsys: pytest.CaptureFixture[str]) -> None:
    exec(compile(source, str(DOC), "exec", dont_inherit=True), {"__name__": "docs_apis_rrt"})
    expected = [line[2:] for line in source.splitlines() if line.startswith("# ")]
    assert capsys.readouterr().out.splitlines() == expected


@pytest.mark.parametrize("algorithm", ALGORITHMS)
def test_start_already_at_the_goal(algorithm: str) -> None:
    # informed samplers fail on a zero start-goal distance inside OMPL: answered before planning
    world = World(
        workspace=Workspace(xmin=-3, xmax=2, ymin=100, ymax=101),
        obstacles=(Circle(center=(0, 100.5), radius=0.3),),
    )
    same = rrt(world, (-2.5, 100.5), (-2.5, 100.5), algorithm=algorithm)
    assert same.solved
    assert same.cost == 0.0
    near = rrt(world, (-2.5, 100.5), (-2.4, 100.5), goal_tolerance=0.5, algorithm=algorithm)
    assert near.solved
    np.testing.assert_array_equal(near.waypoints, [[-2.5, 100.5], [-2.4, 100.5]])
    around = rrt(world, (-2.5, 100.5), (1.5, 100.5), algorithm=algorithm, time_limit=0.2)
    assert around.solved
    assert_collision_free(world, around.waypoints)
    assert 4.0 < around.cost < 4.0 * 1.05
