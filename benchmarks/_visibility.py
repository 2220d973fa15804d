"""Shortest collision-free paths in a World by a visibility graph (a benchmark helper, not the library).

The free space is the workspace minus the union of the obstacles, as a shapely polygon. Every
shortest path among polygons is a polyline that bends only at vertices of the free space's boundary,
where it is tangent to the boundary; so the graph has the start, the goal and those vertices as
nodes, and an edge for every pair that sees each other (the closed segment lies in the closed free
space) and is tangent at its boundary endpoints. Dijkstra on it gives the exact shortest path for
polygonal obstacles (squares, rectangles, polygons).

Circles are replaced by regular polygons with ``sides`` sides, either **circumscribed** (containing
the circle: less free space, so the shortest length is an *upper* bound on the true optimum, and its
path is feasible for the circles) or **inscribed** (inside the circle: more free space, a *lower*
bound). :func:`shortest_path_bounds` returns both; the true optimum lies between them.
"""

from __future__ import annotations

import math

import numpy as np
import shapely
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra

from audere.world import Circle, Polygon, Rectangle, Square, World


def _shape(obstacle: object, sides: int, circumscribed: bool) -> shapely.Polygon:
    if isinstance(obstacle, Circle):
        # circumscribed edges touch the circle at their midpoints: grow by 1e-9 so that rounding
        # cannot put a path along such an edge into the circle
        r = obstacle.radius * (1 + 1e-9) / math.cos(math.pi / sides) if circumscribed else obstacle.radius
        a = 2 * math.pi * np.arange(sides) / sides
        cx, cy = obstacle.center
        return shapely.Polygon(np.column_stack([cx + r * np.cos(a), cy + r * np.sin(a)]))
    if isinstance(obstacle, Square):
        (cx, cy), h = obstacle.center, obstacle.half_side
        return shapely.box(cx - h, cy - h, cx + h, cy + h)
    if isinstance(obstacle, Rectangle):
        return shapely.box(obstacle.xmin, obstacle.ymin, obstacle.xmax, obstacle.ymax)
    if isinstance(obstacle, Polygon):
        return shapely.Polygon(obstacle.vertices)
    raise TypeError(f"unknown obstacle {obstacle!r}")


def shortest_path(
    world: World,
    start: tuple[float, float],
    goal: tuple[float, float],
    *,
    sides: int = 64,
    circumscribed: bool = True,
) -> tuple[float, np.ndarray]:
    """Length and waypoints of the shortest path from ``start`` to ``goal`` avoiding the obstacles.

    Parameters
    ----------
    world
        Workspace and obstacles.
    start, goal
        ``(x, y)`` in metres, in the free space.
    sides
        Sides of the polygon that replaces each circle.
    circumscribed
        Circumscribed (upper bound, feasible path) or inscribed (lower bound) circle polygons.

    Returns
    -------
    tuple
        ``(length, waypoints (k, 2))``; ``(inf, empty)`` when the goal cannot be reached.
    """
    ws = world.workspace
    box = shapely.box(ws.xmin, ws.ymin, ws.xmax, ws.ymax)
    blocked = shapely.union_all([_shape(o, sides, circumscribed) for o in world.obstacles])
    free = box.difference(blocked)
    shapely.prepare(free)
    # boundary vertices with their ring neighbours (for the tangency test)
    pts, prev, nxt = [], [], []
    polys = list(free.geoms) if hasattr(free, "geoms") else [free]
    for poly in polys:
        for ring in (poly.exterior, *poly.interiors):
            xy = np.asarray(ring.coords)[:-1]
            pts.append(xy)
            prev.append(np.roll(xy, 1, axis=0))
            nxt.append(np.roll(xy, -1, axis=0))
    v = np.vstack([np.asarray([start, goal], dtype=float), *pts])
    pv = np.vstack([np.full((2, 2), np.nan), *prev])
    nv = np.vstack([np.full((2, 2), np.nan), *nxt])
    n = len(v)
    i, j = np.triu_indices(n, k=1)

    def tangent(a: np.ndarray, b: np.ndarray) -> np.ndarray:
        d = v[b] - v[a]
        o1 = d[:, 0] * (pv[a, 1] - v[a, 1]) - d[:, 1] * (pv[a, 0] - v[a, 0])
        o2 = d[:, 0] * (nv[a, 1] - v[a, 1]) - d[:, 1] * (nv[a, 0] - v[a, 0])
        return (a < 2) | (o1 * o2 >= -1e-12)

    keep = tangent(i, j) & tangent(j, i)
    i, j = i[keep], j[keep]
    lines = shapely.linestrings(np.stack([v[i], v[j]], axis=1))
    ok = shapely.covers(free, lines)
    i, j = i[ok], j[ok]
    w = np.hypot(*(v[i] - v[j]).T)
    graph = coo_matrix((np.r_[w, w], (np.r_[i, j], np.r_[j, i])), shape=(n, n)).tocsr()
    dist, pred = dijkstra(graph, indices=0, return_predecessors=True)
    if not np.isfinite(dist[1]):
        return math.inf, np.zeros((0, 2))
    path, k = [1], 1
    while k != 0:
        k = int(pred[k])
        path.append(k)
    return float(dist[1]), v[path[::-1]]


def shortest_path_bounds(
    world: World, start: tuple[float, float], goal: tuple[float, float], *, sides: int = 64
) -> tuple[float, float]:
    """Lower and upper bounds on the shortest path length (equal without circles).

    Returns
    -------
    tuple
        ``(lower, upper)`` in metres: inscribed and circumscribed circle polygons.
    """
    upper, _ = shortest_path(world, start, goal, sides=sides, circumscribed=True)
    if not any(isinstance(o, Circle) for o in world.obstacles):
        return upper, upper
    lower, _ = shortest_path(world, start, goal, sides=sides, circumscribed=False)
    return lower, upper
