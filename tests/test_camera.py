"""camera.py against PyGLM (lookAtRH, project, unProject), the seed's uvw frame, and viewing properties.

The frame is the seed's: n = N/|N| with N = eye − target, u = V×n/|V×n|, v = n×u (Hearn & Baker ch. 10);
its left-handed variant keeps u, v and turns z_view toward the scene (rows u, v, −n).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import assume, given
from hypothesis import strategies as st
from pyglm import glm

from frustum.camera import Camera, Ray, ViewFrame, look_at
from frustum.errors import CameraError
from frustum.projection import Axonometric, Frustum, Oblique, Orthographic, Perspective, perspective
from frustum.transforms import apply, compose, translate
from oracles import assert_close, glm_matrix, glm_vec
from strategies import vectors

PERSPECTIVE = Perspective(math.radians(60), 0.5, 50.0)


@st.composite
def frames(draw: st.DrawFn) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(eye, target, up) at least 0.5 apart, with up at least ~6° away from the line of sight."""
    eye, target, up = draw(vectors()), draw(vectors()), draw(vectors())
    sight = target - eye
    assume(np.linalg.norm(sight) > 0.5 and np.linalg.norm(up) > 0.1)
    assume(np.linalg.norm(np.cross(sight / np.linalg.norm(sight), up / np.linalg.norm(up))) > 0.1)
    return eye, target, up


@st.composite
def cameras(draw: st.DrawFn) -> Camera:
    """A camera on a sphere around a target, with a perspective or an orthographic projection."""
    target = draw(vectors())
    distance = draw(st.floats(2.0, 30.0))
    azimuth = draw(st.floats(-math.pi, math.pi))
    elevation = draw(st.floats(-1.4, 1.4))
    projection = draw(
        st.sampled_from([PERSPECTIVE, Orthographic(8.0, 0.5, 60.0), Frustum(-0.3, 0.5, -0.2, 0.4, 0.5, 60.0)])
    )
    width, height = draw(st.integers(1, 2000)), draw(st.integers(1, 2000))
    return Camera.orbit(target, distance, azimuth, elevation, projection, width, height)


# --- the uvw frame ----------------------------------------------------------------------------------------


@given(frames())
def test_look_at_matches_glm_look_at_rh(frame):
    eye, target, up = frame
    expected = glm_matrix(glm.lookAtRH(glm_vec(eye), glm_vec(target), glm_vec(up)))
    # float64 oracle (dvec3 arguments); translations are O(100), the helper scales 1e-12 by that.
    assert_close(look_at(eye, target, up), expected)
    assert_close(ViewFrame(eye, target=target, up=up).matrix, expected)


@given(frames())
def test_view_frame_is_orthonormal_right_handed_and_the_seeds_uvw(frame):
    eye, target, up = frame
    view = ViewFrame(eye, target=target, up=up)
    axes = np.array([view.u, view.v, view.n])
    # Unit vectors built by normalizing and crossing: orthonormal to a few ulps.
    assert_close(axes @ axes.T, np.eye(3))
    assert_close(np.cross(view.u, view.v), view.n)
    n = (eye - target) / np.linalg.norm(eye - target)
    u = np.cross(up, n) / np.linalg.norm(np.cross(up, n))
    assert_close(view.n, n)
    assert_close(view.u, u)
    assert_close(view.v, np.cross(n, u))
    assert_close(view.direction, -n)


@given(frames())
def test_eye_maps_to_origin_and_target_onto_negative_z(frame):
    eye, target, up = frame
    view_from_world = ViewFrame(eye, target=target, up=up).matrix
    distance = np.linalg.norm(target - eye)
    # Coordinates up to ~350 in size; assert_close scales 1e-12 by that.
    assert_close(apply(view_from_world, [eye, target]), [[0, 0, 0], [0, 0, -distance]])


