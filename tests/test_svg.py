"""SVG drawings (``frustum.output.svg``): valid XML, exact coordinates, styles, fills against the raster renderer.

Oracles: ``xml.etree`` parses every document; cairosvg rasterizes it and the picture is compared with
``frustum.render`` (coverage of the silhouette, and which object is seen where for the back-to-front fill);
the ``bezier`` library evaluates 3D Bézier curves for the exact-projection check of ``svg_path_from_bezier``.
"""

from __future__ import annotations

import io
import math
import re
import xml.etree.ElementTree as ET

import bezier
import cairosvg
import numpy as np
import pytest
import trimesh
from PIL import Image

from frustum import (
    Axonometric,
    Camera,
    FrustumError,
    Material,
    Oblique,
    Orthographic,
    OutputError,
    Perspective,
    Scene,
    ViewFrame,
    render,
    translate,
)
from frustum.geometry import Mesh, Polyline
from frustum.output.svg import _placed_meshes, render_svg, save_svg, svg_path_from_bezier, svg_path_from_polyline
from frustum.visibility.hidden_lines import remove_hidden_lines

SVG = "{http://www.w3.org/2000/svg}"
NUMBER = re.compile(r"-?\d+(?:\.\d+)?(?:e-?\d+)?")


def _box(extents, center=(0.0, 0.0, 0.0)) -> Mesh:
    box = trimesh.creation.box(extents=extents)
    return Mesh(np.asarray(box.vertices) + np.asarray(center, dtype=float), box.faces)


def _part_scene() -> Scene:
    scene = Scene()
    scene.add(_box((4.0, 0.5, 2.0)), Material(color=(0.8, 0.2, 0.2)), translate(0, -0.25, 0))
    scene.add(_box((0.5, 2.5, 2.0)), Material(color=(0.2, 0.7, 0.2)), translate(-1.75, 1.25, 0))
    sphere = trimesh.creation.icosphere(subdivisions=2, radius=0.6)
    scene.add(Mesh(sphere.vertices, sphere.faces), Material(color=(0.2, 0.3, 0.9)), translate(1.0, 0.6, 0.2))
    return scene


def _camera(width=320, height=240, projection=None) -> Camera:
    projection = Perspective(0.8, 0.5, 30) if projection is None else projection
    return Camera.look_at((4.0, 3.5, 6.0), (0, 0.6, 0), (0, 1, 0), projection, width, height)


def _segments(path_d: str) -> np.ndarray:
    """(K, 2, 2) from path data made of ``M x y L x y`` pairs."""
    assert re.fullmatch(r"(M\S+ \S+ L\S+ \S+ ?)+", path_d + " "), path_d[:80]
    numbers = np.array([float(v) for v in NUMBER.findall(path_d)])
    return numbers.reshape(-1, 2, 2)


def _group(root: ET.Element, name: str) -> ET.Element | None:
    return next((g for g in root.iter(f"{SVG}g") if g.get("id") == name), None)


def _rasterize(svg_text: str) -> np.ndarray:
    return np.array(Image.open(io.BytesIO(cairosvg.svg2png(bytestring=svg_text.encode()))).convert("RGBA"))


# --- document and exact coordinates ------------------------------------------------------------------------


def test_render_svg_is_valid_xml_with_the_camera_size():
    text = render_svg(_part_scene(), _camera())
    root = ET.fromstring(text.encode())
    assert root.tag == f"{SVG}svg"
    assert (root.get("width"), root.get("height"), root.get("viewBox")) == ("320", "240", "0 0 320 240")
    assert text == render_svg(_part_scene(), _camera())  # same input, same bytes


@pytest.mark.parametrize(
    "projection",
    [Perspective(0.8, 0.5, 30), Orthographic(6, 0.5, 30), Oblique.cabinet(6, 0.5, 30), Axonometric.isometric(6, 1, 19)],
    ids=["perspective", "orthographic", "cabinet", "isometric"],
)
def test_visible_and_hidden_paths_are_the_hidden_line_pieces_with_y_flipped(projection):
    scene, camera = _part_scene(), _camera(projection=projection)
    lines = remove_hidden_lines([(i.mesh, i.world_from_model) for i in scene.items], camera)
    root = ET.fromstring(render_svg(scene, camera).encode())
    for name, pieces in (("visible", lines.visible), ("hidden", lines.hidden)):
        drawn = _segments(_group(root, name).find(f"{SVG}path").get("d"))
        expected = np.stack([pieces[..., 0], 240 - pieces[..., 1]], axis=-1)
        # numbers are written as repr(float): they read back bit for bit
        assert np.array_equal(drawn, expected)


