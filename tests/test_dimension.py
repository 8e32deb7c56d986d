"""geometry/dimension.py: box counting against the known similarity dimensions (ORACLES.md recipe) and 3 − H."""

from __future__ import annotations

import math

import numpy as np
import pytest

from frustum.errors import GeometryError
from frustum.geometry.dimension import box_counting_dimension
from frustum.geometry.fractals import (
    cantor_set,
    fbm_terrain,
    koch_curve,
    menger_sponge,
    sierpinski_triangle,
    similarity_dimension,
)
from frustum.geometry.mesh import Mesh

KOCH, SIERPINSKI = math.log(4) / math.log(3), math.log(3) / math.log(2)
CANTOR, MENGER = math.log(2) / math.log(3), math.log(20) / math.log(3)


def test_cantor_exact_counts():
    midpoints = cantor_set(10).mean(axis=1)[:, None]  # interval centres, not ends (ends sit on box edges)
    result = box_counting_dimension(midpoints, 3.0 ** -np.arange(1, 9))
    assert result.counts.tolist() == [2**k for k in range(1, 9)]
    assert abs(result.dimension - CANTOR) < 1e-12 and abs(CANTOR - similarity_dimension(2, 1 / 3)) < 1e-15
    low, high = result.interval
    assert low <= result.dimension <= high and high - low < 1e-6


def test_sierpinski_mesh_exact_counts():
    mesh = sierpinski_triangle(8, corners=((0, 0), (1, 0), (0, 1)))  # the right variant gives exact counts
    result = box_counting_dimension(mesh, 2.0 ** -np.arange(1, 7))
    assert result.counts.tolist() == [3**k for k in range(1, 7)]
    assert abs(result.dimension - SIERPINSKI) < 1e-12


def test_equilateral_sierpinski_within_002():
    result = box_counting_dimension(sierpinski_triangle(8), 2.0 ** -np.arange(1, 7))
    assert abs(result.dimension - SIERPINSKI) < 0.02


def test_menger_mesh_exact_counts():
    # faces on box boundaries count for the box their solid is in; a level-3 mesh resolves boxes down to 1/9
    result = box_counting_dimension(menger_sponge(3), [1.0, 1 / 3, 1 / 9])
    assert result.counts.tolist() == [1, 20, 400]
    assert abs(result.dimension - MENGER) < 1e-12


def test_koch_within_002_over_fine_scales():
    # sample size: a level-8 curve, 8 points per segment (524 288 points); boxes 3^-4 … 3^-7. Coarse boxes
    # overcount (N(3^-k+1)/N(3^-k) = 5.0, 4.5, 4.4, 4.2 before settling at 4), so the fit uses the fine end.
    curve = koch_curve(8)[:, :2]
    t = np.linspace(0.0, 1.0, 8, endpoint=False)
    points = (curve[:-1, None, :] + (curve[1:] - curve[:-1])[:, None, :] * t[None, :, None]).reshape(-1, 2)
    result = box_counting_dimension(points, 3.0 ** -np.arange(4, 8))
    assert abs(result.dimension - KOCH) < 0.02
    assert result.interval[0] < result.dimension < result.interval[1]


@pytest.mark.parametrize("hurst", [0.5, 0.7, 0.8])
def test_fbm_terrain_dimension_is_3_minus_h(hurst):
    # sample size: one (2^10 + 1)² diamond-square heightfield, seed 0, σ = 1 on the unit square; blocks of 2 to
    # 64 cells (differential box counting)
    heights = fbm_terrain(10, hurst, seed=0)
    result = box_counting_dimension(heights, [2, 4, 8, 16, 32, 64])
    assert abs(result.dimension - (3.0 - hurst)) < 0.1


def test_binary_image_of_a_filled_square_is_2_and_a_line_is_1():
    square = np.ones((64, 64), dtype=bool)
    assert box_counting_dimension(square).dimension == pytest.approx(2.0, abs=1e-12)
    line = np.zeros((64, 64), dtype=bool)
    line[10] = True
    result = box_counting_dimension(line, [1, 2, 4, 8])
    assert result.counts.tolist() == [64, 32, 16, 8] and result.dimension == pytest.approx(1.0, abs=1e-12)


