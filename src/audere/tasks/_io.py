"""Reading and writing task files (JSON or YAML)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Literal

from pydantic import ValidationError

from audere.errors import InvalidArgumentError
from audere.tasks._models import MazeTask, ReachAvoidTask, STLTask, TaskAdapter, TrackingTask

__all__ = ["load_task", "parse_task", "save_task"]

AnyTask = TrackingTask | ReachAvoidTask | MazeTask | STLTask


def parse_task(text: str, *, format: Literal["json", "yaml"] = "yaml") -> AnyTask:
    """Build a task from JSON or YAML text.

    Parameters
    ----------
    text
        The task as JSON or YAML (YAML is a superset of JSON, so ``"yaml"`` reads both).
    format
        ``"json"`` or ``"yaml"``.

    Returns
    -------
    Task
        The validated task.

    Raises
    ------
    pydantic.ValidationError
        When a field is invalid (the message names the field).
    InvalidArgumentError
        When the text cannot be parsed at all.
    """
    if format == "json":
        try:
            data = json.loads(text)
        except json.JSONDecodeError as exc:
            raise InvalidArgumentError(f"task text is not valid JSON: {exc}") from None
    elif format == "yaml":
        import yaml

        try:
            data = yaml.safe_load(text)
        except yaml.YAMLError as exc:
            raise InvalidArgumentError(f"task text is not valid YAML: {exc}") from None
    else:
        raise InvalidArgumentError(f"format must be 'json' or 'yaml', got {format!r}")
    if not isinstance(data, dict):
        raise InvalidArgumentError(f"a task must be a mapping of fields, got {type(data).__name__}")
    return TaskAdapter.validate_python(data)


def load_task(path: str | Path) -> AnyTask:
    """Read a task file (``.json``, ``.yaml`` or ``.yml``).

    Parameters
    ----------
    path
        The file to read.

    Returns
    -------
    Task
        The validated task.

    Raises
    ------
    InvalidArgumentError
        When the file is missing, has an unknown extension or cannot be parsed.
    pydantic.ValidationError
        When a field is invalid.
    """
    p = Path(path)
    if p.suffix.lower() not in {".json", ".yaml", ".yml"}:
        raise InvalidArgumentError(f"path must end in .json, .yaml or .yml, got {str(p)!r}")
    try:
        text = p.read_text(encoding="utf-8")
    except OSError as exc:
        raise InvalidArgumentError(f"cannot read task file {str(p)!r}: {exc.strerror}") from None
    try:
        return parse_task(text, format="json" if p.suffix.lower() == ".json" else "yaml")
    except ValidationError:
        raise
    except InvalidArgumentError as exc:
        raise InvalidArgumentError(f"{p}: {exc}") from None


def save_task(task: AnyTask, path: str | Path) -> Path:
    """Write a task file; the format follows the extension (``.json``, ``.yaml``, ``.yml``).

    Parameters
    ----------
    task
        The task to write.
    path
        Destination file.

    Returns
    -------
    pathlib.Path
        The path written.
    """
    p = Path(path)
    suffix = p.suffix.lower()
    if suffix == ".json":
        p.write_text(task.to_json() + "\n", encoding="utf-8")
    elif suffix in {".yaml", ".yml"}:
        p.write_text(task.to_yaml(), encoding="utf-8")
    else:
        raise InvalidArgumentError(f"path must end in .json, .yaml or .yml, got {str(p)!r}")
    return p
