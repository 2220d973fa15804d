"""Test infrastructure for the sandbox matrix: host processes, process tracking, listeners, outside files.

Nothing hostile runs in the test process. Each :class:`Host` is a separate process running
``host_runner.py`` with fake secrets in its environment (a per-host *tag*). While it lives, a sampler
thread records every descendant it ever had, so that a process that escaped the supervisor's tree is
still known; processes that carry the tag (in ``environ``, ``cmdline`` or ``comm``) are found by a scan
of ``/proc``. Snippets that start processes put the tag into them on purpose.
"""

from __future__ import annotations

import contextlib
import glob
import json
import os
import queue
import secrets
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

HOST_RUNNER = Path(__file__).with_name("host_runner.py")
LEFTOVER_GRACE_S = 1.0


# --- /proc ---------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Proc:
    """One process as seen in ``/proc/<pid>/stat``; ``(pid, start)`` identifies it despite pid reuse."""

    pid: int
    ppid: int
    start: int
    state: str
    comm: str

    @property
    def key(self) -> tuple[int, int]:
        return (self.pid, self.start)


def read_proc(pid: int) -> Proc | None:
    """The process ``pid`` now, or ``None`` if it is gone."""
    try:
        with open(f"/proc/{pid}/stat", "rb") as handle:
            raw = handle.read()
    except OSError:
        return None
    close = raw.rfind(b")")
    comm = raw[raw.find(b"(") + 1 : close].decode(errors="replace")
    fields = raw[close + 2 :].split()
    return Proc(pid=pid, ppid=int(fields[1]), start=int(fields[19]), state=fields[0].decode(), comm=comm)


def proc_table() -> dict[int, Proc]:
    """Every process on the machine."""
    table: dict[int, Proc] = {}
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            info = read_proc(int(entry))
            if info is not None:
                table[info.pid] = info
    return table


def descendants(root: int, table: Mapping[int, Proc]) -> list[Proc]:
    """Every process below ``root`` in ``table``."""
    children: dict[int, list[Proc]] = {}
    for info in table.values():
        children.setdefault(info.ppid, []).append(info)
    found: list[Proc] = []
    stack = [root]
    while stack:
        for child in children.get(stack.pop(), []):
            found.append(child)
            stack.append(child.pid)
    return found


def running(info: Proc) -> bool:
    """Whether that very process (same start time) still exists and is not a zombie."""
    now = read_proc(info.pid)
    return now is not None and now.start == info.start and now.state not in ("Z", "X")


def _read_bytes(path: str) -> bytes:
    try:
        with open(path, "rb") as handle:
            return handle.read()
    except OSError:
        return b""


def tagged(tag: str, *, exclude: Iterable[int] = ()) -> list[Proc]:
    """Live processes whose environment, command line or name contains ``tag``."""
    needle = tag.encode()
    skip = {*exclude, os.getpid()}
    found: list[Proc] = []
    for entry in os.listdir("/proc"):
        if not entry.isdigit() or int(entry) in skip:
            continue
        base = f"/proc/{entry}"
        if any(needle in _read_bytes(f"{base}/{name}") for name in ("environ", "cmdline", "comm")):
            info = read_proc(int(entry))
            if info is not None and info.state not in ("Z", "X"):
                found.append(info)
    return found


def describe(info: Proc) -> str:
    """``pid comm 'cmdline'`` for failure messages."""
    cmdline = _read_bytes(f"/proc/{info.pid}/cmdline").replace(b"\0", b" ").decode(errors="replace")
    return f"{info.pid} ({info.comm}, ppid {info.ppid}) {cmdline[:160]!r}"


def kill_all(procs: Iterable[Proc]) -> None:
    """SIGKILL these processes (only if they are still the same processes)."""
    for info in procs:
        if running(info):
            with contextlib.suppress(ProcessLookupError, PermissionError):
                os.kill(info.pid, signal.SIGKILL)


def status_value(pid: int, name: str) -> int:
    """A ``kB`` field of ``/proc/<pid>/status`` (e.g. ``VmHWM``) in bytes, 0 if unreadable."""
    for line in _read_bytes(f"/proc/{pid}/status").decode(errors="replace").splitlines():
        if line.startswith(name + ":"):
            return int(line.split()[1]) * 1024
    return 0


# --- listeners the snippets try to reach ---------------------------------------------------------------


