"""Gaussian splat kernels: the 3DGS rasterizer (Kerbl et al. 2023) on the CPU, tile by tile.

1. ``project_splats`` (parallel over splats): the world covariance $Σ = A R S Sᵀ Rᵀ Aᵀ$ (A the modeling matrix's
   3x3 part) goes to view space ($V Σ Vᵀ$) and to the screen with the Jacobian J of the window mapping at the
   splat's centre (EWA: $Σ' = J V Σ Vᵀ Jᵀ + 0.3·I$, the 0.3-pixel low-pass dilation). For a perspective camera J
   is 3DGS's $[[f_x/z, 0, −f_x·x/z²], [0, f_y/z, −f_y·y/z²]]$; here it is taken from the projection matrix P
   for any camera: row i of J is $(W_i/2)·(P_i/w − c_i·P₃/w²)$ with c = P·v, w = c₃, $W_0 = W$, $W_1 = H$.
   Its inverse (the conic), a square bound of half side $⌈k·√λ_max⌉$ pixels and the
   view-dependent colour $max(0.5 + Σ_lm SH_lm(d)·k_lm, 0)$ (d: the unit direction from the eye to the centre,
   in model axes; the real SH basis and constants of the 3DGS code, degree 0–3) complete the record. A splat is
   culled unless its centre lies between the near and far planes ($w > 0$, $−w <= z_c <= w$). The bound is the
   3DGS 3σ box tightened to where the splat can be drawn at all: $k = √(2·ln(255·o))$ standard deviations along
   the major axis, where $o·exp(−½k²) = 1/255$ (gsplat's opacity-aware radius; k ≤ 3.33 as o ≤ 1, k < 3 for
   o < 0.35), so no pixel with α ≥ 1/255 lies outside it and the tiles change no pixel.
2. ``count_tiles`` / ``fill_tiles``: each splat's bound is binned into 16 × 16-pixel tiles, visited in the
   caller's order (sorted by depth), so every tile's list is sorted front to back.
3. ``blend_tiles`` (parallel over tiles): per pixel, front to back, $α = min(0.99, o·exp(−½ dᵀΣ'⁻¹d))$ at the
   pixel centre (d from the projected centre), skipped below 1/255; $C += c·α·T$, $T ← T·(1 − α)$, stopping
   before T would fall below 1e-4 (that splat not drawn); a splat at or behind the depth already in the depth
   buffer (an opaque surface) ends the pixel. The expected depth $Σ wᵢ zᵢ / Σ wᵢ$ ($wᵢ = αᵢ·Tᵢ$, z window depth
   of the centre) is written where $Σ wᵢ > 0$, and the item of the median splat: the one whose compositing brings
   the accumulated alpha $1 − T$ to ½ or more (T from above ½ to at most ½; −1 where it stays below ½), as 3DGS's
   median depth picks its splat; item i holds the records from ``item_starts[i]`` up to (not including)
   ``item_starts[i + 1]``.

Records (``SPLAT_FIELDS`` float64): window x, y (y up), window depth z of the centre, bound half side r (pixels,
0: culled), conic (A, B, C) of $Σ'⁻¹$ in window axes, opacity o, colour (3), Σ' in image axes (x right,
y down, 3DGS's convention; a, b, c) for testing, and the half sides $k·√Σ'_{xx}$, $k·√Σ'_{yy}$ of the box around the
ellipse $dᵀΣ'⁻¹d <= k²$ (inside the square bound: the pixels and tiles actually visited). Kernels never validate
(arrays contiguous, shapes as stated).

References
----------
Kerbl, Kopanas, Leimkühler, Drettakis, "3D Gaussian Splatting for Real-Time Radiance Field Rendering" (2023)
§4–§6 and its ``forward.cu`` (``computeCov2D``, ``computeColorFromSH``, ``renderCUDA``); Zwicker, Pfister,
van Baar, Gross, "EWA Splatting" (2002) (the Jacobian and the low-pass filter).
"""

from __future__ import annotations

import math

import numpy as np

from frustum.raster._jit import kernel, parallel_kernel, prefetch

__all__ = [
    "LAYER_CHANNELS", "SPLAT_FIELDS", "TILE", "blend_tiles", "count_tiles", "fill_tiles", "project_splats", "sh_color",
]  # fmt: skip

