"""The scene's drawn triangles in window coordinates, one flat list, for the visible-surface methods.

The depth buffer draws each item straight from its vertices' window records, triangle by triangle. The other
methods (scan-line, area subdivision, depth sort, BSP, A-buffer) need every surface at once: ``window_triangles``
runs the same vertex stage (``raster.vertices.project_vertices``), the same trivial accept / reject, cull and box
(``raster.triangles.face_box``) and the same clipping of faces crossing the view volume
(``raster.triangles.clip_faces``) and lists the results in drawing order (item by item, face by face; a clipped
face's fan in place of the face). Every method then writes, per pixel, the depth-buffer's depth, face code and
barycentrics of the surface it finds visible (``raster.window.write_pixel``), so that the one shading kernel
colors them: the same illumination model, the same bytes wherever the same surface is found.

References
----------
[HB 16] "Visible-Surface Detection Methods"; [seed] "Visible-surface detection".
"""

from __future__ import annotations

import dataclasses

import numpy as np

from frustum.camera import Camera
from frustum.clipping import VIEW_VOLUME_PLANES
from frustum.scene import SceneItem

__all__ = ["WindowTriangles", "window_triangles"]


@dataclasses.dataclass(frozen=True)
class WindowTriangles:
    """T drawn triangles in window coordinates (layout of ``raster.window``): ``xy`` (T, 6) int64 snapped
    counter-clockwise corners, ``zq`` (T, 3, 4) float64 ``z_w, 1/w`` and the snap residuals, ``weights`` (T, 3, 2)
    float64 barycentric weights onto the source face, ``code`` (T,) int64 $2·face + back$, ``box`` (T, 4) int64
    pixel box, ``item`` (T,) int64 index of the scene item; ``width``, ``height`` of the image."""

    xy: np.ndarray
    zq: np.ndarray
    weights: np.ndarray
    code: np.ndarray
    box: np.ndarray
    item: np.ndarray
    width: int
    height: int

    @property
    def code_type(self) -> type:
        """dtype of a face-code buffer for these triangles (the depth buffer's: int32 while codes fit)."""
        return np.int32 if int(self.code.max(initial=0)) < 2**31 - 1 else np.int64

    @property
    def count(self) -> int:
        """Number of triangles T."""
        return int(self.code.shape[0])

    def select(self, keep: np.ndarray) -> WindowTriangles:
        """The triangles where the (T,) bool `keep` holds, in order."""
        return WindowTriangles(
            *(np.ascontiguousarray(a[keep]) for a in (self.xy, self.zq, self.weights, self.code, self.box, self.item)),
            self.width, self.height,
        )  # fmt: skip


def _faces(item: SceneItem) -> np.ndarray:
    """The item's faces counter-clockwise after its modeling transform (as ``render.stages.world_faces``)."""
    faces = np.ascontiguousarray(item.mesh.faces, dtype=np.int64)
    if np.linalg.det(np.asarray(item.world_from_model)[:3, :3]) < 0.0:
        return np.ascontiguousarray(faces[:, [0, 2, 1]])
    return faces


