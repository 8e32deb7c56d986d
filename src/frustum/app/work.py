"""The work of ``frustum render``, the same wherever it runs: the program's own plain-render path
(``frustum.app._program``), Typer's ``render`` command (``frustum.app.cli``) and the resident render process
(``frustum.app.resident``)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from frustum.app.runtime import UsageError
from frustum.errors import FrustumError

__all__ = ["MAX_SIZE", "image_size", "render_files"]

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


def render_files(scene: Path, output: Sequence[Path] | None, size: str | None, up: str,
                 shadows: str | None) -> list[Path]:  # fmt: skip
    """``frustum render``: render the scene or mesh file `scene` to `output` (None: the file's outputs) and
    return the files written."""
    from frustum.app.warmup import compile_in_background
    from frustum.scenefile import render_scene_file

    compile_in_background()  # a cold cache: a second process compiles part of the kernels meanwhile

    choices = {None: None, "on": True, "off": False, "ray": "ray"}
    if shadows not in choices:
        raise FrustumError(f"render: --shadows {shadows!r} is unknown; expected on, off or ray")
    written = render_scene_file(scene, list(output) if output else None, size=image_size(size) if size else None,
                                shadows=choices[shadows], up=up)  # fmt: skip
    return written if isinstance(written, list) else [written]
