"""Geometric planning scenarios: ``plan-easy`` and ``plan-hard`` (the paper's).

Both are path tasks (``dynamics=None``): the solution is a polyline of waypoints, checked exactly
(every waypoint and every segment). Solvability is certified by :func:`certify` on the task's
inflated world; a layout it cannot certify is resampled.

Square convention: the authors' "square of radius r" has side ``r * sqrt(2)`` (it is inscribed in
the circle of radius r). We keep the same physical sizes and store squares by their half side,
``half_side = r / sqrt(2)``; the "radius" of every obstacle (circle radius, or the square's
circumradius ``half_side * sqrt(2)``) is what the spacing rules use.
"""

from __future__ import annotations

import math
from collections import deque

import numpy as np

from audere.scenarios._base import F, Generated, GenerationError, retry, rounded
from audere.scenarios._grid import certify, grid_path
from audere.tasks import Door, MazeTask, ReachAvoidTask, Solution
from audere.world import Circle, Obstacle, Square, Workspace

__all__ = ["EASY", "HARD", "plan_easy", "plan_hard"]

_WORKSPACE = Workspace(xmin=0.0, xmax=10.0, ymin=0.0, ymax=10.0)
_DIAGONAL = math.hypot(10.0, 10.0)


class EASY:
    """Parameters of plan-easy."""

    n_obstacles = 12
    radius = (0.8, 2.0)
    clearance = 0.5
    min_distance = 0.75 * _DIAGONAL
    endpoint_box = (0.25, 9.75)
    goal_tolerance = 0.1
    grid_spacing = 0.125
    pool = 8192
    """Candidate obstacles drawn per layout (see :func:`_place`)."""


class HARD:
    """Parameters of plan-hard."""

    rows = 3
    cols = 3
    door_probability = 0.85
    door_width = 1.0
    wall_thickness = 0.1
    corner_clearance = 0.35
    """Least distance from a door's edge to the cell corner, metres."""
    obstacles_per_cell = 4
    radius = (0.2, 0.35)
    margin = 0.15
    tolerance = 0.05
    min_door_hops = math.ceil(0.8 * (rows + cols - 2) - 1e-9)
    """Least number of doors between the start cell and the goal cell: ceil(0.8 (M + N - 2)) = 4."""
    endpoint_border = 0.5
    """Start and goal keep this far from their cell's borders, metres."""
    wall_gap = 0.55
    """An obstacle's circumcircle keeps this far from its cell's borders (0.2 m free after inflation)."""
    door_gap = 0.75
    """An obstacle's circumcircle keeps this far from the centre of each of its cell's doors."""
    endpoint_gap = 0.5
    """An obstacle's circumcircle keeps this far from the start and the goal."""
    obstacle_gap = 0.1
    """Least distance between the circumcircles of two obstacles of a cell."""
    grid_spacing = 0.125
    pool = 256
    """Candidate obstacles drawn per cell (see :func:`_place`)."""


