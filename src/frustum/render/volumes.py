"""The volume pass of ``render``: every placed volume ray cast into the frame after the opaque surfaces.

``draw_volumes(scene, camera, depth, color)`` runs once the opaque meshes are in the buffers: each ray stops at
the opaque depth (the window depth of its pixel, turned back into the ray's parameter), so a mesh inside a
volume hides what lies behind it and is seen through what lies in front. Volumes are drawn back to front by the
view distance of their centres, except that two or more composite volumes are drawn together: each ray
composites the samples of all of them in depth order (``raster.volume.cast_composite_merged``), so overlapping
volumes mix sample by sample. The kernels
are ``raster.volume``'s; this module builds their arrays: the grid ↔ window matrices, clip planes in grid
coordinates, the transfer function's table with its opacity corrected for the step, and the per-block
min/max/empty flags of empty-space skipping.
"""

from __future__ import annotations

import math
import weakref
from typing import TYPE_CHECKING

import numpy as np

from frustum.budgets import check_memory, check_operations
from frustum.camera import Camera
from frustum.errors import FrustumError
from frustum.scene import Scene, VolumeItem
from frustum.shading import pack_lights

if TYPE_CHECKING:  # the volume module loads with the first volume (not on the path of a scene without one)
    from frustum.geometry.volume import Volume

__all__ = ["MODES", "TABLE_SIZE", "TERMINATE", "draw_volumes", "volume_arrays"]

MODES = {"composite": 0, "mip": 1, "minip": 2, "average": 3, "isosurface": 4}
"""Mode names and the kernel's mode numbers (``raster.volume.MODE_*``)."""
TABLE_SIZE = 4096
"""Entries of the transfer-function lookup table over its range."""
TERMINATE = 1.0 - 1.0 / 512.0
"""Early ray termination: a composite ray stops once its accumulated opacity reaches this (what is left behind
could change a pixel by under half a level)."""
BISECTIONS = 16
_BYTES_PER_BLOCK = 84
"""Work memory per empty-space block of ``volume_arrays``: the cached min/max/flag (12 bytes), this frame's copy
(12) and the composite mode's float64 temporaries (four of 8 bytes, the index arrays 2 × 8, the flags 4)."""
_block_cache: weakref.WeakKeyDictionary[Volume, np.ndarray] = weakref.WeakKeyDictionary()


def _blocks(volume: Volume) -> np.ndarray:
    """(bx, by, bz, 3) float32 min, max of each block of ``raster.volume.BLOCK`` cells (cached per volume)."""
    from frustum.raster import volume as kernels

    cached = _block_cache.get(volume)
    if cached is None:
        cells = np.array(volume.shape) - 1
        counts = (cells + kernels.BLOCK - 1) // kernels.BLOCK
        cached = np.zeros((*counts, 3), dtype=np.float32)
        kernels.block_ranges(volume.data, cached)
        _block_cache[volume] = cached
    return cached


