"""glTF metallic–roughness shading: the BRDF against the specification's formulas written here (not the code's),
the kernel against both, a sphere per pixel, energy bounds (Hypothesis), image-based lighting's white furnace, tone
maps, glTF loading of the metallic–roughness channels, and bad input. Oracles from other renderers (pyrender,
Mitsuba 3) are in ``test_pbr_oracles.py``."""

from __future__ import annotations

import math

import numpy as np
import pytest
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st
from PIL import Image

import frustum as fr
from frustum.errors import FrustumError, ShadingError
from frustum.raster import pbr as kernels
from frustum.shading import ibl, pbr, tone

# --- the specification, written here -------------------------------------------------------------------------


def spec_brdf(n, l, v, base, metallic, roughness):  # noqa: E741
    """glTF 2.0 Appendix B (and the Khronos sample renderer's height-correlated visibility), per sample, from the
    formulas: h the half vector, α = roughness², D the GGX distribution, V_GGX the height-correlated Smith term,
    F Schlick's. For metallic 0 the BRDF is (1 − F(0.04))·base/π + F(0.04)·V·D; for metallic 1 it is
    V·D·F(base); in between the specification mixes the two linearly by metallic."""
    out = np.zeros((len(n), 3))
    for i in range(len(n)):
        N, L, Vw = n[i], l[i], v[i]
        H = (L + Vw) / np.linalg.norm(L + Vw)
        a = roughness[i] ** 2
        NdotL, NdotV, NdotH, VdotH = N @ L, N @ Vw, N @ H, Vw @ H
        if NdotL <= 0:
            continue
        d_ggx = a * a / (math.pi * (NdotH * NdotH * (a * a - 1) + 1) ** 2) if NdotH > 0 else 0.0
        a2 = a * a
        v_ggx = 0.5 / (NdotL * math.sqrt(NdotV**2 * (1 - a2) + a2) + NdotV * math.sqrt(NdotL**2 * (1 - a2) + a2))
        schlick = (1 - abs(VdotH)) ** 5
        f_dielectric = 0.04 + 0.96 * schlick
        dielectric = (1 - f_dielectric) * base[i] / math.pi + f_dielectric * v_ggx * d_ggx
        metal = v_ggx * d_ggx * (base[i] + (1 - base[i]) * schlick)
        out[i] = (1 - metallic[i]) * dielectric + metallic[i] * metal
    return out


def _unit(rng, count):
    x = rng.normal(size=(count, 3))
    return x / np.linalg.norm(x, axis=1, keepdims=True)


def _random_configurations(seed, count=400):
    rng = np.random.default_rng(seed)
    n = _unit(rng, count)
    l, v = _unit(rng, count), _unit(rng, count)  # noqa: E741
    l = np.where(((n * l).sum(1) < 0.02)[:, None], l - 2 * (n * l).sum(1, keepdims=True) * n, l)  # noqa: E741
    v = np.where(((n * v).sum(1) < 0.02)[:, None], v - 2 * (n * v).sum(1, keepdims=True) * n, v)
    keep = ((n * l).sum(1) > 0.02) & ((n * v).sum(1) > 0.02)
    base = rng.random((count, 3))
    metallic = rng.random(count)
    roughness = 0.05 + 0.95 * rng.random(count)
    return n[keep], l[keep], v[keep], base[keep], metallic[keep], roughness[keep]


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_numpy_brdf_equals_the_specification(seed):
    n, l, v, base, metallic, roughness = _random_configurations(seed)  # noqa: E741
    np.testing.assert_allclose(pbr.brdf(n, l, v, base, metallic, roughness),
                               spec_brdf(n, l, v, base, metallic, roughness), rtol=1e-5, atol=1e-5)  # fmt: skip


