"""The shadow pass's place in the surface passes: between filling the depth buffer with the opaque items and shading
them, ``prepare`` finds each drawn pixel's world point and, with shadows on, the fraction of each light reaching
it (``render.shadows.fractions``: shadow maps drawn by ``fractions.draw_depth``, the renderer's own binning and
tile fill from the light, or shadow rays), into the frame's context; ``shade_item`` then shades with those
fractions (``raster.shadow``) or, where there are none, exactly as ``stages.shade_item`` does. Off the ordinary
path: nothing here runs, and no kernel of ``raster.shadow`` compiles, unless ``render`` is asked for shadows or the
"position" buffer."""

from __future__ import annotations

import dataclasses

import numpy as np

from frustum.budgets import check_memory
from frustum.camera import Camera
from frustum.geometry import Mesh
from frustum.raster import shade
from frustum.render import bumps, pbr, reflection
from frustum.render.buffers import give_back, take_array
from frustum.render.context import FrameContext
from frustum.render.options import RenderOptions
from frustum.render.stages import (
    TILED_BITS,
    Lighting,
    Pixels,
    bin_item,
    directional,
    item_flags,
    shading_parameters,
    world_attributes,
    world_faces,
)  # fmt: skip
from frustum.render.stages import shade_item as shade_item_plainly
from frustum.scene import Scene, SceneItem

SHADOWED_MODES = (shade.SHADE_PHONG, shade.SHADE_GOURAUD, shade.SHADE_FLAT, pbr.SHADE_PBR)
"""Shading modes in which shadows darken the picture (``"none"``, ``"normals"`` and ``"depth"`` ignore them)."""


def prepare(
    scene: Scene, items: list[SceneItem], drawn: list[tuple[int, np.ndarray, int]], camera: Camera,
    options: RenderOptions, lighting: Lighting, pixels: Pixels, context: FrameContext,
) -> None:  # fmt: skip
    """World points of the drawn opaque pixels (items ``(index, world positions, face offset)``) and, with shadows
    on, each light's fraction reaching them, into ``context.outputs`` ("position", "seen", "casting"). Nothing
    where neither shadows nor the "position" buffer are asked for (``options.positions_wanted``)."""
    if not options.positions_wanted:
        return
    from frustum.render.shadows import fractions  # the shadow maps' module: loaded by the first frame that needs it

    points, facing = fractions.surface_points(items, drawn, pixels.depth, pixels.codes, pixels.bary,
                                              options.shadow is not None)  # fmt: skip
    context.outputs["position"] = points
    if options.shadow is not None:
        context.outputs["seen"] = fractions.light_fractions(
            scene, items, camera, options.shadow, lighting.lights, pixels.depth, points, facing, "render"
        )
        context.outputs["casting"] = np.array(fractions.shadow_lights(scene)[0], dtype=np.int64)
    give_back(facing)


