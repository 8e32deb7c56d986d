"""What every command of the ``frustum`` program shares: the one-line failure report, the interruptible run, the
garbage-collector pause of a short-lived process and the compile notice (each written once, here).

The bottom of the program's package (``frustum.app``): it imports nothing of the package's other modules.
"""

from __future__ import annotations

import contextlib
import gc
import os
import sys
import threading
import time
from collections.abc import Callable
from typing import Any, NoReturn

from frustum.errors import FrustumError

__all__ = ["GC_PAUSE_S", "INTERRUPTED_STATUS", "REPORTED", "UsageError", "as_program", "end_program",
           "exit_with_parent", "fail", "failure", "install_compile_notice", "report_failure", "run_interruptible",
           "run_program", "say"]  # fmt: skip


class UsageError(FrustumError):
    """A command-line argument that frustum cannot read (exit status 2)."""


_STATE: dict[str, Any] = {"debug": False, "resume_gc_at": None}

GC_PAUSE_S = 3.0
"""Seconds the ``frustum`` program runs with Python's cyclic garbage collector paused (``as_program``)."""

INTERRUPTED_STATUS = 130
"""Exit status after Ctrl-C (128 + SIGINT), as shells report it."""

INTERRUPTED_MESSAGE = "interrupted (Ctrl-C); no output file was written or changed"
"""The line (after ``error: ``) the program prints when Ctrl-C stops a command."""

REPORTED = (RecursionError, FrustumError, OSError, ValueError, TypeError, RuntimeError, MemoryError)
"""The exceptions the program reports in one line (``failure``) instead of a traceback (without --debug)."""


def say(text: str, stream: Any = None) -> None:
    """One line on stdout (or `stream`), as the program prints it: no markup, no highlighting, no wrapping."""
    target = sys.stdout if stream is None else stream
    target.write(text + "\n")


def failure(error: BaseException) -> tuple[str, int]:
    """The one-line message and exit status the program reports for `error` (not for Click's own errors)."""
    if isinstance(error, RecursionError):
        return "the input is nested too deeply to process", 1
    if isinstance(error, UsageError):
        return str(error), 2
    if isinstance(error, FrustumError):
        return str(error), 1
    text = " ".join(str(error).split()) or "no details"
    return f"{type(error).__name__}: {text}", 1


def error_line(message: str) -> str:
    """``error: <message>`` with control characters escaped (a file name cannot move the terminal's cursor)."""
    from frustum._arrays import escape_control

    return f"error: {escape_control(message, keep_newlines=True)}"


def report_failure(error: BaseException) -> int:
    """Print `error` as the program's one ``error:`` line on stderr (``failure``); its exit status."""
    text, status = failure(error)
    say(error_line(text), sys.stderr)
    return status


def fail(message: str, status: int) -> None:
    """Print ``error: <message>`` on stderr and exit with `status`."""
    say(error_line(message), sys.stderr)
    raise SystemExit(status)


def _resume_gc_when_due() -> None:
    """Re-enable the garbage collector once the program has run ``GC_PAUSE_S`` (checked by the waiting main thread)."""
    due = _STATE.get("resume_gc_at")
    if due is not None and time.monotonic() >= due:
        _STATE["resume_gc_at"] = None
        gc.enable()


def as_program(work: Callable[[], Any]) -> Any:
    """Run `work` as the short-lived program does: the cyclic garbage collector paused for the first ``GC_PAUSE_S``
    seconds and every object frozen on the way out.

    The program's objects are nearly all long-lived modules (Numba's ~800): the collector's passes over the growing
    module graph cost ~0.1 s of the README render, and ``gc.freeze`` before exit spares interpreter shutdown the
    traversal and tear-down of that graph object by object (~0.3 s). A command still running after the pause
    collects garbage as usual (``run_interruptible`` resumes it). Called from Python, the commands leave the
    collector alone (this function is not used then).
    """
    gc.disable()
    _STATE["resume_gc_at"] = time.monotonic() + GC_PAUSE_S
    try:
        return work()
    finally:
        gc.freeze()


