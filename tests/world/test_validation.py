"""Bad input: every message names the argument, the expectation and what was received."""

from __future__ import annotations

import numpy as np
import pytest
from pydantic import ValidationError

from audere.errors import InvalidArgumentError
from audere.world import (
    Circle,
    Polygon,
    Rectangle,
    Square,
    Workspace,
    World,
    bounding_box,
    contains,
    describe_shape,
    inflate,
    segment_distance,
    segments_intersect,
    signed_distance,
)

C = Circle(center=(0.0, 0.0), radius=1.0)
WORLD = World(workspace=Workspace(), obstacles=(C,))

BAD_POINTS = [
    pytest.param("abc", r"points must be an array of numbers, got str", id="string"),
    pytest.param([[0.0, 1.0], [2.0]], r"points must be an array of numbers", id="ragged"),
    pytest.param(
        [1.0, 2.0, 3.0], r"points must have shape \(n, 2\) or \(2,\), got shape \(3,\)", id="3-vector"
    ),
    pytest.param(
        [[1.0, 2.0, 3.0]], r"points must have shape \(n, 2\) or \(2,\), got shape \(1, 3\)", id="n-by-3"
    ),
    pytest.param(
        np.zeros((2, 2, 2)), r"points must have shape \(n, 2\) or \(2,\), got shape \(2, 2, 2\)", id="3-d"
    ),
    pytest.param(3.0, r"points must have shape \(n, 2\) or \(2,\), got shape \(\)", id="scalar"),
    pytest.param([[0.0, np.nan]], r"points must be finite, got nan at index \[0, 1\]", id="nan"),
    pytest.param([np.inf, 0.0], r"points must be finite, got inf at index \[0\]", id="inf-single"),
]


@pytest.mark.parametrize(("points", "match"), BAD_POINTS)
@pytest.mark.parametrize(
    "call",
    [
        lambda x: signed_distance(C, x),
        lambda x: contains(C, x),
        WORLD.signed_distance,
        WORLD.points_in_collision,
        WORLD.in_workspace,
    ],
    ids=[
        "signed_distance",
        "contains",
        "World.signed_distance",
        "World.points_in_collision",
        "World.in_workspace",
    ],
)
def test_bad_points(call, points, match: str) -> None:
    with pytest.raises(InvalidArgumentError, match=match):
        call(points)


BAD_SEGMENTS = [
    pytest.param(
        [[0, 0], [1, 1]], [[1, 1]], r"p and q must have the same shape .* got shapes \(2, 2\) and \(1, 2\)"
    ),
    pytest.param([0, 0], [[1, 1]], r"p and q must have the same shape .* got shapes \(2,\) and \(1, 2\)"),
    pytest.param([[0, 0, 0]], [[1, 1]], r"p must have shape \(n, 2\) or \(2,\), got shape \(1, 3\)"),
    pytest.param([[0, 0]], [[1, np.nan]], r"q must be finite, got nan at index \[0, 1\]"),
    pytest.param([[0, 0]], "x", r"q must be an array of numbers, got str"),
]


@pytest.mark.parametrize(("p", "q", "match"), BAD_SEGMENTS)
@pytest.mark.parametrize(
    "call",
    [
        lambda p, q: segments_intersect(C, p, q),
        lambda p, q: segment_distance(C, p, q),
        WORLD.segments_in_collision,
    ],
    ids=["segments_intersect", "segment_distance", "World.segments_in_collision"],
)
def test_bad_segments(call, p, q, match: str) -> None:
    with pytest.raises(InvalidArgumentError, match=match):
        call(p, q)


BAD_MARGINS = [
    pytest.param(-0.5, r"margin must be a finite number >= 0, got -0.5", id="negative"),
    pytest.param(float("nan"), r"margin must be a finite number >= 0, got nan", id="nan"),
    pytest.param(float("inf"), r"margin must be a finite number >= 0, got inf", id="inf"),
    pytest.param("0.5", r"margin must be a number >= 0, got str: '0.5'", id="string"),
    pytest.param(True, r"margin must be a number >= 0, got bool: True", id="bool"),
    pytest.param(None, r"margin must be a number >= 0, got NoneType: None", id="none"),
]


@pytest.mark.parametrize(("margin", "match"), BAD_MARGINS)
@pytest.mark.parametrize("call", [lambda m: inflate(C, m), WORLD.inflate], ids=["inflate", "World.inflate"])
def test_bad_margins(call, margin, match: str) -> None:
    with pytest.raises(InvalidArgumentError, match=match):
        call(margin)


