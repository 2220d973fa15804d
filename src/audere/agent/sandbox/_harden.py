"""Kernel hardening layers for the per-run sandbox child: Landlock, seccomp, a network namespace.

Imported inside the sandbox supervisor, so only the standard library is imported at module load
(``pyseccomp`` is imported lazily by the seccomp functions). The per-run child applies the layers in
this order, after forking and before running any model-written code:

1. :func:`set_no_new_privs`
2. :func:`apply_netns` (skipped inside bubblewrap, which has already unshared the network)
3. :func:`apply_landlock`
4. :func:`apply_seccomp` (last: it denies ``unshare``, which step 2 needs)

The probes (:func:`landlock_abi`, :func:`seccomp_status`, :func:`netns_status`) never raise and never
hang; their answers are cached for the life of the process.

Landlock is driven by raw ``syscall(2)`` calls through :mod:`ctypes` (numbers 444-446, the generic
numbers every architecture audere supports uses). The rights requested depend on the kernel's ABI:

======  ==========================================================================
ABI     what is handled
======  ==========================================================================
1       filesystem: execute, read, write, list, create and remove entries
2       + ``REFER`` (renames and links across directories)
3       + ``TRUNCATE``
4       + TCP ``bind`` and ``connect`` (handled with no port allowed: all denied)
5       + ``IOCTL_DEV`` (ioctl on device files)
6, 7    + scoping of abstract unix sockets and signals to the sandbox's own domain
======  ==========================================================================
"""

from __future__ import annotations

import ctypes
import errno
import functools
import importlib
import json
import logging
import os
import socket
import stat
import subprocess
import sys
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

from audere.errors import InvalidArgumentError

__all__ = [
    "apply_landlock",
    "apply_netns",
    "apply_seccomp",
    "broad_dirs",
    "default_read_paths",
    "isolated_sys_path",
    "landlock_abi",
    "netns_status",
    "seccomp_status",
    "set_no_new_privs",
]

_LOG = logging.getLogger(__name__)

# --- libc -----------------------------------------------------------------------------------------

_PR_SET_NO_NEW_PRIVS = 38
_PR_SET_SECCOMP = 22
_SECCOMP_MODE_FILTER = 2
_CLONE_NEWNS = 0x00020000
_CLONE_NEWCGROUP = 0x02000000
_CLONE_NEWUTS = 0x04000000
_CLONE_NEWIPC = 0x08000000
_CLONE_NEWUSER = 0x10000000
_CLONE_NEWPID = 0x20000000
_CLONE_NEWNET = 0x40000000
_TIOCSTI = 0x5412
_TIOCLINUX = 0x541C
_S_IFMT = 0o170000  # stat.S_IFMT is a function, not the mask

# Time allowed to a probe subprocess before it is killed and the layer reported unavailable.
_PROBE_TIMEOUT_S = 10.0
_PROBE_ENV = {"PATH": "/usr/local/bin:/usr/bin:/bin:/usr/sbin:/sbin", "LC_ALL": "C.UTF-8"}


@functools.cache
def _libc() -> ctypes.CDLL:
    """The C library of this process, with ``errno`` kept for :func:`ctypes.get_errno`."""
    libc = ctypes.CDLL(None, use_errno=True)
    libc.syscall.restype = ctypes.c_long
    libc.prctl.restype = ctypes.c_int
    libc.unshare.restype = ctypes.c_int
    return libc


def _os_error(err: int, what: str) -> OSError:
    return OSError(err, f"{what}: {os.strerror(err)}")


def _prctl(option: int, arg2: int = 0, arg3: int = 0) -> int:
    """Call ``prctl(option, arg2, arg3, 0, 0)``; return its result (``-1`` with errno set on failure)."""
    ulong = ctypes.c_ulong
    return int(_libc().prctl(ctypes.c_int(option), ulong(arg2), ulong(arg3), ulong(0), ulong(0)))


