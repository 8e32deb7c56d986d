"""The A-buffer (Carpenter 1984): per pixel a list of fragments with 4×4 coverage masks, resolved front to back.

Each triangle leaves in every pixel it touches a fragment: which of the pixel's 16 subsamples it covers (the
depth buffer's top-left rule at each subsample) and the shading inputs at the centroid of those subsamples (the
renderer shades each fragment once, with the one illumination model). Resolving composites, per subsample, the
fragments covering it in order of their plane's depth there: $C = Σ_k T_k·α_k·c_k + T·under$ with
$T_k = Π_{m<k}(1 − α_m)$; the pixel is the mean of its subsamples.

What that buys: transparency that is exact whatever the order of the surfaces (two transparent surfaces that cut
through each other, or overlap cyclically, are composited right on each side of the cut), and anti-aliased
edges from 16 coverage samples with one shading per fragment instead of 16 (supersampling shades every
subsample and multiplies every buffer by 16). What it costs: memory per fragment (counted first, checked against
the work budget before anything is allocated) and a sort per subsample. The per-object sort (whole transparent
objects back to front by their centres) stays the default: it is right when transparent objects do not
interpenetrate and each is convex (or seen without self-overlap), and it needs no fragment memory.

References
----------
L. Carpenter, "The A-buffer, an antialiased hidden surface method", SIGGRAPH 1984; [HB 16] "A-Buffer Method";
[seed] "A-buffer".
"""

from __future__ import annotations

import contextlib
import contextvars
import dataclasses

import numpy as np

from frustum.budgets import check_memory
from frustum.errors import GeometryError
from frustum.visibility.recording import recording_into
from frustum.visibility.window import WindowTriangles

__all__ = ["FRAGMENT_BYTES", "Fragments", "build_fragments", "recording", "resolve_fragments"]

_RECORDING: contextvars.ContextVar[list[dict] | None] = contextvars.ContextVar("a_buffer_log", default=None)


def recording() -> contextlib.AbstractContextManager[list[dict]]:
    """Recording mode (``frustum.steps``): every ``resolve_fragments`` inside the block appends to the list the
    ``fragments`` it resolves and their ``premultiplied`` colors (the A-buffer's per-pixel lists as composited)."""
    return recording_into(_RECORDING)


FRAGMENT_BYTES = 8 + 2 + 4 + 8 + 8 + 4
"""Bytes per fragment: triangle, mask, and the shading column (depth, code, barycentrics, color)."""


@dataclasses.dataclass(frozen=True)
class Fragments:
    """N fragments, pixel by pixel (row-major, top row first): pixel p's are ``starts[p]:starts[p + 1]``.

    ``triangle`` (N,) int64 and ``mask`` (N,) uint16 (bit $4·b + a$ for subsample column a, row b from the
    bottom); the shading column image ``depth`` (N, 1) float32, ``code`` (N, 1) int64, ``bary`` (N, 1, 2) float32.
    """

    starts: np.ndarray
    triangle: np.ndarray
    mask: np.ndarray
    depth: np.ndarray
    code: np.ndarray
    bary: np.ndarray

    @property
    def count(self) -> int:
        return int(self.triangle.shape[0])


def build_fragments(triangles: WindowTriangles, where: str = "render") -> Fragments:
    """Count the fragments of every triangle, check the memory they need, write them and order them by pixel.

    Raises
    ------
    GeometryError
        If the fragments would exceed the work budget (``frustum.budgets``).
    """
    from frustum.raster import abuffer

    height, width = triangles.height, triangles.width
    size = np.array([width, height], dtype=np.int64)
    per_triangle = np.empty(triangles.count, dtype=np.int64)
    abuffer.count_fragments(triangles.xy, size, per_triangle)
    first = np.zeros(triangles.count + 1, dtype=np.int64)
    np.cumsum(per_triangle, out=first[1:])
    total = int(first[-1])
    check_memory(
        total * (2 * FRAGMENT_BYTES + 16) + 8 * (height * width + 1), where=where,
        cause=f"an A-buffer of {total} fragments ({total / max(1, height * width):.2f} per pixel) at {width}x{height}",
        error=GeometryError,
    )  # fmt: skip
    code_type = triangles.code_type
    pixel = np.empty(total, dtype=np.int64)
    columns = (
        np.empty(total, dtype=np.int64), np.empty(total, dtype=np.uint16), np.empty(total, dtype=np.float32),
        np.empty(total, dtype=code_type), np.empty((total, 2), dtype=np.float32),
    )  # fmt: skip
    abuffer.write_fragments(
        triangles.xy, triangles.zq, triangles.weights, triangles.code, size, first, pixel, *columns
    )  # fmt: skip
    starts = np.zeros(height * width + 1, dtype=np.int64)
    np.cumsum(np.bincount(pixel, minlength=height * width), out=starts[1:])
    order = np.empty(total, dtype=np.int64)
    abuffer.group_by_pixel(pixel, starts[:-1].copy(), order)
    del pixel
    triangle, mask, depth, code, bary = (np.take(column, order, axis=0) for column in columns)
    return Fragments(starts, triangle, mask, depth.reshape(-1, 1), code.reshape(-1, 1), bary.reshape(-1, 1, 2))


def resolve_fragments(
    fragments: Fragments, premultiplied: np.ndarray, triangles: WindowTriangles, under: np.ndarray,
    under_depth: np.ndarray, color: np.ndarray, depth: np.ndarray,
) -> dict:  # fmt: skip
    """Composite every pixel's fragments over `under` (module docstring) into `color`; the nearest opaque
    fragment's depth at each pixel centre into `depth` (a triangle that covers the centre but none of the 16
    subsamples makes no fragment, as it would not show in 16× supersampling either). premultiplied (N, 4) uint8:
    $α·c$ and $α$ per fragment (what the shading kernel writes blending over transparent black).

    Returns the counts ``fragments``, ``fragments_per_pixel`` (mean over pixels with any), ``max_fragments``
    (in one pixel), ``pixels_with_fragments``, ``sample_composites`` (fragment–subsample pairs blended).
    """
    from frustum.raster import abuffer

    height, width = color.shape[:2]
    logs = _RECORDING.get()
    if logs is not None:
        logs.append({"fragments": fragments, "premultiplied": premultiplied.copy()})
    stats = np.zeros((height * width, 2), dtype=np.int64)
    abuffer.resolve(
        fragments.starts, fragments.triangle, fragments.mask, premultiplied, triangles.xy, triangles.zq, under,
        under_depth, color, depth, stats,
    )  # fmt: skip
    per_pixel = stats[:, 0]
    covered = int(np.count_nonzero(per_pixel))
    return {
        "fragments": fragments.count,
        "fragments_per_pixel": round(fragments.count / covered, 4) if covered else 0.0,
        "max_fragments": int(per_pixel.max(initial=0)),
        "pixels_with_fragments": covered,
        "sample_composites": int(stats[:, 1].sum()),
    }
