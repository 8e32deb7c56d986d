"""Ray-casting visible-surface method: a ray per pixel, its first hit through the scene's spatial index.

Image space, one pixel at a time [HB 16 "Ray-Casting Method"]: from the centre of each pixel a ray goes along the
line of sight (``Camera.ray``: from the near plane toward the far plane; for a parallel projection along the
projection direction) and the nearest surface it meets is the visible one. Testing every surface per ray is the
notes' "consider an object many times"; the scene's bounding-volume hierarchy (``Scene._triangle_index``, the
index ``Scene.pick`` uses: world-space triangles of every item, Morton-ordered leaves, boxes from the leaves up)
cuts a ray's tests to the boxes it enters, nearer child first, so the time grows with the pixels and only
logarithmically with the faces (object coherence through the hierarchy; no coherence between pixels).

The hit is taken within the view volume (t in [0, 1) between the near and far planes: the side planes hold
every pixel centre's ray), back faces are skipped when culling (the ray goes on to what lies behind, as the depth
buffer never draws them) and otherwise hit with the two-sided code ``2·face + 1``. Each pixel gets the depth
buffer's window depth, face code and the hit's barycentrics (world barycentrics are the perspective-correct
ones), and the one shading kernel colors them. Kernel: ``raster.bvh.cast_pixels``.

References
----------
[HB 16] "Ray-Casting Method"; [seed] "Visible-surface detection", "ray casting".
"""

from __future__ import annotations

import contextlib
import contextvars
from collections.abc import Iterator

import numpy as np

from frustum.camera import Camera
from frustum.scene import Scene

__all__ = ["ray_casting", "recording"]

_RECORDING: contextvars.ContextVar[tuple[tuple[int, int], list[dict]] | None] = contextvars.ContextVar(
    "ray_casting_log", default=None
)
_LOG_ROWS = 1 << 16


@contextlib.contextmanager
def recording(pixel: tuple[int, int]) -> Iterator[list[dict]]:
    """Recording mode (``frustum.steps``): every ``ray_casting`` inside the block appends to the list the
    traversal of the ray through window pixel ``(i, j)`` (y up): ``log`` (L, 4) rows ``(kind, node, t, face)``
    (``raster.bvh.LOG_EVENTS``), the hierarchy's ``lo``/``hi`` boxes and the ray's ``items`` and ``starts``."""
    logs: list[dict] = []
    token = _RECORDING.set(((int(pixel[0]), int(pixel[1])), logs))
    try:
        yield logs
    finally:
        _RECORDING.reset(token)


def ray_casting(
    scene: Scene, camera: Camera, cull: bool, depth: np.ndarray, codes: np.ndarray, bary: np.ndarray
) -> dict:  # fmt: skip
    """Write the visible opaque surface of every pixel (depth, code, barycentrics) by casting a ray through it.

    Parameters
    ----------
    scene : Scene
        Its opaque items (``Material.opacity >= 1``) are hit; transparent ones are skipped (drawn afterwards).
    camera : Camera
    cull : bool
        Skip back faces (``render(..., cull_back_faces=True)``).
    depth : (H, W) float32
        Cleared to 1.0 (far); written where a ray hits (top row first).
    codes : (H, W) int32 or int64
        ``2·face + back``, faces numbered across ``scene.items`` as the shading kernel reads them.
    bary : (H, W, 2) float32
        Weights of the face's corners 1 and 2 at the hit.

    Returns
    -------
    dict
        ``rays`` (one per pixel), ``hits``, ``box_tests`` (ray–box slab tests), ``nodes_visited`` (BVH nodes
        entered), ``triangle_tests`` (ray–triangle intersection tests), ``tests_per_ray``, ``indexed_triangles``
        (opaque triangles in the index), ``bvh_nodes``.
    """
    from frustum.raster import bvh

    height, width = depth.shape
    stats = np.zeros((height, len(bvh.CAST_STATS)), dtype=np.int64)
    found = scene._triangle_index(where="render")
    if found is None:
        result = {name: 0 for name in bvh.CAST_STATS}
        result["rays"] = height * width
        result.update(tests_per_ray=0.0, indexed_triangles=0, bvh_nodes=0)
        return result
    items, index, starts = found
    clear = np.array([item.material.opacity < 1.0 for item in items])
    skip = np.repeat(clear, np.diff(starts)).astype(np.uint8) if clear.any() else np.empty(0, dtype=np.uint8)
    window_from_world = np.ascontiguousarray(camera.viewport_matrix @ camera.clip_from_world, dtype=np.float64)
    world_from_window = np.ascontiguousarray(camera.world_from_window, dtype=np.float64)
    recorder = _RECORDING.get()
    log = np.full((_LOG_ROWS if recorder is not None else 0, 4), np.nan)
    log_pixel = np.array(recorder[0] if recorder is not None else (-1, -1), dtype=np.int64)
    bvh.cast_pixels(index.lo, index.hi, index.triangles, index.order, skip, world_from_window, window_from_world,
                    int(cull), depth, codes, bary, stats, log, log_pixel)  # fmt: skip
    if recorder is not None:
        recorder[1].append({"log": log[~np.isnan(log[:, 0])], "lo": index.lo, "hi": index.hi, "order": index.order})
    totals = stats.sum(axis=0)
    result = {name: int(value) for name, value in zip(bvh.CAST_STATS, totals, strict=True)}
    result["tests_per_ray"] = round(result["triangle_tests"] / max(1, result["rays"]), 3)
    result["indexed_triangles"] = int(starts[-1]) - int(skip.sum())
    result["bvh_nodes"] = int(index.lo.shape[0])
    return result