def set_no_new_privs() -> None:
    """Set ``PR_SET_NO_NEW_PRIVS``: no later ``execve`` can gain privileges (setuid bits, file caps).

    Landlock needs it when the process lacks ``CAP_SYS_ADMIN``; it is inherited by every child and
    cannot be unset.

    Raises
    ------
    OSError
        When ``prctl`` fails.
    """
    if _prctl(_PR_SET_NO_NEW_PRIVS, 1) != 0:
        raise _os_error(ctypes.get_errno(), "prctl(PR_SET_NO_NEW_PRIVS)")


# --- Landlock -------------------------------------------------------------------------------------

# Syscall numbers: the generic table, shared by x86_64 and aarch64 (and every other architecture
# that adopted the unified numbering for syscalls added after Linux 5.1).
_LANDLOCK_SYSCALLS: dict[str, tuple[int, int, int]] = dict.fromkeys(
    ("x86_64", "amd64", "aarch64", "arm64"), (444, 445, 446)
)
_LANDLOCK_CREATE_RULESET_VERSION = 1
_LANDLOCK_RULE_PATH_BENEATH = 1

_FS_EXECUTE = 1 << 0
_FS_WRITE_FILE = 1 << 1
_FS_READ_FILE = 1 << 2
_FS_READ_DIR = 1 << 3
_FS_REMOVE_DIR = 1 << 4
_FS_REMOVE_FILE = 1 << 5
_FS_MAKE_CHAR = 1 << 6
_FS_MAKE_DIR = 1 << 7
_FS_MAKE_REG = 1 << 8
_FS_MAKE_SOCK = 1 << 9
_FS_MAKE_FIFO = 1 << 10
_FS_MAKE_BLOCK = 1 << 11
_FS_MAKE_SYM = 1 << 12
_FS_REFER = 1 << 13  # ABI 2
_FS_TRUNCATE = 1 << 14  # ABI 3
_FS_IOCTL_DEV = 1 << 15  # ABI 5
_NET_BIND_TCP = 1 << 0  # ABI 4
_NET_CONNECT_TCP = 1 << 1  # ABI 4
_SCOPE_ABSTRACT_UNIX_SOCKET = 1 << 0  # ABI 6
_SCOPE_SIGNAL = 1 << 1  # ABI 6

_FS_ABI1 = (1 << 13) - 1  # EXECUTE .. MAKE_SYM
# Rights that make sense on a regular file; the others are directory-only, and a rule on a file
# that names one fails with EINVAL.
_FS_FILE_RIGHTS = _FS_EXECUTE | _FS_WRITE_FILE | _FS_READ_FILE | _FS_TRUNCATE | _FS_IOCTL_DEV
_FS_READ_RIGHTS = _FS_EXECUTE | _FS_READ_FILE | _FS_READ_DIR
# Write paths get everything except creating device nodes: a root process allowed MAKE_BLOCK in its
# scratch dir could create a node for the host's disk and read it raw.
_FS_WRITE_EXCLUDED = _FS_MAKE_CHAR | _FS_MAKE_BLOCK


class _RulesetAttr(ctypes.Structure):
    _fields_ = [
        ("handled_access_fs", ctypes.c_uint64),
        ("handled_access_net", ctypes.c_uint64),  # ABI 4
        ("scoped", ctypes.c_uint64),  # ABI 6
    ]


class _PathBeneathAttr(ctypes.Structure):
    _pack_ = 1  # packed in the kernel's UAPI header: 12 bytes
    _fields_ = [("allowed_access", ctypes.c_uint64), ("parent_fd", ctypes.c_int32)]


def _handled_fs(abi: int) -> int:
    """Filesystem rights a ruleset handles (denies unless a rule allows them) at ``abi``."""
    rights = _FS_ABI1
    if abi >= 2:
        rights |= _FS_REFER
    if abi >= 3:
        rights |= _FS_TRUNCATE
    if abi >= 5:
        rights |= _FS_IOCTL_DEV
    return rights


def _handled_net(abi: int) -> int:
    return _NET_BIND_TCP | _NET_CONNECT_TCP if abi >= 4 else 0


def _scoped(abi: int) -> int:
    return _SCOPE_ABSTRACT_UNIX_SOCKET | _SCOPE_SIGNAL if abi >= 6 else 0


