"""Issue 46, round 2: the metallic–roughness model on the one-mesh tile path (the general path's bytes), the
emissive texture, and bump/normal maps under that model."""

from __future__ import annotations

import numpy as np
import pytest
from tests.test_pbr import spec_brdf

import frustum as fr
from frustum.raster import pbr_tiled
from frustum.shading.tone import srgb_to_linear


def _sky():
    theta = (np.arange(16) + 0.5) / 16 * np.pi
    sky = np.stack([0.3 + 0.5 * np.cos(theta) ** 2, 0.4 + 0.4 * np.cos(theta), 0.8 + 0.2 * np.cos(theta)], axis=-1)
    image = np.repeat(sky[:, None, :], 32, axis=1)
    image[4:7, 8:12] = [3.0, 2.2, 1.2]  # a warm lobe
    return fr.EnvironmentMap(image.astype(np.float32))


@pytest.mark.parametrize(("metallic", "roughness", "tone_map"), [(0.6, 0.45, "none"), (0.0, 0.9, "aces"),
                                                                 (1.0, 0.1, "khronos-neutral")])  # fmt: skip
def test_the_tile_path_gives_the_general_paths_bytes(monkeypatch, metallic, roughness, tone_map):
    lights = [fr.DirectionalLight((0.4, -0.5, -1.0), intensity=2.5),
              fr.PointLight(position=(1.5, 1.0, 2.0), intensity=6.0, range=8.0),
              fr.SpotLight(position=(-1.0, 2.0, 2.0), direction=(0.3, -0.6, -0.6), intensity=9.0)]  # fmt: skip
    scene = fr.Scene(lights, environment=_sky())
    scene.add(fr.icosphere(1.0, 4), fr.Material(color=(0.8, 0.45, 0.2), metallic=metallic, roughness=roughness,
                                                model="pbr", emissive=(0.05, 0.0, 0.02)))  # fmt: skip
    camera = fr.Camera.look_at((0.3, 0.4, 3.2), (0, 0, 0), (0, 1, 0), fr.Perspective(0.75, 0.1, 10.0), 150, 130)
    calls = []
    real = pbr_tiled.draw_tiles_pbr
    monkeypatch.setattr(pbr_tiled, "draw_tiles_pbr", lambda *args: calls.append(1) or real(*args))
    tiled = fr.render(scene, camera, shading="pbr", tone_map=tone_map, background=(0.1, 0.2, 0.3, 1.0))
    assert calls, "the frame of one opaque mesh went tile by tile"
    general = fr.render(scene, camera, shading="pbr", tone_map=tone_map, background=(0.1, 0.2, 0.3, 1.0),
                        buffers=("normals",))  # fmt: skip
    assert len(calls) == 1, "extra buffers take the stage-by-stage path"
    assert (tiled.depth < 1.0).sum() > 5000
    np.testing.assert_array_equal(tiled.depth, general.depth)
    np.testing.assert_array_equal(tiled.color, general.color)


def _bilinear(texture, u, v):
    """The texture lookup of the kernels, written here: repeat wrapping, texel centres at half integers, v = 0 the
    image's bottom row."""
    height, width = texture.shape[:2]
    x = (u - np.floor(u)) * width - 0.5
    y = (1.0 - (v - np.floor(v))) * height - 0.5
    x0, y0 = np.floor(x), np.floor(y)
    fx, fy = (x - x0)[:, None], (y - y0)[:, None]
    i0, j0 = x0.astype(int) % width, y0.astype(int) % height
    i1, j1 = (i0 + 1) % width, (j0 + 1) % height
    top = texture[j0, i0] * (1 - fx) + texture[j0, i1] * fx
    bottom = texture[j1, i0] * (1 - fx) + texture[j1, i1] * fx
    return top * (1 - fy) + bottom * fy


def _srgb_encode(linear):
    linear = np.clip(linear, 0.0, 1.0)
    return np.where(linear <= 0.0031308, 12.92 * linear, 1.055 * linear ** (1 / 2.4) - 0.055)


