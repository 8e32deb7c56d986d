"""Whitted ray tracing: ``render(..., method="ray-tracing")`` and the rays of one pixel (``ray_path``).

From the eye through the centre of each pixel a primary ray goes from the near plane toward the far plane (the
view volume, as ``method="ray-casting"``: back faces skipped when culling); at the nearest surface it meets
[HB 21 "Ray-Tracing Methods": basic ray-tracing algorithm, reflection and refraction]:

* the local color ``I_local`` is the illumination formula of ``frustum.shading`` (the one the depth buffer
  evaluates per pixel with ``shading="phong"``: interpolated vertex normal, flipped toward the ray on a back
  face; base color = material color × vertex color; the same ambient, diffuse and specular terms, Blinn-Phong or
  Phong), where each positioned light's diffuse and specular terms are multiplied by its visibility: a shadow ray
  from the point toward the light (to a point or spot light's position, or along a directional light's to-light
  direction without end) blocked by any surface, when shadows are on (``shadows`` None or True) and the light
  has ``cast_shadows``. Shadow rays are cast only where $N·L > 0$ (elsewhere the light adds nothing anyway).
  Every surface blocks light, transparent ones included;
* a **reflected** ray $R = I + 2(N·(−I))N$ when ``Material.reflectivity`` k_r > 0;
* a **refracted** ray when ``Material.opacity`` α < 1, bent by Snell's law $η₁ sin θ₁ = η₂ sin θ₂$ with
  $η = 1/ior$ entering a surface from its front and ``ior`` leaving through its back (the outside is air:
  index 1; media are not nested), $T = ηI + (η cos θ₁ − √(1 − η²(1 − cos² θ₁)))N$. Beyond the critical angle
  ($η² sin² θ₁ > 1$) the light is **totally reflected**: the transmitted weight goes to the reflected ray.

The contributions are weighted without a Fresnel term (the default and only weighting; the textbook's
$I = I_local + k_r·I_r + k_t·I_t$ with the local part scaled so that weights sum to one):

$$I = (1 − k_r)·(α·I_local + (1 − α)·I_t) + k_r·I_r$$

so that an opaque matte surface ($k_r = 0$, $α = 1$) gives the depth buffer's color, a perfect mirror ($k_r = 1$)
only what it reflects, and a transparent surface of $ior = 1$ the depth buffer's blend $α·I + (1 − α)·behind$.
Rays that leave the scene see the ``background`` color, or the scene's environment map (``Scene(environment=)``)
along their direction for reflected and refracted rays (primary rays that miss show it as the depth buffer
does). After ``max_depth`` levels of reflected and refracted rays no more are spawned (their share of the color
is black), and rays whose weight is below ``MIN_WEIGHT`` are not traced. The normal used to reflect and refract
is the interpolated (shading) normal; rays start $ε$ (1e-9 of the scene's size) off the surface along the
geometric normal, on the side they leave to, so that they do not meet it again.

An item the metallic–roughness model shades (``render(shading="pbr")``, or a ``Material(model="pbr")``:
``frustum.render.pbr.applies``) gets that model's local color instead: the same BRDF, light units and
image-based light as the depth buffer's (``frustum.shading.pbr``, ``frustum.shading.ibl``, NumPy here), each
positioned light's term multiplied by its shadow ray's visibility; a rough metal thus reflects the environment's
prefiltered light. A smooth one (roughness 0, metal or not) reflects the scene itself: its image-based specular
term is replaced by a traced **mirror ray** along R, weighted by Schlick's Fresnel colour
$F = F_0 + (1 − F_0)(1 − n·v)⁵$, $F_0 = mix(0.04, base, metallic)$ (a metal's base colour), traced recursively
like the Whitted mirrors of ``Material.reflectivity``; where it leaves the scene it sees the surroundings that
image-based lighting uses (the ambient radiance plus the environment map along R). The light of these items is
summed as linear radiance over the pixel's rays and goes through exposure and the tone map once, at the end.

The depth buffer receives the window depth of each primary hit, so volumes and particles are composited along
the primary rays exactly as with ``method="ray-casting"``; ``buffers=("normals", "object_id")`` show the primary
hit's. Surface textures are not sampled by this method (the base color is the material's and the vertex
colors'). Every ray goes through the scene's ray index (``Scene.intersect``, ``Scene.occluded``:
``raster.rays``); the shading is vectorized NumPy over the rays of one level, so no kernel beyond the index's
two is compiled.

References
----------
[HB 21] "Ray-Tracing Methods": "Basic Ray-Tracing Algorithm", "Ray-Surface Intersection Calculations",
"Reflection and Refraction" (Snell's law, total internal reflection); T. Whitted, "An Improved Illumination
Model for Shaded Display", CACM 23(6), 1980.
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from frustum.budgets import check_operations
from frustum.camera import Camera
from frustum.errors import FrustumError
from frustum.render.context import FrameContext
from frustum.render.options import RenderOptions
from frustum.scene import Scene
from frustum.shading import AmbientLight, DirectionalLight, SpotLight, pack_lights
from frustum.shading.light import specular_terms, toward_light

__all__ = ["MIN_WEIGHT", "RaySegment", "draw_surfaces", "ray_path"]

MIN_WEIGHT = 1.0 / 1024.0
"""Reflected and refracted rays whose share of a pixel's color is below this are not traced (< 1/4 of a level)."""
CHUNK = 1 << 17
"""Primary rays traced together (memory: about 2 KiB per ray of work arrays)."""
COST_PER_RAY = 64
"""Operations counted per ray against the work budget (a ray through the index: some tens of box and triangle
tests)."""


