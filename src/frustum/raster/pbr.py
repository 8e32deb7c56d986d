"""Shading kernel of the glTF metallic–roughness model: ``frustum.shading.pbr``'s BRDF with glTF light units,
``frustum.shading.ibl``'s image-based lighting, then exposure and ``frustum.shading.tone``'s tone maps, per pixel.

Deferred like ``raster.shade.shade_pixels`` (face codes and perspective-correct weights of the finished depth
buffer), with the same interpolated, renormalized normal (flipped for a back face drawn two-sided), base colour
(material colour × vertex colour × texture), depth cueing and blending; per pixel

    L = Σ_l f(l, v)·E_l·(n·l)·seen_l + ao·(S·(P(R) + I_a) + (1 − m)·(1 − S_0)·base·(E_sh(n)/π + I_a)) + emissive

(emissive: the factor times the emissive texture, where there is one)

then $T(exposure·L)$, clamped and stored as $floor(c·255 + 0.5)$. The terms are written as in the NumPy module
(each helper names its formula); ``tests/test_pbr.py`` holds the two equal.

Array contracts (kernels never validate): params (shade.PARAMS,) as ``raster.shade``; pbr (PBR,) float64 laid
out by the ``Q_*`` indices; lights (K, 16) rows of ``pack_lights`` (column 15: a point or spot light's range, 0
for none); sh (9, 3); maps (levels, H, 2H, 3) float32; table (n, n, 2); textures and emission (Ht, Wt, 4)
float32 or empty; seen (H, W, K) float32 light fractions or an empty (0, 0, 0) array.
"""

from __future__ import annotations

import math

import numpy as np

from frustum.raster._jit import kernel, parallel_kernel
from frustum.raster.shade import (
    _CHUNK,
    _DB,
    _DG,
    _DR,
    _NX,
    _NY,
    _NZ,
    _POW,
    _PX,
    _PY,
    _PZ,
    _SIGN,
    _VX,
    _VY,
    _VZ,
    I_BLEND,
    I_FACE_OFFSET,
    I_OBJECT_ID,
    I_WRITE_IDS,
    I_WRITE_NORMALS,
    P_COLOR,
    P_CUE_ON,
    P_EMISSIVE,
    P_EYE,
    P_OPACITY,
    P_VIEW_AXIS,
    _cue,
    _interpolate,
    _sample,
    _surface,
    _to_byte,
)

__all__ = ["PBR", "SHADE_PBR", "shade_chunk_pbr", "shade_pixels_pbr"]

SHADE_PBR = 6
"""``render(shading="pbr")``: the shading mode code beside ``raster.shade``'s SHADE_* (0–5)."""

Q_METALLIC, Q_ROUGHNESS, Q_OCCLUSION_STRENGTH, Q_EXPOSURE, Q_TONE_MAP, Q_ENVIRONMENT, Q_AMBIENT = 0, 1, 2, 3, 4, 5, 6
PBR = 9
DIELECTRIC_F0 = 0.04
INV_PI = 1.0 / math.pi
_NDV = _POW  # the chunk scratch row holding n·v (``shade_chunk_pbr``)


@kernel
def distribution_ggx(n_dot_h: float, alpha: float) -> float:
    """$D = α²·χ⁺(n·h) / (π·((n·h)²(α² − 1) + 1)²)$."""
    a2 = alpha * alpha
    if n_dot_h <= 0.0 or a2 == 0.0:  # a mirror: a delta lobe that no single direction hits
        return 0.0
    denominator = n_dot_h * n_dot_h * (a2 - 1.0) + 1.0
    return a2 / (math.pi * denominator * denominator)


@kernel
def visibility_smith_ggx(n_dot_l: float, n_dot_v: float, alpha: float) -> float:
    """$V = 0.5 / (|n·l|·√((n·v)²(1 − α²) + α²) + |n·v|·√((n·l)²(1 − α²) + α²))$."""
    nl, nv = abs(n_dot_l), abs(n_dot_v)
    a2 = alpha * alpha
    total = nl * math.sqrt(nv * nv * (1.0 - a2) + a2) + nv * math.sqrt(nl * nl * (1.0 - a2) + a2)
    return 0.5 / total if total > 0.0 else 0.0


