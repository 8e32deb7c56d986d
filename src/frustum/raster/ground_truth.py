"""Ground-truth kernels: per-pixel model coordinates, NOCS and optical flow (``frustum.render.ground_truth`` drives
them and documents the formulas). Parallel over image rows; they compile only when a render asks for
``object_coords``, ``nocs`` or ``flow``.

Array contracts (kernels never validate):

- ``instance`` (H, W) int32 item index per pixel, −1 on background; ``position`` (H, W, 3) float64 world points
  (rounded to float32, the ``position`` buffer's values, before use);
- ``model_from_world`` (K, 12) float64: each item's inverse modeling transform, the top three rows row-major;
- ``boxes`` (K, 4) float64: the centre of each model's bounding box and 1 / its diagonal;
- ``now``, ``later`` (K, 16) float64: clip_from_model of each item, row-major, for this frame and the next
  (``matched[k]`` < 0: the item is absent from the next frame);
- ``next_depth`` (H', W') float32 the next frame's window depth (1.0 where nothing), ``setup`` (8,) float64:
  W, H, W', H', the next projection's $A = P_{22}$, $B = P_{23}$, $C = P_{32}$, $D = P_{33}$, and
  ``tolerance`` the relative depth margin;
- ``coordinates``, ``nocs`` (H, W, 3), ``flow`` (H, W, 2) float32 and ``occluded`` (H, W) bool: the outputs.
"""

from __future__ import annotations

import numpy as np

from frustum.raster._jit import parallel_kernel

__all__ = ["item_ids", "point_truth"]


@parallel_kernel(lambda *args: args[0].shape[0], work=lambda *args: args[0].size, grain=16384)
def point_truth(instance: np.ndarray, position: np.ndarray, model_from_world: np.ndarray, boxes: np.ndarray,
                now: np.ndarray, later: np.ndarray, matched: np.ndarray, next_depth: np.ndarray, setup: np.ndarray,
                tolerance: float, flags: int, coordinates: np.ndarray, nocs: np.ndarray, flow: np.ndarray,
                occluded: np.ndarray, start: int, stop: int) -> None:  # fmt: skip
    """Per drawn pixel, from its world point rounded to float32: the model point $X = (world\\_from\\_model)^{-1}·P$
    (``coordinates``, flag 1), its NOCS $(X − centre)/diagonal + ½$ (``nocs``, flag 2), and (flag 4) its window
    position now and in the next frame, the displacement (x right, y down) into ``flow`` and whether the next
    depth buffer hides it into ``occluded`` (``render.ground_truth.hidden_points``' test). Computed in float64,
    stored float32; NaN (not occluded) on the background. Outputs whose flag is off may be 1-pixel dummies."""
    width = instance.shape[1]
    write_coordinates, write_nocs, write_flow = flags & 1 != 0, flags & 2 != 0, flags & 4 != 0
    w0, h0, w1, h1 = setup[0], setup[1], setup[2], setup[3]
    a_, b_, c_, d_ = setup[4], setup[5], setup[6], setup[7]
    rows = next_depth.shape[0]  # H'
    for r in range(start, stop):
        for c in range(width):
            k = instance[r, c]
            if k < 0:
                if write_coordinates:
                    coordinates[r, c, 0] = coordinates[r, c, 1] = coordinates[r, c, 2] = np.nan
                if write_nocs:
                    nocs[r, c, 0] = nocs[r, c, 1] = nocs[r, c, 2] = np.nan
                if write_flow:
                    flow[r, c, 0] = flow[r, c, 1] = np.nan
                    occluded[r, c] = False
                continue
            px = float(np.float32(position[r, c, 0]))
            py = float(np.float32(position[r, c, 1]))
            pz = float(np.float32(position[r, c, 2]))
            m = model_from_world[k]
            x = m[0] * px + m[1] * py + m[2] * pz + m[3]
            y = m[4] * px + m[5] * py + m[6] * pz + m[7]
            z = m[8] * px + m[9] * py + m[10] * pz + m[11]
            if write_coordinates:
                coordinates[r, c, 0], coordinates[r, c, 1], coordinates[r, c, 2] = x, y, z
            if write_nocs:
                nocs[r, c, 0] = (x - boxes[k, 0]) * boxes[k, 3] + 0.5
                nocs[r, c, 1] = (y - boxes[k, 1]) * boxes[k, 3] + 0.5
                nocs[r, c, 2] = (z - boxes[k, 2]) * boxes[k, 3] + 0.5
            if not write_flow:
                continue
            flow[r, c, 0] = flow[r, c, 1] = np.nan
            occluded[r, c] = True
            j = matched[k]
            if j < 0:
                continue
            m = now[k]
            cw = m[12] * x + m[13] * y + m[14] * z + m[15]
            x0 = ((m[0] * x + m[1] * y + m[2] * z + m[3]) / cw + 1.0) * 0.5 * w0
            y0 = ((m[4] * x + m[5] * y + m[6] * z + m[7]) / cw + 1.0) * 0.5 * h0
            n = later[k]
            nw = n[12] * x + n[13] * y + n[14] * z + n[15]
            if not nw > 0.0:
                continue
            x1 = ((n[0] * x + n[1] * y + n[2] * z + n[3]) / nw + 1.0) * 0.5 * w1
            y1 = ((n[4] * x + n[5] * y + n[6] * z + n[7]) / nw + 1.0) * 0.5 * h1
            d1 = ((n[8] * x + n[9] * y + n[10] * z + n[11]) / nw + 1.0) * 0.5
            flow[r, c, 0] = x1 - x0
            flow[r, c, 1] = y0 - y1
            if not (0.0 <= x1 < w1 and 0.0 <= y1 < h1 and 0.0 <= d1 <= 1.0):  # the pixel holding it: in the image
                continue
            surface_ndc = 2.0 * float(next_depth[rows - 1 - int(y1), int(x1)]) - 1.0  # int() floors x, y >= 0
            point_ndc = 2.0 * d1 - 1.0
            surface = -(b_ - surface_ndc * d_) / (surface_ndc * c_ - a_)
            point = -(b_ - point_ndc * d_) / (point_ndc * c_ - a_)
            occluded[r, c] = point > surface * (1.0 + tolerance)


@parallel_kernel(lambda depth, *_: depth.shape[0], work=lambda depth, *_: depth.size, grain=32768)
def item_ids(depth: np.ndarray, codes: np.ndarray, face_offset: int, face_count: int, index: int, ids: np.ndarray,
             start: int, stop: int) -> None:  # fmt: skip
    """``ids[r, c] = index`` at the drawn pixels whose face code belongs to the item (its `face_count` faces from
    `face_offset` on; $code = 2·face + side$, as ``raster.shade`` reads it)."""
    for r in range(start, stop):
        for c in range(depth.shape[1]):
            if depth[r, c] >= 1.0:
                continue
            code = codes[r, c]
            if code < 0:
                continue
            f = code // 2 - face_offset
            if 0 <= f < face_count:
                ids[r, c] = index