def _kernel_brdf(n, l, v, base, metallic, roughness):  # noqa: E741
    """The kernel's radiance with one directional light of illuminance 1 and nothing else, divided by n·l."""
    from frustum.raster import shade

    params = np.zeros(shade.PARAMS)
    values = np.zeros(kernels.PBR)
    sh, maps, table = np.zeros((9, 3)), np.zeros((2, 1, 2, 3), np.float32), ibl.brdf_table()
    out = np.zeros((len(n), 3))
    for i in range(len(n)):
        point = np.zeros(3)
        params[shade.P_EYE : shade.P_EYE + 3] = point + v[i]  # the eye one unit along v
        lights = np.zeros((1, 16))
        lights[0, 1:4] = 1.0
        lights[0, 7:10] = l[i]
        r, g, b = kernels.radiance(n[i, 0], n[i, 1], n[i, 2], 0.0, 0.0, 0.0, base[i, 0], base[i, 1], base[i, 2],
                                   metallic[i], roughness[i], 1.0, params, values, lights, sh, maps, table,
                                   np.empty((0, 0, 0), np.float32), 0, 0)  # fmt: skip
        out[i] = np.array([r, g, b]) / (n[i] @ l[i])
    return out


@pytest.mark.parametrize("seed", [3, 4])
def test_kernel_brdf_equals_the_specification(seed):
    n, l, v, base, metallic, roughness = _random_configurations(seed, 150)  # noqa: E741
    np.testing.assert_allclose(_kernel_brdf(n, l, v, base, metallic, roughness),
                               spec_brdf(n, l, v, base, metallic, roughness), rtol=1e-5, atol=1e-5)  # fmt: skip


# --- a sphere, per pixel ----------------------------------------------------------------------------------------

SUN = (0.4, -0.5, -1.0)


def _sphere_scene(material, lights=None, environment=None):
    scene = fr.Scene(lights if lights is not None else [fr.DirectionalLight(SUN, intensity=2.5)],
                     environment=environment)  # fmt: skip
    scene.add(fr.icosphere(1.0, 4), material)
    return scene


def _camera(size=96):
    return fr.Camera.look_at((0.3, 0.4, 3.2), (0, 0, 0), (0, 1, 0), fr.Perspective(0.75, 0.1, 10.0), size, size)


@pytest.mark.parametrize(("metallic", "roughness", "tone_map", "exposure"),
                         [(0.0, 0.35, "none", 1.0), (1.0, 0.5, "none", 1.0), (0.4, 0.8, "aces", 1.5),
                          (0.0, 0.25, "khronos-neutral", 2.0)])  # fmt: skip
def test_a_sphere_under_a_directional_light_equals_the_specification_at_every_pixel(metallic, roughness, tone_map,
                                                                                       exposure):  # fmt: skip
    base = np.array([0.8, 0.45, 0.2])
    material = fr.Material(color=base, metallic=metallic, roughness=roughness, model="pbr")
    camera = _camera()
    frame = fr.render(_sphere_scene(material), camera, buffers=("normals", "position"), tone_map=tone_map,
                      exposure=exposure)  # fmt: skip
    drawn = frame.depth < 1.0
    assert drawn.sum() > 2000
    normals = frame.normals[drawn].astype(np.float64)
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    points = frame.position[drawn].astype(np.float64)
    to_eye = camera.frame.eye - points
    to_eye /= np.linalg.norm(to_eye, axis=1, keepdims=True)
    to_light = -np.asarray(SUN) / np.linalg.norm(SUN)
    count = len(points)
    f = spec_brdf(normals, np.tile(to_light, (count, 1)), to_eye, np.tile(base, (count, 1)), np.full(count, metallic),
                  np.full(count, roughness))  # fmt: skip
    radiance = f * 2.5 * np.maximum(normals @ to_light, 0.0)[:, None]
    expected = np.floor(tone.tone_map(radiance, tone_map, exposure) * 255 + 0.5)
    got = frame.color[drawn][:, :3].astype(int)
    assert np.abs(got - expected).max() <= 1


def test_classical_pictures_are_untouched_and_pbr_materials_shade_by_their_model():
    plastic = fr.Material(color=(0.8, 0.45, 0.2))
    classical = fr.render(_sphere_scene(plastic), _camera())
    again = fr.render(_sphere_scene(plastic.with_(metallic=0.7, roughness=0.2)), _camera())
    assert np.array_equal(classical.color, again.color)  # the metallic-roughness fields do not touch Phong
    physical = fr.render(_sphere_scene(plastic.with_(model="pbr")), _camera())
    forced = fr.render(_sphere_scene(plastic.with_(model="pbr")), _camera(), shading="pbr")
    assert np.array_equal(physical.color, forced.color) and not np.array_equal(physical.color, classical.color)
    # a classical material under shading="pbr": base = color, roughness from the shininess
    mapped = fr.render(_sphere_scene(plastic), _camera(), shading="pbr")
    same = fr.render(_sphere_scene(plastic.with_(model="pbr", roughness=pbr.phong_roughness(32.0))), _camera())
    assert np.array_equal(mapped.color, same.color)
    gouraud = fr.render(_sphere_scene(plastic.with_(model="pbr")), _camera(), shading="gouraud")
    assert np.array_equal(gouraud.color, fr.render(_sphere_scene(plastic), _camera(), shading="gouraud").color)


