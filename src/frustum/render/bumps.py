"""Bump and normal maps pass: per-pixel shading normals from ``Material.bump`` / ``Material.normal_map``.

For an item whose material has a bump or normal map and whose mesh has UVs, in Phong shading: each of its pixels
gets its interpolated position, UV and unit normal from the face code and barycentrics the depth buffer stored,
the normal is perturbed (``frustum.shading.surface_detail``: Blinn's formula for a height map, the tangent frame for a
normal map), and the pixels are shaded by the same kernel as every other pixel (``raster.shade.shade_pixels``)
as a one-row image of one small face per pixel whose corners all carry that pixel's point, normal, UV and color:
the same illumination model, texture lookup, depth cue, blending and extra outputs, with nothing new to compile.
Flat and Gouraud shading evaluate lighting per face or per vertex and leave the maps unused (documented in
``frustum.shading.surface_detail``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from frustum.raster import shade
from frustum.scene import SceneItem
from frustum.shading.surface_detail import (
    _bilinear_wrapped,
    bumped_normals,
    height_gradient,
    mapped_normals,
    tangent_frames,
)


def has_detail(item: SceneItem) -> bool:
    """Whether the item's material has a bump or normal map its mesh can use (it has UVs)."""
    material = item.material
    maps = material.bump is not None or material.normal_map is not None
    return maps and getattr(item.mesh, "uvs", None) is not None


def detail_pixels(
    item: SceneItem, faces: np.ndarray, world: np.ndarray, normals: np.ndarray, face_offset: int,
    depth: np.ndarray, codes: np.ndarray, bary: np.ndarray,
) -> tuple | None:  # fmt: skip
    """The item's pixels of these image rows and their perturbed normals (module docstring): (rows, cols, count,
    point, normal, uv, interpolate) with the (count, 3) world points, unit shading normals and (count, 2) UVs, and
    the function interpolating (vertices, k) values at them; None where the item has no pixel here."""
    mesh, material = item.mesh, item.material
    face = codes.astype(np.int64) // 2 - face_offset
    rows, cols = np.nonzero((depth < 1.0) & (face >= 0) & (face < faces.shape[0]))
    count = rows.size
    if count == 0:
        return None
    f = face[rows, cols]
    u1 = bary[rows, cols, 0].astype(np.float64)[:, None]
    u2 = bary[rows, cols, 1].astype(np.float64)[:, None]
    u0 = (1.0 - u1) - u2
    corners = faces[f]

    def interpolate(values: np.ndarray) -> np.ndarray:
        return u0 * values[corners[:, 0]] + u1 * values[corners[:, 1]] + u2 * values[corners[:, 2]]

    world64, normals64 = np.asarray(world, dtype=np.float64), np.asarray(normals, dtype=np.float64)
    uvs = np.asarray(mesh.uvs, dtype=np.float64)
    point, uv = interpolate(world64), interpolate(uvs)
    normal = interpolate(normals64)
    normal /= np.where((length := np.linalg.norm(normal, axis=1, keepdims=True)) > 0.0, length, 1.0)
    p_u, p_v = tangent_frames(world64, faces, uvs)
    p_u, p_v = interpolate(p_u), interpolate(p_v)
    if material.normal_map is not None:
        texel = _bilinear_wrapped(material.normal_map[..., :3].astype(np.float64), uv[:, 0], uv[:, 1])
        normal = mapped_normals(normal, p_u, p_v, texel)
    if material.bump is not None:
        b_u, b_v = height_gradient(material.bump, material.bump_scale, uv[:, 0], uv[:, 1])
        normal = bumped_normals(normal, p_u, p_v, b_u, b_v)
    return rows, cols, count, point, normal, uv, interpolate


