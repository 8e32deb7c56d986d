"""Mesh: validation at the boundary, read-only arrays, area-weighted vertex normals."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from frustum import GeometryError
from frustum.geometry import Mesh


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
