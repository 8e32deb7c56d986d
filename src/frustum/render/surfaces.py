"""The depth buffer's surface passes (stages 1–6 of ``frustum.render``'s docstring): ``draw_opaque``, the opaque
items stage by stage (every item binned and filled, then every item shaded) or, for a frame of one opaque mesh on
the directional path, tile by tile (``raster.tiled``); ``draw_transparent``, the transparent items back to front,
each blended over the frame. The driver draws what goes between them (the volumes)."""

from __future__ import annotations

import numpy as np

from frustum.camera import Camera
from frustum.render import pbr
from frustum.render.buffers import FrameBuffers, clear_buffers
from frustum.render.context import FrameContext
from frustum.render.options import RenderOptions
from frustum.render.shadows import passes as shadows
from frustum.render.stages import (
    TILED_BITS,
    Lighting,
    Pixels,
    bin_item,
    code_type,
    directional,
    draw_item,
    face_offsets,
    item_flags,
    shading_parameters,
    world_attributes,
)
from frustum.render.stages import draw_transparent as draw_transparent
from frustum.scene import Scene, SceneItem


def draw_opaque(scene: Scene, items: list[SceneItem], camera: Camera, options: RenderOptions,
                context: FrameContext) -> None:  # fmt: skip
    """Stages 1–5 for the opaque items of `items` into ``context.depth`` and ``context.color`` (recycled
    ``FrameBuffers``): every item binned and filled, the shadow pass, then every item shaded (or, for a frame of
    one opaque mesh, or of opaque meshes with shadow maps, ``shadows.tiled``, tile by tile)."""
    height, width = camera.height, camera.width
    opaque = [i for i, item in enumerate(items) if item.material.opacity >= 1.0]
    context.depth = depth = FrameBuffers.take((height, width), np.float32)
    context.color = color = FrameBuffers.take((height, width, 4), np.uint8)
    face_total = sum(item.mesh.face_count for item in items)
    lighting = Lighting.of(scene)
    scratch = context.scratch
    if len(items) == 1 and opaque and face_total and directional(items[0], options, lighting.lights):
        draw_tiled(items[0], camera, options, lighting, context)
    elif len(items) == 1 and opaque and face_total and pbr.tiled(items[0], options):
        draw_tiled_pbr(items[0], camera, options, lighting, context)
    elif len(opaque) == len(items) and face_total and shadows.tiled(scene, items, options, lighting.lights):
        shadows.draw_tiled(scene, items, camera, options, lighting, context)
    else:
        offsets = face_offsets(items)
        codes = scratch.empty((height, width), code_type(items))
        bary = scratch.empty((height, width, 2), np.float32)  # codes and bary are read only where depth < 1
        clear_buffers(depth, color, options.background)
        pixels = Pixels(depth, codes, bary, color, context.extra())
        drawn = []
        for index in opaque:
            world, normals, band = draw_item(items[index], camera, options.cull, offsets[index], pixels, scratch)
            drawn.append((index, world, normals, band))
        shadows.prepare(scene, items, [(i, w, offsets[i]) for i, w, _, _ in drawn], camera, options, lighting, pixels,
                        context)  # fmt: skip
        for index, world, normals, band in drawn:
            shadows.shade_item(items[index], index, offsets[index], camera, options, lighting, (world, normals),
                               pixels, band, False, context)  # fmt: skip
        scratch.recycle(bary)  # the transparent items' weights (draw_transparent)


def draw_tiled(
    item: SceneItem, camera: Camera, options: RenderOptions, lighting: Lighting, context: FrameContext
) -> None:  # fmt: skip
    """Stages 1–5 for a frame of one opaque mesh on the directional fast path: bin, then clear, fill and shade
    tile by tile (``raster.tiled``): the same bytes as the stage-by-stage path, without image-sized codes and
    weights or a second pass over the image."""
    from frustum.raster import tiled

    binned = bin_item(item, camera, options.cull, 0, context.scratch, tile_bits=TILED_BITS)
    world, normals = world_attributes(item, context.scratch)
    tiling = np.array([1 << TILED_BITS, binned.tiles_x, 0, camera.width, camera.height], dtype=np.int64)
    params = shading_parameters(item, camera, options, lighting.ambient)
    flags = item_flags(0, 0, options, False, False, False)
    tiled.draw_tiles_directional(
        binned.faces, binned.win_int, binned.win_float, binned.tri_int, binned.tri_float, binned.tri_weights,
        binned.tile_starts, binned.tile_entries, tiling, context.depth, world, normals, params, lighting.lights,
        flags, options.background, context.color,
    )  # fmt: skip


def draw_tiled_pbr(
    item: SceneItem, camera: Camera, options: RenderOptions, lighting: Lighting, context: FrameContext
) -> None:  # fmt: skip
    """``draw_tiled`` for an item of the metallic–roughness model (``render.pbr.tiled``; ``raster.pbr_tiled``): the
    same bytes as the stage-by-stage path's ``render.pbr.shade_item``."""
    from frustum.raster import pbr_tiled

    binned = bin_item(item, camera, options.cull, 0, context.scratch, tile_bits=TILED_BITS)
    world, normals = world_attributes(item, context.scratch)
    tiling = np.array([1 << TILED_BITS, binned.tiles_x, 0, camera.width, camera.height], dtype=np.int64)
    params = shading_parameters(item, camera, options, lighting.ambient)
    flags = item_flags(0, 0, options, False, False, False)
    sh, maps, table, lit = pbr.image_light(options)
    values = pbr.physical_parameters(item.material, options, lit)
    if lit:  # one roughness: the two levels around it blended once (render.pbr.blended_level)
        maps = pbr.blended_level(maps, values[pbr.kernel.Q_ROUGHNESS])
    pbr_tiled.draw_tiles_pbr(
        binned.faces, binned.win_int, binned.win_float, binned.tri_int, binned.tri_float, binned.tri_weights,
        binned.tile_starts, binned.tile_entries, tiling, context.depth, np.asarray(world, dtype=np.float64),
        np.asarray(normals, dtype=np.float64), params, lighting.lights, flags, options.background, context.color,
        values, sh, maps, table,
    )  # fmt: skip
