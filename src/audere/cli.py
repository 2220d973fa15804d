"""The ``audere`` command line: solve a task with the agent, run and report the benchmark, and more.

``audere solve TASK``, ``audere bench run ...``, ``audere bench report DIR``, ``audere apis [NAME]``,
``audere scenarios list``, ``audere scenarios show NAME``, ``audere check TASK_FILE SOLUTION_FILE`` and
``audere --version``. Each command group is its own :class:`typer.Typer` added to :data:`app`, so new
commands (``solve``, ``bench``) are added with ``app.add_typer(...)`` or ``@app.command()``.

Exit codes: 0 success; 1 a checked solution fails; 2 a usage error (unknown scenario, unreadable
or invalid file), reported as one red line on standard error without a traceback.
"""

from __future__ import annotations

import json
from enum import StrEnum
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, NoReturn

import typer
from pydantic import ValidationError
from rich import box
from rich.console import Console
from rich.markup import escape
from rich.table import Table

import audere
from audere.errors import AudereError

if TYPE_CHECKING:
    from audere.tasks import CheckReport, MazeTask, ReachAvoidTask, STLTask, TrackingTask

    AnyTask = TrackingTask | ReachAvoidTask | MazeTask | STLTask

__all__ = ["app", "main"]

app = typer.Typer(
    name="audere",
    help="Robot planning and control driven by language models: solve, benchmark, scenarios, checkers.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    rich_markup_mode="rich",
)
scenarios_app = typer.Typer(
    help="The benchmark scenarios: list them, show one as a model sees it.", no_args_is_help=True
)
app.add_typer(scenarios_app, name="scenarios")
bench_app = typer.Typer(
    help="The benchmark: run the experiment grid (resumably), report its metrics.", no_args_is_help=True
)
app.add_typer(bench_app, name="bench")

EXIT_FAILURE = 1
"""A checked solution does not solve its task."""

EXIT_USAGE = 2
"""Bad input: unknown scenario, unreadable or invalid file, bad option value."""


class TaskFormat(StrEnum):
    """How ``scenarios show`` prints a task."""

    text = "text"
    json = "json"
    yaml = "yaml"


def _stdout() -> Console:
    return Console(highlight=False, soft_wrap=True)  # soft wrap: long lines stay whole when piped


def _stderr() -> Console:
    return Console(stderr=True, highlight=False, soft_wrap=True)


def _fail(message: str) -> NoReturn:
    """Print one red line on standard error and exit with :data:`EXIT_USAGE`."""
    _stderr().print(f"[bold red]error:[/bold red] [red]{escape(message)}[/red]")
    raise typer.Exit(EXIT_USAGE)


def _one_line(exc: BaseException) -> str:
    """An exception as one line (pydantic's multi-line messages become ``field: problem; ...``)."""
    if isinstance(exc, ValidationError):
        parts = []
        for error in exc.errors():
            loc = [str(p) for p in error["loc"]]
            if loc and loc[0] in _TASK_KINDS:  # the union's tag: the kind is in the file already
                loc = loc[1:]
            message = error["msg"].removeprefix("Value error, ")
            parts.append(f"{'.'.join(loc)}: {message}" if loc else message)
        return "invalid task: " + "; ".join(parts)
    return " ".join(str(exc).split())


_TASK_KINDS = ("tracking", "reach_avoid", "maze", "stl")


def _version(value: bool) -> None:
    if value:
        typer.echo(f"audere {audere.__version__}")
        raise typer.Exit()


@app.callback()
def _root(
    version: Annotated[
        bool,
        typer.Option("--version", callback=_version, is_eager=True, help="Print the version and exit."),
    ] = False,
) -> None:
    """Robot planning and control driven by language models: scenarios, checkers, plots."""


# ---------------------------------------------------------------------------------------- scenarios


@scenarios_app.command("list")
def scenarios_list() -> None:
    """List the scenarios: name, paper label, task kind, dynamics, capabilities, natural APIs."""
    from audere.scenarios import list_scenarios

    table = Table(box=box.SIMPLE_HEAD, pad_edge=False, header_style="bold")
    table.add_column("name", style="bold cyan", no_wrap=True)
    table.add_column("paper label", min_width=6)
    table.add_column("kind", min_width=6, overflow="fold")
    table.add_column("dynamics", min_width=8, overflow="fold")
    table.add_column("capabilities", min_width=14, ratio=3)
    table.add_column("natural APIs", min_width=10, ratio=2)
    for info in list_scenarios():
        row = (
            info.name,
            info.paper_label or "-",
            info.kind,
            info.dynamics or "none (path)",
            ", ".join(info.capabilities),
            ", ".join(info.natural_apis),
        )
        table.add_row(*(escape(cell) for cell in row))
    out = _stdout()
    if not out.is_terminal:  # piped or captured: do not squeeze the table into 80 columns
        out.width = max(out.width, 120)
    out.print(table)


