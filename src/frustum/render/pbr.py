"""The metallic–roughness model's place in the surface passes: which items it shades (every item with
``shading="pbr"``; items whose ``Material.model`` is ``"pbr"`` with per-pixel ``shading="phong"``), the kernel's
parameters (``raster.pbr``), and the shading of one item's pixels, with the scene's environment map as image-based
light (``shading.ibl``, precomputed once per map) and, with shadows on, each light's fraction reaching a pixel.

Bump and normal maps perturb the shading normal as in Phong shading (``render.bumps``: the pixels shaded as a strip
of one small face per pixel), and ``Material.emissive_texture`` (sRGB-decoded, times ``emissive``) is the emission.
Not drawn by this model (documented, docs/materials.md): ``Material.reflectivity`` (the environment reflects through
the BRDF instead), and the other shading modes (``"gouraud"`` and ``"flat"`` shade a ``"pbr"`` material with its
classical coefficients)."""

from __future__ import annotations

import weakref

import numpy as np

from frustum.camera import Camera
from frustum.raster import pbr as kernel
from frustum.raster import shade
from frustum.render import bumps
from frustum.render.options import RenderOptions
from frustum.scene import SceneItem
from frustum.shading import Material
from frustum.shading.pbr import phong_roughness

SHADE_PBR = kernel.SHADE_PBR

_NO_MAPS = np.zeros((2, 1, 2, 3), dtype=np.float32)
_NO_SH = np.zeros((9, 3))
_BLENDED: dict[tuple[int, float], tuple[weakref.ref, np.ndarray]] = {}
_SURFACE_MAPS: weakref.WeakKeyDictionary[Material, np.ndarray] = weakref.WeakKeyDictionary()
_EMISSION: weakref.WeakKeyDictionary[Material, np.ndarray] = weakref.WeakKeyDictionary()


def applies(item: SceneItem, options: RenderOptions) -> bool:
    """Whether the item's pixels are shaded by the metallic–roughness model."""
    return options.shade_mode == SHADE_PBR or (
        options.shade_mode == shade.SHADE_PHONG and item.material.model == "pbr"
    )


def tiled(item: SceneItem, options: RenderOptions) -> bool:
    """Whether a frame of this one item may be drawn tile by tile (``raster.pbr_tiled``): shaded by this model,
    opaque, no vertex colours, textures or normal maps it can use, no depth cue, shadows or extra buffers."""
    mesh, material = item.mesh, item.material
    mapped = getattr(mesh, "uvs", None) is not None and any(
        image is not None for image in (material.texture, material.metallic_roughness_texture,
                                        material.occlusion_texture, material.normal_map, material.bump,
                                        material.emissive_texture)
    )  # fmt: skip
    return (
        applies(item, options) and material.opacity >= 1.0 and getattr(mesh, "vertex_colors", None) is None
        and not mapped and options.depth_cue is None and options.shadow is None and not options.buffers
    )  # fmt: skip


def physical_parameters(material: Material, options: RenderOptions, lit_by_environment: bool) -> np.ndarray:
    """(raster.pbr.PBR,) float64: metallic, roughness (a ``"phong"`` material's from its shininess), occlusion
    strength, exposure, tone map code, whether an environment lights the item, the ambient radiance (3)."""
    values = np.zeros(kernel.PBR)
    values[kernel.Q_METALLIC] = material.metallic
    values[kernel.Q_ROUGHNESS] = (
        material.roughness if material.model == "pbr" else phong_roughness(material.shininess)
    )
    values[kernel.Q_OCCLUSION_STRENGTH] = material.occlusion_strength
    values[kernel.Q_EXPOSURE] = options.exposure
    values[kernel.Q_TONE_MAP] = options.tone_map
    values[kernel.Q_ENVIRONMENT] = float(lit_by_environment)
    values[kernel.Q_AMBIENT : kernel.Q_AMBIENT + 3] = options.physical_ambient
    return values


def surface_maps(material: Material) -> np.ndarray:
    """(H, W, 4) float32: the occlusion texture's R in channel 0, the metallic–roughness texture's G (roughness)
    and B (metallic) in channels 1 and 2 (1 where a texture is missing; the occlusion texture resampled to the
    other's size, nearest texel, when they differ); (0, 0, 4) without either. Cached per material."""
    metal_rough, occlusion = material.metallic_roughness_texture, material.occlusion_texture
    if metal_rough is None and occlusion is None:
        return np.empty((0, 0, 4), dtype=np.float32)
    cached = _SURFACE_MAPS.get(material)
    if cached is not None:
        return cached
    shape = (metal_rough if metal_rough is not None else occlusion).shape[:2]
    maps = np.ones((*shape, 4), dtype=np.float32)
    if metal_rough is not None:
        maps[..., 1:3] = metal_rough[..., 1:3]
    if occlusion is not None:
        rows = (np.arange(shape[0]) * occlusion.shape[0]) // shape[0]
        columns = (np.arange(shape[1]) * occlusion.shape[1]) // shape[1]
        maps[..., 0] = occlusion[rows[:, None], columns[None, :], 0]
    maps.setflags(write=False)
    _SURFACE_MAPS[material] = maps
    return maps


