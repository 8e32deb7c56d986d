"""Image-based lighting for the metallic–roughness model: the light a scene's ``EnvironmentMap`` sends onto a
surface, precomputed once per map (and once for all maps: the BRDF table) so that shading a pixel costs a few
lookups [Karis 2013, "Real Shading in Unreal Engine 4"; Ramamoorthi & Hanrahan 2001].

* **Diffuse**: the irradiance $E(n) = ∫ L(l)·max(n·l, 0) dω$ from the map's first nine spherical harmonics,
  $E(n) = Σ_{l ≤ 2} Â_l Σ_m L_{lm} Y_{lm}(n)$ with $Â_0 = π$, $Â_1 = 2π/3$, $Â_2 = π/4$; a Lambertian surface of
  colour c reflects $c·E(n)/π$ (``irradiance_sh`` stores the coefficients already times $Â_l/π$).
* **Specular** by the split sum: $∫ L·f·(n·l) dω ≈ prefiltered(R_d, roughness)·(f0·A + B)$, with R = 2(n·v)n − v the
  mirror direction of v about n turned toward n as the lobe of a rough surface is, $R_d = t·R + (1 − t)·n$, $t = s(√s
  + α)$, $s = 1 − α$ (the dominant direction of Lagarde & de Rousiers, "Moving Frostbite to PBR", 2014).
  ``prefiltered`` is the map convolved with the GGX lobe around R (n = v = R assumed), weighted by n·l: $P(R) = Σ_l
  L(l)·D(h)·(n·l)·Δω / Σ_l D(h)·(n·l)·Δω$ summed exactly over the texels of a resampled map (no sampling noise; each
  row a circular correlation by FFT), one latitude–longitude map per roughness of ``ROUGHNESS_LEVELS`` (roughness 0:
  the map itself); between levels the shader interpolates linearly. A and B (``brdf_table``) are the scale and bias to
  f0 of the directional albedo of the GGX specular lobe with the height-correlated Smith term, $A = ∫ (1 −
  F_c)·G_vis$, $B = ∫ F_c·G_vis$, $F_c = (1 − v·h)⁵$, over (n·v, roughness), by importance sampling once (Hammersley
  points) and cached for the process.

The metallic–roughness BRDF then reflects, for specular weight $S = f0·A + B$ (f0 = mix(0.04, base, metallic)),
$S·P(R) + (1 − metallic)·(1 − (0.04·A + B))·base·E(n)/π$, times the occlusion $1 + k·(occlusion − 1)$: for a
white dielectric in a uniform environment of radiance L this is exactly L (the white furnace). A metal loses the
energy single-scattering GGX loses (no multiple bounces between microfacets): the white furnace of a white
metal returns $(A + B)·L$, about 0.99 L at roughness 0.25, 0.87 at 0.5, 0.63 at 0.75 and 0.41 at 1 (averaged
over the visible sphere, weighted by n·v); Mitsuba's ``roughconductor`` loses the same.

The maps are latitude–longitude, in the layout of ``EnvironmentMap`` (``kind="equirect"``: u from
atan2(x, −z), v from acos(y)), whatever the map's own kind.
"""

from __future__ import annotations

import math
import weakref
from functools import lru_cache
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum.shading.environment import EnvironmentMap
from frustum.shading.pbr import DIELECTRIC_F0, distribution_ggx, visibility_smith_ggx

__all__ = [
    "BRDF_TABLE_SIZE",
    "ROUGHNESS_LEVELS",
    "ImageLighting",
    "brdf_table",
    "image_lighting",
    "image_radiance",
    "irradiance_sh",
    "sh_basis",
]

ROUGHNESS_LEVELS = (0.0, 0.2, 0.4, 0.6, 0.8, 1.0)
"""Roughness of each prefiltered map."""
MAP_HEIGHT = 128
"""Rows of each stored prefiltered map (columns: twice as many)."""
BRDF_TABLE_SIZE = 32
"""Samples of n·v and of roughness in the split-sum table."""
_SOURCE_HEIGHTS = {0.2: 128, 0.4: 64}  # the resampled map each level is convolved from (rows); the rest: 32
_SH_SCALE = np.array([1.0] + [2.0 / 3.0] * 3 + [1.0 / 4.0] * 5)  # Â_l / π


class ImageLighting(NamedTuple):
    """What the shader reads of an environment: ``sh`` (9, 3) irradiance coefficients times $Â_l/π$,
    ``prefiltered`` (levels, H, 2H, 3) float32 maps for ``ROUGHNESS_LEVELS``, ``table`` the (n, n, 2) split-sum
    table (``brdf_table``)."""

    sh: NDArray[np.float64]
    prefiltered: NDArray[np.float32]
    table: NDArray[np.float64]


