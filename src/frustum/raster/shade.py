"""Shading kernels: the illumination model of ``frustum.shading`` per vertex, per face or per pixel.

Deferred: after the depth buffer is complete, each pixel holds $code = 2·face + back$ (−1: background) and
the perspective-correct weights (u1, u2) of its surface point with respect to the face's corners
(u0 = 1 − u1 − u2). Every model writes, per channel,

    I = base·D + S + emissive,  base = color · vertex color · texture(u, v)

with D = k_a·I_a + Σ f·k_d·I_l·max(N·L, 0) (ambient + diffuse) and S = Σ f·k_s·I_l·spec (specular), where
the models differ only in where D and S are evaluated [HB 17] "Polygon Rendering Methods":

- ``SHADE_FLAT``: once per face, with the face normal at the face centroid (constant-intensity shading);
- ``SHADE_GOURAUD``: once per vertex with the vertex normal, D and S interpolated across the face;
- ``SHADE_PHONG``: per pixel with the interpolated, renormalized normal (normal-vector interpolation);
- ``SHADE_NONE``: base color only; ``SHADE_NORMALS``: $0.5·N + 0.5$ (world normal); ``SHADE_DEPTH``: gray
  $(far − d)/(far − near)$ of the view distance d.

A back face drawn two-sided has its normal flipped toward the viewer. Depth cueing then blends
$f·I + (1 − f)·cue$; the result is clamped to [0, 1] and stored as $floor(I·255 + 0.5)$.

Array contracts (kernels never validate): params (PARAMS,) float64 laid out by the ``P_*`` indices below,
lights (K, 16) float64 rows of ``frustum.shading.pack_lights``, item (ITEM,) int64 laid out by ``I_*``.
"""

from __future__ import annotations

import math

import numpy as np

from frustum.raster._jit import kernel, parallel_kernel, prefetch
from frustum.raster.light import SPECULAR_BLINN as SPECULAR_BLINN
from frustum.raster.light import SPECULAR_PHONG as SPECULAR_PHONG
from frustum.raster.light import light_terms, power
from frustum.raster.power import SQUARING_MAX

__all__ = [
    "SHADE_DEPTH",
    "SHADE_FLAT",
    "SHADE_GOURAUD",
    "SHADE_NONE",
    "SHADE_NORMALS",
    "SHADE_PHONG",
    "light_faces",
    "light_vertices",
    "power",
    "shade_pixels",
    "shade_pixels_directional",
    "shade_pixels_phong",
]

SHADE_NONE, SHADE_PHONG, SHADE_FLAT, SHADE_GOURAUD, SHADE_NORMALS, SHADE_DEPTH = 0, 1, 2, 3, 4, 5

# params layout
P_EYE, P_COLOR, P_AMBIENT, P_DIFFUSE, P_SPECULAR, P_SHININESS = 0, 3, 6, 7, 8, 9
P_EMISSIVE, P_LIGHT_AMBIENT, P_VIEW_AXIS = 10, 13, 16
P_CUE_ON, P_CUE_NEAR, P_CUE_FAR, P_CUE_MIN, P_CUE_MAX, P_CUE_COLOR = 19, 20, 21, 22, 23, 24
P_DEPTH_NEAR, P_DEPTH_FAR, P_OPACITY = 27, 28, 29
PARAMS = 30
# item layout
I_FACE_OFFSET, I_MODE, I_SPECULAR_MODEL, I_OBJECT_ID, I_WRITE_NORMALS, I_WRITE_IDS, I_BLEND = 0, 1, 2, 3, 4, 5, 6
ITEM = 7


@kernel
def _to_byte(value: float) -> np.uint8:
    """$floor(clamp(v, 0, 1)·255 + 0.5)$: round half up to 8 bits."""
    return np.uint8(math.floor(min(max(value, 0.0), 1.0) * 255.0 + 0.5))


@kernel
def _interpolate(u0: float, u1: float, u2: float, va: float, vb: float, vc: float) -> float:
    """$(u0·va + u1·vb) + u2·vc$ (scalar arguments only: per-pixel helpers take no arrays, so they inline)."""
    return (u0 * va + u1 * vb) + u2 * vc


