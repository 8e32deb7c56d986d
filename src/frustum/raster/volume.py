"""Volume ray casting: one ray per pixel through a scalar grid, composited into a framebuffer [HB 15] "Visual
Representations for Scalar Fields" (volume rendering); Levoy, "Display of surfaces from volume data", 1988.

Per pixel (window centre (x + ½, y + ½), y up), in grid-index coordinates u (voxel (i, j, k) at u = (i, j, k)):

1. Ray: $A = grid_from_window·(x, y, 0, 1)$, $B = grid_from_window·(x, y, 1, 1)$ (divided by w), the points
   on the near and far planes; $u(s) = A + s·(B − A)$, s ∈ [0, 1]. This is every projection's ray: through the
   eye for a perspective camera, along the projection direction for a parallel one.
2. Entry and exit: s clipped by the box $0 <= u <= n − 1$ (slabs), by each clip plane $a·u + d >= 0$, and by
   the opaque depth buffer: a pixel whose window depth is $z < 1$ ends the ray at its point's s.
3. Samples at the middles of segments of model length Δ (the last one shorter), trilinear; a segment of
   model length δ uses the opacity $α' = 1 − (1 − α)^(δ/Δ₀)$. With ``P_ANCHORED`` set (sampling "near"):
   at every whole multiple of Δ from the ray's point on the near plane (s = 0) instead, each standing for Δ.
4. Modes: composite front to back $C += (1 − A)·α'·c$, $A += (1 − A)·α'$, stopped once A reaches the
   termination threshold (early ray termination); ``mip`` / ``minip`` the largest / smallest sample; ``average``
   the length-weighted mean; ``isosurface`` the first sign change of $value − level$ between two samples,
   refined by bisection. The last three classify their value through the table and blend it over the buffer.
5. Empty-space skipping: blocks of ``BLOCK`` cells carry (min, max, empty); a ray walks the blocks it crosses
   (3D DDA, Amanatides & Woo 1987) and skips the samples of a block whose value range the transfer function
   maps to opacity 0 (composite) or whose max cannot beat its current maximum (MIP); the samples kept are
   exactly the ones a ray without skipping would use (up to rounding at block faces, where the values of both
   blocks are the face's).
6. Several composite volumes: ``cast_composite_merged`` merges their sample sequences along each ray.

Gradient shading uses ``frustum.shading``'s model with the base color of the transfer function and the normal
$−∇f/|∇f|$ (central differences of the trilinear field, one voxel apart) turned toward the viewer.

Kernels take plain arrays only; ``frustum.render.volumes`` builds them.
"""

from __future__ import annotations

import math

import numpy as np

from frustum.raster._jit import kernel, parallel_kernel
from frustum.raster.light import SPECULAR_BLINN, SPECULAR_PHONG, light_terms

__all__ = [
    "BLOCK",
    "MODE_AVERAGE",
    "MODE_COMPOSITE",
    "MODE_ISOSURFACE",
    "MODE_MINIP",
    "MODE_MIP",
    "PARAMS",
    "block_ranges",
    "cast_composite",
    "cast_composite_merged",
    "cast_isosurface",
    "cast_projection",
    "cast_rays",
]

MODE_COMPOSITE, MODE_MIP, MODE_MINIP, MODE_AVERAGE, MODE_ISOSURFACE = 0, 1, 2, 3, 4
BLOCK = 8
"""Cells per side of an empty-space-skipping block."""

# params layout (float64)
P_STEP, P_UNIT, P_LEVEL, P_SHADE = 0, 1, 2, 3
P_KA, P_KD, P_KS, P_SHININESS = 4, 5, 6, 7
P_AMBIENT = 8  # 3 values
P_EYE = 11  # 3 values
P_SPECULAR_PHONG, P_TABLE_LOW, P_TABLE_SCALE, P_TERMINATE, P_BISECTIONS, P_ANCHORED = 14, 15, 16, 17, 18, 19
P_CLEAR_BELOW = 20  # values at or below this have opacity 0 in the table (no lookup needed)
PARAMS = 21
# matrices (5, 4, 4)
M_GRID_FROM_WINDOW, M_MODEL_FROM_GRID, M_WINDOW_FROM_GRID, M_WORLD_FROM_GRID, M_NORMAL_FROM_GRID = 0, 1, 2, 3, 4
# blocks (bx, by, bz, 3) float32: min, max, empty (1.0: opacity 0 over the block's range)
B_MIN, B_MAX, B_EMPTY = 0, 1, 2


@kernel
def block_ranges(data, blocks):  # pragma: no cover - compiled
    """Min and max of the (BLOCK + 1)³ grid points each block's cells touch, into ``blocks[..., :2]`` (serial:
    one pass over the data, once per volume)."""
    nx, ny, nz = data.shape
    bx, by, bz = blocks.shape[0], blocks.shape[1], blocks.shape[2]
    for b in range(bx):
        i0, i1 = b * BLOCK, min(b * BLOCK + BLOCK, nx - 1)
        for c in range(by):
            j0, j1 = c * BLOCK, min(c * BLOCK + BLOCK, ny - 1)
            for d in range(bz):
                k0, k1 = d * BLOCK, min(d * BLOCK + BLOCK, nz - 1)
                low, high = np.inf, -np.inf
                for i in range(i0, i1 + 1):
                    for j in range(j0, j1 + 1):
                        for k in range(k0, k1 + 1):
                            v = data[i, j, k]
                            low = min(low, v)
                            high = max(high, v)
                blocks[b, c, d, B_MIN] = low
                blocks[b, c, d, B_MAX] = high


