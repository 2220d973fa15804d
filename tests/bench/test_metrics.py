"""The benchmark's metrics on hand-made records: Wilson intervals, rates, rounds, success@k, tables."""

from __future__ import annotations

import csv
import itertools
import json
import math
from pathlib import Path
from typing import Any

import pytest

from audere.bench._metrics import (
    CATEGORIES,
    GROUP,
    format_markdown,
    read_records,
    success_at_k,
    summarize,
    wilson_interval,
    write_csv,
)
from audere.errors import AudereError, InvalidArgumentError

Z = 1.959963984540054


def make_record(
    *,
    scenario: str = "plan-easy",
    seed: int = 0,
    method: str = "use-api",
    model: str = "openai/gpt-4o",
    temperature: float = 0.1,
    provision: str = "on-demand",
    max_rounds: int = 6,
    status: str = "solved",
    categories: list[str] | None = None,
    cost: float | None = 0.01,
    calls: int | None = None,
    wall_s: float = 4.0,
) -> dict[str, Any]:
    """A realistic record of results.jsonl; solved records end in a success round."""
    if categories is None:
        categories = {
            "solved": ["success"],
            "failed": ["task_failure"] * max_rounds,
            "model_error": ["model_error"],
            "invalid_task": [],
            "error": [],
        }[status]
    rounds = len(categories)
    solved = status == "solved"
    if calls is None:
        calls = 0 if status == "error" else rounds + (1 if method == "use-api" else 0)
    return {
        "key": f"{scenario}/seed={seed}/{method}/{model}/t={temperature}/{provision}/r={max_rounds}",
        "scenario": scenario,
        "seed": seed,
        "method": method,
        "model": model,
        "temperature": temperature,
        "provision": provision,
        "max_rounds": max_rounds,
        "status": status,
        "success": solved,
        "rounds": rounds,
        "rounds_to_success": rounds if solved else None,
        "calls": calls,
        "calls_to_success": calls if solved else None,
        "categories": categories,
        "selected_apis": ["rrt"] if method == "use-api" else [],
        "apis_called": ["rrt"] if solved else [],
        "prompt_tokens": 1000 * max(calls, 0),
        "completion_tokens": 100 * max(calls, 0),
        "cost": None if status == "error" else cost,
        "wall_s": wall_s,
        "model_s": wall_s / 2,
        "prompt_version": "2025-01",
        "audere_version": "0.1.0.dev0",
        "finished_at": f"2025-01-01T00:00:{seed:02d}+00:00",
        "error": "Traceback: boom" if status == "error" else None,
    }


def wilson(k: int, n: int, z: float = Z) -> tuple[float, float]:
    """The Wilson interval, written out from the formula."""
    p = k / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z / (1 + z * z / n) * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n))
    return centre - half, centre + half


# --------------------------------------------------------------------------------------------------
# Wilson
# --------------------------------------------------------------------------------------------------


@pytest.mark.parametrize(("k", "n"), [(0, 10), (10, 10), (5, 10), (1, 3), (19, 20), (0, 1)])
def test_wilson_matches_the_formula(k: int, n: int) -> None:
    low, high = wilson_interval(k, n)
    expected_low, expected_high = wilson(k, n)
    assert low == pytest.approx(expected_low, abs=1e-12)
    assert high == pytest.approx(expected_high, abs=1e-12)
    assert 0.0 <= low <= k / n <= high <= 1.0


def test_wilson_edges_and_a_literature_value() -> None:
    assert wilson_interval(0, 10)[0] == 0.0
    assert wilson_interval(10, 10)[1] == 1.0
    assert wilson_interval(0, 10)[1] == pytest.approx(0.2775, abs=1e-4)
    assert wilson_interval(5, 10) == pytest.approx((0.2366, 0.7634), abs=1e-4)
    # Newcombe (1998) / Wikipedia's worked example: 81 successes of 263.
    assert tuple(round(v, 4) for v in wilson_interval(81, 263)) == (0.2553, 0.3662)
    assert wilson_interval(0, 0) == (0.0, 1.0)
    # A larger z widens the interval.
    assert wilson_interval(5, 10, z=2.576)[0] < wilson_interval(5, 10)[0]