SPLAT_FIELDS = 16
TILE = 16
"""Tile side in pixels."""
F_X, F_Y, F_Z, F_RADIUS, F_CONIC, F_OPACITY, F_COLOR, F_COV, F_EXTENT = 0, 1, 2, 3, 4, 7, 8, 11, 14
LAYER_CHANNELS = 7
"""``blend_tiles``' per-pixel outputs: colour (3), transmittance, $Σ wᵢ$, $Σ wᵢ zᵢ$, the median splat's item."""
PREFETCH_AHEAD = 8
"""Tile entries ahead whose records ``blend_tiles`` prefetches."""
DILATION = 0.3
"""Pixels² added to the screen covariance's diagonal (the low-pass filter)."""
ALPHA_MAX = 0.99
ALPHA_MIN = 1.0 / 255.0
T_MIN = 1e-4

SH_C0 = 0.28209479177387814
SH_C1 = 0.4886025119029199
SH_C2 = (1.0925484305920792, -1.0925484305920792, 0.31539156525252005, -1.0925484305920792, 0.5462742152960396)
SH_C3 = (-0.5900435899266435, 2.890611442640554, -0.4570457994644658, 0.3731763325901154, -0.4570457994644658,
         1.445305721320277, -0.5900435899266435)  # fmt: skip


@kernel
def sh_color(sh: np.ndarray, k: int, channel: int, x: float, y: float, z: float) -> float:
    """$max(0.5 + Σ_lm SH_lm(d)·k_lm, 0)$ of splat k's `channel` in the unit direction d = (x, y, z)."""
    count = sh.shape[1]
    result = SH_C0 * sh[k, 0, channel]
    if count > 1:
        result += (-SH_C1 * y * sh[k, 1, channel] + SH_C1 * z * sh[k, 2, channel]) - SH_C1 * x * sh[k, 3, channel]
        if count > 4:
            xx, yy, zz, xy, yz, xz = x * x, y * y, z * z, x * y, y * z, x * z
            result += (SH_C2[0] * xy * sh[k, 4, channel] + SH_C2[1] * yz * sh[k, 5, channel]
                       + SH_C2[2] * (2.0 * zz - xx - yy) * sh[k, 6, channel] + SH_C2[3] * xz * sh[k, 7, channel]
                       + SH_C2[4] * (xx - yy) * sh[k, 8, channel])  # fmt: skip
            if count > 9:
                result += (SH_C3[0] * y * (3.0 * xx - yy) * sh[k, 9, channel]
                           + SH_C3[1] * xy * z * sh[k, 10, channel]
                           + SH_C3[2] * y * (4.0 * zz - xx - yy) * sh[k, 11, channel]
                           + SH_C3[3] * z * (2.0 * zz - 3.0 * xx - 3.0 * yy) * sh[k, 12, channel]
                           + SH_C3[4] * x * (4.0 * zz - xx - yy) * sh[k, 13, channel]
                           + SH_C3[5] * z * (xx - yy) * sh[k, 14, channel]
                           + SH_C3[6] * x * (xx - 3.0 * yy) * sh[k, 15, channel])  # fmt: skip
    return max(result + 0.5, 0.0)


