"""A benchmark run killed with SIGKILL mid-way resumes with nothing lost or duplicated; a replayed
cassette reproduces the recorded run's metrics exactly."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from collections import Counter
from pathlib import Path

import pytest

pytestmark = pytest.mark.skipif(sys.platform != "linux", reason="the sandbox runs on Linux only")

from audere.agent import OfflineReply, OfflineRequest, register_model  # noqa: E402
from audere.agent._expert import answer  # noqa: E402
from audere.agent._offline import unregister_model  # noqa: E402
from audere.bench import make_grid, read_jsonl, run_grid  # noqa: E402
from audere.bench._store import RESULTS, TRANSCRIPTS  # noqa: E402

GRID = ["--scenarios", "track-lin,track-double", "--methods", "use-api,predict", "--seeds", "6"]
EXPECTED = 2 * 6 * 2


def _bench(out: Path, *extra: str) -> subprocess.Popen[bytes]:
    env = {**os.environ, "LITELLM_LOCAL_MODEL_COST_MAP": "True", "MPLBACKEND": "Agg"}
    env.pop("AUDERE_MODEL", None)
    command = [
        sys.executable,
        "-m",
        "audere.cli",
        "bench",
        "run",
        "--out",
        str(out),
        *GRID,
        "--quiet",
        *extra,
    ]
    return subprocess.Popen(
        command, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=True
    )


def _lines(path: Path) -> int:
    return path.read_bytes().count(b"\n") if path.exists() else 0


def test_kill_minus_9_then_resume(tmp_path: Path) -> None:
    out = tmp_path / "results"
    run = _bench(out, "--concurrency", "2")
    deadline = time.monotonic() + 240
    while _lines(out / RESULTS) < 4 and run.poll() is None and time.monotonic() < deadline:
        time.sleep(0.05)
    assert run.poll() is None, run.communicate()[1].decode()[-2000:]
    os.killpg(run.pid, signal.SIGKILL)  # the whole run, its sandbox supervisors included
    run.communicate(timeout=30)  # reaps it and closes its pipes
    killed_at = _lines(out / RESULTS)
    assert 4 <= killed_at < EXPECTED

    again = _bench(out)
    stdout, stderr = again.communicate(timeout=600)
    assert again.returncode == 0, stderr.decode()[-2000:]
    assert f"{EXPECTED} experiments: {killed_at} already done" in stdout.decode()

    records = list(read_jsonl(out / RESULTS))
    keys = [r["key"] for r in records]
    assert len(keys) == EXPECTED  # nothing lost
    assert len(set(keys)) == EXPECTED  # nothing duplicated
    assert all(r["status"] in ("solved", "failed") for r in records)
    transcripts = {t["key"] for t in read_jsonl(out / TRANSCRIPTS)}
    assert set(keys) <= transcripts
    runs = [json.loads(line) for line in (out / "runs.jsonl").read_text().splitlines()]
    assert [r["to_do"] for r in runs] == [EXPECTED, EXPECTED - killed_at]


def _careless(request: OfflineRequest) -> OfflineReply:
    """A deterministic 'model': the expert, but its first code always has a syntax error."""
    last = next(m for m in reversed(request.messages) if m.get("role") in ("user", "tool"))
    said = answer(request.messages, request.tools)
    if str(last.get("content", "")).startswith("# Step 2 of 2"):
        return OfflineReply(
            content="```python\ndef solve(task)\n    pass\n```", prompt_tokens=1000, completion_tokens=9
        )
    if said.tool_call is not None:
        return OfflineReply(tool_calls=(said.tool_call,), prompt_tokens=900, completion_tokens=40)
    return OfflineReply(content=said.content, prompt_tokens=900, completion_tokens=40)


def test_replayed_cassette_reproduces_the_metrics(tmp_path: Path) -> None:
    register_model("careless", _careless)
    try:
        grid = make_grid(scenarios=["track-lin", "plan-stl"], seeds=range(3), models=["audere/careless"])
        cassette = tmp_path / "cassette.json"
        recorded = run_grid(grid, tmp_path / "recorded", record=cassette, concurrency=2)
    finally:
        unregister_model("careless")
    assert recorded.ran == 6
    replay = make_grid(scenarios=["track-lin", "plan-stl"], seeds=range(3), models=["audere/replay"])
    replayed = run_grid(replay, tmp_path / "replayed", cassette=cassette, concurrency=2)
    assert replayed.ran == 6

    fields = (
        "status",
        "rounds",
        "rounds_to_success",
        "calls",
        "categories",
        "prompt_tokens",
        "completion_tokens",
        "cost",
        "selected_apis",
        "apis_called",
    )

    def metrics(directory: Path) -> dict[tuple[str, int], tuple[object, ...]]:
        return {
            (r["scenario"], r["seed"]): tuple(r[f] for f in fields) for r in read_jsonl(directory / RESULTS)
        }

    first, second = metrics(tmp_path / "recorded"), metrics(tmp_path / "replayed")
    assert first == second
    assert Counter(v[0] for v in first.values()) == {"solved": 6}
    assert {v[4] == ["syntax", "success"] for v in first.values()} == {True}
