"""The timing harness used by the scripts in ``benchmarks/``."""

from __future__ import annotations

import importlib.util
import re
import sys
import time
from collections.abc import Iterator
from pathlib import Path
from types import ModuleType

import pytest

HARNESS_PATH = Path(__file__).resolve().parents[1] / "benchmarks" / "_harness.py"


@pytest.fixture(scope="module")
def harness() -> Iterator[ModuleType]:
    # benchmarks/ is a folder of scripts, not a package: load the harness from its path. Dataclasses
    # need the module registered in sys.modules while it executes.
    name = "_audere_bench_harness"
    spec = importlib.util.spec_from_file_location(name, HARNESS_PATH)
    assert spec is not None
    assert spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    try:
        spec.loader.exec_module(module)
        yield module
    finally:
        del sys.modules[name]


def test_compare_interleaves_repeats_and_counts_calls(harness: ModuleType) -> None:
    calls: list[str] = []
    timings = harness.compare(
        {"a": lambda: calls.append("a"), "b": lambda: calls.append("b")}, repeat=3, warmup=2, number=4
    )
    # Warm-up calls per case first, then round-robin: one repeat (4 calls) of a, then of b, ...
    assert calls == ["a", "a", "b", "b", *(["a"] * 4 + ["b"] * 4) * 3]
    assert [t.label for t in timings] == ["a", "b"]
    assert all(len(t.seconds) == 3 and t.number == 4 for t in timings)


def test_min_and_median(harness: ModuleType) -> None:
    timing = harness.Timing(label="x", seconds=(3.0, 1.0, 2.0, 10.0))
    assert timing.min == 1.0
    assert timing.median == 2.5


def test_markdown_table_ratios_against_baseline(harness: ModuleType) -> None:
    fast = harness.Timing(label="fast", seconds=(0.001, 0.002, 0.003))
    slow = harness.Timing(label="slow", seconds=(0.004, 0.008, 0.010))
    table = harness.markdown_table([fast, slow], baseline="fast", title="demo")
    lines = table.splitlines()
    assert lines[0] == "### demo"
    assert "median / fast" in lines[2]
    assert re.search(r"\| fast \| 1 ms \| 2 ms \| 3 x 1 \| 1\.00x \|", table)
    assert re.search(r"\| slow \| 4 ms \| 8 ms \| 3 x 1 \| 4\.00x \|", table)
    # The first case is the default baseline.
    assert "median / fast" in harness.markdown_table([fast, slow])


def test_time_call_measures_real_time(harness: ModuleType) -> None:
    timing = harness.time_call(lambda: time.sleep(0.002), label="sleep", repeat=2, warmup=0)
    assert timing.min >= 0.002


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"repeat": 0}, "repeat must be >= 1, got 0"),
        ({"warmup": -1}, "warmup must be >= 0, got -1"),
        ({"number": 0}, "number must be >= 1, got 0"),
    ],
)
def test_compare_rejects_bad_counts(harness: ModuleType, kwargs: dict[str, int], match: str) -> None:
    with pytest.raises(ValueError, match=match):
        harness.compare({"a": lambda: None}, **kwargs)


def test_markdown_table_rejects_unknown_baseline(harness: ModuleType) -> None:
    timing = harness.Timing(label="a", seconds=(1.0,))
    with pytest.raises(ValueError, match=r"baseline must be one of the labels \['a'\], got 'b'"):
        harness.markdown_table([timing], baseline="b")