def volume_arrays(item: VolumeItem, camera: Camera, lights_packed: tuple[np.ndarray, np.ndarray] | None = None):
    """The kernel arguments of one placed volume: (mode, data, blocks, table, matrices, planes, params, lights).

    Checks the work budget first: pixels × samples per ray (the box diagonal over the step) inner iterations.
    """
    from frustum.raster import volume as kernels

    volume = item.volume
    diagonal = float(np.linalg.norm((np.array(volume.shape) - 1.0) * volume.spacing))
    samples = diagonal / item.step + 2.0
    check_operations(camera.width * camera.height * samples, where="render",
                     cause=f"a volume of shape {volume.shape} with step = {item.step!r} ({samples:.3g} samples per "
                           f"ray) at {camera.width}x{camera.height} pixels", error=FrustumError)  # fmt: skip
    block_count = math.prod(-(-(n - 1) // kernels.BLOCK) for n in volume.shape)
    check_memory(block_count * _BYTES_PER_BLOCK, where="render", error=FrustumError,
                 cause=f"the empty-space blocks of a volume of shape {volume.shape}")  # fmt: skip
    world_from_grid = np.asarray(item.world_from_model) @ volume.model_from_grid
    window_from_grid = camera.viewport_matrix @ camera.clip_from_world @ world_from_grid
    matrices = np.zeros((5, 4, 4))
    matrices[kernels.M_GRID_FROM_WINDOW] = np.linalg.inv(window_from_grid)
    matrices[kernels.M_MODEL_FROM_GRID] = volume.model_from_grid
    matrices[kernels.M_WINDOW_FROM_GRID] = window_from_grid
    matrices[kernels.M_WORLD_FROM_GRID] = world_from_grid
    matrices[kernels.M_NORMAL_FROM_GRID, :3, :3] = np.linalg.inv(world_from_grid[:3, :3]).T
    # clip planes: keep n·(P − p) <= 0 in world, i.e. the row (−n, n·p) · (P, 1) >= 0, pulled back to the grid
    planes = np.zeros((item.clip_planes.shape[0], 4))
    for index, (point, normal) in enumerate(item.clip_planes):
        planes[index] = np.append(-normal, normal @ point) @ world_from_grid
    tf = item.transfer_function
    table = np.empty((5, TABLE_SIZE))  # rows r, g, b, α, α' (kernels read one row per lookup)
    table[:4] = tf.table(TABLE_SIZE).T
    unit = volume.unit_distance
    table[4] = 1.0 - (1.0 - table[3]) ** (item.step / unit)  # α' = 1 − (1 − α)^(Δ/Δ₀)
    low, high = tf.range
    scale = (TABLE_SIZE - 1) / (high - low)
    blocks = _blocks(volume).copy()
    if item.mode == "composite":  # a block is empty when no table entry its values can reach is opaque
        f_low = np.clip((blocks[..., 0] - low) * scale, 0.0, TABLE_SIZE - 1.0)
        f_high = np.clip((blocks[..., 1] - low) * scale, 0.0, TABLE_SIZE - 1.0)
        first = np.floor(f_low).astype(np.int64)
        last = np.minimum(np.floor(f_high).astype(np.int64) + 1, TABLE_SIZE - 1)
        opaque = np.concatenate([[0], np.cumsum(table[3] > 0.0)])
        blocks[..., 2] = (opaque[last + 1] - opaque[first] == 0).astype(np.float32)
    ambient, lights = pack_lights([]) if lights_packed is None else lights_packed
    material = item.material
    params = np.zeros(kernels.PARAMS)
    params[kernels.P_STEP], params[kernels.P_UNIT], params[kernels.P_LEVEL] = item.step, unit, item.level
    params[kernels.P_SHADE] = float(item.shade)
    params[kernels.P_KA], params[kernels.P_KD] = material.ambient, material.diffuse
    params[kernels.P_KS], params[kernels.P_SHININESS] = material.specular, material.shininess
    params[kernels.P_AMBIENT : kernels.P_AMBIENT + 3] = ambient
    params[kernels.P_EYE : kernels.P_EYE + 3] = camera.frame.eye
    params[kernels.P_TABLE_LOW], params[kernels.P_TABLE_SCALE] = low, scale
    params[kernels.P_TERMINATE], params[kernels.P_BISECTIONS] = TERMINATE, BISECTIONS
    params[kernels.P_ANCHORED] = float(item.sampling == "near")
    # entries up to first − 1 have opacity 0, and so has the table between them: values mapping there need no lookup
    first = int(np.argmax(table[3] > 0.0)) if (table[3] > 0.0).any() else TABLE_SIZE
    params[kernels.P_CLEAR_BELOW] = low + (first - 1) / scale if first >= 1 else -np.inf
    return (MODES[item.mode], volume.data, blocks, table, matrices, planes, params,
            np.ascontiguousarray(lights, dtype=np.float64))  # fmt: skip


def draw_volumes(scene: Scene, camera: Camera, depth: np.ndarray, color: np.ndarray) -> None:
    """Ray cast every volume of `scene` into `color` (H, W, 4) uint8, each ray stopped at `depth` (H, W) float32.

    The isosurface mode writes the window depth of its hits into `depth`.
    """
    if not scene.volumes:
        return
    from frustum.raster import volume as kernels

    packed = pack_lights(scene.world_lights())
    eye, axis = np.asarray(camera.frame.eye), np.asarray(camera.frame.n)

    def distance(item: VolumeItem) -> float:
        centre = item.volume.bounds.mean(axis=0)
        centre = item.world_from_model[:3, :3] @ centre + item.world_from_model[:3, 3]
        return float((eye - centre) @ axis)

    merged = [item for item in scene.volumes if item.mode == "composite"]
    merged = merged if len(merged) > 1 else []
    drawn = False
    for item in sorted(scene.volumes, key=distance, reverse=True):
        if any(item is other for other in merged):  # drawn together, where the farthest of them comes
            if not drawn:
                _draw_merged(merged, camera, packed, depth, color)
                drawn = True
            continue
        arguments = volume_arrays(item, camera, packed)
        kernels.cast_rays(*arguments, depth, color)


def _draw_merged(items: list[VolumeItem], camera: Camera, packed: tuple, depth: np.ndarray, color: np.ndarray) -> None:
    """Composite volumes drawn together (``raster.volume.cast_composite_merged``): their kernel arguments stacked,
    the clip planes padded with rows of zeros (always kept)."""
    from frustum.raster import volume as kernels

    arguments = [volume_arrays(item, camera, packed) for item in items]
    # tuples, not numba.typed.List: building a typed list from Python compiles its helpers in every process
    datas, blocks = tuple(a[1] for a in arguments), tuple(a[2] for a in arguments)
    planes = np.zeros((len(items), max(a[5].shape[0] for a in arguments), 4))
    for index, a in enumerate(arguments):
        planes[index, : a[5].shape[0]] = a[5]
    kernels.cast_composite_merged(datas, blocks, np.stack([a[3] for a in arguments]),
                                  np.stack([a[4] for a in arguments]), planes, np.stack([a[6] for a in arguments]),
                                  arguments[0][7], depth, color)  # fmt: skip

