"""The host side of the sandbox: a warm supervisor process, one request at a time, restarted on loss."""

from __future__ import annotations

import contextlib
import json
import logging
import math
import os
import select
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Mapping, Sequence
from typing import Any, Protocol, runtime_checkable

import numpy as np

from audere.agent.sandbox._execution import (
    AGENT_FILENAME,
    ExceptionInfo,
    Execution,
    ExecutionStatus,
    LayerReport,
    Limits,
)
from audere.agent.sandbox._protocol import (
    ProtocolError,
    decode_arrays,
    decode_frame,
    encode_arrays,
    encode_frame,
    frame_length,
)
from audere.errors import AudereError, InvalidArgumentError

__all__ = [
    "DEFAULT_HIDDEN",
    "DEFAULT_PRELOAD",
    "LAYERS",
    "Executor",
    "SandboxExecutor",
    "probe_layers",
]

log = logging.getLogger(__name__)

LAYERS: tuple[str, ...] = ("landlock", "seccomp", "netns", "bwrap")
"""The hardening layers, in the order they wrap the code (bwrap outermost)."""

DEFAULT_PRELOAD: tuple[str, ...] = (
    "numpy",
    "scipy",
    "scipy.integrate",
    "scipy.interpolate",
    "scipy.optimize",
    "scipy.linalg",
    "casadi",
    "torch",
    "ompl",
    "cvxpy",
    "control",
    "shapely",
    "audere.apis",
    "audere.controllers",
    "audere.dynamics",
    "audere.planners",
    "audere.stl",
    "audere.tasks",
    "audere.world",
)
"""Modules the supervisor imports once, so that each execution starts warm (missing ones are skipped)."""

DEFAULT_HIDDEN: tuple[str, ...] = ("audere.scenarios", "audere.recipes")
"""Modules the code cannot import: the scenario generator and the expert's recipes."""

_STARTUP_GRACE_S = 120.0
_BWRAP_RUNS = "/tmp/audere-runs"  # inside bubblewrap: output files, on the tmpfs over /tmp
_BWRAP_SCRATCH = "/tmp/audere-scratch"  # inside bubblewrap: the code's scratch dirs, on a tmpfs of their own
_BWRAP_TMPFS_BYTES = 256 << 20
_REPLY_GRACE_S = 5.0
_SIGNAL_NAMES = {s.value: s.name for s in signal.Signals}
_BAD_ERRNO_LIMITS = {"EFBIG": "file_size", "EMFILE": "open_files", "ENOSPC": "disk"}


@runtime_checkable
class Executor(Protocol):
    """Anything that runs code in isolation and reports an :class:`Execution`."""

    def run(
        self,
        code: str,
        *,
        inputs: Mapping[str, object] | None = None,
        timeout_s: float = 10.0,
        limits: Limits | None = None,
    ) -> Execution:
        """Run ``code`` with ``inputs`` as global names; never raise for anything the code does."""
        ...

    def close(self) -> None:
        """Release the executor's processes and files."""
        ...


_probe_lock = threading.Lock()
_probe_cache: LayerReport | None = None


def probe_layers() -> LayerReport:
    """Probe which hardening layers this machine supports (cached for the process).

    Returns
    -------
    LayerReport
        For ``landlock``, ``seccomp``, ``netns`` and ``bwrap``: available or not, and why.
    """
    global _probe_cache
    with _probe_lock:
        if _probe_cache is None:
            from audere.agent.sandbox import _bwrap, _harden

            abi = _harden.landlock_abi()
            seccomp_ok, seccomp_detail = _harden.seccomp_status()
            netns_ok, netns_detail = _harden.netns_status()
            bwrap_ok, bwrap_detail = _bwrap.bwrap_status()
            _probe_cache = LayerReport(
                available={"landlock": abi > 0, "seccomp": seccomp_ok, "netns": netns_ok, "bwrap": bwrap_ok},
                details={
                    "landlock": f"ABI {abi}" if abi > 0 else "Landlock is not supported by this kernel",
                    "seccomp": seccomp_detail,
                    "netns": netns_detail,
                    "bwrap": bwrap_detail,
                },
            )
        return _probe_cache


def _minimal_env() -> dict[str, str]:
    from audere.agent.sandbox._supervisor import SANDBOX_ENV

    # read at import time by litellm and matplotlib, should the code import them
    return {**SANDBOX_ENV, "LITELLM_LOCAL_MODEL_COST_MAP": "True", "MPLBACKEND": "Agg"}


