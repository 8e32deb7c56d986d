"""The pipeline driver: ``render(scene, camera)`` runs every stage in order and returns a ``Frame``.

Fast path, per scene item (one compiled pass each, buffers shared between items):

1. ``raster.vertices.transform_vertices``: clip = clip_from_world·world_from_model·P, world positions and
   normals, region codes (parallel over vertices).
2. ``raster.triangles.window_vertices`` then ``setup_triangles``: perspective divide, viewport and snap to
   1/256 pixel once per vertex inside the view volume; per face trivial accept (those per-vertex records, no
   clip work) / reject, Sutherland–Hodgman clipping of crossing triangles against the view volume (divide,
   viewport, snap per clipped corner), back-face culling by signed window area, pixel bounding box (parallel
   over chunks of faces: count, prefix sum, write).
3. ``raster.tiles``: bin the triangles into square tiles, keeping drawing order inside each tile.
4. ``raster.triangles.rasterize_tiles``: edge functions with the top-left rule, depth test "less" against a
   float32 buffer cleared to 1.0, perspective-correct barycentrics stored per pixel (parallel over tiles; the
   first drawn mesh's pass also clears each tile's depth and face codes, so no numpy fill of the buffers).
5. ``raster.shade.shade_pixels``: deferred Blinn-Phong (or flat color) once per visible pixel; the last
   item's pass (rasterization complete) also paints the background pixels.

``mode="wireframe"`` and ``mode="points"`` replace stages 2–5 by one serial kernel per item
(``raster.lines``): every unique mesh edge clipped by Liang–Barsky in clip space, divided, mapped and drawn as a
1-pixel line (DDA over pixel centres along the major axis), or every vertex inside the view volume drawn as the
pixel containing it; depth test "less" against the same float32 buffer cleared to 1.0, the item's flat material
color (no lighting, no culling), background bytes elsewhere.

The textbook path is the public stage functions (``Camera.project``, ``clip_triangles``,
``visibility.backface_mask``); ``tests/test_render.py`` holds both paths equal.
"""

from __future__ import annotations

from typing import Any

import numba
import numpy as np

from frustum._arrays import describe
from frustum.camera import Camera
from frustum.clipping import VIEW_VOLUME_PLANES
from frustum.errors import FrustumError, ShadingError
from frustum.frame import Frame
from frustum.raster import lines, shade, tiles, triangles
from frustum.raster.vertices import transform_vertices
from frustum.scene import Scene, SceneItem
from frustum.shading import DirectionalLight

__all__ = ["RENDER_MODES", "SHADING_MODES", "TILE_SIZE", "mesh_edges", "render"]

SHADING_MODES = {"phong": shade.SHADE_PHONG, "none": shade.SHADE_NONE}
"""Shading names ``render`` accepts (``None`` means ``"none"``)."""
RENDER_MODES = ("surface", "wireframe", "points")
"""What ``render`` draws of each mesh: filled triangles, unique edges as lines, or vertices as pixels."""
TILE_SIZE = 32
"""Side of a square screen tile in pixels: the unit of parallel work of the rasterizer."""
_SETUP_CHUNK = 4096
_BIN_CHUNK = 16384


