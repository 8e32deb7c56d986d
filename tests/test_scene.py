"""The scene graph (``Node``, ``Scene``), polylines, exploded and cutaway views."""

from __future__ import annotations

import math

import numpy as np
import pytest
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st

from frustum import FrustumError, GeometryError
from frustum.geometry import Mesh, Polyline
from frustum.scene import Node, Scene, cutaway, exploded
from frustum.shading import Material, PointLight
from frustum.transforms import compose, rotate, rotate_z, scale, translate


def box_mesh(extents=(1.0, 1.0, 1.0)) -> Mesh:
    box = trimesh.creation.box(extents=extents)
    return Mesh(box.vertices, box.faces)


def assembly() -> tuple[Scene, Mesh]:
    """base + arm (a sub-assembly of two links), the second link an instance of the first's mesh."""
    link = box_mesh((1.0, 0.2, 0.2))
    scene = Scene()
    scene.add(box_mesh((2.0, 0.5, 2.0)), Material(color=(0.5, 0.5, 0.5)), name="base")
    arm = scene.add(Node("arm", transform=translate(0, 1.0, 0) @ rotate_z(0.3), material=Material(color=(1, 0, 0))))
    arm.add(Node("link1", transform=translate(0.5, 0, 0), geometry=link))
    arm.add(Node("link2", transform=translate(1.5, 0, 0) @ rotate_z(0.5), geometry=link))
    return scene, link


def test_world_transforms_compose_down_the_parent_chain():
    scene, _ = assembly()
    placed = {p.node.name: p.world_from_model for p in scene.walk()}
    arm = translate(0, 1.0, 0) @ rotate_z(0.3)
    assert np.allclose(placed["link2"], arm @ translate(1.5, 0, 0) @ rotate_z(0.5), atol=1e-15)
    assert np.allclose(placed["link1"], compose(translate(0.5, 0, 0), arm), atol=1e-15)
    names = [p.node.name for p in scene.walk()]
    assert names == ["base", "arm", "link1", "link2"]  # depth-first, parents first
    node, world = next(iter(scene.walk()))  # unpacks as (node, world_from_model)
    assert node.name == "base" and world.shape == (4, 4)


def test_items_inherit_materials_and_share_instanced_meshes():
    scene, link = assembly()
    items = scene.items
    assert len(items) == 3 and items[1].mesh is link and items[2].mesh is link
    assert tuple(items[1].material.color) == (1.0, 0.0, 0.0)  # inherited from "arm"
    assert tuple(items[0].material.color) == (0.5, 0.5, 0.5)


def test_find_by_path_and_a_clear_error_for_a_missing_name():
    scene, _ = assembly()
    assert scene.find("arm/link2").name == "link2"
    with pytest.raises(FrustumError, match=r"no 'link3' under 'arm'; children: 'link1', 'link2'"):
        scene.find("arm/link3")
    with pytest.raises(FrustumError, match="without '/'"):
        Node("a/b")


def test_lights_on_nodes_are_moved_into_world_coordinates():
    scene = Scene()
    lamp = scene.add(Node("lamp", transform=translate(1, 2, 3) @ rotate(np.array([0, 0, 1.0]), math.pi / 2)))
    lamp.add_light(PointLight(position=(1.0, 0.0, 0.0)))
    (light,) = scene.world_lights()
    assert np.allclose(light.position, (1.0, 3.0, 3.0))


def centroid(mesh: Mesh, world: np.ndarray) -> np.ndarray:
    points = mesh.vertices @ world[:3, :3].T + world[:3, 3]
    corners = points[mesh.faces]
    areas = 0.5 * np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]), axis=1)
    return (areas[:, None] * corners.mean(axis=1)).sum(axis=0) / areas.sum()


def test_exploding_by_zero_is_the_identity_and_the_original_is_untouched():
    scene, _ = assembly()
    before = [p.world_from_model.copy() for p in scene.walk()]
    same = exploded(scene, 0.0)
    assert all((a == b.world_from_model).all() for a, b in zip(before, same.walk(), strict=True))
    exploded(scene, 2.0)
    assert all((a == b.world_from_model).all() for a, b in zip(before, scene.walk(), strict=True))


def test_parts_move_away_from_the_assembly_centre_by_the_factor():
    scene = Scene()
    a, b = box_mesh(), box_mesh((0.5, 0.5, 0.5))
    scene.add(a, transform=translate(2.0, 0.0, 0.0), name="a")
    scene.add(b, transform=translate(-1.0, 1.0, 0.0) @ scale(2.0, 1.0, 1.0), name="b")
    centre = np.array([0.5, 0.0, 0.0])
    moved = exploded(scene, 0.5, center=centre)
    for placed_before, placed_after in zip(scene.walk(), moved.walk(), strict=True):
        mesh = placed_before.node.geometry
        c0 = centroid(mesh, placed_before.world_from_model)
        c1 = centroid(mesh, placed_after.world_from_model)
        assert np.allclose(c1, c0 + 0.5 * (c0 - centre), atol=1e-12)


