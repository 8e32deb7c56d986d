"""The pipeline driver: ``render(scene, camera)`` runs every stage in order and returns a ``Frame``.

Fast path, per scene item (one compiled pass each, buffers shared between items):

1. ``raster.vertices.project_vertices``: clip = clip_from_world·world_from_model·P, region codes and, for the
   vertices inside the view volume, the perspective divide, viewport and snap to 1/256 pixel, once per vertex
   (parallel over vertices; clip coordinates are not stored).
2. ``raster.tiles.count_tiles`` / ``fill_tiles`` (triangle setup and binning in one): per face trivial reject,
   trivial accept (drawn straight from its vertices' records: nothing per triangle is stored but its tile list
   entries), back-face culling by signed window area, pixel bounding box, and the tiles it touches, counted then
   written in face order (parallel over chunks of faces). The few faces crossing the view volume are clipped by
   Sutherland–Hodgman (``raster.triangles.clip_faces``, divide, viewport and snap per clipped corner) into
   triangle records that take their face's place in the tile lists.
3. World positions and unit normals for shading (``raster.vertices.world_points``, ``transform_normals``), or
   the mesh's own arrays when the modeling transform leaves them unchanged.
4. ``raster.triangles.rasterize_tiles``: edge functions with the top-left rule (rows of wide boxes visit only
   their covered span), depth on the triangle's plane (``z = (z_0 + β·ΔY) + α·ΔX``, no division per pixel),
   depth test "less" against a float32 buffer cleared to 1.0 (``clear_buffers``, NumPy fills, which also
   paint the background color), face code and perspective-correct barycentrics stored per drawn pixel
   (parallel over tiles).
5. ``raster.shade.shade_pixels``: deferred shading once per visible pixel (``frustum.shading``'s model,
   flat, Gouraud or Phong; per-vertex or per-face terms first by ``light_vertices`` / ``light_faces``), or
   ``shade_pixels_directional`` where it applies (per-pixel Blinn-Phong, directional lights: the same bytes).

A frame of one opaque mesh on the directional path runs stages 4–5 tile by tile instead (``raster.tiled``, as
llvmpipe does): each tile's depth, codes and weights live in L1-sized scratch, are shaded there and copied out
once, with no image-sized codes or weights and no second pass over the image; the same bytes. The Frame's color
and depth arrays are recycled once no Frame holds them (``FrameBuffers``), so an animation loop does not
first-touch new pages every frame.
6. Transparent items (``Material.opacity < 1``) after all opaque ones, back to front by the view distance of
   their centres: each rasterized alone against a copy of the opaque depth buffer (its nearest surface) and
   blended ``α·I + (1 − α)·under``.
7. Edges (``"surface+edges"``, ``"hidden-line"``): ``raster.lines`` against the finished depth buffer.

``mode="wireframe"`` and ``mode="points"`` replace stages 2–5 by one serial kernel per item
(``raster.lines``): every unique mesh edge clipped by Liang–Barsky in clip space, divided, mapped and drawn as a
1-pixel line (DDA over pixel centres along the major axis), or every vertex inside the view volume drawn as the
pixel containing it; depth test "less" against the same float32 buffer cleared to 1.0, the item's flat material
color (no lighting, no culling), background bytes elsewhere.

The textbook path is the public stage functions (``Camera.project``, ``clip_triangles``,
``visibility.backface_mask``); ``tests/test_render.py`` holds both paths equal.
"""

from __future__ import annotations

import dataclasses
import math
import sys
import threading
import weakref
from typing import Any, ClassVar

import numpy as np

from frustum._arrays import as_scalar, describe
from frustum.budgets import check_memory
from frustum.camera import Camera
from frustum.clipping import VIEW_VOLUME_PLANES
from frustum.errors import FrustumError
from frustum.frame import Frame, background_bytes
from frustum.geometry import Mesh
from frustum.hidden_lines import EdgeAdjacency, classify_edges, edge_adjacency, front_facing, welded_adjacency
from frustum.raster import lines, shade, tiles, triangles
from frustum.raster._jit import threads
from frustum.raster.vertices import project_vertices, transform_normals, world_points
from frustum.scene import Scene, SceneItem
from frustum.shading import SPECULAR_MODELS, DepthCue, pack_lights

__all__ = [
    "HIDDEN_STYLES", "RENDER_METHODS", "RENDER_MODES", "SHADING_MODES", "TILE_SIZE", "TRANSPARENCY_MODES",
    "VISIBILITY_METHODS", "mesh_edges", "release_memory", "render",
]  # fmt: skip

SHADING_MODES = {
    "phong": shade.SHADE_PHONG,
    "gouraud": shade.SHADE_GOURAUD,
    "flat": shade.SHADE_FLAT,
    "normals": shade.SHADE_NORMALS,
    "depth": shade.SHADE_DEPTH,
    "none": shade.SHADE_NONE,
}
"""Shading names ``render`` accepts (``None`` means ``"none"``)."""
RENDER_MODES = ("surface", "wireframe", "points", "hidden-line", "surface+edges")
"""What ``render`` draws: filled surfaces, edges as lines, vertices as pixels, visible edges only, or both."""
HIDDEN_STYLES = (None, "dimmed", "dashed")
"""How ``mode="hidden-line"`` draws the hidden parts of edges: not at all, solid in `hidden_color`, or dashed."""
EDGE_SETS = ("all", "feature")
FILTERS = ("box", "tent")
COLOR_SPACES = ("linear", "srgb")
BUFFERS = ("normals", "object_id", "position", "shadow")
TILE_BITS = 5
TILE_SIZE = 1 << TILE_BITS
ONE_PASS_CLIPPING = 16384
"""Up to this many faces crossing the view volume are clipped in one pass into ``triangles.FAN_MAX`` record slots
each (at most 21 MiB of records); more are counted first, then written (two passes, no slots to spare)."""
TILED_BITS = 6
"""Tiles of the one-mesh tile pipeline (``raster.tiled``) are 64 pixels square: 3–5 % less CPU than 32 there (fewer
triangles spanning two tiles); the general path keeps 32, whose bands bound each small item's shading rows."""
"""Side of a square screen tile in pixels (32): the unit of parallel work of the rasterizer."""
_BIN_CHUNK = 16384
_HUGE_PAGE = 1 << 21
_EDGE_OFFSET = 1e-5
"""Window-depth offset of the hidden-line test (``raster.lines``), against stitching of edges into faces."""


@dataclasses.dataclass(frozen=True)
class _Options:
    shade_mode: int
    specular_model: int
    background: np.ndarray  # (4,) uint8
    cull: bool
    mode: str
    edges: str
    crease_angle: float
    edge_color: np.ndarray | None  # (4,) bytes as float, or None for the material color
    hidden: str | None
    hidden_color: np.ndarray
    line_width: float
    depth_cue: DepthCue | None
    buffers: tuple[str, ...]
    method: str = "depth-buffer"
    transparency: str = "sort"
    counts: dict | None = None  # the method's counts (Frame.stats), filled while drawing
    shadow: Any = None  # shadow_pass.ShadowOptions, or None: no shadows
    outputs: dict | None = None  # "position", "seen" (shadow_pass), filled while drawing where asked for


class Scratch:
    """Work arrays of one ``render`` call (buffers no Frame returns: face codes, barycentrics, window records,
    tile lists), taken from the arrays the previous call gave back when shape and dtype match.

    A fresh large array costs a first-touch pass (the kernel zeroes every page) on top of its use: reusing the
    last frame's saves that on every frame of an animation or a multi-view render of the same scene. At most one
    call's arrays are kept (``release`` replaces them); concurrent calls each take distinct arrays (a lock
    guards the pool), so renders in threads never share one.
    """

    _pool: ClassVar[dict[tuple, list[np.ndarray]]] = {}
    _lock: ClassVar[threading.Lock] = threading.Lock()

    def __init__(self) -> None:
        self.taken: list[np.ndarray] = []
        self.free: dict[tuple, list[np.ndarray]] = {}

    def empty(self, shape: tuple[int, ...], dtype: Any = np.float64) -> np.ndarray:
        """An uninitialized array like ``np.empty(shape, dtype)``: one this call recycled, or one of the pool."""
        key = (tuple(int(n) for n in shape), np.dtype(dtype).str)
        arrays = self.free.get(key)
        array = arrays.pop() if arrays else None
        if array is None:
            with Scratch._lock:
                arrays = Scratch._pool.get(key)
                array = arrays.pop() if arrays else None
        if array is None:
            array = np.empty(key[0], dtype=dtype)
        self.taken.append(array)
        return array

    def recycle(self, *arrays: np.ndarray) -> None:
        """Arrays this call took and no longer reads: free for its next ``empty`` of the same shape (next item)."""
        for array in arrays:
            self.free.setdefault((array.shape, array.dtype.str), []).append(array)

    def release(self) -> None:
        """Give this call's arrays to the pool, in place of what it held."""
        pool: dict[tuple, list[np.ndarray]] = {}
        for array in {id(a): a for a in self.taken}.values():
            pool.setdefault((array.shape, array.dtype.str), []).append(array)
        with Scratch._lock:
            Scratch._pool = pool
        self.taken, self.free = [], {}