def render(
    scene: Scene,
    camera: Camera,
    *,
    shading: str | None = "phong",
    background: Any = (0.0, 0.0, 0.0, 1.0),
    cull_back_faces: bool = True,
    mode: str = "surface",
) -> Frame:
    """Render `scene` seen by `camera` into a ``Frame`` (color (H, W, 4) uint8 and depth (H, W) float32).

    Parameters
    ----------
    scene : Scene
        Meshes with materials; for ``shading="phong"`` exactly one ``DirectionalLight`` (white, intensity 1).
    camera : Camera
        Its width and height are the image size.
    shading : {"phong", "none"} or None
        ``"phong"``: per-pixel Blinn-Phong (``frustum.shading``). ``"none"`` or None: no lighting, every
        visible pixel gets its material's flat color (the depth buffer alone decides visibility).
    background : (4,) array_like
        RGBA in [0, 1] for pixels no triangle covers; stored as ``round(255·value)``.
    cull_back_faces : bool
        True: drop triangles that are clockwise (or of zero area) in window coordinates. False: draw both
        sides, lighting a back face with its normal flipped toward the viewer (two-sided lighting, for open
        surfaces such as the teapot). Lines and points are never culled.
    mode : {"surface", "wireframe", "points"}
        ``"surface"``: filled, shaded triangles. ``"wireframe"``: every unique edge of the faces (each undirected
        edge once), clipped in homogeneous clip space, as a 1-pixel line with window depth linear along it.
        ``"points"``: every mesh vertex inside the view volume as the one pixel containing it. Both draw the
        item's material color with alpha 255 (no lighting, so `shading` and the lights are not used) with the
        depth test "less"; the pixel rules are in ``frustum.raster.lines``.

    Raises
    ------
    FrustumError
        For a bad argument: unknown shading name or mode, wrong types, background outside [0, 1], a non-white light.

    References
    ----------
    [HB 16] "Back-Face Detection", "Depth-Buffer Method"; [seed] "Back-face detection", "Depth-buffer method".
    """
    where = "render"
    if not isinstance(mode, str) or mode not in RENDER_MODES:
        raise FrustumError(
            f"{where}: mode = {describe(mode)} is unknown; expected one of " + ", ".join(repr(n) for n in RENDER_MODES)
        )
    if mode != "surface":
        _check_arguments(scene, camera, "none", cull_back_faces, where)
        return _render_lines_or_points(scene, camera, _background_bytes(background, where), mode == "points")
    shade_mode, light = _check_arguments(scene, camera, shading, cull_back_faces, where)
    background_bytes = _background_bytes(background, where)
    height, width = camera.height, camera.width
    # uninitialized: the first rasterized item clears depth and codes tile by tile, the last shading pass
    # paints the background (both inside the parallel kernels); numpy fills only when no kernel runs
    depth = np.empty((height, width), dtype=np.float32)
    face_total = sum(item.mesh.face_count for item in scene.items)
    codes = np.empty((height, width), dtype=np.int32 if 2 * face_total < 2**31 else np.int64)
    bary = np.empty((height, width, 2), dtype=np.float32)  # read only where codes >= 0
    color = np.empty((height, width, 4), dtype=np.uint8)
    if face_total == 0:
        depth.fill(1.0)
        codes.fill(-1)
    if not scene.items:
        color[:, :] = background_bytes
    eye = _eye_position(camera)
    face_offset = 0
    clear = face_total > 0
    for index, item in enumerate(scene.items):
        world, normals = _draw_item(item, camera, bool(cull_back_faces), face_offset, depth, codes, bary, clear)
        clear = clear and item.mesh.face_count == 0
        params = _shading_parameters(item, light, eye)
        last = int(index == len(scene.items) - 1)
        options = np.array([face_offset, shade_mode, last, *background_bytes], dtype=np.int64)
        shade.shade_pixels(codes, bary, item.mesh.faces, world, normals, params, options, color)
        face_offset += item.mesh.face_count
    return Frame(color=color, depth=depth)


def _render_lines_or_points(scene: Scene, camera: Camera, background_bytes: np.ndarray, points: bool) -> Frame:
    """``mode="wireframe"`` (or ``"points"``): each item's edges (or vertices) in scene order, one kernel each."""
    depth = np.ones((camera.height, camera.width), dtype=np.float32)
    color = np.empty((camera.height, camera.width, 4), dtype=np.uint8)
    color[:, :] = background_bytes
    view = np.array([camera.width / 2.0, camera.height / 2.0])
    for item in scene.items:
        mesh = item.mesh
        rgba = np.empty(4, dtype=np.uint8)
        rgba[:3] = np.floor(np.clip(item.material.color, 0.0, 1.0) * 255.0 + 0.5)
        rgba[3] = 255
        clip = np.empty((mesh.vertex_count, 4))
        vertex_codes = np.empty(mesh.vertex_count, dtype=np.int64)
        transform_vertices(
            mesh.vertices, np.ones((mesh.vertex_count, 3)), _item_matrices(item, camera), VIEW_VOLUME_PLANES,
            clip, np.empty((mesh.vertex_count, 3)), np.empty((mesh.vertex_count, 3)), vertex_codes,
        )  # fmt: skip
        if points:
            lines.draw_points(clip, vertex_codes, view, rgba, depth, color)
        else:
            lines.draw_lines(clip, mesh_edges(mesh.faces), VIEW_VOLUME_PLANES, view, rgba, depth, color)
    return Frame(color=color, depth=depth)


def mesh_edges(faces: np.ndarray) -> np.ndarray:
    """(E, 2) int64: every undirected edge of the triangles `faces` once, as ``(low, high)`` rows in sorted order."""
    faces = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    pairs = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    pairs.sort(axis=1)
    return np.ascontiguousarray(np.unique(pairs, axis=0), dtype=np.int64).reshape(-1, 2)


