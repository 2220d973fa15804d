"""LQR: stationary (one dlqr) against time-varying (backward Riccati) gains, and the tracking recipes.

Two tables:

1. ``lqr`` on the double integrator regulating to the origin over horizons of 20, 100 and 500 steps,
   ``mode="stationary"`` (python-control ``dlqr`` once) against ``mode="time_varying"`` (the
   backward recursion), both after a warm-up call that imports python-control;
2. the track-lin and track-double recipes on seeds 0..N-1: success under ``Task.check``, median and
   p95 time per task.

Run: ``python benchmarks/bench_lqr.py [--seeds N] [--repeat R]``.
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Callable

import numpy as np
from _harness import compare, machine_summary, markdown_table  # benchmarks/ is on sys.path

from audere import scenarios
from audere.controllers import lqr
from audere.recipes._track_double import solve_track_double
from audere.recipes._track_lin import solve_track_lin


def _case(horizon: int, mode: str) -> Callable[[], object]:
    reference = np.zeros((horizon + 1, 4))
    return lambda: lqr("double_integrator", [1.0, -1.0, 0.0, 0.0], reference, dt=0.1, mode=mode)  # type: ignore[arg-type]


def gains_table(repeat: int) -> str:
    lines = []
    for horizon in (20, 100, 500):
        cases = {
            f"stationary, T={horizon}": _case(horizon, "stationary"),
            f"time_varying, T={horizon}": _case(horizon, "time_varying"),
        }
        timings = compare(cases, repeat=repeat)
        lines.append(
            markdown_table(
                timings,
                baseline=f"stationary, T={horizon}",
                title=f"Double integrator regulation, horizon {horizon}",
            )
        )
    return "\n\n".join(lines)


def recipe_table(seeds: int) -> str:
    rows = ["| scenario | passed | median time | p95 time |", "|---|---|---|---|"]
    for name, solve in (("track-lin", solve_track_lin), ("track-double", solve_track_double)):
        times, passed = [], 0
        for seed in range(seeds):
            task = scenarios.make(name, seed=seed)
            start = time.perf_counter()
            solution = solve(task)
            times.append(time.perf_counter() - start)
            passed += task.check(solution).success
        p95 = float(np.percentile(times, 95))
        rows.append(
            f"| {name} | {passed}/{seeds} | {statistics.median(times) * 1e3:.1f} ms | {p95 * 1e3:.1f} ms |"
        )
    return "\n".join(rows)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=100)
    parser.add_argument("--repeat", type=int, default=7)
    args = parser.parse_args()
    print(machine_summary())
    print()
    print(gains_table(args.repeat))
    print()
    print(recipe_table(args.seeds))


if __name__ == "__main__":
    main()
