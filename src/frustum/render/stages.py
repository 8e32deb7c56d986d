"""The stages of one placed mesh, shared by the passes that draw surfaces: its matrices, the vertex stage, triangle
setup and binning into screen tiles (``bin_item``), the tile fill (``draw_item``), world positions and normals
(``world_attributes``), and deferred shading of its pixels (``shade_item``); the back-to-front order of
transparent items. Plain functions of an item, the camera, the options and the pixel arrays: no pass state."""

from __future__ import annotations

import dataclasses
from typing import NamedTuple

import numpy as np

from frustum.camera import Camera
from frustum.clipping import VIEW_VOLUME_PLANES
from frustum.raster import shade, tiles, triangles
from frustum.raster._jit import threads
from frustum.raster.vertices import project_vertices, transform_normals, world_points
from frustum.render import bumps, pbr, reflection
from frustum.render.buffers import Scratch
from frustum.render.context import FrameContext
from frustum.render.options import GROUND_TRUTH_BUFFERS, RenderOptions
from frustum.scene import Scene, SceneItem
from frustum.shading import pack_lights
from frustum.visibility.window import clip_crossing

TILE_BITS = 5
TILE_SIZE = 1 << TILE_BITS
"""Side of a square screen tile in pixels (32): the unit of parallel work of the rasterizer."""
TILED_BITS = 6
"""Tiles of the one-mesh tile pipeline (``raster.tiled``) are 64 pixels square: 3–5 % less CPU than 32 there (fewer
triangles spanning two tiles); the general path keeps 32, whose bands bound each small item's shading rows."""
ONE_PASS_CLIPPING = 16384
"""Up to this many faces crossing the view volume are clipped in one pass into ``triangles.FAN_MAX`` record slots
each (at most 21 MiB of records); more are counted first, then written (two passes, no slots to spare)."""
KERNEL_MIN_VERTICES = 65536
"""Meshes with fewer vertices get their world points and normals (and lines and edges their clip coordinates) from
NumPy rather than the ``raster.vertices`` kernels: the same operations in the same order, so the same bits, and
no kernel to compile for a small scene (the README example's cold start)."""
_BIN_CHUNK = 16384


class Lighting(NamedTuple):
    """The scene's lights packed for ``raster.shade``: ambient RGB (3,) and the light records (L, LIGHT)."""

    ambient: np.ndarray
    lights: np.ndarray

    @classmethod
    def of(cls, scene: Scene) -> Lighting:
        return cls(*pack_lights(scene.world_lights()))


@dataclasses.dataclass(frozen=True)
class Pixels:
    """The per-pixel arrays the tile fill writes and the shader reads: window ``depth`` (H, W) float32, face
    ``codes`` (H, W) and barycentrics ``bary`` (H, W, 2) float32; and what the shader writes: ``color``
    (H, W, 4) uint8 and ``extra``, the normal and object-id outputs (1-pixel dummies where not asked for)."""

    depth: np.ndarray
    codes: np.ndarray
    bary: np.ndarray
    color: np.ndarray
    extra: tuple[np.ndarray, np.ndarray]


def item_matrices(item: SceneItem, camera: Camera | None) -> np.ndarray:
    """(3, 4, 4): clip_from_model (zeros without a camera), world_from_model, and the normal matrix (inverse
    transpose) in a 4x4."""
    world_from_model = np.asarray(item.world_from_model, dtype=np.float64)
    matrices = np.zeros((3, 4, 4))
    if camera is not None:
        matrices[0] = camera.clip_from_world @ world_from_model
    matrices[1] = world_from_model
    matrices[2, :3, :3] = np.linalg.inv(world_from_model[:3, :3]).T
    matrices[2, 3, 3] = 1.0
    return matrices


