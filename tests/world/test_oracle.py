"""Every exact function against shapely and against dense sampling, on random shapes.

Two kinds of data: free coordinates, and coordinates on a 0.5 grid, where arithmetic is exact and
segments often touch vertices, run along edges or stop on the boundary. Squares, rectangles and
polygons must then agree with shapely's robust predicates *exactly*; circles (polygons of 1024
vertices in shapely) are compared only where the answer is not within the approximation gap.
"""

from __future__ import annotations

import numpy as np
import pytest
import shapely

from audere.world import (
    Circle,
    bounding_box,
    contains,
    segment_distance,
    segments_intersect,
    signed_distance,
)

from .reference import (
    KINDS,
    random_points,
    random_shape,
    ref_segment_distance,
    ref_segments_intersect,
    ref_signed_distance,
    ref_touches_or_intersects,
    to_shapely,
    tolerance,
)

CASES = [(kind, on_grid) for kind in KINDS for on_grid in (False, True)]
SHAPES_PER_CASE = 8


def _shapes(kind: str, on_grid: bool, seed: int = 0) -> list:
    rng = np.random.default_rng([seed, KINDS.index(kind), on_grid])
    return [random_shape(rng, kind, grid=on_grid) for _ in range(SHAPES_PER_CASE)]


def _boundary_points(shape) -> np.ndarray:
    """Points exactly on the boundary: vertices and edge midpoints (circles: the four extreme points)."""
    if isinstance(shape, Circle):
        (cx, cy), r = shape.center, shape.radius
        return np.array([(cx + r, cy), (cx - r, cy), (cx, cy + r), (cx, cy - r)])
    ring = np.asarray(to_shapely(shape).exterior.coords)
    return np.r_[ring[:-1], 0.5 * (ring[:-1] + ring[1:])]


def _segments(rng: np.random.Generator, shape, on_grid: bool, n: int = 300) -> tuple[np.ndarray, np.ndarray]:
    """Random segments, zero-length ones, and segments between and through boundary points.

    Segments through *computed* points (edge midpoints, reflections) are only built on the grid,
    where they are exact: with free coordinates they pass within rounding of a vertex, where
    shapely's relate (which rounds intersection points) and an exact answer may differ.
    """
    p = random_points(rng, n, grid=on_grid)
    q = random_points(rng, n, grid=on_grid)
    b = _boundary_points(shape) if on_grid else np.asarray(to_shapely(shape).exterior.coords)[:-1]
    i, j = rng.integers(0, len(b), (2, 60))
    p = np.r_[p, b[i], p[:20]]
    q = np.r_[q, b[j], p[:20]]  # chords between boundary points, zero length
    if on_grid:
        p = np.r_[p, b[i]]
        q = np.r_[q, 2 * b[j] - b[i]]  # through a boundary point and beyond
    return p, q


@pytest.mark.parametrize(("kind", "on_grid"), CASES)
def test_signed_distance_and_contains_match_shapely(kind: str, on_grid: bool) -> None:
    rng = np.random.default_rng(1)
    for shape in _shapes(kind, on_grid):
        pts = np.r_[random_points(rng, 400, grid=on_grid), _boundary_points(shape)]
        sd = signed_distance(shape, pts)
        ref = ref_signed_distance(shape, pts)
        tol = tolerance(shape)
        np.testing.assert_allclose(sd, ref, rtol=0, atol=tol)
        inside = contains(shape, pts)
        clear = np.abs(ref) > tol
        np.testing.assert_array_equal(inside[clear], shapely.contains_xy(to_shapely(shape), *pts[clear].T))
        np.testing.assert_array_equal(inside, sd < 0)


@pytest.mark.parametrize(("kind", "on_grid"), CASES)
def test_boundary_points_are_not_inside(kind: str, on_grid: bool) -> None:
    for shape in _shapes(kind, on_grid):
        pts = _boundary_points(shape)
        if on_grid:  # exactly on the boundary: distance exactly 0, not inside
            assert not contains(shape, pts).any()
            np.testing.assert_array_equal(signed_distance(shape, pts), 0.0)
        else:  # the boundary points themselves are rounded
            np.testing.assert_allclose(signed_distance(shape, pts), 0.0, atol=1e-12)


