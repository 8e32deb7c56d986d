"""Point kernels: squares, disks, sphere impostors and surfels written into the depth buffer like surfaces.

Every point is depth-tested "less" against the float32 depth buffer and, where it wins, writes its depth, its
color bytes and (when asked for) its unit world normal and object id: points hide one another and meshes as
triangles do.

- ``STYLE_SQUARE``: a square of side s pixels centred on the point's window position covers the pixels whose
  centres lie in $[x − s/2, x + s/2) × [y − s/2, y + s/2)$ (OpenGL's ``GL_POINTS`` with ``gl_PointSize = s``);
  ``STYLE_DISK``: those whose centres lie within s/2 of it. Depth: the point's window depth.
- ``STYLE_SPHERE``: the pixel's ray $o + t·d$ (view space, through the pixel centre from the near to the far
  plane) meets the sphere $|p − c|² = r²$ at the smaller root $t = (−b − √(b² − a·k))/a$ with $a = d·d$,
  $b = (o − c)·d$, $k = |o − c|² − r²$; depth is that point's window depth, the normal $(p − c)/r$.
- ``STYLE_SURFEL``: the ray meets the disk's plane $n·(p − c) = 0$ at $t = n·(c − o)/(n·d)$, kept where
  $|p − c| < r$; the normal n turned toward the viewer.

Projection (``project_points`` / ``project_impostors``, parallel over points) writes one record per point, in
point order, and the frame-row range it touches (first > last: not drawn; a point is drawn when its centre
lies inside the view volume, as GL clips points; an impostor also when its bounding cube lies in front of the
near plane). Rows are binned into bands (``raster.particles.count_bands`` / ``fill_bands``: point order kept
inside each band) and each band is drawn by one thread, which owns its rows: no write races, the same bytes on
any number of threads, and for equal depths the first point wins.

Contract (kernels never validate): ``clip_from_model`` (4, 4), ``frame`` (width, height), records and rows
allocated by the caller with one row per point; ``colors`` (N, 3 | 4) float64 or (0, 3); ``normals`` (N, 3) unit
or (0, 3); ``params`` / ``lights`` / the lighting of ``raster.shade`` (``_illuminate``); ``item`` (ITEM,) int64
laid out by ``I_*``.
"""

from __future__ import annotations

import math

import numpy as np

from frustum.raster._jit import kernel, parallel_kernel, prefetch
from frustum.raster.shade import P_COLOR, P_EMISSIVE, _illuminate, _to_byte

__all__ = [
    "IMPOSTOR_FIELDS", "ITEM", "POINT_FIELDS", "STYLE_DISK", "STYLE_SPHERE", "STYLE_SQUARE", "STYLE_SURFEL",
    "draw_impostors", "draw_points", "project_impostors", "project_points",
]  # fmt: skip

STYLE_SQUARE, STYLE_DISK, STYLE_SPHERE, STYLE_SURFEL = 0, 1, 2, 3
POINT_FIELDS = 4
"""Square/disk record: window x, y, depth z, half size s/2 (pixels)."""
IMPOSTOR_FIELDS = 12
"""Sphere/surfel record: window box x_low, x_high, y_low, y_high; view centre (3), radius, view normal (3),
clip w of the centre."""
PREFETCH_AHEAD = 32
"""Entries ahead whose record and color ``draw_points`` prefetches."""
# item layout
I_STYLE, I_LIT, I_SPECULAR_MODEL, I_OBJECT_ID, I_WRITE_NORMALS, I_WRITE_IDS = 0, 1, 2, 3, 4, 5
ITEM = 6


@kernel
def _row(m: np.ndarray, k: int, x: float, y: float, z: float) -> float:
    """Row k of $M·[x, y, z, 1]$."""
    return ((m[k, 0] * x + m[k, 1] * y) + m[k, 2] * z) + m[k, 3]


