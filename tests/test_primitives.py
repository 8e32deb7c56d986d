"""Primitives: counts, exact polyhedral areas/volumes, convergence to the smooth solids, trimesh as oracle,
outward normals and UVs, and bad resolution parameters."""

from __future__ import annotations

import math

import numpy as np
import pytest
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st

from frustum import GeometryError
from frustum.geometry import Mesh
from frustum.geometry import primitives as prim

CLOSED = {
    "box": lambda: prim.box(size=(1.0, 2.0, 3.0), center=(1.0, -2.0, 0.5)),
    "uv_sphere": lambda: prim.uv_sphere(radius=1.5, segments=24, rings=12),
    "icosphere": lambda: prim.icosphere(radius=0.7, subdivisions=2),
    "cylinder": lambda: prim.cylinder(radius=0.5, height=2.0, segments=20),
    "cone": lambda: prim.cone(radius=1.0, height=1.5, segments=20),
    "torus": lambda: prim.torus(major_radius=2.0, minor_radius=0.5, major_segments=24, minor_segments=12),
    "arrow": lambda: prim.arrow(direction=(1.0, 2.0, -0.5), origin=(3.0, 0.0, 0.0)),
}


def _oracle(mesh: Mesh) -> trimesh.Trimesh:
    # trimesh welds seam vertices by position (merge_vertices) before judging closedness
    tm = trimesh.Trimesh(np.array(mesh.vertices), np.array(mesh.faces), process=False)
    tm.merge_vertices(merge_tex=True, merge_norm=True)
    return tm


@pytest.mark.parametrize("name", sorted(CLOSED))
def test_closed_primitives_are_watertight_outward_and_match_trimesh(name):
    mesh = CLOSED[name]()
    oracle = _oracle(mesh)
    assert mesh.is_watertight and oracle.is_watertight and oracle.is_winding_consistent
    assert mesh.volume > 0.0  # outward normals
    assert mesh.volume == pytest.approx(oracle.volume, rel=1e-12)
    assert mesh.area == pytest.approx(oracle.area, rel=1e-12)
    # stored (analytic) vertex normals agree with every face they touch: no inward normal anywhere
    corner_dot = np.einsum("fkj,fj->fk", mesh.vertex_normals[mesh.faces], mesh.face_normals)
    assert (corner_dot > 0.0).all()
    assert mesh.uvs is not None and mesh.uvs.shape == (mesh.vertex_count, 2)
    assert np.isfinite(mesh.uvs).all()


def test_box_is_exact():
    mesh = prim.box(size=(1.0, 2.0, 3.0), center=(1.0, -2.0, 0.5))
    assert (mesh.vertex_count, mesh.face_count) == (24, 12)
    np.testing.assert_array_equal(mesh.bounds, [[0.5, -3.0, -1.0], [1.5, -1.0, 2.0]])
    assert mesh.volume == pytest.approx(6.0, rel=1e-15)
    assert mesh.area == pytest.approx(2 * (2 + 6 + 3), rel=1e-15)
    np.testing.assert_allclose(mesh.vertex_normals[mesh.faces].mean(axis=1), mesh.face_normals, atol=1e-15)
    assert set(map(tuple, mesh.uvs)) == {(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)}


def _polygon_area(n, r):
    return 0.5 * n * r * r * math.sin(2 * math.pi / n)  # inscribed regular n-gon


@pytest.mark.parametrize("n", [3, 7, 32])
def test_cylinder_cone_disk_are_exact_polyhedra(n):
    r, h = 0.5, 2.0
    cyl = prim.cylinder(radius=r, height=h, segments=n)
    assert cyl.face_count == 4 * n
    assert cyl.volume == pytest.approx(_polygon_area(n, r) * h, rel=1e-13)
    side = n * 2 * r * math.sin(math.pi / n) * h
    assert cyl.area == pytest.approx(side + 2 * _polygon_area(n, r), rel=1e-13)
    np.testing.assert_allclose(cyl.bounds[:, 2], [-h / 2, h / 2])
    open_cyl = prim.cylinder(radius=r, height=h, segments=n, caps=False)
    assert open_cyl.face_count == 2 * n and not open_cyl.is_watertight
    cone = prim.cone(radius=r, height=h, segments=n)
    assert cone.face_count == 2 * n
    assert cone.volume == pytest.approx(_polygon_area(n, r) * h / 3, rel=1e-13)
    disk = prim.disk(radius=r, segments=n)
    assert disk.face_count == n and disk.area == pytest.approx(_polygon_area(n, r), rel=1e-13)
    np.testing.assert_array_equal(disk.vertex_normals, np.tile([0.0, 0.0, 1.0], (disk.vertex_count, 1)))
    assert (disk.face_normals[:, 2] > 0.99).all()


