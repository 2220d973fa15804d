"""Record model replies to a cassette file, and replay them without the model.

A cassette is a JSON file::

    {"format": "audere-cassette", "version": 1, "entries": [
        {"key": "<sha256 hex>", "model": "gpt-4o",
         "request": {"messages": [...], "tools": [...] | null, "temperature": 0.1, "seed": null},
         "reply": {... Reply.to_dict() ...}},
        ...]}

An entry's key is :func:`request_key` of its request: the messages, tools, temperature and seed, but
not the model, so a run recorded from a hosted model replays under ``"audere/replay"``. Replayed
replies keep their recorded tokens and cost, so a replayed run reproduces the recorded metrics.

``ModelClient(..., record=path)`` appends to a cassette; ``ModelClient("audere/replay",
cassette=path)`` loads it with :func:`use_cassette` and the offline provider answers from it.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import math
import os
import re
import tempfile
import threading
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Final

from audere.agent._llm import Reply
from audere.errors import AudereError, InvalidArgumentError

__all__ = [
    "CASSETTE_FORMAT",
    "CASSETTE_VERSION",
    "Cassette",
    "CassetteEntry",
    "CassetteError",
    "ReplayMissError",
    "find_reply",
    "forget_cassettes",
    "loaded_cassettes",
    "request_key",
    "use_cassette",
]

CASSETTE_FORMAT: Final = "audere-cassette"
CASSETTE_VERSION: Final = 1

_KEY = re.compile(r"[0-9a-f]{64}\Z")
_REQUEST_FIELDS: Final = ("messages", "tools", "temperature", "seed")


class CassetteError(AudereError, ValueError):
    """A cassette file is missing, unreadable or malformed; the message names the file and the fault."""


class ReplayMissError(AudereError, LookupError):
    """A replayed request has no recorded reply."""


def _canonical(value: object) -> str:
    return json.dumps(value, sort_keys=True, separators=(",", ":"), ensure_ascii=False, allow_nan=False)


def request_key(
    messages: Sequence[Mapping[str, Any]],
    tools: Sequence[Mapping[str, Any]] | None,
    temperature: float | None,
    seed: int | None,
) -> str:
    """The cassette key of a request: the SHA-256 of its canonical JSON.

    The canonical JSON holds exactly ``messages``, ``tools``, ``temperature`` and ``seed`` (sorted
    keys, no whitespace); the model is left out on purpose, so that a recording replays under
    another model string.

    Parameters
    ----------
    messages
        The conversation as sent.
    tools
        The tool definitions as sent, or None.
    temperature
        The sampling temperature (an integer counts as the same float).
    seed
        The sampling seed, or None.

    Returns
    -------
    str
        64 lowercase hexadecimal digits.

    Raises
    ------
    TypeError
        If the request holds something JSON cannot represent.
    ValueError
        If it holds a NaN or an infinity.
    """
    if temperature is not None:
        temperature = float(temperature)  # 1 and 1.0 are the same temperature
    payload = {
        "messages": list(messages),
        "tools": None if tools is None else list(tools),
        "temperature": temperature,
        "seed": seed,
    }
    return hashlib.sha256(_canonical(payload).encode("utf-8")).hexdigest()


@dataclass(frozen=True)
class CassetteEntry:
    """One recorded request and its reply.

    Parameters
    ----------
    key
        :func:`request_key` of ``request``.
    model
        The model string that answered when recording.
    request
        ``{"messages": ..., "tools": ..., "temperature": ..., "seed": ...}``.
    reply
        The recorded reply.
    """

    key: str
    model: str
    request: dict[str, Any]
    reply: Reply

    def to_dict(self) -> dict[str, Any]:
        """Return the entry as stored in the file.

        Returns
        -------
        dict
            ``{"key", "model", "request", "reply"}``.
        """
        return {"key": self.key, "model": self.model, "request": self.request, "reply": self.reply.to_dict()}


class Cassette:
    """The entries of one cassette file, looked up by request key.

    Build one with :meth:`load`, or let :meth:`append` write a file.

    Parameters
    ----------
    path
        The file the entries come from.
    entries
        The entries, in recording order. When several share a key, :meth:`lookup` returns the first.
    """

    def __init__(self, path: str | os.PathLike[str], entries: Sequence[CassetteEntry] = ()) -> None:
        self._path = os.fspath(path)
        self._entries = tuple(entries)
        self._index: dict[str, Reply] = {}
        for entry in self._entries:
            self._index.setdefault(entry.key, entry.reply)

    @property
    def path(self) -> str:
        """The cassette file."""
        return self._path

    @property
    def entries(self) -> tuple[CassetteEntry, ...]:
        """The entries, in recording order."""
        return self._entries

    def __len__(self) -> int:
        return len(self._entries)

    def __repr__(self) -> str:
        return f"Cassette({self._path!r}, {len(self._entries)} entries)"

    def lookup(self, key: str) -> Reply | None:
        """The recorded reply for a request key.

        Parameters
        ----------
        key
            A :func:`request_key`.

        Returns
        -------
        Reply or None
            The first reply recorded under ``key``, or None when there is none.
        """
        return self._index.get(key)

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> Cassette:
        """Read and validate a cassette file.

        Parameters
        ----------
        path
            The file.

        Returns
        -------
        Cassette
            Its entries.

        Raises
        ------
        CassetteError
            If the file is missing, unreadable, not JSON, or not a valid cassette; the message names
            the file and, for a bad entry, its index and field.
        """
        name = os.fspath(path)
        try:
            with open(name, encoding="utf-8") as stream:
                text = stream.read()
        except FileNotFoundError:
            raise CassetteError(f"cassette {name}: expected an existing file, got no such file") from None
        except (OSError, UnicodeDecodeError) as exc:
            raise CassetteError(f"cassette {name}: cannot be read: {exc}") from exc
        try:
            data = json.loads(text)
        except json.JSONDecodeError as exc:
            raise CassetteError(
                f"cassette {name}: expected JSON, got invalid JSON at line {exc.lineno} "
                f"column {exc.colno}: {exc.msg}"
            ) from exc
        return cls(name, _parse(name, data))

    @classmethod
    def append(
        cls,
        path: str | os.PathLike[str],
        key: str,
        model: str,
        request: Mapping[str, Any],
        reply: Reply,
    ) -> Cassette:
        """Add one entry to a cassette file, creating the file if it does not exist.

        The existing entries are kept. The file is rewritten atomically: the new content goes to a
        temporary file in the same directory, which then replaces the cassette, so a crash never
        leaves half a cassette.

        Parameters
        ----------
        path
            The cassette file.
        key
            :func:`request_key` of ``request``.
        model
            The model string that answered.
        request
            ``{"messages": ..., "tools": ..., "temperature": ..., "seed": ...}``.
        reply
            The reply to record.

        Returns
        -------
        Cassette
            The cassette with the new entry. If the file is loaded for replay (:func:`use_cassette`),
            the replay sees the new entry too.

        Raises
        ------
        CassetteError
            If the existing file is not a valid cassette.
        InvalidArgumentError
            If ``key``, ``model`` or ``request`` is malformed.
        """
        name = os.fspath(path)
        if not isinstance(key, str) or not _KEY.match(key):
            raise InvalidArgumentError(f"key: expected 64 lowercase hexadecimal digits, got {key!r}")
        if not isinstance(model, str) or not model:
            raise InvalidArgumentError(f"model: expected a non-empty string, got {model!r}")
        if not isinstance(request, Mapping) or set(request) != set(_REQUEST_FIELDS):
            got = sorted(request) if isinstance(request, Mapping) else type(request).__name__
            raise InvalidArgumentError(
                f"request: expected exactly the fields {list(_REQUEST_FIELDS)}, got {got}"
            )
        if not isinstance(reply, Reply):
            raise InvalidArgumentError(f"reply: expected a Reply, got {type(reply).__name__}")
        try:  # a deep copy: the caller goes on appending to its message list
            copied = json.loads(_canonical(dict(request)))
        except (TypeError, ValueError) as exc:
            raise InvalidArgumentError(f"request: expected JSON-serializable values, got {exc}") from exc
        entry = CassetteEntry(key=key, model=model, request=copied, reply=reply)
        with _write_lock:
            existing = cls.load(name).entries if os.path.exists(name) else ()
            cassette = cls(name, (*existing, entry))
            _write_atomically(name, cassette)
        with _store_lock:
            stored = _store.get(_resolve(name))
            if stored is not None:
                _store[_resolve(name)] = cls(stored.path, cassette.entries)
        return cassette

    def to_dict(self) -> dict[str, Any]:
        """Return the cassette as stored in its file.

        Returns
        -------
        dict
            ``{"format": "audere-cassette", "version": 1, "entries": [...]}``.
        """
        return {
            "format": CASSETTE_FORMAT,
            "version": CASSETTE_VERSION,
            "entries": [entry.to_dict() for entry in self._entries],
        }


_write_lock = threading.Lock()


def _write_atomically(name: str, cassette: Cassette) -> None:
    directory = os.path.dirname(os.path.abspath(name))
    text = json.dumps(cassette.to_dict(), indent=1, ensure_ascii=False, allow_nan=False) + "\n"
    handle, temporary = tempfile.mkstemp(prefix=".cassette-", suffix=".tmp", dir=directory)
    try:
        with os.fdopen(handle, "w", encoding="utf-8") as stream:
            stream.write(text)
            stream.flush()
            os.fsync(stream.fileno())
        os.replace(temporary, name)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(temporary)
        raise


def _parse(name: str, data: object) -> list[CassetteEntry]:
    """Validate a cassette's decoded JSON and return its entries."""
    if not isinstance(data, dict):
        raise CassetteError(f"cassette {name}: expected a JSON object, got {type(data).__name__}")
    if data.get("format") != CASSETTE_FORMAT:
        raise CassetteError(
            f"cassette {name}: expected format {CASSETTE_FORMAT!r}, got {data.get('format')!r}"
        )
    if data.get("version") != CASSETTE_VERSION:
        raise CassetteError(
            f"cassette {name}: expected version {CASSETTE_VERSION}, got {data.get('version')!r}"
        )
    raw = data.get("entries")
    if not isinstance(raw, list):
        raise CassetteError(f"cassette {name}: expected 'entries' to be a list, got {raw!r}")
    entries = []
    for index, item in enumerate(raw):
        where = f"cassette {name}: entry {index}"
        if not isinstance(item, dict):
            raise CassetteError(f"{where}: expected an object, got {type(item).__name__}")
        key, model, request = item.get("key"), item.get("model"), item.get("request")
        if not isinstance(key, str) or not _KEY.match(key):
            raise CassetteError(f"{where}: key: expected 64 lowercase hexadecimal digits, got {key!r}")
        if not isinstance(model, str) or not model:
            raise CassetteError(f"{where}: model: expected a non-empty string, got {model!r}")
        if not isinstance(request, dict) or set(request) != set(_REQUEST_FIELDS):
            got = sorted(request) if isinstance(request, dict) else repr(request)
            raise CassetteError(
                f"{where}: request: expected exactly the fields {list(_REQUEST_FIELDS)}, got {got}"
            )
        messages, tools, temperature, seed = (request[field] for field in _REQUEST_FIELDS)
        if not isinstance(messages, list):
            raise CassetteError(f"{where}: request messages: expected a list, got {messages!r}")
        if tools is not None and not isinstance(tools, list):
            raise CassetteError(f"{where}: request tools: expected a list or null, got {tools!r}")
        if temperature is not None and (
            isinstance(temperature, bool)
            or not isinstance(temperature, int | float)
            or not math.isfinite(temperature)
        ):
            raise CassetteError(
                f"{where}: request temperature: expected a number or null, got {temperature!r}"
            )
        if seed is not None and (isinstance(seed, bool) or not isinstance(seed, int)):
            raise CassetteError(f"{where}: request seed: expected an integer or null, got {seed!r}")
        if request_key(messages, tools, temperature, seed) != key:
            raise CassetteError(
                f"{where}: key: expected the request's key, got {key!r} (was the request edited?)"
            )
        try:
            reply = Reply.from_dict(item.get("reply"))  # type: ignore[arg-type]  # validated inside
        except InvalidArgumentError as exc:
            raise CassetteError(f"{where}: {exc}") from exc
        entries.append(CassetteEntry(key=key, model=model, request=request, reply=reply))
    return entries


