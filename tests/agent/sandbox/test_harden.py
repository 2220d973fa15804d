"""Hardening layers of the sandbox (Landlock, seccomp, netns, bubblewrap), one layer at a time.

Every layer is applied in a forked child that reports what it observed through a pipe as JSON; the
test process itself is never restricted. A layer whose probe says it is unavailable is skipped with
the probe's reason. ``kill(-1)`` is never executed: its seccomp rule is checked in the exported filter.
"""

from __future__ import annotations

import ctypes
import errno
import json
import os
import select
import signal
import socket
import stat
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

from audere.agent.sandbox import _bwrap, _harden
from audere.errors import InvalidArgumentError, MissingDependencyError

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="Linux-only kernel features")

ABI = _harden.landlock_abi()
SECCOMP_OK, SECCOMP_DETAIL = _harden.seccomp_status()
NETNS_OK, NETNS_DETAIL = _harden.netns_status()
BWRAP_OK, BWRAP_DETAIL = _bwrap.bwrap_status()

needs_landlock = pytest.mark.skipif(ABI < 1, reason="Landlock unavailable (landlock_abi() == 0)")
needs_seccomp = pytest.mark.skipif(not SECCOMP_OK, reason=f"seccomp unavailable: {SECCOMP_DETAIL}")
needs_netns = pytest.mark.skipif(not NETNS_OK, reason=f"netns unavailable: {NETNS_DETAIL}")
needs_bwrap = pytest.mark.skipif(not BWRAP_OK, reason=f"bubblewrap unavailable: {BWRAP_DETAIL}")


# --- running a layer in a forked child ------------------------------------------------------------


def in_child(work: Callable[[], dict[str, Any]], *, timeout_s: float = 30.0) -> dict[str, Any]:
    """Run ``work`` in a forked child and return the dict it produced; re-raise its failure here."""
    read_fd, write_fd = os.pipe()
    pid = os.fork()
    if pid == 0:  # pragma: no cover - the child never returns
        try:
            os.close(read_fd)
            try:
                payload: dict[str, Any] = {"ok": True, "result": work()}
            except BaseException as exc:
                payload = {"ok": False, "error": f"{type(exc).__name__}: {exc}"}
            data = json.dumps(payload, default=repr).encode()
            while data:
                data = data[os.write(write_fd, data) :]
        finally:
            os._exit(0)
    os.close(write_fd)
    chunks = []
    deadline = time.monotonic() + timeout_s
    try:
        while (left := deadline - time.monotonic()) > 0:
            ready, _, _ = select.select([read_fd], [], [], left)
            if not ready:
                continue
            chunk = os.read(read_fd, 1 << 16)
            if not chunk:
                break
            chunks.append(chunk)
        else:
            os.kill(pid, signal.SIGKILL)
    finally:
        os.close(read_fd)
        _, status = os.waitpid(pid, 0)
    assert chunks, f"child reported nothing (wait status {status})"
    payload = json.loads(b"".join(chunks))
    assert payload["ok"], f"child failed: {payload.get('error')}"
    result: dict[str, Any] = payload["result"]
    return result


def attempt(action: Callable[[], object]) -> str:
    """``"ok"`` when ``action`` succeeds, else the errno name of the OSError it raised."""
    try:
        action()
    except OSError as exc:
        return errno.errorcode.get(exc.errno or 0, str(exc))
    return "ok"


def write_file(path: str | Path) -> None:
    with open(path, "w") as f:
        f.write("x")


def read_file(path: str | Path) -> None:
    with open(path, "rb") as f:
        f.read()


def tcp_connect(address: tuple[str, int]) -> None:
    with socket.create_connection(address, timeout=2):
        pass


@pytest.fixture
def listener() -> Iterator[socket.socket]:
    """A TCP listener on 127.0.0.1 in the test process."""
    server = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    server.bind(("127.0.0.1", 0))
    server.listen(4)
    yield server
    server.close()


@pytest.fixture
def layout(tmp_path: Path) -> dict[str, Path]:
    """A scratch dir, a fake secret beside it, and an outside dir; none is under a read path."""
    scratch = tmp_path / "scratch"
    secret_dir = tmp_path / "secret"
    outside = tmp_path / "outside"
    for d in (scratch, secret_dir, outside):
        d.mkdir()
    (secret_dir / "key.txt").write_text("API_KEY=hunter2")
    (outside / "readable.txt").write_text("readable")
    (outside / "appendable.log").write_text("")
    return {"tmp": tmp_path, "scratch": scratch, "secret": secret_dir / "key.txt", "outside": outside}


