"""Nonlinear unicycle MPC (horizon 20): the compiled problem reused with warm starts vs rebuilt every solve.

Every case solves the same 30 closed-loop problems: tracking a circle of radius 3 m with the unicycle
(dt = 0.2 s, |omega|, |a| <= 1), from the states visited by a reference closed-loop run. Reported
times are per solve (each repeat's time for the 30 solves divided by 30).

- ``mpc() end to end``: the public call, 30 closed-loop steps (one build, amortized over the solves);
- ``reused, warm start``: audere's compiled problem built once, each solve started from the previous
  plan shifted by one step (what ``mpc`` does between steps);
- ``reused, cold start``: the same compiled problem, each solve started from rest;
- ``rebuilt (ours) every solve``: audere's problem built and compiled for every solve;
- ``rebuilt Opti every solve``: a plain ``casadi.Opti`` formulation (as a research script would
  write it) built for every solve.

Run: ``python benchmarks/bench_mpc.py`` (about 30 s on two cores). With ``--recipes``, it also runs the
MPC recipes (track-car, reach-unicycle, arm-reach) on seeds 0-99 through each task's checker and
prints the pass count and the median and p95 time per task (about 2 minutes more).
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable

import casadi as ca
import numpy as np
from _harness import Timing, compare, machine_summary, markdown_table

from audere.controllers import mpc
from audere.controllers._mpc import _Problem, _Solve, _Spec, _window
from audere.dynamics import get_dynamics

N = 20
DT = 0.2
STEPS = 30
X0 = np.array([3.3, -0.3, np.pi / 2, 0.0])
T = DT * np.arange(STEPS + N + 1)
REFERENCE = np.column_stack([3.0 * np.cos(0.1 * T), 3.0 * np.sin(0.1 * T)])
MODEL = get_dynamics("unicycle")
U_BOUND = 1.0


def _spec() -> _Spec:
    inf = np.full(4, np.inf)
    return _Spec(
        model=MODEL,
        dt=DT,
        method="euler",
        horizon=N,
        on_position=True,
        q=np.eye(2),
        r=0.1 * np.eye(2),
        qf=10.0 * np.eye(2),
        u_lo=np.full(2, -U_BOUND),
        u_hi=np.full(2, U_BOUND),
        x_lo=-inf,
        x_hi=inf,
        obstacles=(),
        margin=0.0,
        solver="ipopt",
        max_iter=200,
        time_limit=5.0,
    )


def _public() -> np.ndarray:
    result = mpc(
        MODEL,
        X0,
        reference=REFERENCE,
        steps=STEPS,
        horizon=N,
        dt=DT,
        u_min=-U_BOUND,
        u_max=U_BOUND,
    )
    assert result.status == "solved", result.message
    assert result.states is not None
    return result.states


def _reused(problem: _Problem, states: np.ndarray, *, warm: bool) -> Callable[[], None]:
    def run() -> None:
        previous: _Solve | None = None
        for k in range(STEPS):
            state = states[k]
            guess = problem.shifted(previous) if warm and previous is not None else problem.cold_guess(state)
            previous = problem.solve(state, _window(REFERENCE, k, N), guess)

    return run


def _rebuilt_ours(states: np.ndarray) -> None:
    for k in range(STEPS):
        problem = _Problem(_spec())
        problem.solve(states[k], _window(REFERENCE, k, N), problem.cold_guess(states[k]))


def _opti_solve(state: np.ndarray, ref: np.ndarray) -> np.ndarray:
    """One solve with a freshly built casadi.Opti problem (the same objective and constraints)."""
    step = MODEL.casadi_function(DT)
    opti = ca.Opti()
    x = opti.variable(4, N + 1)
    u = opti.variable(2, N)
    x0 = opti.parameter(4)
    r = opti.parameter(2, N + 1)
    opti.subject_to(x[:, 0] == x0)
    cost = 0
    for k in range(N):
        opti.subject_to(x[:, k + 1] == step(x[:, k], u[:, k]))
        cost += ca.sumsqr(x[0:2, k] - r[:, k]) + 0.1 * ca.sumsqr(u[:, k])
    cost += 10.0 * ca.sumsqr(x[0:2, N] - r[:, N])
    opti.subject_to(opti.bounded(-U_BOUND, u, U_BOUND))
    opti.minimize(cost)
    opti.solver("ipopt", {"print_time": False, "ipopt.print_level": 0, "ipopt.sb": "yes"})
    opti.set_value(x0, state)
    opti.set_value(r, ref.T)
    opti.set_initial(x, np.tile(state[:, None], (1, N + 1)))
    sol = opti.solve()
    return np.asarray(sol.value(u))[:, 0]


def _rebuilt_opti(states: np.ndarray) -> None:
    for k in range(STEPS):
        _opti_solve(states[k], _window(REFERENCE, k, N))


def _recipes(seeds: range) -> None:
    from audere import recipes, scenarios

    print()
    print(f"### MPC recipes, seeds {seeds.start}-{seeds.stop - 1}: checker passes and time per task")
    print()
    print("| scenario | passes | median | p95 | max |")
    print("|---|---:|---:|---:|---:|")
    for name in ("track-car", "reach-unicycle", "arm-reach"):
        solve = recipes.get_recipe(name).function
        seconds = []
        passed = 0
        for seed in seeds:
            task = scenarios.make(name, seed=seed)
            start = time.perf_counter()
            solution = solve(task)
            seconds.append(time.perf_counter() - start)
            passed += bool(task.check(solution).success)
        median, p95 = np.percentile(seconds, [50, 95])
        print(
            f"| {name} | {passed}/{len(seeds)} | {median * 1e3:.0f} ms | {p95 * 1e3:.0f} ms "
            f"| {max(seconds) * 1e3:.0f} ms |"
        )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--recipes", action="store_true", help="also time the MPC recipes on 100 seeds")
    args = parser.parse_args()
    states = _public()
    problem = _Problem(_spec())
    # All formulations agree on the first input of every solve (same problem, same optimum).
    first = problem.solve(states[5], _window(REFERENCE, 5, N), problem.cold_guess(states[5])).inputs[0]
    np.testing.assert_allclose(_opti_solve(states[5], _window(REFERENCE, 5, N)), first, atol=1e-5)

    timings = compare(
        {
            "mpc() end to end": _public,
            "reused, warm start": _reused(problem, states, warm=True),
            "reused, cold start": _reused(problem, states, warm=False),
            "rebuilt (ours) every solve": lambda: _rebuilt_ours(states),
            "rebuilt Opti every solve": lambda: _rebuilt_opti(states),
        },
        repeat=5,
        warmup=1,
    )
    per_solve = [Timing(t.label, tuple(s / STEPS for s in t.seconds), t.number) for t in timings]
    print(machine_summary())
    print()
    print(
        markdown_table(
            per_solve,
            baseline="reused, warm start",
            title=f"Unicycle NMPC, horizon {N}, IPOPT: time per solve ({STEPS} solves per repeat)",
        )
    )
    by_label = {t.label: t for t in per_solve}
    speedup = by_label["rebuilt Opti every solve"].median / by_label["reused, warm start"].median
    print()
    print(f"Reused with warm starts vs Opti rebuilt every solve: {speedup:.1f}x faster (goal: >= 5x).")
    if args.recipes:
        _recipes(range(100))


if __name__ == "__main__":
    main()