class RaySegment(NamedTuple):
    """One ray of a pixel's tree (``ray_path``).

    ``kind``: "primary", "reflected", "refracted" or "shadow"; ``depth``: 0 for the primary ray and its shadow
    rays, +1 per reflection or refraction; ``parent``: the index in the path of the ray whose hit spawned it (−1
    for the primary ray); ``origin``, ``direction`` (unit for reflected and refracted rays; the primary ray's runs
    from the near to the far plane over t in [0, 1); a shadow ray's to a point light ends at t = 1);
    ``t`` the hit's distance (inf: none; a shadow ray: where it is blocked); ``item`` (index into ``Scene.items``)
    and ``face`` of the hit (−1); ``point`` and ``normal`` (the interpolated unit normal turned toward the ray) of
    the hit (NaN without one); ``weight`` the ray's share of the pixel's color; ``light`` (shadow rays: the index
    of the light in ``Scene.world_lights()``, else −1); ``blocked`` (shadow rays: whether a surface hides the
    light); ``total_internal_reflection``: a reflected ray that also carries the refracted share."""

    kind: str
    depth: int
    parent: int
    origin: NDArray[np.float64]
    direction: NDArray[np.float64]
    t: float
    item: int
    face: int
    point: NDArray[np.float64]
    normal: NDArray[np.float64]
    weight: float
    light: int = -1
    blocked: bool = False
    total_internal_reflection: bool = False


class _Scene:
    """What the tracer reads of a scene, gathered once: the ray index, per-item material arrays, world vertex
    normals and colors with faces in global vertex numbers, and the lights."""

    def __init__(self, scene: Scene, specular_phong: bool, shadows: bool, options: RenderOptions | None = None) -> None:
        found = scene._triangle_index(where="render")
        self.options = options
        self.empty = found is None
        self.lights = scene.world_lights()
        self.ambient, _ = pack_lights(self.lights)
        self.positioned = [(i, light) for i, light in enumerate(self.lights) if not isinstance(light, AmbientLight)]
        self.shadows = shadows
        self.specular_phong = specular_phong
        if found is None:
            return
        items, self.index, self.starts = found
        self.numbers, self.swapped = scene._pick_index[4], scene._pick_index[5]
        materials = [item.material for item in items]
        self.color = np.array([m.color for m in materials], dtype=np.float64)
        self.emissive = np.array([m.emissive for m in materials], dtype=np.float64)
        self.k = np.array([[m.ambient, m.diffuse, m.specular, m.shininess] for m in materials], dtype=np.float64)
        self.reflectivity = np.array([m.reflectivity for m in materials], dtype=np.float64)
        self.opacity = np.array([m.opacity for m in materials], dtype=np.float64)
        self.ior = np.array([m.ior for m in materials], dtype=np.float64)
        self.physical = np.zeros(len(materials), dtype=bool)
        self.mirror = self.physical
        if options is not None:  # the metallic–roughness model for the items it shades (render.pbr.applies)
            from frustum.render.pbr import applies
            from frustum.shading.pbr import phong_roughness

            self.physical = np.array([applies(item, options) for item in items], dtype=bool)
            self.metallic = np.array([m.metallic for m in materials], dtype=np.float64)
            self.roughness = np.array([m.roughness if m.model == "pbr" else phong_roughness(m.shininess)
                                       for m in materials], dtype=np.float64)  # fmt: skip
            self.mirror = self.physical & (self.roughness == 0.0)  # smooth: a traced mirror ray (_mirror_rays)
        normals, faces, colors, offset = [], [], [], 0
        any_colors = any(item.mesh.vertex_colors is not None for item in items)
        for item in items:
            mesh = item.mesh
            matrix = np.asarray(item.world_from_model, dtype=np.float64)
            normal_matrix = np.linalg.inv(matrix[:3, :3]).T
            n = mesh.vertex_normals @ normal_matrix.T
            n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)
            normals.append(n)
            faces.append(mesh.faces.astype(np.int64) + offset)
            if any_colors:
                vc = mesh.vertex_colors
                colors.append(np.ones((mesh.vertex_count, 3)) if vc is None else np.asarray(vc)[:, :3])
            offset += mesh.vertex_count
        self.normals = np.concatenate(normals)
        self.faces = np.concatenate(faces)
        self.vertex_colors = np.concatenate(colors) if any_colors else None
        corners = self.index.triangles.reshape(-1, 3)
        size = float(np.max(corners.max(axis=0) - corners.min(axis=0))) if corners.size else 1.0
        self.epsilon = 1e-9 * max(size, float(np.abs(corners).max()), 1e-300)

    def shadow_lights(self) -> int:
        return sum(1 for _, light in self.positioned if self.shadows and light.cast_shadows)