def test_sub_assemblies_explode_within_themselves():
    scene, _ = assembly()
    moved = exploded(scene, 1.0)
    before = {p.node.name: p.world_from_model for p in scene.walk()}
    after = {p.node.name: p.world_from_model for p in moved.walk()}
    link = scene.find("arm/link1").geometry
    arm_shift = centroid(link, after["link1"]) - centroid(link, before["link1"])
    # link1 moves with the arm and, inside the arm, away from the arm's centroid: not just the arm's shift
    assert np.linalg.norm(arm_shift) > 0.1
    gap_before = np.linalg.norm(centroid(link, before["link2"]) - centroid(link, before["link1"]))
    gap_after = np.linalg.norm(centroid(link, after["link2"]) - centroid(link, after["link1"]))
    assert gap_after == pytest.approx(2.0 * gap_before)


@settings(max_examples=25, deadline=None)
@given(
    offset=st.floats(-0.4, 0.4),
    normal=st.tuples(st.floats(-1, 1), st.floats(-1, 1), st.floats(-1, 1)).filter(
        lambda n: math.sqrt(sum(c * c for c in n)) > 0.2
    ),
)
def test_a_cutaway_never_leaves_geometry_on_the_removed_side(offset, normal):
    scene = Scene()
    scene.add(box_mesh(), transform=translate(0.1, 0.0, 0.0), name="box")
    unit = np.asarray(normal) / np.linalg.norm(normal)
    point = offset * unit
    cut = cutaway(scene, plane=(point, normal))
    for item in cut.items:
        signed = (item.mesh.vertices - point) @ unit
        assert signed.max() <= 1e-9


def test_capped_cut_of_a_closed_box_is_a_closed_half_box():
    scene = Scene()
    scene.add(box_mesh((2.0, 2.0, 2.0)))
    body, section = cutaway(scene, plane=((0.0, 0.0, 0.0), (1.0, 0.0, 0.0))).items  # the cap is its own node
    whole = Mesh.merged(body.mesh, section.mesh)
    half = trimesh.Trimesh(whole.vertices, whole.faces)
    half.merge_vertices()
    assert half.is_watertight and half.volume == pytest.approx(4.0)
    (open_item,) = cutaway(scene, plane=((0.0, 0.0, 0.0), (1.0, 0.0, 0.0)), cap=False).items
    assert not trimesh.Trimesh(open_item.mesh.vertices, open_item.mesh.faces).is_watertight


def test_box_cutaway_removes_the_inside_and_ghosts_it_on_request():
    scene = Scene()
    scene.add(box_mesh((2.0, 2.0, 2.0)), Material(color=(0.2, 0.4, 0.9)))
    low, high = np.array([0.0, 0.0, 0.0]), np.array([3.0, 3.0, 3.0])
    cut = cutaway(scene, box=(low, high), ghost=0.3)
    solid, section, ghost = cut.items
    centroids = solid.mesh.vertices[solid.mesh.faces].mean(axis=1)
    assert not ((centroids > low + 1e-9) & (centroids < high - 1e-9)).all(axis=1).any()
    whole = Mesh.merged(solid.mesh, section.mesh)
    assert trimesh.Trimesh(whole.vertices, whole.faces).volume == pytest.approx(7.0)
    assert section.material.hatch == 6.0
    assert ghost.material.opacity == 0.3 and tuple(ghost.material.color) == pytest.approx((0.2, 0.4, 0.9))
    assert trimesh.Trimesh(ghost.mesh.vertices, ghost.mesh.faces).volume == pytest.approx(1.0)
    open_cut = cutaway(scene, box=(low, high), cap=False)
    (item,) = open_cut.items
    centroids = item.mesh.vertices[item.mesh.faces].mean(axis=1)
    assert not ((centroids > low + 1e-9) & (centroids < high - 1e-9)).all(axis=1).any()


def test_polylines_count_segments_and_are_placed_separately_from_meshes():
    assert Polyline(np.zeros((5, 3))).segments.shape == (4, 2)
    assert Polyline(np.zeros((5, 3)), closed=True).segments.tolist()[-1] == [4, 0]
    assert Polyline(np.zeros((1, 3))).segments.shape == (0, 2)
    scene = Scene()
    scene.add(Polyline([[0, 0, 0], [1, 0, 0]]), name="line")
    scene.add(box_mesh())
    assert len(scene.items) == 1 and len(scene.polylines) == 1


