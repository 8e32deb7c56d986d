"""Environment mapping pass: the scene's ``EnvironmentMap`` as the background, and reflection mapping.

* **Background** (``paint_background``): every pixel where no opaque surface was drawn (depth 1) shows the map
  along its own viewing ray (``Camera.ray`` through the pixel centre), when ``render`` was given no background.
  It runs right after the opaque surfaces, so volumes and transparent items are composited over it.
* **Reflection mapping** (``reflect``): after an item with ``Material.reflectivity`` r > 0 is shaded, each of its
  pixels becomes $(1 − r)·I + r·env(R)$ with $R = V − 2 (N·V) N$, V the unit viewing ray through the pixel and
  N the interpolated unit normal (flipped for a back face drawn two-sided), per pixel with a bilinear lookup
  [HB "Environment Mapping"]. Only the surroundings are reflected, not the other objects (that is ray tracing).

Colors are linear; bytes are $floor(I·255 + 0.5)$ as the shading kernels store them.
"""

from __future__ import annotations

import numpy as np

from frustum.camera import Camera
from frustum.render.context import FrameContext
from frustum.render.options import RenderOptions
from frustum.shading.environment import reflect_directions


def _to_bytes(values: np.ndarray) -> np.ndarray:
    return np.floor(np.clip(values, 0.0, 1.0) * 255.0 + 0.5).astype(np.uint8)


def _pixel_rays(camera: Camera, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
    """(N, 3) unit world directions of the viewing rays through the centres of the pixels (row from the top)."""
    window = np.column_stack([cols + 0.5, camera.height - rows - 0.5])
    return camera.ray(window).direction if len(rows) else np.empty((0, 3))


def paint_background(camera: Camera, options: RenderOptions, context: FrameContext) -> None:
    """Where nothing opaque was drawn, the environment map along each pixel's ray (when asked for)."""
    if options.environment is None or not options.environment_background:
        return
    rows, cols = np.nonzero(context.depth >= 1.0)
    colors = options.environment.lookup(_pixel_rays(camera, rows, cols))
    context.color[rows, cols, :3] = _to_bytes(colors)
    context.color[rows, cols, 3] = 255


def reflect(
    item_faces: np.ndarray, face_offset: int, reflectivity: float, camera: Camera, options: RenderOptions,
    normals: np.ndarray, depth: np.ndarray, codes: np.ndarray, bary: np.ndarray, color: np.ndarray, first_row: int,
) -> None:  # fmt: skip
    """Blend the reflected environment into the item's pixels of `color` (rows of the image from `first_row`)."""
    face = codes.astype(np.int64) // 2 - face_offset
    mine = (depth < 1.0) & (face >= 0) & (face < item_faces.shape[0])
    rows, cols = np.nonzero(mine)
    if rows.size == 0:
        return
    f = face[rows, cols]
    back = (codes[rows, cols] % 2 == 1)[:, None]
    u1 = bary[rows, cols, 0].astype(np.float64)[:, None]
    u2 = bary[rows, cols, 1].astype(np.float64)[:, None]
    corners = item_faces[f]
    n = (1.0 - u1 - u2) * normals[corners[:, 0]] + u1 * normals[corners[:, 1]] + u2 * normals[corners[:, 2]]
    n /= np.where((length := np.linalg.norm(n, axis=1, keepdims=True)) > 0.0, length, 1.0)
    n = np.where(back, -n, n)
    view = _pixel_rays(camera, rows + first_row, cols)
    mirrored = options.environment.lookup(reflect_directions(view, n))
    local = color[rows, cols, :3].astype(np.float64) / 255.0
    color[rows, cols, :3] = _to_bytes((1.0 - reflectivity) * local + reflectivity * mirrored)
