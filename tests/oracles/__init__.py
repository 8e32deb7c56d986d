"""Adapters to the independent oracle libraries (test-only): PyGLM, SciPy, trimesh.transformations.

Each adapter returns plain float64 numpy arrays in frustum's conventions, so tests compare like with like.
The convention traps they encode are written beside each adapter: PyGLM builds float32 matrices unless given
float64 vectors (``glm_vec``), ``np.array`` of a PyGLM matrix is already in mathematical layout (``glm_matrix``),
its quaternions store (w, x, y, z) in that order (``glm_wxyz``), and q and −q are one rotation.
"""

from __future__ import annotations

import numpy as np
from pyglm import glm


def glm_vec(v) -> glm.dvec3:
    """A float64 PyGLM vector (dvec3), so builders return float64 dmat4."""
    return glm.dvec3(*map(float, v))


def glm_matrix(m) -> np.ndarray:
    """PyGLM matrix → numpy in mathematical layout: np.array(m) needs no transpose."""
    return np.array(m, dtype=np.float64)


def glm_wxyz(q) -> np.ndarray:
    """PyGLM quaternion → (w, x, y, z)."""
    return np.array([q.w, q.x, q.y, q.z], dtype=np.float64)


def assert_close(actual, expected, tol: float = 1e-12) -> None:
    """Equal to `tol` relative to the larger of 1 and the expected magnitude (round-off scales with size)."""
    actual, expected = np.asarray(actual, dtype=np.float64), np.asarray(expected, dtype=np.float64)
    assert actual.shape == expected.shape, (actual.shape, expected.shape)
    scale = max(1.0, float(np.abs(expected).max(initial=0.0)))
    np.testing.assert_allclose(actual, expected, rtol=0, atol=tol * scale)


def assert_same_rotation(q, r, tol: float = 1e-12) -> None:
    """Quaternions equal up to sign (q and −q are one rotation)."""
    q, r = np.asarray(q, dtype=np.float64), np.asarray(r, dtype=np.float64)
    assert min(np.abs(q - r).max(), np.abs(q + r).max()) <= tol, (q, r)
