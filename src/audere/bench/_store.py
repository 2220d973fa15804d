"""The results store: append-only JSONL files, each finished experiment written durably as it completes.

A results directory holds:

- ``results.jsonl``: one record per finished experiment (the metrics); a record's line is written
  last, flushed and fsynced, so it is the commit mark of its experiment;
- ``transcripts.jsonl``: the full :class:`~audere.agent.SolveResult` of each experiment, written
  (and fsynced) just before its record;
- ``responses.jsonl``: the response cache, so that no identical model request is ever paid twice;
- ``runs.jsonl``: one line per ``bench run`` invocation (its grid and options).

Killing a run at any moment, even with SIGKILL, loses at most the experiments in flight: the next
run repairs a torn last line, skips what is done and never writes an experiment twice. One run at a
time may write to a directory (an advisory lock says so).
"""

from __future__ import annotations

import contextlib
import datetime as _dt
import fcntl
import json
import os
import threading
from collections.abc import Iterator, Mapping
from pathlib import Path
from typing import Any

from audere.errors import AudereError, InvalidArgumentError

__all__ = [
    "RESULTS",
    "TRANSCRIPTS",
    "ResponseCache",
    "ResultStore",
    "iter_jsonl",
    "read_jsonl",
    "record_for",
]

RESULTS = "results.jsonl"
TRANSCRIPTS = "transcripts.jsonl"
RESPONSES = "responses.jsonl"
RUNS = "runs.jsonl"
_LOCK = ".lock"


def _repair(path: Path) -> int:
    """Cut a torn last line (a write interrupted by a kill) off ``path``; return the bytes removed."""
    if not path.exists():
        return 0
    with open(path, "rb+") as handle:
        handle.seek(0, os.SEEK_END)
        size = handle.tell()
        if size == 0:
            return 0
        handle.seek(size - 1)
        if handle.read(1) == b"\n":
            return 0
        step = 1 << 16
        position = size
        while position > 0:
            start = max(0, position - step)
            handle.seek(start)
            chunk = handle.read(position - start)
            newline = chunk.rfind(b"\n")
            if newline >= 0:
                keep = start + newline + 1
                break
            position = start
        else:
            keep = 0
        handle.truncate(keep)
        handle.flush()
        os.fsync(handle.fileno())
        return size - keep


def iter_jsonl(path: Path) -> Iterator[tuple[int, dict[str, Any]]]:
    """Yield ``(line number, object)`` for each line of a JSON Lines file that a run appends to.

    Blank lines are skipped. The last line may have been torn by a killed run: it is skipped when it
    does not parse. Any other line that does not parse as a JSON object is an error.

    Parameters
    ----------
    path
        The file.

    Yields
    ------
    tuple of (int, dict)
        The 1-based line number and the object on it.

    Raises
    ------
    AudereError
        If a line other than the last is not a JSON object, naming the file and the line number.
    """
    pending: tuple[int, str] | None = None
    with path.open("r", encoding="utf-8", errors="replace") as handle:
        for number, line in enumerate(handle, start=1):
            if not line.strip():
                continue
            if pending is not None:
                yield _parse_line(path, *pending)
            pending = (number, line)
    if pending is not None:
        number, line = pending
        try:
            value = json.loads(line)
        except json.JSONDecodeError:
            return  # torn by a killed run
        if isinstance(value, dict):
            yield number, value
        else:
            yield _parse_line(path, number, line)


def _parse_line(path: Path, number: int, line: str) -> tuple[int, dict[str, Any]]:
    try:
        value = json.loads(line)
    except json.JSONDecodeError as exc:
        raise AudereError(
            f"{path}: line {number}: expected a JSON object, got text that does not parse ({exc.msg} at "
            f"column {exc.colno}): {line.strip()[:80]!r}"
        ) from exc
    if not isinstance(value, dict):
        raise AudereError(f"{path}: line {number}: expected a JSON object, got {type(value).__name__}")
    return number, value


def read_jsonl(path: str | os.PathLike[str]) -> Iterator[dict[str, Any]]:
    """The JSON objects of a JSONL file (nothing for a missing file), a torn last line skipped.

    Raises
    ------
    AudereError
        For a malformed line that is not the last one (naming the file and the line).
    """
    file = Path(path)
    if file.exists():
        for _, value in iter_jsonl(file):
            yield value


def _append_line(path: Path, value: Mapping[str, Any], *, durable: bool) -> None:
    data = (json.dumps(value, separators=(",", ":"), allow_nan=False) + "\n").encode()
    with open(path, "ab") as handle:
        handle.write(data)
        handle.flush()
        if durable:
            os.fsync(handle.fileno())