@pytest.mark.parametrize(
    ("args", "match"),
    [
        ((-1, 10), "successes: expected an integer >= 0, got -1"),
        ((11, 10), "successes: expected at most n=10, got 11"),
        ((1, -2), "n: expected an integer >= 0, got -2"),
        ((1.5, 10), "successes: expected an integer >= 0, got 1.5"),
        ((True, 10), "successes: expected an integer >= 0, got True"),
        ((1, 10, 0.0), "z: expected a finite number > 0, got 0.0"),
        ((1, 10, math.nan), "z: expected a finite number > 0, got nan"),
    ],
)
def test_wilson_rejects_bad_arguments(args: tuple[Any, ...], match: str) -> None:
    with pytest.raises(InvalidArgumentError, match=match):
        wilson_interval(*args)


# --------------------------------------------------------------------------------------------------
# summarize
# --------------------------------------------------------------------------------------------------


def test_success_rate_excludes_infrastructure_failures() -> None:
    records = [
        make_record(seed=0, status="solved"),
        make_record(seed=1, status="solved", categories=["syntax", "runtime", "success"]),
        make_record(seed=2, status="failed"),
        make_record(seed=3, status="model_error", categories=["task_failure", "model_error"]),
        make_record(seed=4, status="error"),
    ]
    (row,) = summarize(records)
    assert {k: row[k] for k in GROUP} == {
        "scenario": "plan-easy",
        "method": "use-api",
        "model": "openai/gpt-4o",
        "temperature": 0.1,
        "provision": "on-demand",
    }
    assert (row["n"], row["n_infra"], row["solved"]) == (3, 2, 2)
    assert row["success_rate"] == pytest.approx(2 / 3)
    assert (row["ci_low"], row["ci_high"]) == pytest.approx(wilson(2, 3))
    # Rounds played, over the counted experiments only: 1, 3 and 6.
    assert row["mean_rounds"] == pytest.approx(10 / 3)
    assert row["mean_wall_s"] == pytest.approx(4.0)


def test_mean_rounds_and_calls_to_success_are_over_the_solved_only() -> None:
    records = [
        make_record(seed=0, categories=["success"]),  # 1 round, 2 calls (selection + code)
        make_record(seed=1, categories=["syntax", "task_failure", "success"]),  # 3 rounds, 4 calls
        make_record(seed=2, status="failed"),  # 6 rounds: not in the mean
    ]
    (row,) = summarize(records)
    assert row["mean_rounds_to_success"] == pytest.approx(2.0)
    assert row["mean_calls_to_success"] == pytest.approx(3.0)
    assert row["mean_rounds"] == pytest.approx((1 + 3 + 6) / 3)
    (unsolved,) = summarize([make_record(status="failed")])
    assert unsolved["mean_rounds_to_success"] is None
    assert unsolved["mean_calls_to_success"] is None
    assert unsolved["success_rate"] == 0.0


def test_error_counts_per_category_over_every_round() -> None:
    records = [
        make_record(seed=0, categories=["parsing", "syntax", "success"]),
        make_record(seed=1, status="failed", categories=["runtime", "timeout", "task_failure", "runtime"]),
        make_record(seed=2, status="model_error", categories=["syntax", "model_error"]),
        make_record(seed=3, status="failed", categories=["sandbox_error", "task_failure"]),
    ]
    (row,) = summarize(records)
    assert {c: row[c] for c in CATEGORIES} == {
        "parsing": 1,
        "syntax": 2,
        "runtime": 2,
        "timeout": 1,
        "task_failure": 2,
        "model_error": 1,
        "sandbox_error": 1,
    }
    assert "success" not in row


def test_tokens_and_cost_totals_with_none_propagation() -> None:
    priced = [make_record(seed=0, cost=0.25), make_record(seed=1, cost=0.5, status="failed")]
    (row,) = summarize(priced)
    assert row["cost"] == pytest.approx(0.75)
    assert row["prompt_tokens"] == 1000 * (2 + 7)
    assert row["completion_tokens"] == 100 * (2 + 7)
    (unknown,) = summarize([*priced, make_record(seed=2, cost=None)])
    assert unknown["cost"] is None
    # A harness error made no model call: it has no price, and costs nothing.
    (with_error,) = summarize([*priced, make_record(seed=3, status="error")])
    assert with_error["cost"] == pytest.approx(0.75)