def read_paths_excluding(path: Path) -> list[str]:
    """:func:`default_read_paths` minus any entry that would cover ``path`` (e.g. a sys.path entry)."""
    return [p for p in _harden.default_read_paths() if not path.is_relative_to(p)]


# --- probes ---------------------------------------------------------------------------------------


def test_probes_answer_without_raising() -> None:
    assert isinstance(ABI, int)
    assert ABI >= 0
    for ok, detail in (_harden.seccomp_status(), _harden.netns_status(), _bwrap.bwrap_status()):
        assert isinstance(ok, bool)
        assert isinstance(detail, str)
        assert detail


def test_probes_report_missing_pieces(monkeypatch: pytest.MonkeyPatch) -> None:
    def no_pyseccomp() -> object:
        raise ImportError("No module named 'pyseccomp'")

    monkeypatch.setattr(_harden, "_import_pyseccomp", no_pyseccomp)
    ok, detail = _harden.seccomp_status.__wrapped__()
    assert not ok
    assert "pyseccomp not installed" in detail
    assert "audere[sandbox]" in detail

    monkeypatch.setattr(_harden, "_landlock_syscalls", lambda: None)
    assert _harden.landlock_abi.__wrapped__() == 0

    monkeypatch.setattr(_bwrap.shutil, "which", lambda *args, **kwargs: None)
    ok, detail = _bwrap.bwrap_status.__wrapped__()
    assert not ok
    assert "bwrap not found" in detail


def test_default_read_paths() -> None:
    paths = _harden.default_read_paths()
    assert paths == list(dict.fromkeys(paths))
    for path in paths:
        assert os.path.isabs(path)
        assert os.path.exists(path)
        assert path != "/proc"
        assert not path.startswith("/proc/")
        assert path not in ("/", "/tmp", "/root", "/home")

    def covered(target: str) -> bool:
        return any(Path(os.path.realpath(target)).is_relative_to(p) for p in paths)

    assert covered(sys.base_prefix)
    assert covered(sys.prefix)
    assert covered(os.__file__)
    assert covered("/usr/lib")
    if os.path.exists("/etc/passwd"):
        assert covered("/etc/passwd")
    if os.path.exists("/etc/shadow"):
        assert not covered("/etc/shadow")


# --- Landlock -------------------------------------------------------------------------------------


def test_apply_landlock_rejects_bad_arguments() -> None:
    # Validation happens before any syscall, so this is safe in the test process.
    with pytest.raises(InvalidArgumentError, match="abi"):
        _harden.apply_landlock(read_paths=[], write_paths=[], abi=0)
    with pytest.raises(InvalidArgumentError, match="read_paths"):
        _harden.apply_landlock(read_paths=["usr"], write_paths=[], abi=1)
    with pytest.raises(InvalidArgumentError, match="write_paths"):
        _harden.apply_landlock(read_paths=[], write_paths="/tmp", abi=1)


@needs_landlock
@pytest.mark.parametrize("abi", range(1, max(ABI, 1) + 1))
def test_landlock_filesystem(layout: dict[str, Path], abi: int) -> None:
    """Each ABI up to the kernel's: writes only in scratch, no secret, no /proc, files handled."""
    outside = layout["outside"]

    def work() -> dict[str, Any]:
        label = _harden.apply_landlock(
            read_paths=[*read_paths_excluding(layout["tmp"]), str(outside / "readable.txt")],
            write_paths=[str(layout["scratch"]), str(outside / "appendable.log")],
            abi=abi,
        )
        return {
            "label": label,
            "scratch_write": attempt(lambda: write_file(layout["scratch"] / "ok.txt")),
            "scratch_mkdir": attempt(lambda: os.mkdir(layout["scratch"] / "sub")),
            "outside_write": attempt(lambda: write_file(outside / "new.txt")),
            "tmp_write": attempt(lambda: write_file(layout["tmp"] / "new.txt")),
            "secret_read": attempt(lambda: read_file(layout["secret"])),
            "secret_list": attempt(lambda: os.listdir(layout["secret"].parent)),
            "file_rule_read": attempt(lambda: read_file(outside / "readable.txt")),
            "file_rule_write": attempt(lambda: write_file(outside / "readable.txt")),
            "rw_file_rule_write": attempt(lambda: write_file(outside / "appendable.log")),
            "parent_environ": attempt(lambda: read_file(f"/proc/{os.getppid()}/environ")),
            "self_environ": attempt(lambda: read_file("/proc/self/environ")),
            "system_read": attempt(lambda: read_file("/etc/passwd")),
            "home_list": attempt(lambda: os.listdir(os.path.expanduser("~"))),
        }

    seen = in_child(work)
    assert seen == {
        "label": f"landlock:abi{abi}",
        "scratch_write": "ok",
        "scratch_mkdir": "ok",
        "outside_write": "EACCES",
        "tmp_write": "EACCES",
        "secret_read": "EACCES",
        "secret_list": "EACCES",
        "file_rule_read": "ok",
        "file_rule_write": "EACCES",
        "rw_file_rule_write": "ok",
        "parent_environ": "EACCES",
        "self_environ": "EACCES",
        "system_read": "ok",
        "home_list": "EACCES",
    }
    assert (layout["scratch"] / "ok.txt").exists()
    assert not (outside / "new.txt").exists()


