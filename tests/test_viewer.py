"""The viewer's Python side: the camera-interaction model, the message protocol, picking, the widget and serve."""

from __future__ import annotations

import math
import socket
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from pyglm import glm

import frustum
from frustum import MULTIVIEWS, Camera, CameraError, FrustumError, Orthographic, Perspective
from frustum.viewer import KEYS, ORBIT_RADIANS_PER_PIXEL, ZOOM_PER_NOTCH, CameraControl, ViewerSession
from frustum.viewer.server import SceneSource, open_socket
from oracles import assert_close, glm_matrix, glm_vec

ROOT = Path(__file__).resolve().parents[1]
TEAPOT_FILE = ROOT / "examples" / "teapot.toml"


def control(**changes) -> CameraControl:
    values = dict(target=(0.0, 1.0, 0.0), distance=10.0, azimuth=0.3, elevation=0.2, width=800, height=600)
    values.update(changes)
    return CameraControl(**values)


@pytest.fixture(scope="module")
def teapot_session() -> ViewerSession:
    scene_file = frustum.load_scene_file(TEAPOT_FILE)
    camera = Camera(scene_file.camera.frame, scene_file.camera.projection, 160, 120)
    return ViewerSession(scene_file.scene, camera, scene_file.options, rest_samples=1)


# --- the interaction model ------------------------------------------------------------------------------------


def test_orbit_drag_changes_angles_by_the_documented_rate():
    c = control()
    assert c.begin_drag(100, 100)
    assert c.drag_to(150, 80)  # dx = 50, dy = -20 (y down)
    assert c.azimuth == pytest.approx(0.3 - 50 * ORBIT_RADIANS_PER_PIXEL, abs=1e-12)
    assert c.elevation == pytest.approx(0.2 - 20 * ORBIT_RADIANS_PER_PIXEL, abs=1e-12)
    assert c.drag_to(150, 80)  # no motion, no change
    assert c.azimuth == pytest.approx(-0.2, abs=1e-12)
    assert c.end_drag() and not c.dragging


def test_orbit_elevation_is_clamped_at_the_poles():
    c = control()
    c.begin_drag(0, 0)
    c.drag_to(0, 600)
    assert c.elevation == math.pi / 2
    # at the pole the view is the top view: looking down -y with up = -z rotated by the azimuth
    camera = c.camera()
    assert_close(-camera.frame.n, [0.0, -1.0, 0.0], 1e-12)


@given(st.floats(-3.0, 3.0), st.floats(-1.5, 1.5), st.floats(0.5, 50.0))
def test_control_camera_equals_camera_orbit(azimuth, elevation, distance):
    c = control(azimuth=azimuth, elevation=elevation, distance=distance)
    expected = Camera.orbit((0.0, 1.0, 0.0), distance, azimuth, elevation, width=800, height=600)
    # the two up vectors differ but span the same plane with the line of sight: the frames agree to rounding
    assert_close(c.camera().view_matrix, expected.view_matrix, 1e-9 * max(1.0, distance))


def test_wheel_zooms_by_the_documented_factor():
    c = control()
    assert c.wheel(-100)
    assert c.distance == pytest.approx(10.0 / ZOOM_PER_NOTCH, rel=1e-12)
    assert c.zoom == pytest.approx(ZOOM_PER_NOTCH, rel=1e-12)
    assert c.wheel(250)
    assert c.distance == pytest.approx(10.0 * ZOOM_PER_NOTCH**1.5, rel=1e-12)
    for _ in range(200):  # zoom stays within [1e-3, 1e3]
        c.wheel(-10_000)
    assert c.zoom == pytest.approx(1e3)


@pytest.mark.parametrize("projection", ["perspective", "orthographic", "cavalier"])
def test_pan_keeps_the_point_under_the_pointer(projection):
    c = control(projection=projection)
    before = c.camera().project(c.target)
    target = c.target.copy()
    c.begin_drag(400, 300, "pan")
    c.drag_to(430, 280)  # 30 right, 20 up (window y is up)
    after = c.camera().project(target)
    assert_close(after[:2] - before[:2], [30.0, 20.0], 1e-9)


