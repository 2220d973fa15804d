"""A tiny timing harness for the scripts in ``benchmarks/``.

House rule: numbers are compared side by side *within one run* (same machine, same load), never
against numbers from another run. :func:`compare` therefore times every case in the same process,
interleaving the repeats round-robin so that a change in machine load hits all cases alike, and
:func:`markdown_table` prints each case's ratio to a baseline case from that same run.

Usage from a benchmark script (run as ``python benchmarks/bench_<topic>.py``, or all of them with
``nox -s bench``)::

    from _harness import compare, markdown_table, machine_summary

    timings = compare({"numpy": run_numpy, "casadi": run_casadi}, repeat=7)
    print(machine_summary())
    print(markdown_table(timings, baseline="numpy", title="Unicycle rollout, horizon 20"))
"""

from __future__ import annotations

import gc
import os
import platform
import statistics
import sys
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

__all__ = ["Timing", "compare", "machine_summary", "markdown_table", "time_call"]


@dataclass(frozen=True)
class Timing:
    """Wall-clock times of one benchmark case.

    Parameters
    ----------
    label
        Name of the case, as shown in the table.
    seconds
        Time per call of each repeat, in seconds (each repeat's total divided by ``number``).
    number
        Calls per repeat.
    """

    label: str
    seconds: tuple[float, ...]
    number: int = 1

    @property
    def min(self) -> float:
        """Fastest repeat, seconds per call: the least disturbed by other load on the machine."""
        return min(self.seconds)

    @property
    def median(self) -> float:
        """Median repeat, seconds per call: what a user typically sees."""
        return statistics.median(self.seconds)


def _check_counts(*, repeat: int, warmup: int, number: int) -> None:
    if repeat < 1:
        raise ValueError(f"repeat must be >= 1, got {repeat}")
    if warmup < 0:
        raise ValueError(f"warmup must be >= 0, got {warmup}")
    if number < 1:
        raise ValueError(f"number must be >= 1, got {number}")


def _once(fn: Callable[[], object], number: int) -> float:
    """Time ``number`` calls of ``fn`` with the garbage collector paused; return seconds per call."""
    gc_was_enabled = gc.isenabled()
    gc.collect()
    gc.disable()
    try:
        start = time.perf_counter()
        for _ in range(number):
            fn()
        elapsed = time.perf_counter() - start
    finally:
        if gc_was_enabled:
            gc.enable()
    return elapsed / number


def compare(
    cases: Mapping[str, Callable[[], object]],
    *,
    repeat: int = 7,
    warmup: int = 1,
    number: int = 1,
) -> list[Timing]:
    """Time several cases in this run, interleaving their repeats round-robin.

    Parameters
    ----------
    cases
        Label -> zero-argument callable doing the work to time (build inputs outside it, or with
        ``functools.partial``). Labels are kept in the given order.
    repeat
        Number of timed repeats per case (>= 1).
    warmup
        Untimed calls per case before timing (>= 0): imports, JIT, caches, first-solve setup.
    number
        Calls per repeat (>= 1); use more than one for calls much shorter than a millisecond.

    Returns
    -------
    list of Timing
        One per case, in the order of ``cases``.
    """
    _check_counts(repeat=repeat, warmup=warmup, number=number)
    if not cases:
        raise ValueError("cases must hold at least one callable, got an empty mapping")
    for fn in cases.values():
        for _ in range(warmup):
            fn()
    samples: dict[str, list[float]] = {label: [] for label in cases}
    for _ in range(repeat):
        for label, fn in cases.items():
            samples[label].append(_once(fn, number))
    return [Timing(label=label, seconds=tuple(s), number=number) for label, s in samples.items()]


def time_call(
    fn: Callable[[], object],
    *,
    label: str,
    repeat: int = 7,
    warmup: int = 1,
    number: int = 1,
) -> Timing:
    """Time one callable, like :func:`compare` with a single case.

    Parameters
    ----------
    fn
        Zero-argument callable doing the work to time.
    label
        Name of the case, as shown in the table.
    repeat
        Number of timed repeats (>= 1).
    warmup
        Untimed calls before timing (>= 0).
    number
        Calls per repeat (>= 1).

    Returns
    -------
    Timing
        The times of each repeat, in seconds per call.
    """
    return compare({label: fn}, repeat=repeat, warmup=warmup, number=number)[0]


def _format_seconds(seconds: float) -> str:
    """Format a duration with a unit that keeps three significant digits readable."""
    if seconds >= 1.0:
        return f"{seconds:.3g} s"
    if seconds >= 1e-3:
        return f"{seconds * 1e3:.3g} ms"
    return f"{seconds * 1e6:.3g} µs"


def markdown_table(
    timings: Sequence[Timing],
    *,
    baseline: str | None = None,
    title: str | None = None,
) -> str:
    """Render timings as a Markdown table with each case's ratio to a baseline from the same run.

    Parameters
    ----------
    timings
        Results of :func:`compare` or :func:`time_call`, all from this run.
    baseline
        Label of the case the ratios are relative to; defaults to the first case.
    title
        Optional heading printed above the table (as a level-3 Markdown heading).

    Returns
    -------
    str
        The table: case, min, median (per call), repeats x calls, and median / baseline median.
    """
    if not timings:
        raise ValueError("timings must hold at least one Timing, got an empty sequence")
    by_label = {t.label: t for t in timings}
    reference = by_label.get(baseline if baseline is not None else timings[0].label)
    if reference is None:
        raise ValueError(f"baseline must be one of the labels {list(by_label)}, got {baseline!r}")
    lines = []
    if title:
        lines += [f"### {title}", ""]
    lines += [
        f"| case | min | median | repeats x calls | median / {reference.label} |",
        "|---|---:|---:|---:|---:|",
    ]
    for t in timings:
        ratio = t.median / reference.median if reference.median > 0 else float("nan")
        lines.append(
            f"| {t.label} | {_format_seconds(t.min)} | {_format_seconds(t.median)} "
            f"| {len(t.seconds)} x {t.number} | {ratio:.2f}x |"
        )
    return "\n".join(lines)


def machine_summary() -> str:
    """Return one line describing the machine and interpreter, to print above the tables.

    Returns
    -------
    str
        Python version, platform, and the number of CPUs this process may use.
    """
    try:
        cpus = len(os.sched_getaffinity(0))
    except AttributeError:  # not available on macOS and Windows
        cpus = os.cpu_count() or 1
    return (
        f"Python {sys.version.split()[0]} on {platform.platform(terse=True)} "
        f"({platform.machine()}), {cpus} CPU(s) available"
    )
