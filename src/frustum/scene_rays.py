"""Ray queries on a scene: the triangle index of its meshes, ``Scene.intersect`` and ``Scene.occluded``.

The index (``raster.rays``: a SAH bounding-volume hierarchy over every placed mesh's world triangles, collapsed
to four-wide nodes for the traversal) is built on first use and kept on the scene until its meshes or their
transforms change; ``Scene.pick``, ``Scene.intersect``, ``Scene.occluded`` and ``render(...,
method="ray-casting"/"ray-tracing")`` share it. ``intersect`` asks the kernel for the ``RayHits`` columns wanted
(``fields``), each computed in the traversal's own pass (``raster.rays.intersect``); nothing is assembled
afterwards in NumPy. Per call, Python only checks the arguments.

Why a module of its own: the scene (``frustum.scene``) places things; this is what is asked of them by rays.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from frustum._arrays import describe
from frustum.errors import FrustumError, GeometryError

__all__ = ["RAY_FIELDS", "RayHits", "check_rays", "intersect", "occluded", "triangle_index"]

RAY_FIELDS = ("t", "item", "face", "barycentrics", "point", "normal", "shading_normal", "back")
"""The columns of ``RayHits``, the names ``Scene.intersect(..., fields=...)`` takes."""


class RayHits(NamedTuple):
    """What ``Scene.intersect`` finds for N rays (a miss: t = inf, item = face = −1, the other fields NaN).

    ``t`` (N,) distance along each ray in units of its direction's length ($point = origin + t·direction$);
    ``item`` (N,) index into ``Scene.items``; ``face`` (N,) the face index in that item's mesh;
    ``barycentrics`` (N, 3) the weights of the face's corners 0, 1, 2 (in the mesh's corner order) at the hit;
    ``point`` (N, 3) the world point; ``normal`` (N, 3) the **geometric** unit normal: the face's plane normal in
    world coordinates, on its front side (counter-clockwise corners, as the renderer draws it), whichever side
    the ray meets; ``shading_normal`` (N, 3) the **interpolated** unit normal: the mesh's vertex normals in world
    coordinates (inverse transpose of the modeling matrix) blended by the barycentrics, as Phong shading
    interpolates them; ``back`` (N,) bool, True where the ray meets the face's back (direction · normal > 0).
    A field left out of ``Scene.intersect``'s `fields` is None."""

    t: NDArray[np.float64]
    item: NDArray[np.int64]
    face: NDArray[np.int64]
    barycentrics: NDArray[np.float64]
    point: NDArray[np.float64]
    normal: NDArray[np.float64]
    shading_normal: NDArray[np.float64]
    back: NDArray[np.bool_]


def _is_numeric(value: Any) -> bool:
    try:
        array = np.asarray(value)
    except (TypeError, ValueError):
        return False
    return array.dtype.kind in "biuf"