def _read_paths(extra: Sequence[str]) -> list[str]:
    from audere.agent.sandbox import _harden

    return list(_harden.default_read_paths(extra))


def _check_paths(paths: Sequence[str]) -> tuple[str, ...]:
    from audere.agent.sandbox import _harden

    if isinstance(paths, str):
        raise InvalidArgumentError(f"paths: expected a sequence of paths, got the string {paths!r}")
    out: list[str] = []
    for entry in paths:
        if not isinstance(entry, str | os.PathLike) or not os.path.exists(entry):
            raise InvalidArgumentError(f"paths: expected existing files or directories, got {entry!r}")
        path = os.path.realpath(entry)
        if path in _harden.broad_dirs():
            raise InvalidArgumentError(
                f"paths: {path!r} is too broad to expose to the code; name the directory of your modules"
            )
        out.append(path)
    return tuple(dict.fromkeys(out))


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def _clean_stale(parent: str) -> None:
    """Remove sandbox directories left behind by hosts that died (their ``host.pid`` is gone)."""
    with contextlib.suppress(OSError):
        for entry in os.listdir(parent):
            if not entry.startswith("audere-sandbox-"):
                continue
            path = os.path.join(parent, entry)
            try:
                with open(os.path.join(path, "host.pid"), encoding="ascii") as handle:
                    pid = int(handle.read().strip())
            except (OSError, ValueError):
                continue
            if not _pid_alive(pid):
                shutil.rmtree(path, ignore_errors=True)


