"""Volumes in SVG drawings: the ray-cast picture of every placed volume as one raster ``<image>`` layer.

A volume has no vector form, so ``render_svg`` embeds what ``render`` would composite: the volumes ray cast
(``frustum.render.volumes.draw_volumes``, the same kernels and bytes) into a transparent image of the camera's
size, one pixel per SVG user unit, as a PNG data URI in the group ``volumes``, drawn over the faces and the
lines and under the particles. Each ray stops at the nearest of

- the faces (every placed mesh, opaque as the SVG paints and hides with them, both sides), rasterized into a
  depth buffer by ``render``;
- the visible pieces of the drawing's lines (mesh edges and polylines), rasterized at the stroke width into
  that depth buffer (``raster.lines``),

so over a face or a line only the part of a volume in front of it is painted: a line inside a cloud is seen
through the cloud in front of it, a line or face in front of a volume is not covered, and an
``"isosurface"``-mode volume hides what lies behind it. The image stores straight (not premultiplied) alpha:
$color = C/A$ of the ray's premultiplied ``(C, A)``, so a viewer's "over" gives $C + (1 − A)·under$, the
renderer's blend, within a level.

References: [HB 15] "Visualization of Data Sets" (volume rendering); [HB 16] "Wire-Frame Visibility Methods".
"""

from __future__ import annotations

import base64
import dataclasses
import io

import numpy as np
from numpy.typing import NDArray

from frustum.camera import Camera
from frustum.scene import Scene

__all__ = ["volume_image", "volume_image_element"]


def _stop_depth(scene: Scene, camera: Camera, segments: NDArray, segment_depth: NDArray,
                stroke_width: float) -> NDArray[np.float32]:  # fmt: skip
    """(H, W) float32 window depth where the rays stop: the faces, then the visible line pieces over them."""
    from frustum.render import render

    depth = np.ones((camera.height, camera.width), dtype=np.float32)
    meshes = [item for item in scene.items if item.mesh.face_count]
    if meshes:  # the SVG paints (and hides lines with) every face opaque and two-sided
        faces = Scene(lights=scene.world_lights())
        for item in meshes:
            faces.add(item.mesh, dataclasses.replace(item.material, opacity=1.0), item.world_from_model)
        depth = render(faces, camera, cull_back_faces=False).depth.copy()
    if segments.shape[0]:
        from frustum.clipping import VIEW_VOLUME_PLANES
        from frustum.raster import lines

        count = segments.shape[0]
        clip = np.ones((2 * count, 4))  # window → clip with w = 1 (NDC): x/(W/2) − 1, y/(H/2) − 1, 2z − 1
        clip[:, 0] = segments[:, :, 0].reshape(-1) / (camera.width / 2.0) - 1.0
        clip[:, 1] = segments[:, :, 1].reshape(-1) / (camera.height / 2.0) - 1.0
        clip[:, 2] = 2.0 * segment_depth.reshape(-1) - 1.0
        edges = np.arange(2 * count, dtype=np.int64).reshape(count, 2)
        view = np.array([camera.width / 2.0, camera.height / 2.0])
        style = lines.line_style((0.0, 0.0, 0.0, 0.0), width=max(1.0, float(round(stroke_width))))
        scratch = np.zeros((camera.height, camera.width, 4), dtype=np.uint8)
        lines.draw_lines(clip, np.zeros(2 * count), edges, np.asarray(VIEW_VOLUME_PLANES, dtype=np.float64), view,
                         style, depth, scratch)  # fmt: skip
    return depth


def volume_image(
    scene: Scene, camera: Camera, segments: NDArray | None = None, segment_depth: NDArray | None = None,
    stroke_width: float = 1.0,
) -> NDArray[np.uint8]:  # fmt: skip
    """(H, W, 4) uint8 premultiplied RGBA: every volume of `scene` ray cast over transparent black, each ray
    stopped at the faces of `scene` and at the window `segments` (K, 2, 2) of window depth `segment_depth` (K, 2)
    drawn `stroke_width` pixels wide (the module docstring)."""
    from frustum.render.volumes import draw_volumes

    segments = np.zeros((0, 2, 2)) if segments is None else np.asarray(segments, dtype=np.float64)
    segment_depth = np.zeros((0, 2)) if segment_depth is None else np.asarray(segment_depth, dtype=np.float64)
    depth = _stop_depth(scene, camera, segments, segment_depth, stroke_width)
    color = np.zeros((camera.height, camera.width, 4), dtype=np.uint8)
    draw_volumes(scene, camera, depth, color)
    return color


def volume_image_element(
    scene: Scene, camera: Camera, segments: NDArray, segment_depth: NDArray, stroke_width: float
) -> str:  # fmt: skip
    """The ``<g id="volumes">`` element holding ``volume_image`` as a straight-alpha PNG ``<image>``."""
    from PIL import Image

    premultiplied = volume_image(scene, camera, segments, segment_depth, stroke_width)
    alpha = premultiplied[..., 3:].astype(np.float64)
    rgb = np.where(alpha > 0, premultiplied[..., :3] * 255.0 / np.maximum(alpha, 1.0), 0.0)  # C/A
    straight = premultiplied.copy()
    straight[..., :3] = np.floor(np.clip(rgb, 0.0, 255.0) + 0.5).astype(np.uint8)
    buffer = io.BytesIO()
    Image.fromarray(straight).save(buffer, format="PNG", optimize=True)
    data = base64.b64encode(buffer.getvalue()).decode("ascii")
    return (
        f'<g id="volumes" data-count="{len(scene.volumes)}"><image x="0" y="0" width="{camera.width}" '
        f'height="{camera.height}" preserveAspectRatio="none" href="data:image/png;base64,{data}"/></g>'
    )