def test_point_and_spot_lights_fall_off_by_the_inverse_square_and_the_range_window():
    material = fr.Material(color=(0.6, 0.6, 0.6), metallic=0.0, roughness=0.7, model="pbr")
    near = fr.render(_sphere_scene(material, [fr.PointLight((0.0, 0.0, 3.0), intensity=9.0)]), _camera())
    far = fr.render(_sphere_scene(material, [fr.PointLight((0.0, 0.0, 5.0), intensity=25.0)]), _camera())
    centre = near.color[48, 48, :3].astype(int)
    # at the point facing the light the illuminance is I/d²: 9/2² = 2.25 and 25/4² = 1.5625
    assert centre[0] > far.color[48, 48, 0]
    ranged = fr.render(_sphere_scene(material, [fr.PointLight((0.0, 0.0, 3.0), intensity=9.0, range=2.5)]),
                       _camera())  # fmt: skip
    window = (1 - (2.0 / 2.5) ** 4) ** 2  # the nearest point is 2 away
    assert 0 < ranged.color[48, 48, 0] < centre[0] * window + 8
    spot = fr.SpotLight((0.0, 0.0, 3.0), (0.0, 0.0, -1.0), intensity=9.0, inner_angle=0.05, outer_angle=0.1)
    lit = fr.render(_sphere_scene(material, [spot]), _camera())
    assert (lit.color[..., 0] > 0).sum() < (near.color[..., 0] > 0).sum() / 4  # only a cone is lit


# --- energy ------------------------------------------------------------------------------------------------------


@settings(max_examples=60, deadline=None, derandomize=True)
@given(st.floats(0.02, 1.0), st.floats(0.0, 1.0), st.floats(0.01, 1.0), st.floats(0.01, 1.0), st.floats(0.0, 6.28))
def test_the_brdf_is_reciprocal(roughness, metallic, cos_l, cos_v, phi):
    n = np.array([[0.0, 0.0, 1.0]])
    sin_l, sin_v = math.sqrt(1 - cos_l**2), math.sqrt(1 - cos_v**2)
    l = np.array([[sin_l, 0.0, cos_l]])  # noqa: E741
    v = np.array([[sin_v * math.cos(phi), sin_v * math.sin(phi), cos_v]])
    base = np.array([0.9, 0.5, 0.1])
    forward, backward = pbr.brdf(n, l, v, base, metallic, roughness), pbr.brdf(n, v, l, base, metallic, roughness)
    np.testing.assert_allclose(forward, backward, rtol=1e-12, atol=1e-14)


def _albedo(roughness, metallic, theta_v, base=1.0, steps=400):
    """∫ f(l, v)·(n·l) dω over the hemisphere by the midpoint rule in (θ, φ)."""
    theta = (np.arange(steps) + 0.5) * (math.pi / 2) / steps
    phi = (np.arange(2 * steps) + 0.5) * math.pi / steps
    t, p = np.meshgrid(theta, phi, indexing="ij")
    l = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], axis=-1).reshape(-1, 3)  # noqa: E741
    v = np.array([math.sin(theta_v), 0.0, math.cos(theta_v)])
    n = np.array([0.0, 0.0, 1.0])
    count = len(l)
    f = pbr.brdf(np.tile(n, (count, 1)), l, np.tile(v, (count, 1)), np.full((count, 3), base), metallic, roughness)
    weight = (np.cos(t) * np.sin(t)).reshape(-1) * (math.pi / 2 / steps) * (math.pi / steps)
    return (f[:, 0] * weight).sum()


@settings(max_examples=30, deadline=None, derandomize=True)
@given(st.floats(0.3, 1.0), st.floats(0.0, 1.45))
def test_a_white_metal_reflects_no_more_than_it_receives(roughness, theta_v):
    # the white furnace bound: directional albedo <= 1 (single-scattering GGX loses energy, never gains it)
    assert _albedo(roughness, 1.0, theta_v) <= 1.0 + 2e-3