@given(frames())
def test_view_frame_steps_translate_then_rotate(frame):
    eye, target, up = frame
    view = ViewFrame(eye, target=target, up=up)
    (translation, rotation) = view.steps
    assert_close(translation.matrix, translate(*-eye))
    assert_close(rotation.matrix[:3, :3], [view.u, view.v, view.n])
    assert_close(compose(translation.matrix, rotation.matrix), view.matrix)
    assert_close(view.world_from_view @ view.matrix, np.eye(4))


def test_view_frame_from_normal_equals_frame_from_target():
    eye, target = np.array([3.0, 1.0, 2.0]), np.array([-1.0, 0.5, 0.0])
    from_normal = ViewFrame(eye, normal=2.5 * (eye - target), up=(0, 1, 0))
    assert_close(from_normal.matrix, ViewFrame(eye, target=target).matrix)


def test_view_frame_takes_eye_target_up_positionally_like_look_at():
    eye, target, up = (3.0, 1.0, 2.0), (-1.0, 0.5, 0.0), (0.2, 1.0, 0.1)
    frame = ViewFrame(eye, target, up)
    assert_close(frame.matrix, look_at(eye, target, up))
    assert_close(frame.matrix, Camera.look_at(eye, target, up, PERSPECTIVE, 320, 200).view_matrix)
    assert_close(frame.up, up) and frame.normal is None
    # normal is keyword-only: a fourth positional argument is refused by Python itself
    with pytest.raises(TypeError, match=r"positional"):
        ViewFrame(eye, target, up, (0.0, 0.0, 1.0))  # type: ignore[misc]


def test_left_handed_frame_points_z_view_along_the_line_of_sight():
    eye, target = np.array([1.0, 2.0, 5.0]), np.array([0.0, 0.0, 0.0])
    right = ViewFrame(eye, target=target)
    left = ViewFrame(eye, target=target, handedness="left")
    assert_close(left.matrix, np.diag([1.0, 1.0, -1.0, 1.0]) @ right.matrix)
    assert np.linalg.det(left.matrix) == pytest.approx(-1.0, abs=1e-12)
    # The seed: increasing z_view is further from the eye along the line of sight.
    assert_close(apply(left.matrix, target), [0.0, 0.0, np.linalg.norm(eye)])
    # A camera converts back before projecting: the picture is the same.
    points = np.random.default_rng(3).uniform(-1, 1, (10, 3))
    cameras = [Camera(frame, PERSPECTIVE, 320, 200) for frame in (right, left)]
    assert_close(cameras[1].project(points), cameras[0].project(points))
    assert_close(compose(*(s.matrix for s in cameras[1].steps())), compose(*(s.matrix for s in cameras[0].steps())))


def test_view_frame_is_immutable():
    view = ViewFrame((0, 0, 5), target=(0, 0, 0))
    with pytest.raises(dataclasses.FrozenInstanceError):
        view.eye = np.zeros(3)  # type: ignore[misc]
    for array in (view.eye, view.u, view.v, view.n, view.matrix, view.up, view.target):
        with pytest.raises(ValueError, match="read-only"):
            array[0] = 1.0


# --- Camera: project, unproject, ray ----------------------------------------------------------------------


