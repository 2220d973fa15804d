"""plan-easy: a point path between two far-apart points among twelve circles and squares.

The expert way is one call: an asymptotically optimal sampling planner (:func:`audere.planners.rrt`
with informed RRT*, which after its first solution samples only where a shorter path can be) on the
task's world, with the task's clearance margin and goal tolerance, then OMPL's path simplifier.
Every motion the planner considers is checked exactly, so the path passes ``task.check``. A short
budget is enough: the first solution comes within milliseconds and the rest of the budget shortens
it. Should the budget ever run out without a path, RRT-Connect (the quickest to a first solution)
tries again with a longer one.
"""

from __future__ import annotations

from audere.planners import rrt
from audere.recipes import recipe
from audere.tasks import ReachAvoidTask, Solution

__all__ = ["solve_plan_easy"]

TIME_LIMIT = 0.2
"""Planning budget of the first attempt, seconds."""


@recipe("plan-easy", apis=("rrt",))
def solve_plan_easy(task: ReachAvoidTask) -> Solution:
    """Solve a plan-easy task with informed RRT* (RRT-Connect as a fallback).

    Parameters
    ----------
    task
        A path :class:`audere.tasks.ReachAvoidTask` (``scenarios.make("plan-easy", seed=...)``).

    Returns
    -------
    audere.tasks.Solution
        Waypoints (k, 2) in metres from ``x0`` to within ``goal_tolerance`` of the goal.

    Raises
    ------
    RuntimeError
        When neither attempt finds a path (never seen on the scenario's seeds).
    """
    world = task.world(inflated=False)  # rrt grows the obstacles by the margin itself
    result = rrt(
        world,
        task.x0,
        task.goal_position,
        algorithm="informed_rrt_star",
        time_limit=TIME_LIMIT,
        goal_tolerance=task.goal_tolerance,
        margin=task.margin,
    )
    if not result.solved:
        result = rrt(
            world,
            task.x0,
            task.goal_position,
            algorithm="rrt_connect",
            time_limit=5.0,
            goal_tolerance=task.goal_tolerance,
            margin=task.margin,
        )
    if not result.solved:
        raise RuntimeError(f"no path found for {task.name}: {result.status}: {result.message}")
    solution: Solution = result.to_solution()
    return solution