@parallel_kernel(lambda points, *_: points.shape[0], grain=16384)
def project_points(points: np.ndarray, sizes: np.ndarray, clip_from_model: np.ndarray, frame: np.ndarray,
                   records: np.ndarray, rows: np.ndarray, start: int, stop: int) -> None:  # fmt: skip
    """Records (x, y, z, s/2) and frame-row ranges of points [start, stop).

    ``frame`` = (width, height, scale): ``sizes`` (N,), or (1,) one for all, is the side s in pixels when scale is
    0, else a world size shown as $s·scale/w$ pixels (scale = |P₁₁|·H/2). Drawn when $w > 0$ and
    $−w <= x_c, y_c, z_c <= w$; window $x = (x_c/w + 1)·W/2$, $y = (y_c/w + 1)·H/2$, $z = (z_c/w + 1)/2$.
    """
    width, height, scale = frame[0], frame[1], frame[2]
    last_row = int(height) - 1
    one = sizes.shape[0] == 1
    for k in range(start, stop):
        x, y, z = points[k, 0], points[k, 1], points[k, 2]
        w = _row(clip_from_model, 3, x, y, z)
        xc = _row(clip_from_model, 0, x, y, z)
        yc = _row(clip_from_model, 1, x, y, z)
        zc = _row(clip_from_model, 2, x, y, z)
        rows[k, 0], rows[k, 1] = 1, 0
        if not (w > 0.0 and -w <= xc <= w and -w <= yc <= w and -w <= zc <= w):
            continue
        half = 0.5 * (sizes[0] if one else sizes[k])
        if scale > 0.0:
            half *= scale / w
        wx = (xc / w + 1.0) * (width / 2.0)
        wy = (yc / w + 1.0) * (height / 2.0)
        records[k, 0], records[k, 1], records[k, 2], records[k, 3] = wx, wy, (zc / w + 1.0) * 0.5, half
        low_y = max(math.ceil(wy - half - 0.5), 0)
        high_y = min(math.ceil(wy + half - 0.5) - 1, last_row)
        if high_y < low_y:
            continue
        rows[k, 0] = last_row - high_y
        rows[k, 1] = last_row - low_y


@parallel_kernel(lambda centers, *_: centers.shape[0], grain=8192)
def project_impostors(centers: np.ndarray, radii: np.ndarray, normals: np.ndarray, view_from_model: np.ndarray,
                      clip_from_view: np.ndarray, frame: np.ndarray, records: np.ndarray, rows: np.ndarray,
                      start: int, stop: int) -> None:  # fmt: skip
    """Records and frame-row ranges of spheres or surfels [start, stop): centre c (view), radius r and normal
    (view; ``normals`` (0, 3) for spheres), and the window box of the cube $c ± r$ (which holds the sphere, so
    its image holds the sphere's and the disk's). Drawn when the centre is inside the view volume and the
    cube's corners all lie in front of the near plane ($z_c >= −w$, $w > 0$)."""
    width, height = frame[0], frame[1]
    last_row = int(height) - 1
    one = radii.shape[0] == 1
    for k in range(start, stop):
        rows[k, 0], rows[k, 1] = 1, 0
        px, py, pz = centers[k, 0], centers[k, 1], centers[k, 2]
        cx = _row(view_from_model, 0, px, py, pz)
        cy = _row(view_from_model, 1, px, py, pz)
        cz = _row(view_from_model, 2, px, py, pz)
        w = _row(clip_from_view, 3, cx, cy, cz)
        xc = _row(clip_from_view, 0, cx, cy, cz)
        yc = _row(clip_from_view, 1, cx, cy, cz)
        zc = _row(clip_from_view, 2, cx, cy, cz)
        if not (w > 0.0 and -w <= xc <= w and -w <= yc <= w and -w <= zc <= w):
            continue
        r = radii[0] if one else radii[k]
        x_low, x_high, y_low, y_high = math.inf, -math.inf, math.inf, -math.inf
        inside = True
        for corner in range(8):
            qx = cx + (r if corner & 1 else -r)
            qy = cy + (r if corner & 2 else -r)
            qz = cz + (r if corner & 4 else -r)
            qw = _row(clip_from_view, 3, qx, qy, qz)
            qz_clip = _row(clip_from_view, 2, qx, qy, qz)
            if not (qw > 0.0 and qz_clip >= -qw):
                inside = False
                break
            wx = (_row(clip_from_view, 0, qx, qy, qz) / qw + 1.0) * (width / 2.0)
            wy = (_row(clip_from_view, 1, qx, qy, qz) / qw + 1.0) * (height / 2.0)
            x_low, x_high = min(x_low, wx), max(x_high, wx)
            y_low, y_high = min(y_low, wy), max(y_high, wy)
        if not inside:
            continue
        records[k, 0], records[k, 1], records[k, 2], records[k, 3] = x_low, x_high, y_low, y_high
        records[k, 4], records[k, 5], records[k, 6], records[k, 7] = cx, cy, cz, r
        if normals.shape[0] > 0:
            nx, ny, nz = normals[k, 0], normals[k, 1], normals[k, 2]
            vx = (view_from_model[0, 0] * nx + view_from_model[0, 1] * ny) + view_from_model[0, 2] * nz
            vy = (view_from_model[1, 0] * nx + view_from_model[1, 1] * ny) + view_from_model[1, 2] * nz
            vz = (view_from_model[2, 0] * nx + view_from_model[2, 1] * ny) + view_from_model[2, 2] * nz
            length = math.sqrt((vx * vx + vy * vy) + vz * vz)
            records[k, 8], records[k, 9], records[k, 10] = vx / length, vy / length, vz / length
        records[k, 11] = w
        low_y = max(math.ceil(y_low - 0.5), 0)
        high_y = min(math.floor(y_high - 0.5), last_row)
        if high_y < low_y or x_high < 0.5 or x_low > width - 0.5:
            continue
        rows[k, 0] = last_row - high_y
        rows[k, 1] = last_row - low_y


