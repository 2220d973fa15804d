"""bubblewrap (``bwrap``): probe and command line for running the sandbox supervisor in namespaces.

Imported inside the sandbox supervisor: only the standard library, :mod:`audere.errors` and the
hardening module (stdlib-only too, whose path checks and probe settings it shares) load with it.

The sandbox built by :func:`bwrap_argv`: every namespace unshared (network with only ``lo``, pids,
IPC, UTS, cgroup, user), all capabilities dropped, the root filesystem read-only, sized tmpfs over
the directories that hold users' data and scratch files (``/root``, ``/home``, ``/tmp``, and
``/var/tmp`` and ``/run`` when they exist), a minimal ``/dev``, its own ``/proc``, a new session (no
terminal injection), and death with its parent (no orphans when the host is killed). Paths the
sandbox needs beneath a hidden directory (an interpreter under ``/root/.pyenv``, a venv under
``/tmp``) are bound back read-only, and the caller's writable directories are bound read-write.
"""

from __future__ import annotations

import functools
import os
import shutil
import subprocess
from collections.abc import Sequence

from audere.agent.sandbox._harden import (
    _PROBE_ENV,
    _PROBE_TIMEOUT_S,
    _check_paths,
    _last_line,
    _run_probe,
)
from audere.errors import InvalidArgumentError, MissingDependencyError

__all__ = ["bwrap_argv", "bwrap_path", "bwrap_status"]

# Directories replaced by an empty tmpfs inside the sandbox; the first three always, the others when
# they exist as real directories on the host.
_HIDDEN_ROOTS = ("/root", "/home", "/tmp", "/var/tmp", "/run")


def bwrap_path() -> str | None:
    """Absolute path of the ``bwrap`` executable on ``PATH``, or None when it is not installed.

    Returns
    -------
    str or None
        E.g. ``"/usr/bin/bwrap"``.
    """
    path = shutil.which("bwrap")
    return os.path.abspath(path) if path else None


def _beneath(path: str, root: str) -> bool:
    return path == root or path.startswith(root.rstrip("/") + "/")


def _hidden_roots() -> list[str]:
    return [
        root
        for root in _HIDDEN_ROOTS
        if root in ("/root", "/home", "/tmp") or (os.path.isdir(root) and not os.path.islink(root))
    ]


