"""plan-hard: a 3x3 maze with doors and small obstacles in every cell.

The expert way, in three steps:

1. **Which cells.** Search the door graph (:func:`audere.planners.cell_graph`, one node per cell,
   one edge per door) with :func:`audere.planners.astar_graph` for the sequence of cells from the
   start's cell to the goal's.
2. **How to cross them.** Rasterize the task's world, grown by its margin, into a fine occupancy
   grid (:func:`audere.planners.occupancy_grid`, 5 cm), block every grid cell outside the chosen
   maze cells (the door openings between consecutive cells stay open), and run
   :func:`audere.planners.astar` from ``x0`` to the goal. Its path through free grid cells is
   collision-free in the inflated world by construction. Should the corridor hold no path (a door
   choked by obstacles), the search runs again on the whole grid.
3. **Smooth.** :func:`audere.planners.shortcut` keeps a subsequence of the waypoints whose every
   new segment is checked exactly against the inflated world.
"""

from __future__ import annotations

import numpy as np

from audere.planners import OccupancyGrid, astar, astar_graph, cell_graph, occupancy_grid, shortcut
from audere.recipes import recipe
from audere.tasks import MazeTask, Solution

Cell = tuple[int, int]

__all__ = ["solve_plan_hard"]

RESOLUTION = 0.05
"""Occupancy grid cell side, metres: a door (1 m wide, 0.7 m once the walls grow by the 0.15 m
margin) spans 14 cells, the narrowest gaps between grown obstacles and walls several."""


@recipe("plan-hard", apis=("astar",))
def solve_plan_hard(task: MazeTask) -> Solution:
    """Solve a plan-hard maze: door-graph A*, fine-grid A* inside the chosen cells, shortcut.

    Parameters
    ----------
    task
        A :class:`audere.tasks.MazeTask` (``scenarios.make("plan-hard", seed=...)``).

    Returns
    -------
    audere.tasks.Solution
        Waypoints (k, 2) in metres from ``x0`` to the goal, collision-free in ``task.world()``.

    Raises
    ------
    RuntimeError
        When no path is found (never on the scenario's seeds: every maze is certified solvable).
    """
    start, goal = task.start, task.goal
    # 1. the cells to cross, by A* over the door graph
    doors = cell_graph(task)
    route = astar_graph(
        doors.adjacency, task.cell_of(start), task.cell_of(goal), coordinates=doors.coordinates
    )
    # 2. a fine grid of the world grown by the margin, restricted to those cells
    grid = occupancy_grid(task.world(inflated=False), resolution=RESOLUTION, margin=task.margin)
    attempts = [grid]
    if route.solved and route.nodes is not None:
        attempts.insert(0, _restricted(grid, task, route.nodes))
    for g in attempts:  # the corridor first; the whole grid if the corridor is choked
        path = astar(g, start, goal, connectivity=8, heuristic="octile")
        if path.solved and path.waypoints is not None:
            # 3. smooth, every new segment checked exactly against the inflated world
            return Solution(waypoints=shortcut(path.waypoints, task.world()))
    raise RuntimeError(f"{task.name}: no collision-free path found on a {RESOLUTION} m grid")


def _restricted(grid: OccupancyGrid, task: MazeTask, cells: tuple[Cell, ...]) -> OccupancyGrid:
    """``grid`` with every grid cell whose centre lies outside the maze ``cells`` blocked."""
    rows, cols = grid.shape
    index = np.stack(np.meshgrid(np.arange(rows), np.arange(cols), indexing="ij"), axis=-1)
    centres = grid.to_world(index.reshape(-1, 2))
    ws = task.workspace
    w, h = task.cell_size  # the maze cell of a point, as MazeTask.cell_of computes it, vectorized
    maze_col = np.clip((centres[:, 0] - ws.xmin) // w, 0, task.cols - 1).astype(int)
    maze_row = np.clip((centres[:, 1] - ws.ymin) // h, 0, task.rows - 1).astype(int)
    inside = np.zeros(rows * cols, dtype=bool)
    for r, c in cells:
        inside |= (maze_row == r) & (maze_col == c)
    return OccupancyGrid(
        origin=grid.origin, resolution=grid.resolution, blocked=grid.blocked | ~inside.reshape(rows, cols)
    )
