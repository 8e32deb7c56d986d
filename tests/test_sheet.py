"""Engineering sheets (``frustum.output.sheet``): true lengths in the orthographic views, layout, title, scale bar.

Oracles: model dimensions known by construction (a 40 x 20 x 10 mm block, also turned about the line of
sight), read back from the SVG paths with ``xml.etree``; cairosvg renders the sheet.
"""

from __future__ import annotations

import io
import math
import re
import shutil
import subprocess
import xml.etree.ElementTree as ET

import cairosvg
import numpy as np
import pytest
import trimesh
from PIL import Image, ImageDraw

from frustum import FrustumError, OutputError, Scene, rotate_x, rotate_z, translate
from frustum.geometry import Mesh, cylinder
from frustum.output.sheet import PAPER_SIZES, STANDARD_SCALES, dimension_text, drawing_sheet, scale_label
from frustum.output.svg import save_svg

SVG = "{http://www.w3.org/2000/svg}"
NUMBER = re.compile(r"-?\d+(?:\.\d+)?(?:e-?\d+)?")


def _block(transform=None) -> Scene:
    box = trimesh.creation.box(extents=(40.0, 20.0, 10.0))
    scene = Scene()
    scene.add(Mesh(box.vertices, box.faces), transform=transform)
    return scene


def _bracket() -> Scene:
    scene = _block()
    upright = trimesh.creation.box(extents=(8.0, 30.0, 10.0))
    scene.add(Mesh(upright.vertices, upright.faces), transform=translate(-16.0, 25.0, 0.0))
    return scene


def _segments(root: ET.Element, group_id: str) -> np.ndarray:
    group = next((g for g in root.iter(f"{SVG}g") if g.get("id") == group_id), None)
    if group is None:
        return np.zeros((0, 2, 2))
    numbers = [float(v) for path in group.iter(f"{SVG}path") for v in NUMBER.findall(path.get("d"))]
    return np.array(numbers).reshape(-1, 2, 2)


def _lengths(segments: np.ndarray) -> np.ndarray:
    return np.sort(np.linalg.norm(segments[:, 1] - segments[:, 0], axis=1))


@pytest.mark.parametrize("scale", [2.0, 1.0, 0.5])
def test_orthographic_views_measure_model_lengths_times_scale(scale):
    root = ET.fromstring(drawing_sheet(_block(), views=("front", "top", "right"), scale=scale).encode())
    # each view shows one face of the block as its outline, every edge whole and parallel to the view plane
    expected = {"front": [20, 20, 40, 40], "top": [10, 10, 40, 40], "right": [10, 10, 20, 20]}
    for view, sides in expected.items():
        visible = _segments(root, f"{view}-visible")
        np.testing.assert_allclose(_lengths(visible), np.array(sides) * scale, rtol=0, atol=1e-9)
        # the back face's edges lie under the outline, hidden, with the same lengths
        np.testing.assert_allclose(_lengths(_segments(root, f"{view}-hidden")), np.array(sides) * scale, atol=1e-9)


def test_lengths_stay_true_for_edges_turned_in_the_view_plane():
    # the block turned 30 degrees about z: in the front view its front face is a turned 40 x 20 rectangle
    root = ET.fromstring(drawing_sheet(_block(rotate_z(math.radians(30))), views=("front",), scale=2.0).encode())
    visible = _segments(root, "front-visible")
    np.testing.assert_allclose(_lengths(visible), [40, 40, 80, 80], rtol=0, atol=1e-9)
    direction = visible[:, 1] - visible[:, 0]
    angles = np.degrees(np.arctan2(-direction[:, 1], direction[:, 0])) % 180  # paper y points down
    np.testing.assert_allclose(np.sort(angles), [30, 30, 120, 120], atol=1e-9)


