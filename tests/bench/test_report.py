"""Reports: the summary files and figures of a run, and the HTML page of one experiment."""

from __future__ import annotations

import html
import json
import re
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from audere.bench._figures import (
    figure_errors,
    figure_models,
    figure_provision,
    figure_success_and_rounds,
    figure_success_at_k,
    figure_temperature,
    save_figure,
)
from audere.bench._metrics import success_at_k, summarize
from audere.bench._report import experiment_html, safe_key, write_experiment_html, write_report
from audere.errors import AudereError, InvalidArgumentError

from .test_metrics import make_record

if sys.platform == "linux":
    from audere.agent import Agent, ErrorCategory, OfflineReply, ScriptedModel, SolveResult

linux_only = pytest.mark.skipif(sys.platform != "linux", reason="the sandbox runs on Linux only")

STRAIGHT_LINE = """\
import numpy as np
from audere.tasks import Solution

def solve(task):
    return Solution(waypoints=np.array([task.x0, task.goal]))
"""
# Characters that must be escaped in HTML, in the code and in the traceback sent back.
RAISES = """\
def solve(task):
    if len(task.obstacles) > 0 and "<b>" != "&amp;":
        raise ValueError("a < b & c > d")
"""


def write_results(directory: Path, records: list[dict[str, Any]]) -> Path:
    directory.mkdir(parents=True, exist_ok=True)
    lines = "".join(json.dumps(r) + "\n" for r in records)
    (directory / "results.jsonl").write_text(lines, encoding="utf-8")
    return directory


def grid(**overrides: Any) -> list[dict[str, Any]]:
    """A small grid: two scenarios, three methods, four seeds, every outcome."""
    outcomes = [
        ("solved", ["success"]),
        ("solved", ["syntax", "task_failure", "success"]),
        ("failed", ["parsing", "runtime", "timeout", "task_failure", "task_failure", "runtime"]),
        ("model_error", ["task_failure", "model_error"]),
    ]
    return [
        make_record(scenario=scenario, method=method, seed=seed, status=status, categories=cats, **overrides)
        for scenario in ("plan-hard", "track-lin")
        for method in ("code", "use-api", "predict")
        for seed, (status, cats) in enumerate(outcomes)
    ]


# --------------------------------------------------------------------------------------------------
# write_report and the figures
# --------------------------------------------------------------------------------------------------


def test_write_report_writes_tables_and_figures(tmp_path: Path) -> None:
    run = write_results(tmp_path / "run", grid())
    report = write_report(run)
    assert report.out_dir == run / "report"
    assert report.n_records == 24
    for path in report.paths:
        assert path.is_file()
        assert path.stat().st_size > 0
    names = sorted(p.name for p in (run / "report" / "figures").iterdir())
    # One model, one temperature, one provision: those figures have no data and are not written.
    assert names == [
        "errors.png",
        "errors.svg",
        "success_and_rounds.png",
        "success_and_rounds.svg",
        "success_at_k.png",
        "success_at_k.svg",
    ]
    assert sorted(p.name for p in report.figures) == names
    png = (run / "report" / "figures" / "success_and_rounds.png").read_bytes()
    assert png.startswith(b"\x89PNG")
    assert b"<svg" in (run / "report" / "figures" / "errors.svg").read_bytes()[:1000]

    text = (run / "report" / "summary.md").read_text(encoding="utf-8")
    assert text == report.markdown
    assert text.startswith("# Benchmark summary\n")
    assert "24 experiments read" in text
    assert "18 counted (12 solved), 6 ended by infrastructure trouble" in text
    assert "| scenario | `track-lin`, `plan-hard` |" in text  # the paper's order
    assert "| method | `use-api`, `code`, `predict` |" in text
    assert "| seed | 4 (0-3) |" in text
    assert "| model | `openai/gpt-4o` |" in text
    assert "![Error categories](figures/errors.png)" in text
    assert "temperature.png" not in text
    headline, full = [line for line in text.splitlines() if line.startswith("| track-lin | use-api |")]
    assert headline == "| track-lin | use-api | 2/3 | 67 % [21, 94] | 2.00 | 3.00 |"  # the glance table
    assert "| 3 | 1 | 2 | 0.6667 |" in full  # n, n_infra, solved, success_rate

    summary = (run / "report" / "summary.csv").read_text(encoding="utf-8").splitlines()
    assert summary[0].startswith("scenario,method,model,temperature,provision,n,n_infra,solved,success_rate")
    assert len(summary) == 1 + 6
    sak = (run / "report" / "success_at_k.csv").read_text(encoding="utf-8").splitlines()
    assert sak[0] == "scenario,method,model,temperature,provision,k,n,solved,success_rate,ci_low,ci_high"
    assert len(sak) == 1 + 6 * 6


