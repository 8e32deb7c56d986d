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


def shade_detailed(
    item: SceneItem, faces: np.ndarray, world: np.ndarray, normals: np.ndarray, params: np.ndarray,
    lights: np.ndarray, flags: np.ndarray, depth: np.ndarray, codes: np.ndarray, bary: np.ndarray,
    color: np.ndarray, extra: tuple[np.ndarray, np.ndarray], seen: np.ndarray | None = None,
) -> None:  # fmt: skip
    """Shade the item's pixels of these image rows with perturbed normals (module docstring); `flags` is the item
    record of ``raster.shade`` (its face offset tells the item's pixels). With `seen` (rows, W, K) float32, the
    fraction of each light reaching each pixel (shadows, ``render.shadows``): ``raster.shadow``'s kernel instead,
    each light's terms scaled by its fraction."""
    mesh, material = item.mesh, item.material
    face_offset = int(flags[shade.I_FACE_OFFSET])
    face = codes.astype(np.int64) // 2 - face_offset
    rows, cols = np.nonzero((depth < 1.0) & (face >= 0) & (face < faces.shape[0]))
    count = rows.size
    if count == 0:
        return
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
    # one face per pixel, its three corners alike: the kernel's interpolation gives back the pixel's values
    virtual_faces = np.arange(3 * count, dtype=np.int64).reshape(count, 3)
    vertex_colors = getattr(mesh, "vertex_colors", None)
    if vertex_colors is None:
        vertex_colors = np.empty((0, 3))
    else:
        vertex_colors = np.repeat(interpolate(np.asarray(vertex_colors[:, :3], dtype=np.float64)), 3, axis=0)
    texture = material.texture
    if texture is None:
        texture, virtual_uvs = np.empty((0, 0, 4), dtype=np.float32), np.empty((0, 2))
    else:
        virtual_uvs = np.repeat(uv, 3, axis=0)
    virtual_codes = (2 * np.arange(count, dtype=np.int64) + codes[rows, cols] % 2).reshape(1, count)
    weights = np.full((1, count, 2), 1.0 / 3.0, dtype=np.float32)
    strip = color[rows, cols].reshape(1, count, 4).copy()
    write_normals = flags[shade.I_WRITE_NORMALS] != 0
    write_ids = flags[shade.I_WRITE_IDS] != 0
    normal_strip = np.zeros((1, count, 3), dtype=np.float32) if write_normals else extra[0]
    id_strip = np.zeros((1, count), dtype=np.int32) if write_ids else extra[1]
    record = flags.copy()
    record[shade.I_FACE_OFFSET] = 0
    if seen is not None:
        from frustum.raster import shadow

        shadow.shade_pixels_shadowed(
            depth[rows, cols].reshape(1, count), virtual_codes, weights, virtual_faces, np.repeat(point, 3, axis=0),
            np.repeat(normal, 3, axis=0), np.empty((0, 3 + 6 * lights.shape[0])), vertex_colors, virtual_uvs,
            texture, params, lights, record, np.ascontiguousarray(seen[rows, cols]).reshape(1, count, -1), strip,
            normal_strip, id_strip,
        )  # fmt: skip
    else:
        _shade_plainly(depth, rows, cols, count, virtual_codes, weights, virtual_faces, point, normal,
                       vertex_colors, virtual_uvs, texture, params, lights, record, strip, normal_strip, id_strip)
    color[rows, cols] = strip[0]
    if write_normals:
        extra[0][rows, cols] = normal_strip[0]
    if write_ids:
        extra[1][rows, cols] = id_strip[0]


def _shade_plainly(
    depth: np.ndarray, rows: np.ndarray, cols: np.ndarray, count: int, virtual_codes: np.ndarray,
    weights: np.ndarray, virtual_faces: np.ndarray, point: np.ndarray, normal: np.ndarray,
    vertex_colors: np.ndarray, virtual_uvs: np.ndarray, texture: np.ndarray, params: np.ndarray,
    lights: np.ndarray, record: np.ndarray, strip: np.ndarray, normal_strip: np.ndarray, id_strip: np.ndarray,
) -> None:  # fmt: skip
    """The strip of ``shade_detailed`` through ``raster.shade.shade_pixels`` (no shadows)."""
    shade.shade_pixels(
        depth[rows, cols].reshape(1, count), virtual_codes, weights, virtual_faces, np.repeat(point, 3, axis=0),
        np.repeat(normal, 3, axis=0), np.empty((0, 6)), vertex_colors, virtual_uvs, texture, params, lights, record,
        strip, normal_strip, id_strip,
    )  # fmt: skip