@kernel
def schlick_weight(v_dot_h: float) -> float:
    """$(1 − |v·h|)⁵$, the Schlick Fresnel weight: $F = f0 + (1 − f0)·(1 − |v·h|)⁵$."""
    x = 1.0 - abs(v_dot_h)
    x2 = x * x
    return x2 * x2 * x


@kernel
def _brdf_channel(base: float, metallic: float, diffuse: float, specular: float, weight: float) -> float:
    """One channel of $mix((1 − F_d)·base/π + F_d·V·D, V·D·(base + (1 − base)·w), metallic)$, $F_d = 0.04 + 0.96·w$
    (``diffuse`` = base/π, ``specular`` = V·D, ``weight`` w = (1 − |v·h|)⁵)."""
    fd = DIELECTRIC_F0 + (1.0 - DIELECTRIC_F0) * weight
    dielectric = (1.0 - fd) * diffuse + fd * specular
    metal = specular * (base + (1.0 - base) * weight)
    return (1.0 - metallic) * dielectric + metallic * metal


@kernel
def sh_irradiance(sh: np.ndarray, channel: int, x: float, y: float, z: float) -> float:
    """$Σ_{lm} c_{lm}·Y_{lm}(n)$ with ``ibl.sh_basis``'s nine functions (coefficients already times Â_l/π)."""
    return (
        sh[0, channel] * 0.282095
        + 0.488603 * (sh[1, channel] * y + sh[2, channel] * z + sh[3, channel] * x)
        + 1.092548 * (sh[4, channel] * x * y + sh[5, channel] * y * z + sh[7, channel] * x * z)
        + sh[6, channel] * 0.315392 * (3.0 * z * z - 1.0)
        + sh[8, channel] * 0.546274 * (x * x - y * y)
    )


@kernel
def _texel(maps: np.ndarray, level: int, fx: float, fy: float) -> tuple[float, float, float]:
    """Bilinear lookup of map `level` at continuous texel coordinates (fx, fy) (centres at integers; columns wrap,
    rows clamp)."""
    height, width = maps.shape[1], maps.shape[2]
    x0, y0 = math.floor(fx), math.floor(fy)
    tx, ty = fx - x0, fy - y0
    i0 = int(x0)  # fx in [−0.5, width − 0.5]: x0 in [−1, width − 1], wrapped without a division
    i0 = width - 1 if i0 < 0 else i0
    i1 = 0 if i0 + 1 >= width else i0 + 1
    j0 = min(max(int(y0), 0), height - 1)
    j1 = min(max(int(y0) + 1, 0), height - 1)
    w00, w01, w10, w11 = (1.0 - tx) * (1.0 - ty), tx * (1.0 - ty), (1.0 - tx) * ty, tx * ty
    r = (w00 * maps[level, j0, i0, 0] + w01 * maps[level, j0, i1, 0]) + (w10 * maps[level, j1, i0, 0]
                                                                          + w11 * maps[level, j1, i1, 0])
    g = (w00 * maps[level, j0, i0, 1] + w01 * maps[level, j0, i1, 1]) + (w10 * maps[level, j1, i0, 1]
                                                                          + w11 * maps[level, j1, i1, 1])
    b = (w00 * maps[level, j0, i0, 2] + w01 * maps[level, j0, i1, 2]) + (w10 * maps[level, j1, i0, 2]
                                                                          + w11 * maps[level, j1, i1, 2])
    return r, g, b


