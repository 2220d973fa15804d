"""The private grid search behind the solvability guarantees: sound (its paths are collision-free) and
complete enough (it finds the obvious paths and reports the impossible ones)."""

from __future__ import annotations

import numpy as np
import pytest
from shapely.geometry import LineString, Point, box
from shapely.geometry.base import BaseGeometry

from audere.scenarios._grid import certify, grid_path
from audere.world import Circle, Rectangle, Square, Workspace, World

WS = Workspace(xmin=0.0, xmax=10.0, ymin=0.0, ymax=10.0)


def _shapely(world: World) -> list[BaseGeometry]:
    out: list[BaseGeometry] = []
    for o in world.obstacles:
        if isinstance(o, Circle):
            out.append(Point(o.center).buffer(o.radius, quad_segs=64))
        elif isinstance(o, Square):
            (x, y), h = o.center, o.half_side
            out.append(box(x - h, y - h, x + h, y + h))
        else:
            assert isinstance(o, Rectangle)
            out.append(box(o.xmin, o.ymin, o.xmax, o.ymax))
    return out


def test_empty_world_straight_path() -> None:
    world = World(workspace=WS)
    path = grid_path(world, (1.0, 1.0), (9.0, 9.0), spacing=0.5)
    assert path is not None
    np.testing.assert_array_equal(path[[0, -1]], [[1.0, 1.0], [9.0, 9.0]])
    # Collinear grid moves are merged: the diagonal is one straight run.
    assert len(path) <= 4
    assert certify(world, (1.0, 1.0), (9.0, 9.0), spacing=0.5)


def test_a_wall_across_the_map_blocks_everything() -> None:
    world = World(workspace=WS, obstacles=(Rectangle(xmin=4.9, xmax=5.1, ymin=-1.0, ymax=11.0),))
    assert grid_path(world, (1.0, 5.0), (9.0, 5.0), spacing=0.1) is None
    assert not certify(world, (1.0, 5.0), (9.0, 5.0), spacing=0.1)


@pytest.mark.parametrize("gap", [0.6, 1.0])
def test_finds_the_gap_in_a_wall(gap: float) -> None:
    lo, hi = 5.0 - gap / 2, 5.0 + gap / 2
    walls = (
        Rectangle(xmin=4.9, xmax=5.1, ymin=-1.0, ymax=lo),
        Rectangle(xmin=4.9, xmax=5.1, ymin=hi, ymax=11.0),
    )
    world = World(workspace=WS, obstacles=walls)
    path = grid_path(world, (1.0, 1.0), (9.0, 9.0), spacing=0.1)
    assert path is not None
    assert world.first_collision(path) is None
    line = LineString(path)
    assert not any(line.intersects(s.buffer(-1e-6)) for s in _shapely(world))
    assert certify(world, (1.0, 1.0), (9.0, 9.0), spacing=0.1)


def test_paths_never_enter_obstacles_random_worlds() -> None:
    rng = np.random.default_rng(0)
    found = 0
    for _ in range(30):
        obstacles = []
        for _ in range(int(rng.integers(5, 25))):
            c = (float(rng.uniform(0, 10)), float(rng.uniform(0, 10)))
            if rng.random() < 0.5:
                obstacles.append(Circle(center=c, radius=float(rng.uniform(0.2, 1.5))))
            else:
                obstacles.append(Square(center=c, half_side=float(rng.uniform(0.2, 1.0))))
        world = World(workspace=WS, obstacles=tuple(obstacles))
        start, goal = (0.1, 0.1), (9.9, 9.9)
        if world.points_in_collision(np.array([start, goal])).any():
            continue
        path = grid_path(world, start, goal, spacing=0.2)
        assert certify(world, start, goal, spacing=0.2) == (path is not None)
        if path is None:
            continue
        found += 1
        assert world.first_collision(path) is None
        assert world.in_workspace(path).all()
        # Independent check with shapely: the polyline does not enter any shape's interior.
        line = LineString(path)
        for s in _shapely(world):
            assert not line.intersects(s.buffer(-1e-6))
    assert found >= 10
