"""Each scenario's parameters stay in the ranges of docs/scenarios.md (and of the paper where it has one).

Geometric facts are measured independently of audere.world, with shapely and plain formulas.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
import shapely
from shapely.geometry import LineString, Point, box
from shapely.geometry.base import BaseGeometry

from audere.scenarios import make
from audere.tasks import MazeTask, ReachAvoidTask, Solution, STLTask, TrackingTask
from audere.world import Circle, Obstacle, Rectangle, Square

from .witnesses import swing_up

SEEDS = range(20)
EPS = 1e-9
ROUND = 1e-3  # generated numbers are rounded to millimetres


def _geom(shape: Obstacle) -> BaseGeometry:
    """Centre point of a circle (the radius is handled separately) or the polygon of a box shape."""
    if isinstance(shape, Circle):
        return Point(shape.center)
    if isinstance(shape, Square):
        (cx, cy), h = shape.center, shape.half_side
        return box(cx - h, cy - h, cx + h, cy + h)
    assert isinstance(shape, Rectangle)
    return box(shape.xmin, shape.ymin, shape.xmax, shape.ymax)


def _radius(shape: Obstacle) -> float:
    return shape.radius if isinstance(shape, Circle) else 0.0


def _distance(a: Obstacle, b: Obstacle) -> float:
    """Exact distance between two convex shapes (a disc is its centre grown by its radius)."""
    return max(0.0, _geom(a).distance(_geom(b)) - _radius(a) - _radius(b))


def _point_distance(p: tuple[float, float], shape: Obstacle) -> float:
    return max(0.0, Point(p).distance(_geom(shape)) - _radius(shape))


def _circumradius(shape: Obstacle) -> float:
    """The authors' "radius": a circle's radius, a square's circumradius half_side * sqrt(2)."""
    if isinstance(shape, Circle):
        return shape.radius
    assert isinstance(shape, Square)
    return shape.half_side * math.sqrt(2.0)


# ------------------------------------------------------------------------------------------- tracking


def _lateral_extent(reference: np.ndarray) -> float:
    """Largest distance of a reference point from the chord between its ends."""
    line = LineString([reference[0], reference[-1]])
    return max(line.distance(Point(p)) for p in reference)


def test_track_lin() -> None:
    shapes = set()
    for seed in SEEDS:
        task = make("track-lin", seed)
        assert isinstance(task, TrackingTask)
        assert (task.dynamics, task.horizon, task.dt, task.tolerance) == ("single_integrator", 20, 1.0, 1.0)
        assert task.u_min == (-0.5, -0.5)
        assert task.u_max == (0.5, 0.5)
        x0 = np.array(task.x0)
        assert np.all((x0 >= 0.5) & (x0 <= 1.5))
        ref = np.asarray(task.reference)
        assert ref.shape == (21, 2)
        assert np.array_equal(ref[0], x0)
        assert np.abs(np.diff(ref, axis=0)).max() <= 0.5  # feasible: a perfect tracker exists
        assert np.all((ref >= 0) & (ref <= 10))
        # The perfect tracker, built here from the reference alone.
        report = task.check(Solution(inputs=np.diff(ref, axis=0) / task.dt))
        assert report.success
        assert report.metrics["mean_tracking_error"] <= 1e-9
        shapes.add("curved" if _lateral_extent(ref) > 0.1 else "flat")
    assert shapes == {"flat", "curved"}


def test_track_car() -> None:
    for seed in SEEDS:
        task = make("track-car", seed)
        assert isinstance(task, TrackingTask)
        assert (task.dynamics, task.horizon, task.dt, task.tolerance) == ("unicycle", 20, 1.0, 2.0)
        assert task.u_min == (-0.3, -0.5)
        assert task.u_max == (0.3, 0.5)
        assert 0.5 <= task.x0[0] <= 1.5
        assert 0.5 <= task.x0[1] <= 1.5
        assert task.x0[2:] == (0.0, 0.0)
        ref = np.asarray(task.reference)
        assert ref.shape == (21, 2)
        assert np.array_equal(ref[0], task.x0[:2])
        assert np.all((ref >= 0) & (ref <= 10))
        assert np.linalg.norm(np.diff(ref, axis=0), axis=1).sum() >= 4.0  # the car has to go somewhere


