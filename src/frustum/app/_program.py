"""The ``frustum`` program's entry point, and what it shares with the Typer command line (``frustum.app.cli``).

``main`` runs the most common command, ``frustum render FILE -o OUT`` (with ``--size``, ``--up``, ``--shadows``),
straight away: building the Typer application with its fourteen commands and coercing their parameters (Typer
imports Pydantic for that) took about 0.3 s of a 1.2 s warm one-command render, more than the render itself. The
same function (``render_files``) does the work, with the same checks, messages, exit statuses, Ctrl-C handling
and garbage-collector pause. Any other command line (another command, ``--help``, global options, an option this
module does not know, a value that looks like an option) goes to ``frustum.app.cli.main`` unchanged.
"""

from __future__ import annotations

import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from frustum.app.runtime import as_program, end_program

__all__ = ["main", "plain_render"]


_RENDER_OPTIONS = {"-o": "output", "--output": "output", "--size": "size", "--up": "up", "--shadows": "shadows"}


def plain_render(argv: Sequence[str]) -> dict[str, Any] | None:
    """The arguments of a ``render`` command line in the plain form ``main`` runs itself, or None.

    Plain: ``render``, one file (not a folder or a glob pattern), and only ``-o/--output`` (repeatable, no
    ``{field}`` of an output pattern), ``--size``, ``--up`` and ``--shadows`` (each at most once), as ``--name
    value`` or ``--name=value``, no value starting with "-"."""
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
    scene = found["scene"]
    if scene is None or Path(scene).is_dir() or (set(scene) & set("*?[") and not Path(scene).exists()):
        return None  # a folder or a pattern: several inputs (``frustum.app.many``)
    if any("{" in str(path) for path in found["output"]):
        return None  # an output pattern
    return found


def main(arguments: Sequence[str] | None = None) -> None:
    """Entry point of the ``frustum`` console script and ``python -m frustum``: a plain ``render`` command line
    (``plain_render``) runs here; every other one runs through ``frustum.app.cli.main`` (Typer).

    As the program (`arguments` None) a plain render goes to the resident render process when one was started on
    purpose and takes it (``frustum.app.resident``: the same work without the start-up); otherwise it runs here as
    a short-lived program (``runtime.as_program``). Only with ``FRUSTUM_RESIDENT=1`` and only after a successful
    render does it start a resident process for the next command (and says so); by default nothing is left
    behind. As the program it ends with ``runtime.end_program`` (no tear-down of the modules)."""
    from frustum.app.work import run_render

    argv = list(sys.argv[1:] if arguments is None else arguments)
    request = plain_render(argv)
    if request is None:
        from frustum.app.cli import main as typer_main

        typer_main(arguments)
        return
    if arguments is not None:
        status = run_render(request)
    else:
        from frustum.app import resident_identity

        status = None
        if resident_identity.maybe_running():  # the client (sockets, JSON) is imported only then
            from frustum.app import resident

            status = resident.handed(request)
        if status is None:
            status = as_program(lambda: run_render(request))
            if status == 0 and resident_identity.wanted():
                from frustum.app import resident

                resident.start()
        end_program(status)
    if status:
        raise SystemExit(status)