@kernel
def _shade(params: np.ndarray, lights: np.ndarray, item: np.ndarray, colors: np.ndarray, k: int,
           px: float, py: float, pz: float, nx: float, ny: float, nz: float) -> tuple[float, float, float]:  # fmt: skip
    """Linear RGB of point k: base = the point's color (the material color for a cloud without colors); lit by
    ``raster.shade``'s model at world point P with unit world normal N when ``item[I_LIT]``, else the base color."""
    r, g, b = params[P_COLOR], params[P_COLOR + 1], params[P_COLOR + 2]
    if colors.shape[0] > 0:
        r, g, b = colors[k, 0], colors[k, 1], colors[k, 2]
    if item[I_LIT] == 0:
        return r, g, b
    dr, dg, db, sr, sg, sb = _illuminate(params, lights, item[I_SPECULAR_MODEL], px, py, pz, nx, ny, nz)
    return (r * dr + sr) + params[P_EMISSIVE], (g * dg + sg) + params[P_EMISSIVE + 1], (b * db + sb) + params[
        P_EMISSIVE + 2
    ]


@parallel_kernel(lambda records, starts, *_: starts.size - 1, pieces_per_thread=32)
def draw_points(records: np.ndarray, starts: np.ndarray, entries: np.ndarray, band_rows: int,
                world: np.ndarray, colors: np.ndarray, normals: np.ndarray, params: np.ndarray, lights: np.ndarray,
                item: np.ndarray, depth: np.ndarray, color: np.ndarray, normal_out: np.ndarray,
                id_out: np.ndarray, start: int, stop: int) -> None:  # fmt: skip
    """Squares or disks (``item[I_STYLE]``) of every band [start, stop) into the buffers, depth test "less".

    ``world`` (N, 3) world points and ``normals`` (N, 3) unit world normals, read when lit or written (else
    (0, 3)). Pixel (row, col) has its centre at window $(col + ½, H − 1 − row + ½)$.
    """
    height, width = depth.shape
    disk = item[I_STYLE] == STYLE_DISK
    has_normals = normals.shape[0] > 0
    for band in range(start, stop):
        first_row = band * band_rows
        last_row = min(first_row + band_rows, height) - 1
        end = starts[band + 1]
        for e in range(starts[band], end):
            if e + PREFETCH_AHEAD < end:  # records and colors are gathered at random: start the loads early
                ahead = entries[e + PREFETCH_AHEAD]
                prefetch(records, ahead, 0)
                if colors.shape[0] > 0:
                    prefetch(colors, ahead, 0)
            k = entries[e]
            x, y, z, half = records[k, 0], records[k, 1], records[k, 2], records[k, 3]
            low_y = max(math.ceil(y - half - 0.5), height - 1 - last_row)
            high_y = min(math.ceil(y + half - 0.5) - 1, height - 1 - first_row)
            low_x = max(math.ceil(x - half - 0.5), 0)
            high_x = min(math.ceil(x + half - 0.5) - 1, width - 1)
            zf = np.float32(z)
            shaded = False
            red, green, blue = np.uint8(0), np.uint8(0), np.uint8(0)
            nx, ny, nz = 0.0, 0.0, 0.0
            for wy in range(low_y, high_y + 1):
                row = height - 1 - wy
                dy = wy + 0.5 - y
                for col in range(low_x, high_x + 1):
                    if disk:
                        dx = col + 0.5 - x
                        if dx * dx + dy * dy > half * half:
                            continue
                    if not zf < depth[row, col]:
                        continue
                    if not shaded:
                        shaded = True
                        if has_normals:
                            nx, ny, nz = normals[k, 0], normals[k, 1], normals[k, 2]
                        px, py, pz = (world[k, 0], world[k, 1], world[k, 2]) if world.shape[0] > 0 else (0.0, 0.0, 0.0)
                        r, g, b = _shade(params, lights, item, colors, k, px, py, pz, nx, ny, nz)
                        red, green, blue = _to_byte(r), _to_byte(g), _to_byte(b)
                    depth[row, col] = zf
                    color[row, col, 0], color[row, col, 1], color[row, col, 2] = red, green, blue
                    color[row, col, 3] = 255
                    if item[I_WRITE_NORMALS]:
                        normal_out[row, col, 0], normal_out[row, col, 1], normal_out[row, col, 2] = nx, ny, nz
                    if item[I_WRITE_IDS]:
                        id_out[row, col] = item[I_OBJECT_ID]


