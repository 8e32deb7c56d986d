"""Vertex stage kernels: model → clip coordinates and region codes, window coordinates, world positions and normals.

``transform_vertices`` is the whole vertex stage in one pass (the readable reference of the others; the line and
point paths do the same operations in NumPy, ``render.lines.clip_vertices``, and the tests check both against it). The
surface path splits it by what each later stage reads, so nothing is written that
is not read: ``project_vertices`` (clip coordinates straight to region codes and snapped window coordinates,
the clip coordinates themselves not stored), ``world_points`` and ``transform_normals`` (for shading, and skipped
when the modeling transform leaves them unchanged). Every kernel computes a vertex with the same operations in
the same order, so all paths agree bit for bit.

Contract (kernels never validate): vertices, normals (N, 3) float64; matrices (3, 4, 4) float64 holding
clip_from_model, world_from_model and, in its 3x3 block, the normal matrix (inverse transpose of
world_from_model's 3x3 block); planes (P, 4) float64 with P <= 63. Every row is independent, so the loops run
in parallel.
"""

from __future__ import annotations

import math

import numpy as np

from frustum.raster._jit import kernel, parallel_kernel
from frustum.raster.fixed_point import SUBPIXEL, snap

__all__ = [
    "clip_vertex",
    "project_vertices",
    "transform_normals",
    "transform_vertices",
    "view_volume_code",
    "world_points",
]


@kernel
def _affine_row(m: np.ndarray, k: int, x: float, y: float, z: float) -> float:
    """Row k of $M·[x, y, z, 1]$, summed left to right: $((m0·x + m1·y) + m2·z) + m3$."""
    return ((m[k, 0] * x + m[k, 1] * y) + m[k, 2] * z) + m[k, 3]


@kernel
def _linear_row(m: np.ndarray, k: int, x: float, y: float, z: float) -> float:
    """Row k of $A·[x, y, z]$ with A the 3x3 block of m: $(a0·x + a1·y) + a2·z$."""
    return (m[k, 0] * x + m[k, 1] * y) + m[k, 2] * z


@kernel
def clip_vertex(vertices: np.ndarray, i: int, m: np.ndarray, out: np.ndarray) -> None:
    """$out = clip_from_model·P_i$ (out (4,) float64): the clip coordinates ``transform_vertices`` writes."""
    x, y, z = vertices[i, 0], vertices[i, 1], vertices[i, 2]
    for k in range(4):
        out[k] = _affine_row(m, k, x, y, z)


@kernel
def _region_code(planes: np.ndarray, cx: float, cy: float, cz: float, cw: float) -> int:
    """Bit k set when the clip-space point is outside plane k ($planes[k]·clip < 0$)."""
    code = 0
    for k in range(planes.shape[0]):
        distance = ((planes[k, 0] * cx + planes[k, 1] * cy) + planes[k, 2] * cz) + planes[k, 3] * cw
        if distance < 0.0:
            code |= 1 << k
    return code


@kernel
def view_volume_code(cx: float, cy: float, cz: float, cw: float) -> int:
    """Region code against the six planes of ``clipping.VIEW_VOLUME_PLANES`` in their bit order: left $w + x < 0$,
    right $w − x < 0$, bottom, top (y), near, far (z). Bit for bit ``_region_code`` with those planes (its
    $((±1·x + 0·y) + 0·z) + 1·w$ is exactly ``w ± x``), without the loads and the loop."""
    code = 1 if cx + cw < 0.0 else 0
    code |= 2 if cw - cx < 0.0 else 0
    code |= 4 if cy + cw < 0.0 else 0
    code |= 8 if cw - cy < 0.0 else 0
    code |= 16 if cz + cw < 0.0 else 0
    code |= 32 if cw - cz < 0.0 else 0
    return code


