"""frustum.steps: each algorithm's record ends in the production result, worked examples give the notes' numbers,
figures are SVG, animations have one frame per step, pages and tables are written, bad input is refused."""

from __future__ import annotations

import math
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from PIL import Image

import frustum
from frustum import steps as fs
from frustum.clipping import VIEW_VOLUME_PLANES, clip_line, clip_polygon
from frustum.errors import FrustumError, OutputError
from frustum.geometry import curves
from frustum.steps._record import FIGURE_HEIGHT, FIGURE_WIDTH
from frustum.steps.catalog import ALGORITHMS, build

ROOT = Path(__file__).resolve().parents[1]

coordinate = st.floats(-4.0, 4.0, allow_nan=False, allow_infinity=False)
point3 = st.tuples(coordinate, coordinate, coordinate)
point4 = st.tuples(coordinate, coordinate, coordinate, st.floats(0.1, 3.0))


def _same_segment(a, b) -> bool:
    if a is None or b is None:
        return a is None and b is None
    return (np.array_equal(a.start, b.start) and np.array_equal(a.end, b.end) and a.u_start == b.u_start
            and a.u_end == b.u_end)  # fmt: skip


# --- clipping ---------------------------------------------------------------------------------------------


@settings(max_examples=150, deadline=None)
@given(point4, point4)
def test_cohen_sutherland_steps_end_in_clip_lines_result(p0, p1):
    recorded = fs.cohen_sutherland(p0, p1)
    assert _same_segment(recorded.result, clip_line(p0, p1, method="cohen-sutherland"))
    assert recorded[-1].title in ("Trivially accepted", "Trivially rejected", "Rejected: parallel to a plane it is "
                                  "outside of")  # fmt: skip


@settings(max_examples=150, deadline=None)
@given(point4, point4)
def test_liang_barsky_twin_equals_the_kernel_bit_for_bit(p0, p1):
    recorded = fs.liang_barsky(p0, p1)
    assert _same_segment(recorded.result, clip_line(p0, p1))  # the compiled kernel
    from frustum.clipping.lines import _liang_barsky
    from frustum.raster.clip import clip_segment

    start, end = np.array(p0, float), np.array(p1, float)
    assert _liang_barsky(start, end, VIEW_VOLUME_PLANES, lambda *a, **k: None) == clip_segment(
        start, end, VIEW_VOLUME_PLANES
    )


@settings(max_examples=100, deadline=None)
@given(st.lists(point4, min_size=3, max_size=7))
def test_sutherland_hodgman_steps_end_in_clip_polygon_result(polygon):
    recorded = fs.sutherland_hodgman(polygon)
    expected = clip_polygon(polygon)
    assert np.array_equal(recorded.result.vertices, expected.vertices)
    last_plane = [s for s in recorded if s.title.startswith("After the")]
    assert len(last_plane) <= 6
    assert recorded[-1].values["vertices"] == len(expected.vertices)


def test_cohen_sutherland_worked_example_codes_and_intersections():
    recorded = fs.cohen_sutherland((-2.0, 0.5, 0.0), (2.0, 0.3, -3.0))
    for step in recorded:
        print(step.title, dict(step.values))
    first = recorded[0].values
    assert (first["code P1"], first["code P2"]) == ("000001", "010010")  # left; near and right
    moves = [s for s in recorded if s.title.startswith("Move")]
    assert [m.values["plane"] for m in moves] == ["left", "right", "near"]
    np.testing.assert_allclose(moves[0].values["new P1"], (-1.0, 0.45, -0.75, 1.0))
    np.testing.assert_allclose(moves[1].values["new P2"], (1.0, 0.35, -2.25, 1.0))
    np.testing.assert_allclose(moves[2].values["new P2"], (-2 / 3, 0.5 - 0.2 / 3, -1.0, 1.0))
    assert recorded[-1].title == "Trivially accepted"
    assert (recorded.result.u_start, recorded.result.u_end) == (0.25, pytest.approx(1 / 3))


def test_cohen_sutherland_trivial_reject_names_the_common_bit():
    recorded = fs.cohen_sutherland((-3.0, 0.0, 0.0), (-2.0, 0.5, 0.2))
    assert len(recorded) == 2 and recorded.result is None
    assert recorded[-1].values["c1 & c2"] == "000001"