def test_track_double() -> None:
    for seed in SEEDS:
        task = make("track-double", seed)
        assert isinstance(task, TrackingTask)
        assert (task.dynamics, task.horizon, task.dt, task.tolerance) == ("double_integrator", 20, 1.0, 0.5)
        assert task.u_min == (-0.25, -0.25)
        assert task.u_max == (0.25, 0.25)
        ref = np.asarray(task.reference)
        assert ref.shape == (21, 4)
        assert np.array_equal(ref[0], task.x0)
        assert task.x0[2:] == (0.0, 0.0)
        # The reference is a rollout: positions integrate velocities (to rounding) ...
        np.testing.assert_allclose(ref[1:, :2], ref[:-1, :2] + task.dt * ref[:-1, 2:], atol=2 * ROUND)
        # ... and the velocity changes are admissible accelerations, which track it.
        accel = np.diff(ref[:, 2:], axis=0) / task.dt
        assert np.abs(accel).max() <= 0.25
        report = task.check(Solution(inputs=accel))
        assert report.success
        assert report.metrics["mean_tracking_error"] < 0.05


# ------------------------------------------------------------------------------------------ plan-easy


def test_plan_easy() -> None:
    kinds = set()
    for seed in SEEDS:
        task = make("plan-easy", seed)
        assert isinstance(task, ReachAvoidTask)
        assert task.dynamics is None
        assert task.margin == 0.0
        assert task.goal_tolerance == 0.1
        assert (task.workspace.xmin, task.workspace.xmax, task.workspace.ymin, task.workspace.ymax) == (
            0,
            10,
            0,
            10,
        )
        assert math.dist(task.start, task.goal_position) >= 0.75 * math.hypot(10, 10)
        obstacles = task.obstacles
        assert len(obstacles) == 12
        kinds |= {o.kind for o in obstacles}
        for o in obstacles:
            assert 0.8 - ROUND <= _circumradius(o) <= 2.0 + ROUND
            assert 0 <= o.center[0] <= 10
            assert 0 <= o.center[1] <= 10
            for p in (task.start, task.goal_position):
                assert math.dist(p, o.center) >= _circumradius(o) + 0.5 - EPS  # type: ignore[union-attr]
                assert _point_distance(p, o) >= 0.5 - EPS
        for a, b in itertools.combinations(obstacles, 2):
            gap = math.dist(a.center, b.center) - _circumradius(a) - _circumradius(b)  # type: ignore[union-attr]
            assert gap >= 0.5 - EPS  # the spacing rule, on the authors' radii
            assert _distance(a, b) >= 0.5 - EPS  # hence the exact shapes are that far apart too
    assert kinds == {"circle", "square"}


# ------------------------------------------------------------------------------------------ plan-hard


def _door_fraction(seeds: range) -> float:
    present = 0
    for seed in seeds:
        task = make("plan-hard", seed)
        assert isinstance(task, MazeTask)
        present += len(task.doors)
    return present / (12 * len(seeds))


