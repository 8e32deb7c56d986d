"""Mesh: validation, read-only arrays, normals; derived data and operations against trimesh; the seed's strips,
fans and grids."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st
from tests.strategies import angles, axes, scale_factors, vectors

from frustum import GeometryError, TransformError
from frustum.geometry import Mesh
from frustum.transforms import apply, apply_to_normals, compose, rotate, scale, translate


def test_vertex_normals_are_area_weighted_face_normals():
    # two faces at a shared edge: a big one in z = 0 (normal +z) and a small one in x = 0 (normal +x)
    vertices = [[0.0, 0.0, 0.0], [0.0, 2.0, 0.0], [2.0, 0.0, 0.0], [0.0, 0.0, 1.0]]
    mesh = Mesh(vertices, [[0, 2, 1], [0, 1, 3]])
    # face 0: cross = (0, 0, 4) (area 2); face 1: cross = (2, 0, 0) (area 1); shared vertices get (2, 0, 4)/|.|
    np.testing.assert_allclose(mesh.vertex_normals[0], np.array([2.0, 0.0, 4.0]) / np.sqrt(20.0), rtol=0, atol=1e-15)
    np.testing.assert_array_equal(mesh.vertex_normals[2], [0.0, 0.0, 1.0])
    np.testing.assert_array_equal(mesh.vertex_normals[3], [1.0, 0.0, 0.0])


def test_vertex_normals_match_trimesh_on_a_sphere():
    sphere = trimesh.creation.icosphere(subdivisions=2)
    mesh = Mesh(sphere.vertices, sphere.faces)
    radial = sphere.vertices / np.linalg.norm(sphere.vertices, axis=1)[:, None]
    assert (np.einsum("ij,ij->i", mesh.vertex_normals, radial) > 0.999).all()  # icosphere facets: within ~2.5°


def test_given_normals_are_normalized_and_arrays_are_read_only():
    mesh = Mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]], vertex_normals=[[0, 0, 2], [0, 0, 3], [0, 0, 1]])
    np.testing.assert_array_equal(mesh.vertex_normals, np.tile([0.0, 0.0, 1.0], (3, 1)))
    for array in (mesh.vertices, mesh.faces, mesh.vertex_normals, mesh.face_normals):
        assert not array.flags.writeable
    with pytest.raises(AttributeError):
        mesh.vertices = np.zeros((3, 3))  # frozen


def test_unused_vertex_gets_a_finite_default_normal_and_empty_mesh_is_valid():
    mesh = Mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0], [5, 5, 5]], [[0, 1, 2]])
    np.testing.assert_array_equal(mesh.vertex_normals[3], [0.0, 0.0, 1.0])
    empty = Mesh(np.empty((0, 3)), np.empty((0, 3), dtype=np.int64))
    assert empty.face_count == 0 and empty.vertex_normals.shape == (0, 3)


@pytest.mark.parametrize(
    ("vertices", "faces", "normals", "fragment"),
    [
        ([[0, 0, 0], [1, 0, 0]], [[0, 1, 2]], None, r"faces\[0\] = \[0, 1, 2\] indexes outside the 2 vertices"),
        ([[0, 0, 0], [1, 0, np.inf], [0, 1, 0]], [[0, 1, 2]], None, r"vertices\[1\] = .* is not finite"),
        ([[0, 0], [1, 0], [0, 1]], [[0, 1, 2]], None, r"vertices has shape \(3, 2\)"),
        ([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0.0, 1.0, 2.0]], None, "dtype float64"),
        ([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, -1]], None, "indexes outside"),
        ([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]], [[0, 0, 1]], "1 rows for 3 vertices"),
        (
            [[0, 0, 0], [1, 0, 0], [0, 1, 0]],
            [[0, 1, 2]],
            [[0, 0, 1], [0, 0, 0], [0, 0, 1]],
            r"vertex_normals\[1\].*zero",
        ),
        ([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]], [[0, 0, 1], [0, np.nan, 1], [0, 0, 1]], "not finite"),
    ],
)
def test_mesh_rejects_bad_input(vertices, faces, normals, fragment):
    with pytest.raises(GeometryError, match=fragment):
        Mesh(vertices, faces, vertex_normals=normals)


# --- derived data against trimesh ---------------------------------------------------------------------------


def _trimesh_of(mesh: Mesh) -> trimesh.Trimesh:
    return trimesh.Trimesh(np.array(mesh.vertices), np.array(mesh.faces), process=False)


def _lumpy_sphere() -> Mesh:
    # an icosphere pushed off-centre and scaled unevenly: closed, no symmetry to hide mistakes
    sphere = trimesh.creation.icosphere(subdivisions=2)
    vertices = sphere.vertices * [1.0, 2.0, 0.5] + [3.0, -1.0, 2.0]
    return Mesh(vertices, sphere.faces)


def test_area_volume_centroid_match_trimesh():
    mesh = _lumpy_sphere()
    oracle = _trimesh_of(mesh)
    assert mesh.area == pytest.approx(oracle.area, rel=1e-12)
    assert mesh.volume == pytest.approx(oracle.volume, rel=1e-12)
    np.testing.assert_allclose(mesh.centroid, oracle.centroid, rtol=0, atol=1e-12)
    np.testing.assert_allclose(mesh.face_areas, oracle.area_faces, rtol=1e-12, atol=0)
    np.testing.assert_allclose(mesh.face_normals, oracle.face_normals, rtol=0, atol=1e-12)


def test_edges_match_trimesh_unique_edges():
    mesh = _lumpy_sphere()
    oracle = np.unique(np.sort(_trimesh_of(mesh).edges_unique, axis=1), axis=0)
    np.testing.assert_array_equal(mesh.edges, oracle)
    assert mesh.edges.shape == (mesh.vertex_count + mesh.face_count - 2, 2)  # Euler: V − E + F = 2


def test_watertightness_matches_trimesh_and_open_mesh_has_no_volume():
    closed = _lumpy_sphere()
    opened = Mesh(closed.vertices, closed.faces[1:])
    assert closed.is_watertight and _trimesh_of(closed).is_watertight
    assert not opened.is_watertight and not _trimesh_of(opened).is_watertight
    with pytest.raises(GeometryError, match="not watertight"):
        _ = opened.volume
    assert not Mesh(np.empty((0, 3)), np.empty((0, 3), dtype=np.int64)).is_watertight


def test_split_seam_vertices_still_count_as_closed():
    # a tetrahedron whose vertex 0 is duplicated for one face (as a UV seam would do)
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [0, 0, 0]], dtype=float)
    faces = [[0, 2, 1], [0, 1, 3], [4, 3, 2], [1, 2, 3]]
    mesh = Mesh(v, faces)
    assert mesh.is_watertight
    assert mesh.volume == pytest.approx(1.0 / 6.0, rel=1e-14)


def test_centroid_of_degenerate_and_empty_meshes():
    line = Mesh([[0, 0, 0], [1, 0, 0], [2, 0, 0]], [[0, 1, 2]])
    np.testing.assert_array_equal(line.centroid, [1.0, 0.0, 0.0])
    assert np.isnan(Mesh(np.empty((0, 3)), np.empty((0, 3), dtype=np.int64)).centroid).all()


@st.composite
def affine_matrices(draw):
    factors = [draw(scale_factors) for _ in range(3)]
    return compose(scale(*factors), rotate(draw(axes()), draw(angles)), translate(*draw(vectors())))


@settings(max_examples=40)
@given(matrix=affine_matrices())
def test_transformed_matches_trimesh_and_keeps_normals_outward(matrix):
    mesh = _lumpy_sphere()
    moved = mesh.transformed(matrix)
    oracle = _trimesh_of(mesh)
    oracle.apply_transform(matrix)  # trimesh also reverses winding for det < 0
    np.testing.assert_allclose(moved.vertices, apply(matrix, mesh.vertices), rtol=0, atol=1e-9)
    np.testing.assert_allclose(moved.vertex_normals, apply_to_normals(matrix, mesh.vertex_normals), atol=1e-12)
    assert moved.volume > 0.0
    assert moved.volume == pytest.approx(oracle.volume, rel=1e-9)
    assert moved.volume == pytest.approx(mesh.volume * abs(np.linalg.det(matrix[:3, :3])), rel=1e-9)
    # normals still agree with the faces' geometric normals (outward)
    corner_normals = moved.vertex_normals[moved.faces].sum(axis=1)
    assert (np.einsum("ij,ij->i", corner_normals, moved.face_normals) > 0).all()


def test_transformed_by_a_reflection_flips_winding_and_keeps_uvs():
    mesh = Mesh(_lumpy_sphere().vertices, _lumpy_sphere().faces, uvs=np.zeros((162, 2)))
    mirrored = mesh.transformed(np.diag([-1.0, 1.0, 1.0, 1.0]))
    np.testing.assert_array_equal(mirrored.faces, mesh.faces[:, ::-1])
    assert mirrored.uvs is not None and mirrored.volume == pytest.approx(mesh.volume, rel=1e-12)
    with pytest.raises(TransformError):
        mesh.transformed(np.diag([1.0, 0.0, 1.0, 1.0]))


def test_flipped_negates_volume_and_normals_and_is_an_involution():
    mesh = _lumpy_sphere()
    flipped = mesh.flipped()
    assert flipped.volume == pytest.approx(-mesh.volume, rel=1e-12)
    np.testing.assert_allclose(flipped.vertex_normals, -mesh.vertex_normals, rtol=0, atol=1e-15)
    np.testing.assert_array_equal(flipped.flipped().faces, mesh.faces)


def test_merged_reindexes_faces_and_combines_attributes():
    a = Mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]], uvs=[[0, 0], [1, 0], [0, 1]], vertex_colors=np.eye(3))
    b = Mesh([[0, 0, 1], [1, 0, 1], [0, 1, 1]], [[0, 1, 2]], vertex_colors=np.full((3, 4), 0.5))
    c = Mesh([[5, 0, 0], [6, 0, 0], [5, 1, 0]], [[0, 2, 1]])
    merged = Mesh.merged(a, b, c)
    np.testing.assert_array_equal(merged.faces, [[0, 1, 2], [3, 4, 5], [6, 8, 7]])
    assert merged.uvs is None  # b and c have none
    assert merged.vertex_colors.shape == (9, 4)
    np.testing.assert_array_equal(merged.vertex_colors[:3], np.c_[np.eye(3), np.ones(3)])
    np.testing.assert_array_equal(merged.vertex_colors[6:], np.ones((3, 4)))
    assert merged.area == pytest.approx(a.area + b.area + c.area)
    with pytest.raises(GeometryError, match=r"meshes\[1\] = 'box' is not a Mesh"):
        a.merged("box")


def test_without_degenerate_faces_drops_repeated_and_collinear():
    v = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [2, 0, 0]]
    mesh = Mesh(v, [[0, 1, 2], [0, 0, 1], [0, 1, 3], [1, 2, 0]])
    clean = mesh.without_degenerate_faces()
    np.testing.assert_array_equal(clean.faces, [[0, 1, 2], [1, 2, 0]])
    assert clean.vertex_count == 4
    assert mesh.without_degenerate_faces(area_tolerance=1.0).face_count == 0
    with pytest.raises(GeometryError, match=r"area_tolerance = -1\.0 is negative"):
        mesh.without_degenerate_faces(area_tolerance=-1.0)


def test_welded_joins_seams_like_trimesh_merge_vertices():
    sphere = trimesh.creation.icosphere(subdivisions=1)
    # split every face apart: 3 vertices per face
    split = Mesh(sphere.vertices[sphere.faces].reshape(-1, 3), np.arange(sphere.faces.size).reshape(-1, 3))
    assert split.edges.shape[0] == 3 * split.face_count  # nothing shared before welding
    welded = split.welded()
    assert welded.vertex_count == len(sphere.vertices) and welded.face_count == len(sphere.faces)
    assert welded.is_watertight and welded.volume == pytest.approx(sphere.volume, rel=1e-12)
    np.testing.assert_array_equal(welded.edges.shape, sphere.edges_unique.shape)
    # jittered copies merge only with a tolerance larger than the jitter
    jitter = split.vertices + np.random.default_rng(0).uniform(-1e-7, 1e-7, split.vertices.shape)
    assert Mesh(jitter, split.faces).welded().vertex_count == split.vertex_count
    assert Mesh(jitter, split.faces).welded(tolerance=1e-5).vertex_count == len(sphere.vertices)


def test_welded_drops_collapsed_faces_and_rejects_negative_tolerance():
    mesh = Mesh([[0, 0, 0], [1e-9, 0, 0], [0, 1, 0], [1, 1, 0]], [[0, 1, 2], [1, 3, 2]])
    welded = mesh.welded(tolerance=1e-6)
    assert welded.vertex_count == 3 and welded.face_count == 1
    with pytest.raises(GeometryError, match=r"tolerance = -0\.5 is negative"):
        mesh.welded(-0.5)


# --- the seed's constructors ----------------------------------------------------------------------------------


@pytest.mark.parametrize("n", [3, 4, 7, 10])
def test_triangle_strip_has_n_minus_2_consistently_wound_triangles(n):
    # a zig-zag strip in z = 0: v0 (0,0), v1 (0,1), v2 (1,0), v3 (1,1), ...
    k = np.arange(n)
    vertices = np.stack([k // 2, (k + 1) % 2 == 0, np.zeros(n)], axis=1).astype(float)
    strip = Mesh.from_triangle_strip(vertices)
    assert strip.face_count == n - 2  # [seed] "Triangular Mesh"
    normals = strip.face_normals
    np.testing.assert_allclose(normals, np.tile(normals[0], (n - 2, 1)))
    assert strip.area == pytest.approx(0.5 * (n - 2))
    # every triangle is (v_k, v_k+1, v_k+2) as a set
    np.testing.assert_array_equal(np.sort(strip.faces, axis=1), np.stack([k[:-2], k[:-2] + 1, k[:-2] + 2], axis=1))


def test_triangle_fan_has_n_minus_2_triangles_around_the_first_vertex():
    angles_ = np.linspace(0, np.pi, 6)
    rim = np.stack([np.cos(angles_), np.sin(angles_), np.zeros(6)], axis=1)
    fan = Mesh.from_triangle_fan(np.vstack([[0, 0, 0], rim]))
    assert fan.face_count == 5
    assert (fan.faces[:, 0] == 0).all()
    np.testing.assert_allclose(fan.face_normals, np.tile([0, 0, 1.0], (5, 1)))
    trimesh_area = trimesh.Trimesh(np.array(fan.vertices), np.array(fan.faces), process=False).area
    assert fan.area == pytest.approx(trimesh_area, rel=1e-14)


@pytest.mark.parametrize(("n", "m"), [(2, 2), (3, 5), (6, 4)])
def test_grid_gives_n_minus_1_by_m_minus_1_quads(n, m):
    i, j = np.meshgrid(np.arange(n, dtype=float), np.arange(m, dtype=float), indexing="ij")
    points = np.stack([i, j, np.zeros_like(i)], axis=-1)
    mesh = Mesh.from_grid(points, uvs=np.stack([i, j], axis=-1))
    assert mesh.face_count == 2 * (n - 1) * (m - 1)  # [seed] "Quadrilateral Mesh": (n−1)(m−1) quads
    np.testing.assert_allclose(mesh.face_normals, np.tile([0, 0, 1.0], (mesh.face_count, 1)))  # ∂P/∂i × ∂P/∂j
    assert mesh.area == pytest.approx((n - 1) * (m - 1))
    assert mesh.uvs.shape == (n * m, 2)


def test_from_polygons_triangulates_quads_and_ragged_lists():
    cube = trimesh.creation.box()
    quads = np.array([[0, 1, 3, 2], [4, 6, 7, 5], [0, 4, 5, 1], [2, 3, 7, 6], [0, 2, 6, 4], [1, 5, 7, 3]])
    mesh = Mesh.from_polygons(cube.vertices, quads)
    assert mesh.face_count == 12 and mesh.is_watertight
    assert mesh.volume == pytest.approx(1.0)
    mixed = Mesh.from_polygons(cube.vertices, [[0, 1, 3, 2], [4, 6, 7], [0, 4, 5, 1, 3]])
    assert mixed.face_count == 2 + 1 + 3


@pytest.mark.parametrize(
    ("call", "fragment"),
    [
        (lambda: Mesh.from_triangle_strip([[0, 0, 0], [1, 0, 0]]), "vertices has 2 rows; give at least 3"),
        (lambda: Mesh.from_triangle_fan([[0, 0, np.nan], [1, 0, 0], [0, 1, 0]]), r"vertices\[0\] = .* not finite"),
        (lambda: Mesh.from_grid(np.zeros((1, 4, 3))), r"shape \(1, 4, 3\); a grid needs n >= 2"),
        (lambda: Mesh.from_grid(np.zeros((3, 4))), r"points has shape \(3, 4\)"),
        (lambda: Mesh.from_grid(np.zeros((3, 4, 3)), uvs=np.zeros((3, 3, 2))), r"uvs has shape \(3, 3, 2\)"),
        (lambda: Mesh.from_polygons(np.zeros((4, 3)), [[0, 1, 2], [0, 1]]), r"polygons\[1\] = .* has 2 vertices"),
        (lambda: Mesh.from_polygons(np.zeros((4, 3)), [[0.0, 1.0, 2.0]]), "dtype float64"),
        (lambda: Mesh.from_polygons(np.zeros((4, 3)), [[0, 1, 7, 2]]), "indexes outside the 4 vertices"),
    ],
)
def test_constructors_reject_bad_input(call, fragment):
    with pytest.raises(GeometryError, match=fragment):
        call()


# --- UVs and vertex colors ------------------------------------------------------------------------------------

_TRIANGLE = ([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])


def test_uint8_colors_are_scaled_and_float_colors_kept():
    mesh = Mesh(*_TRIANGLE, vertex_colors=np.array([[255, 0, 0], [0, 255, 0], [0, 0, 51]], dtype=np.uint8))
    np.testing.assert_array_equal(mesh.vertex_colors, [[1, 0, 0], [0, 1, 0], [0, 0, 0.2]])
    rgba = Mesh(*_TRIANGLE, vertex_colors=np.full((3, 4), 0.25), uvs=[[0, 0], [1, 0], [0, 1]])
    assert rgba.vertex_colors.shape == (3, 4) and not rgba.vertex_colors.flags.writeable
    assert not rgba.uvs.flags.writeable


@pytest.mark.parametrize(
    ("kwargs", "fragment"),
    [
        ({"uvs": [[0, 0], [1, 0]]}, "uvs has 2 rows for 3 vertices"),
        ({"uvs": [[0, 0, 0]] * 3}, r"uvs has shape \(3, 3\)"),
        ({"uvs": [[0, 0], [np.nan, 0], [0, 1]]}, r"uvs\[1\] = \(nan, 0.0\) is not finite"),
        ({"vertex_colors": [[0, 0, 0], [1.5, 0, 0], [0, 0, 0]]}, r"vertex_colors\[1\] = \(1.5, 0.0, 0.0\) is outside"),
        ({"vertex_colors": [[0, 0], [0, 0], [0, 0]]}, r"vertex_colors has shape \(3, 2\)"),
        ({"vertex_colors": [[0, 0, 0]]}, "vertex_colors has 1 rows for 3 vertices"),
        ({"vertex_colors": "red"}, "vertex_colors = 'red' is not numeric"),
    ],
)
def test_bad_uvs_and_colors_are_rejected(kwargs, fragment):
    with pytest.raises(GeometryError, match=fragment):
        Mesh(*_TRIANGLE, **kwargs)


@settings(max_examples=20)
@given(k=st.integers(3, 12), radius=st.floats(0.1, 10.0), start=angles)
def test_from_polygons_area_equals_the_shoelace_area_of_a_convex_polygon(k, radius, start):
    theta = start + 2 * np.pi * np.arange(k) / k
    x, y = radius * np.cos(theta), radius * np.sin(theta)
    mesh = Mesh.from_polygons(np.stack([x, y, np.zeros(k)], axis=1), [list(range(k))])
    shoelace = 0.5 * (x * np.roll(y, -1) - np.roll(x, -1) * y).sum()
    assert mesh.face_count == k - 2
    assert mesh.area == pytest.approx(shoelace, rel=1e-12)
    assert (mesh.face_normals[:, 2] > 0).all()  # counter-clockwise polygon → +z triangles


def test_repr_is_short():
    mesh = Mesh(*_TRIANGLE, uvs=np.zeros((3, 2)))
    assert repr(mesh) == "Mesh(vertex_count=3, face_count=1, uvs=(3, 2))"


# --- compact storage (issue 16, memory): float32 vertices kept, int32 faces, index arithmetic in int64 ----------


def test_float32_vertices_and_int32_faces_are_stored_without_upcasting():
    sphere = trimesh.creation.icosphere(subdivisions=1)
    vertices32, faces32 = sphere.vertices.astype(np.float32), sphere.faces.astype(np.int32)
    mesh = Mesh(vertices32, faces32)
    assert mesh.vertices.dtype == np.float32 and mesh.faces.dtype == np.int32
    np.testing.assert_array_equal(mesh.vertices, vertices32)
    np.testing.assert_array_equal(mesh.faces, faces32)
    assert not np.may_share_memory(mesh.vertices, vertices32) and not np.may_share_memory(mesh.faces, faces32)
    assert vertices32.flags.writeable and faces32.flags.writeable  # the caller's arrays are untouched
    # int64 faces are stored compactly too (every index < 2**31); float64 vertices are never narrowed
    wide = Mesh(sphere.vertices, sphere.faces.astype(np.int64))
    assert wide.vertices.dtype == np.float64 and wide.faces.dtype == np.int32
    assert Mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]]).vertices.dtype == np.float64
    # operations keep the compact storage
    assert mesh.flipped().vertices.dtype == np.float32 and mesh.merged(mesh).faces.dtype == np.int32


def test_a_float32_mesh_derives_the_same_numbers_as_its_float64_copy():
    sphere = trimesh.creation.icosphere(subdivisions=2)
    vertices32 = (sphere.vertices * [1.0, 0.7, 1.3] + [3.0, -1.0, 0.25]).astype(np.float32)
    compact, wide = Mesh(vertices32, sphere.faces), Mesh(vertices32.astype(np.float64), sphere.faces)
    for name in ("vertex_normals", "face_normals", "face_areas", "bounds", "centroid", "edges"):
        got, expected = getattr(compact, name), getattr(wide, name)
        assert got.dtype == expected.dtype, name
        np.testing.assert_array_equal(got, expected, err_msg=name)
    assert compact.area == wide.area and compact.volume == wide.volume and compact.is_watertight
    np.testing.assert_array_equal(compact.welded(1e-3).vertices, wide.welded(1e-3).vertices)


def test_edge_keys_of_int32_faces_do_not_overflow_with_large_vertex_counts():
    # i·n + j overflows int32 once n > 46341: with n = 70000 the keys of the edges below reach 4.9e9
    n = 70_000
    rng = np.random.default_rng(3)
    vertices = rng.random((n, 3)).astype(np.float32)
    faces = np.array([[n - 3, n - 2, n - 1], [0, n - 1, n - 2], [1, 50_000, n - 1]], dtype=np.int32)
    mesh = Mesh(vertices, faces)
    assert mesh.faces.dtype == np.int32
    expected = sorted({tuple(sorted((int(f[a]), int(f[b])))) for f in faces for a, b in ((0, 1), (1, 2), (2, 0))})
    assert mesh.edges.dtype == np.int64
    assert [tuple(e) for e in mesh.edges.tolist()] == expected
    from frustum.visibility.hidden_lines import edge_adjacency

    adjacency = edge_adjacency(mesh.faces, n)
    assert adjacency.edges.dtype == np.int64 and [tuple(e) for e in adjacency.edges.tolist()] == expected
    # a closed tetrahedron on the last four indices: every directed edge finds its opposite
    tetra = np.array([[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]], dtype=np.int32) + (n - 4)
    corners = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=np.float32)
    closed = Mesh(np.concatenate([vertices[: n - 4] + 5.0, corners]), tetra)
    assert closed.is_watertight and closed.volume == pytest.approx(1.0 / 6.0)


def test_given_normals_are_normalized_in_float64_and_float32_ones_stored_float32():
    rng = np.random.default_rng(5)
    normals = rng.normal(size=(70_000, 3)) * rng.uniform(0.1, 10.0, (70_000, 1))  # more rows than one block
    vertices = rng.random((70_000, 3))
    wide = Mesh(vertices, [[0, 1, 2]], vertex_normals=normals)
    assert wide.vertex_normals.dtype == np.float64
    np.testing.assert_array_equal(wide.vertex_normals, normals / np.sqrt((normals * normals).sum(axis=1))[:, None])
    normals32 = normals.astype(np.float32)
    compact = Mesh(vertices.astype(np.float32), [[0, 1, 2]], vertex_normals=normals32)
    wide32 = normals32.astype(np.float64)
    unit = wide32 / np.sqrt((wide32 * wide32).sum(axis=1))[:, None]
    assert compact.vertex_normals.dtype == np.float32
    np.testing.assert_array_equal(compact.vertex_normals, unit.astype(np.float32))  # rounded once
    np.testing.assert_allclose(np.linalg.norm(compact.vertex_normals.astype(np.float64), axis=1), 1.0, atol=2e-7)
    normals32[66_000] = 0.0  # a zero normal in the second block is named by its own index
    with pytest.raises(GeometryError, match=r"vertex_normals\[66000\] = \[0.0, 0.0, 0.0\] has zero length"):
        Mesh(vertices, [[0, 1, 2]], vertex_normals=normals32)


def test_copy_false_keeps_the_callers_vertex_and_face_buffers_and_still_validates():
    vertices = np.random.default_rng(3).random((40, 3)).astype(np.float32)
    faces = np.random.default_rng(4).integers(0, 40, (30, 3)).astype(np.int32)
    shared = Mesh(vertices, faces, copy=False)
    assert np.shares_memory(shared.vertices, vertices) and np.shares_memory(shared.faces, faces)
    assert not shared.vertices.flags.writeable and not shared.faces.flags.writeable
    assert vertices.flags.writeable and faces.flags.writeable  # the caller's own flags are left alone
    copied = Mesh(vertices, faces)
    assert not np.shares_memory(copied.vertices, vertices) and not np.shares_memory(copied.faces, faces)
    np.testing.assert_array_equal(shared.vertex_normals, copied.vertex_normals)
    v64 = vertices.astype(np.float64)
    wide = Mesh(v64, faces.astype(np.int64), copy=False)  # int64 faces are stored int32: a copy
    assert wide.faces.dtype == np.int32 and np.shares_memory(wide.vertices, v64)
    bad = vertices.copy()
    bad[7, 1] = np.nan
    with pytest.raises(GeometryError, match=r"vertices\[7\]"):
        Mesh(bad, faces, copy=False)
    outside = faces.copy()
    outside[5, 2] = 40
    with pytest.raises(GeometryError, match=r"faces\[5\]"):
        Mesh(vertices, outside, copy=False)