PROJECTIVE = np.eye(4)
PROJECTIVE[3, 2] = -1.0


@pytest.mark.parametrize(
    ("build", "error", "fragment"),
    [
        (lambda: Scene().add("mesh"), FrustumError, "is not a Mesh, Polyline or Node"),
        (lambda: Scene().add(box_mesh(), transform=PROJECTIVE), FrustumError, "projective"),
        (lambda: Node("x", geometry=[1, 2]), FrustumError, "not a Mesh or Polyline"),
        (lambda: Node("x").add_light("sun"), FrustumError, "is not a light"),
        (lambda: Polyline([[0, 0, np.nan]]), GeometryError, "points"),
        (lambda: cutaway(Scene(), plane=((0, 0, 0), (0, 0, 0))), GeometryError, "zero length"),
        (lambda: cutaway(Scene(), box=((0, 0, 0), (1, -1, 1))), GeometryError, "is empty"),
        (lambda: cutaway(Scene()), GeometryError, "exactly one of"),
        (lambda: cutaway(Scene(), plane=((0, 0, 0), (0, 0, 1)), ghost=1.5), GeometryError, "ghost = 1.5"),
        (lambda: exploded("scene", 1.0), FrustumError, "not a Scene or Node"),
    ],
)
def test_bad_scene_input_raises_named_errors(build, error, fragment):
    with pytest.raises(error, match=fragment):
        build()


def test_polylines_from_curves_segments_and_control_polygons():
    from frustum.geometry import BezierCurve, NURBSCurve

    curve = BezierCurve([[0, 0], [1, 2], [3, -1], [4, 1]])  # 2D: z = 0 is added
    line = Polyline.from_curve(curve, tolerance=1e-4)
    assert line.points.shape[1] == 3 and (line.points[:, 2] == 0).all()
    assert np.allclose(line.points[[0, -1], :2], [[0, 0], [4, 1]])
    exact = curve.evaluate(np.linspace(0, 1, 50))
    sampled = Polyline.from_curve(curve, samples=50)
    assert np.allclose(sampled.points[:, :2], exact)
    polygon = Polyline.control_polygon(curve)
    assert polygon.segments.shape == (3, 2) and not polygon.markers
    assert Polyline.control_polygon(curve, markers=True).markers
    circle = Polyline.from_curve(NURBSCurve.circle(2.0, (0.0, 0.0)), tolerance=1e-6)
    assert np.allclose(np.linalg.norm(circle.points[:, :2], axis=1), 2.0)
    net = Polyline.from_segments([[[0, 0, 0], [1, 0, 0]], [[0, 1, 0], [1, 1, 0]]])
    assert net.segments.tolist() == [[0, 1], [2, 3]]
    with pytest.raises(GeometryError, match="pairs index"):
        Polyline([[0, 0, 0], [1, 0, 0]], pairs=[[0, 2]])
    with pytest.raises(GeometryError, match=r"segments has shape \(2, 3\)"):
        Polyline.from_segments(np.zeros((2, 3)))


def test_section_caps_are_separate_hatched_nodes_in_the_cutting_plane():
    from frustum import Camera, render_svg

    scene = Scene()
    scene.add(box_mesh((2.0, 2.0, 2.0)), Material(color=(0.3, 0.5, 0.9)), name="block")
    cut = cutaway(scene, plane=((0.0, 0.0, 0.25), (0.0, 0.0, 1.0)), hatch=4.0)
    section = cut.find("block/block:section")
    corners = section.geometry.vertices[section.geometry.faces]
    assert np.allclose(corners[..., 2], 0.25) and section.material.hatch == 4.0
    area = 0.5 * np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]), axis=1).sum()
    assert area == pytest.approx(4.0)  # the 2 x 2 cross-section
    normals = section.geometry.face_normals
    assert np.allclose(normals, (0.0, 0.0, 1.0))  # facing the removed side, toward a viewer looking in
    camera = Camera.look_at((3, 4, 5), (0, 0, 0), (0, 1, 0), width=120, height=90)
    svg = render_svg(cut, camera, fill=True)
    assert '<pattern id="hatch-0"' in svg and svg.count("url(#hatch-0)") == len(section.geometry.faces)
    plain = cutaway(scene, plane=((0.0, 0.0, 0.25), (0.0, 0.0, 1.0)), hatch=None)
    assert plain.find("block/block:section").material.hatch is None
    with pytest.raises(GeometryError, match=r"hatch = -1\.0"):
        cutaway(scene, plane=((0, 0, 0), (0, 0, 1)), hatch=-1)