def run_program(work: Callable[[], Any]) -> NoReturn:
    """Run `work` as the program (``as_program``) and end the process with its exit status (``end_program``): the
    value it returns when an int, else 0, or the code of the ``SystemExit`` it raises."""
    try:
        status = as_program(work)
    except SystemExit as exit:
        end_program(exit.code)
    end_program(status if isinstance(status, int) else 0)


def end_program(code: int | str | None) -> NoReturn:
    """End the program now with ``SystemExit``'s `code` (None: 0; a text: printed on stderr, status 1) as Python
    ends, in its order: other threads' work waited for, exit handlers run (``atexit``: a background compiler child
    is stopped, coverage saved), standard streams flushed; then ``os._exit``, without Python's tear-down of its
    modules one by one (Numba's ~800 with NumPy's: about 0.03 s of CPU of a warm render even with every object
    frozen). Only for the program's own process (``main`` with no arguments): called from Python the commands
    return or raise as usual."""
    import atexit

    if isinstance(code, str):
        say(code, sys.stderr)
        code = 1
    shutdown = getattr(threading, "_shutdown", None)  # what Python does first at its end: thread pools told to end,
    if shutdown is not None:  # work still running on other (not daemon) threads waited for
        shutdown()
    atexit._run_exitfuncs()
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(OSError, ValueError):  # a closed pipe (``| head``): nothing more can be said there
            stream.flush()
    os._exit(int(code or 0) & 0xFF)


def run_interruptible(work: Callable[[], Any]) -> Any:
    """Run `work` on a worker thread while the main thread waits in short timeouts, so Ctrl-C is honoured at once.

    Python delivers SIGINT to the main thread only; a Numba kernel (nogil) or an import that catches
    ``BaseException`` (trimesh's optional imports) on the worker cannot swallow or delay it. On Ctrl-C the
    output files still being written (temporaries, ``frustum._files``) are removed, one line is printed and
    the process exits with status 130 at once, abandoning the worker.
    """
    outcome: dict[str, Any] = {}

    def target() -> None:
        try:
            outcome["value"] = work()
        except BaseException as error:  # handed to the main thread, which re-raises it
            outcome["error"] = error

    worker = threading.Thread(target=target, name="frustum-work", daemon=True)
    try:
        worker.start()
        while worker.is_alive():
            worker.join(0.1)
            _resume_gc_when_due()
    except KeyboardInterrupt:
        from frustum._files import remove_partial_files

        remove_partial_files()
        say(f"error: {INTERRUPTED_MESSAGE}", sys.stderr)
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(INTERRUPTED_STATUS)
    if "error" in outcome:
        raise outcome["error"]
    return outcome.get("value")


COMPILE_NOTICE = "compiling render kernels, first run only (`frustum warmup` does it ahead of time) ..."
"""The program's line on stderr once the kernels have been compiling for a second (a first run in a new
environment)."""


def _compile_notice() -> None:
    say(COMPILE_NOTICE, sys.stderr)


def install_compile_notice() -> None:
    """Make the kernels tell the program's compile notice (``frustum.raster.compile_notice``) instead of the
    library's."""
    import frustum.raster

    frustum.raster.compile_notice = _compile_notice


def exit_with_parent(parent: int) -> None:
    """In a worker process of a command (``--jobs``, ``frustum warmup``): end it, its partial files removed, as soon
    as `parent`, the command's process, is gone. A pool's worker of a killed command would otherwise wait on its
    task queue for ever (it holds a writing end of that queue itself, so it never reads the end of it)."""
    threading.Thread(target=_watch_parent, args=(parent,), name="frustum-parent-watch", daemon=True).start()


def _watch_parent(parent: int) -> None:
    from frustum._files import remove_partial_files

    while os.getppid() == parent:
        time.sleep(0.25)
    remove_partial_files()
    os._exit(1)