def _ruleset_attr_size(abi: int) -> int:
    """Size passed to ``landlock_create_ruleset``: only the fields the kernel's ABI knows about."""
    if abi >= 6:
        return 24
    if abi >= 4:
        return 16
    return 8


def _landlock_syscalls() -> tuple[int, int, int] | None:
    return _LANDLOCK_SYSCALLS.get(os.uname().machine)


@functools.cache
def landlock_abi() -> int:
    """Landlock ABI version offered by the kernel; 0 when Landlock is unavailable.

    Unavailable means: not Linux, an architecture without known syscall numbers, a kernel built
    without Landlock (``ENOSYS``) or booted with it disabled (``EOPNOTSUPP``). Never raises; the
    answer is cached.

    Returns
    -------
    int
        The ABI version (7 on Linux 6.15+), or 0.
    """
    try:
        numbers = _landlock_syscalls()
        if numbers is None or not sys.platform.startswith("linux"):
            return 0
        abi = int(
            _libc().syscall(
                ctypes.c_long(numbers[0]),
                None,
                ctypes.c_size_t(0),
                ctypes.c_uint32(_LANDLOCK_CREATE_RULESET_VERSION),
            )
        )
        if abi < 0:
            _LOG.debug("Landlock unavailable: %s", os.strerror(ctypes.get_errno()))
            return 0
        return abi
    except Exception:  # a probe never raises
        _LOG.debug("Landlock probe failed", exc_info=True)
        return 0


def _thread_count() -> int | None:
    try:
        return len(os.listdir("/proc/self/task"))
    except OSError:
        return None


def _check_paths(field: str, paths: Sequence[str]) -> list[str]:
    if isinstance(paths, str | bytes):
        raise InvalidArgumentError(
            f"{field}: expected a sequence of absolute paths, got the string {paths!r}"
        )
    checked = []
    for path in paths:
        if not isinstance(path, str) or not os.path.isabs(path):
            raise InvalidArgumentError(f"{field}: expected absolute paths, got {path!r}")
        checked.append(os.path.normpath(path))
    return checked


def apply_landlock(*, read_paths: Sequence[str], write_paths: Sequence[str], abi: int) -> str:
    """Restrict this process (and every future child) with a Landlock ruleset.

    Reading and executing is allowed only beneath ``read_paths``; everything (except creating device
    nodes) only beneath ``write_paths``; every other filesystem access is denied, ``/proc`` included.
    At ABI >= 4, TCP bind and connect are denied; at ABI >= 6, signals and abstract unix socket
    connections to processes outside this Landlock domain are denied. Sets ``no_new_privs`` first.

    Landlock restricts only the calling thread, so this must run while the process has a single
    thread (as in a freshly forked child); it refuses otherwise.

    Parameters
    ----------
    read_paths
        Absolute paths (directories or files) readable and executable; missing ones are skipped.
        Usually :func:`default_read_paths`.
    write_paths
        Absolute paths with full access (the run's scratch dir); each must exist.
    abi
        The ABI to target, normally :func:`landlock_abi`; a lower value than the kernel's gives the
        rights of that older ABI.

    Returns
    -------
    str
        The layer's label, e.g. ``"landlock:abi7"``.

    Raises
    ------
    InvalidArgumentError
        ``abi`` below 1 or a relative path.
    OSError
        When a syscall fails (``FileNotFoundError`` for a missing write path), or when the process
        has more than one thread.
    """
    if isinstance(abi, bool) or not isinstance(abi, int) or abi < 1:
        raise InvalidArgumentError(f"abi: expected a Landlock ABI version >= 1, got {abi!r}")
    reads = _check_paths("read_paths", read_paths)
    writes = _check_paths("write_paths", write_paths)
    numbers = _landlock_syscalls()
    if numbers is None:
        raise _os_error(errno.ENOSYS, f"Landlock syscall numbers unknown on {os.uname().machine}")
    nr_create, nr_add, nr_restrict = numbers
    threads = _thread_count()
    if threads is not None and threads > 1:
        raise OSError(errno.EBUSY, f"Landlock restricts one thread only, and this process has {threads}")

    handled_fs = _handled_fs(abi)
    attr = _RulesetAttr(
        handled_access_fs=handled_fs, handled_access_net=_handled_net(abi), scoped=_scoped(abi)
    )
    libc = _libc()
    ruleset_fd = int(
        libc.syscall(
            ctypes.c_long(nr_create),
            ctypes.byref(attr),
            ctypes.c_size_t(_ruleset_attr_size(abi)),
            ctypes.c_uint32(0),
        )
    )
    if ruleset_fd < 0:
        raise _os_error(ctypes.get_errno(), f"landlock_create_ruleset (abi {abi})")
    try:
        read_rights = _FS_READ_RIGHTS & handled_fs
        write_rights = handled_fs & ~_FS_WRITE_EXCLUDED
        for path in reads:
            _add_path_rule(nr_add, ruleset_fd, path, read_rights, required=False)
        for path in writes:
            _add_path_rule(nr_add, ruleset_fd, path, write_rights, required=True)
        set_no_new_privs()
        if int(libc.syscall(ctypes.c_long(nr_restrict), ctypes.c_int(ruleset_fd), ctypes.c_uint32(0))) != 0:
            raise _os_error(ctypes.get_errno(), "landlock_restrict_self")
    finally:
        os.close(ruleset_fd)
    return f"landlock:abi{abi}"


