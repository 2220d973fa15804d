"""A* search on occupancy grids and weighted graphs, with the helpers that build them.

- :func:`occupancy_grid` rasterizes a :class:`audere.world.World` into an :class:`OccupancyGrid`
  whose free cells are clear of every obstacle grown by a margin (conservative: a path through free
  cells is collision-free in the inflated world);
- :func:`astar` searches a grid (8-connected without corner cutting, or 4-connected);
- :func:`astar_graph` searches a general weighted graph (an adjacency mapping or a list of edges);
- :func:`cell_graph` turns a :class:`audere.tasks.MazeTask` into the graph of its cells and doors;
- :func:`shortcut` smooths a path by greedy line of sight, every new segment checked exactly.

Every search returns an :class:`AStarResult`; its ``cost`` is optimal for the searched graph (the
heuristics offered are admissible and consistent for the connectivity chosen, which is validated).
"""

from __future__ import annotations

import heapq
import math
import time
from collections.abc import Hashable, Mapping, Sequence
from dataclasses import dataclass
from typing import Annotated, Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray
from pydantic import BaseModel, ConfigDict, Field, PlainSerializer, PlainValidator, WithJsonSchema

from audere._arrays import as_float_array
from audere.apis import Result
from audere.apis._registry import register_api
from audere.errors import InvalidArgumentError
from audere.world import World

__all__ = [
    "AStarResult",
    "CellGraph",
    "OccupancyGrid",
    "astar",
    "astar_graph",
    "cell_graph",
    "occupancy_grid",
    "shortcut",
]

Cell = tuple[int, int]

_SQRT2 = math.sqrt(2.0)
# 8 moves (drow, dcol): the four axis moves first, then the diagonals.
_MOVES = ((0, 1), (1, 0), (0, -1), (-1, 0), (1, 1), (1, -1), (-1, 1), (-1, -1))
_ADMISSIBLE: dict[int, tuple[str, ...]] = {
    4: ("manhattan", "octile", "euclidean", "zero"),
    8: ("octile", "euclidean", "zero"),
}
_CHECK_EVERY = 1024
"""Expansions between two looks at the clock."""


def _as_blocked(value: Any) -> NDArray[np.bool_]:
    arr = np.array(value)
    if arr.dtype != np.bool_:
        if arr.size and not np.isin(arr, (0, 1)).all():
            raise ValueError(f"blocked must hold booleans (or 0/1), got dtype {arr.dtype}")
        arr = arr.astype(bool)
    if arr.ndim != 2 or arr.shape[0] < 1 or arr.shape[1] < 1:
        raise ValueError(f"blocked must be a non-empty 2-D array (rows, cols), got shape {arr.shape}")
    arr.setflags(write=False)
    return arr


BoolGrid = Annotated[
    NDArray[np.bool_],
    PlainValidator(_as_blocked),
    PlainSerializer(lambda a: np.asarray(a).tolist(), return_type=list),
    WithJsonSchema(
        {
            "type": "array",
            "items": {"type": "array", "items": {"type": "boolean"}},
            "description": "rows of cells",
        }
    ),
]