@kernel
def _cell(data, u0, u1, u2):  # pragma: no cover - compiled
    """The cell (i, j, k) holding grid position u (clamped into the box) and the fractions (fx, fy, fz) in it."""
    nx, ny, nz = data.shape
    u0 = min(max(u0, 0.0), nx - 1.0)
    u1 = min(max(u1, 0.0), ny - 1.0)
    u2 = min(max(u2, 0.0), nz - 1.0)
    i, j, k = min(int(u0), nx - 2), min(int(u1), ny - 2), min(int(u2), nz - 2)
    return i, j, k, u0 - i, u1 - j, u2 - k


@kernel
def _trilinear(data, i, j, k, fx, fy, fz):  # pragma: no cover - compiled
    """Trilinear interpolation inside cell (i, j, k) at fractions (fx, fy, fz)."""
    c00 = data[i, j, k] * (1.0 - fz) + data[i, j, k + 1] * fz
    c01 = data[i, j + 1, k] * (1.0 - fz) + data[i, j + 1, k + 1] * fz
    c10 = data[i + 1, j, k] * (1.0 - fz) + data[i + 1, j, k + 1] * fz
    c11 = data[i + 1, j + 1, k] * (1.0 - fz) + data[i + 1, j + 1, k + 1] * fz
    c0 = c00 * (1.0 - fy) + c01 * fy
    c1 = c10 * (1.0 - fy) + c11 * fy
    return c0 * (1.0 - fx) + c1 * fx


@kernel
def _sample(data, u0, u1, u2):  # pragma: no cover - compiled
    """Trilinear value at grid position (u0, u1, u2), clamped into the box."""
    i, j, k, fx, fy, fz = _cell(data, u0, u1, u2)
    return _trilinear(data, i, j, k, fx, fy, fz)


@kernel
def _table_index(table, params, value):  # pragma: no cover - compiled
    """Entry i and fraction t of `value` in the transfer-function table (clamped at the ends)."""
    size = table.shape[1]
    f = (value - params[P_TABLE_LOW]) * params[P_TABLE_SCALE]
    f = min(max(f, 0.0), size - 1.0)
    i = min(int(f), size - 2)
    return i, f - i


@kernel
def _lookup(table, params, value, channel):  # pragma: no cover - compiled
    """One channel of the transfer-function table at `value` (linear between entries, clamped at the ends)."""
    size = table.shape[1]
    f = (value - params[P_TABLE_LOW]) * params[P_TABLE_SCALE]
    f = min(max(f, 0.0), size - 1.0)
    i = min(int(f), size - 2)
    t = f - i
    return table[channel, i] * (1.0 - t) + table[channel, i + 1] * t


@kernel
def _block_of(blocks, data, u0, u1, u2):  # pragma: no cover - compiled
    """(bx, by, bz) of the block holding the cell of grid position u."""
    nx, ny, nz = data.shape
    i = min(max(int(u0), 0), nx - 2) // BLOCK
    j = min(max(int(u1), 0), ny - 2) // BLOCK
    k = min(max(int(u2), 0), nz - 2) // BLOCK
    return i, j, k


@kernel
def _block_exit(origin, direction, bi, bj, bk, shape):  # pragma: no cover - compiled
    """The ray parameter where u = origin + s·direction leaves block (bi, bj, bk)'s cell box."""
    exit_s = np.inf
    index = (bi, bj, bk)
    for a in range(3):
        d = direction[a]
        if d == 0.0:
            continue
        low = index[a] * BLOCK
        high = min(low + BLOCK, shape[a] - 1)
        bound = high if d > 0.0 else low
        exit_s = min(exit_s, (bound - origin[a]) / d)
    return exit_s