class _Hits(NamedTuple):
    rows: NDArray[np.int64]  # which rays hit
    t: NDArray[np.float64]
    item: NDArray[np.int64]  # index into the items with faces
    face: NDArray[np.int64]  # face in the item's mesh
    point: NDArray[np.float64]
    incoming: NDArray[np.float64]  # unit ray direction
    normal: NDArray[np.float64]  # interpolated, toward the incoming side
    geometric: NDArray[np.float64]  # geometric, toward the incoming side
    back: NDArray[np.bool_]
    base: NDArray[np.float64]  # vertex color (ones without vertex colors)


def _hits(data: _Scene, origins: np.ndarray, directions: np.ndarray, t_max: float, cull: bool) -> _Hits:
    from frustum.raster import rays

    found = rays.closest_hits(data.index, origins, directions, 0.0, t_max, None, cull)
    rows = np.flatnonzero(found.face >= 0)
    face_global = found.face[rows]
    k = np.searchsorted(data.starts, face_global, side="right") - 1
    t = found.t[rows]
    d = directions[rows]
    point = origins[rows] + t[:, None] * d
    incoming = d / np.linalg.norm(d, axis=1, keepdims=True)
    tri = data.index.triangles[found.row[rows]]
    geometric = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    geometric /= np.maximum(np.linalg.norm(geometric, axis=1, keepdims=True), 1e-300)
    u, v = found.uv[rows, 0], found.uv[rows, 1]
    flip = data.swapped[k]
    weights = np.stack([1.0 - u - v, np.where(flip, v, u), np.where(flip, u, v)], axis=1)
    corners = data.faces[face_global]
    normal = np.einsum("nc,nci->ni", weights, data.normals[corners])
    length = np.linalg.norm(normal, axis=1, keepdims=True)
    normal = np.where(length > 0.0, normal / np.where(length > 0.0, length, 1.0), geometric)
    back = found.back[rows] != 0
    side = np.where(back, -1.0, 1.0)[:, None]
    base = np.ones((rows.shape[0], 3)) if data.vertex_colors is None else np.einsum(
        "nc,nci->ni", weights, data.vertex_colors[corners])  # fmt: skip
    return _Hits(rows, t, k, face_global - data.starts[k], point, incoming, normal * side, geometric * side, back,
                 base)  # fmt: skip