@parallel_kernel(lambda positions, *_: positions.shape[0], grain=4096)
def project_splats(positions: np.ndarray, scales: np.ndarray, rotations: np.ndarray, opacities: np.ndarray,
                   sh: np.ndarray, matrices: np.ndarray, frame: np.ndarray, records: np.ndarray,
                   start: int, stop: int) -> None:  # fmt: skip
    """Records of splats [start, stop) (module docstring, step 1).

    ``matrices`` (4, 4, 4): ``view_from_model``, ``clip_from_view``, ``model_from_world`` (for the SH direction),
    ``world_from_model``; ``frame`` = (width, height, eye x, y, z in world coordinates).
    """
    view, clip, model_from_world, world = matrices[0], matrices[1], matrices[2], matrices[3]
    width, height = frame[0], frame[1]
    sigma = np.empty((3, 3))
    m = np.empty((3, 3))
    for k in range(start, stop):
        records[k, F_RADIUS] = 0.0
        px, py, pz = positions[k, 0], positions[k, 1], positions[k, 2]
        vx = ((view[0, 0] * px + view[0, 1] * py) + view[0, 2] * pz) + view[0, 3]
        vy = ((view[1, 0] * px + view[1, 1] * py) + view[1, 2] * pz) + view[1, 3]
        vz = ((view[2, 0] * px + view[2, 1] * py) + view[2, 2] * pz) + view[2, 3]
        c0 = ((clip[0, 0] * vx + clip[0, 1] * vy) + clip[0, 2] * vz) + clip[0, 3]
        c1 = ((clip[1, 0] * vx + clip[1, 1] * vy) + clip[1, 2] * vz) + clip[1, 3]
        c2 = ((clip[2, 0] * vx + clip[2, 1] * vy) + clip[2, 2] * vz) + clip[2, 3]
        w = ((clip[3, 0] * vx + clip[3, 1] * vy) + clip[3, 2] * vz) + clip[3, 3]
        if not (w > 0.0 and -w <= c2 <= w):
            continue
        # Σ = R S Sᵀ Rᵀ in model axes, then V Σ Vᵀ (V: the 3x3 part of view_from_model, modeling included)
        qw, qx, qy, qz = rotations[k, 0], rotations[k, 1], rotations[k, 2], rotations[k, 3]
        sx, sy, sz = scales[k, 0], scales[k, 1], scales[k, 2]
        m[0, 0], m[0, 1], m[0, 2] = (1.0 - 2.0 * (qy * qy + qz * qz)) * sx, 2.0 * (qx * qy - qw * qz) * sy, 2.0 * (
            qx * qz + qw * qy) * sz  # fmt: skip
        m[1, 0], m[1, 1], m[1, 2] = 2.0 * (qx * qy + qw * qz) * sx, (1.0 - 2.0 * (qx * qx + qz * qz)) * sy, 2.0 * (
            qy * qz - qw * qx) * sz  # fmt: skip
        m[2, 0], m[2, 1], m[2, 2] = 2.0 * (qx * qz - qw * qy) * sx, 2.0 * (qy * qz + qw * qx) * sy, (
            1.0 - 2.0 * (qx * qx + qy * qy)) * sz  # fmt: skip
        for i in range(3):  # V·(R S): the view-space factor; Σ_view = (V R S)(V R S)ᵀ
            for j in range(3):
                sigma[i, j] = (view[i, 0] * m[0, j] + view[i, 1] * m[1, j]) + view[i, 2] * m[2, j]
        # J: rows (W/2)·(P₀/w − c₀·P₃/w²) and (H/2)·(P₁/w − c₁·P₃/w²)
        j00 = (width / 2.0) * (clip[0, 0] / w - c0 * clip[3, 0] / (w * w))
        j01 = (width / 2.0) * (clip[0, 1] / w - c0 * clip[3, 1] / (w * w))
        j02 = (width / 2.0) * (clip[0, 2] / w - c0 * clip[3, 2] / (w * w))
        j10 = (height / 2.0) * (clip[1, 0] / w - c1 * clip[3, 0] / (w * w))
        j11 = (height / 2.0) * (clip[1, 1] / w - c1 * clip[3, 1] / (w * w))
        j12 = (height / 2.0) * (clip[1, 2] / w - c1 * clip[3, 2] / (w * w))
        a, b, c = 0.0, 0.0, 0.0  # Σ' = (J V R S)(J V R S)ᵀ
        for j in range(3):
            t0 = (j00 * sigma[0, j] + j01 * sigma[1, j]) + j02 * sigma[2, j]
            t1 = (j10 * sigma[0, j] + j11 * sigma[1, j]) + j12 * sigma[2, j]
            a += t0 * t0
            b += t0 * t1
            c += t1 * t1
        a += DILATION
        c += DILATION
        det = a * c - b * b
        if not det > 0.0:
            continue
        if not opacities[k] * 255.0 > 1.0:  # α = o·G < 1/255 everywhere: never drawn
            continue
        extent = math.sqrt(2.0 * math.log(255.0 * opacities[k]))  # σ where o·exp(−½k²) = 1/255
        mid = 0.5 * (a + c)
        largest = mid + math.sqrt(max(0.1, mid * mid - det))
        records[k, F_X] = (c0 / w + 1.0) * (width / 2.0)
        records[k, F_Y] = (c1 / w + 1.0) * (height / 2.0)
        records[k, F_Z] = (c2 / w + 1.0) * 0.5
        records[k, F_CONIC], records[k, F_CONIC + 1], records[k, F_CONIC + 2] = c / det, -b / det, a / det
        records[k, F_OPACITY] = opacities[k]
        records[k, F_COV], records[k, F_COV + 1], records[k, F_COV + 2] = a, -b, c
        # colour: the SH direction from the eye to the centre, in model axes
        gx = ((world[0, 0] * px + world[0, 1] * py) + world[0, 2] * pz) + world[0, 3] - frame[2]
        gy = ((world[1, 0] * px + world[1, 1] * py) + world[1, 2] * pz) + world[1, 3] - frame[3]
        gz = ((world[2, 0] * px + world[2, 1] * py) + world[2, 2] * pz) + world[2, 3] - frame[4]
        dx = (model_from_world[0, 0] * gx + model_from_world[0, 1] * gy) + model_from_world[0, 2] * gz
        dy = (model_from_world[1, 0] * gx + model_from_world[1, 1] * gy) + model_from_world[1, 2] * gz
        dz = (model_from_world[2, 0] * gx + model_from_world[2, 1] * gy) + model_from_world[2, 2] * gz
        length = math.sqrt((dx * dx + dy * dy) + dz * dz)
        if length > 0.0:
            dx, dy, dz = dx / length, dy / length, dz / length
        for channel in range(3):
            records[k, F_COLOR + channel] = sh_color(sh, k, channel, dx, dy, dz)
        records[k, F_RADIUS] = math.ceil(extent * math.sqrt(largest))
        # the box around the ellipse dᵀΣ'⁻¹d <= k² (half sides k·√Σ'_{xx}, k·√Σ'_{yy}): inside the square, and tight
        records[k, F_EXTENT], records[k, F_EXTENT + 1] = extent * math.sqrt(a), extent * math.sqrt(c)


