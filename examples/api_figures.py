"""Draw each of the eight APIs solving a benchmark scenario: the figures of the API pages.

Run it with ``python examples/api_figures.py [OUT_DIR]`` (default: the current directory; the docs'
figures are made with ``python examples/api_figures.py docs/images``). Each API is called the way
its documentation page shows, the solution is judged by the task's checker, and the task, the
trajectory and the verdict are drawn into ``api-<name>.png``.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

from audere import recipes, scenarios
from audere.controllers import pid
from audere.planners import grad
from audere.tasks import Solution
from audere.viz import plot


def _pid(task: Any) -> Solution:
    result = pid(task.dynamics, task.x0, task.reference, task.dt, u_min=task.u_min, u_max=task.u_max)
    return result.to_solution()


def _grad(task: Any) -> Solution:
    result = grad(
        task.model,
        task.x0,
        goal=task.goal,
        goal_on="position",
        goal_weight=10.0,
        obstacles=task.obstacles,
        margin=task.margin + 0.1,
        horizon=task.horizon,
        dt=task.dt,
        u_min=task.u_min,
        u_max=task.u_max,
        iterations=400,
        restarts=8,
        seed=0,
    )
    return result.to_solution()


# API -> (scenario, seed, solver); the recipes are the expert solutions built on each API
CASES: dict[str, tuple[str, int, Callable[[Any], Solution]]] = {
    "astar": ("plan-hard", 1, recipes.get_recipe("plan-hard").function),
    "rrt": ("plan-easy", 1, recipes.get_recipe("plan-easy").function),
    "cem": ("pendulum-swingup", 1, recipes.get_recipe("pendulum-swingup").function),
    "grad": ("reach-unicycle", 1, _grad),
    "milp": ("plan-stl", 1, recipes.get_recipe("plan-stl").function),
    "pid": ("track-car", 1, _pid),
    "lqr": ("track-double", 1, recipes.get_recipe("track-double").function),
    "mpc": ("track-car", 1, recipes.get_recipe("track-car").function),
}


def main() -> None:
    out = Path(sys.argv[1]) if len(sys.argv) > 1 else Path()
    out.mkdir(parents=True, exist_ok=True)
    for api, (scenario, seed, solver) in CASES.items():
        task = scenarios.make(scenario, seed=seed)
        solution = solver(task)
        report = task.check(solution)
        figure = plot(task, solution, report, title=f"{api} on {scenario} (seed {seed})")
        path = out / f"api-{api}.png"
        figure.savefig(path, dpi=90, bbox_inches="tight")
        print(f"{api:6} {scenario:17} {'passes' if report.success else 'FAILS'}  -> {path}")
        if not report.success:
            raise SystemExit(f"{api} did not solve {scenario} seed {seed}: {report.summary()}")


if __name__ == "__main__":
    main()
