"""Scan-line visible-surface method: edge table, active list sorted by x, span coherence.

Image space, one scan line at a time [HB 16 "Scan-Line Method"]: the edge table lists the triangles by their
first row; the active list holds those crossing the current row, sorted by the x of their spans (insertion sort,
which exploits scan-line coherence: the order hardly changes from one row to the next); walking the row through
the span boundaries gives runs of pixels in which the same surfaces are "in". A run with one surface is filled
without a depth test; with several, the planes' depths at the run's two ends decide (depth coherence: a plane is
affine along the run) unless surfaces cut through each other inside it, where the nearest is found pixel by
pixel. Kernel: ``raster.scanline``.

References
----------
[HB 16] "Scan-Line Method"; [seed] "Scan-line method", "coherence".
"""

from __future__ import annotations

import contextlib
import contextvars

import numpy as np

from frustum.visibility.recording import recording_into
from frustum.visibility.window import WindowTriangles

__all__ = ["recording", "scan_line"]

_RECORDING: contextvars.ContextVar[list[dict] | None] = contextvars.ContextVar("scan_line_log", default=None)


def recording() -> contextlib.AbstractContextManager[list[dict]]:
    """Recording mode (``frustum.steps``): every ``scan_line`` run inside the block appends a dict to the list:
    ``order``, ``bucket`` (the edge table), ``active`` (H, capacity, 3) and ``spans`` (H, 2·capacity + 1, 4)
    (``raster.scanline``'s logs, −1 where unused), ``box`` (T, 4) and ``code`` (T,) of the triangles."""
    return recording_into(_RECORDING)


def scan_line(triangles: WindowTriangles, depth: np.ndarray, codes: np.ndarray, bary: np.ndarray) -> dict:
    """Write the visible surface of every pixel (depth, code, barycentrics) by the scan-line method.

    Parameters
    ----------
    triangles : WindowTriangles
    depth : (H, W) float32
        Cleared to 1.0 (far); written where a surface is visible.
    codes : (H, W) int32 or int64
    bary : (H, W, 2) float32

    Returns
    -------
    dict
        ``spans`` (runs of pixels filled), ``edge_updates`` (edge crossings stepped to the next row),
        ``depth_tests``, ``split_spans`` (runs resolved pixel by pixel), ``active_max`` (most triangles on one
        row), ``triangles``.
    """
    from frustum.raster import scanline

    height = depth.shape[0]
    box = triangles.box
    order = np.argsort(box[:, 2], kind="stable").astype(np.int64)
    first = box[order, 2]
    bucket = np.searchsorted(first, np.arange(height + 1), side="left").astype(np.int64)
    rows = np.zeros(height + 1, dtype=np.int64)
    np.add.at(rows, box[:, 2], 1)
    np.add.at(rows, box[:, 3] + 1, -1)
    capacity = int(max(1, np.cumsum(rows).max(initial=0)))
    stats = np.zeros((height, len(scanline.STATS)), dtype=np.int64)
    logs = _RECORDING.get()
    rows = height if logs is not None else 0
    active_log = np.full((rows, capacity, 3), -1, dtype=np.int64)
    span_log = np.full((rows, 2 * capacity + 1, 4), -1, dtype=np.int64)
    scanline.scan_lines(
        triangles.xy, triangles.zq, triangles.weights, triangles.code, box, order, bucket, capacity, depth, codes,
        bary, stats, active_log, span_log,
    )  # fmt: skip
    if logs is not None:
        logs.append({"order": order, "bucket": bucket, "active": active_log, "spans": span_log, "box": box.copy(),
                     "code": triangles.code.copy()})  # fmt: skip
    totals = stats.sum(axis=0)
    result = {name: int(value) for name, value in zip(scanline.STATS, totals, strict=True)}
    result["active_max"] = capacity if triangles.count else 0
    result["triangles"] = triangles.count
    return result
