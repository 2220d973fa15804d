"""Independent references for the world tests: shapely versions of our shapes and random shape generators.

Circles become shapely polygons with 1024 vertices (inscribed), so a shapely answer about a circle
is only trusted where the point or segment is farther than :func:`circle_tolerance` from the circle.
"""

from __future__ import annotations

import numpy as np
import shapely
from numpy.typing import NDArray

from audere.world import Circle, Obstacle, Polygon, Rectangle, Square

QUAD_SEGS = 256
"""Segments per quarter circle of the shapely circles."""


def circle_tolerance(radius: float) -> float:
    """Largest gap between a circle and its shapely polygon (plus rounding)."""
    return radius * (1.0 - np.cos(np.pi / (4 * QUAD_SEGS))) + 1e-9


def tolerance(shape: Obstacle) -> float:
    """How far shapely's version of ``shape`` may lie from the exact one."""
    return circle_tolerance(shape.radius) if isinstance(shape, Circle) else 1e-9


def to_shapely(shape: Obstacle) -> shapely.Polygon:
    """The shape as a shapely polygon (circles approximated, see :data:`QUAD_SEGS`)."""
    if isinstance(shape, Circle):
        return shapely.Point(shape.center).buffer(shape.radius, quad_segs=QUAD_SEGS)
    if isinstance(shape, Square):
        (cx, cy), h = shape.center, shape.half_side
        return shapely.box(cx - h, cy - h, cx + h, cy + h)
    if isinstance(shape, Rectangle):
        return shapely.box(shape.xmin, shape.ymin, shape.xmax, shape.ymax)
    return shapely.Polygon(shape.vertices)


def ref_signed_distance(shape: Obstacle, points: NDArray[np.float64]) -> NDArray[np.float64]:
    """Signed distance by shapely: distance to the shape outside, minus distance to its boundary inside."""
    geom = to_shapely(shape)
    pts = shapely.points(points)
    inside = shapely.contains(geom, pts)
    return np.where(inside, -shapely.distance(geom.exterior, pts), shapely.distance(geom, pts))


def lines(p: NDArray[np.float64], q: NDArray[np.float64]) -> NDArray[np.object_]:
    """Shapely line strings for segments (a zero-length segment becomes a point)."""
    out = np.empty(len(p), dtype=object)
    for i, (a, b) in enumerate(zip(p, q, strict=True)):
        out[i] = shapely.Point(a) if np.array_equal(a, b) else shapely.LineString([a, b])
    return out


def ref_segments_intersect(
    shape: Obstacle, p: NDArray[np.float64], q: NDArray[np.float64]
) -> NDArray[np.bool_]:
    """Does the closed segment meet the open interior: DE-9IM interior/interior or boundary/interior."""
    geom = to_shapely(shape)
    segs = lines(p, q)
    return np.asarray(
        shapely.relate_pattern(segs, geom, "T********") | shapely.relate_pattern(segs, geom, "***T*****")
    )


def ref_segment_distance(
    shape: Obstacle, p: NDArray[np.float64], q: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Distance between the closed segment and the closed shape by shapely."""
    return np.asarray(shapely.distance(lines(p, q), to_shapely(shape)))


def ref_touches_or_intersects(
    shape: Obstacle, p: NDArray[np.float64], q: NDArray[np.float64]
) -> NDArray[np.bool_]:
    """Does the closed segment meet the closed shape."""
    return np.asarray(shapely.intersects(lines(p, q), to_shapely(shape)))


# ------------------------------------------------------------------------------------------ generators


def random_polygon(rng: np.random.Generator, *, grid: bool = False) -> Polygon:
    """A random star-shaped (so simple) polygon, often non-convex; on an integer grid if ``grid``."""
    while True:
        n = int(rng.integers(3, 11))
        angles = np.sort(rng.uniform(0, 2 * np.pi, n))
        if np.min(np.diff(np.r_[angles, angles[0] + 2 * np.pi])) < 0.15:
            continue
        radii = rng.uniform(0.5, 3.0, n)
        center = rng.uniform(-3, 3, 2)
        verts = center + radii[:, None] * np.c_[np.cos(angles), np.sin(angles)]
        if grid:
            verts = np.round(verts * 2) / 2
        try:
            return Polygon(vertices=tuple(map(tuple, verts)))
        except ValueError:
            continue


def random_shape(rng: np.random.Generator, kind: str, *, grid: bool = False) -> Obstacle:
    """A random shape of ``kind``; coordinates on a 0.5 grid if ``grid`` (so contacts are exact)."""

    def num(low: float, high: float) -> float:
        value = rng.uniform(low, high)
        return float(np.round(value * 2) / 2) if grid else float(value)

    if kind == "circle":
        return Circle(center=(num(-3, 3), num(-3, 3)), radius=max(num(0.5, 3), 0.5))
    if kind == "square":
        return Square(center=(num(-3, 3), num(-3, 3)), half_side=max(num(0.5, 3), 0.5))
    if kind == "rectangle":
        x0, y0 = num(-4, 2), num(-4, 2)
        return Rectangle(xmin=x0, xmax=x0 + max(num(0.5, 4), 0.5), ymin=y0, ymax=y0 + max(num(0.5, 4), 0.5))
    return random_polygon(rng, grid=grid)


def random_points(rng: np.random.Generator, n: int, *, grid: bool = False) -> NDArray[np.float64]:
    """``n`` points in [-6, 6]^2 (on a 0.5 grid if ``grid``)."""
    pts = rng.uniform(-6, 6, (n, 2))
    return np.round(pts * 2) / 2 if grid else pts


KINDS = ("circle", "square", "rectangle", "polygon")


def exact_circle_segment_sign(
    p: NDArray[np.float64], q: NDArray[np.float64], circle: Circle
) -> NDArray[np.int8]:
    """Sign of (distance from the circle's centre to the closed segment) - radius, in exact rationals."""
    from fractions import Fraction

    out = np.empty(len(p), dtype=np.int8)
    cx, cy = (Fraction(v) for v in circle.center)
    rr = Fraction(circle.radius) ** 2
    for i, (a, b) in enumerate(zip(p, q, strict=True)):
        ax, ay, bx, by = (Fraction(float(v)) for v in (*a, *b))
        # closest point of the segment to the centre: minimise a quadratic in t over [0, 1]
        dx, dy = bx - ax, by - ay
        dd = dx * dx + dy * dy
        t = (
            Fraction(0)
            if dd == 0
            else min(max(((cx - ax) * dx + (cy - ay) * dy) / dd, Fraction(0)), Fraction(1))
        )
        ex, ey = ax + t * dx - cx, ay + t * dy - cy
        d2 = ex * ex + ey * ey
        out[i] = (d2 > rr) - (d2 < rr)
    return out
