"""Quadric and superquadric surfaces: implicit functions, parametric forms with signed powers, and meshes.

Implicit functions return the left-hand side F of the seed's Cartesian equation, so the surface is F = 1,
the inside F < 1 and the outside F > 1. Parametric forms use the **signed power** $spow(c, e) = sign(c)·|c|^e$
(Barr 1981): a plain $cos(θ)^s$ is NaN for negative cosines and non-integer s, and the octants collapse.
Meshes are sampled on a latitude η ∈ [−π/2, π/2] × longitude ω ∈ [0, 2π) grid (rows north to south, like
``uv_sphere``), with normals from the analytic gradient ∇F, which at the parametric point simplifies to

    n ∝ (spow(cos η, 2 − s1)·spow(cos ω, 2 − s2)/rx, spow(cos η, 2 − s1)·spow(sin ω, 2 − s2)/ry,
         spow(sin η, 2 − s1)/rz).

For s < 2 this is finite and nonzero everywhere, poles included (no division by the vanishing |x|^(2/s − 1)
terms of ∇F). For s >= 2 the surface has edges or cusps where the gradient is undefined; there the mesh uses
its area-weighted face normal instead.

References
----------
[seed] "Quadric Surfaces", "Superquadrics: superellipse", "superellipsoid".
[HB 13] "Quadric Surfaces", "Superquadrics".
A. H. Barr, "Superquadrics and angle-preserving transformations", IEEE CG&A 1(1), 1981 (supertoroid, signed
powers).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import Points, as_count, as_points, as_scalar, as_vector3, describe
from frustum.errors import GeometryError
from frustum.geometry.mesh import Mesh, _area_weighted_normals, _grid_faces
from frustum.geometry.primitives import _check_grid_memory, _positive

__all__ = [
    "ellipsoid",
    "ellipsoid_implicit",
    "sphere",
    "sphere_implicit",
    "superellipse",
    "superellipse_implicit",
    "superellipsoid",
    "superellipsoid_implicit",
    "supertoroid",
    "supertoroid_implicit",
]


def signed_power(c: ArrayLike, e: float) -> NDArray[np.float64]:
    """$spow(c, e) = sign(c)·|c|^e$, the odd extension of ``c^e`` used by superquadric parametric forms."""
    c = np.asarray(c, dtype=np.float64)
    return np.sign(c) * np.abs(c) ** e


# --- implicit functions -------------------------------------------------------------------------------------


def sphere_implicit(points: ArrayLike, radius: float = 1.0) -> NDArray[np.float64]:
    """$F = (x² + y² + z²)/r²$ for each point: the sphere $x² + y² + z² = r²$ is F = 1.

    References
    ----------
    [seed] "Quadric Surfaces: Sphere"; [HB 13] "Quadric Surfaces".
    """
    where = "sphere_implicit"
    p = as_points(points, where=where)
    r = _positive(radius, "radius", where)
    return (p * p).sum(axis=1) / (r * r)


def ellipsoid_implicit(points: ArrayLike, radii: ArrayLike = (1.0, 1.0, 1.0)) -> NDArray[np.float64]:
    """$F = (x/rx)² + (y/ry)² + (z/rz)²$: the ellipsoid is F = 1.

    References
    ----------
    [seed] "Quadric Surfaces: Ellipsoid"; [HB 13] "Quadric Surfaces".
    """
    where = "ellipsoid_implicit"
    p = as_points(points, where=where)
    q = p / _radii(radii, where)
    return (q * q).sum(axis=1)


def superellipse_implicit(points: ArrayLike, radii: ArrayLike = (1.0, 1.0), s: float = 1.0) -> NDArray[np.float64]:
    """$F = |x/rx|^(2/s) + |y/ry|^(2/s)$ for (N, 2) points: the superellipse is F = 1 (s = 1: an ellipse).

    References
    ----------
    [seed] "Superquadrics: superellipse"; [HB 13] "Superquadrics".
    """
    where = "superellipse_implicit"
    p = _points2(points, where)
    r = _radii2(radii, where)
    e = _exponent(s, "s", where)
    return (np.abs(p / r) ** (2.0 / e)).sum(axis=1)


def superellipsoid_implicit(
    points: ArrayLike, radii: ArrayLike = (1.0, 1.0, 1.0), s1: float = 1.0, s2: float = 1.0
) -> NDArray[np.float64]:
    """$F = (|x/rx|^(2/s2) + |y/ry|^(2/s2))^(s2/s1) + |z/rz|^(2/s1)$: the superellipsoid is F = 1.

    s1 shapes the latitude (north–south) profile, s2 the cross-section about z; s1 = s2 = 1 is the ellipsoid.

    References
    ----------
    [seed] "superellipsoid"; [HB 13] "Superquadrics".
    """
    where = "superellipsoid_implicit"
    p = as_points(points, where=where) / _radii(radii, where)
    e1, e2 = _exponent(s1, "s1", where), _exponent(s2, "s2", where)
    a = np.abs(p[:, 0]) ** (2.0 / e2) + np.abs(p[:, 1]) ** (2.0 / e2)
    return a ** (e2 / e1) + np.abs(p[:, 2]) ** (2.0 / e1)


def supertoroid_implicit(
    points: ArrayLike, major_radius: float = 1.0, minor_radius: float = 0.25, s1: float = 1.0, s2: float = 1.0
) -> NDArray[np.float64]:
    """$F = |((|x|^(2/s2) + |y|^(2/s2))^(s2/2) − R)/r|^(2/s1) + |z/r|^(2/s1)$: the supertoroid is F = 1.

    s1 = s2 = 1 gives the ring torus $(√(x² + y²) − R)² + z² = r²$.

    References
    ----------
    Barr 1981, "supertoroid"; [HB 13] "Superquadrics".
    """
    where = "supertoroid_implicit"
    p = as_points(points, where=where)
    big, small = _torus_radii(major_radius, minor_radius, where)
    e1, e2 = _exponent(s1, "s1", where), _exponent(s2, "s2", where)
    rho = (np.abs(p[:, 0]) ** (2.0 / e2) + np.abs(p[:, 1]) ** (2.0 / e2)) ** (e2 / 2.0)
    return np.abs((rho - big) / small) ** (2.0 / e1) + np.abs(p[:, 2] / small) ** (2.0 / e1)


# --- parametric curves and meshes ---------------------------------------------------------------------------


def superellipse(radii: ArrayLike = (1.0, 1.0), s: float = 1.0, segments: int = 64) -> NDArray[np.float64]:
    """Points $(rx·spow(cos θ, s), ry·spow(sin θ, s))$ at θ = 2πk/segments: a closed curve, counter-clockwise.

    Returns (segments, 2) float64 (the first point is not repeated at the end). s = 1 gives the ellipse
    $(rx cos θ, ry sin θ)$ exactly; s < 1 bulges toward a rectangle, s = 2 is a rhombus, s > 2 pinches in.

    References
    ----------
    [seed] "Superquadrics: superellipse" (parametric form); [HB 13] "Superquadrics".
    """
    where = "superellipse"
    r = _radii2(radii, where)
    e = _exponent(s, "s", where)
    n = as_count(segments, "segments", 3, where=where)
    _check_grid_memory(n, where, f"segments = {n}")
    theta = 2 * np.pi * np.arange(n) / n
    return np.stack([r[0] * signed_power(np.cos(theta), e), r[1] * signed_power(np.sin(theta), e)], axis=1)


def sphere(radius: float = 1.0, segments: int = 32, rings: int = 16) -> Mesh:
    """The sphere $x² + y² + z² = r²$ as a latitude-longitude mesh (an ``ellipsoid`` with equal radii)."""
    r = _positive(radius, "radius", "sphere")
    return _superquadric_mesh((r, r, r), 1.0, 1.0, segments, rings, "sphere")


def ellipsoid(radii: ArrayLike = (1.0, 1.0, 1.0), segments: int = 32, rings: int = 16) -> Mesh:
    """The ellipsoid $(x/rx)² + (y/ry)² + (z/rz)² = 1$: $(rx cos η cos ω, ry cos η sin ω, rz sin η)$.

    Normals $∝ ∇F = (x/rx², y/ry², z/rz²)$. `segments` (>= 3) around z, `rings` (>= 2) pole to pole.
    """
    return _superquadric_mesh(_radii(radii, "ellipsoid"), 1.0, 1.0, segments, rings, "ellipsoid")


def superellipsoid(
    radii: ArrayLike = (1.0, 1.0, 1.0), s1: float = 1.0, s2: float = 1.0, segments: int = 32, rings: int = 16
) -> Mesh:
    """The superellipsoid sampled from its parametric form (signed powers):

    $x = rx·spow(cos η, s1)·spow(cos ω, s2)$, $y = ry·spow(cos η, s1)·spow(sin ω, s2)$,
    $z = rz·spow(sin η, s1)$, with η ∈ [−π/2, π/2], ω ∈ [0, 2π). s1 = s2 = 1 gives ``ellipsoid`` exactly.

    References
    ----------
    [seed] "superellipsoid"; [HB 13] "Superquadrics"; Barr 1981.
    """
    where = "superellipsoid"
    return _superquadric_mesh(
        _radii(radii, where), _exponent(s1, "s1", where), _exponent(s2, "s2", where), segments, rings, where
    )


def supertoroid(
    major_radius: float = 1.0,
    minor_radius: float = 0.25,
    s1: float = 1.0,
    s2: float = 1.0,
    major_segments: int = 48,
    minor_segments: int = 24,
) -> Mesh:
    """The supertoroid about z: $x = (R + r·spow(cos η, s1))·spow(cos ω, s2)$,
    $y = (R + r·spow(cos η, s1))·spow(sin ω, s2)$, $z = r·spow(sin η, s1)$, η, ω ∈ [0, 2π); needs r < R.

    References
    ----------
    Barr 1981; [HB 13] "Superquadrics".
    """
    where = "supertoroid"
    big, small = _torus_radii(major_radius, minor_radius, where)
    e1, e2 = _exponent(s1, "s1", where), _exponent(s2, "s2", where)
    n_major = as_count(major_segments, "major_segments", 3, where=where)
    n_minor = as_count(minor_segments, "minor_segments", 3, where=where)
    _check_grid_memory((n_major + 1) * (n_minor + 1), where,
                       f"major_segments = {n_major}, minor_segments = {n_minor}")  # fmt: skip
    eta = -2 * np.pi * np.arange(n_minor) / n_minor  # decreasing: the outer side runs downward (outward front)
    cos_eta, sin_eta = np.append(np.cos(eta), 1.0), np.append(np.sin(eta), 0.0)
    cos_om, sin_om = _circle(n_major)
    ce, se = cos_eta[:, None], sin_eta[:, None]
    ring = big + small * signed_power(ce, e1)
    points = np.stack(
        np.broadcast_arrays(
            ring * signed_power(cos_om, e2), ring * signed_power(sin_om, e2), small * signed_power(se, e1)
        ),
        axis=-1,
    )
    normals = _gradient_normals(ce, se, cos_om, sin_om, e1, e2, np.ones(3))
    uv = np.stack(
        np.broadcast_arrays(np.arange(n_major + 1) / n_major, (np.arange(n_minor + 1) / n_minor)[:, None]), -1
    )
    return _grid_mesh(points, normals, uv)


# --- helpers ------------------------------------------------------------------------------------------------


def _superquadric_mesh(radii: Any, e1: float, e2: float, segments: Any, rings: Any, where: str) -> Mesh:
    n_seg = as_count(segments, "segments", 3, where=where)
    n_ring = as_count(rings, "rings", 2, where=where)
    _check_grid_memory((n_seg + 1) * (n_ring + 1), where, f"segments = {n_seg}, rings = {n_ring}")
    r = np.asarray(radii, dtype=np.float64)
    eta = np.pi / 2 - np.pi * np.arange(n_ring + 1) / n_ring  # north (row 0) to south
    cos_eta, sin_eta = np.cos(eta), np.sin(eta)
    cos_eta[[0, -1]], sin_eta[[0, -1]] = 0.0, (1.0, -1.0)  # exact poles
    cos_om, sin_om = _circle(n_seg)
    ce, se = cos_eta[:, None], sin_eta[:, None]
    points = np.stack(
        np.broadcast_arrays(
            r[0] * signed_power(ce, e1) * signed_power(cos_om, e2),
            r[1] * signed_power(ce, e1) * signed_power(sin_om, e2),
            r[2] * signed_power(se, e1),
        ),
        axis=-1,
    )
    normals = _gradient_normals(ce, se, cos_om, sin_om, e1, e2, r)
    uv = np.stack(
        np.broadcast_arrays(np.arange(n_seg + 1) / n_seg, 1.0 - (np.arange(n_ring + 1) / n_ring)[:, None]), -1
    )
    return _grid_mesh(points, normals, uv)


def _circle(n: int) -> tuple[NDArray, NDArray]:
    """cos ω, sin ω at ω = 2πj/n, j = 0 … n, with the seam column (j = n) an exact copy of j = 0."""
    omega = 2 * np.pi * np.arange(n) / n
    return np.append(np.cos(omega), 1.0)[None, :], np.append(np.sin(omega), 0.0)[None, :]


def _gradient_normals(ce: NDArray, se: NDArray, co: NDArray, so: NDArray, e1: float, e2: float, r: NDArray) -> NDArray:
    """∇F at the parametric point, up to a positive factor; NaN where it is undefined (edges, cusps)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        lat_c, lat_s = signed_power(ce, 2.0 - e1), signed_power(se, 2.0 - e1)
        n = np.stack(
            np.broadcast_arrays(
                lat_c * signed_power(co, 2.0 - e2) / r[0], lat_c * signed_power(so, 2.0 - e2) / r[1], lat_s / r[2]
            ),
            axis=-1,
        )
        length = np.sqrt((n * n).sum(axis=-1, keepdims=True))
        return n / length


