"""Deferred shading kernel: one pass over the visible pixels after the depth buffer is complete.

Each pixel holds ``code = 2·face + back`` (−1: background) and the perspective-correct weights (u1, u2) of
the surface point with respect to its face's corners (u0 = 1 − u1 − u2). ``SHADE_NONE`` writes the flat
material color; ``SHADE_PHONG`` evaluates Blinn-Phong (``frustum.shading``) with the world-space point P and
the normalized interpolated normal N (flipped for back faces drawn two-sided):

    ndl = max(N·L, 0);  spec = ndl > 0 ? max(N·H, 0)^shininess : 0
    rgb = clamp(color·(ambient + diffuse·ndl) + specular·spec, 0, 1);  byte = floor(rgb·255 + 0.5)
"""

from __future__ import annotations

import math

import numpy as np

from frustum.raster._jit import kernel, parallel_kernel, prange

__all__ = ["SHADE_NONE", "SHADE_PHONG", "shade_pixels"]

SHADE_NONE = 0
"""Flat material color, no lighting (depth-only rendering)."""
SHADE_PHONG = 1
"""Per-pixel Blinn-Phong with one directional light."""


@kernel
def _to_byte(value: float) -> np.uint8:
    """``floor(clamp(v, 0, 1)·255 + 0.5)``: round half up to 8 bits."""
    return np.uint8(math.floor(min(max(value, 0.0), 1.0) * 255.0 + 0.5))


@kernel
def _interpolate(u0: float, u1: float, u2: float, va: float, vb: float, vc: float) -> float:
    """``(u0·va + u1·vb) + u2·vc`` (scalar arguments only: per-pixel helpers take no arrays, so they inline)."""
    return (u0 * va + u1 * vb) + u2 * vc


@kernel
def _phong(
    lx: float, ly: float, lz: float, ex: float, ey: float, ez: float, shininess: float,
    px: float, py: float, pz: float, nx: float, ny: float, nz: float,
) -> tuple[float, float]:  # fmt: skip
    """Blinn-Phong terms ``(ndl, spec)`` shared by the three channels: L, eye, shininess, point P, unit normal N.

    Channel k is then ``color_k·(ambient + diffuse·ndl) + specular·spec``.
    """
    vx, vy, vz = ex - px, ey - py, ez - pz
    length = math.sqrt((vx * vx + vy * vy) + vz * vz)
    vx, vy, vz = vx / length, vy / length, vz / length
    hx, hy, hz = lx + vx, ly + vy, lz + vz
    length = math.sqrt((hx * hx + hy * hy) + hz * hz)
    hx, hy, hz = hx / length, hy / length, hz / length
    ndl = max((nx * lx + ny * ly) + nz * lz, 0.0)
    spec = 0.0
    if ndl > 0.0:
        spec = max((nx * hx + ny * hy) + nz * hz, 0.0) ** shininess
    return ndl, spec


@parallel_kernel
def shade_pixels(
    codes: np.ndarray, bary: np.ndarray, faces: np.ndarray, world: np.ndarray, normals: np.ndarray,
    params: np.ndarray, item: np.ndarray, color: np.ndarray,
) -> None:  # fmt: skip
    """Shade the pixels of one scene item: those whose face ``code // 2 − face_offset`` lies in [0, M).

    codes (H, W) int32 or int64, bary (H, W, 2) float32, faces (M, 3) int64, world and normals (N, 3) float64
    (unit normals), params (13,) float64 = (L, eye, color, ambient, diffuse, specular, shininess), item =
    (face_offset, mode, paint, r, g, b, a) int64; color (H, W, 4) uint8 is written at those pixels (RGB, alpha
    255) and, when paint != 0, at the background pixels (code < 0) with the bytes (r, g, b, a).
    """
    for row in prange(codes.shape[0]):
        _shade_row(row, codes, bary, faces, world, normals, params, item, color)


@kernel
def _shade_row(
    row: int, codes: np.ndarray, bary: np.ndarray, faces: np.ndarray, world: np.ndarray, normals: np.ndarray,
    params: np.ndarray, item: np.ndarray, color: np.ndarray,
) -> None:  # fmt: skip
    """One image row of ``shade_pixels``."""
    face_offset, mode, paint = item[0], item[1], item[2]
    lx, ly, lz, ex, ey, ez = params[0], params[1], params[2], params[3], params[4], params[5]
    ambient, diffuse, specular, shininess = params[9], params[10], params[11], params[12]
    for col in range(codes.shape[1]):
        code = codes[row, col]
        if code < 0 and paint != 0:
            for k in range(4):
                color[row, col, k] = item[3 + k]
            continue
        f = code // 2 - face_offset
        if code < 0 or f < 0 or f >= faces.shape[0]:
            continue
        color[row, col, 3] = 255
        if mode == SHADE_NONE:
            for k in range(3):
                color[row, col, k] = _to_byte(params[6 + k])
            continue
        a, b, c = faces[f, 0], faces[f, 1], faces[f, 2]
        u1, u2 = float(bary[row, col, 0]), float(bary[row, col, 1])
        u0 = (1.0 - u1) - u2
        px = _interpolate(u0, u1, u2, world[a, 0], world[b, 0], world[c, 0])
        py = _interpolate(u0, u1, u2, world[a, 1], world[b, 1], world[c, 1])
        pz = _interpolate(u0, u1, u2, world[a, 2], world[b, 2], world[c, 2])
        nx = _interpolate(u0, u1, u2, normals[a, 0], normals[b, 0], normals[c, 0])
        ny = _interpolate(u0, u1, u2, normals[a, 1], normals[b, 1], normals[c, 1])
        nz = _interpolate(u0, u1, u2, normals[a, 2], normals[b, 2], normals[c, 2])
        length = math.sqrt((nx * nx + ny * ny) + nz * nz)
        sign = -1.0 if code % 2 == 1 else 1.0  # two-sided lighting: a back face's normal faces the viewer
        nx, ny, nz = sign * nx / length, sign * ny / length, sign * nz / length
        ndl, spec = _phong(lx, ly, lz, ex, ey, ez, shininess, px, py, pz, nx, ny, nz)
        for k in range(3):
            color[row, col, k] = _to_byte(params[6 + k] * (ambient + diffuse * ndl) + specular * spec)
