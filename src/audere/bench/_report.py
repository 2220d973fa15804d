"""Reports of a benchmark run: the summary table and figures, and one HTML page per experiment.

:func:`write_report` turns a results directory (``results.jsonl``) into ``summary.md``,
``summary.csv``, ``success_at_k.csv`` and ``figures/``; :func:`write_experiment_html` turns one
transcript of ``transcripts.jsonl`` into a self-contained page showing every round: what the model
chose, the code it wrote, the trajectory with its violations, and the feedback it was sent.
"""

from __future__ import annotations

import base64
import html
import io
import re
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Final

from audere.bench._figures import (
    figure_errors,
    figure_models,
    figure_provision,
    figure_success_and_rounds,
    figure_success_at_k,
    figure_temperature,
    save_figure,
)
from audere.bench._metrics import (
    CATEGORIES,
    GROUP,
    RESULTS_FILE,
    _order_key,
    format_markdown,
    is_counted,
    read_records,
    success_at_k,
    summarize,
    write_csv,
)
from audere.bench._store import TRANSCRIPTS, iter_jsonl
from audere.errors import AudereError, InvalidArgumentError

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from audere.agent import ModelCall, Round, SolveResult

__all__ = [
    "TRANSCRIPTS_FILE",
    "Report",
    "experiment_html",
    "headline_markdown",
    "safe_key",
    "write_experiment_html",
    "write_report",
]

TRANSCRIPTS_FILE: Final = TRANSCRIPTS
"""The name of the transcripts file inside a results directory."""

_GRID: Final = ("scenario", "seed", "method", "model", "temperature", "provision", "max_rounds")


@dataclass(frozen=True)
class Report:
    """What :func:`write_report` wrote.

    Attributes
    ----------
    out_dir
        The directory written into.
    summary_md, summary_csv, success_at_k_csv
        The summary table (Markdown with a header, and CSV) and the success@k table (CSV).
    figures
        Every figure file written (a PNG and an SVG per figure), in order.
    markdown
        The text of ``summary.md``.
    n_records
        The number of experiments read.
    """

    out_dir: Path
    summary_md: Path
    summary_csv: Path
    success_at_k_csv: Path
    figures: tuple[Path, ...]
    markdown: str
    n_records: int

    @property
    def paths(self) -> tuple[Path, ...]:
        """Every file written."""
        return (self.summary_md, self.summary_csv, self.success_at_k_csv, *self.figures)


# --------------------------------------------------------------------------------------------------
# The run's report
# --------------------------------------------------------------------------------------------------


def _values_text(field: str, values: Sequence[Any]) -> str:
    if field == "seed" and values and all(isinstance(v, int) for v in values):
        if values == list(range(values[0], values[-1] + 1)) and len(values) > 2:
            return f"{len(values)} ({values[0]}-{values[-1]})"
        return f"{len(values)} ({', '.join(str(v) for v in values)})"
    return ", ".join(
        f"`{v}`" if isinstance(v, str) else f"{v:g}" if isinstance(v, float) else str(v) for v in values
    )


def _header(records: Sequence[Mapping[str, Any]], source: Path) -> str:
    counted = sum(1 for r in records if is_counted(r))
    infra = len(records) - counted
    solved = sum(1 for r in records if is_counted(r) and r.get("status") == "solved")
    lines = [
        "# Benchmark summary",
        "",
        f"{len(records)} experiments read from `{source}`: {counted} counted ({solved} solved), "
        f"{infra} ended by infrastructure trouble (model or harness errors, left out of the success rates).",
        "",
        "## Grid",
        "",
        "| variable | values |",
        "|:---|:---|",
    ]
    for field in _GRID:
        values = sorted(
            {r[field] for r in records if field in r and r[field] is not None},
            key=lambda value, f=field: _order_key(f, value),  # type: ignore[misc]
        )
        if values:
            lines.append(f"| {field} | {_values_text(field, values)} |")
    for field in ("prompt_version", "audere_version"):
        versions = sorted({str(r[field]) for r in records if r.get(field) is not None})
        if versions:
            lines.append(f"| {field} | {', '.join(f'`{v}`' for v in versions)} |")
    finished = sorted(str(r["finished_at"]) for r in records if r.get("finished_at"))
    if finished:
        lines.append(f"| finished | {finished[0]} to {finished[-1]} |")
    lines += [
        "",
        "## Results",
        "",
        "`n`: experiments counted; `n_infra`: ended by model or harness errors (not counted); "
        "`success_rate` with its 95 % Wilson interval `ci_low`-`ci_high`; `mean_rounds_to_success` "
        "and `mean_calls_to_success` over the solved experiments (every model call counts, the API "
        "selection included); error columns count the rounds that ended in each category "
        f"({', '.join(CATEGORIES)}); tokens and cost (USD, `–` when a price is unknown) are totals; "
        "wall time in seconds.",
        "",
        "",
    ]
    return "\n".join(lines)


