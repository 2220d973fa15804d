"""World: queries against brute force over the per-shape functions, first collisions, clearance, speed."""

from __future__ import annotations

import time

import numpy as np
import pytest

from audere.world import (
    Circle,
    Collision,
    Polygon,
    Rectangle,
    Square,
    Workspace,
    World,
    contains,
    inflate,
    segment_distance,
    segments_intersect,
    signed_distance,
)

from .reference import KINDS, random_shape

NOTCHED = Polygon(vertices=((0.0, 0.0), (4.0, 0.0), (4.0, 4.0), (2.0, 1.0), (0.0, 4.0)))


def _world(seed: int, n: int = 12, kinds: tuple[str, ...] = KINDS) -> World:
    rng = np.random.default_rng(seed)
    obstacles = []
    for i in range(n):
        shape = random_shape(rng, kinds[i % len(kinds)])
        shift = rng.uniform(-6, 6, 2)  # spread them out
        obstacles.append(_shifted(shape, shift))
    return World(workspace=Workspace(xmin=-10, xmax=10, ymin=-10, ymax=10), obstacles=obstacles)


def _shifted(shape, shift):
    dx, dy = float(shift[0]), float(shift[1])
    if isinstance(shape, Circle):
        return Circle(center=(shape.center[0] + dx, shape.center[1] + dy), radius=shape.radius)
    if isinstance(shape, Square):
        return Square(center=(shape.center[0] + dx, shape.center[1] + dy), half_side=shape.half_side)
    if isinstance(shape, Rectangle):
        return Rectangle(
            xmin=shape.xmin + dx, xmax=shape.xmax + dx, ymin=shape.ymin + dy, ymax=shape.ymax + dy
        )
    return Polygon(vertices=tuple((x + dx, y + dy) for x, y in shape.vertices))


def _path(seed: int, k: int = 12, step: float = 1.5) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return rng.uniform(-8, 8, 2) + np.cumsum(rng.normal(0, step, (k, 2)), axis=0)


def _brute_first(world: World, path: np.ndarray):
    """(kind, index, obstacles hit) of the first collision in path order, from the per-shape functions."""
    for i in range(len(path)):
        inside = [j for j, o in enumerate(world.obstacles) if contains(o, path[i])]
        if inside:
            return "point", i, inside
        if i + 1 < len(path):
            hits = [j for j, o in enumerate(world.obstacles) if segments_intersect(o, path[i], path[i + 1])]
            if hits:
                return "segment", i, hits
    return None


@pytest.mark.parametrize("seed", range(40))
def test_first_collision_matches_brute_force(seed: int) -> None:
    world = _world(seed)
    path = _path(seed)
    found = world.first_collision(path)
    expected = _brute_first(world, path)
    if expected is None:
        assert found is None
        return
    assert found is not None
    kind, index, hits = expected
    assert (found.kind, found.index) == (kind, index)
    assert found.obstacle == world.obstacles[found.obstacle_index]
    if kind == "point":
        assert found.obstacle_index == min(hits)
        assert found.point == tuple(path[index])
        return
    assert found.obstacle_index in hits
    p, q = path[index], path[index + 1]
    point = np.array(found.point)
    # the entry point is on the segment, on the obstacle's boundary (or the segment's start) ...
    t = float(np.dot(point - p, q - p) / np.dot(q - p, q - p))
    np.testing.assert_allclose(p + t * (q - p), point, atol=1e-9)
    assert abs(float(signed_distance(found.obstacle, point))) < 1e-9 or t == 0.0
    # ... and nothing before it along the segment is inside any obstacle
    before = p + np.linspace(0.0, max(t - 1e-9, 0.0), 400)[:, None] * (q - p)
    assert (world.signed_distance(before) > -1e-9).all()


