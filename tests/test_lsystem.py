"""geometry/lsystem.py: rewriting counts, the turtle against hand-worked paths and fractals.koch_curve, tubes."""

from __future__ import annotations

import math

import numpy as np
import pytest
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st

from frustum.errors import GeometryError
from frustum.geometry.fractals import koch_curve
from frustum.geometry.lsystem import CLASSIC_LSYSTEMS, LSystem, TurtlePath, interpret, parse_rules, tube_mesh


def test_parse_rules_forms():
    assert parse_rules("F -> F+F--F+F\nX → F[X]  # comment\n\nY = -FX") == {"F": "F+F--F+F", "X": "F[X]", "Y": "-FX"}
    assert parse_rules("A -> B; B -> AB") == {"A": "B", "B": "AB"}
    assert parse_rules({"F": "F F"}) == {"F": "FF"}


def test_expand_algae_counts_are_fibonacci():
    algae = LSystem("A", "A -> AB; B -> A", angle=0.0)
    assert [algae.expand(n) for n in range(5)] == ["A", "AB", "ABA", "ABAAB", "ABAABABA"]
    assert [algae.length(n) for n in range(10)] == [1, 2, 3, 5, 8, 13, 21, 34, 55, 89]


@pytest.mark.parametrize("level", range(6))
def test_koch_lsystem_has_4_to_the_n_segments_and_equals_the_geometric_construction(level):
    path = CLASSIC_LSYSTEMS["koch"].path(level)
    assert path.segments.shape == (4**level, 2, 3)
    np.testing.assert_allclose(path.points, koch_curve(level), atol=1e-12)


def test_turtle_commands_by_hand():
    # H = +x, L = +y, U = +z; + turns towards L, & pitches towards -U, \ rolls L towards U, | turns around
    ends = interpret("F+F-F&F^F\\+F", 90).segments[:, 1]
    expected = [[1, 0, 0], [1, 1, 0], [2, 1, 0], [2, 1, -1], [3, 1, -1], [3, 1, 0]]
    np.testing.assert_allclose(ends, expected, atol=1e-12)
    np.testing.assert_allclose(interpret("F/+F", 90).segments[:, 1], [[1, 0, 0], [1, 0, -1]], atol=1e-12)
    np.testing.assert_allclose(interpret("F|F", 90).segments[:, 1], [[1, 0, 0], [0, 0, 0]], atol=1e-12)


def test_brackets_restore_state_and_record_depth():
    path = interpret("F[+F[-F]]F", 90)
    np.testing.assert_allclose(path.segments[:, 1], [[1, 0, 0], [1, 1, 0], [2, 1, 0], [2, 0, 0]], atol=1e-12)
    assert path.depths.tolist() == [0, 1, 2, 0]
    # one run F+F-F (continuous), then the F after the pops starts a new run at (1, 0, 0)
    assert [p.shape[0] for p in path.polylines] == [4, 2]
    moved = interpret("FfF", 90)
    assert moved.segments.shape == (2, 2, 3) and len(moved.polylines) == 2


@settings(max_examples=30)
@given(st.text(alphabet="F+-&^\\/|", max_size=40), st.floats(1.0, 179.0))
def test_turtle_steps_have_unit_length(word, angle):
    path = interpret(word, angle)
    assert path.segments.shape[0] == word.count("F")
    lengths = np.linalg.norm(path.segments[:, 1] - path.segments[:, 0], axis=1)
    np.testing.assert_allclose(lengths, 1.0, rtol=1e-9)


def test_tree_3d_is_three_dimensional_and_deterministic():
    tree = CLASSIC_LSYSTEMS["tree_3d"]
    a = tree.path(4, heading=(0, 0, 1), left=(0, 1, 0))
    assert np.ptp(a.segments.reshape(-1, 3), axis=0).min() > 0.5
    assert a.segments.tobytes() == tree.path(4, heading=(0, 0, 1), left=(0, 1, 0)).segments.tobytes()
    assert a.depths.max() == 4


def test_tube_mesh_is_closed_outward_prism():
    mesh = tube_mesh(interpret("F", 0.0, step=2.0), radius=0.5, sides=64)
    tm = trimesh.Trimesh(mesh.vertices, mesh.faces, process=False)
    assert mesh.face_count == 4 * 64 - 4 and tm.is_watertight
    # a regular 64-gon prism: area (n/2) r² sin(2π/n) times the length
    assert tm.volume == pytest.approx(32 * 0.25 * math.sin(2 * math.pi / 64) * 2.0, rel=1e-12)
    branched = tube_mesh(interpret("F[+F]", 90.0), radius=0.1, taper=0.5, sides=4)
    assert branched.face_count == 2 * 12
    np.testing.assert_allclose(np.ptp(branched.vertices[8:16, 0]), 0.1, atol=1e-12)  # depth 1: radius 0.05


def test_malformed_rules_and_words():
    with pytest.raises(GeometryError, match=r"rule 1 successor = 'F\[\+F' leaves 1 '\[' unclosed"):
        LSystem("F", "F -> F[+F", 25)
    with pytest.raises(GeometryError, match=r"axiom = 'F\]' closes a bracket at position 1"):
        LSystem("F]", "F -> FF", 25)
    with pytest.raises(GeometryError, match=r"symbols \['Q', 'Z'\] are unknown"):
        LSystem("FQ", "F -> F[Z]", 25)
    assert LSystem("FQ", "F -> F", 25, ignore="Q").expand(1) == "FQ"
    with pytest.raises(GeometryError, match=r"rule 1 = 'F F' has no arrow"):
        parse_rules("F F")
    with pytest.raises(GeometryError, match=r"predecessor = 'AB' is not one symbol"):
        parse_rules("AB -> F")
    with pytest.raises(GeometryError, match=r"word = 'F\[' leaves 1"):
        interpret("F[", 90)
    with pytest.raises(GeometryError, match=r"left = .* is parallel to heading"):
        interpret("F", 90, heading=(1, 0, 0), left=(2, 0, 0))
    with pytest.raises(GeometryError, match=r"path = 'F' is not a TurtlePath"):
        tube_mesh("F")
    with pytest.raises(GeometryError, match=r"path.depths has shape \(2,\)"):
        tube_mesh(TurtlePath(np.zeros((1, 2, 3)), np.zeros(2, dtype=np.int64)))


def test_expansion_over_the_memory_budget_fails_before_expanding():
    with pytest.raises(GeometryError, match=r"level = 30 needs about .* over the memory budget of 8\.0 GiB"):
        CLASSIC_LSYSTEMS["plant"].expand(30)
    with pytest.raises(GeometryError, match=r"level = -1 is negative"):
        CLASSIC_LSYSTEMS["koch"].expand(-1)


def test_empty_path():
    path = interpret("+-", 30)
    assert path.segments.shape == (0, 2, 3) and path.polylines == [] and path.points.shape == (0, 3)
    assert tube_mesh(TurtlePath(path.segments, path.depths)).face_count == 0