def shade_item(
    item: SceneItem, index: int, face_offset: int, camera: Camera, options: RenderOptions, lighting: Lighting,
    attributes: tuple[np.ndarray, np.ndarray], pixels: Pixels, band: tuple[int, int], blend: bool,
    context: FrameContext,
) -> None:  # fmt: skip
    """``stages.shade_item`` with shadows: an opaque item in a shadowed mode goes through
    ``raster.shadow.shade_pixels_shadowed`` with the fractions ``prepare`` found (an item with a bump or normal
    map in Phong shading: ``bumps.shade_detailed`` with those fractions; an environment to reflect is blended in
    afterwards, as without shadows); anything else is shaded as without shadows (transparent items receive
    none)."""
    seen = context.outputs.get("seen")
    plain = seen is None or blend or options.shade_mode not in SHADOWED_MODES or seen.shape[:2] != pixels.codes.shape
    if plain:
        shade_item_plainly(item, index, face_offset, camera, options, lighting, attributes, pixels, band, blend)
        return
    from frustum.raster import shadow

    mesh, material = item.mesh, item.material
    ambient, lights = lighting
    rows = slice(*band)
    codes = pixels.codes[rows]
    write_normals = pixels.extra[0].shape[:2] == pixels.codes.shape
    write_ids = pixels.extra[1].shape == pixels.codes.shape
    extra = (pixels.extra[0][rows] if write_normals else pixels.extra[0],
             pixels.extra[1][rows] if write_ids else pixels.extra[1])  # fmt: skip
    params = shading_parameters(item, camera, options, ambient)
    faces = world_faces(item) if mesh.face_count else np.empty((0, 3), dtype=np.int64)
    world, normals = (np.asarray(a, dtype=np.float64) for a in attributes)
    flags = item_flags(index, face_offset, options, blend, write_normals, write_ids)
    if pbr.applies(item, options):  # the metallic–roughness model with each light's fraction (render.pbr)
        pbr.shade_item(item, index, face_offset, camera, options, params, lights, (world, normals), faces,
                       (pixels.depth[rows], codes, pixels.bary[rows], pixels.color[rows], *extra), blend, flags,
                       seen=seen[rows])  # fmt: skip
        return
    if options.shade_mode == shade.SHADE_PHONG and bumps.has_detail(item):  # per-pixel normals from the maps
        bumps.shade_detailed(item, faces, world, normals, params, lights, flags, pixels.depth[rows], codes,
                             pixels.bary[rows], pixels.color[rows], extra, seen=seen[rows])  # fmt: skip
    else:
        lit = lit_per_light(mesh, faces, world, normals, params, lights, options)
        vertex_colors = getattr(mesh, "vertex_colors", None)
        vertex_colors = (np.empty((0, 3)) if vertex_colors is None
                         else np.ascontiguousarray(vertex_colors[:, :3], float))  # fmt: skip
        uvs, texture = getattr(mesh, "uvs", None), material.texture
        if texture is None or uvs is None:
            texture, uvs = np.empty((0, 0, 4), dtype=np.float32), np.empty((0, 2))
        else:
            uvs = np.ascontiguousarray(uvs, dtype=np.float64)
        shadow.shade_pixels_shadowed(
            pixels.depth[rows], codes, pixels.bary[rows], faces, world, normals, lit, vertex_colors, uvs, texture,
            params, lights, flags, seen[rows], pixels.color[rows], extra[0], extra[1],
        )  # fmt: skip
    if options.environment is not None and material.reflectivity > 0.0:
        reflection.reflect(faces, face_offset, material.reflectivity, camera, options, normals, pixels.depth[rows],
                           codes, pixels.bary[rows], pixels.color[rows], band[0])  # fmt: skip


def lit_per_light(
    mesh: Mesh, faces: np.ndarray, world: np.ndarray, normals: np.ndarray, params: np.ndarray, lights: np.ndarray,
    options: RenderOptions,
) -> np.ndarray:  # fmt: skip
    """Gouraud (per vertex) or flat (per face) terms kept apart per light: (rows, 3 + 6·K) with the ambient term
    first, then each light's (D, S) without ambient (``raster.shadow.shade_pixels_shadowed``); empty for Phong."""
    mode = options.shade_mode
    if mode == shade.SHADE_PHONG or mesh.face_count == 0:
        return np.empty((0, 3 + 6 * lights.shape[0]))
    count = mesh.vertex_count if mode == shade.SHADE_GOURAUD else mesh.face_count
    lit = np.empty((count, 3 + 6 * lights.shape[0]))
    lit[:, :3] = params[shade.P_AMBIENT] * params[shade.P_LIGHT_AMBIENT : shade.P_LIGHT_AMBIENT + 3]
    unlit = params.copy()
    unlit[shade.P_LIGHT_AMBIENT : shade.P_LIGHT_AMBIENT + 3] = 0.0
    terms = np.empty((count, 6))
    for k in range(lights.shape[0]):
        one = np.ascontiguousarray(lights[k : k + 1])
        if mode == shade.SHADE_GOURAUD:
            shade.light_vertices(world, normals, unlit, one, options.specular_model, terms)
        else:
            shade.light_faces(world, faces, unlit, one, options.specular_model, terms)
        lit[:, 3 + 6 * k : 9 + 6 * k] = terms
    return lit