@kernel
def _tile_box(records: np.ndarray, k: int, height: int, tiles_x: int,
              tiles_y: int) -> tuple[int, int, int, int]:  # fmt: skip
    """Tile columns and rows [x0, x1] × [y0, y1] that splat k's bound touches (frame rows, top first)."""
    half_x, half_y = records[k, F_EXTENT], records[k, F_EXTENT + 1]
    x, row = records[k, F_X], height - records[k, F_Y]  # the centre in column and frame-row coordinates
    x0 = max(math.floor((x - half_x) / TILE), 0)
    x1 = min(math.floor((x + half_x) / TILE), tiles_x - 1)
    y0 = max(math.floor((row - half_y) / TILE), 0)
    y1 = min(math.floor((row + half_y) / TILE), tiles_y - 1)
    return x0, x1, y0, y1


@kernel
def count_tiles(records: np.ndarray, order: np.ndarray, height: int, tiles_x: int, tiles_y: int,
                counts: np.ndarray) -> None:  # fmt: skip
    """counts[t] = the number of splats (of `order`) whose bound touches tile t = row·tiles_x + column."""
    for e in range(order.shape[0]):
        k = order[e]
        if records[k, F_RADIUS] <= 0.0:
            continue
        x0, x1, y0, y1 = _tile_box(records, k, height, tiles_x, tiles_y)
        for ty in range(y0, y1 + 1):
            for tx in range(x0, x1 + 1):
                counts[ty * tiles_x + tx] += 1


# kernel specialisation kept on purpose: the second pass of count-then-fill, the loop of count_tiles with a write
@kernel
def fill_tiles(records: np.ndarray, order: np.ndarray, height: int, tiles_x: int, tiles_y: int,
               starts: np.ndarray, entries: np.ndarray) -> None:  # fmt: skip
    """entries[starts[t] : starts[t + 1]] = the splats touching tile t, in the order of `order`."""
    cursor = starts[:-1].copy()
    for e in range(order.shape[0]):
        k = order[e]
        if records[k, F_RADIUS] <= 0.0:
            continue
        x0, x1, y0, y1 = _tile_box(records, k, height, tiles_x, tiles_y)
        for ty in range(y0, y1 + 1):
            for tx in range(x0, x1 + 1):
                t = ty * tiles_x + tx
                entries[cursor[t]] = k
                cursor[t] += 1


