"""Camera conventions of other software, converted exactly from a frustum ``Camera``.

frustum's camera (``frustum.camera``) looks down −z_view with x right and y up (OpenGL); window coordinates
have **y up**, pixel centres at half-integers, and depth in [0, 1] (1 = far). Images are stored top row first,
so the pixel in stored row ``r``, column ``i`` has its centre at window $(i + 0.5, H − r − 0.5)$.

- Blender NeRF ``transforms.json``: OpenGL camera axes (x right, y up, looking down −z), camera-to-world 4x4,
  ``camera_angle_x`` (horizontal field of view), principal point at the image centre.
- nerfstudio ``transforms.json``: OpenGL axes, camera-to-world 4x4, ``fl_x, fl_y, cx, cy, w, h`` in pixels with
  the top-left pixel's centre at (0.5, 0.5) (nerfstudio adds 0.5 to pixel indices).
- COLMAP text: OpenCV axes (x right, y down, looking down +z), world-to-camera as a scalar-first quaternion
  ``QW QX QY QZ`` and ``TX TY TZ``; ``PINHOLE fx fy cx cy`` with the top-left pixel's centre at (0.5, 0.5).

With the projection's clip_from_view matrix ``P`` (a perspective one: bottom row (0, 0, −1, 0)) and an image
of W x H pixels, a view point (x, y, z) lands at window $x_w = W/2·(P00·x/(−z) − P02 + 1)$; in pixel
coordinates u (right), v (down) with the top-left pixel centre at (0.5, 0.5):
$fx = W/2·P00$, $cx = W/2·(1 − P02)$, $fy = H/2·P11$, $cy = H/2·(1 + P12)$ — for a symmetric
``Perspective`` $fx = fy = H / (2·tan(fovy/2))$, $cx = W/2$, $cy = H/2$. OpenCV axes are the OpenGL ones
turned half a turn about x: $camera_cv = diag(1, −1, −1) · camera_gl$.

Depth: the Frame's window depth d in [0, 1] goes back to view z through the projection's third and fourth rows,
$z_ndc = 2d − 1 = (A·z + B)/(C·z + D)$, so $z = (B − z_ndc·D)/(z_ndc·C − A)$; the metric z-depth written to
datasets is $−z$ (distance along the viewing axis), 0 where nothing was drawn.

References: [HB 10] "The Viewport Transformation and Three-Dimensional Screen Coordinates"; COLMAP "Output
format" and "Camera models"; nerfstudio "Data conventions"; the NeRF synthetic data set's transforms.json.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from frustum._arrays import Matrix4, describe
from frustum.camera import Camera
from frustum.errors import CameraError
from frustum.quaternion import Quaternion

__all__ = [
    "OPENCV_FROM_OPENGL",
    "camera_record",
    "colmap_pose",
    "intrinsics",
    "metric_depth",
    "opengl_camera_to_world",
]

# fmt: off
OPENCV_FROM_OPENGL = np.array([
    [1.0,  0.0,  0.0, 0.0],
    [0.0, -1.0,  0.0, 0.0],
    [0.0,  0.0, -1.0, 0.0],
    [0.0,  0.0,  0.0, 1.0],
])
# fmt: on
"""Half a turn about x: OpenGL camera axes (y up, looking down −z) to OpenCV ones (y down, looking down +z)."""
OPENCV_FROM_OPENGL.flags.writeable = False


def _clip_from_view(camera: Camera) -> Matrix4:
    """The right-handed clip_from_view (the frame's handedness only relabels z; the picture is the same)."""
    return camera.projection.matrix(camera.aspect)


def intrinsics(camera: Camera, *, where: str = "intrinsics") -> dict[str, float]:
    """Pinhole intrinsics of a perspective camera in pixels: fx, fy, cx, cy (u right, v down, top-left centre 0.5).

    $fx = W/2·P00$, $fy = H/2·P11$, $cx = W/2·(1 − P02)$, $cy = H/2·(1 + P12)$ from clip_from_view P.

    Raises
    ------
    CameraError
        If the projection is not a pinhole perspective (parallel, oblique or general projections have no
        pinhole intrinsics).
    """
    clip_from_view = _clip_from_view(camera)
    pinhole = (
        np.array_equal(clip_from_view[3], (0.0, 0.0, -1.0, 0.0))
        and clip_from_view[0, 1] == 0.0 and clip_from_view[1, 0] == 0.0
        and clip_from_view[0, 3] == 0.0 and clip_from_view[1, 3] == 0.0
    )  # fmt: skip
    if not pinhole:
        raise CameraError(
            f"{where}: projection = {describe(camera.projection)} is not a pinhole perspective; the camera "
            "formats need Perspective or Frustum (use format 'files' for parallel projections)"
        )
    w, h = camera.width, camera.height
    return {
        "fx": w / 2 * float(clip_from_view[0, 0]),
        "fy": h / 2 * float(clip_from_view[1, 1]),
        "cx": w / 2 * (1.0 - float(clip_from_view[0, 2])),
        "cy": h / 2 * (1.0 + float(clip_from_view[1, 2])),
    }


def opengl_camera_to_world(camera: Camera) -> Matrix4:
    """world_from_camera with OpenGL camera axes: columns u, v, n and the eye (NeRF's ``transform_matrix``)."""
    frame = camera.frame
    world_from_camera = np.eye(4)
    world_from_camera[:3, 0], world_from_camera[:3, 1], world_from_camera[:3, 2] = frame.u, frame.v, frame.n
    world_from_camera[:3, 3] = frame.eye
    return world_from_camera


def colmap_pose(camera: Camera) -> tuple[tuple[float, float, float, float], tuple[float, float, float]]:
    """COLMAP's world-to-camera pose: scalar-first unit quaternion (QW, QX, QY, QZ) and translation (TX, TY, TZ).

    $camera_cv = R·world + t$ with $[R | t] = OPENCV_FROM_OPENGL · (world_from_camera_gl)⁻¹$.
    """
    frame = camera.frame
    rotation_gl = np.array([frame.u, frame.v, frame.n])  # rows u, v, n: view_from_world's rotation
    rotation = OPENCV_FROM_OPENGL[:3, :3] @ rotation_gl
    translation = -(rotation @ np.asarray(frame.eye))
    q = Quaternion.from_matrix(rotation)
    # + 0.0 turns −0.0 into 0.0 (the same pose, written the same way)
    quaternion = (float(q.w) + 0.0, float(q.x) + 0.0, float(q.y) + 0.0, float(q.z) + 0.0)
    return quaternion, (float(translation[0]) + 0.0, float(translation[1]) + 0.0, float(translation[2]) + 0.0)


def metric_depth(window_depth: NDArray[np.float32], camera: Camera) -> NDArray[np.float32]:
    """Metric z-depth (distance along the viewing axis, world units) of a Frame's window depth; 0 on background.

    $z_ndc = 2d − 1$, $z_view = (B − z_ndc·D)/(z_ndc·C − A)$ with (A, B) and (C, D) the z and w entries of
    clip_from_view's third and fourth rows; the result is $−z_view$ (positive in front of the camera).
    Computed in float64, returned as float32.

    Parameters
    ----------
    window_depth : (H, W) float32
        ``Frame.depth``: window depth in [0, 1], 1.0 where nothing was drawn.
    camera : Camera
        The camera that rendered the frame.

    Raises
    ------
    CameraError
        If the projection's depth depends on x or y (a general projection onto a tilted plane).
    """
    clip_from_view = _clip_from_view(camera)
    if clip_from_view[2, 0] or clip_from_view[2, 1] or clip_from_view[3, 0] or clip_from_view[3, 1]:
        raise CameraError(
            f"metric_depth: projection = {describe(camera.projection)} makes depth depend on x and y; metric "
            "depth needs a projection whose third and fourth rows involve z only"
        )
    a, b = float(clip_from_view[2, 2]), float(clip_from_view[2, 3])
    c, d = float(clip_from_view[3, 2]), float(clip_from_view[3, 3])
    depth = np.asarray(window_depth, dtype=np.float64)
    z_ndc = 2.0 * depth - 1.0
    with np.errstate(divide="ignore", invalid="ignore"):
        z_view = (b - z_ndc * d) / (z_ndc * c - a)
    out = np.where(depth < 1.0, -z_view, 0.0)
    return out.astype(np.float32)


def camera_record(camera: Camera) -> dict[str, Any]:
    """Everything a dataset writes about one camera, as JSON-ready numbers.

    Keys: ``width``, ``height``, ``camera_to_world_opengl`` (4x4), ``world_to_camera_opencv`` (4x4),
    ``view_from_world`` and ``clip_from_view`` (frustum's own matrices), ``near``/``far`` when the projection
    has them, and for pinhole cameras ``fx``, ``fy``, ``cx``, ``cy``, ``camera_angle_x``, ``camera_angle_y``.
    """
    world_from_camera = opengl_camera_to_world(camera)
    camera_cv_from_world = OPENCV_FROM_OPENGL @ np.linalg.inv(world_from_camera)
    record: dict[str, Any] = {
        "width": camera.width,
        "height": camera.height,
        "camera_to_world_opengl": world_from_camera.tolist(),
        "world_to_camera_opencv": camera_cv_from_world.tolist(),
        "view_from_world": np.asarray(camera.view_matrix).tolist(),
        "clip_from_view": _clip_from_view(camera).tolist(),
    }
    for name in ("near", "far"):
        value = getattr(camera.projection, name, None)
        if value is not None:
            record[name] = float(value)
    try:
        pinhole = intrinsics(camera)
    except CameraError:
        return record
    record.update(pinhole)
    record["camera_angle_x"] = 2.0 * math.atan(camera.width / (2.0 * pinhole["fx"]))
    record["camera_angle_y"] = 2.0 * math.atan(camera.height / (2.0 * pinhole["fy"]))
    return record
