"""Exact geometry of one shape: signed distance, containment, segment tests, inflation, text.

Conventions (the same everywhere in :mod:`audere.world`):

- a point *collides* with a shape when it lies strictly inside it; points on the boundary do not;
- a segment ``[p, q]`` is closed (its ends included) and collides when some point of it lies
  strictly inside the shape; a segment that only touches the boundary or runs along an edge does
  not collide;
- results are exact (closed forms, no sampling) up to floating-point rounding; boundary contact
  with axis-aligned edges and vertices is decided without rounding error.

Points are arrays of shape ``(N, 2)``; a single point of shape ``(2,)`` is accepted and gives a
result of shape ``()`` (a 0-d array: use ``float(...)`` or ``bool(...)``).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Literal, overload

import numpy as np
import shapely
from numpy.typing import ArrayLike, NDArray

from audere._arrays import as_float_array
from audere.errors import InvalidArgumentError
from audere.world import _kernels as kn
from audere.world._shapes import Circle, Obstacle, Polygon, Rectangle, Square, Workspace

__all__ = [
    "bounding_box",
    "contains",
    "describe_shape",
    "inflate",
    "segment_distance",
    "segments_intersect",
    "signed_distance",
]

F = NDArray[np.float64]
B = NDArray[np.bool_]
Shape = Circle | Square | Rectangle | Polygon
GroupKind = Literal["circle", "box", "polygon"]

_MITRE_LIMIT = 5.0
"""Mitre joins of an inflated polygon reach at most this many margins from the original vertex."""

_MIN_RELATIVE_MARGIN = 1e-12
"""Polygon margins below this fraction of the coordinates' magnitude are rounded up to it."""

_SHAPE_TYPES = (Circle, Square, Rectangle, Polygon)


# ------------------------------------------------------------------------------------- validation


def as_points(value: ArrayLike, *, name: str) -> tuple[F, bool]:
    """Validate points: ``(N, 2)`` or a single ``(2,)`` point, finite.

    Returns
    -------
    tuple
        The points as a float array of shape ``(N, 2)`` and whether a single point was given.
    """
    arr = as_float_array(value, name=name, finite=False)
    if arr.ndim == 1 and arr.shape[0] == 2:
        single = True
    elif arr.ndim == 2 and arr.shape[1] == 2:
        single = False
    else:
        raise InvalidArgumentError(f"{name} must have shape (n, 2) or (2,), got shape {tuple(arr.shape)}")
    if not np.all(np.isfinite(arr)):
        as_float_array(arr, name=name)  # raises with the position of the first bad entry
    return arr.reshape(-1, 2), single


def as_segments(p: ArrayLike, q: ArrayLike) -> tuple[F, F, bool]:
    """Validate segment ends ``p`` and ``q``: the same shape, ``(N, 2)`` or ``(2,)``, finite."""
    p_arr, p_single = as_points(p, name="p")
    q_arr, q_single = as_points(q, name="q")
    if p_arr.shape != q_arr.shape or p_single != q_single:
        raise InvalidArgumentError(
            "p and q must have the same shape (one segment per row), got shapes "
            f"{np.shape(p)} and {np.shape(q)}"
        )
    return p_arr, q_arr, p_single


def as_margin(margin: float) -> float:
    """Validate an inflation margin: a finite number >= 0."""
    if isinstance(margin, bool) or not isinstance(margin, int | float | np.integer | np.floating):
        raise InvalidArgumentError(f"margin must be a number >= 0, got {type(margin).__name__}: {margin!r}")
    value = float(margin)
    if not math.isfinite(value) or value < 0:
        raise InvalidArgumentError(f"margin must be a finite number >= 0, got {value}")
    return value


def as_shape(shape: object, *, name: str = "shape") -> Shape:
    """Check that ``shape`` is one of the obstacle shapes."""
    if not isinstance(shape, _SHAPE_TYPES):
        raise InvalidArgumentError(
            f"{name} must be a Circle, Square, Rectangle or Polygon, got {type(shape).__name__}: {shape!r}"
        )
    return shape