def rows(points: np.ndarray, m: np.ndarray, count: int, affine: bool) -> np.ndarray:
    """Rows 0..count−1 of $M·[x, y, z, 1]$ summed left to right, $((m0·x + m1·y) + m2·z) + m3$ (``affine``),
    or of $A·[x, y, z]$, $(a0·x + a1·y) + a2·z$ — ``raster.vertices._affine_row`` / ``_linear_row`` in NumPy."""
    x, y, z = (np.asarray(points[:, k], dtype=np.float64) for k in range(3))
    summed = [(m[k, 0] * x + m[k, 1] * y) + m[k, 2] * z for k in range(count)]
    return np.stack([row + m[k, 3] for k, row in enumerate(summed)] if affine else summed, axis=1)


def world_faces(item: SceneItem) -> np.ndarray:
    """The item's faces, counter-clockwise seen from the front *after* its modeling transform: a transform that
    swaps handedness (det < 0, e.g. a reflection) turns the winding around, so corners 1 and 2 are swapped."""
    faces = item.mesh.faces
    (a, b, c), (d, e, f), (g, h, i) = np.asarray(item.world_from_model)[:3, :3].tolist()
    if a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g) < 0.0:  # det < 0
        return np.ascontiguousarray(faces[:, [0, 2, 1]])
    return faces


def world_attributes(item: SceneItem, scratch: Scratch) -> tuple[np.ndarray, np.ndarray]:
    """World positions and unit world normals of the item's vertices (``raster.vertices``); the mesh's own arrays
    where the modeling transform leaves them unchanged (identity, or a translation for the normals: the Mesh's
    normals are unit already)."""
    mesh = item.mesh
    model = np.asarray(item.world_from_model, dtype=np.float64)
    world, normals = mesh.vertices, mesh.vertex_normals
    small = mesh.vertex_count < KERNEL_MIN_VERTICES  # NumPy: the same operations in order, no kernel to compile
    if not np.array_equal(model, np.eye(4)):
        if small:
            world = rows(mesh.vertices, model, 3, affine=True)
        else:
            world = scratch.empty((mesh.vertex_count, 3))
            world_points(mesh.vertices, model, world)
    if not np.array_equal(model[:3, :3], np.eye(3)):
        normal_matrix = item_matrices(item, None)[2]
        if small:
            normals = rows(mesh.vertex_normals, normal_matrix, 3, affine=False)
            normals /= np.sqrt((normals[:, :1] * normals[:, :1] + normals[:, 1:2] * normals[:, 1:2])
                               + normals[:, 2:] * normals[:, 2:])  # fmt: skip
        else:
            normals = scratch.empty((mesh.vertex_count, 3))
            transform_normals(mesh.vertex_normals, normal_matrix, normals)
    return world, normals


@dataclasses.dataclass(frozen=True)
class Binned:
    """One item after the vertex stage, triangle setup and binning: everything the tile fill reads.

    ``win_int`` (N, 2) snapped window ``X, Y`` and ``win_float`` (N, 4) ``z_w, 1/w`` and the snap residuals of the
    vertices inside the view volume (``vertex_codes == 0``; other rows are undefined); the clipped triangles'
    records ``tri_int``, ``tri_float``, ``tri_weights`` (``raster.triangles``) of the ``crossing`` faces; tile t's
    entries, in drawing order, ``tile_entries[tile_starts[t]:tile_starts[t + 1]]``: a face index f >= 0 or
    $−1 − r$ for record r; ``tiles_x`` tiles of ``TILE_SIZE`` pixels per row.
    """

    faces: np.ndarray
    win_int: np.ndarray
    win_float: np.ndarray
    vertex_codes: np.ndarray
    crossing: np.ndarray
    tri_int: np.ndarray
    tri_float: np.ndarray
    tri_weights: np.ndarray
    tile_starts: np.ndarray
    tile_entries: np.ndarray
    tiles_x: int