@pytest.mark.parametrize("angle", ["third", "first"])
def test_views_are_aligned_and_placed_by_the_projection_angle(angle):
    root = ET.fromstring(drawing_sheet(_bracket(), projection_angle=angle, scale=1.0).encode())
    front, top, right = (_segments(root, f"{v}-visible").reshape(-1, 2) for v in ("front", "top", "right"))
    # the top view shares the front view's x extent, the right view its y extent (projection lines)
    np.testing.assert_allclose([top[:, 0].min(), top[:, 0].max()], [front[:, 0].min(), front[:, 0].max()], atol=1e-9)
    np.testing.assert_allclose(
        [right[:, 1].min(), right[:, 1].max()], [front[:, 1].min(), front[:, 1].max()], atol=1e-9
    )
    above = top[:, 1].max() < front[:, 1].min()
    right_of = right[:, 0].min() > front[:, 0].max()
    assert (above, right_of) == ((True, True) if angle == "third" else (False, False))
    if angle == "first":
        assert top[:, 1].min() > front[:, 1].max() and right[:, 0].max() < front[:, 0].min()
    assert f"{angle.upper()} ANGLE PROJECTION" in ET.tostring(root, encoding="unicode")
    # the isometric view: in the free corner of the top view's row, right of the front view's column
    iso = _segments(root, "isometric-visible").reshape(-1, 2)
    assert (
        iso[:, 0].min() > front[:, 0].max() and iso[:, 1].min() < top[:, 1].max() and iso[:, 1].max() > top[:, 1].min()
    )


def test_title_block_labels_and_scale_bar():
    text = drawing_sheet(_block(), scale=2.0, title="Block <A&B>")
    root = ET.fromstring(text.encode())
    texts = [t.text for t in root.iter(f"{SVG}text")]
    block = _group(root, "title-block")
    assert "Block <A&B>" in texts and "SCALE" in texts and "2:1" in texts and block.get("data-scale") == "2:1"
    assert {"FRONT VIEW", "TOP VIEW", "RIGHT VIEW", "ISOMETRIC VIEW"} <= set(texts)
    bar = next(g for g in root.iter(f"{SVG}g") if g.get("id") == "scale-bar")
    length = float(bar.get("data-length"))
    line = [float(v) for v in NUMBER.findall(next(bar.iter(f"{SVG}path")).get("d"))[:4]]
    assert line[2] - line[0] == pytest.approx(length * 2.0, abs=1e-9) and line[1] == line[3]
    assert f"{length:g} mm" in texts


def test_automatic_scale_is_the_largest_standard_scale_that_fits():
    text = drawing_sheet(_bracket(), paper="A4")
    chosen = _group(ET.fromstring(text.encode()), "title-block").get("data-scale")
    scale = next(s for s in STANDARD_SCALES if scale_label(s) == chosen)
    larger = [s for s in STANDARD_SCALES if s > scale]
    with pytest.raises(OutputError, match=r"does not fit"):
        drawing_sheet(_bracket(), paper="A4", scale=min(larger))
    # everything inside the border of the A4 sheet
    root = ET.fromstring(text.encode())
    width, height = PAPER_SIZES["A4"]
    points = np.array([float(v) for p in root.iter(f"{SVG}path") for v in NUMBER.findall(p.get("d"))]).reshape(-1, 2)
    assert (points >= 10 - 1e-9).all() and (points[:, 0] <= width - 10 + 1e-9).all()
    assert (points[:, 1] <= height - 10 + 1e-9).all()


def test_sheet_renders_with_cairosvg():
    text = drawing_sheet(_bracket(), scale=0.5, paper="A4")
    png = Image.open(io.BytesIO(cairosvg.svg2png(bytestring=text.encode(), output_width=1123)))
    gray = np.asarray(png.convert("L"))
    assert png.size[0] == 1123 and (gray < 128).mean() > 0.005
    assert text == drawing_sheet(_bracket(), scale=0.5, paper="A4")  # deterministic


def test_scale_labels():
    assert [scale_label(s) for s in (1.0, 2.0, 10.0, 0.5, 0.2, 0.01)] == ["1:1", "2:1", "10:1", "1:2", "1:5", "1:100"]
    assert scale_label(0.3) == "1:3.333333"