@pytest.mark.parametrize("key", ["f", "t", "r"])
def test_preset_keys_match_the_multiview_cameras(key):
    c = control()
    assert c.key(key)
    name = KEYS[key]
    expected = Camera.multiview(name, Orthographic(1.0, 0.1, 100.0), c.target, c.distance, 800, 600)
    assert_close(c.camera().view_matrix, expected.view_matrix, 1e-12)
    assert c.projection == "orthographic"
    assert MULTIVIEWS[name].direction == pytest.approx(-c.camera().frame.n)


def test_isometric_key_looks_along_the_cube_diagonal_and_reset_restores():
    c = control(projection="perspective")
    home = c.camera().view_matrix.copy()
    assert c.key("i")
    assert_close(c.camera().frame.n, np.ones(3) / math.sqrt(3.0), 1e-12)
    assert c.key("0")
    assert_close(c.camera().view_matrix, home, 0.0)
    assert c.projection == "perspective"


def test_view_and_projection_match_glm():
    c = control(projection="perspective", fovy=0.9)
    camera = c.camera()
    expected_view = glm_matrix(glm.lookAtRH(glm_vec(c.eye), glm_vec(c.target), glm_vec(c.up)))
    assert_close(camera.view_matrix, expected_view, 1e-12)
    p = camera.projection
    expected_projection = glm_matrix(glm.perspectiveRH_NO(0.9, 800 / 600, p.near, p.far))
    assert_close(camera.projection_matrix, expected_projection, 1e-6)  # glm builds float32 entries


def test_from_camera_reproduces_a_y_up_camera():
    camera = Camera.look_at((5.0, 4.5, 7.0), (0.0, 1.2, 0.0), projection=Perspective(0.7, 0.1, 100.0))
    c = CameraControl.from_camera(camera, radius=2.0)
    assert_close(c.camera().view_matrix, camera.view_matrix, 1e-12)
    assert c.fovy == 0.7 and (c.width, c.height) == (640, 480)


def test_control_rejects_bad_construction():
    with pytest.raises(CameraError, match=r"distance = 0\.0 must be a finite number > 0"):
        control(distance=0.0)
    with pytest.raises(CameraError, match=r"projection = 'fisheye' is unknown; expected one of perspective"):
        control(projection="fisheye")
    with pytest.raises(CameraError, match=r"elevation = 2\.0 is outside"):
        control(elevation=2.0)
    with pytest.raises(CameraError, match=r"width = 0 is not a positive integer"):
        control(width=0)
    with pytest.raises(CameraError, match="is not a Camera"):
        CameraControl.from_camera("camera")


# --- the message protocol ---------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "message",
    [
        {"type": "pointer", "action": "down", "x": -1, "y": 10, "button": 0},
        {"type": "pointer", "action": "down", "x": 10, "y": 1e9, "button": 0},
        {"type": "pointer", "action": "down", "x": float("nan"), "y": 10, "button": 0},
        {"type": "pointer", "action": "down", "x": "10", "y": 10, "button": 0},
        {"type": "pointer", "action": "down", "x": 10, "y": 10, "button": 7},
        {"type": "pointer", "action": "down", "x": 10, "y": 10, "button": True},
        {"type": "pointer", "action": "move", "x": 10, "y": 10},  # no drag in progress
        {"type": "pointer", "action": "up"},
        {"type": "wheel", "delta": float("inf")},
        {"type": "wheel", "delta": 1e7},
        {"type": "wheel", "delta": True},
        {"type": "key", "key": "q"},
        {"type": "key", "key": 3},
        {"type": "control", "name": "projection", "value": "fisheye"},
        {"type": "control", "name": "depth_cue", "value": 1},
        {"type": "control", "name": "shading", "value": True},
        {"type": "control", "name": "samples", "value": 16},
        {"type": "control", "name": {}, "value": 1},  # unhashable name: ignored, not a TypeError (issue 38)
        {"type": "control", "name": ["mode"], "value": "wireframe"},
        {"type": {}, "key": []},
        {"type": "pick", "x": 160, "y": 5},
        {"type": "pick", "x": 5},
        {"type": "teleport"},
        ["pointer"],
        None,
    ],
)
def test_out_of_range_or_malformed_events_are_ignored(teapot_session, message):
    before = teapot_session.control.state()
    controls = dict(teapot_session.controls)
    assert teapot_session.handle(message) is None
    assert teapot_session.control.state() == before
    assert teapot_session.controls == controls
    assert teapot_session.replies([message]) == [({"type": "ignored"}, None)]