@kernel
def arctangent(y: float, x: float) -> float:
    """atan2(y, x) to 2e-8 rad, branch-free arithmetic (no libm call): $atan t ≈ t·Σ_k a_{2k}·t^{2k}$ on
    t = min(|x|, |y|)/max(|x|, |y|) in [0, 1] (Abramowitz & Stegun 4.4.49), then the octant's reflections."""
    ax, ay = abs(x), abs(y)
    big, small = max(ax, ay), min(ax, ay)
    t = small / big if big > 0.0 else 0.0
    t2 = t * t
    p = ((((((0.0028662257 * t2 - 0.0161657367) * t2 + 0.0429096138) * t2 - 0.0752896400) * t2 + 0.1065626393) * t2
          - 0.1420889944) * t2 + 0.1999355085) * t2 - 0.3333314528  # fmt: skip
    r = t * (p * t2 + 1.0)
    r = 0.5 * math.pi - r if ay > ax else r
    r = math.pi - r if x < 0.0 else r
    return -r if y < 0.0 else r


@kernel
def prefiltered(maps: np.ndarray, roughness: float, x: float, y: float, z: float) -> tuple[float, float, float]:
    """The prefiltered radiance along the unit direction (x, y, z) (``EnvironmentMap``'s equirect layout:
    $u = 1/2 + atan2(x, −z)/2π$, $v = acos(y)/π$, by ``arctangent``), linear between the two levels around
    $roughness·(levels − 1)$ (one map: that map, the two levels blended already, ``render.pbr.blended_level``)."""
    top = maps.shape[0] - 1
    y = min(max(y, -1.0), 1.0)
    fx = (0.5 + arctangent(x, -z) / (2.0 * math.pi)) * maps.shape[2] - 0.5
    fy = arctangent(math.sqrt((1.0 - y) * (1.0 + y)), y) / math.pi * maps.shape[1] - 0.5  # acos(y)
    if top == 0:
        return _texel(maps, 0, fx, fy)
    level = min(max(roughness, 0.0), 1.0) * top
    low = min(math.floor(level), top - 1)
    t = level - low
    r0, g0, b0 = _texel(maps, low, fx, fy)
    if t == 0.0:
        return r0, g0, b0
    r1, g1, b1 = _texel(maps, low + 1, fx, fy)
    return (1.0 - t) * r0 + t * r1, (1.0 - t) * g0 + t * g1, (1.0 - t) * b0 + t * b1


@kernel
def split_sum(table: np.ndarray, n_dot_v: float, roughness: float) -> tuple[float, float]:
    """(A, B) bilinearly from the split-sum table: rows at n·v = (i + 0.5)/n (clamped), columns at j/(n − 1)."""
    size = table.shape[0]
    x = min(max(n_dot_v * size - 0.5, 0.0), size - 1.0)
    y = min(max(roughness * (size - 1), 0.0), size - 1.0)
    i0 = min(math.floor(x), size - 2)
    j0 = min(math.floor(y), size - 2)
    fx, fy = x - i0, y - j0
    a = ((1 - fx) * (1 - fy) * table[i0, j0, 0] + fx * (1 - fy) * table[i0 + 1, j0, 0]
         + (1 - fx) * fy * table[i0, j0 + 1, 0] + fx * fy * table[i0 + 1, j0 + 1, 0])  # fmt: skip
    b = ((1 - fx) * (1 - fy) * table[i0, j0, 1] + fx * (1 - fy) * table[i0 + 1, j0, 1]
         + (1 - fx) * fy * table[i0, j0 + 1, 1] + fx * fy * table[i0 + 1, j0 + 1, 1])  # fmt: skip
    return a, b


