"""Camera conventions of other software (OpenCV, COLMAP, OpenGL, nerfstudio, Blender), converted exactly.

frustum's camera (``frustum.camera``) looks down −z_view with x right and y up (OpenGL); window coordinates
have **y up**, pixel centres at half-integers, and depth in [0, 1] (1 = far). Images are stored top row first,
so the pixel in stored row ``r``, column ``i`` has its centre at window $(i + 0.5, H − r − 0.5)$.

Camera axes. OpenCV (and COLMAP): x right, y down, looking down +z. OpenGL (and nerfstudio, Blender, pyrender):
x right, y up, looking down −z. One is the other turned half a turn about x:
$camera_cv = diag(1, −1, −1) · camera_gl$ (``OPENCV_FROM_OPENGL``, its own inverse).

Intrinsics. $K = [[fx, 0, cx], [0, fy, cy], [0, 0, 1]]$ maps a point (x, y, z) in OpenCV camera axes to pixel
coordinates $u = fx·x/z + cx$ (right), $v = fy·y/z + cy$ (down). Pixel-centre rule: u, v are continuous with
the image's top-left corner at (0, 0), so the top-left pixel's centre is (0.5, 0.5) — COLMAP's, nerfstudio's and
pyrender's rule, and frustum's window x and $H − y$. OpenCV's ``projectPoints`` computes the same u, v from the
same K but counts pixel centres at integers (the top-left one at (0, 0)): the pixel it names is $round(u)$, the
one frustum draws $floor(u)$. For a K calibrated by OpenCV, pass cx + 0.5 and cy + 0.5 to draw its pixels.

With the projection's clip_from_view matrix ``P`` (a pinhole perspective: bottom row (0, 0, −1, 0)) and an
image of W x H pixels: $fx = W/2·P00$, $cx = W/2·(1 − P02)$, $fy = H/2·P11$, $cy = H/2·(1 + P12)$; the other
way, the window on the near plane (distance n) is $left = −cx·n/fx$, $right = (W − cx)·n/fx$,
$top = cy·n/fy$, $bottom = −(H − cy)·n/fy$ (an off-centre frustum when cx ≠ W/2 or cy ≠ H/2).

Depth: a Frame's window depth d in [0, 1] goes back to view z through the projection's third and fourth rows,
$z_ndc = 2d − 1 = (A·z + B)/(C·z + D)$, so $z = (B − z_ndc·D)/(z_ndc·C − A)$; metric z-depth is $−z$
(distance along the viewing axis), 0 where nothing was drawn (pyrender's and the datasets' convention).

References: [HB 10] "The Viewport Transformation and Three-Dimensional Screen Coordinates"; OpenCV "Camera
Calibration and 3D Reconstruction"; COLMAP "Output format" and "Camera models"; nerfstudio "Data conventions".
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from frustum._arrays import Matrix4, Vector3, describe
from frustum.errors import CameraError
from frustum.quaternion import Quaternion

__all__ = [
    "CONVENTIONS",
    "OPENCV_FROM_OPENGL",
    "colmap_intrinsics",
    "colmap_pose",
    "colmap_world_to_camera",
    "intrinsic_matrix",
    "intrinsics",
    "metric_depth",
    "near_plane_window",
    "nerfstudio_intrinsics",
    "opengl_camera_to_world",
    "pinhole_from_matrix",
    "view_from_pose",
    "world_to_camera",
]

CONVENTIONS = ("opencv", "opengl")
"""Camera-axis conventions of a pose: OpenCV/COLMAP (y down, looking down +z), OpenGL/nerfstudio (y up, −z)."""

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

# |RᵀR − I| and |det R − 1| above this count as "not a rotation": poses read from text files carry about 1e-16
# of round-off per entry, quaternions printed with 17 digits a little more; a scale or shear is far larger.
_RIGID_TOLERANCE = 1e-6
# COLMAP camera models frustum draws exactly (no lens distortion), with their parameter names.
_COLMAP_PINHOLES = {"SIMPLE_PINHOLE": ("f", "cx", "cy"), "PINHOLE": ("fx", "fy", "cx", "cy")}


def _convention(value: Any, where: str) -> str:
    if not isinstance(value, str) or value not in CONVENTIONS:
        raise CameraError(
            f"{where}: convention = {describe(value)} is unknown; expected 'opencv' (x right, y down, looking down "
            "+z: OpenCV, COLMAP) or 'opengl' (y up, looking down −z: nerfstudio, Blender, pyrender)"
        )
    return value


def pinhole_from_matrix(K: Any, where: str) -> tuple[float, float, float, float]:
    """(fx, fy, cx, cy) of a 3x3 intrinsic matrix with zero skew; CameraError naming the failed check."""
    try:
        matrix = np.asarray(K, dtype=np.float64)
    except (TypeError, ValueError):
        raise CameraError(f"{where}: K = {describe(K)} is not numeric; give a 3x3 intrinsic matrix") from None
    if matrix.shape != (3, 3):
        raise CameraError(
            f"{where}: K has shape {matrix.shape}; expected a 3x3 intrinsic matrix "
            "[[fx, 0, cx], [0, fy, cy], [0, 0, 1]]"
        )
    if not np.isfinite(matrix).all():
        raise CameraError(f"{where}: K = {describe(matrix)} has a value that is not finite")
    fx, fy, cx, cy = float(matrix[0, 0]), float(matrix[1, 1]), float(matrix[0, 2]), float(matrix[1, 2])
    for name, value in (("fx = K[0, 0]", fx), ("fy = K[1, 1]", fy)):
        if not value > 0.0:
            raise CameraError(f"{where}: {name} = {value!r} must be > 0 (a focal length in pixels)")
    if matrix[0, 1] != 0.0:
        raise CameraError(f"{where}: skew K[0, 1] = {float(matrix[0, 1])!r} is not 0; frustum draws zero-skew cameras")
    if matrix[1, 0] != 0.0 or not np.array_equal(matrix[2], [0.0, 0.0, 1.0]):
        raise CameraError(
            f"{where}: K = {describe(matrix)} is not of the form [[fx, 0, cx], [0, fy, cy], [0, 0, 1]] (K[1, 0] and "
            "the last row (0, 0, 1) are fixed)"
        )
    return fx, fy, cx, cy


def near_plane_window(
    fx: float, fy: float, cx: float, cy: float, width: int, height: int, near: float
) -> tuple[float, float, float, float]:
    """(left, right, bottom, top) of the view window on the near plane for pinhole intrinsics in pixels.

    $left = −cx·n/fx$, $right = (W − cx)·n/fx$, $bottom = −(H − cy)·n/fy$, $top = cy·n/fy$ (v down, pixel
    centres at +0.5): ``projection.frustum`` of this window gives back fx, fy, cx, cy exactly.
    """
    return (-cx * near / fx, (width - cx) * near / fx, -(height - cy) * near / fy, cy * near / fy)


def intrinsic_matrix(clip_from_view: Matrix4, width: int, height: int, where: str) -> NDArray[np.float64]:
    """The 3x3 K of a pinhole perspective clip_from_view for a W x H image (pixel centres at +0.5, v down).

    $fx = W/2·P00$, $fy = H/2·P11$, $cx = W/2·(1 − P02)$, $cy = H/2·(1 + P12)$.

    Raises
    ------
    CameraError
        If the projection is not a pinhole perspective (parallel, oblique or general projections have no K).
    """
    p = np.asarray(clip_from_view, dtype=np.float64)
    pinhole = (
        np.array_equal(p[3], (0.0, 0.0, -1.0, 0.0))
        and p[0, 1] == 0.0 and p[1, 0] == 0.0 and p[0, 3] == 0.0 and p[1, 3] == 0.0
    )  # fmt: skip
    if not pinhole:
        raise CameraError(
            f"{where}: the projection is not a pinhole perspective (clip_from_view = {describe(p)}); intrinsics "
            "exist for Perspective and Frustum projections only"
        )
    return np.array([
        [width / 2 * float(p[0, 0]), 0.0, width / 2 * (1.0 - float(p[0, 2]))],
        [0.0, height / 2 * float(p[1, 1]), height / 2 * (1.0 + float(p[1, 2]))],
        [0.0, 0.0, 1.0],
    ])  # fmt: skip


def intrinsics(camera: Any, *, where: str = "intrinsics") -> dict[str, float]:
    """Pinhole intrinsics of a perspective camera in pixels: fx, fy, cx, cy (u right, v down, top-left centre 0.5).

    Raises
    ------
    CameraError
        If the projection is not a pinhole perspective (the camera formats need Perspective or Frustum).
    """
    try:
        k = intrinsic_matrix(camera.projection.matrix(camera.aspect), camera.width, camera.height, where)
    except CameraError:
        raise CameraError(
            f"{where}: projection = {describe(camera.projection)} is not a pinhole perspective; the camera "
            "formats need Perspective or Frustum (use format 'files' for parallel projections)"
        ) from None
    return {"fx": float(k[0, 0]), "fy": float(k[1, 1]), "cx": float(k[0, 2]), "cy": float(k[1, 2])}


def _as_pose(value: Any, name: str, where: str) -> Matrix4:
    """A 4x4 (or 3x4) rigid transform as 4x4 float64; CameraError naming the failed check."""
    try:
        matrix = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise CameraError(f"{where}: {name} = {describe(value)} is not numeric; give a 4x4 rigid transform") from None
    if matrix.shape == (3, 4):
        matrix = np.vstack([matrix, (0.0, 0.0, 0.0, 1.0)])
    if matrix.shape != (4, 4):
        raise CameraError(f"{where}: {name} has shape {matrix.shape}; expected a 4x4 (or 3x4) rigid transform")
    if not np.isfinite(matrix).all():
        raise CameraError(f"{where}: {name} = {describe(matrix)} has a value that is not finite")
    if not np.array_equal(matrix[3], (0.0, 0.0, 0.0, 1.0)):
        raise CameraError(f"{where}: {name} bottom row = {describe(matrix[3])} is not (0, 0, 0, 1); a pose is affine")
    rotation = matrix[:3, :3]
    deviation = float(np.abs(rotation.T @ rotation - np.eye(3)).max())
    if deviation > _RIGID_TOLERANCE:
        raise CameraError(
            f"{where}: {name} is not a rigid transform: its upper 3x3 R has RᵀR − I up to {deviation:.3g} (above "
            f"{_RIGID_TOLERANCE:g}); a camera pose is a rotation and a translation, no scale or shear"
        )
    determinant = float(np.linalg.det(rotation))
    if determinant < 0.0:
        raise CameraError(
            f"{where}: {name} is not a rigid transform: its upper 3x3 has determinant {determinant:.6g} (a "
            "reflection); a camera pose is a proper rotation (determinant +1) and a translation"
        )
    return matrix


def view_from_pose(
    world_to_camera: Any, camera_to_world: Any, convention: Any, where: str
) -> tuple[Vector3, Vector3, Vector3, Vector3]:
    """(eye, u, v, n) of frustum's view frame from a pose in OpenCV or OpenGL camera axes (exactly one given).

    $[R | t]_gl = OPENCV_FROM_OPENGL · [R | t]_cv$; rows u, v, n of $R_gl$ and $eye = −R_glᵀ·t$.
    """
    convention = _convention(convention, where)
    if (world_to_camera is None) == (camera_to_world is None):
        raise CameraError(
            f"{where}: give exactly one of world_to_camera and camera_to_world (the pose as a 4x4 rigid transform)"
        )
    if world_to_camera is not None:
        camera_from_world = _as_pose(world_to_camera, "world_to_camera", where)
    else:
        world_from_camera = _as_pose(camera_to_world, "camera_to_world", where)
        camera_from_world = np.eye(4)
        camera_from_world[:3, :3] = world_from_camera[:3, :3].T
        camera_from_world[:3, 3] = -(world_from_camera[:3, :3].T @ world_from_camera[:3, 3])
    if convention == "opencv":
        camera_from_world = OPENCV_FROM_OPENGL @ camera_from_world
    rotation = camera_from_world[:3, :3]
    eye = -(rotation.T @ camera_from_world[:3, 3])
    return eye, rotation[0].copy(), rotation[1].copy(), rotation[2].copy()


def world_to_camera(frame: Any, convention: Any, where: str = "Camera.world_to_camera") -> Matrix4:
    """The 4x4 world-to-camera transform of a view frame in OpenCV or OpenGL camera axes.

    OpenGL: rows u, v, n and $t = −R·eye$ (frustum's right-handed view_from_world); OpenCV: that matrix turned by
    ``OPENCV_FROM_OPENGL`` (rows u, −v, −n).
    """
    convention = _convention(convention, where)
    matrix = np.eye(4)
    matrix[0, :3], matrix[1, :3], matrix[2, :3] = frame.u, frame.v, frame.n
    matrix[:3, 3] = -(matrix[:3, :3] @ np.asarray(frame.eye))
    if convention == "opencv":
        matrix = OPENCV_FROM_OPENGL @ matrix
    return matrix + 0.0  # + 0.0 turns −0.0 into 0.0


def opengl_camera_to_world(camera: Any) -> Matrix4:
    """world_from_camera with OpenGL camera axes: columns u, v, n and the eye (NeRF's ``transform_matrix``)."""
    frame = camera.frame
    world_from_camera = np.eye(4)
    world_from_camera[:3, 0], world_from_camera[:3, 1], world_from_camera[:3, 2] = frame.u, frame.v, frame.n
    world_from_camera[:3, 3] = frame.eye
    return world_from_camera


def colmap_pose(camera: Any) -> tuple[tuple[float, float, float, float], tuple[float, float, float]]:
    """COLMAP's world-to-camera pose: scalar-first unit quaternion (QW, QX, QY, QZ) and translation (TX, TY, TZ).

    $camera_cv = R·world + t$ with $[R | t] = OPENCV_FROM_OPENGL · (world_from_camera_gl)⁻¹$.
    """
    matrix = world_to_camera(camera.frame, "opencv", "colmap_pose")
    q = Quaternion.from_matrix(matrix[:3, :3])
    # + 0.0 turns −0.0 into 0.0 (the same pose, written the same way)
    quaternion = (float(q.w) + 0.0, float(q.x) + 0.0, float(q.y) + 0.0, float(q.z) + 0.0)
    t = matrix[:3, 3]
    return quaternion, (float(t[0]) + 0.0, float(t[1]) + 0.0, float(t[2]) + 0.0)


def metric_depth(window_depth: NDArray[np.float32], camera: Any) -> NDArray[np.float32]:
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
    clip_from_view = camera.projection.matrix(camera.aspect)
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


# --- readers of other programs' camera records -----------------------------------------------------------------


def _row(value: Any) -> list[str] | None:
    """A text-format row as its fields (a line of cameras.txt / images.txt, or a sequence of them); None if not."""
    if isinstance(value, str):
        return value.split()
    if isinstance(value, list | tuple):
        return [str(field) for field in value]
    return None


def colmap_intrinsics(camera: Any, where: str = "Camera.from_colmap") -> tuple[int, int, NDArray[np.float64]]:
    """(width, height, K) of a COLMAP camera: a ``pycolmap.Camera`` or a cameras.txt row
    ``CAMERA_ID MODEL WIDTH HEIGHT PARAMS[]``; pinhole models only (SIMPLE_PINHOLE f cx cy, PINHOLE fx fy cx cy).

    COLMAP's pixel-centre rule is frustum's: the top-left pixel's centre is (0.5, 0.5).
    """
    fields = _row(camera)
    if fields is not None:
        if len(fields) < 5:
            raise CameraError(
                f"{where}: camera row {describe(camera)} is not 'CAMERA_ID MODEL WIDTH HEIGHT PARAMS[]' (cameras.txt)"
            )
        model, size, raw = fields[1].upper(), fields[2:4], fields[4:]
        try:
            width, height = int(size[0]), int(size[1])
            params = [float(p) for p in raw]
        except ValueError:
            raise CameraError(f"{where}: camera row {describe(camera)} has a width, height or parameter that is not "
                              "a number") from None  # fmt: skip
    else:
        model_attr = getattr(camera, "model", None)
        if model_attr is None or not hasattr(camera, "params"):
            raise CameraError(
                f"{where}: camera = {describe(camera)} is neither a pycolmap.Camera nor a cameras.txt row"
            )
        model = str(getattr(model_attr, "name", model_attr)).split(".")[-1].upper()
        width, height = int(camera.width), int(camera.height)
        params = [float(p) for p in np.asarray(camera.params, dtype=np.float64)]
    if model not in _COLMAP_PINHOLES:
        raise CameraError(
            f"{where}: camera model {model!r} has lens distortion frustum does not draw; expected "
            f"{' or '.join(_COLMAP_PINHOLES)} (undistort the images first: colmap image_undistorter)"
        )
    names = _COLMAP_PINHOLES[model]
    if len(params) != len(names):
        raise CameraError(f"{where}: camera model {model} takes {len(names)} parameters ({', '.join(names)}); got "
                          f"{len(params)}")  # fmt: skip
    if model == "SIMPLE_PINHOLE":
        params = [params[0], *params]
    fx, fy, cx, cy = params
    return width, height, np.array([[fx, 0.0, cx], [0.0, fy, cy], [0.0, 0.0, 1.0]])


def colmap_world_to_camera(image: Any, where: str = "Camera.from_colmap") -> Matrix4:
    """The 4x4 world-to-camera pose (OpenCV axes) of a ``pycolmap.Image`` or an images.txt row
    ``IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME``: $R = R(q)$, $camera = R·world + t$."""
    fields = _row(image)
    if fields is not None:
        if len(fields) < 8:
            raise CameraError(
                f"{where}: image row {describe(image)} is not 'IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME'"
            )
        try:
            qw, qx, qy, qz, tx, ty, tz = (float(f) for f in fields[1:8])
        except ValueError:
            raise CameraError(f"{where}: image row {describe(image)} has a pose value that is not a number") from None
        norm = math.sqrt(qw * qw + qx * qx + qy * qy + qz * qz)
        if not norm > 0.0 or not math.isfinite(norm):
            raise CameraError(f"{where}: image row {describe(image)} has a zero or non-finite quaternion")
        matrix = np.eye(4)
        matrix[:3, :3] = Quaternion(qw / norm, qx / norm, qy / norm, qz / norm).to_matrix()[:3, :3]
        matrix[:3, 3] = (tx, ty, tz)
        return matrix
    pose = getattr(image, "cam_from_world", None)
    if pose is None:
        raise CameraError(f"{where}: image = {describe(image)} is neither a pycolmap.Image nor an images.txt row")
    if callable(pose):  # a method in pycolmap 4.x, an attribute in 3.x
        pose = pose()
    return np.vstack([np.asarray(pose.matrix(), dtype=np.float64), (0.0, 0.0, 0.0, 1.0)])


def nerfstudio_intrinsics(
    frame: Any, transforms: Any, where: str = "Camera.from_nerfstudio"
) -> tuple[int, int, NDArray[np.float64]]:
    """(width, height, K) from a nerfstudio frame, its keys overriding the file's top level (`transforms`).

    ``fl_x``, ``fl_y``, ``cx``, ``cy``, ``w``, ``h`` in pixels (top-left pixel centre at (0.5, 0.5)); Blender's
    ``camera_angle_x`` (horizontal field of view, radians) stands in for a missing ``fl_x``: $fx = w/(2·tan(a/2))$;
    fy defaults to fx and (cx, cy) to the image centre. Distortion coefficients other than 0 are refused.
    """
    top = transforms if isinstance(transforms, dict) else {}
    if transforms is not None and not isinstance(transforms, dict):
        raise CameraError(f"{where}: transforms = {describe(transforms)} is not a dict (the transforms.json data)")

    def get(key: str) -> Any:
        return frame.get(key, top.get(key))

    for key in ("k1", "k2", "k3", "k4", "p1", "p2"):
        if get(key) not in (None, 0, 0.0):
            raise CameraError(
                f"{where}: {key} = {get(key)!r} is lens distortion frustum does not draw; undistort the images first"
            )
    width, height = get("w"), get("h")
    if width is None or height is None:
        raise CameraError(f"{where}: the image size w, h is missing from the frame and from transforms")
    fx = get("fl_x")
    if fx is None:
        angle = get("camera_angle_x")
        if angle is None:
            raise CameraError(f"{where}: neither fl_x nor camera_angle_x is given; the focal length is unknown")
        fx = float(width) / (2.0 * math.tan(float(angle) / 2.0))
    fy = get("fl_y")
    fx = float(fx)
    fy = fx if fy is None else float(fy)
    cx = get("cx")
    cy = get("cy")
    cx = float(width) / 2.0 if cx is None else float(cx)
    cy = float(height) / 2.0 if cy is None else float(cy)
    return int(width), int(height), np.array([[fx, 0.0, cx], [0.0, fy, cy], [0.0, 0.0, 1.0]])
