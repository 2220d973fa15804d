"""The experiment grid and the append-only results store."""

from __future__ import annotations

import json
import os
import sys
from pathlib import Path

import pytest

from audere.bench import Experiment, ResponseCache, ResultStore, make_grid, parse_seeds, read_jsonl
from audere.bench._store import RESULTS, TRANSCRIPTS, _repair
from audere.errors import AudereError, InvalidArgumentError


@pytest.mark.parametrize(
    ("text", "seeds"),
    [("3", [0, 1, 2]), ("100-102", [100, 101, 102]), ("1,5,9", [1, 5, 9]), (" 2 ", [0, 1]), ("5-5", [5])],
)
def test_parse_seeds(text: str, seeds: list[int]) -> None:
    assert parse_seeds(text) == seeds


@pytest.mark.parametrize("text", ["", "x", "5-2", "0", "-3", "1,a", "1-"])
def test_parse_seeds_rejects(text: str) -> None:
    with pytest.raises(InvalidArgumentError, match="seeds: expected"):
        parse_seeds(text)


def test_make_grid_product_and_provision_only_for_use_api() -> None:
    grid = make_grid(
        scenarios=["track-lin", "plan-easy"],
        seeds=[0, 1],
        methods=["use-api", "code", "predict"],
        models=["audere/expert", "gpt-4o"],
        temperatures=[0.1, 0.7],
        provisions=["on-demand", "all"],
    )
    # use-api: 2 provisions; code and predict: once each
    assert len(grid) == 2 * 2 * 2 * 2 * (2 + 1 + 1)
    assert len({e.key for e in grid}) == len(grid)
    assert {e.provision for e in grid if e.method != "use-api"} == {"on-demand"}
    assert grid[0].scenario == "track-lin"


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"scenarios": ["nope"]}, r"scenarios: unknown \['nope'\]"),
        ({"methods": ["guess"]}, r"methods: unknown \['guess'\]"),
        ({"provisions": ["some"]}, r"provisions: unknown \['some'\]"),
        ({"temperatures": [3.0]}, "temperatures: expected values in"),
        ({"models": [" "]}, "models: expected at least one"),
        ({"scenarios": []}, "scenarios: expected at least one"),
        ({"seeds": []}, "seeds: expected at least one"),
    ],
)
def test_make_grid_rejects(kwargs: dict[str, object], match: str) -> None:
    base: dict[str, object] = {"scenarios": ["track-lin"], "seeds": [0]}
    with pytest.raises(InvalidArgumentError, match=match):
        make_grid(**{**base, **kwargs})  # type: ignore[arg-type]


def test_experiment_key_is_stable() -> None:
    e = Experiment(scenario="plan-easy", seed=3)
    assert e.key == "plan-easy/seed=3/use-api/audere/expert/t=0.1/on-demand/rounds=6/timeout=30"
    assert Experiment.model_validate(e.model_dump()).key == e.key


def _record(key: str) -> dict[str, object]:
    return {"key": key, "status": "solved", "success": True}


def test_store_appends_once_and_survives_a_torn_line(tmp_path: Path) -> None:
    with ResultStore(tmp_path) as store:
        assert store.append(_record("a"), {"x": 1})
        assert not store.append(_record("a"), {"x": 2})  # never twice
        assert store.append(_record("b"), None)
    with open(tmp_path / RESULTS, "ab") as handle:  # a kill in the middle of a write
        handle.write(b'{"key": "c", "sta')
    assert [r["key"] for r in read_jsonl(tmp_path / RESULTS)] == ["a", "b"]  # the torn line is skipped
    with ResultStore(tmp_path) as store:  # opening repairs it
        assert store.done_keys() == {"a", "b"}
        assert store.append(_record("c"), None)
    lines = (tmp_path / RESULTS).read_text().splitlines()
    assert [json.loads(line)["key"] for line in lines] == ["a", "b", "c"]
    assert [t["key"] for t in read_jsonl(tmp_path / TRANSCRIPTS)] == ["a"]


def test_repair_cuts_only_a_torn_tail(tmp_path: Path) -> None:
    path = tmp_path / "f.jsonl"
    path.write_bytes(b'{"a": 1}\n{"b": 2}\n')
    assert _repair(path) == 0
    path.write_bytes(b'{"a": 1}\n{"b"')
    assert _repair(path) == 4
    assert path.read_bytes() == b'{"a": 1}\n'
    path.write_bytes(b'{"b"')
    assert _repair(path) == 4
    assert path.read_bytes() == b""


def test_malformed_middle_line_is_an_error(tmp_path: Path) -> None:
    path = tmp_path / RESULTS
    path.write_text('{"key": "a"}\nnot json\n{"key": "b"}\n')
    with pytest.raises(AudereError, match="line 2: expected a JSON object"):
        list(read_jsonl(path))


@pytest.mark.skipif(sys.platform != "linux", reason="flock semantics")
def test_one_run_at_a_time(tmp_path: Path) -> None:
    with ResultStore(tmp_path), pytest.raises(AudereError, match="another run is writing"):
        ResultStore(tmp_path).__enter__()


def test_out_must_be_a_directory(tmp_path: Path) -> None:
    file = tmp_path / "file"
    file.write_text("")
    with pytest.raises(InvalidArgumentError, match="out: expected a directory"):
        ResultStore(file)


def test_response_cache_round_trip(tmp_path: Path) -> None:
    from audere.agent._llm import Reply, ToolCall

    reply = Reply(
        content="hi",
        tool_calls=(ToolCall(id="call_0", name="submit_code", arguments="{}"),),
        prompt_tokens=10,
        completion_tokens=2,
        cost=0.001,
        latency_s=0.5,
        model="gpt-4o",
        finish_reason="tool_calls",
    )
    cache = ResponseCache(tmp_path / "responses.jsonl")
    assert cache.get("k") is None
    cache.put("k", "gpt-4o", {}, reply)
    cache.put("k", "gpt-4o", {}, reply)  # kept once
    again = ResponseCache(tmp_path / "responses.jsonl")
    assert len(again) == 1
    assert again.get("k") == reply
    assert again.hits == 1
    assert os.path.getsize(tmp_path / "responses.jsonl") > 0


def test_load_results_gives_one_row_per_experiment(tmp_path: Path) -> None:
    pytest.importorskip("pandas")
    from audere.bench import load_results

    with ResultStore(tmp_path) as store:
        for key, seed in (("a", 0), ("b", 1)):
            store.append(
                {**_record(key), "scenario": "track-lin", "seed": seed, "categories": ["success"]}, None
            )
    with open(tmp_path / RESULTS, "a") as handle:  # a duplicate line (never written by the store)
        handle.write(json.dumps({**_record("a"), "seed": 99}) + "\n")
    frame = load_results(tmp_path)
    assert list(frame["key"]) == ["a", "b"]
    assert list(frame["seed"]) == [0, 1]
    assert {"scenario", "status", "success", "categories"} <= set(frame.columns)
    assert len(load_results(tmp_path / RESULTS)) == 2