def test_liang_barsky_worked_example_u1_u2_table():
    recorded = fs.liang_barsky((-2.0, 0.5, 0.0), (2.0, 0.3, -3.0))
    rows = [s.values for s in recorded if "boundary" in s.values]
    print("k  boundary  p_k  q_k  u1  u2")
    for row in rows:
        print(row["k"], row["boundary"], row["p_k"], row["q_k"], row["u1"], row["u2"])
    table = [(r["boundary"], r["p_k"], r["q_k"], r["u1"], r["u2"]) for r in rows]
    expected = [
        ("left", -4.0, -1.0, 0.25, 1.0),
        ("right", 4.0, 3.0, 0.25, 0.75),
        ("bottom", 0.2, 1.5, 0.25, 0.75),
        ("top", -0.2, 0.5, 0.25, 0.75),
        ("near", 3.0, 1.0, 0.25, 1 / 3),
        ("far", -3.0, 1.0, 0.25, 1 / 3),
    ]
    for got, want in zip(table, expected, strict=True):
        assert got[0] == want[0]
        np.testing.assert_allclose(got[1:], want[1:], rtol=1e-12)


def test_sutherland_hodgman_shows_the_polygon_after_each_plane():
    recorded = fs.sutherland_hodgman([(-1.5, -0.5, 0.0), (1.5, -0.2, 0.3), (0.2, 1.6, -0.2)])
    after = [s.values["vertices after"] for s in recorded if s.title.startswith("After the")]
    assert after == [4, 5, 5, 6, 6, 6]  # left, right, bottom, top, near, far


# --- modeling and viewing ------------------------------------------------------------------------------------


@settings(max_examples=60, deadline=None)
@given(point3, st.floats(-6.0, 6.0), point3)
def test_rotation_steps_compose_to_rotate(axis, angle, point):
    if np.linalg.norm(axis) < 1e-3:
        return
    recorded = fs.rotation_about_axis(axis, angle, point)
    matrices = [s.matrix for s in frustum.rotate_steps(axis, angle, point)]
    assert np.array_equal(recorded.result, frustum.compose(*matrices))
    np.testing.assert_allclose(recorded.result, frustum.rotate(axis, angle, point), atol=1e-9)
    assert len(recorded) == 9  # the object, the seven matrices, the composite


def test_viewing_pipeline_ends_in_the_window_coordinates_of_trace():
    recorded = fs.viewing_pipeline()
    camera = fs.viewing.default_camera()
    points = fs.modeling.HOUSE_POINTS
    assert np.array_equal(recorded.result, frustum.trace(points, camera).window)
    np.testing.assert_allclose(recorded.result, camera.project(points), atol=1e-9)
    assert [s.title.split(" ")[0] for s in recorded][:2] == ["Modeling", "World"]
    assert len(recorded) == len(frustum.STAGE_NAMES)


@settings(max_examples=40, deadline=None)
@given(st.lists(point3, min_size=3, max_size=8), st.integers(0, 2**31))
def test_back_faces_steps_equal_backface_mask(vertices, seed):
    rng = np.random.default_rng(seed)
    faces = rng.integers(0, len(vertices), size=(5, 3))
    camera = fs.viewing.default_camera()
    recorded = fs.back_faces(vertices, faces, camera)
    assert np.array_equal(recorded.result, frustum.backface_mask(vertices, faces, camera))
    assert [s.values["back"] for s in recorded[1:-1]] == recorded.result.tolist()


# --- curves ------------------------------------------------------------------------------------------------


control_polygons = st.lists(st.tuples(coordinate, coordinate), min_size=2, max_size=7)


@settings(max_examples=100, deadline=None)
@given(control_polygons, st.floats(0.0, 1.0))
def test_de_casteljau_steps_end_in_evaluate_and_split(points, t):
    recorded = fs.de_casteljau(points, t)
    curve = frustum.BezierCurve(points)
    point, (left, right) = recorded.result
    assert np.array_equal(point, curve.evaluate(t))
    halves = curve.split(t)
    assert np.array_equal(left, halves[0].control_points) and np.array_equal(right, halves[1].control_points)
    assert len(recorded) == len(points) + 1  # polygon, n levels, subdivision