def _circle_ambiguous(shape, p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Segments whose distance to the circle's centre is within shapely's approximation gap of the radius."""
    if not isinstance(shape, Circle):
        return np.zeros(len(p), dtype=bool)
    from .reference import lines

    d = shapely.distance(shapely.Point(shape.center), lines(p, q))
    return np.abs(d - shape.radius) <= tolerance(shape)


@pytest.mark.parametrize(("kind", "on_grid"), CASES)
def test_segments_intersect_matches_shapely(kind: str, on_grid: bool) -> None:
    rng = np.random.default_rng(2)
    for shape in _shapes(kind, on_grid):
        p, q = _segments(rng, shape, on_grid)
        mine = segments_intersect(shape, p, q)
        ref = ref_segments_intersect(shape, p, q)
        keep = ~_circle_ambiguous(shape, p, q)
        np.testing.assert_array_equal(mine[keep], ref[keep])
        np.testing.assert_array_equal(mine, segments_intersect(shape, q, p))  # direction does not matter


@pytest.mark.parametrize(("kind", "on_grid"), CASES)
def test_segment_distance_matches_shapely(kind: str, on_grid: bool) -> None:
    rng = np.random.default_rng(3)
    for shape in _shapes(kind, on_grid):
        p, q = _segments(rng, shape, on_grid)
        dist = segment_distance(shape, p, q)
        np.testing.assert_allclose(dist, ref_segment_distance(shape, p, q), rtol=0, atol=tolerance(shape))
        np.testing.assert_allclose(dist, segment_distance(shape, q, p), rtol=0, atol=1e-12)
        if not isinstance(shape, Circle):  # zero exactly when the closed sets meet
            np.testing.assert_array_equal(dist == 0, ref_touches_or_intersects(shape, p, q))


@pytest.mark.parametrize(("kind", "on_grid"), CASES)
def test_segments_intersect_agrees_with_dense_sampling(kind: str, on_grid: bool) -> None:
    """A segment that passes the exact test has no sample strictly inside; a sample inside implies a hit."""
    rng = np.random.default_rng(4)
    s = np.linspace(0.0, 1.0, 301)
    for shape in _shapes(kind, on_grid)[:4]:
        p, q = _segments(rng, shape, on_grid, n=150)
        samples = p[:, None, :] + s[None, :, None] * (q - p)[:, None, :]
        flat = samples.reshape(-1, 2)
        # Samples are rounded off the segment: only those clearly away from the boundary count.
        if isinstance(shape, Circle):  # analytic reference
            inside = np.hypot(*(flat - shape.center).T) < shape.radius - 1e-9
        else:
            geom = to_shapely(shape)
            shapely.prepare(geom)
            inside = shapely.contains_xy(geom, *flat.T)
            inside &= shapely.distance(geom.exterior, shapely.points(flat)) > 1e-9
        sampled_hit = inside.reshape(len(p), len(s)).any(axis=1)
        hit = segments_intersect(shape, p, q)
        assert not (sampled_hit & ~hit).any(), "a sample lies inside but the exact test says no"
        # Conversely a hit must reach the interior: the deepest point is strictly inside.
        dist = segment_distance(shape, p, q)
        assert (dist[hit] == 0).all()


@pytest.mark.parametrize(("kind", "on_grid"), CASES)
def test_bounding_box_matches_shapely(kind: str, on_grid: bool) -> None:
    for shape in _shapes(kind, on_grid):
        box = bounding_box(shape)
        ref = to_shapely(shape).bounds
        np.testing.assert_allclose(
            (box.xmin, box.ymin, box.xmax, box.ymax), ref, atol=tolerance(shape) if kind != "circle" else 1e-9
        )
