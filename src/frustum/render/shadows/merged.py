"""Several placed meshes as one world-space mesh, for the passes that draw them all in one go: the depth-only fill
of a shadow map (every opaque caster binned and filled in one pass from the light, ``fractions.draw_depth``) and
the tile pipeline with shadows of a frame of several opaque items (``passes.draw_tiled``).

The items' world positions and unit world normals (``stages.world_attributes``, the arrays the stage-by-stage
shading reads) are concatenated in item order, their counter-clockwise faces (``stages.world_faces``) offset by the
vertices before them; ``owner`` gives each face its item's position in the list. Item order is kept, so where two
items' surfaces tie in depth the earlier one stays drawn, as when they are drawn one after another. The result is
kept under the items' ``casters_key`` (their bytes and transforms) for the next frame (a static scene merges once).
"""

from __future__ import annotations

import threading
from typing import NamedTuple

import numpy as np

from frustum.geometry import Mesh
from frustum.render.buffers import Scratch
from frustum.render.stages import world_attributes, world_faces
from frustum.scene import SceneItem
from frustum.scene.graph import IDENTITY

__all__ = ["Merged", "merge"]


class Merged(NamedTuple):
    """Placed meshes as one: ``item`` (world positions, identity transform, the first item's material),
    ``normals`` (V, 3) the unit world normals, ``owner`` (F,) int32 each face's item (position in the list)."""

    item: SceneItem
    normals: np.ndarray
    owner: np.ndarray


_KEPT: dict[tuple, Merged] = {}
_LOCK = threading.Lock()
KEPT_MERGES = 4
"""How many merged item lists are kept for later frames."""


def merge(items: list[SceneItem], key: tuple | None) -> Merged:
    """`items` (placed meshes with faces) as one world-space mesh (the module's docstring); kept under `key` (a
    tuple of the items' ``casters_key``, None: not kept)."""
    if key is not None:
        with _LOCK:
            found = _KEPT.get(key)
        if found is not None:
            return found
    scratch = Scratch()  # its arrays are copied out below and not given to the pool
    worlds, normals, faces, owner = [], [], [], []
    start = 0
    for position, item in enumerate(items):
        world, normal = world_attributes(item, scratch)
        worlds.append(np.asarray(world, dtype=np.float64))
        normals.append(np.asarray(normal, dtype=np.float64))
        faces.append(world_faces(item) + start)
        owner.append(np.full(item.mesh.face_count, position, dtype=np.int32))
        start += item.mesh.vertex_count
    vertices = np.concatenate(worlds)
    unit = np.concatenate(normals)
    mesh = Mesh(vertices, np.concatenate(faces), vertex_normals=unit, copy=False)
    merged = Merged(SceneItem(mesh, items[0].material, IDENTITY), unit, np.concatenate(owner))
    if key is not None:
        with _LOCK:
            while len(_KEPT) >= KEPT_MERGES:
                _KEPT.pop(next(iter(_KEPT)))
            _KEPT[key] = merged
    return merged


def release() -> int:
    """Forget the merged lists kept for later frames; return their bytes."""
    with _LOCK:
        released = sum(m.item.mesh.vertices.nbytes + m.item.mesh.faces.nbytes + m.normals.nbytes + m.owner.nbytes
                       for m in _KEPT.values())  # fmt: skip
        _KEPT.clear()
    return released
