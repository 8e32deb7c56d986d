"""Naive references for the clipping tests: brute-force sampling and shapely in a triangle's own 2D parameters.

Nothing here shares code with ``frustum.clipping``: every function is the obvious, slow way (stumpy's
``naive.py`` habit). A triangle ``(P0, P1, P2)`` in clip space is parametrized by ``(s, t)`` as
``P = P0 + s·(P1 − P0) + t·(P2 − P0)`` (barycentric weights ``(1 − s − t, s, t)``); every clip plane is then a
half-plane in (s, t), so the clipped triangle is a 2D convex polygon that shapely computes exactly (up to
round-off), for any sign of w.
"""

from __future__ import annotations

import numpy as np
import shapely
from shapely.geometry import Polygon

CUBE_PLANES = np.array(
    [[1.0, 0, 0, 1], [-1.0, 0, 0, 1], [0, 1.0, 0, 1], [0, -1.0, 0, 1], [0, 0, 1.0, 1], [0, 0, -1.0, 1]]
)
"""−w <= x, y, z <= w written out independently of the library's constant."""

UNIT_TRIANGLE = Polygon([(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)])


def inside(points: np.ndarray, planes: np.ndarray = CUBE_PLANES) -> np.ndarray:
    """(N,) bool: every plane value a·x + b·y + c·z + d·w >= 0."""
    return (np.atleast_2d(points) @ planes.T >= 0).all(axis=1)


def plane_margin(points: np.ndarray, planes: np.ndarray = CUBE_PLANES, scale: float | None = None) -> np.ndarray:
    """(N,) smallest plane value of each point over |plane|·scale (negative = outside).

    `scale` is the size of the geometry the points were interpolated from (round-off is relative to it);
    by default each point's own length.
    """
    points = np.atleast_2d(points)
    values = points @ planes.T
    sizes = np.linalg.norm(points, axis=1)[:, None] if scale is None else np.full((len(points), 1), scale)
    return (values / np.maximum(sizes * np.linalg.norm(planes, axis=1)[None, :], 1e-300)).min(axis=1)


def sampled_interval(p0: np.ndarray, p1: np.ndarray, planes: np.ndarray, samples: int = 4001):
    """Brute force: the parameters u in [0, 1] (a grid) whose point P0 + (P1 − P0)u is inside every plane."""
    u = np.linspace(0.0, 1.0, samples)
    points = p0[None, :] + (p1 - p0)[None, :] * u[:, None]
    return u, inside(points, planes)


def half_plane(a: float, b: float, c: float, reach: float = 100.0) -> Polygon | None:
    """The region a + b·s + c·t >= 0 as a big polygon (None: empty; the unit square's cover: whole plane)."""
    length = np.hypot(b, c)
    if length == 0.0:
        return None if a < 0 else Polygon([(-reach, -reach), (reach, -reach), (reach, reach), (-reach, reach)])
    n = np.array([b, c]) / length
    v = np.array([-n[1], n[0]])
    origin = -a / length * n
    corners = [origin - reach * v, origin + reach * v, origin + reach * v + reach * n, origin - reach * v + reach * n]
    return Polygon(corners)


def clip_triangle_in_parameters(triangle: np.ndarray, planes: np.ndarray = CUBE_PLANES) -> Polygon:
    """The clipped triangle in its (s, t) parameters: the unit triangle cut by each plane's half-plane."""
    region = UNIT_TRIANGLE
    for plane in planes:
        d0, d1, d2 = triangle @ plane
        cut = half_plane(d0, d1 - d0, d2 - d0)
        if cut is None:
            return Polygon()
        region = region.intersection(cut)
    return region


def clip_triangle_after_divide(triangle: np.ndarray) -> np.ndarray:
    """For w > 0 at every vertex: divide first, then clip the NDC triangle to [−1, 1]³; (K, 3) NDC vertices.

    Works in the NDC triangle's own affine (s, t) parameters, q = A + s(B − A) + t(C − A), where the six
    conditions −1 <= q_x, q_y, q_z <= 1 are half-planes: independent of homogeneous coordinates altogether.
    """
    ndc = triangle[:, :3] / triangle[:, 3:]
    a, ab, ac = ndc[0], ndc[1] - ndc[0], ndc[2] - ndc[0]
    region = UNIT_TRIANGLE
    for axis in range(3):
        for sign in (1.0, -1.0):  # 1 + sign·q_axis >= 0
            cut = half_plane(1.0 + sign * a[axis], sign * ab[axis], sign * ac[axis])
            region = Polygon() if cut is None else region.intersection(cut)
    if region.is_empty or region.area == 0.0:
        return np.empty((0, 3))
    st = np.asarray(shapely.get_coordinates(region.exterior))[:-1]
    return a + st[:, :1] * ab + st[:, 1:] * ac


def polygon_area_3d(points: np.ndarray) -> float:
    """Area of a planar polygon in 3D: half the length of Σ P_i × P_{i+1}."""
    if len(points) < 3:
        return 0.0
    return 0.5 * float(np.linalg.norm(np.cross(points, np.roll(points, -1, axis=0)).sum(axis=0)))


def same_point_sets(a: np.ndarray, b: np.ndarray, tolerance: float) -> bool:
    """Every point of `a` is within `tolerance` of some point of `b`, and the other way round."""
    if len(a) == 0 or len(b) == 0:
        return len(a) == len(b)
    distances = np.linalg.norm(a[:, None, :] - b[None, :, :], axis=2)
    return bool(distances.min(axis=1).max() <= tolerance and distances.min(axis=0).max() <= tolerance)


def distance_to_boundary(points: np.ndarray, polygon: np.ndarray) -> np.ndarray:
    """(N,) distance of each point to the closed polygon's boundary (its edge segments), in any dimension."""
    starts, ends = polygon, np.roll(polygon, -1, axis=0)
    edges = ends - starts
    lengths = np.maximum((edges * edges).sum(axis=1), 1e-300)
    offsets = points[:, None, :] - starts[None, :, :]
    u = np.clip((offsets * edges[None]).sum(axis=2) / lengths[None], 0.0, 1.0)
    nearest = starts[None] + u[..., None] * edges[None]
    return np.linalg.norm(points[:, None, :] - nearest, axis=2).min(axis=1)


def random_clip_points(rng: np.random.Generator, count: int, behind: bool = True) -> np.ndarray:
    """(count, 4) clip-space points around the cube: x, y, z in [−3, 3]; w in [−1, 2] (or [0.2, 2])."""
    xyz = rng.uniform(-3.0, 3.0, size=(count, 3))
    w = rng.uniform(-1.0, 2.0, size=(count, 1)) if behind else rng.uniform(0.2, 2.0, size=(count, 1))
    return np.hstack([xyz, w])
