"""Recipe for ``track-lin``: LQR tracking of the reference with a single integrator.

The reference is a sequence of positions the single integrator can follow exactly within its
speed bound, so the feed-forward inputs LQR infers from it (``(x_ref[k+1] - x_ref[k]) / dt``)
already track it perfectly; the feedback only matters if the start is off the reference.
"""

from __future__ import annotations

from audere.apis import Result
from audere.controllers import lqr
from audere.recipes import recipe
from audere.tasks import Solution, TrackingTask

__all__ = ["solve_track_lin"]


@recipe("track-lin", apis=("lqr",))
def solve_track_lin(task: TrackingTask) -> Solution:
    """Track the reference of a ``track-lin`` task with LQR.

    Parameters
    ----------
    task
        A ``track-lin`` task (single integrator, reference of shape (horizon+1, 2)).

    Returns
    -------
    audere.tasks.Solution
        The closed-loop inputs (and states), judged by ``task.check``.
    """
    result: Result = lqr(
        task.model or "single_integrator",
        task.x0,
        task.reference,
        dt=task.dt,
        u_min=task.u_min,
        u_max=task.u_max,
        state_weight=1.0,
        input_weight=0.1,
        method=task.integrator,
    )
    solution: Solution = result.to_solution()
    return solution
