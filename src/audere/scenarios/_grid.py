"""A certified grid search: is there a collision-free path from a start to a goal in a world?

Private helper of the generators (they resample a layout it cannot certify) and of the witnesses
(the path it returns must pass the task checker). The public A* planner lives in
:mod:`audere.planners`; this is deliberately the simplest search that is *sound*:

- the nodes are the points of a regular grid of spacing ``h`` over the workspace;
- a node is free when it lies outside every obstacle grown by ``h * sqrt(2) / 2``
  (:meth:`audere.world.World.inflate` grows to a superset, so a free node's signed distance to the
  obstacles is at least ``h * sqrt(2) / 2``);
- free nodes are joined to their 8 neighbours. Every point of a move between two neighbours lies
  within ``h * sqrt(2) / 2`` of one of its ends and the signed distance is 1-Lipschitz, so no move
  reaches an obstacle's interior;
- the start and the goal are joined to a nearby free node by a straight segment checked exactly
  (:meth:`audere.world.World.segments_in_collision`).

A path found is therefore collision-free in the world searched (pass a task's *inflated* world to
respect its margin). A path not found may still exist through passages narrower than about
``1.5 h``; the generators then resample, so they never produce an unsolvable task.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from audere.world import World

__all__ = ["certify", "grid_path"]

_LINK_RADIUS = 3
"""The start and the goal are joined to free nodes at most this many spacings away (per axis)
from their nearest node."""


@dataclass(frozen=True)
class _Grid:
    nodes: NDArray[np.float64]  # (ny * nx, 2), row-major: index = iy * nx + ix
    free: NDArray[np.bool_]  # (ny, nx)
    a: int  # node joined to the start
    b: int  # node joined to the goal


def _grid(
    world: World, start: NDArray[np.float64], goal: NDArray[np.float64], spacing: float
) -> _Grid | None:
    ws = world.workspace
    nx = math.floor((ws.xmax - ws.xmin) / spacing + 1e-9) + 1
    ny = math.floor((ws.ymax - ws.ymin) / spacing + 1e-9) + 1
    gx, gy = np.meshgrid(ws.xmin + spacing * np.arange(nx), ws.ymin + spacing * np.arange(ny))
    nodes = np.column_stack([gx.ravel(), gy.ravel()])
    grown = world.inflate(spacing * math.sqrt(2.0) / 2.0 * (1.0 + 1e-9) + 1e-12)
    free = (~grown.points_in_collision(nodes)).reshape(ny, nx)
    a = _attach(world, start, nodes, free, spacing)
    b = _attach(world, goal, nodes, free, spacing)
    if a is None or b is None:
        return None
    return _Grid(nodes=nodes, free=free, a=a, b=b)


def _attach(
    world: World,
    point: NDArray[np.float64],
    nodes: NDArray[np.float64],
    free: NDArray[np.bool_],
    spacing: float,
) -> int | None:
    """Index of the nearest free node joined to ``point`` by a collision-free segment."""
    ny, nx = free.shape
    origin = nodes[0]
    ix = round(float(point[0] - origin[0]) / spacing)
    iy = round(float(point[1] - origin[1]) / spacing)
    xs = np.arange(max(ix - _LINK_RADIUS, 0), min(ix + _LINK_RADIUS, nx - 1) + 1)
    ys = np.arange(max(iy - _LINK_RADIUS, 0), min(iy + _LINK_RADIUS, ny - 1) + 1)
    cand = (ys[:, None] * nx + xs[None, :]).ravel()
    cand = cand[free.ravel()[cand]]
    if cand.size == 0:
        return None
    cand = cand[np.argsort(np.linalg.norm(nodes[cand] - point, axis=1), kind="stable")]
    blocked = world.segments_in_collision(np.broadcast_to(point, nodes[cand].shape), nodes[cand])
    ok = cand[~blocked]
    return int(ok[0]) if ok.size else None


def certify(world: World, start: tuple[float, float], goal: tuple[float, float], *, spacing: float) -> bool:
    """Whether the grid holds a collision-free path from ``start`` to ``goal`` (see the module text).

    Parameters
    ----------
    world
        The world to search; give a task's inflated world to respect its margin.
    start, goal
        Ends of the path (x, y), metres, in the workspace.
    spacing
        Grid spacing ``h``, metres, ``> 0``.

    Returns
    -------
    bool
        ``True`` proves that a path exists (:func:`grid_path` returns one); ``False`` proves nothing.
    """
    from scipy.ndimage import label

    grid = _grid(world, np.asarray(start, dtype=float), np.asarray(goal, dtype=float), spacing)
    if grid is None:
        return False
    labels, _ = label(grid.free, structure=np.ones((3, 3), dtype=bool))
    flat = labels.ravel()
    return bool(flat[grid.a] == flat[grid.b])


def grid_path(
    world: World,
    start: tuple[float, float],
    goal: tuple[float, float],
    *,
    spacing: float,
) -> NDArray[np.float64] | None:
    """A collision-free polyline from ``start`` to ``goal`` in ``world``, or ``None`` if none is found.

    Parameters
    ----------
    world
        The world to search; give a task's inflated world to respect its margin.
    start, goal
        Ends of the path (x, y), metres, in the workspace.
    spacing
        Grid spacing ``h``, metres, ``> 0``.

    Returns
    -------
    numpy.ndarray or None
        Waypoints of shape ``(k, 2)``, metres, starting exactly at ``start`` and ending exactly at
        ``goal``, in the workspace and outside every obstacle's interior (waypoints and segments);
        ``None`` when the grid holds no such path. Collinear runs of grid moves are merged.
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import breadth_first_order

    p0, p1 = np.asarray(start, dtype=float), np.asarray(goal, dtype=float)
    grid = _grid(world, p0, p1, spacing)
    if grid is None:
        return None
    free = grid.free
    ny, nx = free.shape
    ids = np.arange(nx * ny).reshape(ny, nx)
    rows: list[NDArray[np.int_]] = []
    cols: list[NDArray[np.int_]] = []
    for dy, dx in ((0, 1), (1, 0), (1, 1), (1, -1)):  # each undirected 8-neighbour edge once
        x0, x1 = max(0, -dx), nx - max(0, dx)
        src = ids[0 : ny - dy, x0:x1]
        dst = ids[dy:ny, x0 + dx : x1 + dx]
        both = free[0 : ny - dy, x0:x1] & free[dy:ny, x0 + dx : x1 + dx]
        rows.append(src[both])
        cols.append(dst[both])
    r, c = np.concatenate(rows), np.concatenate(cols)
    n = nx * ny
    graph = coo_matrix((np.ones(r.size), (r, c)), shape=(n, n)).tocsr()
    _, pred = breadth_first_order(graph, grid.a, directed=False, return_predecessors=True)
    if grid.a != grid.b and pred[grid.b] < 0:
        return None
    chain = [grid.b]
    while chain[-1] != grid.a:
        chain.append(int(pred[chain[-1]]))
    pts = np.vstack([p0, grid.nodes[chain[::-1]], p1])
    # Drop grid nodes in the middle of straight runs (same direction in and out).
    d = np.diff(pts, axis=0)
    keep = np.ones(len(pts), dtype=bool)
    keep[1:-1] = np.abs(d[1:, 0] * d[:-1, 1] - d[1:, 1] * d[:-1, 0]) > 1e-12
    return np.asarray(pts[keep], dtype=np.float64)
