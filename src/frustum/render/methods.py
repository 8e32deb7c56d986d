"""The visible-surface methods other than the depth buffer (``render(..., method=...)``, docs/visibility.md):
dispatch to ``visibility/`` (scan-line, Warnock, depth sort, BSP, ray casting fill the depth buffer's depth, face
codes and barycentrics; the shading is the depth buffer's), the A-buffer (fragments shaded once and composited
per subsample, also the ``transparency="a-buffer"`` of every method), the octree method, and the depth buffer's
counts (``stats=True``)."""

from __future__ import annotations

import dataclasses
import importlib
from collections.abc import Callable
from typing import Any

import numpy as np

from frustum.camera import Camera
from frustum.frame import Frame, background_bytes
from frustum.geometry import Mesh
from frustum.render.buffers import Buffers, Scratch, clear_buffers
from frustum.render.options import METHOD_NAMES, RenderOptions, check_arguments
from frustum.render.shadows import passes as shadows
from frustum.render.stages import (
    Lighting,
    Pixels,
    back_to_front,
    code_type,
    draw_item,
    face_offsets,
    shade_item,
    world_attributes,
)
from frustum.scene import Scene, SceneItem

VISIBILITY_METHODS = {
    "depth-buffer": None,
    "scan-line": "frustum.visibility.scanline:scan_line",
    "area-subdivision": "frustum.visibility.warnock:area_subdivision",
    "depth-sort": "frustum.visibility.painter:depth_sort",
    "bsp": "frustum.visibility.painter:bsp_tree",
    "a-buffer": "frustum.visibility.abuffer",
    "ray-casting": "frustum.visibility.raycast:ray_casting",
}
"""``render(..., method=...)``: name → the visibility function that fills depth, codes and barycentrics (the
depth buffer is the renderer's own path; the A-buffer resolves fragments instead)."""


def render_octrees(scene: Scene, camera: Camera, *, background: Any) -> Frame:
    """``method="octree"``: every placed octree by the octree method, nearest surface kept between octrees."""
    from frustum.visibility.octree import draw_octree_into, octree_face_colors

    if not isinstance(scene, Scene) or not isinstance(camera, Camera):
        check_arguments(scene, camera, "phong", "blinn-phong", background, True, "surface", None, 0.0, None, None,
                        (0.6, 0.6, 0.6), 1.0, None, (), "render")  # fmt: skip
    rgba = background_bytes(background, "render")
    color = np.empty((camera.height, camera.width, 4), dtype=np.uint8)
    color[:, :] = rgba
    depth = np.ones((camera.height, camera.width), dtype=np.float32)
    lights = scene.world_lights()
    for item in scene.octrees:
        item_color, item_depth = color.copy(), np.ones_like(depth)
        written = np.zeros(depth.shape, dtype=bool)
        faces = octree_face_colors(item.mesh, item.material, lights, item.world_from_model, camera.frame.eye)
        draw_octree_into(item.mesh, camera, item.world_from_model, faces, item_color, item_depth, written)
        nearer = written & (item_depth < depth)
        color[nearer], depth[nearer] = item_color[nearer], item_depth[nearer]
    if scene.volumes:  # ray cast over the octrees, each ray stopped at their depth
        from frustum.render.volumes import draw_volumes

        draw_volumes(scene, camera, depth, color)
    return Frame(color=color, depth=depth)


RENDER_METHODS = {name: render_octrees if name == "octree" else None for name in METHOD_NAMES}
"""Visible-surface methods of ``render(..., method=...)``: None for the methods of the mesh pipeline
(``VISIBILITY_METHODS``), else the function that draws the frame."""


def count_depth_tests(items: list[SceneItem], camera: Camera, options: RenderOptions) -> None:
    """The depth buffer's counts: depth tests (pixel centres covered, summed over the drawn triangles)."""
    from frustum.raster import window
    from frustum.visibility.window import window_triangles

    tris = window_triangles(items, list(range(len(items))), face_offsets(items), camera, options.cull)
    covered = np.empty(tris.count, dtype=np.int64)
    window.count_covered(tris.xy, tris.box, covered)
    assert options.counts is not None
    options.counts.update(depth_tests=int(covered.sum()), triangles=tris.count)


