"""grad: time per Adam iteration against restarts and horizon, with one torch thread.

``grad`` on the unicycle (goal position, one circle obstacle) for 50 iterations, 1 / 8 / 32 restarts
and horizons 20 / 60; the first call (torch import and the first Adam construction, several
seconds) is the untimed warm-up. Ratios are to 8 restarts at horizon 20.

Run: ``python benchmarks/bench_grad.py [--repeat R]``.
"""

from __future__ import annotations

import argparse
from collections.abc import Callable

from _harness import compare, machine_summary, markdown_table  # benchmarks/ is on sys.path

from audere.planners import grad
from audere.world import Circle


def _case(restarts: int, horizon: int) -> Callable[[], object]:
    return lambda: grad(
        "unicycle",
        [0.0, 0.0, 0.0, 0.0],
        goal=[3.0, 1.0],
        goal_on="position",
        obstacles=[Circle(center=(1.5, 0.5), radius=0.4)],
        horizon=horizon,
        dt=5.0 / horizon,
        u_min=[-1.0, -1.0],
        u_max=[1.0, 1.0],
        restarts=restarts,
        iterations=50,
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()
    cases = {f"{r} restarts, T={h}": _case(r, h) for h in (20, 60) for r in (1, 8, 32)}
    timings = compare(cases, repeat=args.repeat)
    print(machine_summary())
    print()
    print(markdown_table(timings, baseline="8 restarts, T=20", title="grad, 50 Adam iterations (unicycle)"))


if __name__ == "__main__":
    main()