def _draw_item(
    item: SceneItem, camera: Camera, cull: bool, face_offset: int,
    depth: np.ndarray, codes: np.ndarray, bary: np.ndarray, clear: bool,
) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """Stages 1–4 for one placed mesh; returns its world positions and unit world normals for shading.

    With `clear`, the tile kernel first sets its tiles' depth to 1 and codes to −1 (the first drawn mesh).
    """
    mesh = item.mesh
    vertex_count = mesh.vertex_count
    world = np.empty((vertex_count, 3))
    normals = np.empty((vertex_count, 3))
    if mesh.face_count == 0:
        return world, normals
    clip = np.empty((vertex_count, 4))
    vertex_codes = np.empty(vertex_count, dtype=np.int64)
    transform_vertices(
        mesh.vertices, mesh.vertex_normals, _item_matrices(item, camera), VIEW_VOLUME_PLANES,
        clip, world, normals, vertex_codes,
    )  # fmt: skip
    tri_int, tri_float, tri_weights = _setup_records(mesh.faces, clip, vertex_codes, camera, cull, face_offset)
    tile_starts, tile_triangles, tiling = bin_triangles(tri_int, camera.width, camera.height)
    tiling = np.array([tiling[0], tiling[1], int(clear)], dtype=np.int64)
    triangles.rasterize_tiles(
        tri_int, tri_float, tri_weights, tile_starts, tile_triangles, tiling, depth, codes, bary
    )  # fmt: skip
    return world, normals


def setup(
    faces: np.ndarray, clip: np.ndarray, vertex_codes: np.ndarray, camera: Camera, cull: bool, face_offset: int = 0
) -> tuple[np.ndarray, np.ndarray]:
    """Triangle records ``tri_int, tri_float`` (``raster.triangles``) of `faces` in clip space: clipped, divided,
    snapped, culled (the clipped triangles' weights, ``tri_weights``, are left out: see ``_setup_records``)."""
    tri_int, tri_float, _ = _setup_records(faces, clip, vertex_codes, camera, cull, face_offset)
    return tri_int, tri_float