def tiled(scene: Scene, items: list[SceneItem], options: RenderOptions, lights: np.ndarray) -> bool:
    """Whether a frame of these opaque meshes with shadow maps goes through the tile pipeline with shadows
    (``draw_tiled``): every item with faces, shading that is the directional fast path's without shadows
    (``stages.directional``) and no buffer to read back."""
    if options.shadow is None or options.shadow.method != "map" or options.buffers or not items:
        return False
    plain = dataclasses.replace(options, shadow=None)
    return all(item.mesh.face_count > 0 and directional(item, plain, lights) for item in items)


def draw_tiled(
    scene: Scene, items: list[SceneItem], camera: Camera, options: RenderOptions, lighting: Lighting,
    context: FrameContext,
) -> None:  # fmt: skip
    """Stages 1–5 of a frame of opaque meshes with shadow maps, tile by tile (``raster.shadow_tiled``): several
    items are drawn as one world-space mesh (``merged.merge``, each face shaded with its item's parameters), each
    shadow-casting (directional) light's map is fitted to what the camera can see of the meshes before anything is
    drawn (``fractions.view_map``) and filled in one pass per culling (``fractions.caster_groups``), or taken as
    it is from an earlier frame where nothing it depends on changed (``fractions.kept_maps``: the same vertex and
    face bytes and modeling transform of every item, light camera and size, as in a turntable of a model the
    camera sees whole under a fixed sun); then each tile is filled and shaded, the map lookups made per pixel
    inside the shading (no image-sized world points, normals or fractions)."""
    from frustum.raster import shadow, shadow_tiled
    from frustum.render.shadows import fractions, merged

    size, softness = options.shadow.map_size, float(options.shadow.softness)
    rows, casting = fractions.shadow_lights(scene)
    keys = [fractions.casters_key(item, bool(item.mesh.is_watertight)) for item in items] if casting else []
    casters = None if not keys or any(key is None for key in keys) else tuple(keys)
    if len(items) == 1:
        item, owner = items[0], np.empty(0, dtype=np.int32)
        world, normals = world_attributes(item, context.scratch)
        casters = casters[0] if casters else None
    else:
        kept = None if not keys or any(key is None for key in keys) else ("frame", *keys)
        one = merged.merge(items, kept)
        item, owner, world, normals = one.item, one.owner, one.item.mesh.vertices, one.normals
    binned = bin_item(item, camera, options.cull, 0, context.scratch, tile_bits=TILED_BITS)
    fitted = [fractions.view_map(light, world, camera, size, softness, casters) for light in casting]
    records = [(row, found) for row, found in zip(rows, fitted, strict=True) if found is not None]
    check_memory(len(records) * size * size * 4, where="render",
                 cause=f"shadow_map_size = {size} with {len(records)} shadow-casting light(s)")  # fmt: skip
    lights = lighting.lights
    shape = (max(len(records), 1), size, size)
    views = np.zeros((shape[0], shadow.MAP_FIELDS))
    map_of = np.full(lights.shape[0], -1, dtype=np.int64)
    for m, (row, (light_camera, texel)) in enumerate(records):
        views[m] = fractions.map_record(light_camera, texel, None)
        map_of[row] = m
    key = None
    if records:  # the maps depend on the casters, the light cameras and nothing else: reused while those stay
        key = fractions.map_key(casters, [found[0] for _, found in records], views)
    maps = fractions.kept_maps(key, shape)
    if maps is None:
        maps = take_array(shape, np.float32)
        groups = fractions.caster_groups(items, keys) if records and len(items) > 1 else [(item, None)]
        for m, (_, (light_camera, _)) in enumerate(records):
            for number, (caster, cull) in enumerate(groups):
                fractions.draw_depth(caster, light_camera, maps[m], number == 0, cull)
    tiling = np.array([1 << TILED_BITS, binned.tiles_x, 0, camera.width, camera.height], dtype=np.int64)
    params = np.array([shading_parameters(placed, camera, options, lighting.ambient) for placed in items])
    flags = item_flags(0, 0, options, False, False, False)
    shadow_tiled.draw_tiles_shadowed(
        binned.faces, binned.win_int, binned.win_float, binned.tri_int, binned.tri_float, binned.tri_weights,
        binned.tile_starts, binned.tile_entries, tiling, context.depth, world, normals, params, lights,
        flags, options.background, context.color, maps, views, map_of, softness, owner,
    )  # fmt: skip
    fractions.keep_maps(key, maps)