@needs_landlock
def test_landlock_denies_device_nodes_in_scratch(layout: dict[str, Path]) -> None:
    def work() -> dict[str, Any]:
        _harden.apply_landlock(read_paths=[], write_paths=[str(layout["scratch"])], abi=ABI)
        node = layout["scratch"] / "disk"
        return {"mknod": attempt(lambda: os.mknod(node, 0o600 | stat.S_IFBLK, os.makedev(7, 0)))}

    assert in_child(work) == {"mknod": "EACCES"}


@needs_landlock
@pytest.mark.skipif(ABI < 4, reason=f"Landlock TCP rules need ABI >= 4 (kernel has {ABI})")
def test_landlock_denies_tcp(layout: dict[str, Path], listener: socket.socket) -> None:
    address = listener.getsockname()

    def work() -> dict[str, Any]:
        _harden.apply_landlock(read_paths=[], write_paths=[str(layout["scratch"])], abi=ABI)

        def bind() -> None:
            with socket.socket() as s:
                s.bind(("127.0.0.1", 0))

        return {"connect": attempt(lambda: tcp_connect(address)), "bind": attempt(bind)}

    assert in_child(work) == {"connect": "EACCES", "bind": "EACCES"}


@needs_landlock
@pytest.mark.skipif(ABI < 6, reason=f"Landlock scoping needs ABI >= 6 (kernel has {ABI})")
def test_landlock_scopes_signals_and_abstract_sockets(layout: dict[str, Path]) -> None:
    name = f"\0audere-test-harden-{os.getpid()}"
    with socket.socket(socket.AF_UNIX, socket.SOCK_STREAM) as server:
        server.bind(name)
        server.listen(1)

        def work() -> dict[str, Any]:
            before = attempt(lambda: os.kill(os.getppid(), 0))
            _harden.apply_landlock(read_paths=[], write_paths=[str(layout["scratch"])], abi=ABI)

            def connect() -> None:
                with socket.socket(socket.AF_UNIX, socket.SOCK_STREAM) as s:
                    s.connect(name)

            return {
                "kill_parent_before": before,
                "kill_parent": attempt(lambda: os.kill(os.getppid(), 0)),
                "kill_self": attempt(lambda: os.kill(os.getpid(), 0)),
                "abstract_connect": attempt(connect),
            }

        seen = in_child(work)
    assert seen == {
        "kill_parent_before": "ok",
        "kill_parent": "EPERM",
        "kill_self": "ok",
        "abstract_connect": "EPERM",
    }


@needs_landlock
def test_landlock_allows_heavy_imports(layout: dict[str, Path]) -> None:
    """The read allowlist is not too tight: a fresh interpreter imports scipy.optimize under it."""
    pytest.importorskip("scipy")

    def work() -> dict[str, Any]:
        _harden.apply_landlock(
            read_paths=read_paths_excluding(layout["tmp"]), write_paths=[str(layout["scratch"])], abi=ABI
        )
        proc = subprocess.run(
            [sys.executable, "-I", "-c", "import scipy.optimize, json, email.mime.text; print('imported')"],
            capture_output=True,
            text=True,
            timeout=60,
            cwd=layout["scratch"],
            env={"PATH": "/usr/bin:/bin", "TMPDIR": str(layout["scratch"]), "HOME": str(layout["scratch"])},
            check=False,
        )
        return {"rc": proc.returncode, "out": proc.stdout.strip(), "err": proc.stderr[-2000:]}

    seen = in_child(work)
    assert (seen["rc"], seen["out"]) == (0, "imported"), seen["err"]