def test_de_casteljau_worked_example_at_one_half():
    recorded = fs.de_casteljau([(0, 0), (1, 2), (3, 2), (4, 0)], 0.5)
    for step in recorded:
        print(step.title, dict(step.values))
    np.testing.assert_array_equal(recorded[1].values["P^1"], [(0.5, 1.0), (2.0, 2.0), (3.5, 1.0)])
    np.testing.assert_array_equal(recorded[2].values["P^2"], [(1.25, 1.5), (2.75, 1.5)])
    np.testing.assert_array_equal(recorded[3].values["P^3"], [(2.0, 1.5)])


@settings(max_examples=40, deadline=None)
@given(st.lists(st.floats(0.0, 5.0), min_size=4, max_size=9), st.integers(1, 3))
def test_b_spline_basis_steps_equal_cox_de_boor(knots, order):
    knots = sorted(knots)
    if len(knots) <= order or knots[-1] == knots[0]:
        return
    recorded = fs.b_spline_basis(knots, order, samples=33)
    grid = np.linspace(knots[0], knots[-1], 33)
    expected = np.array([frustum.cox_de_boor(knots, i, order, grid) for i in range(len(knots) - order)])
    assert np.array_equal(recorded.result, expected)
    assert len(recorded) == order + 1


def test_b_spline_knot_span_shows_order_functions_non_zero():
    recorded = fs.b_spline_basis([0, 0, 0, 1, 2, 3, 3, 3], 3, u=1.5)
    assert recorded[0].values["knot span s"] == 3
    assert recorded[-1].values["non-zero on the span"] == ["N1,3", "N2,3", "N3,3"]


def test_hermite_steps_end_in_the_curve_point():
    recorded = fs.hermite((0, 0), (3, 0), (3, 3), (3, -3), t=0.3)
    curve = frustum.HermiteCurve((0, 0), (3, 0), (3, 3), (3, -3))
    assert np.array_equal(recorded.result, curve.evaluate(0.3))
    weights = recorded[-1].values["weights"]
    np.testing.assert_allclose(weights, curves.hermite_blending(0.3))
    np.testing.assert_allclose(weights @ np.array([(0, 0), (3, 0), (3, 3), (3, -3)], float), recorded.result)


# --- fractals ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize("level", [0, 1, 4])
def test_koch_steps_end_in_koch_curve(level):
    recorded = fs.koch(level)
    assert np.array_equal(recorded.result, frustum.koch_curve(level))
    assert len(recorded) == level + 1


@settings(max_examples=20, deadline=None)
@given(st.integers(0, 6), st.integers(0, 1000), st.floats(0.1, 0.9))
def test_midpoint_displacement_steps_end_in_fractal_coastline(level, seed, hurst):
    line = [(0.0, 0.0, 0.0), (1.0, 0.2, 0.0), (2.0, 0.0, 0.0)]
    recorded = fs.midpoint_displacement(line, level, seed=seed, hurst=hurst)
    assert np.array_equal(recorded.result, frustum.fractal_coastline(line, level, seed=seed, hurst=hurst))
    assert len(recorded) == level + 1


def test_box_counting_steps_show_each_size_and_the_fit():
    recorded = fs.box_counting()
    expected = frustum.box_counting_dimension(frustum.koch_curve(6)[:, :2])
    assert recorded.result.dimension == expected.dimension
    assert len(recorded) == len(expected.sizes) + 2
    assert recorded[-1].values["D"] == pytest.approx(math.log(4) / math.log(3), abs=0.05)


def test_recording_over_the_memory_budget_is_refused_with_the_estimate():
    with frustum.budget(bytes="1M"), pytest.raises(OutputError, match=r"level = 8 needs about .* over the memory"):
        fs.koch(8)
    with pytest.raises(OutputError, match=r"GiB, over the memory budget"):
        fs.koch(14)  # default budget: about 19 GiB of polylines and figures