def sh_basis(directions: ArrayLike) -> NDArray[np.float64]:
    """(N, 9) real spherical harmonics $Y_{lm}$, l ≤ 2, of unit directions: 0.282095; 0.488603·(y, z, x);
    1.092548·(xy, yz, xz), 0.315392·(3z² − 1), 0.546274·(x² − y²) in the order (0,0), (1,−1), (1,0), (1,1),
    (2,−2), (2,−1), (2,0), (2,1), (2,2)."""
    d = np.asarray(directions, dtype=np.float64).reshape(-1, 3)
    x, y, z = d[:, 0], d[:, 1], d[:, 2]
    return np.stack([
        np.full_like(x, 0.282095), 0.488603 * y, 0.488603 * z, 0.488603 * x,
        1.092548 * x * y, 1.092548 * y * z, 0.315392 * (3.0 * z * z - 1.0), 1.092548 * x * z,
        0.546274 * (x * x - y * y),
    ], axis=1)  # fmt: skip


def texel_directions(height: int) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Unit directions (H·2H, 3) of the texel centres of a latitude–longitude map and their solid angles
    $Δω = (2π/W)·(cos θ_0 − cos θ_1)$."""
    width = 2 * height
    theta = (np.arange(height) + 0.5) * math.pi / height
    phi = ((np.arange(width) + 0.5) / width - 0.5) * 2.0 * math.pi
    t, p = np.meshgrid(theta, phi, indexing="ij")
    directions = np.stack([np.sin(t) * np.sin(p), np.cos(t), -np.sin(t) * np.cos(p)], axis=-1).reshape(-1, 3)
    edges = np.cos(np.arange(height + 1) * math.pi / height)
    solid = np.repeat((edges[:-1] - edges[1:]) * (2.0 * math.pi / width), width)
    return directions, solid


def resampled(environment: EnvironmentMap, height: int, supersample: int = 4) -> NDArray[np.float64]:
    """The map as an (H, 2H, 3) latitude–longitude image, each texel the mean of supersample² lookups."""
    big = supersample * height
    directions, _ = texel_directions(big)
    values = environment.lookup(directions).reshape(height, supersample, 2 * height, supersample, 3)
    return values.mean(axis=(1, 3))


def irradiance_sh(environment: EnvironmentMap, height: int = 64) -> NDArray[np.float64]:
    """(9, 3): $L_{lm} = Σ L(ω)·Y_{lm}(ω)·Δω$ over the texels of the resampled map, times $Â_l/π$."""
    directions, solid = texel_directions(height)
    radiance = resampled(environment, height).reshape(-1, 3)
    coefficients = sh_basis(directions).T @ (radiance * solid[:, None])
    return coefficients * _SH_SCALE[:, None]


def _convolve(radiance: NDArray, roughness: float) -> NDArray[np.float64]:
    """An (H, 2H, 3) map: the GGX-weighted mean of `radiance` (an (H, 2H, 3) map) around each texel's direction R
    (module docstring), summed over every source texel. The weight of source texel (r, c) for output texel
    (i, j) depends on c − j only (cos of their angle is $cos θ_i cos θ_r + sin θ_i sin θ_r cos(φ_c − φ_j)$), so
    each output row is a circular correlation along the columns: computed for column 0, applied by FFT."""
    height, width = radiance.shape[0], radiance.shape[1]
    source, solid = texel_directions(height)
    first = source.reshape(height, width, 3)[:, 0]  # the output texels of column 0, one per row
    n_dot_l = (first @ source.T).reshape(height, height, width)  # (output row i, source row r, column c)
    n_dot_h = np.sqrt(np.maximum(0.5 * (1.0 + n_dot_l), 0.0))  # h = (l + R)/|l + R|, so R·h = √((1 + R·l)/2)
    alpha = roughness * roughness
    weight = np.where(n_dot_l > 0.0, distribution_ggx(n_dot_h, alpha) * n_dot_l, 0.0)
    weight *= solid.reshape(height, width)[None]
    total = weight.sum(axis=(1, 2))
    spectrum = np.einsum("irf,rfc->ifc", np.conj(np.fft.rfft(weight, axis=2)), np.fft.rfft(radiance, axis=1))
    return np.fft.irfft(spectrum, n=width, axis=1) / total[:, None, None]


def _upsampled(image: NDArray, height: int) -> NDArray[np.float64]:
    """`image` (h, 2h, 3) looked up bilinearly at the texel centres of an (H, 2H) map (the same layout)."""
    if image.shape[0] == height:
        return image
    directions, _ = texel_directions(height)
    return EnvironmentMap(image.astype(np.float32)).lookup(directions).reshape(height, 2 * height, 3)


_CACHE: weakref.WeakKeyDictionary[EnvironmentMap, ImageLighting] = weakref.WeakKeyDictionary()


def image_lighting(environment: EnvironmentMap) -> ImageLighting:
    """The precomputed lighting of `environment` (cached while the map lives: a few seconds the first time)."""
    cached = _CACHE.get(environment)
    if cached is not None:
        return cached
    maps = [resampled(environment, MAP_HEIGHT)]
    sources = {MAP_HEIGHT: maps[0]}
    for roughness in ROUGHNESS_LEVELS[1:]:
        height = _SOURCE_HEIGHTS.get(roughness, 32)
        if height not in sources:
            sources[height] = resampled(environment, height)
        maps.append(_upsampled(_convolve(sources[height], roughness), MAP_HEIGHT))
    lighting = ImageLighting(irradiance_sh(environment), np.ascontiguousarray(np.stack(maps), dtype=np.float32),
                             brdf_table())  # fmt: skip
    _CACHE[environment] = lighting
    return lighting


def _hammersley(count: int) -> NDArray[np.float64]:
    """(count, 2) Hammersley points: $(i/N, radical inverse of i in base 2)$."""
    i = np.arange(count, dtype=np.uint64)
    bits = i.copy()
    bits = ((bits << np.uint64(16)) | (bits >> np.uint64(16))) & np.uint64(0xFFFFFFFF)
    bits = ((bits & np.uint64(0x55555555)) << np.uint64(1)) | ((bits & np.uint64(0xAAAAAAAA)) >> np.uint64(1))
    bits = ((bits & np.uint64(0x33333333)) << np.uint64(2)) | ((bits & np.uint64(0xCCCCCCCC)) >> np.uint64(2))
    bits = ((bits & np.uint64(0x0F0F0F0F)) << np.uint64(4)) | ((bits & np.uint64(0xF0F0F0F0)) >> np.uint64(4))
    bits = ((bits & np.uint64(0x00FF00FF)) << np.uint64(8)) | ((bits & np.uint64(0xFF00FF00)) >> np.uint64(8))
    return np.stack([i / count, bits.astype(np.float64) / 2.0**32], axis=1)


@lru_cache(maxsize=1)
def brdf_table(size: int = BRDF_TABLE_SIZE, samples: int = 1024) -> NDArray[np.float64]:
    """(size, size, 2) split-sum (A, B) at n·v = (i + 0.5)/size (rows i) and roughness = j/(size − 1) (columns j):
    the mean over GGX-sampled half vectors h of $G_vis = 4·V·(n·l)·(v·h)/(n·h)$ times $1 − F_c$ and $F_c$."""
    nv = (np.arange(size) + 0.5) / size
    roughness = np.arange(size) / (size - 1)
    xi = _hammersley(samples)
    table = np.empty((size, size, 2))
    for j, r in enumerate(roughness):
        alpha = max(r * r, 1e-4)
        cos_h = np.sqrt((1.0 - xi[:, 1]) / (1.0 + (alpha * alpha - 1.0) * xi[:, 1]))
        sin_h = np.sqrt(1.0 - cos_h * cos_h)
        phi = 2.0 * math.pi * xi[:, 0]
        h = np.stack([sin_h * np.cos(phi), sin_h * np.sin(phi), cos_h], axis=1)
        v = np.stack([np.sqrt(1.0 - nv * nv), np.zeros_like(nv), nv], axis=1)  # (size, 3), n = +z
        v_dot_h = v @ h.T  # (size, samples)
        l_z = 2.0 * v_dot_h * h[:, 2][None, :] - v[:, 2][:, None]
        valid = (l_z > 0.0) & (v_dot_h > 0.0)
        vis = visibility_smith_ggx(l_z, nv[:, None], alpha)
        g_vis = np.where(valid, 4.0 * vis * l_z * v_dot_h / cos_h[None, :], 0.0)
        fc = (1.0 - np.clip(v_dot_h, 0.0, 1.0)) ** 5
        table[:, j, 0] = ((1.0 - fc) * g_vis).mean(axis=1)
        table[:, j, 1] = (fc * g_vis).mean(axis=1)
    table.setflags(write=False)
    return table


def table_lookup(table: NDArray, n_dot_v: ArrayLike, roughness: ArrayLike) -> tuple[NDArray, NDArray]:
    """(A, B) bilinearly from the table at n·v (rows at (i + 0.5)/n, clamped) and roughness (columns at j/(n − 1))."""
    size = table.shape[0]
    x = np.clip(np.asarray(n_dot_v, dtype=np.float64) * size - 0.5, 0.0, size - 1.0)
    y = np.clip(np.asarray(roughness, dtype=np.float64) * (size - 1), 0.0, size - 1.0)
    i0, j0 = np.minimum(np.floor(x).astype(int), size - 2), np.minimum(np.floor(y).astype(int), size - 2)
    fx, fy = (x - i0)[..., None], (y - j0)[..., None]
    value = ((1 - fx) * (1 - fy) * table[i0, j0] + fx * (1 - fy) * table[i0 + 1, j0]
             + (1 - fx) * fy * table[i0, j0 + 1] + fx * fy * table[i0 + 1, j0 + 1])  # fmt: skip
    return value[..., 0], value[..., 1]


def prefiltered_lookup(maps: NDArray, directions: ArrayLike, roughness: ArrayLike) -> NDArray[np.float64]:
    """(N, 3) prefiltered radiance along unit directions, interpolated linearly between the two nearest levels."""
    d = np.asarray(directions, dtype=np.float64).reshape(-1, 3)
    level = np.clip(np.asarray(roughness, dtype=np.float64), 0.0, 1.0) * (len(ROUGHNESS_LEVELS) - 1)
    level = np.broadcast_to(level, d.shape[:1])
    low = np.minimum(np.floor(level).astype(int), len(ROUGHNESS_LEVELS) - 2)
    t = (level - low)[:, None]
    out = np.zeros((d.shape[0], 3))
    for k in range(len(ROUGHNESS_LEVELS) - 1):
        chosen = low == k
        if chosen.any():
            below = EnvironmentMap(maps[k]).lookup(d[chosen])
            above = EnvironmentMap(maps[k + 1]).lookup(d[chosen])
            out[chosen] = (1.0 - t[chosen]) * below + t[chosen] * above
    return out


def image_radiance(
    lighting: ImageLighting | None, ambient: ArrayLike, normal: ArrayLike, to_viewer: ArrayLike, base: ArrayLike,
    metallic: ArrayLike, roughness: ArrayLike, occlusion: ArrayLike = 1.0, specular: bool = True,
) -> NDArray[np.float64]:  # fmt: skip
    """(N, 3) radiance the environment (``lighting``, or None) and a uniform ambient radiance (3,) reflect toward
    the viewer: $ao·(S·(P(R) + I_a) + (1 − metallic)·(1 − S_0)·base·(E(n)/π + I_a))$ (module docstring); without
    the specular term $S·(P(R) + I_a)$ when not `specular` (a ray tracer's mirror ray brings that light instead)."""
    n = np.atleast_2d(np.asarray(normal, dtype=np.float64))
    v = np.atleast_2d(np.asarray(to_viewer, dtype=np.float64))
    base = np.broadcast_to(np.asarray(base, dtype=np.float64), n.shape)
    metallic = np.broadcast_to(np.asarray(metallic, dtype=np.float64), n.shape[:1])[:, None]
    roughness = np.broadcast_to(np.asarray(roughness, dtype=np.float64), n.shape[:1])
    ambient = np.asarray(ambient, dtype=np.float64)
    n_dot_v = np.clip((n * v).sum(axis=1), 0.0, 1.0)
    a, b = table_lookup(brdf_table(), n_dot_v, roughness)
    f0 = (1.0 - metallic) * DIELECTRIC_F0 + metallic * base
    specular_weight = f0 * a[:, None] + b[:, None]
    diffuse_weight = (1.0 - metallic) * (1.0 - (DIELECTRIC_F0 * a + b))[:, None] * base
    if not specular:
        specular_weight = np.zeros_like(specular_weight)
    specular_light = np.broadcast_to(ambient, n.shape).copy()
    diffuse_light = specular_light.copy()
    if lighting is not None:
        reflected = 2.0 * (n * v).sum(axis=1, keepdims=True) * n - v
        smooth = 1.0 - (roughness * roughness)[:, None]
        t = smooth * (np.sqrt(smooth) + 1.0 - smooth)
        dominant = t * reflected + (1.0 - t) * n
        specular_light += prefiltered_lookup(lighting.prefiltered, dominant, roughness)
        diffuse_light += np.maximum(sh_basis(n) @ lighting.sh, 0.0)
    occlusion = np.asarray(occlusion, dtype=np.float64)
    return (specular_weight * specular_light + diffuse_weight * diffuse_light) * (occlusion[..., None]
                                                                                  if occlusion.ndim else occlusion)