def test_write_report_ablation_figures_and_no_error_figure(tmp_path: Path) -> None:
    records = [
        make_record(scenario=s, method=m, temperature=t, model=model, provision=p, seed=seed)
        for s in ("plan-easy", "plan-stl")
        for m in ("use-api", "code")
        for t in (0.0, 0.7)
        for model in ("openai/gpt-4o", "anthropic/claude-sonnet")
        for p in ("on-demand", "all")
        for seed in range(2)
    ]
    out = tmp_path / "elsewhere"
    report = write_report(write_results(tmp_path / "run", records), out)
    assert report.out_dir == out
    stems = sorted({p.stem for p in (out / "figures").iterdir()})
    # Every experiment solved in round 1: there is no error to draw.
    assert stems == ["models", "provision", "success_and_rounds", "success_at_k", "temperature"]
    assert all(p.stat().st_size > 0 for p in (out / "figures").iterdir())
    assert "| temperature | 0, 0.7 |" in report.markdown
    assert "| provision | `on-demand`, `all` |" in report.markdown


def test_write_report_without_results(tmp_path: Path) -> None:
    with pytest.raises(AudereError, match="no file"):
        write_report(tmp_path)
    (tmp_path / "results.jsonl").write_text('{"key": "torn', encoding="utf-8")
    with pytest.raises(AudereError, match="expected at least one finished experiment"):
        write_report(tmp_path)
    assert not (tmp_path / "report").exists()


def test_figures_directly(tmp_path: Path) -> None:
    records = grid(temperature=0.0) + grid(temperature=1.0)
    rows = summarize(records)
    figures = {
        "fig4": figure_success_and_rounds(rows),
        "fig5": figure_success_at_k(success_at_k(records)),
        "fig6": figure_errors(records),
        "temperature": figure_temperature(rows),
    }
    fig4 = figures["fig4"]
    left, right = fig4.axes[:2]
    assert "Wilson" in left.get_title()
    assert "fraction" in left.get_ylabel()
    assert "rounds" in right.get_ylabel()
    assert fig4.legends  # one legend for both panels
    legend = [t.get_text() for t in fig4.legends[0].get_texts()]
    assert legend == [f"{m} · T={t:g}" for m in ("use-api", "code", "predict") for t in (0.0, 1.0)]
    assert "per scenario" in figures["fig5"].get_suptitle()
    assert [ax.get_title() for ax in figures["fig5"].axes] == ["track-lin", "plan-hard"]
    assert figure_models(rows) is None
    assert figure_provision(rows) is None
    for name, fig in figures.items():
        assert fig is not None
        png, svg = save_figure(fig, tmp_path / "figs" / f"{name}.v1")
        assert (png.name, svg.name) == (f"{name}.v1.png", f"{name}.v1.svg")
        assert png.stat().st_size > 0
        assert svg.stat().st_size > 0
    with pytest.raises(InvalidArgumentError, match="rows: expected at least one row"):
        figure_success_and_rounds([])
    with pytest.raises(InvalidArgumentError, match=r"missing \['solved'\]"):
        figure_success_and_rounds([{"scenario": "x", "method": "code", "n": 1, "mean_rounds_to_success": 1}])


# --------------------------------------------------------------------------------------------------
# One experiment's page, with real transcripts
# --------------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def solved() -> SolveResult:
    return Agent("plan-easy", seed=1).solve()  # the offline expert, through the full loop


@pytest.fixture(scope="module")
def failing() -> Iterator[SolveResult]:
    replies = [
        OfflineReply(content="APIs: rrt\nA sampling planner for a point path."),
        OfflineReply(content=f"Plan: a straight line.\n\n```python\n{STRAIGHT_LINE}```\n"),
        OfflineReply(content="Plan: fix it.\n\n```python\ndef solve(task)\n    return None\n```\n"),
        OfflineReply(content=f"Plan: raise <on purpose>.\n\n```python\n{RAISES}```\n"),
    ]
    with ScriptedModel("bench-report-failing", replies, replace=True) as model:
        yield Agent("plan-easy", seed=1, model=model.model, tool_calls=False, max_rounds=3).solve()