def headline_markdown(rows: Sequence[Mapping[str, Any]]) -> str:
    """A compact table of summary rows: who, success rate with its 95 % interval, rounds, calls.

    Parameters
    ----------
    rows
        Rows of :func:`audere.bench._metrics.summarize`.

    Returns
    -------
    str
        A Markdown table: scenario, method, model (and temperature and provision when they vary),
        solved / counted, success rate [95 % CI], mean rounds to success, mean calls to success.
    """
    varying = [f for f in ("model", "temperature", "provision") if len({r.get(f) for r in rows}) > 1]
    fields = ["scenario", "method", *varying]
    head = [*fields, "solved", "success rate [95 % CI]", "rounds to success", "calls to success"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(fields) + "---:|---:|---:|---:|"]

    def mean(value: Any) -> str:
        return "–" if value is None else f"{value:.2f}"

    for row in rows:
        rate = row.get("success_rate")
        interval = (
            "–"
            if rate is None
            else f"{100 * rate:.0f} % [{100 * row['ci_low']:.0f}, {100 * row['ci_high']:.0f}]"
        )
        cells = [str(row.get(f)) for f in fields]
        cells += [f"{row['solved']}/{row['n']}", interval, mean(row.get("mean_rounds_to_success"))]
        cells.append(mean(row.get("mean_calls_to_success")))
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def write_report(results_dir: str | Path, out_dir: str | Path | None = None) -> Report:
    """Write the report of a benchmark run: tables and figures.

    Parameters
    ----------
    results_dir
        The run's directory (holding ``results.jsonl``).
    out_dir
        Where to write; None is ``<results_dir>/report``.

    Returns
    -------
    Report
        The paths written and the Markdown text. Files: ``summary.md`` (how many experiments, the
        grid's variables, the table of :func:`~audere.bench._metrics.summarize` grouped by
        :data:`~audere.bench._metrics.GROUP`, and the figures), ``summary.csv``, ``success_at_k.csv``
        and, under ``figures/``, PNG and SVG files of ``success_and_rounds``, ``success_at_k``,
        ``errors`` (when some round failed), ``temperature``, ``models`` and ``provision`` (when the
        run has at least two values of that variable).

    Raises
    ------
    AudereError
        If there is no ``results.jsonl``, a line of it is malformed, or it holds no experiment.
    """
    source = Path(results_dir)
    records = read_records(source)
    results_file = source / RESULTS_FILE if source.is_dir() else source
    if not records:
        raise AudereError(
            f"results_dir: expected at least one finished experiment in {str(results_file)!r}, got none "
            "(has the run written any result yet?)"
        )
    target = Path(out_dir) if out_dir is not None else results_file.parent / "report"
    target.mkdir(parents=True, exist_ok=True)
    rows = summarize(records, GROUP)
    sak_rows = success_at_k(records, GROUP)
    summary_csv = write_csv(rows, target / "summary.csv")
    sak_csv = write_csv(sak_rows, target / "success_at_k.csv")

    makers: list[tuple[str, str, Callable[[], Figure | None]]] = [
        ("success_and_rounds", "Success rate and rounds to success", lambda: figure_success_and_rounds(rows)),
        ("success_at_k", "Success within k rounds", lambda: figure_success_at_k(sak_rows)),
    ]
    if any(row[c] for row in rows for c in CATEGORIES):
        makers.append(("errors", "Error categories", lambda: figure_errors(records)))
    makers += [
        ("temperature", "Temperature", lambda: figure_temperature(rows)),
        ("models", "Models", lambda: figure_models(rows)),
        ("provision", "API provision", lambda: figure_provision(rows)),
    ]
    figures: list[Path] = []
    shown: list[str] = []
    for name, caption, make in makers:
        fig = make()
        if fig is None:
            continue
        files = save_figure(fig, target / "figures" / name)
        figures += files
        shown.append(f"![{caption}](figures/{files[0].name})")

    markdown = (
        _header(records, results_file)
        + "## At a glance\n\n"
        + headline_markdown(rows)
        + "\n## Every metric\n\n"
        + format_markdown(rows)
    )
    if shown:
        markdown += "\n## Figures\n\n" + "\n\n".join(shown) + "\n"
    summary_md = target / "summary.md"
    summary_md.write_text(markdown, encoding="utf-8")
    return Report(
        out_dir=target,
        summary_md=summary_md,
        summary_csv=summary_csv,
        success_at_k_csv=sak_csv,
        figures=tuple(figures),
        markdown=markdown,
        n_records=len(records),
    )