def test_groups_are_ordered_as_in_the_paper() -> None:
    scenarios = ["zeta-other", "plan-stl", "arm-reach", "plan-hard", "track-car", "plan-easy", "track-lin"]
    methods = ["predict", "code", "use-api"]
    records = [make_record(scenario=s, method=m) for s in scenarios for m in methods]
    rows = summarize(records)
    order = [(r["scenario"], r["method"]) for r in rows]
    expected_scenarios = [
        "track-lin",
        "track-car",
        "plan-easy",
        "plan-hard",
        "plan-stl",
        "arm-reach",
        "zeta-other",
    ]
    assert order == [(s, m) for s in expected_scenarios for m in ["use-api", "code", "predict"]]


def test_temperatures_sort_numerically_and_by_selects_the_grouping() -> None:
    records = [
        make_record(temperature=t, seed=s, status="solved" if s < 2 else "failed")
        for t in (1.0, 0.0, 0.7)
        for s in range(4)
    ]
    rows = summarize(records)
    assert [r["temperature"] for r in rows] == [0.0, 0.7, 1.0]
    (pooled,) = summarize(records, by=("method",))
    assert set(pooled) >= {"method", "n", "success_rate"}
    assert "scenario" not in pooled
    assert (pooled["n"], pooled["solved"]) == (12, 6)
    (everything,) = summarize(records, by=())
    assert everything["n"] == 12
    assert summarize([]) == []


def test_summarize_rejects_bad_input() -> None:
    with pytest.raises(InvalidArgumentError, match="by: expected a sequence of field names"):
        summarize([make_record()], by="scenario")
    with pytest.raises(InvalidArgumentError, match=r"records\[1\]: expected a record dict"):
        summarize([make_record(), 3])  # type: ignore[list-item]
    broken = make_record()
    del broken["categories"]
    with pytest.raises(AudereError, match="expected a field 'categories'"):
        summarize([broken])


# --------------------------------------------------------------------------------------------------
# success@k
# --------------------------------------------------------------------------------------------------


def test_success_at_k_is_monotone_and_ends_at_the_success_rate() -> None:
    records = [
        make_record(seed=0, categories=["success"]),
        make_record(seed=1, categories=["syntax", "success"]),
        make_record(seed=2, categories=["syntax", "runtime", "task_failure", "success"]),
        make_record(seed=3, status="failed"),
        make_record(seed=4, status="model_error"),
    ]
    rows = success_at_k(records)
    assert [r["k"] for r in rows] == [1, 2, 3, 4, 5, 6]
    rates = [r["success_rate"] for r in rows]
    assert rates == pytest.approx([1 / 4, 2 / 4, 2 / 4, 3 / 4, 3 / 4, 3 / 4])
    assert all(a <= b for a, b in itertools.pairwise(rates))
    (summary,) = summarize(records)
    assert rates[-1] == pytest.approx(summary["success_rate"])
    assert all(r["n"] == 4 for r in rows)
    assert (rows[0]["ci_low"], rows[0]["ci_high"]) == pytest.approx(wilson(1, 4))
    assert {k: rows[0][k] for k in GROUP} == {k: summary[k] for k in GROUP}


def test_success_at_k_range_and_groups() -> None:
    records = [
        make_record(method="use-api", max_rounds=3, categories=["success"]),
        make_record(method="code", max_rounds=5, categories=["runtime", "success"]),
    ]
    rows = success_at_k(records)
    # k runs to the largest max_rounds, for every group.
    assert [(r["method"], r["k"]) for r in rows] == [("use-api", k) for k in range(1, 6)] + [
        ("code", k) for k in range(1, 6)
    ]
    code = [r["success_rate"] for r in rows if r["method"] == "code"]
    assert code == [0.0, 1.0, 1.0, 1.0, 1.0]
    assert len(success_at_k(records, k_max=2)) == 4
    assert success_at_k([]) == []
    with pytest.raises(InvalidArgumentError, match="k_max: expected an integer >= 1 or None, got 0"):
        success_at_k(records, k_max=0)