def opaque_only(items: list[SceneItem]) -> list[SceneItem]:
    """`items` with every transparent item's mesh replaced by an empty one (drawn elsewhere: the A-buffer)."""
    return [
        item if item.material.opacity >= 1.0 else item._replace(mesh=Mesh(np.empty((0, 3)), np.empty((0, 3), int)))
        for item in items
    ]


def draw_surfaces_by_method(
    scene: Scene, camera: Camera, options: RenderOptions, buffers: Buffers, between: Callable[[], None]
) -> None:  # fmt: skip
    """Stages 1–6 by a visible-surface method other than the depth buffer into ``buffers.depth`` and
    ``buffers.color``: the opaque items, `between` (the volumes), then the transparent items (back to front, or
    through an A-buffer).

    The method writes the depth-buffer's depth, face code and barycentrics of the surface it finds at each pixel
    (``visibility.window``); ``stages.shade_item`` shades them as for the depth buffer. The A-buffer shades one
    sample per fragment (a column image through the same kernel) and composites.
    """
    from frustum.visibility.window import window_triangles

    items = scene.items
    height, width = camera.height, camera.width
    counts = options.counts if options.counts is not None else {}
    offsets = face_offsets(items)
    opaque = [i for i, item in enumerate(items) if item.material.opacity >= 1.0]
    clear_items = [i for i, item in enumerate(items) if item.material.opacity < 1.0]
    buffers.depth = depth = np.empty((height, width), dtype=np.float32)
    buffers.color = color = np.empty((height, width, 4), dtype=np.uint8)
    clear_buffers(depth, color, options.background)
    lighting = Lighting.of(scene)
    extra = buffers.extra()
    scratch = buffers.scratch
    if options.method == "a-buffer":
        # with volumes: the opaque fragments, the volumes (rays stop at their depth), then the transparent ones
        volumes_between = bool(scene.volumes) and options.volumes_with_surfaces
        first = opaque if volumes_between else list(range(len(items)))
        tris = window_triangles(items, first, offsets, camera, options.cull)
        counts.update(_composite(tris, items, offsets, camera, options, lighting, color, depth, scratch))
        counts["triangles"] = tris.count
        if volumes_between:
            between()
            if clear_items:
                tris = window_triangles(items, clear_items, offsets, camera, options.cull)
                found = _composite(tris, items, offsets, camera, options, lighting, color, depth.copy(), scratch,
                                   under_depth=depth)  # fmt: skip
                counts.update({f"transparent_{key}": value for key, value in found.items()})
                counts["triangles"] += tris.count
        return
    codes_dtype = code_type(items)  # the depth buffer's: the shading kernels are compiled for it already
    pixels = Pixels(depth, np.zeros((height, width), dtype=codes_dtype),
                    np.zeros((height, width, 2), dtype=np.float32), color, extra)  # fmt: skip
    module, name = VISIBILITY_METHODS[options.method].split(":")  # type: ignore[union-attr]
    draw = getattr(importlib.import_module(module), name)
    if options.method == "ray-casting":  # world-space rays through the scene's index, not window triangles
        counts.update(draw(scene, camera, options.cull, depth, pixels.codes, pixels.bary))
    else:
        tris = window_triangles(items, opaque, offsets, camera, options.cull)
        counts.update(draw(tris, depth, pixels.codes, pixels.bary))
    attributes = {index: world_attributes(items[index], scratch) for index in opaque}
    shadows.prepare(scene, items, [(i, attributes[i][0], offsets[i]) for i in opaque], camera, options, lighting,
                    pixels)  # fmt: skip
    for index in opaque:
        shadows.shade_item(items[index], index, offsets[index], camera, options, lighting, attributes[index], pixels,
                           (0, height), blend=False)  # fmt: skip
    between()
    if not clear_items:
        return
    if options.transparency == "a-buffer":
        composite_transparent(scene, camera, options, buffers)
        return
    for index in back_to_front(items, clear_items, camera):  # per-object sort, as the depth buffer does
        item = items[index]
        layer = Pixels(depth.copy(), np.full((height, width), -1, dtype=codes_dtype), pixels.bary, color, extra)
        world, normals, band = draw_item(item, camera, options.cull, offsets[index], layer, scratch)
        shade_item(item, index, offsets[index], camera, options, lighting, (world, normals), layer, band,
                   blend=True)  # fmt: skip