@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        ({"scene": None}, FrustumError, r"drawing_sheet: scene = None is not a Scene"),
        ({"scene": Scene()}, OutputError, r"scene has no faces to draw"),
        ({"views": ("front", "side")}, OutputError, r"views has 'side', which is unknown"),
        ({"views": ("front", "front")}, OutputError, r"names a view twice"),
        ({"views": ()}, OutputError, r"views = \(\) is empty"),
        ({"scale": 0.0}, OutputError, r"scale = 0.0 must be > 0"),
        ({"scale": float("nan")}, OutputError, r"scale = nan is not finite"),
        (
            {"scale": 50.0},
            OutputError,
            r"scale = 50.0 does not fit 4 views on A3 \(the largest standard scale that fits is 2:1\)",
        ),
        ({"orientation": "sideways"}, OutputError, r"orientation = 'sideways' is unknown; expected 'landscape'"),
        ({"dimensions": "yes"}, OutputError, r"dimensions = 'yes' is unknown; expected 'overall', 'parts' or False"),
        ({"paper": "B5"}, OutputError, r"paper = 'B5' is unknown"),
        ({"paper": (50, 40)}, OutputError, r"paper = \(50.0, 40.0\) is not a paper name"),
        ({"projection_angle": "second"}, OutputError, r"projection_angle = 'second' is unknown"),
        ({"hidden": "dotted"}, OutputError, r"hidden = 'dotted' is unknown"),
    ],
)
def test_drawing_sheet_rejects_bad_input(kwargs, error, match):
    arguments = {"scene": _block(), **kwargs}
    scene = arguments.pop("scene")
    with pytest.raises(error, match=match):
        drawing_sheet(scene, **arguments)


# --- a part a drafter would draw: a box with a cylinder standing on it ----------------------------------------


def _box_with_cylinder() -> tuple[Scene, trimesh.Trimesh]:
    """A 60 x 10 x 40 mm plate (each face split into many coplanar triangles) with a ⌀20 x 30 mm cylinder on top
    (frustum's primitive: cap and seam vertices split from the side's), and the same part as one trimesh."""
    plate = trimesh.creation.box(extents=(60.0, 10.0, 40.0)).subdivide().subdivide()
    post = cylinder(radius=10.0, height=30.0, segments=48)
    place = translate(5.0, 20.0, -4.0) @ rotate_x(-math.pi / 2)  # axis along y, standing on the plate's top
    scene = Scene()
    scene.add(Mesh(plate.vertices, plate.faces))
    scene.add(post, transform=place)
    post_world = trimesh.Trimesh(post.vertices, post.faces).apply_transform(place)
    return scene, trimesh.util.concatenate([plate, post_world])


def _group(root: ET.Element, group_id: str) -> ET.Element | None:
    return next((g for g in root.iter(f"{SVG}g") if g.get("id") == group_id), None)


def _oracle_feature_edges(part: trimesh.Trimesh) -> np.ndarray:
    """(E, 2, 3) edges between faces more than 1e-3 rad apart, by trimesh (vertices merged by position)."""
    merged = part.copy()
    merged.merge_vertices(digits_vertex=9)
    sharp = merged.face_adjacency_angles > 1e-3
    return merged.vertices[merged.face_adjacency_edges[sharp]]