@kernel
def _shade(data, matrices, params, lights, u, view_dir, r, g, b):  # pragma: no cover - compiled
    """``frustum.shading``'s illumination of base color (r, g, b) at grid position u with the gradient normal.

    ``view_dir`` is the unit vector toward the eye (world). Returns (r, g, b) clamped to [0, 1]; a zero
    gradient leaves the base color unlit.
    """
    h = 1.0
    g0 = _sample(data, u[0] + h, u[1], u[2]) - _sample(data, u[0] - h, u[1], u[2])
    g1 = _sample(data, u[0], u[1] + h, u[2]) - _sample(data, u[0], u[1] - h, u[2])
    g2 = _sample(data, u[0], u[1], u[2] + h) - _sample(data, u[0], u[1], u[2] - h)
    m = matrices[M_NORMAL_FROM_GRID]
    n0 = -(m[0, 0] * g0 + m[0, 1] * g1 + m[0, 2] * g2)
    n1 = -(m[1, 0] * g0 + m[1, 1] * g1 + m[1, 2] * g2)
    n2 = -(m[2, 0] * g0 + m[2, 1] * g1 + m[2, 2] * g2)
    length = math.sqrt(n0 * n0 + n1 * n1 + n2 * n2)
    if not length > 1e-12:
        return r, g, b
    n0, n1, n2 = n0 / length, n1 / length, n2 / length
    if n0 * view_dir[0] + n1 * view_dir[1] + n2 * view_dir[2] < 0.0:  # two-sided: face the viewer
        n0, n1, n2 = -n0, -n1, -n2
    w = matrices[M_WORLD_FROM_GRID]
    p0 = w[0, 0] * u[0] + w[0, 1] * u[1] + w[0, 2] * u[2] + w[0, 3]
    p1 = w[1, 0] * u[0] + w[1, 1] * u[1] + w[1, 2] * u[2] + w[1, 3]
    p2 = w[2, 0] * u[0] + w[2, 1] * u[1] + w[2, 2] * u[2] + w[2, 3]
    ka, kd, ks, shininess = params[P_KA], params[P_KD], params[P_KS], params[P_SHININESS]
    dr, dg, db = ka * params[P_AMBIENT], ka * params[P_AMBIENT + 1], ka * params[P_AMBIENT + 2]
    sr, sg, sb = 0.0, 0.0, 0.0
    e0, e1, e2 = params[P_EYE] - p0, params[P_EYE + 1] - p1, params[P_EYE + 2] - p2
    el = math.sqrt(e0 * e0 + e1 * e1 + e2 * e2)
    if el > 0.0:
        e0, e1, e2 = e0 / el, e1 / el, e2 / el
    specular_model = SPECULAR_PHONG if params[P_SPECULAR_PHONG] != 0.0 else SPECULAR_BLINN
    for k in range(lights.shape[0]):
        lit, lambert, spec = light_terms(lights, k, specular_model, shininess, 1.0, p0, p1, p2, n0, n1, n2, e0, e1, e2)
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
    return (min(max(r * dr + sr, 0.0), 1.0), min(max(g * dg + sg, 0.0), 1.0), min(max(b * db + sb, 0.0), 1.0))


@kernel
def _samples(s0, s1, ds, anchored):  # pragma: no cover - compiled
    """Where the samples of the ray part [s0, s1] lie: (first, count, tail_s, tail).

    Full samples k = 0 … count − 1 at $first + k·ds$ each stand for a segment ds; when $tail > 0$ one more at
    ``tail_s`` stands for a segment tail (<= ds). ``anchored`` false (sampling "entry"): the middles of segments
    ds from s0, the last one (the tail) shorter. True (sampling "near"): every whole multiple of ds from the
    ray's point on the near plane (s = 0) inside [s0, s1], no tail.
    """
    if anchored:
        k0 = math.ceil(s0 / ds)
        return k0 * ds, max(math.floor(s1 / ds) - k0 + 1, 0), s1, 0.0
    count = math.ceil((s1 - s0) / ds)
    last = (s1 - s0) - (count - 1) * ds
    return s0 + 0.5 * ds, count - 1, s0 + (count - 1) * ds + 0.5 * last, last


@kernel
def _walk_start(o0, o1, o2, e0, e1, e2, nx, ny, nz, u0, u1, u2):  # pragma: no cover - compiled
    """Start of a 3D DDA over the blocks along the ray u = o + s·e (grid of shape (nx, ny, nz)) from grid position
    u: the block (bi, bj, bk) of u's cell, the step (±1, 0) per axis, the ray parameter where the ray leaves the
    block through each axis (inf if never) and the increments of those parameters per block."""
    bi = max(min(int(u0), nx - 2), 0) // BLOCK
    bj = max(min(int(u1), ny - 2), 0) // BLOCK
    bk = max(min(int(u2), nz - 2), 0) // BLOCK
    step0, t0, dt0 = _axis_start(o0, e0, bi)
    step1, t1, dt1 = _axis_start(o1, e1, bj)
    step2, t2, dt2 = _axis_start(o2, e2, bk)
    return bi, bj, bk, step0, step1, step2, t0, t1, t2, dt0, dt1, dt2


@kernel
def _axis_start(o, d, b):  # pragma: no cover - compiled
    """One axis of ``_walk_start``: (step, exit parameter, parameter per block)."""
    if d > 0.0:
        return 1, ((b + 1) * BLOCK - o) / d, BLOCK / d
    if d < 0.0:
        return -1, (b * BLOCK - o) / d, -BLOCK / d
    return 0, np.inf, np.inf


@kernel
def _cell_at(data, u0, u1, u2):  # pragma: no cover - compiled
    """``_cell`` for a position inside the box up to rounding (integer clamps only)."""
    nx, ny, nz = data.shape
    i = max(min(int(u0), nx - 2), 0)
    j = max(min(int(u1), ny - 2), 0)
    k = max(min(int(u2), nz - 2), 0)
    return i, j, k, u0 - i, u1 - j, u2 - k


@kernel
def _value(data, u0, u1, u2):  # pragma: no cover - compiled
    """Trilinear value at a position inside the box up to rounding."""
    i, j, k, fx, fy, fz = _cell_at(data, u0, u1, u2)
    return _trilinear(data, i, j, k, fx, fy, fz)


