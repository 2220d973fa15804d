"""The ``audere`` command line: scenarios, checking solutions, plots.

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
    help="Robot planning and control driven by language models: scenarios, checkers, plots.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    rich_markup_mode="rich",
)
scenarios_app = typer.Typer(
    help="The benchmark scenarios: list them, show one as a model sees it.", no_args_is_help=True
)
app.add_typer(scenarios_app, name="scenarios")

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
