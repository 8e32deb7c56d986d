"""Object-space ordering drawn as a raster frame: the depth sort and the BSP tree paint filled, shaded fragments.

``frustum.visibility.bsp`` orders polygons back to front (splitting where no order exists) for vector output. Here the
same two methods order the scene's *window triangles* (the triangles the depth buffer draws, after clipping to
the view volume), given to them in window coordinates $(x, y, −S·z_w)$ with S the larger image side: the
projection is already applied, so every camera becomes a parallel view along −z (a perspective divide maps
planes to planes), and no polygon reaches behind the eye. The fragments are then painted back to front
(``raster.painter``): each covers the pixels of its triangle (top-left rule) inside the fragment.

References
----------
[HB 16] "Depth-Sorting Method", "BSP-Tree Method"; [seed] "Depth-sorting method", "BSP trees".
"""

from __future__ import annotations

import numpy as np

from frustum.visibility.window import WindowTriangles

__all__ = ["bsp_tree", "depth_sort", "window_polygons"]

_MAX_CORNERS = 8


def window_polygons(triangles: WindowTriangles) -> np.ndarray:
    """(T, 3, 3) float64: the triangles as $(x, y, −S·z_w)$ polygons (pixels; S = the larger image side)."""
    scale = float(max(triangles.width, triangles.height))
    polygons = np.empty((triangles.count, 3, 3))
    polygons[:, :, 0] = triangles.xy[:, 0::2] / 256.0
    polygons[:, :, 1] = triangles.xy[:, 1::2] / 256.0
    polygons[:, :, 2] = -scale * triangles.zq[:, :, 0]
    return polygons


def _paint(
    fragments: list[tuple[np.ndarray, int]], triangles: WindowTriangles, depth: np.ndarray, codes: np.ndarray,
    bary: np.ndarray,
) -> dict:  # fmt: skip
    from frustum.raster import painter

    count = len(fragments)
    corners = np.zeros((count, _MAX_CORNERS, 2))
    counts = np.zeros(count, dtype=np.int64)
    source = np.zeros(count, dtype=np.int64)
    for n, (polygon, label) in enumerate(fragments):
        k = min(polygon.shape[0], _MAX_CORNERS)
        corners[n, :k] = polygon[:k, :2]
        counts[n], source[n] = k, label
    stats = np.zeros(2, dtype=np.int64)
    painter.paint_fragments(
        np.arange(count, dtype=np.int64), corners, counts, source, triangles.xy, triangles.zq, triangles.weights,
        triangles.code, triangles.box, depth, codes, bary, stats,
    )  # fmt: skip
    return {"fragments": int(stats[0]), "pixels_painted": int(stats[1]), "triangles": triangles.count}


def depth_sort(triangles: WindowTriangles, depth: np.ndarray, codes: np.ndarray, bary: np.ndarray) -> dict:
    """Newell–Newell–Sancha depth sort (``visibility.bsp.depth_sort``) of the window triangles, painted back to front.

    Buffers as ``scanline.scan_line``. Returns ``fragments`` painted, ``pixels_painted`` (overdraw included),
    ``splits`` (cyclic overlaps and piercing triangles cut), ``unresolved``, ``triangles``.
    """
    from frustum.camera import Camera, ViewFrame
    from frustum.projection import Orthographic
    from frustum.visibility.depth_sort import depth_sort as sort

    if triangles.count == 0:
        return {"fragments": 0, "pixels_painted": 0, "splits": 0, "unresolved": 0, "triangles": 0}
    width, height = triangles.width, triangles.height
    scale = float(max(width, height))
    centre = (width / 2.0, height / 2.0)
    frame = ViewFrame((*centre, 1.0), target=(*centre, 0.0), up=(0.0, 1.0, 0.0))
    camera = Camera(frame, Orthographic(float(height) + 2.0, 0.5, scale + 1.5), width + 2, height + 2)
    order = sort(window_polygons(triangles), camera)
    result = _paint(order.fragments, triangles, depth, codes, bary)
    result["splits"], result["unresolved"] = order.split_count, order.unresolved_count
    return result


def bsp_tree(triangles: WindowTriangles, depth: np.ndarray, codes: np.ndarray, bary: np.ndarray) -> dict:
    """BSP tree (``frustum.visibility.bsp.BSPTree``) of the window triangles, read back to front and painted.

    Buffers as ``scanline.scan_line``. Returns ``fragments`` painted, ``pixels_painted``, ``nodes``, ``splits``,
    ``triangles``.
    """
    from frustum.visibility.bsp import BSPTree

    if triangles.count == 0:
        return {"fragments": 0, "pixels_painted": 0, "nodes": 0, "splits": 0, "triangles": 0}
    tree = BSPTree(window_polygons(triangles))
    order = tree.back_to_front_indices(direction=(0.0, 0.0, -1.0))
    fragments, ids = tree.fragments, tree.ids
    result = _paint([(fragments[i], int(ids[i])) for i in order.tolist()], triangles, depth, codes, bary)
    result["nodes"], result["splits"] = tree.node_count, tree.split_count
    return result
