"""Bump and normal maps: Blinn's formula against the analytic normal of the displaced surface, tangent-space normal
maps against the normals they encode, and the no-op cases (flat normal map, Gouraud shading)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import frustum as fr
from frustum.errors import ShadingError
from frustum.shading.surface_detail import bumped_normals, height_gradient, mapped_normals, tangent_frames

LIGHT = [fr.DirectionalLight((0.3, -0.4, -1.0), intensity=0.45), fr.PointLight((0.5, 0.8, 2.0), intensity=0.3)]


def _camera(size: int = 64) -> fr.Camera:
    return fr.Camera.look_at((0.2, -0.3, 3.0), (0, 0, 0), (0, 1, 0), fr.Perspective(0.45, 0.1, 10.0), size, size)


def _render(mesh: fr.Mesh, material: fr.Material, **options) -> np.ndarray:
    scene = fr.Scene(LIGHT)
    scene.add(mesh, material)
    return fr.render(scene, _camera(), **options).color.astype(int)


def test_tangent_frames_of_a_plane_are_its_uv_derivatives():
    mesh = fr.plane((2.0, 3.0), (3, 2))  # x = 2u − 1, y = 3v − 1.5
    p_u, p_v = tangent_frames(mesh.vertices, mesh.faces, mesh.uvs)
    np.testing.assert_allclose(p_u, np.tile([2.0, 0.0, 0.0], (mesh.vertex_count, 1)), atol=1e-12)
    np.testing.assert_allclose(p_v, np.tile([0.0, 3.0, 0.0], (mesh.vertex_count, 1)), atol=1e-12)


def test_blinns_formula_gives_the_displaced_surfaces_normal():
    # the plane x = L u, y = L v displaced by B(u) = k u: the surface z = (k / L) x, normal ∝ (−k/L, 0, 1)
    length, k = 2.0, 0.7
    normal = bumped_normals([[0.0, 0.0, 1.0]], [[length, 0.0, 0.0]], [[0.0, length, 0.0]], [k], [0.0])
    expected = np.array([-k / length, 0.0, 1.0]) / math.hypot(k / length, 1.0)
    np.testing.assert_allclose(normal[0], expected, atol=1e-12)


def test_height_gradient_of_a_ramp_is_constant():
    ramp = np.tile(np.linspace(0.0, 1.0, 64, dtype=np.float32), (16, 1))  # gray = column / 63
    texture = np.repeat(ramp[:, :, None], 4, axis=2)
    b_u, b_v = height_gradient(texture, 0.5, np.linspace(0, 1, 50), np.linspace(0, 1, 50))
    np.testing.assert_allclose(b_u, 0.5 * 64 / 63, rtol=1e-6)
    np.testing.assert_allclose(b_v, 0.0, atol=1e-9)


def test_a_plane_with_a_height_ramp_shades_as_the_tilted_plane():
    mesh = fr.plane((2.0, 2.0), (8, 8))  # P_u = (2, 0, 0), P_v = (0, 2, 0)
    ramp = np.tile(np.linspace(0.0, 1.0, 128), (32, 1))
    scale = 0.3
    bumped = _render(mesh, fr.Material(bump=ramp, bump_scale=scale))
    slope = scale * (128 / 127) / 2.0  # dB/du over dx/du
    tilted = np.tile(np.array([-slope, 0.0, 1.0]) / math.hypot(slope, 1.0), (mesh.vertex_count, 1))
    reference = _render(fr.Mesh(mesh.vertices, mesh.faces, tilted, mesh.uvs), fr.Material())
    assert np.abs(bumped - reference).max() <= 1
    flat = _render(mesh, fr.Material())
    assert np.abs(bumped - flat).max() > 10  # the bump shows


def test_a_flat_normal_map_changes_nothing():
    mesh = fr.uv_sphere(1.0, 48, 24)
    flat_map = np.zeros((16, 32, 3), dtype=np.uint8)
    flat_map[:] = (128, 128, 255)
    for shading in ("phong", "gouraud", "flat"):
        plain = _render(mesh, fr.Material(), shading=shading)
        mapped = _render(mesh, fr.Material(normal_map=flat_map), shading=shading)
        assert np.abs(plain - mapped).max() <= 1, shading


def test_a_normal_map_sets_the_encoded_tangent_space_normal():
    mesh = fr.plane((2.0, 2.0), (4, 4))  # tangent +x, bitangent +y, normal +z
    texel = np.array([200, 90, 220], dtype=np.uint8)
    image = np.broadcast_to(texel, (8, 8, 3)).copy()
    encoded = (texel - 128.0) / 127.0  # 8-bit values b as (b − 128)/127
    encoded = encoded / np.linalg.norm(encoded)
    mapped = _render(mesh, fr.Material(normal_map=image))
    reference = _render(fr.Mesh(mesh.vertices, mesh.faces, np.tile(encoded, (mesh.vertex_count, 1)), mesh.uvs),
                        fr.Material())  # fmt: skip
    assert np.abs(mapped - reference).max() <= 1
    np.testing.assert_allclose(
        mapped_normals([[0, 0, 1.0]], [[2.0, 0, 0]], [[0, 2.0, 0]], [texel / 255.0])[0], encoded, atol=1e-12
    )


def test_gouraud_shading_leaves_a_bump_map_unused():
    mesh = fr.plane((2.0, 2.0), (8, 8))
    ramp = np.tile(np.linspace(0.0, 1.0, 128), (32, 1))
    assert np.array_equal(_render(mesh, fr.Material(bump=ramp), shading="gouraud"),
                          _render(mesh, fr.Material(), shading="gouraud"))  # fmt: skip


def test_bad_maps_are_refused():
    with pytest.raises(ShadingError, match="bump"):
        fr.Material(bump=np.zeros((4, 4, 2)))
    with pytest.raises(ShadingError, match="normal_map"):
        fr.Material(normal_map=np.full((4, 4, 3), np.nan))
    with pytest.raises(ShadingError, match="bump_scale"):
        fr.Material(bump_scale=float("inf"))


def test_a_gltf_normal_texture_loads_as_the_parts_normal_map(tmp_path):
    import trimesh
    from PIL import Image

    box = trimesh.creation.box()
    uvs = np.random.default_rng(0).random((len(box.vertices), 2))
    normals = np.zeros((4, 4, 3), dtype=np.uint8)
    normals[:] = (140, 120, 250)
    material = trimesh.visual.material.PBRMaterial(baseColorFactor=[200, 100, 50, 255],
                                                   normalTexture=Image.fromarray(normals))  # fmt: skip
    box.visual = trimesh.visual.TextureVisuals(uv=uvs, material=material)
    box.export(tmp_path / "box.glb")
    part = fr.load_parts(tmp_path / "box.glb")[0]
    np.testing.assert_array_equal(part.normal_map, normals)
    assert fr.Material(normal_map=part.normal_map).normal_map.shape == (4, 4, 4)
