"""What one execution of model-written code produced: status, result arrays, output, diagnostics."""

from __future__ import annotations

import dataclasses
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from enum import StrEnum
from typing import Any

import numpy as np
from numpy.typing import NDArray

from audere.errors import InvalidArgumentError

__all__ = [
    "AGENT_FILENAME",
    "ExceptionInfo",
    "Execution",
    "ExecutionStatus",
    "Frame",
    "LayerReport",
    "Limits",
]

AGENT_FILENAME = "<agent_code>"
"""The file name the code is compiled under: tracebacks and crash dumps point at its lines."""

_FAULT_LINE = re.compile(r'File "<agent_code>", line (\d+)')


class ExecutionStatus(StrEnum):
    """How an execution ended."""

    OK = "ok"
    """The code ran to the end (``result`` is ``None`` when it did not set ``result``)."""
    EXCEPTION = "exception"
    """An uncaught exception, ``SystemExit`` and ``KeyboardInterrupt`` included."""
    SYNTAX_ERROR = "syntax_error"
    """The code does not compile."""
    TIMEOUT = "timeout"
    """The wall-clock deadline passed; the process group was killed."""
    SIGNALED = "signaled"
    """The process was killed by a signal (a native crash such as SIGSEGV, or an abort)."""
    EXITED = "exited"
    """The process ended itself with an exit code (``os._exit``)."""
    LIMIT = "limit"
    """A resource limit was hit: CPU time, memory, file size, open files or disk space."""
    BAD_RESULT = "bad_result"
    """``result`` is not numeric, is too big, or the result frame is malformed."""
    SANDBOX_ERROR = "sandbox_error"
    """Infrastructure trouble (the supervisor was lost or spoke garbage): not the code's fault as such."""


@dataclass(frozen=True)
class Limits:
    """Resource limits of one execution (rlimits of the child process, and output caps).

    Parameters
    ----------
    memory_bytes
        Address-space limit (``RLIMIT_AS``). The preloaded libraries (numpy, scipy, casadi, torch,
        OMPL) already map about 1.5 GiB of address space, so keep this well above that.
    cpu_s
        CPU-time limit in seconds (``RLIMIT_CPU``): SIGXCPU at the soft limit, SIGKILL one second later.
    file_size_bytes
        Largest file the code may write (``RLIMIT_FSIZE``); larger writes fail with ``EFBIG``.
    open_files
        Maximum number of open file descriptors (``RLIMIT_NOFILE``).
    processes
        New processes and threads the code may start (``RLIMIT_NPROC`` set to this much headroom
        over the user's current count). Applied only when the sandbox does not run as root: the
        kernel does not enforce it for root. ``None`` leaves it unset.
    output_bytes
        Bytes of stdout and of stderr kept; the rest is dropped and the truncation reported.
    result_bytes
        Largest accepted result frame in bytes.
    """

    memory_bytes: int = 4 << 30
    cpu_s: float = 60.0
    file_size_bytes: int = 16 << 20
    open_files: int = 256
    processes: int | None = 64
    output_bytes: int = 1 << 20
    result_bytes: int = 64 << 20

    def __post_init__(self) -> None:
        for name in ("memory_bytes", "file_size_bytes", "open_files", "output_bytes", "result_bytes"):
            value = getattr(self, name)
            if not isinstance(value, int) or isinstance(value, bool) or value <= 0:
                raise InvalidArgumentError(f"Limits.{name}: expected a positive integer, got {value!r}")
        if not isinstance(self.cpu_s, int | float) or isinstance(self.cpu_s, bool) or not self.cpu_s > 0:
            raise InvalidArgumentError(
                f"Limits.cpu_s: expected a positive number of seconds, got {self.cpu_s!r}"
            )
        if self.processes is not None and (
            not isinstance(self.processes, int) or isinstance(self.processes, bool) or self.processes <= 0
        ):
            raise InvalidArgumentError(
                f"Limits.processes: expected a positive integer or None, got {self.processes!r}"
            )

    def to_dict(self) -> dict[str, Any]:
        """The limits as a JSON-able mapping."""
        return dataclasses.asdict(self)


@dataclass(frozen=True)
class Frame:
    """One frame of a traceback inside ``<agent_code>``."""

    lineno: int
    name: str
    line: str


@dataclass(frozen=True)
class ExceptionInfo:
    """An exception raised by the code (or its syntax error), restricted to the code's own frames.

    Attributes
    ----------
    type
        The exception class name, e.g. ``"IndexError"``.
    message
        ``str(exception)``.
    lineno
        The line in ``<agent_code>`` where it was raised (the innermost frame in the code), if any.
    offset
        Column of a syntax error (1-based), else ``None``.
    frames
        Frames in ``<agent_code>``, outermost first.
    formatted
        The traceback as text, restricted to frames in ``<agent_code>``, ending with the exception line.
    """

    type: str
    message: str
    lineno: int | None = None
    offset: int | None = None
    frames: tuple[Frame, ...] = ()
    formatted: str = ""

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> ExceptionInfo:
        """Rebuild from :meth:`to_dict` output (or the sandbox's JSON header)."""
        frames = tuple(
            Frame(lineno=int(f["lineno"]), name=str(f["name"]), line=str(f["line"]))
            for f in data.get("frames", ())
        )
        lineno = data.get("lineno")
        offset = data.get("offset")
        return cls(
            type=str(data["type"]),
            message=str(data.get("message", "")),
            lineno=None if lineno is None else int(lineno),
            offset=None if offset is None else int(offset),
            frames=frames,
            formatted=str(data.get("formatted", "")),
        )

    def to_dict(self) -> dict[str, Any]:
        """A JSON-able mapping."""
        return dataclasses.asdict(self)