def test_drag_beyond_the_image_during_capture_is_followed_then_far_values_ignored():
    c = control()
    c.begin_drag(10, 10)
    assert c.drag_to(-100, 700)  # pointer capture: up to one image size outside
    assert not c.drag_to(-1000, 10)
    assert not c.drag_to(10, float("-inf"))


def test_replies_render_low_resolution_while_dragging_and_full_at_rest(teapot_session):
    s = teapot_session
    assert s.replies({"type": "pointer", "action": "down", "x": 80, "y": 60, "button": 0}) == []
    moves = [{"type": "pointer", "action": "move", "x": 80 + k, "y": 60, "seq": k} for k in (1, 2, 3)]
    ((header, data),) = s.replies(moves)  # coalesced: one frame for three moves, with the last seq
    state = header.pop("state")
    assert header == {"type": "frame", "width": 80, "height": 60, "quality": "interactive", "seq": 3}
    assert len(data) == 80 * 60 * 4
    assert state["camera"]["azimuth"] == pytest.approx(s.control.home["azimuth"] - 3 * ORBIT_RADIANS_PER_PIXEL)
    assert state == s.state()
    ((header, data),) = s.replies({"type": "pointer", "action": "up"})
    assert (header["width"], header["height"], header["quality"]) == (160, 120, "rest")
    assert len(data) == 160 * 120 * 4
    assert s.handle({"type": "reset"}) == "rest"


def test_state_matrices_equal_the_cameras(teapot_session):
    s = teapot_session
    s.handle({"type": "wheel", "delta": 120})
    s.handle({"type": "control", "name": "projection", "value": "cabinet"})
    state = s.state()
    camera = CameraControl.from_state(state["camera"]).camera()
    assert_close(np.array(state["matrices"]["view"]), camera.view_matrix, 0.0)
    assert_close(np.array(state["matrices"]["projection"]), camera.projection_matrix, 0.0)
    assert_close(np.array(state["matrices"]["viewport"]), camera.viewport_matrix, 0.0)
    assert_close(camera.view_matrix, s.control.camera().view_matrix, 0.0)
    assert state["controls"]["projection"] == "cabinet"
    s.handle({"type": "reset"})


@pytest.mark.parametrize(
    ("name", "value"),
    [
        ("shading", "flat"),
        ("mode", "hidden-line"),
        ("mode", "wireframe"),
        ("depth_cue", True),
        ("projection", "isometric"),
        ("shadows", True),
    ],
)
def test_controls_reach_the_render_options(teapot_session, name, value):
    s = teapot_session
    previous = s.controls[name]
    assert s.handle({"type": "control", "name": name, "value": value}) == "rest"
    options = s.render_options("rest")
    if name == "depth_cue":
        assert isinstance(options["depth_cue"], frustum.DepthCue)
    elif name == "projection":
        assert type(s.camera().projection).__name__ == "Axonometric"
    else:
        assert options[name] == value
    frame = s.render("interactive")
    assert frame.color.shape == (60, 80, 4)
    s.handle({"type": "control", "name": name, "value": previous})


# --- picking ------------------------------------------------------------------------------------------------


