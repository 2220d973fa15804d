"""Hypothesis properties of the per-shape functions, on free coordinates and on a 0.5 grid."""

from __future__ import annotations

import math

import numpy as np
import shapely
from hypothesis import given
from hypothesis import strategies as st

from audere.world import (
    Circle,
    Polygon,
    Workspace,
    World,
    bounding_box,
    contains,
    inflate,
    segment_distance,
    segments_intersect,
    signed_distance,
)

from .reference import exact_circle_segment_sign, ref_touches_or_intersects, to_shapely
from .strategies import margins, points, segments, shapes


@given(shapes(), points())
def test_signed_distance_is_negative_exactly_inside(shape, pts) -> None:
    np.testing.assert_array_equal(signed_distance(shape, pts) < 0, contains(shape, pts))


@given(shapes(on_grid=True), points(on_grid=True))
def test_signed_distance_is_zero_exactly_on_the_boundary(shape, pts) -> None:
    sd = signed_distance(shape, pts)
    if isinstance(shape, Circle):  # exact rational reference
        sign = exact_circle_segment_sign(pts, pts, shape)
        np.testing.assert_array_equal(np.sign(sd), sign)
    else:  # grid data: shapely's predicates are exact
        np.testing.assert_array_equal(sd == 0, shapely.touches(to_shapely(shape), shapely.points(pts)))
        np.testing.assert_array_equal(sd < 0, shapely.contains(to_shapely(shape), shapely.points(pts)))


@given(shapes(), margins, st.integers(0, 2**32 - 1))
def test_inflate_contains_every_point_within_the_margin(shape, margin, seed) -> None:
    rng = np.random.default_rng(seed)
    box = bounding_box(shape)
    pad = margin + 1.0
    pts = rng.uniform((box.xmin - pad, box.ymin - pad), (box.xmax + pad, box.ymax + pad), (400, 2))
    grown = inflate(shape, margin)
    near = signed_distance(shape, pts) <= margin
    assert (signed_distance(grown, pts[near]) <= 1e-9).all()


@given(shapes(), margins.filter(lambda m: m > 0), st.integers(0, 2**32 - 1))
def test_inflate_stays_close(shape, margin, seed) -> None:
    """Conservative but bounded: circles exact, boxes within margin*sqrt(2), polygons within mitre limit."""
    rng = np.random.default_rng(seed)
    box = bounding_box(shape)
    pad = 6 * margin + 1.0
    pts = rng.uniform((box.xmin - pad, box.ymin - pad), (box.xmax + pad, box.ymax + pad), (400, 2))
    grown = inflate(shape, margin)
    assert type(grown) is type(shape)
    if isinstance(shape, Circle):
        np.testing.assert_allclose(
            signed_distance(grown, pts), signed_distance(shape, pts) - margin, atol=1e-12
        )
        return
    if isinstance(shape, Polygon):  # spikes cut at 5 margins; filled pockets lie within the hull
        far = shapely.distance(to_shapely(shape).convex_hull, shapely.points(pts)) > 5 * margin + 1e-9
    else:
        far = signed_distance(shape, pts) > math.sqrt(2) * margin + 1e-9
    assert (signed_distance(grown, pts[far]) > 0).all()


@given(shapes(on_grid=True), segments(on_grid=True))
def test_segment_distance_is_zero_iff_the_segment_meets_the_shape(shape, seg) -> None:
    p, q = seg
    dist = segment_distance(shape, p, q)
    if isinstance(shape, Circle):
        meets = exact_circle_segment_sign(p, q, shape) <= 0
        np.testing.assert_array_equal(
            segments_intersect(shape, p, q), exact_circle_segment_sign(p, q, shape) < 0
        )
    else:
        meets = ref_touches_or_intersects(shape, p, q)
    np.testing.assert_array_equal(dist == 0, meets)


@given(shapes(), segments())
def test_segment_predicates_are_consistent(shape, seg) -> None:
    p, q = seg
    hit = segments_intersect(shape, p, q)
    dist = segment_distance(shape, p, q)
    assert (dist >= 0).all()
    assert (dist[hit] == 0).all()  # reaching the interior means meeting
    # the ends are on the segment: the segment is at least as close as either end
    ends = np.maximum(np.minimum(signed_distance(shape, p), signed_distance(shape, q)), 0.0)
    assert (dist <= ends + 1e-12).all()
    assert (hit | ~(contains(shape, p) | contains(shape, q))).all()
    np.testing.assert_array_equal(hit, segments_intersect(shape, q, p))


@given(shapes(), points())
def test_zero_length_segments_behave_like_points(shape, pts) -> None:
    np.testing.assert_array_equal(segments_intersect(shape, pts, pts), contains(shape, pts))
    np.testing.assert_allclose(
        segment_distance(shape, pts, pts),
        np.maximum(signed_distance(shape, pts), 0.0),
        rtol=1e-12,
        atol=1e-12,
    )


@given(st.lists(shapes(), max_size=6), points(max_n=20), segments(max_n=20))
def test_world_queries_equal_the_per_shape_queries(obstacles, pts, seg) -> None:
    world = World(workspace=Workspace(), obstacles=obstacles)
    p, q = seg
    if obstacles:
        sd = np.min([signed_distance(o, pts) for o in obstacles], axis=0)
        inside = np.any([contains(o, pts) for o in obstacles], axis=0)
        hit = np.any([segments_intersect(o, p, q) for o in obstacles], axis=0)
    else:
        sd, inside, hit = np.full(len(pts), np.inf), np.zeros(len(pts), bool), np.zeros(len(p), bool)
    np.testing.assert_allclose(world.signed_distance(pts), sd, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(world.points_in_collision(pts), inside)
    np.testing.assert_array_equal(world.segments_in_collision(p, q), hit)