def release_memory() -> int:
    """Free the work arrays ``render`` keeps between calls (face codes, barycentrics, window records, tile lists
    of the last frame: about 200 MiB after a 4096² frame) and the color and depth buffers of the last two frames
    that no Frame holds any more (``FrameBuffers``); return how many bytes were released.

    The next ``render`` allocates (and first-touches) them anew. Call it when a program that rendered large
    frames goes on to other work.
    """
    with Scratch._lock:
        released = sum(a.nbytes for arrays in Scratch._pool.values() for a in arrays)
        Scratch._pool = {}
    if "frustum.shadow_pass" in sys.modules:  # the shadow maps and per-pixel arrays of the shadow pass
        released += sys.modules["frustum.shadow_pass"].release_memory()
    return released + FrameBuffers.release()


def render(
    scene: Scene,
    camera: Camera,
    *,
    shading: str | None = "phong",
    specular: str = "blinn-phong",
    background: Any = (0.0, 0.0, 0.0, 1.0),
    cull_back_faces: bool = True,
    mode: str = "surface",
    edges: str | None = None,
    crease_angle: float = math.radians(30.0),
    edge_color: Any = None,
    hidden: str | None = None,
    hidden_color: Any = (0.6, 0.6, 0.6),
    line_width: float = 1.0,
    depth_cue: DepthCue | None = None,
    samples: int = 1,
    filter: str = "box",
    color_space: str = "linear",
    buffers: tuple[str, ...] = (),
    method: str = "depth-buffer",
    transparency: str = "sort",
    stats: bool = False,
    shadows: bool | str | None = None,
    shadow_map_size: int = 2048,
    shadow_softness: float = 1.0,
) -> Frame:
    """Render `scene` seen by `camera` into a ``Frame`` (color (H, W, 4) uint8 and depth (H, W) float32).

    Parameters
    ----------
    scene : Scene
        Placed meshes with materials and any number of lights (``frustum.shading``).
    camera : Camera
        Its width and height are the image size.
    shading : {"phong", "gouraud", "flat", "normals", "depth", "none"} or None
        Where the illumination model is evaluated: per pixel, per vertex (interpolated), or per face
        (``raster/shade.py``); ``"normals"`` shows ``0.5·N + 0.5`` of the world normal, ``"depth"`` the gray
        ``(far − d)/(far − near)`` of the view distance; ``"none"`` (or None): the base color, no lighting.
    specular : {"blinn-phong", "phong"}
        The specular term: (N·H)^n or (R·V)^n.
    background : (4,) array_like
        RGBA in [0, 1] for pixels nothing covers; stored as ``round(255·value)``.
    cull_back_faces : bool
        True: drop triangles that are clockwise (or of zero area) in window coordinates. False: draw both
        sides, lighting a back face with its normal flipped toward the viewer (two-sided lighting, for open
        surfaces such as the teapot). Lines and points are never culled.
    mode : {"surface", "wireframe", "points", "hidden-line", "surface+edges"}
        ``"surface"``: filled, shaded triangles. ``"wireframe"``: every unique edge, clipped in homogeneous clip
        space, as a line with window depth linear along it. ``"points"``: every vertex inside the view volume
        as the pixel containing it. ``"hidden-line"``: the surfaces fill the depth buffer in the background
        color and only the visible parts of the edges are drawn (hidden parts per `hidden`).
        ``"surface+edges"``: shaded surfaces with their visible edges on top. With `cull_back_faces`, edges of back
        faces only (``hidden_lines.front_facing``) count as hidden whatever the depth buffer says.
        Placed volumes (``Scene.add_volume``) are ray cast in every mode and by every `method`: in the surface
        modes after the opaque surfaces, their edges and the polylines (rays stop at the surfaces and polylines)
        and before transparent items; in
        ``"wireframe"`` and ``"points"`` after the lines or points, each ray stopped at the depth they write; in
        ``"hidden-line"`` after the visible edges, rays stopped at the (invisible) surfaces (docs/rendering.md).
    edges : {"all", "feature"} or None
        Which edges the line modes draw: every edge, or ``hidden_lines`` feature edges (boundaries, creases
        sharper than `crease_angle`, silhouettes). None: "all" for wireframe, "feature" for the others.
    edge_color : (3,) or (4,) array_like or None
        Line color in [0, 1]; None: the material color (wireframe, points), or for the edge modes black on a
        light background and white on a dark one.
    hidden : {None, "dimmed", "dashed"}
        ``"hidden-line"`` only: draw hidden edge parts solid or dashed in `hidden_color`.
    line_width : float
        Line width (and point size) in pixels of the output image, >= 1.
    depth_cue : DepthCue or None
        Blend surfaces, lines and points toward the cue color (default the background) by view distance.
    samples : int
        Supersampling: 1, 4, 9, 16 (any square): render at √samples times the size and downsample with
        `filter` ("box": the mean of each block; "tent": a separable triangle filter twice as wide). Lines
        are drawn √samples times as wide, so they come out anti-aliased. Depth keeps each block's nearest.
    color_space : {"linear", "srgb"}
        Output encoding; "srgb" applies the sRGB transfer curve to the linear result.
    buffers : tuple of {"normals", "object_id", "position", "shadow"}
        Extra per-pixel outputs on the Frame: unit world normals (0 on background), the index of the item
        in ``scene.items`` (−1 on background), the world point of the nearest opaque surface ((H, W, 3) float32,
        NaN on background) and, with `shadows` on, the fraction of each shadow-casting light reaching it ((H, W,
        L) float32, NaN on background; lights in ``Scene.world_lights`` order, ``frustum.shadow_pass``).
    method : str
        The visible-surface method (``RENDER_METHODS``, docs/visibility.md). For the meshes
        (``VISIBILITY_METHODS``): ``"depth-buffer"`` (the default), ``"scan-line"``, ``"area-subdivision"``
        (Warnock), ``"depth-sort"``, ``"bsp"``, ``"ray-casting"`` (a ray per pixel through the scene's BVH) or
        ``"a-buffer"`` (anti-aliased edges, exact transparency). All
        shade with the same model, so where they find the same surface they give the same bytes. Surface modes
        only; each returns its counts in ``Frame.stats``. ``"octree"``: the scene's octrees (``Scene.octrees``)
        by ``visibility.octree.render_octree``, front to back, each face orientation shaded once with the
        scene's lights; only `background` of the other options applies, and meshes are not drawn (volumes are,
        over the octrees).
    transparency : {"sort", "a-buffer"}
        How transparent items are composited: whole items back to front by the view distance of their centres
        (fast; right for transparent objects that do not cut through or overlap each other cyclically), or
        per subsample through an A-buffer (exact whatever the order, anti-aliased edges; costs fragment memory).
    stats : bool
        ``method="depth-buffer"`` only: also count its depth tests (an extra counting pass) into ``Frame.stats``.
    shadows : None, False, True or "ray"
        None: the method's own (off for the depth buffer and every method here, so pictures of today do not
        change); False: off; True: shadow maps (the depth-buffer method from each light); ``"ray"``: exact
        shadow rays through the scene's BVH (``method="ray-casting"`` always uses rays). Lights with
        ``cast_shadows=False`` and ambient light cast none. Surface modes only; not with ``method="octree"`` or
        ``"a-buffer"``. What casts, what receives and how each shading mode uses the result:
        ``frustum.shadow_pass``.
    shadow_map_size : int
        Texels on a side of each shadow map, a power of two in [64, 16384] (a point light has six).
    shadow_softness : float
        Percentage-closer filter radius in texels, in [0, 16]; 0: hard edges.

    Raises
    ------
    FrustumError
        For a bad argument: unknown names (the message lists the valid ones), wrong types, background outside
        [0, 1], samples not a square.

    References
    ----------
    [HB 16] "Back-Face Detection", "Depth-Buffer Method"; [HB 17] "Polygon Rendering Methods";
    [seed] "Back-face detection", "Depth-buffer method", "wire-frame displays".
    """
    where = "render"
    _check_method(method, where)
    if RENDER_METHODS[method] is not None:
        return RENDER_METHODS[method](scene, camera, background=background)
    options = _check_arguments(
        scene, camera, shading, specular, background, cull_back_faces, mode, edges, crease_angle, edge_color,
        hidden, hidden_color, line_width, depth_cue, buffers, where,
    )  # fmt: skip
    factor = _supersampling(samples, where)
    options = _method_options(options, method, transparency, stats, where)
    options = _shadow_options(options, shadows, shadow_map_size, shadow_softness, where)
    _choice(filter, FILTERS, "filter", where)
    _choice(color_space, COLOR_SPACES, "color_space", where)
    _check_image_budget(camera, factor, options.buffers, filter, color_space, where)
    if factor == 1:
        color, depth, normals, ids = _render_buffers(scene, camera, options)
        linear = None
    else:
        big = dataclasses.replace(camera, width=camera.width * factor, height=camera.height * factor)
        wide = dataclasses.replace(options, line_width=options.line_width * factor)
        color, depth, normals, ids = _render_buffers(scene, big, wide)
        linear = None
        if filter == "box" and color_space == "linear":
            color = resolve_color(color, factor)
        else:
            linear = _downsample(color.astype(np.float64) / 255.0, factor, filter)
        depth = _block_min(depth, factor)
        middle = factor // 2
        normals = None if normals is None else np.ascontiguousarray(normals[middle::factor, middle::factor])
        ids = None if ids is None else np.ascontiguousarray(ids[middle::factor, middle::factor])
        if options.outputs:
            for key in ("position", "seen"):  # the middle sample of each block, as for normals
                if key in options.outputs:
                    options.outputs[key] = np.ascontiguousarray(options.outputs[key][middle::factor, middle::factor])
    if color_space == "srgb":
        values = color.astype(np.float64) / 255.0 if linear is None else linear
        values[..., :3] = np.where(
            values[..., :3] <= 0.0031308, 12.92 * values[..., :3], 1.055 * values[..., :3] ** (1 / 2.4) - 0.055
        )
        linear = values
    if linear is not None:
        color = np.floor(np.clip(linear, 0.0, 1.0) * 255.0 + 0.5).astype(np.uint8)
    position, shadow = _shadow_buffers(options)
    return Frame(color=color, depth=depth, normals=normals, object_id=ids, stats=options.counts, position=position,
                 shadow=shadow)  # fmt: skip


