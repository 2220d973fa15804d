"""Recipe for ``track-car``: closed-loop nonlinear MPC of the unicycle along the reference positions.

The reference is the rollout of an admissible input sequence, so an exact tracker exists; a
receding-horizon MPC with IPOPT, the task's input bounds and the workspace as position bounds follows
it closely (mean error far below the 2 m tolerance). The simulation inside :func:`mpc` uses the
task's model, integrator and step, so the returned states are what the checker rolls out.
"""

from __future__ import annotations

import math

from audere.controllers import mpc
from audere.recipes import recipe
from audere.tasks import Solution, TrackingTask

__all__ = ["solve_track_car"]

HORIZON = 8
"""Prediction horizon, steps (8 s at the scenario's dt = 1 s)."""


@recipe("track-car", apis=("mpc",))
def solve_track_car(task: TrackingTask) -> Solution:
    """Track the reference of a ``track-car`` task with closed-loop MPC.

    Parameters
    ----------
    task
        A ``track-car`` task (unicycle, reference positions of shape (horizon+1, 2)).

    Returns
    -------
    audere.tasks.Solution
        The closed-loop inputs (and states), judged by ``task.check``.
    """
    ws = task.workspace
    result = mpc(
        task.model or "unicycle",
        task.x0,
        reference=task.reference,  # positions (x, y) per step: the position error is weighted
        steps=task.horizon,
        horizon=HORIZON,
        dt=task.dt,
        Q=1.0,
        R=0.1,
        Qf=1.0,
        u_min=task.u_min,
        u_max=task.u_max,
        x_min=[ws.xmin, ws.ymin, -math.inf, -math.inf],
        x_max=[ws.xmax, ws.ymax, math.inf, math.inf],
        method=task.integrator,
    )
    solution: Solution = result.to_solution()
    return solution
