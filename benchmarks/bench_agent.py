"""Agent: the framework's overhead per round, everything but the model's own latency.

Each case solves ``--seeds`` seeds of a scenario with the offline expert through the full loop
(LiteLLM call, prompt, parsing, sandbox, checker) after one untimed warm-up solve that starts the
sandbox. Per round, the wall time splits into:

- **model**: waiting for the model (for the offline expert: LiteLLM's own overhead and the
  expert's answer, a few milliseconds);
- **code**: the model's code running in the sandbox child, which includes the APIs' own computing
  (RRT's planning budget, the MILP solve);
- **framework**: the rest: building prompts, parsing replies, the sandbox's fork, transport and
  sweep, the checker.

``wall - model`` is what the issue's target is about: everything except the model's latency.

Run: ``python benchmarks/bench_agent.py`` (about a minute on two cores; ``--seeds`` to change).
"""

from __future__ import annotations

import argparse
import statistics
import time

from _harness import machine_summary

from audere.agent import Agent

SCENARIOS = ("plan-easy", "plan-hard", "plan-stl", "track-lin", "track-car")


def _median_ms(values: list[float]) -> str:
    return f"{statistics.median(values) * 1e3:.0f} ms"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=10, help="seeds per scenario (default 10)")
    args = parser.parse_args()

    start = time.perf_counter()
    Agent("track-lin", seed=0).solve()  # starts the shared sandbox
    warmup = time.perf_counter() - start

    rows = []
    for name in SCENARIOS:
        wall, model, code, framework, ok = [], [], [], [], 0
        for seed in range(args.seeds):
            result = Agent(name, seed=seed).solve()
            ok += result.success
            for r in result.rounds:
                run = float((r.execution or {}).get("wall_s", 0.0))
                wall.append(r.wall_s)
                model.append(r.model_s)
                code.append(run)
                framework.append(max(0.0, r.wall_s - r.model_s - run))
        rows.append((name, ok, len(wall), wall, model, code, framework))

    print(machine_summary())
    print(f"warm-up solve (starts the sandbox supervisor): {warmup:.2f} s")
    print()
    print("### Agent round, offline expert, medians per round")
    print()
    print("| scenario | solved | rounds | wall | model | code in sandbox | framework | wall - model |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|")
    for name, ok, n, wall, model, code, framework in rows:
        rest = [w - m for w, m in zip(wall, model, strict=True)]
        print(
            f"| {name} | {ok}/{args.seeds} | {n} | {_median_ms(wall)} | {_median_ms(model)} | "
            f"{_median_ms(code)} | {_median_ms(framework)} | {_median_ms(rest)} |"
        )


if __name__ == "__main__":
    main()