def _grid_mesh(points: NDArray, normals: NDArray, uv: NDArray) -> Mesh:
    """Grid → triangles, dropping triangles collapsed at poles, then unused vertices; fill undefined normals."""
    k, m = points.shape[:2]
    vertices, normal, uvs = points.reshape(-1, 3), normals.reshape(-1, 3), uv.reshape(-1, 2)
    faces = _grid_faces(k, m)
    v = vertices[faces]
    collapsed = (v[:, 0] == v[:, 1]).all(axis=1) | (v[:, 1] == v[:, 2]).all(axis=1) | (v[:, 0] == v[:, 2]).all(axis=1)
    faces = faces[~collapsed]
    used = np.zeros(vertices.shape[0], dtype=bool)
    used[faces.ravel()] = True
    remap = np.cumsum(used) - 1
    vertices, normal, uvs, faces = vertices[used], normal[used], uvs[used], remap[faces]
    bad = ~np.isfinite(normal).all(axis=1)
    if bad.any():
        # where ∇F is undefined (s >= 2: edges and cusps), use the area-weighted normal of the faces around
        normal[bad] = _area_weighted_normals(vertices, faces)[bad]
    return Mesh(vertices, faces, normal, uvs)


def _exponent(value: Any, name: str, where: str) -> float:
    number = as_scalar(value, name, where=where, error=GeometryError)
    if number <= 0.0:
        raise GeometryError(f"{where}: {name} = {number!r} is not positive; give an exponent > 0 (1 = quadric)")
    return number