@given(frames(), st.floats(0.3, 2.5), st.integers(1, 2000), st.integers(1, 2000))
def test_camera_project_matches_glm_project(frame, fovy, width, height):
    eye, target, up = frame
    camera = Camera.look_at(eye, target, up, Perspective(fovy, 0.5, 500.0), width, height)
    points = target + np.random.default_rng(4).uniform(-1, 1, (6, 3))
    model = glm.lookAtRH(glm_vec(eye), glm_vec(target), glm_vec(up))
    projection = glm.dmat4(glm.perspectiveRH_NO(fovy, width / height, 0.5, 500.0))  # float32 entries
    # glm mirrors points behind the eye plane through the divide; frustum returns NaN rows for them (w <= 0):
    # compare only points in front of the eye, and check the NaN rows separately.
    w = np.c_[points, np.ones(len(points))] @ camera.clip_from_world[3]
    assert np.isnan(camera.project(points[w <= 0])).all()
    points = points[w > 0]
    if len(points) == 0:
        return
    expected = [np.array(glm.project(glm_vec(p), model, projection, glm.dvec4(0, 0, width, height))) for p in points]
    result = camera.project(points)
    # The float32 projection matrix limits the oracle: ~1e-7 relative of a window up to 2000 px → 1e-3 px;
    # depth near 1 with far/near = 1000 keeps ~1e-6 (ORACLES tolerance advice).
    np.testing.assert_allclose(result[:, :2], np.array(expected)[:, :2], atol=1e-3 * max(1, width, height) / 1000)
    np.testing.assert_allclose(result[:, 2], np.array(expected)[:, 2], atol=1e-5)
    # The same formula with frustum's own float64 matrices is exact to round-off.
    clip = np.c_[points, np.ones(len(points))] @ camera.clip_from_world.T
    ndc = clip[:, :3] / clip[:, 3:]
    window = np.column_stack([width * (ndc[:, 0] + 1) / 2, height * (ndc[:, 1] + 1) / 2, (ndc[:, 2] + 1) / 2])
    assert_close(result, window, 1e-9)


def test_camera_project_window_y_is_up_and_center_is_the_image_center():
    camera = Camera.look_at((0, 0, 10), (0, 0, 0), projection=PERSPECTIVE, width=400, height=300)
    center, above, right = camera.project([[0, 0, 0], [0, 1, 0], [1, 0, 0]])
    assert_close(center[:2], [200, 150])
    assert above[1] > center[1] and above[0] == pytest.approx(200)
    assert right[0] > center[0]


def test_camera_project_depth_is_zero_at_near_one_at_far_and_nan_behind_the_eye():
    camera = Camera.look_at((0, 0, 0), (0, 0, -1), projection=PERSPECTIVE, width=64, height=64)
    near, far, behind = camera.project([[0, 0, -0.5], [0, 0, -50], [0, 0, 3]])
    # The far plane's depth row cancels ~far/near ulps.
    assert near[2] == pytest.approx(0.0, abs=1e-12) and far[2] == pytest.approx(1.0, abs=1e-12)
    assert np.isnan(behind).all()
    assert camera.project([0, 0, -0.5]).shape == (3,)
    assert camera.project(np.empty((0, 3))).shape == (0, 3)


@given(cameras(), st.floats(0, 1), st.floats(0, 1), st.floats(0, 1))
def test_unproject_inverts_project(camera, s, t, depth):
    window = np.array([s * camera.width, t * camera.height, depth])
    world = camera.unproject(window)
    # Round trip through a matrix and its inverse; window values up to 2000 px, depth up to 1: the
    # perspective depth row is ill-conditioned by far/near = 120, hence 1e-7 relative to the window size.
    np.testing.assert_allclose(camera.project(world), window, atol=1e-7 * max(camera.width, camera.height))


@given(cameras())
def test_project_inverts_unproject_for_points_in_the_view_volume(camera):
    points = camera.unproject(np.random.default_rng(5).uniform(0, 1, (5, 3)) * [camera.width, camera.height, 1])
    # World coordinates are O(100): a few ulps times the conditioning of the projection (far/near = 120).
    np.testing.assert_allclose(camera.unproject(camera.project(points)), points, atol=1e-7)


def test_unproject_matches_glm_unproject():
    camera = Camera.look_at((1, 2, 6), (0, 0, 0), projection=Perspective(1.0, 1.0, 20.0), width=640, height=480)
    window = np.array([[100.5, 200.5, 0.3], [320.0, 240.0, 0.9], [639.5, 0.5, 0.0]])
    model = glm.mat4(glm.lookAtRH(glm.vec3(1, 2, 6), glm.vec3(0, 0, 0), glm.vec3(0, 1, 0)))
    projection = glm.perspectiveRH_NO(1.0, 640 / 480, 1.0, 20.0)
    expected = [np.array(glm.unProject(glm.vec3(*w), model, projection, glm.vec4(0, 0, 640, 480))) for w in window]
    # glm.unProject runs in float32: ~1e-3 relative (ORACLES tolerance advice).
    np.testing.assert_allclose(camera.unproject(window), expected, rtol=1e-3, atol=1e-3)


