"""pyrender's light model per pixel over frustum's frame buffers, and metric depth (``frustum.interop``).

The model and its parameters are documented once, in ``frustum.interop.pyrender_shading``, which packs the
arrays this kernel reads. Kernels never validate: the caller passes contiguous arrays of the stated shapes.
"""

from __future__ import annotations

import math

import numpy as np

from frustum.raster._jit import kernel, parallel_kernel
from frustum.raster.shade import _to_byte  # the one 8-bit rounding of every shading kernel

__all__ = ["CAMERA_FIELDS", "ITEM_FIELDS", "LIGHT_FIELDS", "shade_pixels"]

ITEM_FIELDS = 10
"""Per item: base colour (3), metallic, roughness, emissive factor (3), mode (0 constant base, 1 textured: drawn
bytes are the sRGB texture, 2 vertex colours: drawn bytes multiply the result), has normals (0 or 1)."""
LIGHT_FIELDS = 13
"""Per light: kind (0 directional, 1 point, 2 spot), E (3), position (3), direction it shines (3), spot scale s,
spot offset o, column of the visibility buffer (−1: no shadow)."""
CAMERA_FIELDS = 27
"""world_from_window (16, row-major), eye (3), ambient (3), the z rows' A, B, C, D of clip_from_view (4), lit."""
_PI = math.pi
_MIN_ROUGHNESS = 0.04


@kernel
def _srgb_to_linear(c: float) -> float:
    if c < 0.04045:
        return c / 12.92
    return ((c + 0.055) / 1.055) ** 2.4


@kernel
def _clamp(x: float, low: float, high: float) -> float:
    return min(max(x, low), high)


@parallel_kernel(lambda depth, *_: depth.shape[0], work=lambda depth, *_: depth.size, grain=16384)
def shade_pixels(
    depth: np.ndarray, color: np.ndarray, normals: np.ndarray, ids: np.ndarray, items: np.ndarray,
    lights: np.ndarray, visibility: np.ndarray, camera: np.ndarray, metric: np.ndarray,
    start: int, stop: int,
) -> None:  # fmt: skip
    """Rows [start, stop): metric depth $−z_view$ (0 where depth is 1) into `metric` (H, W) float32, and where
    ``camera[26]`` is nonzero pyrender's colour of every covered pixel into `color` (H, W, 4) uint8, whose bytes
    hold frustum's unlit drawing on entry. depth (H, W) float32 window depth, normals (H, W, 3) float32 unit
    normals, ids (H, W) int32 item index, items (I, ITEM_FIELDS), lights (L, LIGHT_FIELDS) float64,
    visibility (H, W, K) float32 (K shadow-casting lights; any shape when no light has a column)."""
    height = depth.shape[0]
    a, b, c, d = camera[22], camera[23], camera[24], camera[25]
    lit = camera[26] != 0.0
    for row in range(start, stop):
        for col in range(depth.shape[1]):
            window_depth = float(depth[row, col])
            if window_depth >= 1.0:
                metric[row, col] = 0.0
                continue
            z_ndc = 2.0 * window_depth - 1.0
            metric[row, col] = -((b - z_ndc * d) / (z_ndc * c - a))
            if lit:
                _shade_pixel(row, col, height, window_depth, color, normals, ids, items, lights, visibility, camera)


@kernel
def _channel(base: float, metallic: float, schlick: float, geometry: float, distribution: float, nl: float,
             nv: float) -> float:  # fmt: skip
    """One colour channel of the BRDF times N·L: $(1 − F)·c_diff/π + F·G·D/(4·N·L·N·V + 0.001)$, times N·L."""
    f0 = _MIN_ROUGHNESS * (1.0 - metallic) + base * metallic
    fresnel = f0 + (1.0 - f0) * schlick
    c_diff = base * (1.0 - _MIN_ROUGHNESS) * (1.0 - metallic)
    return nl * ((1.0 - fresnel) * c_diff / _PI + fresnel * geometry * distribution / (4.0 * nl * nv + 0.001))