def test_pick_unprojects_the_depth_buffer_onto_the_surface_and_matches_trace(teapot_session):
    trimesh = pytest.importorskip("trimesh")
    s = teapot_session
    s.handle({"type": "reset"})
    result = s.pick(80.0, 60.0)
    assert result["hit"] and result["item"] == 0
    camera = s.control.camera()
    # the traced point lands on the pixel's center: window = (c + 0.5, H - r - 0.5, depth)
    assert_close(np.array(result["stages"][-1]["point"][:2]), [80.5, 120 - 60 - 0.5], 1e-6)
    # oracle: trimesh's closest point on the placed teapot mesh is within the depth buffer's float32 resolution
    item = s.scene.items[0]
    world_vertices = frustum.apply(item.world_from_model, item.mesh.vertices)
    mesh = trimesh.Trimesh(world_vertices, item.mesh.faces, process=False)
    _, distance, _ = trimesh.proximity.closest_point(mesh, [result["world"]])
    # depth in float32 (2^-24) magnified by the perspective divide at this distance: well under 1e-3 units
    assert distance[0] < 1e-3
    # the same numbers frustum.trace gives for the point in modeling coordinates
    model_point = frustum.apply(np.linalg.inv(item.world_from_model), np.array([result["world"]]))
    expected = frustum.trace(model_point, camera, model=item.world_from_model)
    for stage, entry in zip(expected.stages, result["stages"], strict=True):
        assert entry["name"] == stage.name
        assert_close(np.array(entry["point"]), stage.points[0], 1e-9)
        if stage.matrix is not None:
            assert_close(np.array(entry["matrix"]), stage.matrix, 0.0)
    clipping = result["stages"][STAGE_INDEX["clipping"]]
    assert clipping["code"] == 0 and clipping["regions"] == []


STAGE_INDEX = {name: k for k, name in enumerate(frustum.STAGE_NAMES)}


def test_picks_in_one_list_are_merged_the_latest_wins(teapot_session, monkeypatch):
    calls = []
    original = teapot_session.pick
    monkeypatch.setattr(teapot_session, "pick", lambda x, y: calls.append((x, y)) or original(x, y))
    replies = teapot_session.replies([{"type": "pick", "x": 10 + k, "y": 60} for k in range(50)])
    assert calls == [(59, 60)]
    assert [header["type"] for header, _ in replies] == ["pick"] and replies[0][0]["pixel"] == [59, 60]


def test_pick_on_background_is_a_miss(teapot_session):
    teapot_session.handle({"type": "reset"})
    result = teapot_session.replies({"type": "pick", "x": 1, "y": 1})[0][0]
    assert result["type"] == "pick" and not result["hit"] and "background" in result["label"]


# --- the widget, imports and serve's pieces ------------------------------------------------------------------------


