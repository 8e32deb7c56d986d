"""Dimensions per part on engineering sheets (``drawing_sheet(dimensions="parts")``, ISO 129-1 conventions).

Oracles: each part's extents from its placed vertices (NumPy), the SVG read back with ``xml.etree``, and
``shapely`` for the geometry of the annotations: no extension line or dimension line of one dimension meets
another's dimension line, and no text box overlaps another text or a visible edge.
"""

from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
import shapely
from shapely import affinity
from shapely.geometry import LineString, Point, box

from frustum import OutputError, Scene, rotate_x, translate
from frustum.geometry import box as box_mesh
from frustum.geometry import cylinder
from frustum.output.sheet import dimension_text, drawing_sheet
from frustum.scenefile import load_scene_file
from sheet_scenes import plate

SVG = "{http://www.w3.org/2000/svg}"
NUMBER = re.compile(r"-?\d+(?:\.\d+)?(?:e-?\d+)?")
EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
LETTER = 3.5


def _groups(root: ET.Element, kind: str) -> list[ET.Element]:
    return [g for g in root.iter(f"{SVG}g") if g.get("class") == kind]


def _lines(group: ET.Element) -> np.ndarray:
    path = next(p for p in group.iter(f"{SVG}path") if p.get("class") == "lines")
    return np.array([float(v) for v in NUMBER.findall(path.get("d"))]).reshape(-1, 2, 2)


def _text_boxes(root: ET.Element) -> list[tuple[str, shapely.Polygon]]:
    """(text, box) of every text outside the title block, as the sheet sizes them: 0.6·h per character."""
    title = next(g for g in root.iter(f"{SVG}g") if g.get("id") == "title-block")
    skip = set(title.iter(f"{SVG}text"))
    boxes = []
    for text in root.iter(f"{SVG}text"):
        if text in skip or not text.text:
            continue
        x, y = float(text.get("x")), float(text.get("y"))
        size = float(text.get("font-size"))
        run = 0.6 * size * len(text.text)
        low, high = {"start": (0.0, run), "middle": (-run / 2, run / 2), "end": (-run, 0.0)}[text.get("text-anchor")]
        if "rotate(-90" in (text.get("transform") or ""):
            boxes.append((text.text, box(x - size, y - high, x, y - low)))
        else:
            boxes.append((text.text, box(x + low, y - size, x + high, y)))
    return boxes


def _visible_edges(root: ET.Element) -> list:
    """Visible straight edges, circles and whole ellipses (true curves) of every view."""
    edges = []
    for group in root.iter(f"{SVG}g"):
        if group.get("id", "").endswith("-visible"):
            for path in group.iter(f"{SVG}path"):
                numbers = np.array([float(v) for v in NUMBER.findall(path.get("d"))]).reshape(-1, 2, 2)
                edges += [LineString(segment) for segment in numbers]
        if group.get("id", "").endswith("-visible-curves"):
            for circle in group.iter(f"{SVG}circle"):
                centre = Point(float(circle.get("cx")), float(circle.get("cy")))
                edges.append(centre.buffer(float(circle.get("r")), 64).exterior)
            for ellipse in group.iter(f"{SVG}ellipse"):
                cx, cy, rx, ry = (float(ellipse.get(k)) for k in ("cx", "cy", "rx", "ry"))
                shape = affinity.scale(Point(cx, cy).buffer(1.0, 64), rx, ry)
                angle = float(NUMBER.findall(ellipse.get("transform"))[0])
                edges.append(affinity.rotate(shape, angle, origin=(cx, cy)).exterior)
    return edges


