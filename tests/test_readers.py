"""frustum's own mesh readers (``frustum.geometry.readers``) give exactly what the trimesh path of ``load_parts``
gives — the same vertices in the same order, faces, normals, UVs, colours, texture images, names, placements — on
the reference files and on generated ones (trimesh is the oracle), fall back to trimesh for what they do not
read, and keep trimesh out of the process for the plain files."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st
from PIL import Image

import frustum.geometry.io as mesh_io
from frustum.geometry import Mesh
from frustum.geometry import primitives as prim
from frustum.geometry.io import load_parts, save
from frustum.geometry.readers import read_parts
from testdata import DATA

SPOT = DATA / "spot"


def _trimesh_parts(path: Path) -> list[mesh_io.MeshPart]:
    """``load_parts`` through trimesh only (the oracle)."""
    native = mesh_io._native_parts
    mesh_io._native_parts = lambda file, text: None
    try:
        return load_parts(path)
    finally:
        mesh_io._native_parts = native


def _same(a: object, b: object) -> bool:
    if a is None or b is None:
        return a is None and b is None
    return np.array_equal(np.asarray(a), np.asarray(b))


def _assert_native_equals_trimesh(path: Path) -> None:
    assert read_parts(path, mesh_io._text_bytes(path)) is not None, f"{path.name} was not read natively"
    ours, theirs = load_parts(path), _trimesh_parts(path)
    assert [p.name for p in ours] == [p.name for p in theirs]
    for a, b in zip(ours, theirs, strict=True):
        for field in ("vertices", "faces", "vertex_normals", "uvs", "vertex_colors"):
            x, y = getattr(a.mesh, field), getattr(b.mesh, field)
            assert _same(x, y), f"{path.name} {a.name}: mesh.{field} differs"
            assert x is None or x.dtype == y.dtype
        for field in ("world_from_model", "texture", "normal_map"):
            assert _same(getattr(a, field), getattr(b, field)), f"{path.name} {a.name}: {field} differs"
        assert (a.color, a.emissive, a.alpha_mode) == (b.color, b.emissive, b.alpha_mode)


def _spot_obj_with_mtl(folder: Path, kd: str = "1 1 1", image: str | None = "spot_texture.png") -> Path:
    lines = ["newmtl cow", f"Kd {kd}"] + ([f"map_Kd {image}"] if image else [])
    (folder / "spot.mtl").write_text("\n".join(lines) + "\n")
    (folder / "spot_texture.png").write_bytes((SPOT / "spot_texture.png").read_bytes())
    path = folder / "spot.obj"
    path.write_text("mtllib spot.mtl\nusemtl cow\n" + (SPOT / "spot_triangulated.obj").read_text())
    return path


def _spot_glb(folder: Path, **material: object) -> Path:
    mesh = trimesh.load(SPOT / "spot_triangulated.obj", process=False)
    texture = Image.open(SPOT / "spot_texture.png")
    pbr = trimesh.visual.material.PBRMaterial(baseColorTexture=texture, **material)
    mesh.visual = trimesh.visual.TextureVisuals(uv=mesh.visual.uv, material=pbr)
    path = folder / "spot.glb"
    mesh.export(path)
    return path


# --- the reference files and the benchmark's files ------------------------------------------------------------


@pytest.mark.parametrize(
    "name", ["bun_zipper.ply", "bun_zipper_res2.ply", "bun_zipper_res3.ply", "bun_zipper_res4.ply"]
)
def test_bunny_ply_files(name):
    _assert_native_equals_trimesh(DATA / "bunny" / name)


@pytest.mark.parametrize("path", [DATA / "teapot_n10.obj", SPOT / "spot_triangulated.obj"])
def test_obj_reference_files(path):
    _assert_native_equals_trimesh(path)


def test_obj_with_material_library_and_texture(tmp_path):
    _assert_native_equals_trimesh(_spot_obj_with_mtl(tmp_path))


@pytest.mark.parametrize("kd", ["0.8 0.2 0.1", "0.333 0.5 1.7"])
def test_obj_material_colour_without_image(tmp_path, kd):
    _assert_native_equals_trimesh(_spot_obj_with_mtl(tmp_path, kd=kd, image=None))


def test_obj_library_with_several_materials_names_the_part_after_its_material(tmp_path):
    path = _spot_obj_with_mtl(tmp_path)
    (tmp_path / "spot.mtl").write_text("newmtl other\nKd 1 0 0\nnewmtl cow\nKd 0.5 0.5 0.5\nmap_Kd spot_texture.png\n")
    _assert_native_equals_trimesh(path)
    assert load_parts(path)[0].name == "cow"


@pytest.mark.parametrize(
    "material",
    [
        {},
        {"baseColorFactor": [0.3, 0.6, 0.9, 1.0]},
        {"emissiveFactor": [0.2, 0.0, 0.5], "alphaMode": "BLEND"},
        {"alphaMode": "OPAQUE", "baseColorFactor": [1.0, 1.0, 1.0, 0.5]},
    ],
)
def test_glb_with_embedded_texture_and_material(tmp_path, material):
    _assert_native_equals_trimesh(_spot_glb(tmp_path, **material))


def test_glb_normal_texture(tmp_path):
    normal = Image.fromarray(np.full((8, 8, 3), (128, 128, 255), dtype=np.uint8))
    path = _spot_glb(tmp_path, normalTexture=normal)
    _assert_native_equals_trimesh(path)
    assert load_parts(path)[0].normal_map.shape == (8, 8, 3)


@pytest.mark.parametrize(("suffix", "binary"), [(".stl", True), (".off", True), (".ply", True), (".ply", False)])
def test_bunny_in_other_formats(tmp_path, suffix, binary):
    bunny = trimesh.load(DATA / "bunny" / "bun_zipper_res3.ply", process=False)
    path = tmp_path / f"bunny{suffix}"
    if suffix == ".ply":
        path.write_bytes(trimesh.exchange.ply.export_ply(bunny, encoding="binary" if binary else "ascii"))
    else:
        bunny.export(path)
    _assert_native_equals_trimesh(path)


# --- generated meshes -----------------------------------------------------------------------------------------


@st.composite
def meshes(draw: st.DrawFn) -> Mesh:
    """A sphere, box or cylinder, jittered, with or without its normals and UVs."""
    shape = draw(st.sampled_from(["sphere", "box", "cylinder"]))
    base = {"sphere": prim.uv_sphere(radius=1.0, segments=7, rings=5), "box": prim.box(),
            "cylinder": prim.cylinder(segments=9)}[shape]  # fmt: skip
    seed = draw(st.integers(0, 2**16))
    jitter = np.random.default_rng(seed).normal(scale=0.05, size=base.vertices.shape)
    normals = base.vertex_normals if draw(st.booleans()) else None
    uvs = base.uvs if base.uvs is not None and draw(st.booleans()) else None
    return Mesh(base.vertices + jitter, base.faces, normals, uvs)


@settings(max_examples=25, deadline=None)
@given(mesh=meshes(), suffix=st.sampled_from([".obj", ".ply", ".stl", ".off", ".glb", ".gltf"]),
       binary=st.booleans())  # fmt: skip
def test_generated_files_read_the_same(tmp_path_factory, mesh, suffix, binary):
    path = save(mesh, tmp_path_factory.mktemp("gen") / f"m{suffix}", binary=binary)
    if read_parts(path, mesh_io._text_bytes(path)) is None:  # ASCII STL and PLY with UVs: trimesh reads them
        assert (suffix == ".stl" and not binary) or (suffix == ".ply" and mesh.uvs is not None)
        return
    _assert_native_equals_trimesh(path)


@settings(max_examples=20, deadline=None)
@given(mesh=meshes(), suffix=st.sampled_from([".obj", ".glb"]))
def test_generated_textured_files_read_the_same(tmp_path_factory, mesh, suffix):
    texture = (np.arange(8 * 16 * 3) % 251).astype(np.uint8).reshape(8, 16, 3)
    if mesh.uvs is None:
        mesh = Mesh(mesh.vertices, mesh.faces, mesh.vertex_normals, np.zeros((mesh.vertex_count, 2)) + 0.25)
    path = save(mesh, tmp_path_factory.mktemp("tex") / f"t{suffix}", texture=texture)
    _assert_native_equals_trimesh(path)


# --- what goes to trimesh, and what stays out of the process ---------------------------------------------------


def test_files_outside_the_plain_subset_go_to_trimesh(tmp_path):
    quads = SPOT / "spot_quadrangulated.obj"
    assert read_parts(quads, mesh_io._text_bytes(quads)) is None  # quads: trimesh triangulates them
    ascii_stl = save(prim.box(), tmp_path / "box.stl", binary=False)
    assert read_parts(ascii_stl) is None
    grouped = tmp_path / "grouped.obj"
    grouped.write_text("o thing\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    assert read_parts(grouped) is None
    assert load_parts(grouped)[0].name == "thing"  # trimesh's reading, as before
    broken = tmp_path / "broken.ply"
    broken.write_bytes((DATA / "bunny" / "bun_zipper_res4.ply").read_bytes()[:-200])  # truncated: trimesh says so
    assert read_parts(broken) is None


def test_rendering_a_plain_file_does_not_import_trimesh(tmp_path):
    spot = _spot_obj_with_mtl(tmp_path)
    files = [DATA / "bunny" / "bun_zipper_res4.ply", DATA / "teapot_n10.obj", spot]
    code = (
        "import sys\nfrom frustum.scenefile.models import model_scene\n"
        f"for path in {[str(f) for f in files]!r}:\n    model_scene(path)\n"
        "print(sorted(m for m in sys.modules if m.split('.')[0] in ('trimesh', 'networkx')))\n"
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert result.stdout.strip() == "[]"


def test_running_out_of_memory_in_a_native_reader_is_the_load_error(tmp_path, monkeypatch):
    """A MemoryError inside frustum's own readers is said as on trimesh's path: a GeometryError naming the file."""
    import frustum.geometry.readers as readers
    from frustum.errors import GeometryError

    path = prim.box().save(tmp_path / "box.stl")

    def exhausted(file, data):
        raise MemoryError

    monkeypatch.setitem(readers._READERS, ".stl", exhausted)
    with pytest.raises(GeometryError, match=r"box\.stl.*ran out of memory while loading"):
        load_parts(path)


def test_a_large_obj_goes_to_trimesh_with_the_same_result(monkeypatch):
    """OBJ files over OBJ_NATIVE_BYTES are read by trimesh (its parser is faster there); the parts are the same."""
    import frustum.geometry.readers as readers

    path = DATA / "teapot_n10.obj"
    native = load_parts(path)
    assert read_parts(path) is not None
    monkeypatch.setattr(readers, "OBJ_NATIVE_BYTES", path.stat().st_size - 1)
    assert read_parts(path) is None
    through_trimesh = load_parts(path)
    assert len(native) == len(through_trimesh)
    for ours, theirs in zip(native, through_trimesh, strict=True):
        np.testing.assert_array_equal(ours.mesh.vertices, theirs.mesh.vertices)
        np.testing.assert_array_equal(ours.mesh.faces, theirs.mesh.faces)
