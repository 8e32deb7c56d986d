"""Stereo pairs: off-axis eye frusta against PyGLM (frustumRH_NO, lookAtRH), parallax, and image compositions."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from pyglm import glm

from frustum import Camera, CameraError, Material, Mesh, Orthographic, OutputError, Perspective, Scene, ViewFrame
from frustum.output.stereo import anaglyph, over_under, render_stereo, side_by_side
from frustum.stereo import StereoCamera
from oracles import assert_close, glm_matrix, glm_vec

# glm.frustumRH_NO builds float32 matrices (ORACLES trap 2): each entry is a few float32 roundings (eps 1.2e-7)
# away from the float64 one, e.g. 2n/(r - l) with an off-centre window differs by 1.3e-6 relative.
GLM_FLOAT32 = {"rtol": 4e-6, "atol": 1e-6}

fovys = st.floats(min_value=0.2, max_value=2.5)
sizes = st.integers(min_value=16, max_value=1920)
nears = st.floats(min_value=0.05, max_value=5.0)
separations = st.floats(min_value=1e-3, max_value=2.0)
coordinates = st.floats(min_value=-50.0, max_value=50.0)


@st.composite
def stereo_cameras(draw: st.DrawFn) -> StereoCamera:
    eye = np.array([draw(coordinates) for _ in range(3)])
    direction = np.array([draw(st.floats(-1, 1)) for _ in range(3)])
    if np.linalg.norm(direction) < 0.1:
        direction = np.array([0.0, 0.0, -1.0])
    up = np.array([0.0, 1.0, 0.0])
    if np.linalg.norm(np.cross(up, direction)) < 0.1 * np.linalg.norm(direction):
        up = np.array([1.0, 0.0, 0.0])
    near = draw(nears)
    far = near * draw(st.floats(min_value=5.0, max_value=500.0))
    convergence = near * draw(st.floats(min_value=1.5, max_value=4.0))
    projection = Perspective(draw(fovys), near, far)
    camera = Camera.look_at(eye, eye + 3.0 * direction, up, projection, draw(sizes), draw(sizes))
    return StereoCamera(camera, draw(separations) * near, convergence)


def expected_windows(stereo: StereoCamera) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """(left, right, bottom, top) of each eye: the centre window shifted by ±(e/2)·near/D."""
    projection = stereo.camera.projection
    top = projection.near * math.tan(projection.fovy / 2)
    half_width = top * stereo.camera.width / stereo.camera.height
    shift = stereo.eye_separation / 2 * projection.near / stereo.convergence_distance
    return (-half_width + shift, half_width + shift, -top, top), (-half_width - shift, half_width - shift, -top, top)


@given(stereo_cameras())
def test_eye_projections_are_glm_frustums_with_shifted_windows(stereo):
    near, far = stereo.camera.projection.near, stereo.camera.projection.far
    for eye_camera, window in zip((stereo.left, stereo.right), expected_windows(stereo), strict=True):
        got = (eye_camera.projection.left, eye_camera.projection.right)
        got += (eye_camera.projection.bottom, eye_camera.projection.top)
        np.testing.assert_allclose(got, window, rtol=1e-12, atol=0)
        expected = glm_matrix(glm.frustumRH_NO(*window, near, far))
        np.testing.assert_allclose(eye_camera.projection_matrix, expected, **GLM_FLOAT32)
    left_window, right_window = expected_windows(stereo)
    assert left_window[0] + left_window[1] > 0 > right_window[0] + right_window[1]  # asymmetric, toward the centre


@given(stereo_cameras())
def test_eye_views_are_glm_look_at_from_the_offset_eyes(stereo):
    frame = stereo.camera.frame
    for sign, eye_camera in ((-1.0, stereo.left), (+1.0, stereo.right)):
        offset = sign * stereo.eye_separation / 2 * np.asarray(frame.u)
        expected = glm_matrix(
            glm.lookAtRH(glm_vec(frame.eye + offset), glm_vec(frame.target + offset), glm_vec(frame.up))
        )
        assert_close(eye_camera.view_matrix, expected)
        # parallel lines of sight (no toe-in): the same u, v, n as the centre camera
        assert_close(np.asarray(eye_camera.frame.n), np.asarray(frame.n))
        assert_close(np.asarray(eye_camera.frame.v), np.asarray(frame.v))
    assert_close(np.linalg.norm(stereo.eyes[1] - stereo.eyes[0]), stereo.eye_separation)


def _points_at_distance(stereo: StereoCamera, distance: float, seed: int = 0) -> np.ndarray:
    """Points `distance` in front of the centre eye, spread over the middle of the view."""
    frame = stereo.camera.frame
    rng = np.random.default_rng(seed)
    top = distance * math.tan(stereo.camera.projection.fovy / 2)
    a, b = rng.uniform(-0.5, 0.5, (2, 20, 1))
    return frame.eye + distance * frame.direction + a * top * stereo.camera.aspect * frame.u + b * top * frame.v


@settings(max_examples=50)
@given(stereo_cameras())
def test_zero_parallax_on_the_convergence_plane_positive_behind_negative_in_front(stereo):
    distance = stereo.convergence_distance
    on_plane = _points_at_distance(stereo, distance)
    left, right = stereo.left.project(on_plane), stereo.right.project(on_plane)
    # same window x and y in both eyes; round-off of a few ulps of the window size
    np.testing.assert_allclose(right[:, :2], left[:, :2], rtol=0, atol=1e-9 * max(stereo.camera.width, 1))
    np.testing.assert_allclose(stereo.parallax(on_plane), 0.0, atol=1e-9 * stereo.camera.width)
    assert (stereo.parallax(_points_at_distance(stereo, 1.5 * distance)) > 0).all()
    near = stereo.camera.projection.near
    assert (stereo.parallax(_points_at_distance(stereo, (near + distance) / 2)) < 0).all()


def test_parallax_grows_toward_the_eye_separation_far_away():
    # at distance z the window parallax is (e·near/D − e·near/z) / window width · image width (pixels)
    camera = Camera.look_at((0, 0, 0), (0, 0, -1), (0, 1, 0), Perspective(1.0, 0.5, 1000.0), 400, 300)
    stereo = StereoCamera(camera, 0.1, 5.0)
    window_width = 2 * 0.5 * math.tan(0.5) * 400 / 300
    for z in (2.0, 5.0, 20.0, 500.0):
        expected = (0.1 * 0.5 / 5.0 - 0.1 * 0.5 / z) / window_width * 400
        assert stereo.parallax((0.0, 0.3, -z)) == pytest.approx(expected, rel=1e-9, abs=1e-9)


def test_frames_given_by_normal_and_left_handed_frames_keep_zero_parallax():
    for frame in (
        ViewFrame((1.0, 2.0, 3.0), normal=(0.2, 0.1, 1.0), up=(0, 1, 0)),
        ViewFrame((1.0, 2.0, 3.0), target=(0.0, 0.0, 0.0), up=(0, 1, 0), handedness="left"),
    ):
        stereo = StereoCamera(Camera(frame, Perspective(1.0, 0.2, 50.0), 320, 240), 0.2, 4.0)
        assert stereo.left.frame.handedness == frame.handedness
        np.testing.assert_allclose(stereo.parallax(_points_at_distance(stereo, 4.0)), 0.0, atol=1e-9)
        assert (stereo.parallax(_points_at_distance(stereo, 8.0)) > 0).all()


# --- image compositions ----------------------------------------------------------------------------------


def _images() -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(7)
    return rng.integers(0, 256, (5, 6, 4), dtype=np.uint8), rng.integers(0, 256, (5, 6, 4), dtype=np.uint8)


def test_color_anaglyph_takes_red_from_the_left_and_green_blue_from_the_right():
    left, right = _images()
    image = anaglyph(left, right)
    np.testing.assert_array_equal(image[..., 0], left[..., 0])
    np.testing.assert_array_equal(image[..., 1:3], right[..., 1:3])
    np.testing.assert_array_equal(image[..., 3], np.maximum(left[..., 3], right[..., 3]))


def test_gray_anaglyph_puts_the_luma_of_each_eye_in_its_channels():
    left = np.zeros((1, 2, 4), dtype=np.uint8)
    left[0, 0] = (255, 0, 0, 255)  # pure red: luma 0.299
    left[0, 1] = (0, 0, 255, 255)  # pure blue: luma 0.114
    right = left[:, ::-1].copy()
    image = anaglyph(left, right, "gray")
    np.testing.assert_array_equal(image[0, 0], (round(0.299 * 255), round(0.114 * 255), round(0.114 * 255), 255))
    np.testing.assert_array_equal(image[0, 1], (round(0.114 * 255), round(0.299 * 255), round(0.299 * 255), 255))


def test_dubois_anaglyph_keeps_white_and_black_and_codes_each_eye_in_its_filter():
    white = np.full((2, 2, 4), 255, dtype=np.uint8)
    black = np.zeros((2, 2, 4), dtype=np.uint8)
    black[..., 3] = 255
    # the rows of Dubois's two matrices together sum to 0.999, 1.0 and 1.0: white stays white
    np.testing.assert_array_equal(anaglyph(white, white, "dubois"), white)
    np.testing.assert_array_equal(anaglyph(black, black, "dubois"), black)
    only_left = anaglyph(white, black, "dubois")[0, 0]
    only_right = anaglyph(black, white, "dubois")[0, 0]
    assert only_left[0] > 200 and only_left[1] == only_left[2] == 0  # left eye: red light only
    assert only_right[0] == 0 and only_right[1] > 200 and only_right[2] > 200  # right eye: cyan


def test_side_by_side_and_over_under_layouts():
    left, right = _images()
    np.testing.assert_array_equal(side_by_side(left, right), np.concatenate([left, right], axis=1))
    np.testing.assert_array_equal(side_by_side(left, right, cross_eyed=True), np.concatenate([right, left], axis=1))
    np.testing.assert_array_equal(over_under(left, right), np.concatenate([left, right], axis=0))
    assert side_by_side(left, right).shape == (5, 12, 4) and over_under(left, right).shape == (10, 6, 4)


def _square_scene(distance: float, half: float = 0.6) -> Scene:
    vertices = [[-half, -half, -distance], [half, -half, -distance], [half, half, -distance], [-half, half, -distance]]
    mesh = Mesh(np.array(vertices) + np.array([0.013, 0.007, 0.0]), [[0, 1, 2], [0, 2, 3]])
    scene = Scene()
    scene.add(mesh, Material(color=(1.0, 1.0, 1.0)))
    return scene


def test_rendered_square_on_the_convergence_plane_coincides_in_both_eyes():
    camera = Camera.look_at((0, 0, 0), (0, 0, -1), (0, 1, 0), Perspective(0.8, 0.5, 50.0), 96, 72)
    stereo = StereoCamera(camera, 0.3, 4.0)
    frame = render_stereo(_square_scene(4.0), stereo, "side-by-side", shading="none")
    left, right = frame.color[:, :96, 0] > 0, frame.color[:, 96:, 0] > 0
    assert left.sum() > 200 and (left == right).mean() >= 0.999
    # behind the convergence plane the right eye sees the square shifted to the right (positive parallax)
    frame = render_stereo(_square_scene(8.0), stereo, "side-by-side", shading="none")
    columns = np.arange(96)
    left_center = (frame.color[:, :96, 0] > 0).sum(axis=0) @ columns / (frame.color[:, :96, 0] > 0).sum()
    right_center = (frame.color[:, 96:, 0] > 0).sum(axis=0) @ columns / (frame.color[:, 96:, 0] > 0).sum()
    assert right_center - left_center == pytest.approx(stereo.parallax((0.013, 0.007, -8.0)), abs=0.5)


def test_render_stereo_layouts_compose_the_two_eyes_renders():
    from frustum import render

    camera = Camera.look_at((0, 0, 0), (0, 0, -1), (0, 1, 0), Perspective(0.8, 0.5, 50.0), 40, 30)
    stereo = StereoCamera(camera, 0.4, 3.0)
    scene = _square_scene(6.0)
    left, right = render(scene, stereo.left, shading="none"), render(scene, stereo.right, shading="none")
    frame = render_stereo(scene, stereo, shading="none")
    np.testing.assert_array_equal(frame.color, anaglyph(left.color, right.color))
    np.testing.assert_array_equal(frame.depth, np.minimum(left.depth, right.depth))
    gray = render_stereo(scene, stereo, anaglyph_method="gray", shading="none")
    np.testing.assert_array_equal(gray.color, anaglyph(left.color, right.color, "gray"))
    frame = render_stereo(scene, stereo, "over-under", shading="none")
    np.testing.assert_array_equal(frame.color, over_under(left.color, right.color))
    np.testing.assert_array_equal(frame.depth, np.concatenate([left.depth, right.depth]))
    frame = render_stereo(scene, stereo, "side-by-side", cross_eyed=True, shading="none")
    np.testing.assert_array_equal(frame.color, side_by_side(left.color, right.color, cross_eyed=True))
    np.testing.assert_array_equal(frame.depth, np.concatenate([right.depth, left.depth], axis=1))
    with_ids = render_stereo(scene, stereo, "over-under", shading="none", buffers=("object_id",))
    left_ids = render(scene, stereo.left, shading="none", buffers=("object_id",)).object_id
    right_ids = render(scene, stereo.right, shading="none", buffers=("object_id",)).object_id
    np.testing.assert_array_equal(with_ids.object_id, np.concatenate([left_ids, right_ids]))


# --- bad input -------------------------------------------------------------------------------------------

CAMERA = Camera.look_at((0, 0, 5), (0, 0, 0), (0, 1, 0), Perspective(1.0, 0.5, 50.0), 64, 48)


@pytest.mark.parametrize(
    ("separation", "message"),
    [
        (0.0, "eye_separation = 0.0 must be > 0"),
        (-0.1, r"eye_separation = -0.1 must be > 0"),
        (float("nan"), "eye_separation = nan is not finite"),
        (float("inf"), "eye_separation = inf is not finite"),
        ("wide", "eye_separation = 'wide' is not a number"),
    ],
)
def test_bad_eye_separation_raises_camera_error_naming_it(separation, message):
    with pytest.raises(CameraError, match=message):
        StereoCamera(CAMERA, separation, 4.0)


@pytest.mark.parametrize(
    ("distance", "message"),
    [
        (0.5, r"convergence_distance = 0.5 is not beyond near = 0.5"),
        (0.1, r"convergence_distance = 0.1 is not beyond near = 0.5"),
        (-3.0, r"convergence_distance = -3.0 is not beyond near = 0.5"),
        (float("inf"), "convergence_distance = inf is not finite"),
    ],
)
def test_bad_convergence_distance_raises_camera_error_naming_it(distance, message):
    with pytest.raises(CameraError, match=message):
        StereoCamera(CAMERA, 0.1, distance)


def test_non_perspective_cameras_raise_camera_error():
    orthographic = Camera.look_at((0, 0, 5), (0, 0, 0), (0, 1, 0), Orthographic(2.0, 0.5, 50.0))
    with pytest.raises(CameraError, match=r"camera.projection = Orthographic\(height=2.0.* is not a Perspective"):
        StereoCamera(orthographic, 0.1, 4.0)
    with pytest.raises(CameraError, match="camera = 'left' is not a Camera"):
        StereoCamera("left", 0.1, 4.0)


def test_bad_images_raise_output_error_naming_them():
    left, right = _images()
    with pytest.raises(OutputError, match=r"method = 'magenta' is unknown"):
        anaglyph(left, right, "magenta")
    with pytest.raises(OutputError, match=r"right has shape \(5, 5, 4\) but left has \(5, 6, 4\)"):
        side_by_side(left, right[:, :5])
    with pytest.raises(OutputError, match=r"left has dtype float64 and shape \(5, 6, 4\)"):
        over_under(left / 255.0, right)
    with pytest.raises(OutputError, match=r"right has dtype uint8 and shape \(5, 6, 3\)"):
        anaglyph(left, right[..., :3])
    stereo = StereoCamera(CAMERA, 0.1, 4.0)
    with pytest.raises(OutputError, match="layout = 'interlaced' is unknown"):
        render_stereo(Scene(), stereo, "interlaced")
    with pytest.raises(OutputError, match="anaglyph_method = 'green' is unknown"):
        render_stereo(Scene(), stereo, anaglyph_method="green")
    with pytest.raises(OutputError, match="stereo_camera = 'pair' is not a StereoCamera"):
        render_stereo(Scene(), "pair")
