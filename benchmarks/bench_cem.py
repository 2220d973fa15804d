"""CEM: time against population size, and the pendulum-swingup recipe over seeds.

Two tables:

1. ``cem`` on pendulum-swingup seed 0 (horizon 100, 20 iterations) with populations 64, 256 and
   1024: the cost of the batched numpy rollouts as the batch grows;
2. the pendulum-swingup recipe (CEM swing-up, CEM refinement, LQR at the top) on seeds 0..N-1:
   success under ``Task.check``, median and p95 time per task.

Run: ``python benchmarks/bench_cem.py [--seeds N] [--repeat R]``.
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Callable

import numpy as np
from _harness import compare, machine_summary, markdown_table  # benchmarks/ is on sys.path

from audere import scenarios
from audere.planners import cem
from audere.recipes._pendulum_swingup import solve_pendulum_swingup


def _case(population: int) -> Callable[[], object]:
    task = scenarios.make("pendulum-swingup", seed=0)
    return lambda: cem(
        task.model,
        task.x0,
        goal=task.goal,
        angle_indices=(0,),
        horizon=task.horizon,  # type: ignore[arg-type]
        dt=task.dt,
        u_min=task.u_min,
        u_max=task.u_max,
        population=population,
        iterations=20,
    )


def population_table(repeat: int) -> str:
    cases = {f"population {n}": _case(n) for n in (64, 256, 1024)}
    timings = compare(cases, repeat=repeat)
    return markdown_table(
        timings, baseline="population 256", title="CEM, pendulum horizon 100, 20 iterations"
    )


def recipe_table(seeds: int) -> str:
    times, passed, distances = [], 0, []
    for seed in range(seeds):
        task = scenarios.make("pendulum-swingup", seed=seed)
        start = time.perf_counter()
        solution = solve_pendulum_swingup(task)
        times.append(time.perf_counter() - start)
        report = task.check(solution)
        passed += report.success
        distances.append(report.metrics["goal_distance"])
    return "\n".join(
        [
            "| scenario | passed | median time | p95 time | median / worst goal distance |",
            "|---|---|---|---|---|",
            f"| pendulum-swingup | {passed}/{seeds} | {statistics.median(times):.2f} s | "
            f"{float(np.percentile(times, 95)):.2f} s | "
            f"{statistics.median(distances):.3f} / {max(distances):.3f} |",
        ]
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=100)
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()
    print(machine_summary())
    print()
    print(population_table(args.repeat))
    print()
    print(recipe_table(args.seeds))


if __name__ == "__main__":
    main()