def finish(values: NDArray[np.generic], single: bool) -> NDArray[np.generic]:
    """Return ``values`` of shape ``(N,)``, or shape ``()`` when a single point was given."""
    return values.reshape(()) if single else values


# ---------------------------------------------------------------------------------------- packing

PointKernel = Callable[..., F]
SegmentKernel = Callable[..., F]
SegmentPredicate = Callable[..., B]

_SD: dict[GroupKind, PointKernel] = {"circle": kn.circle_sd, "box": kn.box_sd, "polygon": kn.polygon_point_sd}
_INTERSECT: dict[GroupKind, SegmentPredicate] = {
    "circle": kn.circle_segments_intersect,
    "box": kn.box_segments_intersect,
    "polygon": kn.polygon_segments_intersect,
}
_DISTANCE: dict[GroupKind, SegmentKernel] = {
    "circle": kn.circle_segment_distance,
    "box": kn.box_segment_distance,
    "polygon": kn.polygon_segment_distance,
}
_ENTRY: dict[GroupKind, SegmentKernel] = {
    "circle": kn.circle_entry,
    "box": kn.box_entry,
    "polygon": kn.polygon_entry,
}
_DEPTH: dict[GroupKind, SegmentKernel] = {
    "circle": kn.circle_segment_signed,
    "box": kn.box_segment_signed,
    "polygon": kn.polygon_segment_depth,
}

Index = NDArray[np.intp]


def xy(points: F) -> tuple[F, F]:
    """Split ``(N, 2)`` points into contiguous ``x`` and ``y`` arrays."""
    return np.ascontiguousarray(points[:, 0]), np.ascontiguousarray(points[:, 1])


