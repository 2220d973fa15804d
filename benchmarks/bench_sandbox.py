"""Sandbox: per-execution latency of the warm executor vs a cold ``python -I`` worker, and timeout precision.

The snippet is trivial (``import numpy as np, casadi; x = casadi.SX.sym("x"); result = np.zeros((1000, 4))``),
so the numbers are the sandbox's own overhead. Cases, timed side by side in this run:

- ``warm, core``: :class:`~audere.agent.sandbox.SandboxExecutor` with ``layers=()`` (separate process,
  rlimits, clean environment, descendant sweep), supervisor already started;
- ``warm, all layers``: the same with every hardening layer this machine supports (Landlock, seccomp,
  network namespace, bubblewrap);
- ``cold python -I``: a fresh ``python -I`` that imports the same libraries the supervisor preloads
  (:data:`~audere.agent.sandbox.DEFAULT_PRELOAD`), then runs the snippet: what a sandbox without a
  warm supervisor pays for every execution.

Each warm run includes creating and removing the run directory, the fork, the child's hardening, the
run, the result frame, the descendant sweep and the host's validation of the reply. The one-off start
of each supervisor is reported apart. Then ``while True: pass`` runs ``--timeouts`` times with a 1 s
limit under all layers, and the script reports how far past the limit the host got its answer.

Run: ``python benchmarks/bench_sandbox.py`` (about 1-2 minutes on two cores; ``--repeat`` to change).
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import time

from _harness import compare, machine_summary, markdown_table

from audere.agent.sandbox import DEFAULT_PRELOAD, ExecutionStatus, SandboxExecutor, probe_layers

SNIPPET = 'import numpy as np, casadi\nx = casadi.SX.sym("x")\nresult = np.zeros((1000, 4))\n'
COLD_ENV = {"PATH": "/usr/local/bin:/usr/bin:/bin", "LANG": "C.UTF-8", "OMP_NUM_THREADS": "1"}


def _cold_source() -> str:
    imports = "".join(f"    importlib.import_module({name!r})\n" for name in DEFAULT_PRELOAD)
    return f"import importlib\ntry:\n{imports}except ImportError:\n    pass\n{SNIPPET}"


def _warm(executor: SandboxExecutor) -> None:
    execution = executor.run(SNIPPET, timeout_s=30.0)
    if execution.status is not ExecutionStatus.OK:
        raise RuntimeError(f"the warm run failed: {execution.message}")


def _cold(source: str) -> None:
    subprocess.run([sys.executable, "-I", "-c", source], env=COLD_ENV, check=True, timeout=120)


def _started(layers: tuple[str, ...] | None) -> tuple[SandboxExecutor, float]:
    executor = SandboxExecutor(layers=layers)
    start = time.perf_counter()
    executor.start()
    return executor, time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=9, help="timed repeats per case (default 9)")
    parser.add_argument("--timeouts", type=int, default=10, help="1 s timeouts to measure (default 10)")
    args = parser.parse_args()

    report = probe_layers()
    core, core_start = _started(())
    hardened, hardened_start = _started(None)
    source = _cold_source()
    try:
        timings = compare(
            {
                "warm, core": lambda: _warm(core),
                f"warm, all layers ({', '.join(hardened.applied_layers) or 'none here'})": lambda: _warm(
                    hardened
                ),
                "cold python -I (same imports)": lambda: _cold(source),
            },
            repeat=args.repeat,
            warmup=1,
        )
        late: list[float] = []
        for _ in range(args.timeouts):
            start = time.perf_counter()
            execution = hardened.run("while True:\n    pass\n", timeout_s=1.0)
            late.append(time.perf_counter() - start - 1.0)
            if execution.status is not ExecutionStatus.TIMEOUT:
                raise RuntimeError(f"expected a timeout, got {execution.status}: {execution.message}")
    finally:
        core.close()
        hardened.close()

    print(machine_summary())
    print(f"hardening layers on this machine: {report}")
    print()
    print(markdown_table(timings, baseline="warm, core", title="One trivial execution, end to end"))
    print()
    print(f"supervisor start (one-off): core {core_start:.2f} s, all layers {hardened_start:.2f} s")
    print(
        f"timeout of 1 s, {len(late)} runs under all layers: the host had its answer "
        f"{statistics.median(late) * 1e3:.0f} ms (median), {max(late) * 1e3:.0f} ms (max) after the limit"
    )


if __name__ == "__main__":
    main()