# --------------------------------------------------------------------------------------------------
# Reading
# --------------------------------------------------------------------------------------------------


def write_lines(path: Path, lines: list[str]) -> Path:
    path.write_text("".join(lines), encoding="utf-8")
    return path


def test_read_records_skips_a_torn_last_line(tmp_path: Path) -> None:
    records = [make_record(seed=s) for s in range(3)]
    torn = json.dumps(make_record(seed=3))[:57]
    write_lines(tmp_path / "results.jsonl", [json.dumps(r) + "\n" for r in records] + [torn])
    assert read_records(tmp_path) == records
    assert read_records(tmp_path / "results.jsonl") == records
    # A blank line, and a torn line followed by a newline, at the end are skipped too.
    write_lines(tmp_path / "results.jsonl", [json.dumps(r) + "\n" for r in records] + ["\n", torn + "\n"])
    assert read_records(tmp_path) == records


def test_read_records_keeps_the_first_record_of_a_key(tmp_path: Path) -> None:
    first = make_record(seed=1, status="model_error")
    again = {**make_record(seed=1), "key": first["key"]}
    write_lines(tmp_path / "results.jsonl", [json.dumps(first) + "\n", json.dumps(again) + "\n"])
    assert read_records(tmp_path) == [first]


def test_read_records_names_a_malformed_line(tmp_path: Path) -> None:
    lines = [json.dumps(make_record(seed=0)) + "\n", "{not json\n", json.dumps(make_record(seed=2)) + "\n"]
    path = write_lines(tmp_path / "results.jsonl", lines)
    with pytest.raises(AudereError, match=r"results\.jsonl: line 2: expected a JSON object"):
        read_records(path)
    write_lines(path, [json.dumps(make_record(seed=0)) + "\n", "[1, 2]\n", "{}\n"])
    with pytest.raises(AudereError, match="line 2: expected a JSON object, got list"):
        read_records(path)
    with pytest.raises(AudereError, match="no file"):
        read_records(tmp_path / "missing")


# --------------------------------------------------------------------------------------------------
# Tables
# --------------------------------------------------------------------------------------------------


def test_markdown_table() -> None:
    rows = summarize(
        [
            make_record(method="use-api", seed=0),
            make_record(method="code", seed=0, status="failed", cost=None),
        ]
    )
    table = format_markdown(rows, columns=["scenario", "method", "n", "success_rate", "ci_high", "cost"])
    lines = table.splitlines()
    assert lines[0] == "| scenario | method | n | success_rate | ci_high | cost |"
    assert lines[1] == "|:---|:---|---:|---:|---:|---:|"
    assert lines[2] == "| plan-easy | use-api | 1 | 1 | 1 | 0.01 |"
    assert lines[3] == "| plan-easy | code | 1 | 0 | 0.7935 | – |"
    assert table.endswith("\n")
    full = format_markdown(rows)
    assert full.splitlines()[0].split(" | ")[:3] == ["| scenario", "method", "model"]
    assert len(full.splitlines()[0].split("|")) - 2 == len(rows[0])
    assert format_markdown([{"name": "a|b", "values": [1, 2]}]).splitlines()[2] == "| a\\|b | 1, 2 |"
    assert format_markdown([]) == ""


def test_csv_round_trip(tmp_path: Path) -> None:
    rows = summarize([make_record(method="use-api"), make_record(method="code", status="failed", cost=None)])
    path = write_csv(rows, tmp_path / "deep" / "summary.csv")
    with path.open(newline="", encoding="utf-8") as handle:
        read = list(csv.DictReader(handle))
    assert list(read[0]) == list(rows[0])
    assert [r["method"] for r in read] == ["use-api", "code"]
    assert read[0]["success_rate"] == "1.0"
    assert read[1]["cost"] == ""
    assert read[1]["mean_rounds_to_success"] == ""
    assert float(read[1]["ci_high"]) == rows[1]["ci_high"]