def _radii(value: ArrayLike, where: str) -> NDArray:
    r = as_vector3(value, "radii", where=where, error=GeometryError)
    if not (r > 0.0).all():
        raise GeometryError(f"{where}: radii = {describe(r)} has a component <= 0; give radii > 0")
    return r


def _radii2(value: ArrayLike, where: str) -> NDArray:
    try:
        r = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        r = None
    if r is None or r.shape != (2,) or not np.isfinite(r).all() or not (r > 0.0).all():
        raise GeometryError(f"{where}: radii = {describe(value)} is not two positive numbers; give (rx, ry) > 0")
    return r


def _torus_radii(major: Any, minor: Any, where: str) -> tuple[float, float]:
    big, small = _positive(major, "major_radius", where), _positive(minor, "minor_radius", where)
    if small >= big:
        raise GeometryError(
            f"{where}: minor_radius = {small!r} is not below major_radius = {big!r}; a ring torus needs r < R"
        )
    return big, small


def _points2(value: ArrayLike, where: str) -> Points:
    try:
        p = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise GeometryError(f"{where}: points = {describe(value)} is not numeric; expected (N, 2) points") from None
    if p.ndim != 2 or p.shape[1] != 2:
        raise GeometryError(f"{where}: points has shape {p.shape}; expected (N, 2) points (x, y)")
    bad = np.flatnonzero(~np.isfinite(p).all(axis=1))
    if bad.size:
        i = int(bad[0])
        raise GeometryError(f"{where}: points[{i}] = {describe(p[i])} is not finite; coordinates must be finite")
    return p