@kernel
def _average(data, origin, direction, s0, s1, ds, anchored):  # pragma: no cover - compiled
    """Length-weighted mean of the samples along the ray (NaN when there is none)."""
    first, count, tail_s, tail = _samples(s0, s1, ds, anchored)
    total = 0.0
    for k in range(count):
        s = first + k * ds
        total += _value(data, origin[0] + s * direction[0], origin[1] + s * direction[1], origin[2] + s * direction[2])
    total *= ds
    if tail > 0.0:
        total += tail * _value(data, origin[0] + tail_s * direction[0], origin[1] + tail_s * direction[1],
                               origin[2] + tail_s * direction[2])  # fmt: skip
    length = count * ds + tail
    return total / length if length > 0.0 else np.nan


@kernel
def _position(first, ds, count, tail_s, tail, s1, m):  # pragma: no cover - compiled
    """Ray parameter of the m-th of the isosurface search's points: the full samples, the tail sample, then s1."""
    if m < count:
        return first + m * ds
    if m == count and tail > 0.0:
        return tail_s
    return s1


@kernel
def _first_crossing(data, blocks, origin, direction, s0, s1, ds, level, bisections,
                    anchored):  # pragma: no cover - compiled  # fmt: skip
    """Ray parameter of the first crossing of `level` (bisection between the samples around it), or −1.

    The values compared are at s0, every sample, and s1."""
    first, count, tail_s, tail = _samples(s0, s1, ds, anchored)
    points = count + (1 if tail > 0.0 else 0) + 1
    previous_s, previous = s0, _sample(data, origin[0] + s0 * direction[0], origin[1] + s0 * direction[1],
                                       origin[2] + s0 * direction[2]) - level  # fmt: skip
    m = 0
    while m < points:
        s = _position(first, ds, count, tail_s, tail, s1, m)
        u0, u1, u2 = origin[0] + s * direction[0], origin[1] + s * direction[1], origin[2] + s * direction[2]
        if m < count:
            bi, bj, bk = _block_of(blocks, data, u0, u1, u2)
            low, high = blocks[bi, bj, bk, B_MIN] - level, blocks[bi, bj, bk, B_MAX] - level
            if (previous < 0.0 and high < 0.0) or (previous > 0.0 and low > 0.0):  # the block stays on one side
                exit_s = _block_exit(origin, direction, bi, bj, bk, data.shape)
                m_next = math.ceil((exit_s - first) / ds)
                if m_next > m + 1:
                    m = min(m_next, count) - 1  # keep the sample before the next block as `previous`
                    previous_s = first + m * ds
                    m += 1
                    continue
        value = _sample(data, u0, u1, u2) - level
        if value == 0.0 or (value > 0.0) != (previous > 0.0):
            if value == 0.0:
                return s
            a, b, fa = previous_s, s, previous
            for _ in range(bisections):
                mid = 0.5 * (a + b)
                fm = _sample(data, origin[0] + mid * direction[0], origin[1] + mid * direction[1],
                             origin[2] + mid * direction[2]) - level  # fmt: skip
                if (fm > 0.0) == (fa > 0.0) and fm != 0.0:
                    a, fa = mid, fm
                else:
                    b = mid
            return 0.5 * (a + b)
        previous_s, previous = s, value
        m += 1
    return -1.0


@kernel
def _ray(matrices, planes, shape, x, y, window_depth, origin, direction):  # pragma: no cover - compiled
    """Ray of window point (x, y) in grid coordinates into origin/direction; returns (s0, s1) (empty: s0 >= s1)."""
    m = matrices[M_GRID_FROM_WINDOW]
    for z, target in ((0.0, origin), (1.0, direction)):
        w = m[3, 0] * x + m[3, 1] * y + m[3, 2] * z + m[3, 3]
        for a in range(3):
            target[a] = (m[a, 0] * x + m[a, 1] * y + m[a, 2] * z + m[a, 3]) / w
    for a in range(3):
        direction[a] -= origin[a]
    s0, s1 = 0.0, 1.0
    for a in range(3):  # slabs 0 <= u_a <= n_a − 1
        d = direction[a]
        high = shape[a] - 1.0
        if d == 0.0:
            if origin[a] < 0.0 or origin[a] > high:
                return 1.0, 0.0
            continue
        t0, t1 = (0.0 - origin[a]) / d, (high - origin[a]) / d
        if t0 > t1:
            t0, t1 = t1, t0
        s0, s1 = max(s0, t0), min(s1, t1)
    for p in range(planes.shape[0]):  # half-spaces a·u + d >= 0
        start = planes[p, 0] * origin[0] + planes[p, 1] * origin[1] + planes[p, 2] * origin[2] + planes[p, 3]
        rate = planes[p, 0] * direction[0] + planes[p, 1] * direction[1] + planes[p, 2] * direction[2]
        if rate == 0.0:
            if start < 0.0:
                return 1.0, 0.0
        elif rate > 0.0:
            s0 = max(s0, -start / rate)
        else:
            s1 = min(s1, -start / rate)
    if window_depth < 1.0 and s0 < s1:  # the opaque surface's point on this ray ends it
        w = m[3, 0] * x + m[3, 1] * y + m[3, 2] * window_depth + m[3, 3]
        along, norm2 = 0.0, 0.0
        for a in range(3):
            q = (m[a, 0] * x + m[a, 1] * y + m[a, 2] * window_depth + m[a, 3]) / w - origin[a]
            along += q * direction[a]
            norm2 += direction[a] * direction[a]
        s1 = min(s1, along / norm2)
    return s0, s1


