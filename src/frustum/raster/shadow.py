"""Shadow kernels: surface points per pixel, shadow-map lookups with percentage-closer filtering, and the shading of
pixels with a visibility factor per light (shadow rays go through ``Scene.occluded``, ``raster.rays``).

None of these runs on an ordinary render: they compile only when ``render(..., shadows=...)`` or the
``"position"``/``"shadow"`` buffers ask for them (``frustum.render.shadows.fractions`` drives them).

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
from frustum.raster.fixed_point import HALF_SUBPIXEL, SUBPIXEL
from frustum.raster.light import light_terms
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
    _cue,
    _interpolate,
    _sample,
    _surface,
    _to_byte,
)  # fmt: skip
from frustum.raster.triangles import (
    _ALPHA,
    _BETA,
    _FLOAT_ROWS,
    _GENERAL,
    _IMAX,
    _IMIN,
    _INT_ROWS,
    _JMAX,
    _JMIN,
    _KIND,
    _LOWEST_BIT,
    _X0,
    _X1,
    _X2,
    _Y0,
    _Y1,
    _Y2,
    _Z0,
    FILL_BLOCK,
    _setup_entries,
    _span,
)  # fmt: skip

__all__ = [
    "MAP_FIELDS", "fill_depth_tiles", "map_visibility", "shade_pixels_shadowed", "surface_points",
]  # fmt: skip

# map record layout
M_MATRIX, M_KIND, M_NEAR, M_FAR, M_TEXEL, M_LIGHT = 0, 16, 17, 18, 19, 20
MAP_FIELDS = 23
KIND_ORTHOGRAPHIC, KIND_PERSPECTIVE = 0.0, 1.0
SLOPE_LIMIT = 8.0
"""Largest tan θ the slope-scaled bias uses (θ: angle between the surface normal and the light): grazing faces
are barely lit, and a larger bias would detach shadows from their casters."""


# kernel specialisation kept on purpose: the pixel loop and face decoding of shade_pixels_shadowed below
@parallel_kernel(lambda depth, *_: depth.shape[0], work=lambda depth, *_: depth.size, grain=16384)
def surface_points(
    depth: np.ndarray, codes: np.ndarray, bary: np.ndarray, faces: np.ndarray, world: np.ndarray,
    face_offset: int, points: np.ndarray, facing: np.ndarray, normals: bool,
    start: int, stop: int,
) -> None:  # fmt: skip
    """World point $(u0·Pa + u1·Pb) + u2·Pc$ and, where `normals`, unit face normal (turned toward the viewer:
    flipped for a back face drawn two-sided) of every pixel of one item (face $code // 2 − face_offset$ in [0, M)).

    depth (H, W) float32, codes (H, W) int, bary (H, W, 2) float32, faces (M, 3) int64 counter-clockwise seen from
    the front, world (N, 3) float; points and facing (H, W, 3) float64 written at those pixels only (facing not
    read where not `normals`: any (1, 1, 3) array).
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
            if not normals:
                continue
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
    $texel·(1 + (1 + softness)·min(tan θ, SLOPE_LIMIT))$ against acne. Softness 0: the nearest texel (hard);
    0 < softness <= 1: the four texels around P's image bilinearly weighted (the GPU's ``sampler2DShadow`` with
    linear filtering, 2 × 2 PCF), each weight ramping over `softness` texels (1: plain bilinear); softness > 1:
    taps on a (2m + 1)² grid spanning ±softness texels, each the nearest texel, m = ceil(softness).
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
    if 0.0 < softness <= 1.0:  # the four texels around P, bilinearly weighted (ramps `softness` texels wide)
        gx, gy = x - 0.5, y - 0.5
        fx, fy = math.floor(gx), math.floor(gy)
        col, up = int(fx), int(fy)
        wx = min(max((gx - fx - 0.5) / softness + 0.5, 0.0), 1.0)
        wy = min(max((gy - fy - 0.5) / softness + 0.5, 0.0), 1.0)
        limit, row = receiver - bias, size - 1 - up
        t00, t10, t01, t11 = 1.0, 1.0, 1.0, 1.0  # inline: a call taking the map costs reference counting
        if 0 <= row < size:
            if 0 <= col < size:
                stored = shadow_map[row, col]
                t00 = 1.0 if stored >= 1.0 or limit <= _linear_depth(view, stored) else 0.0
            if 0 <= col + 1 < size:
                stored = shadow_map[row, col + 1]
                t10 = 1.0 if stored >= 1.0 or limit <= _linear_depth(view, stored) else 0.0
        if 0 <= row - 1 < size:
            if 0 <= col < size:
                stored = shadow_map[row - 1, col]
                t01 = 1.0 if stored >= 1.0 or limit <= _linear_depth(view, stored) else 0.0
            if 0 <= col + 1 < size:
                stored = shadow_map[row - 1, col + 1]
                t11 = 1.0 if stored >= 1.0 or limit <= _linear_depth(view, stored) else 0.0
        return (1.0 - wy) * ((1.0 - wx) * t00 + wx * t10) + wy * ((1.0 - wx) * t01 + wx * t11)
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