def _render_octrees(scene: Scene, camera: Camera, *, background: Any) -> Frame:
    """``method="octree"``: every placed octree by the octree method, nearest surface kept between octrees."""
    from frustum.visibility.octree import draw_octree_into, octree_face_colors

    if not isinstance(scene, Scene) or not isinstance(camera, Camera):
        _check_arguments(scene, camera, "phong", "blinn-phong", background, True, "surface", None, 0.0, None, None,
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
        from frustum.volume_pass import draw_volumes

        draw_volumes(scene, camera, depth, color)
    return Frame(color=color, depth=depth)


RENDER_METHODS = {
    "depth-buffer": None, "scan-line": None, "area-subdivision": None, "depth-sort": None, "bsp": None,
    "a-buffer": None, "octree": _render_octrees, "ray-casting": None,
}  # fmt: skip
"""Visible-surface methods of ``render(..., method=...)``: None for the methods of the mesh pipeline
(``VISIBILITY_METHODS``), else the function that draws the frame."""


def _render_buffers(
    scene: Scene, camera: Camera, options: _Options
) -> tuple[np.ndarray, np.ndarray, np.ndarray | None, np.ndarray | None]:
    """Color, depth and the asked-for extra buffers at the camera's size."""
    height, width = camera.height, camera.width
    items = scene.items
    normal_out = np.zeros((height, width, 3), dtype=np.float32) if "normals" in options.buffers else None
    id_out = np.full((height, width), -1, dtype=np.int32) if "object_id" in options.buffers else None
    if options.mode in ("wireframe", "points"):
        depth = np.ones((height, width), dtype=np.float32)
        color = np.empty((height, width, 4), dtype=np.uint8)
        color[:, :] = options.background
        _draw_edges(items, camera, options, depth, color)
        _draw_polylines(scene.polylines, camera, options, depth, color)
        _draw_volumes_after_lines(scene, camera, options, depth, color)
        _draw_particles(scene, camera, depth, color)
        return color, depth, normal_out, id_out
    scratch = Scratch()
    if options.method == "depth-buffer" and options.transparency == "sort":
        depth, color = _draw_surfaces(scene, items, camera, options, normal_out, id_out, scratch)
        if options.counts is not None:
            _count_depth_tests(items, camera, options)
    else:
        depth, color = _draw_surfaces_by_method(scene, items, camera, options, normal_out, id_out, scratch)
    scratch.release()
    if options.mode == "hidden-line":
        color[:, :] = options.background
    if not (scene.volumes and _volumes_with_surfaces(options)):  # else drawn before the volumes
        if options.mode in ("hidden-line", "surface+edges"):
            _draw_edges(items, camera, options, depth, color)
        _draw_polylines(scene.polylines, camera, options, depth, color)
    _draw_volumes_after_lines(scene, camera, options, depth, color)
    _draw_particles(scene, camera, depth, color)
    return color, depth, normal_out, id_out


def _volumes_with_surfaces(options: _Options) -> bool:
    """Whether the volumes are ray cast right after the opaque surfaces (``"surface"``, ``"surface+edges"``:
    before transparent items) rather than after the lines (``_draw_volumes_after_lines``)."""
    return options.mode in ("surface", "surface+edges")


def _draw_volumes_after_lines(
    scene: Scene, camera: Camera, options: _Options, depth: np.ndarray, color: np.ndarray
) -> None:  # fmt: skip
    """``"wireframe"``, ``"points"``, ``"hidden-line"``: the volumes ray cast over the finished lines or points,
    each ray stopped at the depth they (wireframe, points) or the invisible surfaces (hidden-line) left, so a
    line inside a cloud is seen through the part of the cloud in front of it (``frustum.volume_pass``)."""
    if scene.volumes and not _volumes_with_surfaces(options):
        from frustum.volume_pass import draw_volumes

        draw_volumes(scene, camera, depth, color)


def _draw_particles(scene: Scene, camera: Camera, depth: np.ndarray, color: np.ndarray) -> None:
    """Particle layers over the finished surfaces: depth-tested, depth not written (``frustum.particle_pass``)."""
    if getattr(scene, "particle_layers", None):
        from frustum.particle_pass import draw_particles

        draw_particles(scene.particle_layers, camera, depth, color)


def _draw_surfaces(
    scene: Scene, items: list[SceneItem], camera: Camera, options: _Options,
    normal_out: np.ndarray | None, id_out: np.ndarray | None, scratch: Scratch,
) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """Stages 1–6 for every item: the depth and color buffers."""
    height, width = camera.height, camera.width
    opaque = [i for i, item in enumerate(items) if item.material.opacity >= 1.0]
    clear_items = [i for i, item in enumerate(items) if item.material.opacity < 1.0]
    depth = FrameBuffers.take((height, width), np.float32)
    color = FrameBuffers.take((height, width, 4), np.uint8)
    face_total = sum(item.mesh.face_count for item in items)
    code_type = np.int32 if 2 * face_total < 2**31 else np.int64
    ambient, lights = pack_lights(scene.world_lights())
    offsets = np.cumsum([0] + [item.mesh.face_count for item in items])
    extra = _extra(normal_out, id_out)
    bary = None
    if len(items) == 1 and opaque and face_total and _directional(items[0], options, lights):
        _draw_tiled(items[0], camera, options, ambient, lights, depth, color, scratch)
    else:
        codes = scratch.empty((height, width), code_type)
        bary = scratch.empty((height, width, 2), np.float32)  # codes and bary are read only where depth < 1
        clear_buffers(depth, color, options.background)
        drawn = []
        for index in opaque:
            world, normals, rows = _draw_item(items[index], camera, options.cull, int(offsets[index]), depth,
                                              codes, bary, scratch)  # fmt: skip
            drawn.append((index, world, normals, rows))
        if options.outputs is not None:
            _shadow_pass(scene, items, [(i, w, int(offsets[i])) for i, w, _, _ in drawn], camera, options, lights,
                         depth, codes, bary)  # fmt: skip
        for index, world, normals, rows in drawn:
            _shade_item(items[index], index, int(offsets[index]), camera, options, ambient, lights, world, normals,
                        depth, codes, bary, color, extra, rows, blend=False)  # fmt: skip
    _draw_volumes_over_surfaces(scene, camera, options, depth, color)
    if clear_items and bary is None:
        bary = scratch.empty((height, width, 2), np.float32)
    for index in back_to_front(items, clear_items, camera):
        item = items[index]
        layer_depth = depth.copy()
        layer_codes = np.full((height, width), -1, dtype=code_type)
        world, normals, rows = _draw_item(
            item, camera, options.cull, int(offsets[index]), layer_depth, layer_codes, bary, scratch
        )
        _shade_item(item, index, int(offsets[index]), camera, options, ambient, lights, world, normals,
                    layer_depth, layer_codes, bary, color, extra, rows, blend=True)  # fmt: skip
    return depth, color


def _extra(normal_out: np.ndarray | None, id_out: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
    """The normal and object-id buffers ``shade.shade_pixels`` writes, or 1-pixel dummies where not asked for."""
    return (
        np.zeros((1, 1, 3), dtype=np.float32) if normal_out is None else normal_out,
        np.zeros((1, 1), dtype=np.int32) if id_out is None else id_out,
    )


def _draw_tiled(
    item: SceneItem, camera: Camera, options: _Options, ambient: np.ndarray, lights: np.ndarray,
    depth: np.ndarray, color: np.ndarray, scratch: Scratch,
) -> None:  # fmt: skip
    """Stages 1–5 for a frame of one opaque mesh on the directional fast path: bin, then clear, fill and shade
    tile by tile (``raster.tiled``): the same bytes as the stage-by-stage path, without image-sized codes and
    weights or a second pass over the image."""
    from frustum.raster import tiled

    binned = bin_item(item, camera, options.cull, 0, scratch, tile_bits=TILED_BITS)
    world, normals = _world_attributes(item, scratch)
    tiling = np.array([1 << TILED_BITS, binned.tiles_x, 0, camera.width, camera.height], dtype=np.int64)
    params = _shading_parameters(item, camera, options, ambient)
    flags = _item_flags(0, 0, options, False, False, False)
    tiled.draw_tiles_directional(
        binned.faces, binned.win_int, binned.win_float, binned.tri_int, binned.tri_float, binned.tri_weights,
        binned.tile_starts, binned.tile_entries, tiling, depth, world, normals, params, lights, flags,
        options.background, color,
    )  # fmt: skip


def _draw_volumes_over_surfaces(
    scene: Scene, camera: Camera, options: _Options, depth: np.ndarray, color: np.ndarray
) -> None:  # fmt: skip
    """The surface modes: every volume ray cast after the opaque surfaces (rays stop at their depth), before the
    transparent items, whatever visible-surface method filled the depth buffer. In a scene with volumes the
    edges (``"surface+edges"``) and polylines come first (``_render_buffers`` then leaves them out), so the part
    of a cloud in front of a line covers it; polylines write depth, so they stop the rays too."""
    if scene.volumes and _volumes_with_surfaces(options):
        from frustum.volume_pass import draw_volumes

        if options.mode == "surface+edges":
            _draw_edges(scene.items, camera, options, depth, color)
        _draw_polylines(scene.polylines, camera, options, depth, color)
        draw_volumes(scene, camera, depth, color)


def back_to_front(items: list[SceneItem], indices: list[int], camera: Camera) -> list[int]:
    """The items `indices` farthest first, by the view distance ``(eye − c)·n`` of their bounding-box centres c
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


def _directional(item: SceneItem, options: _Options, lights: np.ndarray) -> bool:
    """Whether the item shades through ``shade.shade_pixels_directional``: per-pixel Blinn-Phong, directional
    lights only, no vertex colors, texture, depth cue, blending or extra buffers."""
    mesh = item.mesh
    return (
        item.material.opacity >= 1.0
        and options.shade_mode == shade.SHADE_PHONG and options.specular_model == shade.SPECULAR_BLINN
        and bool((lights[:, 0] == 0.0).all()) and getattr(mesh, "vertex_colors", None) is None
        and (item.material.texture is None or getattr(mesh, "uvs", None) is None)
        and options.depth_cue is None and not options.buffers and options.shadow is None
    )  # fmt: skip


def _plain_phong(item: SceneItem, options: _Options) -> bool:
    """Whether the item shades through ``shade.shade_pixels_phong``: per-pixel Phong with any lights and no vertex
    colors, texture, depth cue, blending or extra buffers."""
    mesh = item.mesh
    return (
        item.material.opacity >= 1.0 and options.shade_mode == shade.SHADE_PHONG
        and getattr(mesh, "vertex_colors", None) is None
        and (item.material.texture is None or getattr(mesh, "uvs", None) is None)
        and options.depth_cue is None and not options.buffers
    )  # fmt: skip


def _item_flags(
    index: int, face_offset: int, options: _Options, blend: bool, write_normals: bool, write_ids: bool
) -> np.ndarray:  # fmt: skip
    """The (ITEM,) int64 item record of ``raster.shade``."""
    flags = np.zeros(shade.ITEM, dtype=np.int64)
    flags[shade.I_FACE_OFFSET], flags[shade.I_MODE] = face_offset, options.shade_mode
    flags[shade.I_SPECULAR_MODEL], flags[shade.I_OBJECT_ID] = options.specular_model, index
    flags[shade.I_WRITE_NORMALS], flags[shade.I_WRITE_IDS] = int(write_normals), int(write_ids)
    flags[shade.I_BLEND] = int(blend)
    return flags


def _shade_item(
    item: SceneItem, index: int, face_offset: int, camera: Camera, options: _Options, ambient: np.ndarray,
    lights: np.ndarray, world: np.ndarray, normals: np.ndarray, depth: np.ndarray, codes: np.ndarray,
    bary: np.ndarray, color: np.ndarray, extra: tuple[np.ndarray, np.ndarray], rows: tuple[int, int], blend: bool,
) -> None:  # fmt: skip
    """Stage 5 for one item: shade its pixels (the background is painted when the buffers are cleared), scanning
    only the image rows [rows[0], rows[1]) its tiles cover (a scene of many small meshes shades each in its band)."""
    mesh, material = item.mesh, item.material
    write_normals = extra[0].shape[:2] == codes.shape
    write_ids = extra[1].shape == codes.shape
    band = slice(*rows)
    depth, codes, bary, color = depth[band], codes[band], bary[band], color[band]
    extra = (extra[0][band] if write_normals else extra[0], extra[1][band] if write_ids else extra[1])
    params = _shading_parameters(item, camera, options, ambient)
    mode = options.shade_mode
    faces = _world_faces(item) if mesh.face_count else np.empty((0, 3), dtype=np.int64)
    seen = None if options.outputs is None else options.outputs.get("seen")
    if seen is not None and not blend and seen[band].shape[:2] == codes.shape and mode in _SHADOWED_MODES:
        from frustum.raster import shadow

        world, normals = np.asarray(world, dtype=np.float64), np.asarray(normals, dtype=np.float64)
        lit = _lit_per_light(mesh, faces, world, normals, params, lights, options)
        vertex_colors = getattr(mesh, "vertex_colors", None)
        vertex_colors = np.empty((0, 3)) if vertex_colors is None else np.ascontiguousarray(vertex_colors[:, :3], float)
        uvs, texture = getattr(mesh, "uvs", None), material.texture
        if texture is None or uvs is None:
            texture, uvs = np.empty((0, 0, 4), dtype=np.float32), np.empty((0, 2))
        else:
            uvs = np.ascontiguousarray(uvs, dtype=np.float64)
        flags = _item_flags(index, face_offset, options, blend, write_normals, write_ids)
        shadow.shade_pixels_shadowed(depth, codes, bary, faces, world, normals, lit, vertex_colors, uvs, texture,
                                     params, lights, flags, seen[band], color, extra[0], extra[1])  # fmt: skip
        return
    if not blend and _directional(item, options, lights):  # the same bytes without the general branches
        flags = _item_flags(index, face_offset, options, blend, False, False)
        shade.shade_pixels_directional(depth, codes, bary, faces, world, normals, params, lights, flags, color)
        return
    if not blend and _plain_phong(item, options):  # the same bytes, without the other models' branches
        flags = _item_flags(index, face_offset, options, blend, False, False)
        shade.shade_pixels_phong(depth, codes, bary, faces, world, normals, params, lights, flags, color)
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
    flags = _item_flags(index, face_offset, options, blend, write_normals, write_ids)
    shade.shade_pixels(depth, codes, bary, faces, world, normals, lit, vertex_colors, uvs, texture, params, lights,
                       flags, color, extra[0], extra[1])  # fmt: skip


def _world_faces(item: SceneItem) -> np.ndarray:
    """The item's faces, counter-clockwise seen from the front *after* its modeling transform: a transform that
    swaps handedness (det < 0, e.g. a reflection) turns the winding around, so corners 1 and 2 are swapped."""
    faces = item.mesh.faces
    (a, b, c), (d, e, f), (g, h, i) = np.asarray(item.world_from_model)[:3, :3].tolist()
    if a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g) < 0.0:  # det < 0
        return np.ascontiguousarray(faces[:, [0, 2, 1]])
    return faces


def mesh_edges(faces: np.ndarray) -> np.ndarray:
    """(E, 2) int64: every undirected edge of the triangles `faces` once, as ``(low, high)`` rows in sorted order."""
    faces = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    return edge_adjacency(faces, int(faces.max()) + 1 if faces.size else 0).edges


_ADJACENCY: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _adjacency(mesh: Mesh) -> EdgeAdjacency:
    """The mesh's edges and their faces, computed once per mesh (meshes are immutable)."""
    cached = _ADJACENCY.get(mesh)
    if cached is None:
        cached = _ADJACENCY[mesh] = edge_adjacency(mesh.faces, mesh.vertex_count)
    return cached


class FrameBuffers:
    """The color and depth arrays a Frame returns, recycled once nobody holds them (double buffering).

    A new large array costs a first-touch pass (the kernel zeroes each page on first write) on top of the clear:
    about 18 ms of a 4096² frame. The buffers of the last few frames stay in a short list; a request takes one of
    them when no array outside the list still refers to it (its reference count says so: every view of a NumPy
    array holds its base), so a program that keeps the previous Frame while rendering the next (an animation
    loop) alternates between two sets, and one that keeps every Frame gets new arrays each time. Buffers start on
    a 2 MiB boundary, so the kernel can back them with huge pages (2 page faults per 4 MiB instead of ~1000).
    ``release_memory()`` empties the list.
    """

    KEEP = 4
    """Buffers kept: color and depth of two frames."""
    _kept: ClassVar[list[np.ndarray]] = []
    _lock: ClassVar[threading.Lock] = threading.Lock()

    @classmethod
    def take(cls, shape: tuple[int, ...], dtype: Any) -> np.ndarray:
        """An uninitialized ``np.empty(shape, dtype)``, 2 MiB-aligned: a kept buffer nobody holds, or a new one."""
        dtype = np.dtype(dtype)
        size = math.prod(shape) * dtype.itemsize
        if size < _HUGE_PAGE:
            return np.empty(shape, dtype=dtype)
        with cls._lock:
            for index in range(len(cls._kept)):
                raw = cls._kept[index]  # free when only the list, this name and getrefcount's argument hold it
                if raw.nbytes == size + _HUGE_PAGE and sys.getrefcount(raw) == 3:
                    del cls._kept[index]
                    break
            else:
                raw = np.empty(size + _HUGE_PAGE, dtype=np.uint8)
            cls._kept.append(raw)  # most recently used last; the oldest go first
            del cls._kept[: -cls.KEEP]
            start = -raw.ctypes.data % _HUGE_PAGE
            return raw[start : start + size].view(dtype).reshape(shape)

    @classmethod
    def release(cls) -> int:
        """Forget the kept buffers; return their bytes (those still held by Frames stay alive with them)."""
        with cls._lock:
            released = sum(raw.nbytes for raw in cls._kept if sys.getrefcount(raw) == 3)
            cls._kept = []
        return released


def _draw_item(
    item: SceneItem, camera: Camera, cull: bool, face_offset: int,
    depth: np.ndarray, codes: np.ndarray, bary: np.ndarray, scratch: Scratch,
) -> tuple[np.ndarray, np.ndarray, tuple[int, int]]:  # fmt: skip
    """Stages 1–4 for one placed mesh into the buffers; returns its world positions, unit world normals and the
    image rows [first, last) of the tiles it touches."""
    mesh = item.mesh
    if mesh.face_count == 0:
        return np.empty((0, 3)), np.empty((0, 3)), (0, 0)
    binned = bin_item(item, camera, cull, face_offset, scratch)
    used = np.flatnonzero(np.diff(binned.tile_starts)) // binned.tiles_x  # tile rows, window y up
    height = depth.shape[0]
    rows = (0, 0) if used.size == 0 else (max(height - (int(used[-1]) + 1) * TILE_SIZE, 0),
                                          min(height - int(used[0]) * TILE_SIZE, height))  # fmt: skip
    tiling = np.array([TILE_SIZE, binned.tiles_x, face_offset, depth.shape[1], height], dtype=np.int64)
    triangles.rasterize_tiles(
        binned.faces, binned.win_int, binned.win_float, binned.tri_int, binned.tri_float, binned.tri_weights,
        binned.tile_starts, binned.tile_entries, tiling, depth, codes, bary,
    )  # fmt: skip
    scratch.recycle(binned.win_int, binned.win_float, binned.vertex_codes, binned.tile_entries)
    return (*_world_attributes(item, scratch), rows)


def _world_attributes(item: SceneItem, scratch: Scratch) -> tuple[np.ndarray, np.ndarray]:
    """World positions and unit world normals of the item's vertices (``raster.vertices``); the mesh's own arrays
    where the modeling transform leaves them unchanged (identity, or a translation for the normals: the Mesh's
    normals are unit already)."""
    mesh = item.mesh
    model = np.asarray(item.world_from_model, dtype=np.float64)
    world, normals = mesh.vertices, mesh.vertex_normals
    small = mesh.vertex_count < KERNEL_MIN_VERTICES  # NumPy: the same operations in order, no kernel to compile
    if not np.array_equal(model, np.eye(4)):
        if small:
            world = _rows(mesh.vertices, model, 3, affine=True)
        else:
            world = scratch.empty((mesh.vertex_count, 3))
            world_points(mesh.vertices, model, world)
    if not np.array_equal(model[:3, :3], np.eye(3)):
        normal_matrix = _item_matrices(item, None)[2]
        if small:
            normals = _rows(mesh.vertex_normals, normal_matrix, 3, affine=False)
            normals /= np.sqrt((normals[:, :1] * normals[:, :1] + normals[:, 1:2] * normals[:, 1:2])
                               + normals[:, 2:] * normals[:, 2:])  # fmt: skip
        else:
            normals = scratch.empty((mesh.vertex_count, 3))
            transform_normals(mesh.vertex_normals, normal_matrix, normals)
    return world, normals


KERNEL_MIN_VERTICES = 65536
"""Meshes with fewer vertices get their world points and normals (and lines and edges their clip coordinates) from
NumPy rather than the ``raster.vertices`` kernels: the same operations in the same order, so the same bits, and
no kernel to compile for a small scene (the README example's cold start)."""


def _rows(points: np.ndarray, m: np.ndarray, count: int, affine: bool) -> np.ndarray:
    """Rows 0..count−1 of ``M·[x, y, z, 1]`` summed left to right, ``((m0·x + m1·y) + m2·z) + m3`` (``affine``),
    or of ``A·[x, y, z]``, ``(a0·x + a1·y) + a2·z`` — ``raster.vertices._affine_row`` / ``_linear_row`` in NumPy."""
    x, y, z = (np.asarray(points[:, k], dtype=np.float64) for k in range(3))
    rows = [(m[k, 0] * x + m[k, 1] * y) + m[k, 2] * z for k in range(count)]
    return np.stack([row + m[k, 3] for k, row in enumerate(rows)] if affine else rows, axis=1)


@dataclasses.dataclass(frozen=True)
class Binned:
    """One item after the vertex stage, triangle setup and binning: everything the tile fill reads.

    ``win_int`` (N, 2) snapped window ``X, Y`` and ``win_float`` (N, 2) ``z_w, 1/w`` of the vertices inside the
    view volume (``vertex_codes == 0``; other rows are undefined); the clipped triangles' records ``tri_int``,
    ``tri_float``, ``tri_weights`` (``raster.triangles``) of the ``crossing`` faces; tile t's entries, in
    drawing order, ``tile_entries[tile_starts[t]:tile_starts[t + 1]]``: a face index f >= 0 or ``−1 − r`` for
    record r; ``tiles_x`` tiles of ``TILE_SIZE`` pixels per row.
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
    """Stages 1–3 for one placed mesh with faces (module docstring): project, set up, clip, cull and bin into tiles
    of ``2^tile_bits`` pixels (work arrays from `scratch`, if given)."""
    empty = np.empty if scratch is None else scratch.empty
    mesh = item.mesh
    faces = _world_faces(item)
    width, height = camera.width, camera.height
    view = np.array([width / 2.0, height / 2.0])
    clip_from_model = _item_matrices(item, camera)[0]
    small = triangles.SUBPIXEL * (max(width, height) + 2) < 2**31
    win_int = empty((mesh.vertex_count, 2), np.int32 if small else np.int64)
    win_float = empty((mesh.vertex_count, 2), np.float64)
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
    tri_float, tri_weights = np.empty((0, 3, 2)), np.empty((0, 3, 2))
    record_starts = np.zeros(crossing.shape[0] + 1, dtype=np.int64)
    if crossing.shape[0]:
        triangles.list_crossing(listed, listed_tiles, chunk, listed_counts, crossing_starts[:-1], crossing)
        clip_options = np.array([width, height, int(cull), face_offset, 0], dtype=np.int64)
        arguments = (crossing, faces, mesh.vertices, clip_from_model, VIEW_VOLUME_PLANES, view, clip_options)
        if crossing.shape[0] <= ONE_PASS_CLIPPING:  # clip once into FAN_MAX slots per face, then close the gaps
            slots = crossing.shape[0] * triangles.FAN_MAX
            tri_int = np.empty((slots, triangles.RECORD_FIELDS), dtype=np.int64)
            tri_float, tri_weights = np.empty((slots, 3, 2)), np.empty((slots, 3, 2))
            made = np.arange(0, slots, triangles.FAN_MAX, dtype=np.int64)  # first slots in, record counts out
            clip_options[4] = 2
            triangles.clip_faces(*arguments, made, tri_int, tri_float, tri_weights)
            kept = (np.arange(triangles.FAN_MAX) < made[:, None]).ravel()
            tri_int, tri_float, tri_weights = tri_int[kept], tri_float[kept], tri_weights[kept]
            record_starts[1:] = np.cumsum(made)
        else:  # count, prefix sum, write (no slots to spare for a mesh crossing the view volume everywhere)
            triangles.clip_faces(*arguments, record_starts[1:], tri_int, tri_float, tri_weights)
            record_starts = np.cumsum(record_starts)
            total = int(record_starts[-1])
            tri_int = np.empty((total, triangles.RECORD_FIELDS), dtype=np.int64)
            tri_float, tri_weights = np.empty((total, 3, 2)), np.empty((total, 3, 2))
            clip_options[4] = 1
            triangles.clip_faces(*arguments, record_starts[:-1], tri_int, tri_float, tri_weights)
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


def clear_buffers(depth: np.ndarray, color: np.ndarray, background: np.ndarray) -> None:
    """Depth 1.0 (far) and the background color bytes (4,) everywhere (NumPy's fills run at memory bandwidth, as
    a compiled loop did, without its compile time). Face codes need no clearing: a pixel is drawn exactly where
    its depth is below 1, and only there are codes and barycentrics read."""
    depth.fill(1.0)
    color.view(np.uint32).fill(background.view(np.uint32)[0])


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


def _item_matrices(item: SceneItem, camera: Camera | None) -> np.ndarray:
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


def _shading_parameters(item: SceneItem, camera: Camera, options: _Options, ambient: np.ndarray) -> np.ndarray:
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
        params[shade.P_CUE_COLOR : shade.P_CUE_COLOR + 3] = _cue_color(options)
    params[shade.P_DEPTH_NEAR], params[shade.P_DEPTH_FAR] = camera.projection.near, camera.projection.far
    params[shade.P_OPACITY] = material.opacity
    return params


def _cue_color(options: _Options) -> np.ndarray:
    """The depth cue's color in [0, 1]: its own, or the background's."""
    cue = options.depth_cue
    return options.background[:3] / 255.0 if cue is None or cue.color is None else np.asarray(cue.color)


def _draw_edges(items: list[SceneItem], camera: Camera, options: _Options, depth: np.ndarray, color: np.ndarray):
    """Lines (or points) of every item into the buffers, serially in scene order (``raster.lines``)."""
    view = np.array([camera.width / 2.0, camera.height / 2.0])
    eye = np.asarray(camera.frame.eye, dtype=np.float64)
    axis = np.asarray(camera.frame.n, dtype=np.float64)
    edge_modes = options.mode in ("hidden-line", "surface+edges")
    cue = _line_cue(options)
    for item in items:
        mesh = item.mesh
        if options.edge_color is not None:
            rgba = options.edge_color
        else:
            rgba = np.append(np.floor(np.clip(item.material.color, 0.0, 1.0) * 255.0 + 0.5), 255.0)
        style = lines.line_style(
            rgba, width=options.line_width, write_depth=not edge_modes, hidden_line=edge_modes, offset=_EDGE_OFFSET,
            hidden={None: 0, "dimmed": 1, "dashed": 2}[options.hidden] if options.mode == "hidden-line" else 0,
            hidden_rgba=options.hidden_color, dash=6.0 * options.line_width, cue=cue,
        )  # fmt: skip
        clip, world, vertex_codes = _clip_vertices(mesh.vertices, item.world_from_model, camera)
        view_depth = (eye - world) @ axis
        if options.mode == "points":
            lines.draw_points(clip, view_depth, vertex_codes, view, style, depth, color)
            continue
        # feature edges by shared positions: a cap's rim or a seam split for normals or UVs is not a boundary
        adjacency = welded_adjacency(mesh) if options.edges == "feature" else _adjacency(mesh)
        edges = adjacency.edges
        if edge_modes or options.edges == "feature":
            faces = _world_faces(item)
            facing = front_facing(camera.clip_from_world, world, faces)
            if options.edges == "feature":
                keep = classify_edges(adjacency, world, faces, facing, options.crease_angle) != 0
            else:
                keep = np.ones(edges.shape[0], dtype=bool)
            if edge_modes and options.cull:  # edges of back faces only are hidden, whatever the depth buffer says
                in_front = facing[adjacency.first] | ((adjacency.second >= 0) & facing[np.maximum(adjacency.second, 0)])
                if style[lines.S_HIDDEN] != 0.0:
                    always_hidden = style.copy()
                    always_hidden[lines.S_OFFSET] = -np.inf  # z − offset < depth never holds
                    lines.draw_lines(clip, view_depth, np.ascontiguousarray(edges[keep & ~in_front]),
                                     VIEW_VOLUME_PLANES, view, always_hidden, depth, color)  # fmt: skip
                keep &= in_front
            edges = np.ascontiguousarray(edges[keep])
        lines.draw_lines(clip, view_depth, edges, VIEW_VOLUME_PLANES, view, style, depth, color)


def _draw_polylines(
    line_items: list[SceneItem], camera: Camera, options: _Options, depth: np.ndarray, color: np.ndarray
) -> None:  # fmt: skip
    """Every placed ``Polyline`` as depth-tested lines (or marker squares) in its material color, in order."""
    view = np.array([camera.width / 2.0, camera.height / 2.0])
    cue = _line_cue(options)
    for item in line_items:
        line = item.mesh
        if line.vertex_count == 0:
            continue
        rgba = np.append(np.floor(np.clip(item.material.color, 0.0, 1.0) * 255.0 + 0.5), 255.0)
        width = options.line_width + (2.0 if line.markers else 0.0)
        style = lines.line_style(rgba, width=width, cue=cue)
        clip, world, vertex_codes = _clip_vertices(line.points, item.world_from_model, camera)
        view_depth = (np.asarray(camera.frame.eye) - world) @ np.asarray(camera.frame.n)
        if line.markers:
            lines.draw_points(clip, view_depth, vertex_codes, view, style, depth, color)
        else:
            lines.draw_lines(clip, view_depth, line.segments, VIEW_VOLUME_PLANES, view, style, depth, color)


def _clip_vertices(points: np.ndarray, world_from_model: np.ndarray, camera: Camera):
    """Clip coordinates (N, 4), world positions (N, 3) and view-volume region codes (N,) int64 of model-space
    points, in NumPy (lines and edges have few points; no kernel to compile): each row of ``M·[x, y, z, 1]``
    summed left to right, ``((m0·x + m1·y) + m2·z) + m3``, and bit k of the code set when
    ``((p0·x_c + p1·y_c) + p2·z_c) + p3·w_c < 0`` for plane k of ``VIEW_VOLUME_PLANES`` — the operations, in the
    order, of the kernels' vertex stage (``raster.vertices``), so the same bytes."""
    item = SceneItem(None, None, world_from_model)  # type: ignore[arg-type]
    matrices = _item_matrices(item, camera)
    clip, world = _rows(points, matrices[0], 4, affine=True), _rows(points, matrices[1], 3, affine=True)
    vertex_codes = np.zeros(points.shape[0], dtype=np.int64)
    for k, p in enumerate(VIEW_VOLUME_PLANES):
        distance = ((p[0] * clip[:, 0] + p[1] * clip[:, 1]) + p[2] * clip[:, 2]) + p[3] * clip[:, 3]
        vertex_codes |= (distance < 0.0).astype(np.int64) << k
    return clip, world, vertex_codes


def _line_cue(options: _Options) -> tuple | None:
    """The depth cue in ``lines.line_style`` form (color in bytes), or None."""
    if options.depth_cue is None:
        return None
    c = options.depth_cue
    return (c.near, c.far, c.min_intensity, c.max_intensity, *(255.0 * _cue_color(options)))


def _choice(value: Any, valid: tuple, name: str, where: str) -> Any:
    if not isinstance(value, str | type(None)) or value not in valid:
        raise FrustumError(
            f"{where}: {name} = {describe(value)} is unknown; expected one of " + ", ".join(repr(v) for v in valid)
        )
    return value


def _supersampling(samples: Any, where: str) -> int:
    """√samples for a perfect square samples >= 1, else a FrustumError."""
    if isinstance(samples, bool) or not isinstance(samples, int | np.integer) or samples < 1:
        raise FrustumError(f"{where}: samples = {describe(samples)} is not a positive integer; use 1, 4, 9 or 16")
    factor = math.isqrt(int(samples))
    if factor * factor != samples:
        raise FrustumError(f"{where}: samples = {samples} is not a perfect square; use 1, 4, 9 or 16")
    return factor


def resolve_color(big: np.ndarray, factor: int) -> np.ndarray:
    """Box-filter resolve in integers: (H·s, W·s, 4) uint8 → (H, W, 4) uint8, each channel the rounded mean of
    its s×s block, ``floor(Σ/s² + 1/2) = (2·Σ + s²) // (2·s²)`` (exactly the rounded mean)."""
    height, width = big.shape[0] // factor, big.shape[1] // factor
    area = factor * factor
    # Σ + ⌊s²/2⌋ ≤ 255·s² + s²/2 fits uint16 up to s = 16; the rounded mean is then (Σ + ⌊s²/2⌋) // s², the same
    # integer as above. Rows first (contiguous planes of whole rows), then the s samples side by side: a few
    # in-place adds instead of a strided two-axis reduction (23 → 1.6 ms for 480 × 360 × 4 samples).
    dtype = np.uint16 if area <= 256 else np.uint32
    rows = big.reshape(height, factor, width * factor * 4)
    across = rows[:, 0].astype(dtype)
    for i in range(1, factor):
        across += rows[:, i]
    columns = across.reshape(height, width, factor, 4)
    total = columns[:, :, 0].copy()
    for j in range(1, factor):
        total += columns[:, :, j]
    total += area // 2
    total //= area
    return total.astype(np.uint8)


def _block_min(values: np.ndarray, factor: int) -> np.ndarray:
    """(H·s, W·s) → (H, W): the minimum of each s×s block, as in-place ``np.minimum`` of its row and column
    planes (0.2 ms for 960 × 720 against 11 ms for a strided ``min(axis=(1, 3))``; the same values)."""
    height, width = values.shape[0] // factor, values.shape[1] // factor
    rows = values.reshape(height, factor, width * factor)
    across = rows[:, 0].copy()
    for i in range(1, factor):
        np.minimum(across, rows[:, i], out=across)
    columns = across.reshape(height, width, factor)
    result = columns[:, :, 0].copy()
    for j in range(1, factor):
        np.minimum(result, columns[:, :, j], out=result)
    return result


def _downsample(values: np.ndarray, factor: int, kind: str) -> np.ndarray:
    """(H·s, W·s, C) → (H, W, C): the mean of each s×s block ("box"), or a separable tent of width 2s centred
    on each block (weights ``s − |offset|`` for the 2s − 1 samples around it, edges clamped)."""
    height, width = values.shape[0] // factor, values.shape[1] // factor
    if kind == "box":
        return values.reshape(height, factor, width, factor, -1).mean(axis=(1, 3))
    offsets = np.arange(-(factor - 1), factor) if factor > 1 else np.array([0])
    weights = (factor - np.abs(offsets)).astype(np.float64)
    weights /= weights.sum()

    def along(array: np.ndarray, axis: int, size: int) -> np.ndarray:
        # output k is centred between samples k·s + (s − 1)/2: use the sample pair around the centre
        total = np.zeros((*array.shape[:axis], size, *array.shape[axis + 1 :]))
        for offset, weight in zip(offsets, weights, strict=True):
            index = np.clip(np.arange(size) * factor + (factor - 1) // 2 + offset, 0, array.shape[axis] - 1)
            if factor % 2 == 0:  # even blocks: average the two centre-adjacent alignments
                index2 = np.clip(index + 1, 0, array.shape[axis] - 1)
                total += 0.5 * weight * (np.take(array, index, axis=axis) + np.take(array, index2, axis=axis))
            else:
                total += weight * np.take(array, index, axis=axis)
        return total

    return along(along(values, 0, height), 1, width)


def _color_bytes(value: Any, name: str, where: str) -> np.ndarray:
    """(4,) float64 bytes of an RGB or RGBA color in [0, 1] (alpha 1 if not given)."""
    try:
        array = np.asarray(value, dtype=np.float64).ravel()
    except (TypeError, ValueError):
        array = np.array([np.nan])
    if array.shape not in ((3,), (4,)) or not np.isfinite(array).all() or (array < 0).any() or (array > 1).any():
        raise FrustumError(
            f"{where}: {name} = {describe(value)} is not an RGB(A) color; expected 3 or 4 numbers in [0, 1]"
        )
    if array.shape == (3,):
        array = np.append(array, 1.0)
    return np.floor(array * 255.0 + 0.5)


def _check_image_budget(camera: Camera, factor: int, buffers: tuple[str, ...], filter: str, color_space: str,
                       where: str) -> None:  # fmt: skip
    """Refuse, before any buffer is allocated, an image whose buffers exceed the memory budget (``frustum.budgets``).

    Per rendered pixel (``width·height·samples`` of them): color 4 + depth 4 bytes, about 4 bytes of the
    renderer's work arrays (measured with tracemalloc: 12 bytes a pixel at 1024², surface mode), 12 for a
    ``normals`` buffer and 4 for ``object_id``; a float64 copy for the tent filter or sRGB (2 × 32 bytes).
    """
    pixels = camera.width * camera.height * factor * factor
    per_pixel = 12 + 12 * ("normals" in buffers) + 4 * ("object_id" in buffers)
    if filter != "box" or color_space != "linear":
        per_pixel += 64
    cause = f"a {camera.width} x {camera.height} image x samples = {factor * factor}"
    check_memory(pixels * per_pixel, where=where, cause=cause, error=FrustumError)


_MAX_LINE_WIDTH = 256.0
"""Widest line (and largest point) ``render`` draws, in output pixels."""


def _check_arguments(
    scene: Any, camera: Any, shading: Any, specular: Any, background: Any, cull_back_faces: Any, mode: Any,
    edges: Any, crease_angle: Any, edge_color: Any, hidden: Any, hidden_color: Any, line_width: Any,
    depth_cue: Any, buffers: Any, where: str,
) -> _Options:  # fmt: skip
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
            + ", ".join(repr(n) for n in SHADING_MODES)
            + " or None"
        )
    _choice(specular, SPECULAR_MODELS, "specular", where)
    _choice(mode, RENDER_MODES, "mode", where)
    if not isinstance(cull_back_faces, bool | np.bool_):
        raise FrustumError(f"{where}: cull_back_faces = {describe(cull_back_faces)} is not a bool; give True or False")
    if edges is None:
        edges = "all" if mode in ("wireframe", "points") else "feature"
    _choice(edges, EDGE_SETS, "edges", where)
    angle = as_scalar(crease_angle, "crease_angle", where=where, error=FrustumError)
    if not 0.0 <= angle <= math.pi:
        raise FrustumError(f"{where}: crease_angle = {angle!r} is outside [0, pi] radians")
    _choice(hidden, HIDDEN_STYLES, "hidden", where)
    width = as_scalar(line_width, "line_width", where=where, error=FrustumError)
    if width < 1.0:
        raise FrustumError(f"{where}: line_width = {width!r} is below 1; give a width in pixels >= 1")
    if width > _MAX_LINE_WIDTH:
        raise FrustumError(
            f"{where}: line_width = {width!r} is above {_MAX_LINE_WIDTH:g}; give a width in pixels in [1, "
            f"{_MAX_LINE_WIDTH:g}]"
        )
    if depth_cue is not None and not isinstance(depth_cue, DepthCue):
        raise FrustumError(
            f"{where}: depth_cue = {describe(depth_cue)} is not a DepthCue; build one with DepthCue(near, far)"
        )
    if isinstance(buffers, str) or not all(isinstance(b, str) and b in BUFFERS for b in buffers):
        raise FrustumError(
            f"{where}: buffers = {describe(buffers)} is not a tuple of buffer names; valid names: "
            + ", ".join(repr(b) for b in BUFFERS)
        )
    background_rgba = background_bytes(background, where)
    if edge_color is None:  # material colors for wireframes; black on light backgrounds, white on dark ones
        light = background_rgba[:3].astype(float) @ (0.2126, 0.7152, 0.0722) > 127.5
        edge = (
            None if mode in ("wireframe", "points") else np.array([0.0, 0.0, 0.0, 255.0]) * light + 255.0 * (not light)
        )
    else:
        edge = _color_bytes(edge_color, "edge_color", where)
    return _Options(
        shade_mode=SHADING_MODES[name],
        specular_model=shade.SPECULAR_PHONG if specular == "phong" else shade.SPECULAR_BLINN,
        background=background_rgba,
        cull=bool(cull_back_faces),
        mode=mode,
        edges=edges,
        crease_angle=angle,
        edge_color=edge,
        hidden=hidden,
        hidden_color=_color_bytes(hidden_color, "hidden_color", where),
        line_width=width,
        depth_cue=depth_cue,
        buffers=tuple(buffers),
    )


# --- visible-surface methods (render(..., method=...), docs/visibility.md) -----------------------------------

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
PLANNED_METHODS: dict[str, str] = {}
"""Methods of the visible-surface chapter that this version does not draw yet."""
TRANSPARENCY_MODES = ("sort", "a-buffer")


def _check_method(method: Any, where: str) -> None:
    """A FrustumError listing the available methods for an unknown or not yet available `method`."""
    valid = ", ".join(repr(name) for name in RENDER_METHODS)
    if isinstance(method, str) and method in PLANNED_METHODS:
        raise FrustumError(
            f"{where}: method = {method!r} is not available yet ({PLANNED_METHODS[method]}); available: {valid}"
        )
    if not isinstance(method, str) or method not in RENDER_METHODS:
        raise FrustumError(f"{where}: method = {describe(method)} is unknown; expected one of {valid}")


def _method_options(options: _Options, method: Any, transparency: Any, stats: Any, where: str) -> _Options:
    """Check `transparency` and `stats`; the options with the method (a mesh pipeline one, ``_check_method``
    first), the transparency and a counts dict where counted."""
    _choice(transparency, TRANSPARENCY_MODES, "transparency", where)
    if not isinstance(stats, bool | np.bool_):
        raise FrustumError(f"{where}: stats = {describe(stats)} is not a bool; give True or False")
    if (method != "depth-buffer" or transparency != "sort") and options.mode in ("wireframe", "points"):
        raise FrustumError(
            f"{where}: method = {method!r} with transparency = {transparency!r} draws surfaces; mode = "
            f"{options.mode!r} draws lines or points with the depth buffer: use mode 'surface', 'hidden-line' or "
            "'surface+edges', or method 'depth-buffer'"
        )
    if method == "a-buffer" and options.buffers:
        raise FrustumError(
            f"{where}: buffers = {describe(options.buffers)} are not available with method 'a-buffer' (a pixel "
            "holds several surfaces); use another method for per-pixel normals or object ids"
        )
    counted = method != "depth-buffer" or transparency != "sort" or bool(stats)
    counts = {"method": method} if counted else None
    return dataclasses.replace(options, method=method, transparency=transparency, counts=counts)


def _code_type(items: list[SceneItem]) -> type:
    """The dtype of the face-code buffer, as ``_draw_surfaces`` chooses it."""
    return np.int32 if 2 * sum(item.mesh.face_count for item in items) < 2**31 else np.int64


def _face_offsets(items: list[SceneItem]) -> list[int]:
    return [int(n) for n in np.cumsum([0] + [item.mesh.face_count for item in items])[:-1]]


def _count_depth_tests(items: list[SceneItem], camera: Camera, options: _Options) -> None:
    """The depth buffer's counts: depth tests (pixel centres covered, summed over the drawn triangles)."""
    from frustum.raster import window
    from frustum.visibility.window import window_triangles

    tris = window_triangles(items, list(range(len(items))), _face_offsets(items), camera, options.cull)
    covered = np.empty(tris.count, dtype=np.int64)
    window.count_covered(tris.xy, tris.box, covered)
    assert options.counts is not None
    options.counts.update(depth_tests=int(covered.sum()), triangles=tris.count)


def _draw_surfaces_by_method(
    scene: Scene, items: list[SceneItem], camera: Camera, options: _Options,
    normal_out: np.ndarray | None, id_out: np.ndarray | None, scratch: Scratch,
) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """Stages 1–6 by another visible-surface method, or with A-buffer transparency: the depth and color buffers.

    The method writes the depth-buffer's depth, face code and barycentrics of the surface it finds at each pixel
    (``visibility.window``); ``_shade_item`` shades them as for the depth buffer. The A-buffer shades one sample
    per fragment (a column image through the same kernel) and composites.
    """
    import importlib

    from frustum.visibility.window import window_triangles

    height, width = camera.height, camera.width
    counts = options.counts if options.counts is not None else {}
    offsets = _face_offsets(items)
    opaque = [i for i, item in enumerate(items) if item.material.opacity >= 1.0]
    clear_items = [i for i, item in enumerate(items) if item.material.opacity < 1.0]
    depth = np.empty((height, width), dtype=np.float32)
    color = np.empty((height, width, 4), dtype=np.uint8)
    clear_buffers(depth, color, options.background)
    ambient, lights = pack_lights(scene.world_lights())
    extra = _extra(normal_out, id_out)
    if options.method == "a-buffer":
        # with volumes: the opaque fragments, the volumes (rays stop at their depth), then the transparent ones
        volumes_between = bool(scene.volumes) and _volumes_with_surfaces(options)
        first = opaque if volumes_between else list(range(len(items)))
        tris = window_triangles(items, first, offsets, camera, options.cull)
        counts.update(_composite(tris, items, offsets, camera, options, ambient, lights, color, depth, scratch))
        counts["triangles"] = tris.count
        if volumes_between:
            _draw_volumes_over_surfaces(scene, camera, options, depth, color)
            if clear_items:
                tris = window_triangles(items, clear_items, offsets, camera, options.cull)
                found = _composite(tris, items, offsets, camera, options, ambient, lights, color, depth.copy(),
                                   scratch, under_depth=depth)  # fmt: skip
                counts.update({f"transparent_{key}": value for key, value in found.items()})
                counts["triangles"] += tris.count
        return depth, color
    code_type = _code_type(items)  # the depth buffer's: the shading kernels are compiled for it already
    codes = np.zeros((height, width), dtype=code_type)
    bary = np.zeros((height, width, 2), dtype=np.float32)
    if options.method == "depth-buffer":
        hidden = [
            item if item.material.opacity >= 1.0 else item._replace(mesh=Mesh(np.empty((0, 3)), np.empty((0, 3), int)))
            for item in items
        ]  # fmt: skip
        depth, color = _draw_surfaces(scene, hidden, camera, options, normal_out, id_out, scratch)
    else:
        module, name = VISIBILITY_METHODS[options.method].split(":")  # type: ignore[union-attr]
        draw = getattr(importlib.import_module(module), name)
        if options.method == "ray-casting":  # world-space rays through the scene's index, not window triangles
            counts.update(draw(scene, camera, options.cull, depth, codes, bary))
        else:
            tris = window_triangles(items, opaque, offsets, camera, options.cull)
            counts.update(draw(tris, depth, codes, bary))
        attributes = {index: _world_attributes(items[index], scratch) for index in opaque}
        if options.outputs is not None:
            _shadow_pass(scene, items, [(i, attributes[i][0], offsets[i]) for i in opaque], camera, options, lights,
                         depth, codes, bary)  # fmt: skip
        for index in opaque:
            world, normals = attributes[index]
            _shade_item(items[index], index, offsets[index], camera, options, ambient, lights, world, normals,
                        depth, codes, bary, color, extra, (0, height), blend=False)  # fmt: skip
        _draw_volumes_over_surfaces(scene, camera, options, depth, color)  # (_draw_surfaces casts them itself)
    if not clear_items:
        return depth, color
    if options.transparency == "a-buffer":
        tris = window_triangles(items, clear_items, offsets, camera, options.cull)
        found = _composite(tris, items, offsets, camera, options, ambient, lights, color, depth.copy(), scratch,
                           under_depth=depth)  # fmt: skip
        counts.update({f"transparent_{key}": value for key, value in found.items()})
        return depth, color
    for index in back_to_front(items, clear_items, camera):  # per-object sort, as the depth buffer does
        item = items[index]
        layer_depth = depth.copy()
        layer_codes = np.full((height, width), -1, dtype=code_type)
        world, normals, rows = _draw_item(
            item, camera, options.cull, offsets[index], layer_depth, layer_codes, bary, scratch
        )
        _shade_item(item, index, offsets[index], camera, options, ambient, lights, world, normals, layer_depth,
                    layer_codes, bary, color, extra, rows, blend=True)  # fmt: skip
    return depth, color


def _composite(
    tris: Any, items: list[SceneItem], offsets: list[int], camera: Camera, options: _Options, ambient: np.ndarray,
    lights: np.ndarray, color: np.ndarray, depth: np.ndarray, scratch: Scratch, under_depth: np.ndarray | None = None,
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
    for index in sorted(set(tris.item.tolist())):
        # the item's fragments as a (rows, 256) image, padded with depth 1 (nothing drawn), shaded by the one kernel:
        # opaque items as the depth buffer shades them, transparent ones blended over transparent black
        chosen = np.flatnonzero(owner == index)
        rows = -(-chosen.shape[0] // columns)
        depth_image = np.ones(rows * columns, dtype=np.float32)
        code_image = np.zeros(rows * columns, dtype=_code_type(items))
        bary_image = np.zeros((rows * columns, 2), dtype=np.float32)
        depth_image[: chosen.shape[0]] = fragments.depth[chosen, 0]
        code_image[: chosen.shape[0]] = fragments.code[chosen, 0]
        bary_image[: chosen.shape[0]] = fragments.bary[chosen, 0]
        color_image = np.zeros((rows, columns, 4), dtype=np.uint8)
        world, normals = _world_attributes(items[index], scratch)
        _shade_item(items[index], index, offsets[index], camera, options, ambient, lights, world, normals,
                    depth_image.reshape(rows, columns), code_image.reshape(rows, columns),
                    bary_image.reshape(rows, columns, 2), color_image, dummy, (0, rows),
                    blend=items[index].material.opacity < 1.0)  # fmt: skip
        premultiplied[chosen] = color_image.reshape(-1, 4)[: chosen.shape[0]]
    if under_depth is None:
        under_depth = np.ones(depth.shape, dtype=np.float32)
    return abuffer.resolve_fragments(fragments, premultiplied, tris, color, under_depth, color, depth)


# --- shadows (frustum.shadow_pass) ---------------------------------------------------------------------------

_SHADOWED_MODES = (shade.SHADE_PHONG, shade.SHADE_GOURAUD, shade.SHADE_FLAT)


def _shadow_options(options: _Options, shadows: Any, map_size: Any, softness: Any, where: str) -> _Options:
    """Check the shadow arguments; the options with the shadow settings and an outputs dict where needed."""
    from frustum.shadow_pass import check_shadows

    shadow = check_shadows(shadows, map_size, softness, options.method, options.mode, where)
    if "shadow" in options.buffers and shadow is None:
        raise FrustumError(
            f"{where}: buffers = {describe(options.buffers)} asks for 'shadow' with shadows = {describe(shadows)}; "
            "give shadows=True or 'ray'"
        )
    if "position" in options.buffers and options.mode in ("wireframe", "points"):
        raise FrustumError(
            f"{where}: buffers = {describe(options.buffers)} asks for 'position' with mode = {options.mode!r}; "
            "positions are those of surfaces: use a surface mode"
        )
    wanted = shadow is not None or "position" in options.buffers
    return dataclasses.replace(options, shadow=shadow, outputs={} if wanted else None)


def _draw_depth(item: SceneItem, camera: Camera, depth: np.ndarray, codes: np.ndarray, bary: np.ndarray) -> None:
    """Stages 1–4 of one item, both sides, into `depth` alone (codes and weights are scratch): a shadow map."""
    binned = bin_item(item, camera, False)
    tiling = np.array([TILE_SIZE, binned.tiles_x, 0, depth.shape[1], depth.shape[0]], dtype=np.int64)
    triangles.rasterize_tiles(
        binned.faces, binned.win_int, binned.win_float, binned.tri_int, binned.tri_float, binned.tri_weights,
        binned.tile_starts, binned.tile_entries, tiling, depth, codes, bary,
    )  # fmt: skip


def _shadow_pass(
    scene: Scene, items: list[SceneItem], drawn: list[tuple[int, np.ndarray, int]], camera: Camera,
    options: _Options, lights: np.ndarray, depth: np.ndarray, codes: np.ndarray, bary: np.ndarray,
) -> None:  # fmt: skip
    """World points of the drawn opaque pixels and, with shadows on, each light's fraction reaching them, into
    ``options.outputs`` ("position", "seen")."""
    from frustum import shadow_pass

    assert options.outputs is not None
    points, facing = shadow_pass.surface_points(items, drawn, depth, codes, bary)
    options.outputs["position"] = points
    if options.shadow is not None:
        options.outputs["seen"] = shadow_pass.light_fractions(
            scene, items, camera, options.shadow, lights, depth, points, facing, _draw_depth, "render"
        )
        options.outputs["casting"] = np.array(shadow_pass.shadow_lights(scene)[0], dtype=np.int64)
    shadow_pass.give_back(facing)


def _lit_per_light(
    mesh: Mesh, faces: np.ndarray, world: np.ndarray, normals: np.ndarray, params: np.ndarray, lights: np.ndarray,
    options: _Options,
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


def _shadow_buffers(options: _Options) -> tuple[np.ndarray | None, np.ndarray | None]:
    """``Frame.position`` and ``Frame.shadow`` where asked for (float32, NaN where nothing is drawn)."""
    if options.outputs is None:
        return None, None
    position = shadow = None
    points = options.outputs.get("position")
    if "position" in options.buffers and points is not None:
        position = points.astype(np.float32)
    if "shadow" in options.buffers and points is not None:
        seen = options.outputs["seen"][..., options.outputs["casting"]]
        shadow = np.where(np.isnan(points[..., :1]), np.float32(np.nan), seen).astype(np.float32)
    if points is not None:  # copied out above: the next frame may have it
        from frustum.shadow_pass import give_back

        give_back(points)
    return position, shadow