@kernel
def _squarable(n: float) -> bool:
    """Whether ``power`` takes x^n by repeated squaring: n integral in [0, SQUARING_MAX]."""
    return n == math.floor(n) and 0.0 <= n <= SQUARING_MAX




@kernel
def _illuminate(
    params: np.ndarray, lights: np.ndarray, specular_model: int,
    px: float, py: float, pz: float, nx: float, ny: float, nz: float,
) -> tuple[float, float, float, float, float, float]:  # fmt: skip
    """(D_r, D_g, D_b, S_r, S_g, S_b) at point P with unit normal N: the module docstring's D and S, each light's
    terms by ``raster.light.light_terms`` (unshadowed: visibility 1)."""
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
        lit, lambert, spec = light_terms(lights, k, specular_model, shininess, 1.0, px, py, pz, nx, ny, nz, vx, vy, vz)
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


@parallel_kernel(lambda world, *_: world.shape[0], grain=1024)
def light_vertices(
    world: np.ndarray, normals: np.ndarray, params: np.ndarray, lights: np.ndarray, specular_model: int,
    lit: np.ndarray,
    start: int, stop: int,
) -> None:  # fmt: skip
    """Gouraud: D and S at every vertex with its unit normal; lit (N, 6) float64 written."""
    for v in range(start, stop):
        terms = _illuminate(
            params, lights, specular_model, world[v, 0], world[v, 1], world[v, 2],
            normals[v, 0], normals[v, 1], normals[v, 2],
        )  # fmt: skip
        for k in range(6):
            lit[v, k] = terms[k]


@parallel_kernel(lambda world, faces, *_: faces.shape[0], grain=1024)
def light_faces(
    world: np.ndarray, faces: np.ndarray, params: np.ndarray, lights: np.ndarray, specular_model: int,
    lit: np.ndarray,
    start: int, stop: int,
) -> None:  # fmt: skip
    """Flat: D and S of every face at its centroid with the unit face normal $(v1 − v0)×(v2 − v0)$; lit (M, 6)."""
    for f in range(start, stop):
        a, b, c = faces[f, 0], faces[f, 1], faces[f, 2]
        e1x, e1y, e1z = world[b, 0] - world[a, 0], world[b, 1] - world[a, 1], world[b, 2] - world[a, 2]
        e2x, e2y, e2z = world[c, 0] - world[a, 0], world[c, 1] - world[a, 1], world[c, 2] - world[a, 2]
        nx, ny, nz = e1y * e2z - e1z * e2y, e1z * e2x - e1x * e2z, e1x * e2y - e1y * e2x
        length = math.sqrt((nx * nx + ny * ny) + nz * nz)
        if length == 0.0:
            nx, ny, nz, length = 0.0, 0.0, 1.0, 1.0
        terms = _illuminate(
            params, lights, specular_model,
            (world[a, 0] + world[b, 0] + world[c, 0]) / 3.0,
            (world[a, 1] + world[b, 1] + world[c, 1]) / 3.0,
            (world[a, 2] + world[b, 2] + world[c, 2]) / 3.0,
            nx / length, ny / length, nz / length,
        )  # fmt: skip
        for k in range(6):
            lit[f, k] = terms[k]


@kernel
def _sample(texture: np.ndarray, u: float, v: float) -> tuple[float, float, float, float]:
    """Bilinear texture lookup (r, g, b, a) with repeat wrapping; v = 0 is the image's bottom row (OpenGL, OBJ)."""
    height, width = texture.shape[0], texture.shape[1]
    x = (u - math.floor(u)) * width - 0.5
    y = (1.0 - (v - math.floor(v))) * height - 0.5
    x0, y0 = math.floor(x), math.floor(y)
    fx, fy = x - x0, y - y0
    i0, j0 = int(x0) % width, int(y0) % height
    i1, j1 = (i0 + 1) % width, (j0 + 1) % height
    gx, gy = 1.0 - fx, 1.0 - fy
    r0 = texture[j0, i0, 0] * gx + texture[j0, i1, 0] * fx
    r1 = texture[j1, i0, 0] * gx + texture[j1, i1, 0] * fx
    g0 = texture[j0, i0, 1] * gx + texture[j0, i1, 1] * fx
    g1 = texture[j1, i0, 1] * gx + texture[j1, i1, 1] * fx
    b0 = texture[j0, i0, 2] * gx + texture[j0, i1, 2] * fx
    b1 = texture[j1, i0, 2] * gx + texture[j1, i1, 2] * fx
    a0 = texture[j0, i0, 3] * gx + texture[j0, i1, 3] * fx
    a1 = texture[j1, i0, 3] * gx + texture[j1, i1, 3] * fx
    return r0 * gy + r1 * fy, g0 * gy + g1 * fy, b0 * gy + b1 * fy, a0 * gy + a1 * fy