def bin_item(
    item: SceneItem, camera: Camera, cull: bool, face_offset: int = 0, scratch: Scratch | None = None,
    tile_bits: int = TILE_BITS,
) -> Binned:  # fmt: skip
    """Stages 1–3 for one placed mesh with faces (``frustum.render``'s docstring): project, set up, clip, cull and
    bin into tiles of ``2^tile_bits`` pixels (work arrays from `scratch`, if given)."""
    empty = np.empty if scratch is None else scratch.empty
    mesh = item.mesh
    faces = world_faces(item)
    width, height = camera.width, camera.height
    view = np.array([width / 2.0, height / 2.0])
    clip_from_model = item_matrices(item, camera)[0]
    small = triangles.SUBPIXEL * (max(width, height) + 2) < 2**31
    win_int = empty((mesh.vertex_count, 2), np.int32 if small else np.int64)
    win_float = empty((mesh.vertex_count, 4), np.float64)  # z_w, 1/w and the snap residuals (depth_plane)
    vertex_codes = empty((mesh.vertex_count,), np.uint8)  # 6 view-volume planes: one bit each
    project_vertices(mesh.vertices, clip_from_model, view, win_int, win_float, vertex_codes)
    # per face: reject / accept / crossing, cull, box, count its tiles (parallel over chunks of faces)
    tiles_x, tiles_y = -(-width >> tile_bits), -(-height >> tile_bits)
    chunk_count = min(max(1, -(-faces.shape[0] // _BIN_CHUNK)), 4 * threads())
    chunk = max(1, -(-faces.shape[0] // chunk_count))
    chunk_count = -(-faces.shape[0] // chunk)
    options = np.array([width, height, int(cull), tile_bits, tiles_x, chunk, face_offset], dtype=np.int64)
    counts = np.empty((chunk_count, tiles_x * tiles_y), dtype=np.int64)
    crossing_counts = np.empty(chunk_count, dtype=np.int64)
    listed = empty((faces.shape[0],), np.int32 if faces.shape[0] < 2**31 else np.int64)
    listed_tiles = empty((faces.shape[0],), np.int32)
    listed_counts = np.empty(chunk_count, dtype=np.int64)
    tiles.count_tiles(
        faces, vertex_codes, win_int, options, counts, crossing_counts, listed, listed_tiles, listed_counts
    )
    # the crossing faces: clipped into records (count, prefix sum, write), which join their face's chunk
    crossing_starts = np.concatenate([[0], np.cumsum(crossing_counts)])
    crossing = np.empty(int(crossing_starts[-1]), dtype=np.int64)
    tri_int = np.empty((0, triangles.RECORD_FIELDS), dtype=np.int64)
    tri_float, tri_weights = np.empty((0, 3, 4)), np.empty((0, 3, 2))
    record_starts = np.zeros(crossing.shape[0] + 1, dtype=np.int64)
    if crossing.shape[0]:
        triangles.list_crossing(listed, listed_tiles, chunk, listed_counts, crossing_starts[:-1], crossing)
        clip_options = np.array([width, height, int(cull), face_offset, 0], dtype=np.int64)
        arguments = (crossing, faces, mesh.vertices, clip_from_model, VIEW_VOLUME_PLANES, view, clip_options)
        if crossing.shape[0] <= ONE_PASS_CLIPPING:  # clip once into FAN_MAX slots per face, then close the gaps
            slots = crossing.shape[0] * triangles.FAN_MAX
            tri_int = np.empty((slots, triangles.RECORD_FIELDS), dtype=np.int64)
            tri_float, tri_weights = np.empty((slots, 3, 4)), np.empty((slots, 3, 2))
            made = np.arange(0, slots, triangles.FAN_MAX, dtype=np.int64)  # first slots in, record counts out
            clip_options[4] = 2
            triangles.clip_faces(*arguments, made, tri_int, tri_float, tri_weights)
            kept = (np.arange(triangles.FAN_MAX) < made[:, None]).ravel()
            tri_int, tri_float, tri_weights = tri_int[kept], tri_float[kept], tri_weights[kept]
            record_starts[1:] = np.cumsum(made)
        else:  # count, prefix sum, write (no slots to spare for a mesh crossing the view volume everywhere)
            record_starts, tri_int, tri_float, tri_weights = clip_crossing(arguments)
        tiles.add_record_tiles(tri_int, options, counts)
    offsets, tile_starts = tile_offsets(counts)
    entry_type = np.int32 if max(faces.shape[0], tri_int.shape[0] + 1) < 2**31 else np.int64
    tile_entries = empty((int(tile_starts[-1]),), entry_type)
    tiles.fill_tiles(
        faces, vertex_codes, win_int, options, listed, listed_tiles, listed_counts, offsets, crossing_starts[:-1],
        record_starts, tri_int, tile_entries,
    )  # fmt: skip
    if scratch is not None:
        scratch.recycle(listed, listed_tiles)
    return Binned(faces, win_int, win_float, vertex_codes, crossing, tri_int, tri_float, tri_weights, tile_starts,
                  tile_entries, tiles_x)  # fmt: skip


def tile_offsets(counts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(offsets, tile_starts)`` of the binning's counts (C, tiles): the exclusive prefix sum in tile-major order,
    ``offsets[c, t]`` (C-contiguous int64) where chunk c writes in tile t's list, and each tile's first slot
    followed by the total, (tiles + 1,) int64."""
    flat = counts.T.ravel()  # tile-major: chunk c's entries precede chunk c + 1's within every tile
    ends = np.cumsum(flat)
    starts = (ends - flat).reshape(counts.shape[1], counts.shape[0])
    tile_starts = np.empty(counts.shape[1] + 1, dtype=np.int64)
    tile_starts[:-1] = starts[:, 0]
    tile_starts[-1] = ends[-1]
    return np.ascontiguousarray(starts.T), tile_starts


def draw_item(
    item: SceneItem, camera: Camera, cull: bool, face_offset: int, pixels: Pixels, scratch: Scratch
) -> tuple[np.ndarray, np.ndarray, tuple[int, int]]:  # fmt: skip
    """Stages 1–4 for one placed mesh into ``pixels``' depth, codes and barycentrics; returns its world positions,
    unit world normals and the image rows [first, last) of the tiles it touches."""
    mesh = item.mesh
    if mesh.face_count == 0:
        return np.empty((0, 3)), np.empty((0, 3)), (0, 0)
    depth = pixels.depth
    binned = bin_item(item, camera, cull, face_offset, scratch)
    used = np.flatnonzero(np.diff(binned.tile_starts)) // binned.tiles_x  # tile rows, window y up
    height = depth.shape[0]
    band = (0, 0) if used.size == 0 else (max(height - (int(used[-1]) + 1) * TILE_SIZE, 0),
                                          min(height - int(used[0]) * TILE_SIZE, height))  # fmt: skip
    tiling = np.array([TILE_SIZE, binned.tiles_x, face_offset, depth.shape[1], height], dtype=np.int64)
    triangles.rasterize_tiles(
        binned.faces, binned.win_int, binned.win_float, binned.tri_int, binned.tri_float, binned.tri_weights,
        binned.tile_starts, binned.tile_entries, tiling, depth, pixels.codes, pixels.bary,
    )  # fmt: skip
    scratch.recycle(binned.win_int, binned.win_float, binned.vertex_codes, binned.tile_entries)
    return (*world_attributes(item, scratch), band)


def shading_parameters(item: SceneItem, camera: Camera, options: RenderOptions, ambient: np.ndarray) -> np.ndarray:
    """(PARAMS,) float64 in the layout of ``raster.shade``: eye, material, ambient light, view axis, cueing."""
    material = item.material
    params = np.zeros(shade.PARAMS)
    params[shade.P_EYE : shade.P_EYE + 3] = camera.frame.eye
    params[shade.P_COLOR : shade.P_COLOR + 3] = material.color
    params[shade.P_AMBIENT], params[shade.P_DIFFUSE] = material.ambient, material.diffuse
    params[shade.P_SPECULAR], params[shade.P_SHININESS] = material.specular, material.shininess
    params[shade.P_EMISSIVE : shade.P_EMISSIVE + 3] = material.emissive
    params[shade.P_LIGHT_AMBIENT : shade.P_LIGHT_AMBIENT + 3] = ambient
    params[shade.P_VIEW_AXIS : shade.P_VIEW_AXIS + 3] = camera.frame.n
    cue = options.depth_cue
    if cue is not None:
        params[shade.P_CUE_ON] = 1.0
        params[shade.P_CUE_NEAR], params[shade.P_CUE_FAR] = cue.near, cue.far
        params[shade.P_CUE_MIN], params[shade.P_CUE_MAX] = cue.min_intensity, cue.max_intensity
        params[shade.P_CUE_COLOR : shade.P_CUE_COLOR + 3] = cue_color(options)
    params[shade.P_DEPTH_NEAR], params[shade.P_DEPTH_FAR] = camera.projection.near, camera.projection.far
    params[shade.P_OPACITY] = material.opacity
    return params


def cue_color(options: RenderOptions) -> np.ndarray:
    """The depth cue's color in [0, 1]: its own, or the background's."""
    cue = options.depth_cue
    return options.background[:3] / 255.0 if cue is None or cue.color is None else np.asarray(cue.color)


IDS_APART = frozenset(("object_id", "position", *GROUND_TRUTH_BUFFERS))
"""Buffers the fast shading kernels allow when the item ids are filled apart, from the face codes
(``raster.ground_truth.item_ids``): none of them is written by a shading kernel but the ids."""


def directional(item: SceneItem, options: RenderOptions, lights: np.ndarray, ids_apart: bool = False) -> bool:
    """Whether the item shades through ``shade.shade_pixels_directional``: per-pixel Blinn-Phong, directional
    lights only, no vertex colors, texture, depth cue, blending or extra buffers (with `ids_apart`, ids and the
    buffers computed from them allowed: the caller fills the ids)."""
    mesh = item.mesh
    return (
        item.material.opacity >= 1.0
        and options.shade_mode == shade.SHADE_PHONG and options.specular_model == shade.SPECULAR_BLINN
        and bool((lights[:, 0] == 0.0).all()) and getattr(mesh, "vertex_colors", None) is None
        and (item.material.texture is None or getattr(mesh, "uvs", None) is None)
        and options.depth_cue is None and options.shadow is None and _plain_surface(item, options)
        and (not options.buffers or (ids_apart and IDS_APART.issuperset(options.buffers)))
    )  # fmt: skip


def _plain_surface(item: SceneItem, options: RenderOptions) -> bool:
    """A classical material with no bump or normal map to shade per pixel, and no environment to reflect."""
    material = item.material
    return material.model == "phong" and material.bump is None and material.normal_map is None and (
        options.environment is None or material.reflectivity == 0.0
    )


def _plain_phong(item: SceneItem, options: RenderOptions, ids_apart: bool = False) -> bool:
    """Whether the item shades through ``shade.shade_pixels_phong``: per-pixel Phong with any lights and no vertex
    colors, texture, depth cue, blending or extra buffers (`ids_apart`: as for ``directional``)."""
    mesh = item.mesh
    return (
        item.material.opacity >= 1.0 and options.shade_mode == shade.SHADE_PHONG
        and getattr(mesh, "vertex_colors", None) is None
        and (item.material.texture is None or getattr(mesh, "uvs", None) is None)
        and options.depth_cue is None and _plain_surface(item, options)
        and (not options.buffers or (ids_apart and IDS_APART.issuperset(options.buffers)))
    )  # fmt: skip


def item_flags(
    index: int, face_offset: int, options: RenderOptions, blend: bool, write_normals: bool, write_ids: bool
) -> np.ndarray:  # fmt: skip
    """The (ITEM,) int64 item record of ``raster.shade``."""
    flags = np.zeros(shade.ITEM, dtype=np.int64)
    flags[shade.I_FACE_OFFSET], flags[shade.I_MODE] = face_offset, options.shade_mode
    flags[shade.I_SPECULAR_MODEL], flags[shade.I_OBJECT_ID] = options.specular_model, index
    flags[shade.I_WRITE_NORMALS], flags[shade.I_WRITE_IDS] = int(write_normals), int(write_ids)
    flags[shade.I_BLEND] = int(blend)
    return flags


def shade_item(
    item: SceneItem, index: int, face_offset: int, camera: Camera, options: RenderOptions, lighting: Lighting,
    attributes: tuple[np.ndarray, np.ndarray], pixels: Pixels, band: tuple[int, int], blend: bool,
) -> None:  # fmt: skip
    """Stage 5 for one item: shade its pixels (the background is painted when the buffers are cleared), scanning
    only the image rows ``[band[0], band[1])`` its tiles cover (a scene of many small meshes shades each in its
    band). `attributes`: its world positions and unit world normals (``world_attributes``)."""
    mesh, material = item.mesh, item.material
    ambient, lights = lighting
    world, normals = attributes
    codes = pixels.codes
    write_normals = pixels.extra[0].shape[:2] == codes.shape
    write_ids = pixels.extra[1].shape == codes.shape
    rows_ = slice(*band)
    depth, codes, bary, color = pixels.depth[rows_], codes[rows_], pixels.bary[rows_], pixels.color[rows_]
    extra = (pixels.extra[0][rows_] if write_normals else pixels.extra[0],
             pixels.extra[1][rows_] if write_ids else pixels.extra[1])  # fmt: skip
    params = shading_parameters(item, camera, options, ambient)
    faces = world_faces(item) if mesh.face_count else np.empty((0, 3), dtype=np.int64)
    if pbr.applies(item, options):  # the metallic–roughness model (render.pbr)
        flags = item_flags(index, face_offset, options, blend, write_normals, write_ids)
        pbr.shade_item(item, index, face_offset, camera, options, params, lights, attributes, faces,
                       (depth, codes, bary, color, *extra), blend, flags)  # fmt: skip
        return
    if options.shade_mode == shade.SHADE_PHONG and bumps.has_detail(item):  # per-pixel normals from the maps
        flags = item_flags(index, face_offset, options, blend, write_normals, write_ids)
        bumps.shade_detailed(item, faces, world, normals, params, lights, flags, depth, codes, bary, color, extra)
    else:
        _shade_pixels(item, index, face_offset, options, lights, params, faces, world, normals, depth, codes, bary,
                      color, extra, blend, write_normals, write_ids)  # fmt: skip
    if options.environment is not None and material.reflectivity > 0.0:
        reflection.reflect(faces, face_offset, material.reflectivity, camera, options, np.asarray(normals, float),
                           depth, codes, bary, color, band[0])  # fmt: skip


def _shade_pixels(
    item: SceneItem, index: int, face_offset: int, options: RenderOptions, lights: np.ndarray, params: np.ndarray,
    faces: np.ndarray, world: np.ndarray, normals: np.ndarray, depth: np.ndarray, codes: np.ndarray, bary: np.ndarray,
    color: np.ndarray, extra: tuple[np.ndarray, np.ndarray], blend: bool, write_normals: bool, write_ids: bool,
) -> None:  # fmt: skip
    """The shading kernel for the item's pixels: the directional or plain Phong fast paths where they apply."""
    mesh, material = item.mesh, item.material
    mode = options.shade_mode
    apart = not write_normals  # item ids, if asked for, filled from the face codes after a fast kernel
    if not blend and directional(item, options, lights, apart):  # the same bytes without the general branches
        flags = item_flags(index, face_offset, options, blend, False, False)
        shade.shade_pixels_directional(depth, codes, bary, faces, world, normals, params, lights, flags, color)
        _fill_ids(index, face_offset, mesh.face_count, depth, codes, extra[1], write_ids)
        return
    if not blend and _plain_phong(item, options, apart):  # the same bytes, without the other models' branches
        flags = item_flags(index, face_offset, options, blend, False, False)
        shade.shade_pixels_phong(depth, codes, bary, faces, world, normals, params, lights, flags, color)
        _fill_ids(index, face_offset, mesh.face_count, depth, codes, extra[1], write_ids)
        return
    # The two kernels above interpolate float32 positions and normals with float64 weights (the same numbers as
    # from a float64 copy); the others do arithmetic on them directly, so a float32 Mesh gives them an exact copy.
    world, normals = np.asarray(world, dtype=np.float64), np.asarray(normals, dtype=np.float64)
    if mode == shade.SHADE_GOURAUD and mesh.face_count:
        lit = np.empty((mesh.vertex_count, 6))
        shade.light_vertices(world, normals, params, lights, options.specular_model, lit)
    elif mode == shade.SHADE_FLAT and mesh.face_count:
        lit = np.empty((mesh.face_count, 6))
        shade.light_faces(world, faces, params, lights, options.specular_model, lit)
    else:
        lit = np.empty((0, 6))
    vertex_colors = getattr(mesh, "vertex_colors", None)
    vertex_colors = np.empty((0, 3)) if vertex_colors is None else np.ascontiguousarray(vertex_colors[:, :3], float)
    uvs = getattr(mesh, "uvs", None)
    texture = material.texture
    if texture is None or uvs is None:
        texture, uvs = np.empty((0, 0, 4), dtype=np.float32), np.empty((0, 2))
    else:
        uvs = np.ascontiguousarray(uvs, dtype=np.float64)
    flags = item_flags(index, face_offset, options, blend, write_normals, write_ids)
    shade.shade_pixels(depth, codes, bary, faces, world, normals, lit, vertex_colors, uvs, texture, params, lights,
                       flags, color, extra[0], extra[1])  # fmt: skip


def _fill_ids(index: int, face_offset: int, face_count: int, depth: np.ndarray, codes: np.ndarray, ids: np.ndarray,
              write_ids: bool) -> None:  # fmt: skip
    """The item's index into `ids` at its drawn pixels (face codes of its faces), as the general kernel writes it."""
    if write_ids:
        from frustum.raster import ground_truth

        ground_truth.item_ids(depth, codes, face_offset, face_count, index, ids)


def back_to_front(items: list[SceneItem], indices: list[int], camera: Camera) -> list[int]:
    """The items `indices` farthest first, by the view distance $(eye − c)·n$ of their bounding-box centres c
    (the per-object sort of transparent items: right when they do not interpenetrate or cyclically overlap)."""
    axis = np.asarray(camera.frame.n, dtype=np.float64)
    eye = np.asarray(camera.frame.eye, dtype=np.float64)

    def distance(index: int) -> float:
        item = items[index]
        if item.mesh.vertex_count == 0:
            return 0.0
        centre = item.mesh.bounds.mean(axis=0)
        centre = item.world_from_model[:3, :3] @ centre + item.world_from_model[:3, 3]
        return float((eye - centre) @ axis)

    return sorted(indices, key=distance, reverse=True)


def code_type(items: list[SceneItem]) -> type:
    """The dtype of the face-code buffer: int32 while twice the scene's face count fits it."""
    return np.int32 if 2 * sum(item.mesh.face_count for item in items) < 2**31 else np.int64


def face_offsets(items: list[SceneItem]) -> list[int]:
    """Each item's first face code: the face counts of the items before it, summed."""
    return [int(n) for n in np.cumsum([0] + [item.mesh.face_count for item in items])[:-1]]


def draw_transparent(scene: Scene, items: list[SceneItem], camera: Camera, options: RenderOptions,
                     context: FrameContext) -> None:  # fmt: skip
    """Stage 6: the transparent items of `items` back to front by the view distance of their centres, each
    rasterized alone against a copy of the finished depth buffer and blended over ``context.color``."""
    clear_items = [i for i, item in enumerate(items) if item.material.opacity < 1.0]
    if not clear_items:
        return
    height, width = camera.height, camera.width
    codes_dtype = code_type(items)
    lighting = Lighting.of(scene)
    offsets = face_offsets(items)
    extra = context.extra()
    bary = context.scratch.empty((height, width, 2), np.float32)
    for index in back_to_front(items, clear_items, camera):
        item = items[index]
        layer = Pixels(context.depth.copy(), np.full((height, width), -1, dtype=codes_dtype), bary, context.color,
                       extra)  # fmt: skip
        world, normals, band = draw_item(item, camera, options.cull, offsets[index], layer, context.scratch)
        shade_item(item, index, offsets[index], camera, options, lighting, (world, normals), layer, band,
                   blend=True)  # fmt: skip