def _local(data: _Scene, hit: _Hits, counts: dict, record: list | None, parents: np.ndarray | None,
           depth: int) -> np.ndarray:  # fmt: skip
    """I_local (n, 3) at the hits, with shadow rays (module docstring): display values, except at the hits the
    metallic–roughness model shades (``data.physical``), where it is linear radiance (``_physical_radiance``)."""
    from frustum.raster import rays

    k = hit.item
    base = data.color[k] * hit.base
    ka, kd, ks, shininess = data.k[k, 0], data.k[k, 1], data.k[k, 2], data.k[k, 3]
    diffuse_sum = ka[:, None] * data.ambient[None, :]
    specular_sum = np.zeros_like(diffuse_sum)
    n = hit.normal
    view = -hit.incoming
    physical = data.physical[k]
    direct = np.zeros((int(physical.sum()), 3))  # the metallic–roughness model's direct light (shading.pbr)
    for number, light in data.positioned:
        intensity = np.asarray(light.color, dtype=np.float64) * light.intensity
        to_light, falloff = toward_light(light, hit.point)  # the light model's attenuation and spot cone
        cosine = np.einsum("ij,ij->i", n, to_light)
        ndl = np.maximum(cosine, 0.0)
        lit = ndl > 0.0
        if data.shadows and light.cast_shadows and lit.any():
            chosen = np.flatnonzero(lit)
            origins = hit.point[chosen] + data.epsilon * hit.geometric[chosen]
            if isinstance(light, DirectionalLight):
                directions, t_max = np.ascontiguousarray(to_light[chosen]), np.inf
            else:
                directions, t_max = np.asarray(light.position, dtype=np.float64) - origins, 1.0
            blocked = rays.any_hits(data.index, origins, directions, 0.0, t_max)
            counts["shadow_rays"] = counts.get("shadow_rays", 0) + int(chosen.shape[0])
            lit[chosen[blocked]] = False
            if record is not None and parents is not None:
                for j, row in enumerate(chosen):
                    record.append(RaySegment(
                        "shadow", depth, int(parents[row]), origins[j], directions[j], np.inf, -1, -1,
                        np.full(3, np.nan), np.full(3, np.nan), 0.0, number, bool(blocked[j]),
                    ))  # fmt: skip
        spec = specular_terms(to_light, cosine, n, view, shininess, data.specular_phong, lit)  # where lit, unshadowed
        shade = np.where(lit, falloff * ndl, 0.0)
        diffuse_sum = diffuse_sum + (kd * shade)[:, None] * intensity
        specular_sum = specular_sum + (ks * falloff * spec)[:, None] * intensity
        if direct.shape[0]:
            direct += _physical_light(data, light, hit, physical, base, to_light, lit) * intensity
    color = np.clip(base * diffuse_sum + specular_sum + data.emissive[k], 0.0, 1.0)
    if direct.shape[0]:
        color[physical] = _physical_radiance(data, hit, physical, base, direct)
    return color


def _physical_light(data: _Scene, light: Any, hit: _Hits, physical: np.ndarray, base: np.ndarray,
                    to_light: np.ndarray, lit: np.ndarray) -> np.ndarray:  # fmt: skip
    """$f(l, v)·E·(n·l)$ per unit light intensity at the physical hits (``shading.pbr``: lux, or candela over d²
    with the range window and the squared spot cone), 0 where the light is hidden."""
    from frustum.shading import pbr

    k = hit.item[physical]
    point, n, l = hit.point[physical], hit.normal[physical], np.asarray(to_light)[physical]  # noqa: E741
    illuminance = np.ones(point.shape[0])
    if not isinstance(light, DirectionalLight):
        offset = np.asarray(light.position, dtype=np.float64) - point
        d2 = np.einsum("ij,ij->i", offset, offset)
        illuminance = pbr.range_window(np.sqrt(d2), light.range or 0.0) / np.maximum(d2, 1e-300)
        if isinstance(light, SpotLight):
            cos_alpha = -(l @ np.asarray(light.direction, dtype=np.float64))
            illuminance *= pbr.spot_cone(cos_alpha, math.cos(light.inner_angle), math.cos(light.outer_angle))
    f = pbr.brdf(n, l, -hit.incoming[physical], base[physical], data.metallic[k], data.roughness[k])
    cosine = np.maximum(np.einsum("ij,ij->i", n, l), 0.0)
    return f * np.where(lit[physical], illuminance * cosine, 0.0)[:, None]


