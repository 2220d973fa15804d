"""The warm sandbox supervisor and the per-run child: this module runs inside the sandbox.

The host starts ``python -I -u -c "...; main()"`` with a minimal environment (optionally inside
bubblewrap). The supervisor pre-imports the heavy libraries once, marks itself a child subreaper,
then serves one request at a time: it forks a child per execution, which hardens itself (session,
fds, signals, scratch dir, rlimits, network namespace, Landlock, seccomp) and runs the code under the
file name ``<agent_code>``. The supervisor enforces the wall-clock deadline, kills the child's process
group and sweeps every remaining descendant, and sends the raw outcome back. It interprets nothing:
the host decodes and validates every byte that comes out of here.

Wire: fd 0 carries request frames from the host, fd 1 reply frames to the host (see ``_protocol``).
"""

from __future__ import annotations

import builtins
import contextlib
import ctypes
import errno
import faulthandler
import functools
import importlib
import importlib.abc
import io
import json
import linecache
import math
import os
import resource
import select
import shutil
import signal
import sys
import tempfile
import time
import traceback
from collections.abc import Callable, Mapping, Sequence
from typing import Any

from audere.agent.sandbox._protocol import (
    ProtocolError,
    decode_frame,
    encode_frame,
    frame_length,
)

AGENT_FILENAME = "<agent_code>"
_PR_SET_PDEATHSIG = 1
_PR_SET_CHILD_SUBREAPER = 36
_RESULT_FD = 3
_MAX_REQUEST = 1 << 30
_CHILD_FAILED = 70  # the child's own set-up failed before the code ran

_CALLS: list[str] = []  # registered APIs called by the code (filled in the child only)
SANDBOX_ENV = {  # the environment of the supervisor and of every run: nothing from the host
    "PATH": "/usr/local/bin:/usr/bin:/bin",
    "LANG": "C.UTF-8",
    "HOME": "/nonexistent",
    "OPENBLAS_NUM_THREADS": "1",
    "OMP_NUM_THREADS": "1",
    "MKL_NUM_THREADS": "1",
    "PYTHONDONTWRITEBYTECODE": "1",
}

_current_child: int | None = None


# --- small system helpers ----------------------------------------------------------------------


def _prctl(option: int, value: int) -> None:
    libc = ctypes.CDLL(None, use_errno=True)
    if libc.prctl(option, ctypes.c_ulong(value), 0, 0, 0) != 0:
        raise OSError(ctypes.get_errno(), f"prctl({option}) failed")


def _write_all(fd: int, data: bytes) -> None:
    view = memoryview(data)
    while view:
        written = os.write(fd, view)
        view = view[written:]


def _read_frame(fd: int, *, max_bytes: int) -> bytes | None:
    """Read one frame from ``fd``; ``None`` on end of file before any byte."""
    buffer = bytearray()
    total: int | None = None
    while total is None or len(buffer) < total:
        chunk = os.read(fd, 1 << 16 if total is None else min(1 << 20, total - len(buffer)))
        if not chunk:
            if buffer:
                raise ProtocolError(f"end of stream inside a frame ({len(buffer)} bytes read)")
            return None
        buffer += chunk
        if total is None:
            total = frame_length(bytes(buffer), max_bytes=max_bytes)
    return bytes(buffer)


def _descendants(root: int) -> list[int]:
    """Every live process below ``root``, read from ``/proc`` (zombies included)."""
    children: dict[int, list[int]] = {}
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/stat", "rb") as handle:
                stat = handle.read()
        except OSError:
            continue
        fields = stat[stat.rfind(b")") + 2 :].split()
        if len(fields) > 1:
            children.setdefault(int(fields[1]), []).append(int(entry))
    found: list[int] = []
    stack = [root]
    while stack:
        for child in children.get(stack.pop(), []):
            found.append(child)
            stack.append(child)
    return found


def _reap_all() -> None:
    while True:
        try:
            pid, _ = os.waitpid(-1, os.WNOHANG)
        except ChildProcessError:
            return
        if pid == 0:
            return


