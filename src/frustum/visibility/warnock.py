"""Area-subdivision (Warnock) visible-surface method: recursive quartering down to a pixel.

Image space, by areas [HB 16 "Area-Subdivision Method"]: each area is tested against the surfaces left by its
parent — each one *surrounding*, *overlapping*, *inside* or *outside* it — and finished when no surface is left,
when a surrounding surface is nearer than every other one over the whole area ("the surrounding surface hides
all others"), when a single surface is left, or when the area is a pixel; otherwise it is cut into four.
Kernel: ``raster.warnock`` (an explicit stack of areas).

References
----------
[HB 16] "Area-Subdivision Method"; [seed] "Area-subdivision method", "area coherence".
"""

from __future__ import annotations

import contextlib
import contextvars

import numpy as np

from frustum.budgets import check_memory
from frustum.errors import GeometryError
from frustum.visibility.recording import recording_into
from frustum.visibility.window import WindowTriangles

__all__ = ["area_subdivision", "recording"]

_RECORDING: contextvars.ContextVar[list[np.ndarray] | None] = contextvars.ContextVar("warnock_log", default=None)


def recording() -> contextlib.AbstractContextManager[list[np.ndarray]]:
    """Recording mode (``frustum.steps``): every ``area_subdivision`` run inside the block appends its area log,
    an (A, 9) int64 array (``raster.warnock.LOG_COLUMNS``: one row per area visited, in order), to the list."""
    return recording_into(_RECORDING)


def area_subdivision(triangles: WindowTriangles, depth: np.ndarray, codes: np.ndarray, bary: np.ndarray) -> dict:
    """Write the visible surface of every pixel (depth, code, barycentrics) by Warnock's area subdivision.

    Parameters and buffers as ``scanline.scan_line``.

    Returns
    -------
    dict
        ``areas_per_level`` (list: areas visited at each level, the whole image at level 0), ``areas``, the exits
        ``exit_empty``, ``exit_surrounding``, ``exit_single``, ``exit_pixel``, the relations met ``outside``,
        ``surrounding``, ``inside``, ``overlapping``, ``depth_tests``, ``triangles``.
    """
    from frustum.raster import warnock

    height, width = depth.shape
    levels = 2 * max(1, int(np.ceil(np.log2(max(width, height, 2))))) + 2
    entries = triangles.count * (levels + 2) + 1
    itemsize = 4 if entries < 2**31 else 8
    check_memory(
        entries * itemsize, where="render", cause=f"area subdivision lists of {triangles.count} triangles",
        error=GeometryError,
    )  # fmt: skip
    lists = np.empty(entries, dtype=np.int32 if itemsize == 4 else np.int64)
    stats = np.zeros(warnock.LEVELS + len(warnock.STATS), dtype=np.int64)
    logs = _RECORDING.get()
    # an area of two pixels or more has at least two non-empty quarters, so at most 2·W·H areas are visited
    log = np.full((2 * width * height + 1 if logs is not None else 0, 9), -1, dtype=np.int64)
    warnock.subdivide(
        triangles.xy, triangles.zq, triangles.weights, triangles.code, triangles.box, lists, depth, codes, bary, stats,
        log,
    )  # fmt: skip
    if logs is not None:
        logs.append(log[: int(stats[: warnock.LEVELS].sum())])
    per_level = stats[: warnock.LEVELS]
    used = int(np.flatnonzero(per_level).max(initial=-1)) + 1
    result: dict = {"areas_per_level": [int(n) for n in per_level[:used]], "areas": int(per_level.sum())}
    result.update({name: int(v) for name, v in zip(warnock.STATS, stats[warnock.LEVELS :], strict=True)})
    result["triangles"] = triangles.count
    return result