@needs_landlock
def test_landlock_refuses_a_threaded_process(layout: dict[str, Path]) -> None:
    def work() -> dict[str, Any]:
        stop = threading.Event()
        thread = threading.Thread(target=stop.wait)
        thread.start()
        try:
            return {
                "apply": attempt(
                    lambda: _harden.apply_landlock(
                        read_paths=[], write_paths=[str(layout["scratch"])], abi=ABI
                    )
                ),
                "write_after": attempt(lambda: write_file(layout["outside"] / "still.txt")),
            }
        finally:
            stop.set()
            thread.join()

    assert in_child(work) == {"apply": "EBUSY", "write_after": "ok"}


# --- seccomp --------------------------------------------------------------------------------------


@needs_seccomp
def test_seccomp_blocks_network_sockets_and_namespaces(tmp_path: Path) -> None:
    def work() -> dict[str, Any]:
        _harden.apply_seccomp()

        def socketpair() -> None:
            a, b = socket.socketpair(socket.AF_UNIX, socket.SOCK_STREAM)
            a.sendall(b"x")
            assert b.recv(1) == b"x"
            a.close()
            b.close()

        def fork_child() -> None:
            pid = os.fork()
            if pid == 0:  # pragma: no cover
                os._exit(7)
            _, status = os.waitpid(pid, 0)
            assert os.waitstatus_to_exitcode(status) == 7

        def thread() -> None:
            box: list[int] = []
            t = threading.Thread(target=lambda: box.append(1))
            t.start()
            t.join()
            assert box == [1]

        return {
            "tcp": attempt(lambda: socket.socket(socket.AF_INET, socket.SOCK_STREAM).close()),
            "udp": attempt(lambda: socket.socket(socket.AF_INET, socket.SOCK_DGRAM).close()),
            "tcp6": attempt(lambda: socket.socket(socket.AF_INET6, socket.SOCK_STREAM).close()),
            "netlink": attempt(lambda: socket.socket(socket.AF_NETLINK, socket.SOCK_RAW).close()),
            "unix": attempt(lambda: socket.socket(socket.AF_UNIX, socket.SOCK_STREAM).close()),
            "socketpair": attempt(socketpair),
            "unshare": attempt(lambda: _harden._unshare(0x40000000)),  # CLONE_NEWNET
            "mknod_block": attempt(
                lambda: os.mknod(tmp_path / "disk", 0o600 | stat.S_IFBLK, os.makedev(7, 0))
            ),
            "fifo": attempt(lambda: os.mkfifo(tmp_path / "fifo")),
            "fork": attempt(fork_child),
            "thread": attempt(thread),
            "exec": attempt(lambda: subprocess.run(["true"], check=True)),
        }

    assert in_child(work) == {
        "tcp": "EACCES",
        "udp": "EACCES",
        "tcp6": "EACCES",
        "netlink": "EACCES",
        "unix": "ok",
        "socketpair": "ok",
        "unshare": "EPERM",
        "mknod_block": "EPERM",
        "fifo": "ok",
        "fork": "ok",
        "thread": "ok",
        "exec": "ok",
    }
    assert not (tmp_path / "disk").exists()


@needs_seccomp
def test_seccomp_filter_denies_kill_minus_one() -> None:
    """The kill(-1) rule, checked in the exported filter: kill(-1) itself is never run here."""
    sc = _harden._import_pyseccomp()
    nr = int(sc.resolve_syscall(sc.Arch.NATIVE, "kill"))
    with tempfile.TemporaryFile("w+") as out:
        _harden._build_seccomp_filter(sc).export_pfc(out)
        out.seek(0)
        pfc = out.read()
    block = pfc.split(f'"kill" ({nr})', 1)[1].split("# filter for syscall", 1)[0]
    assert f"$syscall == {nr}" in block
    assert "$a0.lo32 & 0xffffffff == 4294967295" in block
    assert f"ERRNO({errno.EPERM})" in block


# --- network namespace ----------------------------------------------------------------------------