def test_an_emissive_texture_times_its_factor_is_the_emission():
    rng = np.random.default_rng(46)
    texture = rng.integers(0, 256, (6, 8, 3), dtype=np.uint8)
    factor = np.array([1.0, 0.6, 0.3])
    material = fr.Material(color=(0.0, 0.0, 0.0), model="pbr", emissive=factor, emissive_texture=texture)
    scene = fr.Scene([])  # unlit: a black base reflects nothing then (its specular needs a light)
    scene.add(fr.plane((2.0, 2.0)), material)
    camera = fr.Camera.look_at((0.1, -0.2, 2.5), (0, 0, 0), (0, 1, 0), fr.Perspective(0.9, 0.1, 10.0), 90, 80)
    frame = fr.render(scene, camera, shading="pbr", color_space="srgb", buffers=("position",))
    drawn = frame.depth < 1.0
    assert drawn.sum() > 2000
    points = frame.position[drawn].astype(np.float64)
    u, v = (points[:, 0] + 1.0) / 2.0, (points[:, 1] + 1.0) / 2.0
    linear = _bilinear(srgb_to_linear(texture / 255.0).astype(np.float64), u, v) * factor
    stored = np.floor(np.clip(linear, 0.0, 1.0) * 255 + 0.5) / 255  # the frame's linear bytes, then encoded
    expected = np.floor(_srgb_encode(stored) * 255 + 0.5)
    got = frame.color[drawn][:, :3].astype(int)
    assert np.abs(got - expected).max() <= 1
    unlit = fr.render(scene, camera, shading="pbr", color_space="srgb")  # no extra buffer: the same pixels
    assert np.array_equal(unlit.color, frame.color)
    assert np.abs(got - np.floor(_srgb_encode(factor * 0.0) * 255 + 0.5)).max() > 50  # the texture shows


@pytest.mark.parametrize(("metallic", "roughness"), [(0.0, 0.4), (1.0, 0.6)])
def test_a_normal_mapped_plane_under_pbr_equals_the_brdf_at_the_perturbed_normal(metallic, roughness):
    tangent_normal = np.array([0.3, -0.2, 0.9])
    tangent_normal /= np.linalg.norm(tangent_normal)
    image = np.tile((127.0 * tangent_normal + 128.0) / 255.0, (4, 4, 1)).astype(np.float32)  # 128 encodes 0
    base = np.array([0.8, 0.45, 0.2])
    material = fr.Material(color=base, metallic=metallic, roughness=roughness, model="pbr", normal_map=image)
    sun, lux = np.array([0.2, 0.3, -1.0]), 2.0
    scene = fr.Scene([fr.DirectionalLight(sun, intensity=lux)])
    scene.add(fr.plane((2.0, 2.0)), material)
    camera = fr.Camera.look_at((0.4, -0.6, 2.2), (0, 0, 0), (0, 1, 0), fr.Perspective(0.9, 0.1, 10.0), 90, 80)
    frame = fr.render(scene, camera, shading="pbr", buffers=("position",))
    drawn = frame.depth < 1.0
    assert drawn.sum() > 2000
    points = frame.position[drawn].astype(np.float64)
    count = len(points)
    # the plane's tangent frame: p_u = +x, p_v = +y, n = +z, so the encoded normal is the world normal
    normal = np.tile(tangent_normal, (count, 1))
    to_eye = camera.frame.eye - points
    to_eye /= np.linalg.norm(to_eye, axis=1, keepdims=True)
    to_light = np.tile(-sun / np.linalg.norm(sun), (count, 1))
    f = spec_brdf(normal, to_light, to_eye, np.tile(base, (count, 1)), np.full(count, metallic),
                  np.full(count, roughness))  # fmt: skip
    radiance = f * lux * np.maximum(np.sum(normal * to_light, axis=1), 0.0)[:, None]
    expected = np.floor(np.clip(radiance, 0.0, 1.0) * 255 + 0.5)
    got = frame.color[drawn][:, :3].astype(int)
    assert np.abs(got - expected).max() <= 1
    unmapped = fr.Scene([fr.DirectionalLight(sun, intensity=lux)])
    unmapped.add(fr.plane((2.0, 2.0)), material.with_(normal_map=None))
    assert np.array_equal(fr.render(scene, camera, shading="pbr").color, frame.color)  # without the buffer too
    assert np.abs(fr.render(unmapped, camera, shading="pbr").color.astype(int) - frame.color).max() > 10


def test_a_scene_file_names_the_emissive_texture(tmp_path):
    from PIL import Image

    from frustum.scenefile import load_scene_file

    texels = np.zeros((4, 4, 3), dtype=np.uint8)
    texels[:, :2] = (255, 128, 0)
    Image.fromarray(texels).save(tmp_path / "glow.png")
    (tmp_path / "scene.toml").write_text(
        '[camera]\neye = [0.0, 0.0, 2.5]\ntarget = [0.0, 0.0, 0.0]\n\n'
        '[materials.glow]\nmodel = "pbr"\ncolor = [0.0, 0.0, 0.0]\nemissive = [1.0, 1.0, 1.0]\n'
        'emissive_texture = "glow.png"\n\n'
        '[[nodes]]\nname = "quad"\nmaterial = "glow"\ngeometry = { type = "plane", size = [2.0, 2.0] }\n'
    )  # fmt: skip
    loaded = load_scene_file(tmp_path / "scene.toml")
    material = loaded.scene.items[0].material
    np.testing.assert_array_equal(np.round(material.emissive_texture[..., :3] * 255), texels)