def window_triangles(
    items: list[SceneItem], indices: list[int], face_offsets: list[int], camera: Camera, cull: bool
) -> WindowTriangles:
    """The drawn triangles of ``items[k]`` for k in `indices` (face numbers offset by ``face_offsets[k]``).

    Parameters
    ----------
    items : list of SceneItem
        ``scene.items``.
    indices : list of int
        Which items to list, in drawing order.
    face_offsets : list of int
        Per item, the number of faces of the items before it (the shading kernel's face numbering).
    camera : Camera
    cull : bool
        Drop back faces (clockwise in window coordinates); otherwise draw them with corners 1 and 2 swapped.
    """
    from frustum.raster import triangles
    from frustum.raster import window as kernels
    from frustum.raster.vertices import project_vertices

    width, height = camera.width, camera.height
    view = np.array([width / 2.0, height / 2.0])
    parts: list[tuple[np.ndarray, ...]] = []
    for k in indices:
        item = items[k]
        mesh = item.mesh
        if mesh.face_count == 0:
            continue
        faces = _faces(item)
        clip_from_model = camera.clip_from_world @ np.asarray(item.world_from_model, dtype=np.float64)
        small = triangles.SUBPIXEL * (max(width, height) + 2) < 2**31  # as render.bin_item: one compiled version
        win_int = np.empty((mesh.vertex_count, 2), dtype=np.int32 if small else np.int64)
        win_float = np.empty((mesh.vertex_count, 4))  # z_w, 1/w and the snap residuals
        vertex_codes = np.zeros(mesh.vertex_count, dtype=np.uint8)
        project_vertices(mesh.vertices, clip_from_model, view, win_int, win_float, vertex_codes)
        options = np.array([width, height, int(cull), face_offsets[k], 0], dtype=np.int64)
        slots = np.empty(faces.shape[0], dtype=np.int64)
        out = _allocate(0)
        kernels.gather_faces(faces, vertex_codes, win_int, win_float, options, slots, *out)
        drawn = slots.astype(bool)
        starts = np.cumsum(slots) - slots
        out = _allocate(int(slots.sum()))
        options[4] = 1
        kernels.gather_faces(faces, vertex_codes, win_int, win_float, options, starts, *out)
        order = np.flatnonzero(drawn)
        # the faces crossing the view volume: their clipped fans (``render.bin_item``'s second half)
        c = vertex_codes[faces]
        crossing = np.flatnonzero(((c[:, 0] & c[:, 1] & c[:, 2]) == 0) & ((c[:, 0] | c[:, 1] | c[:, 2]) != 0))
        if crossing.shape[0]:
            clip_options = np.array([width, height, int(cull), face_offsets[k], 0], dtype=np.int64)
            arguments = (crossing, faces, mesh.vertices, clip_from_model, VIEW_VOLUME_PLANES, view, clip_options)
            record_starts, tri_int, tri_float, tri_weights = clip_crossing(arguments)
            counts = np.diff(record_starts)
            records = (
                np.ascontiguousarray(tri_int[:, :6]), tri_float, tri_weights, tri_int[:, 6].copy(),
                np.ascontiguousarray(tri_int[:, 7:11]),
            )  # fmt: skip
            out = tuple(np.concatenate([a, b]) for a, b in zip(out, records, strict=True))
            order = np.concatenate([order, np.repeat(crossing, counts)])
        rank = np.argsort(order, kind="stable")  # face order, a clipped fan in place of its face
        parts.append((*(np.ascontiguousarray(a[rank]) for a in out), np.full(rank.shape[0], k, dtype=np.int64)))
    if not parts:
        return WindowTriangles(*_allocate(0), np.empty(0, dtype=np.int64), width, height)
    return WindowTriangles(*(np.concatenate(column) for column in zip(*parts, strict=True)), width, height)


def clip_crossing(arguments: tuple) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The faces crossing the view volume clipped into window-triangle records by ``raster.triangles.clip_faces``
    (`arguments`: its leading arguments, the crossing faces first and the options last), in two passes: count,
    prefix sum, write. Returns (record_starts (C + 1,), tri_int, tri_float, tri_weights); ``render.bin_item``
    clips this way too."""
    from frustum.raster import triangles

    clip_options = arguments[-1]
    record_starts = np.zeros(arguments[0].shape[0] + 1, dtype=np.int64)
    tri_int = np.empty((0, triangles.RECORD_FIELDS), dtype=np.int64)
    tri_float, tri_weights = np.empty((0, 3, 4)), np.empty((0, 3, 2))  # z_w, 1/w, the snap residuals
    clip_options[4] = 0
    triangles.clip_faces(*arguments, record_starts[1:], tri_int, tri_float, tri_weights)
    record_starts = np.cumsum(record_starts)
    total = int(record_starts[-1])
    tri_int = np.empty((total, triangles.RECORD_FIELDS), dtype=np.int64)
    tri_float, tri_weights = np.empty((total, 3, 4)), np.empty((total, 3, 2))
    clip_options[4] = 1
    triangles.clip_faces(*arguments, record_starts[:-1], tri_int, tri_float, tri_weights)
    return record_starts, tri_int, tri_float, tri_weights


def _allocate(count: int) -> tuple[np.ndarray, ...]:
    return (
        np.empty((count, 6), dtype=np.int64), np.empty((count, 3, 4)), np.empty((count, 3, 2)),
        np.empty(count, dtype=np.int64), np.empty((count, 4), dtype=np.int64),
    )  # fmt: skip
