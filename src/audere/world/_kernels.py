"""Vectorized exact geometry kernels on packed shape parameters (private).

Coordinates are passed as separate ``x`` and ``y`` arrays (numpy loops over a trailing axis of
size 2 are slow when broadcasting). Every kernel broadcasts with numpy rules, so the same kernel
serves one shape against ``N`` points (parameters of shape ``(1,)``), ``N`` points against ``K``
shapes of one kind (points ``(N, 1)``, parameters ``(K,)``) and gathered (segment, shape) pairs
(both ``(M,)``).

Shape parameters (``P`` below):

- circle: ``cx, cy, r``;
- box (squares and rectangles): ``x0, y0, x1, y1`` (``xmin, ymin, xmax, ymax``);
- polygon (counter-clockwise): vertices ``(ax, ay)``, the next vertices ``(bx, by)`` (so the edges
  run from ``a`` to ``b``) and the previous vertices ``(ux, uy)``, each with a trailing axis
  ``(..., E)``; a polygon with fewer than ``E`` vertices is padded with copies of its first vertex
  (zero-length edges, flat angles), which change no result below.

Point kernels are called as ``kernel(x, y, *P)``, segment kernels as
``kernel(px, py, qx, qy, *P)`` for the closed segment from ``(px, py)`` to ``(qx, qy)``.

Exactness: every formula is a closed form (no sampling) except :func:`polygon_segment_depth`.
Every yes/no answer (inside, on the boundary, outside; segment reaches the interior, touches,
misses) comes from coordinate comparisons and the robust predicates of
:mod:`audere.world._predicates`, so it is exact for the given floating-point coordinates. Distances
are computed in floating point (a few ulps of error) and carry the exact sign: 0 exactly on the
boundary or on contact, never 0 otherwise.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from audere.world._predicates import orient, point_circle_sign, segment_circle_sign, with_sign

F = NDArray[np.float64]
B = NDArray[np.bool_]

TINY = float(np.finfo(np.float64).tiny)
"""Smallest positive normal float: a distance that rounding made vanish but that is not zero."""

POLYGON_DEPTH_SAMPLES = 65
"""Evenly spaced samples per segment used to approximate a polygon's penetration depth."""

# Pairs (i, j) of the four linear functions bounding a box, used by ``box_segment_signed``.
_PAIRS = ((0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3))


def safe_div(num: F, den: F) -> F:
    """``num / den`` where ``den != 0``, else 0 (no floating-point warnings).

    A subnormal ``den`` may overflow the quotient to infinity; callers clip or ignore such values.
    """
    ok = den != 0
    with np.errstate(over="ignore"):
        return np.asarray(np.where(ok, num / np.where(ok, den, 1.0), 0.0))


def point_segment_distance(x: F, y: F, ax: F, ay: F, bx: F, by: F) -> F:
    """Distance from points to closed segments ``[a, b]`` (zero-length segments allowed)."""
    ex = bx - ax
    ey = by - ay
    wx = x - ax
    wy = y - ay
    ee = ex * ex + ey * ey
    t = safe_div(wx * ex + wy * ey, ee)
    interior = (t > 0) & (t < 1)
    # Perpendicular distance through the cross product: exactly 0 on an axis-aligned edge.
    perp = np.abs(ex * wy - ey * wx) / np.sqrt(np.where(ee > 0, ee, 1.0))
    ends = np.minimum(np.hypot(wx, wy), np.hypot(x - bx, y - by))
    return np.asarray(np.where(interior, perp, ends))