def cast_rays(mode, data, blocks, table, matrices, planes, params, lights, depth, color):
    """Cast one ray per pixel and blend the result over ``color`` (H, W, 4) uint8 (a driver: the compiled
    kernel of `mode` runs over pieces of the rows on a pool of threads; only that mode's kernel is compiled).

    `data` (nx, ny, nz) float32; `blocks` (bx, by, bz, 3) float32 from ``block_ranges`` plus the empty flags;
    `table` (5, T) float64 rows r, g, b, α, α corrected for the step Δ (each row one contiguous run: the
    opacity lookups of every sample stay in one small array) over the scalar range
    $value = low + t / scale$; `matrices` (5, 4, 4) as the ``M_*`` constants; `planes` (P, 4) clip planes in
    grid coordinates; `params` (PARAMS,) as the ``P_*`` constants; `lights` (K, 16) from
    ``shading.pack_lights``; `depth` (H, W) float32 window depth (read; the isosurface mode writes its hits).
    Rows of the buffers are stored top row first (row r is window y = H − 1 − r). Pieces of rows are taken by
    the threads as they finish (rows off the volume cost nothing); each piece owns its rows, so the bytes do not
    depend on the thread count.
    """
    if mode == MODE_COMPOSITE:
        cast_composite(data, blocks, table, matrices, planes, params, lights, depth, color)
    elif mode == MODE_ISOSURFACE:
        cast_isosurface(data, blocks, table, matrices, planes, params, lights, depth, color)
    else:
        cast_projection(mode, data, blocks, table, matrices, planes, params, depth, color)


@parallel_kernel(lambda *arguments: arguments[-2].shape[0], pieces_per_thread=16)
def cast_composite(data, blocks, table, matrices, planes, params, lights, depth, color, start,
                   stop):  # pragma: no cover  # fmt: skip
    """``MODE_COMPOSITE`` over image rows [start, stop) (see ``cast_rays``): front to back along each ray.

    Empty-space skipping walks the blocks the ray crosses (a 3D DDA over the block grid, Amanatides & Woo): the
    samples before an empty block's exit are skipped, the others run without a block lookup each. (The ray loop
    is written out here, not called per pixel: a call passing this many arrays cost ~0.3 µs per ray.)
    """
    height, width = depth.shape
    shape = np.array(data.shape, dtype=np.float64)
    origin, direction, view_dir, out, u = np.empty(3), np.empty(3), np.empty(3), np.empty(4), np.empty(3)
    nbx, nby, nbz = blocks.shape[0], blocks.shape[1], blocks.shape[2]
    nx, ny, nz = data.shape
    threshold = params[P_TERMINATE]
    shade = params[P_SHADE] != 0.0
    anchored = params[P_ANCHORED] != 0.0
    clear_below = params[P_CLEAR_BELOW]
    for row in range(start, stop):
        y = height - 1 - row + 0.5
        for column in range(width):
            s0, s1, ds, model_length = _pixel_ray(matrices, planes, shape, params, column + 0.5, y,
                                                  depth[row, column], origin, direction, view_dir, shade)  # fmt: skip
            if not s0 < s1:
                continue
            first, count, tail_s, tail = _samples(s0, s1, ds, anchored)
            cr, cg, cb, acc = 0.0, 0.0, 0.0, 0.0
            done = False
            if count > 0:
                b0, b1, b2 = (origin[0] + first * direction[0], origin[1] + first * direction[1],
                              origin[2] + first * direction[2])  # fmt: skip
                d0, d1, d2 = ds * direction[0], ds * direction[1], ds * direction[2]
                bi, bj, bk, step0, step1, step2, t0, t1, t2, dt0, dt1, dt2 = _walk_start(
                    origin[0], origin[1], origin[2], direction[0], direction[1], direction[2], nx, ny, nz, b0, b1, b2)
                inverse_ds = 1.0 / ds
                k = 0
                while True:
                    end = (min(t0, t1, t2) - first) * inverse_ds  # samples before the block's exit: k < ceil(end)
                    k_stop = count if end >= count else math.ceil(end)
                    if blocks[bi, bj, bk, B_EMPTY] == 0.0:  # else opacity 0 over the block: its samples add nothing
                        while k < k_stop:
                            u0, u1, u2 = b0 + k * d0, b1 + k * d1, b2 + k * d2
                            k += 1
                            value = _value(data, u0, u1, u2)
                            if value <= clear_below:  # opacity 0: no lookup
                                continue
                            t_index, t = _table_index(table, params, value)
                            alpha = table[4, t_index] * (1.0 - t) + table[4, t_index + 1] * t  # corrected for Δ
                            if alpha > 0.0 or not shade:  # (unshaded, α = 0 adds 0: no branch on α)
                                # kernel specialisation kept on purpose (the tail's and cast_composite_merged's
                                # twin): one shared call for colour, shading and 'over' ran 3.4× slower here
                                r = table[0, t_index] * (1.0 - t) + table[0, t_index + 1] * t
                                g = table[1, t_index] * (1.0 - t) + table[1, t_index + 1] * t
                                b = table[2, t_index] * (1.0 - t) + table[2, t_index + 1] * t
                                if shade:
                                    u[0], u[1], u[2] = u0, u1, u2
                                    r, g, b = _shade(data, matrices, params, lights, u, view_dir, r, g, b)
                                weight = (1.0 - acc) * alpha
                                cr += weight * r
                                cg += weight * g
                                cb += weight * b
                                acc += weight
                                if acc >= threshold:  # early ray termination
                                    done = True
                                    break
                    k = max(k, k_stop)
                    if done or k >= count:
                        break
                    if t0 <= t1 and t0 <= t2:  # (kernel specialisation kept on purpose: cast_projection's DDA step)
                        bi += step0
                        t0 += dt0
                    elif t1 <= t2:
                        bj += step1
                        t1 += dt1
                    else:
                        bk += step2
                        t2 += dt2
                    if bi < 0 or bj < 0 or bk < 0 or bi >= nbx or bj >= nby or bk >= nbz:  # rounding at the faces
                        bi, bj, bk = min(max(bi, 0), nbx - 1), min(max(bj, 0), nby - 1), min(max(bk, 0), nbz - 1)
            if tail > 0.0 and not done:  # the last, shorter segment: its opacity corrected for its own length
                u0, u1, u2 = (origin[0] + tail_s * direction[0], origin[1] + tail_s * direction[1],
                              origin[2] + tail_s * direction[2])  # fmt: skip
                t_index, t = _table_index(table, params, _value(data, u0, u1, u2))
                alpha = table[3, t_index] * (1.0 - t) + table[3, t_index + 1] * t
                if alpha > 0.0:
                    alpha = 1.0 - (1.0 - alpha) ** (tail * model_length / params[P_UNIT])
                    # kernel specialisation kept on purpose: the sample loop's colour and 'over', for the tail
                    r = table[0, t_index] * (1.0 - t) + table[0, t_index + 1] * t
                    g = table[1, t_index] * (1.0 - t) + table[1, t_index + 1] * t
                    b = table[2, t_index] * (1.0 - t) + table[2, t_index + 1] * t
                    if shade:
                        u[0], u[1], u[2] = u0, u1, u2
                        r, g, b = _shade(data, matrices, params, lights, u, view_dir, r, g, b)
                    weight = (1.0 - acc) * alpha
                    cr += weight * r
                    cg += weight * g
                    cb += weight * b
                    acc += weight
            out[0], out[1], out[2], out[3] = cr, cg, cb, acc
            _blend(color, row, column, out)