# --------------------------------------------------------------------------------------------------
# One experiment's page
# --------------------------------------------------------------------------------------------------

_STYLE: Final = """
body { font-family: system-ui, sans-serif; max-width: 70rem; margin: 1rem auto; padding: 0 1rem;
       color: #1f2933; line-height: 1.4; }
pre { background: #f4f5f7; padding: 0.6rem; overflow-x: auto; white-space: pre-wrap; font-size: 0.85rem; }
section.round { border-top: 2px solid #c8ccd0; margin-top: 1.5rem; padding-top: 0.5rem; }
.success { color: #2e7d32; } .failure { color: #c62828; } .infra { color: #6d6d6d; }
img { max-width: 100%; height: auto; }
table.meta td, table.meta th { text-align: left; padding: 0.1rem 0.8rem 0.1rem 0; vertical-align: top; }
details { margin: 0.3rem 0; }
"""


def _esc(text: object) -> str:
    return html.escape(str(text), quote=True)


def _pre(text: str | None, empty: str = "(none)") -> str:
    if not text:
        return f"<p><i>{_esc(empty)}</i></p>"
    return f"<pre>{_esc(text)}</pre>"


def _png(fig: Figure, alt: str) -> str:
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=90)
    data = base64.b64encode(buffer.getvalue()).decode("ascii")
    return f'<img src="data:image/png;base64,{data}" alt="{_esc(alt)}"/>'


def _plot(result: SolveResult, round_: Round | None, alt: str) -> str:
    """An inline PNG of the task with a round's trajectory and violations, or the error text."""
    if result.task is None:
        return "<p><i>(no plot: there is no task)</i></p>"
    try:
        from audere.viz import plot

        if round_ is None:
            fig = plot(result.task)
        else:
            name = result.task.name or result.task.kind
            fig = plot(result.task, round_.solution, round_.report, title=f"{name}: round {round_.index}")
        return _png(fig, alt)
    except Exception as error:  # a plot must never break the page
        return f'<p class="failure">(no plot: {_esc(type(error).__name__)}: {_esc(error)})</p>'


def _css_class(category: str) -> str:
    if category == "success":
        return "success"
    if category in ("model_error", "sandbox_error"):
        return "infra"
    return "failure"


def _call_html(index: int, call: ModelCall) -> str:
    cost = "" if call.cost is None else f", ${call.cost:.5f}"
    head = (
        f"call {index}: {_esc(call.purpose)} ({call.prompt_tokens}+{call.completion_tokens} tokens{cost}, "
        f"{call.latency_s:.2f} s, {call.attempts} attempt(s))"
    )
    parts = [f"<details><summary>{head}</summary>", "<p>Prompt (new messages):</p>", _pre(call.prompt)]
    parts += ["<p>Response:</p>", _pre(call.response, "(no text)")]
    if call.tool_calls:
        calls = "\n".join(f"{name}({arguments})" for name, arguments in call.tool_calls)
        parts += ["<p>Tool calls:</p>", _pre(calls)]
    if call.error:
        parts += ['<p class="failure">Provider error:</p>', _pre(call.error)]
    parts.append("</details>")
    return "\n".join(parts)