def check_rays(origins: Any, directions: Any, where: str) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(N, 3) float64 origins and directions from (N, 3) or (3,) rows; FrustumError naming the bad one."""
    result = []
    for name, value in (("origins", origins), ("directions", directions)):
        array = np.asarray(value, dtype=np.float64) if _is_numeric(value) else None
        if array is None or array.ndim not in (1, 2) or array.shape[-1] != 3:
            raise FrustumError(f"{where}: {name} = {describe(value)} is not (N, 3) or (3,) numbers")
        if not np.isfinite(array).all():
            raise FrustumError(f"{where}: {name} has a value that is not finite (NaN or inf)")
        result.append(np.ascontiguousarray(array.reshape(-1, 3)))
    o, d = result
    if o.shape[0] != d.shape[0]:
        if o.shape[0] == 1:
            o = np.ascontiguousarray(np.broadcast_to(o, d.shape))
        elif d.shape[0] == 1:
            d = np.ascontiguousarray(np.broadcast_to(d, o.shape))
        else:
            raise FrustumError(f"{where}: {o.shape[0]} origins and {d.shape[0]} directions; give one of each per ray")
    zero = (d[:, 0] == 0.0) & (d[:, 1] == 0.0) & (d[:, 2] == 0.0)  # (a column at a time: 6× faster than any(axis=1))
    if zero.any():
        raise FrustumError(f"{where}: directions[{int(np.argmax(zero))}] is zero; a ray needs a direction")
    return o, d


def _fields(fields: Iterable[str] | None, where: str) -> int:
    """The bit mask of ``raster.rays.FIELDS`` for `fields` (None: all)."""
    if fields is None:
        return (1 << len(RAY_FIELDS)) - 1
    names = [fields] if isinstance(fields, str) else list(fields) if isinstance(fields, Iterable) else None
    if names is None or not names:
        raise FrustumError(f"{where}: fields = {describe(fields)} is not a non-empty list of names from {RAY_FIELDS}")
    wanted = 0
    for name in names:
        if name not in RAY_FIELDS:
            raise FrustumError(f"{where}: fields has {describe(name)}; expected names from {RAY_FIELDS}")
        wanted |= 1 << RAY_FIELDS.index(name)
    return wanted


def triangle_index(scene: Any, where: str = "Scene.pick") -> tuple[list[Any], Any, np.ndarray] | None:
    """The scene's triangle index: ``(items, index, starts)`` or None when no mesh has a face.

    `items` are ``scene.items`` that have faces, `index` the ``raster.rays.Index`` of all their triangles in
    world coordinates (item by item, face by face: triangle ``starts[k] + f`` is face f of ``items[k]``, the
    renderer's face numbering), corners counter-clockwise seen from the front after the modeling transform
    (corners 1 and 2 swapped where it reverses handedness, as the renderer draws them). Built once and kept on the
    scene (``scene._pick_index``: key, index, starts, meshes, item numbers, swapped flags) until its meshes or
    transforms change; its memory is checked against the work budget first.

    Raises
    ------
    GeometryError
        The index would exceed the memory budget (``frustum.budgets``).
    """
    from frustum.budgets import check_memory
    from frustum.raster import rays

    every = scene.items
    numbers = np.array([i for i, item in enumerate(every) if item.mesh.face_count], dtype=np.int64)
    items = [every[i] for i in numbers]
    if not items:
        return None
    key = tuple((id(item.mesh), item.world_from_model.tobytes()) for item in items)
    cached = getattr(scene, "_pick_index", None)
    if cached is None or cached[0] != key:
        count = sum(item.mesh.face_count for item in items)
        check_memory(3 * 72 * count + rays.memory_bytes(count), where=where,
                     cause=f"a triangle index (BVH) over {count} triangles", error=GeometryError)  # fmt: skip
        corners = []
        swapped = []
        for item in items:
            matrix = np.asarray(item.world_from_model, dtype=np.float64)
            faces = item.mesh.faces
            swapped.append(bool(np.linalg.det(matrix[:3, :3]) < 0.0))
            if swapped[-1]:
                faces = faces[:, [0, 2, 1]]
            corners.append(item.mesh.vertices[faces] @ matrix[:3, :3].T + matrix[:3, 3])
        starts = np.cumsum([0] + [c.shape[0] for c in corners])
        cached = (key, rays.build(np.concatenate(corners)), starts, [item.mesh for item in items], numbers,
                  np.array(swapped, dtype=bool))  # fmt: skip
        scene._pick_index = cached
        scene._ray_normals = None
    index, starts = cached[1], cached[2]
    return items, index, starts


def _vertex_normals(scene: Any, items: list[Any]) -> tuple[np.ndarray, np.ndarray]:
    """(face_vertices (F, 3) int64, vertex_normals (V, 3) float64): every item's faces numbered into one list of
    its vertex normals in world coordinates ($N_world = (M₃⁻¹)ᵀ·N$, M₃ the modeling matrix's linear part), item by
    item as the index numbers triangles; made when a shading normal is first asked for and kept with the index."""
    cached = getattr(scene, "_ray_normals", None)
    if cached is None:
        faces, normals, offset = [], [], 0
        for item in items:
            matrix = np.asarray(item.world_from_model, dtype=np.float64)
            normals.append(item.mesh.vertex_normals @ np.linalg.inv(matrix[:3, :3]))  # (M⁻¹)ᵀ·n as rows: n·M⁻¹
            faces.append(np.asarray(item.mesh.faces, dtype=np.int64) + offset)
            offset += item.mesh.vertices.shape[0]
        cached = (np.ascontiguousarray(np.concatenate(faces)), np.ascontiguousarray(np.concatenate(normals)))
        scene._ray_normals = cached
    return cached


def intersect(scene: Any, origins: Any, directions: Any, fields: Iterable[str] | None = None) -> RayHits:
    """``Scene.intersect``: the first surface each ray meets, the `fields` asked for (None: all)."""
    from frustum.raster import rays

    where = "Scene.intersect"
    o, d = check_rays(origins, directions, where)
    wanted = _fields(fields, where)
    count = o.shape[0]
    found = triangle_index(scene, where=where)
    if found is None or count == 0:
        misses = {"t": np.full(count, np.inf), "item": np.full(count, -1, dtype=np.int64),
                  "face": np.full(count, -1, dtype=np.int64), "back": np.zeros(count, dtype=bool)}  # fmt: skip
        return RayHits(*(misses.get(name, np.full((count, 3), np.nan)) if wanted >> bit & 1 else None
                         for bit, name in enumerate(RAY_FIELDS)))  # fmt: skip
    items, index, starts = found
    numbers, swapped = scene._pick_index[4], scene._pick_index[5]
    shading = wanted >> RAY_FIELDS.index("shading_normal") & 1
    face_vertices, vertex_normals = _vertex_normals(scene, items) if shading else (np.empty((0, 3), np.int64),
                                                                                     np.empty((0, 3)))  # fmt: skip
    columns = rays.intersect(index, o, d, wanted, np.ascontiguousarray(starts, dtype=np.int64), numbers,
                             swapped.view(np.uint8), face_vertices, vertex_normals)  # fmt: skip
    if "back" in columns:
        columns["back"] = columns["back"].view(np.bool_)
    return RayHits(*(columns.get(name) for name in RAY_FIELDS))


def occluded(scene: Any, origins: Any, directions: Any, t_max: Any) -> NDArray[np.bool_]:
    """``Scene.occluded``: whether each ray meets a surface at some 0 <= t < `t_max`."""
    from frustum.raster import rays

    where = "Scene.occluded"
    o, d = check_rays(origins, directions, where)
    count = o.shape[0]
    limit = np.asarray(t_max, dtype=np.float64) if _is_numeric(t_max) else None
    if limit is None or limit.ndim > 1 or (limit.ndim == 1 and limit.shape[0] != count):
        raise FrustumError(f"{where}: t_max = {describe(t_max)} is not a number or one number per ray ({count})")
    if np.isnan(limit).any() or (limit < 0.0).any():
        raise FrustumError(f"{where}: t_max = {describe(t_max)} has a value below 0 or NaN; expected t_max >= 0")
    found = triangle_index(scene, where=where)
    if found is None or count == 0:
        return np.zeros(count, dtype=bool)
    return rays.any_hits(found[1], o, d, 0.0, limit)