def _make(name: str, seed: int) -> AnyTask:
    from audere.scenarios import make

    try:
        return make(name, seed=seed)
    except AudereError as exc:
        _fail(_one_line(exc))


@scenarios_app.command("show")
def scenarios_show(
    name: Annotated[str, typer.Argument(help="Scenario name, e.g. plan-easy (see `audere scenarios list`).")],
    seed: Annotated[int, typer.Option("--seed", "-s", help="Random seed of the generated task.")] = 0,
    plot: Annotated[
        Path | None,
        typer.Option(
            "--plot", "-p", help="Also draw the task into this image file (.png, .pdf, .svg).", dir_okay=False
        ),
    ] = None,
    output_format: Annotated[
        TaskFormat,
        typer.Option(
            "--format",
            "-f",
            help="text: the description a model sees; json or yaml: the task file.",
            case_sensitive=False,
        ),
    ] = TaskFormat.text,
) -> None:
    """Generate one task of a scenario and print it (description or task file); optionally plot it."""
    task = _make(name, seed)
    if output_format is TaskFormat.json:
        text = task.to_json()
    elif output_format is TaskFormat.yaml:
        text = task.to_yaml().rstrip("\n")
    else:
        text = task.describe()
    typer.echo(text)
    if plot is not None:
        _save_plot(task, plot)


# ---------------------------------------------------------------------------------------- check


@app.command("check")
def check(
    task_file: Annotated[Path, typer.Argument(help="The task (.json, .yaml or .yml).", dir_okay=False)],
    solution_file: Annotated[
        Path,
        typer.Argument(
            help=(
                "The solution: .npy (a bare array, read by shape as the checker does), .npz or .json "
                "(the Solution fields inputs, states, waypoints, times; a JSON list is a bare array)."
            ),
            dir_okay=False,
        ),
    ],
    plot: Annotated[
        Path | None,
        typer.Option(
            "--plot", "-p", help="Also draw the task, the solution and its first violation.", dir_okay=False
        ),
    ] = None,
    max_chars: Annotated[
        int, typer.Option("--max-chars", min=20, help="Cap on the length of the feedback text.")
    ] = 2000,
) -> None:
    """Check a solution against a task: print the verdict and the feedback a model would get.

    Exit code 0 when the solution solves the task, 1 when it does not.
    """
    from audere.tasks import load_task

    try:
        task = load_task(task_file)
    except (AudereError, ValidationError, ValueError) as exc:
        _fail(f"{task_file}: {_one_line(exc)}")
    solution = _load_solution(solution_file)
    report = task.check(solution)
    out = _stdout()
    colour = "green" if report.success else "red"
    out.print(f"[bold {colour}]{escape(report.summary())}[/bold {colour}]")
    out.print(escape(report.feedback(max_chars=max_chars)))
    if plot is not None:
        malformed = report.first_violation is not None and report.first_violation.kind == "malformed"
        _save_plot(task, plot, solution=None if malformed else solution, report=report)
    raise typer.Exit(0 if report.success else EXIT_FAILURE)


def _load_solution(path: Path) -> Any:
    """A solution file's content: a bare array or a mapping of Solution fields (judged by the checker)."""
    import numpy as np

    suffix = path.suffix.lower()
    if suffix not in (".npy", ".npz", ".json"):
        _fail(
            f"{path}: a solution file must end in .npy, .npz or .json, got {path.suffix or 'no extension'!r}"
        )
    if not path.is_file():
        _fail(f"{path}: no such solution file")
    try:
        if suffix == ".npy":
            return np.load(path, allow_pickle=False)
        if suffix == ".npz":
            with np.load(path, allow_pickle=False) as data:
                return {key: data[key] for key in data.files}
        content = json.loads(path.read_text(encoding="utf-8"))
    except json.JSONDecodeError as exc:
        _fail(f"{path}: not valid JSON: {exc}")
    except (OSError, ValueError) as exc:
        _fail(f"{path}: cannot read the solution: {_one_line(exc)}")
    if not isinstance(content, dict | list):
        _fail(
            f"{path}: a JSON solution must be an object of Solution fields or a list, "
            f"got {type(content).__name__}"
        )
    return content


