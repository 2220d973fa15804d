"""The ``audere`` command line: every command, its output and its exit code, errors included."""

from __future__ import annotations

import importlib.util
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

import audere
from audere.cli import app
from audere.tasks import ReachAvoidTask, load_task, save_task
from audere.world import Circle

runner = CliRunner()

needs_scenarios = pytest.mark.skipif(
    importlib.util.find_spec("audere.scenarios") is None, reason="audere.scenarios is not written yet"
)


def _task_file(tmp_path: Path, suffix: str = ".yaml") -> Path:
    task = ReachAvoidTask(
        name="cli/test", x0=(1.0, 1.0), goal=(9.0, 9.0), obstacles=(Circle(center=(5.0, 5.0), radius=1.0),)
    )
    return save_task(task, tmp_path / f"task{suffix}")


def _assert_usage_error(result: object, *fragments: str) -> None:
    """Exit code 2, one red line on standard error naming the problem, no traceback."""
    assert result.exit_code == 2, (result.exit_code, result.output)  # type: ignore[attr-defined]
    err = result.stderr  # type: ignore[attr-defined]
    assert err.startswith("error: "), err
    assert len(err.strip().splitlines()) == 1, err
    assert "Traceback" not in result.output  # type: ignore[attr-defined]
    for fragment in fragments:
        assert fragment in err, err


# ---------------------------------------------------------------------------------------- version, help


def test_version() -> None:
    result = runner.invoke(app, ["--version"])
    assert result.exit_code == 0
    assert result.stdout.strip() == f"audere {audere.__version__}"


def test_help_lists_the_commands() -> None:
    result = runner.invoke(app, ["--help"])
    assert result.exit_code == 0
    for command in ("check", "scenarios"):
        assert command in result.stdout