def _execution_html(execution: Mapping[str, Any] | None) -> str:
    if not execution:
        return "<p><i>(the code was not run)</i></p>"
    parts = [f"<p>Sandbox: <b>{_esc(execution.get('status', '?'))}</b></p>"]
    for name in ("stdout", "stderr"):
        text = execution.get(name)
        if text:
            parts += [f"<p>{name}:</p>", _pre(str(text))]
    return "\n".join(parts)


def _round_html(result: SolveResult, round_: Round) -> str:
    category = round_.category.value
    apis = ", ".join(round_.selected_apis) or "(none)"
    called = ", ".join(round_.apis_called) or "(none)"
    verdict = round_.report.summary() if round_.report is not None else ""
    parts = [
        f'<section class="round" id="round-{round_.index}">',
        f'<h2>Round {round_.index}: <span class="{_css_class(category)}">{_esc(category)}</span></h2>',
        '<table class="meta">',
        f"<tr><th>selected APIs</th><td>{_esc(apis)}</td></tr>",
        f"<tr><th>APIs called</th><td>{_esc(called)}</td></tr>",
        f"<tr><th>checker</th><td>{_esc(verdict or '(no report)')}</td></tr>",
        f"<tr><th>time</th><td>{round_.wall_s:.2f} s ({round_.model_s:.2f} s waiting for the model)"
        "</td></tr>",
        "</table>",
    ]
    if round_.solution is None:
        parts.append(f"<p><i>No solution in this round (it ended in {_esc(category)}).</i></p>")
    else:
        parts.append(_plot(result, round_, f"round {round_.index}: trajectory and violations"))
    parts += ["<h3>Plan</h3>", _pre(round_.plan)]
    if round_.code is not None or result.method != "predict":
        parts += ["<h3>Code</h3>", _pre(round_.code, "(no code)")]
    if round_.prediction is not None:
        numbers = "\n".join(f"{name} = {values!r}" for name, values in round_.prediction.items())
        parts += ["<h3>Prediction</h3>", _pre(numbers)]
    parts += ["<h3>Execution</h3>", _execution_html(round_.execution)]
    parts += ["<h3>Feedback sent to the model</h3>", _pre(round_.feedback, "(none: the round succeeded)")]
    if round_.calls:
        parts.append("<h3>Model calls</h3>")
        parts += [_call_html(i, call) for i, call in enumerate(round_.calls, start=1)]
    parts.append("</section>")
    return "\n".join(parts)


def experiment_html(result: SolveResult) -> str:
    """A self-contained HTML page of one experiment's transcript.

    Parameters
    ----------
    result
        The experiment's :class:`audere.agent.SolveResult`.

    Returns
    -------
    str
        The page: the task (name, a picture, and the description the model saw), the verdict, and
        one ``<section class="round">`` per round with its category, the APIs selected and called,
        the round's trajectory drawn on the task with its first violation (or a note when the round
        produced no solution), the plan, the code, the sandbox's output, the feedback sent to the
        model and every model call. Images are inline base64 PNGs and every text is HTML-escaped. A
        plot that fails shows its error text instead.

    Raises
    ------
    InvalidArgumentError
        If ``result`` is not a SolveResult.
    """
    from audere.agent import SolveResult

    if not isinstance(result, SolveResult):
        raise InvalidArgumentError(
            f"result: expected an audere.agent.SolveResult, got {type(result).__name__}"
        )
    task = result.task
    name = (task.name or task.kind) if task is not None else "(no task)"
    verdict_class = "success" if result.success else "infra" if result.status == "model_error" else "failure"
    parts = [
        "<!DOCTYPE html>",
        '<html lang="en"><head><meta charset="utf-8"/>',
        f"<title>{_esc(name)}: {_esc(result.status)}</title>",
        f"<style>{_STYLE}</style></head><body>",
        f"<h1>{_esc(name)}</h1>",
        f'<p class="{verdict_class}"><b>{_esc(result.status)}</b>: {_esc(result.message)}</p>',
        f"<p>{_esc(result.summary())}</p>",
        '<table class="meta">',
        f"<tr><th>method</th><td>{_esc(result.method)}</td></tr>",
        f"<tr><th>model</th><td>{_esc(result.model_label)}</td></tr>",
        f"<tr><th>temperature</th><td>{result.temperature:g}</td></tr>",
        f"<tr><th>API provision</th><td>{_esc(result.api_provision)}</td></tr>",
        f"<tr><th>rounds</th><td>{len(result.rounds)} of at most {result.max_rounds}</td></tr>",
        f"<tr><th>prompt version</th><td>{_esc(result.prompt_version)}</td></tr>",
        "</table>",
        "<h2>Task</h2>",
    ]
    if task is not None:
        parts.append(_plot(result, None, "the task"))
        parts += ["<p>Description the model saw:</p>", _pre(task.describe())]
    else:
        parts.append("<p><i>No task: the text could not be turned into one.</i></p>")
    if result.task_text:
        parts += ["<p>Task text:</p>", _pre(result.task_text)]
    if result.parse_calls:
        parts.append("<h3>Task parsing calls</h3>")
        parts += [_call_html(i, call) for i, call in enumerate(result.parse_calls, start=1)]
    if not result.rounds:
        parts.append("<p><i>No round was played.</i></p>")
    parts += [_round_html(result, round_) for round_ in result.rounds]
    parts.append("</body></html>")
    return "\n".join(parts) + "\n"