def composite_transparent(scene: Scene, camera: Camera, options: RenderOptions, buffers: Buffers) -> None:
    """``transparency="a-buffer"``: the transparent items' fragments composited per subsample over the finished
    opaque frame (behind its depth), their counts as ``transparent_*`` in ``options.counts``."""
    from frustum.visibility.window import window_triangles

    items = scene.items
    clear_items = [i for i, item in enumerate(items) if item.material.opacity < 1.0]
    if not clear_items:
        return
    counts = options.counts if options.counts is not None else {}
    offsets = face_offsets(items)
    depth = buffers.depth
    tris = window_triangles(items, clear_items, offsets, camera, options.cull)
    found = _composite(tris, items, offsets, camera, options, Lighting.of(scene), buffers.color, depth.copy(),
                       buffers.scratch, under_depth=depth)  # fmt: skip
    counts.update({f"transparent_{key}": value for key, value in found.items()})


def _composite(
    tris: Any, items: list[SceneItem], offsets: list[int], camera: Camera, options: RenderOptions,
    lighting: Lighting, color: np.ndarray, depth: np.ndarray, scratch: Scratch, under_depth: np.ndarray | None = None,
) -> dict:  # fmt: skip
    """A-buffer: fragments of `tris`, each shaded once (blended over transparent black: premultiplied bytes),
    composited per subsample over `color` (behind `under_depth`, default the far plane) into `color`; the
    nearest opaque fragment's depth at each pixel centre into `depth`."""
    from frustum.visibility import abuffer

    fragments = abuffer.build_fragments(tris)
    premultiplied = np.zeros((fragments.count, 4), dtype=np.uint8)
    dummy = (np.zeros((1, 1, 3), dtype=np.float32), np.zeros((1, 1), dtype=np.int32))
    owner = tris.item[fragments.triangle]
    columns = 256
    flat_options = dataclasses.replace(options, environment=None)  # fragment images have no pixel rays to reflect
    for index in sorted(set(tris.item.tolist())):
        # the item's fragments as a (rows, 256) image, padded with depth 1 (nothing drawn), shaded by the one kernel:
        # opaque items as the depth buffer shades them, transparent ones blended over transparent black
        chosen = np.flatnonzero(owner == index)
        rows = -(-chosen.shape[0] // columns)
        depth_image = np.ones(rows * columns, dtype=np.float32)
        code_image = np.zeros(rows * columns, dtype=code_type(items))
        bary_image = np.zeros((rows * columns, 2), dtype=np.float32)
        depth_image[: chosen.shape[0]] = fragments.depth[chosen, 0]
        code_image[: chosen.shape[0]] = fragments.code[chosen, 0]
        bary_image[: chosen.shape[0]] = fragments.bary[chosen, 0]
        color_image = np.zeros((rows, columns, 4), dtype=np.uint8)
        attributes = world_attributes(items[index], scratch)
        image = Pixels(depth_image.reshape(rows, columns), code_image.reshape(rows, columns),
                       bary_image.reshape(rows, columns, 2), color_image, dummy)  # fmt: skip
        shade_item(items[index], index, offsets[index], camera, flat_options, lighting, attributes, image, (0, rows),
                   blend=items[index].material.opacity < 1.0)  # fmt: skip
        premultiplied[chosen] = color_image.reshape(-1, 4)[: chosen.shape[0]]
    if under_depth is None:
        under_depth = np.ones(depth.shape, dtype=np.float32)
    return abuffer.resolve_fragments(fragments, premultiplied, tris, color, under_depth, color, depth)