@dataclass(frozen=True, eq=False)
class Group:
    """Shapes of one kind packed into arrays, with their positions among the obstacles.

    ``params`` are the kernel parameters of :mod:`audere.world._kernels`, each with a leading axis of
    length ``K``: ``(cx, cy, r)`` for circles, ``(x0, y0, x1, y1)`` for boxes (squares and
    rectangles), ``(ax, ay, bx, by)`` of shape ``(K, E)`` for polygons. ``bounds`` are the bounding
    boxes ``(x0, y0, x1, y1)``. Pairwise methods take member indices ``k`` aligned with their rows.

    Polygons cost more per pair, so their point queries first discard pairs using bounds: the signed
    distance to a polygon is at least the signed distance to its bounding box (the polygon lies in
    it) and at most the distance to its first vertex.
    """

    kind: GroupKind
    index: Index
    params: tuple[F, ...]
    bounds: tuple[F, F, F, F]

    def take(self, k: Index) -> tuple[F, ...]:
        """Parameters of members ``k (M,)``, each with leading axis ``M``."""
        return tuple(a[k] for a in self.params)

    def point_sd(self, x: F, y: F, k: Index) -> F:
        """Signed distances from points ``(M,)`` to members ``k (M,)``."""
        return _SD[self.kind](x, y, *self.take(k))

    def point_sd_min(self, x: F, y: F) -> F:
        """Least signed distance ``(N,)`` from each point to the members."""
        xc, yc = x[:, None], y[:, None]
        if self.kind != "polygon":
            return np.asarray(_SD[self.kind](xc, yc, *self.params).min(axis=1), dtype=np.float64)
        lower = kn.box_sd(xc, yc, *self.bounds)
        ax, ay = self.params[0][:, 0], self.params[1][:, 0]
        upper = np.hypot(xc - ax, yc - ay).min(axis=1)
        i, k = np.nonzero(lower <= upper[:, None])
        out = np.full(x.shape[0], np.inf)
        np.minimum.at(out, i, self.point_sd(x[i], y[i], k))
        return out

    def inside_pairs(self, x: F, y: F) -> tuple[Index, Index]:
        """(point, member) pairs where the point lies strictly inside the member."""
        x0, y0, x1, y1 = self.bounds
        xc, yc = x[:, None], y[:, None]
        i, k = np.nonzero((xc > x0) & (xc < x1) & (yc > y0) & (yc < y1))
        if self.kind == "box":
            return i, k  # strictly inside the bounding box is strictly inside the box
        hit = self.point_sd(x[i], y[i], k) < 0
        return i[hit], k[hit]

    def candidate_pairs(self, px: F, py: F, qx: F, qy: F) -> tuple[Index, Index]:
        """(segment, member) pairs whose closed bounding boxes overlap."""
        x0, y0, x1, y1 = self.bounds
        sx0, sx1 = np.minimum(px, qx)[:, None], np.maximum(px, qx)[:, None]
        sy0, sy1 = np.minimum(py, qy)[:, None], np.maximum(py, qy)[:, None]
        i, k = np.nonzero((sx1 >= x0) & (sx0 <= x1) & (sy1 >= y0) & (sy0 <= y1))
        return i, k

    def intersecting_pairs(self, px: F, py: F, qx: F, qy: F) -> tuple[Index, Index]:
        """(segment, member) pairs where the closed segment reaches the member's interior."""
        i, k = self.candidate_pairs(px, py, qx, qy)
        hit = _INTERSECT[self.kind](px[i], py[i], qx[i], qy[i], *self.take(k))
        return i[hit], k[hit]

    def entry(self, px: F, py: F, qx: F, qy: F, k: Index) -> F:
        """Entry parameters ``t`` of intersecting segments ``(M,)`` into members ``k (M,)``."""
        return _ENTRY[self.kind](px, py, qx, qy, *self.take(k))

    def depth(self, px: F, py: F, qx: F, qy: F, k: Index) -> F:
        """Least signed distance along intersecting segments ``(M,)`` in members ``k (M,)`` (negative)."""
        return _DEPTH[self.kind](px, py, qx, qy, *self.take(k))

    def segment_distance_below(self, px: F, py: F, qx: F, qy: F, bound: float) -> float:
        """Least distance from the segments to the members when below ``bound``, else ``bound``.

        Only pairs whose bounding boxes are at most ``bound`` apart are computed exactly.
        """
        x0, y0, x1, y1 = self.bounds
        gx = np.maximum(np.maximum(x0 - np.maximum(px, qx)[:, None], np.minimum(px, qx)[:, None] - x1), 0.0)
        gy = np.maximum(np.maximum(y0 - np.maximum(py, qy)[:, None], np.minimum(py, qy)[:, None] - y1), 0.0)
        i, k = np.nonzero(np.hypot(gx, gy) <= bound)
        if i.size == 0:
            return bound
        dist = _DISTANCE[self.kind](px[i], py[i], qx[i], qy[i], *self.take(k))
        return min(bound, float(np.min(dist)))


def pack(obstacles: Sequence[Shape]) -> tuple[Group, ...]:
    """Pack shapes into one :class:`Group` per kind present (circles, boxes, polygons)."""
    circles = [(i, o) for i, o in enumerate(obstacles) if isinstance(o, Circle)]
    boxes = [(i, o) for i, o in enumerate(obstacles) if isinstance(o, Square | Rectangle)]
    polygons = [(i, o) for i, o in enumerate(obstacles) if isinstance(o, Polygon)]
    groups: list[Group] = []
    if circles:
        c = np.array([(*o.center, o.radius) for _, o in circles], dtype=np.float64)
        cx, cy, r = (np.ascontiguousarray(c[:, j]) for j in range(3))
        bounds = (cx - r, cy - r, cx + r, cy + r)
        groups.append(Group("circle", np.array([i for i, _ in circles], dtype=np.intp), (cx, cy, r), bounds))
    if boxes:
        b = np.array([_box_bounds(o) for _, o in boxes], dtype=np.float64)
        x0, x1, y0, y1 = (np.ascontiguousarray(b[:, j]) for j in range(4))
        box_params = (x0, y0, x1, y1)
        groups.append(Group("box", np.array([i for i, _ in boxes], dtype=np.intp), box_params, box_params))
    if polygons:
        rings = [_ccw_ring(o) for _, o in polygons]
        n_vertices = max(len(r) for r in rings)
        a = np.empty((len(polygons), n_vertices, 2))
        for j, ring in enumerate(rings):
            a[j, : len(ring)] = ring
            a[j, len(ring) :] = ring[0]  # padding: copies of the first vertex
        b = np.empty_like(a)
        u = np.empty_like(a)
        for j, ring in enumerate(rings):
            b[j] = a[j, 0]
            u[j] = a[j, 0]
            b[j, : len(ring)] = np.roll(ring, -1, axis=0)
            u[j, : len(ring)] = np.roll(ring, 1, axis=0)
        ax, ay, bx, by, ux, uy = (np.ascontiguousarray(arr[..., j]) for arr in (a, b, u) for j in (0, 1))
        poly_bounds = (ax.min(axis=1), ay.min(axis=1), ax.max(axis=1), ay.max(axis=1))
        groups.append(
            Group(
                "polygon",
                np.array([i for i, _ in polygons], dtype=np.intp),
                (ax, ay, bx, by, ux, uy),
                poly_bounds,
            )
        )
    return tuple(groups)


