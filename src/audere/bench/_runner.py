"""Running the grid: where experiments run is a seam (:class:`Runner`); a local pool runs them here.

:func:`run_grid` owns the store (skip what is done, write each result as it completes) and knows
nothing of how experiments are executed. A :class:`Runner` takes the experiments still to do and
reports each one's :class:`~audere.agent.SolveResult` (or its error) through a callback, in any
order; :class:`LocalRunner` does it with asyncio (bounded concurrency, model calls awaited) and a
pool of warm sandbox workers sized to the machine's cores. A distributed engine (say Ray) plugs in
as another ``Runner`` without touching the grid, the store or the metrics.
"""

from __future__ import annotations

import asyncio
import os
import queue
import threading
import time
import traceback
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Protocol

from audere.bench._grid import Experiment
from audere.bench._store import ResultStore, record_for
from audere.errors import InvalidArgumentError

__all__ = ["ExecutorPool", "LocalRunner", "OnResult", "RunSummary", "Runner", "run_grid"]

OnResult = Callable[[Experiment, Any, "str | None"], None]
"""``on_result(experiment, solve_result_or_None, error_or_None)``, called once per experiment."""


class Runner(Protocol):
    """Where experiments run. Implementations call ``on_result`` once per experiment, from one thread."""

    def run(self, experiments: Sequence[Experiment], on_result: OnResult) -> None:
        """Run ``experiments``; report each one through ``on_result``."""
        ...


class ExecutorPool:
    """Warm sandbox workers shared by concurrent experiments: :meth:`run` borrows a free one.

    Parameters
    ----------
    size
        Number of sandbox supervisors (each started on first use).
    setup
        What the sandbox imports, hides and may read (:func:`audere.agent._agent.sandbox_setup`).
    """

    def __init__(self, size: int, *, setup: Any) -> None:
        if isinstance(size, bool) or not isinstance(size, int) or size < 1:
            raise InvalidArgumentError(f"size: expected a positive integer, got {size!r}")
        self._setup = setup
        self._free: queue.Queue[Any] = queue.Queue()
        self._all: list[Any] = []
        self._lock = threading.Lock()
        self._size = size
        self._closed = False

    def _borrow(self) -> Any:
        from audere.agent.sandbox import SandboxExecutor

        with self._lock:
            if self._free.empty() and len(self._all) < self._size:
                executor = SandboxExecutor(
                    hidden=self._setup.hidden, preload=self._setup.preload, paths=self._setup.paths
                )
                self._all.append(executor)
                return executor
        return self._free.get()

    def run(
        self,
        code: str,
        *,
        inputs: Any = None,
        timeout_s: float = 10.0,
        limits: Any = None,
    ) -> Any:
        """Run ``code`` on a free worker (waiting for one); see :meth:`SandboxExecutor.run`."""
        executor = self._borrow()
        try:
            return executor.run(code, inputs=inputs, timeout_s=timeout_s, limits=limits)
        finally:
            self._free.put(executor)

    def close(self) -> None:
        """Stop every worker."""
        with self._lock:
            for executor in self._all:
                executor.close()
            self._all.clear()
            self._closed = True