def test_default_sizes_and_a_smooth_surface():
    flat = np.zeros((129, 129))
    assert box_counting_dimension(flat).dimension == pytest.approx(2.0, abs=1e-12)
    centres = (np.arange(200) + 0.5) / 200  # cell centres: points on box edges would count (2^k + 1)² boxes
    grid = np.stack(np.meshgrid(centres, centres), -1).reshape(-1, 2)
    assert box_counting_dimension(grid).dimension == pytest.approx(2.0, abs=0.05)


def test_bad_input():
    with pytest.raises(GeometryError, match=r"data has shape \(5, 4, 2\)"):
        box_counting_dimension(np.zeros((5, 4, 2)))
    with pytest.raises(GeometryError, match=r"data\[1\] = \(nan, 0.0\) is not finite"):
        box_counting_dimension([[0.0, 0.0], [math.nan, 0.0], [1.0, 1.0]])
    with pytest.raises(GeometryError, match=r"sizes = \(0.5, 0.0, 0.25\) is not 3 or more finite sizes > 0"):
        box_counting_dimension(np.random.default_rng(0).random((50, 2)), [0.5, 0.0, 0.25])
    with pytest.raises(GeometryError, match=r"confidence = 1.5 is outside \(0, 1\)"):
        box_counting_dimension([[0.0], [1.0]], confidence=1.5)
    with pytest.raises(GeometryError, match=r"image has no True pixel"):
        box_counting_dimension(np.zeros((8, 8), dtype=bool))
    with pytest.raises(GeometryError, match=r"zero extent"):
        box_counting_dimension([[1.0, 1.0], [1.0, 1.0]])
    with pytest.raises(GeometryError, match=r"mesh has no faces"):
        box_counting_dimension(Mesh([[0, 0, 0], [1, 1, 1]], np.empty((0, 3), dtype=np.int64)), [1.0, 0.5, 0.25])


def _square_grid(count: int) -> np.ndarray:
    side = np.linspace(0.0, 2.0, count)  # to the square's edges
    return np.stack(np.meshgrid(side, side), -1).reshape(-1, 2)


def _line(count: int) -> np.ndarray:
    return np.linspace(0.0, 1.0, count)[:, None] * np.array([[3.0, 1.0]]) + np.array([[2.0, -1.0]])


@pytest.mark.parametrize(
    ("name", "data", "expected"),
    [
        ("Koch curve, level-7 vertices", lambda: koch_curve(7), KOCH),
        ("Koch curve, level-8 vertices (x, y)", lambda: koch_curve(8)[:, :2], KOCH),
        ("Sierpinski triangle mesh, level 8", lambda: sierpinski_triangle(8), SIERPINSKI),
        ("Cantor set, level-10 interval ends", lambda: cantor_set(10).reshape(-1, 1), CANTOR),
        ("Cantor set, level-10 interval centres", lambda: cantor_set(10).mean(axis=1)[:, None], CANTOR),
        ("Menger sponge mesh, level 3", lambda: menger_sponge(3), MENGER),
        ("straight line, 10001 points off the axes", lambda: _line(10001), 1.0),
        ("filled square, 300 x 300 grid", lambda: _square_grid(300), 2.0),
        ("filled square, 60000 random points", lambda: np.random.default_rng(0).random((60000, 2)), 2.0),
    ],
)  # fmt: skip
def test_default_sizes_give_the_documented_dimensions_within_002(name, data, expected):
    result = box_counting_dimension(data())  # no sizes: the defaults alone
    assert abs(result.dimension - expected) < 0.02, (name, result.dimension, result.sizes, result.counts)
    assert result.sizes.size >= 3 and np.all(np.diff(result.sizes) < 0)


def test_default_sizes_are_the_finest_three_octaves_of_well_filled_tiling_boxes():
    points = koch_curve(7)
    result = box_counting_dimension(points)
    # boxes of side extent/m (whole m) over the bounding box; the finest still holds >= 4 points on average
    m = 1.0 / result.sizes  # the Koch curve's extent is 1
    np.testing.assert_allclose(m, np.round(m), atol=1e-9)
    assert result.counts[-1] <= points.shape[0] / 4 and result.sizes[0] / result.sizes[-1] <= 8.0 * (1 + 1e-9)
    # exact counts on a line sampled to its ends: m boxes for every m (the last box of the tiling is closed)
    line = box_counting_dimension(_line(4001))
    np.testing.assert_array_equal(line.counts, np.round(3.0 / line.sizes).astype(np.int64))
    assert line.dimension == pytest.approx(1.0, abs=1e-12)