# ---------------------------------------------------------------------------------------- solve


class MethodName(StrEnum):
    """The agent's methods."""

    use_api = "use-api"
    code = "code"
    predict = "predict"


class ProvisionName(StrEnum):
    """How the APIs' documentation reaches the model."""

    on_demand = "on-demand"
    all = "all"


def _show_event(out: Console, event: Any, *, show_code: bool) -> None:
    from rich.syntax import Syntax

    if event.kind == "task":
        task = event.task
        out.print(
            f"[bold]task[/bold] {escape(task.name or task.kind)}: {escape(task.kind)}, "
            f"dynamics {escape(str(task.dynamics or 'none (a point path)'))}"
        )
    elif event.kind == "call":
        call = event.call
        if call.error:
            out.print(f"  [red]model call ({escape(call.purpose)}) failed: {escape(call.error)}[/red]")
        else:
            tools = ", ".join(name for name, _ in call.tool_calls)
            how = f" -> {escape(tools)}" if tools else ""
            out.print(
                f"  [dim]model call ({escape(call.purpose)}){how}: "
                f"{call.prompt_tokens}+{call.completion_tokens} tokens, {call.latency_s:.2f} s[/dim]"
            )
    elif event.kind == "round":
        r = event.round
        colour = "green" if r.category.value == "success" else "yellow"
        apis = ", ".join(r.selected_apis) or "-"
        called = ", ".join(r.apis_called) or "-"
        out.print(
            f"[bold]round {r.index}[/bold]: [{colour}]{escape(r.category.value)}[/{colour}]  "
            f"selected: {escape(apis)}  called: {escape(called)}  ({r.wall_s:.2f} s)"
        )
        if show_code and r.code:
            lines = r.code.splitlines()
            shown = "\n".join(lines[:60]) + (
                f"\n# ... {len(lines) - 60} more lines" if len(lines) > 60 else ""
            )
            out.print(Syntax(shown, "python", line_numbers=True, word_wrap=True))
        if r.report is not None:
            out.print(f"  check: {escape(r.report.summary())}")
        elif r.feedback:
            out.print(f"  {escape(r.feedback.splitlines()[0][:200])}")


@app.command("solve")
def solve(
    task: Annotated[
        str,
        typer.Argument(
            help="A scenario name (with --seed), a task file (.json/.yaml), or the task in words."
        ),
    ],
    seed: Annotated[int | None, typer.Option("--seed", "-s", help="The scenario seed.")] = None,
    model: Annotated[
        str | None,
        typer.Option(
            "--model", "-m", help="A LiteLLM model string; default $AUDERE_MODEL, else the offline expert."
        ),
    ] = None,
    method: Annotated[
        MethodName, typer.Option("--method", help="use-api, or a baseline.")
    ] = MethodName.use_api,
    max_rounds: Annotated[int, typer.Option("--max-rounds", min=1, help="Most rounds.")] = 6,
    temperature: Annotated[float, typer.Option("--temperature", "-t", min=0.0, max=2.0)] = 0.1,
    provision: Annotated[ProvisionName, typer.Option("--provision")] = ProvisionName.on_demand,
    timeout: Annotated[float, typer.Option("--timeout", min=0.1, help="Seconds per run of the code.")] = 30.0,
    api_base: Annotated[str | None, typer.Option("--api-base", help="An OpenAI-compatible server.")] = None,
    record: Annotated[
        Path | None, typer.Option("--record", help="Append every model call to this cassette.")
    ] = None,
    cassette: Annotated[
        Path | None, typer.Option("--cassette", help="Replay (with --model audere/replay).")
    ] = None,
    plot: Annotated[
        Path | None, typer.Option("--plot", "-p", help="Draw the final trajectory.", dir_okay=False)
    ] = None,
    save: Annotated[
        Path | None, typer.Option("--save", help="Write the whole result as JSON.", dir_okay=False)
    ] = None,
    html: Annotated[
        Path | None, typer.Option("--html", help="Write a report page of every round.", dir_okay=False)
    ] = None,
    show_code: Annotated[bool, typer.Option("--code/--no-code", help="Print each round's code.")] = True,
) -> None:
    """Solve a task with the agent, showing each round as it happens; exit 0 when solved, 1 when not."""
    from audere.agent import Agent

    out = _stdout()
    try:
        agent = Agent(
            task,
            seed=seed,
            model=model,
            method=method.value,
            max_rounds=max_rounds,
            temperature=temperature,
            api_provision=provision.value,
            timeout_s=timeout,
            api_base=api_base,
            record=record,
            cassette=cassette,
            on_event=lambda event: _show_event(out, event, show_code=show_code),
        )
    except (AudereError, ValueError) as exc:
        _fail(_one_line(exc))
    out.print(f"[bold]model[/bold] {escape(agent.model_label)}  [bold]method[/bold] {method.value}")
    result = agent.solve()
    if result.task is not None and agent.task_text is not None:
        out.print("[bold]the task as parsed from the text[/bold]:")
        out.print(escape(result.task.describe()))
    colour = "green" if result.success else "red"
    out.print(f"[bold {colour}]{escape(result.summary())}[/bold {colour}]")
    if save is not None:
        result.save(save)
        _stderr().print(f"wrote {escape(str(save))}")
    if html is not None:
        from audere.bench._report import experiment_html

        html.write_text(experiment_html(result), encoding="utf-8")
        _stderr().print(f"wrote {escape(str(html))}")
    if plot is not None and result.task is not None:
        last = result.rounds[-1] if result.rounds else None
        solution = result.solution or (last.solution if last else None)
        _save_plot(result.task, plot, solution=solution, report=result.report)
    raise typer.Exit(0 if result.success else EXIT_FAILURE)