@parallel_kernel(lambda *arguments: arguments[-2].shape[0], pieces_per_thread=16)
def cast_projection(mode, data, blocks, table, matrices, planes, params, depth, color, start,
                    stop):  # pragma: no cover  # fmt: skip
    """``MODE_MIP``, ``MODE_MINIP`` or ``MODE_AVERAGE`` over image rows [start, stop): one value per ray,
    classified by the table (no opacity correction) and blended over the buffer. MIP / MinIP walk the blocks
    along the ray as ``cast_composite`` does and skip a block whose max (min) cannot beat the current extreme."""
    height, width = depth.shape
    shape = np.array(data.shape, dtype=np.float64)
    origin, direction, view_dir, out = np.empty(3), np.empty(3), np.empty(3), np.empty(4)
    anchored = params[P_ANCHORED] != 0.0
    nbx, nby, nbz = blocks.shape[0], blocks.shape[1], blocks.shape[2]
    nx, ny, nz = data.shape
    sign = -1.0 if mode == MODE_MINIP else 1.0
    bound = B_MIN if mode == MODE_MINIP else B_MAX
    for row in range(start, stop):
        y = height - 1 - row + 0.5
        for column in range(width):
            s0, s1, ds, _ = _pixel_ray(matrices, planes, shape, params, column + 0.5, y, depth[row, column],
                                       origin, direction, view_dir, False)  # fmt: skip
            if not s0 < s1:
                continue
            if mode == MODE_AVERAGE:
                value = _average(data, origin, direction, s0, s1, ds, anchored)
                if math.isnan(value):  # no sample on this ray
                    continue
            else:
                first, count, tail_s, tail = _samples(s0, s1, ds, anchored)
                if count == 0 and not tail > 0.0:  # no sample on this ray
                    continue
                best = -np.inf  # the largest of sign · value
                if count > 0:
                    b0, b1, b2 = (origin[0] + first * direction[0], origin[1] + first * direction[1],
                                  origin[2] + first * direction[2])  # fmt: skip
                    d0, d1, d2 = ds * direction[0], ds * direction[1], ds * direction[2]
                    bi, bj, bk, step0, step1, step2, t0, t1, t2, dt0, dt1, dt2 = _walk_start(
                        origin[0], origin[1], origin[2], direction[0], direction[1], direction[2], nx, ny, nz, b0, b1,
                        b2)  # fmt: skip
                    inverse_ds = 1.0 / ds
                    k = 0
                    while True:
                        end = (min(t0, t1, t2) - first) * inverse_ds  # samples before the block's exit
                        k_stop = count if end >= count else math.ceil(end)
                        limit = sign * blocks[bi, bj, bk, bound]
                        if limit > best:  # else nothing in this block can beat the current extreme
                            while k < k_stop:
                                best = max(best, sign * _value(data, b0 + k * d0, b1 + k * d1, b2 + k * d2))
                                k += 1
                                if best >= limit:
                                    break
                        k = max(k, k_stop)
                        if k >= count:
                            break
                        if t0 <= t1 and t0 <= t2:  # (kernel specialisation kept on purpose: cast_composite's)
                            bi += step0
                            t0 += dt0
                        elif t1 <= t2:
                            bj += step1
                            t1 += dt1
                        else:
                            bk += step2
                            t2 += dt2
                        if bi < 0 or bj < 0 or bk < 0 or bi >= nbx or bj >= nby or bk >= nbz:  # rounding
                            bi, bj, bk = min(max(bi, 0), nbx - 1), min(max(bj, 0), nby - 1), min(max(bk, 0), nbz - 1)
                if tail > 0.0:
                    best = max(best, sign * _value(data, origin[0] + tail_s * direction[0],
                                                   origin[1] + tail_s * direction[1],
                                                   origin[2] + tail_s * direction[2]))  # fmt: skip
                value = sign * best
            alpha = _lookup(table, params, value, 3)
            for c in range(3):
                out[c] = alpha * _lookup(table, params, value, c)
            out[3] = alpha
            _blend(color, row, column, out)