def test_top_view_draws_only_feature_edges_of_the_solid():
    scene, part = _box_with_cylinder()
    text = drawing_sheet(scene, views=("front", "top", "right"), paper="A3")
    root = ET.fromstring(text.encode())
    view = _group(root, "view-top")
    scale = float(view.get("data-scale"))
    centre = np.array([float(v) for v in view.get("data-centre").split()])
    drawn = np.concatenate([_segments(root, "top-visible"), _segments(root, "top-hidden")])
    assert drawn.shape[0] > 0
    # the top view: paper x = x, paper y = z (the front toward the bottom), around the part's box centre
    low, high = part.bounds
    middle = (low + high) / 2.0
    oracle = _oracle_feature_edges(part)[:, :, [0, 2]]
    oracle = centre + scale * (oracle - middle[[0, 2]])
    oracle = oracle[np.linalg.norm(oracle[:, 1] - oracle[:, 0], axis=1) > 1e-9]  # edges seen end-on are points
    a, b = oracle[:, 0], oracle[:, 1]
    direction = b - a
    length2 = (direction**2).sum(axis=1)

    def distance(p: np.ndarray) -> np.ndarray:  # from point p to every oracle segment
        t = np.clip(((p - a) * direction).sum(axis=1) / length2, 0.0, 1.0)
        return np.linalg.norm(a + t[:, None] * direction - p, axis=1)

    for start, end in drawn:
        # both ends (and the middle) on one projected feature edge; 1e-6 mm is round-off of the paper mapping
        on = (distance(start) < 1e-6) & (distance(end) < 1e-6) & (distance((start + end) / 2.0) < 1e-6)
        assert on.any(), f"segment {start} -> {end} is not on a feature edge of the part"
    # and the outline is complete: points along the plate's rectangle and the post's circle are all drawn
    visible = _segments(root, "top-visible")
    p, q = visible[:, 0], visible[:, 1]

    def drawn_at(point: np.ndarray) -> bool:
        t = np.clip(((point - p) * (q - p)).sum(axis=1) / ((q - p) ** 2).sum(axis=1), 0.0, 1.0)
        return bool((np.linalg.norm(p + t[:, None] * (q - p) - point, axis=1) < 1e-6).any())

    corners = centre + scale * np.array([[-30.0, -20.0], [30.0, -20.0], [30.0, 20.0], [-30.0, 20.0]])
    along = np.linspace(0.0, 1.0, 25)[:, None]
    outline = [corners[k] + along * (corners[(k + 1) % 4] - corners[k]) for k in range(4)]
    assert all(drawn_at(point) for point in np.concatenate(outline))
    # the post's rim is a true circle (output/true_curves.py), not its 48-gon
    axis = centre + scale * (np.array([5.0, -4.0]) - middle[[0, 2]])
    circles = _group(root, "top-visible-curves").findall(f"{SVG}circle")
    assert len(circles) == 1
    found = [float(circles[0].get(k)) for k in ("cx", "cy", "r")]
    np.testing.assert_allclose(found, [*axis, scale * 10.0], rtol=0, atol=1e-9)


@pytest.mark.parametrize(
    ("paper", "orientation", "angle"),
    [("A3", "landscape", "third"), ("A4", "portrait", "third"), ("Letter", "landscape", "first"),
     ("A4", "landscape", "first")],
)  # fmt: skip
def test_views_fill_the_drawing_area_at_the_largest_standard_scale(paper, orientation, angle):
    scene, _ = _box_with_cylinder()
    text = drawing_sheet(scene, paper=paper, orientation=orientation, projection_angle=angle)
    root = ET.fromstring(text.encode())
    width, height = (float(root.get(k).removesuffix("mm")) for k in ("width", "height"))
    long, short = (
        max(PAPER_SIZES[paper.upper() if paper.startswith("A") else paper.lower()]),
        min(PAPER_SIZES[paper.upper() if paper.startswith("A") else paper.lower()]),
    )
    assert (width, height) == ((long, short) if orientation == "landscape" else (short, long))
    # every view as drawn (its lines, dimensions and diameter leaders) together: a bounding box over >= 60 % of
    # the drawing area's width or height (the 1, 2, 5 scale series can leave the geometry alone at 40 %)
    views = ("front", "top", "right", "isometric")
    points = np.array(
        [
            float(v)
            for g in root.iter(f"{SVG}g")
            if g.get("id", "").startswith(tuple(f"{view}-" for view in views))
            for path in g.iter(f"{SVG}path")
            if path.get("class") != "arc"  # true curves (elliptical arcs) lie inside the views' outlines
            for v in NUMBER.findall(path.get("d"))
        ]
    ).reshape(-1, 2)
    area_width, area_height = width - 20.0, height - 20.0 - 36.0
    used = points.max(axis=0) - points.min(axis=0)
    assert max(used[0] / area_width, used[1] / area_height) >= 0.6
    # and the next larger standard scale does not fit
    chosen = float(_group(root, "view-front").get("data-scale"))
    larger = [s for s in STANDARD_SCALES if s > chosen]
    with pytest.raises(OutputError, match="does not fit"):
        drawing_sheet(scene, paper=paper, orientation=orientation, projection_angle=angle, scale=min(larger))


