"""Atomic output files: every writer writes a temporary file beside the target and renames it when complete.

``with atomic_path(target, where=...) as temporary: write(temporary)`` creates ``.<name>.<random>.part<suffix>``
in the target's folder (so the rename is atomic, and an unwritable folder fails before any work), renames it
over `target` when the block ends normally and removes it when the block raises (an error, a full disk,
``KeyboardInterrupt``): a file that exists keeps its old content until the new one is complete, and no
partial file is ever left under the target's name. The temporary keeps the target's suffix, because encoders
(ffmpeg) choose the container from it.

The CLI removes the temporaries still open when it is interrupted (:func:`remove_partial_files`).
"""

from __future__ import annotations

import contextlib
import os
import stat
import tempfile
import threading
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from frustum.errors import FrustumError, OutputError

__all__ = ["allow_new_files", "atomic_path", "os_reason", "remove_partial_files", "track_process"]

_lock = threading.Lock()
_open: set[str] = set()
_processes: set[Any] = set()
_closed = False
_umask: int | None = None


def _file_mode() -> int:
    """0o666 less the process umask: what ``open(path, "w")`` would have given (mkstemp makes 0o600)."""
    global _umask
    if _umask is None:
        with _lock:
            _umask = os.umask(0o022)
            os.umask(_umask)
    return 0o666 & ~_umask


def file_kind(path: str | os.PathLike) -> str:
    """What an existing path that is not a regular file is: "a folder", "a character device" (``/dev/zero``),
    "a block device", "a named pipe", "a socket"; "missing" if nothing is there."""
    try:
        mode = os.stat(path).st_mode
    except OSError:
        return "missing"
    for test, name in ((stat.S_ISDIR, "a folder"), (stat.S_ISCHR, "a character device"),
                       (stat.S_ISBLK, "a block device"), (stat.S_ISFIFO, "a named pipe"),
                       (stat.S_ISSOCK, "a socket"), (stat.S_ISREG, "a regular file")):  # fmt: skip
        if test(mode):
            return name
    return "not a regular file"


def os_reason(error: BaseException) -> str:
    """The short reason of an OS error ("No space left on device"), never a command line or a bare number."""
    strerror = getattr(error, "strerror", None)
    if isinstance(strerror, str) and strerror:
        return strerror
    text = " ".join(str(error).split())
    if "CAIRO_STATUS_WRITE_ERROR" in text:  # cairo's OSError(message, 11): its status, not an errno
        return "cairo could not write it: the disk is full or the file cannot be written"
    for known in ("No space left on device", "Permission denied", "Disk quota exceeded", "Read-only file system",
                  "File too large"):  # fmt: skip
        if known.lower() in text.lower():
            return known
    text = text.split("FFMPEG COMMAND")[0].strip(" :")  # imageio appends ffmpeg's whole command line
    return type(error).__name__ if not text else text[:120]


@contextlib.contextmanager
def atomic_path(target: str | os.PathLike, *, where: str, error: type[FrustumError] = OutputError) -> Iterator[Path]:
    """Yield a temporary path beside `target`; rename it to `target` on success, remove it on any failure.

    Raises
    ------
    OutputError (or `error`)
        If the temporary cannot be created (missing or unwritable folder, full disk): before any work is done.
    """
    target = Path(target)
    try:
        handle, name = tempfile.mkstemp(prefix=f".{target.stem[:60]}.", suffix=".part" + target.suffix,
                                        dir=target.parent if str(target.parent) else ".")  # fmt: skip
    except OSError as failure:
        raise error(
            f"{where}: path = {_quoted(target)} cannot be written ({os_reason(failure)}); give a path in an "
            "existing, writable folder"
        ) from None
    os.close(handle)
    with _lock:
        _open.add(name)
        closed = _closed
    try:
        if closed:  # the CLI is shutting down after an interrupt
            raise KeyboardInterrupt
        os.chmod(name, _file_mode())
        yield Path(name)
        if target.is_dir():
            raise error(f"{where}: path = {_quoted(target)} is a folder; give a file name")
        os.replace(name, target)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(name)
        raise
    finally:
        with _lock:
            _open.discard(name)


@contextlib.contextmanager
def track_process(process: Any) -> Iterator[Any]:
    """Kill `process` (an encoder writing a temporary file) if the block fails, and let
    :func:`remove_partial_files` kill it on Ctrl-C, before the temporary is removed (it could recreate it)."""
    with _lock:
        _processes.add(process)
    try:
        yield process
    except BaseException:
        _stop(process)
        raise
    finally:
        with _lock:
            _processes.discard(process)


def _stop(process: Any) -> None:
    if process.poll() is None:
        with contextlib.suppress(OSError):
            process.kill()
        with contextlib.suppress(Exception):
            process.wait(timeout=2.0)


def remove_partial_files() -> list[str]:
    """Stop the encoders, remove every temporary file still being written and refuse new ones (the CLI calls
    it on Ctrl-C)."""
    global _closed
    with _lock:
        _closed = True
        for process in list(_processes):
            _stop(process)
        names = sorted(_open)
        for name in names:
            with contextlib.suppress(OSError):
                os.unlink(name)
        _open.clear()
    return names


def allow_new_files() -> None:
    """Accept new temporary files again after :func:`remove_partial_files` (the resident render process, between
    one cancelled request and the next)."""
    global _closed
    with _lock:
        _closed = False


def _quoted(path: Path) -> str:
    return repr(str(path))  # repr escapes control and other non-printable characters