# kernel specialisation kept on purpose: the light loop of raster.volume's gradient shading, with fractions
@kernel
def _illuminate_visible(
    params: np.ndarray, lights: np.ndarray, specular_model: int, seen: np.ndarray, row: int, col: int,
    px: float, py: float, pz: float, nx: float, ny: float, nz: float,
) -> tuple[float, float, float, float, float, float]:  # fmt: skip
    """``raster.shade._illuminate`` with each light's visibility the fraction ``seen[row, col, k]`` of it that
    reaches the point (``raster.light.light_terms`` scales its diffuse and specular terms)."""
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
        visible = float(seen[row, col, k])
        lit, lambert, spec = light_terms(lights, k, specular_model, shininess, visible, px, py, pz, nx, ny, nz,
                                         vx, vy, vz)  # fmt: skip
        if not lit:
            continue
        diffuse = kd * lambert
        specular = ks * spec
        dr += diffuse * lights[k, 1]
        dg += diffuse * lights[k, 2]
        db += diffuse * lights[k, 3]
        sr += specular * lights[k, 1]
        sg += specular * lights[k, 2]
        sb += specular * lights[k, 3]
    return dr, dg, db, sr, sg, sb


# Kernel specialization kept on purpose: ``raster.shade.shade_pixels`` with each light's fraction (the visibility
# argument of ``raster.light.light_terms``); apart, so frames without shadows compile no fraction arrays.
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
            # kernel specialisation kept on purpose: raster.shade._shade_row's cue, blend and store, per pixel here
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


MAP_NARROW = 24
"""Boxes of a shadow-map triangle at most this wide test every centre of each row without a branch (vectorized);
wider ones find each row's covered span first. A 2048² map of bunny_like_100k (median box 11 texels): 2× faster
than the branching test of ``triangles._fill_tile`` (whose threshold is 8)."""


