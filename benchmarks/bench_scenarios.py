"""Scenario generation: 100 seeds of every scenario, timed, then every task validated and solved.

The issue's target: generating 100 seeds of each scenario takes under 5 s in total. Validation is
not timed: every task is re-validated from its JSON, generated twice to check determinism, and its
witness (built by the generator, or by an energy-pumping controller for the pendulum) must pass
``Task.check``.

Run: ``python benchmarks/bench_scenarios.py [--seeds N] [--repeat R]``.
"""

from __future__ import annotations

import argparse
import sys
import time
from functools import partial
from pathlib import Path

from _harness import compare, machine_summary, markdown_table  # benchmarks/ is on sys.path

from audere.scenarios import list_scenarios, make
from audere.scenarios._registry import generate
from audere.tasks import ReachAvoidTask, TaskAdapter

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from scenarios.witnesses import swing_up_any  # the tests' swing-up controller (pendulum witness)


def _generate_all(name: str, seeds: int) -> None:
    for seed in range(seeds):
        make(name, seed)


def _validate(name: str, seeds: int) -> list[str]:
    """Problems found in the first ``seeds`` tasks of ``name`` (empty when all is well)."""
    problems = []
    for seed in range(seeds):
        generated = generate(name, seed)
        task = generated.task
        text = task.to_json()
        if TaskAdapter.validate_json(text) != task:
            problems.append(f"{task.name}: does not round-trip through JSON")
        if make(name, seed).to_json() != text:
            problems.append(f"{task.name}: not deterministic")
        if generated.witness is not None:
            solution = generated.witness()
        else:
            assert isinstance(task, ReachAvoidTask)
            solution, _ = swing_up_any(task)
        report = task.check(solution)
        if not report.success:
            problems.append(f"{task.name}: witness fails: {report.summary()}")
    return problems


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=100, help="seeds per scenario (default 100)")
    parser.add_argument("--repeat", type=int, default=3, help="timed repeats (default 3)")
    args = parser.parse_args()
    names = [s.name for s in list_scenarios()]
    cases = {name: partial(_generate_all, name, args.seeds) for name in names}
    timings = compare(cases, repeat=args.repeat, warmup=1)
    total_min = sum(t.min for t in timings)
    total_median = sum(t.median for t in timings)
    print(machine_summary())
    print()
    print(
        markdown_table(timings, title=f"Generating {args.seeds} seeds of each scenario (time per scenario)")
    )
    print()
    print(
        f"**Total for {args.seeds} seeds of all {len(names)} scenarios: {total_median:.2f} s median, "
        f"{total_min:.2f} s min** (target: under 5 s for 100 seeds; per task: "
        f"{1e3 * total_median / (args.seeds * len(names)):.1f} ms median)"
    )
    print()
    start = time.perf_counter()
    problems = [p for name in names for p in _validate(name, args.seeds)]
    elapsed = time.perf_counter() - start
    if problems:
        print(f"Validation FAILED ({len(problems)} problems):")
        for p in problems[:20]:
            print(f"- {p}")
        raise SystemExit(1)
    print(
        f"Validation: all {args.seeds * len(names)} tasks valid, deterministic and solved by their "
        f"witness ({elapsed:.1f} s)."
    )


if __name__ == "__main__":
    main()
