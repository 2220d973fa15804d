"""STL MILP on plan-stl: solve time (building included) over seeds, per solver, and the checker's verdict.

Runs ``planners.milp`` as the plan-stl recipe calls it (max robustness capped at 0.1 m) on seeds
0..99 with HiGHS, and with every other installed MILP solver asked for (``--solvers``), the solvers
interleaved seed by seed so that load changes hit them alike. ``--objectives`` adds, on fewer seeds,
the uncapped maximum robustness and the minimum effort with HiGHS.

    python benchmarks/bench_milp.py                      # HiGHS, 100 seeds
    python benchmarks/bench_milp.py --solvers HIGHS GUROBI --objectives

Gurobi needs ``gurobipy`` importable (not an audere dependency; its pip wheel has a size-limited
license), e.g. ``pip install --target /tmp/gurobi_site gurobipy`` and ``PYTHONPATH=/tmp/gurobi_site``.
"""

from __future__ import annotations

import argparse
import statistics
from collections.abc import Callable
from functools import partial

import numpy as np
from _harness import compare, machine_summary

from audere import scenarios
from audere.planners import MILPResult, milp
from audere.planners._milp import installed_mip_solvers
from audere.tasks import STLTask


def _solve(
    task: STLTask, *, solver: str, objective: str, cap: float | None, limit: float, out: list[MILPResult]
) -> None:
    out.append(
        milp(
            task.formula,
            task.regions,
            task.x0,
            horizon=task.horizon,
            dt=task.dt,
            u_min=task.u_min,
            u_max=task.u_max,
            workspace=task.workspace,
            objective=objective,  # type: ignore[arg-type]
            robustness_cap=cap,
            solver=solver,
            time_limit=limit,
        )
    )


def _row(label: str, tasks: list[STLTask], results: list[MILPResult], wall: list[float]) -> str:
    times = np.array([r.solve_time for r in results])
    ok = sum(
        r.states is not None and t.check(r.to_solution()).success for t, r in zip(tasks, results, strict=True)
    )
    statuses = ", ".join(f"{s} {n}" for s, n in sorted(_count([r.status for r in results]).items()))
    binaries = statistics.median(r.n_binaries for r in results)
    return (
        f"| {label} | {len(results)} | {np.median(times):.3f} s | {np.percentile(times, 95):.3f} s "
        f"| {times.max():.3f} s | {np.median(wall):.3f} s | {ok}/{len(results)} | {statuses} "
        f"| {binaries:.0f} |"
    )


def _count(items: list[str]) -> dict[str, int]:
    out: dict[str, int] = {}
    for item in items:
        out[item] = out.get(item, 0) + 1
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=100, help="number of plan-stl seeds (0..n-1)")
    parser.add_argument("--solvers", nargs="+", default=["HIGHS"], help="cvxpy MILP solver names")
    parser.add_argument("--objectives", action="store_true", help="also uncapped max robustness, min effort")
    parser.add_argument("--objective-seeds", type=int, default=5, help="seeds for --objectives")
    parser.add_argument("--time-limit", type=float, default=30.0, help="solver time limit, seconds")
    args = parser.parse_args()
    installed = installed_mip_solvers()
    solvers = [s.upper() for s in args.solvers if s.upper() in installed]
    skipped = [s for s in args.solvers if s.upper() not in installed]
    tasks = [scenarios.make("plan-stl", seed=seed) for seed in range(args.seeds)]

    limit = args.time_limit
    cases: dict[str, tuple[str, str, float | None, int]] = {
        f"{s}, max robustness capped at 0.1 (recipe)": (s, "max_robustness", 0.1, args.seeds) for s in solvers
    }
    if args.objectives:
        cases["HIGHS, max robustness (uncapped)"] = ("HIGHS", "max_robustness", None, args.objective_seeds)
        cases["HIGHS, min effort (margin 1e-3)"] = ("HIGHS", "min_effort", None, args.objective_seeds)
    results: dict[str, list[MILPResult]] = {label: [] for label in cases}
    wall: dict[str, list[float]] = {label: [] for label in cases}
    # warm-up: imports (cvxpy, the solvers) are not part of a solve
    for solver, objective, cap, _ in {(s, "max_robustness", 0.1, 0) for s in solvers}:
        _solve(tasks[0], solver=solver, objective=objective, cap=cap, limit=limit, out=[])
    for i, task in enumerate(tasks):
        run: dict[str, Callable[[], object]] = {
            label: partial(_solve, task, solver=s, objective=o, cap=c, limit=limit, out=results[label])
            for label, (s, o, c, n) in cases.items()
            if i < n
        }
        for timing in compare(run, repeat=1, warmup=0):
            wall[timing.label].append(timing.min)

    print(machine_summary())
    print()
    print(f"### plan-stl with planners.milp (time limit {limit:g} s)")
    print()
    print("| case | seeds | median | p95 | max | median wall | task.check | status | binaries |")
    print("|---|---:|---:|---:|---:|---:|---:|---|---:|")
    for label, (_, _, _, n) in cases.items():
        print(_row(label, tasks[:n], results[label], wall[label]))
    print()
    print("median / p95 / max: MILPResult.solve_time (building the program + cvxpy + solver), seconds;")
    print("median wall: the whole call, timed by the harness.")
    if skipped:
        print(f"\nSkipped (not installed): {', '.join(skipped)}; installed: {', '.join(installed)}")


if __name__ == "__main__":
    main()