@needs_netns
def test_netns_leaves_only_loopback(listener: socket.socket) -> None:
    address = listener.getsockname()

    def work() -> dict[str, Any]:
        before = [name for _, name in socket.if_nameindex()]
        _harden.apply_netns()
        return {
            "before_has_more": len(before) > 1,
            "after": [name for _, name in socket.if_nameindex()],
            "connect": attempt(lambda: tcp_connect(address)),
        }

    seen = in_child(work)
    assert seen["after"] == ["lo"]
    assert seen["connect"] in ("ENETUNREACH", "ECONNREFUSED")


@needs_netns
@pytest.mark.skipif(os.geteuid() != 0, reason="the non-root path is exercised directly when not root")
def test_netns_as_an_unprivileged_user() -> None:
    """Root drops to nobody in the child, then takes the user-namespace path with uid/gid maps."""

    def work() -> dict[str, Any]:
        os.setgroups([])
        os.setresgid(65534, 65534, 65534)
        os.setresuid(65534, 65534, 65534)
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(4, 1, 0, 0, 0)  # PR_SET_DUMPABLE: setuid cleared it, making /proc/self/*_map root's
        outcome = attempt(_harden.apply_netns)
        return {
            "apply": outcome,
            "uid": os.getuid(),
            "gid": os.getgid(),
            "names": [name for _, name in socket.if_nameindex()] if outcome == "ok" else [],
        }

    seen = in_child(work)
    if seen["apply"] in ("EPERM", "EACCES", "ENOSPC", "EINVAL"):
        pytest.skip(f"unprivileged user namespaces refused here ({seen['apply']})")
    assert seen == {"apply": "ok", "uid": 65534, "gid": 65534, "names": ["lo"]}


@needs_landlock
@needs_seccomp
@needs_netns
def test_layers_stack_in_the_supervisor_order(layout: dict[str, Path], listener: socket.socket) -> None:
    address = listener.getsockname()

    def work() -> dict[str, Any]:
        _harden.set_no_new_privs()
        _harden.apply_netns()
        label = _harden.apply_landlock(
            read_paths=read_paths_excluding(layout["tmp"]), write_paths=[str(layout["scratch"])], abi=ABI
        )
        _harden.apply_seccomp()

        def udp() -> None:
            with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
                s.sendto(b"x", address)

        return {
            "label": label,
            "udp": attempt(udp),
            "tcp": attempt(lambda: tcp_connect(address)),
            "scratch": attempt(lambda: write_file(layout["scratch"] / "ok.txt")),
            "outside": attempt(lambda: write_file(layout["outside"] / "no.txt")),
        }

    seen = in_child(work)
    assert seen == {
        "label": f"landlock:abi{ABI}",
        "udp": "EACCES",
        "tcp": "EACCES",
        "scratch": "ok",
        "outside": "EACCES",
    }


# --- bubblewrap -----------------------------------------------------------------------------------