class SandboxExecutor:
    """Run model-written code in a hardened child of a warm supervisor process.

    The supervisor is started on the first :meth:`run` (or :meth:`start`) with a minimal
    environment, pre-imports the heavy libraries, and forks one child per execution. The child
    runs in its own session with rlimits, in a fresh scratch directory, under the hardening layers
    this machine supports. If the supervisor dies (a snippet killed it, say), the next run starts a
    new one. Use it as a context manager, or call :meth:`close`.

    Parameters
    ----------
    layers
        Hardening layers to apply: any of ``"landlock"``, ``"seccomp"``, ``"netns"``, ``"bwrap"``.
        ``None`` applies every layer the probes find available; ``()`` runs the core only
        (separate process, rlimits, clean environment, descendant sweep). Asking for a layer
        this machine lacks raises :class:`audere.errors.AudereError` naming the reason.
    preload
        Modules the supervisor imports once (missing optional ones are skipped). Put the
        modules of your own registered APIs here so that the code can call them.
    hidden
        Modules the code cannot import.
    paths
        Directories (or files) put first on the supervisor's ``sys.path`` and allowed for reading:
        where your own API modules live when they are not installed. The code can read everything
        beneath them. The supervisor runs ``python -I``, so without this it sees only the installed
        packages, not the directory of your script or notebook.
    base_dir
        Parent directory of the sandbox's run directories (default: the system temp dir).

    Examples
    --------
    >>> with SandboxExecutor() as executor:  # doctest: +SKIP
    ...     execution = executor.run("import numpy as np\\nresult = np.ones(3) * k", inputs={"k": 2.0})
    >>> execution.status, execution.result["result"]  # doctest: +SKIP
    (<ExecutionStatus.OK: 'ok'>, array([2., 2., 2.]))
    """

    def __init__(
        self,
        *,
        layers: Sequence[str] | None = None,
        preload: Sequence[str] = DEFAULT_PRELOAD,
        hidden: Sequence[str] = DEFAULT_HIDDEN,
        paths: Sequence[str] = (),
        base_dir: str | None = None,
    ) -> None:
        if isinstance(layers, str):
            raise InvalidArgumentError(
                f"layers: expected a sequence of layer names, got the string {layers!r}"
            )
        if layers is not None:
            unknown = [name for name in layers if name not in LAYERS]
            if unknown:
                raise InvalidArgumentError(f"layers: unknown layer(s) {unknown}; choose from {list(LAYERS)}")
        for field_name, names in (("preload", preload), ("hidden", hidden)):
            if isinstance(names, str) or not all(isinstance(n, str) and n for n in names):
                raise InvalidArgumentError(
                    f"{field_name}: expected a sequence of module names, got {names!r}"
                )
        if base_dir is not None and not os.path.isdir(base_dir):
            raise InvalidArgumentError(f"base_dir: expected an existing directory, got {base_dir!r}")
        self._requested = None if layers is None else tuple(dict.fromkeys(layers))
        self._preload = tuple(preload)
        self._hidden = tuple(hidden)
        self._paths = _check_paths(paths)
        self._parent_dir = base_dir or tempfile.gettempdir()
        self._lock = threading.RLock()
        self._proc: subprocess.Popen[bytes] | None = None
        self._base: str | None = None
        self._layers: tuple[str, ...] | None = None
        self._info: dict[str, Any] = {}
        self._starts = 0
        self._closed = False

    # --- lifecycle ----------------------------------------------------------------------------

    def __enter__(self) -> SandboxExecutor:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __del__(self) -> None:
        with contextlib.suppress(Exception):
            self.close()

    def layers(self) -> LayerReport:
        """What the hardening-layer probes found on this machine (see :func:`probe_layers`)."""
        return probe_layers()

    @property
    def applied_layers(self) -> tuple[str, ...]:
        """The layers this executor applies (resolved from ``layers`` and the probes)."""
        if self._layers is None and self._requested == ():
            self._layers = ()
        if self._layers is None:
            report = probe_layers()
            if self._requested is None:
                self._layers = tuple(name for name in LAYERS if report.available[name])
            else:
                missing = [name for name in self._requested if not report.available[name]]
                if missing:
                    reasons = "; ".join(f"{name}: {report.details[name]}" for name in missing)
                    raise AudereError(f"hardening layer(s) not available on this machine: {reasons}")
                self._layers = tuple(name for name in LAYERS if name in self._requested)
        return self._layers

    @property
    def info(self) -> dict[str, Any]:
        """What the running supervisor reported at start: pid, preloaded and missing modules, APIs."""
        return dict(self._info)

    @property
    def starts(self) -> int:
        """How many supervisors this executor has started (restarts after losses included)."""
        return self._starts

    def start(self) -> None:
        """Start the supervisor now (otherwise the first :meth:`run` does)."""
        with self._lock:
            if self._closed:
                raise AudereError("this SandboxExecutor is closed; create a new one")
            if self._proc is not None and self._proc.poll() is None:
                return
            self._stop_supervisor()
            self._start_supervisor()

    def close(self) -> None:
        """Stop the supervisor (killing any running code) and remove the run directories."""
        with self._lock:
            self._closed = True
            self._stop_supervisor()

    def _start_supervisor(self) -> None:
        layers = self.applied_layers
        _clean_stale(self._parent_dir)
        self._base = tempfile.mkdtemp(prefix="audere-sandbox-", dir=self._parent_dir)
        with open(os.path.join(self._base, "host.pid"), "w", encoding="ascii") as handle:
            handle.write(str(os.getpid()))
        read_paths = _read_paths(self._paths) if {"landlock", "bwrap"} & set(layers) else []
        command = [
            sys.executable,
            "-I",
            "-u",
            "-c",
            "from audere.agent.sandbox._supervisor import main; main()",
        ]
        if "bwrap" in layers:
            from audere.agent.sandbox import _bwrap

            # Scratch lives on bubblewrap's own sized tmpfs over /tmp (disk use bounded), and nothing
            # of the host is bound writable: the supervisor reads the run's files itself.
            runs, scratch, cwd = _BWRAP_RUNS, _BWRAP_SCRATCH, "/"
            argv = _bwrap.bwrap_argv(
                bind_rw=(), ro_paths=read_paths, tmpfs_bytes=_BWRAP_TMPFS_BYTES, scratch=scratch
            )
            command = [*argv, *command]
        else:
            runs, scratch, cwd = os.path.join(self._base, "runs"), None, self._base
            os.mkdir(runs, 0o700)
        log_path = os.path.join(self._base, "supervisor.log")
        with open(log_path, "wb") as log_file:
            self._proc = subprocess.Popen(
                command,
                stdin=subprocess.PIPE,
                stdout=subprocess.PIPE,
                stderr=log_file,
                env=_minimal_env(),
                cwd=cwd,
                start_new_session=True,
                close_fds=True,
            )
        self._starts += 1
        config = {
            "preload": list(self._preload),
            "hidden": list(self._hidden),
            "paths": list(self._paths),
            "layers": list(layers),
            "read_paths": read_paths,
            "base_dir": runs,
            "scratch_dir": scratch,
            "landlock_abi": _landlock_abi() if "landlock" in layers else 0,
        }
        try:
            self._send(encode_frame(config))
            header, _ = self._receive(time.monotonic() + _STARTUP_GRACE_S, max_bytes=1 << 20)
        except (ProtocolError, OSError, TimeoutError) as error:
            detail = self._log_tail()
            self._stop_supervisor()
            raise AudereError(
                f"the sandbox supervisor did not start: {error}. Its log ends with: {detail}"
            ) from None
        if not header.get("ready"):
            self._stop_supervisor()
            raise AudereError(f"the sandbox supervisor sent an unexpected greeting: {header!r}")
        self._info = header
        if header.get("missing"):
            log.debug("sandbox supervisor could not preload %s", header["missing"])

    def _log_tail(self) -> str:
        if self._base is None:
            return ""
        try:
            with open(os.path.join(self._base, "supervisor.log"), "rb") as handle:
                handle.seek(0, os.SEEK_END)
                handle.seek(max(0, handle.tell() - 2000))
                return handle.read().decode(errors="replace").strip() or "(empty)"
        except OSError:
            return "(no log)"

    def _stop_supervisor(self) -> None:
        proc, self._proc = self._proc, None
        if proc is not None:
            if proc.stdin is not None:
                with contextlib.suppress(OSError):
                    proc.stdin.close()  # the supervisor kills its child and sweeps on end of file
            try:
                proc.wait(timeout=2.0)
            except subprocess.TimeoutExpired:
                with contextlib.suppress(ProcessLookupError, PermissionError):
                    os.killpg(proc.pid, signal.SIGKILL)
                with contextlib.suppress(subprocess.TimeoutExpired):
                    proc.wait(timeout=2.0)
            if proc.stdout is not None:
                with contextlib.suppress(OSError):
                    proc.stdout.close()
        if self._base is not None:
            shutil.rmtree(self._base, ignore_errors=True)
            self._base = None

    # --- transport ------------------------------------------------------------------------------

    def _pipes(self) -> tuple[Any, Any]:
        proc = self._proc
        if proc is None or proc.stdin is None or proc.stdout is None:
            raise OSError("the sandbox supervisor is not running")
        return proc.stdin, proc.stdout

    def _send(self, data: bytes) -> None:
        stdin, _ = self._pipes()
        stdin.write(data)
        stdin.flush()

    def _receive(self, deadline: float, *, max_bytes: int) -> tuple[dict[str, Any], dict[str, bytes]]:
        _, stdout = self._pipes()
        fd = stdout.fileno()
        buffer = bytearray()
        total: int | None = None
        while total is None or len(buffer) < total:
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                raise TimeoutError("no reply from the sandbox supervisor in time")
            ready, _, _ = select.select([fd], [], [], remaining)
            if not ready:
                continue
            chunk = os.read(fd, 1 << 20)
            if not chunk:
                raise OSError("the sandbox supervisor closed its pipe (it died)")
            buffer += chunk
            if total is None:
                total = frame_length(bytes(buffer), max_bytes=max_bytes)
        if len(buffer) > total:
            raise ProtocolError(f"{len(buffer) - total} stray bytes after the reply")
        return decode_frame(bytes(buffer), max_bytes=max_bytes)

    # --- running code ---------------------------------------------------------------------------

    def run(
        self,
        code: str,
        *,
        inputs: Mapping[str, object] | None = None,
        timeout_s: float = 10.0,
        limits: Limits | None = None,
    ) -> Execution:
        """Run ``code`` in a fresh hardened child process and report what happened.

        Parameters
        ----------
        code
            Python source. It sees ``inputs`` as global names and reports by setting ``result``
            (an array, a mapping of names to arrays, or an :class:`audere.tasks.Solution`).
        inputs
            Values for the code, by name: numpy arrays, JSON-able values, or audere tasks (which
            arrive as tasks whose ``check`` is unavailable).
        timeout_s
            Wall-clock limit in seconds.
        limits
            Resource limits (default :class:`Limits`).

        Returns
        -------
        Execution
            Status, result arrays, output, diagnostics, times, APIs called, layers applied. Whatever
            the code does, this method returns (infrastructure trouble is ``sandbox_error``).

        Raises
        ------
        InvalidArgumentError
            For bad arguments (not for anything the code does).
        """
        if not isinstance(code, str):
            raise InvalidArgumentError(f"code: expected Python source as a str, got {type(code).__name__}")
        if (
            not isinstance(timeout_s, int | float)
            or isinstance(timeout_s, bool)
            or not math.isfinite(timeout_s)
            or timeout_s <= 0
        ):
            raise InvalidArgumentError(f"timeout_s: expected a positive number of seconds, got {timeout_s!r}")
        limits = Limits() if limits is None else limits
        if not isinstance(limits, Limits):
            raise InvalidArgumentError(f"limits: expected an audere Limits, got {type(limits).__name__}")
        spec, blobs = _encode_inputs(inputs)
        request = {
            "op": "run",
            "code": code,
            "inputs": spec,
            "timeout_s": float(timeout_s),
            "limits": limits.to_dict(),
        }
        frame = encode_frame(request, blobs)
        max_reply = limits.result_bytes + 2 * limits.output_bytes + (1 << 20)
        with self._lock:
            self.start()
            started = time.monotonic()
            try:
                self._send(frame)
                header, out = self._receive(started + timeout_s + _REPLY_GRACE_S, max_bytes=max_reply)
            except (OSError, ProtocolError, TimeoutError) as error:
                detail = self._log_tail()
                self._stop_supervisor()
                return Execution(
                    status=ExecutionStatus.SANDBOX_ERROR,
                    message=f"the sandbox supervisor was lost ({error}); a new one starts with the next run",
                    wall_s=time.monotonic() - started,
                    layers=self.applied_layers,
                    extra={"supervisor_log": detail},
                )
            except BaseException:
                self._stop_supervisor()  # Ctrl-C: kill the code and its descendants, then re-raise
                raise
        return _interpret(header, out, limits=limits, timeout_s=float(timeout_s), layers=self.applied_layers)