@kernel
def _surface(
    f: int, back: bool, u0: float, u1: float, u2: float, faces: np.ndarray, world: np.ndarray, normals: np.ndarray
) -> tuple[float, float, float, float, float, float]:  # fmt: skip
    """(N, P) of face f at weights (u0, u1, u2): the unit interpolated normal, flipped for a back face drawn
    two-sided (so it faces the viewer), and the world point."""
    a, b, c = faces[f, 0], faces[f, 1], faces[f, 2]
    sign = -1.0 if back else 1.0
    nx = _interpolate(u0, u1, u2, normals[a, 0], normals[b, 0], normals[c, 0])
    ny = _interpolate(u0, u1, u2, normals[a, 1], normals[b, 1], normals[c, 1])
    nz = _interpolate(u0, u1, u2, normals[a, 2], normals[b, 2], normals[c, 2])
    length = math.sqrt((nx * nx + ny * ny) + nz * nz)
    if length == 0.0:
        nx, ny, nz, length = 0.0, 0.0, 1.0, 1.0
    nx, ny, nz = sign * nx / length, sign * ny / length, sign * nz / length
    px = _interpolate(u0, u1, u2, world[a, 0], world[b, 0], world[c, 0])
    py = _interpolate(u0, u1, u2, world[a, 1], world[b, 1], world[c, 1])
    pz = _interpolate(u0, u1, u2, world[a, 2], world[b, 2], world[c, 2])
    return nx, ny, nz, px, py, pz


@kernel
def shade_point(
    f: int, back: bool, u0: float, u1: float, u2: float,
    faces: np.ndarray, world: np.ndarray, normals: np.ndarray, lit: np.ndarray,
    vertex_colors: np.ndarray, uvs: np.ndarray, texture: np.ndarray,
    params: np.ndarray, lights: np.ndarray, item: np.ndarray,
) -> tuple[float, float, float, float, float, float, float]:  # fmt: skip
    """Linear (r, g, b, alpha) of face f's point with weights (u0, u1, u2), and its unit world normal (3).

    Alpha is the texture's alpha times the material opacity. Colors are not clamped yet.
    """
    mode = item[I_MODE]
    a, b, c = faces[f, 0], faces[f, 1], faces[f, 2]
    nx, ny, nz, px, py, pz = _surface(f, back, u0, u1, u2, faces, world, normals)
    alpha = params[P_OPACITY]
    if mode == SHADE_NORMALS:
        return 0.5 * nx + 0.5, 0.5 * ny + 0.5, 0.5 * nz + 0.5, alpha, nx, ny, nz
    if mode == SHADE_DEPTH:
        d = ((params[P_EYE] - px) * params[P_VIEW_AXIS] + (params[P_EYE + 1] - py) * params[P_VIEW_AXIS + 1]) + (
            params[P_EYE + 2] - pz
        ) * params[P_VIEW_AXIS + 2]
        gray = (params[P_DEPTH_FAR] - d) / (params[P_DEPTH_FAR] - params[P_DEPTH_NEAR])
        return gray, gray, gray, alpha, nx, ny, nz
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
        return base_r, base_g, base_b, alpha, nx, ny, nz
    if mode == SHADE_PHONG:
        dr, dg, db, sr, sg, sb = _illuminate(params, lights, item[I_SPECULAR_MODEL], px, py, pz, nx, ny, nz)
    elif mode == SHADE_FLAT:
        dr, dg, db, sr, sg, sb = lit[f, 0], lit[f, 1], lit[f, 2], lit[f, 3], lit[f, 4], lit[f, 5]
    else:  # Gouraud
        dr = _interpolate(u0, u1, u2, lit[a, 0], lit[b, 0], lit[c, 0])
        dg = _interpolate(u0, u1, u2, lit[a, 1], lit[b, 1], lit[c, 1])
        db = _interpolate(u0, u1, u2, lit[a, 2], lit[b, 2], lit[c, 2])
        sr = _interpolate(u0, u1, u2, lit[a, 3], lit[b, 3], lit[c, 3])
        sg = _interpolate(u0, u1, u2, lit[a, 4], lit[b, 4], lit[c, 4])
        sb = _interpolate(u0, u1, u2, lit[a, 5], lit[b, 5], lit[c, 5])
    r = (base_r * dr + sr) + params[P_EMISSIVE]
    g = (base_g * dg + sg) + params[P_EMISSIVE + 1]
    b = (base_b * db + sb) + params[P_EMISSIVE + 2]
    return r, g, b, alpha, nx, ny, nz


