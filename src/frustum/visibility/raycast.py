"""Ray-casting visible-surface method: a ray per pixel, its first hit through the scene's spatial index.

Image space, one pixel at a time [HB 16 "Ray-Casting Method"]: from the centre of each pixel a ray goes along the
line of sight (``Camera.ray``: from the near plane toward the far plane; for a parallel projection along the
projection direction) and the nearest surface it meets is the visible one. Testing every surface per ray is the
notes' "consider an object many times"; the scene's bounding-volume hierarchy (``Scene._triangle_index``, the
index ``Scene.pick`` and ``Scene.intersect`` use: world-space triangles of every item, split by the surface
area heuristic, ``raster.rays``) cuts a ray's tests to the boxes it enters, nearer child first, so the time grows
with the pixels and only logarithmically with the faces (object coherence through the hierarchy; no coherence
between pixels).

The hit is taken within the view volume (t in [0, 1) between the near and far planes: the side planes hold
every pixel centre's ray), back faces are skipped when culling (the ray goes on to what lies behind, as the depth
buffer never draws them) and otherwise hit with the two-sided code $2·face + 1$. Each pixel gets the depth
buffer's window depth, face code and the hit's barycentrics (world barycentrics are the perspective-correct
ones), and the one shading kernel colors them. Kernel: ``raster.rays.cast_pixels``.

References
----------
[HB 16] "Ray-Casting Method"; [seed] "Visible-surface detection", "ray casting".
"""

from __future__ import annotations

import numpy as np

from frustum.camera import Camera
from frustum.scene import Scene

__all__ = ["ray_casting"]


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
        $2·face + back$, faces numbered across ``scene.items`` as the shading kernel reads them.
    bary : (H, W, 2) float32
        Weights of the face's corners 1 and 2 at the hit.

    Returns
    -------
    dict
        ``rays`` (one per pixel), ``hits``, ``box_tests`` (ray–box slab tests), ``nodes_visited`` (BVH nodes
        entered: inner nodes and leaves), ``triangle_tests`` (ray–triangle intersection tests), ``tests_per_ray``,
        ``indexed_triangles`` (opaque triangles in the index), ``bvh_nodes``
        (inner nodes; each holds its children's boxes).
    """
    from frustum.raster import rays as bvh

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
    bvh.cast_pixels(index.boxes, index.links, index.triangles, index.order, index.depth, skip, world_from_window,
                    window_from_world, int(cull), depth, codes, bary, stats)  # fmt: skip
    totals = stats.sum(axis=0)
    result = {name: int(value) for name, value in zip(bvh.CAST_STATS, totals, strict=True)}
    result["tests_per_ray"] = round(result["triangle_tests"] / max(1, result["rays"]), 3)
    result["indexed_triangles"] = int(starts[-1]) - int(skip.sum())
    result["bvh_nodes"] = index.nodes
    return result