@parallel_kernel(lambda *arguments: arguments[-2].shape[0], pieces_per_thread=16)
def cast_isosurface(data, blocks, table, matrices, planes, params, lights, depth, color, start,
                    stop):  # pragma: no cover  # fmt: skip
    """``MODE_ISOSURFACE`` over image rows [start, stop): the first crossing of the level, shaded with the table's
    color at the level, opaque; its window depth goes into `depth`."""
    height, width = depth.shape
    shape = np.array(data.shape, dtype=np.float64)
    origin, direction, view_dir, out, u = np.empty(3), np.empty(3), np.empty(3), np.empty(4), np.empty(3)
    level = params[P_LEVEL]
    r = _lookup(table, params, level, 0)
    g = _lookup(table, params, level, 1)
    b = _lookup(table, params, level, 2)
    wm = matrices[M_WINDOW_FROM_GRID]
    for row in range(start, stop):
        y = height - 1 - row + 0.5
        for column in range(width):
            s0, s1, ds, _ = _pixel_ray(matrices, planes, shape, params, column + 0.5, y, depth[row, column],
                                       origin, direction, view_dir, True)  # fmt: skip
            if not s0 < s1:
                continue
            hit = _first_crossing(data, blocks, origin, direction, s0, s1, ds, level, int(params[P_BISECTIONS]),
                                  params[P_ANCHORED] != 0.0)  # fmt: skip
            if hit < 0.0:
                continue
            for a in range(3):
                u[a] = origin[a] + hit * direction[a]
            out[0], out[1], out[2] = _shade(data, matrices, params, lights, u, view_dir, r, g, b)
            out[3] = 1.0
            zw = wm[2, 0] * u[0] + wm[2, 1] * u[1] + wm[2, 2] * u[2] + wm[2, 3]
            ww = wm[3, 0] * u[0] + wm[3, 1] * u[1] + wm[3, 2] * u[2] + wm[3, 3]
            depth[row, column] = min(depth[row, column], zw / ww)
            _blend(color, row, column, out)


