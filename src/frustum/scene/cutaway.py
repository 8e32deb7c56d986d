"""Exploded and cutaway views of a scene: parts moved apart from the assembly's centre, or cut by a plane or a box
(meshes sliced and capped, volumes clipped), each returning a new scene.

References: [HB 11] "Hierarchical Modeling"; [seed] "exploded and cutaway views".
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from frustum._arrays import Matrix4, as_scalar, as_vector3, describe
from frustum.errors import FrustumError, GeometryError
from frustum.geometry import Mesh, Polyline
from frustum.scene.graph import IDENTITY, Node, Scene, VolumeItem, is_octree, modeling_transform
from frustum.shading import Material
from frustum.transforms import translate

__all__ = ["cutaway", "exploded"]


def _world_centroid(node: Node, world: Matrix4) -> np.ndarray | None:
    """Area-weighted centroid of every mesh at or below `node` in world coordinates (None if no area)."""
    total, weighted = 0.0, np.zeros(3)
    stack = [(node, world)]
    while stack:
        current, m = stack.pop()
        stack.extend((child, m @ child.transform) for child in current.children)
        mesh = current.geometry
        if not isinstance(mesh, Mesh) or mesh.face_count == 0:
            continue
        points = mesh.vertices @ m[:3, :3].T + m[:3, 3]
        corners = points[mesh.faces]
        areas = 0.5 * np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]), axis=1)
        total += areas.sum()
        weighted += (areas[:, None] * corners.mean(axis=1)).sum(axis=0)
    return weighted / total if total > 0.0 else None


def exploded(target: Scene | Node, factor: float, center: ArrayLike | None = None) -> Scene | Node:
    """An exploded view: each part moved away from the assembly center by $factor·(c_part − center)$.

    The parts of a node are its children; each child's world centroid ``c_part`` (area-weighted) moves by
    $factor·(c_part − center)$ in world space, ``center`` being the assembly's centroid unless given.
    Hierarchy-aware: a child with children (a sub-assembly) is then exploded within itself about its own
    centroid. Returns a new scene or node; the original is not changed. $factor = 0$ gives the same transforms.
    """
    where = "exploded"
    amount = as_scalar(factor, "factor", where=where, error=GeometryError)
    given = None if center is None else as_vector3(center, "center", where=where, error=GeometryError)
    if isinstance(target, Scene):
        return target._with_root(_explode(target.root.copy(), IDENTITY, amount, given))
    if not isinstance(target, Node):
        raise FrustumError(f"{where}: target = {describe(target)} is not a Scene or Node")
    return _explode(target.copy(), IDENTITY, amount, given)


def _explode(node: Node, parent_world: Matrix4, factor: float, center: np.ndarray | None) -> Node:
    world = parent_world @ node.transform
    if center is None:
        center = _world_centroid(node, world)
    for child in node.children:
        child_world = world @ child.transform
        centroid = _world_centroid(child, child_world)
        if center is not None and centroid is not None:
            offset = factor * (centroid - center)
            # a world-space shift in the parent's frame: W⁻¹·T(o)·W = T(A⁻¹·o) for the affine W = [A t]
            local = translate(*np.linalg.solve(world[:3, :3], offset))
            child.transform = modeling_transform(local @ child.transform, "exploded")
        if child.children:
            _explode(child, world, factor, None)
    return node


def cutaway(
    scene: Scene,
    plane: tuple[ArrayLike, ArrayLike] | None = None,
    box: tuple[ArrayLike, ArrayLike] | None = None,
    *,
    cap: bool = True,
    ghost: Material | float | None = None,
    hatch: float | None = 6.0,
) -> Scene:
    """A cutaway view: geometry on the side of $plane = (point, normal)$ the normal points to, or inside the
    axis-aligned world $box = (min_corner, max_corner)$, is removed.

    Each mesh is cut in world coordinates (the result's nodes keep the hierarchy; cut meshes are placed with
    their node's world transform baked in). With ``cap`` a closed (watertight) mesh gets its cross-section
    filled (section caps), so solids stay solid; open meshes are cut without caps. With ``ghost`` (an opacity
    in (0, 1) or a Material) the removed part is kept, semi-transparent, instead of dropped. Cutting keeps
    positions and recomputes normals; UVs and vertex colors of cut meshes are not kept. Polylines are kept
    whole (not cut). The section caps hang on a child node ``"<name>:section"`` whose material is the part's
    with ``hatch`` set (45° section lines of that spacing in filled vector output; None: no hatching).
    Placed volumes (``Scene.add_volume``) get a plane cut as a clip plane; a box cut leaves them whole.
    """
    where = "cutaway"
    if (plane is None) == (box is None):
        raise GeometryError(f"{where}: give exactly one of plane = (point, normal) or box = (min, max)")
    if plane is not None:
        point = as_vector3(plane[0], "plane point", where=where, error=GeometryError)
        normal = as_vector3(plane[1], "plane normal", where=where, error=GeometryError)
        if not np.linalg.norm(normal) > 0.0:
            raise GeometryError(f"{where}: plane normal = {describe(normal)} has zero length; give a nonzero normal")
        region: tuple = ("plane", point, normal / np.linalg.norm(normal))
    else:
        low = as_vector3(box[0], "box min", where=where, error=GeometryError)
        high = as_vector3(box[1], "box max", where=where, error=GeometryError)
        if not (low < high).all():
            raise GeometryError(f"{where}: box = {describe(low)}, {describe(high)} is empty; need min < max per axis")
        region = ("box", low, high)
    ghost_material = None
    if ghost is not None and not isinstance(ghost, Material):
        opacity = as_scalar(ghost, "ghost", where=where, error=GeometryError)
        if not 0.0 < opacity < 1.0:
            raise GeometryError(f"{where}: ghost = {opacity!r} is not an opacity in (0, 1) or a Material")
        ghost_material = opacity
    elif ghost is not None:
        ghost_material = ghost
    if hatch is not None:
        hatch = as_scalar(hatch, "hatch", where=where, error=GeometryError)
        if not hatch > 0.0:
            raise GeometryError(f"{where}: hatch = {hatch!r} is not a positive spacing; give a number > 0 or None")
    result = Scene()
    result.root.lights = list(scene.root.lights)
    result.volumes = [_cut_volume(item, region) for item in scene.volumes]
    _cut_node(scene.root, result.root, IDENTITY, Material(), region, cap, ghost_material, hatch)
    return result


def _cut_volume(item: VolumeItem, region: tuple) -> VolumeItem:
    """The volume with a plane cut added to its clip planes (the ray caster clips to half-spaces; what a box cut
    keeps is not convex, so volumes stay whole under a box cut)."""
    if region[0] != "plane":
        return item
    planes = np.concatenate([item.clip_planes, np.array([[region[1], region[2]]])])
    return item._replace(clip_planes=planes)


def _cut_node(
    source: Node, target: Node, parent_world: Matrix4, inherited: Material, region: tuple, cap: bool, ghost: Any,
    hatch: float | None,
) -> None:  # fmt: skip
    world = parent_world @ source.transform
    material = source.material if source.material is not None else inherited
    for child in source.children:
        copy = Node(child.name, None, None, None, lights=[light.transformed(world @ child.transform)
                                                          for light in child.lights], label=child.label)  # fmt: skip
        child_world = world @ child.transform
        child_material = child.material if child.material is not None else material
        if isinstance(child.geometry, Polyline):  # kept whole, baked into world coordinates like the meshes
            line = child.geometry
            points = line.points @ child_world[:3, :3].T + child_world[:3, 3]
            copy.geometry = Polyline(points, line.closed, line.markers)
            copy.material = child_material
        elif child.geometry is not None:
            mesh = child.geometry.surface if is_octree(child.geometry) else child.geometry  # its cell faces
            kept, removed = _cut_mesh(mesh, child_world, region, cap)
            if kept is not None:
                body, section = _split_section(kept, region) if cap else (kept, None)
                copy.geometry = body
                copy.material = child_material
                if section is not None:
                    copy.add(Node(child.name + ":section", None, section, child_material.with_(hatch=hatch)))
            if removed is not None and ghost is not None:
                ghost_material = ghost if isinstance(ghost, Material) else child_material.with_(opacity=ghost)
                copy.add(Node(child.name + ":ghost", None, removed, ghost_material))
        target.add(copy)
        _cut_node(child, copy, child_world, child_material, region, cap, ghost, hatch)
        # the copy holds world-space geometry: children were cut in world space too, so no transforms remain


def _cut_mesh(mesh: Mesh, world: Matrix4, region: tuple, cap: bool) -> tuple[Mesh | None, Mesh | None]:
    """(kept, removed) parts of `mesh` placed by `world`, in world coordinates; None where empty."""
    import trimesh

    if mesh.face_count == 0:
        return None, None
    points = mesh.vertices @ world[:3, :3].T + world[:3, 3]
    solid = trimesh.Trimesh(points, mesh.faces, process=False)
    solid.merge_vertices(merge_tex=True, merge_norm=True)  # meshes split vertices at UV and normal seams
    closed = cap and solid.is_watertight
    if region[0] == "plane":
        _, point, normal = region
        kept = _slice(solid, point, -normal, closed)
        removed = _slice(solid, point, normal, closed)
    else:
        _, low, high = region
        box = trimesh.creation.box(bounds=[low, high])
        if closed:
            try:
                kept = solid.difference(box, engine="manifold")
                removed = solid.intersection(box, engine="manifold")
            except Exception as error:  # manifold3d refuses inputs it cannot repair
                raise GeometryError(f"cutaway: box cut of a closed mesh failed ({error}); try cap=False") from None
        else:
            kept, inside = _outside_box(solid, low, high)
            removed = inside
    return _as_mesh(kept), _as_mesh(removed)


def _split_section(mesh: Mesh, region: tuple) -> tuple[Mesh | None, Mesh | None]:
    """(body, section caps) of a cut mesh: the caps are the faces lying in the cutting plane (or a box face)."""
    corners = mesh.vertices[mesh.faces]  # (M, 3, 3)
    scale = max(float(np.abs(mesh.vertices).max()), 1.0)
    tolerance = 1e-9 * scale
    if region[0] == "plane":
        _, point, normal = region
        on = (np.abs((corners - point) @ normal) <= tolerance).all(axis=1)
    else:
        _, low, high = region
        inside = ((corners >= low - tolerance) & (corners <= high + tolerance)).all(axis=(1, 2))
        on_face = np.zeros(len(corners), dtype=bool)
        for axis in range(3):
            for value in (low[axis], high[axis]):
                on_face |= (np.abs(corners[:, :, axis] - value) <= tolerance).all(axis=1)
        on = inside & on_face
    if not on.any():
        return mesh, None
    body = Mesh(mesh.vertices, mesh.faces[~on]) if (~on).any() else None
    return body, Mesh(mesh.vertices, mesh.faces[on])


def _slice(solid: Any, point: np.ndarray, keep_normal: np.ndarray, cap: bool) -> Any:
    """The part of `solid` on the side `keep_normal` points to (trimesh keeps the positive side)."""
    if solid is None or len(solid.faces) == 0:
        return None
    try:
        return solid.slice_plane(point, keep_normal, cap=cap)
    except Exception as error:  # trimesh's capping (triangulating the section loops) can fail on odd sections
        raise GeometryError(
            f"cutaway: plane through {describe(point)} cuts a mesh of {len(solid.faces)} faces but the section cap "
            f"fails ({type(error).__name__}: {error}); try cap=False"
        ) from None


def _outside_box(solid: Any, low: np.ndarray, high: np.ndarray) -> tuple[Any, Any]:
    """Open-mesh box cut: outside = ∪_k (inside planes 0..k−1) ∩ (outside plane k); inside = the rest."""
    import trimesh

    pieces = []
    remaining = solid
    planes = [(low, np.array(n)) for n in np.eye(3)] + [(high, -np.array(n)) for n in np.eye(3)]
    for point, inward in planes:
        if remaining is None or len(remaining.faces) == 0:
            break
        outside = _slice(remaining, point, -inward, False)
        if outside is not None and len(outside.faces):
            pieces.append(outside)
        remaining = _slice(remaining, point, inward, False)
    kept = trimesh.util.concatenate(pieces) if pieces else None
    return kept, remaining


def _as_mesh(part: Any) -> Mesh | None:
    if part is None or len(part.faces) == 0:
        return None
    return Mesh(np.asarray(part.vertices, dtype=np.float64), np.asarray(part.faces, dtype=np.int64))