def test_bwrap_argv_rejects_bad_arguments(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    with pytest.raises(InvalidArgumentError, match="bind_rw"):
        _bwrap.bwrap_argv(bind_rw=["relative/dir"], ro_paths=[])
    with pytest.raises(InvalidArgumentError, match="bind_rw"):
        _bwrap.bwrap_argv(bind_rw=[str(tmp_path / "missing")], ro_paths=[])
    with pytest.raises(InvalidArgumentError, match="ro_paths"):
        _bwrap.bwrap_argv(bind_rw=[], ro_paths="/usr")
    with pytest.raises(InvalidArgumentError, match="tmpfs_bytes"):
        _bwrap.bwrap_argv(bind_rw=[], ro_paths=[], tmpfs_bytes=0)
    for scratch in ("/var/tmp/scratch", "/tmp", "tmp/scratch", "/tmpx/scratch"):
        with pytest.raises(InvalidArgumentError, match="scratch: expected an absolute path beneath /tmp"):
            _bwrap.bwrap_argv(bind_rw=[], ro_paths=[], scratch=scratch)
    monkeypatch.setattr(_bwrap, "bwrap_path", lambda: None)
    with pytest.raises(MissingDependencyError, match="apt-get install bubblewrap"):
        _bwrap.bwrap_argv(bind_rw=[], ro_paths=[])


@needs_bwrap
def test_bwrap_argv_layout(tmp_path: Path) -> None:
    rw = tmp_path / "runs"
    nested_ro = rw / "ro"
    nested_ro.mkdir(parents=True)
    argv = _bwrap.bwrap_argv(
        bind_rw=[str(rw)],
        ro_paths=[*_harden.default_read_paths(), str(nested_ro), str(tmp_path / "missing")],
        tmpfs_bytes=1 << 20,
    )
    assert argv[0] == _bwrap.bwrap_path()
    assert argv[-3:] == ["--hostname", "sandbox", "--"]
    for flag in ("--unshare-all", "--die-with-parent", "--new-session"):
        assert flag in argv
    assert argv[argv.index("--cap-drop") + 1] == "ALL"
    assert argv[argv.index("--ro-bind") : argv.index("--ro-bind") + 3] == ["--ro-bind", "/", "/"]

    def position(*triple: str) -> int:
        for i in range(len(argv) - len(triple) + 1):
            if tuple(argv[i : i + len(triple)]) == triple:
                return i
        raise AssertionError(f"{triple} not in {argv}")

    tmpfs = {root: position("--size", str(1 << 20), "--tmpfs", root) for root in ("/root", "/home", "/tmp")}
    last_tmpfs = max(tmpfs.values())
    rw_at = position("--bind", str(rw), str(rw))
    assert rw_at > last_tmpfs
    if Path(sys.base_prefix).is_relative_to("/root"):  # the interpreter under root's home is bound back
        base = os.path.realpath(sys.base_prefix)
        assert position("--ro-bind", base, base) > last_tmpfs
    assert position("--ro-bind", str(nested_ro), str(nested_ro)) > rw_at  # nested binds after their parent
    assert str(tmp_path / "missing") not in argv


def test_bwrap_argv_mounts_a_scratch_tmpfs_after_tmp() -> None:
    argv = _bwrap.bwrap_argv(bind_rw=[], ro_paths=[], tmpfs_bytes=1 << 20, scratch="/tmp/scratch")
    triples = [tuple(argv[i : i + 4]) for i in range(len(argv) - 3)]
    tmp_at = triples.index(("--size", str(1 << 20), "--tmpfs", "/tmp"))
    scratch_at = triples.index(("--size", str(1 << 20), "--tmpfs", "/tmp/scratch"))
    assert scratch_at > tmp_at


@needs_bwrap
def test_bwrap_runs_the_venv_python_isolated(tmp_path: Path) -> None:
    pytest.importorskip("casadi")
    rw = tmp_path / "runs"
    rw.mkdir()
    (tmp_path / "secret.txt").write_text("API_KEY=hunter2")
    marker = f"/tmp/audere-bwrap-marker-{os.getpid()}"
    code = f"""
import json, os, socket
import numpy, casadi, audere
out = {{}}
def attempt(name, action):
    try:
        action()
        out[name] = "ok"
    except OSError as exc:
        out[name] = exc.strerror
attempt("tmp_write", lambda: open({marker!r}, "w").write("x"))
attempt("rw_write", lambda: open({str(rw / "out.txt")!r}, "w").write("y"))
attempt("etc_write", lambda: open("/etc/audere-bwrap-test", "w"))
attempt("secret_read", lambda: open({str(tmp_path / "secret.txt")!r}).read())
out["ifaces"] = [name for _, name in socket.if_nameindex()]
out["hostname"] = socket.gethostname()
out["pid_small"] = os.getpid() < 10
out["cap_eff"] = [l.split()[1] for l in open("/proc/self/status") if l.startswith("CapEff")][0]
print(json.dumps(out))
"""
    argv = _bwrap.bwrap_argv(bind_rw=[str(rw)], ro_paths=_harden.default_read_paths())
    proc = subprocess.run(
        [*argv, sys.executable, "-I", "-c", code],
        capture_output=True,
        text=True,
        timeout=120,
        env={"PATH": "/usr/bin:/bin", "MPLBACKEND": "Agg"},
        check=False,
    )
    assert proc.returncode == 0, proc.stderr[-3000:]
    seen = json.loads(proc.stdout)
    assert seen == {
        "tmp_write": "ok",
        "rw_write": "ok",
        "etc_write": "Read-only file system",
        "secret_read": "No such file or directory",
        "ifaces": ["lo"],
        "hostname": "sandbox",
        "pid_small": True,
        "cap_eff": "0000000000000000",
    }
    assert not os.path.exists(marker)
    assert (rw / "out.txt").read_text() == "y"