# --- pictures ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", sorted(ALGORITHMS))
def test_every_figure_is_svg_and_the_table_has_a_row_per_step(name):
    recorded = build(name, {})
    for i in range(len(recorded)):
        root = ET.fromstring(recorded.figure(i))
        assert root.tag == "{http://www.w3.org/2000/svg}svg"
    ET.fromstring(recorded.sheet())
    table = recorded.to_markdown().splitlines()
    assert len([line for line in table if line.startswith("| ") and line[2].isdigit()]) == len(recorded)


def test_animation_has_one_frame_per_step(tmp_path):
    recorded = fs.cohen_sutherland((-2.0, 0.5, 0.0), (2.0, 0.3, -3.0))
    path = tmp_path / "cs.gif"
    recorded.save(path, fps=2)
    with Image.open(path) as image:
        assert image.n_frames == len(recorded)
        assert image.size == (FIGURE_WIDTH, FIGURE_HEIGHT)


def test_save_writes_numbered_svgs_html_and_markdown(tmp_path):
    recorded = fs.de_casteljau([(0, 0), (1, 2), (3, 2), (4, 0)])
    paths = recorded.save(tmp_path / "dc.svg", sheet=False)
    assert [p.name for p in paths] == [f"dc-{i:02d}.svg" for i in range(1, len(recorded) + 1)]
    for path in paths:
        ET.parse(path)
    (page,) = recorded.save(tmp_path / "dc.html")
    text = page.read_text()
    assert text.count('class="frustum-step"') == len(recorded) and 'type="range"' in text
    (table,) = recorded.save(tmp_path / "dc.md")
    assert "Level 3: 1 point" in table.read_text()
    assert 'type="range"' in recorded._repr_html_()


def test_bad_input_is_refused_with_a_clear_message(tmp_path):
    recorded = fs.koch(1)
    with pytest.raises(OutputError, match=r"i = 7 is not a step index"):
        recorded.figure(7)
    with pytest.raises(OutputError, match=r"suffix '.png'.*'.gif'"):
        recorded.save(tmp_path / "koch.png")
    with pytest.raises(FrustumError, match=r"algorithm = 'zbuffer' is unknown; expected one of rotation, "):
        build("zbuffer", {})
    with pytest.raises(FrustumError, match=r"--from = '1,2' is not 3 or 4"):
        build("cohen-sutherland", {"from": "1,2"})
    with pytest.raises(frustum.GeometryError, match=r"t = 1.5 lies outside"):
        fs.de_casteljau([(0, 0), (1, 1)], 1.5)


def test_cli_lists_writes_and_refuses_unknown_names(tmp_path):
    env = {"PYTHONPATH": str(ROOT / "src")}
    run = [sys.executable, "-m", "frustum", "steps"]
    listed = subprocess.run([*run, "--list"], capture_output=True, text=True, env=env, check=True)
    assert all(name in listed.stdout for name in ALGORITHMS)
    out = tmp_path / "cs.svg"
    subprocess.run([*run, "cohen-sutherland", "--from", "-2,0.5,0", "--to", "2,0.3,-3", "-o", str(out)], env=env,
                   check=True, capture_output=True)  # fmt: skip
    ET.parse(out)
    unknown = subprocess.run([*run, "zbuffer", "-o", str(tmp_path / "w.gif")], capture_output=True, text=True, env=env)
    assert unknown.returncode == 1
    assert len(unknown.stderr.strip().splitlines()) == 1 and "expected one of rotation" in unknown.stderr
    refused = subprocess.run([*run, "koch", "--level", "14", "-o", str(tmp_path / "k.gif")], capture_output=True,
                             text=True, env=env)  # fmt: skip
    assert refused.returncode == 1 and "needs about" in refused.stderr


def test_recording_hooks_change_no_result():
    # the hooks are inert when off: the production functions return what they returned with a recorder
    segment = ((-2.0, 0.5, 0.0, 1.0), (2.0, 0.3, -3.0, 1.0))
    calls = []
    recorded = clip_line(*segment, method="cohen-sutherland", record=lambda *a, **k: calls.append(a))
    assert _same_segment(clip_line(*segment, method="cohen-sutherland"), recorded)
    assert calls


