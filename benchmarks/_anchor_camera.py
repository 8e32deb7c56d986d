"""The camera of a standard bench scene (``../shared/bench/scenes.py``'s ``.npz``) as the llvmpipe anchors draw it:
OpenGL's perspective matrix and look-at view, written once for ``anchor_moderngl_pbr.py`` and
``anchor_moderngl_shadows.py``."""

from __future__ import annotations

import numpy as np


def look_at(eye: np.ndarray, target: np.ndarray, up: np.ndarray) -> np.ndarray:
    """The 4×4 view matrix of a camera at `eye` looking at `target` (OpenGL: −z forward, y up)."""
    forward = (target - eye) / np.linalg.norm(target - eye)
    side = np.cross(forward, up)
    side /= np.linalg.norm(side)
    view = np.eye(4)
    view[0, :3], view[1, :3], view[2, :3] = side, np.cross(side, forward), -forward
    view[:3, 3] = -view[:3, :3] @ eye
    return view


def scene_camera(path: str) -> tuple[dict[str, np.ndarray], int, int, np.ndarray]:
    """(the scene's arrays, width, height, clip_from_world float32) of the bench scene file `path`."""
    data = np.load(path)
    scene = {key: data[key] for key in data.files}
    width, height = int(scene["width"]), int(scene["height"])
    near, far = float(scene["near"]), float(scene["far"])
    f = 1.0 / np.tan(np.radians(float(scene["fovy_deg"])) / 2.0)
    projection = np.zeros((4, 4))
    projection[0, 0], projection[1, 1] = f / (width / height), f
    projection[2, 2], projection[2, 3] = -(far + near) / (far - near), -2.0 * far * near / (far - near)
    projection[3, 2] = -1.0
    view = look_at(*(scene[k].astype(float) for k in ("eye", "target", "up")))
    return scene, width, height, (projection @ view).astype(np.float32)