@settings(max_examples=30, deadline=None, derandomize=True)
@given(st.floats(0.3, 1.0), st.floats(0.0, 1.0), st.floats(0.0, 1.45))
def test_the_specifications_dielectric_mix_exceeds_one_only_by_its_fresnel_at_grazing_views(roughness, metallic,
                                                                                               theta_v):  # fmt: skip
    # glTF's mix(base/π, V·D, F(v·h)) weights the diffuse part by 1 − F per microfacet, so a white dielectric seen
    # at a grazing angle reflects up to 1.27 of what it receives (roughness 0.3, 83°: docs/materials.md); the
    # excess stays below Schlick's F at the view angle, and views within 40° of the normal stay within 1
    albedo = _albedo(roughness, metallic, theta_v)
    assert albedo <= 1.0 + (1.0 - metallic) * (0.04 + 0.96 * (1.0 - math.cos(theta_v)) ** 5) + 2e-3
    if theta_v <= 0.7:
        assert albedo <= 1.0 + 2e-3


def test_no_pixel_is_brighter_than_the_light_allows():
    # a white Lambertian-like surface under illuminance E reflects at most E·(f·cos)max; E = 1 keeps every
    # channel below the brightest value the BRDF takes at normal light
    material = fr.Material(color=(1.0, 1.0, 1.0), metallic=0.0, roughness=1.0, model="pbr")
    frame = fr.render(_sphere_scene(material, [fr.DirectionalLight((0, 0, -1), intensity=1.0)]), _camera())
    bound = pbr.brdf([[0, 0, 1]], [[0, 0, 1]], [[0, 0, 1]], [1, 1, 1], 0.0, 1.0)[0, 0]
    assert frame.color[..., :3].max() <= math.floor(bound * 255 + 0.5) + 1


def test_the_split_sum_table_never_creates_energy():
    table = ibl.brdf_table()
    assert (table >= 0).all() and (table.sum(axis=2) <= 1.0 + 1e-4).all()
    # smooth surfaces at normal view reflect almost everything; the table's A + B matches the albedo integral
    for j, roughness in ((31, 1.0), (16, 16 / 31)):
        for i in (8, 24):
            theta = math.acos((i + 0.5) / 32)
            assert table[i, j].sum() == pytest.approx(_albedo(roughness, 1.0, theta), abs=0.02)


# --- image-based lighting ---------------------------------------------------------------------------------------


@pytest.mark.parametrize("roughness", [0.1, 0.5, 1.0])
def test_white_furnace_a_white_dielectric_returns_the_environment(roughness):
    environment = fr.EnvironmentMap(np.full((16, 32, 3), 0.5, dtype=np.float32))
    material = fr.Material(color=(1.0, 1.0, 1.0), metallic=0.0, roughness=roughness, model="pbr")
    frame = fr.render(_sphere_scene(material, [], environment), _camera(), background=(0, 0, 0, 1))
    drawn = frame.depth < 1.0
    assert np.abs(frame.color[drawn][:, :3].astype(int) - 128).max() <= 1


def test_ambient_light_is_a_uniform_environment():
    material = fr.Material(color=(0.7, 0.3, 0.9), metallic=0.3, roughness=0.6, model="pbr")
    environment = fr.EnvironmentMap(np.full((16, 32, 3), 0.4, dtype=np.float32))
    by_map = fr.render(_sphere_scene(material, [], environment), _camera(), background=(0, 0, 0, 1))
    by_light = fr.render(_sphere_scene(material, [fr.AmbientLight(intensity=0.4)]), _camera())
    assert np.abs(by_map.color.astype(int) - by_light.color.astype(int)).max() <= 1


