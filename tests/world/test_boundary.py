"""Contact cases spelled out: touching the boundary is allowed, reaching the interior is a collision."""

from __future__ import annotations

import numpy as np
import pytest

from audere.world import (
    Circle,
    Polygon,
    Rectangle,
    Square,
    contains,
    segment_distance,
    segments_intersect,
    signed_distance,
)

UNIT_CIRCLE = Circle(center=(0.0, 0.0), radius=1.0)
CIRCLE = Circle(center=(3.25, 4.125), radius=1.25)  # binary fractions: contacts are exact
CIRCLE5 = Circle(center=(0.0, 0.0), radius=5.0)
SQUARE = Square(center=(0.0, 0.0), half_side=1.0)
RECT = Rectangle(xmin=1.0, xmax=4.0, ymin=-1.0, ymax=1.0)
# An arrow head with a notch: vertices (0,0), (4,0), (4,4), reflex vertex (2,1), (0,4).
NOTCHED = Polygon(vertices=((0.0, 0.0), (4.0, 0.0), (4.0, 4.0), (2.0, 1.0), (0.0, 4.0)))
TRIANGLE = Polygon(vertices=((0.0, 0.0), (3.0, 1.0), (1.0, 3.0)))  # slanted edges

# (shape, p, q, reaches the interior, distance)
SEGMENTS = [
    # circle
    pytest.param(UNIT_CIRCLE, (-2, 1), (2, 1), False, 0.0, id="circle-tangent"),
    pytest.param(UNIT_CIRCLE, (-2, -1), (2, -1), False, 0.0, id="circle-tangent-below"),
    pytest.param(UNIT_CIRCLE, (-2, 0), (-1, 0), False, 0.0, id="circle-ends-on-boundary"),
    pytest.param(UNIT_CIRCLE, (1, 0), (3, 0), False, 0.0, id="circle-starts-on-boundary-leaves"),
    pytest.param(UNIT_CIRCLE, (1, 0), (0.5, 0), True, 0.0, id="circle-starts-on-boundary-enters"),
    pytest.param(UNIT_CIRCLE, (-1, 0), (1, 0), True, 0.0, id="circle-diameter"),
    pytest.param(UNIT_CIRCLE, (0.6, 0.8), (0.6, -0.8), True, 0.0, id="circle-chord"),
    pytest.param(UNIT_CIRCLE, (-2, 1.5), (2, 1.5), False, 0.5, id="circle-misses"),
    pytest.param(UNIT_CIRCLE, (0, 0), (0, 0), True, 0.0, id="circle-zero-length-centre"),
    pytest.param(UNIT_CIRCLE, (0, 1), (0, 1), False, 0.0, id="circle-zero-length-boundary"),
    pytest.param(CIRCLE, (2.0, 2.0), (2.0, 6.0), False, 0.0, id="circle-offcentre-tangent"),
    pytest.param(CIRCLE5, (-1, 7), (7, 1), False, 0.0, id="circle-slanted-tangent-at-3-4"),
    pytest.param(CIRCLE5, (-1, 6.9), (7, 0.9), True, 0.0, id="circle-slanted-just-inside"),
    # square
    pytest.param(SQUARE, (-2, 1), (2, 1), False, 0.0, id="square-along-top-edge-extended"),
    pytest.param(SQUARE, (-0.5, 1), (0.5, 1), False, 0.0, id="square-inside-top-edge"),
    pytest.param(SQUARE, (-1, -1), (1, -1), False, 0.0, id="square-whole-bottom-edge"),
    pytest.param(SQUARE, (-2, 0), (0, 2), False, 0.0, id="square-through-corner-only"),
    pytest.param(SQUARE, (-2, -2), (-1, -1), False, 0.0, id="square-ends-at-corner"),
    pytest.param(SQUARE, (-1, -1), (1, 1), True, 0.0, id="square-diagonal"),
    pytest.param(SQUARE, (-1, 1), (0, 0), True, 0.0, id="square-corner-to-centre"),
    pytest.param(SQUARE, (-1, -1), (1, -0.5), True, 0.0, id="square-corner-into-interior"),
    pytest.param(SQUARE, (2, 0), (3, 0), False, 1.0, id="square-misses"),
    pytest.param(SQUARE, (2, 2), (3, 3), False, np.sqrt(2), id="square-misses-corner"),
    pytest.param(SQUARE, (1, -3), (1, 3), False, 0.0, id="square-along-right-edge-through"),
    pytest.param(SQUARE, (0.5, -3), (0.5, 3), True, 0.0, id="square-vertical-through"),
    # rectangle
    pytest.param(RECT, (0, 1), (5, 1), False, 0.0, id="rect-along-top"),
    pytest.param(RECT, (1, -2), (1, 2), False, 0.0, id="rect-along-left"),
    pytest.param(RECT, (0, 0), (1, 0), False, 0.0, id="rect-ends-on-left-edge"),
    pytest.param(RECT, (0, 0), (1.5, 0), True, 0.0, id="rect-enters"),
    pytest.param(RECT, (0, 3), (5, 3), False, 2.0, id="rect-misses"),
    # polygon
    pytest.param(NOTCHED, (1, 3), (3, 3), False, 1 / np.sqrt(13), id="poly-in-notch"),
    pytest.param(NOTCHED, (0, 4), (4, 4), False, 0.0, id="poly-across-notch-mouth-vertex-to-vertex"),
    pytest.param(NOTCHED, (-1, 4), (5, 4), False, 0.0, id="poly-across-notch-mouth-extended"),
    pytest.param(NOTCHED, (1, 0), (3, 0), False, 0.0, id="poly-along-bottom-edge"),
    pytest.param(NOTCHED, (4, 4), (2, 1), False, 0.0, id="poly-along-slanted-edge"),
    pytest.param(NOTCHED, (6, 7), (2, 1), False, 0.0, id="poly-along-slanted-edge-from-outside"),
    pytest.param(NOTCHED, (6, 7), (0, -2), True, 0.0, id="poly-along-slanted-edge-then-inside"),
    pytest.param(NOTCHED, (2, 1), (2, 3), False, 0.0, id="poly-from-reflex-vertex-into-notch"),
    pytest.param(NOTCHED, (2, 1), (2, 0.5), True, 0.0, id="poly-from-reflex-vertex-inwards"),
    pytest.param(NOTCHED, (2, 1), (3, 1), True, 0.0, id="poly-from-reflex-vertex-sideways"),
    pytest.param(NOTCHED, (0, 2), (-1, 2), False, 0.0, id="poly-from-edge-outwards"),
    pytest.param(NOTCHED, (0, 2), (1, 2), True, 0.0, id="poly-from-edge-inwards"),
    pytest.param(NOTCHED, (-1, -1), (0, 0), False, 0.0, id="poly-ends-at-vertex"),
    pytest.param(NOTCHED, (-1, -1), (1, 1), True, 0.0, id="poly-through-vertex-inwards"),
    pytest.param(NOTCHED, (-1, 1), (1, -1), False, 0.0, id="poly-through-vertex-outside"),
    pytest.param(TRIANGLE, (0, 0), (3, 1), False, 0.0, id="triangle-slanted-edge"),
    pytest.param(TRIANGLE, (3, 1), (1, 3), False, 0.0, id="triangle-slanted-edge-2"),
    pytest.param(TRIANGLE, (1.5, 0.5), (2, 2), True, 0.0, id="triangle-from-edge-midpoint-in"),
    pytest.param(TRIANGLE, (1.5, 0.5), (2, -1), False, 0.0, id="triangle-from-edge-midpoint-out"),
    pytest.param(TRIANGLE, (-3, -1), (6, 2), False, 0.0, id="triangle-edge-line-overlap"),
]


