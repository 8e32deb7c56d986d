"""The ``frustum`` program's entry point, and what it shares with the Typer command line (``frustum.cli``).

``main`` runs the most common command, ``frustum render FILE -o OUT`` (with ``--size``, ``--up``, ``--shadows``),
straight away: building the Typer application with its fourteen commands and coercing their parameters (Typer
imports Pydantic for that) took about 0.3 s of a 1.2 s warm one-command render, more than the render itself. The
same function (``render_files``) does the work, with the same checks, messages, exit statuses, Ctrl-C handling
and garbage-collector pause. Any other command line (another command, ``--help``, global options, an option this
module does not know, a value that looks like an option) goes to ``frustum.cli.main`` unchanged.
"""

from __future__ import annotations

import gc
import os
import sys
import threading
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from frustum.errors import FrustumError

__all__ = ["main"]


class UsageError(FrustumError):
    """A command-line argument that frustum cannot read (exit status 2)."""


_STATE: dict[str, Any] = {"debug": False, "resume_gc_at": None}

GC_PAUSE_S = 3.0
"""Seconds the ``frustum`` program runs with Python's cyclic garbage collector paused (``main``)."""

INTERRUPTED_STATUS = 130
"""Exit status after Ctrl-C (128 + SIGINT), as shells report it."""

MAX_SIZE = 8192
"""Largest --size width or height (the scene files' ``[render] size`` limit)."""


def _say(text: str, stream: Any = None) -> None:
    """One line on stdout (or `stream`), as the Rich consoles of ``frustum.cli`` print it (no markup, no
    highlighting, no wrapping)."""
    target = sys.stdout if stream is None else stream
    target.write(text + "\n")


def _fail(message: str, status: int) -> None:
    from frustum._arrays import escape_control

    _say(f"error: {escape_control(message, keep_newlines=True)}", sys.stderr)
    raise SystemExit(status)


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


REPORTED = (RecursionError, FrustumError, OSError, ValueError, TypeError, RuntimeError, MemoryError)
"""The exceptions the program reports in one line (``failure``) instead of a traceback (without --debug)."""


def _resume_gc_when_due() -> None:
    """Re-enable the garbage collector once the program has run ``GC_PAUSE_S`` (checked by the waiting main thread)."""
    due = _STATE.get("resume_gc_at")
    if due is not None and time.monotonic() >= due:
        _STATE["resume_gc_at"] = None
        gc.enable()


def _run_interruptible(work: Callable[[], Any]) -> Any:
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
        _say("error: interrupted (Ctrl-C); no output file was written or changed", sys.stderr)
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(INTERRUPTED_STATUS)
    if "error" in outcome:
        raise outcome["error"]
    return outcome.get("value")


def _compile_notice() -> None:
    """Told by the kernels once they have been compiling for a second (a first run in a new environment)."""
    _say("compiling render kernels, first run only (`frustum warmup` does it ahead of time) ...", sys.stderr)


def image_size(text: str) -> tuple[int, int]:
    """``WxH`` (e.g. 640x480) as two positive integers, or a UsageError."""
    width, sep, height = text.lower().partition("x")
    try:
        size = (int(width), int(height)) if sep else None
    except ValueError:
        size = None
    if size is None or min(size) <= 0:
        raise UsageError(f"--size = {text!r} is not WIDTHxHEIGHT; write two positive integers, e.g. 640x480")
    if max(size) > MAX_SIZE:
        raise UsageError(
            f"--size = {text!r} is over the limit of {MAX_SIZE} pixels a side; give width and height in [1, {MAX_SIZE}]"
        )
    return size


def render_files(scene: Path, output: Sequence[Path] | None, size: str | None, up: str,
                 shadows: str | None) -> list[Path]:  # fmt: skip
    """``frustum render``: render the scene or mesh file `scene` to `output` (None: the file's outputs) and
    return the files written."""
    from frustum.scenefile import render_scene_file
    from frustum.warmup import compile_in_background

    compile_in_background()  # a cold cache: a second process compiles part of the kernels meanwhile

    choices = {None: None, "on": True, "off": False, "ray": "ray"}
    if shadows not in choices:
        raise FrustumError(f"render: --shadows {shadows!r} is unknown; expected on, off or ray")
    written = render_scene_file(scene, list(output) if output else None, size=image_size(size) if size else None,
                                shadows=choices[shadows], up=up)  # fmt: skip
    return written if isinstance(written, list) else [written]


_RENDER_OPTIONS = {"-o": "output", "--output": "output", "--size": "size", "--up": "up", "--shadows": "shadows"}


def plain_render(argv: Sequence[str]) -> dict[str, Any] | None:
    """The arguments of a ``render`` command line in the plain form ``main`` runs itself, or None.

    Plain: ``render``, one file, and only ``-o/--output`` (repeatable), ``--size``, ``--up`` and ``--shadows``
    (each at most once), as ``--name value`` or ``--name=value``, no value starting with "-"."""
    if not argv or argv[0] != "render":
        return None
    found: dict[str, Any] = {"output": [], "size": None, "up": None, "shadows": None, "scene": None}
    words = list(argv[1:])
    while words:
        word = words.pop(0)
        if not word:
            return None
        if not word.startswith("-"):
            if found["scene"] is not None:
                return None
            found["scene"] = word
            continue
        name, equals, value = word.partition("=")
        if name not in _RENDER_OPTIONS or (equals and name == "-o"):
            return None
        if not equals:
            if not words:
                return None
            value = words.pop(0)
        if not value or value.startswith("-"):
            return None
        key = _RENDER_OPTIONS[name]
        if key == "output":
            found["output"].append(Path(value))
        elif found[key] is not None:
            return None
        else:
            found[key] = value
    if found["scene"] is None:
        return None
    return found


def main(arguments: Sequence[str] | None = None) -> None:
    """Entry point of the ``frustum`` console script and ``python -m frustum``: a plain ``render`` command line
    (``plain_render``) runs here; every other one runs through ``frustum.cli.main`` (Typer).

    As the program (`arguments` None) a plain render goes to the resident render process when one answers
    (``frustum.resident``: the same work without the start-up); otherwise it runs here, with the cyclic garbage
    collector paused for ``GC_PAUSE_S`` seconds and every object frozen on the way out (see ``frustum.cli.main``),
    and leaves a resident process behind for the next command."""
    argv = list(sys.argv[1:] if arguments is None else arguments)
    request = plain_render(argv)
    if request is None:
        from frustum.cli import main as typer_main

        typer_main(arguments)
        return
    if arguments is not None:
        _render(request)
        return
    from frustum import resident

    status = resident.handed(request)
    if status is not None:
        raise SystemExit(status)
    gc.disable()
    _STATE["resume_gc_at"] = time.monotonic() + GC_PAUSE_S
    try:
        _render(request)
    finally:
        gc.freeze()
        resident.start()  # for the next command (``frustum.resident``); nothing when one runs or it is off


def _render(request: dict[str, Any]) -> None:
    import frustum.raster

    frustum.raster.compile_notice = _compile_notice
    try:
        written = _run_interruptible(lambda: render_files(Path(request["scene"]), request["output"] or None,
                                                          request["size"], request["up"] or "y",
                                                          request["shadows"]))  # fmt: skip
    except REPORTED as error:
        _fail(*failure(error))
    for path in written:
        _say(f"wrote {path}")