def _landlock_abi() -> int:
    from audere.agent.sandbox import _harden

    return _harden.landlock_abi()


def _encode_inputs(inputs: Mapping[str, object] | None) -> tuple[dict[str, Any], dict[str, bytes]]:
    if inputs is None:
        return {}, {}
    if not isinstance(inputs, Mapping):
        raise InvalidArgumentError(
            f"inputs: expected a mapping of names to values, got {type(inputs).__name__}"
        )
    spec: dict[str, Any] = {}
    arrays: dict[str, Any] = {}
    for name, value in inputs.items():
        if not isinstance(name, str) or not name.isidentifier():
            raise InvalidArgumentError(f"inputs: names must be Python identifiers, got {name!r}")
        if isinstance(value, np.ndarray):
            if value.dtype.kind not in "biufc":
                raise InvalidArgumentError(
                    f"inputs[{name!r}]: arrays must be numeric, got dtype {value.dtype}"
                )
            spec[name] = {"kind": "array"}
            arrays[f"in:{name}"] = value
        elif _is_task(value):
            spec[name] = {"kind": "task", "value": value.model_dump(mode="json")}  # type: ignore[attr-defined]
        else:
            try:
                json.dumps(value, allow_nan=False)
            except (TypeError, ValueError) as error:
                raise InvalidArgumentError(
                    f"inputs[{name!r}]: expected a numpy array, an audere task or a JSON-able value; {error}"
                ) from None
            spec[name] = {"kind": "json", "value": value}
    return spec, encode_arrays(arrays)


