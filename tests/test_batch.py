"""frustum.batch: camera conventions, render_many on every executor, datasets (round trips), resume and bad input.

The round-trip tests are the ones that catch convention errors: each reads a format's camera files with its own
small parser (written from the formats' documentation, not from frustum.batch), back-projects the written depth
of every drawn pixel and checks the points lie on the scene's surface (trimesh's closest point).
"""

from __future__ import annotations

import io
import json
import os
import signal
import subprocess
import sys
import tarfile
import time
from pathlib import Path

import numpy as np
import pytest
import trimesh
from hypothesis import given
from hypothesis import strategies as st
from PIL import Image
from scipy.spatial.transform import Rotation

import frustum
from frustum import Camera, CameraError, Frustum, FrustumError, Orthographic, OutputError, Perspective, SceneFileError
from frustum.app.cli import main
from frustum.batch import RenderJob, dataset_cameras, render_dataset, render_many
from frustum.batch.cameras import colmap_pose, intrinsics, metric_depth
from frustum.batch.jobs import TEMPORARY_MARK, write_atomically
from frustum.scene import Scene
from frustum.scenefile import load_scene_file
from scene_texts import ball_scene

SCENE = ball_scene("batch test")
SRC = Path(frustum.__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def scene_path(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("scene") / "scene.toml"
    path.write_text(SCENE)
    return path


@pytest.fixture(scope="module")
def surface(scene_path: Path) -> trimesh.Trimesh:
    """The scene's triangles in world coordinates, one trimesh."""
    parts = []
    for item in load_scene_file(scene_path).scene.items:
        part = trimesh.Trimesh(item.mesh.vertices, item.mesh.faces, process=False)
        part.apply_transform(item.world_from_model)
        parts.append(part)
    return trimesh.util.concatenate(parts)


def files_of(folder: Path) -> dict[str, bytes]:
    """Every file under `folder` but the run log (its lines hold timings and arrive in completion order)."""
    return {
        p.relative_to(folder).as_posix(): p.read_bytes()
        for p in sorted(folder.rglob("*"))
        if p.is_file() and p.name != "manifest.jsonl"
    }


# --- camera conventions ---------------------------------------------------------------------------------------


def _cameras() -> list[Camera]:
    return [
        Camera.look_at((0.3, 1.0, 4.0), (0.0, 0.0, 0.0), projection=Perspective(0.8, 1.0, 10.0), width=64, height=48),
        Camera.look_at((-3.0, -2.0, 1.0), (0.2, 0.1, 0.0), (0, 0, 1), Frustum(-0.3, 0.5, -0.2, 0.4, 0.7, 20.0), 50, 30),
        Camera.look_at((1.0, 5.0, 0.5), (0.0, 0.0, 0.0), projection=Perspective(1.2, 0.5, 50.0), width=31, height=77,
                       handedness="left"),
    ]  # fmt: skip


@pytest.mark.parametrize("camera", _cameras())
def test_intrinsics_and_colmap_pose_reproduce_camera_project(camera: Camera) -> None:
    rng = np.random.default_rng(0)
    points = camera.frame.eye - 5.0 * camera.frame.n + rng.uniform(-1.5, 1.5, size=(50, 3))
    window = camera.project(points)
    k = intrinsics(camera)
    (qw, qx, qy, qz), t = colmap_pose(camera)
    rotation = Rotation.from_quat([qx, qy, qz, qw]).as_matrix()  # SciPy is scalar-last
    camera_cv = points @ rotation.T + np.asarray(t)
    u = k["fx"] * camera_cv[:, 0] / camera_cv[:, 2] + k["cx"]
    v = k["fy"] * camera_cv[:, 1] / camera_cv[:, 2] + k["cy"]
    # window y is up with pixel centres at half-integers; COLMAP's v is down with the top-left centre at 0.5
    np.testing.assert_allclose(u, window[:, 0], atol=1e-9)
    np.testing.assert_allclose(v, camera.height - window[:, 1], atol=1e-9)
    assert np.all(camera_cv[:, 2] > 0)  # OpenCV cameras look down +z
    assert abs(qw**2 + qx**2 + qy**2 + qz**2 - 1.0) < 1e-12


@pytest.mark.parametrize(
    "camera",
    [
        *_cameras(),
        Camera.look_at((2.0, 1.0, 3.0), (0.0, 0.0, 0.0), projection=Orthographic(3.0, 0.5, 12.0), width=40, height=30),
    ],
)
def test_metric_depth_is_distance_along_the_viewing_axis(camera: Camera) -> None:
    rng = np.random.default_rng(1)
    points = camera.frame.eye - 4.0 * camera.frame.n + rng.uniform(-1.0, 1.0, size=(40, 3))
    window_depth = camera.project(points)[:, 2].astype(np.float32)
    expected = (points - camera.frame.eye) @ -np.asarray(camera.frame.n)
    # float32 window depth: its rounding (6e-8 near 1) magnified by dz/dd = z²(far − near)/(far·near) ≤ 8e3 here
    np.testing.assert_allclose(metric_depth(window_depth[None, :], camera)[0], expected, rtol=0, atol=2e-4)
    assert metric_depth(np.ones((2, 3), np.float32), camera).tolist() == [[0.0] * 3] * 2


@given(
    st.integers(0, 2**32 - 1),
    st.floats(0.2, 2.5),
    st.integers(1, 300),
    st.integers(1, 300),
    st.booleans(),
)
def test_pixel_and_depth_conventions_hold_for_any_pinhole_camera(seed, fovy, width, height, off_centre) -> None:
    """Property: OpenCV pixel coordinates from the written intrinsics and COLMAP pose, and metric_depth of the
    window depth, reproduce Camera.project for any pose, field of view, image size and (off-centre) window."""
    rng = np.random.default_rng(seed)
    eye = rng.uniform(-10, 10, 3)
    target = eye + rng.normal(size=3) * rng.uniform(0.5, 5.0)
    up = rng.normal(size=3)
    near, far = rng.uniform(0.1, 1.0), rng.uniform(20.0, 50.0)
    if off_centre:
        left, bottom = rng.uniform(-0.5, 0.1, 2) * near
        projection = Frustum(left, left + rng.uniform(0.2, 1.0) * near, bottom, bottom + rng.uniform(0.2, 1.0) * near,
                             near, far)  # fmt: skip
    else:
        projection = Perspective(fovy, near, far)
    try:
        camera = Camera.look_at(eye, target, up, projection, width, height)
    except CameraError:  # up drawn parallel to the line of sight
        return
    distance = rng.uniform(2.0, 15.0, 20)
    clip = np.column_stack([rng.uniform(-0.9, 0.9, (20, 2)), np.zeros(20), np.ones(20)])  # inside the view
    points = camera.unproject(np.column_stack([(clip[:, 0] + 1) * width / 2, (clip[:, 1] + 1) * height / 2,
                                               np.full(20, 0.5)]))  # fmt: skip
    points = eye + (points - eye) * (distance / ((points - eye) @ -camera.frame.n))[:, None]  # z-depth = distance
    window = camera.project(points)
    k = intrinsics(camera)
    (qw, qx, qy, qz), t = colmap_pose(camera)
    camera_cv = points @ Rotation.from_quat([qx, qy, qz, qw]).as_matrix().T + np.asarray(t)
    u = k["fx"] * camera_cv[:, 0] / camera_cv[:, 2] + k["cx"]
    v = k["fy"] * camera_cv[:, 1] / camera_cv[:, 2] + k["cy"]
    scale = 1e-9 * max(width, height, k["fx"], k["fy"])  # round-off of products of O(fx)-sized numbers
    np.testing.assert_allclose(u, window[:, 0], atol=scale)
    np.testing.assert_allclose(v, height - window[:, 1], atol=scale)
    np.testing.assert_allclose(camera_cv[:, 2], distance, rtol=1e-9)
    # float64 window depth here: the conversion itself is exact to round-off
    np.testing.assert_allclose(metric_depth(window[None, :, 2], camera)[0], distance, rtol=1e-6)


def test_intrinsics_refuses_parallel_projections() -> None:
    camera = Camera.look_at((0, 0, 5), (0, 0, 0), projection=Orthographic(2.0, 0.1, 10.0))
    with pytest.raises(CameraError, match="not a pinhole perspective"):
        intrinsics(camera)


# --- round trips: the written depth back-projected with the written cameras lies on the surface -----------------


def _back_project_gl(depth: np.ndarray, fx: float, fy: float, cx: float, cy: float, c2w: np.ndarray) -> np.ndarray:
    """OpenGL camera (x right, y up, looking down −z), pixel centres at +0.5, z-depth."""
    rows, cols = np.nonzero(depth > 0)
    z = depth[rows, cols].astype(np.float64)
    x = (cols + 0.5 - cx) / fx * z
    y = -(rows + 0.5 - cy) / fy * z
    return np.column_stack([x, y, -z]) @ c2w[:3, :3].T + c2w[:3, 3]


def _back_project_cv(depth: np.ndarray, fx: float, fy: float, cx: float, cy: float, rotation, t) -> np.ndarray:
    """OpenCV camera (x right, y down, looking down +z), world-to-camera X_cam = R X + t."""
    rows, cols = np.nonzero(depth > 0)
    z = depth[rows, cols].astype(np.float64)
    camera = np.column_stack([(cols + 0.5 - cx) / fx * z, (rows + 0.5 - cy) / fy * z, z])
    return (camera - np.asarray(t)) @ rotation  # R⁻¹ = Rᵀ


def _points_nerf(out: Path) -> list[np.ndarray]:
    data = json.loads((out / "transforms.json").read_text())
    points = []
    for frame in data["frames"]:
        depth = np.load(out / frame["depth_file_path"])
        h, w = depth.shape
        image = Image.open(out / (frame["file_path"] + ".png"))
        assert image.size == (w, h)
        focal = 0.5 * w / np.tan(0.5 * data["camera_angle_x"])  # square pixels, centred principal point
        points.append(_back_project_gl(depth, focal, focal, w / 2, h / 2, np.array(frame["transform_matrix"])))
    return points


def _points_nerfstudio(out: Path) -> list[np.ndarray]:
    data = json.loads((out / "transforms.json").read_text())
    points = []
    for frame in data["frames"]:
        depth = np.load(out / frame["depth_file_path"])
        assert depth.shape == (data["h"], data["w"])
        mask = np.asarray(Image.open(out / frame["mask_path"]))
        assert np.array_equal(mask > 0, depth > 0)
        c2w = np.array(frame["transform_matrix"])
        points.append(_back_project_gl(depth, data["fl_x"], data["fl_y"], data["cx"], data["cy"], c2w))
    return points


def _points_colmap(out: Path) -> list[np.ndarray]:
    cameras = [line.split() for line in (out / "sparse/0/cameras.txt").read_text().splitlines() if line[0] != "#"]
    (_, model, w, h, fx, fy, cx, cy), = cameras  # fmt: skip
    assert model == "PINHOLE"
    lines = [line for line in (out / "sparse/0/images.txt").read_text().splitlines() if not line.startswith("#")]
    points = []
    for line in lines[0::2]:  # each image line is followed by its (empty) POINTS2D line
        _, qw, qx, qy, qz, tx, ty, tz, _, name = line.split()
        rotation = Rotation.from_quat([float(qx), float(qy), float(qz), float(qw)]).as_matrix()
        depth = np.load(out / "depth" / (Path(name).stem + ".npy"))
        assert depth.shape == (int(h), int(w))
        assert (out / "images" / name).is_file()
        t = (float(tx), float(ty), float(tz))
        points.append(_back_project_cv(depth, float(fx), float(fy), float(cx), float(cy), rotation, t))
    return points


def _points_files(out: Path) -> list[np.ndarray]:
    points = []
    for key, record in json.loads((out / "cameras.json").read_text()).items():
        depth = np.load(out / "depth" / f"{key}.npy")
        w2c = np.array(record["world_to_camera_opencv"])
        points.append(
            _back_project_cv(depth, record["fx"], record["fy"], record["cx"], record["cy"], w2c[:3, :3], w2c[:3, 3])
        )
    return points


def _points_webdataset(out: Path) -> list[np.ndarray]:
    samples: dict[str, dict[str, bytes]] = {}
    for shard in sorted((out / "shards").glob("*.tar")):
        with tarfile.open(shard) as archive:
            for member in archive.getmembers():
                key, _, extension = member.name.partition(".")  # WebDataset: the key ends at the first dot
                samples.setdefault(key, {})[extension] = archive.extractfile(member).read()
    points = []
    for fields in samples.values():
        assert set(fields) == {"png", "depth.npy", "normals.npy", "object_id.png", "mask.png", "json"}
        record = json.loads(fields["json"])
        depth = np.load(io.BytesIO(fields["depth.npy"]))
        c2w = np.array(record["camera_to_world_opengl"])
        points.append(_back_project_gl(depth, record["fx"], record["fy"], record["cx"], record["cy"], c2w))
    return points


PARSERS = {
    "nerf": _points_nerf,
    "nerfstudio": _points_nerfstudio,
    "colmap": _points_colmap,
    "files": _points_files,
    "webdataset": _points_webdataset,
}


@pytest.mark.parametrize("format", sorted(PARSERS))
def test_round_trip_back_projected_depth_lies_on_the_surface(format, scene_path, surface, tmp_path) -> None:
    result = render_dataset(scene_path, tmp_path, views=6, layout="sphere", format=format, executor="serial",
                            progress=False)  # fmt: skip
    assert result.ok and len(result.rendered) == 6
    points = PARSERS[format](tmp_path)
    assert len(points) == 6
    size = float(np.linalg.norm(surface.bounds[1] - surface.bounds[0]))
    for view in points:
        assert len(view) > 300  # the objects fill a good part of each 64x48 view
        _, distance, _ = trimesh.proximity.closest_point(surface, view)
        # 1e-4 of the scene size: the rasterizer snaps vertices to 1/256 pixel (≈ 3e-4 units here, half of it
        # on average); a half-pixel convention error would be ≈ 0.035 units
        assert distance.max() <= 1e-4 * size


def test_dataset_buffers_agree_with_each_other(scene_path, tmp_path) -> None:
    render_dataset(scene_path, tmp_path, views=2, format="files", executor="serial", progress=False)
    depth = np.load(tmp_path / "depth/view_00001.npy")
    ids = np.asarray(Image.open(tmp_path / "object_id/view_00001.png"))
    normals = np.load(tmp_path / "normals/view_00001.npy")
    mask = np.asarray(Image.open(tmp_path / "masks/view_00001.png"))
    assert depth.dtype == np.float32 and ids.dtype == np.uint16 and normals.dtype == np.float32
    assert set(np.unique(ids)) == {0, 1, 2}  # background, the ball (item 0) and the cube (item 1)
    assert np.array_equal(ids > 0, depth > 0) and np.array_equal(mask == 255, depth > 0)
    np.testing.assert_allclose(np.linalg.norm(normals[depth > 0], axis=1), 1.0, atol=1e-5)
    assert not normals[depth == 0].any()
    readme = (tmp_path / "README.txt").read_text()
    assert "z-depth" in readme and "(0.5, 0.5)" in readme


def test_png16_depth_is_metric_depth_in_steps_of_the_written_scale(scene_path, tmp_path) -> None:
    render_dataset(scene_path, tmp_path / "a", views=2, format="nerfstudio", executor="serial", progress=False)
    render_dataset(scene_path, tmp_path / "b", views=2, format="nerfstudio", executor="serial", progress=False,
                   depth_format="png16")  # fmt: skip
    scale = json.loads((tmp_path / "b/transforms.json").read_text())["depth_unit_scale_factor"]
    steps = np.asarray(Image.open(tmp_path / "b/depth/view_00000.png")).astype(np.float64)
    exact = np.load(tmp_path / "a/depth/view_00000.npy")
    np.testing.assert_allclose(steps * scale, exact, atol=scale / 2 + 1e-6)
    assert str(scale) in (tmp_path / "b/README.txt").read_text()


# --- executors ------------------------------------------------------------------------------------------------


def test_same_bytes_for_serial_and_process_pools_of_one_and_two_workers(scene_path, tmp_path) -> None:
    runs = {}
    for name, executor, workers in (("serial", "serial", None), ("p1", "process", 1), ("p2", "process", 2)):
        result = render_dataset(scene_path, tmp_path / name, views=5, layout="random", format="webdataset",
                                executor=executor, workers=workers, progress=False)  # fmt: skip
        assert result.ok
        runs[name] = files_of(tmp_path / name)
    assert len(runs["serial"]) == 5 * 5 + 3  # five files per view, cameras.json, README.txt, one shard
    assert runs["p1"] == runs["serial"]
    assert runs["p2"] == runs["serial"]


def test_render_many_returns_metadata_in_job_order_and_reports_a_failing_view(tmp_path) -> None:
    from frustum.geometry import icosphere

    scene = Scene()
    scene.add(icosphere(1))
    camera = Camera.look_at((0, 0, 4), (0, 0, 0), width=24, height=16)
    jobs = [RenderJob(f"v{i}", scene, camera, {"color": tmp_path / f"v{i}.png"}) for i in range(3)]
    jobs.insert(1, RenderJob("bad", scene, camera, {"color": tmp_path / "bad.png"}, {"shading": "glossy"}))
    results = render_many(jobs, executor="serial", progress=False)
    assert [r.key for r in results] == ["v0", "bad", "v1", "v2"]
    assert [r.ok for r in results] == [True, False, True, True]
    assert "shading" in results[1].error and "glossy" in results[1].error
    assert not (tmp_path / "bad.png").exists()
    assert results[0].files == {"color": str(tmp_path / "v0.png")}
    assert Image.open(tmp_path / "v2.png").size == (24, 16)


def test_failed_views_are_retried_then_listed_and_the_cli_exits_3(scene_path, tmp_path, monkeypatch, capsys):
    render_module = sys.modules["frustum.render"]  # `frustum.render` is the function
    real = render_module.render
    calls: dict[str, int] = {}

    def flaky(scene, camera, **options):  # view_00001 fails once, view_00002 always
        key = "view_00001" if np.allclose(camera.frame.eye, cameras[1][1].frame.eye) else None
        key = "view_00002" if np.allclose(camera.frame.eye, cameras[2][1].frame.eye) else key
        calls[key] = calls.get(key, 0) + 1
        if key == "view_00002" or (key == "view_00001" and calls[key] == 1):
            raise FrustumError("render: the test says no")
        return real(scene, camera, **options)

    cameras = dataset_cameras(load_scene_file(scene_path).cameras[0], 4, "orbit")
    monkeypatch.setattr(render_module, "render", flaky)
    status = None
    try:
        main(["dataset", str(scene_path), "--out", str(tmp_path), "--views", "4", "--format", "colmap",
              "--executor", "serial", "--no-progress", "--retries", "2"])  # fmt: skip
    except SystemExit as exit_:
        status = exit_.code
    assert status == 3
    captured = capsys.readouterr()
    assert "failed view_00002: FrustumError: render: the test says no" in captured.err
    assert "3 views rendered" in captured.out and "1 failed" in captured.out
    assert calls == {None: 2, "view_00001": 2, "view_00002": 3}
    images = (tmp_path / "sparse/0/images.txt").read_text()
    assert "view_00001.png" in images and "view_00002.png" not in images


@pytest.fixture(scope="session")
def ray_cluster():
    ray = pytest.importorskip("ray")
    for attempt in range(3):  # a loaded machine can miss the 30 s Ray gives its raylet to register
        try:
            # address="local": a cluster of its own, never one found on the machine (RAY_ADDRESS, a running
            # `ray start` or a stale ray_current_cluster file), whose num_cpus could not be set
            saved = os.environ.pop("RAY_ADDRESS", None)  # Ray reads it even for address="local"
            try:
                ray.init(address="local", num_cpus=2, include_dashboard=False, log_to_driver=False,
                         configure_logging=False)  # fmt: skip
            finally:
                if saved is not None:
                    os.environ["RAY_ADDRESS"] = saved
            break
        except Exception:
            ray.shutdown()
            if attempt == 2:
                raise
    yield ray
    ray.shutdown()


def test_ray_executor_writes_the_same_bytes(ray_cluster, scene_path, tmp_path) -> None:
    for name, executor in (("serial", "serial"), ("ray", "ray")):
        # 5 actors asked of a 2-CPU cluster: capped at the free CPUs (more would wait for ever)
        # 16 views on 2 actors: batches of 2 views per task
        result = render_dataset(scene_path, tmp_path / name, views=16, layout="orbit", format="nerfstudio",
                                executor=executor, workers=5, progress=False)  # fmt: skip
        assert result.ok
    assert files_of(tmp_path / "ray") == files_of(tmp_path / "serial")
    lines = (tmp_path / "ray/manifest.jsonl").read_text().splitlines()[1:]
    workers = {json.loads(line)["worker"] for line in lines}
    assert 1 <= len(workers) <= 2 and f"{os.uname().nodename}:{os.getpid()}" not in workers  # in the actors


def test_ray_driver_collect_writes_the_same_bytes_and_memory_urls_go_through_the_driver(
    ray_cluster, scene_path, tmp_path
) -> None:
    """collect="driver": the actors return encoded bytes, this process writes them (what a cluster whose nodes
    share no disk needs; tests/test_batch_cluster.py runs it on two nodes)."""
    import fsspec

    render_dataset(scene_path, tmp_path / "serial", views=7, format="colmap", executor="serial", progress=False)
    result = render_dataset(scene_path, tmp_path / "driver", views=7, format="colmap", executor="ray",
                            progress=False, collect="driver")  # fmt: skip
    assert result.ok and files_of(tmp_path / "driver") == files_of(tmp_path / "serial")
    lines = (tmp_path / "driver/manifest.jsonl").read_text().splitlines()[1:]
    assert f"{os.uname().nodename}:{os.getpid()}" not in {json.loads(line)["worker"] for line in lines}
    # memory:// lives in this process: the default collect mode sends the bytes here, "workers" is refused
    result = render_dataset(scene_path, "memory://collect/ds", views=7, format="colmap", executor="ray",
                            progress=False)  # fmt: skip
    assert result.ok and result.out == "memory://collect/ds"
    fs = fsspec.filesystem("memory")
    written = {p[len("/collect/ds/") :]: fs.cat_file(p) for p in fs.find("/collect/ds")}
    written.pop("manifest.jsonl")
    assert written == files_of(tmp_path / "serial")
    with pytest.raises(FrustumError, match="memory:// lives in one process"):
        render_dataset(scene_path, "memory://collect/other", views=2, executor="ray", progress=False,
                       collect="workers")  # fmt: skip


# --- resume and safety ----------------------------------------------------------------------------------------


def test_resume_after_sigkill_equals_an_uninterrupted_run(scene_path, tmp_path) -> None:
    arguments = ["--views", "40", "--layout", "sphere", "--format", "files", "--size", "320x240", "--no-progress"]
    killed = tmp_path / "killed"
    environment = {**os.environ, "PYTHONPATH": os.pathsep.join([str(SRC), os.environ.get("PYTHONPATH", "")])}
    process = subprocess.Popen(
        [sys.executable, "-m", "frustum", "dataset", str(scene_path), "--out", str(killed), "--executor", "serial",
         *arguments],
        env=environment, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
    )  # fmt: skip
    log = killed / "manifest.jsonl"
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and process.poll() is None:
        if log.exists() and log.read_text().count("\n") >= 4:  # the configuration and three views
            break
        time.sleep(0.002)
    process.send_signal(signal.SIGKILL)
    process.wait()
    finished = log.read_text().count("\n") - 1
    assert 3 <= finished < 40, "the first run was not stopped midway"
    main(["dataset", str(scene_path), "--out", str(killed), "--executor", "process", "--workers", "2", *arguments])
    assert not [p for p in killed.rglob("*") if TEMPORARY_MARK in p.name]
    reference = tmp_path / "reference"
    main(["dataset", str(scene_path), "--out", str(reference), "--executor", "serial", *arguments])
    assert files_of(killed) == files_of(reference)


def test_second_run_skips_every_done_view(scene_path, tmp_path) -> None:
    first = render_dataset(scene_path, tmp_path, views=3, format="nerf", executor="serial", progress=False)
    before = files_of(tmp_path)
    os.remove(tmp_path / "normals/view_00001.npy")  # a lost file: that view is rendered again
    second = render_dataset(scene_path, tmp_path, views=3, format="nerf", executor="serial", progress=False)
    assert first.rendered == ("view_00000", "view_00001", "view_00002") and first.skipped == ()
    assert second.rendered == ("view_00001",) and second.skipped == ("view_00000", "view_00002")
    assert files_of(tmp_path) == before


def test_changed_configuration_is_refused_unless_overwrite(scene_path, tmp_path) -> None:
    render_dataset(scene_path, tmp_path, views=3, format="nerf", executor="serial", progress=False)
    with pytest.raises(OutputError, match=r"another configuration \(format = 'nerf' → 'colmap'; views = 3 → 4\)"):
        render_dataset(scene_path, tmp_path, views=4, format="colmap", executor="serial", progress=False)
    result = render_dataset(scene_path, tmp_path, views=4, format="colmap", executor="serial", progress=False,
                            overwrite=True)  # fmt: skip
    assert len(result.rendered) == 4 and result.skipped == ()
    assert not (tmp_path / "transforms.json").exists()  # the old format's camera file went with the old views
    assert (tmp_path / "sparse/0/images.txt").read_text().count(".png") == 4


def test_interrupted_write_leaves_no_file(tmp_path) -> None:
    def half_then_interrupt(file) -> None:
        file.write(b"half")
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        write_atomically(tmp_path / "sub/out.npy", half_then_interrupt)
    assert list((tmp_path / "sub").iterdir()) == []


# --- layouts --------------------------------------------------------------------------------------------------


def test_layouts_keep_the_distance_and_random_views_depend_only_on_seed_and_key(scene_path, tmp_path) -> None:
    base = load_scene_file(scene_path).cameras[0]
    radius = float(np.linalg.norm(base.frame.eye))
    orbit = dataset_cameras(base, 8, "orbit")
    heights = [float(c.frame.eye[1]) for _, c in orbit]
    np.testing.assert_allclose(heights, base.frame.eye[1], atol=1e-12)
    np.testing.assert_allclose(orbit[0][1].frame.eye, base.frame.eye, atol=1e-12)
    for layout in ("orbit", "sphere", "random"):
        for _, camera in dataset_cameras(base, 8, layout, seed=3):
            assert abs(np.linalg.norm(camera.frame.eye) - radius) < 1e-9
            assert camera.projection is base.projection and (camera.width, camera.height) == (64, 48)
    few, many = dataset_cameras(base, 3, "random", seed=7), dataset_cameras(base, 9, "random", seed=7)
    assert [c.frame.eye.tolist() for _, c in few] == [c.frame.eye.tolist() for _, c in many[:3]]
    other = dataset_cameras(base, 3, "random", seed=8)
    assert few[0][1].frame.eye.tolist() != other[0][1].frame.eye.tolist()
    ys = sorted(float(c.frame.eye[1]) for _, c in dataset_cameras(base, 50, "sphere"))
    assert ys[0] < -0.9 * radius and ys[-1] > 0.9 * radius
    listed = tmp_path / "cameras.json"
    listed.write_text(json.dumps([{"eye": [0, 0, 3], "target": [0, 0, 0]}, {"eye": [3, 0, 0], "target": [0, 0, 0]}]))
    from_file = dataset_cameras(base, None, "file", cameras_file=listed)
    assert [k for k, _ in from_file] == ["view_00000", "view_00001"]
    assert from_file[1][1].frame.eye.tolist() == [3.0, 0.0, 0.0]


# --- bad input ------------------------------------------------------------------------------------------------


def test_output_folder_that_is_a_file_or_not_writable_is_refused(scene_path, tmp_path) -> None:
    a_file = tmp_path / "taken"
    a_file.write_text("x")
    with pytest.raises(OutputError, match="is a file; give a folder"):
        render_dataset(scene_path, a_file, views=2, executor="serial", progress=False)
    with pytest.raises(OutputError, match="is not writable"):
        render_dataset(scene_path, a_file / "below", views=2, executor="serial", progress=False)


def test_scene_that_fails_to_load_is_reported_once_before_any_work(tmp_path, capsys) -> None:
    broken = tmp_path / "broken.toml"
    broken.write_text(SCENE.replace('type = "box"', 'type = "boxx"'))
    with pytest.raises(SceneFileError, match=r"broken.toml:\d+: .*boxx"):
        render_dataset(broken, tmp_path / "out", views=50, executor="process", progress=False)
    assert not (tmp_path / "out").exists()
    with pytest.raises(SystemExit) as exit_:
        main(["dataset", str(broken), "--out", str(tmp_path / "out"), "--views", "50", "--no-progress"])
    assert exit_.value.code == 1
    assert capsys.readouterr().err.count("boxx") == 1


@pytest.mark.parametrize(
    ("arguments", "error", "message"),
    [
        ({"format": "blender"}, OutputError, "format = 'blender' is unknown; expected one of nerf, nerfstudio, colmap, "
                                             "files, webdataset"),
        ({"layout": "spiral"}, CameraError, "layout = 'spiral' is unknown; expected one of orbit, sphere, random, "
                                            "file"),
        ({"depth_format": "exr"}, OutputError, "depth_format = 'exr' is unknown; expected one of npy, png16"),
        ({"executor": "dask"}, FrustumError, "executor = 'dask' is unknown; expected one of serial, process, ray"),
        ({"views": 0}, CameraError, "views = 0 must be a positive integer"),
        ({"layout": "file"}, CameraError, "layout = 'file' needs cameras_file"),
        ({"retries": -1}, FrustumError, "retries = -1 must be an integer >= 0"),
    ],
)  # fmt: skip
def test_bad_dataset_arguments_are_named_with_the_valid_ones(scene_path, tmp_path, arguments, error, message):
    with pytest.raises(error, match=message.replace("(", r"\(").replace(")", r"\)")):
        render_dataset(scene_path, tmp_path, **{"views": 2, "progress": False, **arguments})


def test_camera_formats_refuse_projections_they_cannot_describe(tmp_path) -> None:
    scene = tmp_path / "ortho.toml"
    scene.write_text(SCENE.replace("fovy_deg = 45", 'projection = "orthographic"\nheight = 3.0'))
    with pytest.raises(CameraError, match="not a pinhole perspective"):
        render_dataset(scene, tmp_path / "out", views=2, format="colmap", progress=False)
    result = render_dataset(scene, tmp_path / "files", views=2, format="files", executor="serial", progress=False)
    assert result.ok and "fx" not in json.loads((tmp_path / "files/cameras.json").read_text())["view_00000"]


@pytest.mark.parametrize(
    ("jobs", "message"),
    [
        (["not a job"], "jobs\\[0\\] = 'not a job' is not a RenderJob"),
        ([RenderJob("a", "x", None, {"colour": "a.png"})],
         "outputs has kind 'colour'; expected one of annotations, color"),
        ([RenderJob("a", "x", None, {"depth": "a.exr"})], "has suffix '.exr'; expected .npy or .png"),
        ([RenderJob("a", 42, None, {})], "scene = 42 is not a Scene or a scene file path"),
    ],
)
def test_render_many_rejects_bad_jobs(jobs, message) -> None:
    with pytest.raises(FrustumError, match=message):
        render_many(jobs, executor="serial", progress=False)


def test_render_many_rejects_repeated_keys_and_bad_workers(tmp_path) -> None:
    scene = Scene()
    camera = Camera.look_at((0, 0, 4), (0, 0, 0), width=8, height=8)
    jobs = [RenderJob("a", scene, camera, {}), RenderJob("a", scene, camera, {})]
    with pytest.raises(FrustumError, match="key = 'a' is repeated"):
        render_many(jobs, executor="serial", progress=False)
    with pytest.raises(FrustumError, match="workers = 0 must be a positive integer"):
        render_many(jobs[:1], workers=0, progress=False)


def test_render_many_rejects_unknown_collect_modes_and_memory_urls_in_a_pool(tmp_path) -> None:
    scene = Scene()
    camera = Camera.look_at((0, 0, 4), (0, 0, 0), width=8, height=8)
    with pytest.raises(FrustumError, match="collect = 'nodes' is unknown; expected one of driver, workers or None"):
        render_many([RenderJob("a", scene, camera, {})], executor="serial", progress=False, collect="nodes")
    with pytest.raises(FrustumError, match=r"'memory://x/a\.png' with executor = 'process': memory:// lives in one"):
        render_many([RenderJob("a", scene, camera, {"color": "memory://x/a.png"})], progress=False)


def test_driver_collect_pieces_rebuild_every_file(scene_path, tmp_path, monkeypatch) -> None:
    """collect="driver": a task returns its files cut into pieces small enough to travel inside Ray's reply (not
    through the object store the driver would map); written piece by piece they are encode_view's bytes, also
    when the pieces are tiny and when the files outgrow the values planned (the rest comes as one list)."""
    from frustum.batch import executors
    from frustum.batch.jobs import encode_view, write_view

    camera = load_scene_file(scene_path).cameras[0]
    kinds = {"color": ".png", "depth": ".npy", "normals": ".n.npy", "mask": ".m.png"}
    jobs = [RenderJob(key, str(scene_path), c, {kind: f"{tmp_path}/{key}{end}" for kind, end in kinds.items()})
            for key, c in dataset_cameras(camera, 3, "sphere")]  # fmt: skip
    scenes, plain = executors._prepare(jobs, "test")
    expected = {job.key: encode_view(scenes[0][0], job, scenes[0][1])[1] for job in plain}
    actor = object.__new__(executors._RayRenderer)  # the actor's class, here in this process
    actor.scenes = scenes
    for step, planned in ((96 * 1024, None), (1000, None), (1000, 5)):
        monkeypatch.setattr(executors, "RAY_INLINE_BYTES", step)
        parts = planned or executors._parts(plain)
        values = actor.encode(plain, parts)
        assert len(values) == parts  # the task's num_returns
        pieces = [v for v in values[1:-1] if v is not None] + values[-1]
        assert all(len(piece) <= step for piece in pieces)
        assert (values[-1] == []) == (planned is None)  # the plan holds every piece unless cut short on purpose
        for result, encoded in executors._pieced(values):
            assert {kind: b"".join(p) for kind, p in encoded.items()} == expected[result.key]
            job = next(j for j in plain if j.key == result.key)
            assert write_view(job, result, encoded).ok
            assert {k: Path(job.outputs[k]).read_bytes() for k in encoded} == expected[result.key]


# --- URL outputs (fsspec) -------------------------------------------------------------------------------------


def _url_files(url: str) -> dict[str, bytes]:
    import fsspec

    fs, root = fsspec.core.url_to_fs(url)
    return {p[len(root) + 1 :]: fs.cat_file(p) for p in sorted(fs.find(root)) if not p.endswith("manifest.jsonl")}


def test_url_datasets_equal_a_folder_and_resume_and_refuse_like_one(scene_path, tmp_path) -> None:
    pytest.importorskip("fsspec")
    render_dataset(scene_path, tmp_path / "folder", views=4, format="webdataset", executor="serial", progress=False)
    reference = files_of(tmp_path / "folder")
    for url in ("memory://urls/ds", f"file://{tmp_path}/url"):
        result = render_dataset(scene_path, url, views=4, format="webdataset", executor="serial", progress=False)
        assert result.ok and result.out == url and result.camera_files[0] == f"{url}/cameras.json"
        assert _url_files(url) == reference
        import fsspec

        fs, root = fsspec.core.url_to_fs(url)
        fs.rm_file(f"{root}/depth/view_00002.npy")  # a lost file: that view again
        again = render_dataset(scene_path, url, views=4, format="webdataset", executor="serial", progress=False)
        assert again.rendered == ("view_00002",) and len(again.skipped) == 3
        assert _url_files(url) == reference
        assert not fs.exists(f"{root}/manifest.parts")  # the run log's parts were merged at the end
        with pytest.raises(OutputError, match=r"another configuration \(format = 'webdataset' → 'nerf'\)"):
            render_dataset(scene_path, url, views=4, format="nerf", executor="serial", progress=False)
    with pytest.raises(OutputError, match=r"out = 'file://.*' is a file"):
        render_dataset(scene_path, f"file://{tmp_path}/folder/cameras.json", views=2, executor="serial",
                       progress=False)  # fmt: skip


def test_url_resume_after_sigkill_reads_the_parts_of_the_run_log(scene_path, tmp_path) -> None:
    """A URL's run log is written in parts every few seconds: a killed run leaves them, the next run reads them.

    The killed run writes a part every 0.05 s (``URL_LOG_SECONDS`` is 2 s: on a quiet machine the 300 views took
    less than that, so the first run finished before any part was written)."""
    pytest.importorskip("fsspec")
    arguments = ["--views", "300", "--layout", "sphere", "--format", "files", "--size", "200x150", "--no-progress",
                 "--executor", "serial"]  # fmt: skip
    url = f"file://{tmp_path}/killed"
    environment = {**os.environ, "PYTHONPATH": os.pathsep.join([str(SRC), os.environ.get("PYTHONPATH", "")])}
    program = ("import sys; import frustum.batch.dataset as d; d.URL_LOG_SECONDS = 0.05; "
               "from frustum.app.cli import main; sys.argv[0] = 'frustum'; main()")  # fmt: skip
    process = subprocess.Popen([sys.executable, "-c", program, "dataset", str(scene_path), "--out", url,
                                *arguments], env=environment, stdout=subprocess.DEVNULL,
                               stderr=subprocess.DEVNULL)  # fmt: skip
    parts = tmp_path / "killed/manifest.parts"
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and process.poll() is None:
        if parts.is_dir() and any(parts.glob("*.jsonl")):
            break
        time.sleep(0.01)
    process.send_signal(signal.SIGKILL)
    process.wait()
    assert not (tmp_path / "killed/cameras.json").exists(), "the first run was not stopped midway"
    logged = sum(p.read_text().count("\n") for p in parts.glob("*.jsonl"))
    result = render_dataset(scene_path, url, views=300, layout="sphere", format="files", size=(200, 150),
                            executor="serial", progress=False)  # fmt: skip
    assert len(result.skipped) == logged > 0 and len(result.rendered) == 300 - logged
    assert not parts.exists() or not any(parts.iterdir())
    render_dataset(scene_path, tmp_path / "reference", views=300, layout="sphere", format="files", size=(200, 150),
                   executor="serial", progress=False)  # fmt: skip
    assert files_of(tmp_path / "killed") == files_of(tmp_path / "reference")


def test_import_frustum_loads_neither_ray_nor_a_process_pool() -> None:
    code = "import sys, frustum; print(sorted(m for m in sys.modules if m.split('.')[0] == 'ray' or m in " \
           "('concurrent.futures.process', 'multiprocessing.pool', 'tarfile')))"  # fmt: skip
    environment = {**os.environ, "PYTHONPATH": str(SRC)}
    output = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=environment, check=True)
    assert output.stdout.strip() == "[]"


def test_dataset_over_the_memory_budget_is_refused_before_any_work(scene_path, tmp_path) -> None:
    # 100 kB: above one 64x48 image (the scene file's own image check, 61 kB), below the dataset's estimate (344 kB)
    with frustum.budget(bytes=100_000), pytest.raises(OutputError, match=r"size = 64x48, .* over the memory budget"):
        render_dataset(scene_path, tmp_path / "out", views=3, executor="serial", progress=False)
    assert not (tmp_path / "out").exists()