def _dimension(root: ET.Element, group_id: str) -> tuple[float, str, np.ndarray]:
    group = _group(root, group_id)
    assert group is not None and group.get("class") == "dimension", group_id
    lines = np.array([float(v) for v in NUMBER.findall(group.find(f"{SVG}path").get("d"))]).reshape(-1, 2, 2)
    return float(group.get("data-value")), group.find(f"{SVG}text").text, lines


@pytest.mark.parametrize("scale", [1.0, 2.0])
def test_dimension_values_are_the_model_extents_and_lines_measure_them_times_scale(scale):
    scene, part = _box_with_cylinder()
    root = ET.fromstring(
        drawing_sheet(scene, views=("front", "top", "right"), scale=scale, dimensions="overall").encode()
    )
    extent = part.bounds[1] - part.bounds[0]  # (60, 40, 40): x, y, z
    # (horizontal, vertical) model axes of each view
    axes = {"front": (0, 1), "top": (0, 2), "right": (2, 1)}
    for view, (across, up) in axes.items():
        geometry = np.concatenate([_segments(root, f"{view}-visible"), _segments(root, f"{view}-hidden")])
        size = geometry.reshape(-1, 2).max(axis=0) - geometry.reshape(-1, 2).min(axis=0)
        for name, axis, paper_axis in (("horizontal", across, 0), ("vertical", up, 1)):
            value, label, lines = _dimension(root, f"{view}-dimension-{name}")
            assert value == pytest.approx(extent[axis], abs=1e-9) and label == dimension_text(extent[axis])
            # the dimension line (the one along the measured direction) spans extent × scale, as does the view
            along = np.abs(lines[:, 1, paper_axis] - lines[:, 0, paper_axis])
            assert along.max() == pytest.approx(extent[axis] * scale, abs=1e-9)
            assert size[paper_axis] == pytest.approx(extent[axis] * scale, abs=1e-9)
    # the post is seen end-on in the top view only: its diameter there, and centre lines
    diameters = [g for g in root.iter(f"{SVG}g") if g.get("class") == "diameter"]
    assert [g.get("id") for g in diameters] == ["top-diameter-0"]
    assert (
        float(diameters[0].get("data-value")) == pytest.approx(20.0) and diameters[0].find(f"{SVG}text").text == "⌀20"
    )
    # centre lines: a cross through the circle in the top view, the post's axis in the side views (30 mm tall,
    # 2 mm past each end), vertical and on the post's axis (x = 5 in the front view, z = −4 in the right view)
    assert _group(root, "top-centre-lines") is not None
    for view, axis_paper_x in (("front", 5.0 - (part.bounds[0][0] + part.bounds[1][0]) / 2),
                               ("right", 4.0 + (part.bounds[0][2] + part.bounds[1][2]) / 2)):  # fmt: skip
        group = _group(root, f"{view}-centre-lines")
        # a chain line drawn as its dashes (long dashes at both ends: no stray dots)
        dashes = np.array([float(v) for v in NUMBER.findall(group.find(f"{SVG}path").get("d"))]).reshape(-1, 2, 2)
        centre = [float(v) for v in _group(root, f"view-{view}").get("data-centre").split()]
        np.testing.assert_allclose(dashes[:, :, 0], centre[0] + axis_paper_x * scale, atol=1e-9)
        ys = np.sort(dashes[:, :, 1], axis=1)
        assert ys.max() - ys.min() == pytest.approx(30.0 * scale + 4.0, abs=1e-9)
        ordered = ys[np.argsort(ys[:, 0])]
        assert (ordered[[0, -1], 1] - ordered[[0, -1], 0] >= 2.0).all()  # the end dashes are long ones
    arrowheads = [p for p in root.iter(f"{SVG}path") if p.get("class") == "arrowheads"]
    assert len(arrowheads) == 7 and all(p.get("d").count("Z") in (1, 2) for p in arrowheads)


def test_dimensions_false_draws_no_dimensions():
    scene, _ = _box_with_cylinder()
    root = ET.fromstring(drawing_sheet(scene, dimensions=False).encode())
    assert not [g for g in root.iter(f"{SVG}g") if g.get("class") in ("dimension", "diameter")]
    assert _group(root, "top-centre-lines") is not None


