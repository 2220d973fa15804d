"""Recipe for ``track-double``: LQR tracking of a state reference with a double integrator.

The reference holds full states (position and velocity) reachable within the acceleration
bound, so the feed-forward accelerations LQR infers from it (``(v_ref[k+1] - v_ref[k]) / dt``) follow
it exactly; position errors are weighted ten times more than velocity errors.
"""

from __future__ import annotations

from audere.apis import Result
from audere.controllers import lqr
from audere.recipes import recipe
from audere.tasks import Solution, TrackingTask

__all__ = ["solve_track_double"]


@recipe("track-double", apis=("lqr",))
def solve_track_double(task: TrackingTask) -> Solution:
    """Track the state reference of a ``track-double`` task with LQR.

    Parameters
    ----------
    task
        A ``track-double`` task (double integrator, reference of shape (horizon+1, 4)).

    Returns
    -------
    audere.tasks.Solution
        The closed-loop inputs (and states), judged by ``task.check``.
    """
    result: Result = lqr(
        task.model or "double_integrator",
        task.x0,
        task.reference,
        dt=task.dt,
        u_min=task.u_min,
        u_max=task.u_max,
        state_weight=[10.0, 10.0, 1.0, 1.0],
        input_weight=1.0,
        method=task.integrator,
    )
    solution: Solution = result.to_solution()
    return solution
