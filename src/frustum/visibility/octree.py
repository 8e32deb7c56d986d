"""The octree visible-surface method: draw a solid octree front to back, each pixel written once.

[HB 16] "Octree Methods": traverse the octree so that the octants nearer the viewer are processed first; a
pixel is written only where nothing nearer was written, and nodes whose screen area is already covered are
skipped. The child order is chosen per node from the eye position (in the octree's model coordinates): the
child on the eye's side of the node's three mid-planes first, then those across one plane, two, three
(``mask XOR c`` for c = 0 … 7), which is correct for perspective views too (a cell can hide only cells behind
the mid-planes that separate it from the eye). The drawn faces of a full cell are those facing the eye; each
face orientation (±x, ±y, ±z) is shaded once with ``frustum.shading.illuminate`` at the octree's centre.

The kernel is ``raster.octree.draw_octree`` (serial: the traversal order is the method).
"""

from __future__ import annotations

import contextlib
import contextvars
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from frustum._arrays import as_matrix, describe
from frustum.camera import Camera
from frustum.errors import FrustumError
from frustum.frame import Frame, background_bytes
from frustum.geometry.octree import Octree
from frustum.shading import LIGHT_TYPES, DirectionalLight, Light, Material, illuminate
from frustum.visibility.recording import recording_into

__all__ = ["draw_octree_into", "octree_face_colors", "recording", "render_octree"]

_RECORDING: contextvars.ContextVar[list[np.ndarray] | None] = contextvars.ContextVar("octree_log", default=None)


def recording() -> contextlib.AbstractContextManager[list[np.ndarray]]:
    """Recording mode (``frustum.steps``): every ``draw_octree_into`` inside the block appends its traversal log,
    an (N, 4) int64 array of ``(level, Morton code, outcome, pixels drawn)`` per node visited in order
    (``raster.octree.draw_octree``)."""
    return recording_into(_RECORDING)

_AXES = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], dtype=np.float64)
_DEFAULT_LIGHTS: tuple[Light, ...] = (DirectionalLight((-0.4, -0.6, -1.0)),)


def octree_face_colors(
    octree: Octree, material: Material, lights: list[Light], world_from_model: np.ndarray, eye: ArrayLike
) -> np.ndarray:
    """(6, 4) uint8 RGBA of the faces facing +x, −x, +y, −y, +z, −z: ``illuminate`` once per orientation, at the
    octree's centre, with the world normal $(M⁻¹)ᵀ·n$ of the face's model normal n."""
    normal_matrix = np.linalg.inv(world_from_model[:3, :3]).T
    center = world_from_model[:3, :3] @ octree.bounds.mean(axis=0) + world_from_model[:3, 3]
    colors = np.empty((6, 4), dtype=np.uint8)
    for f, axis in enumerate(_AXES):
        rgb = illuminate(material, list(lights), center, normal_matrix @ axis, eye)
        colors[f, :3] = np.floor(rgb * 255.0 + 0.5)
        colors[f, 3] = 255
    return colors


