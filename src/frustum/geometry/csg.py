"""Constructive solid geometry: union, difference and intersection of closed meshes through manifold3d.

Each operand is first welded (vertices at the same position become one, so seams that primitives split for
UVs or sharp normals close up) and must then be watertight and outward-facing (positive volume). The boolean
itself is computed by manifold3d, which is exact about topology and always returns a closed, oriented
2-manifold. Result normals are area-weighted but split along edges sharper than `sharp_angle`, so boxes
stay flat-shaded and spheres smooth. UVs and vertex colors of the operands are not carried over.

References
----------
[seed] "General Modeling Techniques: Constructive Solid Geometry".
[HB 15] "Constructive Solid-Geometry Methods".
"""

from __future__ import annotations

from typing import Any

import numpy as np

from frustum._arrays import as_scalar, describe
from frustum.errors import GeometryError
from frustum.geometry.mesh import Mesh

__all__ = ["difference", "intersection", "union"]


def union(a: Mesh, b: Mesh, *others: Mesh, sharp_angle: float = 60.0) -> Mesh:
    """``A ∪ B ∪ …``: the points inside any of the solids.

    Parameters
    ----------
    a, b, *others : Mesh
        Closed, consistently outward-wound meshes (``Mesh.is_watertight`` after welding; positive volume).
    sharp_angle : float
        Dihedral angle in degrees (0 … 180) above which an edge is drawn sharp (normals split there).

    Raises
    ------
    GeometryError
        An operand that is not a Mesh, not closed (open, or edges shared by more than two faces), or inside out.
    """
    return _boolean("union", (a, b, *others), sharp_angle)


def difference(a: Mesh, b: Mesh, *others: Mesh, sharp_angle: float = 60.0) -> Mesh:
    """$A − B − …$: the points inside `a` and outside every other solid. Parameters as for ``union``."""
    return _boolean("difference", (a, b, *others), sharp_angle)


def intersection(a: Mesh, b: Mesh, *others: Mesh, sharp_angle: float = 60.0) -> Mesh:
    """``A ∩ B ∩ …``: the points inside every solid (may be empty). Parameters as for ``union``."""
    return _boolean("intersection", (a, b, *others), sharp_angle)


def _boolean(where: str, meshes: tuple[Any, ...], sharp_angle: Any) -> Mesh:
    import manifold3d

    angle = as_scalar(sharp_angle, "sharp_angle", where=where, error=GeometryError)
    if not 0.0 <= angle <= 180.0:
        raise GeometryError(f"{where}: sharp_angle = {angle!r} is outside [0, 180]; give degrees in [0, 180]")
    solids = [_to_manifold(manifold3d, mesh, f"meshes[{i}]", where) for i, mesh in enumerate(meshes)]
    result = solids[0]
    for solid in solids[1:]:
        if where == "union":
            result = result + solid
        elif where == "difference":
            result = result - solid
        else:
            result = result ^ solid
    if result.is_empty():
        return Mesh(np.empty((0, 3)), np.empty((0, 3), dtype=np.int64))
    out = result.calculate_normals(0, angle).to_mesh64()
    properties = np.asarray(out.vert_properties, dtype=np.float64)
    faces = np.asarray(out.tri_verts, dtype=np.int64)
    normals = properties[:, 3:6]
    lengths = np.linalg.norm(normals, axis=1)
    normals = np.where(lengths[:, None] > 0.0, normals, [0.0, 0.0, 1.0])
    return Mesh(np.ascontiguousarray(properties[:, :3]), faces, normals)


def _to_manifold(manifold3d: Any, mesh: Any, name: str, where: str) -> Any:
    if not isinstance(mesh, Mesh):
        raise GeometryError(f"{where}: {name} = {describe(mesh)} is not a Mesh; give closed frustum meshes")
    solid = mesh.welded()
    if not solid.is_watertight:
        raise GeometryError(
            f"{where}: {name} (a mesh with {mesh.face_count} faces) is not a closed manifold: it has boundary "
            "edges, edges shared by more than two faces, or inconsistent winding; CSG needs closed solids"
        )
    if solid.volume <= 0.0:
        raise GeometryError(
            f"{where}: {name} has volume = {solid.volume!r} <= 0 (its faces wind inward); use mesh.flipped()"
        )
    data = manifold3d.Mesh64(
        vert_properties=np.array(solid.vertices, dtype=np.float64, order="C"),
        tri_verts=np.array(solid.faces, dtype=np.uint64, order="C"),
    )
    result = manifold3d.Manifold(data)
    status = result.status()
    if status != manifold3d.Error.NoError:
        raise GeometryError(f"{where}: {name} is rejected by manifold3d ({status.name}); CSG needs closed 2-manifolds")
    return result
