"""The turtle-interpretation kernel of ``geometry/lsystem.py``.

Kernels only (numpy + numba): imported on first use by the module named above, so ``import frustum`` never
loads Numba.
"""

from __future__ import annotations

import numpy as np

from frustum.raster._jit import kernel


@kernel
def _turtle_kernel(codes, cos_d, sin_d, step, frame0, start, max_depth, segments, depths):  # pragma: no cover
    """Walk the opcodes; frame0 rows are H, L, U. Writes segments/depths; returns the number written."""
    px, py, pz = start[0], start[1], start[2]
    f = frame0.copy()
    stack_p = np.empty((max_depth + 1, 3))
    stack_f = np.empty((max_depth + 1, 3, 3))
    top = 0
    m = 0
    tmp = np.empty(3)
    for t in range(codes.shape[0]):
        c = codes[t]
        if c == 0:
            continue
        if c == 1 or c == 2 or c == 3:  # F, G draw; f moves
            qx = px + step * f[0, 0]
            qy = py + step * f[0, 1]
            qz = pz + step * f[0, 2]
            if c != 3:
                segments[m, 0, 0] = px
                segments[m, 0, 1] = py
                segments[m, 0, 2] = pz
                segments[m, 1, 0] = qx
                segments[m, 1, 1] = qy
                segments[m, 1, 2] = qz
                depths[m] = top
                m += 1
            px, py, pz = qx, qy, qz
        elif c == 11:  # [
            stack_p[top, 0] = px
            stack_p[top, 1] = py
            stack_p[top, 2] = pz
            stack_f[top] = f
            top += 1
        elif c == 12:  # ]
            top -= 1
            px, py, pz = stack_p[top, 0], stack_p[top, 1], stack_p[top, 2]
            f[:, :] = stack_f[top]
        else:
            # rotation in the plane of rows (a, b): a' = a cos + b sin, b' = -a sin + b cos
            cs, sn = cos_d, sin_d
            if c == 4 or c == 5:  # + - : yaw, H towards L
                a, b = 0, 1
                if c == 5:
                    sn = -sn
            elif c == 6 or c == 7:  # & ^ : pitch, & turns H towards -U
                a, b = 0, 2
                if c == 6:
                    sn = -sn
            elif c == 8 or c == 9:  # \ / : roll, \ turns L towards U
                a, b = 1, 2
                if c == 9:
                    sn = -sn
            else:  # c == 10, | : yaw by 180°
                a, b = 0, 1
                cs, sn = -1.0, 0.0
            for k in range(3):
                tmp[k] = f[a, k] * cs + f[b, k] * sn
                f[b, k] = -f[a, k] * sn + f[b, k] * cs
                f[a, k] = tmp[k]
    return m