@kernel
def tone(code: int, exposure: float, r: float, g: float, b: float) -> tuple[float, float, float]:
    """Exposure, then ``shading.tone``'s map `code` (0 none, 1 ACES fit, 2 Khronos PBR Neutral)."""
    r, g, b = max(r * exposure, 0.0), max(g * exposure, 0.0), max(b * exposure, 0.0)
    if code == 1:
        r = (r * (2.51 * r + 0.03)) / (r * (2.43 * r + 0.59) + 0.14)
        g = (g * (2.51 * g + 0.03)) / (g * (2.43 * g + 0.59) + 0.14)
        b = (b * (2.51 * b + 0.03)) / (b * (2.43 * b + 0.59) + 0.14)
    elif code == 2:
        start = 0.8 - 0.04
        x = min(r, min(g, b))
        offset = x - 6.25 * x * x if x < 0.08 else 0.04
        r, g, b = r - offset, g - offset, b - offset
        peak = max(r, max(g, b))
        if peak >= start:
            d = 1.0 - start
            new_peak = 1.0 - d * d / (peak + d - start)
            scale = new_peak / peak
            r, g, b = r * scale, g * scale, b * scale
            w = 1.0 - 1.0 / (0.15 * (peak - new_peak) + 1.0)
            r, g, b = (1.0 - w) * r + w * new_peak, (1.0 - w) * g + w * new_peak, (1.0 - w) * b + w * new_peak
    return r, g, b


@kernel
def radiance(
    nx: float, ny: float, nz: float, px: float, py: float, pz: float,
    base_r: float, base_g: float, base_b: float, metallic: float, roughness: float, occlusion: float,
    params: np.ndarray, pbr: np.ndarray, lights: np.ndarray, sh: np.ndarray, maps: np.ndarray, table: np.ndarray,
    seen: np.ndarray, row: int, col: int,
) -> tuple[float, float, float]:  # fmt: skip
    """Linear radiance toward the eye (module docstring's L without emission) at P with unit normal N: each
    light's ``direct_light``, then ``image_light``."""
    vx, vy, vz, n_dot_v = view(params, px, py, pz, nx, ny, nz)
    alpha = roughness * roughness
    r, g, b = 0.0, 0.0, 0.0
    shadowed = seen.shape[0] > 0
    for k in range(lights.shape[0]):
        visible = seen[row, col, k] if shadowed else 1.0
        dr, dg, db = direct_light(lights, k, visible, px, py, pz, nx, ny, nz, vx, vy, vz, n_dot_v, alpha,
                                  base_r, base_g, base_b, metallic)  # fmt: skip
        r, g, b = r + dr, g + dg, b + db
    ir, ig, ib = image_light(pbr, sh, maps, table, nx, ny, nz, vx, vy, vz, n_dot_v, alpha, roughness,
                             base_r, base_g, base_b, metallic, occlusion)  # fmt: skip
    return r + ir, g + ig, b + ib


@kernel
def view(
    params: np.ndarray, px: float, py: float, pz: float, nx: float, ny: float, nz: float
) -> tuple[float, float, float, float]:  # fmt: skip
    """(V, n·v): the unit direction from P to the eye and its cosine with the unit normal N."""
    vx, vy, vz = params[P_EYE] - px, params[P_EYE + 1] - py, params[P_EYE + 2] - pz
    length = math.sqrt((vx * vx + vy * vy) + vz * vz)
    if length > 0.0:
        vx, vy, vz = vx / length, vy / length, vz / length
    return vx, vy, vz, (nx * vx + ny * vy) + nz * vz


