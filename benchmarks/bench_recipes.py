"""The expert recipes on every scenario: success rate, median and p95 solve time.

Each recipe (audere.recipes) solves the first N seeds of its scenario; ``Task.check`` judges each
solution. Solve time is the wall-clock time of the recipe call (generation and checking excluded).
The first call of each recipe is preceded by one untimed warm-up solve (seed N, not counted), so that
one-off imports (torch, casadi, control, cvxpy, ompl) do not land in the statistics.

Run: ``python benchmarks/bench_recipes.py [--seeds N] [--scenarios a,b,...]``.
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from _harness import machine_summary  # benchmarks/ is on sys.path

from audere.recipes import get_recipe
from audere.scenarios import list_scenarios, make


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=100, help="seeds 0..N-1 of every scenario")
    parser.add_argument("--scenarios", default="", help="comma-separated subset (default: all)")
    args = parser.parse_args()
    names = [s.name for s in list_scenarios()]
    if args.scenarios:
        names = [n for n in args.scenarios.split(",") if n]
    print(machine_summary())
    print()
    print("| scenario | recipe APIs | success | median solve | p95 solve | max solve |")
    print("|---|---|---:|---:|---:|---:|")
    failures: list[str] = []
    for name in names:
        recipe = get_recipe(name)
        recipe.function(make(name, args.seeds))  # warm-up: imports and first compilations
        times, ok = [], 0
        for seed in range(args.seeds):
            task = make(name, seed)
            start = time.perf_counter()
            solution = recipe.function(task)
            times.append(time.perf_counter() - start)
            report = task.check(solution)
            if report.success:
                ok += 1
            else:
                failures.append(f"{task.name}: {report.summary()}")
        t = np.asarray(times)
        print(
            f"| {name} | {', '.join(recipe.apis)} | {ok}/{args.seeds} | {np.median(t):.3f} s "
            f"| {np.percentile(t, 95):.3f} s | {t.max():.3f} s |",
            flush=True,
        )
    for line in failures:
        print("FAILED", line)
    return 1 if failures else 0


if __name__ == "__main__":
    raise SystemExit(main())
