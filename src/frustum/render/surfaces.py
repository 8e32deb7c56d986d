"""The depth buffer's surface pass (stages 1–6 of ``frustum.render``'s docstring): opaque items stage by stage
(every item binned and filled, then every item shaded) or, for a frame of one opaque mesh on the directional
path, tile by tile (``raster.tiled``); then transparent items back to front, each blended over the frame."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from frustum.camera import Camera
from frustum.render.buffers import Buffers, FrameBuffers, clear_buffers
from frustum.render.options import RenderOptions
from frustum.render.shadows import passes as shadows
from frustum.render.stages import (
    TILED_BITS,
    Lighting,
    Pixels,
    back_to_front,
    bin_item,
    code_type,
    directional,
    draw_item,
    face_offsets,
    item_flags,
    shade_item,
    shading_parameters,
    world_attributes,
)
from frustum.scene import Scene, SceneItem


def draw_surfaces(
    scene: Scene, items: list[SceneItem], camera: Camera, options: RenderOptions, buffers: Buffers,
    between: Callable[[], None],
) -> None:  # fmt: skip
    """Stages 1–6 for every item of `items` into ``buffers.depth`` and ``buffers.color`` (recycled
    ``FrameBuffers``): the opaque items, then `between` (what is drawn over the opaque surfaces and under the
    transparent ones: the volumes), then the transparent items back to front."""
    height, width = camera.height, camera.width
    opaque = [i for i, item in enumerate(items) if item.material.opacity >= 1.0]
    clear_items = [i for i, item in enumerate(items) if item.material.opacity < 1.0]
    buffers.depth = depth = FrameBuffers.take((height, width), np.float32)
    buffers.color = color = FrameBuffers.take((height, width, 4), np.uint8)
    face_total = sum(item.mesh.face_count for item in items)
    codes_dtype = code_type(items)
    lighting = Lighting.of(scene)
    offsets = face_offsets(items)
    extra = buffers.extra()
    scratch = buffers.scratch
    bary = None
    if len(items) == 1 and opaque and face_total and directional(items[0], options, lighting.lights):
        draw_tiled(items[0], camera, options, lighting, buffers)
    elif len(items) == 1 and opaque and face_total and shadows.tiled(scene, items[0], options, lighting.lights):
        shadows.draw_tiled(scene, items[0], camera, options, lighting, buffers)
    else:
        codes = scratch.empty((height, width), codes_dtype)
        bary = scratch.empty((height, width, 2), np.float32)  # codes and bary are read only where depth < 1
        clear_buffers(depth, color, options.background)
        pixels = Pixels(depth, codes, bary, color, extra)
        drawn = []
        for index in opaque:
            world, normals, band = draw_item(items[index], camera, options.cull, offsets[index], pixels, scratch)
            drawn.append((index, world, normals, band))
        shadows.prepare(scene, items, [(i, w, offsets[i]) for i, w, _, _ in drawn], camera, options, lighting, pixels)
        for index, world, normals, band in drawn:
            shadows.shade_item(items[index], index, offsets[index], camera, options, lighting, (world, normals),
                               pixels, band, blend=False)  # fmt: skip
    between()
    if clear_items and bary is None:
        bary = scratch.empty((height, width, 2), np.float32)
    for index in back_to_front(items, clear_items, camera):
        item = items[index]
        layer = Pixels(depth.copy(), np.full((height, width), -1, dtype=codes_dtype), bary, color, extra)
        world, normals, band = draw_item(item, camera, options.cull, offsets[index], layer, scratch)
        shade_item(item, index, offsets[index], camera, options, lighting, (world, normals), layer, band,
                   blend=True)  # fmt: skip


def draw_tiled(item: SceneItem, camera: Camera, options: RenderOptions, lighting: Lighting, buffers: Buffers) -> None:
    """Stages 1–5 for a frame of one opaque mesh on the directional fast path: bin, then clear, fill and shade
    tile by tile (``raster.tiled``): the same bytes as the stage-by-stage path, without image-sized codes and
    weights or a second pass over the image."""
    from frustum.raster import tiled

    binned = bin_item(item, camera, options.cull, 0, buffers.scratch, tile_bits=TILED_BITS)
    world, normals = world_attributes(item, buffers.scratch)
    tiling = np.array([1 << TILED_BITS, binned.tiles_x, 0, camera.width, camera.height], dtype=np.int64)
    params = shading_parameters(item, camera, options, lighting.ambient)
    flags = item_flags(0, 0, options, False, False, False)
    tiled.draw_tiles_directional(
        binned.faces, binned.win_int, binned.win_float, binned.tri_int, binned.tri_float, binned.tri_weights,
        binned.tile_starts, binned.tile_entries, tiling, buffers.depth, world, normals, params, lighting.lights,
        flags, options.background, buffers.color,
    )  # fmt: skip
