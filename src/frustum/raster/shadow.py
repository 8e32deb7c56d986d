"""Shadow kernels: surface points per pixel, shadow-map lookups with percentage-closer filtering, and the shading of
pixels with a visibility factor per light (shadow rays go through ``Scene.occluded``, ``raster.rays``).

None of these runs on an ordinary render: they compile only when ``render(..., shadows=...)`` or the
``"position"``/``"shadow"`` buffers ask for them (``frustum.shadow_pass`` drives them).

Array contracts (kernels never validate):

- ``points`` (H, W, 3) float64 world point of each drawn pixel, ``facing`` (H, W, 3) float64 the unit geometric
  normal of its face turned toward the viewer (so the drawn side);
- a shadow map is (S, S) float32 window depth seen from the light (1.0 where nothing), top row first, with a
  ``view`` record (MAP_FIELDS,) float64 laid out by the ``M_*`` indices: window_from_world (16, row-major),
  projection kind (0 orthographic, 1 perspective), near, far, texel size (orthographic: world units per texel;
  perspective: texel size per unit of distance, $2·tan(fov/2)/S$), and the light's position or direction;
- ``lights`` (K, 16) float64 rows of ``frustum.shading.pack_lights``; ``visibility`` (H, W, K) float32 the
  fraction of light k reaching each pixel (1: lit, 0: shadowed).
"""

from __future__ import annotations

import math

import numpy as np

from frustum.raster._jit import kernel, parallel_kernel
from frustum.raster.shade import (
    I_BLEND,
    I_FACE_OFFSET,
    I_MODE,
    I_OBJECT_ID,
    I_SPECULAR_MODEL,
    I_WRITE_IDS,
    I_WRITE_NORMALS,
    P_AMBIENT,
    P_COLOR,
    P_CUE_ON,
    P_DIFFUSE,
    P_EMISSIVE,
    P_EYE,
    P_LIGHT_AMBIENT,
    P_OPACITY,
    P_SHININESS,
    P_SPECULAR,
    P_VIEW_AXIS,
    SHADE_FLAT,
    SHADE_NONE,
    SHADE_PHONG,
    SPECULAR_PHONG,
    _cue,
    _interpolate,
    _sample,
    _surface,
    _to_byte,
    power,
)  # fmt: skip

__all__ = [
    "MAP_FIELDS", "map_visibility", "shade_pixels_shadowed", "surface_points",
]  # fmt: skip

# map record layout
M_MATRIX, M_KIND, M_NEAR, M_FAR, M_TEXEL, M_LIGHT = 0, 16, 17, 18, 19, 20
MAP_FIELDS = 23
KIND_ORTHOGRAPHIC, KIND_PERSPECTIVE = 0.0, 1.0
SLOPE_LIMIT = 8.0
"""Largest tan θ the slope-scaled bias uses (θ: angle between the surface normal and the light): grazing faces
are barely lit, and a larger bias would detach shadows from their casters."""


@parallel_kernel(lambda depth, *_: depth.shape[0], work=lambda depth, *_: depth.size, grain=16384)
def surface_points(
    depth: np.ndarray, codes: np.ndarray, bary: np.ndarray, faces: np.ndarray, world: np.ndarray,
    face_offset: int, points: np.ndarray, facing: np.ndarray,
    start: int, stop: int,
) -> None:  # fmt: skip
    """World point $(u0·Pa + u1·Pb) + u2·Pc$ and unit face normal (turned toward the viewer: flipped for a back
    face drawn two-sided) of every pixel of one item (face $code // 2 − face_offset$ in [0, M)).

    depth (H, W) float32, codes (H, W) int, bary (H, W, 2) float32, faces (M, 3) int64 counter-clockwise seen from
    the front, world (N, 3) float; points and facing (H, W, 3) float64 written at those pixels only.
    """
    for row in range(start, stop):
        for col in range(depth.shape[1]):
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
            a, b, c = faces[f, 0], faces[f, 1], faces[f, 2]
            for k in range(3):
                points[row, col, k] = _interpolate(u0, u1, u2, world[a, k], world[b, k], world[c, k])
            e1x, e1y, e1z = world[b, 0] - world[a, 0], world[b, 1] - world[a, 1], world[b, 2] - world[a, 2]
            e2x, e2y, e2z = world[c, 0] - world[a, 0], world[c, 1] - world[a, 1], world[c, 2] - world[a, 2]
            nx, ny, nz = e1y * e2z - e1z * e2y, e1z * e2x - e1x * e2z, e1x * e2y - e1y * e2x
            length = math.sqrt((nx * nx + ny * ny) + nz * nz)
            if length == 0.0:
                nx, ny, nz, length = 0.0, 0.0, 1.0, 1.0
            sign = -1.0 if code % 2 == 1 else 1.0
            facing[row, col, 0] = sign * nx / length
            facing[row, col, 1] = sign * ny / length
            facing[row, col, 2] = sign * nz / length