@kernel
def direct_light(
    lights: np.ndarray, k: int, visible: float, px: float, py: float, pz: float, nx: float, ny: float, nz: float,
    vx: float, vy: float, vz: float, n_dot_v: float, alpha: float, base_r: float, base_g: float, base_b: float,
    metallic: float,
) -> tuple[float, float, float]:  # fmt: skip
    """$f(l, v)·E·(n·l)·seen$ of light k (lux; candela over d² in the ``range`` window and the spot's cone), its
    visible fraction `visible`; zero where n·l <= 0."""
    kind = lights[k, 0]
    illuminance = 1.0
    if kind == 0.0:
        lx, ly, lz = lights[k, 7], lights[k, 8], lights[k, 9]
    else:
        lx, ly, lz = lights[k, 4] - px, lights[k, 5] - py, lights[k, 6] - pz
        d2 = (lx * lx + ly * ly) + lz * lz
        distance = math.sqrt(d2)
        if distance == 0.0:
            return 0.0, 0.0, 0.0
        lx, ly, lz = lx / distance, ly / distance, lz / distance
        illuminance = 1.0 / d2
        reach = lights[k, 15]
        if reach > 0.0:
            q = distance / reach
            window = min(max(1.0 - q * q * q * q, 0.0), 1.0)
            illuminance *= window * window
        if kind == 2.0:
            cos_alpha = -((lx * lights[k, 7] + ly * lights[k, 8]) + lz * lights[k, 9])
            scale = 1.0 / max(1e-3, lights[k, 13] - lights[k, 14])
            t = min(max((cos_alpha - lights[k, 14]) * scale, 0.0), 1.0)
            illuminance *= t * t
    n_dot_l = (nx * lx + ny * ly) + nz * lz
    if n_dot_l <= 0.0 or illuminance == 0.0:
        return 0.0, 0.0, 0.0
    illuminance *= visible
    hx, hy, hz = lx + vx, ly + vy, lz + vz
    length = math.sqrt((hx * hx + hy * hy) + hz * hz)
    if length > 0.0:
        hx, hy, hz = hx / length, hy / length, hz / length
    n_dot_h = (nx * hx + ny * hy) + nz * hz
    v_dot_h = (vx * hx + vy * hy) + vz * hz
    specular = visibility_smith_ggx(n_dot_l, n_dot_v, alpha) * distribution_ggx(n_dot_h, alpha)
    w = schlick_weight(v_dot_h)
    scale = illuminance * n_dot_l
    diffuse_r, diffuse_g, diffuse_b = base_r * INV_PI, base_g * INV_PI, base_b * INV_PI
    return (_brdf_channel(base_r, metallic, diffuse_r, specular, w) * lights[k, 1] * scale,
            _brdf_channel(base_g, metallic, diffuse_g, specular, w) * lights[k, 2] * scale,
            _brdf_channel(base_b, metallic, diffuse_b, specular, w) * lights[k, 3] * scale)  # fmt: skip


@kernel
def image_light(
    pbr: np.ndarray, sh: np.ndarray, maps: np.ndarray, table: np.ndarray, nx: float, ny: float, nz: float,
    vx: float, vy: float, vz: float, n_dot_v: float, alpha: float, roughness: float,
    base_r: float, base_g: float, base_b: float, metallic: float, occlusion: float,
) -> tuple[float, float, float]:  # fmt: skip
    """$ao·(S·(P(R) + I_a) + (1 − m)·(1 − S_0)·base·(E_sh(n)/π + I_a))$: image-based and ambient light by the split
    sum (ibl's docstring), S = F0·A + B."""
    a, bias = split_sum(table, min(max(n_dot_v, 0.0), 1.0), roughness)
    s0 = DIELECTRIC_F0 * a + bias
    keep = (1.0 - metallic) * (1.0 - s0)
    ar, ag, ab = pbr[Q_AMBIENT], pbr[Q_AMBIENT + 1], pbr[Q_AMBIENT + 2]
    spec_r, spec_g, spec_b = ar, ag, ab
    irr_r, irr_g, irr_b = ar, ag, ab
    if pbr[Q_ENVIRONMENT] != 0.0:
        d = 2.0 * n_dot_v  # the lobe's dominant direction: R = 2(n·v)n − v turned toward n (ibl's docstring)
        smooth = 1.0 - alpha
        t = smooth * (math.sqrt(smooth) + alpha)
        rx, ry, rz = t * (d * nx - vx) + (1.0 - t) * nx, t * (d * ny - vy) + (1.0 - t) * ny, (
            t * (d * nz - vz) + (1.0 - t) * nz)
        pr, pg, pb = prefiltered(maps, roughness, rx, ry, rz)
        spec_r, spec_g, spec_b = spec_r + pr, spec_g + pg, spec_b + pb
        irr_r += max(sh_irradiance(sh, 0, nx, ny, nz), 0.0)
        irr_g += max(sh_irradiance(sh, 1, nx, ny, nz), 0.0)
        irr_b += max(sh_irradiance(sh, 2, nx, ny, nz), 0.0)
    f0_r = (1.0 - metallic) * DIELECTRIC_F0 + metallic * base_r
    f0_g = (1.0 - metallic) * DIELECTRIC_F0 + metallic * base_g
    f0_b = (1.0 - metallic) * DIELECTRIC_F0 + metallic * base_b
    return (occlusion * ((f0_r * a + bias) * spec_r + keep * base_r * irr_r),
            occlusion * ((f0_g * a + bias) * spec_g + keep * base_g * irr_g),
            occlusion * ((f0_b * a + bias) * spec_b + keep * base_b * irr_b))  # fmt: skip


