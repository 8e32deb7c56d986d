"""The pipeline driver: ``render(scene, camera)`` runs the passes in order and returns a ``Frame``.

The passes, one module each (``_draw`` lists them in order; a new pass is a module and a line there):
``options`` (the checked options, one frozen object: configuration only), ``context`` (what one image's passes
draw into and hand on: buffers, counts, outputs; the Frame made of them), ``buffers`` (recycled arrays, filters),
``surfaces`` (the depth buffer's opaque and transparent surfaces), ``methods`` (the other visible-surface methods,
dispatched to ``visibility/``), ``lines`` (edges, wireframes, points, polylines), ``volumes`` (volumes ray cast over
the surfaces, each ray stopped at the depth there), ``particles`` (particle layers, depth-tested, depth not
written), ``shadows`` (shadow maps and rays, a sub-package), ``raytrace`` and ``radiosity``; ``stages`` holds
the per-item stages the surface passes share.

Fast path, per scene item (one compiled pass each, buffers shared between items):

1. ``raster.vertices.project_vertices``: $clip = clip_from_world·world_from_model·P$, region codes and, for the
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
   their covered span), depth on the triangle's plane ($z = (z_0 + β·ΔY) + α·ΔX$, no division per pixel),
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
   blended $α·I + (1 − α)·under$.
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
from typing import Any

from frustum.camera import Camera
from frustum.frame import Frame
from frustum.render import (
    eye_dome,
    ground_truth,
    lines,
    methods,
    particles,
    points,
    reflection,
    splats,
    surfaces,
    volumes,
)
from frustum.render.buffers import FrameBuffers as FrameBuffers
from frustum.render.buffers import Scratch as Scratch
from frustum.render.buffers import block_min as block_min
from frustum.render.buffers import clear_buffers as clear_buffers
from frustum.render.buffers import release_kept
from frustum.render.buffers import resolve_color as resolve_color
from frustum.render.context import FrameContext
from frustum.render.lines import mesh_edges as mesh_edges
from frustum.render.methods import RENDER_METHODS as RENDER_METHODS
from frustum.render.methods import VISIBILITY_METHODS as VISIBILITY_METHODS
from frustum.render.options import (
    DEFAULT_BACKGROUND,
    EDGE_MODES,
    LINE_MODES,
    RenderOptions,
    check_method,
    check_next,
)
from frustum.render.options import HIDDEN_STYLES as HIDDEN_STYLES
from frustum.render.options import RENDER_MODES as RENDER_MODES
from frustum.render.options import SHADING_MODES as SHADING_MODES
from frustum.render.options import TRANSPARENCY_MODES as TRANSPARENCY_MODES
from frustum.render.stages import TILE_SIZE as TILE_SIZE
from frustum.render.stages import Binned as Binned
from frustum.render.stages import bin_item as bin_item
from frustum.render.stages import item_matrices as item_matrices
from frustum.scene import Scene
from frustum.shading import DepthCue

__all__ = [
    "HIDDEN_STYLES", "RENDER_METHODS", "RENDER_MODES", "SHADING_MODES", "TILE_SIZE", "TRANSPARENCY_MODES",
    "VISIBILITY_METHODS", "mesh_edges", "release_memory", "render",
]  # fmt: skip


def release_memory() -> int:
    """Free the work arrays ``render`` keeps between calls (face codes, barycentrics, window records, tile lists
    of the last frame: about 200 MiB after a 4096² frame) and the color and depth buffers of the last two frames
    that no Frame holds any more (``FrameBuffers``); return how many bytes were released.

    The next ``render`` allocates (and first-touches) them anew. Call it when a program that rendered large
    frames goes on to other work.
    """
    # the shadow pass's maps kept for reuse and the per-pixel arrays of every pass (render.buffers.take_array)
    return Scratch.release_pool() + FrameBuffers.release() + release_kept()


def render(
    scene: Scene,
    camera: Camera,
    *,
    shading: str | None = "phong",
    specular: str = "blinn-phong",
    background: Any = DEFAULT_BACKGROUND,
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
    max_depth: int = 5,
    shadows: bool | str | None = None,
    shadow_map_size: int = 2048,
    shadow_softness: float = 1.0,
    eye_dome: bool = False,
    eye_dome_strength: float = 1.0,
    tone_map: str = "none",
    exposure: float = 1.0,
    next: tuple[Scene, Camera] | None = None,
) -> Frame:
    """Render `scene` seen by `camera` into a ``Frame`` (color (H, W, 4) uint8 and depth (H, W) float32).

    Parameters
    ----------
    scene : Scene
        Placed meshes with materials and any number of lights (``frustum.shading``).
    camera : Camera
        Its width and height are the image size.
    shading : {"phong", "gouraud", "flat", "pbr", "normals", "depth", "none"} or None
        Where the illumination model is evaluated: per pixel, per vertex (interpolated), or per face
        (``raster/shade.py``); ``"normals"`` shows $0.5·N + 0.5$ of the world normal, ``"depth"`` the gray
        $(far − d)/(far − near)$ of the view distance; ``"none"`` (or None): the base color, no lighting.
        ``"pbr"``: every item per pixel by glTF's metallic–roughness model (``frustum.shading.pbr``, lights in
        glTF units, the scene's environment map as image-based light; a classical material by the mapping
        there); with ``"phong"`` an item whose ``Material.model`` is ``"pbr"`` is shaded that way too.
        docs/materials.md.
    specular : {"blinn-phong", "phong"}
        The specular term: (N·H)^n or (R·V)^n.
    background : (4,) array_like
        RGBA in [0, 1] for pixels nothing covers; stored as $round(255·value)$. Not given, a scene with an
        ``environment`` map shows the map there (``render.reflection``), else opaque black.
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
        are drawn √samples times as wide, so they come out anti-aliased. Depth keeps each block's nearest
        (with a ground-truth buffer asked for, the block's middle sample: the one its ids and points come from).
    color_space : {"linear", "srgb"}
        Output encoding; "srgb" applies the sRGB transfer curve to the linear result.
    buffers : tuple of {"normals", "object_id", "position", "shadow", "instance", "semantic", "amodal",
            "object_coords", "nocs", "flow"}
        Extra per-pixel outputs on the Frame: unit world normals (0 on background), the index of the item
        in ``scene.items`` (−1 on background), the world point of the nearest opaque surface ((H, W, 3) float32,
        NaN on background) and, with `shadows` on, the fraction of each shadow-casting light reaching it ((H, W,
        L) float32, NaN on background; lights in ``Scene.world_lights`` order, ``frustum.render.shadows.fractions``);
        the ground truth of ``frustum.render.ground_truth``: instance and semantic ids, amodal masks with
        ``Frame.visibility``, object coordinates, NOCS and optical flow to `next` with ``Frame.flow_occluded``.
        Ids and points come from one sample per pixel (never a blend of two objects).
    method : str
        The visible-surface method (``RENDER_METHODS``, docs/visibility.md). For the meshes
        (``VISIBILITY_METHODS``): ``"depth-buffer"`` (the default), ``"scan-line"``, ``"area-subdivision"``
        (Warnock), ``"depth-sort"``, ``"bsp"``, ``"ray-casting"`` (a ray per pixel through the scene's BVH) or
        ``"a-buffer"`` (anti-aliased edges, exact transparency). ``"ray-tracing"``: Whitted ray tracing (shadow
        rays, mirror reflection by ``Material.reflectivity``, refraction through surfaces of opacity < 1 by
        ``Material.ior``, to `max_depth` levels; ``frustum.render.raytrace``, docs/ray-tracing.md). All
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
    max_depth : int
        ``method="ray-tracing"``: levels of reflected and refracted rays after the primary ray, 0 … 64
        (0: primary rays and shadow rays only).
    shadows : None, False, True or "ray"
        None: the method's own (on for ``method="ray-tracing"``, which casts shadow rays; off for the depth buffer
        and the other methods, so pictures of today do not change); False: off; True: shadow maps (the
        depth-buffer method from each light; ``"ray-tracing"`` always uses its shadow rays); ``"ray"``: exact
        shadow rays through the scene's BVH (``method="ray-casting"`` always uses rays). Lights with
        ``cast_shadows=False`` and ambient light cast none. Surface modes only; not with ``method="octree"`` or
        ``"a-buffer"``. What casts, what receives and how each shading mode uses the result:
        ``frustum.render.shadows.fractions`` (pass: ``render.shadows``).
    shadow_map_size : int
        Texels on a side of each shadow map, a power of two in [64, 16384] (a point light has six).
    shadow_softness : float
        Percentage-closer filter width in texels, in [0, 16]; 0: hard edges; up to 1 (default): the 2 × 2 texels
        around the point, bilinearly weighted (``frustum.render.shadows.fractions``).
    eye_dome, eye_dome_strength : bool, float
        Eye-dome lighting, a post-pass that darkens each pixel by how far its neighbours stand in front of it
        (``render.eye_dome``): shape for unlit point clouds (scans); the strength (> 0) scales the darkening.
    tone_map : {"none", "aces", "khronos-neutral"}
        The metallic–roughness model's output transform after `exposure` and before `color_space`
        (``frustum.shading.tone``): ``"none"`` (default: the radiance, clamped, as the classical model's), the
        ACES filmic fit, or Khronos PBR Neutral. Classical items are not tone mapped.
    exposure : float
        Linear factor (> 0) on the metallic–roughness model's radiance before the tone map.
    next : (Scene, Camera) or None
        With ``"flow"`` in `buffers`: the scene and camera of the next frame (items matched by node path,
        ``Scene.item_paths``). Backward flow: swap the two frames.

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
    check_method(method, "render")
    check_next(buffers, next, "render")  # the methods of RENDER_METHODS too
    if RENDER_METHODS[method] is not None:
        return RENDER_METHODS[method](scene, camera, background=background)
    options = RenderOptions.from_keywords(
        scene, camera, shading=shading, specular=specular, background=background, cull_back_faces=cull_back_faces,
        mode=mode, edges=edges, crease_angle=crease_angle, edge_color=edge_color, hidden=hidden,
        hidden_color=hidden_color, line_width=line_width, depth_cue=depth_cue, samples=samples, filter=filter,
        color_space=color_space, buffers=buffers, method=method, transparency=transparency, stats=stats,
        max_depth=max_depth, shadows=shadows, shadow_map_size=shadow_map_size, shadow_softness=shadow_softness,
        eye_dome=eye_dome, eye_dome_strength=eye_dome_strength,
        tone_map=tone_map, exposure=exposure, next=next,
    )  # fmt: skip
    if options.factor == 1:
        return _draw(scene, camera, options).to_frame(options)
    big = dataclasses.replace(camera, width=camera.width * options.factor, height=camera.height * options.factor)
    return _draw(scene, big, options.supersampled()).to_frame(options)


def _draw(scene: Scene, camera: Camera, options: RenderOptions) -> FrameContext:
    """The passes of one image at the camera's size, in order, into the frame's context (``render.context``)."""
    context = FrameContext.for_image(camera, options)
    if options.mode in LINE_MODES:  # lines or points straight into the depth buffer, no surfaces
        context.start(camera, options)
        lines.draw_edges(scene.items, camera, options, context)
        lines.draw_polylines(scene.polylines, camera, options, context)
        points.draw_point_clouds(scene, camera, options, context)
        reflection.paint_background(camera, options, context)
        volumes.draw_volumes(scene, camera, context.depth, context.color)  # rays stopped at the lines' depth
        splats.draw_splats(scene, camera, options, context)
        particles.draw_particles(scene.particle_layers, camera, context.depth, context.color)
        eye_dome.shade(camera, options, context)
        return context
    _draw_surfaces(scene, camera, options, context)
    context.scratch.release()
    if options.mode == "hidden-line":  # the surfaces only fill the depth buffer
        context.color[:, :] = options.background
    volumes_between = bool(scene.volumes) and options.volumes_with_surfaces
    if not volumes_between:  # else drawn under the volumes, by _draw_between
        if options.mode in EDGE_MODES:
            lines.draw_edges(scene.items, camera, options, context)
        lines.draw_polylines(scene.polylines, camera, options, context)
        if not options.volumes_with_surfaces:  # "hidden-line": rays stopped at the (invisible) surfaces
            volumes.draw_volumes(scene, camera, context.depth, context.color)
    particles.draw_particles(scene.particle_layers, camera, context.depth, context.color)
    eye_dome.shade(camera, options, context)
    ground_truth.draw(scene, camera, options, context)  # ids, masks, model points, flow of the opaque surfaces
    return context


def _draw_surfaces(scene: Scene, camera: Camera, options: RenderOptions, context: FrameContext) -> None:
    """The surface modes: the opaque surfaces by the method, then what goes between (``_draw_between``), then
    the transparent items."""
    if options.method == "ray-tracing":
        from frustum.render import raytrace

        raytrace.draw_surfaces(scene, camera, options, context)
        _draw_between(scene, camera, options, context)
    elif options.method == "a-buffer":
        if scene.volumes and options.volumes_with_surfaces:  # opaque fragments, volumes, transparent fragments
            methods.draw_fragments(scene, camera, options, context, "opaque")
            _draw_between(scene, camera, options, context)
            methods.draw_fragments(scene, camera, options, context, "transparent")
        else:
            methods.draw_fragments(scene, camera, options, context)
    elif options.method == "depth-buffer":
        # transparent items through an A-buffer over the depth buffer's opaque frame, or sorted by the depth buffer
        items = scene.items if options.transparency == "sort" else methods.opaque_only(scene.items)
        surfaces.draw_opaque(scene, items, camera, options, context)
        _draw_between(scene, camera, options, context)
        surfaces.draw_transparent(scene, items, camera, options, context)
        if options.transparency == "a-buffer":
            methods.composite_transparent(scene, camera, options, context)
        elif options.counted:
            methods.count_depth_tests(scene.items, camera, options, context)
    else:
        methods.draw_opaque_by_method(scene, camera, options, context)
        _draw_between(scene, camera, options, context)
        methods.draw_transparent_by_method(scene, camera, options, context)


def _draw_between(scene: Scene, camera: Camera, options: RenderOptions, context: FrameContext) -> None:
    """What goes over the opaque surfaces and under the transparent ones: the environment where no opaque surface
    is, and (with volumes) every volume ray cast, rays stopped at the surfaces' depth; the edges and polylines
    first, so the part of a cloud in front of a line covers it (polylines write depth, so they stop the rays
    too)."""
    points.draw_point_clouds(scene, camera, options, context)  # opaque, like the surfaces
    reflection.paint_background(camera, options, context)
    if scene.volumes and options.volumes_with_surfaces:
        if options.mode == "surface+edges":
            lines.draw_edges(scene.items, camera, options, context)
        lines.draw_polylines(scene.polylines, camera, options, context)
        volumes.draw_volumes(scene, camera, context.depth, context.color)
    splats.draw_splats(scene, camera, options, context)  # over the opaque surfaces, composited by depth