class LocalRunner:
    """Run experiments in this process: asyncio for the model calls, a sandbox pool for the code.

    Parameters
    ----------
    concurrency
        Experiments in flight at once (their model calls overlap; a remote model's latency hides).
    workers
        Sandbox supervisors per method that runs code (default: the machine's cores).
    cache
        A response cache for every agent (e.g. the store's), or None.
    record
        A cassette every model call is appended to (replay it with ``model="audere/replay"``).
    cassette
        The cassette to answer from, for experiments whose model is ``"audere/replay"``.
    """

    def __init__(
        self,
        *,
        concurrency: int = 2,
        workers: int | None = None,
        cache: Any = None,
        record: str | os.PathLike[str] | None = None,
        cassette: str | os.PathLike[str] | None = None,
    ) -> None:
        if isinstance(concurrency, bool) or not isinstance(concurrency, int) or concurrency < 1:
            raise InvalidArgumentError(f"concurrency: expected a positive integer, got {concurrency!r}")
        count = workers if workers is not None else max(1, len(os.sched_getaffinity(0)))
        if isinstance(count, bool) or not isinstance(count, int) or count < 1:
            raise InvalidArgumentError(f"workers: expected a positive integer, got {workers!r}")
        self.concurrency = concurrency
        self.workers = count
        self.cache = cache
        self.record = record
        self.cassette = cassette
        self._pools: dict[Any, ExecutorPool] = {}

    def _pool(self, method: str) -> ExecutorPool:
        from audere.agent._agent import sandbox_setup

        setup = sandbox_setup(method)
        if setup not in self._pools:
            self._pools[setup] = ExecutorPool(self.workers, setup=setup)
        return self._pools[setup]

    def run(self, experiments: Sequence[Experiment], on_result: OnResult) -> None:
        """Run ``experiments`` with at most ``concurrency`` in flight; report each as it finishes."""
        try:
            asyncio.run(self._main(experiments, on_result))
        finally:
            for pool in self._pools.values():
                pool.close()
            self._pools.clear()

    async def _main(self, experiments: Sequence[Experiment], on_result: OnResult) -> None:
        gate = asyncio.Semaphore(self.concurrency)

        async def one(experiment: Experiment) -> None:
            async with gate:
                result, error = await self._solve(experiment)
            on_result(experiment, result, error)

        await asyncio.gather(*(one(e) for e in experiments))

    async def _solve(self, experiment: Experiment) -> tuple[Any, str | None]:
        from audere.agent import Agent

        try:
            agent = Agent(
                experiment.scenario,
                seed=experiment.seed,
                model=experiment.model,
                method=experiment.method,
                temperature=experiment.temperature,
                api_provision=experiment.provision,
                max_rounds=experiment.max_rounds,
                timeout_s=experiment.timeout_s,
                executor=self._pool(experiment.method),
                cache=self.cache if experiment.model != "audere/replay" else None,
                record=self.record,
                cassette=self.cassette if experiment.model == "audere/replay" else None,
            )
            return await agent.asolve(), None
        except Exception as error:  # a harness failure is recorded, and the grid goes on
            summary = "".join(traceback.format_exception_only(type(error), error)).strip()
            return None, summary


@dataclass(frozen=True)
class RunSummary:
    """What :func:`run_grid` did."""

    total: int
    skipped: int
    ran: int
    solved: int
    errors: int
    wall_s: float
    directory: Path


def run_grid(
    experiments: Sequence[Experiment],
    out: str | os.PathLike[str],
    *,
    runner: Runner | None = None,
    concurrency: int = 2,
    workers: int | None = None,
    record: str | os.PathLike[str] | None = None,
    cassette: str | os.PathLike[str] | None = None,
    options: dict[str, Any] | None = None,
    progress: Callable[[int, int, dict[str, Any]], None] | None = None,
) -> RunSummary:
    """Run the experiments not yet in ``out``; write each one durably as it completes.

    Parameters
    ----------
    experiments
        The grid (:func:`audere.bench.make_grid`).
    out
        The results directory; rerunning the same grid into it resumes.
    runner
        Where to run (default: a :class:`LocalRunner` with the store's response cache).
    concurrency, workers, record, cassette
        For the default runner (see :class:`LocalRunner`).
    options
        What to log about this invocation in ``runs.jsonl``.
    progress
        Called as ``progress(done, to_do, record)`` after each experiment is written.

    Returns
    -------
    RunSummary
        Counts and wall time.
    """
    started = time.monotonic()
    keys = [e.key for e in experiments]
    if len(set(keys)) != len(keys):
        raise InvalidArgumentError("experiments: expected distinct experiments, got duplicates")
    with ResultStore(out) as store:
        done = store.done_keys()
        todo = [e for e in experiments if e.key not in done]
        store.log_run({**(options or {}), "experiments": len(experiments), "to_do": len(todo)})
        chosen = (
            runner
            if runner is not None
            else LocalRunner(
                concurrency=concurrency,
                workers=workers,
                cache=store.cache(),
                record=record,
                cassette=cassette,
            )
        )
        counts = {"ran": 0, "solved": 0, "errors": 0}

        def on_result(experiment: Experiment, result: Any, error: str | None) -> None:
            record = record_for(experiment, result, error=error)
            transcript = result.model_dump(mode="json") if result is not None else None
            if store.append(record, transcript):
                counts["ran"] += 1
                counts["solved"] += bool(record["success"])
                counts["errors"] += record["status"] == "error"
                if progress is not None:
                    progress(counts["ran"], len(todo), record)

        if todo:
            chosen.run(todo, on_result)
    return RunSummary(
        total=len(experiments),
        skipped=len(experiments) - len(todo),
        ran=counts["ran"],
        solved=counts["solved"],
        errors=counts["errors"],
        wall_s=time.monotonic() - started,
        directory=Path(out),
    )