@pytest.mark.parametrize(("shape", "p", "q", "hit", "distance"), SEGMENTS)
def test_contact_cases(shape, p, q, hit: bool, distance: float) -> None:
    p_arr = np.array(p, dtype=float)
    q_arr = np.array(q, dtype=float)
    assert bool(segments_intersect(shape, p_arr, q_arr)) is hit
    assert bool(segments_intersect(shape, q_arr, p_arr)) is hit
    if distance == 0.0:
        assert float(segment_distance(shape, p_arr, q_arr)) == 0.0
    else:
        assert float(segment_distance(shape, p_arr, q_arr)) == pytest.approx(distance, rel=1e-12)


# (shape, point, signed distance)
POINTS = [
    pytest.param(UNIT_CIRCLE, (1, 0), 0.0, id="circle-boundary"),
    pytest.param(CIRCLE5, (3, 4), 0.0, id="circle-boundary-diagonal"),
    pytest.param(CIRCLE5, (-3, -4), 0.0, id="circle-boundary-diagonal-2"),
    pytest.param(UNIT_CIRCLE, (0, 0), -1.0, id="circle-centre"),
    pytest.param(UNIT_CIRCLE, (3, 4), 4.0, id="circle-outside"),
    pytest.param(SQUARE, (1, 0.3), 0.0, id="square-edge"),
    pytest.param(SQUARE, (1, 1), 0.0, id="square-corner"),
    pytest.param(SQUARE, (0, 0), -1.0, id="square-centre"),
    pytest.param(SQUARE, (0.5, 0.25), -0.5, id="square-inside"),
    pytest.param(SQUARE, (4, 5), 5.0, id="square-outside-corner"),
    pytest.param(RECT, (2.5, -1), 0.0, id="rect-edge"),
    pytest.param(RECT, (2.5, 0), -1.0, id="rect-centre"),
    pytest.param(NOTCHED, (2, 1), 0.0, id="poly-reflex-vertex"),
    pytest.param(NOTCHED, (3, 2.5), 0.0, id="poly-slanted-edge-midpoint"),
    pytest.param(NOTCHED, (2, 0.5), -0.5, id="poly-below-reflex-vertex"),
    pytest.param(NOTCHED, (2, 2), 2 / np.sqrt(13), id="poly-in-notch"),
    pytest.param(TRIANGLE, (1.5, 0.5), 0.0, id="triangle-slanted-midpoint"),
    pytest.param(TRIANGLE, (2, 2), 0.0, id="triangle-hypotenuse-midpoint"),
]


@pytest.mark.parametrize(("shape", "point", "sd"), POINTS)
def test_point_cases(shape, point, sd: float) -> None:
    x = np.array(point, dtype=float)
    assert float(signed_distance(shape, x)) == pytest.approx(sd, rel=1e-12, abs=0.0)
    assert bool(contains(shape, x)) is bool(sd < 0)


def test_single_point_gives_zero_dimensional_results() -> None:
    assert signed_distance(UNIT_CIRCLE, [2.0, 0.0]).shape == ()
    assert contains(UNIT_CIRCLE, (0.0, 0.0)).shape == ()
    assert segments_intersect(SQUARE, (0.0, 0.0), (2.0, 0.0)).shape == ()
    assert segment_distance(SQUARE, (2.0, 0.0), (3.0, 0.0)).shape == ()
    assert signed_distance(UNIT_CIRCLE, [[2.0, 0.0]]).shape == (1,)
    assert signed_distance(UNIT_CIRCLE, np.zeros((0, 2))).shape == (0,)