def test_hidden_styles_dashed_dimmed_or_left_out():
    scene, camera = _part_scene(), _camera()
    dashed = _group(ET.fromstring(render_svg(scene, camera, hidden="dashed").encode()), "hidden")
    assert dashed.get("stroke-dasharray") is not None and dashed.get("stroke") == "#000000"
    dimmed = _group(ET.fromstring(render_svg(scene, camera, hidden="dimmed").encode()), "hidden")
    assert dimmed.get("stroke-dasharray") is None and dimmed.get("stroke") == "#9a9a9a"
    assert _group(ET.fromstring(render_svg(scene, camera, hidden=None).encode()), "hidden") is None
    visible = _group(ET.fromstring(render_svg(scene, camera, stroke_width=2.5).encode()), "visible")
    assert visible.get("stroke-width") == "2.5"


def test_depth_cue_fades_and_thins_distant_lines():
    scene, camera = _part_scene(), _camera()
    lines = remove_hidden_lines([(i.mesh, i.world_from_model) for i in scene.items], camera)
    root = ET.fromstring(render_svg(scene, camera, depth_cue=True, stroke_width=2.0).encode())
    paths = list(_group(root, "visible").iter(f"{SVG}path"))
    assert len(paths) == lines.visible.shape[0]
    depth = lines.visible_depth.mean(axis=1)
    gray = np.array([int(p.get("stroke")[1:3], 16) for p in paths])
    width = np.array([float(p.get("stroke-width")) for p in paths])
    order = np.argsort(depth)
    assert gray[order[0]] == 0 and width[order[0]] == 2.0  # nearest: black, full width
    assert gray[order[-1]] == round(255 * 0.75) and width[order[-1]] == pytest.approx(0.8)
    assert np.all(np.diff(gray[order]) >= 0) and np.all(np.diff(width[order]) <= 1e-12)


# --- against the raster renderer ---------------------------------------------------------------------------


def test_filled_drawing_covers_the_renderers_silhouette():
    scene, camera = _part_scene(), _camera()
    text = render_svg(scene, camera, fill=True, hidden=None, background=None, stroke_width=0.5)
    drawn = _rasterize(text)[..., 3] > 127
    frame = render(scene, camera, shading="none", background=(0, 0, 0, 0))
    covered = frame.color[..., 3] > 0
    # the renderer samples pixel centres, cairosvg anti-aliases areas and the polygons carry a 0.5 px seam
    # stroke: they may differ only in a one-pixel band along the outline, and there in at most 4 % of the area
    band = np.zeros_like(covered)
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            band |= np.roll(np.roll(covered, dy, 0), dx, 1) != covered
    differ = drawn != covered
    assert not (differ & ~band).any()
    assert differ.sum() <= 0.04 * covered.sum()


def test_line_drawing_traces_the_renderers_outline():
    scene, camera = _part_scene(), _camera()
    ink = _rasterize(render_svg(scene, camera, hidden=None, background=None))[..., 3] > 127
    covered = render(scene, camera, shading="none", background=(0, 0, 0, 0)).color[..., 3] > 0

    def grow(mask, steps):
        for _ in range(steps):
            mask = mask | np.roll(mask, 1, 0) | np.roll(mask, -1, 0) | np.roll(mask, 1, 1) | np.roll(mask, -1, 1)
        return mask

    outline = covered & ~(np.roll(covered, 1, 0) & np.roll(covered, -1, 0) & np.roll(covered, 1, 1)
                          & np.roll(covered, -1, 1))  # fmt: skip
    # every line lies on the parts (within 2 px of anti-aliasing) and the parts' outline is drawn (within 2 px)
    assert not (ink & ~grow(covered, 2)).any()
    assert (outline & grow(ink, 2)).sum() >= 0.99 * outline.sum()


def _cyclic_sticks() -> Scene:
    """Three sticks, each above the next at one crossing and below the previous at the other: no order exists."""
    corners = [np.array([math.cos(a), math.sin(a)]) for a in np.radians([90, 210, 330])]
    scene = Scene()
    for k, color in enumerate([(1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)]):
        start, end = corners[k], corners[(k + 1) % 3]
        along = (end - start) / np.linalg.norm(end - start)
        across = np.array([-along[1], along[0]]) * 0.15
        a, b = start - 0.5 * along, end + 0.5 * along  # low end (z = −0.5) at `start`, high end at `end`
        quad = np.array([[*(a - across), -0.5], [*(b - across), 0.5], [*(b + across), 0.5], [*(a + across), -0.5]])
        scene.add(Mesh(quad, [[0, 1, 2], [0, 2, 3]]), Material(color=color))
    return scene