def _physical_radiance(data: _Scene, hit: _Hits, physical: np.ndarray, base: np.ndarray,
                       direct: np.ndarray) -> np.ndarray:  # fmt: skip
    """The physical hits' linear radiance: direct light, image-based and ambient light (``shading.ibl``; at a
    smooth hit without its specular term, which the mirror ray brings: ``_mirror_rays``) and emission."""
    from frustum.render.pbr import image_light
    from frustum.shading.ibl import ImageLighting, image_radiance

    options = data.options
    k = hit.item[physical]
    sh, maps, table, lit = image_light(options)
    lighting = ImageLighting(sh, maps, table) if lit else None
    indirect = np.empty_like(direct)
    for smooth in (False, True):
        rows = data.mirror[k] == smooth
        indirect[rows] = image_radiance(lighting, options.physical_ambient, hit.normal[physical][rows],
                                        -hit.incoming[physical][rows], base[physical][rows], data.metallic[k][rows],
                                        data.roughness[k][rows], specular=not smooth)  # fmt: skip
    return direct + indirect + data.emissive[k]


def _display(data: _Scene, radiance: np.ndarray) -> np.ndarray:
    """Display values of linear radiance: the render's exposure and tone map (``shading.tone``)."""
    from frustum.shading.tone import TONE_MAPS, tone_map

    options = data.options
    name = {code: name for name, code in TONE_MAPS.items()}[options.tone_map]
    return tone_map(radiance, name, options.exposure)


