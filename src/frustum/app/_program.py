"""The ``frustum`` program's entry point, and what it shares with the Typer command line (``frustum.app.cli``).

``main`` runs the most common command, ``frustum render FILE -o OUT`` (with ``--size``, ``--up``, ``--shadows``),
and its many-files form (several inputs, folders, glob patterns, output patterns, ``--jobs``) straight away:
building the Typer application with its fourteen commands and coercing their parameters (Typer imports Pydantic
for that) took about 0.3 s of a 1.2 s warm one-command render, more than the render itself. The same functions
(``render_files``, ``frustum.app.many.render_inputs``) do the work, with the same checks, messages, exit statuses,
Ctrl-C handling and garbage-collector pause. Any other command line (another command, ``--help``, global options,
an option this module does not know, a value that looks like an option) goes to ``frustum.app.cli.main``
unchanged.
"""

from __future__ import annotations

import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from frustum.app.runtime import (
    REPORTED,
    as_program,
    end_program,
    install_compile_notice,
    report_failure,
    run_interruptible,
    run_program,
)

__all__ = ["main", "plain_render", "render_words"]


_RENDER_OPTIONS = {"-o": "output", "--output": "output", "--size": "size", "--up": "up", "--shadows": "shadows",
                   "--jobs": "jobs", "-j": "jobs"}  # fmt: skip


def render_words(argv: Sequence[str]) -> dict[str, Any] | None:
    """The arguments of a ``render`` command line that ``main`` runs itself, or None (Typer runs it).

    Taken: ``render``, input words (files, folders, glob patterns), and only ``-o/--output`` (repeatable, output
    patterns allowed), ``--size``, ``--up``, ``--shadows`` and ``--jobs/-j`` (each at most once; ``--jobs`` digits),
    as ``--name value`` or ``--name=value``, no value starting with "-"."""
    if not argv or argv[0] != "render":
        return None
    found: dict[str, Any] = {"output": [], "size": None, "up": None, "shadows": None, "jobs": None, "scenes": []}
    words = list(argv[1:])
    while words:
        word = words.pop(0)
        if not word:
            return None
        if not word.startswith("-"):
            found["scenes"].append(word)
            continue
        name, equals, value = word.partition("=")
        if name not in _RENDER_OPTIONS or (equals and name in ("-o", "-j")):
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
        elif found[key] is not None or (key == "jobs" and not (value.isascii() and value.isdigit())):
            return None  # a repeated option, or a --jobs Typer would refuse in its own words
        else:
            found[key] = value
    return found if found["scenes"] else None


def plain_render(argv: Sequence[str]) -> dict[str, Any] | None:
    """The arguments of a ``render`` command line in the plain form (one input) ``main`` runs itself, or None.

    Plain: a command line ``render_words`` takes with one file (not a folder or a glob pattern), no output
    pattern (``{field}``) and no ``--jobs``: the form a resident render process may be handed."""
    found = render_words(argv)
    if found is None or len(found["scenes"]) != 1 or found["jobs"] is not None:
        return None
    scene = found["scenes"][0]
    if Path(scene).is_dir() or (set(scene) & set("*?[") and not Path(scene).exists()):
        return None  # a folder or a pattern: several inputs (``frustum.app.many``)
    if any("{" in str(path) for path in found["output"]):
        return None  # an output pattern
    return {"output": found["output"], "size": found["size"], "up": found["up"], "shadows": found["shadows"],
            "scene": scene}  # fmt: skip


def _render_inputs(found: dict[str, Any]) -> int:
    """A ``render`` command line of several inputs (``render_words``) as Typer's ``render`` runs it: the exit
    status, a failure before any work as one error line."""
    from frustum.app.many import render_inputs

    install_compile_notice()
    try:
        return run_interruptible(lambda: render_inputs(
            [Path(scene) for scene in found["scenes"]], found["output"] or None, found["size"], found["up"] or "y",
            found["shadows"], int(found["jobs"] or 1)))  # fmt: skip
    except REPORTED as error:
        return report_failure(error)


def main(arguments: Sequence[str] | None = None) -> None:
    """Entry point of the ``frustum`` console script and ``python -m frustum``: a ``render`` command line of the
    options ``render_words`` knows runs here (one input: ``plain_render``; several: ``frustum.app.many``, as Typer's
    ``render`` runs them, without building the Typer application); every other one runs through
    ``frustum.app.cli.main`` (Typer).

    As the program (`arguments` None) a plain render goes to the resident render process when one was started on
    purpose and takes it (``frustum.app.resident``: the same work without the start-up); otherwise it runs here as
    a short-lived program (``runtime.as_program``). Only with ``FRUSTUM_RESIDENT=1`` and only after a successful
    render does it start a resident process for the next command (and says so); by default nothing is left
    behind. As the program it ends with ``runtime.end_program`` (no tear-down of the modules)."""
    from frustum.app.work import run_render

    argv = list(sys.argv[1:] if arguments is None else arguments)
    request = plain_render(argv)
    if request is None:
        found = render_words(argv)
        if found is None:
            from frustum.app.cli import main as typer_main

            typer_main(arguments)
            return
        if arguments is None:
            run_program(lambda: _render_inputs(found))
        status = _render_inputs(found)
    elif arguments is not None:
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