def _is_task(value: object) -> bool:
    tasks = sys.modules.get("audere.tasks._models")
    return tasks is not None and isinstance(value, tasks._TaskBase)


def _interpret(
    header: Mapping[str, Any],
    blobs: Mapping[str, bytes],
    *,
    limits: Limits,
    timeout_s: float,
    layers: tuple[str, ...],
) -> Execution:
    """Turn the supervisor's raw report into an :class:`Execution`, validating every byte."""
    stdout = blobs.get("stdout", b"").decode("utf-8", errors="replace")
    stderr = blobs.get("stderr", b"").decode("utf-8", errors="replace")
    common: dict[str, Any] = {
        "stdout": stdout,
        "stderr": stderr,
        "stdout_truncated": int(header.get("stdout_size", 0)) > limits.output_bytes,
        "stderr_truncated": int(header.get("stderr_size", 0)) > limits.output_bytes,
        "wall_s": float(header.get("wall_s", 0.0)),
        "cpu_s": float(header.get("cpu_s", 0.0)),
        "layers": layers,
    }
    child_header: dict[str, Any] = {}
    child_blobs: dict[str, bytes] = {}
    frame_error: str | None = None
    raw = blobs.get("child", b"")
    if raw:
        try:
            child_header, child_blobs = decode_frame(raw, max_bytes=limits.result_bytes)
        except ProtocolError as error:
            frame_error = str(error)
    if child_header:
        applied = child_header.get("layers")
        if isinstance(applied, list) and all(isinstance(x, str) for x in applied):
            common["layers"] = tuple(applied)
        calls = child_header.get("apis_called", [])
        if isinstance(calls, list):
            common["apis_called"] = tuple(str(c) for c in calls)

    if header.get("timed_out"):
        return Execution(
            status=ExecutionStatus.TIMEOUT, message=f"timed out after {timeout_s:g} s (wall clock)", **common
        )
    if header.get("too_big"):
        return Execution(
            status=ExecutionStatus.BAD_RESULT,
            message=f"result too big: more than {limits.result_bytes} bytes",
            **common,
        )
    status = int(header.get("wait_status", 0))
    if os.WIFSIGNALED(status):
        number = os.WTERMSIG(status)
        name = _SIGNAL_NAMES.get(number, f"signal {number}")
        line = _fault_line(stderr)
        where = f" at line {line}" if line is not None else ""
        if number == signal.SIGXCPU or (number == signal.SIGKILL and common["cpu_s"] >= limits.cpu_s):
            return Execution(
                status=ExecutionStatus.LIMIT,
                signal=name,
                limit="cpu",
                message=f"CPU time limit of {limits.cpu_s:g} s exceeded ({name}){where}",
                **common,
            )
        return Execution(
            status=ExecutionStatus.SIGNALED, signal=name, message=f"killed by {name}{where}", **common
        )
    code = os.WEXITSTATUS(status) if os.WIFEXITED(status) else -1
    if frame_error is not None:
        return Execution(
            status=ExecutionStatus.BAD_RESULT, message=f"malformed result: {frame_error}", **common
        )
    kind = child_header.get("kind")
    if kind == "setup_error":
        return Execution(
            status=ExecutionStatus.SANDBOX_ERROR, message=str(child_header.get("message", "")), **common
        )
    if not child_header or code != 0:
        return Execution(
            status=ExecutionStatus.EXITED,
            exit_code=code,
            message=f"the process exited with code {code} before the code finished",
            **common,
        )
    if kind == "syntax_error":
        info = ExceptionInfo.from_dict(child_header["exception"])
        where = f" at line {info.lineno}" if info.lineno is not None else ""
        return Execution(
            status=ExecutionStatus.SYNTAX_ERROR,
            exception=info,
            message=f"SyntaxError{where}: {info.message}",
            **common,
        )
    if kind == "exception":
        raw_info = child_header["exception"]
        info = ExceptionInfo.from_dict(raw_info)
        where = f" at line {info.lineno}" if info.lineno is not None else ""
        message = f"{info.type}{where}: {info.message}"
        limit = None
        if info.type == "MemoryError":
            limit = "memory"
        elif raw_info.get("errno") in _BAD_ERRNO_LIMITS:
            limit = _BAD_ERRNO_LIMITS[raw_info["errno"]]
        if limit is not None:
            return Execution(
                status=ExecutionStatus.LIMIT,
                exception=info,
                limit=limit,
                message=f"{limit} limit: {message}",
                **common,
            )
        return Execution(status=ExecutionStatus.EXCEPTION, exception=info, message=message, **common)
    if kind == "bad_result":
        return Execution(
            status=ExecutionStatus.BAD_RESULT, message=str(child_header.get("message", "")), **common
        )
    if kind == "ok":
        if child_header.get("no_result"):
            return Execution(status=ExecutionStatus.OK, message="ran to the end (no `result` set)", **common)
        try:
            arrays = decode_arrays(child_blobs)
        except ProtocolError as error:
            return Execution(status=ExecutionStatus.BAD_RESULT, message=str(error), **common)
        shapes = ", ".join(f"{k} {v.shape}" for k, v in arrays.items())
        return Execution(
            status=ExecutionStatus.OK, result=arrays, message=f"ran to the end; result: {shapes}", **common
        )
    return Execution(
        status=ExecutionStatus.BAD_RESULT, message=f"malformed result: unknown kind {kind!r}", **common
    )


def _fault_line(stderr: str) -> int | None:
    marker = f'File "{AGENT_FILENAME}", line '
    index = stderr.find(marker)
    if index < 0:
        return None
    digits = ""
    for char in stderr[index + len(marker) :]:
        if not char.isdigit():
            break
        digits += char
    return int(digits) if digits else None