def _ccw_ring(polygon: Polygon) -> F:
    """The polygon's vertices counter-clockwise, without repeated consecutive vertices."""
    v = np.array(polygon.vertices, dtype=np.float64)
    keep = np.any(v != np.roll(v, -1, axis=0), axis=1)
    v = v[keep]
    x, y = v[:, 0], v[:, 1]
    twice_area = float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))
    return v if twice_area > 0 else v[::-1].copy()


def _box_bounds(shape: Shape) -> tuple[float, float, float, float]:
    """``(xmin, xmax, ymin, ymax)`` of a square or rectangle."""
    if isinstance(shape, Square):
        (cx, cy), h = shape.center, shape.half_side
        return cx - h, cx + h, cy - h, cy + h
    if isinstance(shape, Rectangle):
        return shape.xmin, shape.xmax, shape.ymin, shape.ymax
    raise InvalidArgumentError(f"shape must be a Square or Rectangle, got {type(shape).__name__}")


# ------------------------------------------------------------------------------------ public API


def signed_distance(shape: Obstacle, points: ArrayLike) -> NDArray[np.float64]:
    """Euclidean signed distance from points to a shape (negative strictly inside).

    Parameters
    ----------
    shape
        A :class:`Circle`, :class:`Square`, :class:`Rectangle` or :class:`Polygon`.
    points
        Points, array of shape ``(N, 2)`` in metres, or one point of shape ``(2,)``.

    Returns
    -------
    numpy.ndarray
        Shape ``(N,)`` (``()`` for one point), metres: the distance to the boundary, with a minus
        sign for points strictly inside and 0 on the boundary.
    """
    (group,) = pack([as_shape(shape)])
    x, single = as_points(points, name="points")
    return np.asarray(finish(_SD[group.kind](*xy(x), *group.params), single), dtype=np.float64)


def contains(shape: Obstacle, points: ArrayLike) -> NDArray[np.bool_]:
    """Which points lie strictly inside a shape (points on the boundary do not).

    Parameters
    ----------
    shape
        A :class:`Circle`, :class:`Square`, :class:`Rectangle` or :class:`Polygon`.
    points
        Points, array of shape ``(N, 2)`` in metres, or one point of shape ``(2,)``.

    Returns
    -------
    numpy.ndarray
        Booleans of shape ``(N,)`` (``()`` for one point); equal to ``signed_distance(shape, points) < 0``.
    """
    (group,) = pack([as_shape(shape)])
    x, single = as_points(points, name="points")
    return np.asarray(finish(_SD[group.kind](*xy(x), *group.params) < 0, single), dtype=np.bool_)


def segments_intersect(shape: Obstacle, p: ArrayLike, q: ArrayLike) -> NDArray[np.bool_]:
    """Which closed segments ``[p, q]`` reach the interior of a shape (exact test).

    A segment that only touches the boundary, or runs along an edge, does not intersect.

    Parameters
    ----------
    shape
        A :class:`Circle`, :class:`Square`, :class:`Rectangle` or :class:`Polygon`.
    p
        Segment starts, array of shape ``(N, 2)`` in metres, or one point of shape ``(2,)``.
    q
        Segment ends, the same shape as ``p``.

    Returns
    -------
    numpy.ndarray
        Booleans of shape ``(N,)`` (``()`` for one segment).
    """
    shape = as_shape(shape)
    p_arr, q_arr, single = as_segments(p, q)
    (group,) = pack([shape])
    out = _INTERSECT[group.kind](*xy(p_arr), *xy(q_arr), *group.params)
    return np.asarray(finish(np.asarray(out, dtype=bool), single), dtype=np.bool_)


