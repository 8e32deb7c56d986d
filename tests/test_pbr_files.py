"""Metallic–roughness materials and lights as files carry them: the PBR statements of MTL files (``Pr``, ``Pm``,
``map_Pr``, ``map_Pm``), glTF's ``KHR_lights_punctual`` lights, the ray tracer's mirror for smooth metals, and the
output transform where the viewer, datasets and turntables render."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from frustum.geometry.io import load_parts
from frustum.scenefile.models import part_material

# --- MTL PBR statements -------------------------------------------------------------------------------------

_OBJ = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl a\nf 1/1 2/2 3/3\n"


def _obj_pair(folder: Path, mtl: str) -> tuple[Path, Path]:
    """The same triangle twice: a plain OBJ (frustum's own reader) and one with an ``o`` line (trimesh's)."""
    (folder / "m.mtl").write_text(mtl)
    (folder / "plain.obj").write_text(_OBJ)
    (folder / "object.obj").write_text("o thing\n" + _OBJ)
    return folder / "plain.obj", folder / "object.obj"


def test_an_mtl_with_pr_and_pm_loads_as_a_pbr_material(tmp_path):
    for path in _obj_pair(tmp_path, "newmtl a\nKd 0.8 0.2 0.1\nPr 0.3\nPm 0.75\n"):
        (part,) = load_parts(path)
        assert part.physical and (part.metallic, part.roughness) == (0.75, 0.3)
        material = part_material(part)
        assert material.model == "pbr" and (material.metallic, material.roughness) == (0.75, 0.3)
        assert np.allclose(material.color, np.round(np.array([0.8, 0.2, 0.1]) * 255) / 255)


def test_one_pbr_statement_gives_the_other_factor_its_default(tmp_path):
    for mtl, expected in (("Pr 0.2\n", (0.0, 0.2)), ("Pm 1\n", (1.0, 0.5)), ("Pm 7\nPr -1\n", (1.0, 0.0))):
        for path in _obj_pair(tmp_path, "newmtl a\nKd 1 1 1\n" + mtl):
            (part,) = load_parts(path)
            assert (part.metallic, part.roughness) == expected, (mtl, path.name)


def test_map_pr_and_map_pm_pack_into_green_and_blue(tmp_path):
    Image.fromarray(np.arange(16, dtype=np.uint8).reshape(4, 4) * 10).save(tmp_path / "r.png")
    Image.fromarray(np.full((2, 2), 200, np.uint8)).save(tmp_path / "m.png")
    for path in _obj_pair(tmp_path, "newmtl a\nKd 1 1 1\nPr 0.5\nmap_Pr r.png\nmap_Pm -bm 1 m.png\n"):
        (part,) = load_parts(path)
        texture = part.metallic_roughness_texture
        assert texture.shape == (4, 4, 3)
        assert (texture[..., 0] == 255).all() and (texture[..., 2] == 200).all()
        assert np.array_equal(texture[..., 1], np.arange(16).reshape(4, 4) * 10)
        assert (part.metallic, part.roughness) == (1.0, 0.5)  # the map alone decides the metallic factor
        assert part_material(part).metallic_roughness_texture is not None


def test_an_mtl_without_pbr_statements_stays_phong(tmp_path):
    for path in _obj_pair(tmp_path, "newmtl a\nKd 0.8 0.2 0.1\nKs 0.5 0.5 0.5\nNs 20\n"):
        (part,) = load_parts(path)
        assert not part.physical and part.metallic is None and part.roughness is None
        assert part.metallic_roughness_texture is None
        material = part_material(part)
        assert material.model == "phong" and material.metallic == 0.0


# --- KHR_lights_punctual ------------------------------------------------------------------------------------


def _glb_with_lights(path: Path) -> Path:
    """A metal-and-plastic sphere GLB (trimesh's export) with three lights patched into its JSON chunk: a
    directional light turned by a node rotation, a point light under a translated parent, a spot light."""
    import json
    import math
    import struct

    import trimesh

    sphere = trimesh.creation.icosphere(subdivisions=3)
    sphere.visual = trimesh.visual.TextureVisuals(material=trimesh.visual.material.PBRMaterial(
        baseColorFactor=[200, 120, 60, 255], metallicFactor=0.3, roughnessFactor=0.4))  # fmt: skip
    data = trimesh.Scene(sphere).export(file_type="glb")
    (length,) = struct.unpack_from("<I", data, 12)
    gltf = json.loads(data[20 : 20 + length])
    rest = data[20 + length :]
    half = math.sqrt(0.5)
    gltf["extensionsUsed"] = ["KHR_lights_punctual"]
    gltf["extensions"] = {"KHR_lights_punctual": {"lights": [
        {"type": "directional", "intensity": 3.0, "color": [1.0, 0.9, 0.8]},
        {"type": "point", "intensity": 40.0, "range": 9.0},
        {"type": "spot", "intensity": 25.0, "color": [0.5, 0.5, 1.0],
         "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.5}},
    ]}}  # fmt: skip
    first = len(gltf["nodes"])
    gltf["nodes"] += [
        {"rotation": [-half, 0.0, 0.0, half], "extensions": {"KHR_lights_punctual": {"light": 0}}},  # −Z → −Y
        {"translation": [0.0, 1.0, 0.0], "children": [first + 2]},
        {"translation": [2.0, 0.0, 3.0], "extensions": {"KHR_lights_punctual": {"light": 1}}},
        {"translation": [0.0, 0.0, 4.0], "extensions": {"KHR_lights_punctual": {"light": 2}}},
    ]
    gltf["scenes"][gltf.get("scene", 0)]["nodes"] += [first, first + 1, first + 3]
    text = json.dumps(gltf).encode()
    text += b" " * (-len(text) % 4)
    body = struct.pack("<I4s", len(text), b"JSON") + text + rest
    path.write_bytes(struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body)
    return path


def _expected_lights() -> list:
    from frustum.shading import DirectionalLight, PointLight, SpotLight

    return [
        DirectionalLight((0.0, -1.0, 0.0), color=(1.0, 0.9, 0.8), intensity=3.0),
        PointLight((2.0, 1.0, 3.0), intensity=40.0, range=9.0),
        SpotLight((0.0, 0.0, 4.0), (0.0, 0.0, -1.0), color=(0.5, 0.5, 1.0), intensity=25.0, inner_angle=0.2,
                  outer_angle=0.5),
    ]


def _same_light(a, b) -> bool:
    fields = ("direction", "position", "color", "intensity", "range", "inner_angle", "outer_angle")
    return type(a) is type(b) and all(
        np.allclose(getattr(a, name), getattr(b, name), atol=1e-12) if getattr(a, name, None) is not None
        else getattr(b, name, None) is None for name in fields)  # fmt: skip


def test_khr_lights_punctual_are_read_with_their_nodes_placements(tmp_path):
    from frustum.scenefile.gltf_lights import gltf_lights

    lights = gltf_lights(_glb_with_lights(tmp_path / "lit.glb"))
    assert len(lights) == 3
    for found, expected in zip(lights, _expected_lights(), strict=True):
        assert _same_light(found, expected), (found, expected)


def test_a_glb_with_lights_renders_as_the_same_scene_lit_by_hand(tmp_path):
    import frustum as fr
    from frustum.scenefile import load_scene_file
    from frustum.scenefile.models import PHYSICAL_AMBIENT, model_scene, part_nodes, physical_options

    path = _glb_with_lights(tmp_path / "lit.glb")
    scene, camera = model_scene(path, size=(96, 72))
    by_hand = fr.Scene()
    for node in part_nodes(load_parts(path)):
        by_hand.add(node)
    for light in [*_expected_lights(), fr.AmbientLight(intensity=PHYSICAL_AMBIENT)]:
        by_hand.root.add_light(light)
    options = physical_options(scene)
    assert options["tone_map"] == "khronos-neutral"
    picture = fr.render(scene, camera, **options).color
    assert np.array_equal(picture, fr.render(by_hand, camera, **options).color)
    assert picture[..., :3].max() > 60  # lit, not black
    loaded = load_scene_file(path)  # what `frustum render lit.glb` draws
    assert [type(light).__name__ for light in loaded.scene.world_lights()] == [
        "DirectionalLight", "PointLight", "SpotLight", "AmbientLight"]  # fmt: skip


def test_a_glb_without_lights_keeps_the_default_lights(tmp_path):
    import trimesh

    from frustum.scenefile.gltf_lights import gltf_lights
    from frustum.scenefile.models import model_scene

    path = tmp_path / "plain.glb"
    trimesh.creation.box().export(path)
    assert gltf_lights(path) == []
    scene, _ = model_scene(path)
    assert len(scene.world_lights()) == 4  # key, fill, rim, ambient


def test_malformed_lights_are_refused_with_the_light(tmp_path):
    import json
    import struct

    from frustum.errors import GeometryError
    from frustum.scenefile.gltf_lights import gltf_lights

    path = _glb_with_lights(tmp_path / "lit.glb")
    data = path.read_bytes()
    (length,) = struct.unpack_from("<I", data, 12)
    gltf = json.loads(data[20 : 20 + length])
    for light, message in (({"type": "area"}, "type = 'area'"), ({"type": "point", "intensity": -1}, "light 0")):
        gltf["extensions"]["KHR_lights_punctual"]["lights"][0] = light
        (tmp_path / "bad.gltf").write_text(json.dumps(gltf))
        with pytest.raises(GeometryError, match=message):
            gltf_lights(tmp_path / "bad.gltf")


# --- ray tracing: the mirror of smooth metals ---------------------------------------------------------------


def test_a_smooth_metal_sphere_reflects_a_coloured_wall_by_its_fresnel_colour():
    """A metal sphere of roughness 0 in front of a glowing wall (behind the camera, black and lit by nothing but its
    emission E): each sphere pixel is $F·E$ where its mirror ray meets the wall (computed here: the primary ray,
    the buffer's normal, R = d − 2(d·n)n, the plane z = 6), $F = F_0 + (1 − F_0)(1 − n·v)⁵$ with $F_0$ = the base
    colour; black where the mirror ray leaves the scene (no ambient light, no environment)."""
    import frustum as fr

    base = np.array([0.95, 0.7, 0.35])
    glow = np.array([0.2, 0.55, 0.9])
    scene = fr.Scene([])
    scene.add(fr.icosphere(1.0, 5), fr.Material(color=base, metallic=1.0, roughness=0.0, model="pbr"))
    wall = fr.Mesh(np.array([[-20.0, -20.0, 6.0], [20.0, -20.0, 6.0], [20.0, 20.0, 6.0], [-20.0, 20.0, 6.0]]),
                   np.array([[0, 2, 1], [0, 3, 2]]))  # fmt: skip
    scene.add(wall, fr.Material(color=(0.0, 0.0, 0.0), emissive=glow, metallic=0.0, roughness=0.6, model="pbr"))
    camera = fr.Camera.look_at((0.3, 0.4, 3.2), (0, 0, 0), (0, 1, 0), fr.Perspective(0.75, 0.1, 10.0), 80, 80)
    frame = fr.render(scene, camera, method="ray-tracing", background=(0, 0, 0, 1), buffers=("normals",))
    sphere = frame.depth < 1.0
    rows, columns = np.nonzero(sphere)
    x, y = columns + 0.5, (camera.height - 1 - rows) + 0.5  # window coordinates, y up
    m = np.asarray(camera.world_from_window, dtype=np.float64)

    def unproject(z):
        w = m[3, 0] * x + m[3, 1] * y + m[3, 2] * z + m[3, 3]
        return np.stack([(m[a, 0] * x + m[a, 1] * y + m[a, 2] * z + m[a, 3]) / w for a in range(3)], axis=1)

    near, point = unproject(0.0), unproject(frame.depth[sphere].astype(np.float64))
    d = point - near
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    n = frame.normals[sphere].astype(np.float64)
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    cos = np.clip(-(d * n).sum(axis=1), 0.0, 1.0)
    reflected = d + 2.0 * cos[:, None] * n
    t = (6.0 - point[:, 2]) / np.where(reflected[:, 2] > 1e-9, reflected[:, 2], np.nan)
    on_wall = np.abs(point[:, :2] + t[:, None] * reflected[:, :2]).max(axis=1) < 20.0
    fresnel = base + (1.0 - base) * (1.0 - cos[:, None]) ** 5
    expected = np.where(on_wall[:, None], fresnel * glow, 0.0)
    got = frame.color[sphere][:, :3].astype(np.float64) / 255.0
    assert on_wall.mean() > 0.4 and (~on_wall).sum() > 50  # both cases are present
    assert np.abs(got - expected).max() < 1.5 / 255.0
    assert np.abs(got - expected).mean() < 0.3 / 255.0


def test_a_smooth_metals_mirror_rays_that_leave_see_the_environment_and_the_ambient_light():
    import frustum as fr

    base = np.array([0.9, 0.5, 0.2])
    sky = fr.EnvironmentMap(np.full((8, 16, 3), 0.3, dtype=np.float32))
    scene = fr.Scene([fr.AmbientLight(intensity=0.4)], environment=sky)
    scene.add(fr.icosphere(1.0, 4), fr.Material(color=base, metallic=1.0, roughness=0.0, model="pbr"))
    camera = fr.Camera.look_at((0.0, 0.0, 3.5), (0, 0, 0), (0, 1, 0), fr.Perspective(0.75, 0.1, 10.0), 48, 48)
    frame = fr.render(scene, camera, method="ray-tracing", background=(0, 0, 0, 1), buffers=("normals",))
    sphere = frame.depth < 1.0
    n = frame.normals[sphere].astype(np.float64)
    eye_side = np.array([0.0, 0.0, 1.0])  # the view direction, nearly: the camera is 3.5 radii away
    cos = np.clip(n @ eye_side / np.linalg.norm(n, axis=1), 0.0, 1.0)
    expected = (base + (1.0 - base) * (1.0 - cos[:, None]) ** 5) * 0.7
    centre = cos > 0.9  # where the view direction's error does not matter
    got = frame.color[sphere][:, :3] / 255.0
    assert np.abs(got[centre] - expected[centre]).max() < 1.5 / 255.0


# --- the output transform where the viewer, datasets and turntables render -----------------------------------

_TONED_SCENE = """
[render]
size = [64, 48]
shading = "pbr"
tone_map = "aces"
exposure = 2.5

[camera]
eye = [0.0, 0.5, 3.5]

[[lights]]
type = "directional"
direction = [-0.3, -0.5, -1.0]
intensity = 4.0

[materials.metal]
color = [0.9, 0.6, 0.3]
model = "pbr"
metallic = 1.0
roughness = 0.35

[[nodes]]
material = "metal"
geometry = { type = "icosphere", radius = 1.0, subdivisions = 3 }
"""


def _toned(tmp_path):
    from frustum.scenefile import load_scene_file

    path = tmp_path / "toned.toml"
    path.write_text(_TONED_SCENE)
    scene_file = load_scene_file(path)
    assert scene_file.options["tone_map"] == "aces" and scene_file.options["exposure"] == 2.5
    return path, scene_file


def _plain_render(scene_file, camera, **changes):
    import frustum as fr

    return fr.render(scene_file.scene, camera, **{**scene_file.options, **changes}).color


def test_the_viewer_renders_with_the_files_tone_map_and_exposure(tmp_path):
    from frustum.viewer import SHADINGS, ViewerSession

    _, scene_file = _toned(tmp_path)
    session = ViewerSession(scene_file.scene, scene_file.camera, scene_file.options, rest_samples=1)
    assert "pbr" in SHADINGS and session.controls["shading"] == "pbr"
    options = session.render_options("rest")
    assert (options["tone_map"], options["exposure"]) == ("aces", 2.5)
    picture = session.render("rest").color
    camera = session.camera("rest")
    assert np.array_equal(picture, _plain_render(scene_file, camera, samples=1, shadows=options["shadows"]))
    assert not np.array_equal(picture, _plain_render(scene_file, camera, samples=1, shadows=options["shadows"],
                                                     tone_map="none", exposure=1.0))  # fmt: skip


def test_a_dataset_renders_with_the_files_tone_map_and_exposure(tmp_path):
    from frustum.batch.dataset import render_dataset

    path, scene_file = _toned(tmp_path)
    render_dataset(path, tmp_path / "out", views=1, layout="orbit", format="files", executor="serial",
                   progress=False, cameras=[scene_file.camera])  # fmt: skip
    image = np.asarray(Image.open(tmp_path / "out" / "images" / "view_00000.png"))
    assert np.array_equal(image[..., :3], _plain_render(scene_file, scene_file.camera)[..., :3])


def test_turntables_render_with_the_tone_map_and_exposure(tmp_path, monkeypatch):
    from frustum.output import animation

    _, scene_file = _toned(tmp_path)
    frames = animation.turntable(scene_file.scene, scene_file.camera, 2, progress=False, shading="pbr",
                                 tone_map="aces", exposure=2.5)  # fmt: skip
    assert np.array_equal(frames[0].color, _plain_render(scene_file, scene_file.camera))
    # the command: a glTF model's default output transform, and --tone-map / --exposure over it
    from typer.testing import CliRunner

    from frustum.app.cli import app

    seen = []
    monkeypatch.setattr(animation, "turntable", lambda *args, **options: seen.append(options) or 1)
    model = _glb_with_lights(tmp_path / "lit.glb")
    runner = CliRunner()
    for extra, expected in (([], ("khronos-neutral", 1.0)), (["--tone-map", "aces", "--exposure", "2"], ("aces", 2.0))):
        result = runner.invoke(app, ["turntable", str(model), "-o", str(tmp_path / "t.gif"), "--frames", "2", *extra])
        assert result.exit_code == 0, result.output
        assert (seen[-1]["tone_map"], seen[-1]["exposure"], seen[-1]["color_space"]) == (*expected, "srgb")
    monkeypatch.undo()  # the real turntable: render refuses an unknown tone map
    result = runner.invoke(app, ["turntable", str(model), "-o", str(tmp_path / "t.gif"), "--frames", "1", "--size",
                                 "16x16", "--tone-map", "filmic"])  # fmt: skip
    assert result.exit_code != 0 and "filmic" in f"{result.output}{result.exception}"