def segments_meet(px: F, py: F, qx: F, qy: F, ax: F, ay: F, bx: F, by: F) -> B:
    """Do closed segments ``[p, q]`` and ``[a, b]`` share a point (orientation test)."""
    s1 = orient(px, py, qx, qy, ax, ay)
    s2 = orient(px, py, qx, qy, bx, by)
    s3 = orient(ax, ay, bx, by, px, py)
    s4 = orient(ax, ay, bx, by, qx, qy)
    boxes = (
        (np.minimum(px, qx) <= np.maximum(ax, bx))
        & (np.minimum(ax, bx) <= np.maximum(px, qx))
        & (np.minimum(py, qy) <= np.maximum(ay, by))
        & (np.minimum(ay, by) <= np.maximum(py, qy))
    )
    return np.asarray((s1 * s2 <= 0) & (s3 * s4 <= 0) & boxes)


def segment_segment_distance(px: F, py: F, qx: F, qy: F, ax: F, ay: F, bx: F, by: F) -> F:
    """Exact distance between closed segments ``[p, q]`` and ``[a, b]``."""
    m = np.minimum(
        np.minimum(
            point_segment_distance(px, py, ax, ay, bx, by), point_segment_distance(qx, qy, ax, ay, bx, by)
        ),
        np.minimum(
            point_segment_distance(ax, ay, px, py, qx, qy), point_segment_distance(bx, by, px, py, qx, qy)
        ),
    )
    return np.asarray(np.where(segments_meet(px, py, qx, qy, ax, ay, bx, by), 0.0, np.maximum(m, TINY)))


def _center_distance(px: F, py: F, qx: F, qy: F, cx: F, cy: F) -> F:
    return point_segment_distance(cx, cy, px, py, qx, qy)


# --------------------------------------------------------------------------------------------- circle


def circle_sd(x: F, y: F, cx: F, cy: F, r: F) -> F:
    """Signed distance from points to discs."""
    approx = np.hypot(x - cx, y - cy) - r
    return with_sign(approx, point_circle_sign(x, y, cx, cy, r, approx))


def _circle_segment(px: F, py: F, qx: F, qy: F, cx: F, cy: F, r: F) -> tuple[F, NDArray[np.int8]]:
    """``dist(c, [p, q]) - r`` and its exact sign."""
    approx = _center_distance(px, py, qx, qy, cx, cy) - r
    return approx, segment_circle_sign(px, py, qx, qy, cx, cy, r, approx)


def circle_segments_intersect(px: F, py: F, qx: F, qy: F, cx: F, cy: F, r: F) -> B:
    """Does each closed segment reach the open disc."""
    return np.asarray(_circle_segment(px, py, qx, qy, cx, cy, r)[1] < 0)


def circle_segment_distance(px: F, py: F, qx: F, qy: F, cx: F, cy: F, r: F) -> F:
    """Distance from each closed segment to the closed disc (0 when they meet)."""
    approx, sign = _circle_segment(px, py, qx, qy, cx, cy, r)
    return with_sign(approx, np.maximum(sign, 0))


def circle_segment_signed(px: F, py: F, qx: F, qy: F, cx: F, cy: F, r: F) -> F:
    """Least signed distance to the disc along each segment (exact)."""
    approx, sign = _circle_segment(px, py, qx, qy, cx, cy, r)
    return with_sign(approx, sign)


def circle_entry(px: F, py: F, qx: F, qy: F, cx: F, cy: F, r: F) -> F:
    """Parameter ``t`` in [0, 1] where ``p + t (q - p)`` first enters the disc (intersecting segments)."""
    dx = qx - px
    dy = qy - py
    dd = dx * dx + dy * dy
    wx = cx - px
    wy = cy - py
    t0 = safe_div(wx * dx + wy * dy, dd)
    h2 = r * r - safe_div((dx * wy - dy * wx) ** 2, dd)
    half = np.sqrt(safe_div(np.maximum(h2, 0.0), dd))
    return np.asarray(np.clip(t0 - half, 0.0, 1.0))


# ------------------------------------------------------------------------------------------------ box


def box_sd(x: F, y: F, x0: F, y0: F, x1: F, y1: F) -> F:
    """Signed distance from points to axis-aligned boxes."""
    ex = np.maximum(x0 - x, x - x1)
    ey = np.maximum(y0 - y, y - y1)
    outside = np.hypot(np.maximum(ex, 0.0), np.maximum(ey, 0.0))
    inside = np.minimum(np.maximum(ex, ey), 0.0)
    return np.asarray(outside + inside)