def _add_path_rule(nr_add: int, ruleset_fd: int, path: str, rights: int, *, required: bool) -> None:
    try:
        fd = os.open(path, os.O_PATH | os.O_CLOEXEC)
    except FileNotFoundError:
        if required:
            raise
        _LOG.debug("Landlock: skipping missing read path %s", path)
        return
    try:
        if not stat.S_ISDIR(os.fstat(fd).st_mode):
            rights &= _FS_FILE_RIGHTS
        rule = _PathBeneathAttr(allowed_access=rights, parent_fd=fd)
        result = _libc().syscall(
            ctypes.c_long(nr_add),
            ctypes.c_int(ruleset_fd),
            ctypes.c_int(_LANDLOCK_RULE_PATH_BENEATH),
            ctypes.byref(rule),
            ctypes.c_uint32(0),
        )
        if int(result) != 0:
            raise _os_error(ctypes.get_errno(), f"landlock_add_rule({path!r})")
    finally:
        os.close(fd)


# Entries of /etc left out of the read allowlist: readable by root, and not needed by Python code.
_ETC_EXCLUDED = (
    "shadow",
    "shadow-",
    "gshadow",
    "gshadow-",
    "sudoers",
    "sudoers.d",
    "ssh",
    "ssl/private",
    "security/opasswd",
    "credstore",
    "credstore.encrypted",
)


def _expand_excluding(root: str, excluded: Iterable[str]) -> list[str]:
    """Paths covering everything beneath ``root`` except the ``excluded`` relative paths."""
    excluded = [e.strip("/") for e in excluded]
    if "" in excluded:
        return []
    nested = {e.split("/", 1)[0] for e in excluded}
    try:
        names = sorted(os.listdir(root))
    except OSError:
        return []
    out: list[str] = []
    for name in names:
        path = os.path.join(root, name)
        if name not in nested:
            out.append(path)
        elif os.path.isdir(path) and not os.path.islink(path):
            deeper = [e.split("/", 1)[1] if "/" in e else "" for e in excluded if e.split("/", 1)[0] == name]
            out.extend(_expand_excluding(path, deeper))
    return out


# Directories never allowed as a whole.
_BROAD_DIRS = ("/tmp", "/var/tmp", "/dev/shm", "/root", "/home", "/run", "/proc", "/sys", "/dev")


@functools.cache
def broad_dirs() -> frozenset[str]:
    """Directories never allowed to the sandbox as a whole: ``/``, ``/tmp``, ``/root``, ``$HOME``..."""
    return frozenset(os.path.realpath(p) for p in ("/", *_BROAD_DIRS, os.path.expanduser("~")))