# ---------------------------------------------------------------------------------------- apis


@app.command("apis")
def apis(
    name: Annotated[
        str | None, typer.Argument(help="An API: print its card (what a model reads first).")
    ] = None,
    source: Annotated[bool, typer.Option("--source", help="Print the implementation instead.")] = False,
) -> None:
    """List the registered APIs (the catalog a model chooses from), or print one's card or source."""
    from audere.apis import api_card, api_source, list_apis

    if name is None:
        table = Table(box=box.SIMPLE_HEAD, pad_edge=False, header_style="bold")
        table.add_column("name", style="bold cyan", no_wrap=True)
        table.add_column("description", ratio=4)
        table.add_column("tags", ratio=2)
        for info in list_apis():
            table.add_row(escape(info.name), escape(info.description), escape(", ".join(info.tags)))
        out = _stdout()
        if not out.is_terminal:
            out.width = max(out.width, 120)
        out.print(table)
        return
    try:
        text = api_source(name) if source else api_card(name)
    except AudereError as exc:
        _fail(_one_line(exc))
    typer.echo(text.rstrip("\n"))


# ---------------------------------------------------------------------------------------- bench


def _split(text: str) -> list[str]:
    return [part.strip() for part in text.split(",") if part.strip()]


@bench_app.command("run")
def bench_run(
    out_dir: Annotated[
        Path, typer.Option("--out", "-o", help="The results directory (rerun to resume).")
    ] = Path("bench-results"),
    scenarios: Annotated[str, typer.Option("--scenarios", help="Comma-separated names, or 'all'.")] = "all",
    methods: Annotated[str, typer.Option("--methods", help="Comma-separated: use-api, code, predict.")] = (
        "use-api,code,predict"
    ),
    models: Annotated[
        str | None,
        typer.Option("--models", help="Comma-separated model strings; default $AUDERE_MODEL or the expert."),
    ] = None,
    temperatures: Annotated[str, typer.Option("--temperatures", help="Comma-separated.")] = "0.1",
    seeds: Annotated[
        str, typer.Option("--seeds", help="A count (100: seeds 0-99), a range (100-199), a list.")
    ] = "100",
    max_rounds: Annotated[int, typer.Option("--max-rounds", min=1)] = 6,
    provision: Annotated[
        str, typer.Option("--provision", help="Comma-separated: on-demand, all.")
    ] = "on-demand",
    timeout: Annotated[float, typer.Option("--timeout", min=0.1, help="Seconds per run of the code.")] = 30.0,
    concurrency: Annotated[
        int, typer.Option("--concurrency", "-j", min=1, help="Experiments in flight.")
    ] = 2,
    workers: Annotated[
        int | None, typer.Option("--workers", min=1, help="Sandbox workers (default: cores).")
    ] = None,
    record: Annotated[
        Path | None, typer.Option("--record", help="Append every model call to this cassette.")
    ] = None,
    cassette: Annotated[
        Path | None, typer.Option("--cassette", help="Replay this cassette (with --models audere/replay).")
    ] = None,
    quiet: Annotated[bool, typer.Option("--quiet", "-q", help="No progress bar.")] = False,
) -> None:
    """Run the experiment grid; every finished experiment is written at once, so a rerun resumes."""
    import os

    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        TextColumn,
        TimeElapsedColumn,
        TimeRemainingColumn,
    )

    from audere.agent._agent import DEFAULT_MODEL
    from audere.bench import make_grid, parse_seeds, run_grid
    from audere.scenarios import list_scenarios

    try:
        names = [i.name for i in list_scenarios()] if scenarios.strip() == "all" else _split(scenarios)
        model_list = _split(models) if models else [os.environ.get("AUDERE_MODEL") or DEFAULT_MODEL]
        grid = make_grid(
            scenarios=names,
            seeds=parse_seeds(seeds),
            methods=_split(methods),
            models=model_list,
            temperatures=[float(t) for t in _split(temperatures)],
            provisions=_split(provision),
            max_rounds=max_rounds,
            timeout_s=timeout,
        )
    except (AudereError, ValueError) as exc:
        _fail(_one_line(exc))
    err = _stderr()
    if model_list == [DEFAULT_MODEL]:
        err.print("no model configured: running the offline expert (a rule-based strategist, not an LLM)")
    options = {
        "scenarios": names,
        "methods": _split(methods),
        "models": model_list,
        "seeds": seeds,
        "temperatures": temperatures,
        "provision": provision,
        "max_rounds": max_rounds,
    }
    progress = Progress(
        TextColumn("[bold]bench[/bold]"),
        BarColumn(),
        MofNCompleteColumn(),
        TextColumn("solved {task.fields[solved]}"),
        TimeElapsedColumn(),
        TextColumn("ETA"),
        TimeRemainingColumn(),
        console=err,
        disable=quiet,
    )
    with progress:
        bar = progress.add_task("run", total=None, solved=0)
        solved = 0

        def tick(done: int, todo: int, record: dict[str, Any]) -> None:
            nonlocal solved
            solved += bool(record["success"])
            progress.update(bar, completed=done, total=todo, solved=solved)

        try:
            summary = run_grid(
                grid,
                out_dir,
                concurrency=concurrency,
                workers=workers,
                record=record,
                cassette=cassette,
                options=options,
                progress=tick,
            )
        except AudereError as exc:
            _fail(_one_line(exc))
    _stdout().print(
        f"{summary.total} experiments: {summary.skipped} already done, {summary.ran} run now "
        f"({summary.solved} solved, {summary.errors} harness errors) in {summary.wall_s:.1f} s "
        f"-> {escape(str(out_dir))}"
    )
    _stdout().print(f"report with: audere bench report {escape(str(out_dir))}")


