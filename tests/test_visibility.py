"""Back-face detection: the plane equation against the viewing position, and the signed window area."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from frustum import Camera, FrustumError, GeometryError, Orthographic, Perspective
from frustum.transforms import apply, rotate, translate
from frustum.visibility import backface_mask, plane_equations, signed_window_areas, viewing_position


def sphere():
    mesh = trimesh.creation.icosphere(subdivisions=2, radius=1.0)
    return np.asarray(mesh.vertices), np.asarray(mesh.faces)


def test_plane_equation_of_a_counter_clockwise_triangle_points_to_its_front():
    planes = plane_equations([[0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [0.0, 1.0, 1.0]], [[0, 1, 2]])
    np.testing.assert_array_equal(planes, [[0.0, 0.0, 1.0, -1.0]])  # z = 1, normal +z, length 2·area = 1


def test_back_face_when_the_viewing_position_is_behind_the_plane():
    triangle = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]  # front side is +z
    front = Camera.look_at((0.2, 0.2, 3.0), (0.2, 0.2, 0.0), (0, 1, 0))
    behind = Camera.look_at((0.2, 0.2, -3.0), (0.2, 0.2, 0.0), (0, 1, 0))
    for method in ("plane", "window"):
        assert not backface_mask(triangle, [[0, 1, 2]], front, method)[0]
        assert backface_mask(triangle, [[0, 1, 2]], behind, method)[0]


@pytest.mark.parametrize(
    "projection", [Perspective(0.9, 0.5, 20.0), Orthographic(3.0, 0.5, 20.0)], ids=["perspective", "orthographic"]
)
def test_plane_and_window_methods_agree_on_a_closed_mesh(projection):
    vertices, faces = sphere()
    camera = Camera.look_at((0.5, 1.0, 4.0), (0, 0, 0), (0, 1, 0), projection=projection, width=64, height=48)
    by_plane = backface_mask(vertices, faces, camera, "plane")
    by_window = backface_mask(vertices, faces, camera, "window")
    # faces seen exactly edge-on could round either way; a sphere seen from outside has none near 0 here
    areas = signed_window_areas(camera.project(vertices), faces)
    assert np.abs(areas).min() > 1e-6
    np.testing.assert_array_equal(by_plane, by_window)
    assert 0.3 < by_plane.mean() < 0.7  # about half of a sphere faces away


def test_back_faces_stay_back_faces_under_a_rigid_motion():
    vertices, faces = sphere()
    camera = Camera.look_at((0.5, 1.0, 4.0), (0, 0, 0), (0, 1, 0))
    motion = translate(0.3, -0.2, 0.1) @ rotate((1.0, 2.0, 0.5), 0.8)
    moved_camera = Camera.look_at(
        apply(motion, [0.5, 1.0, 4.0]),
        apply(motion, [0.0, 0.0, 0.0]),
        apply(motion, [0, 1, 0]) - apply(motion, [0, 0, 0]),
    )
    np.testing.assert_array_equal(
        backface_mask(vertices, faces, camera), backface_mask(apply(motion, vertices), faces, moved_camera)
    )


def test_viewing_position_is_the_eye_or_the_point_at_infinity_toward_the_viewer():
    perspective = Camera.look_at((1.0, 2.0, 3.0), (0, 0, 0), (0, 1, 0))
    np.testing.assert_array_equal(viewing_position(perspective), [1.0, 2.0, 3.0, 1.0])
    parallel = Camera.look_at((0.0, 0.0, 5.0), (0, 0, 0), (0, 1, 0), projection=Orthographic(2.0, 0.1, 10.0))
    position = viewing_position(parallel)
    assert position[3] == 0.0 or abs(position[3]) < 1e-12  # at infinity
    np.testing.assert_allclose(position[:3] / np.linalg.norm(position[:3]), [0, 0, 1], atol=1e-12)  # SVD round-off


def test_window_method_falls_back_to_the_plane_test_behind_the_eye():
    triangle = [[-1.0, -1.0, 1.0], [1.0, -1.0, 1.0], [0.0, 1.0, 1.0]]  # behind a camera at the origin looking -z
    camera = Camera.look_at((0.0, 0.0, 0.0), (0, 0, -1), (0, 1, 0))
    assert backface_mask(triangle, [[0, 1, 2]], camera, "window")[0] == backface_mask(triangle, [[0, 1, 2]], camera)[0]


def test_backface_mask_rejects_bad_input():
    vertices, faces = sphere()
    camera = Camera.look_at((0.0, 0.0, 4.0), (0, 0, 0), (0, 1, 0))
    with pytest.raises(FrustumError, match="method = 'sideways' is unknown"):
        backface_mask(vertices, faces, camera, "sideways")
    with pytest.raises(GeometryError, match="indexes outside"):
        backface_mask(vertices, faces + len(vertices), camera)
    with pytest.raises(FrustumError, match="not a Camera"):
        backface_mask(vertices, faces, None)