@functools.cache
def isolated_sys_path() -> tuple[str, ...]:
    """``sys.path`` of this interpreter started with ``-I``: where the sandbox supervisor imports from.

    That is the standard library, site-packages and what its ``.pth`` files add (editable installs),
    but not the directory of the host's script nor the current directory, which the host's own
    ``sys.path`` starts with and which may hold files such as ``.env``. Asked of a subprocess once
    per process; if that fails, the host's ``sys.path`` without its first entry (unless the host
    itself runs with ``-P``/``-I``) stands in.

    Returns
    -------
    tuple[str, ...]
        Non-empty entries, in ``sys.path`` order.
    """
    try:
        probe = "import json, sys; print(json.dumps(sys.path))"
        code, out, _ = _run_probe([sys.executable, "-I", "-c", probe])
        entries = json.loads(out) if code == 0 else None
    except (OSError, subprocess.SubprocessError, ValueError):
        entries = None
    if not isinstance(entries, list) or not all(isinstance(e, str) for e in entries):
        entries = sys.path if sys.flags.safe_path else sys.path[1:]
    return tuple(entry for entry in entries if entry)


def default_read_paths(extra: Iterable[str] = ()) -> list[str]:
    """Paths a sandboxed Python process needs to read: system dirs, the interpreter and its imports.

    ``/usr /lib /lib64 /bin /sbin``, ``/etc`` minus its secrets (``shadow``, ``gshadow``,
    ``sudoers``, ``ssh``, ``ssl/private``...), ``/dev/null /dev/zero /dev/random /dev/urandom``,
    ``/sys/devices/system/cpu`` (CPU counts for BLAS), ``sys.prefix``, ``sys.base_prefix``,
    ``sys.exec_prefix``, every entry of :func:`isolated_sys_path` (editable installs live outside
    site-packages; the host script's directory is not among them), then ``extra``. Resolved through
    symlinks, deduplicated, only existing paths, never ``/proc``, and never a broad directory as a
    whole (``/``, ``/tmp``, ``/root``, ``/home``, ``$HOME``...).

    Parameters
    ----------
    extra
        More files or directories to allow (e.g. the directory of a user's own API modules).

    Returns
    -------
    list[str]
        Absolute paths, in the order above.
    """
    candidates = [
        "/usr",
        "/lib",
        "/lib32",
        "/lib64",
        "/libx32",
        "/bin",
        "/sbin",
        *_expand_excluding("/etc", _ETC_EXCLUDED),
        "/dev/null",
        "/dev/zero",
        "/dev/random",
        "/dev/urandom",
        "/sys/devices/system/cpu",
        sys.prefix,
        sys.base_prefix,
        sys.exec_prefix,
        sys.base_exec_prefix,
        *isolated_sys_path(),
        *extra,
    ]
    seen: set[str] = set(broad_dirs())
    out: list[str] = []
    for candidate in candidates:
        path = os.path.realpath(candidate)
        # /proc is never allowed (e.g. /etc/mtab -> /proc/self/mounts would resolve to *this* pid).
        if path in seen or path == "/proc" or path.startswith("/proc/") or not os.path.exists(path):
            continue
        seen.add(path)
        if any(path.startswith(parent.rstrip("/") + "/") for parent in out):
            continue  # already beneath an allowed directory
        out.append(path)
    return out


# --- network namespace ----------------------------------------------------------------------------


def _unshare(flags: int) -> None:
    unshare = getattr(os, "unshare", None)  # Python >= 3.12
    if unshare is not None:
        unshare(flags)
        return
    if _libc().unshare(ctypes.c_int(flags)) != 0:
        raise _os_error(ctypes.get_errno(), f"unshare({flags:#x})")


def _write_proc(name: str, text: str) -> None:
    fd = os.open(f"/proc/self/{name}", os.O_WRONLY | os.O_CLOEXEC)
    try:
        os.write(fd, text.encode())
    finally:
        os.close(fd)


