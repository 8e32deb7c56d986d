"""True curves on engineering sheets (``frustum.output.true_curves``): circles, ellipses and arcs, exact.

Oracles: the analytic parallel projection of a circle (centre, radius, and the semi-axes r and r·|cos α| of a
circle tilted by α against the view plane); a drilled block built by CSG (manifold3d); a faceted loop built by
trimesh; ``shapely`` for the pieces that stay straight.
"""

from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ET

import numpy as np
import pytest
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st

from frustum import Scene, rotate_x, rotate_y, rotate_z, translate
from frustum.geometry import Mesh, box, cylinder, uv_sphere
from frustum.geometry.csg import difference
from frustum.output.sheet import drawing_sheet
from frustum.output.true_curves import EllipseArc, _merge, find_circles

SVG = "{http://www.w3.org/2000/svg}"
NUMBER = re.compile(r"-?\d+(?:\.\d+)?(?:e-?\d+)?")
ARC = re.compile(r"A(\S+) (\S+) (\S+) ([01]) ([01]) (\S+) (\S+)")


def _group(root: ET.Element, group_id: str) -> ET.Element | None:
    return next((g for g in root.iter(f"{SVG}g") if g.get("id") == group_id), None)


def _view_centre(root: ET.Element, view: str) -> tuple[np.ndarray, float]:
    group = _group(root, f"view-{view}")
    return np.array([float(v) for v in group.get("data-centre").split()]), float(group.get("data-scale"))


def _elements(root: ET.Element, group_id: str, tag: str) -> list[ET.Element]:
    group = _group(root, group_id)
    return [] if group is None else group.findall(f"{SVG}{tag}")


@pytest.mark.parametrize("scale", [2.0, 0.5])
def test_cylinder_seen_along_its_axis_is_a_true_circle(scale):
    scene = Scene()
    scene.add(cylinder(radius=7.0, height=12.0, segments=40), transform=translate(3.0, -2.0, 1.0))
    root = ET.fromstring(drawing_sheet(scene, views=("front",), scale=scale).encode())
    centre, _ = _view_centre(root, "front")
    circles = _elements(root, "front-visible-curves", "circle")
    # the two rims coincide seen end-on: one circle, the far rim (hidden under the near one) is not drawn twice
    assert len(circles) == 1 and not _elements(root, "front-hidden-curves", "circle")
    found = [float(circles[0].get(k)) for k in ("cx", "cy", "r")]
    # the view is centred on the part's bounding box: the axis projects onto the view's centre
    np.testing.assert_allclose(found, [*centre, 7.0 * scale], rtol=0, atol=1e-9)
    # and no straight piece is left of the 40-gon
    assert _group(root, "front-visible") is None


@pytest.mark.parametrize("tilt_deg", [30.0, 55.0])
def test_cylinder_seen_at_an_angle_gives_ellipses_with_the_analytic_axes(tilt_deg):
    radius, height, scale = 5.0, 16.0, 2.0
    tilt = math.radians(tilt_deg)
    scene = Scene()
    scene.add(cylinder(radius=radius, height=height, segments=64), transform=rotate_x(tilt))
    root = ET.fromstring(drawing_sheet(scene, views=("front",), scale=scale).encode())
    centre, _ = _view_centre(root, "front")
    major, minor = radius * scale, radius * scale * math.cos(tilt)
    # the near rim (axis end at +h/2: world z = h/2·cos α > 0, toward the front camera) is a whole ellipse
    ellipses = _elements(root, "front-visible-curves", "ellipse")
    assert len(ellipses) == 1
    e = ellipses[0]
    near = centre + scale * np.array([0.0, height / 2 * math.sin(tilt)])  # world y = −h/2·sin α, paper y down
    np.testing.assert_allclose([float(e.get(k)) for k in ("cx", "cy", "rx", "ry")], [*near, major, minor], atol=1e-9)
    rotation = float(NUMBER.findall(e.get("transform"))[0])
    assert min(abs(rotation) % 180.0, 180.0 - abs(rotation) % 180.0) < 1e-9
    # the far rim: its front half visible, its back half hidden (dashed), both arcs of the analytic ellipse
    far = centre - scale * np.array([0.0, height / 2 * math.sin(tilt)])
    for group, style in (("front-visible-curves", None), ("front-hidden-curves", "dasharray")):
        paths = [p for p in _elements(root, group, "path") if p.get("class") == "arc"]
        assert len(paths) == 1, group
        if style:
            assert _group(root, group).get("stroke-dasharray")
        d = paths[0].get("d")
        points = [np.array([float(v) for v in NUMBER.findall(d)[:2]])]
        for rx, ry, _rotation, _, _, x, y in ARC.findall(d):
            assert float(rx) == pytest.approx(major, abs=1e-9) and float(ry) == pytest.approx(minor, abs=1e-9)
            points.append(np.array([float(x), float(y)]))
        for point in points:  # every end on the ellipse ((x/a)² + (y/b)² = 1 about the far rim's centre)
            x, y = point - far
            assert (x / major) ** 2 + (y / minor) ** 2 == pytest.approx(1.0, abs=1e-9)
        # half of the ellipse each: from one end of the major axis to the other
        sweep = abs(points[-1][0] - points[0][0])
        assert sweep == pytest.approx(2 * major, abs=1e-6)