@kernel
def _linear_depth(view: np.ndarray, z: float) -> float:
    """Distance along the light's axis of window depth z (orthographic: linear; perspective:
    $2nf/((f + n) − z_ndc·(f − n))$)."""
    near, far = view[M_NEAR], view[M_FAR]
    if view[M_KIND] == KIND_ORTHOGRAPHIC:
        return near + z * (far - near)
    z_ndc = 2.0 * z - 1.0
    return 2.0 * near * far / ((far + near) - z_ndc * (far - near))


@kernel
def _lookup(
    shadow_map: np.ndarray, view: np.ndarray, px: float, py: float, pz: float, nx: float, ny: float, nz: float,
    lx: float, ly: float, lz: float, softness: float,
) -> float:  # fmt: skip
    """Fraction of the PCF taps around P's image in the map that see P (lit), or −1 if P lies outside the map.

    Normal offset (one texel along the drawn side's normal) and a slope-scaled depth bias
    $texel·(1 + (1 + softness)·min(tan θ, SLOPE_LIMIT))$ against acne; taps on a (2m + 1)² grid spanning
    ±softness texels, each the nearest texel, m = ceil(softness).
    """
    size = shadow_map.shape[0]
    cos_theta = min(abs((nx * lx + ny * ly) + nz * lz), 1.0)
    tan_theta = (
        SLOPE_LIMIT
        if cos_theta * SLOPE_LIMIT <= math.sqrt(1.0 - cos_theta * cos_theta)
        else math.sqrt(1.0 - cos_theta * cos_theta) / cos_theta
    )
    m = view
    texel = m[M_TEXEL]
    if m[M_KIND] != KIND_ORTHOGRAPHIC:  # texel size grows with the distance along the axis
        wd = ((m[12] * px + m[13] * py) + m[14] * pz) + m[15]
        texel *= max(wd, 0.0)
    px, py, pz = px + texel * nx, py + texel * ny, pz + texel * nz
    x = ((m[0] * px + m[1] * py) + m[2] * pz) + m[3]
    y = ((m[4] * px + m[5] * py) + m[6] * pz) + m[7]
    z = ((m[8] * px + m[9] * py) + m[10] * pz) + m[11]
    w = ((m[12] * px + m[13] * py) + m[14] * pz) + m[15]
    if w <= 0.0:
        return -1.0
    x, y, z = x / w, y / w, z / w
    if x < 0.0 or y < 0.0 or x >= size or y >= size:
        return -1.0
    receiver = _linear_depth(view, min(max(z, 0.0), 1.0))
    bias = texel * (1.0 + (1.0 + softness) * tan_theta)
    steps = int(math.ceil(softness))  # noqa: RUF046 (an int in Python, a float's type for Numba's typing)
    step = softness / steps if steps > 0 else 0.0
    lit, taps = 0, 0
    for j in range(-steps, steps + 1):
        ty = y + j * step
        row = size - 1 - int(math.floor(ty))  # noqa: RUF046
        for i in range(-steps, steps + 1):
            tx = x + i * step
            col = int(math.floor(tx))  # noqa: RUF046
            taps += 1
            if row < 0 or row >= size or col < 0 or col >= size:
                lit += 1
                continue
            stored = shadow_map[row, col]
            if stored >= 1.0 or receiver - bias <= _linear_depth(view, stored):
                lit += 1
    return lit / taps