def _mirror_rays(data: _Scene, hit: _Hits, local_weight: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(rows, weights (m, 3)) of the mirror rays of the smooth physical hits: $F = F_0 + (1 − F_0)(1 − n·v)^5$
    (Schlick, ``shading.pbr.fresnel_schlick``), $F_0 = mix(0.04, base, metallic)$, times the hit's own weight."""
    from frustum.shading.pbr import DIELECTRIC_F0, fresnel_schlick

    if not data.mirror.any():
        return np.empty(0, dtype=np.int64), np.empty((0, 3))
    rows = np.flatnonzero(data.mirror[hit.item] & (local_weight.max(axis=1) > 0.0))
    k = hit.item[rows]
    metallic = data.metallic[k][:, None]
    f0 = (1.0 - metallic) * DIELECTRIC_F0 + metallic * data.color[k] * hit.base[rows]
    n_dot_v = np.clip(-np.einsum("ij,ij->i", hit.normal[rows], hit.incoming[rows]), 0.0, 1.0)
    return rows, local_weight[rows] * fresnel_schlick(f0, n_dot_v[:, None])


def _primary(camera: Camera, rows: np.ndarray, width: int, height: int) -> tuple[np.ndarray, np.ndarray]:
    """Origins on the near plane and directions to the far plane of the pixels `rows` (numbered j·W + i, y up),
    as ``raster.rays.cast_pixels`` casts them."""
    m = np.asarray(camera.world_from_window, dtype=np.float64)
    x = (rows % width) + 0.5
    y = (rows // width) + 0.5
    nw = m[3, 0] * x + m[3, 1] * y + m[3, 3]
    origin = np.stack([(m[a, 0] * x + m[a, 1] * y + m[a, 3]) / nw for a in range(3)], axis=1)
    fw = nw + m[3, 2]
    end = np.stack([(m[a, 0] * x + m[a, 1] * y + m[a, 2] + m[a, 3]) / fw for a in range(3)], axis=1)
    return origin, end - origin


def _trace(data: _Scene, origins: np.ndarray, directions: np.ndarray, pixel: np.ndarray, count: int,
           max_depth: int, cull: bool, background: np.ndarray, counts: dict, window_from_world: np.ndarray | None,
           record: list | None = None, environment: Any = None,
           ) -> tuple[np.ndarray, _Hits | None, np.ndarray]:  # fmt: skip
    """The color (count, 3) of rays `origins`, `directions` (primary rays over t in [0, 1)) belonging to pixels
    `pixel` (0 … count − 1); the primary hits and their window depths (None: not computed). Each ray carries an
    RGB weight (a smooth physical surface's mirror ray: its Fresnel colour); the light of physically shaded hits
    is summed as radiance and goes through the exposure and tone map once per pixel, at the end."""
    color = np.zeros((count, 3))
    radiance = np.zeros((count, 3))
    weight = np.ones((origins.shape[0], 3))
    kinds = np.zeros(origins.shape[0], dtype=np.int8)  # 0 primary, 1 reflected, 2 refracted
    tir = np.zeros(origins.shape[0], dtype=bool)
    physical_ray = np.zeros(origins.shape[0], dtype=bool)  # a mirror ray of a smooth physical surface
    parents = np.full(origins.shape[0], -1, dtype=np.int64)
    primary: _Hits | None = None
    z = np.empty(0, dtype=np.float32)
    for depth in range(max_depth + 1):
        if origins.shape[0] == 0:
            break
        counts["depth_reached"] = max(counts.get("depth_reached", 0), depth)
        for kind, name in enumerate(("primary", "reflected", "refracted")):
            counts[f"{name}_rays"] = counts.get(f"{name}_rays", 0) + int((kinds == kind).sum())
        if data.empty:
            hit = _Hits(*(np.empty(0, dtype=np.int64),) * 10)  # type: ignore[arg-type]
        else:
            hit = _hits(data, origins, directions, 1.0 if depth == 0 else np.inf, cull and depth == 0)
        if depth == 0 and window_from_world is not None and hit.rows.shape[0]:
            w = window_from_world
            p = hit.point
            zz = ((p @ w[2, :3] + w[2, 3]) / (p @ w[3, :3] + w[3, 3])).astype(np.float32)
            near = zz < 1.0  # as the depth buffer: a depth that rounds to 1 is not drawn
            if not near.all():
                hit = _Hits(*(field[np.flatnonzero(near)] for field in hit))
                zz = zz[near]
            z = zz
        if depth == 0:
            primary = hit
        rows = hit.rows
        counts["hits"] = counts.get("hits", 0) + int(rows.shape[0])
        missed = np.ones(origins.shape[0], dtype=bool)
        missed[rows] = False
        for physical in (False, True):
            _add_missed(data, color if not physical else radiance, pixel, weight, directions,
                        missed & (physical_ray == physical), environment, background, depth, physical)  # fmt: skip
        segment_index = None
        if record is not None:
            segment_index = _record_rays(record, data, hit, origins, directions, kinds, depth, parents, weight, tir)
        if rows.shape[0] == 0:
            break
        k = hit.item
        w = weight[rows]
        kr = data.reflectivity[k]
        alpha = data.opacity[k]
        local_weight = w * ((1.0 - kr) * alpha)[:, None]
        shaded = local_weight.max(axis=1) > 0.0
        if shaded.any():
            sub = _Hits(*(field[shaded] for field in hit))
            hit_parents = None if segment_index is None else segment_index[sub.rows]
            local = local_weight[shaded] * _local(data, sub, counts, record, hit_parents, depth)
            linear = data.physical[sub.item]
            np.add.at(color, pixel[sub.rows[~linear]], local[~linear])
            np.add.at(radiance, pixel[sub.rows[linear]], local[linear])
        if depth == max_depth:
            break
        reflect_weight = w * kr[:, None]
        refract_weight = w * ((1.0 - kr) * (1.0 - alpha))[:, None]
        n = hit.normal
        incoming = hit.incoming
        cos_i = np.clip(-np.einsum("ij,ij->i", n, incoming), 0.0, 1.0)
        eta = np.where(hit.back, data.ior[k], 1.0 / data.ior[k])
        sin2 = eta * eta * (1.0 - cos_i * cos_i)
        total = (refract_weight.max(axis=1) > 0.0) & (sin2 > 1.0)
        counts["total_internal_reflections"] = counts.get("total_internal_reflections", 0) + int(total.sum())
        reflect_weight = reflect_weight + np.where(total[:, None], refract_weight, 0.0)
        refract_weight = np.where(total[:, None], 0.0, refract_weight)
        reflected = incoming + 2.0 * cos_i[:, None] * n
        cos_t = np.sqrt(np.maximum(1.0 - sin2, 0.0))
        refracted = eta[:, None] * incoming + (eta * cos_i - cos_t)[:, None] * n
        go_r = np.flatnonzero(reflect_weight.max(axis=1) >= MIN_WEIGHT)
        go_t = np.flatnonzero(refract_weight.max(axis=1) >= MIN_WEIGHT)
        go_m, mirror_weight = _mirror_rays(data, hit, local_weight)
        strong = mirror_weight.max(axis=1) >= MIN_WEIGHT
        go_m, mirror_weight = go_m[strong], mirror_weight[strong]
        offset = data.epsilon * hit.geometric
        origins = np.concatenate([hit.point[go_r] + offset[go_r], hit.point[go_t] - offset[go_t],
                                  hit.point[go_m] + offset[go_m]])  # fmt: skip
        directions = np.concatenate([reflected[go_r], refracted[go_t], reflected[go_m]])
        pixel = np.concatenate([pixel[rows[go_r]], pixel[rows[go_t]], pixel[rows[go_m]]])
        weight = np.concatenate([reflect_weight[go_r], refract_weight[go_t], mirror_weight])
        kinds = np.concatenate([np.ones(go_r.shape[0], np.int8), np.full(go_t.shape[0], 2, np.int8),
                                np.ones(go_m.shape[0], np.int8)])  # fmt: skip
        tir = np.concatenate([total[go_r], np.zeros(go_t.shape[0] + go_m.shape[0], dtype=bool)])
        physical_ray = np.arange(origins.shape[0]) >= go_r.shape[0] + go_t.shape[0]
        parents = np.empty(0, dtype=np.int64) if segment_index is None else np.concatenate(
            [segment_index[rows[go_r]], segment_index[rows[go_t]], segment_index[rows[go_m]]])  # fmt: skip
        if parents.shape[0] != origins.shape[0]:
            parents = np.full(origins.shape[0], -1, dtype=np.int64)
    if radiance.any():
        color += _display(data, radiance)
    return color, primary, z


def _record_rays(record: list, data: _Scene, hit: _Hits, origins: np.ndarray, directions: np.ndarray,
                 kinds: np.ndarray, depth: int, parents: np.ndarray, weight: np.ndarray, tir: np.ndarray,
                 ) -> np.ndarray:  # fmt: skip
    """A ``RaySegment`` per ray of one level appended to `record` (``ray_path``); their indices in it."""
    names = ("primary", "reflected", "refracted")
    segment_index = np.empty(origins.shape[0], dtype=np.int64)
    for r in range(origins.shape[0]):
        segment_index[r] = len(record)
        found = np.flatnonzero(hit.rows == r)
        j = int(found[0]) if found.size else -1
        record.append(RaySegment(
            names[kinds[r]], depth, int(parents[r]), origins[r], directions[r],
            float(hit.t[j]) if j >= 0 else np.inf, int(data.numbers[hit.item[j]]) if j >= 0 else -1,
            int(hit.face[j]) if j >= 0 else -1, hit.point[j] if j >= 0 else np.full(3, np.nan),
            hit.normal[j] if j >= 0 else np.full(3, np.nan), float(weight[r].max()),
            total_internal_reflection=bool(tir[r]),
        ))  # fmt: skip
    return segment_index


def _add_missed(data: _Scene, out: np.ndarray, pixel: np.ndarray, weight: np.ndarray, directions: np.ndarray,
                missed: np.ndarray, environment: Any, background: np.ndarray, depth: int, physical: bool,
                ) -> None:  # fmt: skip
    """What the rays `missed` see, times their weights, into their pixels of `out`: the background, or the
    environment map for reflected and refracted rays; for `physical` rays (a smooth physical surface's mirror
    rays) the radiance of the surroundings that image-based lighting uses (``shading.ibl``: the uniform ambient
    plus the map), into the radiance sum."""
    if not missed.any():
        return
    if physical:
        seen = np.broadcast_to(np.asarray(data.options.physical_ambient, dtype=np.float64), (int(missed.sum()), 3))
        if environment is not None:
            seen = seen + environment.lookup(directions[missed])
        np.add.at(out, pixel[missed], weight[missed] * seen)
    elif environment is not None and depth > 0:
        np.add.at(out, pixel[missed], weight[missed] * environment.lookup(directions[missed]))
    else:
        np.add.at(out, pixel[missed], weight[missed] * background[None, :3])


def _check_work(camera: Camera, data: _Scene, max_depth: int, where: str) -> None:
    """The work budget: rays (pixels × (max_depth + 1) levels × (1 + shadowing lights)) × COST_PER_RAY."""
    pixels = camera.width * camera.height
    rays_count = pixels * (max_depth + 1) * (1 + data.shadow_lights())
    check_operations(rays_count * COST_PER_RAY, where=where, error=FrustumError,
                     cause=f"ray tracing {camera.width} x {camera.height} pixels x (max_depth + 1 = {max_depth + 1}) "
                           f"levels x {1 + data.shadow_lights()} rays per hit")  # fmt: skip


def draw_surfaces(scene: Scene, camera: Camera, options: RenderOptions, context: FrameContext) -> None:
    """``method="ray-tracing"``: color and depth of every pixel into `context` (the driver then casts the volumes
    over the primary hits' depth). Counts into ``context.counts``: rays per kind, hits, total internal
    reflections, the deepest level reached."""
    height, width = camera.height, camera.width
    counts = context.counter()
    data = _Scene(scene, _is_phong(options), options.shadows, options)
    _check_work(camera, data, options.max_depth, "render")
    context.depth = depth = np.ones((height, width), dtype=np.float32)
    context.color = color = np.empty((height, width, 4), dtype=np.uint8)
    color[:, :] = options.background
    background = options.background.astype(np.float64) / 255.0
    window_from_world = np.asarray(camera.viewport_matrix @ camera.clip_from_world, dtype=np.float64)
    flat_color = color.reshape(-1, 4)
    flat_depth = depth.reshape(-1)
    for key in ("primary_rays", "shadow_rays", "reflected_rays", "refracted_rays", "hits",
                "total_internal_reflections", "depth_reached"):  # fmt: skip
        counts.setdefault(key, 0)
    for start in range(0, width * height, CHUNK):
        pixels = np.arange(start, min(start + CHUNK, width * height))
        origins, directions = _primary(camera, pixels, width, height)
        result, primary, z = _trace(data, origins, directions, np.arange(pixels.shape[0]), pixels.shape[0],
                                    options.max_depth, options.cull, background, counts, window_from_world,
                                    environment=options.environment)  # fmt: skip
        # pixel j·W + i (y up) is row H − 1 − j of the image
        out = (height - 1 - pixels // width) * width + pixels % width
        if primary is None or primary.rows.shape[0] == 0:
            continue
        rows = primary.rows
        target = out[rows]
        flat_color[target, :3] = np.floor(np.clip(result[rows], 0.0, 1.0) * 255.0 + 0.5).astype(np.uint8)
        flat_color[target, 3] = 255
        flat_depth[target] = z
        if context.normals is not None:
            context.normals.reshape(-1, 3)[target] = primary.normal.astype(np.float32)
        if context.object_id is not None:
            context.object_id.reshape(-1)[target] = data.numbers[primary.item].astype(np.int32)


def _is_phong(options: RenderOptions) -> bool:
    from frustum.raster import shade

    return options.specular_model == shade.SPECULAR_PHONG


def ray_path(scene: Scene, camera: Camera, x: float, y: float, *, max_depth: int = 5, shadows: bool = True,
             cull_back_faces: bool = True, specular: str = "blinn-phong") -> list[RaySegment]:  # fmt: skip
    """Every ray ``render(scene, camera, method="ray-tracing")`` traces for the window point (x, y) (y up; pixel
    centres at half-integers): the primary ray, its shadow rays, and the reflected and refracted rays level by
    level, in the order traced (``RaySegment.parent`` links the tree).

    Raises
    ------
    FrustumError
        Not a Scene or Camera, a non-finite point, or `max_depth` outside [0, 64].
    """
    from frustum._arrays import as_scalar, describe
    from frustum.render.options import MAX_DEPTH

    where = "ray_path"
    if not isinstance(scene, Scene) or not isinstance(camera, Camera):
        raise FrustumError(f"{where}: expected a Scene and a Camera, got {describe(scene)}, {describe(camera)}")
    px = as_scalar(x, "x", where=where, error=FrustumError)
    py = as_scalar(y, "y", where=where, error=FrustumError)
    if isinstance(max_depth, bool) or not isinstance(max_depth, int | np.integer) or not 0 <= max_depth <= MAX_DEPTH:
        raise FrustumError(f"{where}: max_depth = {describe(max_depth)} is not an integer in [0, {MAX_DEPTH}]")
    data = _Scene(scene, specular == "phong", bool(shadows))
    m = np.asarray(camera.world_from_window, dtype=np.float64)
    nw = m[3, 0] * px + m[3, 1] * py + m[3, 3]
    origin = np.array([(m[a, 0] * px + m[a, 1] * py + m[a, 3]) / nw for a in range(3)])
    fw = nw + m[3, 2]
    end = np.array([(m[a, 0] * px + m[a, 1] * py + m[a, 2] + m[a, 3]) / fw for a in range(3)])
    record: list[RaySegment] = []
    window_from_world = np.asarray(camera.viewport_matrix @ camera.clip_from_world, dtype=np.float64)
    _trace(data, origin[None], (end - origin)[None], np.zeros(1, dtype=np.int64), 1, int(max_depth),
           bool(cull_back_faces), np.zeros(4), {}, window_from_world, record)  # fmt: skip
    return record
