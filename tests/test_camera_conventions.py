"""Cameras from other programs' conventions (OpenCV K and poses, OpenGL poses, COLMAP, nerfstudio) and back.

Oracles: OpenCV's ``cv2.projectPoints`` for where a point lands, pycolmap for the COLMAP model that
``frustum dataset --format colmap`` writes. OpenCV counts pixel centres at integers, frustum (like COLMAP and
pyrender) at +0.5: the same K gives the same numbers u, v, and the pixel OpenCV names (round(u)) is the one
frustum draws (floor(u)) once cx, cy are shifted by +0.5.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from frustum import Camera, CameraError, Mesh, Perspective, Scene
from frustum.app.cli import main
from frustum.camera_conventions import OPENCV_FROM_OPENGL

cv2 = pytest.importorskip("cv2")


def _random_camera(seed: int) -> tuple[np.ndarray, np.ndarray, int, int]:
    """(K, world_to_camera in OpenCV axes, width, height): fx ≠ fy, cx, cy off centre."""
    rng = np.random.default_rng(seed)
    width, height = int(rng.integers(16, 1200)), int(rng.integers(16, 900))
    fx, fy = rng.uniform(0.3, 3.0) * width, rng.uniform(0.3, 3.0) * width
    cx, cy = rng.uniform(0.1, 0.9) * width, rng.uniform(0.1, 0.9) * height
    k = np.array([[fx, 0.0, cx], [0.0, fy, cy], [0.0, 0.0, 1.0]])
    pose = np.eye(4)
    pose[:3, :3] = Rotation.random(random_state=seed).as_matrix()
    pose[:3, 3] = rng.uniform(-5.0, 5.0, 3)
    return k, pose, width, height


def _points_in_view(k: np.ndarray, pose: np.ndarray, width: int, height: int, rng) -> np.ndarray:
    """World points in front of the camera whose pixels lie inside the image (camera z in [1, 50])."""
    u = rng.uniform(0.0, width, 30)
    v = rng.uniform(0.0, height, 30)
    z = rng.uniform(1.0, 50.0, 30)
    camera_points = np.column_stack([(u - k[0, 2]) / k[0, 0] * z, (v - k[1, 2]) / k[1, 1] * z, z])
    rotation, t = pose[:3, :3], pose[:3, 3]
    return (camera_points - t) @ rotation  # world = Rᵀ(camera − t)


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_from_intrinsics_projects_where_opencv_does(seed: int) -> None:
    """Property: window (x, H − y) of Camera.from_intrinsics equals cv2.projectPoints (u, v) with the same K."""
    k, pose, width, height = _random_camera(seed)
    camera = Camera.from_intrinsics(k, width, height, world_to_camera=pose, near=0.5, far=100.0)
    points = _points_in_view(k, pose, width, height, np.random.default_rng(seed))
    window = camera.project(points)
    uv, _ = cv2.projectPoints(points, cv2.Rodrigues(pose[:3, :3])[0], pose[:3, 3], k, None)
    uv = uv[:, 0]
    # 1e-6 px: float64 products of focal lengths up to ~3600 px and coordinates up to 50 (round-off ~1e-11)
    np.testing.assert_allclose(window[:, 0], uv[:, 0], rtol=0, atol=1e-6)
    np.testing.assert_allclose(height - window[:, 1], uv[:, 1], rtol=0, atol=1e-6)


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_intrinsics_and_world_to_camera_round_trip(seed: int) -> None:
    """Property: K and both poses come back to 1e-9 (relative to their size), in OpenCV and OpenGL axes."""
    k, pose, width, height = _random_camera(seed)
    camera = Camera.from_intrinsics(k, width, height, world_to_camera=pose)
    np.testing.assert_allclose(camera.intrinsics(), k, rtol=0, atol=1e-9 * width)
    np.testing.assert_allclose(camera.world_to_camera(), pose, rtol=0, atol=1e-9)
    gl_pose = OPENCV_FROM_OPENGL @ pose
    again = Camera.from_intrinsics(k, width, height, camera_to_world=np.linalg.inv(gl_pose), convention="opengl")
    np.testing.assert_allclose(again.world_to_camera("opengl"), gl_pose, rtol=0, atol=1e-9)
    np.testing.assert_allclose(again.intrinsics(), k, rtol=0, atol=1e-9 * width)
    np.testing.assert_allclose(again.clip_from_world, camera.clip_from_world, rtol=1e-9, atol=1e-9)


def test_look_at_camera_round_trips_through_its_intrinsics() -> None:
    camera = Camera.look_at((1.0, 2.0, 5.0), (0.0, 0.5, 0.0), projection=Perspective(0.9, 0.1, 50.0), width=320,
                            height=200)  # fmt: skip
    k = camera.intrinsics()
    assert k[0, 0] == pytest.approx(k[1, 1]) and k[0, 2] == pytest.approx(160.0) and k[1, 2] == pytest.approx(100.0)
    again = Camera.from_intrinsics(k, 320, 200, world_to_camera=camera.world_to_camera(), near=0.1, far=50.0)
    np.testing.assert_allclose(again.clip_from_world, camera.clip_from_world, rtol=1e-9, atol=1e-12)
    # a different image size scales K
    np.testing.assert_allclose(camera.intrinsics(640, 400), k * [[2, 1, 2], [1, 2, 2], [1, 1, 1]], rtol=1e-12)


def test_drawn_pixel_is_the_one_opencv_names_after_the_half_pixel_shift() -> None:
    """A point drawn by mode="points" lands in pixel floor(u); OpenCV names round(u): shift cx, cy by +0.5."""
    rng = np.random.default_rng(3)
    k, pose, width, height = _random_camera(11)
    width, height = 96, 64
    k[0, 2], k[1, 2] = 40.3, 25.8
    shifted = k.copy()
    shifted[:2, 2] += 0.5
    camera = Camera.from_intrinsics(shifted, width, height, world_to_camera=pose, near=0.5, far=100.0)
    points = _points_in_view(k, pose, width, height, rng)[:10]
    uv, _ = cv2.projectPoints(points, cv2.Rodrigues(pose[:3, :3])[0], pose[:3, 3], k, None)
    from frustum import render

    for point, (u, v) in zip(points, uv[:, 0], strict=True):
        column, row = int(np.floor(u + 0.5)), int(np.floor(v + 0.5))
        if not (0 <= column < width and 0 <= row < height) or min(abs(u % 1 - 0.5), abs(v % 1 - 0.5)) < 1e-3:
            continue  # outside, or too close to a pixel border to say
        mesh = Mesh(np.array([point, point, point]), np.array([[0, 1, 2]]))
        frame = render(_scene_of(mesh), camera, mode="points")
        drawn = np.argwhere(frame.depth < 1.0)
        assert drawn.tolist() == [[row, column]]


def _scene_of(mesh: Mesh) -> Scene:
    scene = Scene()
    scene.add(mesh)
    return scene


def test_colmap_model_written_by_frustum_dataset_reads_back_through_pycolmap(tmp_path: Path) -> None:
    """pycolmap reads the model `frustum dataset --format colmap` wrote; Camera.from_colmap of each image gives
    back the camera that rendered it (cameras.json holds those cameras)."""
    pycolmap = pytest.importorskip("pycolmap")
    scene_file = tmp_path / "scene.toml"
    scene_file.write_text(
        "[render]\nsize = [40, 30]\n[camera]\neye = [0.3, 1.0, 4.0]\ntarget = [0.0, 0.0, 0.0]\nfovy_deg = 45\n"
        'near = 1.0\nfar = 10.0\n[[nodes]]\nname = "ball"\ngeometry = { type = "icosphere", subdivisions = 1 }\n'
    )
    out = tmp_path / "ds"
    main(["dataset", str(scene_file), "--out", str(out), "--views", "5", "--format", "colmap", "--executor", "serial",
          "--no-progress"])  # fmt: skip
    records = json.loads((out / "cameras.json").read_text())  # {view key: camera record}
    reconstruction = pycolmap.Reconstruction(str(out / "sparse" / "0"))
    assert len(reconstruction.images) == 5
    for image in reconstruction.images.values():
        camera = Camera.from_colmap(reconstruction.cameras[image.camera_id], image, near=1.0, far=10.0)
        record = records[Path(image.name).stem]
        np.testing.assert_allclose(camera.world_to_camera("opencv"), record["world_to_camera_opencv"], atol=1e-9)
        np.testing.assert_allclose(camera.intrinsics(), [[record["fx"], 0, record["cx"]], [0, record["fy"],
                                   record["cy"]], [0, 0, 1]], rtol=1e-12)  # fmt: skip
        np.testing.assert_allclose(camera.clip_from_world, np.asarray(record["clip_from_view"]) @
                                   np.asarray(record["view_from_world"]), rtol=1e-9, atol=1e-9)  # fmt: skip
    # the text rows give the same cameras
    camera_row = (out / "sparse/0/cameras.txt").read_text().splitlines()[-1]
    image_row = next(line for line in (out / "sparse/0/images.txt").read_text().splitlines()
                     if line and not line.startswith("#"))  # fmt: skip
    image = reconstruction.images[int(image_row.split()[0])]
    from_rows = Camera.from_colmap(camera_row, image_row, near=1.0, far=10.0)
    from_objects = Camera.from_colmap(reconstruction.cameras[image.camera_id], image, near=1.0, far=10.0)
    np.testing.assert_allclose(from_rows.clip_from_world, from_objects.clip_from_world, rtol=1e-9, atol=1e-12)


def test_from_nerfstudio_reads_a_frame_and_the_top_level_intrinsics() -> None:
    k, pose, width, height = _random_camera(5)
    camera = Camera.from_intrinsics(k, width, height, world_to_camera=pose)
    transforms = {"fl_x": k[0, 0], "fl_y": k[1, 1], "cx": k[0, 2], "cy": k[1, 2], "w": width, "h": height,
                  "k1": 0.0, "k2": 0.0, "p1": 0.0, "p2": 0.0}  # fmt: skip
    frame = {"file_path": "a.png", "transform_matrix": np.linalg.inv(camera.world_to_camera("opengl")).tolist()}
    again = Camera.from_nerfstudio(frame, transforms)
    np.testing.assert_allclose(again.clip_from_world, camera.clip_from_world, rtol=1e-9, atol=1e-9)
    # Blender NeRF: camera_angle_x alone, centred principal point
    blender = Camera.from_nerfstudio({**frame, "camera_angle_x": 0.8, "w": 100, "h": 80})
    k_blender = blender.intrinsics()
    assert k_blender[0, 0] == pytest.approx(50.0 / np.tan(0.4)) and k_blender[0, 0] == pytest.approx(k_blender[1, 1])
    assert (k_blender[0, 2], k_blender[1, 2]) == pytest.approx((50.0, 40.0))
    with pytest.raises(CameraError, match=r"k1 = 0.1 is lens distortion"):
        Camera.from_nerfstudio(frame, {**transforms, "k1": 0.1})


@pytest.mark.parametrize(
    ("k", "match"),
    [
        (np.eye(4), r"K has shape \(4, 4\); expected a 3x3"),
        ([[0.0, 0, 10], [0, 100, 10], [0, 0, 1]], r"fx = K\[0, 0\] = 0.0 must be > 0"),
        ([[100.0, 0, 10], [0, -5, 10], [0, 0, 1]], r"fy = K\[1, 1\] = -5.0 must be > 0"),
        ([[100.0, 2, 10], [0, 100, 10], [0, 0, 1]], r"skew K\[0, 1\] = 2.0 is not 0"),
        ([[100.0, 0, 10], [0, 100, 10], [0, 0, 2]], r"last row \(0, 0, 1\)"),
        ([[100.0, 0, np.nan], [0, 100, 10], [0, 0, 1]], r"not finite"),
    ],
)
def test_from_intrinsics_rejects_bad_k(k, match: str) -> None:
    with pytest.raises(CameraError, match=match):
        Camera.from_intrinsics(k, 64, 48, world_to_camera=np.eye(4))


def test_from_intrinsics_rejects_poses_that_are_not_rigid() -> None:
    k = [[100.0, 0, 32], [0, 100, 24], [0, 0, 1]]
    scaled = np.diag([2.0, 2.0, 2.0, 1.0])
    with pytest.raises(CameraError, match=r"world_to_camera is not a rigid transform: .*RᵀR − I up to 3"):
        Camera.from_intrinsics(k, 64, 48, world_to_camera=scaled)
    mirrored = np.diag([1.0, 1.0, -1.0, 1.0])
    with pytest.raises(CameraError, match=r"camera_to_world is not a rigid transform: .*determinant -1"):
        Camera.from_intrinsics(k, 64, 48, camera_to_world=mirrored)
    projective = np.eye(4)
    projective[3, 2] = 1.0
    with pytest.raises(CameraError, match=r"bottom row .* is not \(0, 0, 0, 1\)"):
        Camera.from_intrinsics(k, 64, 48, world_to_camera=projective)
    with pytest.raises(CameraError, match=r"exactly one of world_to_camera and camera_to_world"):
        Camera.from_intrinsics(k, 64, 48)
    with pytest.raises(CameraError, match=r"convention = 'blender' is unknown"):
        Camera.from_intrinsics(k, 64, 48, world_to_camera=np.eye(4), convention="blender")
    with pytest.raises(CameraError, match=r"width = 0 is not a positive integer"):
        Camera.from_intrinsics(k, 0, 48, world_to_camera=np.eye(4))


def test_from_colmap_rejects_distorted_models_and_bad_rows() -> None:
    with pytest.raises(CameraError, match=r"camera model 'SIMPLE_RADIAL' has lens distortion"):
        Camera.from_colmap("1 SIMPLE_RADIAL 64 48 100 32 24 0.1", "1 1 0 0 0 0 0 0 1 a.png")
    with pytest.raises(CameraError, match=r"PINHOLE takes 4 parameters"):
        Camera.from_colmap("1 PINHOLE 64 48 100 32 24", "1 1 0 0 0 0 0 0 1 a.png")
    with pytest.raises(CameraError, match=r"zero or non-finite quaternion"):
        Camera.from_colmap("1 PINHOLE 64 48 100 100 32 24", "1 0 0 0 0 0 0 0 1 a.png")


def test_intrinsics_refuse_a_parallel_projection() -> None:
    from frustum import Orthographic

    camera = Camera.look_at((0, 0, 5), (0, 0, 0), projection=Orthographic(2.0, 0.1, 10.0))
    with pytest.raises(CameraError, match=r"Camera.intrinsics: the projection is not a pinhole perspective"):
        camera.intrinsics()