@kernel
def _view_ray(view_from_clip: np.ndarray, xn: float, yn: float) -> tuple[float, float, float, float, float, float]:
    """(origin, direction) in view space of the ray through NDC (xn, yn): from the near plane point
    $V·(xn, yn, −1, 1)$ to the far plane point $V·(xn, yn, 1, 1)$ (after division; V = ``view_from_clip``)."""
    w0 = (view_from_clip[3, 0] * xn + view_from_clip[3, 1] * yn) - view_from_clip[3, 2] + view_from_clip[3, 3]
    w1 = (view_from_clip[3, 0] * xn + view_from_clip[3, 1] * yn) + view_from_clip[3, 2] + view_from_clip[3, 3]
    ox = ((view_from_clip[0, 0] * xn + view_from_clip[0, 1] * yn) - view_from_clip[0, 2] + view_from_clip[0, 3]) / w0
    oy = ((view_from_clip[1, 0] * xn + view_from_clip[1, 1] * yn) - view_from_clip[1, 2] + view_from_clip[1, 3]) / w0
    oz = ((view_from_clip[2, 0] * xn + view_from_clip[2, 1] * yn) - view_from_clip[2, 2] + view_from_clip[2, 3]) / w0
    fx = ((view_from_clip[0, 0] * xn + view_from_clip[0, 1] * yn) + view_from_clip[0, 2] + view_from_clip[0, 3]) / w1
    fy = ((view_from_clip[1, 0] * xn + view_from_clip[1, 1] * yn) + view_from_clip[1, 2] + view_from_clip[1, 3]) / w1
    fz = ((view_from_clip[2, 0] * xn + view_from_clip[2, 1] * yn) + view_from_clip[2, 2] + view_from_clip[2, 3]) / w1
    return ox, oy, oz, fx - ox, fy - oy, fz - oz


