"""Recipe for ``reach-unicycle``: one open-loop MPC (IPOPT) over the whole horizon, around circles.

The whole manoeuvre is planned at once: a strong terminal weight on the goal position, a small input
weight, the task's input bounds, the workspace as position bounds and the circles as constraints
inflated by the task's margin plus a safety allowance. The MPC imposes the circles at every
position and at every segment's midpoint, while the checker tests whole segments exactly: the
allowance covers the chord between the two. Obstacles make the problem nonconvex, so when the
first plan (started from rest) is caught behind a circle, the recipe restarts IPOPT from manoeuvres
that first turn left or right, and keeps the first plan that meets the task's criteria, judged
from the task's own data (code written for the agent runs without the checker).
"""

from __future__ import annotations

import math
from collections.abc import Iterator

import numpy as np
from numpy.typing import NDArray

from audere.controllers import mpc
from audere.recipes import recipe
from audere.tasks import ReachAvoidTask, Solution

__all__ = ["solve_reach_unicycle"]

SAFETY = 0.1
"""Extra clearance (metres) on top of the task's margin: covers segments between constrained points."""

TURNS = (0.4, -0.4, 0.8, -0.8)
"""Turn rates (rad/s) of the restart manoeuvres, held for the first few steps."""


def _initial_guesses(task: ReachAvoidTask) -> Iterator[NDArray[np.float64] | None]:
    """Rest first, then: accelerate while turning at each rate in :data:`TURNS`."""
    yield None
    for turn in TURNS:
        inputs = np.zeros((task.horizon, 2))
        inputs[:6, 0] = turn
        inputs[:4, 1] = 0.5
        yield inputs


@recipe("reach-unicycle", apis=("mpc",))
def solve_reach_unicycle(task: ReachAvoidTask) -> Solution:
    """Reach the goal of a ``reach-unicycle`` task around its circles with open-loop MPC.

    Parameters
    ----------
    task
        A ``reach-unicycle`` task (unicycle, goal position, circles, a margin).

    Returns
    -------
    audere.tasks.Solution
        The planned inputs (and their rollout), judged by ``task.check``; the first plan that meets
        the task's criteria (:func:`_meets_task`), else the first plan.
    """
    ws = task.workspace
    attempts: list[Solution] = []
    for guess in _initial_guesses(task):
        result = mpc(
            task.model or "unicycle",
            task.x0,
            goal=task.goal,
            steps=task.horizon,
            horizon=task.horizon,
            dt=task.dt,
            Q=0.0,  # only the end matters ...
            R=0.1,
            Qf=100.0,  # ... and it matters a lot
            u_min=task.u_min,
            u_max=task.u_max,
            x_min=[ws.xmin, ws.ymin, -math.inf, -math.inf],
            x_max=[ws.xmax, ws.ymax, math.inf, math.inf],
            obstacles=task.obstacles,
            margin=task.margin + SAFETY,
            mode="open_loop",
            method=task.integrator,
            initial_inputs=guess,
        )
        solution: Solution = result.to_solution()
        if _meets_task(task, solution):
            return solution
        attempts.append(solution)
    return attempts[0]


def _meets_task(task: ReachAvoidTask, solution: Solution) -> bool:
    """What the checker asks, judged from the task's own data (the agent's code has no checker):
    the final position within the goal tolerance, every position and segment in the workspace and
    clear of the obstacles grown by the margin."""
    if solution.states is None or task.model is None:
        return False
    positions = np.asarray(task.model.position(np.asarray(solution.states)))
    world = task.world()  # grown by the task's margin
    reached = float(np.hypot(*(positions[-1] - np.asarray(task.goal_position)))) <= task.goal_tolerance
    return reached and bool(world.in_workspace(positions).all()) and world.first_collision(positions) is None