def test_html_slider_works_in_chromium(tmp_path):
    import shutil

    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    if chromium is None:
        pytest.skip("chromium is not installed (.ci/run installs Debian's chromium package)")
    playwright_sync = pytest.importorskip("playwright.sync_api")
    recorded = fs.liang_barsky((-2.0, 0.5, 0.0), (2.0, 0.3, -3.0))
    (page_path,) = recorded.save(tmp_path / "lb.html")
    with playwright_sync.sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=chromium, headless=True,
                                             args=["--headless", "--no-sandbox", "--disable-gpu"])  # fmt: skip
        try:
            page = browser.new_page()
            page.goto(page_path.as_uri())

            def shown() -> list[int]:
                return page.evaluate("""() => Array.from(document.querySelectorAll('.frustum-step'))
                    .filter(d => getComputedStyle(d).display !== 'none').map(d => Number(d.dataset.step))""")

            assert shown() == [0]
            page.fill(".slider", "3")  # a range input: fill sets the value and fires input
            assert shown() == [3]
            assert page.inner_text(".counter") == f"4 / {len(recorded)}"
            page.click(".next")
            assert shown() == [4]
            page.click(".prev")
            page.click(".prev")
            assert shown() == [2]
            title = page.evaluate("document.querySelector('.frustum-step[data-step=\"2\"] svg title').textContent")
            assert recorded[2].title in title
        finally:
            browser.close()


# --- visible surfaces --------------------------------------------------------------------------------------


triangle_soups = st.lists(st.tuples(point3, point3, point3), min_size=1, max_size=6)


@settings(max_examples=40, deadline=None)
@given(triangle_soups, point3)
def test_bsp_steps_end_in_the_trees_back_to_front_order(soup, eye):
    polygons = np.array(soup, dtype=float)
    areas = np.linalg.norm(np.cross(polygons[:, 1] - polygons[:, 0], polygons[:, 2] - polygons[:, 0]), axis=1)
    if (areas < 1e-3).any():
        return
    eye = np.add(eye, np.array([0.0, 0.0, 9.0]))
    recorded = fs.bsp_tree(polygons, eye)
    expected = frustum.BSPTree(polygons).back_to_front_indices(eye=eye)
    assert np.array_equal(recorded.result, expected)
    painted = [s.values["painted so far"] for s in recorded if "painted so far" in s.values]
    assert painted[-1] == expected.tolist()


def test_bsp_worked_example_splits_a_crossing_wall():
    recorded = fs.bsp_tree()
    nodes = [s for s in recorded if s.title.startswith("Node")]
    assert sum(s.values["splits"] for s in nodes) == frustum.BSPTree(fs.visible_surfaces.default_walls()).split_count
    assert sum(s.values["splits"] for s in nodes) == 2


def test_depth_buffer_steps_end_in_the_render_byte_for_byte():
    scene, camera = fs.visible_surfaces.default_scene()
    recorded = fs.depth_buffer(scene, camera)
    frame = frustum.render(scene, camera)
    assert np.array_equal(recorded.result.color, frame.color)
    assert np.array_equal(recorded.result.depth, frame.depth)
    assert len(recorded) == len(scene.root.children) + 1
    written = [s.values["pixels written"] for s in recorded[1:]]
    assert all(n > 0 for n in written)


def test_depth_buffer_recording_of_a_4k_image_is_refused_with_the_estimate():
    scene, camera = fs.visible_surfaces.default_scene()
    big = frustum.Camera(camera.frame, camera.projection, 3840, 2160)
    with frustum.budget(bytes="256M"), pytest.raises(OutputError, match=r"3 surfaces at 3840x2160 needs about 474"):
        fs.depth_buffer(scene, big)


def test_area_subdivision_steps_end_in_the_render_and_log_every_area():
    scene, camera = fs.visible_surfaces.default_scene()
    recorded = fs.area_subdivision(scene, camera)
    frame = frustum.render(scene, camera, method="area-subdivision")
    counts = frame.stats
    assert np.array_equal(recorded.result.color, frame.color)
    assert np.array_equal(recorded.result.depth, frame.depth)
    per_level = [sum(v for k, v in s.values.items() if not k.startswith("single,")) for s in recorded[1:-1]]
    assert per_level == counts["areas_per_level"]
    for step, level in zip(recorded[1:-1], range(len(per_level)), strict=True):
        assert step.title.startswith(f"Level {level}:")
    assert recorded[1].values == {"subdivided": 1}  # the whole image is never decided at once here