@kernel
def _cue(params: np.ndarray, r: float, g: float, b: float, d: float) -> tuple[float, float, float]:
    """Depth cueing $f·I + (1 − f)·cue$ per channel, f clamped to [f_min, f_max], at view distance d."""
    low, high = params[P_CUE_MIN], params[P_CUE_MAX]
    f = low + (high - low) * (params[P_CUE_FAR] - d) / (params[P_CUE_FAR] - params[P_CUE_NEAR])
    f = min(max(f, low), high)
    cue = params[P_CUE_COLOR : P_CUE_COLOR + 3]
    return f * r + (1.0 - f) * cue[0], f * g + (1.0 - f) * cue[1], f * b + (1.0 - f) * cue[2]


@parallel_kernel(lambda depth, codes, *_: codes.shape[0], work=lambda depth, *_: depth.size, grain=16384)
def shade_pixels(
    depth: np.ndarray, codes: np.ndarray, bary: np.ndarray, faces: np.ndarray, world: np.ndarray, normals: np.ndarray,
    lit: np.ndarray, vertex_colors: np.ndarray, uvs: np.ndarray, texture: np.ndarray,
    params: np.ndarray, lights: np.ndarray, item: np.ndarray, color: np.ndarray,
    normal_out: np.ndarray, id_out: np.ndarray,
    start: int, stop: int,
) -> None:  # fmt: skip
    """Shade the pixels of one scene item: those whose face $code // 2 − face_offset$ lies in [0, M).

    depth (H, W) float32, codes (H, W) int32 or int64, bary (H, W, 2) float32, faces (M, 3) int64, world and
    normals (N, 3) float64 (unit normals), lit (N or M, 6) Gouraud or flat terms (any rows otherwise),
    vertex_colors (N, 3) or (0, 3), uvs (N, 2) and texture (Ht, Wt, 4) float32 or empty. color (H, W, 4) uint8 is
    written at those pixels (opaque, or blended $α·I + (1 − α)·under$ when ``item[I_BLEND]``); background
    pixels (depth 1: nothing drawn, so their codes are never read and need no clearing) and codes < 0 are left
    alone. normal_out (H, W, 3) float32 and id_out (H, W) int32 are written when asked for.
    """
    for row in range(start, stop):
        _shade_row(
            row, depth, codes, bary, faces, world, normals, lit, vertex_colors, uvs, texture, params, lights, item,
            color, normal_out, id_out,
        )  # fmt: skip


@kernel
def _shade_row(
    row: int, depth: np.ndarray, codes: np.ndarray, bary: np.ndarray, faces: np.ndarray, world: np.ndarray,
    normals: np.ndarray, lit: np.ndarray, vertex_colors: np.ndarray, uvs: np.ndarray, texture: np.ndarray,
    params: np.ndarray, lights: np.ndarray, item: np.ndarray, color: np.ndarray,
    normal_out: np.ndarray, id_out: np.ndarray,
) -> None:  # fmt: skip
    """One image row of ``shade_pixels``."""
    face_offset = item[I_FACE_OFFSET]
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
        r, g, b, alpha, nx, ny, nz = shade_point(
            f, code % 2 == 1, u0, u1, u2, faces, world, normals, lit, vertex_colors, uvs, texture, params,
            lights, item,
        )  # fmt: skip
        # kernel specialisation kept on purpose: cue, blend and store repeated in shadow.shade_pixels_shadowed and
        # raster.pbr's pixel loop
        if params[P_CUE_ON] != 0.0:
            a, bb, c = faces[f, 0], faces[f, 1], faces[f, 2]
            d = 0.0
            for k in range(3):
                p = _interpolate(u0, u1, u2, world[a, k], world[bb, k], world[c, k])
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