@given(cameras(), st.floats(0, 1), st.floats(0, 1))
def test_ray_through_a_pixel_projects_onto_that_pixel(camera, s, t):
    pixel = np.array([s * camera.width, t * camera.height])
    ray = camera.ray(pixel)
    assert isinstance(ray, Ray)
    assert np.linalg.norm(ray.direction) == pytest.approx(1.0, abs=1e-12)
    along = ray.origin + np.outer([0.0, 0.5, 2.0], ray.direction)
    # Window coordinates up to 2000 px after a projective round trip: 1e-7 relative.
    np.testing.assert_allclose(camera.project(along)[:, :2], [pixel] * 3, atol=1e-7 * max(camera.width, camera.height))
    if camera.projection.parallel:
        # Parallel projection: every ray runs along the line of sight.
        assert_close(ray.direction, camera.frame.direction, 1e-9)
    else:
        # Perspective: the ray's line passes through the eye.
        to_eye = camera.frame.eye - ray.origin
        assert np.linalg.norm(np.cross(to_eye, ray.direction)) < 1e-7 * max(1.0, float(np.linalg.norm(to_eye)))


def test_ray_accepts_many_pixels_and_center_pixel_looks_at_target():
    camera = Camera.look_at((0, 0, 5), (0, 0, 0), projection=PERSPECTIVE, width=4, height=2)
    rays = camera.ray([[2.0, 1.0], [0.5, 0.5]])
    assert rays.origin.shape == (2, 3) and rays.direction.shape == (2, 3)
    assert_close(rays.direction[0], [0.0, 0.0, -1.0])


def test_camera_steps_compose_to_window_from_world():
    camera = Camera.look_at((3, 2, 5), (0, 0, 0), projection=Oblique.cabinet(6, 1, 20), width=300, height=200)
    steps = camera.steps()
    assert [s.name.split()[0] for s in steps] == ["translate", "rotate", "oblique", "orthogonal", "viewport:"]
    assert_close(compose(*(s.matrix for s in steps)), camera.viewport_matrix @ camera.clip_from_world)
    assert_close(camera.clip_from_world, camera.projection_matrix @ camera.view_matrix)
    assert_close(camera.projection_matrix, camera.projection.matrix(1.5))


def test_camera_orbit_places_the_eye_on_the_sphere():
    camera = Camera.orbit((1, 2, 3), 10.0, math.radians(90), math.radians(30))
    expected_eye = np.array([1, 2, 3]) + 10 * np.array([math.cos(math.radians(30)), math.sin(math.radians(30)), 0])
    assert_close(camera.frame.eye, expected_eye)
    assert_close(camera.project([1, 2, 3])[:2], [320, 240])


@pytest.mark.parametrize(
    ("name", "right", "up"),
    [
        ("front", (1, 0, 0), (0, 1, 0)),
        ("rear", (-1, 0, 0), (0, 1, 0)),
        ("right", (0, 0, -1), (0, 1, 0)),
        ("left", (0, 0, 1), (0, 1, 0)),
        ("top", (1, 0, 0), (0, 0, -1)),
        ("bottom", (1, 0, 0), (0, 0, 1)),
    ],
)
def test_multiview_cameras_show_the_expected_axes(name, right, up):
    camera = Camera.multiview(name, Orthographic(4, 1, 20), width=100, height=100)
    center, to_right, to_up = camera.project([[0, 0, 0], right, up])
    assert_close(to_right - center, [25, 0, 0], 1e-9)  # 1 world unit = 100 px / 4 units
    assert_close(to_up - center, [0, 25, 0], 1e-9)