def draw_octree_into(
    octree: Octree, camera: Camera, world_from_model: np.ndarray, face_rgba: np.ndarray, color: np.ndarray,
    depth: np.ndarray, written: np.ndarray,
) -> int:  # fmt: skip
    """Draw `octree` into caller-owned buffers (pixels already `written` stay); returns the nodes visited."""
    from frustum.raster import octree as kernels
    from frustum.visibility import viewing_position

    height, width = camera.height, camera.width
    full_offsets = np.cumsum([0] + [c.size for c in octree.full]).astype(np.int64)
    partial_offsets = np.cumsum([0] + [c.size for c in octree.partial]).astype(np.int64)
    clip_from_model = camera.clip_from_world @ world_from_model
    eye_world = viewing_position(camera)
    eye_model = np.linalg.inv(world_from_model) @ eye_world
    params = np.concatenate([
        octree.bounds[0], [octree.size, octree.depth], clip_from_model.ravel(), eye_model, [width, height]
    ])  # fmt: skip
    tiles = -(-height // kernels.TILE), -(-width // kernels.TILE)
    tile_counts = np.zeros(tiles, dtype=np.int32)
    if written.any():
        padded = np.zeros((tiles[0] * kernels.TILE, tiles[1] * kernels.TILE), dtype=np.int32)
        padded[:height, :width] = written
        tile_counts[:] = padded.reshape(tiles[0], kernels.TILE, tiles[1], kernels.TILE).sum(axis=(1, 3))
    full_codes = np.concatenate([np.asarray(c, dtype=np.uint64) for c in octree.full])
    partial_codes = np.concatenate([np.asarray(c, dtype=np.uint64) for c in octree.partial])
    logs = _RECORDING.get()
    # a full node crossing the near plane is visited through its children, which are no nodes of the octree:
    # room for eight times the nodes (a longer traversal keeps its first rows)
    log = np.full((8 * octree.node_count + 64 if logs is not None else 0, 4), -1, dtype=np.int64)
    rgba = np.ascontiguousarray(face_rgba)
    visited = int(kernels.draw_octree(full_codes, full_offsets, partial_codes, partial_offsets, params, rgba, color,
                                      depth, written, tile_counts, log))  # fmt: skip
    if logs is not None:
        logs.append(log[: min(visited, log.shape[0])])
    return visited


def render_octree(
    octree: Octree,
    camera: Camera,
    *,
    material: Material | None = None,
    lights: list[Light] | None = None,
    world_from_model: ArrayLike | None = None,
    background: Any = (0.0, 0.0, 0.0, 1.0),
) -> Frame:
    """Draw `octree` by the octree visible-surface method into a ``Frame`` (color and window depth).

    Parameters
    ----------
    octree : Octree
    camera : Camera
    material : Material, optional
        Default ``Material()``.
    lights : list of lights, optional
        World-space lights; default one directional light along (−0.4, −0.6, −1).
    world_from_model : (4, 4) array_like, optional
        Affine placement of the octree (default identity); the traversal order uses the eye mapped back
        into the octree's coordinates.
    background : (4,) array_like
        RGBA in [0, 1] where no cell is seen.

    Returns
    -------
    Frame
        ``depth`` is the window depth of the nearest cell face (1.0 elsewhere), as the depth buffer would
        store it; cells crossing the near plane are drawn only through their children in front of it.

    References
    ----------
    [HB 16] "Octree Methods"; [seed] "Octree methods" (visible-surface detection).
    """
    where = "render_octree"
    if not isinstance(octree, Octree):
        raise FrustumError(f"{where}: octree = {describe(octree)} is not an Octree; build one with Octree.from_mesh")
    if not isinstance(camera, Camera):
        raise FrustumError(f"{where}: camera = {describe(camera)} is not a Camera; build one with Camera.look_at")
    material = Material() if material is None else material
    if not isinstance(material, Material):
        raise FrustumError(f"{where}: material = {describe(material)} is not a Material; build one with Material()")
    lights = list(_DEFAULT_LIGHTS if lights is None else lights)
    if not all(isinstance(light, LIGHT_TYPES) for light in lights):
        raise FrustumError(f"{where}: lights = {describe(lights)} holds a non-light; give AmbientLight, "
                           "DirectionalLight, PointLight or SpotLight objects")  # fmt: skip
    matrix = np.eye(4) if world_from_model is None else as_matrix(world_from_model, where=where, error=FrustumError)
    rgba = background_bytes(background, where)
    color = np.empty((camera.height, camera.width, 4), dtype=np.uint8)
    color[:, :] = rgba
    depth = np.ones((camera.height, camera.width), dtype=np.float32)
    written = np.zeros((camera.height, camera.width), dtype=bool)
    faces = octree_face_colors(octree, material, lights, matrix, camera.frame.eye)
    draw_octree_into(octree, camera, matrix, faces, color, depth, written)
    return Frame(color=color, depth=depth)