def apply_netns() -> None:
    """Move this process into a new, empty network namespace (only a loopback device, down).

    As root: ``unshare(CLONE_NEWNET)``. Otherwise (or when root lacks ``CAP_SYS_ADMIN``):
    ``unshare(CLONE_NEWUSER | CLONE_NEWNET)`` and map the current uid and gid to themselves, with
    ``setgroups`` denied. Must run in a single-threaded process (a fresh fork child) and before
    :func:`apply_landlock` and :func:`apply_seccomp`, which forbid what it does.

    Raises
    ------
    OSError
        When the kernel refuses the namespaces (e.g. user namespaces disabled).
    """
    uid, gid = os.geteuid(), os.getegid()
    if uid == 0:
        try:
            _unshare(_CLONE_NEWNET)
            return
        except PermissionError:
            _LOG.debug("unshare(CLONE_NEWNET) refused as root; trying a user namespace")
    _unshare(_CLONE_NEWUSER | _CLONE_NEWNET)
    _write_proc("uid_map", f"{uid} {uid} 1\n")
    if os.path.exists("/proc/self/setgroups"):
        _write_proc("setgroups", "deny\n")
    _write_proc("gid_map", f"{gid} {gid} 1\n")


def _probe_code(body: str) -> str:
    """Source of a probe subprocess that loads this very file (standalone) as ``m``, then runs ``body``."""
    package_root = str(Path(__file__).resolve().parents[3])  # the directory holding the audere package
    return (
        "import importlib.util, sys\n"
        f"sys.path.insert(0, {package_root!r})\n"
        f"spec = importlib.util.spec_from_file_location('_audere_harden_probe', {str(Path(__file__))!r})\n"
        "m = importlib.util.module_from_spec(spec)\n"
        "spec.loader.exec_module(m)\n" + body
    )


def _run_probe(argv: list[str]) -> tuple[int, str, str]:
    result = subprocess.run(
        argv,
        stdin=subprocess.DEVNULL,
        capture_output=True,
        text=True,
        timeout=_PROBE_TIMEOUT_S,
        env=_PROBE_ENV,
        close_fds=True,
        check=False,
    )
    return result.returncode, result.stdout, result.stderr


def _last_line(text: str) -> str:
    lines = [line for line in text.strip().splitlines() if line.strip()]
    return lines[-1].strip() if lines else ""


@functools.cache
def netns_status() -> tuple[bool, str]:
    """Whether :func:`apply_netns` works here, tried in a subprocess; never raises, cached.

    Returns
    -------
    tuple[bool, str]
        ``(True, detail)`` when the subprocess ended up with only ``lo``; ``(False, reason)`` otherwise.
    """
    try:
        code = _probe_code(
            "import socket\nm.apply_netns()\nprint(' '.join(name for _, name in socket.if_nameindex()))\n"
        )
        rc, out, err = _run_probe([sys.executable, "-I", "-S", "-c", code])
        names = out.split()
        if rc == 0 and names == ["lo"]:
            how = "unshare(CLONE_NEWNET)" if os.geteuid() == 0 else "unshare(CLONE_NEWUSER|CLONE_NEWNET)"
            return True, f"{how}: only lo"
        if rc == 0:
            return False, f"new network namespace still has interfaces {names}"
        return False, f"netns probe failed (exit {rc}): {_last_line(err) or 'no message'}"
    except subprocess.TimeoutExpired:
        return False, f"netns probe timed out after {_PROBE_TIMEOUT_S:g} s"
    except Exception as exc:  # a probe never raises
        return False, f"netns probe failed: {type(exc).__name__}: {exc}"


# --- seccomp --------------------------------------------------------------------------------------

_SECCOMP_INSTALL_HINT = "install it with: pip install 'audere[sandbox]'"