def test_a_metal_sphere_shows_the_environment_blurred_by_roughness():
    rng = np.random.default_rng(7)
    image = np.repeat(np.repeat(rng.random((8, 16, 3)), 8, axis=0), 8, axis=1).astype(np.float32)  # blocks
    environment = fr.EnvironmentMap(image)
    spread = []
    for roughness in (0.0, 0.4, 1.0):
        material = fr.Material(color=(1.0, 1.0, 1.0), metallic=1.0, roughness=roughness, model="pbr")
        frame = fr.render(_sphere_scene(material, [], environment), _camera(), background=(0, 0, 0, 1))
        spread.append(frame.color[frame.depth < 1.0][:, :3].astype(float).std())
    assert spread[0] > spread[1] > spread[2]
    # a mirror shows the map along the reflected ray
    camera = _camera()
    mirror = fr.Material(color=(1.0, 1.0, 1.0), metallic=1.0, roughness=0.0, model="pbr")
    frame = fr.render(_sphere_scene(mirror, [], environment), camera, buffers=("normals", "position"))
    drawn = frame.depth < 1.0
    n = frame.normals[drawn].astype(float)
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    v = camera.frame.eye - frame.position[drawn]
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    reflected = 2 * (n * v).sum(1, keepdims=True) * n - v
    a, b = ibl.table_lookup(ibl.brdf_table(), (n * v).sum(1), 0.0)
    expected = environment.lookup(reflected) * (a + b)[:, None]
    close = np.abs(frame.color[drawn][:, :3] - np.floor(np.clip(expected, 0, 1) * 255 + 0.5)) <= 24
    assert close.all(axis=1).mean() > 0.9  # the map resampled to 128 x 256 texels: edges of blocks differ


def test_the_precomputed_maps_and_coefficients():
    environment = fr.EnvironmentMap(np.full((8, 16, 3), 2.0, dtype=np.float32))
    lighting = ibl.image_lighting(environment)
    assert lighting is ibl.image_lighting(environment)  # cached
    np.testing.assert_allclose(lighting.prefiltered, 2.0, rtol=1e-5)
    # irradiance / π of a uniform map of radiance L is L
    np.testing.assert_allclose(ibl.sh_basis([[0.0, 0.0, 1.0], [0.6, 0.8, 0.0]]) @ lighting.sh, 2.0, rtol=1e-3)
    # one bright direction: the SH irradiance is the clamped cosine lobe to the order-2 accuracy (≤ 10 % of peak)
    image = np.zeros((32, 64, 3), dtype=np.float32)
    image[0:2] = 50.0  # a cap around +y
    lighting = ibl.image_lighting(fr.EnvironmentMap(image))
    directions, solid = ibl.texel_directions(64)
    radiance = ibl.resampled(fr.EnvironmentMap(image), 64).reshape(-1, 3)[:, 0]
    for normal in ([0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, -1.0, 0.0]):
        exact = (radiance * np.maximum(directions @ normal, 0) * solid).sum() / math.pi
        peak = (radiance * np.maximum(directions[:, 1], 0) * solid).sum() / math.pi
        assert (ibl.sh_basis([normal]) @ lighting.sh)[0, 0] == pytest.approx(exact, abs=0.1 * peak)


# --- tone maps ------------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", ["none", "aces", "khronos-neutral"])
def test_kernel_tone_maps_equal_numpy(name):
    rng = np.random.default_rng(11)
    colors = rng.random((300, 3)) * rng.choice([0.05, 1.0, 4.0, 20.0], size=(300, 1))
    expected = tone.tone_map(colors, name, 1.3)
    code = tone.TONE_MAPS[name]
    got = np.array([kernels.tone(code, 1.3, *c) for c in colors])
    np.testing.assert_allclose(np.clip(got, 0, 1), expected, atol=1e-12)


def test_tone_maps_known_values():
    assert tone.aces_filmic(0.0) == 0.0 and tone.aces_filmic(100.0) == pytest.approx(1.0, abs=0.05)
    assert tone.aces_filmic(0.18) == pytest.approx(0.18 * (2.51 * 0.18 + 0.03) / (0.18 * (2.43 * 0.18 + 0.59) + 0.14))
    # Khronos PBR Neutral keeps colours below its compression start (after the small toe offset) and maps
    # bright colours below 1
    assert np.allclose(tone.khronos_neutral([[0.5, 0.3, 0.2]]), [[0.46, 0.26, 0.16]])
    assert (tone.khronos_neutral([[50.0, 20.0, 10.0]]) < 1.0).all()
    np.testing.assert_allclose(tone.srgb_to_linear([0.0, 0.04045, 1.0]), [0.0, 0.04045 / 12.92, 1.0], rtol=1e-6)


# --- glTF loading ---------------------------------------------------------------------------------------------------