def sections(page: str) -> list[str]:
    return re.findall(r'<section class="round" id="round-\d+">.*?</section>', page, flags=re.S)


@linux_only
def test_experiment_html_of_a_solved_result(solved: SolveResult) -> None:
    assert solved.success
    page = experiment_html(solved)
    assert page.startswith("<!DOCTYPE html>")
    assert "<h1>plan-easy/seed=1</h1>" in page
    assert html.escape(solved.task.describe().splitlines()[0]) in page  # type: ignore[union-attr]
    assert len(sections(page)) == len(solved.rounds) == 1
    # The task alone, then the round's trajectory.
    assert page.count('<img src="data:image/png;base64,') == 2
    assert html.escape(solved.rounds[0].code or "") in page
    assert "APIs called</th><td>rrt" in page
    assert "<b>solved</b>" in page


@linux_only
def test_experiment_html_of_a_failing_multi_round_result(failing: SolveResult) -> None:
    assert failing.status == "failed"
    assert failing.categories == [ErrorCategory.TASK_FAILURE, ErrorCategory.SYNTAX, ErrorCategory.RUNTIME]
    page = experiment_html(failing)
    found = sections(page)
    assert len(found) == 3
    assert "task_failure" in found[0]
    assert "collision" in found[0]  # the checker's feedback of round 1
    assert "data:image/png;base64," in found[0]  # the straight line and its violation
    assert "No solution in this round" in found[1]
    assert "data:image/png" not in found[1]
    assert "SyntaxError" in found[1]
    # Code, plan and traceback are escaped.
    assert html.escape(RAISES) in found[2]
    assert 'raise ValueError("a < b & c > d")' not in page
    assert "a &lt; b &amp; c &gt; d" in found[2]
    assert "Plan: raise &lt;on purpose&gt;." in found[2]
    assert "<on purpose>" not in page
    assert "<b>failed</b>" in page


@linux_only
def test_experiment_html_survives_a_failing_plot(
    solved: SolveResult, monkeypatch: pytest.MonkeyPatch
) -> None:
    import audere.viz

    def broken(*args: object, **kwargs: object) -> None:
        raise RuntimeError("no <canvas> today")

    monkeypatch.setattr(audere.viz, "plot", broken)
    page = experiment_html(solved)
    assert "data:image/png" not in page
    assert page.count("(no plot: RuntimeError: no &lt;canvas&gt; today)") == 2
    assert len(sections(page)) == 1


@linux_only
def test_write_experiment_html_finds_the_transcript(
    tmp_path: Path, solved: SolveResult, failing: SolveResult
) -> None:
    keys = ["plan-easy/seed=1/use-api/audere/expert", "plan-easy/seed=1/use-api/scripted"]
    lines = [
        json.dumps({"key": key, "result": result.model_dump(mode="json")}) + "\n"
        for key, result in zip(keys, [solved, failing], strict=True)
    ]
    (tmp_path / "transcripts.jsonl").write_text("".join(lines) + '{"key": "tor', encoding="utf-8")
    path = write_experiment_html(tmp_path, keys[1])
    assert path == tmp_path / "report" / "experiments" / f"{safe_key(keys[1])}.html"
    assert path.name == "plan-easy_seed_1_use-api_scripted.html"
    assert len(sections(path.read_text(encoding="utf-8"))) == 3
    chosen = write_experiment_html(tmp_path, keys[0], tmp_path / "page.html")
    assert chosen == tmp_path / "page.html"
    assert len(sections(chosen.read_text(encoding="utf-8"))) == 1
    with pytest.raises(AudereError, match=r"expected one of the 2 transcripts .* got 'nope'"):
        write_experiment_html(tmp_path, "nope")


def test_write_experiment_html_errors(tmp_path: Path) -> None:
    with pytest.raises(AudereError, match="no file"):
        write_experiment_html(tmp_path, "a")
    (tmp_path / "transcripts.jsonl").write_text('{"key": "a"}\n', encoding="utf-8")
    with pytest.raises(AudereError, match="line 1: expected a field 'result'"):
        write_experiment_html(tmp_path, "a")
    with pytest.raises(InvalidArgumentError, match="key: expected a non-empty experiment key"):
        write_experiment_html(tmp_path, "")
    assert safe_key("../../etc/passwd") == "etc_passwd"
    assert safe_key("///") == "experiment"
