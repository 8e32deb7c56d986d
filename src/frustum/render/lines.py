"""The line pass: mesh edges as lines (``"wireframe"``, and the visible edges of ``"hidden-line"`` and
``"surface+edges"``), vertices as points (``"points"``), and placed polylines, depth-tested in scene order by the
serial ``raster.lines`` kernels; the vertex stage of lines in NumPy (``clip_vertices``: few points, no kernel)."""

from __future__ import annotations

import weakref

import numpy as np

from frustum.camera import Camera
from frustum.clipping import VIEW_VOLUME_PLANES
from frustum.geometry import Mesh
from frustum.raster import lines
from frustum.render.context import FrameContext
from frustum.render.options import EDGE_MODES, RenderOptions
from frustum.render.stages import cue_color, item_matrices, rows, world_faces
from frustum.scene import SceneItem
from frustum.visibility.hidden_lines import (
    EdgeAdjacency,
    classify_edges,
    edge_adjacency,
    front_facing,
    welded_adjacency,
)

EDGE_OFFSET = 1e-5
"""Window-depth offset of the hidden-line test (``raster.lines``), against stitching of edges into faces."""


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


def draw_edges(items: list[SceneItem], camera: Camera, options: RenderOptions, context: FrameContext) -> None:
    """Lines (or points) of every item into the frame, serially in scene order (``raster.lines``)."""
    depth, color = context.depth, context.color
    view = np.array([camera.width / 2.0, camera.height / 2.0])
    eye = np.asarray(camera.frame.eye, dtype=np.float64)
    axis = np.asarray(camera.frame.n, dtype=np.float64)
    edge_modes = options.mode in EDGE_MODES
    cue = line_cue(options)
    for item in items:
        mesh = item.mesh
        if options.edge_color is not None:
            rgba = options.edge_color
        else:
            rgba = np.append(np.floor(np.clip(item.material.color, 0.0, 1.0) * 255.0 + 0.5), 255.0)
        style = lines.line_style(
            rgba, width=options.line_width, write_depth=not edge_modes, hidden_line=edge_modes, offset=EDGE_OFFSET,
            hidden={None: 0, "dimmed": 1, "dashed": 2}[options.hidden] if options.mode == "hidden-line" else 0,
            hidden_rgba=options.hidden_color, dash=6.0 * options.line_width, cue=cue,
        )  # fmt: skip
        clip, world, vertex_codes = clip_vertices(mesh.vertices, item.world_from_model, camera)
        view_depth = (eye - world) @ axis
        if options.mode == "points":
            lines.draw_points(clip, view_depth, vertex_codes, view, style, depth, color)
            continue
        # feature edges by shared positions: a cap's rim or a seam split for normals or UVs is not a boundary
        adjacency = welded_adjacency(mesh) if options.edges == "feature" else _adjacency(mesh)
        edges = adjacency.edges
        if edge_modes or options.edges == "feature":
            faces = world_faces(item)
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


def draw_polylines(line_items: list[SceneItem], camera: Camera, options: RenderOptions, context: FrameContext) -> None:
    """Every placed ``Polyline`` as depth-tested lines (or marker squares) in its material color, in order."""
    depth, color = context.depth, context.color
    view = np.array([camera.width / 2.0, camera.height / 2.0])
    cue = line_cue(options)
    for item in line_items:
        line = item.mesh
        if line.vertex_count == 0:
            continue
        rgba = np.append(np.floor(np.clip(item.material.color, 0.0, 1.0) * 255.0 + 0.5), 255.0)
        width = options.line_width + (2.0 if line.markers else 0.0)
        style = lines.line_style(rgba, width=width, cue=cue)
        clip, world, vertex_codes = clip_vertices(line.points, item.world_from_model, camera)
        view_depth = (np.asarray(camera.frame.eye) - world) @ np.asarray(camera.frame.n)
        if line.markers:
            lines.draw_points(clip, view_depth, vertex_codes, view, style, depth, color)
        else:
            lines.draw_lines(clip, view_depth, line.segments, VIEW_VOLUME_PLANES, view, style, depth, color)


def clip_vertices(points: np.ndarray, world_from_model: np.ndarray, camera: Camera):
    """Clip coordinates (N, 4), world positions (N, 3) and view-volume region codes (N,) int64 of model-space
    points, in NumPy (lines and edges have few points; no kernel to compile): each row of $M·[x, y, z, 1]$
    summed left to right, $((m0·x + m1·y) + m2·z) + m3$, and bit k of the code set when
    $((p0·x_c + p1·y_c) + p2·z_c) + p3·w_c < 0$ for plane k of ``VIEW_VOLUME_PLANES`` — the operations, in the
    order, of the kernels' vertex stage (``raster.vertices``), so the same bytes."""
    item = SceneItem(None, None, world_from_model)  # type: ignore[arg-type]
    matrices = item_matrices(item, camera)
    clip, world = rows(points, matrices[0], 4, affine=True), rows(points, matrices[1], 3, affine=True)
    vertex_codes = np.zeros(points.shape[0], dtype=np.int64)
    for k, p in enumerate(VIEW_VOLUME_PLANES):
        distance = ((p[0] * clip[:, 0] + p[1] * clip[:, 1]) + p[2] * clip[:, 2]) + p[3] * clip[:, 3]
        vertex_codes |= (distance < 0.0).astype(np.int64) << k
    return clip, world, vertex_codes


def line_cue(options: RenderOptions) -> tuple | None:
    """The depth cue in ``lines.line_style`` form (color in bytes), or None."""
    if options.depth_cue is None:
        return None
    c = options.depth_cue
    return (c.near, c.far, c.min_intensity, c.max_intensity, *(255.0 * cue_color(options)))