@parallel_kernel(lambda depth, *_: depth.shape[0], work=lambda depth, *_: depth.size, grain=8192)
def map_visibility(
    depth: np.ndarray, points: np.ndarray, facing: np.ndarray, maps: np.ndarray, views: np.ndarray,
    light: np.ndarray, softness: float, visibility: np.ndarray, channel: int,
    start: int, stop: int,
) -> None:  # fmt: skip
    """``visibility[..., channel]`` of one light from its shadow maps (F, S, S) float32 and records (F, MAP_FIELDS):
    one map (directional, spot) or six (a point light's cube, chosen by the major axis of P − light; each face
    ``views[f]`` looks along +x, −x, +y, −y, +z, −z in that order). light: its ``pack_lights`` row. 0 where the
    drawn side faces away from the light (the surface itself is in the way); 1 outside every map.
    """
    kind = light[0]
    for row in range(start, stop):
        for col in range(depth.shape[1]):
            if depth[row, col] >= 1.0:
                continue
            px, py, pz = points[row, col, 0], points[row, col, 1], points[row, col, 2]
            nx, ny, nz = facing[row, col, 0], facing[row, col, 1], facing[row, col, 2]
            if kind == 0.0:
                lx, ly, lz = light[7], light[8], light[9]
            else:
                lx, ly, lz = light[4] - px, light[5] - py, light[6] - pz
                distance = math.sqrt((lx * lx + ly * ly) + lz * lz)
                if distance > 0.0:
                    lx, ly, lz = lx / distance, ly / distance, lz / distance
            if (nx * lx + ny * ly) + nz * lz <= 0.0:
                visibility[row, col, channel] = 0.0
                continue
            face = 0
            if maps.shape[0] == 6:  # cube: the face whose axis is the major axis of P − light
                ax, ay, az = abs(lx), abs(ly), abs(lz)
                if ax >= ay and ax >= az:
                    face = 0 if -lx > 0.0 else 1
                elif ay >= az:
                    face = 2 if -ly > 0.0 else 3
                else:
                    face = 4 if -lz > 0.0 else 5
            found = _lookup(maps[face], views[face], px, py, pz, nx, ny, nz, lx, ly, lz, softness)
            visibility[row, col, channel] = 1.0 if found < 0.0 else found


@kernel
def _illuminate_visible(
    params: np.ndarray, lights: np.ndarray, specular_model: int, seen: np.ndarray, row: int, col: int,
    px: float, py: float, pz: float, nx: float, ny: float, nz: float,
) -> tuple[float, float, float, float, float, float]:  # fmt: skip
    """``raster.shade._illuminate`` with each light's diffuse and specular terms scaled by the fraction
    ``seen[row, col, k]`` of it that reaches the point."""
    ex, ey, ez = params[P_EYE], params[P_EYE + 1], params[P_EYE + 2]
    shininess = params[P_SHININESS]
    kd, ks = params[P_DIFFUSE], params[P_SPECULAR]
    ka = params[P_AMBIENT]
    dr = ka * params[P_LIGHT_AMBIENT]
    dg = ka * params[P_LIGHT_AMBIENT + 1]
    db = ka * params[P_LIGHT_AMBIENT + 2]
    sr, sg, sb = 0.0, 0.0, 0.0
    vx, vy, vz = ex - px, ey - py, ez - pz
    length = math.sqrt((vx * vx + vy * vy) + vz * vz)
    if length > 0.0:
        vx, vy, vz = vx / length, vy / length, vz / length
    for k in range(lights.shape[0]):
        kind = lights[k, 0]
        falloff = float(seen[row, col, k])
        if kind == 0.0:
            lx, ly, lz = lights[k, 7], lights[k, 8], lights[k, 9]
        else:
            lx, ly, lz = lights[k, 4] - px, lights[k, 5] - py, lights[k, 6] - pz
            distance = math.sqrt((lx * lx + ly * ly) + lz * lz)
            lx, ly, lz = lx / distance, ly / distance, lz / distance
            falloff /= (lights[k, 10] + lights[k, 11] * distance) + lights[k, 12] * distance * distance
            if kind == 2.0:
                cos_alpha = -((lx * lights[k, 7] + ly * lights[k, 8]) + lz * lights[k, 9])
                cos_inner, cos_outer = lights[k, 13], lights[k, 14]
                if cos_inner > cos_outer:
                    falloff *= min(max((cos_alpha - cos_outer) / (cos_inner - cos_outer), 0.0), 1.0)
                elif cos_alpha < cos_outer:
                    falloff = 0.0
        ndl = (nx * lx + ny * ly) + nz * lz
        if ndl <= 0.0 or falloff == 0.0:
            continue
        if specular_model == SPECULAR_PHONG:
            rx, ry, rz = 2.0 * ndl * nx - lx, 2.0 * ndl * ny - ly, 2.0 * ndl * nz - lz
            spec = power(max((rx * vx + ry * vy) + rz * vz, 0.0), shininess)
        else:
            hx, hy, hz = lx + vx, ly + vy, lz + vz
            length = math.sqrt((hx * hx + hy * hy) + hz * hz)
            if length > 0.0:
                hx, hy, hz = hx / length, hy / length, hz / length
            spec = power(max((nx * hx + ny * hy) + nz * hz, 0.0), shininess)
        diffuse = kd * (falloff * ndl)
        specular = ks * (falloff * spec)
        dr += diffuse * lights[k, 1]
        dg += diffuse * lights[k, 2]
        db += diffuse * lights[k, 3]
        sr += specular * lights[k, 1]
        sg += specular * lights[k, 2]
        sb += specular * lights[k, 3]
    return dr, dg, db, sr, sg, sb