def segment_distance(shape: Obstacle, p: ArrayLike, q: ArrayLike) -> NDArray[np.float64]:
    """Exact minimum distance from closed segments ``[p, q]`` to a shape (0 when they meet).

    Parameters
    ----------
    shape
        A :class:`Circle`, :class:`Square`, :class:`Rectangle` or :class:`Polygon`.
    p
        Segment starts, array of shape ``(N, 2)`` in metres, or one point of shape ``(2,)``.
    q
        Segment ends, the same shape as ``p``.

    Returns
    -------
    numpy.ndarray
        Distances of shape ``(N,)`` (``()`` for one segment), metres, ``>= 0``. Zero exactly when the
        segment touches or enters the shape.
    """
    shape = as_shape(shape)
    p_arr, q_arr, single = as_segments(p, q)
    (group,) = pack([shape])
    out = _DISTANCE[group.kind](*xy(p_arr), *xy(q_arr), *group.params)
    return np.asarray(finish(np.asarray(out, dtype=np.float64), single), dtype=np.float64)


@overload
def inflate(shape: Circle, margin: float) -> Circle: ...
@overload
def inflate(shape: Square, margin: float) -> Square: ...
@overload
def inflate(shape: Rectangle, margin: float) -> Rectangle: ...
@overload
def inflate(shape: Polygon, margin: float) -> Polygon: ...
@overload
def inflate(shape: Shape, margin: float) -> Shape: ...
def inflate(shape: Shape, margin: float) -> Shape:
    """Grow a shape by a margin, conservatively: the result contains every point within ``margin``.

    - circle: radius ``+ margin`` (exact);
    - square: half side ``+ margin`` (a square again, so its corners reach ``margin * sqrt(2)``);
    - rectangle: every side moved out by ``margin`` (corners as for the square);
    - polygon: mitred offset, every edge moved out by ``margin`` and neighbouring edges extended until
      they meet; at very sharp vertices the spike is cut square at ``5 * margin`` from the vertex.
      Notches narrower than ``2 * margin`` fill up, holes that would appear are filled, and a margin
      below ``1e-12`` times the largest coordinate is rounded up to that.

    Parameters
    ----------
    shape
        A :class:`Circle`, :class:`Square`, :class:`Rectangle` or :class:`Polygon`.
    margin
        Distance to grow by, metres, ``>= 0``.

    Returns
    -------
    Circle | Square | Rectangle | Polygon
        A shape of the same kind; ``shape`` itself when ``margin == 0``.
    """
    shape = as_shape(shape)
    m = as_margin(margin)
    if m == 0:
        return shape
    if isinstance(shape, Circle):
        return Circle(center=shape.center, radius=shape.radius + m)
    if isinstance(shape, Square):
        return Square(center=shape.center, half_side=shape.half_side + m)
    if isinstance(shape, Rectangle):
        return Rectangle(xmin=shape.xmin - m, xmax=shape.xmax + m, ymin=shape.ymin - m, ymax=shape.ymax + m)
    original = shapely.Polygon(shape.vertices)
    # The offset is computed in floating point: margins too small to resolve are rounded up.
    floor = _MIN_RELATIVE_MARGIN * max(1.0, float(np.max(np.abs(shapely.get_coordinates(original)))))
    grown = shapely.buffer(original, max(m, floor), join_style="mitre", mitre_limit=_MITRE_LIMIT)
    coords = np.asarray(grown.exterior.coords)[:-1]
    return Polygon(vertices=tuple((float(x), float(y)) for x, y in coords))