class ResultStore:
    """The results directory of a benchmark run; use it as a context manager (it takes the lock).

    Parameters
    ----------
    directory
        Created if missing.
    """

    def __init__(self, directory: str | os.PathLike[str]) -> None:
        self.directory = Path(directory)
        if self.directory.exists() and not self.directory.is_dir():
            raise InvalidArgumentError(f"out: expected a directory, got the file {str(self.directory)!r}")
        self._lock = threading.Lock()
        self._lock_file: Any = None
        self._done: set[str] | None = None

    def __enter__(self) -> ResultStore:
        self.directory.mkdir(parents=True, exist_ok=True)
        handle = open(self.directory / _LOCK, "a")  # held for the life of the run
        try:
            fcntl.flock(handle.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            handle.close()
            raise AudereError(
                f"another run is writing to {self.directory}; wait for it or use another --out"
            ) from None
        self._lock_file = handle
        for name in (RESULTS, TRANSCRIPTS, RESPONSES, RUNS):
            _repair(self.directory / name)
        return self

    def __exit__(self, *exc: object) -> None:
        if self._lock_file is not None:
            with contextlib.suppress(OSError):
                fcntl.flock(self._lock_file.fileno(), fcntl.LOCK_UN)
            self._lock_file.close()
            self._lock_file = None

    @property
    def results_path(self) -> Path:
        """``results.jsonl``."""
        return self.directory / RESULTS

    def records(self) -> list[dict[str, Any]]:
        """Every finished experiment's record, first occurrence of each key."""
        seen: dict[str, dict[str, Any]] = {}
        for record in read_jsonl(self.results_path):
            seen.setdefault(str(record.get("key")), record)
        return list(seen.values())

    def done_keys(self) -> set[str]:
        """The keys of the finished experiments."""
        with self._lock:
            return set(self._loaded())

    def _loaded(self) -> set[str]:
        # callers hold self._lock
        if self._done is None:
            self._done = {str(r.get("key")) for r in read_jsonl(self.results_path)}
        return self._done

    def append(self, record: Mapping[str, Any], transcript: Mapping[str, Any] | None) -> bool:
        """Write one finished experiment: its transcript, then its record (the commit mark).

        Returns
        -------
        bool
            False when the experiment was already in the store (nothing is written twice).
        """
        key = str(record["key"])
        with self._lock:
            done = self._loaded()
            if key in done:
                return False
            if transcript is not None:
                _append_line(self.directory / TRANSCRIPTS, {"key": key, "result": transcript}, durable=True)
            _append_line(self.results_path, record, durable=True)
            done.add(key)
            return True

    def log_run(self, options: Mapping[str, Any]) -> None:
        """Append one line describing a ``bench run`` invocation."""
        stamp = _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds")
        _append_line(self.directory / RUNS, {"started_at": stamp, **options}, durable=False)

    def cache(self) -> ResponseCache:
        """The response cache of this directory."""
        return ResponseCache(self.directory / RESPONSES)


class ResponseCache:
    """Model replies by request key, kept in an append-only JSONL file; give it to ``Agent(cache=...)``.

    Parameters
    ----------
    path
        The cache file (created on the first reply stored).
    """

    def __init__(self, path: str | os.PathLike[str]) -> None:
        self.path = Path(path)
        self._lock = threading.Lock()
        self._replies: dict[str, dict[str, Any]] = {}
        for entry in read_jsonl(self.path):
            if isinstance(entry.get("key"), str) and isinstance(entry.get("reply"), dict):
                self._replies.setdefault(entry["key"], entry["reply"])
        self.hits = 0

    def __len__(self) -> int:
        return len(self._replies)

    def get(self, key: str) -> Any:
        """The reply stored for ``key`` (an :class:`audere.agent.Reply`), or None."""
        from audere.agent._llm import Reply

        with self._lock:
            data = self._replies.get(key)
            if data is None:
                return None
            self.hits += 1
        return Reply.from_dict(data)

    def put(self, key: str, model: str, request: Mapping[str, Any], reply: Any) -> None:
        """Store ``reply`` for ``key`` (the request itself is not kept: the key identifies it)."""
        data = reply.to_dict()
        with self._lock:
            if key in self._replies:
                return
            self._replies[key] = data
            self.path.parent.mkdir(parents=True, exist_ok=True)
            _append_line(self.path, {"key": key, "model": model, "reply": data}, durable=False)


def record_for(experiment: Any, result: Any, *, error: str | None = None) -> dict[str, Any]:
    """The metrics record of one finished experiment (``result`` a SolveResult, or None on error)."""
    import audere

    base: dict[str, Any] = {"key": experiment.key, **experiment.model_dump(mode="json")}
    stamp = _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds")
    if result is None:
        return {
            **base,
            "status": "error",
            "success": False,
            "rounds": 0,
            "rounds_to_success": None,
            "calls": 0,
            "calls_to_success": None,
            "categories": [],
            "selected_apis": [],
            "apis_called": [],
            "prompt_tokens": 0,
            "completion_tokens": 0,
            "cost": None,
            "wall_s": 0.0,
            "model_s": 0.0,
            "prompt_version": "",
            "audere_version": audere.__version__,
            "finished_at": stamp,
            "error": error,
        }
    calls = result.calls
    return {
        **base,
        "status": result.status,
        "success": result.success,
        "rounds": len(result.rounds),
        "rounds_to_success": result.rounds_to_success,
        "calls": len(calls),
        "calls_to_success": len(calls) if result.success else None,
        "categories": [r.category.value for r in result.rounds],
        "selected_apis": result.selected_apis,
        "apis_called": result.apis_called,
        "prompt_tokens": result.prompt_tokens,
        "completion_tokens": result.completion_tokens,
        "cost": result.cost,
        "wall_s": result.wall_s,
        "model_s": sum(c.latency_s for c in calls),
        "prompt_version": result.prompt_version,
        "audere_version": audere.__version__,
        "finished_at": stamp,
        "error": None,
    }