def _check_clear(root: ET.Element) -> None:
    """No dimension's extension or dimension line meets another dimension's dimension line; no text box
    overlaps another or a visible edge."""
    dimensions = []
    for group in _groups(root, "dimension"):
        lines = _lines(group)
        dimensions.append((group.get("id"), [LineString(s) for s in lines[:-1]], LineString(lines[-1])))
    for name, extensions, line in dimensions:
        for other, other_extensions, other_line in dimensions:
            if other == name:
                continue
            assert not line.intersects(other_line), (name, other)
            for extension in extensions:
                # a shared extension line (chain dimensioning: the other's arrowhead ends on the line this
                # extension line continues) meets it only on that line; anything else is a crossing
                meeting = extension.intersection(other_line)
                shared = any(_on_one_line(extension, own) for own in other_extensions)
                assert meeting.is_empty or shared, (name, "extension line crosses", other)
    boxes = _text_boxes(root)
    for i, (text, shape) in enumerate(boxes):
        for other, other_shape in boxes[i + 1 :]:
            assert not shape.intersects(other_shape), (text, other)
    edges = shapely.union_all(_visible_edges(root))
    for text, shape in boxes:
        assert not shape.intersects(edges), text


def _on_one_line(a: LineString, b: LineString) -> bool:
    (ax0, ay0), (ax1, ay1) = a.coords
    (bx0, by0), (bx1, by1) = b.coords
    if ax0 == ax1 and bx0 == bx1:
        return abs(ax0 - bx0) <= 1e-9
    return ay0 == ay1 and by0 == by1 and abs(ay0 - by0) <= 1e-9


def _part_extents(scene: Scene) -> list[np.ndarray]:
    return [
        np.ptp(item.mesh.vertices @ item.world_from_model[:3, :3].T + item.world_from_model[:3, 3], axis=0)
        for item in scene.items
    ]


def _view_axes(root: ET.Element) -> dict[str, tuple[int, int]]:
    return {"front": (0, 1), "top": (0, 2), "right": (2, 1), "left": (2, 1), "bottom": (0, 2), "rear": (0, 1)}


def test_exploded_assembly_parts_carry_their_own_sizes():
    scene = load_scene_file(EXAMPLES / "exploded_assembly.toml").scene
    text = drawing_sheet(scene)
    root = ET.fromstring(text.encode())
    extents = _part_extents(scene)
    axes = _view_axes(root)
    linear: dict[int, list[float]] = {}
    for group in _groups(root, "dimension"):
        view, rest = group.get("id").split("-", 1)
        part, orientation = re.fullmatch(r"dimension-part(\d+)-(horizontal|vertical)", rest).groups()
        part = int(part)
        scale = float(next(g for g in root.iter(f"{SVG}g") if g.get("id") == f"view-{view}").get("data-scale"))
        axis = axes[view][0 if orientation == "horizontal" else 1]
        value = float(group.get("data-value"))
        # every value is the part's extent; its dimension line measures extent × scale
        assert value == pytest.approx(extents[part][axis], abs=1e-9)
        assert group.find(f"{SVG}text").text.endswith(dimension_text(value))
        line = _lines(group)[-1]
        paper_axis = 0 if orientation == "horizontal" else 1
        assert abs(line[1, paper_axis] - line[0, paper_axis]) >= value * scale - 1e-9
        linear.setdefault(part, []).append(value)
    diameters = sorted(float(g.get("data-value")) for g in _groups(root, "diameter"))
    texts = [g.find(f"{SVG}text").text for g in _groups(root, "diameter")]
    # base plate 2.4 x 0.3 x 1.6; housing ⌀1.2 x 1; lid ⌀1.4 x 0.2; knob S⌀0.36; bolts 2x ⌀0.16 x 0.6
    assert sorted(linear[0]) == pytest.approx([0.3, 1.6, 2.4])
    assert linear[1] == pytest.approx([1.0]) and linear[2] == pytest.approx([0.2])
    assert 3 not in linear and linear[4] == pytest.approx([0.6]) and 5 not in linear  # the second bolt: a copy
    assert diameters == pytest.approx([0.16, 0.36, 1.2, 1.4])
    assert sorted(texts) == ["2× ⌀0.16", "S⌀0.36", "⌀1.2", "⌀1.4"]
    # the exploded layout's overall extents are not stated
    values = {float(g.get("data-value")) for g in _groups(root, "dimension")}
    assert not values & {3.77, 2.06, 3.56}
    _check_clear(root)