def test_import_frustum_loads_no_viewer_stack():
    code = (
        "import sys, frustum; heavy = [m for m in ('anywidget', 'starlette', 'uvicorn', 'ipywidgets') "
        "if m in sys.modules]; print(heavy)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]"


def test_widget_answers_messages_and_falls_back_to_a_png(teapot_session):
    pytest.importorskip("anywidget")
    scene_file = frustum.load_scene_file(TEAPOT_FILE)
    viewer = frustum.Viewer(scene_file.scene, Camera(scene_file.camera.frame, scene_file.camera.projection, 64, 48))
    sent = []
    viewer.send = lambda content, buffers=None: sent.append((content, buffers))
    viewer._on_message(viewer, {"type": "hello"}, [])
    assert [content["type"] for content, _ in sent] == ["frame"]
    assert len(sent[0][1][0]) == 64 * 48 * 4
    assert sent[0][0]["state"]["camera"]["width"] == 64
    bundle = viewer._repr_mimebundle_()
    data = bundle[0] if isinstance(bundle, tuple) else bundle
    assert data["image/png"].startswith(b"\x89PNG")
    assert "application/vnd.jupyter.widget-view+json" in data
    assert "mountViewer" in viewer._esm


def test_viewer_rejects_a_non_scene():
    pytest.importorskip("anywidget")
    with pytest.raises(FrustumError, match=r"scene = .* is not a Scene"):
        frustum.Viewer("teapot.toml")
    with pytest.raises(FrustumError, match=r"camera = .* is not a Camera"):
        ViewerSession(frustum.Scene(), camera=42)
    with pytest.raises(FrustumError, match=r"rest_samples = 3 is not a square number of samples; expected 1, 4, 9"):
        ViewerSession(frustum.Scene(), rest_samples=3)


def test_scene_source_reports_file_line_errors_and_recovers(tmp_path):
    path = tmp_path / "scene.toml"
    source = SceneSource(path)
    assert source.check() and source.scene_file is None
    assert "scene.toml: cannot be read" in source.error
    good = TEAPOT_FILE.read_text()
    path.write_text(good.replace("fovy_deg = 40", 'fovy_deg = "wide"'))
    assert source.check()
    line = next(k for k, text in enumerate(path.read_text().splitlines(), 1) if "fovy_deg" in text)
    assert f"scene.toml:{line}: camera.fovy_deg" in source.error
    assert not source.check()  # unchanged file: nothing to do
    path.write_text(good + "\n")
    assert source.check() and source.error is None and source.scene_file is not None


def test_port_in_use_is_a_clear_error(capsys):
    taken = socket.socket()
    taken.bind(("127.0.0.1", 0))
    taken.listen(1)
    port = taken.getsockname()[1]
    try:
        with pytest.raises(FrustumError, match=rf"port = {port} on 127\.0\.0\.1 is already in use; choose another"):
            open_socket("127.0.0.1", port)
        from frustum.app.cli import main

        with pytest.raises(SystemExit) as exit_info:
            main(["serve", str(TEAPOT_FILE), "--port", str(port)])
        assert exit_info.value.code == 1
        assert "already in use" in capsys.readouterr().err
    finally:
        taken.close()
    with pytest.raises(FrustumError, match=r"port = 70000 is not a TCP port"):
        open_socket("127.0.0.1", 70000)


_NUMBERS = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True), st.integers(-(10**6), 10**6), st.text(max_size=3), st.none()
)
_EVENTS = st.one_of(
    st.fixed_dictionaries(
        {
            "type": st.just("pointer"),
            "action": st.sampled_from(["down", "move", "up", "sideways"]),
            "x": _NUMBERS,
            "y": _NUMBERS,
            "button": st.one_of(st.integers(-1, 3), st.booleans()),
            "shift": st.booleans(),
        }
    ),
    st.fixed_dictionaries({"type": st.just("wheel"), "delta": _NUMBERS}),
    st.fixed_dictionaries(
        {"type": st.just("key"), "key": st.one_of(st.sampled_from(sorted(KEYS)), st.text(max_size=2))}
    ),
    st.fixed_dictionaries(
        {
            "type": st.just("control"),
            "name": st.sampled_from(["projection", "shading", "mode", "depth_cue", "x"]),
            "value": st.one_of(
                st.sampled_from(["orthographic", "cabinet", "flat", "wireframe"]), st.booleans(), _NUMBERS
            ),
        }
    ),
)


@given(st.lists(_EVENTS, max_size=25))
def test_any_event_sequence_leaves_a_valid_camera(events):
    c = control()
    session = ViewerSession.__new__(ViewerSession)  # the protocol only, without a scene
    session.control, session.controls = c, {"projection": c.projection, "shading": "phong", "mode": "surface",
                                           "depth_cue": False}  # fmt: skip
    for event in events:
        assert session.handle(event) in (None, "", "interactive", "rest")
    camera = c.camera()
    assert np.isfinite(camera.view_matrix).all() and np.isfinite(camera.projection_matrix).all()
    assert abs(c.elevation) <= math.pi / 2 and 1e-3 <= c.zoom <= 1e3
    assert session.controls["projection"] == c.projection


def test_a_failing_render_is_reported_not_raised(teapot_session, monkeypatch):
    def refuse(*args, **kwargs):
        raise FrustumError("render: samples = 4 would need 9 GiB; raise the budget with frustum.budget(bytes=...)")

    monkeypatch.setattr(sys.modules["frustum.render"], "render", refuse)
    replies = teapot_session.replies([{"type": "rest"}, {"type": "pick", "x": 80, "y": 60}])
    assert [header["type"] for header, _ in replies] == ["error", "error"]
    assert "raise the budget" in replies[0][0]["message"]


def test_default_camera_frames_the_whole_scene():
    scene = frustum.Scene()
    scene.add(frustum.box((4.0, 1.0, 2.0)), transform=frustum.translate(10.0, -3.0, 5.0))
    session = ViewerSession(scene)
    camera = session.control.camera()
    assert (camera.width, camera.height) == (800, 600)
    corners = np.array([[x, y, z] for x in (8, 12) for y in (-3.5, -2.5) for z in (4, 6)], dtype=float)
    window = camera.project(corners)
    assert (window[:, 0] > 0).all() and (window[:, 0] < 800).all()
    assert (window[:, 1] > 0).all() and (window[:, 1] < 600).all()
    assert ((window[:, 2] > 0) & (window[:, 2] < 1)).all()  # between near and far