class OccupancyGrid(BaseModel):
    """A regular grid of square cells over the plane, each free or blocked.

    Cell ``(row, col)`` is the closed square ``[x0 + col h, x0 + (col + 1) h] x [y0 + row h,
    y0 + (row + 1) h]`` with ``(x0, y0) = origin`` and ``h = resolution``: rows run along y, columns
    along x. Build one from a world with :func:`occupancy_grid`.

    Attributes
    ----------
    origin
        World coordinates (x, y) of the lower-left corner of cell ``(0, 0)``, metres.
    resolution
        Side of a cell, metres, ``> 0``.
    blocked
        Booleans of shape ``(rows, cols)``: ``True`` where the robot may not go (read-only).
    """

    model_config = ConfigDict(frozen=True, extra="forbid", allow_inf_nan=False)

    origin: tuple[float, float] = Field(description="Lower-left corner (x, y) of cell (0, 0), metres.")
    resolution: float = Field(gt=0, description="Cell side, metres.")
    blocked: BoolGrid = Field(description="Blocked cells, shape (rows, cols), rows along y.")

    @property
    def shape(self) -> tuple[int, int]:
        """``(rows, cols)``."""
        return (int(self.blocked.shape[0]), int(self.blocked.shape[1]))

    def to_world(self, cells: ArrayLike) -> NDArray[np.float64]:
        """Centres of cells, in world coordinates.

        Parameters
        ----------
        cells
            Cell indices ``(row, col)``, shape ``(k, 2)`` or ``(2,)``.

        Returns
        -------
        numpy.ndarray
            Points (x, y) in metres, shape ``(k, 2)`` (``(2,)`` for one cell).
        """
        c = np.asarray(cells, dtype=np.float64)
        if c.ndim not in (1, 2) or c.shape[-1] != 2:
            raise InvalidArgumentError(f"cells must have shape (k, 2) or (2,), got shape {c.shape}")
        x = self.origin[0] + (c[..., 1] + 0.5) * self.resolution
        y = self.origin[1] + (c[..., 0] + 0.5) * self.resolution
        return np.stack([x, y], axis=-1)

    def to_cell(self, points: ArrayLike) -> NDArray[np.int64]:
        """The cells holding points (a point on a shared edge goes to the upper/right cell).

        Parameters
        ----------
        points
            Points (x, y) in metres, shape ``(k, 2)`` or ``(2,)``.

        Returns
        -------
        numpy.ndarray
            Integer ``(row, col)`` of shape ``(k, 2)`` (``(2,)`` for one point). Points on the grid's
            upper or right boundary go to the last row or column; points outside the grid get indices
            outside ``[0, rows) x [0, cols)``.
        """
        p = np.asarray(points, dtype=np.float64)
        if p.ndim not in (1, 2) or p.shape[-1] != 2:
            raise InvalidArgumentError(f"points must have shape (k, 2) or (2,), got shape {p.shape}")
        col = np.floor((p[..., 0] - self.origin[0]) / self.resolution).astype(np.int64)
        row = np.floor((p[..., 1] - self.origin[1]) / self.resolution).astype(np.int64)
        rows, cols = self.shape
        col = np.where(col == cols, cols - 1, col)
        row = np.where(row == rows, rows - 1, row)
        return np.stack([row, col], axis=-1)

    def contains(self, points: ArrayLike) -> NDArray[np.bool_]:
        """Which points lie on the grid (its boundary included).

        Parameters
        ----------
        points
            Points (x, y) in metres, shape ``(k, 2)`` or ``(2,)``.

        Returns
        -------
        numpy.ndarray
            Booleans of shape ``(k,)`` (``()`` for one point).
        """
        p = np.asarray(points, dtype=np.float64)
        rows, cols = self.shape
        x0, y0 = self.origin
        x1, y1 = x0 + cols * self.resolution, y0 + rows * self.resolution
        return np.asarray(
            (p[..., 0] >= x0) & (p[..., 0] <= x1) & (p[..., 1] >= y0) & (p[..., 1] <= y1), dtype=np.bool_
        )


class AStarResult(Result):
    """What :func:`astar` and :func:`astar_graph` return.

    ``waypoints`` (k, 2) is the path in world coordinates, metres (``None`` when none was found or,
    for a graph search, when the nodes have no coordinates); ``cost`` its cost (metres on a grid).
    """

    cells: tuple[tuple[int, int], ...] | None = Field(
        None, description="Grid search: the cells (row, col) visited, start cell to goal cell."
    )
    nodes: tuple[Any, ...] | None = Field(None, description="Graph search: the nodes visited, start to goal.")
    expanded: int = Field(0, ge=0, description="Number of nodes expanded (taken off the open list).")


# ------------------------------------------------------------------------------------------ search


@dataclass(frozen=True)
class _Outcome:
    path: list[int] | None
    cost: float
    expanded: int
    timed_out: bool


def _search(
    start: int,
    goal: int,
    neighbours: list[list[int]],
    weights: list[list[float]],
    h: list[float],
    deadline: float,
) -> _Outcome:
    """A* over integer nodes with a consistent heuristic ``h``."""
    n = len(neighbours)
    g = [math.inf] * n
    parent = [-1] * n
    closed = bytearray(n)
    g[start] = 0.0
    heap: list[tuple[float, float, int]] = [(h[start], h[start], start)]
    expanded = 0
    pop, push, clock = heapq.heappop, heapq.heappush, time.perf_counter
    while heap:
        _, _, node = pop(heap)
        if closed[node]:
            continue
        closed[node] = 1
        expanded += 1
        if node == goal:
            path = [node]
            while parent[path[-1]] >= 0:
                path.append(parent[path[-1]])
            return _Outcome(path[::-1], g[goal], expanded, False)
        if expanded % _CHECK_EVERY == 0 and clock() > deadline:
            return _Outcome(None, math.inf, expanded, True)
        gn = g[node]
        for nb, w in zip(neighbours[node], weights[node], strict=True):
            if closed[nb]:
                continue
            cand = gn + w
            if cand < g[nb]:
                g[nb] = cand
                parent[nb] = node
                push(heap, (cand + h[nb], h[nb], nb))
    return _Outcome(None, math.inf, expanded, False)