def _plate_with_parts() -> Scene:
    """A plate with a post, a block, a ball and two pins: parts of many sizes, crowding the dimensions."""
    scene = plate()
    for x in (-33.0, 33.0):
        scene.add(cylinder(2.0, 10.0, 24), transform=translate(x, 8.0, 18.0) @ rotate_x(-math.pi / 2))
    return scene


@pytest.mark.parametrize("angle", ["third", "first"])
@pytest.mark.parametrize("views", [("front", "top", "right", "isometric"), ("front", "top"), ("front", "right")])
def test_no_dimension_crosses_another_and_no_text_overlaps(angle, views):
    scene = _plate_with_parts()
    root = ET.fromstring(drawing_sheet(scene, views=views, projection_angle=angle).encode())
    _check_clear(root)
    # every part's every extent is stated somewhere (linear dimension or diameter)
    stated = {float(g.get("data-value")) for g in root.iter(f"{SVG}g") if g.get("class") in ("dimension", "diameter")}
    for extent in _part_extents(scene):
        for value in extent:
            assert any(abs(value - s) <= 1e-9 for s in stated), value


def test_a_cylinder_without_an_end_on_view_gets_a_linear_diameter():
    scene = Scene()
    scene.add(cylinder(6.0, 20.0, 48), transform=rotate_x(-math.pi / 2))  # axis along y: end-on in top only
    root = ET.fromstring(drawing_sheet(scene, views=("front", "right")).encode())
    texts = sorted(g.find(f"{SVG}text").text for g in _groups(root, "dimension"))
    assert texts == ["20", "⌀12"] and not _groups(root, "diameter")
    root = ET.fromstring(drawing_sheet(scene, views=("front", "top")).encode())
    assert [g.find(f"{SVG}text").text for g in _groups(root, "diameter")] == ["⌀12"]
    assert [g.find(f"{SVG}text").text for g in _groups(root, "dimension")] == ["20"]


# --- title block (ISO 7200) and projection symbol (ISO 5456-2) ---------------------------------------------


@pytest.mark.parametrize("angle", ["third", "first"])
def test_title_block_has_every_field_and_the_projection_symbol_of_the_angle(angle):
    scene = Scene()
    scene.add(box_mesh((40.0, 20.0, 10.0)))
    fields = {"title": "Bracket", "drawing_number": "FR-0042", "sheet": (2, 3), "date": "2026-12-02",
              "author": "A. Drafter", "tolerance": "ISO 2768-f", "units": "mm"}  # fmt: skip
    root = ET.fromstring(drawing_sheet(scene, projection_angle=angle, paper="A4", title_block=fields).encode())
    block = next(g for g in root.iter(f"{SVG}g") if g.get("id") == "title-block")
    texts = [t.text for t in block.iter(f"{SVG}text")]
    for label in ("TITLE", "DRAWING NO.", "DRAWN BY", "DATE", "SCALE", "SHEET", "UNITS", "GENERAL TOLERANCES",
                  "SIZE"):  # fmt: skip
        assert label in texts
    for value in ("Bracket", "FR-0042", "2/3", "2026-12-02", "A. Drafter", "ISO 2768-f", "mm", "A4",
                  f"{angle.upper()} ANGLE PROJECTION", block.get("data-scale")):  # fmt: skip
        assert value in texts, value
    # the symbol: a trapezoid (the truncated cone, small end left) and two concentric circles (its view from
    # the small end), those right of the cone in first angle, left of it in third
    symbol = next(g for g in block.iter(f"{SVG}g") if g.get("id") == f"projection-symbol-{angle}")
    circles = symbol.findall(f"{SVG}circle")
    assert len(circles) == 2 and circles[0].get("cx") == circles[1].get("cx")
    radii = sorted(float(c.get("r")) for c in circles)
    cone = np.array([float(v) for v in NUMBER.findall(symbol.find(f"{SVG}path").get("d"))]).reshape(-1, 2, 2)
    xs = cone[:, :, 0]
    left_side = cone[np.abs(cone[:, 0, 0] - cone[:, 1, 0]) < 1e-9]
    heights = {float(s[0, 0]): abs(s[1, 1] - s[0, 1]) for s in left_side}
    assert heights[min(heights)] == pytest.approx(2 * radii[0]) and heights[max(heights)] == pytest.approx(2 * radii[1])
    circles_x = float(circles[0].get("cx"))
    assert (circles_x > xs.max()) if angle == "first" else (circles_x < xs.min())


