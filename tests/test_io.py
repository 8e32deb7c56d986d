"""Mesh files through trimesh: the reference data's counts (tests/data/README.md), round trips of normals,
UVs, colors and textures, multi-object files, and clear GeometryErrors for bad paths and corrupt files."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import trimesh
from PIL import Image

from frustum import GeometryError
from frustum.geometry import Mesh
from frustum.geometry import primitives as prim
from frustum.geometry.io import SUPPORTED_SUFFIXES, MeshPart, load, load_parts, save
from testdata import DATA

# --- the reference data -------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", ["spot_triangulated.obj", "spot_quadrangulated.obj"])
def test_spot_counts_uvs_and_texture_match_the_readme(name):
    parts = load_parts(DATA / "spot" / name)
    assert len(parts) == 1
    part = parts[0]
    mesh = part.mesh
    # README: 2,930 v, 3,225 vt, 5,856 triangles (2,928 quads); vertices split at UV seams load as 3,225
    assert (mesh.vertex_count, mesh.face_count) == (3225, 5856)
    # the file's vt range (the README's "in [0,1]²" is slightly off: u reaches −0.052, v 1.00065)
    np.testing.assert_array_equal(mesh.uvs.min(axis=0), [-0.0522421, 0.111175])
    np.testing.assert_array_equal(mesh.uvs.max(axis=0), [0.989055, 1.00065])
    welded = mesh.welded()
    assert welded.vertex_count == 2930 and welded.is_watertight
    assert welded.vertex_count - welded.edges.shape[0] + welded.face_count == 2  # genus 0
    np.testing.assert_allclose(mesh.bounds, [[-0.47, -0.74, -0.67], [0.47, 0.95, 1.05]], atol=0.01)
    expected = np.asarray(Image.open(DATA / "spot" / "spot_texture.png").convert("RGB"))
    assert part.texture is not None and part.texture.shape == (1024, 1024, 3)
    np.testing.assert_array_equal(part.texture, expected)
    np.testing.assert_array_equal(part.world_from_model, np.eye(4))


def test_spot_control_mesh_polygons_are_triangulated():
    mesh = load(DATA / "spot" / "spot_control_mesh.obj")
    assert mesh.face_count == 160 * 2 + 16 * 3 + 4  # 160 quads, 16 pentagons, 4 triangles
    assert mesh.welded().vertex_count == 188


def test_teapot_keeps_the_files_normals():
    mesh = load(DATA / "teapot_n10.obj")
    oracle = trimesh.load(DATA / "teapot_n10.obj", process=False)
    assert (mesh.vertex_count, mesh.face_count) == (3864, 6320)  # README: 8 of 3,872 vertices unreferenced
    np.testing.assert_allclose(mesh.vertex_normals, oracle.vertex_normals, atol=1e-7)
    # three.js normals, not recomputed ones: they differ from area-weighted normals at the patch seams
    assert np.abs(mesh.vertex_normals - Mesh(mesh.vertices, mesh.faces).vertex_normals).max() > 0.1
    # README: faces counter-clockwise seen from the side the normals point to, all 6,320
    corner = mesh.vertex_normals[mesh.faces].sum(axis=1)
    assert (np.einsum("ij,ij->i", corner, mesh.face_normals) > 0).all()


@pytest.mark.parametrize(
    ("name", "vertices", "faces"),
    [("bun_zipper_res4.ply", 453, 948), ("bun_zipper_res2.ply", 8171, 16301), ("bun_zipper.ply", 35947, 69451)],
)
def test_bunny_counts_match_the_readme(name, vertices, faces):
    mesh = load(DATA / "bunny" / name)
    assert (mesh.vertex_count, mesh.face_count) == (vertices, faces)
    if name == "bun_zipper.ply":
        np.testing.assert_allclose(mesh.bounds, [[-0.0947, 0.0330, -0.0619], [0.0610, 0.1873, 0.0588]], atol=1e-4)
        assert not mesh.is_watertight  # 5 holes in the bottom
        sorted_edges = np.sort(mesh.faces[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
        _, counts = np.unique(sorted_edges, axis=0, return_counts=True)
        assert (counts == 1).sum() == 223  # README: 223 boundary edges


# --- round trips --------------------------------------------------------------------------------------------


def _uv_mesh() -> Mesh:
    return prim.uv_sphere(radius=1.5, segments=12, rings=6)


@pytest.mark.parametrize("suffix", [".obj", ".ply", ".glb", ".gltf"])
def test_round_trip_keeps_positions_normals_and_uvs(tmp_path, suffix):
    mesh = _uv_mesh()
    back = load(save(mesh, tmp_path / f"sphere{suffix}"))
    assert (back.vertex_count, back.face_count) == (mesh.vertex_count, mesh.face_count)
    np.testing.assert_array_equal(back.faces, mesh.faces)
    np.testing.assert_allclose(back.vertices, mesh.vertices, atol=1e-6)  # glTF/PLY store float32
    np.testing.assert_allclose(back.vertex_normals, mesh.vertex_normals, atol=1e-6)
    np.testing.assert_allclose(back.uvs, mesh.uvs, atol=1e-6)


@pytest.mark.parametrize("suffix", [".obj", ".ply", ".glb"])
def test_round_trip_keeps_vertex_colors(tmp_path, suffix):
    box = prim.box()
    colors = np.linspace(0, 1, box.vertex_count * 4).reshape(-1, 4)
    if suffix == ".obj":
        colors = colors[:, :3]  # OBJ vertex colors are RGB
    mesh = Mesh(box.vertices, box.faces, box.vertex_normals, vertex_colors=colors)
    back = load(save(mesh, tmp_path / f"box{suffix}"))
    np.testing.assert_allclose(back.vertex_colors, colors, atol=0.5 / 255 + 1e-12)  # stored as uint8


@pytest.mark.parametrize(("suffix", "binary"), [(".stl", True), (".stl", False), (".off", True), (".ply", False)])
def test_geometry_only_formats_keep_the_surface(tmp_path, suffix, binary):
    mesh = prim.cylinder(segments=10)
    back = load(save(mesh, tmp_path / f"c{suffix}", binary=binary))
    assert back.face_count == mesh.face_count
    assert back.area == pytest.approx(mesh.area, rel=1e-6)
    assert back.welded(1e-6).volume == pytest.approx(mesh.volume, rel=1e-6)
    if suffix == ".stl":
        assert Path(tmp_path / f"c{suffix}").read_bytes()[:5].startswith(b"solid") == (not binary)


@pytest.mark.parametrize("suffix", [".obj", ".stl", ".ply", ".glb"])
def test_saving_is_deterministic(tmp_path, suffix):
    mesh = _uv_mesh()
    first = save(mesh, tmp_path / f"a{suffix}").read_bytes()
    second = mesh.save(tmp_path / f"b{suffix}").read_bytes()
    assert first == second


def test_texture_round_trip_through_obj_and_glb(tmp_path):
    mesh = prim.box()
    texture = (np.arange(8 * 16 * 3) % 256).astype(np.uint8).reshape(8, 16, 3)
    for suffix in (".obj", ".glb"):
        part = load_parts(save(mesh, tmp_path / f"textured{suffix}", texture=texture))[0]
        np.testing.assert_array_equal(part.texture, texture)
        np.testing.assert_allclose(part.mesh.uvs, mesh.uvs, atol=1e-6)
        assert part.color is None or part.color == (1.0, 1.0, 1.0, 1.0)


def test_explicit_texture_argument(tmp_path):
    path = save(prim.box(), tmp_path / "plain.obj")
    image = np.full((4, 4, 3), 200, dtype=np.uint8)
    Image.fromarray(image).save(tmp_path / "skin.png")
    assert load_parts(path)[0].texture is None  # no material, no sibling image
    np.testing.assert_array_equal(load_parts(path, texture=tmp_path / "skin.png")[0].texture, image)


# --- multi-object files ---------------------------------------------------------------------------------------


def _two_part_scene(path: Path) -> tuple[np.ndarray, np.ndarray]:
    scene = trimesh.Scene()
    lift = trimesh.transformations.translation_matrix([0.0, 2.0, 0.0])
    turn = trimesh.transformations.rotation_matrix(np.pi / 2, [0, 0, 1], point=[1, 0, 0])
    scene.add_geometry(trimesh.creation.box(), node_name="body", geom_name="body_mesh", transform=lift)
    scene.add_geometry(
        trimesh.creation.icosphere(subdivisions=1), node_name="arm", geom_name="arm_mesh", transform=turn
    )
    scene.export(path)
    return lift, turn


def test_multi_object_glb_loads_as_parts_with_transforms(tmp_path):
    lift, turn = _two_part_scene(tmp_path / "robot.glb")
    parts = load_parts(tmp_path / "robot.glb")
    assert [p.name for p in parts] == ["arm", "body"]  # sorted by name
    assert all(isinstance(p, MeshPart) for p in parts)
    np.testing.assert_allclose(parts[0].world_from_model, turn, atol=1e-12)
    np.testing.assert_allclose(parts[1].world_from_model, lift, atol=1e-12)
    assert parts[1].mesh.face_count == 12 and parts[0].mesh.face_count == 80
    merged = load(tmp_path / "robot.glb")
    assert merged.face_count == 92
    # baked: the box's vertices moved up by 2
    np.testing.assert_allclose(merged.vertices[-8:, 1].mean(), 2.0, atol=1e-6)
    np.testing.assert_allclose(merged.vertices[:-8].mean(axis=0)[:2], [1.0, -1.0], atol=0.1)


# --- bad input ------------------------------------------------------------------------------------------------


def test_unknown_suffix_lists_the_supported_ones(tmp_path):
    for call in (lambda p: load(p), lambda p: save(prim.box(), p)):
        with pytest.raises(GeometryError, match=r"suffix '\.fbx'.*\.obj, \.stl, \.ply, \.off, \.gltf, \.glb") as info:
            call(tmp_path / "model.fbx")
        assert "model.fbx" in str(info.value)
    assert SUPPORTED_SUFFIXES == (".obj", ".stl", ".ply", ".off", ".gltf", ".glb")


def _write(path: Path, data: bytes) -> Path:
    path.write_bytes(data)
    return path


@pytest.mark.parametrize(
    ("make", "fragment"),
    [
        (lambda d: d / "missing.obj", "does not exist"),
        (lambda d: d, "has suffix '\\(none\\)'"),
        (lambda d: (d / "folder.obj").mkdir() or d / "folder.obj", r"is not a regular file \(a folder\)"),
        (lambda d: _write(d / "empty.ply", b""), r"is empty \(0 bytes\)"),
        (lambda d: _write(d / "short.stl", b"\0" * 40), "fewer than the 84-byte binary STL header"),
        (
            lambda d: _write(d / "cut.stl", save(prim.box(), d / "whole.stl").read_bytes()[:400]),
            "announces 12 triangles",
        ),
        (
            lambda d: _write(
                d / "bad.ply", b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n1\n"
            ),
            "could not be read as .ply",
        ),
        (lambda d: _write(d / "bad.glb", b"glTF\x02\x00\x00\x00garbage"), "could not be read as .glb"),
        (lambda d: _write(d / "bad.off", b"OFF\n3 1 0\n0 0 0\n1 0 0\n"), "could not be read as .off"),
        (lambda d: _write(d / "points.obj", b"v 0 0 0\nv 1 0 0\n"), "contains no triangles"),
    ],
)
def test_bad_files_raise_geometry_error_with_path_and_reason(tmp_path, make, fragment):
    path = make(tmp_path)
    with pytest.raises(GeometryError, match=fragment) as info:
        load(path)
    assert Path(path).name in str(info.value)
    error = info.value
    assert error.__cause__ is None and (error.__context__ is None or error.__suppress_context__)  # no chain


def test_bad_arguments(tmp_path):
    with pytest.raises(GeometryError, match="path = 3 is not a path"):
        load(3)
    with pytest.raises(GeometryError, match=r"texture = .*nope\.png.* does not exist"):
        load(save(prim.box(), tmp_path / "b.obj"), texture=tmp_path / "nope.png")
    with pytest.raises(GeometryError, match="mesh = 'box' is not a Mesh"):
        save("box", tmp_path / "b.obj")
    with pytest.raises(GeometryError, match=r"texture has shape \(4, 4\)"):
        save(prim.box(), tmp_path / "t.obj", texture=np.zeros((4, 4), dtype=np.uint8))
    with pytest.raises(GeometryError, match="cannot be written"):
        save(prim.box(), tmp_path / "no" / "such" / "folder.stl")
