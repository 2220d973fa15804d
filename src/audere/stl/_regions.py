"""Region predicates: robustness and truth of ``in(R)`` for each world shape, vectorized over points.

Robustness of ``in(R)`` at a point ``p = (x, y)``:

- axis-aligned box (:class:`~audere.world.Rectangle`, :class:`~audere.world.Square`,
  :class:`~audere.world.Workspace`): ``min(x - xmin, xmax - x, y - ymin, ymax - y)``, the linear
  form a MILP encodes (it equals the Euclidean signed distance inside the box, and is more negative
  than it near the corners outside);
- :class:`~audere.world.Circle`: ``radius - ||p - center||``;
- :class:`~audere.world.Polygon`: the negated Euclidean signed distance to the polygon
  (:func:`audere.world.signed_distance`).

Truth is computed separately from robustness: ``in(R)`` holds when ``p`` is strictly inside ``R``
(a point on the boundary is not inside, as for collisions in :mod:`audere.world`).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from audere.world import Circle, Polygon, Rectangle, Square, Workspace, contains, signed_distance

__all__ = ["REGION_TYPES", "RegionShape", "region_robustness", "region_truth"]

RegionShape = Circle | Square | Rectangle | Polygon | Workspace
"""What a region name may map to."""

REGION_TYPES = (Circle, Square, Rectangle, Polygon, Workspace)


def _box(shape: Square | Rectangle | Workspace) -> tuple[float, float, float, float]:
    if isinstance(shape, Square):
        (cx, cy), h = shape.center, shape.half_side
        return cx - h, cx + h, cy - h, cy + h
    return shape.xmin, shape.xmax, shape.ymin, shape.ymax


def region_robustness(shape: RegionShape, points: NDArray[np.float64]) -> NDArray[np.float64]:
    """Robustness of ``in(shape)`` at each point.

    Parameters
    ----------
    shape
        The region.
    points
        Array (N, 2) of positions.

    Returns
    -------
    numpy.ndarray
        Array (N,): positive strictly inside, zero on the boundary, negative outside (metres).
    """
    x, y = points[:, 0], points[:, 1]
    if isinstance(shape, Circle):
        cx, cy = shape.center
        return np.asarray(shape.radius - np.hypot(x - cx, y - cy), dtype=np.float64)
    if isinstance(shape, Polygon):
        return np.asarray(-signed_distance(shape, points), dtype=np.float64)
    xmin, xmax, ymin, ymax = _box(shape)
    return np.minimum(np.minimum(x - xmin, xmax - x), np.minimum(y - ymin, ymax - y))


def region_truth(shape: RegionShape, points: NDArray[np.float64]) -> NDArray[np.bool_]:
    """Whether each point is strictly inside ``shape`` (the boolean meaning of ``in(shape)``).

    Parameters
    ----------
    shape
        The region.
    points
        Array (N, 2) of positions.

    Returns
    -------
    numpy.ndarray
        Boolean array (N,); points on the boundary are not inside.
    """
    x, y = points[:, 0], points[:, 1]
    if isinstance(shape, Circle):
        cx, cy = shape.center
        return np.asarray(np.hypot(x - cx, y - cy) < shape.radius)
    if isinstance(shape, Polygon):
        return np.asarray(contains(shape, points), dtype=np.bool_)
    xmin, xmax, ymin, ymax = _box(shape)
    return (xmin < x) & (x < xmax) & (ymin < y) & (y < ymax)