def sweep() -> int:
    """Kill and reap every descendant of this process; return how many were killed."""
    killed = 0
    me = os.getpid()
    for _ in range(1000):
        pids = _descendants(me)
        if not pids:
            break
        for pid in pids:
            with contextlib.suppress(ProcessLookupError, PermissionError):
                os.kill(pid, signal.SIGKILL)
                killed += 1
        _reap_all()
        time.sleep(0.001)
    _reap_all()
    return killed


def _kill_current_child() -> None:
    if _current_child is not None:
        with contextlib.suppress(ProcessLookupError, PermissionError):
            os.killpg(_current_child, signal.SIGKILL)
        with contextlib.suppress(ProcessLookupError, PermissionError):
            os.kill(_current_child, signal.SIGKILL)
    sweep()


def _on_terminate(signum: int, frame: object) -> None:
    _kill_current_child()
    os._exit(0)


# --- what the code sees --------------------------------------------------------------------------


class _HiddenModules(importlib.abc.MetaPathFinder):
    """Refuse to import the modules the code must not see (the scenario generator, the recipes)."""

    def __init__(self, names: Sequence[str]) -> None:
        self.names = tuple(names)

    def find_spec(self, fullname: str, path: object = None, target: object = None) -> None:
        for name in self.names:
            if fullname == name or fullname.startswith(name + "."):
                raise ImportError(f"{fullname} is not available inside the sandbox", name=fullname)
        return None


def _hide(names: Sequence[str]) -> None:
    if not names:
        return
    for loaded in list(sys.modules):
        if any(loaded == n or loaded.startswith(n + ".") for n in names):
            del sys.modules[loaded]
    sys.meta_path.insert(0, _HiddenModules(names))


def _block_checker() -> None:
    """Make the task checker unusable: the code is judged outside, after it has run."""

    def checker_unavailable(*args: object, **kwargs: object) -> object:
        raise RuntimeError(
            "the checker is not available inside the sandbox; the task is checked after the run"
        )

    models = sys.modules.get("audere.tasks._models")
    if models is not None:
        for value in vars(models).values():
            if isinstance(value, type) and "check" in vars(value):
                value.check = checker_unavailable  # type: ignore[attr-defined]
    checks = sys.modules.get("audere.tasks._check")
    if checks is not None:
        checks.check = checker_unavailable  # type: ignore[attr-defined]
    tasks = sys.modules.get("audere.tasks")
    if tasks is not None and hasattr(tasks, "check"):
        tasks.check = checker_unavailable  # type: ignore[attr-defined]


def _record_api_calls() -> list[str]:
    """Wrap every registered API so that calls are recorded; return the names wrapped."""
    apis = sys.modules.get("audere.apis")
    if apis is None:
        return []
    registry = importlib.import_module("audere.apis._registry")
    wrapped: dict[int, Callable[..., Any]] = {}
    names: list[str] = []
    homes: set[str] = set()  # the modules that define registered APIs (a user's own, say)
    for info in apis.list_apis():
        original = info.function
        homes.add(getattr(original, "__module__", None) or "")

        def make(name: str, function: Callable[..., Any]) -> Callable[..., Any]:
            @functools.wraps(function)
            def recorded(*args: Any, **kwargs: Any) -> Any:
                if name not in _CALLS:
                    _CALLS.append(name)
                return function(*args, **kwargs)

            return recorded

        wrapper = make(info.name, original)
        wrapped[id(original)] = wrapper
        names.append(info.name)
        with contextlib.suppress(Exception):
            registry._REGISTRY[info.name] = _replace_function(info, wrapper)
    for module in list(sys.modules.values()):  # (sys.modules may hold objects that are not modules)
        name = getattr(module, "__name__", None)
        if not isinstance(name, str) or not (name == "audere" or name.startswith("audere.") or name in homes):
            continue
        for attr, value in list(getattr(module, "__dict__", {}).items()):
            if callable(value) and id(value) in wrapped:
                setattr(module, attr, wrapped[id(value)])
    return names


def _replace_function(info: Any, function: Callable[..., Any]) -> Any:
    import dataclasses

    return dataclasses.replace(info, function=function)