# Kernel specialization kept on purpose (docs/architecture.md): ``shade_pixels`` for per-pixel Phong alone, half
# its time; the light itself is the same ``_illuminate`` (``raster.light.light_terms``).
@parallel_kernel(lambda depth, codes, *_: codes.shape[0], work=lambda depth, *_: depth.size, grain=16384)
def shade_pixels_phong(
    depth: np.ndarray, codes: np.ndarray, bary: np.ndarray, faces: np.ndarray, world: np.ndarray,
    normals: np.ndarray, params: np.ndarray, lights: np.ndarray, item: np.ndarray, color: np.ndarray,
    start: int, stop: int,
) -> None:  # fmt: skip
    """``shade_pixels`` specialized to per-pixel Phong shading with any lights, bit for bit, and nothing else: no
    texture, vertex colors, depth cueing, blending or extra buffers (the README example's case). It compiles in
    half the time of the general kernel, which holds every model and option."""
    face_offset = item[I_FACE_OFFSET]
    specular_model = item[I_SPECULAR_MODEL]
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
            nx, ny, nz, px, py, pz = _surface(f, code % 2 == 1, u0, u1, u2, faces, world, normals)
            dr, dg, db, sr, sg, sb = _illuminate(params, lights, specular_model, px, py, pz, nx, ny, nz)
            color[row, col, 0] = _to_byte((params[P_COLOR] * dr + sr) + params[P_EMISSIVE])
            color[row, col, 1] = _to_byte((params[P_COLOR + 1] * dg + sg) + params[P_EMISSIVE + 1])
            color[row, col, 2] = _to_byte((params[P_COLOR + 2] * db + sb) + params[P_EMISSIVE + 2])
            color[row, col, 3] = 255


# Scratch of the directional fast path: one row of _CHUNK float64 per quantity (structure of arrays), at fixed
# offsets, so that LLVM sees the rows cannot overlap and vectorizes the branch-free passes of _shade_chunk.
_CHUNK = 256
_ROWS = 16  # image rows per parallel task; each allocates its scratch once
_NX, _NY, _NZ, _SIGN, _PX, _PY, _PZ, _VX, _VY, _VZ, _X, _NDL, _POW, _DR, _DG, _DB, _SR, _SG, _SB = range(
    0, 19 * _CHUNK, _CHUNK
)
_FIELDS = 19


@parallel_kernel(lambda depth, codes, *_: (codes.shape[0] + _ROWS - 1) // _ROWS,
                 work=lambda depth, *_: depth.size, grain=16384)
def shade_pixels_directional(
    depth: np.ndarray, codes: np.ndarray, bary: np.ndarray, faces: np.ndarray, world: np.ndarray,
    normals: np.ndarray, params: np.ndarray, lights: np.ndarray, item: np.ndarray, color: np.ndarray,
    start: int, stop: int,
) -> None:  # fmt: skip
    """``shade_pixels`` for the common case, bit for bit: per-pixel Blinn-Phong with directional lights only and
    no texture, vertex colors, depth cueing, blending or extra buffers (the benchmark scenes).

    Blocks of ``_ROWS`` image rows run in parallel; each gathers its drawn pixels into chunks of ``_CHUNK`` and
    shades a chunk with one branch-free loop per step (vectorized: the divisions and square roots dominate).
    color must be C-contiguous: a pixel's four bytes are written as one uint32 word.
    """
    height = codes.shape[0]
    for block in range(start, stop):
        start = block * _ROWS
        _shade_rows_directional(
            start, min(start + _ROWS, height), depth, codes, bary, faces, world, normals, params, lights, item, color
        )


