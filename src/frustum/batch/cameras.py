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

The axis conversions, intrinsics (fx, fy, cx, cy from clip_from_view) and metric depth are
``frustum.camera_conventions``'s (one place for every program's camera convention); this module re-exports them
for the dataset writers and adds ``camera_record``.

References: [HB 10] "The Viewport Transformation and Three-Dimensional Screen Coordinates"; COLMAP "Output
format" and "Camera models"; nerfstudio "Data conventions"; the NeRF synthetic data set's transforms.json.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from frustum._arrays import Matrix4
from frustum.camera import Camera
from frustum.camera_conventions import (
    OPENCV_FROM_OPENGL,
    colmap_pose,
    intrinsics,
    metric_depth,
    opengl_camera_to_world,
)
from frustum.errors import CameraError

__all__ = [
    "OPENCV_FROM_OPENGL",
    "camera_record",
    "colmap_pose",
    "intrinsics",
    "metric_depth",
    "opengl_camera_to_world",
]


def _clip_from_view(camera: Camera) -> Matrix4:
    """The right-handed clip_from_view (the frame's handedness only relabels z; the picture is the same)."""
    return camera.projection.matrix(camera.aspect)


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