# --- the steps panel ------------------------------------------------------------------------------------------


def test_steps_camera_is_the_current_view_made_small(teapot_session):
    s = teapot_session
    s.handle({"type": "reset"})
    s.handle({"type": "wheel", "delta": -240})
    full, small = s.control.camera(), s.steps_camera()
    assert (small.width, small.height) == (64, 48)  # 160 x 120 at most STEPS_SIZE = 64 across
    assert_close(small.view_matrix, full.view_matrix, 0.0)
    assert_close(small.projection_matrix, full.projection_matrix, 1e-15)  # the same view volume (aspect 4:3)
    s.handle({"type": "reset"})


@pytest.mark.parametrize("algorithm", ["depth-buffer", "scan-line", "warnock", "a-buffer", "ray-casting"])
def test_steps_panel_records_the_method_on_the_current_view(teapot_session, algorithm):
    from frustum import steps
    from frustum.viewer.session import STEPS_METHODS

    s = teapot_session
    s.handle({"type": "reset"})
    drag = [
        {"type": "pointer", "action": "down", "x": 80, "y": 60, "button": 0},
        {"type": "pointer", "action": "move", "x": 110, "y": 70},
        {"type": "pointer", "action": "up"},
    ]
    s.replies(drag)
    assert algorithm in STEPS_METHODS and s.state()["steps"]["methods"] == list(STEPS_METHODS)
    ((answer, data),) = s.replies({"type": "steps", "algorithm": algorithm})  # no frame: the view did not change
    assert data is None and "error" not in answer
    assert answer["type"] == "steps" and answer["algorithm"] == algorithm and answer["size"] == [64, 48]
    assert answer["camera"] == s.control.state()
    function = {"depth-buffer": steps.depth_buffer, "scan-line": steps.scan_line, "warnock": steps.area_subdivision,
                "a-buffer": steps.a_buffer, "ray-casting": steps.ray_casting}[algorithm]  # fmt: skip
    options = {key: s.options[key] for key in ("background", "cull_back_faces") if key in s.options}
    expected = function(s.scene, s.steps_camera(), shading=s.controls["shading"], **options)
    assert answer["titles"] == [step.title for step in expected]
    assert answer["figures"] == [expected.figure(i) for i in range(len(expected))]
    # the last step shows the production picture of this view
    method = {"warnock": "area-subdivision"}.get(algorithm, algorithm)
    frame = frustum.render(s.scene, s.steps_camera(), method=method, shading=s.controls["shading"], **options)
    np.testing.assert_array_equal(expected.result.color, frame.color)
    # another view, another record
    s.handle({"type": "key", "key": "t"})
    again = s.steps(algorithm)
    assert again["camera"] != answer["camera"] and again["figures"] != answer["figures"]
    s.handle({"type": "reset"})


@pytest.mark.parametrize(
    "message",
    [
        {"type": "steps"},
        {"type": "steps", "algorithm": "bsp"},
        {"type": "steps", "algorithm": ["scan-line"]},
        {"type": "steps", "algorithm": "scan-line; rm -rf /"},
    ],
)
def test_steps_requests_for_other_methods_are_ignored(teapot_session, message):
    assert teapot_session.handle(message) is None
    assert teapot_session.replies([message]) == [({"type": "ignored"}, None)]


def test_steps_requests_merge_and_a_record_over_the_budget_is_reported(teapot_session):
    s = teapot_session
    recorded = []
    original = s.steps
    try:
        s.steps = lambda algorithm: recorded.append(algorithm) or original(algorithm)
        replies = s.replies([{"type": "steps", "algorithm": "scan-line"}, {"type": "rest"},
                             {"type": "steps", "algorithm": "warnock"}])  # fmt: skip
    finally:
        del s.steps
    assert recorded == ["warnock"] and [header["type"] for header, _ in replies] == ["steps", "frame"]
    with frustum.budget(bytes=100_000):  # the scan-line record of 48 rows at 64 x 48 needs more
        answer = s.steps("scan-line")
    assert "figures" not in answer and "steps.scan_line" in answer["error"] and "budget" in answer["error"]