def _as_point(value: ArrayLike, name: str) -> NDArray[np.float64]:
    return as_float_array(value, name=name, shape=(2,))


def _as_time_limit(time_limit: float) -> float:
    if not (isinstance(time_limit, int | float) and math.isfinite(time_limit) and time_limit > 0):
        raise InvalidArgumentError(f"time_limit must be a finite number of seconds > 0, got {time_limit!r}")
    return float(time_limit)


def _grid_search(
    free: NDArray[np.bool_],
    start: Cell,
    goal: Cell,
    connectivity: int,
    h: list[float],
    step: float,
    deadline: float,
) -> _Outcome:
    """A* on a grid, neighbours generated on the fly; nodes are indices into ``free`` padded by one.

    The padding ring is blocked, so no move needs a bounds check. ``h`` is indexed like the padded
    grid; axis moves cost ``step``, diagonal moves ``step * sqrt(2)`` and need both cells beside the
    diagonal free (no corner cutting).
    """
    rows, cols = free.shape
    width = cols + 2
    padded = np.zeros((rows + 2, width), dtype=bool)
    padded[1:-1, 1:-1] = free
    ok = padded.ravel().tolist()
    axis = [(dr * width + dc, step) for dr, dc in _MOVES[:4]]
    diagonal = [(dr * width + dc, dr * width, dc, step * _SQRT2) for dr, dc in _MOVES[4:connectivity]]
    s, t = (start[0] + 1) * width + start[1] + 1, (goal[0] + 1) * width + goal[1] + 1
    n = len(ok)
    g = [math.inf] * n
    parent = [-1] * n
    closed = bytearray(n)
    g[s] = 0.0
    heap: list[tuple[float, float, int]] = [(h[s], h[s], s)]
    expanded = 0
    pop, push, clock = heapq.heappop, heapq.heappush, time.perf_counter
    while heap:
        _, _, node = pop(heap)
        if closed[node]:
            continue
        closed[node] = 1
        expanded += 1
        if node == t:
            path = [node]
            while parent[path[-1]] >= 0:
                path.append(parent[path[-1]])
            cells = [(i // width - 1) * cols + i % width - 1 for i in reversed(path)]
            return _Outcome(cells, g[t], expanded, False)
        if expanded % _CHECK_EVERY == 0 and clock() > deadline:
            return _Outcome(None, math.inf, expanded, True)
        gn = g[node]
        for off, w in axis:
            nb = node + off
            if ok[nb] and not closed[nb] and gn + w < g[nb]:
                g[nb] = gn + w
                parent[nb] = node
                push(heap, (gn + w + h[nb], h[nb], nb))
        for off, o1, o2, w in diagonal:
            nb = node + off
            if ok[nb] and ok[node + o1] and ok[node + o2] and not closed[nb] and gn + w < g[nb]:
                g[nb] = gn + w
                parent[nb] = node
                push(heap, (gn + w + h[nb], h[nb], nb))
    return _Outcome(None, math.inf, expanded, False)


def _grid_heuristic(heuristic: str, rows: int, cols: int, goal: Cell) -> NDArray[np.float64]:
    r, c = np.divmod(np.arange(rows * cols), cols)
    dr = np.abs(r - goal[0]).astype(np.float64)
    dc = np.abs(c - goal[1]).astype(np.float64)
    if heuristic == "octile":
        out = np.maximum(dr, dc) + (_SQRT2 - 1.0) * np.minimum(dr, dc)
    elif heuristic == "euclidean":
        out = np.hypot(dr, dc)
    elif heuristic == "manhattan":
        out = dr + dc
    else:
        out = np.zeros(rows * cols)
    return np.asarray(out, dtype=np.float64)


@register_api(
    "astar",
    description="A* shortest path on an occupancy grid of a 2-D world; use for geometric paths and mazes.",
    tags=("planning", "path", "grid", "search", "optimal"),
)
def astar(
    grid: OccupancyGrid,
    start: ArrayLike,
    goal: ArrayLike,
    *,
    connectivity: Literal[4, 8] = 8,
    heuristic: Literal["octile", "euclidean", "manhattan", "zero"] = "octile",
    time_limit: float = 10.0,
) -> AStarResult:
    """Shortest path on an occupancy grid from the cell holding ``start`` to the cell holding ``goal``.

    Cells are joined to their 4 axis neighbours (move length ``resolution``) and, with
    ``connectivity=8``, to their diagonal neighbours (``resolution * sqrt(2)``) when both cells beside
    the diagonal are free as well (no corner cutting). The search is optimal for that graph.

    The returned waypoints are ``start``, the centres of the cells, then ``goal``. When the grid
    comes from :func:`occupancy_grid` (free cells are clear of the grown obstacles and centred in the
    workspace), every waypoint and every segment of that polyline is collision-free in
    ``world.inflate(margin)``.

    Parameters
    ----------
    grid
        The occupancy grid, e.g. from :func:`occupancy_grid`.
    start
        Start position (x, y), metres, shape ``(2,)``; must lie on the grid.
    goal
        Goal position (x, y), metres, shape ``(2,)``; must lie on the grid.
    connectivity
        8 (axis and diagonal moves, default) or 4 (axis moves only).
    heuristic
        Estimate of the remaining cost: ``"octile"`` (default, exact on an empty 8-connected grid),
        ``"euclidean"``, ``"manhattan"`` (4-connected only: it overestimates diagonal moves) or
        ``"zero"`` (Dijkstra). All are admissible and consistent for the connectivities they allow.
    time_limit
        Wall-clock budget in seconds, ``> 0``; past it the search stops with status ``time_limit``.

    Returns
    -------
    AStarResult
        ``status`` ``"solved"`` with ``cells`` (row, col) from the start cell to the goal cell,
        ``waypoints`` of shape ``(k, 2)`` in metres (consecutive duplicates removed) and ``cost``
        their length in metres; ``"infeasible"`` when the start or goal cell is blocked or no free
        path joins them (``message`` says which); ``"time_limit"`` when the budget ran out. Always
        ``expanded`` and ``solve_time`` (seconds).

    Raises
    ------
    InvalidArgumentError
        When ``grid`` is not an OccupancyGrid, a point is malformed, NaN or off the grid, or the
        connectivity, heuristic or time limit is not one of the allowed values (``manhattan`` with
        ``connectivity=8`` is refused: it is not admissible).

    Examples
    --------
    >>> from audere.planners import astar, occupancy_grid
    >>> from audere.world import Circle, World, Workspace
    >>> world = World(workspace=Workspace(xmin=0, xmax=4, ymin=0, ymax=4),
    ...               obstacles=(Circle(center=(2, 2), radius=1),))
    >>> grid = occupancy_grid(world, resolution=0.1, margin=0.1)
    >>> result = astar(grid, (0.5, 0.5), (3.5, 3.5))
    >>> result.status, world.inflate(0.1).first_collision(result.waypoints) is None
    ('solved', True)
    """
    t0 = time.perf_counter()
    if not isinstance(grid, OccupancyGrid):
        raise InvalidArgumentError(
            f"grid must be an OccupancyGrid (see occupancy_grid), got {type(grid).__name__}"
        )
    p0, p1 = _as_point(start, "start"), _as_point(goal, "goal")
    if connectivity not in (4, 8) or isinstance(connectivity, bool):
        raise InvalidArgumentError(f"connectivity must be 4 or 8, got {connectivity!r}")
    if heuristic not in ("octile", "euclidean", "manhattan", "zero"):
        raise InvalidArgumentError(
            f"heuristic must be one of 'octile', 'euclidean', 'manhattan', 'zero', got {heuristic!r}"
        )
    if heuristic not in _ADMISSIBLE[connectivity]:
        raise InvalidArgumentError(
            f"heuristic {heuristic!r} is not admissible with connectivity={connectivity} (it overestimates "
            f"diagonal moves); use one of {', '.join(repr(h) for h in _ADMISSIBLE[connectivity])}"
        )
    budget = _as_time_limit(time_limit)
    for name, p in (("start", p0), ("goal", p1)):
        if not grid.contains(p):
            rows, cols = grid.shape
            x0, y0 = grid.origin
            raise InvalidArgumentError(
                f"{name} must lie on the grid [{x0:g}, {x0 + cols * grid.resolution:g}] x "
                f"[{y0:g}, {y0 + rows * grid.resolution:g}], got ({p[0]:g}, {p[1]:g})"
            )
    rows, cols = grid.shape
    (r0, c0), (r1, c1) = grid.to_cell(np.stack([p0, p1])).tolist()
    a: Cell = (r0, c0)
    b: Cell = (r1, c1)

    def done(status: Literal["infeasible", "time_limit"], message: str, expanded: int = 0) -> AStarResult:
        return AStarResult(
            status=status, message=message, expanded=expanded, solve_time=time.perf_counter() - t0
        )

    for name, cell in (("start", a), ("goal", b)):
        if grid.blocked[cell]:
            return done("infeasible", f"the {name} cell {cell} is blocked")
    h = (_grid_heuristic(heuristic, rows + 2, cols + 2, (b[0] + 1, b[1] + 1)) * grid.resolution).tolist()
    out = _grid_search(~grid.blocked, a, b, connectivity, h, grid.resolution, t0 + budget)
    if out.timed_out:
        return done("time_limit", f"no path within the {budget:g} s budget", out.expanded)
    if out.path is None:
        return done("infeasible", f"no free path joins the start cell {a} to the goal cell {b}", out.expanded)
    cells = tuple((i // cols, i % cols) for i in out.path)
    waypoints = _dedupe(np.vstack([p0, grid.to_world(np.array(cells)), p1]))
    return AStarResult(
        status="solved",
        message=f"optimal path over {len(cells)} cells",
        cost=_length(waypoints),
        waypoints=waypoints,
        cells=cells,
        expanded=out.expanded,
        solve_time=time.perf_counter() - t0,
    )


def _dedupe(points: NDArray[np.float64]) -> NDArray[np.float64]:
    keep = np.ones(len(points), dtype=bool)
    keep[1:] = np.any(points[1:] != points[:-1], axis=1)
    return np.asarray(points[keep], dtype=np.float64)


def _length(points: NDArray[np.float64]) -> float:
    return float(np.linalg.norm(np.diff(points, axis=0), axis=1).sum())


def astar_graph(
    graph: Mapping[Hashable, Mapping[Hashable, float]] | Sequence[Sequence[Any]],
    start: Hashable,
    goal: Hashable,
    *,
    coordinates: Mapping[Hashable, ArrayLike] | None = None,
    heuristic: Literal["euclidean", "zero"] = "euclidean",
    time_limit: float = 10.0,
) -> AStarResult:
    """Shortest path between two nodes of a weighted graph.

    Parameters
    ----------
    graph
        Either an adjacency mapping ``{node: {neighbour: weight}}`` (directed: list each undirected
        edge both ways) or a sequence of undirected edges ``(u, v, weight)``; an edge ``(u, v)``
        without a weight costs the distance between the nodes' ``coordinates``. Weights are finite
        and ``>= 0``. Nodes are any hashable values.
    start
        The start node.
    goal
        The goal node.
    coordinates
        Position (x, y) in metres of each node, shape ``(2,)`` each. Needed for the ``"euclidean"``
        heuristic and for ``waypoints``; every node of the graph must have one.
    heuristic
        ``"euclidean"`` (straight-line distance to the goal; needs ``coordinates``, and is checked to
        be admissible: every edge must weigh at least the distance between its ends) or ``"zero"``
        (Dijkstra). ``"euclidean"`` falls back to ``"zero"`` when ``coordinates`` is ``None``.
    time_limit
        Wall-clock budget in seconds, ``> 0``.

    Returns
    -------
    AStarResult
        ``nodes`` from ``start`` to ``goal``, ``cost`` (the sum of the weights), ``waypoints`` of shape
        ``(k, 2)`` (the nodes' coordinates, when given), ``expanded``; status ``"infeasible"`` when
        the goal cannot be reached, ``"time_limit"`` when the budget ran out.

    Raises
    ------
    InvalidArgumentError
        Unknown start or goal, malformed edges, negative or NaN weights, missing coordinates, or an
        inadmissible euclidean heuristic.

    Examples
    --------
    >>> from audere.planners import astar_graph
    >>> edges = [("a", "b", 1.0), ("b", "c", 1.0), ("a", "c", 3.0)]
    >>> result = astar_graph(edges, "a", "c", heuristic="zero")
    >>> result.nodes, result.cost
    (('a', 'b', 'c'), 2.0)
    """
    t0 = time.perf_counter()
    budget = _as_time_limit(time_limit)
    if heuristic not in ("euclidean", "zero"):
        raise InvalidArgumentError(f"heuristic must be 'euclidean' or 'zero', got {heuristic!r}")
    coords = _as_coordinates(coordinates)
    adjacency = _as_adjacency(graph, coords)
    for name, node in (("start", start), ("goal", goal)):
        if not isinstance(node, Hashable) or node not in adjacency:
            raise InvalidArgumentError(f"{name} must be a node of the graph, got {node!r}")
    names = list(adjacency)
    index = {node: i for i, node in enumerate(names)}
    neighbours = [[index[v] for v in adjacency[u]] for u in names]
    weights = [list(adjacency[u].values()) for u in names]
    if coords is not None:
        missing = [node for node in names if node not in coords]
        if missing:
            raise InvalidArgumentError(
                f"coordinates must give a position for every node, missing {len(missing)}: {missing[:5]!r}"
            )
        xy = np.array([coords[node] for node in names], dtype=np.float64).reshape(len(names), 2)
    use_h = heuristic == "euclidean" and coords is not None
    if use_h:
        for u in names:
            for v, w in adjacency[u].items():
                d = float(np.hypot(*(xy[index[u]] - xy[index[v]])))
                if w < d * (1.0 - 1e-9):
                    raise InvalidArgumentError(
                        f"heuristic 'euclidean' is not admissible: edge ({u!r}, {v!r}) weighs {w:g}, "
                        f"less than the distance {d:g} between its ends; use heuristic='zero'"
                    )
        h = np.hypot(*(xy - xy[index[goal]]).T).tolist()
    else:
        h = [0.0] * len(names)
    out = _search(index[start], index[goal], neighbours, weights, h, t0 + budget)
    elapsed = time.perf_counter() - t0
    if out.timed_out:
        return AStarResult(
            status="time_limit",
            message=f"no path within the {budget:g} s budget",
            expanded=out.expanded,
            solve_time=elapsed,
        )
    if out.path is None:
        return AStarResult(
            status="infeasible",
            message=f"goal {goal!r} is not reachable from {start!r}",
            expanded=out.expanded,
            solve_time=elapsed,
        )
    nodes = tuple(names[i] for i in out.path)
    return AStarResult(
        status="solved",
        message=f"optimal path over {len(nodes)} nodes",
        cost=out.cost,
        nodes=nodes,
        waypoints=None if coords is None else xy[out.path],
        expanded=out.expanded,
        solve_time=elapsed,
    )


def _as_coordinates(
    coordinates: Mapping[Hashable, ArrayLike] | None,
) -> dict[Hashable, NDArray[np.float64]] | None:
    if coordinates is None:
        return None
    if not isinstance(coordinates, Mapping):
        raise InvalidArgumentError(
            f"coordinates must be a mapping node -> (x, y), got {type(coordinates).__name__}"
        )
    return {k: as_float_array(v, name=f"coordinates[{k!r}]", shape=(2,)) for k, v in coordinates.items()}


def _weight(w: Any, where: str) -> float:
    try:
        value = float(w)
    except (TypeError, ValueError):
        raise InvalidArgumentError(f"{where} must be a number, got {w!r}") from None
    if not (math.isfinite(value) and value >= 0):
        raise InvalidArgumentError(f"{where} must be finite and >= 0, got {w!r}")
    return value


def _as_adjacency(
    graph: Mapping[Hashable, Mapping[Hashable, float]] | Sequence[Sequence[Any]],
    coords: dict[Hashable, NDArray[np.float64]] | None,
) -> dict[Hashable, dict[Hashable, float]]:
    adjacency: dict[Hashable, dict[Hashable, float]] = {}
    if isinstance(graph, Mapping):
        for u, row in graph.items():
            if not isinstance(row, Mapping):
                raise InvalidArgumentError(
                    f"graph[{u!r}] must be a mapping neighbour -> weight, got {type(row).__name__}"
                )
            adjacency.setdefault(u, {})
            for v, w in row.items():
                if not isinstance(v, Hashable):
                    raise InvalidArgumentError(f"graph[{u!r}] has an unhashable neighbour {v!r}")
                adjacency[u][v] = _weight(w, f"graph[{u!r}][{v!r}]")
                adjacency.setdefault(v, {})
        return adjacency
    if isinstance(graph, str | bytes) or not isinstance(graph, Sequence):
        raise InvalidArgumentError(
            f"graph must be a mapping {{node: {{neighbour: weight}}}} "
            f"or a sequence of edges (u, v[, weight]), got {type(graph).__name__}"
        )
    for i, edge in enumerate(graph):
        if isinstance(edge, str | bytes) or not isinstance(edge, Sequence) or len(edge) not in (2, 3):
            raise InvalidArgumentError(f"graph[{i}] must be an edge (u, v) or (u, v, weight), got {edge!r}")
        u, v = edge[0], edge[1]
        if not (isinstance(u, Hashable) and isinstance(v, Hashable)):
            raise InvalidArgumentError(f"graph[{i}] has an unhashable node: {edge!r}")
        if len(edge) == 3:
            w = _weight(edge[2], f"graph[{i}] weight")
        else:
            if coords is None or u not in coords or v not in coords:
                raise InvalidArgumentError(
                    f"graph[{i}] = {edge!r} has no weight: give (u, v, weight) or coordinates for both ends"
                )
            w = float(np.hypot(*(coords[u] - coords[v])))
        for a, b in ((u, v), (v, u)):
            row = adjacency.setdefault(a, {})
            row[b] = min(w, row.get(b, math.inf))
    return adjacency


# ------------------------------------------------------------------------------------------ helpers


def occupancy_grid(world: World, *, resolution: float, margin: float = 0.0) -> OccupancyGrid:
    """Rasterize a world into square cells, blocking every cell that could bring the robot too close.

    The grid starts at the workspace's lower-left corner and has ``ceil(width / resolution)``
    columns and ``ceil(height / resolution)`` rows. A cell is **blocked** when its centre lies
    outside the workspace, or when some point of the closed cell square may lie inside an obstacle
    grown by ``margin`` (:meth:`audere.world.World.inflate`, which contains every point within
    ``margin`` of the obstacle). The test is the signed distance at the cell centre padded by the
    half diagonal ``resolution * sqrt(2) / 2``: the whole square lies within that distance of its
    centre, so the test is conservative (a free cell is provably clear; a few cells that are clear
    may be blocked). A polyline through the centres of free cells, moving between 4-neighbours or
    diagonal neighbours, therefore never enters ``world.inflate(margin)``.

    Parameters
    ----------
    world
        The workspace and obstacles.
    resolution
        Cell side, metres, ``> 0``; at most 4,000,000 cells.
    margin
        Clearance to keep from the obstacles, metres, ``>= 0`` (the robot's radius, a task's margin).

    Returns
    -------
    OccupancyGrid
        With ``origin`` the workspace's lower-left corner.

    Raises
    ------
    InvalidArgumentError
        When ``world`` is not a World, or ``resolution`` or ``margin`` is not a finite number in range.

    Examples
    --------
    >>> from audere.planners import occupancy_grid
    >>> from audere.world import Square, World, Workspace
    >>> world = World(workspace=Workspace(xmin=0, xmax=1, ymin=0, ymax=1),
    ...               obstacles=(Square(center=(0.5, 0.5), half_side=0.1),))
    >>> occupancy_grid(world, resolution=0.25).blocked.astype(int)
    array([[0, 0, 0, 0],
           [0, 1, 1, 0],
           [0, 1, 1, 0],
           [0, 0, 0, 0]])
    """
    if not isinstance(world, World):
        raise InvalidArgumentError(f"world must be an audere.world.World, got {type(world).__name__}")
    for name, value, low in (("resolution", resolution, "> 0"), ("margin", margin, ">= 0")):
        ok = isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)
        if not ok or (value <= 0 if low == "> 0" else value < 0):
            raise InvalidArgumentError(f"{name} must be a finite number of metres {low}, got {value!r}")
    ws = world.workspace
    h = float(resolution)
    cols = max(1, math.ceil((ws.xmax - ws.xmin) / h - 1e-9))
    rows = max(1, math.ceil((ws.ymax - ws.ymin) / h - 1e-9))
    if rows * cols > 4_000_000:
        raise InvalidArgumentError(
            f"resolution {resolution!r} gives {rows} x {cols} cells, more than 4,000,000; use a coarser one"
        )
    grown = world.inflate(float(margin)) if margin > 0 else world
    xs = ws.xmin + (np.arange(cols) + 0.5) * h
    ys = ws.ymin + (np.arange(rows) + 0.5) * h
    gx, gy = np.meshgrid(xs, ys)
    centres = np.column_stack([gx.ravel(), gy.ravel()])
    pad = h * _SQRT2 / 2.0 * (1.0 + 1e-9) + 1e-12
    blocked = grown.signed_distance(centres) < pad
    blocked |= ~world.in_workspace(centres)
    return OccupancyGrid(origin=(ws.xmin, ws.ymin), resolution=h, blocked=blocked.reshape(rows, cols))


@dataclass(frozen=True)
class CellGraph:
    """The cells of a maze and the doors between them, as a weighted graph.

    Attributes
    ----------
    adjacency
        ``{cell: {neighbour: weight}}`` over cells ``(row, col)``; a door's weight is the length,
        metres, of the polyline centre of ``cell`` -> door centre -> centre of ``neighbour``.
    coordinates
        Centre (x, y) of each cell, metres.
    doors
        Centre (x, y) of the door between two cells, metres, for both orders ``(a, b)`` and ``(b, a)``.
    """

    adjacency: Mapping[Cell, Mapping[Cell, float]]
    coordinates: Mapping[Cell, tuple[float, float]]
    doors: Mapping[tuple[Cell, Cell], tuple[float, float]]


def cell_graph(task: Any) -> CellGraph:
    """The door graph of a maze task, over cells, with door centres as the points between cells.

    Search it with :func:`astar_graph` (``coordinates=graph.coordinates``) for the sequence of cells
    from the start's cell to the goal's; ``graph.doors[(a, b)]`` is where the path crosses from
    ``a`` to ``b``. Every edge weighs at least the distance between the cell centres, so the
    euclidean heuristic is admissible.

    Parameters
    ----------
    task
        A :class:`audere.tasks.MazeTask`.

    Returns
    -------
    CellGraph
        Adjacency, cell centres and door centres.

    Raises
    ------
    InvalidArgumentError
        When ``task`` is not a MazeTask.

    Examples
    --------
    >>> from audere import scenarios
    >>> from audere.planners import astar_graph, cell_graph
    >>> task = scenarios.make("plan-hard", seed=0)
    >>> graph = cell_graph(task)
    >>> route = astar_graph(graph.adjacency, task.cell_of(task.start), task.cell_of(task.goal),
    ...                     coordinates=graph.coordinates)
    >>> route.nodes[0] == task.cell_of(task.start), route.nodes[-1] == task.cell_of(task.goal)
    (True, True)
    """
    from audere.tasks import MazeTask

    if not isinstance(task, MazeTask):
        raise InvalidArgumentError(f"task must be a MazeTask, got {type(task).__name__}")
    ws = task.workspace
    w, h = task.cell_size
    coordinates = {
        (r, c): (ws.xmin + (c + 0.5) * w, ws.ymin + (r + 0.5) * h)
        for r in range(task.rows)
        for c in range(task.cols)
    }
    adjacency: dict[Cell, dict[Cell, float]] = {cell: {} for cell in coordinates}
    doors: dict[tuple[Cell, Cell], tuple[float, float]] = {}
    for door, centre in zip(task.doors, task.door_centers(), strict=True):
        a, b = door.cells
        weight = math.dist(coordinates[a], centre) + math.dist(centre, coordinates[b])
        adjacency[a][b] = adjacency[b][a] = weight
        doors[(a, b)] = doors[(b, a)] = centre
    return CellGraph(adjacency=adjacency, coordinates=coordinates, doors=doors)


def shortcut(waypoints: ArrayLike, world: World) -> NDArray[np.float64]:
    """Shorten a path by greedy line of sight, every new segment checked exactly against ``world``.

    From the first waypoint, jump to the farthest later waypoint joined to it by a segment that does
    not enter any obstacle (:meth:`audere.world.World.segments_in_collision`), and repeat from there.
    The ends are kept; the result never collides where the input did not (when no jump is free the
    next waypoint is kept), and it stays in any convex region (the workspace) that holds the input.

    Parameters
    ----------
    waypoints
        The path, shape ``(k, 2)``, metres, ``k >= 1``.
    world
        The world to check against; pass the inflated world (``task.world()``) to keep a margin.

    Returns
    -------
    numpy.ndarray
        A subsequence of ``waypoints``, shape ``(m, 2)`` with ``m <= k``, same first and last rows.

    Raises
    ------
    InvalidArgumentError
        When ``waypoints`` is malformed or not finite, or ``world`` is not a World.

    Examples
    --------
    >>> from audere.planners import shortcut
    >>> from audere.world import World, Workspace
    >>> shortcut([[0, 0], [1, 0], [2, 0], [2, 1]], World(workspace=Workspace()))
    array([[0., 0.],
           [2., 1.]])
    """
    path = as_float_array(waypoints, name="waypoints", shape=(None, 2), min_len=1)
    if not isinstance(world, World):
        raise InvalidArgumentError(f"world must be an audere.world.World, got {type(world).__name__}")
    keep = [0]
    i, last = 0, len(path) - 1
    while i < last:
        later = path[i + 2 :]
        nxt = i + 1
        if len(later):
            free = ~world.segments_in_collision(np.broadcast_to(path[i], later.shape), later)
            hits = np.flatnonzero(free)
            if hits.size:
                nxt = i + 2 + int(hits[-1])
        keep.append(nxt)
        i = nxt
    return np.asarray(path[keep], dtype=np.float64)