def test_warnock_recording_of_a_4k_image_is_refused_with_the_estimate(tmp_path):
    scene, camera = fs.visible_surfaces.default_scene()
    big = frustum.Camera(camera.frame, camera.projection, 3840, 2160)
    with pytest.raises(OutputError, match=r"recording at 3840x2160 .* needs about .* GiB, over the memory budget"):
        fs.area_subdivision(scene, big)


def test_cli_warnock_of_a_scene_file(tmp_path):
    env = {"PYTHONPATH": str(ROOT / "src")}
    out = tmp_path / "warnock.gif"
    scene_file = ROOT / "examples" / "teapot.toml"
    done = subprocess.run([sys.executable, "-m", "frustum", "steps", "warnock", str(scene_file), "--size", "64x48",
                           "-o", str(out)], env=env, capture_output=True, text=True)  # fmt: skip
    assert done.returncode == 0, done.stderr
    with Image.open(out) as image:
        frames = image.n_frames
    assert f"{frames} steps" in done.stdout
    command = [sys.executable, "-m", "frustum", "steps", "warnock", str(scene_file), "--size", "3840x2160", "-o",
               str(tmp_path / "w4k.gif")]  # fmt: skip
    refused = subprocess.run(command, env=env, capture_output=True, text=True)
    assert refused.returncode == 1 and "needs about" in refused.stderr and "3840x2160" in refused.stderr


def test_scan_line_steps_end_in_the_render_and_spans_cover_the_drawn_pixels():
    scene, camera = fs.visible_surfaces.default_scene()
    recorded = fs.scan_line(scene, camera)
    frame = frustum.render(scene, camera, method="scan-line")
    assert np.array_equal(recorded.result.color, frame.color)
    assert np.array_equal(recorded.result.depth, frame.depth)
    drawn_rows = {camera.height - 1 - r for r in np.flatnonzero((np.asarray(frame.depth) < 1.0).any(axis=1))}
    rows = {int(s.title.split("y = ")[1].split(":")[0]) for s in recorded if s.title.startswith("Scan line")}
    assert drawn_rows <= rows
    for step in recorded:
        if step.title.startswith("Scan line"):
            j = int(step.title.split("y = ")[1].split(":")[0])
            covered = np.zeros(camera.width, bool)
            for text in step.values["spans"]:
                x0, x1 = (int(v) for v in text[1 : text.index("]")].split(", "))
                covered[x0 : x1 + 1] = True
            row = np.asarray(frame.depth)[camera.height - 1 - j] < 1.0
            assert not (row & ~covered).any()  # every drawn pixel of the row lies in a recorded span


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 10_000))
def test_depth_sort_steps_end_in_the_production_order(seed):
    rng = np.random.default_rng(seed)
    soup = rng.uniform(-0.8, 0.8, (6, 1, 3)) + rng.uniform(-0.6, 0.6, (6, 3, 3))
    camera = fs.visible_surfaces.default_depth_sort_scene()[1]
    recorded = fs.depth_sort(soup, camera)
    expected = frustum.depth_sort(list(soup), camera)
    assert len(recorded.result.fragments) == len(expected.fragments)
    for (a, label_a), (b, label_b) in zip(recorded.result.fragments, expected.fragments, strict=True):
        assert label_a == label_b and np.array_equal(a, b)
    paints = [s for s in recorded if s.title.startswith(("Paint", "Unresolved"))]
    assert len(paints) == len(expected.fragments)


def test_depth_sort_worked_example_splits_the_cycle():
    recorded = fs.depth_sort()
    titles = [s.title for s in recorded]
    assert titles[0] == "Sorted by greatest depth"
    assert sum(t.startswith("Split") for t in titles) == recorded.result.split_count == 1
    assert sum(t.startswith("Paint") for t in titles) == 4  # three triangles, one cut in two