def test_dimension_text():
    assert [dimension_text(v) for v in (40.0, 2.4, 0.16, 1234.6, 60.00000000001, 0.0)] == [
        "40", "2.4", "0.16", "1235", "60", "0",
    ]  # fmt: skip


def _dark(image: Image.Image, size: tuple[int, int]) -> np.ndarray:
    """Line pixels: darker than 200 of 255 after compositing on white paper (cairosvg leaves it transparent)."""
    paper = Image.new("RGBA", image.size, (255, 255, 255, 255))
    paper.alpha_composite(image.convert("RGBA"))
    return np.asarray(paper.convert("L").resize(size, Image.Resampling.BOX)) < 200


def _near(a: np.ndarray, b: np.ndarray, radius: int) -> float:
    """Fraction of a's True pixels with a True pixel of b within `radius` pixels (square neighbourhood)."""
    grown = b.copy()
    for dy in range(-radius, radius + 1):
        for dx in range(-radius, radius + 1):
            grown |= np.roll(np.roll(b, dy, axis=0), dx, axis=1)
    return float((a & grown).sum() / max(a.sum(), 1))


@pytest.mark.skipif(shutil.which("pdftoppm") is None, reason="pdftoppm (Debian poppler-utils) is not installed")
def test_pdf_and_svg_outputs_read_back_like_the_png(tmp_path):
    scene, _ = _box_with_cylinder()
    text = drawing_sheet(scene, paper="A4", title="Plate with post")
    png_path, pdf_path = save_svg(text, tmp_path / "sheet.png"), save_svg(text, tmp_path / "sheet.pdf")
    png = Image.open(png_path)
    size = png.size
    # PDF → PNG through poppler's pdftoppm, a reader independent of cairo's SVG parser
    subprocess.run(["pdftoppm", "-r", "150", "-png", "-singlefile", str(pdf_path), str(tmp_path / "poppler")],
                   check=True, capture_output=True)  # fmt: skip
    poppler = Image.open(tmp_path / "poppler.png")
    assert abs(poppler.size[0] / poppler.size[1] - size[0] / size[1]) < 0.01  # same A4 landscape page
    ours, theirs = _dark(png, size), _dark(poppler, size)
    # line pixels agree within 2 px both ways (anti-aliasing and hinting differ between the two renderers)
    assert ours.mean() > 0.005 and _near(ours, theirs, 2) > 0.97 and _near(theirs, ours, 2) > 0.97
    # the SVG parsed as XML: its path segments, drawn with PIL, lie on the PNG's line pixels
    root = ET.parse(io.StringIO(text)).getroot()
    width_mm = float(root.get("width").removesuffix("mm"))
    drawing = Image.new("L", size, 255)
    pen = ImageDraw.Draw(drawing)
    factor = size[0] / width_mm
    for group in root.iter(f"{SVG}g"):
        if group.get("id", "").endswith(("-visible", "-hidden")):
            for (x0, y0), (x1, y1) in _segments(root, group.get("id")):
                pen.line([(x0 * factor, y0 * factor), (x1 * factor, y1 * factor)], fill=0, width=1)
    lines = np.asarray(drawing) < 128
    assert lines.sum() > 1000 and _near(lines, ours, 2) > 0.97


def test_a_flat_part_seen_edge_on_gets_no_zero_dimension():
    scene = Scene()
    scene.add(Mesh([[0, 0, 0], [40, 0, 0], [40, 0, 20.0]], [[0, 1, 2]]))  # in the y = 0 plane
    root = ET.fromstring(drawing_sheet(scene, views=("front", "top"), dimensions="overall").encode())
    values = {g.get("id"): float(g.get("data-value")) for g in root.iter(f"{SVG}g") if g.get("class") == "dimension"}
    assert values == {
        "front-dimension-horizontal": 40.0,
        "top-dimension-horizontal": 40.0,
        "top-dimension-vertical": 20.0,
    }
    # per part: each size once, none of them zero
    root = ET.fromstring(drawing_sheet(scene, views=("front", "top"), dimensions="parts").encode())
    values = {g.get("id"): float(g.get("data-value")) for g in root.iter(f"{SVG}g") if g.get("class") == "dimension"}
    assert sorted(values.values()) == [20.0, 40.0]