def _glb(path, metallic_roughness=None, **factors):
    box = trimesh.creation.box()
    uvs = np.random.default_rng(0).random((len(box.vertices), 2))
    texture = None if metallic_roughness is None else Image.fromarray(metallic_roughness)
    box.visual = trimesh.visual.TextureVisuals(uv=uvs, material=trimesh.visual.material.PBRMaterial(
        baseColorFactor=[255, 255, 255, 255], metallicRoughnessTexture=texture, **factors))  # fmt: skip
    box.export(path)
    return path


def test_a_glb_loads_metallic_from_blue_and_roughness_from_green(tmp_path):
    from frustum.render.pbr import surface_maps
    from frustum.scenefile.models import part_material

    channels = np.zeros((4, 4, 3), dtype=np.uint8)
    channels[..., 0], channels[..., 1], channels[..., 2] = 10, 200, 60  # R unused, G roughness, B metallic
    part = fr.load_parts(_glb(tmp_path / "box.glb", channels, metallicFactor=0.5, roughnessFactor=0.25))[0]
    material = part_material(part)
    assert material.model == "pbr" and (material.metallic, material.roughness) == (0.5, 0.25)
    maps = surface_maps(material)
    np.testing.assert_allclose(maps[0, 0], [1.0, 200 / 255, 60 / 255, 1.0], rtol=1e-6)  # occlusion 1, G, B
    # the kernel reads channel 2 as metallic: a fully metal texture takes the diffuse away
    metal = np.zeros((4, 4, 3), dtype=np.uint8)
    metal[..., 1], metal[..., 2] = 128, 255
    dull = metal.copy()
    dull[..., 2] = 0
    lights = [fr.DirectionalLight((0.2, -0.3, -1.0), intensity=3.0)]
    pictures = []
    for name, image in (("metal.glb", metal), ("dull.glb", dull)):
        scene = fr.Scene(lights)
        node = fr.load_parts(_glb(tmp_path / name, image, metallicFactor=1.0, roughnessFactor=1.0))[0]
        scene.add(node.mesh, part_material(node))
        pictures.append(fr.render(scene, _camera(), cull_back_faces=False).color[..., :3].astype(int))
    assert pictures[1].sum() > 1.5 * pictures[0].sum()


def test_a_glb_material_without_factors_gets_the_specifications_defaults(tmp_path):
    from frustum.scenefile.models import part_material

    material = part_material(fr.load_parts(_glb(tmp_path / "plain.glb"))[0])
    assert (material.model, material.metallic, material.roughness) == ("pbr", 1.0, 1.0)


def test_a_glb_emissive_texture_loads_into_the_material_and_glows(tmp_path):
    """glTF's ``emissiveTexture`` × ``emissiveFactor``, by frustum's own glTF reader and by trimesh's (a file the
    own reader leaves to trimesh: a second UV set)."""
    from frustum.geometry import io
    from frustum.scenefile.models import part_material

    glow = np.zeros((8, 8, 3), dtype=np.uint8)
    glow[..., 0], glow[..., 1], glow[..., 2] = 200, 40, 90
    box = trimesh.creation.box()
    material = trimesh.visual.material.PBRMaterial(baseColorFactor=[0, 0, 0, 255], emissiveFactor=[1.0, 0.5, 1.0],
                                                   emissiveTexture=Image.fromarray(glow))  # fmt: skip
    box.visual = trimesh.visual.TextureVisuals(uv=np.full((len(box.vertices), 2), 0.5), material=material)
    path = tmp_path / "glow.glb"
    box.export(path)
    parts = {"own reader": fr.load_parts(path)[0], "trimesh": io.scene_parts(trimesh.load(path, force="scene"),
                                                                             path)[0]}  # fmt: skip
    for reader, part in parts.items():
        np.testing.assert_array_equal(part.emissive_texture, glow, err_msg=reader)
        material = part_material(part)
        assert np.allclose(material.emissive, (1.0, 0.5, 1.0)) and material.emissive_texture is not None, reader
    scene = fr.Scene()  # unlit: the emission alone, factor × texture (linear after sRGB decoding), then sRGB
    scene.add(parts["own reader"].mesh, part_material(parts["own reader"]))
    frame = fr.render(scene, _camera(), shading="pbr", tone_map="none", color_space="srgb")
    covered = frame.depth < 1.0
    texel = np.array([200, 40, 90]) / 255.0
    linear = np.where(texel <= 0.04045, texel / 12.92, ((texel + 0.055) / 1.055) ** 2.4) * (1.0, 0.5, 1.0)
    encoded = np.where(linear <= 0.0031308, 12.92 * linear, 1.055 * linear ** (1 / 2.4) - 0.055) * 255.0
    assert covered.sum() > 100
    assert np.abs(frame.color[covered][:, :3].astype(float) - encoded).max() <= 2.0


