"""Animations: turntable cameras against Camera.orbit, GIF frame counts read back, progress off a terminal, errors."""

from __future__ import annotations

import io
import math
import os
import subprocess
import sys
import textwrap

import imageio.v3 as iio
import numpy as np
import pytest
import trimesh
from PIL import Image
from rich.console import Console

from frustum import (
    Camera,
    CameraError,
    DirectionalLight,
    Material,
    Mesh,
    OutputError,
    Perspective,
    Scene,
    render,
    rotate_y,
)
from frustum.output.animation import framing_camera, orbit_cameras, turntable, write_animation
from oracles import assert_close


@pytest.fixture(scope="module")
def scene() -> Scene:
    box = trimesh.creation.box(extents=(1.0, 0.6, 0.4))
    result = Scene(lights=[DirectionalLight(direction=(-0.4, -0.8, -0.5))])
    result.add(Mesh(box.vertices, box.faces), Material(color=(0.9, 0.4, 0.2)))
    return result


def _camera(width: int = 40, height: int = 30) -> Camera:
    return Camera.orbit((0, 0, 0), 4.0, 0.3, 0.4, Perspective(math.radians(45), 0.5, 20.0), width, height)


def _gif_frames(path) -> list[np.ndarray]:
    return [np.asarray(frame)[:, :, :3] for frame in iio.imiter(path)]


# --- cameras ----------------------------------------------------------------------------------------------------


def test_orbit_cameras_about_y_equal_camera_orbit_at_each_azimuth():
    start = _camera()
    cameras = orbit_cameras(start, 8, axis="y")
    assert len(cameras) == 8 and cameras[0].frame.eye.tolist() == pytest.approx(start.frame.eye.tolist())
    for k, camera in enumerate(cameras):
        expected = Camera.orbit((0, 0, 0), 4.0, 0.3 + 2 * math.pi * k / 8, 0.4, start.projection, 40, 30)
        assert_close(camera.frame.eye, expected.frame.eye)
        assert_close(camera.view_matrix, expected.view_matrix)
        assert camera.projection == start.projection and (camera.width, camera.height) == (40, 30)


@pytest.mark.parametrize("axis", ["x", "z", (1.0, 2.0, 2.0), None])
def test_orbit_cameras_keep_distance_to_target_and_turn_once(axis):
    start = Camera.look_at((1, 2, 5), (0.5, 0, 0), (0, 1, 0))
    cameras = orbit_cameras(start, 6, axis)
    direction = {"x": (1, 0, 0), "z": (0, 0, 1), None: (0, 1, 0)}.get(axis, (1 / 3, 2 / 3, 2 / 3))
    offsets = np.array([c.frame.eye - start.frame.target for c in cameras])
    assert_close(np.linalg.norm(offsets, axis=1), np.full(6, np.linalg.norm(offsets[0])))
    # the offsets' components along the axis stay, the rest turns by 60° per frame
    assert_close(offsets @ direction, np.full(6, offsets[0] @ direction))
    across = offsets - np.outer(offsets @ direction, direction)
    cosines = np.sum(across * np.roll(across, -1, axis=0), axis=1) / np.sum(across * across, axis=1)
    assert_close(cosines, np.full(6, 0.5), 1e-9)


def test_framing_camera_sees_the_whole_scene(scene):
    camera = framing_camera(scene, 64, 48)
    window = camera.project(scene.items[0].mesh.vertices)
    assert (window[:, 0] > 0).all() and (window[:, 0] < 64).all()
    assert (window[:, 1] > 0).all() and (window[:, 1] < 48).all()
    assert ((window[:, 2] > 0) & (window[:, 2] < 1)).all()


# --- files --------------------------------------------------------------------------------------------------------


def test_turntable_gif_has_the_requested_frame_count(scene, tmp_path):
    path = tmp_path / "spin.gif"
    assert turntable(scene, _camera(), frames=7, path=path, progress=False, mode="wireframe") == 7
    frames = _gif_frames(path)
    assert len(frames) == 7
    assert frames[0].shape == (30, 40, 3)
    assert Image.open(path).n_frames == 7


def test_turntable_frames_are_the_rendered_frames(scene, tmp_path):
    camera = _camera()
    frames = turntable(scene, camera, frames=4, progress=False, mode="wireframe")
    assert len(frames) == 4
    np.testing.assert_array_equal(frames[0].color, render(scene, camera, mode="wireframe").color)
    path = tmp_path / "wire.gif"
    turntable(scene, camera, frames=4, path=path, progress=False, mode="wireframe")
    # two colors only: the palette holds them exactly, so the GIF frames equal the renders
    for written, frame in zip(_gif_frames(path), frames, strict=True):
        np.testing.assert_array_equal(written, frame.color[:, :, :3])


def test_identical_frames_are_kept_as_separate_gif_frames(tmp_path):
    image = np.zeros((6, 5, 3), dtype=np.uint8)
    image[2:4, 1:3] = (200, 10, 30)
    path = tmp_path / "still.gif"
    assert write_animation([image] * 5, path, fps=10) == 5
    frames = _gif_frames(path)
    assert len(frames) == 5
    for frame in frames:  # the duplicate palette entry shows the same color
        np.testing.assert_array_equal(frame, image)


def test_gif_bytes_are_deterministic(scene, tmp_path):
    first, second = tmp_path / "a.gif", tmp_path / "b.gif"
    turntable(scene, _camera(), frames=3, path=first, progress=False, mode="wireframe")
    turntable(scene, _camera(), frames=3, path=second, progress=False, mode="wireframe")
    assert first.read_bytes() == second.read_bytes()


def test_gif_frame_duration_follows_fps(tmp_path):
    path = tmp_path / "fps.gif"
    write_animation([np.zeros((4, 4, 3), np.uint8), np.full((4, 4, 3), 255, np.uint8)], path, fps=5)
    assert Image.open(path).info["duration"] == 200