@parallel_kernel(lambda depth, codes, *_: codes.shape[0], work=lambda depth, *_: depth.size, grain=8192)
def shade_pixels_pbr(
    depth: np.ndarray, codes: np.ndarray, bary: np.ndarray, faces: np.ndarray, world: np.ndarray, normals: np.ndarray,
    vertex_colors: np.ndarray, uvs: np.ndarray, texture: np.ndarray, surface_maps: np.ndarray, emission: np.ndarray,
    params: np.ndarray, pbr: np.ndarray, lights: np.ndarray, sh: np.ndarray, maps: np.ndarray, table: np.ndarray,
    seen: np.ndarray, item: np.ndarray, color: np.ndarray, normal_out: np.ndarray, id_out: np.ndarray,
    start: int, stop: int,
) -> None:  # fmt: skip
    """Shade the pixels of one scene item with the metallic–roughness model (``raster.shade.shade_pixels``'s
    contract for depth, codes, bary, faces, world, normals, vertex_colors, uvs, texture, params, item, color and
    the extra outputs). ``surface_maps`` (Ht, Wt, 4) float32: glTF's metallic–roughness texture's G (roughness)
    and B (metallic) in channels 1 and 2 and the occlusion texture's R in channel 0, or empty; sampled at the
    same UVs as the base colour texture; ``emission`` (He, We, 4) float32 the emissive texture (linear), times the
    emissive factor, or empty."""
    for row in range(start, stop):
        _shade_row_pbr(
            row, depth, codes, bary, faces, world, normals, vertex_colors, uvs, texture, surface_maps, emission,
            params, pbr, lights, sh, maps, table, seen, item, color, normal_out, id_out,
        )  # fmt: skip