@kernel
def _shade_pixel(
    row: int, col: int, height: int, window_depth: float, color: np.ndarray, normals: np.ndarray, ids: np.ndarray,
    items: np.ndarray, lights: np.ndarray, visibility: np.ndarray, camera: np.ndarray,
) -> None:  # fmt: skip
    """One covered pixel of ``shade_pixels``."""
    # the world point: world_from_window · (x, y, depth, 1), divided by w
    x, y = col + 0.5, height - row - 0.5
    hx = camera[0] * x + camera[1] * y + camera[2] * window_depth + camera[3]
    hy = camera[4] * x + camera[5] * y + camera[6] * window_depth + camera[7]
    hz = camera[8] * x + camera[9] * y + camera[10] * window_depth + camera[11]
    hw = camera[12] * x + camera[13] * y + camera[14] * window_depth + camera[15]
    px, py, pz = hx / hw, hy / hw, hz / hw
    vx, vy, vz = camera[16] - px, camera[17] - py, camera[18] - pz
    length = math.sqrt(vx * vx + vy * vy + vz * vz)
    vx, vy, vz = vx / length, vy / length, vz / length
    item = items[ids[row, col]]
    mode = int(item[8])
    r, g, b = color[row, col, 0] / 255.0, color[row, col, 1] / 255.0, color[row, col, 2] / 255.0
    base_r, base_g, base_b = item[0], item[1], item[2]
    mult_r, mult_g, mult_b = 1.0, 1.0, 1.0
    if mode == 1:  # the texture's sRGB bytes, decoded after the bilinear lookup (pyrender's shader)
        base_r, base_g, base_b = base_r * _srgb_to_linear(r), base_g * _srgb_to_linear(g), base_b * _srgb_to_linear(b)
    elif mode == 2:  # vertex colours multiply the lit colour
        mult_r, mult_g, mult_b = r, g, b
    if item[9] != 0.0:
        nx, ny, nz = float(normals[row, col, 0]), float(normals[row, col, 1]), float(normals[row, col, 2])
        length = math.sqrt(nx * nx + ny * ny + nz * nz)
        nx, ny, nz = nx / length, ny / length, nz / length
    else:  # pyrender's fallback without normals: N = V
        nx, ny, nz = vx, vy, vz
    metallic = _clamp(item[3], 0.0, 1.0)
    roughness = _clamp(item[4], _MIN_ROUGHNESS, 1.0)
    nv = _clamp(abs(nx * vx + ny * vy + nz * vz), 0.001, 1.0)
    k_g = (roughness + 1.0) * (roughness + 1.0) / 8.0
    g_view = nv / (nv * (1.0 - k_g) + k_g)
    a2 = (roughness * roughness) * (roughness * roughness)
    out_r, out_g, out_b = 0.0, 0.0, 0.0
    for index in range(lights.shape[0]):
        kind = int(lights[index, 0])
        attenuation = 1.0
        if kind == 0:
            lx, ly, lz = -lights[index, 7], -lights[index, 8], -lights[index, 9]
        else:
            lx, ly, lz = lights[index, 4] - px, lights[index, 5] - py, lights[index, 6] - pz
            distance2 = lx * lx + ly * ly + lz * lz
            distance = math.sqrt(distance2)
            lx, ly, lz = lx / distance, ly / distance, lz / distance
            attenuation = 1.0 / distance2
            if kind == 2:
                cos_axis = _clamp(-(lx * lights[index, 7] + ly * lights[index, 8] + lz * lights[index, 9]), 0.0, 1.0)
                cone = _clamp(cos_axis * lights[index, 10] + lights[index, 11], 0.0, 1.0)
                attenuation *= cone * cone
        column = int(lights[index, 12])
        if column >= 0:
            attenuation *= visibility[row, col, column]
        hx, hy, hz = lx + vx, ly + vy, lz + vz
        length = math.sqrt(hx * hx + hy * hy + hz * hz)
        hx, hy, hz = hx / length, hy / length, hz / length
        nl = _clamp(nx * lx + ny * ly + nz * lz, 0.001, 1.0)
        nh = _clamp(nx * hx + ny * hy + nz * hz, 0.0, 1.0)
        vh = _clamp(vx * hx + vy * hy + vz * hz, 0.0, 1.0)
        schlick = _clamp(1.0 - vh, 0.0, 1.0) ** 5
        geometry = g_view * (nl / (nl * (1.0 - k_g) + k_g))
        denominator = nh * nh * (a2 - 1.0) + 1.0
        distribution = a2 / (_PI * denominator * denominator)
        out_r += attenuation * lights[index, 1] * _channel(base_r, metallic, schlick, geometry, distribution, nl, nv)
        out_g += attenuation * lights[index, 2] * _channel(base_g, metallic, schlick, geometry, distribution, nl, nv)
        out_b += attenuation * lights[index, 3] * _channel(base_b, metallic, schlick, geometry, distribution, nl, nv)
    # ambient, pyrender's emissive term (its factor multiplied in twice), vertex colours, gamma 1/2.2
    out_r = (out_r + base_r * camera[19] + item[5] * item[5]) * mult_r
    out_g = (out_g + base_g * camera[20] + item[6] * item[6]) * mult_g
    out_b = (out_b + base_b * camera[21] + item[7] * item[7]) * mult_b
    color[row, col, 0] = _to_byte(max(out_r, 0.0) ** (1.0 / 2.2))
    color[row, col, 1] = _to_byte(max(out_g, 0.0) ** (1.0 / 2.2))
    color[row, col, 2] = _to_byte(max(out_b, 0.0) ** (1.0 / 2.2))