@kernel
def _shade_rows_directional(
    start: int, stop: int, depth: np.ndarray, codes: np.ndarray, bary: np.ndarray, faces: np.ndarray,
    world: np.ndarray, normals: np.ndarray, params: np.ndarray, lights: np.ndarray, item: np.ndarray,
    color: np.ndarray,
) -> None:  # fmt: skip
    """Rows [start, stop) of ``shade_pixels_directional``: list the drawn pixels (face, weights, sign) chunk by
    chunk, then gather and shade each full chunk (``_gather_chunk``, ``_shade_chunk``)."""
    scratch = np.empty(_FIELDS * _CHUNK)
    where = np.empty(3 * _CHUNK, dtype=np.int64)  # row, column, then the face (later the color word) of each pixel
    corners = np.empty(3 * _CHUNK, dtype=np.int64)
    words = color.view(np.uint32)
    face_offset = item[I_FACE_OFFSET]
    n = 0
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
            scratch[_X + n], scratch[_NDL + n] = float(bary[row, col, 0]), float(bary[row, col, 1])
            scratch[_SIGN + n] = -1.0 if code % 2 == 1 else 1.0
            where[n], where[_CHUNK + n], where[2 * _CHUNK + n] = row, col, f
            n += 1
            if n == _CHUNK:
                _gather_chunk(n, scratch, where, corners, faces, world, normals)
                _shade_chunk(n, scratch, where, params, lights, words)
                n = 0
    _gather_chunk(n, scratch, where, corners, faces, world, normals)
    _shade_chunk(n, scratch, where, params, lights, words)


@kernel
def _gather_chunk(
    n: int, s: np.ndarray, where: np.ndarray, corners: np.ndarray, faces: np.ndarray, world: np.ndarray,
    normals: np.ndarray,
) -> None:  # fmt: skip
    """Interpolated normal $(u0·na + u1·nb) + u2·nc$ and world point of the first n listed pixels, from their
    weights (u1, u2 in the _X and _NDL rows). Corners first, then the vertex data, each in its own short loop:
    the loads of many pixels are in flight at once (one long loop per pixel waited on each cache miss in turn)."""
    for i in range(n):
        f = np.uint64(where[2 * _CHUNK + i])  # unsigned indices: no negative-index fix-up
        a, b, c = faces[f, 0], faces[f, 1], faces[f, 2]
        corners[i], corners[_CHUNK + i], corners[2 * _CHUNK + i] = a, b, c
        for v in (a, b, c):  # the second loop's rows, loading meanwhile (_jit.prefetch)
            prefetch(normals, np.uint64(v), 0)
            prefetch(world, np.uint64(v), 0)
    for i in range(n):
        a, b, c = np.uint64(corners[i]), np.uint64(corners[_CHUNK + i]), np.uint64(corners[2 * _CHUNK + i])
        u1, u2 = s[_X + i], s[_NDL + i]
        u0 = (1.0 - u1) - u2
        s[_NX + i] = _interpolate(u0, u1, u2, normals[a, 0], normals[b, 0], normals[c, 0])
        s[_NY + i] = _interpolate(u0, u1, u2, normals[a, 1], normals[b, 1], normals[c, 1])
        s[_NZ + i] = _interpolate(u0, u1, u2, normals[a, 2], normals[b, 2], normals[c, 2])
        s[_PX + i] = _interpolate(u0, u1, u2, world[a, 0], world[b, 0], world[c, 0])
        s[_PY + i] = _interpolate(u0, u1, u2, world[a, 1], world[b, 1], world[c, 1])
        s[_PZ + i] = _interpolate(u0, u1, u2, world[a, 2], world[b, 2], world[c, 2])