def _seen_object(rgba: np.ndarray) -> np.ndarray:
    """0, 1, 2 for red, green, blue dominating; −1 where nothing is drawn."""
    return np.where(rgba[..., 3] > 127, np.argmax(rgba[..., :3], axis=-1), -1)


def test_fill_order_of_the_bsp_tree_matches_the_depth_buffer_on_cyclic_overlaps():
    scene = _cyclic_sticks()
    camera = Camera.look_at((0.3, 0.2, 10), (0, 0, 0), (0, 1, 0), Orthographic(4, 1, 20), 200, 200)
    truth = _seen_object(np.asarray(render(scene, camera, shading="none", background=(0, 0, 0, 0)).color))
    # compare away from outlines: pixels whose 5x5 neighbourhood shows one object in the raster picture
    steady = truth >= 0
    for dy in range(-2, 3):
        for dx in range(-2, 3):
            steady &= np.roll(np.roll(truth, dy, 0), dx, 1) == truth
    assert steady.sum() > 2000 and len(np.unique(truth[steady])) == 3
    agreement = {}
    for order in ("bsp", "depth"):
        text = render_svg(scene, camera, fill=True, fill_order=order, hidden=None, edges="boundary", background=None)
        assert f'data-order="{order}"' in text
        agreement[order] = float((_seen_object(_rasterize(text))[steady] == truth[steady]).mean())
    assert agreement["bsp"] >= 0.999
    assert agreement["depth"] < 0.98  # a whole-face painter's order is wrong somewhere in a cycle


# --- curves --------------------------------------------------------------------------------------------------


def _path_numbers(path_d: str) -> np.ndarray:
    return np.array([float(v) for v in NUMBER.findall(path_d)]).reshape(-1, 2)


