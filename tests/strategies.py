"""Hypothesis strategies shared by the test modules: finite coordinates, unit axes, angles, transforms."""

from __future__ import annotations

import numpy as np
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

# Coordinates of moderate size: large enough to exercise translation, small enough that a 1e-12 relative
# tolerance on products of a few matrices stays meaningful.
coordinates = st.floats(min_value=-100.0, max_value=100.0, allow_nan=False, allow_infinity=False)
angles = st.floats(min_value=-2 * np.pi, max_value=2 * np.pi, allow_nan=False, allow_infinity=False)
# Scale factors bounded away from 0 so that inverses are well conditioned.
scale_factors = st.one_of(st.floats(min_value=0.1, max_value=10.0), st.floats(min_value=-10.0, max_value=-0.1))


@st.composite
def vectors(draw: st.DrawFn) -> np.ndarray:
    """A (3,) float64 vector with coordinates in [-100, 100]."""
    return np.array([draw(coordinates) for _ in range(3)])


@st.composite
def axes(draw: st.DrawFn) -> np.ndarray:
    """A (3,) direction of length at least 1e-3 (the builders normalize it)."""
    v = draw(vectors())
    if np.linalg.norm(v) < 1e-3:
        v = np.array([0.0, 0.0, 1.0])
    return v


def point_arrays(max_rows: int = 20) -> st.SearchStrategy[np.ndarray]:
    """An (N, 3) float64 array of points, 1 <= N <= max_rows."""
    return st.integers(1, max_rows).flatmap(lambda n: arrays(np.float64, (n, 3), elements=coordinates))