def test_block_with_a_drilled_hole_circle_in_plan_dashed_lines_in_elevation():
    radius, scale = 5.0, 2.0
    drill = Mesh(
        cylinder(radius, 20.0, 48).vertices @ rotate_x(-math.pi / 2)[:3, :3].T, cylinder(radius, 20.0, 48).faces
    )
    part = difference(box((40.0, 10.0, 30.0)), Mesh(drill.vertices + np.array([8.0, 0.0, 3.0]), drill.faces))
    scene = Scene()
    scene.add(part)
    root = ET.fromstring(drawing_sheet(scene, views=("front", "top"), scale=scale).encode())
    top, _ = _view_centre(root, "top")
    circles = _elements(root, "top-visible-curves", "circle")
    assert len(circles) == 1
    # top view: paper x = x, paper y = z; the block's centre is the view's centre
    expected = [top[0] + 8.0 * scale, top[1] + 3.0 * scale, radius * scale]
    np.testing.assert_allclose([float(circles[0].get(k)) for k in ("cx", "cy", "r")], expected, atol=1e-9)
    # elevation: the hole's walls are hidden, dashed, full height, at x = 8 ± r
    front, _ = _view_centre(root, "front")
    hidden = _group(root, "front-hidden")
    assert hidden.get("stroke-dasharray")
    segments = np.array([float(v) for v in NUMBER.findall(hidden.find(f"{SVG}path").get("d"))]).reshape(-1, 2, 2)
    vertical = segments[np.abs(segments[:, 0, 0] - segments[:, 1, 0]) < 1e-9]
    for x in (8.0 - radius, 8.0 + radius):
        walls = vertical[np.abs(vertical[:, 0, 0] - (front[0] + x * scale)) < 1e-9]
        assert walls.shape[0] >= 1
        assert np.abs(walls[:, 1, 1] - walls[:, 0, 1]).sum() == pytest.approx(10.0 * scale, abs=1e-9)
    assert not _elements(root, "front-visible-curves", "circle")  # the hole's rims are seen edge-on: lines


