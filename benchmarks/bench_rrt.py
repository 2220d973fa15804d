"""RRT and RRT* through OMPL (planners.rrt) against a pure-Python RRT, on plan-easy and plan-hard.

For every instance (plan-easy: the task's world, start x0, goal; plan-hard: ``task.world()``, which
holds the walls, inflated by the margin) the cases run one after the other, interleaved instance by
instance, so machine load hits all alike:

- ``baseline RRT``: benchmarks/_baseline_rrt.py (linear-scan nearest neighbour, 20 sampled points per
  edge, step 0.5 m, goal bias 0.05);
- ``OMPL RRT`` and ``OMPL RRT-Connect``: ``rrt(..., algorithm=...)``, simplification off, OMPL's
  default range (a fifth of the workspace diagonal, 2.8 m here), and again with ``range=1.0``;
- ``OMPL RRT* (first)``: ``rrt_star`` with ``stop_at_first=True``;
- ``OMPL RRT* 1 s`` and ``OMPL informed RRT* 1 s``: a 1 s budget, simplified (the defaults).

Time to first solution is reported twice for the OMPL planners: the whole ``rrt()`` call (input
checks, OMPL setup, solve, tree export) and the planner's own time to its first solution. Path
length is divided by the shortest collision-free length from a visibility graph
(benchmarks/_visibility.py): circles become 64-gons, inscribed for a lower bound and circumscribed
for an upper bound of the optimum; ratios use the lower bound (the conservative choice).

Run: ``python benchmarks/bench_rrt.py [--seeds N] [--budget SECONDS]``.
"""

from __future__ import annotations

import argparse
import statistics

import numpy as np
from _baseline_rrt import baseline_rrt  # benchmarks/ is on sys.path
from _harness import machine_summary
from _visibility import shortest_path_bounds

from audere.planners import rrt
from audere.scenarios import make


def _p95(values: list[float]) -> float:
    return float(np.percentile(values, 95))


def _length(path: np.ndarray, goal: tuple[float, float]) -> float:
    """Length of the path completed by a straight line to the goal (paths may stop within the tolerance)."""
    path = np.asarray(path, dtype=float)
    return float(np.hypot(*np.diff(path, axis=0).T).sum() + np.hypot(*(path[-1] - goal)))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=10, help="seeds per scenario (default 10)")
    parser.add_argument("--budget", type=float, default=1.0, help="RRT* budget in seconds (default 1)")
    args = parser.parse_args()
    rrt(make("plan-easy", 0).world(), (0.5, 0.5), (9.5, 9.5), algorithm="rrt")  # import and warm up OMPL

    print(machine_summary())
    print()
    for scenario in ("plan-easy", "plan-hard"):
        call: dict[str, list[float]] = {}
        inner: dict[str, list[float]] = {}
        ratio: dict[str, list[float]] = {}
        gaps: list[float] = []
        baseline_misses = 0
        failures: dict[str, int] = {}
        for seed in range(args.seeds):
            task = make(scenario, seed)
            world = task.world()  # inflated by the margin; plan-hard: with the walls
            start, goal = task.start, (float(task.goal[0]), float(task.goal[1]))
            tol = task.goal_tolerance
            lower, upper = shortest_path_bounds(world, start, goal)
            gaps.append(upper / lower - 1)

            path, seconds, _ = baseline_rrt(world, start, goal, goal_tolerance=tol, seed=seed)
            label = "baseline RRT"
            if path is None:
                failures[label] = failures.get(label, 0) + 1
            else:
                call.setdefault(label, []).append(seconds)
                ratio.setdefault(label, []).append(_length(np.asarray(path), goal) / lower)
                baseline_misses += world.first_collision(path) is not None

            runs = {
                "OMPL RRT": {"algorithm": "rrt", "simplify": False, "time_limit": 30.0},
                "OMPL RRT-Connect": {"algorithm": "rrt_connect", "simplify": False, "time_limit": 30.0},
                "OMPL RRT, range 1 m": {
                    "algorithm": "rrt",
                    "range": 1.0,
                    "simplify": False,
                    "time_limit": 30.0,
                },
                "OMPL RRT-Connect, range 1 m": {
                    "algorithm": "rrt_connect",
                    "range": 1.0,
                    "simplify": False,
                    "time_limit": 30.0,
                },
                "OMPL RRT* (first)": {"algorithm": "rrt_star", "stop_at_first": True, "simplify": False},
                "OMPL RRT* 1 s": {"algorithm": "rrt_star", "time_limit": args.budget},
                "OMPL informed RRT* 1 s": {"algorithm": "informed_rrt_star", "time_limit": args.budget},
            }
            for label, options in runs.items():
                result = rrt(world, start, goal, goal_tolerance=tol, seed=seed, **options)  # type: ignore[arg-type]
                if not result.solved or result.waypoints is None:
                    failures[label] = failures.get(label, 0) + 1
                    continue
                if world.first_collision(result.waypoints) is not None:
                    failures[label] = failures.get(label, 0) + 1
                if "1 s" not in label:
                    call.setdefault(label, []).append(result.solve_time)
                    inner.setdefault(label, []).append(result.first_solution_time or result.solve_time)
                ratio.setdefault(label, []).append(_length(result.waypoints, goal) / lower)
                if label == "OMPL RRT":  # the same run (same seed) with the simplifier on
                    simplified = rrt(world, start, goal, goal_tolerance=tol, seed=seed, algorithm="rrt")
                    if simplified.waypoints is not None:
                        ratio.setdefault("OMPL RRT, simplified", []).append(
                            _length(simplified.waypoints, goal) / lower
                        )
                if "RRT* 1 s" in label and result.raw_waypoints is not None:
                    raw = _length(result.raw_waypoints, goal) / lower
                    ratio.setdefault(label + ", before simplification", []).append(raw)

        base = statistics.median(call["baseline RRT"])
        print(f"### {scenario}: time to first solution ({args.seeds} seeds)")
        print()
        print(
            "| planner | whole call, median | p95 | speed-up vs baseline (median) "
            "| planner's own, median | p95 | speed-up |"
        )
        print("|---|---:|---:|---:|---:|---:|---:|")
        for label, values in call.items():
            own = inner.get(label, values)
            print(
                f"| {label} | {1e3 * statistics.median(values):.2f} ms | {1e3 * _p95(values):.2f} ms "
                f"| {base / statistics.median(values):.1f}x | {1e3 * statistics.median(own):.3f} ms "
                f"| {1e3 * _p95(own):.3f} ms | {base / statistics.median(own):.0f}x |"
            )
        print()
        print(f"### {scenario}: path length / shortest path (visibility graph lower bound)")
        print()
        print("| planner | median | p95 | max |")
        print("|---|---:|---:|---:|")
        for label, values in ratio.items():
            print(f"| {label} | {statistics.median(values):.4f} | {_p95(values):.4f} | {max(values):.4f} |")
        print()
        print(
            f"Optimum bounds: circumscribed / inscribed 64-gons differ by at most {100 * max(gaps):.4f} %. "
            f"Baseline paths that fail the exact collision check (sampled edge checks missed): "
            f"{baseline_misses} of {len(call['baseline RRT'])}. Unsolved or invalid: {failures or 'none'}."
        )
        print()


if __name__ == "__main__":
    main()
