"""trace: every stage's matrix against PyGLM, agreement with Camera.project and the renderer, reports, bad input."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from pyglm import glm

from frustum import (
    Axonometric,
    Camera,
    FrustumError,
    GeometryError,
    Mesh,
    Oblique,
    Orthographic,
    Perspective,
    Scene,
    clip_line,
    region_code,
    render,
    rotate_y,
    translate,
)
from frustum.projection import CABINET_ALPHA, ISOMETRIC_ROTATION_X, Frustum
from frustum.scene import SceneItem
from frustum.shading import Material
from frustum.trace import STAGE_NAMES, Stage, Trace, _latex_escape, _placed_meshes, trace
from oracles import assert_close, glm_matrix, glm_vec

_TARGET_DISTANCE = float(np.linalg.norm(np.subtract((2.0, 3.0, 9.0), (0.2, -0.1, 0.3))))
# parallel projections turn (axonometric) or shear (oblique) about the camera's target, so the scene stays in view
PROJECTIONS = {
    "perspective": Perspective(math.radians(50), 0.5, 40.0),
    "frustum": Frustum(-0.3, 0.5, -0.2, 0.4, 0.5, 40.0),
    "orthographic": Orthographic(6.0, 0.5, 40.0),
    "oblique": Oblique(CABINET_ALPHA, math.pi / 4, 6.0, 0.5, 40.0, z_vp=-_TARGET_DISTANCE),
    "axonometric": Axonometric(math.pi / 4, ISOMETRIC_ROTATION_X, 6.0, 0.5, 40.0, pivot=_TARGET_DISTANCE),
}


def _camera(projection="perspective", handedness="right", width=80, height=60) -> Camera:
    return Camera.look_at((2.0, 3.0, 9.0), (0.2, -0.1, 0.3), (0.1, 1.0, 0.0), PROJECTIONS[projection], width, height,
                          handedness)  # fmt: skip


eyes = st.tuples(*[st.floats(-20, 20) for _ in range(3)]).map(np.array)


@st.composite
def look_ats(draw):
    eye = draw(eyes)
    target = draw(eyes)
    if np.linalg.norm(eye - target) < 0.5:
        target = eye + np.array([0.0, 0.0, -1.0])
    up = np.array([0.0, 1.0, 0.0])
    n = (eye - target) / np.linalg.norm(eye - target)
    if np.linalg.norm(np.cross(up, n)) < 0.05:
        up = np.array([1.0, 0.0, 0.0])
    return eye, target, up


# --- stage matrices against PyGLM ---------------------------------------------------------------------------


@settings(max_examples=40)
@given(look_ats())
def test_viewing_steps_match_glm_look_at(frame):
    eye, target, up = frame
    result = trace(target, Camera.look_at(eye, target, up))
    translate_step, rotate_step = result.stage("view_translate"), result.stage("view_rotate")
    assert_close(translate_step.matrix, glm_matrix(glm.translate(glm_vec(-eye))))
    assert_close(rotate_step.matrix @ translate_step.matrix, glm_matrix(glm.lookAtRH(*map(glm_vec, frame))))
    # the rotation step is a pure rotation: rows u, v, n, no translation
    assert_close(rotate_step.matrix[:3, :3] @ rotate_step.matrix[:3, :3].T, np.eye(3))
    assert_close(rotate_step.matrix[:3, 3], np.zeros(3))


@settings(max_examples=30)
@given(st.floats(0.2, 2.8), st.integers(1, 500), st.integers(1, 500), st.floats(0.01, 5.0), st.floats(6.0, 1000.0))
def test_perspective_stage_matches_glm_perspective_rh_no(fovy, width, height, near, far):
    camera = Camera.look_at((0, 0, 5), (0, 0, 0), projection=Perspective(fovy, near, far), width=width, height=height)
    result = trace([0.0, 0.0, 0.0], camera)
    expected = glm_matrix(glm.perspectiveRH_NO(fovy, width / height, near, far))
    # PyGLM projection builders are float32 (ORACLES trap 2): relative 1e-6
    np.testing.assert_allclose(result.stage("projection").matrix, expected, rtol=1e-6, atol=1e-6)
    assert result.stage("normalization").matrix is None  # perspective() normalizes in the same matrix


@settings(max_examples=30)
@given(st.floats(0.5, 50.0), st.integers(1, 500), st.integers(1, 500), st.floats(-5.0, 5.0), st.floats(6.0, 100.0))
def test_orthographic_normalization_matches_glm_ortho_rh_no(view_height, width, height, near, far):
    camera = Camera.look_at((0, 0, 5), (0, 0, 0), projection=Orthographic(view_height, near, far), width=width,
                            height=height)  # fmt: skip
    result = trace([0.0, 0.0, 0.0], camera)
    half_width = view_height * width / height / 2
    expected = glm_matrix(glm.orthoRH_NO(-half_width, half_width, -view_height / 2, view_height / 2, near, far))
    np.testing.assert_allclose(result.stage("normalization").matrix, expected, rtol=1e-6, atol=1e-6)
    assert result.stage("projection").matrix is None  # orthogonal projection: no matrix before normalization


@settings(max_examples=30)
@given(look_ats(), st.integers(1, 1000), st.integers(1, 1000))
@example((np.zeros(3), np.array([0.0, 0.5, 0.0]), np.array([1.0, 0.0, 0.0])), 1, 1)  # points once fell behind the eye
def test_viewport_window_matches_glm_project(frame, width, height):
    eye, target, up = frame
    camera = Camera.look_at(eye, target, up, Perspective(1.0, 0.5, 200.0), width, height)
    # points around the target and in front of the eye: offsets of at most half the eye-target distance (|offset|
    # <= scale * sqrt(3)), so every point's depth along the view direction is at least half that distance; behind
    # the eye trace gives NaN (clip w <= 0) while glm.project mirrors the point
    distance = float(np.linalg.norm(target - eye))
    scale = min(1.0, 0.5 * distance / np.sqrt(3))
    points = target + scale * np.random.default_rng(3).uniform(-1, 1, (5, 3))
    depths = (points - eye) @ ((target - eye) / distance)
    assert (depths >= 0.5 * distance - 1e-12).all()
    window = trace(points, camera).stage("viewport").points
    assert np.isfinite(window).all()
    model = glm.lookAtRH(*map(glm_vec, frame))
    projection = glm.dmat4(glm.perspectiveRH_NO(1.0, width / height, 0.5, 200.0))
    for point, result in zip(points, window, strict=True):
        expected = np.array(glm.project(glm_vec(point), model, projection, glm.dvec4(0, 0, width, height)))
        # float32 projection matrix in the oracle: ~1e-3 px per 1000 px, depth ~1e-5 (ORACLES)
        np.testing.assert_allclose(result[:2], expected[:2], atol=1e-3 * max(1, width, height) / 1000)
        np.testing.assert_allclose(result[2], expected[2], atol=1e-5)


@pytest.mark.parametrize("handedness", ["right", "left"])
@pytest.mark.parametrize("projection", sorted(PROJECTIONS))
def test_stage_matrices_compose_to_the_camera_matrices(projection, handedness):
    camera = _camera(projection, handedness)
    model = translate(0.5, -0.2, 0.1) @ rotate_y(0.3)
    result = trace(np.zeros((1, 3)), camera, model=model)
    assert tuple(stage.name for stage in result.stages) == STAGE_NAMES
    matrices = [result.stage(name).matrix for name in STAGE_NAMES[:6]]
    clip_from_model = np.linalg.multi_dot([m for m in reversed(matrices) if m is not None])
    assert_close(clip_from_model, camera.clip_from_world @ model)
    assert_close(result.stage("viewport").matrix, camera.viewport_matrix)
    if projection in ("oblique", "axonometric"):  # the seed's two steps: projection, then normalization
        names = [step.name for step in camera.projection.steps(camera.aspect)]
        assert names[0] in result.stage("projection").description
        assert names[1] in result.stage("normalization").description


# --- coordinates: each stage applies its matrix; agreement with Camera.project and render ----------------------


@pytest.mark.parametrize("projection", sorted(PROJECTIONS))
def test_each_stage_applies_its_matrix_to_the_previous_points(projection):
    camera = _camera(projection)
    points = np.random.default_rng(1).uniform(-2, 2, (7, 3))
    stages = trace(points, camera, model=translate(0.1, 0.2, 0.3)).stages
    assert_close(stages[0].points, np.column_stack([points, np.ones(7)]))
    for before, stage in itertools.pairwise(stages[:7]):
        expected = before.points if stage.matrix is None else before.points @ stage.matrix.T
        assert_close(stage.points, expected, 1e-12)
    clip = stages[6].points
    np.testing.assert_array_equal(stages[6].codes, region_code(clip))
    front = clip[:, 3] > 0
    assert_close(stages[7].points[front], clip[front, :3] / clip[front, 3:])


@settings(max_examples=40)
@given(look_ats(), st.sampled_from(sorted(PROJECTIONS)))
def test_window_equals_camera_project(frame, projection):
    camera = Camera.look_at(*frame, projection=PROJECTIONS[projection], width=320, height=200)
    points = frame[1] + np.random.default_rng(5).uniform(-3, 3, (8, 3))
    expected = camera.project(points)
    result = trace(points, camera).window
    np.testing.assert_array_equal(np.isnan(result), np.isnan(expected))
    finite = ~np.isnan(expected[:, 0])
    assert_close(result[finite], expected[finite], 1e-9)


def _lit_pixels(frame_color: np.ndarray) -> set[tuple[int, int]]:
    return {(int(r), int(c)) for r, c in zip(*np.nonzero(frame_color[:, :, 0] == 255), strict=True)}


@pytest.mark.parametrize("projection", sorted(PROJECTIONS))
def test_traced_window_positions_are_the_pixels_render_draws(projection):
    camera = _camera(projection, width=96, height=64)
    rng = np.random.default_rng(11)
    model = translate(0.2, 0.1, -0.3) @ rotate_y(0.7)
    vertices = rng.uniform(-1.5, 1.5, (40, 3))
    scene = Scene()
    scene.add(Mesh(vertices, np.empty((0, 3), dtype=np.int64)), Material(color=(1, 0, 0)), model)
    result = trace(scene, camera)
    window = result.window
    inside = result.stage("clipping").codes == 0
    # keep vertices clear of pixel edges: the renderer snaps window x, y to 1/256 pixel first
    fraction = window[:, :2] - np.floor(window[:, :2])
    clear = inside & np.all((fraction > 0.01) & (fraction < 0.99), axis=1)
    assert clear.sum() >= 20
    columns = np.floor(window[:, 0]).astype(int)
    rows = camera.height - 1 - np.floor(window[:, 1]).astype(int)
    keep = np.flatnonzero(clear)
    mesh = Mesh(vertices[keep], np.empty((0, 3), dtype=np.int64))
    kept = Scene()
    kept.add(mesh, Material(color=(1, 0, 0)), model)
    frame = render(kept, camera, mode="points")
    assert _lit_pixels(frame.color) == set(zip(rows[keep].tolist(), columns[keep].tolist(), strict=True))
    for i in keep:  # depth: the nearest vertex on each pixel, stored as float32
        on_pixel = keep[(rows[keep] == rows[i]) & (columns[keep] == columns[i])]
        assert frame.depth[rows[i], columns[i]] == pytest.approx(window[on_pixel, 2].min(), abs=1e-6)


def test_scene_trace_has_a_part_per_item_with_its_modeling_matrix():
    camera = _camera()
    triangle = Mesh([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])
    scene = Scene()
    group = scene.add(triangle, name="first")
    scene.add(Mesh(triangle.vertices, triangle.faces), transform=translate(0, 0, 1), parent=group)
    result = trace(scene, camera)
    assert len(result.parts) == 2
    assert_close(result.stage("world", part=1).matrix, translate(0, 0, 1))
    moved = triangle.vertices + np.array([0.0, 0.0, 1.0])
    assert_close(result.window, camera.project(np.vstack([triangle.vertices, moved])), 1e-9)
    assert result.parts[0].triangles.accepted.tolist() == [True]
    assert "item 0 (first)" in str(result)
    assert "item 1: 3 vertices" in str(result)


def test_placed_meshes_prefers_walk():
    triangle = Mesh([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])

    class Graph:
        items = ()

        def walk(self):
            yield SceneItem(triangle, Material(), translate(1, 2, 3))
            yield triangle, Material(), translate(0, 0, 1)

    placed = list(_placed_meshes(Graph()))
    assert [mesh for _, mesh, _ in placed] == [triangle, triangle]
    assert_close(placed[1][2], translate(0, 0, 1))
    result = trace(Graph(), _camera())
    assert_close(result.stage("world").points[:, :3], triangle.vertices + np.array([1.0, 2.0, 3.0]))


def test_triangle_clipping_accepts_rejects_and_clips():
    camera = Camera.look_at((0, 0, 5), (0, 0, 0), projection=Perspective(1.0, 1.0, 20.0), width=40, height=40)
    vertices = [
        [-0.2, 0, 0], [0.2, 0, 0], [0, 0.2, 0],  # wholly inside
        [-0.2, 0, 30], [0.2, 0, 30], [0, 0.2, 30],  # behind the eye: outside the near plane
        [-0.2, 0, 0], [50.0, 0, 0], [0, 0.2, 0],  # crossing the right plane
    ]  # fmt: skip
    mesh = Mesh(vertices, [[0, 1, 2], [3, 4, 5], [6, 7, 8]])
    triangles = trace(mesh, camera).parts[0].triangles
    assert triangles.accepted.tolist() == [True, False, False]
    assert triangles.rejected.tolist() == [False, True, False]
    assert triangles.clipped.tolist() == [False, False, True]
    assert triangles.pieces[0] == 1 and triangles.pieces[1] == 0 and triangles.pieces[2] >= 1
    assert "1 inside (trivially accepted), 1 outside (trivially rejected), 1 crossing a plane" in (triangles.summary())


def test_point_region_codes_name_the_planes():
    camera = Camera.look_at((0, 0, 5), (0, 0, 0), projection=Perspective(1.0, 1.0, 20.0), width=40, height=40)
    result = trace([[0, 0, 0], [100, 0, 0], [0, 0, -100]], camera)
    assert result.stage("clipping").codes.tolist() == [0, 2, 32]
    text = str(result)
    assert "code 000000  inside" in text
    assert "code 000010  outside: right" in text
    assert "code 100000  outside: far" in text


# --- reports ----------------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def report_trace() -> Trace:
    return trace([[0.1, 0.2, 0.3], [1.0, -1.0, 0.5]], _camera("oblique"))


def test_reports_contain_every_stage(report_trace):
    text, markdown, latex = str(report_trace), report_trace.to_markdown(), report_trace.to_latex()
    assert report_trace._repr_markdown_() == markdown
    for stage in report_trace.stages:
        assert stage.title in text
        assert f"### {STAGE_NAMES.index(stage.name) + 1}. {stage.title}" in markdown
        assert _latex_escape(stage.title) in latex
    assert text.count("column vectors, P' = M·P") == text.count("row vectors, P' = P·Mᵀ") == 6
    assert markdown.count("Row vectors") == 6
    assert latex.count(r"\begin{bmatrix}") == 12
    assert latex.count(r"\begin{tabular}") == 9


def test_reports_print_the_row_form_as_the_transpose(report_trace):
    stage = report_trace.stage("view_translate")
    assert_close(stage.row_matrix, stage.matrix.T)
    text = str(report_trace)
    # T(−eye) has its translation in the last column (column form) and the last row (row form)
    assert "[  1   0   0  -2 ]" in text and "[ -2  -3  -9   1 ]" in text
    latex = report_trace.to_latex()
    assert r"\begin{bmatrix} 1 & 0 & 0 & -2 \\ 0 & 1 & 0 & -3 \\ 0 & 0 & 1 & -9 \\ 0 & 0 & 0 & 1 \end{bmatrix}" in latex
    assert r"\begin{bmatrix} 1 & 0 & 0 & 0 \\ 0 & 1 & 0 & 0 \\ 0 & 0 & 1 & 0 \\ -2 & -3 & -9 & 1 \end{bmatrix}" in latex


def test_rich_renders_every_stage(report_trace):
    from rich.console import Console

    console = Console(width=200, record=True, file=open("/dev/null", "w"))  # noqa: SIM115
    console.print(report_trace)
    text = console.export_text()
    for stage in report_trace.stages:
        assert stage.title in text
    assert "Mᵀ (P' = P·Mᵀ)" in text


def test_long_point_lists_are_cut_in_reports():
    result = trace(np.random.default_rng(0).uniform(-1, 1, (30, 3)), _camera())
    assert "... 22 more" in str(result)
    assert result.stage("viewport").points.shape == (30, 3)


def test_stage_is_a_named_tuple_with_read_only_arrays():
    stage = trace([0.0, 0.0, 0.0], _camera()).stage("world")
    assert isinstance(stage, Stage)
    with pytest.raises(ValueError, match="read-only"):
        stage.points[0, 0] = 1.0
    with pytest.raises(ValueError, match="read-only"):
        stage.matrix[0, 0] = 2.0


# --- bad input --------------------------------------------------------------------------------------------------


def test_trace_rejects_bad_input():
    camera = _camera()
    with pytest.raises(FrustumError, match=r"trace: camera = 'camera' is not a Camera"):
        trace([0, 0, 0], "camera")
    with pytest.raises(GeometryError, match=r"trace: points\[1\] = \(nan, 0.0, 0.0\) is not finite"):
        trace([[0, 0, 0], [math.nan, 0, 0]], camera)
    with pytest.raises(GeometryError, match=r"trace: points has shape \(2, 2\)"):
        trace([[0, 0], [1, 1]], camera)
    with pytest.raises(FrustumError, match=r"trace: model bottom row = \(0.0, 0.0, 1.0, 1.0\) makes it projective"):
        trace([0, 0, 0], camera, model=[[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 1, 1]])
    with pytest.raises(FrustumError, match=r"trace: model has shape \(3, 3\)"):
        trace([0, 0, 0], camera, model=np.eye(3))
    with pytest.raises(FrustumError, match=r"trace: model = .* was given with a scene"):
        trace(Scene(), camera, model=np.eye(4))
    result = trace([0, 0, 0], camera)
    with pytest.raises(FrustumError, match=r"Trace.stage: name = 'screen' is unknown"):
        result.stage("screen")
    with pytest.raises(FrustumError, match=r"Trace.stage: part = 3 is not a part index"):
        result.stage("world", part=3)


def test_empty_inputs_trace_to_empty_stages():
    result = trace(np.empty((0, 3)), _camera())
    assert result.window.shape == (0, 3)
    assert "(no points)" in str(result)
    assert trace(Scene(), _camera()).window.shape == (0, 3)


def test_polyline_segments_are_clipped_like_clip_line():
    camera = Camera.look_at((0, 0, 5), (0, 0, 0), projection=Perspective(1.0, 1.0, 20.0), width=40, height=40)
    points = [[0, 0, 0], [0.2, 0.1, 0], [100, 0, 0], [100, 0, 1], [0, 0, 0.5]]
    result = trace(points, camera, polyline=True)
    segments = result.parts[0].segments
    assert segments.segments.tolist() == [[0, 1], [1, 2], [2, 3], [3, 4]]
    assert segments.accepted.tolist() == [True, False, False, False]
    assert segments.rejected.tolist() == [False, False, True, False]
    clip = result.stage("clipping").points
    for k, (i, j) in enumerate(segments.segments):
        expected = clip_line(clip[i], clip[j])
        if expected is None:
            assert not segments.visible[k]
        else:
            assert segments.parameters[k] == pytest.approx([expected.u_start, expected.u_end], abs=1e-12)
    text = str(result)
    assert "4 segments: 1 inside (trivially accepted), 1 outside (trivially rejected), 2 clipped" in text
    assert "segment p2-p3: outside: dropped" in text
    assert r"\item segment p0-p1: inside: kept whole" in result.to_latex()
    assert trace(points, camera).parts[0].segments is None


@pytest.mark.parametrize("projection", ["perspective", "oblique"])
def test_render_fills_the_pixels_whose_centers_lie_in_the_traced_triangle(projection):
    camera = _camera(projection, width=48, height=40)
    triangle = Mesh([[-1.8, -1.2, 0.4], [2.2, -0.6, -0.8], [0.2, 2.0, 0.6]], [[0, 1, 2]])
    scene = Scene()
    scene.add(triangle, Material(color=(1, 1, 1)))
    window = trace(scene, camera).window[:, :2]
    (ax, ay), (bx, by) = window[1] - window[0], window[2] - window[0]
    if ax * by - ay * bx < 0:  # clockwise in the window (seen from the back): the renderer draws both sides
        window = window[[0, 2, 1]]
    columns, rows = np.meshgrid(np.arange(camera.width), np.arange(camera.height))
    centers = np.stack([columns + 0.5, camera.height - 1 - rows + 0.5], axis=-1)
    # edge functions of the traced window triangle at every pixel center, scaled to pixel distances
    edges = []
    for a, b in ((0, 1), (1, 2), (2, 0)):
        direction = window[b] - window[a]
        offset = centers - window[a]
        edges.append((direction[0] * offset[..., 1] - direction[1] * offset[..., 0]) / np.linalg.norm(direction))
    distance = np.min(edges, axis=0)
    frame = render(scene, camera, shading="none", cull_back_faces=False)
    lit = frame.color[:, :, 0] == 255
    # the renderer snaps vertices to 1/256 pixel: centers within 0.01 px of an edge may go either way
    assert lit[distance > 0.01].all()
    assert not lit[distance < -0.01].any()
    assert (distance > 0.01).sum() > 100