@parallel_kernel(lambda vertices, *_: vertices.shape[0], grain=4096)
def project_vertices(
    vertices: np.ndarray, clip_from_model: np.ndarray, view: np.ndarray,
    win_int: np.ndarray, win_float: np.ndarray, codes: np.ndarray,
    start: int, stop: int,
) -> None:  # fmt: skip
    """View-volume region code of $clip = clip_from_model·P$; inside (code 0) also the window coordinates.

    view = (width/2, height/2). codes (N,) any integer type of 6 bits or more; win_int (N, 2) int32 or
    int64 receives the snapped $X = floor((x_c/w·W/2 + W/2)·256 + 0.5)$, Y alike; win_float (N, 2) float64 the
    window depth $z_w = (z_c/w)·0.5 + 0.5$ and ``1/w``, and where it has four columns the snap residuals
    $x_w·256 − X$, $y_w·256 − Y$ (``triangles.depth_plane``). Rows of vertices outside (code != 0) are left
    unwritten: their faces are clipped (from ``clip_vertex``) or rejected.
    """
    m = clip_from_model
    residuals = win_float.shape[1] >= 4
    for i in range(start, stop):
        x, y, z = vertices[i, 0], vertices[i, 1], vertices[i, 2]
        cx, cy = _affine_row(m, 0, x, y, z), _affine_row(m, 1, x, y, z)
        cz, cw = _affine_row(m, 2, x, y, z), _affine_row(m, 3, x, y, z)
        code = view_volume_code(cx, cy, cz, cw)
        codes[i] = code
        if code != 0:
            continue
        x_w, y_w = (cx / cw) * view[0] + view[0], (cy / cw) * view[1] + view[1]
        win_int[i, 0], win_int[i, 1] = snap(x_w), snap(y_w)
        win_float[i, 0] = (cz / cw) * 0.5 + 0.5
        win_float[i, 1] = 1.0 / cw
        if residuals:
            win_float[i, 2], win_float[i, 3] = x_w * SUBPIXEL - win_int[i, 0], y_w * SUBPIXEL - win_int[i, 1]


@parallel_kernel(lambda vertices, *_: vertices.shape[0], grain=4096)
def world_points(vertices: np.ndarray, world_from_model: np.ndarray, world: np.ndarray, start: int, stop: int) -> None:
    """$world = world_from_model·P$ per vertex (world (N, 3) float64, written)."""
    for i in range(start, stop):
        x, y, z = vertices[i, 0], vertices[i, 1], vertices[i, 2]
        for k in range(3):
            world[i, k] = _affine_row(world_from_model, k, x, y, z)


@parallel_kernel(lambda normals, *_: normals.shape[0], grain=4096)
def transform_normals(normals: np.ndarray, normal_matrix: np.ndarray, out: np.ndarray, start: int, stop: int) -> None:
    """$n' = N·n / |N·n|$ per vertex, N the 3x3 block of normal_matrix (out (N, 3) float64, written)."""
    for i in range(start, stop):
        nx = _linear_row(normal_matrix, 0, normals[i, 0], normals[i, 1], normals[i, 2])
        ny = _linear_row(normal_matrix, 1, normals[i, 0], normals[i, 1], normals[i, 2])
        nz = _linear_row(normal_matrix, 2, normals[i, 0], normals[i, 1], normals[i, 2])
        length = math.sqrt((nx * nx + ny * ny) + nz * nz)
        out[i, 0], out[i, 1], out[i, 2] = nx / length, ny / length, nz / length


@parallel_kernel(lambda vertices, *_: vertices.shape[0], grain=4096)
def transform_vertices(
    vertices: np.ndarray, normals: np.ndarray, matrices: np.ndarray, planes: np.ndarray,
    clip: np.ndarray, world: np.ndarray, world_normals: np.ndarray, codes: np.ndarray,
    start: int, stop: int,
) -> None:  # fmt: skip
    """$clip = clip_from_model·P$, $world = world_from_model·P$, $n' = normalize(N·n)$, region code of clip.

    Written: clip (N, 4), world (N, 3), world_normals (N, 3) float64, codes (N,) int64. The region code has bit k
    set when the clip-space point is outside plane k ($planes[k]·clip < 0$).
    """
    for i in range(start, stop):
        x, y, z = vertices[i, 0], vertices[i, 1], vertices[i, 2]
        for k in range(4):
            clip[i, k] = _affine_row(matrices[0], k, x, y, z)
        for k in range(3):
            world[i, k] = _affine_row(matrices[1], k, x, y, z)
        nx = _linear_row(matrices[2], 0, normals[i, 0], normals[i, 1], normals[i, 2])
        ny = _linear_row(matrices[2], 1, normals[i, 0], normals[i, 1], normals[i, 2])
        nz = _linear_row(matrices[2], 2, normals[i, 0], normals[i, 1], normals[i, 2])
        length = math.sqrt((nx * nx + ny * ny) + nz * nz)
        world_normals[i, 0], world_normals[i, 1], world_normals[i, 2] = nx / length, ny / length, nz / length
        codes[i] = _region_code(planes, clip[i, 0], clip[i, 1], clip[i, 2], clip[i, 3])