@pytest.mark.parametrize(("segments", "rings"), [(8, 4), (32, 16), (128, 64)])
def test_uv_sphere_counts_normals_and_convergence(segments, rings):
    r = 2.0
    mesh = prim.uv_sphere(radius=r, segments=segments, rings=rings)
    assert mesh.face_count == 2 * segments * (rings - 1)
    assert mesh.welded().vertex_count == segments * (rings - 1) + 2
    np.testing.assert_allclose(mesh.vertex_normals, mesh.vertices / r, atol=1e-15)
    np.testing.assert_allclose(np.linalg.norm(mesh.vertices, axis=1), r, rtol=1e-15)
    # inscribed polyhedron: below the sphere, with error O(1/n²)
    h = (math.pi / rings) ** 2 + (2 * math.pi / segments) ** 2
    assert 0 < 4 / 3 * math.pi * r**3 - mesh.volume < 0.5 * h * 4 / 3 * math.pi * r**3
    assert 0 < 4 * math.pi * r**2 - mesh.area < 0.5 * h * 4 * math.pi * r**2
    assert mesh.uvs.min() == 0.0 and mesh.uvs.max() == 1.0


@pytest.mark.parametrize("k", [0, 1, 3])
def test_icosphere_counts_and_convergence(k):
    mesh = prim.icosphere(radius=1.0, subdivisions=k)
    assert mesh.face_count == 20 * 4**k
    assert mesh.welded().vertex_count == 10 * 4**k + 2
    np.testing.assert_allclose(np.linalg.norm(mesh.vertices, axis=1), 1.0, rtol=1e-15)
    np.testing.assert_allclose(mesh.vertex_normals, mesh.vertices, atol=1e-15)
    error = 4 / 3 * math.pi - mesh.volume
    assert 0 < error < 2.5 / 4**k  # halving the edge quarters the error: 1.65, 0.53, 0.04 measured
    # no triangle wraps around the texture seam
    u = mesh.uvs[mesh.faces][:, :, 0]
    assert (u.max(axis=1) - u.min(axis=1)).max() <= 0.5


def test_icosphere_matches_trimesh_vertex_set():
    ours = prim.icosphere(subdivisions=2).welded()
    theirs = trimesh.creation.icosphere(subdivisions=2)
    assert ours.vertex_count == len(theirs.vertices) and ours.face_count == len(theirs.faces)
    assert ours.volume == pytest.approx(theirs.volume, rel=1e-12)


def test_torus_converges_to_pappus():
    big, small = 2.0, 0.5
    coarse = prim.torus(major_radius=big, minor_radius=small, major_segments=16, minor_segments=8)
    fine = prim.torus(major_radius=big, minor_radius=small, major_segments=128, minor_segments=64)
    volume, area = 2 * math.pi**2 * big * small**2, 4 * math.pi**2 * big * small
    assert fine.face_count == 2 * 128 * 64
    assert abs(fine.volume - volume) < abs(coarse.volume - volume) / 50  # O(1/n²): 64 times smaller
    assert fine.volume == pytest.approx(volume, rel=3e-3)  # cross-section: inscribed 64-gon, −1.6e-3
    assert fine.area == pytest.approx(area, rel=3e-3)
    # normals point from the tube's centre circle outward
    ring = fine.vertices.copy()
    ring[:, 2] = 0.0
    centre = ring / np.linalg.norm(ring, axis=1)[:, None] * big
    np.testing.assert_allclose(fine.vertex_normals, (fine.vertices - centre) / small, atol=1e-12)


def test_plane_and_grid():
    plane = prim.plane(size=(2.0, 4.0), divisions=(3, 2))
    assert plane.face_count == 2 * 3 * 2 and plane.vertex_count == 4 * 3
    assert plane.area == pytest.approx(8.0)
    np.testing.assert_array_equal(plane.bounds, [[-1.0, -2.0, 0.0], [1.0, 2.0, 0.0]])
    assert (plane.face_normals[:, 2] == 1.0).all()
    np.testing.assert_allclose(plane.uvs, (plane.vertices[:, :2] + [1.0, 2.0]) / [2.0, 4.0])
    assert prim.grid().face_count == 200
    assert prim.plane(size=3.0, divisions=5).area == pytest.approx(9.0)