@parallel_kernel(lambda records, starts, *_: starts.size - 1, pieces_per_thread=32)
def draw_impostors(records: np.ndarray, starts: np.ndarray, entries: np.ndarray, band_rows: int,
                   matrices: np.ndarray, colors: np.ndarray, params: np.ndarray, lights: np.ndarray,
                   item: np.ndarray, depth: np.ndarray, color: np.ndarray, normal_out: np.ndarray,
                   id_out: np.ndarray, start: int, stop: int) -> None:  # fmt: skip
    """Spheres or surfels (``item[I_STYLE]``) of every band [start, stop), ray-cast per pixel (module docstring).

    ``matrices`` (3, 4, 4): ``view_from_clip``, ``clip_from_view``, ``world_from_view``. Lit with the world
    point and normal of the hit (when ``item[I_LIT]``).
    """
    height, width = depth.shape
    view_from_clip, clip_from_view, world_from_view = matrices[0], matrices[1], matrices[2]
    sphere = item[I_STYLE] == STYLE_SPHERE
    for band in range(start, stop):
        first_row = band * band_rows
        last_row = min(first_row + band_rows, height) - 1
        for e in range(starts[band], starts[band + 1]):
            k = entries[e]
            cx, cy, cz, radius = records[k, 4], records[k, 5], records[k, 6], records[k, 7]
            low_y = max(math.ceil(records[k, 2] - 0.5), height - 1 - last_row)
            high_y = min(math.floor(records[k, 3] - 0.5), height - 1 - first_row)
            low_x = max(math.ceil(records[k, 0] - 0.5), 0)
            high_x = min(math.floor(records[k, 1] - 0.5), width - 1)
            for wy in range(low_y, high_y + 1):
                row = height - 1 - wy
                yn = 2.0 * (wy + 0.5) / height - 1.0
                for col in range(low_x, high_x + 1):
                    xn = 2.0 * (col + 0.5) / width - 1.0
                    ox, oy, oz, dx, dy, dz = _view_ray(view_from_clip, xn, yn)
                    ex, ey, ez = ox - cx, oy - cy, oz - cz
                    if sphere:
                        a = (dx * dx + dy * dy) + dz * dz
                        b = (ex * dx + ey * dy) + ez * dz
                        c = ((ex * ex + ey * ey) + ez * ez) - radius * radius
                        disc = b * b - a * c
                        if disc < 0.0:
                            continue
                        t = (-b - math.sqrt(disc)) / a
                        hx, hy, hz = ox + t * dx, oy + t * dy, oz + t * dz
                        nx, ny, nz = (hx - cx) / radius, (hy - cy) / radius, (hz - cz) / radius
                    else:
                        nx, ny, nz = records[k, 8], records[k, 9], records[k, 10]
                        facing = (nx * dx + ny * dy) + nz * dz
                        if facing == 0.0:
                            continue
                        t = -((nx * ex + ny * ey) + nz * ez) / facing
                        hx, hy, hz = ox + t * dx, oy + t * dy, oz + t * dz
                        qx, qy, qz = hx - cx, hy - cy, hz - cz
                        if (qx * qx + qy * qy) + qz * qz >= radius * radius:
                            continue
                        if facing > 0.0:  # the back of the disk: its normal turned toward the viewer
                            nx, ny, nz = -nx, -ny, -nz
                    if not 0.0 <= t <= 1.0:  # between the near and far planes
                        continue
                    w = _row(clip_from_view, 3, hx, hy, hz)
                    z = np.float32((_row(clip_from_view, 2, hx, hy, hz) / w + 1.0) * 0.5)
                    if not z < depth[row, col]:
                        continue
                    px = _row(world_from_view, 0, hx, hy, hz)
                    py = _row(world_from_view, 1, hx, hy, hz)
                    pz = _row(world_from_view, 2, hx, hy, hz)
                    mx = (world_from_view[0, 0] * nx + world_from_view[0, 1] * ny) + world_from_view[0, 2] * nz
                    my = (world_from_view[1, 0] * nx + world_from_view[1, 1] * ny) + world_from_view[1, 2] * nz
                    mz = (world_from_view[2, 0] * nx + world_from_view[2, 1] * ny) + world_from_view[2, 2] * nz
                    r, g, b = _shade(params, lights, item, colors, k, px, py, pz, mx, my, mz)
                    depth[row, col] = z
                    color[row, col, 0], color[row, col, 1], color[row, col, 2] = _to_byte(r), _to_byte(g), _to_byte(b)
                    color[row, col, 3] = 255
                    if item[I_WRITE_NORMALS]:
                        normal_out[row, col, 0], normal_out[row, col, 1], normal_out[row, col, 2] = mx, my, mz
                    if item[I_WRITE_IDS]:
                        id_out[row, col] = item[I_OBJECT_ID]