def _decode_inputs(spec: Mapping[str, Any], blobs: Mapping[str, bytes]) -> dict[str, Any]:
    values: dict[str, Any] = {}
    for name, item in spec.items():
        kind = item.get("kind")
        if kind == "json":
            values[name] = item["value"]
        elif kind == "array":
            import numpy as np

            values[name] = np.load(io.BytesIO(blobs[f"in:{name}"]), allow_pickle=False)
        elif kind == "task":
            from audere.tasks import parse_task

            values[name] = parse_task(json.dumps(item["value"]), format="json")
        else:
            raise ValueError(f"input {name!r}: unknown kind {kind!r}")
    return values


def _result_arrays(value: object) -> dict[str, Any]:
    """Turn the code's ``result`` into named numeric arrays (raises ValueError with a reason)."""
    import numpy as np

    arrays_method = getattr(value, "arrays", None)
    if callable(arrays_method) and not isinstance(value, np.ndarray):
        value = arrays_method()
    items = list(value.items()) if isinstance(value, Mapping) else [("result", value)]
    out: dict[str, Any] = {}
    for key, item in items:
        if not isinstance(key, str):
            raise ValueError(f"result keys must be strings, got {type(key).__name__} {key!r}")
        try:
            array = np.asarray(item)
        except Exception as error:  # any failure is the code's: report it
            raise ValueError(f"result[{key!r}] is not array-like: {type(error).__name__}: {error}") from None
        if array.dtype.kind not in "biuf":
            raise ValueError(
                f"result[{key!r}] has dtype {array.dtype}; expected numbers (bool, int or float)"
                if key != "result" or isinstance(value, Mapping)
                else f"result has dtype {array.dtype}; expected numbers (bool, int or float)"
            )
        out[key] = array
    return out


def _exception_info(error: BaseException) -> dict[str, Any]:
    frames = [
        {"lineno": f.lineno, "name": f.name, "line": (f.line or "").strip()}
        for f in traceback.extract_tb(error.__traceback__)
        if f.filename == AGENT_FILENAME
    ]
    tb = error.__traceback__
    while tb is not None and tb.tb_frame.f_code.co_filename != AGENT_FILENAME:
        tb = tb.tb_next
    lines = traceback.format_exception(type(error), error, tb) if tb is not None else []
    if not lines:
        lines = traceback.format_exception_only(type(error), error)
    formatted = "".join(line for line in lines if not line.startswith('  File "/'))
    info: dict[str, Any] = {
        "type": type(error).__name__,
        "message": str(error),
        "lineno": frames[-1]["lineno"] if frames else None,
        "offset": None,
        "frames": frames,
        "formatted": formatted,
    }
    if isinstance(error, OSError) and error.errno is not None:
        info["errno"] = errno.errorcode.get(error.errno, str(error.errno))
    if isinstance(error, SyntaxError):
        info["message"] = str(error.msg)
        info["lineno"] = error.lineno
        info["offset"] = error.offset
        info["text"] = (error.text or "").rstrip("\n")
        info["formatted"] = "".join(traceback.format_exception_only(type(error), error))
    return info


# --- the per-run child ---------------------------------------------------------------------------