def emission_map(material: Material) -> np.ndarray:
    """(H, W, 4) float32: ``Material.emissive_texture`` decoded from sRGB to linear values (alpha kept); (0, 0, 4)
    without one. Cached per material."""
    if material.emissive_texture is None:
        return np.empty((0, 0, 4), dtype=np.float32)
    cached = _EMISSION.get(material)
    if cached is None:
        from frustum.shading.tone import srgb_to_linear

        cached = np.array(material.emissive_texture, dtype=np.float32)
        cached[..., :3] = srgb_to_linear(cached[..., :3])
        cached.setflags(write=False)
        _EMISSION[material] = cached
    return cached


def image_light(options: RenderOptions) -> tuple[np.ndarray, np.ndarray, np.ndarray, bool]:
    """(sh, prefiltered maps, split-sum table, whether there is an environment) for the kernel."""
    from frustum.shading.ibl import brdf_table, image_lighting

    if options.environment is None:
        return _NO_SH, _NO_MAPS, brdf_table(), False
    lighting = image_lighting(options.environment)
    return lighting.sh, lighting.prefiltered, lighting.table, True


def blended_level(maps: np.ndarray, roughness: float) -> np.ndarray:
    """(1, H, 2H, 3) float32: the two prefiltered maps around $roughness·(levels − 1)$ blended as
    ``raster.pbr.prefiltered`` blends its two lookups (a lerp of bilinear lookups is the bilinear lookup of the
    lerp, to rounding), for an item of one roughness: one lookup per pixel instead of two. Cached per map."""
    key = (id(maps), float(roughness))
    cached = _BLENDED.get(key)
    if cached is not None and cached[0]() is maps:
        return cached[1]
    top = maps.shape[0] - 1
    level = min(max(float(roughness), 0.0), 1.0) * top
    low = min(int(np.floor(level)), top - 1)
    t = level - low
    blended = ((1.0 - t) * maps[low].astype(np.float64) + t * maps[low + 1]).astype(np.float32)[None]
    if len(_BLENDED) > 16:
        _BLENDED.clear()
    _BLENDED[key] = (weakref.ref(maps), blended)
    return blended


def shade_item(
    item: SceneItem, index: int, face_offset: int, camera: Camera, options: RenderOptions, params: np.ndarray,
    lights: np.ndarray, attributes: tuple[np.ndarray, np.ndarray], faces: np.ndarray, rows: tuple,
    blend: bool, flags: np.ndarray, seen: np.ndarray | None = None,
) -> None:  # fmt: skip
    """Shade the item's pixels in `rows` ((depth, codes, bary, color, normal_out, id_out) of its band) with the
    metallic–roughness model (``raster.pbr.shade_pixels_pbr``); `seen` the (band, W, K) light fractions of the
    shadow pass, or None. With a bump or normal map its mesh can use, the pixels go as ``render.bumps``' strip
    with the perturbed normals."""
    mesh, material = item.mesh, item.material
    world, normals = (np.asarray(a, dtype=np.float64) for a in attributes)
    vertex_colors = getattr(mesh, "vertex_colors", None)
    vertex_colors = np.empty((0, 3)) if vertex_colors is None else np.ascontiguousarray(vertex_colors[:, :3], float)
    uvs = getattr(mesh, "uvs", None)
    texture, maps_of_surface, emission = material.texture, surface_maps(material), emission_map(material)
    if uvs is None:
        texture, uvs = None, np.empty((0, 2))
        maps_of_surface, emission = np.empty((0, 0, 4), dtype=np.float32), np.empty((0, 0, 4), dtype=np.float32)
    else:
        uvs = np.ascontiguousarray(uvs, dtype=np.float64)
    if texture is None:
        texture = np.empty((0, 0, 4), dtype=np.float32)
    sh, maps, table, lit = image_light(options)
    values = physical_parameters(material, options, lit)
    depth, codes, bary, color, normal_out, id_out = rows
    fractions = np.empty((0, 0, 0), dtype=np.float32) if seen is None else np.ascontiguousarray(seen, np.float32)
    if bumps.has_detail(item):  # per-pixel normals from the maps: a strip of one face per pixel
        detail = bumps.detail_pixels(item, faces, world, normals, face_offset, depth, codes, bary)
        if detail is None:
            return
        strip = bumps.Strip.of(item, detail, depth, codes, color, flags, (normal_out, id_out))
        if seen is not None:
            fractions = np.ascontiguousarray(fractions[strip.rows, strip.cols]).reshape(1, detail[2], -1)
        kernel.shade_pixels_pbr(strip.depth, strip.codes, strip.weights, strip.faces, strip.world, strip.normals,
                                strip.vertex_colors, strip.uvs, texture, maps_of_surface, emission, params, values,
                                lights, sh, maps, table, fractions, strip.record, strip.color, strip.normal_out,
                                strip.id_out)  # fmt: skip
        strip.write_back(color, (normal_out, id_out))
        return
    kernel.shade_pixels_pbr(depth, codes, bary, faces, world, normals, vertex_colors, uvs, texture, maps_of_surface,
                            emission, params, values, lights, sh, maps, table, fractions, flags, color, normal_out,
                            id_out)  # fmt: skip