def safe_key(key: str) -> str:
    """A file name for an experiment key: runs of characters other than ``A-Za-z0-9._-`` become ``_``.

    Runs of dots become ``_`` too (no ``..``), and dots, dashes and underscores are stripped from the
    ends.

    Parameters
    ----------
    key
        The experiment key.

    Returns
    -------
    str
        The file name stem (never empty, never starting with a dot).
    """
    stem = re.sub(r"[^A-Za-z0-9._-]+", "_", key)
    stem = re.sub(r"_+", "_", re.sub(r"\.{2,}", "_", stem)).strip("._-")
    return stem[:200] or "experiment"


def write_experiment_html(results_dir: str | Path, key: str, path: str | Path | None = None) -> Path:
    """Write the HTML page of one experiment (see :func:`experiment_html`).

    Parameters
    ----------
    results_dir
        The run's directory (holding ``transcripts.jsonl``).
    key
        The experiment's key, as in ``results.jsonl``.
    path
        The page to write; None is ``<results_dir>/report/experiments/<safe key>.html``.

    Returns
    -------
    pathlib.Path
        The page written.

    Raises
    ------
    AudereError
        If there is no ``transcripts.jsonl``, a line of it is malformed, or no transcript has this key
        (the message says how many there are).
    """
    if not isinstance(key, str) or not key:
        raise InvalidArgumentError(f"key: expected a non-empty experiment key, got {key!r}")
    directory = Path(results_dir)
    file = directory / TRANSCRIPTS_FILE
    if not file.is_file():
        raise AudereError(
            f"results_dir: expected a run directory holding {TRANSCRIPTS_FILE}, got {str(directory)!r} "
            f"(no file {str(file)!r})"
        )
    from audere.agent import SolveResult

    found: Any = None
    count = 0
    for number, entry in iter_jsonl(file):
        count += 1
        if entry.get("key") == key and found is None:  # the first, as for the records
            if "result" not in entry:
                raise AudereError(f"{file}: line {number}: expected a field 'result', got {sorted(entry)}")
            found = (number, entry["result"])
    if found is None:
        raise AudereError(f"key: expected one of the {count} transcripts in {str(file)!r}, got {key!r}")
    number, payload = found
    try:
        result = SolveResult.model_validate(payload)
    except ValueError as exc:
        raise AudereError(
            f"{file}: line {number}: the transcript of {key!r} is not a SolveResult: {exc}"
        ) from exc
    target = (
        Path(path) if path is not None else directory / "report" / "experiments" / f"{safe_key(key)}.html"
    )
    target.parent.mkdir(parents=True, exist_ok=True)
    target.write_text(experiment_html(result), encoding="utf-8")
    return target