# --- bad input ------------------------------------------------------------------------------------------------------


def test_bad_materials_lights_and_options_are_refused_with_the_value():
    with pytest.raises(ShadingError, match="model = 'glossy'"):
        fr.Material(model="glossy")
    with pytest.raises(ShadingError, match=r"metallic = 1\.5"):
        fr.Material(metallic=1.5)
    with pytest.raises(ShadingError, match=r"roughness = -0\.1"):
        fr.Material(roughness=-0.1)
    with pytest.raises(ShadingError, match="both texture and base_color_texture"):
        fr.Material(texture=np.zeros((2, 2, 3), np.uint8), base_color_texture=np.zeros((2, 2, 3), np.uint8))
    with pytest.raises(ShadingError, match=r"range = 0\.0"):
        fr.PointLight((0, 0, 1), range=0.0)
    scene, camera = _sphere_scene(fr.Material()), _camera(8)
    with pytest.raises(FrustumError, match="tone_map = 'filmic' is unknown"):
        fr.render(scene, camera, tone_map="filmic")
    with pytest.raises(FrustumError, match=r"exposure = 0\.0"):
        fr.render(scene, camera, exposure=0.0)
    with pytest.raises(FrustumError, match="A-buffer"):
        fr.render(scene, camera, shading="pbr", method="a-buffer")


def test_a_base_color_texture_is_decoded_from_srgb():
    encoded = np.full((2, 2, 3), 188, dtype=np.uint8)  # sRGB 188/255 ≈ linear 0.5
    material = fr.Material(base_color_texture=encoded, model="pbr")
    assert material.base_color_texture is None and material.texture[0, 0, 0] == pytest.approx(0.5029, abs=1e-3)
    assert np.array_equal(material.with_(roughness=0.3).texture, material.texture)


def test_an_8_bit_base_color_texture_is_decoded_to_the_bytes_of_its_float_form():
    """Bytes go through a table of the curve at their 256 values: the same float32s as the curve at k/255."""
    values = np.arange(256, dtype=np.uint8)
    for encoded in (np.stack([values, values[::-1], values], axis=-1).reshape(16, 16, 3),
                    np.stack([values, values, values[::-1], values], axis=-1).reshape(16, 16, 4),
                    values.reshape(16, 16)):  # fmt: skip
        as_floats = encoded.astype(np.float32) / np.float32(255.0)
        table = fr.Material(base_color_texture=encoded, model="pbr").texture
        curve = fr.Material(base_color_texture=as_floats, model="pbr").texture
        assert table.dtype == curve.dtype == np.float32 and np.array_equal(table, curve)


# --- ray tracing ----------------------------------------------------------------------------------------------------


@pytest.mark.parametrize(("metallic", "roughness"), [(0.0, 0.4), (1.0, 0.6)])
def test_ray_tracing_shades_direct_and_image_light_as_the_depth_buffer(metallic, roughness):
    material = fr.Material(color=(0.8, 0.45, 0.2), metallic=metallic, roughness=roughness, model="pbr")
    environment = fr.EnvironmentMap(np.random.default_rng(2).random((16, 32, 3)).astype(np.float32))
    lights = [fr.DirectionalLight(SUN, intensity=2.0), fr.PointLight((1.0, 2.0, 2.5), intensity=6.0),
              fr.AmbientLight(intensity=0.1)]  # fmt: skip
    scene = _sphere_scene(material, lights, environment)
    buffer = fr.render(scene, _camera(), background=(0, 0, 0, 1), tone_map="aces")
    traced = fr.render(scene, _camera(), background=(0, 0, 0, 1), tone_map="aces", method="ray-tracing")
    both = (buffer.depth < 1.0) & (traced.depth < 1.0)
    difference = np.abs(buffer.color[both].astype(int) - traced.color[both].astype(int))
    # the same formulas, NumPy (shading.pbr, shading.ibl) against the kernel: rounding flips a level here and there
    assert both.sum() > 2000 and (difference <= 1).mean() > 0.95 and difference.max() <= 8  # (rims of the metal)