@dataclass
class Strip:
    """The detailed pixels as a one-row image of one small face per pixel whose corners all carry that pixel's
    point, normal, UV and colour (module docstring): the arguments a shading kernel takes, and ``write_back``."""

    rows: np.ndarray
    cols: np.ndarray
    depth: np.ndarray
    codes: np.ndarray
    weights: np.ndarray
    faces: np.ndarray
    world: np.ndarray
    normals: np.ndarray
    vertex_colors: np.ndarray
    uvs: np.ndarray
    record: np.ndarray
    color: np.ndarray
    normal_out: np.ndarray
    id_out: np.ndarray

    @classmethod
    def of(cls, item: SceneItem, detail: tuple, depth: np.ndarray, codes: np.ndarray, color: np.ndarray,
           flags: np.ndarray, extra: tuple[np.ndarray, np.ndarray]) -> Strip:  # fmt: skip
        """The strip of `detail` (``detail_pixels``) in these rows of the frame; `flags` the item record."""
        rows, cols, count, point, normal, uv, interpolate = detail
        vertex_colors = getattr(item.mesh, "vertex_colors", None)
        if vertex_colors is None:
            vertex_colors = np.empty((0, 3))
        else:
            vertex_colors = np.repeat(interpolate(np.asarray(vertex_colors[:, :3], dtype=np.float64)), 3, axis=0)
        record = flags.copy()
        record[shade.I_FACE_OFFSET] = 0
        return cls(
            rows, cols, depth[rows, cols].reshape(1, count),
            (2 * np.arange(count, dtype=np.int64) + codes[rows, cols] % 2).reshape(1, count),
            np.full((1, count, 2), 1.0 / 3.0, dtype=np.float32), np.arange(3 * count, dtype=np.int64).reshape(count, 3),
            np.repeat(point, 3, axis=0), np.repeat(normal, 3, axis=0), vertex_colors, np.repeat(uv, 3, axis=0), record,
            color[rows, cols].reshape(1, count, 4).copy(),
            np.zeros((1, count, 3), dtype=np.float32) if flags[shade.I_WRITE_NORMALS] != 0 else extra[0],
            np.zeros((1, count), dtype=np.int32) if flags[shade.I_WRITE_IDS] != 0 else extra[1],
        )  # fmt: skip

    def write_back(self, color: np.ndarray, extra: tuple[np.ndarray, np.ndarray]) -> None:
        """Copy the shaded strip (and the normals and ids it wrote) back into the frame's rows."""
        color[self.rows, self.cols] = self.color[0]
        if self.record[shade.I_WRITE_NORMALS] != 0:
            extra[0][self.rows, self.cols] = self.normal_out[0]
        if self.record[shade.I_WRITE_IDS] != 0:
            extra[1][self.rows, self.cols] = self.id_out[0]


def shade_detailed(
    item: SceneItem, faces: np.ndarray, world: np.ndarray, normals: np.ndarray, params: np.ndarray,
    lights: np.ndarray, flags: np.ndarray, depth: np.ndarray, codes: np.ndarray, bary: np.ndarray,
    color: np.ndarray, extra: tuple[np.ndarray, np.ndarray], seen: np.ndarray | None = None,
) -> None:  # fmt: skip
    """Shade the item's pixels of these image rows with perturbed normals (module docstring); `flags` is the item
    record of ``raster.shade`` (its face offset tells the item's pixels). With `seen` (rows, W, K) float32, the
    fraction of each light reaching each pixel (shadows, ``render.shadows``): ``raster.shadow``'s kernel instead,
    each light's terms scaled by its fraction."""
    detail = detail_pixels(item, faces, world, normals, int(flags[shade.I_FACE_OFFSET]), depth, codes, bary)
    if detail is None:
        return
    strip = Strip.of(item, detail, depth, codes, color, flags, extra)
    texture = item.material.texture
    uvs = strip.uvs
    if texture is None:
        texture, uvs = np.empty((0, 0, 4), dtype=np.float32), np.empty((0, 2))
    if seen is not None:
        from frustum.raster import shadow

        count = detail[2]
        shadow.shade_pixels_shadowed(
            strip.depth, strip.codes, strip.weights, strip.faces, strip.world, strip.normals,
            np.empty((0, 3 + 6 * lights.shape[0])), strip.vertex_colors, uvs, texture, params, lights, strip.record,
            np.ascontiguousarray(seen[strip.rows, strip.cols]).reshape(1, count, -1), strip.color, strip.normal_out,
            strip.id_out,
        )  # fmt: skip
    else:
        shade.shade_pixels(
            strip.depth, strip.codes, strip.weights, strip.faces, strip.world, strip.normals, np.empty((0, 6)),
            strip.vertex_colors, uvs, texture, params, lights, strip.record, strip.color, strip.normal_out,
            strip.id_out,
        )  # fmt: skip
    strip.write_back(color, extra)
