"""Vertex stage kernel: model → clip coordinates, world positions and normals, and region codes, per vertex.

Contract (kernels never validate): vertices, normals (N, 3) float64; matrices (3, 4, 4) float64 holding
clip_from_model, world_from_model and, in its 3x3 block, the normal matrix (inverse transpose of
world_from_model's 3x3 block); planes (P, 4) float64 with P <= 63. Written: clip (N, 4), world (N, 3),
world_normals (N, 3) float64, codes (N,) int64. Every row is independent, so the loop runs in parallel.
"""

from __future__ import annotations

import math

import numpy as np

from frustum.raster._jit import kernel, parallel_kernel, prange

__all__ = ["transform_vertices"]


@kernel
def _affine_row(m: np.ndarray, k: int, x: float, y: float, z: float) -> float:
    """Row k of ``M·[x, y, z, 1]``, summed left to right: ``((m0·x + m1·y) + m2·z) + m3``."""
    return ((m[k, 0] * x + m[k, 1] * y) + m[k, 2] * z) + m[k, 3]


@kernel
def _linear_row(m: np.ndarray, k: int, x: float, y: float, z: float) -> float:
    """Row k of ``A·[x, y, z]`` with A the 3x3 block of m: ``(a0·x + a1·y) + a2·z``."""
    return (m[k, 0] * x + m[k, 1] * y) + m[k, 2] * z


@parallel_kernel
def transform_vertices(
    vertices: np.ndarray, normals: np.ndarray, matrices: np.ndarray, planes: np.ndarray,
    clip: np.ndarray, world: np.ndarray, world_normals: np.ndarray, codes: np.ndarray,
) -> None:  # fmt: skip
    """``clip = clip_from_model·P``, ``world = world_from_model·P``, ``n' = normalize(N·n)``, region code of clip.

    The region code has bit k set when the clip-space point is outside plane k (``planes[k]·clip < 0``).
    """
    for i in prange(vertices.shape[0]):
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
        code = 0
        for k in range(planes.shape[0]):
            distance = ((planes[k, 0] * clip[i, 0] + planes[k, 1] * clip[i, 1]) + planes[k, 2] * clip[i, 2]) + (
                planes[k, 3] * clip[i, 3]
            )
            if distance < 0.0:
                code |= 1 << k
        codes[i] = code