def _corners(x0: F, y0: F, x1: F, y1: F) -> tuple[tuple[F, F], ...]:
    return ((x0, y0), (x1, y0), (x1, y1), (x0, y1))


def _box_relation(px: F, py: F, qx: F, qy: F, x0: F, y0: F, x1: F, y1: F, *, strict: bool) -> B:
    """Separating-axis test of closed segments against open (``strict``) or closed boxes.

    The edge directions of the Minkowski difference of a box and a segment are x, y and the
    segment's direction; the segment misses the open box exactly when the projections on one of
    the three normals overlap in at most a point. Along the segment's normal this is an
    orientation test of the four corners against the segment.
    """
    dx = qx - px
    dy = qy - py
    o = [orient(px, py, qx, qy, cx, cy) for cx, cy in _corners(x0, y0, x1, y1)]
    omax = np.maximum(np.maximum(o[0], o[1]), np.maximum(o[2], o[3]))
    omin = np.minimum(np.minimum(o[0], o[1]), np.minimum(o[2], o[3]))
    sx0, sx1 = np.minimum(px, qx), np.maximum(px, qx)
    sy0, sy1 = np.minimum(py, qy), np.maximum(py, qy)
    if strict:
        axes = (sx1 > x0) & (sx0 < x1) & (sy1 > y0) & (sy0 < y1)
        normal = ((omax > 0) & (omin < 0)) | ((dx == 0) & (dy == 0))
    else:
        axes = (sx1 >= x0) & (sx0 <= x1) & (sy1 >= y0) & (sy0 <= y1)
        normal = (omax >= 0) & (omin <= 0)
    return np.asarray(axes & normal)


def box_segments_intersect(px: F, py: F, qx: F, qy: F, x0: F, y0: F, x1: F, y1: F) -> B:
    """Does each closed segment reach the open box."""
    return _box_relation(px, py, qx, qy, x0, y0, x1, y1, strict=True)


def box_segment_distance(px: F, py: F, qx: F, qy: F, x0: F, y0: F, x1: F, y1: F) -> F:
    """Distance from each closed segment to the closed box (0 when they meet).

    Two disjoint convex polygons are closest at a vertex of one and an edge of the other, so the
    distance is the least of the ends' distances to the box and the corners' distances to the
    segment.
    """
    touch = _box_relation(px, py, qx, qy, x0, y0, x1, y1, strict=False)
    best = np.maximum(np.minimum(box_sd(px, py, x0, y0, x1, y1), box_sd(qx, qy, x0, y0, x1, y1)), 0.0)
    for cx, cy in _corners(x0, y0, x1, y1):
        best = np.minimum(best, point_segment_distance(cx, cy, px, py, qx, qy))
    return np.asarray(np.where(touch, 0.0, np.maximum(best, TINY)))


def box_segment_signed(px: F, py: F, qx: F, qy: F, x0: F, y0: F, x1: F, y1: F) -> F:
    """Least signed distance to the box along each segment (exact).

    Inside the box the signed distance is the largest of four linear functions ``a_i + b_i t`` of
    the segment parameter; its minimum over ``[0, 1]`` lies at an end or where two of them cross
    (8 candidates). Where the segment does not reach the interior the result is the segment
    distance.
    """
    dx = qx - px
    dy = qy - py
    a = [x0 - px, px - x1, y0 - py, py - y1]
    b = [-dx, dx, -dy, dy]
    candidates: list[F | float] = [1.0]
    candidates.extend(np.clip(safe_div(a[j] - a[i], b[i] - b[j]), 0.0, 1.0) for i, j in _PAIRS)
    best = np.maximum(np.maximum(a[0], a[1]), np.maximum(a[2], a[3]))  # t = 0
    for t in candidates:
        g = np.maximum(
            np.maximum(a[0] + b[0] * t, a[1] + b[1] * t), np.maximum(a[2] + b[2] * t, a[3] + b[3] * t)
        )
        best = np.minimum(best, g)
    inside = box_segments_intersect(px, py, qx, qy, x0, y0, x1, y1)
    outside = box_segment_distance(px, py, qx, qy, x0, y0, x1, y1)
    return np.asarray(np.where(inside, np.minimum(best, -TINY), outside))