def _cubic(points: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Bernstein form of the SVG ``C`` command, evaluated at t."""
    p0, p1, p2, p3 = points
    s = 1 - t[:, None]
    return s**3 * p0 + 3 * s**2 * t[:, None] * p1 + 3 * s * t[:, None] ** 2 * p2 + t[:, None] ** 3 * p3


@pytest.mark.parametrize(
    "projection",
    [Orthographic(8, 1, 40), Oblique.cavalier(8, 1, 40), Axonometric.isometric(8, 1, 40)],
    ids=["orthographic", "cavalier", "isometric"],
)
def test_bezier_path_is_exact_under_a_parallel_projection(projection):
    controls = np.array([[-2.0, -1.0, 0.5], [-1.0, 2.5, -1.0], [1.5, -2.0, 2.0], [2.5, 1.0, -0.5]])
    camera = Camera(ViewFrame((1, 2, 12), target=(0, 0, 0), up=(0, 1, 0)), projection, 400, 300)
    path = svg_path_from_bezier(camera.project(controls)[:, :2], height=300)
    assert path.startswith("M") and " C" in path
    t = np.linspace(0, 1, 41)
    curve = bezier.Curve(controls.T, degree=3).evaluate_multi(t).T  # the oracle evaluates the 3D curve
    expected = camera.project(curve)[:, :2] * [1, -1] + [0, 300]
    np.testing.assert_allclose(_cubic(_path_numbers(path), t), expected, atol=1e-9)


def test_bezier_path_is_not_the_projected_curve_under_perspective():
    # the reason the helper is for parallel projections only: perspective is not affine
    controls = np.array([[-2.0, -1.0, 0.5], [-1.0, 2.5, -3.0], [1.5, -2.0, 2.0], [2.5, 1.0, -0.5]])
    camera = Camera.look_at((1, 2, 8), (0, 0, 0), (0, 1, 0), Perspective(1.0, 0.5, 40), 400, 300)
    t = np.linspace(0, 1, 41)
    path = svg_path_from_bezier(camera.project(controls)[:, :2], height=300)
    curve = bezier.Curve(controls.T, degree=3).evaluate_multi(t).T
    expected = camera.project(curve)[:, :2] * [1, -1] + [0, 300]
    assert np.abs(_cubic(_path_numbers(path), t) - expected).max() > 1.0


def test_bezier_and_polyline_paths_of_every_degree():
    assert svg_path_from_bezier([[0, 0], [1, 2]]) == "M0 0 L1 2"
    assert svg_path_from_bezier([[0, 0], [1, 2], [3, 0.5]]) == "M0 0 Q1 2 3 0.5"
    assert svg_path_from_bezier([[0, 0], [1, 2], [3, 0.5], [4, 4]], height=10) == "M0 10 C1 8 3 9.5 4 6"
    composite = svg_path_from_bezier(np.arange(14.0).reshape(7, 2))
    assert composite == "M0 1 C2 3 4 5 6 7 C8 9 10 11 12 13"
    assert svg_path_from_polyline([[0, 0, 0.5], [1, 2, 0.5], [3, 1, 0.5]], 10, closed=True) == "M0 10 L1 8 L3 9 Z"
    with pytest.raises(OutputError, match=r"control_points_window has 5 points"):
        svg_path_from_bezier(np.zeros((5, 2)))
    with pytest.raises(OutputError, match=r"has shape \(4, 4\)"):
        svg_path_from_bezier(np.zeros((4, 4)))
    with pytest.raises(OutputError, match=r"is not finite"):
        svg_path_from_polyline([[0, 0], [np.nan, 1]], 10)


def test_polylines_are_drawn_in_their_color_and_hidden_by_faces():
    scene = _part_scene()
    t = np.linspace(0, 1, 33)
    curve = bezier.Curve(np.array([[-3.0, 0.3, 2.0], [-1.0, 3.0, -2.0], [1.0, -1.0, -2.0], [3.0, 2.0, 2.0]]).T, 3)
    scene.add(Polyline(curve.evaluate_multi(t).T), Material(color=(1.0, 0.5, 0.0)))
    camera = _camera()
    lines = remove_hidden_lines([(i.mesh, i.world_from_model) for i in scene.items + scene.polylines], camera)
    root = ET.fromstring(render_svg(scene, camera).encode())
    visible = _group(root, "line3-visible")
    hidden = _group(root, "line3-hidden")
    assert visible.get("stroke") == "#ff8000" and hidden.get("stroke") == "#ff8000"
    ours = lines.edge_meshes[lines.visible_edges] == 3
    drawn = _segments(visible.find(f"{SVG}path").get("d"))
    assert np.array_equal(drawn, np.stack([lines.visible[ours, :, 0], 240 - lines.visible[ours, :, 1]], axis=-1))
    assert _segments(hidden.find(f"{SVG}path").get("d")).shape[0] > 0  # it passes behind the parts
    # the black mesh-edge groups hold no curve pieces
    assert _segments(_group(root, "visible").find(f"{SVG}path").get("d")).shape[0] == np.count_nonzero(~ours)


# --- files ---------------------------------------------------------------------------------------------------


def test_save_svg_writes_svg_pdf_and_png(tmp_path):
    text = render_svg(_part_scene(), _camera(160, 120))
    assert save_svg(text, tmp_path / "part.svg").read_text(encoding="utf-8") == text
    assert (tmp_path / "part.pdf").exists() is False
    save_svg(text, tmp_path / "part.pdf")
    assert (tmp_path / "part.pdf").read_bytes().startswith(b"%PDF")
    save_svg(text, tmp_path / "part.png")
    image = Image.open(tmp_path / "part.png")
    assert image.size == (160, 120)


def test_save_svg_rejects_bad_paths_and_text(tmp_path):
    text = render_svg(Scene(), _camera(16, 12))
    with pytest.raises(OutputError, match=r"suffix '.jpg'; expected '.svg', '.pdf' or '.png'"):
        save_svg(text, tmp_path / "x.jpg")
    with pytest.raises(OutputError, match=r"cannot be written"):
        save_svg(text, tmp_path / "missing" / "x.svg")
    with pytest.raises(OutputError, match=r"svg_text = b'<svg/>' is not a string"):
        save_svg(b"<svg/>", tmp_path / "x.svg")


# --- bad and edge-case input ---------------------------------------------------------------------------------


def test_empty_scene_gives_a_valid_empty_drawing():
    root = ET.fromstring(render_svg(Scene(), _camera(), fill=True).encode())
    assert _group(root, "visible") is None and _group(root, "hidden") is None
    assert len(list(_group(root, "faces"))) == 0


def test_degenerate_faces_are_drawn_without_error():
    box = _box((2, 2, 2))
    vertices = np.vstack([box.vertices, [[0, 0, 1], [0, 0, 1], [1, 0, 1]]])  # a point-like and a line-like face
    faces = np.vstack([box.faces, [[8, 9, 10]], [[8, 8, 8]]])
    scene = Scene()
    scene.add(Mesh(vertices, faces))
    text = render_svg(scene, _camera(), fill=True)
    root = ET.fromstring(text.encode())
    assert _group(root, "visible") is not None
    assert len(list(_group(root, "faces"))) >= 6  # the box's visible faces; the degenerate ones are skipped


def test_camera_inside_an_object_draws_the_walls_inside_the_view():
    sphere = trimesh.creation.icosphere(subdivisions=2, radius=3.0)
    scene = Scene()
    scene.add(Mesh(sphere.vertices, sphere.faces))
    camera = Camera.look_at((0.2, 0.1, 0.3), (0, 0, -1), (0, 1, 0), Perspective(1.4, 0.1, 20), 200, 150)
    root = ET.fromstring(render_svg(scene, camera, edges="all", fill=True).encode())
    segments = _segments(_group(root, "visible").find(f"{SVG}path").get("d"))
    assert (segments[..., 0] >= -1e-9).all() and (segments[..., 0] <= 200 + 1e-9).all()
    assert (segments[..., 1] >= -1e-9).all() and (segments[..., 1] <= 150 + 1e-9).all()
    polygons = [_path_numbers(p.get("points").replace(",", " ")) for p in _group(root, "faces")]
    assert polygons and all(np.isfinite(p).all() for p in polygons)
    assert all((p[:, 0] >= -1e-6).all() and (p[:, 0] <= 200 + 1e-6).all() for p in polygons)


@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        ({"scene": "scene"}, FrustumError, r"render_svg: scene = 'scene' is not a Scene"),
        ({"camera": None}, FrustumError, r"render_svg: camera = None is not a Camera"),
        ({"stroke_width": 0.0}, OutputError, r"stroke_width = 0.0 must be > 0"),
        ({"stroke_width": float("inf")}, OutputError, r"stroke_width = inf is not finite"),
        ({"hidden": "dotted"}, OutputError, r"hidden = 'dotted' is unknown"),
        ({"fill_order": "random"}, OutputError, r"fill_order = 'random' is unknown"),
        ({"edges": "outline"}, FrustumError, r"edges = 'outline' is unknown"),
        ({"crease_angle": 4.0}, FrustumError, r"crease_angle = 4.0 is outside \[0, pi\]"),
    ],
)
def test_render_svg_rejects_bad_input(kwargs, error, match):
    arguments = {"scene": _part_scene(), "camera": _camera(), **kwargs}
    scene, camera = arguments.pop("scene"), arguments.pop("camera")
    with pytest.raises(error, match=match):
        render_svg(scene, camera, **arguments)


def test_placed_meshes_are_the_items_then_the_polylines():
    scene = _part_scene()
    scene.add(Polyline([[0, 0, 0], [1, 1, 1]]))
    placed = _placed_meshes(scene)
    assert [p.mesh for p in placed] == [i.mesh for i in scene.items] + [scene.polylines[0].mesh]


def test_a_visible_curve_under_a_parallel_projection_is_the_exact_bezier_path():
    from frustum import BezierCurve, Orthographic, Perspective

    curve = BezierCurve([[-1.0, -0.5, 0.0], [-0.3, 1.0, 0.2], [0.4, -1.0, -0.1], [1.0, 0.5, 0.0]])
    scene = Scene()
    scene.add(Polyline.from_curve(curve, tolerance=1e-3), Material(color=(1, 0, 0)))
    camera = Camera.look_at((0.5, 0.3, 5), (0, 0, 0), (0, 1, 0), projection=Orthographic(3.0, 1, 10),
                            width=200, height=150)  # fmt: skip
    svg = render_svg(scene, camera)
    (path,) = re.findall(r'class="bezier" d="([^"]+)"', svg)
    numbers = [float(v) for v in NUMBER.findall(path)]
    window = camera.project(curve.control_points)[:, :2]
    expected = np.column_stack([window[:, 0], camera.height - window[:, 1]]).ravel()
    assert path.startswith("M") and " C" in path and np.allclose(numbers, expected, atol=1e-6)
    # hidden in part (a box in front), or seen in perspective: the flattened pieces, no Bézier path
    blocked = Scene()
    blocked.add(Polyline.from_curve(curve, tolerance=1e-3), Material(color=(1, 0, 0)))
    blocked.add(_box((0.6, 0.6, 0.6), center=(0.0, 0.0, 1.0)))
    assert 'class="bezier"' not in render_svg(blocked, camera)
    perspective = Camera.look_at((0.5, 0.3, 5), (0, 0, 0), (0, 1, 0), projection=Perspective(0.8, 1, 10),
                                 width=200, height=150)  # fmt: skip
    assert 'class="bezier"' not in render_svg(scene, perspective)
