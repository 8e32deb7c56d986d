"""The point pass of ``render``: every placed ``PointCloud`` into the depth buffer, after the opaque surfaces.

Per cloud (``Scene.point_clouds``, styles of ``frustum.geometry.points.PointStyle``):

1. ``raster.points.project_points`` (squares, disks) or ``project_impostors`` (spheres, surfels), parallel over
   points: $clip = clip_from_world·world_from_model·P$, kept when the centre lies in the view volume (as GL
   clips points); a square or disk of a world radius r has the side $s = 2r·|P₁₁|·H/2 / w$ pixels.
2. Bands of ``raster.particles.BAND_ROWS`` rows (``count_bands`` / ``fill_bands``, point order kept).
3. ``raster.points.draw_points`` / ``draw_impostors``, parallel over bands: depth test "less", depth, color,
   normal and object id written where a point wins.

Colors: the points' own colors (a cloud without colors: the material's color), which the material's coefficients
light. Squares and disks are lit by the scene's lights (the one model of
``frustum.shading``, ``raster.shade._illuminate``) with their normals when the cloud has normals, else drawn in their
colors (a scan: see ``render(..., eye_dome=True)``); spheres with the true normal of the hit point, surfels with
their disk normal turned toward the viewer (``shading="none"``: colors only). Sizes in pixels are multiplied by
√samples when supersampling. Object ids (``buffers=("object_id",)``) of clouds follow the meshes':
$len(scene.items) + i$ for the i-th placed cloud or splat set (``Scene.point_clouds``), so ``instance``,
``semantic`` and the datasets hold them (``render.ground_truth``); a cloud's amodal mask is the cloud drawn alone
(``silhouette``).

References
----------
Gross & Pfister, "Point-Based Graphics" (2007) §6 (splatting, surfels); the OpenGL 4.6 spec §14.4 (point
rasterization: the square of side ``gl_PointSize`` centred on the point).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from frustum.camera import Camera
from frustum.render.buffers import Scratch
from frustum.render.context import FrameContext
from frustum.render.options import RenderOptions
from frustum.render.particles import bands
from frustum.render.stages import Lighting, shading_parameters
from frustum.scene import PointItem, Scene, SceneItem
from frustum.shading import pack_lights
from frustum.transforms import apply, apply_to_normals

__all__ = ["draw_point_clouds", "draw_points", "silhouette"]


def draw_point_clouds(scene: Scene, camera: Camera, options: RenderOptions, buffers: FrameContext) -> None:
    """Every placed PointCloud of `scene` into `buffers` (splats: ``render.splats``)."""
    placed = scene.point_clouds
    clouds = [(i, p) for i, p in enumerate(placed) if p.style.style != "splats"]
    if not clouds:
        return
    lighting = Lighting.of(scene)
    first_id = len(scene.items)
    before = buffers.depth.copy() if "position" in buffers.outputs else None
    for index, item in clouds:
        draw_points(item, first_id + index, camera, options, lighting, buffers)
    if before is not None:  # the "position" buffer: the points' pixels hold their own world points
        buffers.place_drawn(camera, buffers.depth != before)


def silhouette(item: PointItem, camera: Camera, options: RenderOptions) -> np.ndarray:
    """(H, W) bool at the camera's size: where the cloud `item` drawn alone writes depth (its amodal mask; sizes in
    pixels times ``options.factor``, as when drawn with the scene)."""
    from frustum.raster import shade

    unlit = dataclasses.replace(options, shade_mode=shade.SHADE_NONE)  # coverage only: no lighting needed
    lighting = Lighting(*pack_lights([]))
    context = FrameContext(None, None, Scratch())
    context.depth = np.ones((camera.height, camera.width), dtype=np.float32)
    context.color = np.zeros((camera.height, camera.width, 4), dtype=np.uint8)
    draw_points(item, 0, camera, unlit, lighting, context)
    return context.depth < 1.0




def draw_points(item: PointItem, object_id: int, camera: Camera, options: RenderOptions, lighting: Lighting,
                buffers: FrameContext) -> None:  # fmt: skip
    """One placed cloud into `buffers` (the module docstring's steps)."""
    from frustum.raster import points as kernels
    from frustum.raster import shade

    cloud, style, world_from_model = item.geometry, item.style, item.world_from_model
    count = cloud.point_count
    if count == 0:
        return
    height, width = camera.height, camera.width
    model = np.ascontiguousarray(cloud.points, dtype=np.float64)
    impostor = style.style in ("sphere", "surfel")
    scale_3d = abs(float(np.linalg.det(world_from_model[:3, :3]))) ** (1.0 / 3.0)
    radii = cloud.radii if style.radius is None else np.array([style.radius])
    lit = options.shade_mode != shade.SHADE_NONE and (impostor or cloud.normals is not None)
    normals_out, ids_out = buffers.extra()
    item_array = np.zeros(kernels.ITEM, dtype=np.int64)
    item_array[kernels.I_STYLE] = ("square", "disk", "sphere", "surfel").index(style.style)
    item_array[kernels.I_LIT] = int(lit)
    item_array[kernels.I_SPECULAR_MODEL] = options.specular_model
    item_array[kernels.I_OBJECT_ID] = object_id
    item_array[kernels.I_WRITE_NORMALS] = int(buffers.normals is not None)
    item_array[kernels.I_WRITE_IDS] = int(buffers.object_id is not None)
    params = shading_parameters(SceneItem(None, item.material, world_from_model), camera, options, lighting.ambient)
    colors = np.zeros((0, 3)) if cloud.colors is None else np.ascontiguousarray(cloud.colors)
    if impostor:
        records = buffers.scratch.empty((count, kernels.IMPOSTOR_FIELDS))
        rows = buffers.scratch.empty((count, 2), np.int64)
        view_from_model = np.ascontiguousarray(camera.view_matrix @ world_from_model)
        clip_from_view = np.ascontiguousarray(camera.projection_matrix, dtype=np.float64)
        normals = np.zeros((0, 3)) if style.style == "sphere" else np.ascontiguousarray(cloud.normals)
        frame = np.array([width, height], dtype=np.float64)
        kernels.project_impostors(model, np.ascontiguousarray(radii * scale_3d), normals, view_from_model,
                                  clip_from_view, frame, records, rows)  # fmt: skip
        starts, entries, band_rows = bands(rows, height)
        matrices = np.ascontiguousarray(np.stack([np.linalg.inv(clip_from_view), clip_from_view,
                                                  np.linalg.inv(camera.view_matrix)]))  # fmt: skip
        kernels.draw_impostors(records, starts, entries, band_rows, matrices, colors, params, lighting.lights,
                               item_array, buffers.depth, buffers.color, normals_out, ids_out)  # fmt: skip
        return
    clip_from_model = np.ascontiguousarray(camera.clip_from_world @ world_from_model, dtype=np.float64)
    records = buffers.scratch.empty((count, kernels.POINT_FIELDS))  # recycled: an animation's next frame reuses them
    rows = buffers.scratch.empty((count, 2), np.int64)
    if style.point_size is not None:
        sizes = np.array([style.point_size * options.factor])
        frame = np.array([width, height, 0.0])
    else:  # a world radius: the side 2r·|P11|·H/2 / w, per point
        sizes = 2.0 * scale_3d * np.ascontiguousarray(radii, dtype=np.float64)
        frame = np.array([width, height, abs(float(camera.projection_matrix[1, 1])) * height / 2.0])
    kernels.project_points(model, sizes, clip_from_model, frame, records, rows)
    starts, entries, band_rows = bands(rows, height)
    world = normals = np.zeros((0, 3))
    if lit or buffers.normals is not None:
        if cloud.normals is not None:
            normals = np.ascontiguousarray(apply_to_normals(world_from_model, np.asarray(cloud.normals)))
        if lit:
            world = np.ascontiguousarray(apply(world_from_model, model))
    kernels.draw_points(records, starts, entries, band_rows, world, colors, normals, params, lighting.lights,
                        item_array, buffers.depth, buffers.color, normals_out, ids_out)  # fmt: skip