def box_entry(px: F, py: F, qx: F, qy: F, x0: F, y0: F, x1: F, y1: F) -> F:
    """Parameter ``t`` in [0, 1] where each segment first enters its box (Liang-Barsky clipping)."""
    dx = qx - px
    dy = qy - py
    tx = np.where(dx != 0, np.minimum(safe_div(x0 - px, dx), safe_div(x1 - px, dx)), -np.inf)
    ty = np.where(dy != 0, np.minimum(safe_div(y0 - py, dy), safe_div(y1 - py, dy)), -np.inf)
    return np.asarray(np.clip(np.maximum(tx, ty), 0.0, 1.0))


# -------------------------------------------------------------------------------------------- polygon


def polygon_sd(x: F, y: F, ax: F, ay: F, bx: F, by: F) -> F:
    """Signed distance from points to simple polygons: minus the boundary distance strictly inside.

    Inside/outside by the winding number, on the boundary when the point lies on an edge; both
    decided with exact orientation signs.
    """
    xe = x[..., None]
    ye = y[..., None]
    o = orient(ax, ay, bx, by, xe, ye)
    up = (ay <= ye) & (by > ye) & (o > 0)
    down = (by <= ye) & (ay > ye) & (o < 0)
    winding = up.sum(axis=-1) != down.sum(axis=-1)
    on_edge = (
        (o == 0)
        & (np.minimum(ax, bx) <= xe)
        & (xe <= np.maximum(ax, bx))
        & (np.minimum(ay, by) <= ye)
        & (ye <= np.maximum(ay, by))
    )
    sign = np.where(on_edge.any(axis=-1), 0, np.where(winding, -1, 1)).astype(np.int8)
    dist = point_segment_distance(xe, ye, ax, ay, bx, by).min(axis=-1)
    return with_sign(dist, sign)


def polygon_pieces(px: F, py: F, qx: F, qy: F, ax: F, ay: F, bx: F, by: F) -> tuple[F, B]:
    """Split each segment where it may meet the boundary; classify each piece by its midpoint.

    Breakpoints are the segment's ends, its crossings with every edge's line and the projections of
    every vertex, sorted. Between consecutive breakpoints the open piece meets no edge, so it lies
    wholly inside or wholly outside and its midpoint decides (up to rounding of the midpoint, which
    matters for pieces along an edge: :func:`polygon_events` is the exact test). Used for the depth
    candidates.

    Returns
    -------
    tuple
        ``t`` of shape ``(..., 2E + 2)`` (sorted breakpoints) and ``inside`` of shape
        ``(..., 2E + 1)``: whether the midpoint of piece ``k`` (from ``t[k]`` to ``t[k + 1]``) lies
        strictly inside the polygon.
    """
    dx = (qx - px)[..., None]
    dy = (qy - py)[..., None]
    wx = ax - px[..., None]
    wy = ay - py[..., None]
    ex = bx - ax
    ey = by - ay
    t_cross = safe_div(wx * ey - wy * ex, dx * ey - dy * ex)
    t_vertex = safe_div(wx * dx + wy * dy, dx * dx + dy * dy)
    t_cross, t_vertex = np.broadcast_arrays(t_cross, t_vertex)
    ends = np.broadcast_to(np.array([0.0, 1.0]), (*t_cross.shape[:-1], 2))
    t = np.sort(np.clip(np.concatenate([ends, t_cross, t_vertex], axis=-1), 0.0, 1.0), axis=-1)
    mid = 0.5 * (t[..., :-1] + t[..., 1:])
    inside = _polygon_sd_along(px, py, dx, dy, mid, ax, ay, bx, by) < 0
    return t, np.asarray(inside)