def test_plan_hard() -> None:
    for seed in SEEDS:
        task = make("plan-hard", seed)
        assert isinstance(task, MazeTask)
        assert (task.rows, task.cols, task.wall_thickness, task.margin) == (3, 3, 0.1, 0.15)
        assert task.start_tolerance == task.goal_tolerance == 0.05
        edge = 10 / 3
        for door in task.doors:
            assert door.width == 1.0
            lo, hi = door.offset * edge - 0.5, door.offset * edge + 0.5
            assert lo >= 0.35 - ROUND
            assert hi <= edge - 0.35 + ROUND
        start_cell, goal_cell = task.cell_of(task.start), task.cell_of(task.goal)
        assert start_cell != goal_cell
        path = task.door_path(start_cell, goal_cell)
        assert path is not None
        assert len(path) - 1 >= 0.8 * (3 + 3 - 2)
        for p, (r, c) in ((task.start, start_cell), (task.goal, goal_cell)):
            assert c * edge + 0.5 - EPS <= p[0] <= (c + 1) * edge - 0.5 + EPS
            assert r * edge + 0.5 - EPS <= p[1] <= (r + 1) * edge - 0.5 + EPS
        per_cell: dict[tuple[int, int], int] = {}
        for o in task.obstacles:
            assert 0.2 - ROUND <= _circumradius(o) <= 0.35 + ROUND
            cell = task.cell_of(o.center)  # type: ignore[union-attr]
            per_cell[cell] = per_cell.get(cell, 0) + 1
            for p in (task.start, task.goal):
                assert _point_distance(p, o) >= 0.5 - EPS
        assert per_cell == {(r, c): 4 for r in range(3) for c in range(3)}
        # 0.2 m of free space between obstacles and walls once both are inflated by the margin.
        shapes = np.array([_geom(o) for o in task.obstacles])
        radii = np.array([_radius(o) for o in task.obstacles])
        walls = np.array([_geom(w) for w in task.walls])
        gaps = shapely.distance(shapes[:, None], walls[None, :]) - radii[:, None]
        assert gaps.min() >= 0.5 - EPS
        apart = shapely.distance(shapes[:, None], shapes[None, :]) - radii[:, None] - radii[None, :]
        assert apart[np.triu_indices(len(shapes), 1)].min() >= 0.1 - EPS
    assert 0.7 <= _door_fraction(range(40)) <= 0.97


@pytest.mark.slow
def test_plan_hard_door_probability_over_100_seeds() -> None:
    assert 0.8 <= _door_fraction(range(100)) <= 0.9


# ------------------------------------------------------------------------------------------- plan-stl


def _bounds(r: Rectangle, mirror: bool) -> tuple[float, float, float, float]:
    """Centre and size of ``r`` as in the unmirrored layout."""
    cx = (r.xmin + r.xmax) / 2
    return (10 - cx if mirror else cx, (r.ymin + r.ymax) / 2, r.xmax - r.xmin, r.ymax - r.ymin)


def test_plan_stl() -> None:
    mirrors, windows = set(), set()
    for seed in SEEDS:
        task = make("plan-stl", seed)
        assert isinstance(task, STLTask)
        assert (task.dynamics, task.horizon, task.dt) == ("single_integrator", 20, 1.0)
        assert task.u_min == (-4.0, -4.0)
        assert task.u_max == (4.0, 4.0)
        assert sorted(task.regions) == ["A", "B", "C", "D", "E"]
        regions = {k: v for k, v in task.regions.items() if isinstance(v, Rectangle)}
        assert len(regions) == 5
        mirror = regions["C"].xmin < 5
        mirrors.add(mirror)
        a, b, c, d, e = (_bounds(regions[k], mirror) for k in "ABCDE")
        close = pytest.approx
        assert c == close((7.5, 6, 1, 8), abs=ROUND)
        assert a[:2] == close((1, 9), abs=ROUND)
        assert a[2] == close(a[3], abs=2 * ROUND)
        assert 0.9 - ROUND <= a[2] <= 1.1 + ROUND
        assert b[0] == close(2)
        assert b[1] == close(4.5)
        assert b[2] == close(4)
        assert 4.8 - ROUND <= b[3] <= 6.0 + ROUND
        shift = 5.5 - d[1]
        assert -0.2 - ROUND <= shift <= 0.8 + ROUND
        assert d[0] == close(9)
        assert d[2:] == close((2, 0.5), abs=ROUND)
        assert e[:2] == close((9, 8.2 - shift), abs=2 * ROUND)
        assert 0.72 - ROUND <= e[2] <= 0.88 + ROUND
        assert e[2] == close(e[3], abs=2 * ROUND)
        sx = 10 - task.x0[0] if mirror else task.x0[0]
        assert 0.5 <= sx <= 1.5
        assert 0.5 <= task.x0[1] <= 1.5
        for r in regions.values():  # the start is inside no region
            assert box(r.xmin, r.ymin, r.xmax, r.ymax).distance(Point(task.x0)) > 0
        t_start = int(task.spec.split("[")[1].split(",")[0])
        assert 10 <= t_start < 16
        windows.add(t_start)
        assert task.spec == (f"F[{t_start},17] in(E) & G[0,20] (!in(B) & !in(C)) & (!in(D) U[0,20] in(A))")
        assert str(task.formula) == task.spec
    assert mirrors == {False, True}
    assert len(windows) >= 3