@bench_app.command("report")
def bench_report(
    results: Annotated[Path, typer.Argument(help="A results directory written by `audere bench run`.")],
    out_dir: Annotated[
        Path | None, typer.Option("--out", "-o", help="Where to write (default DIR/report).")
    ] = None,
    experiment: Annotated[
        str | None,
        typer.Option("--experiment", "-e", help="Also write the HTML page of this experiment's key."),
    ] = None,
) -> None:
    """Tables (Markdown, CSV) and figures (PNG, SVG) of a run; the HTML page of one experiment."""
    from audere.bench._report import write_experiment_html, write_report

    if not results.is_dir():
        _fail(f"{results}: not a results directory")
    try:
        report = write_report(results, out_dir)
        page = write_experiment_html(results, experiment) if experiment else None
    except AudereError as exc:
        _fail(_one_line(exc))
    typer.echo(report.markdown.rstrip("\n"))
    err = _stderr()
    for path in report.paths:
        err.print(f"wrote {escape(str(path))}")
    if page is not None:
        err.print(f"wrote {escape(str(page))}")


# ---------------------------------------------------------------------------------------- plots


def _save_plot(task: AnyTask, path: Path, *, solution: Any = None, report: CheckReport | None = None) -> None:
    from audere.viz import plot

    try:
        fig = plot(task, solution, report)
        fig.savefig(path, dpi=150)
    except (AudereError, ValueError, OSError) as exc:
        _fail(f"cannot write the plot {path}: {_one_line(exc)}")
    _stderr().print(f"wrote {escape(str(path))}")


def main() -> None:
    """Run the ``audere`` command line (the console script's entry point)."""
    app()


if __name__ == "__main__":  # pragma: no cover
    main()