def _polygon_sd_along(px: F, py: F, dx: F, dy: F, s: F, ax: F, ay: F, bx: F, by: F) -> F:
    """Signed distances ``(..., S)`` at parameters ``s (..., S)`` along segments to their polygons."""
    x = px[..., None] + s * dx
    y = py[..., None] + s * dy
    e = (..., None, slice(None))
    return polygon_sd(x, y, ax[e], ay[e], bx[e], by[e])


def polygon_events(px: F, py: F, qx: F, qy: F, ax: F, ay: F, bx: F, by: F, ux: F, uy: F) -> tuple[B, F]:
    """Does each closed segment reach the open polygon, and where does it first enter.

    Only orientation tests and comparisons on the input coordinates decide (no derived points). For
    a counter-clockwise polygon, with vertex ``a``, next vertex ``b`` and previous vertex ``u``, the
    segment reaches the interior exactly when one of these holds:

    - an end lies strictly inside;
    - it crosses an edge properly (both ends strictly on either side of the edge's line, both edge
      ends strictly on either side of the segment's line);
    - it passes through or starts/ends at a vertex, heading (forwards or backwards) strictly into
      the interior angle at that vertex;
    - an end lies inside an edge (not at a vertex) and the segment heads into the interior side.

    The first entry is the least parameter of the events that head forwards into the interior.

    Returns
    -------
    tuple
        ``hit (...)`` and ``entry (...)`` (the parameter ``t`` in [0, 1]; 1 where there is no hit).
    """
    e = (..., None)
    p_x, p_y, q_x, q_y = px[e], py[e], qx[e], qy[e]
    dx = q_x - p_x
    dy = q_y - p_y
    ex = bx - ax
    ey = by - ay
    oa = orient(p_x, p_y, q_x, q_y, ax, ay)  # vertices against the segment's line
    ob = orient(p_x, p_y, q_x, q_y, bx, by)
    ou = orient(p_x, p_y, q_x, q_y, ux, uy)
    op = orient(ax, ay, bx, by, p_x, p_y)  # segment ends against the edge's line (> 0: interior side)
    oq = orient(ax, ay, bx, by, q_x, q_y)

    proper = (oa * ob < 0) & (op * oq < 0)
    t_cross = safe_div((ax - p_x) * ey - (ay - p_y) * ex, dx * ey - dy * ex)

    on_segment = (
        (oa == 0)
        & ((dx != 0) | (dy != 0))
        & (np.minimum(p_x, q_x) <= ax)
        & (ax <= np.maximum(p_x, q_x))
        & (np.minimum(p_y, q_y) <= ay)
        & (ay <= np.maximum(p_y, q_y))
    )
    # Heading r = +-(q - p) from a vertex a on the segment lies strictly inside the interior angle
    # when it is left of the next edge (b right of the segment's line, for r = q - p) and right of
    # the previous edge reversed (u left of it); both at a convex vertex, either at a reflex one.
    convex = orient(ux, uy, ax, ay, bx, by) >= 0
    forward_ok = np.where(convex, (ob < 0) & (ou > 0), (ob < 0) | (ou > 0))
    backward_ok = np.where(convex, (ob > 0) & (ou < 0), (ob > 0) | (ou < 0))
    at_q = (ax == q_x) & (ay == q_y)
    at_p = (ax == p_x) & (ay == p_y)
    forward = on_segment & ~at_q & forward_ok
    backward = on_segment & ~at_p & backward_ok
    t_vertex = safe_div((ax - p_x) * dx + (ay - p_y) * dy, dx * dx + dy * dy)

    def inside_edge(x: F, y: F, o: NDArray[np.int8]) -> B:
        """On the edge's line, in its closed bounding box, not at either end."""
        return np.asarray(
            (o == 0)
            & (np.minimum(ax, bx) <= x)
            & (x <= np.maximum(ax, bx))
            & (np.minimum(ay, by) <= y)
            & (y <= np.maximum(ay, by))
            & ((x != ax) | (y != ay))
            & ((x != bx) | (y != by))
        )

    p_edge = inside_edge(p_x, p_y, op) & (oq > 0)
    q_edge = inside_edge(q_x, q_y, oq) & (op > 0)

    p_in = polygon_sd(px, py, ax, ay, bx, by) < 0
    q_in = polygon_sd(qx, qy, ax, ay, bx, by) < 0
    hit = p_in | q_in | np.any(proper | forward | backward | p_edge | q_edge, axis=-1)

    t = np.where(proper & (oq > 0), t_cross, np.inf)
    t = np.where(forward, np.minimum(t, t_vertex), t)
    t = np.where(p_edge, 0.0, t)
    entry = np.where(p_in, 0.0, np.clip(t.min(axis=-1), 0.0, 1.0))
    return np.asarray(hit), np.asarray(entry)