def test_console_script_runs(tmp_path: Path) -> None:
    done = subprocess.run(
        [sys.executable, "-c", "from audere.cli import main; main()", "--version"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        timeout=120,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == f"audere {audere.__version__}"


# ---------------------------------------------------------------------------------------- check


def test_check_success_from_npy(tmp_path: Path) -> None:
    task_file = _task_file(tmp_path)
    path = np.array([[1.0, 1.0], [1.0, 9.0], [9.0, 9.0]])  # around the circle at (5, 5)
    np.save(tmp_path / "path.npy", path)
    result = runner.invoke(app, ["check", str(task_file), str(tmp_path / "path.npy")])
    assert result.exit_code == 0, result.output
    first, *rest = result.stdout.splitlines()
    assert first.startswith("success")
    assert load_task(task_file).check(path).feedback() in result.stdout
    assert rest


def test_check_failure_from_json_with_plot(tmp_path: Path) -> None:
    task_file = _task_file(tmp_path, ".json")
    solution = tmp_path / "solution.json"
    solution.write_text(json.dumps({"waypoints": [[1.0, 1.0], [9.0, 9.0]]}), encoding="utf-8")
    image = tmp_path / "check.png"
    result = runner.invoke(app, ["check", str(task_file), str(solution), "--plot", str(image)])
    assert result.exit_code == 1, result.output
    assert result.stdout.startswith("failure")
    assert "collision" in result.stdout  # the straight line crosses the circle
    assert image.read_bytes()[:4] == b"\x89PNG"
    assert f"wrote {image}" in result.stderr


def test_check_npz_fields_and_json_list(tmp_path: Path) -> None:
    task_file = _task_file(tmp_path)
    path = np.array([[1.0, 1.0], [9.0, 1.0], [9.0, 9.0]])
    np.savez(tmp_path / "solution.npz", waypoints=path)
    (tmp_path / "solution.json").write_text(json.dumps(path.tolist()), encoding="utf-8")
    for name in ("solution.npz", "solution.json"):
        result = runner.invoke(app, ["check", str(task_file), str(tmp_path / name)])
        assert result.exit_code == 0, result.output


def test_check_malformed_solution_is_a_failure_not_an_error(tmp_path: Path) -> None:
    task_file = _task_file(tmp_path)
    np.save(tmp_path / "bad.npy", np.zeros((4, 3)))
    image = tmp_path / "bad.png"
    result = runner.invoke(app, ["check", str(task_file), str(tmp_path / "bad.npy"), "--plot", str(image)])
    assert result.exit_code == 1, result.output
    assert "malformed" in result.stdout
    assert image.stat().st_size > 0


def test_check_missing_task_file(tmp_path: Path) -> None:
    np.save(tmp_path / "path.npy", np.zeros((2, 2)))
    result = runner.invoke(app, ["check", str(tmp_path / "nope.yaml"), str(tmp_path / "path.npy")])
    _assert_usage_error(result, "nope.yaml", "cannot read task file")


def test_check_invalid_task_field(tmp_path: Path) -> None:
    task_file = tmp_path / "task.yaml"
    task_file.write_text("kind: reach_avoid\nx0: [1, 1]\ngoal: [9, 9]\ndt: -1\n", encoding="utf-8")
    np.save(tmp_path / "path.npy", np.zeros((2, 2)))
    result = runner.invoke(app, ["check", str(task_file), str(tmp_path / "path.npy")])
    _assert_usage_error(result, "task.yaml", "dt")


@pytest.mark.parametrize(
    ("name", "content", "fragment"),
    [
        ("solution.txt", "1 2", "must end in .npy, .npz or .json"),
        ("solution.json", "{not json", "not valid JSON"),
        ("solution.json", '"a string"', "must be an object of Solution fields or a list"),
        ("solution.npy", "not an array file", "cannot read the solution"),
        ("missing.npy", None, "no such solution file"),
    ],
)
def test_check_bad_solution_file(tmp_path: Path, name: str, content: str | None, fragment: str) -> None:
    task_file = _task_file(tmp_path)
    if content is not None:
        (tmp_path / name).write_text(content, encoding="utf-8")
    result = runner.invoke(app, ["check", str(task_file), str(tmp_path / name)])
    _assert_usage_error(result, name, fragment)


def test_check_unwritable_plot(tmp_path: Path) -> None:
    task_file = _task_file(tmp_path)
    np.save(tmp_path / "path.npy", np.array([[1.0, 1.0], [9.0, 9.0]]))
    result = runner.invoke(
        app, ["check", str(task_file), str(tmp_path / "path.npy"), "--plot", str(tmp_path / "plot.unknown")]
    )
    _assert_usage_error(result, "cannot write the plot")


# ---------------------------------------------------------------------------------------- scenarios


@needs_scenarios
def test_scenarios_list_table() -> None:
    from audere import scenarios

    result = runner.invoke(app, ["scenarios", "list"], env={"COLUMNS": "200"})
    assert result.exit_code == 0, result.output
    for info in scenarios.list_scenarios():
        assert info.name in result.stdout
        assert ", ".join(info.natural_apis) in result.stdout
    for header in ("name", "paper label", "kind", "dynamics", "capabilities", "natural APIs"):
        assert header in result.stdout


@needs_scenarios
@pytest.mark.parametrize("fmt", ["text", "json", "yaml"])
def test_scenarios_show_formats(fmt: str, tmp_path: Path) -> None:
    from audere import scenarios
    from audere.tasks import parse_task

    name = scenarios.list_scenarios()[0].name
    task = scenarios.make(name, seed=3)
    result = runner.invoke(app, ["scenarios", "show", name, "--seed", "3", "--format", fmt])
    assert result.exit_code == 0, result.output
    if fmt == "text":
        assert result.stdout.strip() == task.describe().strip()
    else:
        assert parse_task(result.stdout, format=fmt) == task  # type: ignore[arg-type]


@needs_scenarios
def test_scenarios_show_plot(tmp_path: Path) -> None:
    from audere import scenarios

    image = tmp_path / "show.png"
    name = scenarios.list_scenarios()[0].name
    result = runner.invoke(app, ["scenarios", "show", name, "--plot", str(image)])
    assert result.exit_code == 0, result.output
    assert image.read_bytes()[:4] == b"\x89PNG"


@needs_scenarios
def test_scenarios_show_unknown_name() -> None:
    result = runner.invoke(app, ["scenarios", "show", "no-such-scenario"])
    _assert_usage_error(result, "no-such-scenario")


def test_scenarios_show_bad_format() -> None:
    result = runner.invoke(app, ["scenarios", "show", "plan-easy", "--format", "xml"])
    assert result.exit_code == 2
    assert "xml" in result.output