def _place(
    rng: np.random.Generator,
    *,
    count: int,
    pool: int,
    radius: tuple[float, float],
    box: tuple[F, F],
    gap: float,
    keep_out: list[tuple[F, float]],
    shrink_box: float,
) -> list[Obstacle] | None:
    """Place ``count`` obstacles by sequential rejection from a pool of random candidates.

    ``pool`` candidates are drawn at once, each a kind (circle or square, even odds), a "radius" r
    uniform in ``radius`` (squares get ``half_side = r / sqrt(2)``; sizes are rounded and the
    circumradius ``rb`` is computed from the rounded size) and a centre uniform in ``box``. Taken in
    order, a candidate is placed when it fits: ``|c - c_j| >= rb + rb_j + gap`` for every obstacle
    already placed, ``|c - p| >= rb + d`` for every ``(p, d)`` of ``keep_out``, and ``c`` inside
    ``box`` shrunk by ``rb + shrink_box``. This is rejection sampling one obstacle after the other,
    so the later obstacles of a crowded layout lean to the small end of ``radius``.

    Returns
    -------
    list of Obstacle or None
        The shapes, or ``None`` when the pool runs out before ``count`` obstacles are placed.
    """
    lo, hi = box
    kind = rng.random(pool) < 0.5
    r = rng.uniform(*radius, size=pool)
    size = rounded(np.where(kind, r / math.sqrt(2.0), r))
    circum = np.where(kind, size * math.sqrt(2.0), size)
    center = rounded(lo + rng.random((pool, 2)) * (hi - lo))
    cx, cy = center[:, 0].copy(), center[:, 1].copy()
    room = circum + shrink_box
    alive = (cx >= lo[0] + room) & (cx <= hi[0] - room) & (cy >= lo[1] + room) & (cy <= hi[1] - room)
    # Squared distances: np.hypot is an order of magnitude slower on these arrays.
    for p, d in keep_out:
        alive &= (cx - p[0]) ** 2 + (cy - p[1]) ** 2 >= (circum + d) ** 2
    shapes: list[Obstacle] = []
    i = -1
    while len(shapes) < count:
        later = np.flatnonzero(alive[i + 1 :])
        if later.size == 0:
            return None
        i += 1 + int(later[0])
        c, s = (float(cx[i]), float(cy[i])), float(size[i])
        shapes.append(Square(center=c, half_side=s) if kind[i] else Circle(center=c, radius=s))
        rest = slice(i + 1, None)  # only the candidates after this one can still be placed
        alive[rest] &= (cx[rest] - c[0]) ** 2 + (cy[rest] - c[1]) ** 2 >= (
            circum[rest] + circum[i] + gap
        ) ** 2
    return shapes


def _certified(
    task: ReachAvoidTask | MazeTask, goal: tuple[float, float], spacing: float
) -> Generated | None:
    """``task`` with its grid-path witness when the grid certifies it solvable, else ``None``."""
    world = task.world()
    if not certify(world, task.start, goal, spacing=spacing):
        return None

    def witness() -> Solution:
        path = grid_path(world, task.start, goal, spacing=spacing)
        if path is None:  # pragma: no cover - certify() said the grid connects them
            raise GenerationError(f"{task.name}: the certified grid path went missing")
        return Solution(waypoints=path)

    return Generated(task, witness)


# ---------------------------------------------------------------------------------------- plan-easy


def plan_easy(rng: np.random.Generator, name: str) -> Generated:
    """plan-easy: start and goal far apart, 12 spaced circles and squares, a path with no dynamics.

    Parameters
    ----------
    rng
        The scenario's random stream.
    name
        The task's name.

    Returns
    -------
    Generated
        The task and a certified collision-free path.
    """

    def attempt() -> Generated | None:
        lo, hi = EASY.endpoint_box
        ends = rounded(rng.uniform(lo, hi, size=(256, 2, 2)))
        far = np.flatnonzero(np.linalg.norm(ends[:, 0] - ends[:, 1], axis=1) >= EASY.min_distance)
        if far.size == 0:
            return None
        start, goal = ends[far[0]]
        placed = _place(
            rng,
            count=EASY.n_obstacles,
            radius=EASY.radius,
            box=(np.zeros(2), np.full(2, 10.0)),
            gap=EASY.clearance,
            keep_out=[(start, EASY.clearance), (goal, EASY.clearance)],
            shrink_box=-math.inf,
            pool=EASY.pool,
        )
        if placed is None:
            return None
        task = ReachAvoidTask(
            name=name,
            x0=(float(start[0]), float(start[1])),
            goal=(float(goal[0]), float(goal[1])),
            goal_tolerance=EASY.goal_tolerance,
            workspace=_WORKSPACE,
            obstacles=tuple(placed),
        )
        return _certified(task, task.goal_position, EASY.grid_spacing)

    return retry(attempt, what="a plan-easy layout with a collision-free path")


# ---------------------------------------------------------------------------------------- plan-hard


def _door_pairs(rows: int, cols: int) -> list[tuple[tuple[int, int], tuple[int, int]]]:
    """Every pair of neighbouring cells, horizontal neighbours first, each ``((r, c), (r', c'))``."""
    pairs = [((r, c), (r, c + 1)) for r in range(rows) for c in range(cols - 1)]
    pairs += [((r, c), (r + 1, c)) for r in range(rows - 1) for c in range(cols)]
    return pairs


