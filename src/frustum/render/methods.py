"""The visible-surface methods other than the depth buffer (``render(..., method=...)``, docs/visibility.md):
dispatch to ``visibility/`` (scan-line, Warnock, depth sort, BSP, ray casting fill the depth buffer's depth, face
codes and barycentrics; the shading is the depth buffer's), the A-buffer (fragments shaded once and composited
per subsample, also the ``transparency="a-buffer"`` of every method), the octree method, and the depth buffer's
counts (``stats=True``)."""

from __future__ import annotations

import dataclasses
import importlib
from typing import Any

import numpy as np

from frustum.camera import Camera
from frustum.frame import Frame, background_bytes
from frustum.geometry import Mesh
from frustum.render.buffers import Scratch, clear_buffers
from frustum.render.context import FrameContext
from frustum.render.options import METHOD_NAMES, RenderOptions, check_arguments
from frustum.render.shadows import passes as shadows
from frustum.render.stages import (
    Lighting,
    Pixels,
    code_type,
    draw_transparent,
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


def count_depth_tests(items: list[SceneItem], camera: Camera, options: RenderOptions, context: FrameContext) -> None:
    """The depth buffer's counts: depth tests (pixel centres covered, summed over the drawn triangles)."""
    from frustum.raster import window
    from frustum.visibility.window import window_triangles

    tris = window_triangles(items, list(range(len(items))), face_offsets(items), camera, options.cull)
    covered = np.empty(tris.count, dtype=np.int64)
    window.count_covered(tris.xy, tris.box, covered)
    context.counter().update(depth_tests=int(covered.sum()), triangles=tris.count)


def opaque_only(items: list[SceneItem]) -> list[SceneItem]:
    """`items` with every transparent item's mesh replaced by an empty one (drawn elsewhere: the A-buffer)."""
    return [
        item if item.material.opacity >= 1.0 else item._replace(mesh=Mesh(np.empty((0, 3)), np.empty((0, 3), int)))
        for item in items
    ]


def draw_fragments(scene: Scene, camera: Camera, options: RenderOptions, context: FrameContext,
                   which: str = "all") -> None:  # fmt: skip
    """``method="a-buffer"``: the fragments of the items (`which`: "all", "opaque" into cleared buffers, or
    "transparent" over the frame drawn so far, behind its depth) shaded once per fragment (a column image through
    the depth buffer's kernel) and composited per subsample into ``context.color`` and ``context.depth``; their
    counts into ``context.counts`` (``transparent_*`` for the transparent pass)."""
    from frustum.visibility.window import window_triangles

    items = scene.items
    counts = context.counter()
    offsets = face_offsets(items)
    lighting = Lighting.of(scene)
    if which == "transparent":
        chosen = [i for i, item in enumerate(items) if item.material.opacity < 1.0]
        if not chosen:
            return
        depth = context.depth
        tris = window_triangles(items, chosen, offsets, camera, options.cull)
        found = _composite(tris, items, offsets, camera, options, lighting, context.color, depth.copy(),
                           context.scratch, under_depth=depth)  # fmt: skip
        counts.update({f"transparent_{key}": value for key, value in found.items()})
        counts["triangles"] = counts.get("triangles", 0) + tris.count
        return
    _clear(camera, options, context)
    chosen = [i for i, item in enumerate(items) if which == "all" or item.material.opacity >= 1.0]
    tris = window_triangles(items, chosen, offsets, camera, options.cull)
    counts.update(_composite(tris, items, offsets, camera, options, lighting, context.color, context.depth,
                             context.scratch))  # fmt: skip
    counts["triangles"] = tris.count


def _clear(camera: Camera, options: RenderOptions, context: FrameContext) -> None:
    """New color and depth arrays at the camera's size, cleared to the background and the far plane."""
    context.depth = np.empty((camera.height, camera.width), dtype=np.float32)
    context.color = np.empty((camera.height, camera.width, 4), dtype=np.uint8)
    clear_buffers(context.depth, context.color, options.background)


def draw_opaque_by_method(scene: Scene, camera: Camera, options: RenderOptions, context: FrameContext) -> None:
    """Stages 1–5 of the opaque items by a visible-surface method other than the depth buffer and the A-buffer,
    into ``context.depth`` and ``context.color``.

    The method writes the depth buffer's depth, face code and barycentrics of the surface it finds at each pixel
    (``visibility.window``); the shadow pass and ``stages.shade_item`` then shade them as for the depth buffer.
    """
    from frustum.visibility.window import window_triangles

    items = scene.items
    height, width = camera.height, camera.width
    counts = context.counter()
    offsets = face_offsets(items)
    opaque = [i for i, item in enumerate(items) if item.material.opacity >= 1.0]
    _clear(camera, options, context)
    lighting = Lighting.of(scene)
    scratch = context.scratch
    codes_dtype = code_type(items)  # the depth buffer's: the shading kernels are compiled for it already
    pixels = Pixels(context.depth, np.zeros((height, width), dtype=codes_dtype),
                    np.zeros((height, width, 2), dtype=np.float32), context.color, context.extra())  # fmt: skip
    module, name = VISIBILITY_METHODS[options.method].split(":")  # type: ignore[union-attr]
    draw = getattr(importlib.import_module(module), name)
    if options.method == "ray-casting":  # world-space rays through the scene's index, not window triangles
        counts.update(draw(scene, camera, options.cull, context.depth, pixels.codes, pixels.bary))
    else:
        tris = window_triangles(items, opaque, offsets, camera, options.cull)
        counts.update(draw(tris, context.depth, pixels.codes, pixels.bary))
    attributes = {index: world_attributes(items[index], scratch) for index in opaque}
    shadows.prepare(scene, items, [(i, attributes[i][0], offsets[i]) for i in opaque], camera, options, lighting,
                    pixels, context)  # fmt: skip
    for index in opaque:
        shadows.shade_item(items[index], index, offsets[index], camera, options, lighting, attributes[index], pixels,
                           (0, height), False, context)  # fmt: skip


def draw_transparent_by_method(scene: Scene, camera: Camera, options: RenderOptions, context: FrameContext) -> None:
    """Stage 6 after ``draw_opaque_by_method``: the transparent items through an A-buffer
    (``transparency="a-buffer"``) or back to front, each blended over the frame as the depth buffer does."""
    items = scene.items
    clear_items = [i for i, item in enumerate(items) if item.material.opacity < 1.0]
    if not clear_items:
        return
    if options.transparency == "a-buffer":
        composite_transparent(scene, camera, options, context)
        return
    draw_transparent(scene, items, camera, options, context)  # per-object sort, as the depth buffer does


def composite_transparent(scene: Scene, camera: Camera, options: RenderOptions, context: FrameContext) -> None:
    """``transparency="a-buffer"``: the transparent items' fragments composited per subsample over the finished
    opaque frame (behind its depth), their counts as ``transparent_*`` in ``context.counts``."""
    from frustum.visibility.window import window_triangles

    items = scene.items
    clear_items = [i for i, item in enumerate(items) if item.material.opacity < 1.0]
    if not clear_items:
        return
    counts = context.counter()
    offsets = face_offsets(items)
    depth = context.depth
    tris = window_triangles(items, clear_items, offsets, camera, options.cull)
    found = _composite(tris, items, offsets, camera, options, Lighting.of(scene), context.color, depth.copy(),
                       context.scratch, under_depth=depth)  # fmt: skip
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