def _child(
    request: Mapping[str, Any], blobs: Mapping[str, bytes], paths: Mapping[str, str], config: Any
) -> None:
    """Harden this freshly forked process, run the code, write the result frame to fd 3, exit."""
    layers: list[str] = []
    try:
        os.setsid()
        _prctl(_PR_SET_PDEATHSIG, signal.SIGKILL)
        limits = request["limits"]
        # fds: 0 = /dev/null, 1 and 2 = capped files, 3 = result pipe, nothing else
        result_w = paths["result_fd"]
        os.dup2(int(result_w), _RESULT_FD)
        null = os.open(os.devnull, os.O_RDWR)
        out = os.open(paths["stdout"], os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
        err = os.open(paths["stderr"], os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
        os.dup2(null, 0)
        os.dup2(out, 1)
        os.dup2(err, 2)
        os.closerange(_RESULT_FD + 1, 1 << 16)
        sys.stdin = open(0, encoding="utf-8", closefd=False)  # noqa: SIM115 - lives as long as the process
        sys.stdout = io.TextIOWrapper(
            io.FileIO(1, "w", closefd=False), encoding="utf-8", errors="backslashreplace", write_through=True
        )
        sys.stderr = io.TextIOWrapper(
            io.FileIO(2, "w", closefd=False), encoding="utf-8", errors="backslashreplace", write_through=True
        )
        faulthandler.enable(file=sys.stderr, all_threads=True)
        os.chdir(paths["scratch"])
        os.environ.clear()
        os.environ.update(SANDBOX_ENV)
        os.environ["TMPDIR"] = paths["scratch"]
        tempfile.tempdir = paths["scratch"]
        signal.signal(signal.SIGINT, signal.default_int_handler)
        for name in ("SIGTERM", "SIGHUP", "SIGQUIT", "SIGUSR1", "SIGUSR2", "SIGPIPE", "SIGCHLD", "SIGXCPU"):
            signal.signal(getattr(signal, name), signal.SIG_DFL)
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        _apply_rlimits(limits, config)
        _apply_layers(request, paths, config, layers)
    except BaseException as error:  # report any set-up failure, then stop
        with contextlib.suppress(BaseException):
            detail = f"sandbox set-up failed: {type(error).__name__}: {error}"
            _write_all(_RESULT_FD, encode_frame({"kind": "setup_error", "message": detail, "layers": layers}))
        os._exit(_CHILD_FAILED)
    _run_code(request, blobs, layers)


def _apply_rlimits(limits: Mapping[str, Any], config: Any) -> None:
    base_as = int(config["address_space"])
    memory = base_as + int(limits["memory_bytes"])
    resource.setrlimit(resource.RLIMIT_AS, (memory, memory))
    cpu = max(1, math.ceil(float(limits["cpu_s"])))
    resource.setrlimit(resource.RLIMIT_CPU, (cpu, cpu + 1))
    size = int(limits["file_size_bytes"])
    resource.setrlimit(resource.RLIMIT_FSIZE, (size, size))
    files = int(limits["open_files"])
    resource.setrlimit(resource.RLIMIT_NOFILE, (files, files))
    resource.setrlimit(resource.RLIMIT_CORE, (0, 0))
    processes = limits.get("processes")
    if processes is not None and os.geteuid() != 0:
        current = _count_user_tasks(os.geteuid())
        cap = current + int(processes)
        resource.setrlimit(resource.RLIMIT_NPROC, (cap, cap))


def _count_user_tasks(uid: int) -> int:
    count = 0
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                if os.stat(f"/proc/{entry}").st_uid == uid:
                    count += len(os.listdir(f"/proc/{entry}/task"))
            except OSError:
                continue
    return count


def _apply_layers(
    request: Mapping[str, Any], paths: Mapping[str, str], config: Any, layers: list[str]
) -> None:
    wanted = set(config["layers"])
    if "bwrap" in wanted:
        layers.append("bwrap")
    if not wanted - {"bwrap"}:
        return
    from audere.agent.sandbox import _harden

    if "netns" in wanted and "bwrap" not in wanted:
        _harden.apply_netns()
        layers.append("netns")
    _harden.set_no_new_privs()
    if "landlock" in wanted:
        applied = _harden.apply_landlock(
            read_paths=config["read_paths"],
            write_paths=[paths["scratch"], os.devnull],
            abi=int(config["landlock_abi"]),
        )
        layers.append(applied)
    if "seccomp" in wanted:
        _harden.apply_seccomp()
        layers.append("seccomp")


def _run_code(request: Mapping[str, Any], blobs: Mapping[str, bytes], layers: list[str]) -> None:
    reserve = bytearray(8 << 20)  # freed on MemoryError so that the report can still be built
    code = str(request["code"])
    header: dict[str, Any] = {"layers": layers}
    out_blobs: dict[str, bytes] = {}
    namespace: dict[str, Any] = {"__name__": "__main__", "__builtins__": builtins}
    try:
        namespace.update(_decode_inputs(request.get("inputs", {}), blobs))
    except Exception as error:
        header.update(
            kind="setup_error", message=f"could not rebuild the inputs: {type(error).__name__}: {error}"
        )
        _finish(header, out_blobs)
    linecache.cache[AGENT_FILENAME] = (len(code), None, code.splitlines(True), AGENT_FILENAME)
    try:
        compiled = compile(code, AGENT_FILENAME, "exec", dont_inherit=True)
    except (SyntaxError, ValueError) as error:
        del reserve
        if isinstance(error, SyntaxError):
            header.update(kind="syntax_error", exception=_exception_info(error))
        else:  # e.g. null bytes in the source
            header.update(
                kind="syntax_error",
                exception={"type": "SyntaxError", "message": str(error), "lineno": None, "frames": []},
            )
        _finish(header, out_blobs)
    try:
        exec(compiled, namespace)
    except BaseException as error:  # everything the code raises is reported
        del reserve
        namespace.clear()
        header.update(kind="exception", exception=_exception_info(error))
        _finish(header, out_blobs)
    try:
        if "result" in namespace:
            from audere.agent.sandbox._protocol import encode_arrays

            out_blobs = encode_arrays(_result_arrays(namespace["result"]))
            header["kind"] = "ok"
        else:
            header["kind"] = "ok"
            header["no_result"] = True
    except BaseException as error:
        out_blobs = {}
        header.update(
            kind="bad_result",
            message=f"{type(error).__name__}: {error}" if not isinstance(error, ValueError) else str(error),
        )
    _finish(header, out_blobs)


def _finish(header: dict[str, Any], blobs: Mapping[str, bytes]) -> None:
    header["apis_called"] = list(_CALLS)
    with contextlib.suppress(BaseException):
        sys.stdout.flush()
        sys.stderr.flush()
    try:
        _write_all(_RESULT_FD, encode_frame(header, blobs))
    except BaseException:  # e.g. the frame cannot be built: the host sees no frame
        os._exit(_CHILD_FAILED)
    os._exit(0)


# --- the supervisor ------------------------------------------------------------------------------


def _read_capped(path: str, cap: int) -> tuple[bytes, int]:
    try:
        size = os.path.getsize(path)
        with open(path, "rb") as handle:
            return handle.read(cap), size
    except OSError:
        return b"", 0


def _serve_one(
    request: dict[str, Any], blobs: dict[str, bytes], config: dict[str, Any], request_fd: int
) -> tuple[dict[str, Any], dict[str, bytes], bool]:
    """Run one request; return the reply header, blobs, and whether the host has gone."""
    global _current_child
    limits = request["limits"]
    run_dir = tempfile.mkdtemp(prefix="run-", dir=config["base_dir"])
    # the scratch dir lives on its own mount under bubblewrap (a sized tmpfs): when the code fills
    # it, the run's stdout and stderr files still have room
    scratch_parent = config.get("scratch_dir")
    if scratch_parent:
        scratch = tempfile.mkdtemp(prefix="scratch-", dir=scratch_parent)
    else:
        scratch = os.path.join(run_dir, "scratch")
        os.mkdir(scratch, 0o700)
    read_fd, write_fd = os.pipe()
    paths = {
        "scratch": scratch,
        "stdout": os.path.join(run_dir, "stdout"),
        "stderr": os.path.join(run_dir, "stderr"),
        "result_fd": str(write_fd),
    }
    start = time.monotonic()
    pid = os.fork()
    if pid == 0:  # the child never returns from here
        try:
            os.close(read_fd)
            _child(request, blobs, paths, config)
        finally:
            os._exit(_CHILD_FAILED)
    _current_child = pid
    os.close(write_fd)
    deadline = start + float(request["timeout_s"])
    cap = int(limits["result_bytes"])
    frame = bytearray()
    too_big = False
    timed_out = False
    host_gone = False
    pidfd = os.pidfd_open(pid)
    watch = [read_fd, pidfd, request_fd]
    try:
        while True:
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                timed_out = True
                break
            ready, _, _ = select.select(watch, [], [], remaining)
            if request_fd in ready:  # the host never writes during a run: end of file means it is gone
                host_gone = True
                break
            if read_fd in ready:
                chunk = os.read(read_fd, 1 << 20)
                if not chunk:
                    watch.remove(read_fd)
                elif too_big or len(frame) + len(chunk) > cap:
                    too_big = True
                    frame.clear()
                else:
                    frame += chunk
            if pidfd in ready:
                break
        if timed_out or host_gone:
            with contextlib.suppress(ProcessLookupError):
                os.killpg(pid, signal.SIGKILL)
            with contextlib.suppress(ProcessLookupError):
                os.kill(pid, signal.SIGKILL)
        _, status, usage = os.wait4(pid, 0)
        _current_child = None
        wall = time.monotonic() - start
        os.set_blocking(read_fd, False)
        with contextlib.suppress(BlockingIOError, OSError):
            while not too_big:
                chunk = os.read(read_fd, 1 << 20)
                if not chunk:
                    break
                if len(frame) + len(chunk) > cap:
                    too_big = True
                    frame.clear()
                else:
                    frame += chunk
        swept = sweep()
    finally:
        _current_child = None
        os.close(read_fd)
        os.close(pidfd)
    cap_out = int(limits["output_bytes"])
    stdout, stdout_size = _read_capped(paths["stdout"], cap_out)
    stderr, stderr_size = _read_capped(paths["stderr"], cap_out)
    shutil.rmtree(run_dir, ignore_errors=True)
    shutil.rmtree(scratch, ignore_errors=True)
    header = {
        "wait_status": status,
        "timed_out": timed_out,
        "too_big": too_big,
        "wall_s": wall,
        "cpu_s": usage.ru_utime + usage.ru_stime,
        "stdout_size": stdout_size,
        "stderr_size": stderr_size,
        "swept": swept,
    }
    return header, {"child": bytes(frame), "stdout": stdout, "stderr": stderr}, host_gone


def _address_space() -> int:
    with open("/proc/self/status", encoding="ascii") as handle:
        for line in handle:
            if line.startswith("VmSize:"):
                return int(line.split()[1]) * 1024
    return 0


def _preload(modules: Sequence[str]) -> tuple[list[str], dict[str, str]]:
    loaded: list[str] = []
    missing: dict[str, str] = {}
    for name in modules:
        try:
            importlib.import_module(name)
        except Exception as error:  # an optional library may be absent
            missing[name] = f"{type(error).__name__}: {error}"
        else:
            loaded.append(name)
    torch = sys.modules.get("torch")
    if torch is not None:
        torch.set_num_threads(1)
    apis = sys.modules.get("audere.apis")
    if apis is not None:
        apis.list_apis()  # loads every built-in API module
    return loaded, missing


def main() -> None:
    """Entry point of the supervisor process (started by :class:`SandboxExecutor`)."""
    request_fd = os.dup(0)
    reply_fd = os.dup(1)
    null = os.open(os.devnull, os.O_RDWR)
    os.dup2(null, 0)
    os.dup2(2, 1)  # stray prints of preloaded libraries go to the log, never into the protocol
    os.close(null)
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the host stops us by closing the pipe, or SIGTERM
    signal.signal(signal.SIGTERM, _on_terminate)
    _prctl(_PR_SET_PDEATHSIG, signal.SIGKILL)
    _prctl(_PR_SET_CHILD_SUBREAPER, 1)
    raw = _read_frame(request_fd, max_bytes=_MAX_REQUEST)
    if raw is None:
        os._exit(0)
    config, _ = decode_frame(raw, max_bytes=_MAX_REQUEST)
    sys.path[:0] = [str(path) for path in config.get("paths", ())]
    loaded, missing = _preload(config.get("preload", ()))
    apis = _record_api_calls()
    _hide(config.get("hidden", ()))
    _block_checker()
    os.makedirs(config["base_dir"], mode=0o700, exist_ok=True)
    config["address_space"] = _address_space()
    ready = {"ready": True, "pid": os.getpid(), "preloaded": loaded, "missing": missing, "apis": apis}
    ready["address_space"] = config["address_space"]
    _write_all(reply_fd, encode_frame(ready))
    while True:
        try:
            raw = _read_frame(request_fd, max_bytes=_MAX_REQUEST)
        except (ProtocolError, OSError):
            break
        if raw is None:
            break
        request, blobs = decode_frame(raw, max_bytes=_MAX_REQUEST)
        if request.get("op") != "run":
            break
        header, out_blobs, host_gone = _serve_one(request, blobs, config, request_fd)
        if host_gone:
            break
        try:
            _write_all(reply_fd, encode_frame(header, out_blobs))
        except OSError:
            break
    sweep()
    os._exit(0)