# ------------------------------------------------------------------------------------ beyond the paper


def test_pendulum_swingup_needs_pumping() -> None:
    for seed in SEEDS:
        task = make("pendulum-swingup", seed)
        assert isinstance(task, ReachAvoidTask)
        assert task.dynamics == "pendulum"
        assert (task.dt, task.horizon) == (0.05, 100)
        assert task.goal == (math.pi, 0.0)
        assert task.goal_on == "state"
        assert task.angle_indices == (0,)
        assert all(abs(v) <= 0.3 for v in task.x0)
        p = task.model.params  # type: ignore[union-attr]
        assert task.u_max == (3.5,)
        assert task.u_min == (-3.5,)
        assert task.u_max[0] < 0.5 * p["mass"] * p["gravity"] * p["length"]  # too weak to lift directly
        for sign in (-1.0, 1.0):  # pushing one way only gets nowhere near upright
            assert not task.check(Solution(inputs=np.full((100, 1), sign * 3.5))).success
    # ... whereas pumping energy in does it (one fixed gain setting, every seed).
    for seed in SEEDS:
        task = make("pendulum-swingup", seed)
        assert isinstance(task, ReachAvoidTask)
        assert task.check(swing_up(task, pump_gain=2.0, catch_level=30.0)).success


def _blocks_straight_line(task: ReachAvoidTask) -> bool:
    line = LineString([task.start, task.goal_position])
    return any(
        line.distance(Point(o.center)) < o.radius + task.margin
        for o in task.obstacles
        if isinstance(o, Circle)
    )


def test_arm_reach() -> None:
    blocked = 0
    for seed in SEEDS:
        task = make("arm-reach", seed)
        assert isinstance(task, ReachAvoidTask)
        assert task.dynamics == "two_link_arm"
        assert (task.dt, task.horizon) == (0.05, 60)
        assert task.u_max == (10.0, 10.0)
        assert task.margin == 0.05
        assert task.goal_tolerance == 0.1
        assert task.x0[2:] == (0.0, 0.0)
        p = task.model.params  # type: ignore[union-attr]
        assert abs(p["l1"] - p["l2"]) <= math.hypot(*task.goal) <= p["l1"] + p["l2"]  # reachable
        assert math.dist(task.start, task.goal_position) >= 1.0
        assert len(task.obstacles) == 2
        for o in task.obstacles:
            assert isinstance(o, Circle)
            assert 0.15 - ROUND <= o.radius <= 0.3 + ROUND
        blocked += _blocks_straight_line(task)
    assert blocked >= len(SEEDS) // 2  # the straight line is usually not an answer


def test_reach_unicycle() -> None:
    blocked = 0
    for seed in SEEDS:
        task = make("reach-unicycle", seed)
        assert isinstance(task, ReachAvoidTask)
        assert task.dynamics == "unicycle"
        assert (task.dt, task.horizon) == (0.5, 40)
        assert task.u_max == (0.8, 0.5)
        assert task.margin == 0.1
        assert task.goal_tolerance == 0.3
        assert 0.5 <= task.x0[0] <= 2
        assert 0.5 <= task.x0[1] <= 2
        assert 0 <= task.x0[2] <= math.pi / 2
        assert task.x0[3] == 0.0
        assert math.dist(task.start, task.goal_position) >= 5.0
        assert len(task.obstacles) == 4
        for o in task.obstacles:
            assert isinstance(o, Circle)
            assert 0.3 - ROUND <= o.radius <= 0.7 + ROUND
        blocked += _blocks_straight_line(task)
    assert blocked >= len(SEEDS) // 2
