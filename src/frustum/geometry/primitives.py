"""Primitive solids and surfaces as triangle meshes with outward normals and texture coordinates.

Every builder takes keyword arguments with defaults (scene files call them with ``**kwargs``), validates them
(a resolution below its minimum raises ``GeometryError`` naming it), and returns a ``Mesh`` centred on the
origin with exact analytic vertex normals and UVs. Closed solids are watertight once seam vertices are
counted by position (``Mesh.is_watertight``) and have positive volume: their faces wind counter-clockwise
seen from outside. Round shapes are built as surfaces of revolution about the z axis; the UV seam is at
angle 0 (the +x side), with the seam column duplicated so u runs from 0 to 1.

References
----------
[HB 13] "Polyhedra", "Quadric Surfaces", "OpenGL Quadric-Surface and Cubic-Surface Functions".
[seed] "Polygon Mesh Models", "Quadric Surfaces".
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import as_count, as_scalar, as_vector3, describe
from frustum.budgets import check_memory
from frustum.errors import GeometryError
from frustum.geometry.mesh import Mesh, _grid_faces
from frustum.transforms import rotate, translate

__all__ = ["arrow", "axes", "box", "cone", "cylinder", "disk", "grid", "icosphere", "plane", "torus", "uv_sphere"]


def box(size: ArrayLike = (1.0, 1.0, 1.0), center: ArrayLike = (0.0, 0.0, 0.0)) -> Mesh:
    """An axis-aligned box: 6 faces × 4 vertices (flat normals per face), 12 triangles, UVs 0..1 per face.

    Parameters
    ----------
    size : (3,) array_like
        Edge lengths along x, y, z (each > 0).
    center : (3,) array_like
    """
    where = "box"
    half = 0.5 * _positive_vector(size, "size", where)
    c = as_vector3(center, "center", where=where, error=GeometryError)
    # (normal, u axis, v axis) with u × v = normal, so the quad (−,−), (+,−), (+,+), (−,+) is counter-clockwise
    frames = np.array(
        [
            [[1, 0, 0], [0, 1, 0], [0, 0, 1]],
            [[-1, 0, 0], [0, -1, 0], [0, 0, 1]],
            [[0, 1, 0], [-1, 0, 0], [0, 0, 1]],
            [[0, -1, 0], [1, 0, 0], [0, 0, 1]],
            [[0, 0, 1], [1, 0, 0], [0, 1, 0]],
            [[0, 0, -1], [1, 0, 0], [0, -1, 0]],
        ],
        dtype=np.float64,
    )
    corners = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]], dtype=np.float64)
    normal, u_axis, v_axis = frames[:, 0], frames[:, 1], frames[:, 2]
    vertices = (
        normal[:, None, :] + corners[None, :, 0:1] * u_axis[:, None, :] + corners[None, :, 1:2] * v_axis[:, None, :]
    ) * half + c
    normals = np.repeat(normal, 4, axis=0)
    uvs = np.tile(0.5 * (corners + 1.0), (6, 1))
    base = 4 * np.arange(6)[:, None]
    faces = np.concatenate([base + np.array([0, 1, 2]), base + np.array([0, 2, 3])], axis=1).reshape(-1, 3)
    return Mesh(vertices.reshape(-1, 3), faces, normals, uvs)


def plane(size: ArrayLike = (1.0, 1.0), divisions: int | ArrayLike = (1, 1)) -> Mesh:
    """A flat rectangle in z = 0 facing +z, x ∈ [−w/2, w/2], y ∈ [−d/2, d/2], cut into a grid of quads.

    Parameters
    ----------
    size : (2,) array_like or float
        Width (x) and depth (y), each > 0; one number gives a square.
    divisions : int or (2,) ints
        Quads along x and y, each >= 1: $2·nx·ny$ triangles. UV (0, 0) is the (−x, −y) corner.
    """
    where = "plane"
    width, depth = _pair(size, "size", where, as_float=True)
    nx, ny = _pair(divisions, "divisions", where, as_float=False)
    for value, name in ((width, "size[0]"), (depth, "size[1]")):
        if value <= 0.0:
            raise GeometryError(f"{where}: {name} = {value!r} is not positive; give a size > 0")
    for value, name in ((nx, "divisions[0]"), (ny, "divisions[1]")):
        if value < 1:
            raise GeometryError(f"{where}: {name} = {value} is below 1; give at least 1 division")
    _check_grid_memory((nx + 1) * (ny + 1), where, f"divisions = ({nx}, {ny})")
    s, t = np.linspace(0.0, 1.0, nx + 1), np.linspace(0.0, 1.0, ny + 1)
    u, v = np.meshgrid(s, t, indexing="ij")  # row i along +x, column j along +y: (∂P/∂i × ∂P/∂j) = +z
    points = np.stack([(u - 0.5) * width, (v - 0.5) * depth, np.zeros_like(u)], axis=-1).reshape(-1, 3)
    normals = np.tile([0.0, 0.0, 1.0], (points.shape[0], 1))
    return Mesh(points, _grid_faces(nx + 1, ny + 1), normals, np.stack([u, v], axis=-1).reshape(-1, 2))


def grid(size: ArrayLike = (1.0, 1.0), divisions: int | ArrayLike = (10, 10)) -> Mesh:
    """A ``plane`` with 10 × 10 quads by default (a ground grid for drawings); same parameters."""
    return plane(size=size, divisions=divisions)


def uv_sphere(radius: float = 1.0, segments: int = 32, rings: int = 16) -> Mesh:
    """A latitude-longitude sphere $x² + y² + z² = r²$: `segments` around z (>= 3), `rings` pole to pole (>= 2).

    $2·segments·(rings − 1)$ triangles (one per segment at each pole). Normals are ``P/r``. UVs are the
    equirectangular map: u = longitude/2π from +x counter-clockwise, v = 0 at the south pole, 1 at the north.
    """
    where = "uv_sphere"
    r = _positive(radius, "radius", where)
    n_seg = as_count(segments, "segments", 3, where=where)
    n_ring = as_count(rings, "rings", 2, where=where)
    _check_grid_memory((n_seg + 1) * (n_ring + 1), where, f"segments = {n_seg}, rings = {n_ring}")
    latitude = np.pi / 2 - np.pi * np.arange(n_ring + 1) / n_ring  # north (i = 0) to south
    cos_lat, sin_lat = np.cos(latitude), np.sin(latitude)
    cos_lat[[0, -1]], sin_lat[[0, -1]] = 0.0, (1.0, -1.0)
    profile = np.stack([r * cos_lat, r * sin_lat], axis=1)
    normals = np.stack([cos_lat, sin_lat], axis=1)
    return _revolve(profile, normals, 1.0 - np.arange(n_ring + 1) / n_ring, n_seg)


def icosphere(radius: float = 1.0, subdivisions: int = 2) -> Mesh:
    """A geodesic sphere: the icosahedron with each triangle split in four `subdivisions` times (0 … 8).

    $20·4^k$ triangles whose vertices are pushed onto the sphere; normals ``P/r``. UVs are the
    equirectangular map (u = longitude/2π, v = latitude/π + ½), with vertices duplicated along the u seam so
    no triangle wraps around the texture.
    """
    where = "icosphere"
    r = _positive(radius, "radius", where)
    k = as_count(subdivisions, "subdivisions", 0, where=where)
    if k > 8:
        raise GeometryError(f"{where}: subdivisions = {k} is above 8 (20·4^k triangles); give 0 … 8")
    t = (1.0 + 5.0**0.5) / 2.0
    vertices = np.array(
        [[-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0], [0, -1, t], [0, 1, t], [0, -1, -t], [0, 1, -t],
         [t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1]],
        dtype=np.float64,
    )  # fmt: skip
    faces = np.array(
        [[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4], [11, 10, 2],
         [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8], [3, 8, 9], [4, 9, 5], [2, 4, 11],
         [6, 2, 10], [8, 6, 7], [9, 8, 1]],
        dtype=np.int64,
    )  # fmt: skip
    vertices /= np.linalg.norm(vertices, axis=1)[:, None]
    for _ in range(k):
        vertices, faces = _subdivide(vertices, faces)
    u = (np.arctan2(vertices[:, 1], vertices[:, 0]) / (2 * np.pi)) % 1.0
    v = np.arcsin(np.clip(vertices[:, 2], -1.0, 1.0)) / np.pi + 0.5
    vertices, faces, uv = _split_u_seam(vertices, faces, np.stack([u, v], axis=1))
    return Mesh(vertices * r, faces, vertices, uv)


def cylinder(radius: float = 1.0, height: float = 1.0, segments: int = 32, caps: bool = True) -> Mesh:
    """A circular cylinder about the z axis, z ∈ [−h/2, h/2], `segments` >= 3 around, with or without caps.

    Side normals are radial; the caps (flat normals ±z, planar UVs) have their own vertices so the rim stays
    sharp. Side UVs: u = angle/2π, v = 0 at the bottom, 1 at the top. Without caps the mesh is open.
    """
    where = "cylinder"
    r = _positive(radius, "radius", where)
    half = 0.5 * _positive(height, "height", where)
    n_seg = as_count(segments, "segments", 3, where=where)
    _check_grid_memory(4 * (n_seg + 1), where, f"segments = {n_seg}")
    side = _revolve(np.array([[r, half], [r, -half]]), np.array([[1.0, 0.0], [1.0, 0.0]]), np.array([1.0, 0.0]), n_seg)
    if not _flag(caps, "caps", where):
        return side
    return side.merged(_cap(r, half, n_seg, up=True), _cap(r, -half, n_seg, up=False))


def cone(radius: float = 1.0, height: float = 1.0, segments: int = 32, cap: bool = True) -> Mesh:
    """A circular cone about z: base of `radius` at z = −h/2, apex at z = +h/2, `segments` >= 3 around.

    Side normals are the analytic $(h·cos θ, h·sin θ, r)/√(h² + r²)$; the apex is split into one vertex per
    segment so each triangle there keeps its own normal direction. The base cap faces −z.
    """
    where = "cone"
    r = _positive(radius, "radius", where)
    h = _positive(height, "height", where)
    n_seg = as_count(segments, "segments", 3, where=where)
    _check_grid_memory(4 * (n_seg + 1), where, f"segments = {n_seg}")
    slope = np.array([h, r]) / np.hypot(h, r)
    side = _revolve(np.array([[0.0, h / 2], [r, -h / 2]]), np.array([slope, slope]), np.array([1.0, 0.0]), n_seg)
    return side.merged(_cap(r, -h / 2, n_seg, up=False)) if _flag(cap, "cap", where) else side


def torus(
    major_radius: float = 1.0, minor_radius: float = 0.25, major_segments: int = 48, minor_segments: int = 24
) -> Mesh:
    """A ring torus about the z axis: $(√(x² + y²) − R)² + z² = r²$ with 0 < r < R.

    $2·major_segments·minor_segments$ triangles; normals point from the tube's centre circle to the surface.
    UVs: u = angle about z / 2π, v = angle about the tube / 2π.
    """
    where = "torus"
    big = _positive(major_radius, "major_radius", where)
    small = _positive(minor_radius, "minor_radius", where)
    if small >= big:
        raise GeometryError(
            f"{where}: minor_radius = {small!r} is not below major_radius = {big!r}; a ring torus needs r < R"
        )
    n_major = as_count(major_segments, "major_segments", 3, where=where)
    n_minor = as_count(minor_segments, "minor_segments", 3, where=where)
    _check_grid_memory((n_major + 1) * (n_minor + 1), where,
                       f"major_segments = {n_major}, minor_segments = {n_minor}")  # fmt: skip
    phi = 2 * np.pi * np.arange(n_minor) / n_minor
    cos_phi, sin_phi = np.append(np.cos(phi), 1.0), np.append(np.sin(phi), 0.0)
    # the profile circle runs downward on its outer side, so ∂P/∂i × ∂P/∂θ points out of the tube
    profile = np.stack([big + small * cos_phi, -small * sin_phi], axis=1)
    normals = np.stack([cos_phi, -sin_phi], axis=1)
    return _revolve(profile, normals, np.arange(n_minor + 1) / n_minor, n_major)


def disk(radius: float = 1.0, segments: int = 32) -> Mesh:
    """A flat disk of `radius` in z = 0 facing +z: `segments` >= 3 triangles around the centre; planar UVs."""
    where = "disk"
    n_seg = as_count(segments, "segments", 3, where=where)
    _check_grid_memory(2 * (n_seg + 1), where, f"segments = {n_seg}")
    return _cap(_positive(radius, "radius", where), 0.0, n_seg, up=True)


def arrow(
    length: float = 1.0,
    shaft_radius: float = 0.02,
    head_radius: float = 0.05,
    head_length: float = 0.2,
    segments: int = 16,
    direction: ArrayLike = (0.0, 0.0, 1.0),
    origin: ArrayLike = (0.0, 0.0, 0.0),
) -> Mesh:
    """A closed arrow from `origin` along `direction`: a cylindrical shaft and a conical head, total `length`.

    Requires $head_length < length$ and $shaft_radius < head_radius$. Built along +z, then rotated onto
    `direction` and moved to `origin`.
    """
    where = "arrow"
    total = _positive(length, "length", where)
    r_shaft = _positive(shaft_radius, "shaft_radius", where)
    r_head = _positive(head_radius, "head_radius", where)
    h_head = _positive(head_length, "head_length", where)
    n_seg = as_count(segments, "segments", 3, where=where)
    _check_grid_memory(12 * (n_seg + 1), where, f"segments = {n_seg}")
    if h_head >= total:
        raise GeometryError(f"{where}: head_length = {h_head!r} is not below length = {total!r}; make the head shorter")
    if r_shaft >= r_head:
        raise GeometryError(
            f"{where}: shaft_radius = {r_shaft!r} is not below head_radius = {r_head!r}; the head must be wider"
        )
    axis = np.array([0.0, 0.0, 1.0])
    to = as_vector3(direction, "direction", where=where, error=GeometryError)
    if not np.linalg.norm(to) > 0.0:
        raise GeometryError(f"{where}: direction = {describe(to)} has zero length; give a nonzero direction")
    start = as_vector3(origin, "origin", where=where, error=GeometryError)
    z_neck = total - h_head
    slope = np.array([h_head, r_head]) / np.hypot(h_head, r_head)
    head = _revolve(np.array([[0.0, total], [r_head, z_neck]]), np.array([slope, slope]), np.array([1.0, 0.0]), n_seg)
    down = np.array([[0.0, -1.0], [0.0, -1.0]])
    collar = _revolve(np.array([[r_head, z_neck], [r_shaft, z_neck]]), down, np.array([1.0, 0.0]), n_seg)
    radial = np.array([[1.0, 0.0], [1.0, 0.0]])
    shaft = _revolve(np.array([[r_shaft, z_neck], [r_shaft, 0.0]]), radial, np.array([1.0, 0.0]), n_seg)
    mesh = head.merged(collar, shaft, _cap(r_shaft, 0.0, n_seg, up=False))
    return mesh.transformed(translate(*start) @ _rotation_onto(axis, to / np.linalg.norm(to)))


def axes(length: float = 1.0, shaft_radius: float = 0.02, head_radius: float = 0.05, segments: int = 16) -> Mesh:
    """Three arrows along +x (red), +y (green), +z (blue) from the origin, as one mesh with vertex colors."""
    parts = []
    for i in range(3):
        direction = np.eye(3)[i]
        part = arrow(
            length=length,
            shaft_radius=shaft_radius,
            head_radius=head_radius,
            head_length=0.2 * as_scalar(length, "length", where="axes", error=GeometryError),
            segments=segments,
            direction=direction,
        )
        colors = np.tile(direction, (part.vertex_count, 1))
        parts.append(Mesh(part.vertices, part.faces, part.vertex_normals, part.uvs, colors))
    return parts[0].merged(*parts[1:])


# --- helpers ------------------------------------------------------------------------------------------------


BYTES_PER_VERTEX = 400
"""Peak bytes a tessellated primitive takes per vertex while it is built (positions, normals, UVs, two
triangles' indices, the temporaries of ``_revolve`` and ``Mesh``), a generous estimate for the budget."""


def _check_grid_memory(vertices: int, where: str, cause: str) -> None:
    """Refuse, before allocating, a tessellation of `vertices` vertices over the memory budget."""
    check_memory(vertices * BYTES_PER_VERTEX, where=where, cause=f"{cause} ({vertices} vertices)", error=GeometryError)


def _revolve(profile: NDArray, normals: NDArray, v: NDArray, segments: int) -> Mesh:
    """Sweep a (k, 2) profile of (radius, z) about z; rows run so that ∂P/∂row × ∂P/∂angle is the front."""
    theta = 2 * np.pi * np.arange(segments) / segments
    cos_t, sin_t = np.append(np.cos(theta), 1.0), np.append(np.sin(theta), 0.0)  # exact seam copy
    k, m = profile.shape[0], segments + 1
    radius, z = profile[:, 0:1], profile[:, 1:2]
    points = np.stack([radius * cos_t, radius * sin_t, np.broadcast_to(z, (k, m))], axis=-1)
    normal = np.stack([normals[:, 0:1] * cos_t, normals[:, 0:1] * sin_t, np.broadcast_to(normals[:, 1:2], (k, m))], -1)
    uv = np.stack(np.broadcast_arrays(np.arange(m)[None, :] / segments, v[:, None]), axis=-1)
    faces = _grid_faces(k, m)
    on_axis = (profile[:, 0] == 0.0).repeat(m)
    f = faces
    collapsed = (on_axis[f[:, 0]] & on_axis[f[:, 2]]) | (on_axis[f[:, 0]] & on_axis[f[:, 1]])
    collapsed |= on_axis[f[:, 1]] & on_axis[f[:, 2]]
    return _compact(points.reshape(-1, 3), faces[~collapsed], normal.reshape(-1, 3), uv.reshape(-1, 2))


def _cap(radius: float, z: float, segments: int, up: bool) -> Mesh:
    """A disk at height z facing +z (`up`) or −z, with planar UVs $(½ + x/2r, ½ ± y/2r)$."""
    nz = 1.0 if up else -1.0
    profile = np.array([[0.0, z], [radius, z]]) if up else np.array([[radius, z], [0.0, z]])
    mesh = _revolve(profile, np.array([[0.0, nz], [0.0, nz]]), np.zeros(2), segments)
    uv = 0.5 + 0.5 * mesh.vertices[:, :2] / radius * np.array([1.0, nz])
    return Mesh(mesh.vertices, mesh.faces, mesh.vertex_normals, uv)


def _compact(vertices: NDArray, faces: NDArray, normals: NDArray, uvs: NDArray) -> Mesh:
    used = np.zeros(vertices.shape[0], dtype=bool)
    used[faces.ravel()] = True
    new_index = np.cumsum(used) - 1
    return Mesh(vertices[used], new_index[faces], normals[used], uvs[used])


def _subdivide(vertices: NDArray, faces: NDArray) -> tuple[NDArray, NDArray]:
    """Split each triangle into four at its edge midpoints (shared midpoints made once), projected to r = 1."""
    edges = np.sort(faces[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
    unique, inverse = np.unique(edges, axis=0, return_inverse=True)
    midpoints = vertices[unique].mean(axis=1)
    midpoints /= np.linalg.norm(midpoints, axis=1)[:, None]
    mid = (inverse.reshape(-1) + vertices.shape[0]).reshape(-1, 3)  # midpoints of edges 01, 12, 20
    a, b, c = faces[:, 0], faces[:, 1], faces[:, 2]
    ab, bc, ca = mid[:, 0], mid[:, 1], mid[:, 2]
    new_faces = np.stack([np.stack(t, axis=1) for t in ((a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca))], axis=1)
    return np.concatenate([vertices, midpoints]), new_faces.reshape(-1, 3)


def _split_u_seam(vertices: NDArray, faces: NDArray, uv: NDArray) -> tuple[NDArray, NDArray, NDArray]:
    """Copy low-u corners of triangles straddling u = 0/1 with u + 1; give each pole corner its triangle's u."""
    faces = faces.copy()
    is_pole = np.abs(vertices[:, 2])[faces] == 1.0
    u = np.where(is_pole, np.nan, uv[:, 0][faces])
    wraps = (np.nanmax(u, axis=1) - np.nanmin(u, axis=1)) > 0.5
    u = np.where(wraps[:, None] & (u < 0.5), u + 1.0, u)
    # every corner that needs a u other than its vertex's (shifted seam corners, all pole corners) gets a copy
    needs_copy = is_pole | (wraps[:, None] & (uv[:, 0][faces] < 0.5))
    u = np.where(is_pole, np.nanmean(u, axis=1)[:, None], u)
    rows, cols = np.nonzero(needs_copy)
    source = faces[rows, cols]
    copies = np.stack([u[rows, cols], uv[source, 1]], axis=1)
    keys, slot = np.unique(np.column_stack([source, copies]), axis=0, return_inverse=True)
    faces[rows, cols] = vertices.shape[0] + slot.reshape(-1)
    vertices = np.concatenate([vertices, vertices[keys[:, 0].astype(np.int64)]])
    uv = np.concatenate([uv, keys[:, 1:]])
    used = np.zeros(vertices.shape[0], dtype=bool)
    used[faces.ravel()] = True
    remap = np.cumsum(used) - 1
    return vertices[used], remap[faces], uv[used]


def _rotation_onto(a: NDArray, b: NDArray) -> NDArray:
    """A rotation taking unit vector a onto unit vector b (a half turn about x when b = −a)."""
    axis = np.cross(a, b)
    sin = float(np.linalg.norm(axis))
    cos = float(np.dot(a, b))
    if sin < 1e-12:
        return np.eye(4) if cos > 0 else rotate((1.0, 0.0, 0.0), np.pi)
    return rotate(axis, float(np.arctan2(sin, cos)))


def _positive(value: Any, name: str, where: str) -> float:
    number = as_scalar(value, name, where=where, error=GeometryError)
    if number <= 0.0:
        raise GeometryError(f"{where}: {name} = {number!r} is not positive; give a value > 0")
    return number


def _positive_vector(value: ArrayLike, name: str, where: str) -> NDArray:
    vector = as_vector3(value, name, where=where, error=GeometryError)
    if not (vector > 0.0).all():
        raise GeometryError(f"{where}: {name} = {describe(vector)} has a component <= 0; give sizes > 0")
    return vector


def _flag(value: Any, name: str, where: str) -> bool:
    if not isinstance(value, bool | np.bool_):
        raise GeometryError(f"{where}: {name} = {describe(value)} is not a boolean; give True or False")
    return bool(value)


def _pair(value: Any, name: str, where: str, as_float: bool) -> tuple[Any, Any]:
    if np.ndim(value) == 0:
        value = (value, value)
    items = list(np.asarray(value, dtype=object).ravel()) if np.ndim(value) == 1 else None
    if items is None or len(items) != 2:
        raise GeometryError(f"{where}: {name} = {describe(value)} is not one or two values; give (x, y)")
    if as_float:
        return tuple(as_scalar(item, f"{name}[{i}]", where=where, error=GeometryError) for i, item in enumerate(items))
    return tuple(as_count(item, f"{name}[{i}]", 1, where=where) for i, item in enumerate(items))