def bounding_box(shape: Obstacle | Workspace) -> Rectangle:
    """The smallest axis-aligned rectangle that contains a shape.

    Parameters
    ----------
    shape
        A :class:`Circle`, :class:`Square`, :class:`Rectangle`, :class:`Polygon` or :class:`Workspace`.

    Returns
    -------
    Rectangle
        The bounds ``xmin, xmax, ymin, ymax`` in metres.
    """
    if isinstance(shape, Workspace | Rectangle):
        return Rectangle(xmin=shape.xmin, xmax=shape.xmax, ymin=shape.ymin, ymax=shape.ymax)
    if isinstance(shape, Circle):
        (cx, cy), r = shape.center, shape.radius
        return Rectangle(xmin=cx - r, xmax=cx + r, ymin=cy - r, ymax=cy + r)
    if isinstance(shape, Square):
        xmin, xmax, ymin, ymax = _box_bounds(shape)
        return Rectangle(xmin=xmin, xmax=xmax, ymin=ymin, ymax=ymax)
    shape = as_shape(shape)
    v = np.array(shape.vertices, dtype=np.float64)  # type: ignore[union-attr]
    return Rectangle(
        xmin=float(v[:, 0].min()),
        xmax=float(v[:, 0].max()),
        ymin=float(v[:, 1].min()),
        ymax=float(v[:, 1].max()),
    )


def format_number(value: float, decimals: int = 2) -> str:
    """``value`` with ``decimals`` decimals, never ``-0.00``."""
    text = f"{value:.{decimals}f}"
    return text[1:] if text.startswith("-") and float(text) == 0 else text


def format_point(point: tuple[float, float] | Sequence[float], decimals: int = 2) -> str:
    """``(x, y)`` with ``decimals`` decimals."""
    return f"({format_number(point[0], decimals)}, {format_number(point[1], decimals)})"


def _bounds_text(shape: Rectangle | Workspace, n: int) -> str:
    return (
        f"x in [{format_number(shape.xmin, n)}, {format_number(shape.xmax, n)}], "
        f"y in [{format_number(shape.ymin, n)}, {format_number(shape.ymax, n)}]"
    )


def as_decimals(decimals: int) -> int:
    """Validate a number of decimals: an integer from 0 to 12."""
    if isinstance(decimals, bool) or not isinstance(decimals, int | np.integer) or not 0 <= decimals <= 12:
        raise InvalidArgumentError(f"decimals must be an integer from 0 to 12, got {decimals!r}")
    return int(decimals)


def describe_shape(shape: Obstacle | Workspace, *, decimals: int = 2) -> str:
    """A short exact description of a shape, numbers rounded to ``decimals`` decimals.

    Examples: ``"circle centred at (3.20, 4.10), radius 1.25"``, ``"square centred at (5.00, 5.00),
    half side 0.50 (side length 1.00)"``, ``"rectangle x in [1.00, 2.00], y in [3.00, 4.50]"``,
    ``"polygon with vertices (0.00, 0.00), (2.00, 0.00), (1.00, 1.50)"``,
    ``"workspace x in [0.00, 10.00], y in [0.00, 10.00]"``. Shapes whose numbers have at most
    ``decimals`` decimals are described exactly.

    Parameters
    ----------
    shape
        A :class:`Circle`, :class:`Square`, :class:`Rectangle`, :class:`Polygon` or :class:`Workspace`.
    decimals
        Decimals of every number, 0 to 12.

    Returns
    -------
    str
        One line, no trailing period.
    """
    n = as_decimals(decimals)
    if isinstance(shape, Workspace):
        return f"workspace {_bounds_text(shape, n)}"
    shape = as_shape(shape)
    if isinstance(shape, Circle):
        return f"circle centred at {format_point(shape.center, n)}, radius {format_number(shape.radius, n)}"
    if isinstance(shape, Square):
        half, side = format_number(shape.half_side, n), format_number(2 * shape.half_side, n)
        return f"square centred at {format_point(shape.center, n)}, half side {half} (side length {side})"
    if isinstance(shape, Rectangle):
        return f"rectangle {_bounds_text(shape, n)}"
    return "polygon with vertices " + ", ".join(format_point(v, n) for v in shape.vertices)
