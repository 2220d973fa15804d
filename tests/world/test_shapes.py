"""Shape models, descriptions, bounding boxes and inflation of each kind."""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from pydantic import TypeAdapter

from audere.errors import InvalidArgumentError
from audere.world import (
    Circle,
    Obstacle,
    Polygon,
    Rectangle,
    Square,
    Workspace,
    bounding_box,
    describe_shape,
    inflate,
    segment_distance,
    segments_intersect,
    signed_distance,
)

DESCRIPTIONS = [
    (Circle(center=(3.2, 4.1), radius=1.25), "circle centred at (3.20, 4.10), radius 1.25"),
    (
        Square(center=(5.0, 5.0), half_side=0.5),
        "square centred at (5.00, 5.00), half side 0.50 (side length 1.00)",
    ),
    (
        # 0.125 rounds (half to even) to 0.12: pass decimals=3 to describe it exactly
        Square(center=(-1.0, 0.0), half_side=0.125),
        "square centred at (-1.00, 0.00), half side 0.12 (side length 0.25)",
    ),
    (Rectangle(xmin=1.0, xmax=2.0, ymin=3.0, ymax=4.5), "rectangle x in [1.00, 2.00], y in [3.00, 4.50]"),
    (Rectangle.from_center(9.0, 5.5, 2.0, 0.5), "rectangle x in [8.00, 10.00], y in [5.25, 5.75]"),
    (
        Polygon(vertices=((0.0, 0.0), (2.0, 0.0), (1.0, 1.5))),
        "polygon with vertices (0.00, 0.00), (2.00, 0.00), (1.00, 1.50)",
    ),
    (
        Circle(center=(-0.001, 0.004), radius=10.0),
        "circle centred at (0.00, 0.00), radius 10.00",
    ),  # no "-0.00"
    (Workspace(), "workspace x in [0.00, 10.00], y in [0.00, 10.00]"),
]


@pytest.mark.parametrize(("shape", "text"), DESCRIPTIONS)
def test_describe_shape(shape, text: str) -> None:
    assert describe_shape(shape) == text


def test_more_decimals_describe_finer_shapes_exactly() -> None:
    square = Square(center=(-1.0, 0.0), half_side=0.125)
    assert describe_shape(square, decimals=3) == (
        "square centred at (-1.000, 0.000), half side 0.125 (side length 0.250)"
    )
    assert (
        describe_shape(Circle(center=(1.0, 2.0), radius=0.5), decimals=0)
        == "circle centred at (1, 2), radius 0"
    )


@pytest.mark.parametrize("decimals", [-1, 13, 2.0, True, "2"])
def test_bad_decimals(decimals) -> None:
    with pytest.raises(
        InvalidArgumentError, match=rf"decimals must be an integer from 0 to 12, got {decimals!r}"
    ):
        describe_shape(Workspace(), decimals=decimals)


def test_square_description_states_both_half_side_and_side_length() -> None:
    text = describe_shape(Square(center=(1.0, 2.0), half_side=0.75))
    assert "half side 0.75" in text
    assert "side length 1.50" in text


@pytest.mark.parametrize(
    ("shape", "bounds"),
    [
        (Circle(center=(1.0, 2.0), radius=0.5), (0.5, 1.5, 1.5, 2.5)),
        (Square(center=(1.0, 2.0), half_side=0.5), (0.5, 1.5, 1.5, 2.5)),
        (Rectangle(xmin=0.0, xmax=3.0, ymin=-1.0, ymax=1.0), (0.0, 3.0, -1.0, 1.0)),
        (Polygon(vertices=((0.0, 0.0), (4.0, 1.0), (1.0, 3.0))), (0.0, 4.0, 0.0, 3.0)),
        (Workspace(xmin=-1, xmax=1, ymin=-2, ymax=2), (-1.0, 1.0, -2.0, 2.0)),
    ],
)
def test_bounding_box(shape, bounds) -> None:
    box = bounding_box(shape)
    assert isinstance(box, Rectangle)
    assert (box.xmin, box.xmax, box.ymin, box.ymax) == bounds