def test_mp4_without_imageio_ffmpeg_says_what_to_install(monkeypatch, tmp_path):
    monkeypatch.setitem(sys.modules, "imageio_ffmpeg", None)  # import raises ImportError
    with pytest.raises(OutputError, match=r"write_animation: path = .*spin.mp4.* needs the imageio-ffmpeg package"):
        write_animation([np.zeros((4, 4, 3), np.uint8)], tmp_path / "spin.mp4")


# --- progress -------------------------------------------------------------------------------------------------------


def test_progress_is_silent_off_a_terminal_and_drawn_on_one(scene):
    plain = io.StringIO()
    turntable(scene, _camera(), frames=3, progress=Console(file=plain, force_terminal=False), mode="points")
    assert plain.getvalue() == ""
    terminal = io.StringIO()
    turntable(scene, _camera(), frames=3, progress=Console(file=terminal, force_terminal=True), mode="points")
    assert "3/3" in terminal.getvalue()


def test_progress_does_not_break_when_output_is_piped(tmp_path):
    script = textwrap.dedent(
        f"""
        import trimesh
        from frustum import Camera, Mesh, Scene
        from frustum.output.animation import turntable
        box = trimesh.creation.box()
        scene = Scene()
        scene.add(Mesh(box.vertices, box.faces))
        camera = Camera.orbit((0, 0, 0), 4.0, 0.0, 0.3, width=24, height=16)
        print(turntable(scene, camera, frames=4, path={str(tmp_path / "piped.gif")!r}, progress=True, mode="points"))
        """
    )
    quiet = {**os.environ, "FRUSTUM_COMPILE_NOTICE": "0"}  # a cold cache's compile notice is not the progress bar
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120, check=False,
                            env=quiet)  # fmt: skip
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "4"
    assert result.stderr == ""
    assert len(_gif_frames(tmp_path / "piped.gif")) == 4


# --- bad input ------------------------------------------------------------------------------------------------------


def test_bad_input_names_the_value(scene, tmp_path):
    camera = _camera()
    with pytest.raises(OutputError, match=r"turntable: path = '.*spin.avi' has suffix '.avi'; expected one of"):
        turntable(scene, camera, frames=2, path=tmp_path / "spin.avi")
    with pytest.raises(OutputError, match=r"turntable: fps = 0.0 is out of range"):
        turntable(scene, camera, frames=2, path=tmp_path / "spin.gif", fps=0)
    with pytest.raises(CameraError, match=r"orbit_cameras: frames = 0 is not a positive integer"):
        turntable(scene, camera, frames=0)
    with pytest.raises(CameraError, match=r"orbit_cameras: axis = 'w' is unknown"):
        turntable(scene, camera, frames=2, axis="w")
    with pytest.raises(CameraError, match=r"orbit_cameras: axis = \(0.0, 0.0, 0.0\) has zero length"):
        orbit_cameras(camera, 2, axis=(0, 0, 0))
    with pytest.raises(OutputError, match=r"turntable: size = \(0.0, 10.0\) is not \(width, height\)"):
        turntable(scene, None, frames=2, size=(0, 10))
    with pytest.raises(CameraError, match=r"framing_camera: the scene has no vertices"):
        turntable(Scene(), None, frames=2)
    with pytest.raises(OutputError, match=r"write_animation: frames is empty"):
        write_animation([], tmp_path / "empty.gif")
    with pytest.raises(OutputError, match=r"write_animation: frames\[1\] has dtype float64"):
        write_animation([np.zeros((4, 4, 3), np.uint8), np.zeros((4, 4, 3))], tmp_path / "bad.gif")
    with pytest.raises(OutputError, match=r"write_animation: frames\[1\] has shape \(5, 4, 3\); expected \(4, 4, 3\)"):
        write_animation([np.zeros((4, 4, 3), np.uint8), np.zeros((5, 4, 3), np.uint8)], tmp_path / "bad.gif")
    with pytest.raises(OutputError, match=r"write_animation: path = '.*missing/spin.gif' cannot be written"):
        write_animation([np.zeros((4, 4, 3), np.uint8)], tmp_path / "missing" / "spin.gif")


def test_turning_lights_with_the_camera_equals_turning_the_object(scene):
    """A real turntable: the object turns under a fixed camera and fixed lights."""
    camera = _camera(64, 48)
    frames = turntable(scene, camera, frames=4, axis="y", progress=False)
    mesh = scene.items[0].mesh
    for k in (1, 2):
        turned = Scene(lights=scene.lights)
        turned.add(mesh, scene.items[0].material, rotate_y(-2 * math.pi * k / 4))
        expected = render(turned, camera).color.astype(int)
        # the same picture up to round-off at a few edge pixels and in the shading
        differ = np.abs(frames[k].color.astype(int) - expected).max(axis=2) > 2
        assert differ.mean() < 0.01
    fixed = turntable(scene, camera, frames=4, axis="y", progress=False, lights_follow=False)
    np.testing.assert_array_equal(fixed[0].color, frames[0].color)
    assert not np.array_equal(fixed[2].color, frames[2].color)


def test_mp4_has_the_requested_frames_when_imageio_ffmpeg_is_installed(tmp_path):
    pytest.importorskip("imageio_ffmpeg")
    frames = [np.full((15, 21, 3), 10 * i, np.uint8) for i in range(6)]
    path = tmp_path / "spin.mp4"
    assert write_animation(frames, path, fps=12) == 6
    written = list(iio.imiter(path, plugin="FFMPEG"))
    assert len(written) == 6
    assert written[0].shape == (16, 22, 3)  # odd sizes padded to even for yuv420p
