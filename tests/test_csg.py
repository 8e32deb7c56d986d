"""CSG through manifold3d: exact volumes of box booleans, inclusion–exclusion, closed outward results, and clear
errors for operands that are not closed solids."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from frustum import GeometryError
from frustum.geometry import Mesh
from frustum.geometry import primitives as prim
from frustum.geometry.csg import difference, intersection, union
from frustum.transforms import reflect, translate


def _assert_closed_and_outward(mesh: Mesh) -> None:
    assert mesh.is_watertight and mesh.volume > 0
    corner_dot = np.einsum("fkj,fj->fk", mesh.vertex_normals[mesh.faces], mesh.face_normals)
    assert (corner_dot > 0).all()


def test_overlapping_boxes_have_exact_volumes():
    a = prim.box(size=(2.0, 2.0, 2.0))
    b = prim.box(size=(2.0, 2.0, 2.0), center=(1.0, 1.0, 1.0))  # overlap: the unit cube [0, 1]³
    assert intersection(a, b).volume == pytest.approx(1.0, rel=1e-12)
    assert union(a, b).volume == pytest.approx(15.0, rel=1e-12)
    assert difference(a, b).volume == pytest.approx(7.0, rel=1e-12)
    np.testing.assert_allclose(intersection(a, b).bounds, [[0, 0, 0], [1, 1, 1]], atol=1e-12)
    for result in (union(a, b), difference(a, b), intersection(a, b)):
        _assert_closed_and_outward(result)
        # flat faces stay flat-shaded: every normal is a coordinate axis
        assert np.allclose(np.abs(result.vertex_normals).max(axis=1), 1.0)


@settings(max_examples=10)
@given(offset=st.tuples(*[st.floats(-0.9, 0.9)] * 3), radius=st.floats(0.3, 0.9))
def test_inclusion_exclusion(offset, radius):
    a = prim.box()
    b = prim.icosphere(radius=radius, subdivisions=1).transformed(translate(*offset))
    va, vb = a.volume, b.welded().volume
    both, either, only_a = intersection(a, b).volume, union(a, b).volume, difference(a, b).volume
    assert either + both == pytest.approx(va + vb, rel=1e-9)
    assert only_a == pytest.approx(va - both, rel=1e-9, abs=1e-12)


def test_sphere_inside_box_and_disjoint_solids():
    box = prim.box(size=(3.0, 3.0, 3.0))
    sphere = prim.uv_sphere(radius=1.0, segments=16, rings=8)
    assert intersection(box, sphere).volume == pytest.approx(sphere.volume, rel=1e-12)
    hollow = difference(box, sphere)
    assert hollow.volume == pytest.approx(27.0 - sphere.volume, rel=1e-12)
    assert hollow.is_watertight  # an inner, inward-facing shell: still closed and oriented
    far = prim.box(center=(10.0, 0.0, 0.0))
    assert intersection(box, far).face_count == 0
    assert union(box, far).volume == pytest.approx(28.0, rel=1e-12)
    assert union(box, far, prim.box(center=(-10.0, 0.0, 0.0))).volume == pytest.approx(29.0, rel=1e-12)


def test_mirrored_operand_still_works_and_inputs_are_untouched():
    cone = prim.cone(segments=12)
    mirrored = cone.transformed(reflect((1.0, 0.0, 0.0), point=(5.0, 0.0, 0.0)))  # winding flipped: still outward
    before = cone.vertices.copy()
    result = union(cone, mirrored)
    assert result.volume == pytest.approx(2 * cone.volume, rel=1e-9)
    np.testing.assert_array_equal(cone.vertices, before)
    _assert_closed_and_outward(result)


@pytest.mark.parametrize(
    ("operand", "fragment"),
    [
        (lambda: prim.plane(), r"meshes\[1\] \(a mesh with 2 faces\) is not a closed manifold"),
        (lambda: prim.cylinder(caps=False), "is not a closed manifold"),
        (lambda: prim.axes(), "is not a closed manifold"),  # three arrows share edges at the origin
        (lambda: prim.box().flipped(), r"meshes\[1\] has volume = -1\.0 <= 0"),
        (lambda: "sphere", r"meshes\[1\] = 'sphere' is not a Mesh"),
    ],
)
def test_non_manifold_or_inverted_input_is_rejected(operand, fragment):
    for op in (union, difference, intersection):
        with pytest.raises(GeometryError, match=fragment):
            op(prim.box(), operand())


def test_bad_sharp_angle():
    with pytest.raises(GeometryError, match=r"sharp_angle = 200\.0 is outside \[0, 180\]"):
        union(prim.box(), prim.box(), sharp_angle=200.0)