@dataclass(frozen=True)
class LayerReport:
    """Which hardening layers are available on this machine, and why the others are not.

    Attributes
    ----------
    available
        Layer name to ``True``/``False`` for ``landlock``, ``seccomp``, ``netns`` and ``bwrap``.
    details
        Layer name to a one-line explanation (``"ABI 7"``, ``"pyseccomp is not installed"``, ...).
    """

    available: Mapping[str, bool]
    details: Mapping[str, str]

    @property
    def missing(self) -> tuple[str, ...]:
        """Names of the layers that cannot be applied here."""
        return tuple(name for name, ok in self.available.items() if not ok)

    def __str__(self) -> str:
        parts = [
            f"{name}: {'yes' if ok else 'no'} ({self.details.get(name, '')})"
            for name, ok in self.available.items()
        ]
        return "; ".join(parts)


@dataclass(frozen=True)
class Execution:
    """The outcome of running one piece of code in the sandbox.

    Attributes
    ----------
    status
        How it ended (:class:`ExecutionStatus`).
    result
        The value of ``result`` as float64 arrays by name (a bare array is stored under ``"result"``),
        or ``None`` when the code did not set it or did not finish.
    stdout, stderr
        Captured output, at most ``Limits.output_bytes`` each.
    stdout_truncated, stderr_truncated
        Whether more output was written than kept.
    exception
        The exception or syntax error, when there was one.
    signal
        Name of the signal that killed the process (``"SIGSEGV"``), for ``signaled`` and ``limit``.
    exit_code
        Exit code for ``exited``.
    limit
        Which limit was hit for ``limit``: ``"cpu"``, ``"memory"``, ``"file_size"``, ``"open_files"``
        or ``"disk"`` (the scratch space is full: bubblewrap's sized tmpfs, or the host's disk).
    message
        One line for people and models: what happened, and where.
    wall_s, cpu_s
        Wall-clock and CPU time of the execution (CPU of the process and its reaped children).
    apis_called
        Registered API names the code called, unique, in first-call order.
    layers
        Hardening layers applied to this execution, e.g. ``("bwrap", "landlock:abi7", "seccomp")``.
    """

    status: ExecutionStatus
    result: dict[str, NDArray[np.float64]] | None = None
    stdout: str = ""
    stderr: str = ""
    stdout_truncated: bool = False
    stderr_truncated: bool = False
    exception: ExceptionInfo | None = None
    signal: str | None = None
    exit_code: int | None = None
    limit: str | None = None
    message: str = ""
    wall_s: float = 0.0
    cpu_s: float = 0.0
    apis_called: tuple[str, ...] = ()
    layers: tuple[str, ...] = ()
    extra: Mapping[str, Any] = field(default_factory=dict)

    @property
    def ok(self) -> bool:
        """Whether the code ran to the end."""
        return self.status is ExecutionStatus.OK

    @property
    def lineno(self) -> int | None:
        """The most useful line in ``<agent_code>``: the exception's, else the last one in a crash dump."""
        if self.exception is not None and self.exception.lineno is not None:
            return self.exception.lineno
        lines = _FAULT_LINE.findall(self.stderr)
        return int(lines[0]) if lines else None

    def to_dict(self) -> dict[str, Any]:
        """A JSON-able mapping (arrays as nested lists); :meth:`from_dict` inverts it."""
        return {
            "status": self.status.value,
            "result": None if self.result is None else {k: v.tolist() for k, v in self.result.items()},
            "stdout": self.stdout,
            "stderr": self.stderr,
            "stdout_truncated": self.stdout_truncated,
            "stderr_truncated": self.stderr_truncated,
            "exception": None if self.exception is None else self.exception.to_dict(),
            "signal": self.signal,
            "exit_code": self.exit_code,
            "limit": self.limit,
            "message": self.message,
            "wall_s": self.wall_s,
            "cpu_s": self.cpu_s,
            "apis_called": list(self.apis_called),
            "layers": list(self.layers),
            "extra": dict(self.extra),
        }

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> Execution:
        """Rebuild an execution saved with :meth:`to_dict`."""
        result = data.get("result")
        exception = data.get("exception")
        return cls(
            status=ExecutionStatus(data["status"]),
            result=None
            if result is None
            else {str(k): np.asarray(v, dtype=np.float64) for k, v in dict(result).items()},
            stdout=str(data.get("stdout", "")),
            stderr=str(data.get("stderr", "")),
            stdout_truncated=bool(data.get("stdout_truncated", False)),
            stderr_truncated=bool(data.get("stderr_truncated", False)),
            exception=None if exception is None else ExceptionInfo.from_dict(exception),
            signal=data.get("signal"),
            exit_code=data.get("exit_code"),
            limit=data.get("limit"),
            message=str(data.get("message", "")),
            wall_s=float(data.get("wall_s", 0.0)),
            cpu_s=float(data.get("cpu_s", 0.0)),
            apis_called=tuple(data.get("apis_called", ())),
            layers=tuple(data.get("layers", ())),
            extra=dict(data.get("extra", {})),
        )