# Its normal pass is repeated by ``raster.pbr.shade_chunk_pbr``: kernel specialisation kept on purpose (no shared call).
# Kernel specialization kept on purpose: ``raster.light.light_terms`` for directional lights (falloff 1), as passes
# over a chunk of pixels that the compiler vectorizes; the same operations in the same order, so the same bytes.
# kernel specialisation kept on purpose: raster.shadow_tiled._shade_chunk_shadowed repeats it with fractions
@kernel
def _shade_chunk(
    n: int, s: np.ndarray, where: np.ndarray, params: np.ndarray, lights: np.ndarray, words: np.ndarray
) -> None:  # fmt: skip
    """Shade the first n gathered pixels: the operations of ``_surface`` and ``_illuminate`` in the same order
    (falloff 1, so $k_d·(1·ndl) = k_d·ndl$), as passes over the chunk with selects for branches; then store
    each pixel's bytes (r, g, b, 255) as one little-endian word (words: color viewed as uint32)."""
    ex, ey, ez = params[P_EYE], params[P_EYE + 1], params[P_EYE + 2]
    ka, kd, ks, shininess = params[P_AMBIENT], params[P_DIFFUSE], params[P_SPECULAR], params[P_SHININESS]
    ar, ag, ab = ka * params[P_LIGHT_AMBIENT], ka * params[P_LIGHT_AMBIENT + 1], ka * params[P_LIGHT_AMBIENT + 2]
    for i in range(n):
        nx, ny, nz = s[_NX + i], s[_NY + i], s[_NZ + i]
        length = math.sqrt((nx * nx + ny * ny) + nz * nz)
        zero = length == 0.0
        nx = 0.0 if zero else nx
        ny = 0.0 if zero else ny
        nz = 1.0 if zero else nz
        length = 1.0 if zero else length
        sign = s[_SIGN + i]
        s[_NX + i], s[_NY + i], s[_NZ + i] = sign * nx / length, sign * ny / length, sign * nz / length
        vx, vy, vz = ex - s[_PX + i], ey - s[_PY + i], ez - s[_PZ + i]
        length = math.sqrt((vx * vx + vy * vy) + vz * vz)
        positive = length > 0.0  # as in _illuminate; also spares the division numba's zero check
        s[_VX + i] = vx / length if positive else vx
        s[_VY + i] = vy / length if positive else vy
        s[_VZ + i] = vz / length if positive else vz
        s[_DR + i], s[_DG + i], s[_DB + i] = ar, ag, ab
        s[_SR + i], s[_SG + i], s[_SB + i] = 0.0, 0.0, 0.0
    for k in range(lights.shape[0]):
        lx, ly, lz = lights[k, 7], lights[k, 8], lights[k, 9]
        for i in range(n):
            nx, ny, nz = s[_NX + i], s[_NY + i], s[_NZ + i]
            hx, hy, hz = lx + s[_VX + i], ly + s[_VY + i], lz + s[_VZ + i]
            length = math.sqrt((hx * hx + hy * hy) + hz * hz)
            positive = length > 0.0
            hx = hx / length if positive else hx
            hy = hy / length if positive else hy
            hz = hz / length if positive else hz
            s[_NDL + i] = (nx * lx + ny * ly) + nz * lz
            s[_X + i] = max((nx * hx + ny * hy) + nz * hz, 0.0)
            s[_POW + i] = 1.0
        if _squarable(shininess):  # power(x, shininess), one pass per step over the chunk
            e = int(shininess)
            while e > 0:
                if e & 1:
                    for i in range(n):
                        s[_POW + i] *= s[_X + i]
                e >>= 1
                if e > 0:
                    for i in range(n):
                        s[_X + i] *= s[_X + i]
        else:
            for i in range(n):
                s[_POW + i] = s[_X + i] ** shininess
        r, g, b = lights[k, 1], lights[k, 2], lights[k, 3]
        for i in range(n):
            ndl = s[_NDL + i]
            lit = not ndl <= 0.0
            diffuse = kd * (1.0 * ndl)
            specular = ks * (1.0 * s[_POW + i])
            s[_DR + i] = s[_DR + i] + diffuse * r if lit else s[_DR + i]
            s[_DG + i] = s[_DG + i] + diffuse * g if lit else s[_DG + i]
            s[_DB + i] = s[_DB + i] + diffuse * b if lit else s[_DB + i]
            s[_SR + i] = s[_SR + i] + specular * r if lit else s[_SR + i]
            s[_SG + i] = s[_SG + i] + specular * g if lit else s[_SG + i]
            s[_SB + i] = s[_SB + i] + specular * b if lit else s[_SB + i]
    r, g, b = params[P_COLOR], params[P_COLOR + 1], params[P_COLOR + 2]
    er, eg, eb = params[P_EMISSIVE], params[P_EMISSIVE + 1], params[P_EMISSIVE + 2]
    for i in range(n):
        where[2 * _CHUNK + i] = (
            int(_to_byte((r * s[_DR + i] + s[_SR + i]) + er))
            | int(_to_byte((g * s[_DG + i] + s[_SG + i]) + eg)) << 8
            | int(_to_byte((b * s[_DB + i] + s[_SB + i]) + eb)) << 16
            | 255 << 24
        )
    for i in range(n):
        words[np.uint64(where[i]), np.uint64(where[_CHUNK + i]), 0] = where[2 * _CHUNK + i]