class Listeners:
    """TCP and UDP listeners on 127.0.0.1 and an abstract unix socket, recording what they receive."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._data: dict[str, bytearray] = {"tcp": bytearray(), "udp": bytearray(), "unix": bytearray()}
        self._stop = threading.Event()
        self.tcp = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        self.tcp.bind(("127.0.0.1", 0))
        self.tcp.listen(16)
        self.udp = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.udp.bind(("127.0.0.1", 0))
        self.unix_name = f"audere-test-{secrets.token_hex(6)}"
        self.unix = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        self.unix.bind("\0" + self.unix_name)
        self.unix.listen(16)
        for sock in (self.tcp, self.udp, self.unix):
            sock.settimeout(0.1)
        self._threads = [
            threading.Thread(target=self._accept_loop, args=("tcp", self.tcp), daemon=True),
            threading.Thread(target=self._accept_loop, args=("unix", self.unix), daemon=True),
            threading.Thread(target=self._udp_loop, daemon=True),
        ]
        for thread in self._threads:
            thread.start()

    @property
    def tcp_port(self) -> int:
        return int(self.tcp.getsockname()[1])

    @property
    def udp_port(self) -> int:
        return int(self.udp.getsockname()[1])

    def inputs(self) -> dict[str, object]:
        """What the snippets need to know to reach the listeners."""
        return {"tcp_port": self.tcp_port, "udp_port": self.udp_port, "unix_name": self.unix_name}

    def _record(self, kind: str, data: bytes) -> None:
        with self._lock:
            self._data[kind] += data

    def _accept_loop(self, kind: str, server: socket.socket) -> None:
        while not self._stop.is_set():
            try:
                conn, _ = server.accept()
            except (TimeoutError, OSError):
                continue
            with conn:
                conn.settimeout(1.0)
                with contextlib.suppress(OSError):
                    while chunk := conn.recv(4096):
                        self._record(kind, chunk)

    def _udp_loop(self) -> None:
        while not self._stop.is_set():
            try:
                data, _ = self.udp.recvfrom(4096)
            except (TimeoutError, OSError):
                continue
            self._record("udp", data)

    def received(self, kind: str, needle: str, *, wait_s: float = 0.3) -> bool:
        """Whether ``needle`` arrived on ``kind`` (waiting a little for in-flight data)."""
        deadline = time.monotonic() + wait_s
        while True:
            with self._lock:
                if needle.encode() in self._data[kind]:
                    return True
            if time.monotonic() > deadline:
                return False
            time.sleep(0.02)

    def close(self) -> None:
        self._stop.set()
        for thread in self._threads:
            thread.join(timeout=2.0)
        for sock in (self.tcp, self.udp, self.unix):
            sock.close()


# --- files outside the sandbox -------------------------------------------------------------------------


def outside_paths(tag: str, outside_dir: str) -> list[str]:
    """The places a snippet must not be able to write to (from the host's point of view)."""
    return [
        os.path.join(outside_dir, f"{tag}-x"),
        f"/tmp/audere-outside-{tag}-x",
        f"/dev/shm/audere-outside-{tag}-x",
    ]


def outside_found(tag: str, outside_dir: str, fake_home: str, home_entries: set[str]) -> list[str]:
    """Files that appeared outside the sandbox: tagged names in the outside places, new files in home."""
    found = [
        *glob.glob(os.path.join(glob.escape(outside_dir), f"{tag}*")),
        *glob.glob(f"/tmp/audere-outside-{tag}*"),
        *glob.glob(f"/dev/shm/audere-outside-{tag}*"),
    ]
    with contextlib.suppress(OSError):
        found += [os.path.join(fake_home, n) for n in os.listdir(fake_home) if n not in home_entries]
    return sorted(found)


def remove_paths(paths: Iterable[str]) -> None:
    for path in paths:
        if os.path.isdir(path) and not os.path.islink(path):
            shutil.rmtree(path, ignore_errors=True)
        else:
            with contextlib.suppress(OSError):
                os.unlink(path)


# --- the host process ----------------------------------------------------------------------------------


@dataclass
class Run:
    """What the host reported for one request."""

    event: dict[str, Any]

    @property
    def ex(self) -> dict[str, Any]:
        execution: dict[str, Any] = self.event["execution"]
        return execution

    @property
    def status(self) -> str:
        return str(self.ex["status"])

    @property
    def elapsed_s(self) -> float:
        return float(self.event["elapsed_s"])

    @property
    def applied(self) -> tuple[str, ...]:
        return tuple(self.ex["layers"])

    @property
    def exception(self) -> dict[str, Any]:
        info = self.ex["exception"]
        assert info is not None, f"no exception reported: {self.brief()}"
        return dict(info)

    def report(self) -> dict[str, Any]:
        """The JSON object the snippet printed last on stdout."""
        lines = [line for line in self.ex["stdout"].splitlines() if line.startswith("{")]
        assert lines, f"the snippet printed no JSON report: {self.brief()}"
        value: dict[str, Any] = json.loads(lines[-1])
        return value

    def brief(self) -> str:
        ex = self.ex
        keep = ("status", "message", "signal", "exit_code", "limit", "wall_s", "layers", "exception")
        summary = {k: ex.get(k) for k in keep}
        if summary["exception"]:
            summary["exception"] = {k: ex["exception"].get(k) for k in ("type", "message", "lineno")}
        return f"{summary} stdout={ex['stdout'][-400:]!r} stderr={ex['stderr'][-600:]!r}"


@dataclass
class Host:
    """A ``host_runner.py`` process owning one SandboxExecutor, with fake secrets in its environment."""

    layers: tuple[str, ...] | None
    preload: tuple[str, ...] | None = None
    sigint: str = "ignore"
    script: Path = HOST_RUNNER
    label: str = ""
    tag: str = field(default_factory=lambda: "adr" + secrets.token_hex(4))

    def __post_init__(self) -> None:
        self.workdir = tempfile.mkdtemp(prefix="audere-test-host-")
        self.home = os.path.join(self.workdir, "home")
        os.mkdir(self.home)
        Path(self.home, ".secret").write_text(f"secret {self.tag}\n")
        self.home_entries = set(os.listdir(self.home))
        self.base_dir = os.path.join(self.workdir, "runs")
        os.mkdir(self.base_dir)
        self._stderr = open(os.path.join(self.workdir, "host.stderr"), "w+b")  # noqa: SIM115 - kept open
        env = {
            "PATH": os.environ.get("PATH", "/usr/bin:/bin"),
            "LANG": "C.UTF-8",
            "HOME": self.home,
            "AUDERE_FAKE_API_KEY": f"sk-FAKE-{self.tag}",
            "AUDERE_TEST_TAG": self.tag,
        }
        options = {
            "tag": self.tag,
            "layers": None if self.layers is None else list(self.layers),
            "preload": None if self.preload is None else list(self.preload),
            "base_dir": self.base_dir,
            "sigint": self.sigint,
        }
        self.proc = subprocess.Popen(
            [sys.executable, str(self.script), json.dumps(options)],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=self._stderr,
            env=env,
            cwd=self.workdir,
        )
        self.pid = self.proc.pid
        self.events: queue.Queue[dict[str, Any]] = queue.Queue()
        self._seen: dict[tuple[int, int], Proc] = {}
        self._seen_lock = threading.Lock()
        self._stop = threading.Event()
        self._reader = threading.Thread(target=self._read_loop, daemon=True)
        self._reader.start()
        self._sampler = threading.Thread(target=self._sample_loop, daemon=True)
        self._sampler.start()
        self._counter = 0
        ready = self.wait_event(lambda e: e["event"] == "ready", timeout_s=60.0)
        assert ready["pid"] == self.pid

    # -- plumbing

    def _read_loop(self) -> None:
        assert self.proc.stdout is not None
        for line in self.proc.stdout:
            text = line.decode(errors="replace").strip()
            if not text:
                continue
            try:
                self.events.put(json.loads(text))
            except json.JSONDecodeError:
                self.events.put({"event": "garbage", "line": text[:500]})
        self.events.put({"event": "eof"})

    def _sample_loop(self) -> None:
        while not self._stop.is_set():
            if self.proc.poll() is not None:
                return
            found = descendants(self.pid, proc_table())
            with self._seen_lock:
                for info in found:
                    self._seen.setdefault(info.key, info)
            self._stop.wait(0.02)

    def stderr_text(self) -> str:
        self._stderr.flush()
        self._stderr.seek(0)
        return self._stderr.read().decode(errors="replace")[-3000:]

    def wait_event(self, accept: Callable[[dict[str, Any]], bool], *, timeout_s: float) -> dict[str, Any]:
        """The next event ``accept`` takes (others are dropped); fails on timeout or end of output."""
        deadline = time.monotonic() + timeout_s
        while True:
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                raise AssertionError(f"host {self.label}: no expected event in {timeout_s} s")
            try:
                event = self.events.get(timeout=remaining)
            except queue.Empty:
                continue
            if accept(event):
                return event
            if event["event"] in ("eof", "garbage", "error"):
                rc = self.proc.poll()
                raise AssertionError(f"host {self.label}: unexpected {event} (rc={rc}); {self.stderr_text()}")

    def send(self, payload: Mapping[str, Any]) -> str:
        """Send a request; return its id."""
        self._counter += 1
        ident = f"r{self._counter}"
        assert self.proc.stdin is not None
        self.proc.stdin.write((json.dumps({"id": ident, **payload}) + "\n").encode())
        self.proc.stdin.flush()
        return ident

    def run(
        self,
        code: str,
        *,
        timeout_s: float = 5.0,
        limits: Mapping[str, Any] | None = None,
        inputs: Mapping[str, Any] | None = None,
    ) -> Run:
        """Run ``code`` in the host's executor and wait for the outcome."""
        ident = self.send(
            {"code": code, "timeout_s": timeout_s, "limits": dict(limits or {}), "inputs": dict(inputs or {})}
        )
        event = self.wait_event(
            lambda e: e.get("id") == ident and e["event"] in ("done", "interrupted"),
            timeout_s=timeout_s + 90.0,
        )
        return Run(event)

    def start_supervisor(self) -> dict[str, Any]:
        ident = self.send({"op": "start"})
        return self.wait_event(lambda e: e.get("id") == ident, timeout_s=120.0)

    # -- processes

    def alive(self) -> bool:
        return self.proc.poll() is None

    def seen(self) -> list[Proc]:
        with self._seen_lock:
            return list(self._seen.values())

    def forget_seen(self) -> None:
        with self._seen_lock:
            self._seen.clear()

    def infrastructure(self, table: Mapping[int, Proc]) -> set[tuple[int, int]]:
        """The supervisor chain: the host's children and what bwrap started (not the per-run child)."""
        if not self.alive():
            return set()
        keep: set[tuple[int, int]] = set()
        for info in descendants(self.pid, table):
            parent = table.get(info.ppid)
            if info.ppid == self.pid or (parent is not None and parent.comm == "bwrap"):
                keep.add(info.key)
        return keep

    def leftovers(self) -> list[Proc]:
        """Processes that should not exist now: anything of the host's tree but the supervisor chain,
        anything that ever was in it and escaped, anything carrying the tag (the host excepted)."""
        table = proc_table()
        infra = self.infrastructure(table)
        found: dict[tuple[int, int], Proc] = {}
        for info in self.seen():
            if info.key not in infra and running(info):
                found[info.key] = info
        if self.alive():
            for info in descendants(self.pid, table):
                if info.key not in infra and info.state not in ("Z", "X"):
                    found[info.key] = info
        for info in tagged(self.tag, exclude=[self.pid] if self.alive() else []):
            if info.key not in infra:
                found[info.key] = info
        return sorted(found.values(), key=lambda p: p.pid)

    def wait_no_leftovers(self, grace_s: float = LEFTOVER_GRACE_S) -> list[Proc]:
        """Wait up to ``grace_s`` for leftovers to go; return (and SIGKILL) what is still there."""
        deadline = time.monotonic() + grace_s
        while True:
            left = self.leftovers()
            if not left or time.monotonic() > deadline:
                break
            time.sleep(0.05)
        described = [describe(p) for p in left]
        kill_all(left)
        self.last_leftover_descriptions = described
        return left

    # -- ending

    def close(self, timeout_s: float = 30.0) -> int:
        """End of input: the host closes its executor and exits; return its exit status."""
        if self.proc.stdin is not None:
            with contextlib.suppress(OSError):
                self.proc.stdin.close()
        try:
            code = self.proc.wait(timeout=timeout_s)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            code = self.proc.wait()
            raise AssertionError(f"host {self.label} did not exit within {timeout_s} s") from None
        return code

    def kill(self) -> None:
        with contextlib.suppress(ProcessLookupError):
            self.proc.kill()
        self.proc.wait()

    def dispose(self) -> None:
        """Stop the threads and delete the host's files (after its processes were checked)."""
        if self.alive():
            self.kill()
        self._stop.set()
        self._sampler.join(timeout=2.0)
        self._reader.join(timeout=2.0)
        for stream in (self.proc.stdin, self.proc.stdout):
            if stream is not None:
                with contextlib.suppress(OSError):
                    stream.close()
        self._stderr.close()
        shutil.rmtree(self.workdir, ignore_errors=True)