# --------------------------------------------------------------------------------------------------
# The replay store: the cassettes "audere/replay" answers from
# --------------------------------------------------------------------------------------------------

_store_lock = threading.Lock()
_store: dict[str, Cassette] = {}


def _entries(count: int) -> str:
    return f"{count} entry" if count == 1 else f"{count} entries"


def _resolve(path: str | os.PathLike[str]) -> str:
    return os.path.realpath(os.fspath(path))


def use_cassette(path: str | os.PathLike[str]) -> Cassette:
    """Load a cassette for ``"audere/replay"`` to answer from (loading it again reloads it).

    Parameters
    ----------
    path
        The cassette file.

    Returns
    -------
    Cassette
        The loaded cassette, whose :attr:`~Cassette.path` is the resolved file path.

    Raises
    ------
    CassetteError
        If the file is missing or not a valid cassette.
    """
    resolved = _resolve(path)
    cassette = Cassette.load(resolved)
    with _store_lock:
        _store[resolved] = cassette
    return cassette


def loaded_cassettes() -> tuple[Cassette, ...]:
    """The cassettes loaded with :func:`use_cassette`.

    Returns
    -------
    tuple of Cassette
        In loading order.
    """
    with _store_lock:
        return tuple(_store.values())


def forget_cassettes() -> None:
    """Unload every cassette loaded with :func:`use_cassette`."""
    with _store_lock:
        _store.clear()


