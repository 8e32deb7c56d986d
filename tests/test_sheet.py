"""Engineering sheets (``frustum.output.sheet``): true lengths in the orthographic views, layout, title, scale bar.

Oracles: model dimensions known by construction (a 40 x 20 x 10 mm block, also turned about the line of
sight), read back from the SVG paths with ``xml.etree``; cairosvg renders the sheet.
"""

from __future__ import annotations

import io
import math
import re
import xml.etree.ElementTree as ET

import cairosvg
import numpy as np
import pytest
import trimesh
from PIL import Image

from frustum import FrustumError, OutputError, Scene, rotate_z, translate
from frustum.geometry import Mesh
from frustum.output.sheet import PAPER_SIZES, STANDARD_SCALES, drawing_sheet, scale_label

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


def test_title_block_labels_and_scale_bar():
    text = drawing_sheet(_block(), scale=2.0, title="Block <A&B>")
    root = ET.fromstring(text.encode())
    texts = [t.text for t in root.iter(f"{SVG}text")]
    assert "Block <A&B>" in texts and "SCALE 2:1" in texts
    assert {"FRONT VIEW", "TOP VIEW", "RIGHT VIEW", "ISOMETRIC VIEW"} <= set(texts)
    bar = next(g for g in root.iter(f"{SVG}g") if g.get("id") == "scale-bar")
    length = float(bar.get("data-length"))
    line = [float(v) for v in NUMBER.findall(bar.find(f"{SVG}path").get("d"))[:4]]
    assert line[2] - line[0] == pytest.approx(length * 2.0, abs=1e-9) and line[1] == line[3]
    assert f"{length:g} mm" in texts


def test_automatic_scale_is_the_largest_standard_scale_that_fits():
    text = drawing_sheet(_bracket(), paper="A4")
    chosen = next(t.text for t in ET.fromstring(text.encode()).iter(f"{SVG}text") if t.text.startswith("SCALE"))
    scale = next(s for s in STANDARD_SCALES if f"SCALE {scale_label(s)}" == chosen)
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
        ({"scale": 50.0}, OutputError, r"scale = 50.0 does not fit 4 views on A3 \(at most"),
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
