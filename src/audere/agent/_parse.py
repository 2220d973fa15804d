"""Reading model replies: code blocks, answer lines, JSON objects, tool-call arguments, entry points.

Pure functions over text. Each reader returns ``None`` (or raises :class:`ReplyError` with a message
meant for the model) instead of guessing.
"""

from __future__ import annotations

import ast
import json
import re
from collections.abc import Iterable, Mapping, Sequence
from typing import Any

import numpy as np

__all__ = [
    "ENTRY_POINT",
    "ReplyError",
    "check_entry_point",
    "extract_apis",
    "extract_code",
    "extract_json",
    "extract_missing",
    "parse_arguments",
    "parse_prediction",
]

ENTRY_POINT = "solve"
"""The function the model's code must define: ``solve(task) -> Solution``."""

_FENCE = re.compile(r"```[ \t]*([A-Za-z0-9_+-]*)[^\n]*\n(.*?)```", re.S)
_APIS_LINE = re.compile(r"^[ \t>*_`#-]*APIs?[ \t*_`]*:[ \t*_`]*(.+?)[ \t*_`]*$", re.I | re.M)
_MISSING_LINE = re.compile(r"^[ \t>*_`-]*MISSING[ \t*_`]*:[ \t]*(.+?)[ \t]*$", re.M)
_PREDICTION_FIELDS = ("inputs", "states", "waypoints", "times")


class ReplyError(ValueError):
    """A reply that cannot be used; the message is feedback for the model."""


def _blocks(text: str) -> list[tuple[str, str]]:
    return [(lang.lower(), body) for lang, body in _FENCE.findall(text or "")]


def extract_code(text: str) -> str | None:
    """The Python code of a reply: its last fenced ``python`` block.

    A fenced block without a language counts when it defines the entry point. ``None`` when the
    reply holds no such block.
    """
    blocks = _blocks(text)
    python = [body for lang, body in blocks if lang in ("python", "py", "python3")]
    if python:
        return python[-1].strip("\n") + "\n"
    bare = [body for lang, body in blocks if not lang and f"def {ENTRY_POINT}" in body]
    return bare[-1].strip("\n") + "\n" if bare else None


def extract_apis(text: str) -> list[str] | None:
    """The API names of an ``APIs: a, b`` line (the last one), or ``None`` when there is none."""
    lines = _APIS_LINE.findall(text or "")
    if not lines:
        return None
    names = [n.strip(" `*_'\".").lower() for n in re.split(r"[,;]|\s+and\s+|\s+", lines[-1])]
    return list(dict.fromkeys(n for n in names if n))


def extract_missing(text: str) -> str | None:
    """The text of a ``MISSING: field: reason`` line, or ``None``."""
    found = _MISSING_LINE.findall(text or "")
    return found[0] if found else None


def extract_json(text: str) -> Any:
    """The JSON value of a reply: its last fenced ``json`` block, else the first ``{...}`` that parses.

    Raises
    ------
    ReplyError
        When a ``json`` block does not parse, or the reply holds no JSON object at all.
    """
    blocks = [body for lang, body in _blocks(text) if lang in ("json", "")]
    if blocks:
        body = blocks[-1]
        try:
            return json.loads(body)
        except json.JSONDecodeError as error:
            raise ReplyError(f"the JSON block does not parse: {error}") from None
    decoder = json.JSONDecoder()
    for match in re.finditer(r"\{", text or ""):
        try:
            value, _ = decoder.raw_decode(text, match.start())
        except json.JSONDecodeError:
            continue
        return value
    raise ReplyError("the reply holds no JSON object (expected one fenced ```json block)")


def parse_arguments(name: str, arguments: str) -> dict[str, Any]:
    """The arguments of a tool call as a JSON object.

    Raises
    ------
    ReplyError
        When they are not a JSON object.
    """
    try:
        value = json.loads(arguments or "{}")
    except json.JSONDecodeError as error:
        raise ReplyError(f"the arguments of the tool call `{name}` are not valid JSON: {error}") from None
    if not isinstance(value, dict):
        raise ReplyError(
            f"the arguments of the tool call `{name}` must be a JSON object, got {type(value).__name__}"
        )
    return value


def check_entry_point(code: str) -> str | None:
    """Why ``code`` cannot run, for the model: a syntax error or a missing ``solve``; ``None`` if fine."""
    try:
        tree = ast.parse(code, filename="<agent_code>")
    except SyntaxError as error:
        where = f"line {error.lineno}" + (f", column {error.offset}" if error.offset else "")
        text = (error.text or "").rstrip("\n")
        shown = f"\n    {text}" if text.strip() else ""
        return f"SyntaxError at {where}: {error.msg}{shown}"
    except ValueError as error:  # e.g. null bytes
        return f"SyntaxError: {error}"
    for node in tree.body:
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef) and node.name == ENTRY_POINT:
            if isinstance(node, ast.AsyncFunctionDef):
                return f"`{ENTRY_POINT}` must be a plain function, not `async def`"
            if not node.args.args and not node.args.vararg:
                return f"`{ENTRY_POINT}` must take the task as its argument: `def {ENTRY_POINT}(task):`"
            return None
        if isinstance(node, ast.Assign) and any(
            isinstance(t, ast.Name) and t.id == ENTRY_POINT for t in node.targets
        ):
            return None
    return f"the code does not define the entry point `def {ENTRY_POINT}(task):` at the top level"


def parse_prediction(value: Any, *, accepted: Iterable[str]) -> dict[str, np.ndarray]:
    """Numeric arrays from a predicted solution (a JSON object of the solution's fields).

    Parameters
    ----------
    value
        The decoded JSON.
    accepted
        The solution fields the task accepts (``inputs``, ``states``, ``waypoints``, ``times``).

    Raises
    ------
    ReplyError
        For anything but an object of finite numeric arrays in accepted fields.
    """
    allowed = set(accepted)
    if not isinstance(value, Mapping):
        raise ReplyError(
            f"the answer must be a JSON object with {sorted(allowed)}, got {type(value).__name__}"
        )
    unknown = [k for k in value if k not in _PREDICTION_FIELDS]
    if unknown:
        raise ReplyError(f"unknown field(s) {unknown}: the answer may hold {sorted(allowed)}")
    fields = {k: v for k, v in value.items() if v is not None}
    if not fields:
        raise ReplyError(f"the answer holds none of the fields {sorted(allowed)}")
    refused = [k for k in fields if k not in allowed]
    if refused:
        raise ReplyError(f"this task does not accept {refused}: give {sorted(allowed)}")
    out: dict[str, np.ndarray] = {}
    for key, raw in fields.items():
        try:
            array = np.asarray(raw, dtype=np.float64)
        except (TypeError, ValueError):
            raise ReplyError(
                f"`{key}` must be an array of numbers (nested lists), got {_short(raw)}"
            ) from None
        if array.size == 0:
            raise ReplyError(f"`{key}` is empty")
        if not np.all(np.isfinite(array)):
            raise ReplyError(f"`{key}` holds values that are not finite numbers")
        out[key] = array
    return out


def _short(value: object, limit: int = 80) -> str:
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def known_apis(names: Sequence[str], chosen: Sequence[str]) -> tuple[list[str], list[str]]:
    """Split ``chosen`` into the registered ``names`` and the unknown ones (both in order)."""
    valid = [n for n in chosen if n in names]
    unknown = [n for n in chosen if n not in names]
    return valid, unknown