@parallel_kernel(lambda *arguments: arguments[-2].shape[0], pieces_per_thread=16)
def cast_composite_merged(datas, blocks, tables, matrices, planes, params, lights, depth, color, start,
                          stop):  # pragma: no cover  # fmt: skip
    """Several ``MODE_COMPOSITE`` volumes composited together over image rows [start, stop): every ray takes the
    samples of all the volumes it crosses in the order of the ray parameter (their sequences merged), each sample
    classified by its own volume's table and opacity-corrected for its own step, so overlapping volumes mix.

    `datas`, `blocks`: tuples of the volumes' grids and block arrays (one compiled specialization per number of
    volumes, cached like every kernel); `tables` (V, 5, T), `matrices`
    (V, 5, 4, 4), `planes` (V, P, 4) (rows of zeros pad), `params` (V, PARAMS): the single-volume arguments
    stacked. Each volume's samples lie where ``cast_composite`` puts them (the ray parameter s is the same for
    every volume: 0 on the near plane, 1 on the far plane), and its empty blocks are skipped per sample.
    """
    height, width = depth.shape
    count_v = len(datas)
    origins, directions, view_dirs = np.empty((count_v, 3)), np.empty((count_v, 3)), np.empty((count_v, 3))
    first, ds, tail_s, tail, model_length = (np.empty(count_v), np.empty(count_v), np.empty(count_v),
                                             np.empty(count_v), np.empty(count_v))  # fmt: skip
    count, k = np.empty(count_v, dtype=np.int64), np.empty(count_v, dtype=np.int64)
    shapes = np.empty((count_v, 3))
    for v in range(count_v):
        for a in range(3):
            shapes[v, a] = datas[v].shape[a]
    out, u = np.empty(4), np.empty(3)
    threshold = params[0, P_TERMINATE]
    for row in range(start, stop):
        y = height - 1 - row + 0.5
        for column in range(width):
            any_ray = False
            for v in range(count_v):
                s0, s1, ds[v], model_length[v] = _pixel_ray(matrices[v], planes[v], shapes[v], params[v],
                                                            column + 0.5, y, depth[row, column], origins[v],
                                                            directions[v], view_dirs[v], True)  # fmt: skip
                k[v], count[v], tail[v] = 0, 0, 0.0
                if s0 < s1:
                    first[v], count[v], tail_s[v], tail[v] = _samples(s0, s1, ds[v], params[v, P_ANCHORED] != 0.0)
                    any_ray = True
            if not any_ray:
                continue
            cr, cg, cb, acc = 0.0, 0.0, 0.0, 0.0
            while acc < threshold:
                v, s = -1, np.inf  # the volume whose next sample comes first along the ray
                for w in range(count_v):
                    if k[w] < count[w]:
                        candidate = first[w] + k[w] * ds[w]
                    elif k[w] == count[w] and tail[w] > 0.0:
                        candidate = tail_s[w]
                    else:
                        continue
                    if candidate < s:
                        v, s = w, candidate
                if v < 0:
                    break
                data, origin, direction = datas[v], origins[v], directions[v]
                u0, u1, u2 = origin[0] + s * direction[0], origin[1] + s * direction[1], origin[2] + s * direction[2]
                full = k[v] < count[v]
                if full:
                    bi, bj, bk = _block_of(blocks[v], data, u0, u1, u2)
                    if blocks[v][bi, bj, bk, B_EMPTY] != 0.0:  # jump to this volume's first sample past the block
                        exit_s = _block_exit(origin, direction, bi, bj, bk, data.shape)
                        k[v] = max(k[v] + 1, math.ceil((exit_s - first[v]) / ds[v]))
                        continue
                k[v] += 1
                table, p = tables[v], params[v]
                t_index, t = _table_index(table, p, _value(data, u0, u1, u2))
                if full:
                    alpha = table[4, t_index] * (1.0 - t) + table[4, t_index + 1] * t
                else:
                    alpha = table[3, t_index] * (1.0 - t) + table[3, t_index + 1] * t
                    if alpha > 0.0:
                        alpha = 1.0 - (1.0 - alpha) ** (tail[v] * model_length[v] / p[P_UNIT])
                if alpha > 0.0:  # kernel specialisation kept on purpose: cast_composite's colour and 'over'
                    r = table[0, t_index] * (1.0 - t) + table[0, t_index + 1] * t
                    g = table[1, t_index] * (1.0 - t) + table[1, t_index + 1] * t
                    b = table[2, t_index] * (1.0 - t) + table[2, t_index + 1] * t
                    if p[P_SHADE] != 0.0:
                        u[0], u[1], u[2] = u0, u1, u2
                        r, g, b = _shade(data, matrices[v], p, lights, u, view_dirs[v], r, g, b)
                    weight = (1.0 - acc) * alpha
                    cr += weight * r
                    cg += weight * g
                    cb += weight * b
                    acc += weight
            out[0], out[1], out[2], out[3] = cr, cg, cb, acc
            _blend(color, row, column, out)


@kernel
def _pixel_ray(matrices, planes, shape, params, x, y, window_depth, origin, direction, view_dir,
               shaded):  # pragma: no cover - compiled  # fmt: skip
    """The ray of window point (x, y) in grid coordinates (origin, direction, and, when `shaded`, the unit world
    vector toward the eye in view_dir); returns (s0, s1, ds, model_length), empty when s0 >= s1."""
    s0, s1 = _ray(matrices, planes, shape, x, y, window_depth, origin, direction)
    if not s0 < s1:
        return s0, s1, 0.0, 0.0
    model = matrices[M_MODEL_FROM_GRID]
    d0 = model[0, 0] * direction[0] + model[0, 1] * direction[1] + model[0, 2] * direction[2]
    d1 = model[1, 0] * direction[0] + model[1, 1] * direction[1] + model[1, 2] * direction[2]
    d2 = model[2, 0] * direction[0] + model[2, 1] * direction[1] + model[2, 2] * direction[2]
    model_length = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)  # model units per unit of s
    if not shaded:
        return s0, s1, params[P_STEP] / model_length, model_length
    world = matrices[M_WORLD_FROM_GRID]
    for a in range(3):  # toward the eye: minus the ray direction, in world coordinates
        view_dir[a] = -(world[a, 0] * direction[0] + world[a, 1] * direction[1] + world[a, 2] * direction[2])
    length = math.sqrt(view_dir[0] ** 2 + view_dir[1] ** 2 + view_dir[2] ** 2)
    for a in range(3):
        view_dir[a] /= length
    return s0, s1, params[P_STEP] / model_length, model_length


@kernel
def _blend(color, row, column, out):  # pragma: no cover - compiled
    """$out + (1 − out_α)·under$ into the pixel's bytes, $floor(255·v + 0.5)$."""
    under = 1.0 - out[3]
    for c in range(4):
        v = out[c] + under * (color[row, column, c] / 255.0)
        color[row, column, c] = np.uint8(math.floor(min(max(v, 0.0), 1.0) * 255.0 + 0.5))
