"""``audere solve``, ``audere apis`` and ``audere bench run/report``: output and exit codes."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest
from typer.testing import CliRunner

from audere.cli import app

pytestmark = pytest.mark.skipif(sys.platform != "linux", reason="the agent's sandbox runs on Linux only")

runner = CliRunner()


def _usage_error(result: object, *fragments: str) -> None:
    assert result.exit_code == 2, (result.exit_code, result.output)  # type: ignore[attr-defined]
    err = result.stderr  # type: ignore[attr-defined]
    assert err.startswith("error: "), err
    for fragment in fragments:
        assert fragment in err, err


def test_solve_a_scenario_offline(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("AUDERE_MODEL", raising=False)
    plot, save, page = tmp_path / "out.png", tmp_path / "result.json", tmp_path / "rounds.html"
    args = [
        "solve",
        "track-lin",
        "--seed",
        "3",
        "--plot",
        str(plot),
        "--save",
        str(save),
        "--html",
        str(page),
    ]
    result = runner.invoke(app, args)
    assert result.exit_code == 0, result.output
    out = result.stdout
    assert "offline rule-based expert, not an LLM" in out
    assert "round 1: success  selected: lqr  called: lqr" in out
    assert "from audere.controllers import lqr" in out  # the round's code is shown
    assert "solved: solved in round 1" in out
    assert plot.stat().st_size > 0
    assert json.loads(save.read_text())["status"] == "solved"
    assert "<section" in page.read_text()


def test_solve_fails_with_exit_1_and_free_text_with_the_expert() -> None:
    result = runner.invoke(app, ["solve", "Go from the door to the window.", "--no-code"])
    assert result.exit_code == 1, result.output
    assert "cannot read free text" in result.stdout


def test_solve_predict_failure_exit_1() -> None:
    result = runner.invoke(
        app, ["solve", "plan-easy", "--seed", "1", "--method", "predict", "--max-rounds", "1"]
    )
    assert result.exit_code == 1
    assert "round 1: task_failure" in result.stdout


@pytest.mark.parametrize(
    ("args", "fragments"),
    [
        (["solve", "plan-easy"], ["seed: expected an integer seed"]),
        (["solve", "missing.yaml"], ["does not exist"]),
        (["apis", "dijkstra"], ["dijkstra"]),
        (["bench", "run", "--seeds", "x"], ["seeds: expected"]),
        (["bench", "run", "--scenarios", "nope"], ["scenarios: unknown"]),
        (["bench", "run", "--methods", "guess"], ["methods: unknown"]),
        (["bench", "report", "/no/such/dir"], ["not a results directory"]),
    ],
)
def test_usage_errors(args: list[str], fragments: list[str]) -> None:
    _usage_error(runner.invoke(app, args), *fragments)


def test_apis() -> None:
    listing = runner.invoke(app, ["apis"])
    assert listing.exit_code == 0
    for name in ("astar", "cem", "grad", "lqr", "milp", "mpc", "pid", "rrt"):
        assert name in listing.stdout
    card = runner.invoke(app, ["apis", "rrt"])
    assert card.exit_code == 0
    assert card.stdout.startswith("# rrt:")
    source = runner.invoke(app, ["apis", "rrt", "--source"])
    assert "def rrt(" in source.stdout
    assert len(source.stdout) > len(card.stdout)


def test_bench_run_then_report(tmp_path: Path) -> None:
    out = tmp_path / "results"
    args = [
        "bench",
        "run",
        "--out",
        str(out),
        "--scenarios",
        "track-lin,plan-easy",
        "--methods",
        "use-api,predict",
    ]
    run = runner.invoke(app, [*args, "--seeds", "2", "--quiet"])
    assert run.exit_code == 0, run.output
    assert "8 experiments: 0 already done, 8 run now" in run.stdout
    again = runner.invoke(app, [*args, "--seeds", "2", "--quiet"])
    assert "8 experiments: 8 already done, 0 run now" in again.stdout
    key = json.loads((out / "results.jsonl").read_text().splitlines()[0])["key"]
    report = runner.invoke(app, ["bench", "report", str(out), "--experiment", key])
    assert report.exit_code == 0, report.output
    assert "| track-lin |" in report.stdout
    assert (out / "report" / "summary.md").exists()
    assert (out / "report" / "summary.csv").exists()
    assert (out / "report" / "figures" / "success_and_rounds.png").stat().st_size > 0
    assert (out / "report" / "figures" / "success_and_rounds.svg").stat().st_size > 0
    assert list((out / "report" / "experiments").glob("*.html"))