def test_first_collision_known_cases() -> None:
    circle = Circle(center=(0.0, 0.0), radius=1.0)
    world = World(workspace=Workspace(xmin=-5, xmax=5, ymin=-5, ymax=5), obstacles=[circle])
    hit = world.first_collision([[-3.0, 0.0], [3.0, 0.0]])
    assert hit is not None
    assert (hit.kind, hit.index, hit.obstacle_index) == ("segment", 0, 0)
    assert hit.point == pytest.approx((-1.0, 0.0), abs=1e-12)
    assert hit.describe() == (
        "segment 0 (waypoint 0 to waypoint 1) enters obstacle 0 "
        "(circle centred at (0.00, 0.00), radius 1.00) at (-1.00, 0.00)"
    )
    start_inside = world.first_collision([[0.5, 0.0], [3.0, 0.0]])
    assert start_inside == Collision(
        index=0, point=(0.5, 0.0), obstacle_index=0, obstacle=circle, kind="point"
    )
    assert start_inside.describe() == (
        "waypoint 0 at (0.50, 0.00) is inside obstacle 0 (circle centred at (0.00, 0.00), radius 1.00)"
    )
    # waypoint 2 is inside, but segment 1 enters first
    later = world.first_collision([[-3.0, 3.0], [-3.0, 0.0], [0.0, 0.0], [3.0, 0.0]])
    assert later is not None
    assert (later.kind, later.index) == ("segment", 1)
    assert later.point == pytest.approx((-1.0, 0.0), abs=1e-12)
    # tangent and touching paths do not collide
    assert world.first_collision([[-3.0, 1.0], [3.0, 1.0], [1.0, 0.0], [3.0, -1.0]]) is None
    # a single waypoint
    assert world.first_collision([[0.0, 0.0]]) is not None
    assert world.first_collision([[4.0, 4.0]]) is None


def test_first_collision_picks_the_obstacle_entered_first() -> None:
    far = Square(center=(2.0, 0.0), half_side=1.0)  # entered at x = 1
    near = Rectangle(xmin=-1.0, xmax=0.5, ymin=-1.0, ymax=1.0)  # entered at x = -1
    same = Circle(center=(-2.0, 0.0), radius=1.0)  # also entered at x = -3 ... first of all
    world = World(workspace=Workspace(), obstacles=[far, near])
    hit = world.first_collision([[-4.0, 0.0], [4.0, 0.0]])
    assert hit is not None
    assert (hit.obstacle_index, hit.point) == (1, (-1.0, 0.0))
    world = World(workspace=Workspace(), obstacles=[far, near, same])
    hit = world.first_collision([[-4.0, 0.0], [4.0, 0.0]])
    assert hit is not None
    assert hit.obstacle_index == 2
    assert hit.point == pytest.approx((-3.0, 0.0), abs=1e-12)
    # equal entry points: the lower obstacle index wins
    twin = World(workspace=Workspace(), obstacles=[near, near])
    hit = twin.first_collision([[-4.0, 0.0], [4.0, 0.0]])
    assert hit is not None
    assert hit.obstacle_index == 0


def test_first_collision_polygon_entry_is_exact() -> None:
    world = World(workspace=Workspace(), obstacles=[NOTCHED])
    # runs along the slanted notch edge from outside, reaches the reflex vertex, then goes inside
    hit = world.first_collision([[6.0, 7.0], [0.0, -2.0]])
    assert hit is not None
    assert hit.point == pytest.approx((2.0, 1.0), abs=1e-12)
    hit = world.first_collision([[1.0, 3.0], [3.0, 3.0], [3.0, 5.0], [-1.0, 2.0]])
    assert hit is not None
    assert (hit.kind, hit.index) == ("segment", 2)
    assert hit.point == pytest.approx((5 / 9, 19 / 6), abs=1e-12)  # crosses the notch edge 3x + 2y = 8