@pytest.mark.parametrize(
    ("title_block", "match"),
    [
        ({"drawing_no": "1"}, r"title_block has 'drawing_no', which is unknown; expected keys from"),
        ({"sheet": (3, 2)}, r"title_block sheet = \(3, 2\) needs 1 <= n <= N"),
        ({"date": 20261202}, r"title_block date = 20261202 is not text"),
        ("Bracket", r"title_block = 'Bracket' is not a mapping"),
    ],
)
def test_title_block_rejects_bad_fields(title_block, match):
    scene = Scene()
    scene.add(box_mesh((40.0, 20.0, 10.0)))
    with pytest.raises(OutputError, match=match):
        drawing_sheet(scene, title_block=title_block)


def test_every_circle_gets_a_centre_mark_without_stray_dots():
    scene = _plate_with_parts()
    root = ET.fromstring(drawing_sheet(scene, views=("front", "top", "right")).encode())
    for view in ("front", "top", "right"):
        group = next(g for g in root.iter(f"{SVG}g") if g.get("id") == f"{view}-centre-lines")
        dashes = np.array([float(v) for v in NUMBER.findall(group.find(f"{SVG}path").get("d"))]).reshape(-1, 2, 2)
        lengths = np.linalg.norm(dashes[:, 1] - dashes[:, 0], axis=1)
        # short dashes of 1 mm only between long ones: every dash that ends a line is >= 2 mm
        ends = {tuple(np.round(p, 6)) for p in dashes.reshape(-1, 2)}
        for dash, length in zip(dashes, lengths, strict=True):
            if length < 2.0:
                # both neighbours along its line exist (a short dash inside a chain, not at an end)
                direction = (dash[1] - dash[0]) / length
                before, after = dash[0] - direction, dash[1] + direction
                assert tuple(np.round(before, 6)) in ends and tuple(np.round(after, 6)) in ends
    # the sphere's centre mark in every view (its outline is a circle seen from every side)
    front_circles = [
        float(c.get("r"))
        for c in next(g for g in root.iter(f"{SVG}g") if g.get("id") == "front-visible-curves").iter(f"{SVG}circle")
    ]
    assert front_circles == [pytest.approx(5.0)]


def test_parts_dimensions_fall_back_to_overall_when_they_crowd_the_paper():
    rng = np.random.default_rng(1)
    scene = Scene()
    for _ in range(14):  # fourteen scattered blocks: some 40 dimensions do not fit an A4 sheet at any scale
        scene.add(box_mesh(tuple(rng.uniform(2, 20, 3))), transform=translate(*rng.uniform(-60, 60, 3)))
    root = ET.fromstring(drawing_sheet(scene, views=("front", "top"), paper="A4").encode())
    block = next(g for g in root.iter(f"{SVG}g") if g.get("id") == "title-block")
    assert block.get("data-dimensions") == "overall"
    assert sorted(g.get("id") for g in _groups(root, "dimension")) == [
        "front-dimension-horizontal", "front-dimension-vertical", "top-dimension-horizontal", "top-dimension-vertical"
    ]  # fmt: skip
    # a small assembly keeps its parts' dimensions
    root = ET.fromstring(drawing_sheet(_plate_with_parts(), paper="A4").encode())
    block = next(g for g in root.iter(f"{SVG}g") if g.get("id") == "title-block")
    assert block.get("data-dimensions") == "parts"
