"""The work of ``frustum render``, the same wherever it runs: the program's own plain-render path
(``frustum.app._program``), Typer's ``render`` command (``frustum.app.cli``) and the resident render process
(``frustum.app.resident``)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

from frustum.app.runtime import REPORTED, UsageError, install_compile_notice, report_failure, run_interruptible, say
from frustum.errors import FrustumError

__all__ = ["MAX_SIZE", "image_size", "render_files", "render_task", "run_render", "shadow_choice"]

MAX_SIZE = 8192
"""Largest --size width or height (the scene files' ``[render] size`` limit)."""


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


def shadow_choice(shadows: str | None) -> bool | str | None:
    """``--shadows`` on, off or ray as ``render_scene_file``'s `shadows` (None: the file's)."""
    choices = {None: None, "on": True, "off": False, "ray": "ray"}
    if shadows not in choices:
        raise FrustumError(f"render: --shadows {shadows!r} is unknown; expected on, off or ray")
    return choices[shadows]


def render_task(scene: Path, output: list[Path] | None, options: dict[str, Any]) -> list[str]:
    """One input of ``frustum render`` with several (``frustum.app.many``): its ``wrote PATH`` lines."""
    return [f"wrote {path}" for path in render_files(scene, output, options["size"], options["up"],
                                                     options["shadows"])]  # fmt: skip


def render_files(scene: Path, output: Sequence[Path] | None, size: str | None, up: str,
                 shadows: str | None) -> list[Path]:  # fmt: skip
    """``frustum render``: render the scene or mesh file `scene` to `output` (None: the file's outputs) and
    return the files written."""
    from frustum.app.numba_start import load_kernels_lean

    load_kernels_lean()  # first: Numba imported and set to load kernels the program's way (``numba_start``)
    from frustum.app.warmup import compile_in_background
    from frustum.scenefile import render_scene_file

    compile_in_background()  # a cold cache: a second process compiles part of the kernels meanwhile

    written = render_scene_file(scene, list(output) if output else None, size=image_size(size) if size else None,
                                shadows=shadow_choice(shadows), up=up)  # fmt: skip
    return written if isinstance(written, list) else [written]


def run_render(request: dict[str, Any]) -> int:
    """Run a plain render `request` (``frustum.app._program.plain_render``) as the program does: ``wrote PATH``
    lines on stdout, a failure as one ``error:`` line on stderr; the exit status."""
    from frustum.app import timing

    install_compile_notice()

    def work() -> list[Path]:
        return render_files(Path(request["scene"]), request["output"] or None, request["size"], request["up"] or "y",
                            request["shadows"])  # fmt: skip

    profile = timing.Profile() if timing.enabled() else None
    try:
        written = run_interruptible(work if profile is None else lambda: timing.profiled(work, profile))
    except REPORTED as error:
        return report_failure(error)
    for path in written:
        say(f"wrote {path}")
    return 0