def find_reply(key: str, path: str | os.PathLike[str] | None = None) -> Reply:
    """The recorded reply for a request key, from one loaded cassette or from any.

    Parameters
    ----------
    key
        The request's :func:`request_key`.
    path
        The cassette to answer from (it is loaded if it is not yet), or None for any loaded one.

    Returns
    -------
    Reply
        The recorded reply.

    Raises
    ------
    ReplayMissError
        If no recorded reply has this key; the message says how many entries were searched.
    CassetteError
        If ``path`` is not loaded and cannot be loaded.
    """
    if path is not None:
        resolved = _resolve(path)
        with _store_lock:
            cassette = _store.get(resolved)
        if cassette is None:
            cassette = use_cassette(resolved)
        reply = cassette.lookup(key)
        if reply is None:
            raise ReplayMissError(
                f"cassette {cassette.path} has no reply for this request (key {key[:12]}...): it holds "
                f"{_entries(len(cassette))}; record it again, or check that the messages, tools, temperature "
                "and seed are those recorded"
            )
        return reply
    cassettes = loaded_cassettes()
    for cassette in cassettes:
        reply = cassette.lookup(key)
        if reply is not None:
            return reply
    if not cassettes:
        raise ReplayMissError(
            "no cassette is loaded to replay from: build ModelClient('audere/replay', cassette=path)"
        )
    names = ", ".join(cassette.path for cassette in cassettes)
    total = sum(len(cassette) for cassette in cassettes)
    raise ReplayMissError(
        f"no loaded cassette ({names}) has a reply for this request (key {key[:12]}...): they hold "
        f"{_entries(total)}"
    )
