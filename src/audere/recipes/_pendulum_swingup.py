"""Recipe for ``pendulum-swingup``: a cross-entropy swing-up, then LQR holds the pendulum upright.

The motor is too weak to lift the pendulum directly (3.5 N m against m g l = 9.81 N m), so the
inputs must pump energy over several swings: a non-convex problem that suits a sampling optimizer,
while holding the upright equilibrium is a textbook job for LQR. The recipe:

1. **CEM swing-up** over the first 70 % of the horizon, with a cost that pulls towards the upright
   state at the end of that window and, more weakly, all along the way
   (``goal_cost(..., running_weight=1)``);
2. **CEM refinement** of that sequence with a small sampling spread on the squared (wrapped)
   distance to the upright state, until it is within a quarter of the tolerance;
3. **LQR stabilization** for the remaining steps: a stationary regulator around ``(pi, 0)`` with the
   angle error wrapped, which drives the pendulum to the equilibrium and keeps it there.

If the hand-over fails (LQR does not end well within the tolerance), the recipe falls back to the
same two CEM stages over the whole horizon.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from audere.apis import Result
from audere.controllers import lqr
from audere.errors import InvalidArgumentError
from audere.planners import cem, goal_cost
from audere.recipes import recipe
from audere.tasks import ReachAvoidTask, Solution

__all__ = ["solve_pendulum_swingup"]

SWING_FRACTION = 0.7
"""Share of the horizon given to the swing-up; LQR holds the pendulum for the rest."""


def _swing_up(task: ReachAvoidTask, horizon: int) -> Result:
    """CEM swing-up to the goal state at step ``horizon``, then a CEM refinement of it."""
    goal = np.asarray(task.goal, dtype=np.float64)
    angles = tuple(task.angle_indices)
    common: dict[str, Any] = {
        "horizon": horizon,
        "dt": task.dt,
        "u_min": task.u_min,
        "u_max": task.u_max,
        "method": task.integrator,
        "population": 256,
        "elite_fraction": 0.1,
        "smoothing": 0.1,
        "seed": 0,
    }
    # 1. Global search: get up there, preferably early.
    swing = cem(
        task.model,
        task.x0,
        cost=goal_cost(goal, weight=[1.0, 0.1], running_weight=1.0, angle_indices=angles),
        iterations=60,
        **common,
    )
    # 2. Local refinement on the squared wrapped distance to the goal state at the end.
    refined = cem(
        task.model,
        task.x0,
        goal=goal,
        angle_indices=angles,
        iterations=40,
        init_mean=swing.inputs,
        init_std=0.5,
        target_cost=(0.25 * task.goal_tolerance) ** 2,
        **common,
    )
    better: Result = refined if (refined.cost or math.inf) <= (swing.cost or math.inf) else swing
    return better


@recipe("pendulum-swingup", apis=("cem", "lqr"))
def solve_pendulum_swingup(task: ReachAvoidTask) -> Solution:
    """Swing the pendulum up with CEM and hold it upright with LQR.

    Parameters
    ----------
    task
        A ``pendulum-swingup`` task (goal state ``(pi, 0)``, ``goal_on="state"``, angle index 0).

    Returns
    -------
    audere.tasks.Solution
        The input sequence (horizon, 1) in N m, judged by ``task.check``.
    """
    model = task.model
    if model is None:  # pragma: no cover - the scenario always has a model
        raise InvalidArgumentError("task must have the pendulum model, got dynamics=None")
    goal = np.asarray(task.goal, dtype=np.float64)
    swing_steps = max(1, int(SWING_FRACTION * task.horizon))
    swing = _swing_up(task, swing_steps)
    if swing.inputs is not None and swing.states is not None:
        # 3. LQR from the end of the swing-up: regulate to the upright equilibrium.
        rest = task.horizon - swing_steps
        hold = lqr(
            model,
            swing.states[-1],
            goal,
            dt=task.dt,
            reference_inputs=np.zeros((rest, model.n_u)),
            state_weight=[10.0, 1.0],
            input_weight=0.1,
            u_min=task.u_min,
            u_max=task.u_max,
            angle_indices=tuple(task.angle_indices),
            method=task.integrator,
        )
        if hold.solved and hold.inputs is not None and hold.tracking_error[-1] < 0.5 * task.goal_tolerance:
            return Solution(inputs=np.concatenate([swing.inputs, hold.inputs]))
    # Fallback: the swing-up over the whole horizon, ending at the goal.
    whole = _swing_up(task, task.horizon)
    if whole.inputs is None:  # pragma: no cover - cem returns a sequence for finite costs
        raise RuntimeError(f"CEM returned no input sequence: {whole.message}")
    return Solution(inputs=whole.inputs)