@parallel_kernel(lambda *args: args[5].shape[0] - 1, work=lambda *args: args[6].shape[0], grain=256)
def fill_depth_tiles(
    faces: np.ndarray, win_int: np.ndarray, win_float: np.ndarray, tri_int: np.ndarray, tri_float: np.ndarray,
    tile_starts: np.ndarray, tile_entries: np.ndarray, tiling: np.ndarray, depth: np.ndarray, fresh: bool,
    start: int, stop: int,
) -> None:  # fmt: skip
    """A shadow map: ``triangles.rasterize_tiles`` writing depth alone (no face codes or weights), each tile filled
    in a contiguous tile-sized buffer (it stays in L1 cache whatever the map's row stride), then copied out. The
    buffer starts cleared to 1.0 where `fresh` (the whole map is written: no clear first), else as the map's tile
    (a later item). The same depths as ``rasterize_tiles`` (the same set-up, formulas and order)."""
    size, tiles_x, width, height = tiling[0], tiling[1], tiling[3], tiling[4]
    near = np.empty((size, size), dtype=np.float32)
    block = np.empty(_INT_ROWS * FILL_BLOCK, dtype=np.int64)
    values = np.empty(_FLOAT_ROWS * FILL_BLOCK)
    for t in range(start, stop):
        col0 = (t % tiles_x) * size
        col1 = min(col0 + size, width)
        row0 = (t // tiles_x) * size
        row1 = min(row0 + size, height)
        top = height - row1  # image rows [top, top + row1 − row0) hold window rows [row0, row1), top row first
        if fresh:
            near[:, :] = 1.0
        else:
            for r in range(row1 - row0):
                for c in range(col1 - col0):
                    near[np.uint64(r), np.uint64(c)] = depth[np.uint64(top + r), np.uint64(col0 + c)]
        _fill_depth_tile(t, faces, win_int, win_float, tri_int, tri_float, tile_starts, tile_entries, tiling,
                         near, block, values, top, col0, col1, row0, row1)  # fmt: skip
        for r in range(row1 - row0):
            for c in range(col1 - col0):
                depth[np.uint64(top + r), np.uint64(col0 + c)] = near[np.uint64(r), np.uint64(c)]


# Kernel specialization kept on purpose: ``raster.triangles._fill_tile`` writing depth alone (a shadow map).
@kernel
def _fill_depth_tile(
    tile: int, faces: np.ndarray, win_int: np.ndarray, win_float: np.ndarray, tri_int: np.ndarray,
    tri_float: np.ndarray, tile_starts: np.ndarray, tile_entries: np.ndarray, tiling: np.ndarray, depth: np.ndarray,
    block: np.ndarray, values: np.ndarray, origin_row: int, col0: int, col1: int, row0: int, row1: int,
) -> None:  # fmt: skip
    """``triangles._fill_tile`` for depth alone: image pixel (row, col) is ``depth[row - origin_row, col - col0]``."""
    face_offset, height = tiling[2], tiling[4]
    first_slot, last_slot = tile_starts[tile], tile_starts[tile + 1]
    top = height - 1 - origin_row
    for first in range(first_slot, last_slot, FILL_BLOCK):
        m = min(first + FILL_BLOCK, last_slot) - first
        _setup_entries(
            tile_entries, first, first + m, faces, win_int, win_float, tri_int, tri_float, face_offset, block, values,
            last_slot, col0, col1, row0, row1,
        )  # fmt: skip
        for n in range(m):
            u = np.uint64(n)
            kind = block[u + _KIND]
            if kind == 0:
                continue
            x0, y0, x1, y1 = block[u + _X0], block[u + _Y0], block[u + _X1], block[u + _Y1]
            x2, y2 = block[u + _X2], block[u + _Y2]
            i_min, j_min = block[u + _IMIN], block[u + _JMIN]
            z0, alpha, beta = values[u + _Z0], values[u + _ALPHA], values[u + _BETA]
            if kind < _GENERAL:  # a box of at most 2 × 2 centres: only the covered ones (the mask)
                mask = kind
                while mask != 0:
                    k = _LOWEST_BIT[mask]
                    mask &= mask - 1
                    ci, cj = k & 1, k >> 1
                    py, px = SUBPIXEL * (j_min + cj) + HALF_SUBPIXEL, SUBPIXEL * (i_min + ci) + HALF_SUBPIXEL
                    z = np.float32((z0 + beta * float(py - y0)) + alpha * float(px - x0))
                    at_row, at = np.uint64(top - (j_min + cj)), np.uint64(i_min + ci - col0)
                    if z < depth[at_row, at]:
                        depth[at_row, at] = z
                continue
            i_max, j_max = block[u + _IMAX], block[u + _JMAX]
            # kernel specialisation kept on purpose: raster.window.edge_setup's edges and top-left biases
            dx0, dy0 = x2 - x1, y2 - y1
            dx1, dy1 = x0 - x2, y0 - y2
            dx2, dy2 = x1 - x0, y1 - y0
            bias0 = 0 if (dy0 < 0 or (dy0 == 0 and dx0 < 0)) else 1
            bias1 = 0 if (dy1 < 0 or (dy1 == 0 and dx1 < 0)) else 1
            bias2 = 0 if (dy2 < 0 or (dy2 == 0 and dx2 < 0)) else 1
            px0 = SUBPIXEL * i_min + HALF_SUBPIXEL
            columns = i_max - i_min + 1
            step0, step1, step2 = dy0 * SUBPIXEL, dy1 * SUBPIXEL, dy2 * SUBPIXEL
            inverse0, inverse1, inverse2 = 0.0, 0.0, 0.0
            if columns > MAP_NARROW:
                inverse0 = 1.0 / step0 if step0 != 0 else 0.0
                inverse1 = 1.0 / step1 if step1 != 0 else 0.0
                inverse2 = 1.0 / step2 if step2 != 0 else 0.0
            for j in range(j_min, j_max + 1):
                py = SUBPIXEL * j + HALF_SUBPIXEL
                e0 = dx0 * (py - y1) - dy0 * (px0 - x1)
                e1 = dx1 * (py - y2) - dy1 * (px0 - x2)
                e2 = dx2 * (py - y0) - dy2 * (px0 - x0)
                z_row = z0 + beta * float(py - y0)
                at_row = np.uint64(top - j)
                first_column, last_column = 0, columns - 1
                if columns > MAP_NARROW:  # a wide box: the row's covered centres found first (_span)
                    first_column, last_column = _span(e0, step0, bias0, inverse0, first_column, last_column)
                    first_column, last_column = _span(e1, step1, bias1, inverse1, first_column, last_column)
                    first_column, last_column = _span(e2, step2, bias2, inverse2, first_column, last_column)
                    for k in range(first_column, last_column + 1):
                        # X_P − X_0 as an integer: the same float as _fill_tile's running sum, no chain
                        z = np.float32(z_row + alpha * float(px0 - x0 + SUBPIXEL * k))
                        at = np.uint64(i_min + k - col0)
                        if z < depth[at_row, at]:
                            depth[at_row, at] = z
                    continue
                for k in range(columns):  # every centre of the box, without a branch (LLVM vectorizes it)
                    at = np.uint64(i_min + k - col0)
                    d = depth[at_row, at]
                    z = np.float32(z_row + alpha * float(px0 - x0 + SUBPIXEL * k))
                    inside = (e0 - step0 * k >= bias0) & (e1 - step1 * k >= bias1) & (e2 - step2 * k >= bias2)
                    depth[at_row, at] = z if inside & (z < d) else d


@kernel
def fit_points(points: np.ndarray, view: np.ndarray, bounds: np.ndarray) -> None:
    """One pass over the (N >= 1, 3) points: ``bounds`` (4, 3) float64 gets their box (rows 0, 1: lowest and
    highest x, y, z) and the box of their light-view coordinates (rows 2, 3), the coordinate along row r of the
    (3, 3) `view` being $(p_0·v_{r0} + p_1·v_{r1}) + p_2·v_{r2}$ (``shadow_pass.view_map``'s order)."""
    for a in range(3):
        bounds[0, a], bounds[1, a] = math.inf, -math.inf
        bounds[2, a], bounds[3, a] = math.inf, -math.inf
    v00, v01, v02 = view[0, 0], view[0, 1], view[0, 2]
    v10, v11, v12 = view[1, 0], view[1, 1], view[1, 2]
    v20, v21, v22 = view[2, 0], view[2, 1], view[2, 2]
    lx, ly, lz, hx, hy, hz = math.inf, math.inf, math.inf, -math.inf, -math.inf, -math.inf
    la, lb, lc, ha, hb, hc = math.inf, math.inf, math.inf, -math.inf, -math.inf, -math.inf
    for i in range(points.shape[0]):
        x, y, z = float(points[i, 0]), float(points[i, 1]), float(points[i, 2])
        lx, ly, lz = min(lx, x), min(ly, y), min(lz, z)
        hx, hy, hz = max(hx, x), max(hy, y), max(hz, z)
        a = (x * v00 + y * v01) + z * v02
        b = (x * v10 + y * v11) + z * v12
        c = (x * v20 + y * v21) + z * v22
        la, lb, lc = min(la, a), min(lb, b), min(lc, c)
        ha, hb, hc = max(ha, a), max(hb, b), max(hc, c)
    bounds[0, 0], bounds[0, 1], bounds[0, 2] = lx, ly, lz
    bounds[1, 0], bounds[1, 1], bounds[1, 2] = hx, hy, hz
    bounds[2, 0], bounds[2, 1], bounds[2, 2] = la, lb, lc
    bounds[3, 0], bounds[3, 1], bounds[3, 2] = ha, hb, hc


_MIX = np.uint64(0x9E3779B97F4A7C15)
_MIX2 = np.uint64(0xBF58476D1CE4E5B9)


@kernel
def fingerprint(words: np.ndarray, seed: np.uint64) -> np.uint64:
    """A 64-bit fingerprint of the 1-D uint64 `words` (an array's bytes): four interleaved multiply–xorshift lanes
    (every bit of every word reaches the result; not cryptographic), folded with the count. Used to tell a shadow
    map's casters apart from the last frame's (``shadow_pass``), ~0.05 ms per MiB."""
    h0, h1 = seed ^ _MIX, seed ^ _MIX2
    h2, h3 = (seed + _MIX) * _MIX2, (seed + _MIX2) * _MIX
    n = words.shape[0]
    quads = n // 4
    for q in range(quads):
        at = 4 * q
        h0 = (h0 ^ words[at]) * _MIX
        h1 = (h1 ^ words[at + 1]) * _MIX
        h2 = (h2 ^ words[at + 2]) * _MIX
        h3 = (h3 ^ words[at + 3]) * _MIX
        h0 ^= h0 >> np.uint64(29)
        h1 ^= h1 >> np.uint64(29)
        h2 ^= h2 >> np.uint64(29)
        h3 ^= h3 >> np.uint64(29)
    for at in range(4 * quads, n):
        h0 = (h0 ^ words[at]) * _MIX
        h0 ^= h0 >> np.uint64(29)
    h = h0 ^ (h1 * _MIX2) ^ ((h2 ^ (h2 >> np.uint64(31))) * _MIX) ^ ((h3 ^ (h3 >> np.uint64(27))) * _MIX2)
    h ^= np.uint64(n)
    h = (h ^ (h >> np.uint64(30))) * _MIX2
    h = (h ^ (h >> np.uint64(27))) * _MIX
    return h ^ (h >> np.uint64(31))
