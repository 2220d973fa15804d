"""Recipe for ``plan-stl``: the STL specification solved exactly as a mixed-integer program.

All five regions of plan-stl (key A, walls B and C, door D, goal E) are axis-aligned rectangles, so
:func:`audere.planners.milp` encodes the robustness of the whole specification exactly. The
recipe asks for the most robust trajectory up to a cap of 0.1 m: any trajectory with robustness
0.1 m is comfortably accepted by the strict checker, and the solver stops as soon as it finds one
instead of proving the true maximum (several times faster). If the time budget runs out, an
incumbent trajectory is still feasible (robustness >= ``margin`` > 0) and is returned.
"""

from __future__ import annotations

from audere.planners import milp
from audere.recipes import recipe
from audere.tasks import Solution, STLTask

__all__ = ["solve_plan_stl"]


@recipe("plan-stl", apis=("milp",))
def solve_plan_stl(task: STLTask) -> Solution:
    """Satisfy the specification of a ``plan-stl`` task with the STL MILP.

    Parameters
    ----------
    task
        A ``plan-stl`` task (single integrator, box regions, spec of horizon 20).

    Returns
    -------
    audere.tasks.Solution
        The planned inputs and states (horizon+1, 2), judged by ``task.check``.
    """
    result = milp(
        task.formula,
        task.regions,  # all Rectangles in plan-stl
        task.x0,
        horizon=task.horizon,
        dt=task.dt,
        u_min=task.u_min,
        u_max=task.u_max,
        workspace=task.workspace,
        obstacles=task.obstacles,  # none in plan-stl (the walls are in the spec), and margin is 0
        objective="max_robustness",
        robustness_cap=0.1,
        time_limit=30.0,
    )
    if result.states is None:  # pragma: no cover - never happened on seeds 0..99
        raise RuntimeError(f"plan-stl: the MILP found no trajectory: {result.status}, {result.message}")
    solution: Solution = result.to_solution()
    return solution