def bwrap_argv(
    *,
    bind_rw: Sequence[str],
    ro_paths: Sequence[str],
    tmpfs_bytes: int = 256 << 20,
    scratch: str | None = None,
) -> list[str]:
    """The ``bwrap`` command line, up to and including ``--``; the caller appends the command.

    Layout: ``bwrap --unshare-all --die-with-parent --new-session --cap-drop ALL --ro-bind / /``,
    then ``--size N --tmpfs D`` for each hidden directory (``/root``, ``/home``, ``/tmp``, and
    ``/var/tmp``, ``/run`` when present), ``--dev /dev --proc /proc``, the re-binds, ``--hostname
    sandbox --``.

    Re-binds: every ``ro_paths`` entry that lives beneath a hidden directory (under its own name and,
    when it is a symlink, under its target's) is bound back read-only; every ``bind_rw`` entry is bound
    read-write wherever it lives (the root is read-only). Binds are ordered shallowest first, so a
    path nested in another bind stays visible. ``ro_paths`` entries that do not exist are skipped.

    ``--cap-drop ALL`` matters when the host runs as root: bwrap would otherwise leave the sandbox
    every capability in its user namespace, enough to unmount the tmpfs over ``/root`` and read what
    it hides.

    Parameters
    ----------
    bind_rw
        Absolute paths of existing directories or files to bind read-write (the runs directory).
    ro_paths
        Absolute paths the sandboxed program needs to read, typically the interpreter prefix, the
        venv and ``sys.path`` (e.g. :func:`audere.agent.sandbox._harden.default_read_paths`).
    tmpfs_bytes
        Size of each tmpfs; writes beyond it fail with ``ENOSPC``.
    scratch
        An absolute path beneath ``/tmp`` to mount one more tmpfs of ``tmpfs_bytes`` on, after the
        hidden directories: a separate space for the code's scratch files, so that filling it
        leaves room in ``/tmp`` for the run's output files.

    Returns
    -------
    list[str]
        The arguments, starting with the ``bwrap`` executable and ending with ``"--"``.

    Raises
    ------
    MissingDependencyError
        When ``bwrap`` is not installed.
    InvalidArgumentError
        For a relative path, a missing ``bind_rw`` path or a non-positive ``tmpfs_bytes``.
    """
    if isinstance(tmpfs_bytes, bool) or not isinstance(tmpfs_bytes, int) or tmpfs_bytes <= 0:
        raise InvalidArgumentError(f"tmpfs_bytes: expected a positive number of bytes, got {tmpfs_bytes!r}")
    if scratch is not None and not (
        os.path.isabs(scratch) and _beneath(scratch, "/tmp") and scratch != "/tmp"
    ):
        raise InvalidArgumentError(f"scratch: expected an absolute path beneath /tmp, got {scratch!r}")
    rw = _check_paths("bind_rw", bind_rw)
    ro = _check_paths("ro_paths", ro_paths)
    for path in rw:
        if not os.path.exists(path):
            raise InvalidArgumentError(f"bind_rw: expected existing paths, got {path!r} (does not exist)")
    executable = bwrap_path()
    if executable is None:
        raise MissingDependencyError(
            "the bubblewrap sandbox layer needs the 'bwrap' executable, which is not on PATH; "
            "install it with: apt-get install bubblewrap"
        )
    hidden = _hidden_roots()

    # (destination, source, writable); later entries for the same destination win (rw over ro).
    binds: dict[str, tuple[str, bool]] = {}
    for path in ro:
        if not os.path.exists(path):
            continue
        source = os.path.realpath(path)
        for dest in dict.fromkeys((path, source)):
            if any(_beneath(dest, root) for root in hidden) and dest not in binds:
                binds[dest] = (source, False)
    for path in rw:
        source = os.path.realpath(path)
        for dest in dict.fromkeys((path, source)):
            binds[dest] = (source, True)

    argv = [
        executable,
        "--unshare-all",
        "--die-with-parent",
        "--new-session",
        "--cap-drop",
        "ALL",
        "--ro-bind",
        "/",
        "/",
    ]
    for root in hidden:
        argv += ["--size", str(tmpfs_bytes), "--tmpfs", root]
    if scratch is not None:
        argv += ["--size", str(tmpfs_bytes), "--tmpfs", scratch]
    argv += ["--dev", "/dev", "--proc", "/proc"]
    for dest in sorted(binds, key=lambda d: (d.count("/"), d)):
        source, writable = binds[dest]
        argv += ["--bind" if writable else "--ro-bind", source, dest]
    argv += ["--hostname", "sandbox", "--"]
    return argv


@functools.cache
def bwrap_status() -> tuple[bool, str]:
    """Whether bubblewrap can build the sandbox here: runs ``true`` inside :func:`bwrap_argv` once.

    Never raises and never hangs (the probe is killed after 10 s); the answer is cached. Fails e.g.
    where unprivileged user namespaces are disabled (Ubuntu's AppArmor restriction, some containers).

    Returns
    -------
    tuple[bool, str]
        ``(True, "/usr/bin/bwrap (bubblewrap 0.8.0)")`` or ``(False, reason)``.
    """
    try:
        executable = bwrap_path()
        if executable is None:
            return False, "bwrap not found on PATH (apt-get install bubblewrap)"
        true = shutil.which("true", path=_PROBE_ENV["PATH"]) or "/bin/true"
        code, _, stderr = _run_probe([*bwrap_argv(bind_rw=(), ro_paths=()), true])
        if code != 0:
            return False, f"bwrap probe failed (exit {code}): {_last_line(stderr) or 'no message'}"
        version = _run_probe([executable, "--version"])[1].strip()
        return True, f"{executable} ({version})" if version else executable
    except subprocess.TimeoutExpired:
        return False, f"bwrap probe timed out after {_PROBE_TIMEOUT_S:g} s"
    except Exception as exc:  # a probe never raises
        return False, f"bwrap probe failed: {type(exc).__name__}: {exc}"