def test_integer_and_numpy_margins_are_accepted() -> None:
    assert inflate(C, 1).radius == 2.0
    assert inflate(C, np.float32(0.5)).radius == 1.5


@pytest.mark.parametrize(
    "call",
    [
        lambda s: signed_distance(s, [0.0, 0.0]),
        lambda s: contains(s, [0.0, 0.0]),
        lambda s: segments_intersect(s, [0.0, 0.0], [1.0, 1.0]),
        lambda s: segment_distance(s, [0.0, 0.0], [1.0, 1.0]),
        lambda s: inflate(s, 1.0),
        describe_shape,
        bounding_box,
    ],
    ids=[
        "signed_distance",
        "contains",
        "segments_intersect",
        "segment_distance",
        "inflate",
        "describe",
        "bbox",
    ],
)
@pytest.mark.parametrize(
    ("shape", "got"),
    [({"kind": "circle", "center": (0, 0), "radius": 1}, "dict"), ("circle", "str"), (None, "NoneType")],
)
def test_not_a_shape(call, shape, got: str) -> None:
    with pytest.raises(
        InvalidArgumentError, match=rf"shape must be a Circle, Square, Rectangle or Polygon, got {got}"
    ):
        call(shape)


def test_workspace_is_not_an_obstacle_shape() -> None:
    with pytest.raises(
        InvalidArgumentError, match="shape must be a Circle, Square, Rectangle or Polygon, got Workspace"
    ):
        signed_distance(Workspace(), [0.0, 0.0])


BAD_PATHS = [
    pytest.param([], r"path must have shape \(k, 2\), got shape \(0,\)", id="empty-list"),
    pytest.param(np.zeros((0, 2)), r"path must have at least 1 rows, got 0", id="no-rows"),
    pytest.param([[0, 0, 0]], r"path must have shape \(k, 2\), got shape \(1, 3\)", id="n-by-3"),
    pytest.param([[0, 0], [np.inf, 1]], r"path must be finite, got inf at index \[1, 0\]", id="inf"),
]


@pytest.mark.parametrize(("path", "match"), BAD_PATHS)
@pytest.mark.parametrize("method", ["first_collision", "clearance"])
def test_bad_paths(method: str, path, match: str) -> None:
    with pytest.raises(InvalidArgumentError, match=match):
        getattr(WORLD, method)(path)


BAD_SHAPES = [
    pytest.param(
        Polygon,
        {"vertices": [(0, 0), (1, 1), (1, 0), (0, 1)]},
        r"vertices\n.*simple polygon.*Self-intersection",
    ),
    pytest.param(
        Polygon, {"vertices": [(0, 0), (1, 1), (2, 2)]}, r"vertices\n.*non-zero area, got 3 collinear"
    ),
    pytest.param(
        Polygon, {"vertices": [(0, 0), (2, 0), (2, 2), (1, 0), (0, 2)]}, r"vertices\n.*simple polygon"
    ),
    pytest.param(Polygon, {"vertices": [(0, 0), (1, 0)]}, r"vertices\n.*at least 3 items"),
    pytest.param(Circle, {"center": (0, 0), "radius": 0}, r"radius\n.*greater than 0"),
    pytest.param(Circle, {"center": (0, np.nan), "radius": 1}, r"center.1\n.*finite number"),
    pytest.param(Square, {"center": (0, 0), "half_side": -1}, r"half_side\n.*greater than 0"),
    pytest.param(Square, {"center": (0, 0), "side": 1}, r"half_side\n.*Field required"),
    pytest.param(
        Rectangle, {"xmin": 1, "xmax": 0, "ymin": 0, "ymax": 1}, r"xmin < xmax, got xmin=1.0, xmax=0.0"
    ),
    pytest.param(Workspace, {"ymin": 5, "ymax": 5}, r"ymin < ymax, got ymin=5.0, ymax=5.0"),
]


@pytest.mark.parametrize(("model", "fields", "match"), BAD_SHAPES)
def test_bad_shapes(model, fields: dict, match: str) -> None:
    with pytest.raises(ValidationError, match=match):
        model(**fields)


def test_bad_world() -> None:
    with pytest.raises(ValidationError, match=r"obstacles\.0\n.*does not match any of the expected tags"):
        World(workspace=Workspace(), obstacles=[{"kind": "triangle"}])
    with pytest.raises(ValidationError, match=r"workspace\n.*Field required"):
        World(obstacles=[])  # type: ignore[call-arg]