@kernel
def _shade_row_pbr(
    row: int, depth: np.ndarray, codes: np.ndarray, bary: np.ndarray, faces: np.ndarray, world: np.ndarray,
    normals: np.ndarray, vertex_colors: np.ndarray, uvs: np.ndarray, texture: np.ndarray, surface_maps: np.ndarray,
    emission: np.ndarray, params: np.ndarray, pbr: np.ndarray, lights: np.ndarray, sh: np.ndarray, maps: np.ndarray,
    table: np.ndarray, seen: np.ndarray, item: np.ndarray, color: np.ndarray, normal_out: np.ndarray,
    id_out: np.ndarray,
) -> None:  # fmt: skip
    """One image row of ``shade_pixels_pbr``."""
    face_offset = item[I_FACE_OFFSET]
    tone_code = int(pbr[Q_TONE_MAP])
    for col in range(codes.shape[1]):
        if depth[row, col] >= 1.0:
            continue
        code = codes[row, col]
        if code < 0:
            continue
        f = code // 2 - face_offset
        if f < 0 or f >= faces.shape[0]:
            continue
        u1, u2 = float(bary[row, col, 0]), float(bary[row, col, 1])
        u0 = (1.0 - u1) - u2
        a, b_, c = faces[f, 0], faces[f, 1], faces[f, 2]
        nx, ny, nz, px, py, pz = _surface(f, code % 2 == 1, u0, u1, u2, faces, world, normals)
        alpha = params[P_OPACITY]
        base_r, base_g, base_b = params[P_COLOR], params[P_COLOR + 1], params[P_COLOR + 2]
        metallic, roughness, occlusion = pbr[Q_METALLIC], pbr[Q_ROUGHNESS], 1.0
        emissive_r, emissive_g, emissive_b = params[P_EMISSIVE], params[P_EMISSIVE + 1], params[P_EMISSIVE + 2]
        if vertex_colors.shape[0] > 0:
            base_r *= _interpolate(u0, u1, u2, vertex_colors[a, 0], vertex_colors[b_, 0], vertex_colors[c, 0])
            base_g *= _interpolate(u0, u1, u2, vertex_colors[a, 1], vertex_colors[b_, 1], vertex_colors[c, 1])
            base_b *= _interpolate(u0, u1, u2, vertex_colors[a, 2], vertex_colors[b_, 2], vertex_colors[c, 2])
        if texture.shape[0] > 0 or surface_maps.shape[0] > 0 or emission.shape[0] > 0:
            tu = _interpolate(u0, u1, u2, uvs[a, 0], uvs[b_, 0], uvs[c, 0])
            tv = _interpolate(u0, u1, u2, uvs[a, 1], uvs[b_, 1], uvs[c, 1])
            if texture.shape[0] > 0:
                texel_r, texel_g, texel_b, texel_a = _sample(texture, tu, tv)
                base_r, base_g, base_b, alpha = base_r * texel_r, base_g * texel_g, base_b * texel_b, alpha * texel_a
            if surface_maps.shape[0] > 0:
                ao, rough, metal, _ = _sample(surface_maps, tu, tv)
                roughness *= rough
                metallic *= metal
                occlusion = 1.0 + pbr[Q_OCCLUSION_STRENGTH] * (ao - 1.0)
            if emission.shape[0] > 0:
                glow_r, glow_g, glow_b, _ = _sample(emission, tu, tv)
                emissive_r, emissive_g, emissive_b = emissive_r * glow_r, emissive_g * glow_g, emissive_b * glow_b
        r, g, b = radiance(nx, ny, nz, px, py, pz, base_r, base_g, base_b, metallic, roughness, occlusion, params,
                           pbr, lights, sh, maps, table, seen, row, col)  # fmt: skip
        r, g, b = tone(tone_code, pbr[Q_EXPOSURE], r + emissive_r, g + emissive_g, b + emissive_b)
        # depth cue and store: the same lines as raster/shade.py's and raster/shadow.py's pixel loops, a kernel
        # specialised per mode on purpose (the Phong kernels stay byte-equal and never compile the PBR terms)
        if params[P_CUE_ON] != 0.0:
            d = 0.0
            for k in range(3):
                p = _interpolate(u0, u1, u2, world[a, k], world[b_, k], world[c, k])
                d += (params[P_EYE + k] - p) * params[P_VIEW_AXIS + k]
            r, g, b = _cue(params, r, g, b, d)
        if item[I_BLEND] != 0:
            alpha = min(max(alpha, 0.0), 1.0)
            r = alpha * min(max(r, 0.0), 1.0) + (1.0 - alpha) * (color[row, col, 0] / 255.0)
            g = alpha * min(max(g, 0.0), 1.0) + (1.0 - alpha) * (color[row, col, 1] / 255.0)
            b = alpha * min(max(b, 0.0), 1.0) + (1.0 - alpha) * (color[row, col, 2] / 255.0)
            alpha = alpha + (1.0 - alpha) * (color[row, col, 3] / 255.0)
        else:
            alpha = 1.0
        color[row, col, 0] = _to_byte(r)
        color[row, col, 1] = _to_byte(g)
        color[row, col, 2] = _to_byte(b)
        color[row, col, 3] = _to_byte(alpha)
        if item[I_WRITE_NORMALS] != 0:
            normal_out[row, col, 0], normal_out[row, col, 1], normal_out[row, col, 2] = nx, ny, nz
        if item[I_WRITE_IDS] != 0:
            id_out[row, col] = item[I_OBJECT_ID]