@pytest.mark.parametrize("seed", range(30))
def test_clearance_matches_brute_force(seed: int) -> None:
    world = _world(seed, kinds=("circle", "square", "rectangle"))
    path = _path(seed + 100, k=6, step=1.0)
    clearance = world.clearance(path)
    p, q = path[:-1], path[1:]
    if not world.segments_in_collision(p, q).any():
        exact = min(float(segment_distance(o, p, q).min()) for o in world.obstacles)
        assert clearance == pytest.approx(exact, rel=1e-12, abs=1e-15)
        return
    # penetration: the deepest signed distance along the path, exact for circles and boxes
    s = np.linspace(0.0, 1.0, 4001)
    samples = (p[:, None, :] + s[None, :, None] * (q - p)[:, None, :]).reshape(-1, 2)
    sampled = float(world.signed_distance(samples).min())
    half_step = float(np.max(np.hypot(*(q - p).T))) / (len(s) - 1) / 2
    assert clearance < 0
    assert sampled - half_step - 1e-12 <= clearance <= sampled + 1e-12


@pytest.mark.parametrize("seed", range(20))
def test_clearance_with_polygons_is_within_the_documented_bound(seed: int) -> None:
    world = _world(seed, kinds=("polygon", "circle"))
    path = _path(seed + 200, k=6, step=1.0)
    clearance = world.clearance(path)
    p, q = path[:-1], path[1:]
    s = np.linspace(0.0, 1.0, 4001)
    samples = (p[:, None, :] + s[None, :, None] * (q - p)[:, None, :]).reshape(-1, 2)
    sampled = float(world.signed_distance(samples).min())
    length = float(np.max(np.hypot(*(q - p).T)))
    half_step = length / (len(s) - 1) / 2
    assert (clearance < 0) == bool(world.segments_in_collision(p, q).any())
    assert sampled - half_step - 1e-12 <= clearance <= sampled + length / 128 + 1e-12


def test_clearance_known_values() -> None:
    circle = Circle(center=(0.0, 0.0), radius=1.0)
    square = Square(center=(10.0, 0.0), half_side=2.0)
    rect = Rectangle(xmin=0.0, xmax=4.0, ymin=20.0, ymax=22.0)
    world = World(workspace=Workspace(), obstacles=[circle, square, rect])
    assert world.clearance([[-2.0, 0.0], [2.0, 0.0]]) == -1.0
    assert world.clearance([[7.0, 0.0], [13.0, 0.0]]) == -2.0
    assert world.clearance([[7.0, 1.0], [13.0, 1.0]]) == -1.0
    assert world.clearance([[1.0, 21.0], [3.0, 21.0]]) == -1.0
    assert world.clearance([[8.0, -3.0], [12.0, 1.0]]) == -1.5  # deepest at (10.5, -0.5)
    assert world.clearance([[11.0, -3.0], [13.0, -1.0]]) == 0.0  # through the corner (12, -2) only
    assert world.clearance([[10.0, -3.0], [13.0, 0.0]]) == -0.5  # cuts the corner, deepest at (11.5, -1.5)
    assert world.clearance([[-2.0, 1.0], [2.0, 1.0]]) == 0.0  # tangent
    assert world.clearance([[-2.0, 1.5], [2.0, 1.5]]) == 0.5
    assert world.clearance([[0.0, 3.0]]) == 2.0  # a single waypoint
    assert world.clearance([[0.0, 0.5]]) == -0.5
    empty = World(workspace=Workspace())
    assert empty.clearance([[0.0, 0.0], [1.0, 1.0]]) == np.inf


def test_empty_world() -> None:
    world = World(workspace=Workspace())
    pts = np.array([[1.0, 2.0], [3.0, 4.0]])
    np.testing.assert_array_equal(world.signed_distance(pts), [np.inf, np.inf])
    assert not world.points_in_collision(pts).any()
    assert not world.segments_in_collision(pts, pts[::-1]).any()
    assert world.first_collision(pts) is None
    assert world.describe() == "workspace x in [0.00, 10.00], y in [0.00, 10.00]\nno obstacles"