# Denied with EPERM, whatever the arguments. Names unknown to libseccomp are skipped.
_SECCOMP_EPERM = (
    # debugging and memory of other processes
    "ptrace",
    "process_vm_readv",
    "process_vm_writev",
    "kcmp",
    # kernel attack surface
    "bpf",
    "perf_event_open",
    "userfaultfd",
    "io_uring_setup",
    "io_uring_enter",
    "io_uring_register",
    # keyrings
    "keyctl",
    "add_key",
    "request_key",
    # namespaces and mounts
    "setns",
    "unshare",
    "mount",
    "umount2",
    "pivot_root",
    "chroot",
    "open_tree",
    "move_mount",
    "fsopen",
    "fsconfig",
    "fsmount",
    "fspick",
    "mount_setattr",
    "open_by_handle_at",
    "name_to_handle_at",
    # the machine itself (a root child would otherwise be allowed these)
    "kexec_load",
    "kexec_file_load",
    "init_module",
    "finit_module",
    "delete_module",
    "reboot",
    "swapon",
    "swapoff",
    "settimeofday",
    "clock_settime",
    "clock_adjtime",
    "adjtimex",
    "sethostname",
    "setdomainname",
    "acct",
    "quotactl",
    "syslog",
    "iopl",
    "ioperm",
    "vhangup",
)


def _import_pyseccomp() -> Any:
    return importlib.import_module("pyseccomp")


@functools.cache
def seccomp_status() -> tuple[bool, str]:
    """Whether :func:`apply_seccomp` can work here; never raises, cached.

    Checks that ``pyseccomp`` imports (it needs the system's libseccomp), that it can build a filter,
    and that the kernel accepts seccomp filters (without installing one).

    Returns
    -------
    tuple[bool, str]
        ``(True, detail)`` or ``(False, reason)``, e.g. ``(False, "pyseccomp not installed; ...")``.
    """
    try:
        try:
            sc = _import_pyseccomp()
        except ImportError:
            return False, f"pyseccomp not installed; {_SECCOMP_INSTALL_HINT}"
        except Exception as exc:  # pyseccomp raises RuntimeError when libseccomp is missing
            return False, f"pyseccomp unusable: {exc}"
        # A NULL filter program: EFAULT when the kernel supports filters, EINVAL when it does not.
        if _prctl(_PR_SET_SECCOMP, _SECCOMP_MODE_FILTER, 0) == 0:  # pragma: no cover - cannot succeed
            return False, "unexpected: prctl(PR_SET_SECCOMP) accepted a NULL filter"
        err = ctypes.get_errno()
        if err != errno.EFAULT:
            return False, f"kernel refuses seccomp filters: {os.strerror(err)}"
        _build_seccomp_filter(sc)
        version = ""
        try:
            from importlib.metadata import version as dist_version

            version = f" {dist_version('pyseccomp')}"
        except Exception:
            pass
        return True, f"pyseccomp{version}, kernel seccomp filters supported"
    except Exception as exc:  # a probe never raises
        return False, f"seccomp probe failed: {type(exc).__name__}: {exc}"


def _masked_eq(sc: Any, arg: int, value: int, mask: int = 0xFFFFFFFF) -> Any:
    return sc.Arg(arg, sc.MASKED_EQ, mask, value)