def test_a_buffer_steps_show_the_pixels_fragments_and_end_in_the_render():
    scene, camera = fs.visible_surfaces.default_transparent_scene()
    recorded = fs.a_buffer(scene, camera)
    frame = frustum.render(scene, camera, method="a-buffer")
    assert np.array_equal(recorded.result.color, frame.color)
    count = recorded[0].values["fragments"]
    assert count == frame.stats["max_fragments"]  # the default pixel is the one with the most fragments
    assert len(recorded) == count + 2
    x, y = (int(v) for v in recorded[0].title.split("(")[1].split(")")[0].split(", "))
    assert np.array_equal(recorded[-1].values["color (RGBA bytes)"], frame.color[camera.height - 1 - y, x])
    for step in recorded[1:-1]:
        assert step.values["covered"] == step.values["mask (rows top to bottom)"].count("1")
    with pytest.raises(OutputError, match=r"pixel = \(64, 0\) lies outside the 64x48 image"):
        fs.a_buffer(scene, camera, pixel=(64, 0))


@pytest.mark.parametrize("pixel", [(32, 24), (5, 5), (20, 30), (40, 22)])
def test_ray_casting_steps_follow_one_ray_and_end_in_the_render(pixel):
    from frustum.raster import rays

    scene, camera = fs.visible_surfaces.default_scene()
    recorded = fs.ray_casting(scene, camera, pixel=pixel)
    frame = frustum.render(scene, camera, method="ray-casting")
    assert np.array_equal(recorded.result.color, frame.color)
    assert np.array_equal(recorded.result.depth, frame.depth)
    # the traced Python twin returns what the compiled kernel returns for this ray
    _items, index, _starts = scene._triangle_index()
    ray = fs.visible_surfaces.rays._pixel_ray(camera, *pixel)
    twin, events = fs.visible_surfaces.traced_closest(index, np.empty(0, np.uint8), ray, 1)
    stack, entry = np.empty(index.depth + 2, dtype=np.int64), np.empty(index.depth + 2)
    compiled = rays._closest(index.boxes, index.links, index.triangles, index.order, np.empty(0, np.uint8), *ray,
                             0.0, 1.0, 1, stack, entry)  # fmt: skip
    assert tuple(twin) == tuple(compiled)
    assert sum(e[0] == "test" for e in events) == compiled[7]  # its triangle tests, counted by the kernel
    assert sum(e[0] in ("node", "leaf") for e in events) == compiled[6]  # its nodes visited
    x, y = pixel
    hit = frame.depth[camera.height - 1 - y, x] < 1.0
    assert (compiled[1] >= 0) == hit
    if hit:  # the window depth of the traced hit is the frame's
        t = twin[0]
        point = np.array(ray[:3]) + t * np.array(ray[3:])
        w = np.asarray(camera.viewport_matrix @ camera.clip_from_world)
        z = np.float32((w[2, :3] @ point + w[2, 3]) / (w[3, :3] @ point + w[3, 3]))
        assert z == frame.depth[camera.height - 1 - y, x]
    distances = [s.values["t"] for s in recorded if s.title.startswith("Nearest hit")]
    assert distances == sorted(distances, reverse=True)


def test_octree_steps_show_levels_then_the_traversal_and_end_in_the_render():
    from frustum.visibility.octree import render_octree

    tree, camera = fs.visible_surfaces.default_octree()
    recorded = fs.octree(tree, camera)
    frame = render_octree(tree, camera)
    assert np.array_equal(recorded.result.color, frame.color)
    assert np.array_equal(recorded.result.depth, frame.depth)
    levels = [s for s in recorded if s.title.startswith("Subdivision")]
    assert [s.values["full cells"] for s in levels] == [len(codes) for codes in tree.full]
    visits = [s for s in recorded if s.title.startswith("Visit")]
    assert visits[0].title.startswith("Visit 1: level 0")  # the root first
    assert sum(s.values["pixels written"] for s in visits) == np.count_nonzero(frame.depth < 1.0)


def test_mp4_has_one_frame_per_step(tmp_path):
    pytest.importorskip("imageio_ffmpeg")
    import imageio

    recorded = fs.koch(3)
    (path,) = recorded.save(tmp_path / "koch.mp4", fps=2)
    reader = imageio.get_reader(path)
    try:
        assert sum(1 for _ in reader) == len(recorded)
    finally:
        reader.close()
