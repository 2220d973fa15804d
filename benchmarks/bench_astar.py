"""A*: grid size against solve time, and the plan-hard recipe over 100 seeds.

Two tables:

1. ``astar`` on random N x N grids (20 % of the cells blocked at random, start and goal at opposite
   corners, 8-connected, octile heuristic) and on empty ones, with Dijkstra (``heuristic="zero"``)
   as the baseline of each size; ``occupancy_grid`` on a plan-hard world at several resolutions.
2. The plan-hard recipe on seeds 0..N-1: success rate under ``Task.check``, median and p95 time.

Run: ``python benchmarks/bench_astar.py [--seeds N] [--repeat R]``.
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Callable

import numpy as np
from _harness import compare, machine_summary, markdown_table  # benchmarks/ is on sys.path

from audere import scenarios
from audere.planners import OccupancyGrid, astar, occupancy_grid
from audere.recipes._plan_hard import solve_plan_hard


def _grid(n: int, density: float, seed: int = 0) -> OccupancyGrid:
    blocked = np.random.default_rng(seed).random((n, n)) < density
    blocked[:3, :3] = blocked[-3:, -3:] = False  # open corners: the start and goal are not walled in
    return OccupancyGrid(origin=(0.0, 0.0), resolution=10.0 / n, blocked=blocked)


def _case(grid: OccupancyGrid, heuristic: str) -> Callable[[], object]:
    far = 10.0 - 1e-6
    return lambda: astar(grid, (1e-6, 1e-6), (far, far), heuristic=heuristic)  # type: ignore[arg-type]


def grid_table(repeat: int) -> str:
    lines = []
    for n in (50, 100, 200, 400):
        for label, density in (("random 20 %", 0.20), ("empty", 0.0)):
            grid = _grid(n, density)
            r = astar(grid, (1e-6, 1e-6), (10 - 1e-6, 10 - 1e-6))
            timings = compare(
                {
                    f"{n}x{n} {label}, octile": _case(grid, "octile"),
                    f"{n}x{n} {label}, zero": _case(grid, "zero"),
                },
                repeat=repeat,
            )
            lines.append(
                markdown_table(
                    timings,
                    baseline=f"{n}x{n} {label}, zero",
                    title=f"astar {n}x{n} {label}: {r.status}, {r.expanded} nodes expanded (octile)",
                )
            )
    task = scenarios.make("plan-hard", seed=0)
    world = task.world(inflated=False)
    cases = {
        f"occupancy_grid plan-hard, {h} m": (lambda h=h: occupancy_grid(world, resolution=h, margin=0.15))
        for h in (0.2, 0.1, 0.05)
    }
    lines.append(markdown_table(compare(cases, repeat=repeat), baseline="occupancy_grid plan-hard, 0.05 m"))
    return "\n\n".join(lines)


def recipe_table(seeds: int) -> str:
    times, failures = [], []
    for seed in range(seeds):
        task = scenarios.make("plan-hard", seed=seed)
        t0 = time.perf_counter()
        solution = solve_plan_hard(task)
        times.append(time.perf_counter() - t0)
        if not task.check(solution).success:
            failures.append(seed)
    p95 = float(np.percentile(times, 95))
    return "\n".join(
        [
            f"plan-hard recipe, seeds 0..{seeds - 1}",
            "",
            "| seeds | passed | median (s) | p95 (s) | max (s) |",
            "|---:|---:|---:|---:|---:|",
            f"| {seeds} | {seeds - len(failures)} | {statistics.median(times):.3f} | {p95:.3f} "
            f"| {max(times):.3f} |",
            "",
            f"failing seeds: {failures or 'none'}",
        ]
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--seeds", type=int, default=100, help="plan-hard seeds (default 100)")
    parser.add_argument("--repeat", type=int, default=5, help="timed repeats per grid case (default 5)")
    args = parser.parse_args()
    print(machine_summary())
    print()
    print(grid_table(args.repeat))
    print()
    print(recipe_table(args.seeds))


if __name__ == "__main__":
    main()