def _build_seccomp_filter(sc: Any) -> Any:
    """The filter :func:`apply_seccomp` loads, built but not loaded (``sc`` is the pyseccomp module)."""
    filt = sc.SyscallFilter(sc.ALLOW)
    eperm = sc.ERRNO(errno.EPERM)

    def resolves(name: str) -> bool:
        # -1 (__NR_SCMP_ERROR) for a name libseccomp does not know; other negative numbers are its
        # pseudo-syscalls for calls absent on this architecture, which it accepts as no-ops.
        known = int(sc.resolve_syscall(sc.Arch.NATIVE, name)) != -1
        if not known:
            _LOG.debug("seccomp: libseccomp does not know syscall %s; no rule", name)
        return known

    # Sockets: only AF_UNIX. Covers UDP (which Landlock does not), raw, packet, netlink, vsock...
    # NE compares all 64 bits, so a family with junk in the upper half is denied too (fails closed).
    filt.add_rule(sc.ERRNO(errno.EACCES), "socket", sc.Arg(0, sc.NE, socket.AF_UNIX))
    for name in _SECCOMP_EPERM:
        if resolves(name):
            filt.add_rule(eperm, name)
    # kill(-1, sig) would signal every process the sandbox may signal; pid_t is 32 bits, so compare
    # the low half only (glibc zero-extends it, a raw syscall may sign-extend it).
    filt.add_rule(eperm, "kill", _masked_eq(sc, 0, 0xFFFFFFFF))
    # Device nodes (a root child could create one for the host's disk).
    for fmt in (stat.S_IFBLK, stat.S_IFCHR):
        filt.add_rule(eperm, "mknod", _masked_eq(sc, 1, fmt, _S_IFMT))
        filt.add_rule(eperm, "mknodat", _masked_eq(sc, 2, fmt, _S_IFMT))
    # Pushing input into a terminal the child may still hold.
    for request in (_TIOCSTI, _TIOCLINUX):
        filt.add_rule(eperm, "ioctl", _masked_eq(sc, 1, request))
    # New namespaces through clone (unshare and setns are denied above). clone3 passes its flags in
    # memory a filter cannot read, so it fails with ENOSYS and glibc falls back to clone.
    if os.uname().machine in ("x86_64", "amd64", "aarch64", "arm64"):  # flags are argument 0 here
        for flag in (
            _CLONE_NEWNS,
            _CLONE_NEWCGROUP,
            _CLONE_NEWUTS,
            _CLONE_NEWIPC,
            _CLONE_NEWUSER,
            _CLONE_NEWPID,
            _CLONE_NEWNET,
        ):
            filt.add_rule(eperm, "clone", _masked_eq(sc, 0, flag, flag))
        if resolves("clone3"):
            filt.add_rule(sc.ERRNO(errno.ENOSYS), "clone3")
    try:
        filt.set_attr(sc.Attr.CTL_TSYNC, 1)  # every thread of the process, not only the caller
    except OSError:
        _LOG.debug("seccomp: TSYNC not supported; filtering the calling thread only")
    return filt


def apply_seccomp() -> None:
    """Load a seccomp filter into this process (inherited by every child; cannot be removed).

    Default allow, then:

    - ``socket`` for any family but ``AF_UNIX`` -> ``EACCES`` (no TCP, UDP, raw, netlink, packet);
    - ``ptrace``, ``process_vm_readv/writev``, ``bpf``, ``perf_event_open``, ``userfaultfd``,
      ``io_uring_*``, ``keyctl``, ``add_key``, ``request_key``, ``mount``, ``umount2``, the new
      mount API, ``setns``, ``unshare``, ``kexec_*``, module loading, ``reboot``, ``swapon/off``,
      clock setting and other machine-wide calls -> ``EPERM``;
    - ``kill(-1, any)``, ``mknod`` of block and character devices, ``ioctl(TIOCSTI/TIOCLINUX)``, and
      ``clone`` with a namespace flag -> ``EPERM``; ``clone3`` -> ``ENOSYS`` (glibc falls back to
      ``clone``).

    Also sets ``no_new_privs`` (libseccomp does). Apply it last: it denies what the other layers use.
    Import ``pyseccomp`` before :func:`apply_landlock` (calling :func:`seccomp_status` in the parent
    before forking does): its import looks libseccomp up with :func:`ctypes.util.find_library`, which
    writes temporary files and runs ``ldconfig``, and fails under Landlock.

    Raises
    ------
    ImportError
        When ``pyseccomp`` (or the libseccomp it loads) is missing; see :func:`seccomp_status`.
    OSError
        When building or loading the filter fails.
    """
    try:
        sc = _import_pyseccomp()
    except ImportError as exc:
        raise ImportError(f"the seccomp layer needs pyseccomp; {_SECCOMP_INSTALL_HINT}") from exc
    except RuntimeError as exc:  # libseccomp not found
        raise ImportError(f"the seccomp layer needs libseccomp: {exc}") from exc
    except OSError as exc:  # pyseccomp's import runs ctypes.util.find_library: temp files, ldconfig
        raise OSError(
            exc.errno,
            f"importing pyseccomp failed ({exc}); import it before Landlock (seccomp_status() does)",
        ) from exc
    _build_seccomp_filter(sc).load()