# Kernel specialisation kept on purpose: ``_shade_row_pbr``'s pixel for the tile path (``raster.pbr_tiled``), as
# passes over a chunk of gathered pixels calling the same helpers in the same order, so the same bytes.
@kernel
def shade_chunk_pbr(
    n: int, s: np.ndarray, where: np.ndarray, params: np.ndarray, pbr: np.ndarray, lights: np.ndarray,
    sh: np.ndarray, maps: np.ndarray, table: np.ndarray, words: np.ndarray,
) -> None:  # fmt: skip
    """Shade the first n pixels gathered by ``shade._gather_chunk`` (an opaque item without textures, vertex
    colours, depth cue or shadows): ``_surface``'s normal, ``view``, each light's ``direct_light`` (one pass per
    light over the chunk), ``image_light``, emission and ``tone``; each pixel's bytes (r, g, b, 255) stored as
    one little-endian word (words: color viewed as uint32)."""
    metallic, roughness = pbr[Q_METALLIC], pbr[Q_ROUGHNESS]
    alpha = roughness * roughness
    base_r, base_g, base_b = params[P_COLOR], params[P_COLOR + 1], params[P_COLOR + 2]
    for i in range(n):  # the normal as raster.shade._shade_chunk's: kernel specialisation kept on purpose
        nx, ny, nz = s[_NX + i], s[_NY + i], s[_NZ + i]
        length = math.sqrt((nx * nx + ny * ny) + nz * nz)
        zero = length == 0.0
        nx = 0.0 if zero else nx
        ny = 0.0 if zero else ny
        nz = 1.0 if zero else nz
        length = 1.0 if zero else length
        sign = s[_SIGN + i]
        nx, ny, nz = sign * nx / length, sign * ny / length, sign * nz / length
        s[_NX + i], s[_NY + i], s[_NZ + i] = nx, ny, nz
        s[_VX + i], s[_VY + i], s[_VZ + i], s[_NDV + i] = view(params, s[_PX + i], s[_PY + i], s[_PZ + i], nx, ny, nz)
        s[_DR + i], s[_DG + i], s[_DB + i] = 0.0, 0.0, 0.0
    for k in range(lights.shape[0]):
        for i in range(n):
            dr, dg, db = direct_light(
                lights, k, 1.0, s[_PX + i], s[_PY + i], s[_PZ + i], s[_NX + i], s[_NY + i], s[_NZ + i],
                s[_VX + i], s[_VY + i], s[_VZ + i], s[_NDV + i], alpha, base_r, base_g, base_b, metallic,
            )  # fmt: skip
            s[_DR + i], s[_DG + i], s[_DB + i] = s[_DR + i] + dr, s[_DG + i] + dg, s[_DB + i] + db
    tone_code, exposure = int(pbr[Q_TONE_MAP]), pbr[Q_EXPOSURE]
    er, eg, eb = params[P_EMISSIVE], params[P_EMISSIVE + 1], params[P_EMISSIVE + 2]
    for i in range(n):
        ir, ig, ib = image_light(pbr, sh, maps, table, s[_NX + i], s[_NY + i], s[_NZ + i], s[_VX + i], s[_VY + i],
                                 s[_VZ + i], s[_NDV + i], alpha, roughness, base_r, base_g, base_b, metallic, 1.0)
        r, g, b = tone(tone_code, exposure, (s[_DR + i] + ir) + er, (s[_DG + i] + ig) + eg, (s[_DB + i] + ib) + eb)
        where[2 * _CHUNK + i] = (
            int(_to_byte(r)) | int(_to_byte(g)) << 8 | int(_to_byte(b)) << 16 | 255 << 24
        )
    for i in range(n):
        words[np.uint64(where[i]), np.uint64(where[_CHUNK + i]), 0] = where[2 * _CHUNK + i]