def _hops(doors: list[Door], rows: int, cols: int) -> dict[tuple[tuple[int, int], tuple[int, int]], int]:
    """Door-graph distance between every ordered pair of connected distinct cells (breadth first)."""
    adj: dict[tuple[int, int], list[tuple[int, int]]] = {(r, c): [] for r in range(rows) for c in range(cols)}
    for d in doors:
        a, b = d.cells
        adj[a].append(b)
        adj[b].append(a)
    out = {}
    for src in adj:
        dist = {src: 0}
        queue = deque([src])
        while queue:
            cell = queue.popleft()
            for n in adj[cell]:
                if n not in dist:
                    dist[n] = dist[cell] + 1
                    queue.append(n)
        out.update({(src, dst): h for dst, h in dist.items() if dst != src})
    return out


def plan_hard(rng: np.random.Generator, name: str) -> Generated:
    """plan-hard: a 3x3 maze with random doors and four small obstacles per cell.

    Parameters
    ----------
    rng
        The scenario's random stream.
    name
        The task's name.

    Returns
    -------
    Generated
        The task and a certified collision-free path (with the 0.15 m margin).
    """
    rows, cols = HARD.rows, HARD.cols
    cw, ch = 10.0 / cols, 10.0 / rows
    pairs = _door_pairs(rows, cols)

    def attempt() -> Generated | None:
        present = rng.random(len(pairs)) < HARD.door_probability
        along = rng.uniform(0.0, 1.0, size=len(pairs))
        doors = []
        for (a, b), keep, t in zip(pairs, present, along, strict=True):
            if not keep:
                continue
            edge = ch if a[0] == b[0] else cw
            lo = HARD.door_width / 2 + HARD.corner_clearance
            offset = round((lo + t * (edge - 2 * lo)) / edge, 3)
            doors.append(Door(cells=(a, b), offset=offset, width=HARD.door_width))
        hops = _hops(doors, rows, cols)
        far = sorted(pair for pair, h in hops.items() if h >= HARD.min_door_hops)
        if not far:
            return None
        start_cell, goal_cell = far[int(rng.integers(len(far)))]

        def point_in(cell: tuple[int, int]) -> F:
            r, c = cell
            b = HARD.endpoint_border
            return rounded(
                [rng.uniform(c * cw + b, (c + 1) * cw - b), rng.uniform(r * ch + b, (r + 1) * ch - b)]
            )

        start, goal = point_in(start_cell), point_in(goal_cell)
        bare = MazeTask(
            name=name,
            x0=(float(start[0]), float(start[1])),
            goal=(float(goal[0]), float(goal[1])),
            rows=rows,
            cols=cols,
            doors=tuple(doors),
            wall_thickness=HARD.wall_thickness,
            margin=HARD.margin,
            start_tolerance=HARD.tolerance,
            goal_tolerance=HARD.tolerance,
            workspace=_WORKSPACE,
        )
        centers = np.asarray(bare.door_centers(), dtype=float).reshape(-1, 2)
        obstacles: list[Obstacle] = []
        for r in range(rows):
            for c in range(cols):
                own = [centers[i] for i, d in enumerate(doors) if (r, c) in d.cells]
                placed = _place(
                    rng,
                    count=HARD.obstacles_per_cell,
                    radius=HARD.radius,
                    box=(np.array([c * cw, r * ch]), np.array([(c + 1) * cw, (r + 1) * ch])),
                    gap=HARD.obstacle_gap,
                    keep_out=[(p, HARD.door_gap) for p in own]
                    + [(start, HARD.endpoint_gap), (goal, HARD.endpoint_gap)],
                    shrink_box=HARD.wall_gap,
                    pool=HARD.pool,
                )
                if placed is None:
                    return None
                obstacles += placed
        task = bare.model_copy(update={"obstacles": tuple(obstacles)})
        return _certified(task, task.goal, HARD.grid_spacing)

    return retry(attempt, what="a plan-hard maze with a collision-free path")
