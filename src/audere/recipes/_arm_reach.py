"""Recipe for ``arm-reach``: one open-loop MPC (IPOPT) of the two-link arm, the end effector around circles.

The goal is a planar position, so :func:`mpc` weights the end effector's position (the arm's
``position()``), not the joint angles: a strong terminal weight on it, a tiny torque weight, the
task's torque bounds, and the circles as constraints on the end effector's positions (and segment
midpoints) inflated by the task's margin plus a safety allowance for the segments the checker tests
exactly. When the first plan (started from rest) is caught behind a circle, the recipe restarts
IPOPT from bang-bang torque profiles in each of the four sign combinations and keeps the first plan
that meets the task's criteria, judged from the task's own data (code written for the agent runs
without the checker).
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
from numpy.typing import NDArray

from audere.controllers import mpc
from audere.recipes import recipe
from audere.tasks import ReachAvoidTask, Solution

__all__ = ["solve_arm_reach"]

SAFETY = 0.05
"""Extra clearance (metres) on top of the task's margin: covers segments between constrained points."""

TORQUE = 3.0
"""Torque (N m) of the restart profiles: +-TORQUE for the first half, the opposite for the second."""


def _initial_guesses(task: ReachAvoidTask) -> Iterator[NDArray[np.float64] | None]:
    """Rest first, then accelerate-decelerate torque profiles in each sign combination."""
    yield None
    half = task.horizon // 2
    for tau1 in (TORQUE, -TORQUE):
        for tau2 in (TORQUE, -TORQUE):
            inputs = np.zeros((task.horizon, 2))
            inputs[:half] = (tau1, tau2)
            inputs[half:] = (-tau1, -tau2)
            yield inputs


@recipe("arm-reach", apis=("mpc",))
def solve_arm_reach(task: ReachAvoidTask) -> Solution:
    """Move the end effector of an ``arm-reach`` task to its goal around the circles with open-loop MPC.

    Parameters
    ----------
    task
        An ``arm-reach`` task (two-link arm, goal position of the end effector, circles, a margin).

    Returns
    -------
    audere.tasks.Solution
        The planned torques (and their rollout), judged by ``task.check``; the first plan that
        meets the task's criteria (:func:`_meets_task`), else the first plan.
    """
    attempts: list[Solution] = []
    for guess in _initial_guesses(task):
        result = mpc(
            task.model or "two_link_arm",
            task.x0,
            goal=task.goal,  # a position (x, y): the end effector is steered, not the joints
            steps=task.horizon,
            horizon=task.horizon,
            dt=task.dt,
            Q=0.0,
            R=0.001,
            Qf=100.0,
            u_min=task.u_min,
            u_max=task.u_max,
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