def polygon_point_sd(x: F, y: F, ax: F, ay: F, bx: F, by: F, ux: F, uy: F) -> F:
    """:func:`polygon_sd` with the packed polygon parameters (previous vertices unused)."""
    return polygon_sd(x, y, ax, ay, bx, by)


def polygon_segments_intersect(px: F, py: F, qx: F, qy: F, ax: F, ay: F, bx: F, by: F, ux: F, uy: F) -> B:
    """Does each closed segment reach the open polygon (see :func:`polygon_events`)."""
    return polygon_events(px, py, qx, qy, ax, ay, bx, by, ux, uy)[0]


def polygon_entry(px: F, py: F, qx: F, qy: F, ax: F, ay: F, bx: F, by: F, ux: F, uy: F) -> F:
    """Parameter ``t`` in [0, 1] where each segment first enters its polygon (intersecting segments)."""
    return polygon_events(px, py, qx, qy, ax, ay, bx, by, ux, uy)[1]


def polygon_segment_distance(px: F, py: F, qx: F, qy: F, ax: F, ay: F, bx: F, by: F, ux: F, uy: F) -> F:
    """Distance from each closed segment to the closed polygon (0 when they meet)."""
    e = (..., None)
    edges = segment_segment_distance(px[e], py[e], qx[e], qy[e], ax, ay, bx, by).min(axis=-1)
    return np.asarray(np.where(polygon_sd(px, py, ax, ay, bx, by) < 0, 0.0, edges))


def polygon_segment_depth(px: F, py: F, qx: F, qy: F, ax: F, ay: F, bx: F, by: F, ux: F, uy: F) -> F:
    """Approximate least signed distance to the polygon along each intersecting segment.

    The signed distance is evaluated at :data:`POLYGON_DEPTH_SAMPLES` evenly spaced points and at
    the midpoints of the pieces found by :func:`polygon_pieces`; as it is 1-Lipschitz, the result is
    at most ``length / (2 * (POLYGON_DEPTH_SAMPLES - 1))`` above the exact minimum, and it is
    negative whenever the segment reaches the interior.
    """
    t, _ = polygon_pieces(px, py, qx, qy, ax, ay, bx, by)
    mid = 0.5 * (t[..., :-1] + t[..., 1:])
    uniform = np.broadcast_to(
        np.linspace(0.0, 1.0, POLYGON_DEPTH_SAMPLES), (*mid.shape[:-1], POLYGON_DEPTH_SAMPLES)
    )
    s = np.concatenate([uniform, mid], axis=-1)
    dx = (qx - px)[..., None]
    dy = (qy - py)[..., None]
    depth = _polygon_sd_along(px, py, dx, dy, s, ax, ay, bx, by).min(axis=-1)
    # An interior reached only between samples: report the smallest negative number, not >= 0.
    return np.asarray(np.where(depth < 0, depth, -TINY))