def test_in_workspace_includes_the_boundary() -> None:
    world = World(workspace=Workspace(xmin=0, xmax=10, ymin=-1, ymax=1))
    pts = [[0, 0], [10, 1], [5, -1], [10.000001, 0], [5, -1.5], [-1e-12, 0]]
    np.testing.assert_array_equal(world.in_workspace(pts), [True, True, True, False, False, False])
    assert world.in_workspace([5.0, 0.0]).shape == ()


def test_single_point_and_segment_results_are_zero_dimensional() -> None:
    world = _world(0)
    assert world.signed_distance([0.0, 0.0]).shape == ()
    assert world.points_in_collision([0.0, 0.0]).shape == ()
    assert world.segments_in_collision([0.0, 0.0], [1.0, 1.0]).shape == ()


def test_inflate_world() -> None:
    world = _world(3)
    grown = world.inflate(0.25)
    assert grown.workspace == world.workspace
    assert grown.obstacles == tuple(inflate(o, 0.25) for o in world.obstacles)
    assert world.inflate(0.0) == world
    pts = np.random.default_rng(0).uniform(-10, 10, (500, 2))
    near = world.signed_distance(pts) <= 0.25
    assert (grown.signed_distance(pts[near]) <= 1e-9).all()


def test_describe_world() -> None:
    world = World(
        workspace=Workspace(),
        obstacles=[Circle(center=(3.2, 4.1), radius=1.25), Square(center=(5.0, 5.0), half_side=0.5)],
    )
    assert world.describe() == (
        "workspace x in [0.00, 10.00], y in [0.00, 10.00]\n"
        "obstacle 0: circle centred at (3.20, 4.10), radius 1.25\n"
        "obstacle 1: square centred at (5.00, 5.00), half side 0.50 (side length 1.00)"
    )


def test_world_is_frozen_json_round_trips_and_compares_by_value() -> None:
    world = _world(5)
    world.signed_distance([0.0, 0.0])  # fills the packed-array cache
    again = World.model_validate_json(world.model_dump_json())
    assert again == world
    assert hash(again) == hash(world)
    assert World.model_validate(world.model_dump()) == world
    with pytest.raises(Exception, match="frozen"):
        world.obstacles = ()  # type: ignore[misc]
    from_dicts = World(
        workspace={"xmin": 0, "xmax": 5, "ymin": 0, "ymax": 5},
        obstacles=[{"kind": "square", "center": [1, 1], "half_side": 0.5}],
    )
    assert from_dicts.obstacles == (Square(center=(1.0, 1.0), half_side=0.5),)


def test_collision_check_is_fast() -> None:
    """1,000 segments against 100 obstacles: a few ms on a laptop; the bound is loose for loaded machines."""
    rng = np.random.default_rng(0)
    obstacles = []
    for j in range(100):
        c = (float(rng.uniform(0, 10)), float(rng.uniform(0, 10)))
        r = float(rng.uniform(0.1, 0.3))
        obstacles.append(
            [
                Circle(center=c, radius=r),
                Square(center=c, half_side=r),
                Rectangle.from_center(*c, r, 2 * r),
                Polygon(vertices=((c[0], c[1]), (c[0] + r, c[1]), (c[0] + r / 2, c[1] + r))),
            ][j % 4]
        )
    world = World(workspace=Workspace(), obstacles=obstacles)
    path = np.clip(5 + np.cumsum(rng.normal(0, 0.1, (1001, 2)), axis=0), 0, 10)
    for call in (
        lambda: world.segments_in_collision(path[:-1], path[1:]),
        lambda: world.first_collision(path),
        lambda: world.clearance(path),
    ):
        call()
        best = min(_timed(call) for _ in range(3))
        assert best < 0.1, f"took {best * 1e3:.1f} ms"


def _timed(call) -> float:
    start = time.perf_counter()
    call()
    return time.perf_counter() - start
