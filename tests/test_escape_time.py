"""geometry/escape_time.py: Numba escape times against a plain-Python oracle, smooth colouring, quaternion Julia."""

from __future__ import annotations

import math

import numpy as np
import pytest
import trimesh

from frustum.errors import GeometryError
from frustum.geometry.escape_time import escape_time_colors, julia, mandelbrot, quaternion_julia, quaternion_julia_mesh

WINDOW = (-2.0, 1.0, -1.2, 1.2)


def naive_escape(z: complex, c: complex, max_iter: int, radius: float) -> float:
    """Plain-Python oracle: the first n with |z_n| > R (z_{n+1} = z_n² + c), inf if none up to max_iter."""
    for n in range(max_iter + 1):
        if abs(z) > radius:
            return float(n)
        if n < max_iter:
            z = z * z + c
    return math.inf


def pixel_point(i: int, j: int, window, width: int, height: int) -> complex:
    x0, x1, y0, y1 = window
    return complex(x0 + (j + 0.5) * (x1 - x0) / width, y1 - (i + 0.5) * (y1 - y0) / height)


def test_mandelbrot_escape_counts_match_plain_python():
    width, height, max_iter = 60, 48, 80
    image = mandelbrot(WINDOW, width, height, max_iter=max_iter, escape_radius=2.0, smooth=False)
    assert image.shape == (height, width)
    rng = np.random.default_rng(0)
    for i, j in zip(rng.integers(0, height, 40), rng.integers(0, width, 40), strict=True):
        c = pixel_point(int(i), int(j), WINDOW, width, height)
        assert image[i, j] == naive_escape(0j, c, max_iter, 2.0), (i, j, c)
    # a point inside (c = -0.1) and one outside: |c| = |1.5 + 1.5i| > 2, so |z_1| > 2 and n = 1
    assert np.isinf(mandelbrot((-0.11, -0.09, -0.01, 0.01), 1, 1, smooth=False)[0, 0])
    assert mandelbrot((1.49, 1.51, 1.49, 1.51), 1, 1, escape_radius=2.0, smooth=False)[0, 0] == 1.0


def test_julia_escape_counts_match_plain_python():
    c = -0.8 + 0.156j
    image = julia(c, (-1.5, 1.5, -1.0, 1.0), 40, 30, max_iter=60, escape_radius=2.0, smooth=False)
    for i, j in [(0, 0), (15, 20), (14, 19), (10, 5), (29, 39), (12, 25)]:
        z = pixel_point(i, j, (-1.5, 1.5, -1.0, 1.0), 40, 30)
        assert image[i, j] == naive_escape(z, c, 60, 2.0)


def test_smooth_count_is_the_renormalized_formula_and_close_to_the_integer_count():
    width, height = 50, 40
    smooth = mandelbrot(WINDOW, width, height, max_iter=100, escape_radius=256.0)
    counts = mandelbrot(WINDOW, width, height, max_iter=100, escape_radius=256.0, smooth=False)
    assert (np.isinf(smooth) == np.isinf(counts)).all()
    out = np.isfinite(counts)
    # ν = n + 1 − log₂(ln|z_n| / ln R) with ln R < ln|z_n| < 2 ln R + small: ν in (n − 1, n + 1]
    assert (smooth[out] > counts[out] - 1.0).all() and (smooth[out] <= counts[out] + 1.0).all()
    i, j = np.argwhere(out)[7]
    c = pixel_point(int(i), int(j), WINDOW, width, height)
    z, n = 0j, 0
    while abs(z) <= 256.0:
        z, n = z * z + c, n + 1
    assert smooth[i, j] == pytest.approx(n + 1 - math.log2(math.log(abs(z)) / math.log(256.0)), abs=1e-9)


def test_mandelbrot_is_symmetric_and_deterministic():
    image = mandelbrot((-2.0, 1.0, -1.0, 1.0), 64, 32, max_iter=64)
    np.testing.assert_array_equal(image, image[::-1])  # conjugate symmetry about the real axis
    assert image.tobytes() == mandelbrot((-2.0, 1.0, -1.0, 1.0), 64, 32, max_iter=64).tobytes()


def test_escape_time_colors():
    rgb = escape_time_colors(np.array([[0.0, np.inf], [16.0, 8.0]]))
    assert rgb.dtype == np.uint8 and rgb.shape == (2, 2, 3)
    assert rgb[0, 1].tolist() == [0, 0, 0] and rgb[0, 0, 0] == 255 and rgb[1, 0, 0] == 0


def test_quaternion_julia_reduces_to_the_complex_julia_set_in_the_1_i_plane():
    # with c and q in span(1, i) the quaternion iteration is the complex one
    c = (-0.8, 0.156, 0.0, 0.0)
    field = quaternion_julia(c, resolution=21, bound=1.2, max_iter=30, escape_radius=2.0)
    axis = np.linspace(-1.2, 1.2, 21)
    for a, b in [(0, 0), (10, 10), (5, 12), (15, 3), (9, 11)]:
        expected = naive_escape(complex(axis[a], axis[b]), complex(-0.8, 0.156), 30, 2.0)
        value = field[a, b, 10]  # z = 0 plane
        if math.isinf(expected):
            assert value == 30.0
        else:
            assert expected - 1.0 < value <= expected + 1.0


def test_quaternion_julia_mesh_is_closed_with_outward_faces():
    mesh = quaternion_julia_mesh(resolution=32)
    tm = trimesh.Trimesh(mesh.vertices, mesh.faces, process=False)
    assert mesh.face_count > 500 and tm.volume > 0.1 and tm.is_watertight
    assert (np.abs(mesh.vertices) <= 1.5 + 1e-9).all()
    centroid = mesh.vertices.mean(axis=0)
    outward = np.einsum("ij,ij->i", mesh.vertex_normals, mesh.vertices - centroid) > 0
    assert outward.mean() > 0.8


def test_bad_input_names_the_value():
    with pytest.raises(GeometryError, match=r"window = \(1.0, 0.0, -1.0, 1.0\) is not"):
        mandelbrot((1.0, 0.0, -1.0, 1.0))
    with pytest.raises(GeometryError, match=r"width = 0 is not an integer >= 1"):
        mandelbrot(width=0)
    with pytest.raises(GeometryError, match=r"escape_radius = 1.0 is below 2"):
        mandelbrot(escape_radius=1.0)
    with pytest.raises(GeometryError, match=r"width·height = 16777216 would need 134217728 bytes"):
        mandelbrot(width=4096, height=4096, max_bytes=2**20)
    with pytest.raises(GeometryError, match=r"c = inf\+0j|c = \(inf\+0j\) is not finite"):
        julia(complex(math.inf, 0))
    with pytest.raises(GeometryError, match=r"c = \(1.0, 2.0\) is not four finite numbers"):
        quaternion_julia((1.0, 2.0))
    with pytest.raises(GeometryError, match=r"level = 99.0 is outside the field's range"):
        quaternion_julia_mesh(resolution=8, level=99.0)


def test_cardioid_and_bulb_shortcut_changes_no_pixel():
    # a window across the main cardioid, the period-2 bulb and their boundaries, every pixel against the oracle
    window, size, max_iter = (-1.3, 0.4, -0.7, 0.7), 20, 60
    image = mandelbrot(window, size, size, max_iter=max_iter, escape_radius=2.0, smooth=False)
    expected = [[naive_escape(0j, pixel_point(i, j, window, size, size), max_iter, 2.0) for j in range(size)]
                for i in range(size)]  # fmt: skip
    np.testing.assert_array_equal(image, expected)
    assert np.isinf(image).mean() > 0.3