@parallel_kernel(lambda depth, *_: depth.shape[0], work=lambda depth, *_: depth.size, grain=16384)
def shade_pixels_shadowed(
    depth: np.ndarray, codes: np.ndarray, bary: np.ndarray, faces: np.ndarray, world: np.ndarray, normals: np.ndarray,
    lit: np.ndarray, vertex_colors: np.ndarray, uvs: np.ndarray, texture: np.ndarray,
    params: np.ndarray, lights: np.ndarray, item: np.ndarray, seen: np.ndarray, color: np.ndarray,
    normal_out: np.ndarray, id_out: np.ndarray,
    start: int, stop: int,
) -> None:  # fmt: skip
    """``raster.shade.shade_pixels`` with shadows: each light's terms scaled by ``seen`` (H, W, K) float32.

    Phong: per pixel (``_illuminate_visible``). Gouraud and flat: `lit` (N or M, 3 + 6·K) holds per vertex (per
    face) the ambient term (3) and each light's unshadowed (D, S) (6 each); per pixel the ambient plus each
    light's interpolated (Gouraud) or constant (flat) terms times the pixel's fraction. The other modes ignore
    shadows.
    """
    face_offset = item[I_FACE_OFFSET]
    mode = item[I_MODE]
    for row in range(start, stop):
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
            a, b, c = faces[f, 0], faces[f, 1], faces[f, 2]
            nx, ny, nz, px, py, pz = _surface(f, code % 2 == 1, u0, u1, u2, faces, world, normals)
            alpha = params[P_OPACITY]
            base_r, base_g, base_b = params[P_COLOR], params[P_COLOR + 1], params[P_COLOR + 2]
            if vertex_colors.shape[0] > 0:
                base_r *= _interpolate(u0, u1, u2, vertex_colors[a, 0], vertex_colors[b, 0], vertex_colors[c, 0])
                base_g *= _interpolate(u0, u1, u2, vertex_colors[a, 1], vertex_colors[b, 1], vertex_colors[c, 1])
                base_b *= _interpolate(u0, u1, u2, vertex_colors[a, 2], vertex_colors[b, 2], vertex_colors[c, 2])
            if texture.shape[0] > 0:
                tu = _interpolate(u0, u1, u2, uvs[a, 0], uvs[b, 0], uvs[c, 0])
                tv = _interpolate(u0, u1, u2, uvs[a, 1], uvs[b, 1], uvs[c, 1])
                texel_r, texel_g, texel_b, texel_a = _sample(texture, tu, tv)
                base_r *= texel_r
                base_g *= texel_g
                base_b *= texel_b
                alpha *= texel_a
            if mode == SHADE_NONE:
                r, g, b = base_r, base_g, base_b
            else:
                if mode == SHADE_PHONG:
                    dr, dg, db, sr, sg, sb = _illuminate_visible(
                        params, lights, item[I_SPECULAR_MODEL], seen, row, col, px, py, pz, nx, ny, nz
                    )
                else:
                    flat = mode == SHADE_FLAT
                    dr, dg, db, sr, sg, sb = 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
                    for k in range(-1, lights.shape[0]):
                        base = 3 + 6 * k if k >= 0 else 0
                        fraction = float(seen[row, col, k]) if k >= 0 else 1.0
                        for q in range(6 if k >= 0 else 3):
                            if flat:
                                value = lit[f, base + q]
                            else:
                                value = _interpolate(u0, u1, u2, lit[a, base + q], lit[b, base + q], lit[c, base + q])
                            value *= fraction
                            if q == 0:
                                dr += value
                            elif q == 1:
                                dg += value
                            elif q == 2:
                                db += value
                            elif q == 3:
                                sr += value
                            elif q == 4:
                                sg += value
                            else:
                                sb += value
                r = (base_r * dr + sr) + params[P_EMISSIVE]
                g = (base_g * dg + sg) + params[P_EMISSIVE + 1]
                b = (base_b * db + sb) + params[P_EMISSIVE + 2]
            if params[P_CUE_ON] != 0.0:
                d = 0.0
                d += (params[P_EYE] - px) * params[P_VIEW_AXIS]
                d += (params[P_EYE + 1] - py) * params[P_VIEW_AXIS + 1]
                d += (params[P_EYE + 2] - pz) * params[P_VIEW_AXIS + 2]
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
