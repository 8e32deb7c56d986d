"""OpenGL (moderngl, EGL) as the tests' oracle: a standalone context, and one draw read back as an image."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest


def gl_context() -> Any:
    """A standalone OpenGL 3.3 context (EGL), or the test is skipped where the machine has none."""
    moderngl = pytest.importorskip("moderngl")
    try:
        return moderngl.create_standalone_context(require=330, backend="egl")
    except Exception as error:  # no EGL / Mesa on this machine
        pytest.skip(f"no OpenGL 3.3 context: {error}")


def draw_and_read(ctx: Any, vao: Any, primitive: int, flags: int, width: int, height: int) -> np.ndarray:
    """(height, width, 4) uint8 RGBA of `vao` drawn as `primitive` with `flags` enabled, into a new framebuffer
    cleared to opaque black with depth 1, top row first; releases `ctx`."""
    fbo = ctx.framebuffer(color_attachments=[ctx.renderbuffer((width, height), 4, dtype="f1")],
                          depth_attachment=ctx.depth_renderbuffer((width, height)))  # fmt: skip
    fbo.use()
    ctx.enable(flags)
    fbo.clear(0.0, 0.0, 0.0, 1.0, depth=1.0)
    vao.render(primitive)
    pixels = np.frombuffer(fbo.read(components=4, dtype="f1"), dtype=np.uint8).reshape(height, width, 4)
    ctx.release()
    return pixels[::-1]  # OpenGL reads the bottom row first