def _setup_records(
    faces: np.ndarray, clip: np.ndarray, vertex_codes: np.ndarray, camera: Camera, cull: bool, face_offset: int = 0
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``setup`` plus ``tri_weights``; tri_int is int32 when its coordinates and codes fit (``raster.triangles``)."""
    view = np.array([camera.width / 2.0, camera.height / 2.0])
    chunk_count = max(1, -(-faces.shape[0] // _SETUP_CHUNK))
    chunk_starts = np.zeros((chunk_count, 2), dtype=np.int64)
    options = np.array([camera.width, camera.height, int(cull), face_offset, _SETUP_CHUNK, 0], dtype=np.int64)
    small = (
        triangles.SUBPIXEL * (max(camera.width, camera.height) + 2) < 2**31
        and 2 * (face_offset + faces.shape[0]) < 2**31
    )
    int_type = np.int32 if small else np.int64
    empty_int = np.empty((0, triangles.INT_FIELDS), dtype=int_type)
    empty_float = np.empty((0, 3, triangles.FLOAT_FIELDS))
    win_int = np.empty((clip.shape[0], 2), dtype=np.int64)
    win_float = np.empty((clip.shape[0], 2))
    triangles.window_vertices(clip, vertex_codes, view, win_int, win_float)
    # count per chunk, exclusive prefix sum, then write
    triangles.setup_triangles(
        faces, clip, vertex_codes, VIEW_VOLUME_PLANES, view, win_int, win_float, options, chunk_starts,
        empty_int, empty_float, empty_float,
    )  # fmt: skip
    total, clipped = (int(n) for n in chunk_starts.sum(axis=0))
    chunk_starts = np.concatenate([np.zeros((1, 2), dtype=np.int64), np.cumsum(chunk_starts, axis=0)[:-1]])
    tri_int = np.empty((total, triangles.INT_FIELDS), dtype=int_type)
    tri_float = np.empty((total, 3, triangles.FLOAT_FIELDS))
    tri_weights = np.empty((clipped, 3, 2))
    options[5] = 1
    triangles.setup_triangles(
        faces, clip, vertex_codes, VIEW_VOLUME_PLANES, view, win_int, win_float, options, chunk_starts,
        tri_int, tri_float, tri_weights,
    )  # fmt: skip
    return tri_int, tri_float, tri_weights


def bin_triangles(tri_int: np.ndarray, width: int, height: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Tile lists: ``tile_triangles[tile_starts[t]:tile_starts[t + 1]]`` are tile t's triangles in order."""
    tiles_x = -(-width // TILE_SIZE)
    tiles_y = -(-height // TILE_SIZE)
    chunk_count = min(max(1, -(-tri_int.shape[0] // _BIN_CHUNK)), 4 * numba.get_num_threads())
    chunk = max(1, -(-tri_int.shape[0] // chunk_count))
    tiling = np.array([TILE_SIZE, tiles_x, chunk], dtype=np.int64)
    counts = np.empty((chunk_count, tiles_x * tiles_y), dtype=np.int64)
    tiles.count_tile_triangles(tri_int, tiling, counts)
    offsets = np.empty_like(counts)
    tile_starts = np.empty(tiles_x * tiles_y + 1, dtype=np.int64)
    tiles.tile_offsets(counts, offsets, tile_starts)
    tile_triangles = np.empty(int(tile_starts[-1]), dtype=np.int32 if tri_int.shape[0] < 2**31 else np.int64)
    tiles.fill_tile_triangles(tri_int, tiling, offsets, tile_triangles)
    return tile_starts, tile_triangles, tiling[:2].copy()


def _item_matrices(item: SceneItem, camera: Camera) -> np.ndarray:
    """(3, 4, 4): clip_from_model, world_from_model, and the normal matrix (inverse transpose) in a 4x4."""
    world_from_model = np.asarray(item.world_from_model, dtype=np.float64)
    matrices = np.zeros((3, 4, 4))
    matrices[0] = camera.clip_from_world @ world_from_model
    matrices[1] = world_from_model
    matrices[2, :3, :3] = np.linalg.inv(world_from_model[:3, :3]).T
    matrices[2, 3, 3] = 1.0
    return matrices


def _eye_position(camera: Camera) -> np.ndarray:
    """World position of the viewer, for V = normalize(eye − P): the frame's eye point."""
    return np.asarray(camera.frame.eye, dtype=np.float64)


def _shading_parameters(item: SceneItem, light: DirectionalLight | None, eye: np.ndarray) -> np.ndarray:
    """(13,) float64: L (toward the light), eye, color, ambient, diffuse, specular, shininess."""
    material = item.material
    to_light = light.to_light if light is not None else np.zeros(3)
    return np.concatenate(
        [to_light, eye, material.color,
         [material.ambient, material.diffuse, material.specular, material.shininess]]
    ).astype(np.float64)  # fmt: skip


def _check_arguments(
    scene: Any, camera: Any, shading: Any, cull_back_faces: Any, where: str
) -> tuple[int, DirectionalLight | None]:
    if not isinstance(scene, Scene):
        raise FrustumError(f"{where}: scene = {describe(scene)} is not a Scene; build one with Scene(lights=[...])")
    if not isinstance(camera, Camera):
        raise FrustumError(
            f"{where}: camera = {describe(camera)} is not a Camera; build one with Camera.look_at(eye, target, up)"
        )
    name = "none" if shading is None else shading
    if not isinstance(name, str) or name not in SHADING_MODES:
        raise FrustumError(
            f"{where}: shading = {describe(shading)} is unknown; expected one of "
            + ", ".join(repr(n) for n in sorted(SHADING_MODES))
            + " or None"
        )
    if not isinstance(cull_back_faces, bool | np.bool_):
        raise FrustumError(f"{where}: cull_back_faces = {describe(cull_back_faces)} is not a bool; give True or False")
    mode = SHADING_MODES[name]
    light = None
    if mode == shade.SHADE_PHONG:
        if len(scene.lights) != 1:
            raise ShadingError(
                f"{where}: scene.lights has {len(scene.lights)} lights; shading='phong' needs exactly one "
                "DirectionalLight in this version"
            )
        light = scene.lights[0]
        if (light.color != 1.0).any() or light.intensity != 1.0:
            raise ShadingError(
                f"{where}: light color = {describe(light.color)}, intensity = {light.intensity!r} is not white of "
                "intensity 1; this version shades with color (1, 1, 1) and intensity 1 only"
            )
    return mode, light


def _background_bytes(background: Any, where: str) -> np.ndarray:
    try:
        values = np.asarray(background, dtype=np.float64)
    except (TypeError, ValueError):
        values = None
    if (
        values is None
        or values.shape != (4,)
        or not np.isfinite(values).all()
        or (values < 0).any()
        or (values > 1).any()
    ):
        raise FrustumError(
            f"{where}: background = {describe(background)} is not an RGBA color; expected four finite numbers in [0, 1]"
        )
    return np.floor(values * 255.0 + 0.5).astype(np.uint8)