def test_inflate_each_kind() -> None:
    assert inflate(Circle(center=(1.0, 1.0), radius=0.5), 0.25) == Circle(center=(1.0, 1.0), radius=0.75)
    assert inflate(Square(center=(1.0, 1.0), half_side=0.5), 0.25) == Square(
        center=(1.0, 1.0), half_side=0.75
    )
    assert inflate(Rectangle(xmin=0.0, xmax=2.0, ymin=0.0, ymax=1.0), 0.5) == Rectangle(
        xmin=-0.5, xmax=2.5, ymin=-0.5, ymax=1.5
    )
    # a square given as a polygon: the mitred offset of right angles is the grown square
    grown = inflate(Polygon(vertices=((0.0, 0.0), (2.0, 0.0), (2.0, 2.0), (0.0, 2.0))), 0.5)
    assert isinstance(grown, Polygon)
    assert sorted(grown.vertices) == [(-0.5, -0.5), (-0.5, 2.5), (2.5, -0.5), (2.5, 2.5)]


def test_inflate_by_zero_returns_the_shape_itself() -> None:
    shape = Polygon(vertices=((0.0, 0.0), (2.0, 0.0), (1.0, 1.5)))
    assert inflate(shape, 0.0) is shape


def test_inflate_sharp_polygon_is_bevelled_at_the_mitre_limit() -> None:
    spike = Polygon(vertices=((0.0, 0.0), (10.0, 0.2), (0.0, 0.4)))
    grown = inflate(spike, 0.5)
    assert bounding_box(grown).xmax == pytest.approx(10.0 + 5 * 0.5, rel=1e-9)
    # still contains every point within the margin, including around the tip
    tip = np.array([10.0, 0.2]) + 0.5 * np.c_[np.cos(np.linspace(-2, 2, 50)), np.sin(np.linspace(-2, 2, 50))]
    assert (signed_distance(grown, tip) <= 1e-12).all()


def test_inflate_fills_a_closing_notch() -> None:
    c_shape = Polygon(vertices=((0, 0), (3, 0), (3, 1), (1, 1), (1, 2), (3, 2), (3, 3), (0, 3)))
    grown = inflate(c_shape, 0.6)
    assert isinstance(grown, Polygon)
    assert signed_distance(grown, [2.0, 1.5]) < 0  # the notch (width 1 < 2 * 0.6) is filled


def test_polygon_orientation_and_repeated_vertices_do_not_matter() -> None:
    ccw = Polygon(vertices=((0.0, 0.0), (4.0, 0.0), (4.0, 4.0), (2.0, 1.0), (0.0, 4.0)))
    cw = Polygon(vertices=tuple(reversed(ccw.vertices)))
    repeated = Polygon(
        vertices=((0.0, 0.0), (4.0, 0.0), (4.0, 0.0), (4.0, 4.0), (2.0, 1.0), (0.0, 4.0), (0.0, 0.0))
    )
    rng = np.random.default_rng(0)
    pts = np.round(rng.uniform(-1, 5, (300, 2)) * 2) / 2
    p, q = pts[:150], pts[150:]
    for other in (cw, repeated):
        np.testing.assert_array_equal(signed_distance(other, pts), signed_distance(ccw, pts))
        np.testing.assert_array_equal(segments_intersect(other, p, q), segments_intersect(ccw, p, q))
        np.testing.assert_array_equal(segment_distance(other, p, q), segment_distance(ccw, p, q))
    assert shapely.Polygon(repeated.vertices).is_valid


def test_obstacle_union_is_discriminated_by_kind() -> None:
    adapter = TypeAdapter(Obstacle)
    assert adapter.validate_python({"kind": "square", "center": [1, 2], "half_side": 0.5}) == Square(
        center=(1.0, 2.0), half_side=0.5
    )
    assert isinstance(adapter.validate_json('{"kind": "circle", "center": [0, 0], "radius": 1}'), Circle)