def test_axonometric_camera_keeps_the_target_centered_and_draws_axes_equally():
    camera = Camera.look_at((0, 0, 10), (0, 0, 0), projection=Axonometric.isometric(4, 1, 19), width=200, height=200)
    center, *ends = camera.project([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    assert_close(center[:2], [100, 100], 1e-9)
    lengths = [np.linalg.norm(end[:2] - center[:2]) for end in ends]
    assert_close(lengths, [50 * math.sqrt(2 / 3)] * 3, 1e-9)


# --- vanishing points -------------------------------------------------------------------------------------


def seed_one_point() -> Camera:
    """The seed's one-point figure: view plane parallel to xy, so only the z axis cuts it."""
    return Camera.look_at((0.5, 0.5, 5), (0.5, 0.5, 0), projection=PERSPECTIVE, width=640, height=480)


def seed_two_point() -> Camera:
    """The seed's two-point figure: view plane parallel to the y axis, cutting x and z."""
    return Camera.look_at((4, 0.5, 5), (0.5, 0.5, 0), projection=PERSPECTIVE, width=640, height=480)


def seed_three_point() -> Camera:
    """The seed's three-point figure: the view plane cuts all three axes."""
    return Camera.look_at((4, 3, 5), (0.5, 0.5, 0), projection=PERSPECTIVE, width=640, height=480)


@pytest.mark.parametrize(
    ("build", "count", "axes"),
    [(seed_one_point, 1, "z"), (seed_two_point, 2, "xz"), (seed_three_point, 3, "xyz")],
)
def test_principal_vanishing_points_count_the_seed_figures(build, count, axes):
    camera = build()
    result = camera.principal_vanishing_points()
    assert result.count == count
    for axis in "xyz":
        assert (getattr(result, axis) is not None) == (axis in axes)


def test_one_point_perspective_vanishes_at_the_center_of_projection():
    assert_close(seed_one_point().vanishing_point((0, 0, -1)), [320, 240])


@pytest.mark.parametrize("build", [seed_one_point, seed_two_point, seed_three_point])
def test_vanishing_point_matches_glm_oracle(build):
    camera = build()
    frame = camera.frame
    view = glm_matrix(glm.lookAtRH(glm_vec(frame.eye), glm_vec(frame.target), glm_vec(frame.up)))
    projection = glm_matrix(glm.perspectiveRH_NO(PERSPECTIVE.fovy, 640 / 480, 0.5, 50.0))
    for direction in np.eye(3):
        h = projection @ view @ [*direction, 0.0]
        if abs(h[3]) < 1e-9:
            assert camera.vanishing_point(direction) is None
            continue
        expected = [640 * (h[0] / h[3] + 1) / 2, 480 * (h[1] / h[3] + 1) / 2]
        # float32 projection entries: ~1e-7 relative of window values up to ~1e3 px.
        np.testing.assert_allclose(camera.vanishing_point(direction), expected, rtol=1e-5, atol=1e-3)


@given(cameras(), vectors(), vectors(), vectors())
def test_parallel_world_lines_meet_at_the_vanishing_point(camera, direction, p, q):
    assume(not camera.projection.parallel)
    assume(np.linalg.norm(direction) > 1.0)
    vp = camera.vanishing_point(direction)
    sight = camera.frame.direction @ (direction / np.linalg.norm(direction))
    assume(vp is not None and abs(sight) > 0.05)
    d = direction / np.linalg.norm(direction) * np.sign(sight)  # lines receding from the eye
    # Two parallel lines through the target's neighbourhood, both starting in front of the eye.
    start = camera.frame.eye + 3.0 * camera.frame.direction
    for offset in (p / 100.0, q / 100.0):
        a, b = camera.project([start + offset, start + offset + d])
        assume(np.isfinite(a).all() and np.isfinite(b).all())
        # The vanishing point lies on the projected line: 2-D cross product ~ 0 (relative to the lengths).
        ab, av = b[:2] - a[:2], vp - a[:2]
        cross = ab[0] * av[1] - ab[1] * av[0]
        assert abs(cross) <= 1e-6 * np.linalg.norm(ab) * max(1.0, np.linalg.norm(av))
        # ... and far along the line the projection approaches it.
        far_point = camera.project(start + offset + 1e7 * d)
        assert np.linalg.norm(far_point[:2] - vp) <= 1e-4 * max(1.0, np.linalg.norm(vp))


def test_parallel_projections_and_directions_in_the_view_plane_have_no_vanishing_point():
    ortho = Camera.look_at((4, 3, 5), (0, 0, 0), projection=Orthographic(4, 1, 20))
    assert ortho.vanishing_point((0, 0, 1)) is None
    assert ortho.principal_vanishing_points().count == 0
    assert seed_one_point().vanishing_point((1, 1, 0)) is None
    camera = seed_two_point()
    assert_close(camera.vanishing_point((1, 0, 0)), camera.vanishing_point((-2, 0, 0)))


# --- bad input --------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("build", "match"),
    [
        (lambda: look_at((0, 0, 5), (0, 0, 0), (0, 0, 1)), r"look_at: up = \(0\.0, 0\.0, 1\.0\) is parallel to the"),
        (lambda: look_at((1, 2, 3), (1, 2, 3)), r"look_at: target = \(1\.0, 2\.0, 3\.0\) equals eye"),
        (lambda: look_at((0, 0, 5), (0, 0, 0), (0, 0, 0)), r"look_at: up = \(0\.0, 0\.0, 0\.0\) has zero length"),
        (lambda: look_at((0, 0, float("inf")), (0, 0, 0)), r"look_at: eye = .* is not finite"),
        (lambda: ViewFrame((0, 0, 5), target=(0, 0, 0), up=(0, 0, -2)), r"ViewFrame: up = \(0\.0, 0\.0, -2\.0\) is"),
        (lambda: ViewFrame((0, 1, 0), target=(0, 0, 0)), r"ViewFrame: up = \(0\.0, 1\.0, 0\.0\) is parallel"),
        (lambda: ViewFrame((0, 0, 1)), r"ViewFrame: target = None and normal = None; give exactly one"),
        (lambda: ViewFrame((0, 0, 1), target=(0, 0, 0), normal=(0, 0, 1)), r"give exactly one"),
        (lambda: ViewFrame((0, 0, 1), normal=(0, 0, 0)), r"ViewFrame: normal = \(0\.0, 0\.0, 0\.0\) has zero length"),
        (lambda: ViewFrame((0, 0, 1), target=(0, 0, 0), handedness="up"), r"handedness = 'up' is unknown"),
        (lambda: Camera.look_at((0, 0, 5), (0, 0, 0), width=0), r"Camera: width = 0 is not a positive integer"),
        (lambda: Camera.look_at((0, 0, 5), (0, 0, 0), height=2.5), r"Camera: height = 2\.5 is not a positive"),
        (lambda: Camera.look_at((0, 0, 5), (0, 0, 0), projection=perspective(1, 1, 1, 2)), r"projection = .* is not"),
        (lambda: Camera("frame", PERSPECTIVE), r"Camera: frame = 'frame' is not a ViewFrame"),
        (
            lambda: Camera.orbit((0, 0, 0), 5, 0, math.pi / 2),
            r"Camera\.orbit: elevation = 1\.57\d* looks straight up or down",
        ),
        (lambda: Camera.orbit((0, 0, 0), 0, 0, 0), r"Camera\.orbit: distance = 0\.0 must be > 0"),
        (lambda: Camera.multiview("iso", Orthographic(1, 1, 2)), r"multiview: name = 'iso' is unknown"),
        (lambda: seed_one_point().vanishing_point((0, 0, 0)), r"vanishing_point: direction = .* has zero length"),
        (lambda: seed_one_point().unproject([[1, 2]]), r"Camera\.unproject: window has shape \(1, 2\)"),
        (lambda: seed_one_point().ray([1, float("nan")]), r"Camera\.ray: pixel\[0\] = \(1\.0, nan\) is not finite"),
        (lambda: seed_one_point().project([[1, 2]]), r"Camera\.project: points has shape \(1, 2\)"),
    ],
)
def test_bad_camera_input_raises_camera_error_naming_the_value(build, match):
    with pytest.raises(CameraError, match=match):
        build()
