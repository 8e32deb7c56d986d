"""Who a resident render process is, where it listens and whom it may serve: the installation's name and
fingerprint, its socket's private folder, the ``FRUSTUM_RESIDENT`` setting, and the conditions (environment,
limits, affinity, cgroup) a request must share with the resident (``frustum.app.resident``)."""

from __future__ import annotations

import contextlib
import os
import stat
import sys
from pathlib import Path
from typing import Any

APPLIED = frozenset({"PWD", "OLDPWD", "SHLVL", "_", "TERM", "COLORTERM", "COLUMNS", "LINES", "PATH", "HOME",
                     "TMPDIR", "TEMP", "TMP", "MAKEFLAGS", "MFLAGS", "MAKELEVEL", "FRUSTUM_RESIDENT",
                     "FRUSTUM_RESIDENT_IDLE_S"})  # fmt: skip
"""Environment variables that may differ between a command and the resident: the request's child takes the
command's values (nothing reads them once at start-up). Any other difference makes the resident refuse."""

APPLIED_PREFIXES = ("SSH_", "XDG_", "TERM_", "WINDOWID", "DISPLAY", "WAYLAND_", "DBUS_", "GPG_", "LS_COLORS")
"""Prefixes of variables treated as ``APPLIED`` (sessions, terminals, desktops)."""


def setting() -> str:
    """``FRUSTUM_RESIDENT``: "on" (1, on, yes, true: use a resident and start one after a successful render), "off"
    (0, off, no, false: never use one) or "auto" (unset: use one started on purpose, start none)."""
    value = os.environ.get("FRUSTUM_RESIDENT", "").strip().lower()
    if value in ("1", "on", "yes", "true"):
        return "on"
    if value in ("0", "off", "no", "false"):
        return "off"
    return "auto"


def enabled() -> bool:
    """Whether this system supports resident processes (Linux: ``SO_PEERCRED`` and ``fork``)."""
    import socket  # here: a plain render without a resident imports no socket module (``maybe_running``)

    return sys.platform == "linux" and hasattr(socket, "SO_PEERCRED") and hasattr(os, "fork")


def wanted() -> bool:
    """Whether a successful plain render should leave a resident process behind (``FRUSTUM_RESIDENT=1``)."""
    return enabled() and setting() == "on"


def _package_dir() -> Path:
    """The ``frustum`` package's folder (this module is in its ``app`` package)."""
    return Path(__file__).resolve().parent.parent


class _Digest:
    """Two CRC-32s of what is fed (a name, not a secret: the socket's folder is what keeps it private); zlib
    loads in a fraction of hashlib's time, which counts in a command that takes 0.1 s."""

    def __init__(self) -> None:
        import zlib

        self.crc32, self.low, self.high = zlib.crc32, 0, 0x5EED

    def update(self, data: bytes) -> None:
        self.low, self.high = self.crc32(data, self.low), self.crc32(data[::-1], self.high)

    def hexdigest(self) -> str:
        return f"{self.low:08x}{self.high:08x}"


def _installation(package: Path | None = None) -> str:
    """16 hex digits naming this user's resident socket: the Python executable and frustum's folder."""
    package = _package_dir() if package is None else package
    digest = _Digest()
    digest.update(f"{os.path.realpath(sys.executable)}\0{sys.prefix}\0{package}\0".encode())
    return digest.hexdigest()


def fingerprint(package: Path | None = None) -> str:
    """16 hex digits naming the state of the installation a resident process serves: the interpreter, frustum's
    source files (name, size, modification time) and the site-packages folders (installing or upgrading a package
    changes their time)."""
    package = _package_dir() if package is None else package
    digest = _Digest()
    digest.update(f"{os.path.realpath(sys.executable)}\0{sys.prefix}\0{sys.version}\0{package}\0".encode())
    for folder, folders, files in os.walk(package):
        folders[:] = sorted(name for name in folders if name != "__pycache__")
        for name in sorted(files):
            if name.endswith(".py"):
                info = os.stat(os.path.join(folder, name))
                digest.update(f"{folder}/{name}\0{info.st_size}\0{info.st_mtime_ns}\0".encode())
    for entry in sys.path:
        if os.path.basename(entry) in ("site-packages", "dist-packages") and os.path.isdir(entry):
            digest.update(f"{entry}\0{os.stat(entry).st_mtime_ns}\0".encode())
    return digest.hexdigest()


def _private_folder(create: bool) -> Path | None:
    """The user's folder for resident sockets, made (mode 0700) when `create`; None when it is missing or unsafe
    (someone else's, a link, or open to other users)."""
    runtime = os.environ.get("XDG_RUNTIME_DIR")
    if runtime and os.path.isabs(runtime):
        base = Path(runtime)
    else:
        import tempfile

        base = Path(tempfile.gettempdir())
    folder = base / ("frustum" if runtime else f"frustum-{os.getuid()}")
    if create:
        with contextlib.suppress(FileExistsError, OSError):
            folder.mkdir(mode=0o700)
    try:
        info = os.lstat(folder)
    except OSError:
        return None
    private = stat.S_ISDIR(info.st_mode) and info.st_uid == os.getuid() and not info.st_mode & 0o077
    return folder if private else None


def _paths(create: bool = False) -> tuple[Path, Path] | None:
    """The socket and lock file of this installation's resident process, or None (unsafe folder, long path)."""
    folder = _private_folder(create)
    if folder is None:
        return None
    name = f"render-{_installation()}"
    path = folder / f"{name}.sock"
    if len(os.fsencode(path)) >= 100:  # sockaddr_un holds 108 bytes
        return None
    return path, folder / f"{name}.lock"


def maybe_running() -> bool:
    """Whether a resident render process of this installation may be listening: its socket exists (a cheap check
    before the client, ``frustum.app.resident``, is imported; ``FRUSTUM_RESIDENT=0`` says no)."""
    if setting() == "off":
        return False
    paths = _paths()
    return paths is not None and paths[0].exists()


def conditions() -> dict[str, Any]:
    """What a request's work runs under besides its command line: the full environment, the umask, the working
    folder, every resource limit (soft, hard), the CPU affinity, the cgroup and the nice value."""
    import resource

    umask = os.umask(0o022)
    os.umask(umask)
    limits = {name: list(resource.getrlimit(getattr(resource, name))) for name in sorted(dir(resource))
              if name.startswith("RLIMIT_")}  # fmt: skip
    try:
        cgroup = Path("/proc/self/cgroup").read_text()
    except OSError:
        cgroup = ""
    return {"env": dict(os.environ), "umask": umask, "cwd": os.getcwd(), "limits": limits,
            "affinity": sorted(os.sched_getaffinity(0)), "cgroup": cgroup,
            "nice": os.getpriority(os.PRIO_PROCESS, 0)}  # fmt: skip


def _applied(name: str) -> bool:
    return name in APPLIED or name.startswith(APPLIED_PREFIXES)


def difference(own: dict[str, Any], theirs: dict[str, Any]) -> str | None:
    """What in `theirs` (a request's ``conditions``) differs from `own` so that the resident must refuse it, in
    words (naming the variable or limit), or None when it may serve it."""
    mine, other = own["env"], theirs["env"]
    for name in sorted(set(mine) | set(other)):
        if not _applied(name) and mine.get(name) != other.get(name):
            return f"the environment variable {name} differs"
    for key, words in (("limits", "the resource limits (ulimit) differ"), ("affinity", "the CPU affinity differs"),
                       ("cgroup", "the cgroup differs"), ("nice", "the nice value differs")):  # fmt: skip
        if own[key] != theirs[key]:
            return words
    return None