def test_a_faceted_loop_of_any_mesh_is_found_as_a_circle():
    # trimesh's cylinder (not frustum's): 37 sides, turned and moved; a triangle fan disk with one vertex moved
    # off the circle by 1e-3 of its radius is not a circle
    part = trimesh.creation.cylinder(radius=4.0, height=3.0, sections=37)
    place = translate(10.0, -3.0, 2.0) @ rotate_y(0.7) @ rotate_x(-math.pi / 2)
    circles = find_circles([(Mesh(part.vertices, part.faces), place)])
    assert len(circles) == 2
    for circle in circles:
        assert circle.radius == pytest.approx(4.0, rel=1e-9) and circle.sides == 37
        np.testing.assert_allclose(abs(circle.normal @ (place[:3, :3] @ [0, 0, 1.0])), 1.0, atol=1e-12)
    angles = 2 * math.pi * np.arange(24) / 24
    rim = np.column_stack([np.cos(angles), np.sin(angles), np.zeros(24)])
    faces = np.array([[24, k, (k + 1) % 24] for k in range(24)])
    disk = np.vstack([rim, [0.0, 0.0, 0.0]])
    assert len(find_circles([(Mesh(disk, faces), np.eye(4))])) == 1
    disk[5] *= 1.001
    # no longer a circle: what is left on it is one arc, from vertex 6 round to vertex 4
    (arc,) = find_circles([(Mesh(disk, faces), np.eye(4))])
    assert arc.kind == "arc" and arc.radius == pytest.approx(1.0, abs=1e-12)
    np.testing.assert_allclose(arc.middle, disk[(6 + 22 // 2) % 24], atol=1e-12)
    # and on a sheet the loop is a true circle in the view along its axis
    scene = Scene()
    scene.add(Mesh(part.vertices, part.faces), transform=rotate_x(-math.pi / 2))  # axis along y: the top view
    root = ET.fromstring(drawing_sheet(scene, views=("top",), scale=2.0).encode())
    circles = _elements(root, "top-visible-curves", "circle")
    assert len(circles) == 1 and float(circles[0].get("r")) == pytest.approx(8.0, abs=1e-9)


def test_a_sphere_is_a_circle_with_centre_lines_in_every_view():
    scene = Scene()
    scene.add(box((30.0, 4.0, 30.0)))
    scene.add(uv_sphere(6.0, 32, 16), transform=translate(0.0, 2.0 + 6.0, 0.0))
    root = ET.fromstring(drawing_sheet(scene, views=("front", "top", "right"), scale=2.0).encode())
    for view in ("front", "top", "right"):
        circles = _elements(root, f"{view}-visible-curves", "circle")
        assert [float(c.get("r")) for c in circles] == [pytest.approx(12.0, abs=1e-9)], view
        centre_lines = _group(root, f"{view}-centre-lines")
        assert centre_lines is not None, view


def test_arc_merging_joins_pieces_and_wraps_across_zero():
    two_pi = 2 * math.pi
    steps = np.linspace(0.0, two_pi, 13)
    pieces = np.column_stack([steps[:-1], steps[1:]])
    assert _merge(pieces) == [(0.0, two_pi)]
    # a gap: pieces from 330° round to 30° and from 90° to 180°
    wrap = np.radians([[330.0, 360.0], [0.0, 30.0], [120.0, 90.0], [150.0, 180.0], [120.0, 150.0]])
    merged = _merge(wrap)
    assert len(merged) == 2
    np.testing.assert_allclose(sorted(merged), np.radians([[90.0, 180.0], [330.0, 390.0]]), atol=1e-12)


def test_ellipse_arc_principal_axes():
    arc = EllipseArc(np.zeros(2), np.array([[3.0, 0.0], [1.0, 2.0]]), 0.0, 2 * math.pi)
    major, minor, _ = arc.principal()
    # conjugate semi-diameters: a² + b² = |A|² + |B|², a·b = |det[A B]|
    assert major**2 + minor**2 == pytest.approx(9 + 1 + 4) and major * minor == pytest.approx(6.0)


@settings(max_examples=25, deadline=None)
@given(
    polar=st.floats(0.05, math.pi / 2 - 0.05),
    azimuth=st.floats(0.0, 2 * math.pi),
    radius=st.floats(0.5, 20.0),
)
def test_rim_ellipse_axes_follow_the_tilt_for_any_orientation(polar, azimuth, radius):
    # a disk-like cylinder turned so that its axis makes angle `polar` with the front view's line of sight: the
    # rims' images have semi-axes r·scale and r·scale·cos(polar) (tolerance: round-off of the paper mapping)
    scene = Scene()
    turn = rotate_z(azimuth) @ rotate_x(polar)
    scene.add(cylinder(radius=radius, height=radius / 4, segments=36), transform=turn)
    root = ET.fromstring(drawing_sheet(scene, views=("front",), scale=1.0, paper="A0").encode())
    found = []
    for group in ("front-visible-curves", "front-hidden-curves"):
        for element in _elements(root, group, "ellipse"):
            found.append((float(element.get("rx")), float(element.get("ry"))))
        for path in _elements(root, group, "path"):
            found += [(float(rx), float(ry)) for rx, ry, *_ in ARC.findall(path.get("d"))]
    assert found
    for rx, ry in found:
        assert rx == pytest.approx(radius, rel=1e-9) and ry == pytest.approx(radius * math.cos(polar), rel=1e-9)


def _rounded_plate(width=60.0, depth=40.0, height=8.0, radius=6.0, segments=8) -> Mesh:
    """A plate with rounded corners (an extruded rounded rectangle), axis y: the caps' outlines are lines and
    quarter circles."""
    outline = []
    x, z = width / 2 - radius, depth / 2 - radius
    corners = [(x, z, 0.0), (-x, z, 0.5), (-x, -z, 1.0), (x, -z, 1.5)]
    for cx, cz, start in corners:
        for k in range(segments + 1):
            angle = math.pi * (start + 0.5 * k / segments)
            outline.append((cx + radius * math.cos(angle), cz + radius * math.sin(angle)))
    outline = np.array(outline)
    n = len(outline)
    bottom = np.column_stack([outline[:, 0], np.full(n, -height / 2), outline[:, 1]])
    top = bottom + np.array([0.0, height, 0.0])
    vertices = np.vstack([bottom, top, [[0.0, -height / 2, 0.0], [0.0, height / 2, 0.0]]])
    faces = []
    for k in range(n):
        j = (k + 1) % n
        faces += [[k, n + k, j], [j, n + k, n + j], [2 * n, j, k], [2 * n + 1, n + k, n + j]]
    return Mesh(vertices, np.array(faces))


def test_arcs_of_a_rounded_outline_are_true_arcs_with_a_radius_leader(tmp_path):
    plate = _rounded_plate()
    arcs = [c for c in find_circles([(plate, np.eye(4))]) if c.kind == "arc"]
    assert len(arcs) == 8 and all(abs(c.radius - 6.0) <= 1e-9 for c in arcs)
    scene = Scene()
    scene.add(plate)
    root = ET.fromstring(drawing_sheet(scene, views=("front", "top"), scale=2.0, path=tmp_path / "s.dxf").encode())
    paths = [p for p in _elements(root, "top-visible-curves", "path") if p.get("class") == "arc"]
    assert len(paths) == 4  # the corners (each cap's arc once: the lower one is hidden under the upper)
    for path in paths:
        for rx, ry, *_ in ARC.findall(path.get("d")):
            assert float(rx) == pytest.approx(12.0, abs=1e-9) and float(ry) == pytest.approx(12.0, abs=1e-9)
    radius = [g for g in root.iter(f"{SVG}g") if g.get("class") == "radius"]
    assert [g.find(f"{SVG}text").text for g in radius] == ["4× R6"]
    import ezdxf

    document = ezdxf.readfile(tmp_path / "s.dxf")
    assert not document.audit().has_errors
    measured = [d.get_measurement() for d in document.modelspace().query("DIMENSION") if d.dimtype == 4]
    assert measured == [pytest.approx(6.0, abs=1e-9)]
    assert len(document.modelspace().query("ARC[layer=='VISIBLE']")) == 4


def test_a_torus_seen_along_its_axis_has_true_circle_outlines():
    from frustum.geometry import torus

    scene = Scene()
    scene.add(torus(10.0, 3.0, 48, 24), transform=translate(5.0, 0.0, 0.0) @ rotate_x(-math.pi / 2))  # axis y
    circles = [c for c in find_circles([(scene.items[0].mesh, scene.items[0].world_from_model)])]
    assert sorted((c.kind, round(c.radius, 9)) for c in circles) == [("torus", 7.0), ("torus", 13.0)]
    root = ET.fromstring(drawing_sheet(scene, views=("front", "top"), scale=2.0).encode())
    top, _ = _view_centre(root, "top")
    found = sorted(
        (float(c.get("r")), float(c.get("cx")), float(c.get("cy")))
        for c in _elements(root, "top-visible-curves", "circle")
    )
    np.testing.assert_allclose(found, [[14.0, *top], [26.0, *top]], atol=1e-9)
    # seen from the side it stays as drawn (no circle), and its diameters are stated in the top view
    assert not _elements(root, "front-visible-curves", "circle")
    texts = sorted(g.find(f"{SVG}text").text for g in root.iter(f"{SVG}g") if g.get("class") == "diameter")
    assert texts == ["⌀14", "⌀26"]