def test_arrow_and_axes():
    arrow = prim.arrow(length=2.0, direction=(0.0, 3.0, 4.0), origin=(1.0, 1.0, 1.0))
    tip = np.array([1.0, 1.0, 1.0]) + 2.0 * np.array([0.0, 0.6, 0.8])
    assert np.linalg.norm(arrow.vertices - tip, axis=1).min() < 1e-12
    # every vertex lies between the base plane and the tip along the direction
    along = (arrow.vertices - [1.0, 1.0, 1.0]) @ np.array([0.0, 0.6, 0.8])
    assert along.min() > -1e-12 and along.max() == pytest.approx(2.0)
    down = prim.arrow(direction=(0.0, 0.0, -1.0))
    assert down.bounds[0, 2] == pytest.approx(-1.0) and down.volume > 0
    axes = prim.axes(length=1.5)
    assert axes.vertex_colors is not None and axes.vertex_colors.shape == (axes.vertex_count, 3)
    x_part = axes.vertices[axes.vertex_colors[:, 0] == 1.0]
    assert x_part[:, 0].max() == pytest.approx(1.5)


@settings(max_examples=15)
@given(segments=st.integers(3, 40), rings=st.integers(2, 20), radius=st.floats(0.01, 100.0))
def test_uv_sphere_is_closed_and_outward_for_any_resolution(segments, rings, radius):
    mesh = prim.uv_sphere(radius=radius, segments=segments, rings=rings)
    assert mesh.is_watertight
    assert 0 < mesh.volume < 4 / 3 * math.pi * radius**3


def test_every_builder_runs_with_defaults():
    for build in (
        prim.box,
        prim.plane,
        prim.grid,
        prim.uv_sphere,
        prim.icosphere,
        prim.cylinder,
        prim.cone,
        prim.torus,
        prim.disk,
        prim.arrow,
    ):
        assert build().face_count > 0
    assert prim.axes().face_count > 0


@pytest.mark.parametrize(
    ("call", "fragment"),
    [
        (lambda: prim.uv_sphere(segments=2), "uv_sphere: segments = 2 is below 3"),
        (lambda: prim.uv_sphere(rings=1), "uv_sphere: rings = 1 is below 2"),
        (lambda: prim.uv_sphere(radius=0.0), r"uv_sphere: radius = 0\.0 is not positive"),
        (lambda: prim.uv_sphere(radius=float("nan")), "radius = nan is not finite"),
        (lambda: prim.uv_sphere(segments=8.0), r"segments = 8\.0 is not an integer"),
        (lambda: prim.icosphere(subdivisions=-1), "subdivisions = -1 is below 0"),
        (lambda: prim.icosphere(subdivisions=9), "subdivisions = 9 is above 8"),
        (lambda: prim.box(size=(1.0, -1.0, 1.0)), r"box: size = \(1\.0, -1\.0, 1\.0\) has a component <= 0"),
        (lambda: prim.box(center=(0.0, 0.0)), "box: center = .* has shape"),
        (lambda: prim.cylinder(segments=True), "segments = True is not an integer"),
        (lambda: prim.cylinder(caps="yes"), "caps = 'yes' is not a boolean"),
        (lambda: prim.cone(height=-1.0), r"cone: height = -1\.0 is not positive"),
        (lambda: prim.torus(major_radius=1.0, minor_radius=1.0), r"minor_radius = 1\.0 is not below major_radius"),
        (lambda: prim.torus(minor_segments=2), "minor_segments = 2 is below 3"),
        (lambda: prim.disk(segments=0), "disk: segments = 0 is below 3"),
        (lambda: prim.plane(divisions=(0, 2)), r"divisions\[0\] = 0 is below 1"),
        (lambda: prim.plane(size=(1.0, 2.0, 3.0)), "size = .* is not one or two values"),
        (lambda: prim.arrow(head_length=2.0), r"head_length = 2\.0 is not below length = 1\.0"),
        (lambda: prim.arrow(shaft_radius=0.1), r"shaft_radius = 0\.1 is not below head_radius"),
        (lambda: prim.arrow(direction=(0.0, 0.0, 0.0)), "direction = .* has zero length"),
    ],
)
def test_bad_parameters_raise_geometry_error_naming_them(call, fragment):
    with pytest.raises(GeometryError, match=fragment):
        call()