# many small pieces: tiles differ in cost by orders of magnitude (empty sky, dense surfaces), so threads balance
@parallel_kernel(lambda records, starts, *_: starts.size - 1, pieces_per_thread=32)
def blend_tiles(records: np.ndarray, starts: np.ndarray, entries: np.ndarray, tiles_x: int, depth: np.ndarray,
                item_starts: np.ndarray, layer: np.ndarray, start: int, stop: int) -> None:  # fmt: skip
    """Tiles [start, stop): ``layer`` (H, W, ``LAYER_CHANNELS``) float32 ← premultiplied colour $Σ cᵢ·αᵢ·Tᵢ$ (3),
    the final transmittance T, $Σ wᵢ$, $Σ wᵢ·zᵢ$ and the median splat's item (−1: none) per pixel (module
    docstring, step 3); `depth` (H, W) is only read."""
    height, width = depth.shape
    color = np.empty((TILE, TILE, 3))
    transmittance = np.empty((TILE, TILE))
    weight = np.empty((TILE, TILE))
    weighted_z = np.empty((TILE, TILE))
    median = np.empty((TILE, TILE))
    opaque = np.empty((TILE, TILE), dtype=np.float32)
    for tile in range(start, stop):
        row0, col0 = (tile // tiles_x) * TILE, (tile % tiles_x) * TILE
        rows, cols = min(TILE, height - row0), min(TILE, width - col0)
        color[:] = 0.0
        transmittance[:] = 1.0
        weight[:] = 0.0
        weighted_z[:] = 0.0
        median[:] = -1.0
        for i in range(rows):
            for j in range(cols):
                opaque[i, j] = depth[row0 + i, col0 + j]
        remaining = rows * cols
        end = starts[tile + 1]
        for e in range(starts[tile], end):
            if remaining == 0:
                break
            if e + PREFETCH_AHEAD < end:  # the records are gathered in depth order: start their loads early
                ahead = entries[e + PREFETCH_AHEAD]
                prefetch(records, ahead, 0)
                prefetch(records, ahead, F_COLOR)
            k = entries[e]
            x, y, z = records[k, F_X], records[k, F_Y], records[k, F_Z]
            half_x, half_y = records[k, F_EXTENT], records[k, F_EXTENT + 1]
            ca, cb, cc = records[k, F_CONIC], records[k, F_CONIC + 1], records[k, F_CONIC + 2]
            opacity = records[k, F_OPACITY]
            faint = -math.log(255.0 * opacity)  # power below this: α < 1/255 (exp not needed to know)
            row_c = height - y
            i0 = max(math.ceil(row_c - half_y - 0.5) - row0, 0)
            i1 = min(math.floor(row_c + half_y - 0.5) - row0, rows - 1)
            j0 = max(math.ceil(x - half_x - 0.5) - col0, 0)
            j1 = min(math.floor(x + half_x - 0.5) - col0, cols - 1)
            for i in range(i0, i1 + 1):
                dy = (height - (row0 + i) - 0.5) - y  # window y of the pixel centre minus the splat's
                for j in range(j0, j1 + 1):
                    if not z < opaque[i, j]:  # at or behind an opaque surface (this and all later), or done
                        if opaque[i, j] >= 0.0:
                            opaque[i, j] = -1.0
                            remaining -= 1
                        continue
                    dx = (col0 + j + 0.5) - x
                    power = -0.5 * ((ca * dx * dx + cc * dy * dy) + 2.0 * cb * dx * dy)
                    if power > 0.0 or power < faint - 1e-9:
                        continue
                    alpha = min(ALPHA_MAX, opacity * math.exp(power))
                    if alpha < ALPHA_MIN:
                        continue
                    t = transmittance[i, j]
                    after = t * (1.0 - alpha)
                    if after < T_MIN:
                        opaque[i, j] = -1.0  # done: no later splat passes the depth test
                        remaining -= 1
                        continue
                    w = alpha * t
                    color[i, j, 0] += records[k, F_COLOR] * w
                    color[i, j, 1] += records[k, F_COLOR + 1] * w
                    color[i, j, 2] += records[k, F_COLOR + 2] * w
                    weight[i, j] += w
                    weighted_z[i, j] += w * z
                    if t > 0.5 >= after:  # the median splat: its item (once per pixel)
                        item = 0
                        while k >= item_starts[item + 1]:
                            item += 1
                        median[i, j] = item
                    transmittance[i, j] = after
        for i in range(rows):
            for j in range(cols):
                r, c = row0 + i, col0 + j
                layer[r, c, 0], layer[r, c, 1], layer[r, c, 2] = color[i, j, 0], color[i, j, 1], color[i, j, 2]
                layer[r, c, 3], layer[r, c, 4], layer[r, c, 5] = transmittance[i, j], weight[i, j], weighted_z[i, j]
                layer[r, c, 6] = median[i, j]
