"""Scene files and the command line for the rest of the surface-rendering chapter: [radiosity], [environment],
material images (texture, bump, normal_map), emission and reflectivity; ``frustum radiosity``."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import frustum as fr
from frustum.errors import SceneFileError
from frustum.scenefile import load_scene, load_scene_file
from frustum.shading.environment import EnvironmentMap

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def test_the_gallery_examples_load_with_their_maps():
    teapot = load_scene_file(EXAMPLES / "chrome_teapot.toml")
    assert isinstance(teapot.scene.environment, EnvironmentMap)
    assert teapot.scene.environment.image.shape == (256, 512, 3)
    assert teapot.scene.items[0].material.reflectivity == 0.8
    wall = load_scene_file(EXAMPLES / "brick_wall.toml")
    assert wall.scene.items[0].material.bump.shape == (256, 256, 4)
    assert wall.scene.items[0].material.bump_scale == 0.03
    box = load_scene_file(EXAMPLES / "cornell_box.toml")
    assert box.radiosity == {"patch_size": 0.05}
    assert box.scene.find("lamp").material.emission == 8.0


def test_a_radiosity_table_lights_the_picture_with_colour_bleeding():
    text = (EXAMPLES / "cornell_box.toml").read_text()
    text = text.replace("patch_size = 0.05", "patch_size = 0.15").replace("size = [400, 400]", "size = [48, 48]")
    scene_file = load_scene(text, base_dir=EXAMPLES)
    frame = scene_file.resized((48, 48)).render()
    floor_left, floor_right = frame.color[44, 8, :3].astype(int), frame.color[44, 39, :3].astype(int)
    assert floor_left[0] - floor_left[1] > floor_right[0] - floor_right[1]  # red wall's bleed on its side


def test_material_images_are_read_relative_to_the_scene_file(tmp_path):
    from PIL import Image

    Image.fromarray(np.full((4, 8, 3), (255, 0, 0), dtype=np.uint8)).save(tmp_path / "red.png")
    text = """
[camera]
eye = [0, 0, 3]
target = [0, 0, 0]
[materials.painted]
texture = "red.png"
[[nodes]]
material = "painted"
geometry = { type = "plane", size = [2, 2] }
"""
    scene_file = load_scene(text, base_dir=tmp_path)
    assert scene_file.scene.items[0].material.texture.shape == (4, 8, 4)
    frame = fr.render(scene_file.scene, scene_file.camera, shading="none")
    drawn = frame.depth < 1
    assert (frame.color[drawn][:, 1:3] == 0).all() and (frame.color[drawn][:, 0] > 200).all()


@pytest.mark.parametrize(
    ("snippet", "message"),
    [
        ('[materials.m]\ntexture = "missing.png"', "does not exist"),
        ('[materials.m]\nbump = 3', "is not a file name"),
        ('[materials.m]\nreflectivity = 2.0', "reflectivity"),
        ('[materials.m]\nemission = -1.0', "emission"),
        ('[environment]\nkind = "cube"', "image is missing"),
        ('[environment]\nimage = "nowhere.hdr"', "does not exist"),
        ("[radiosity]\npatches = 3", "patches"),
        ("[radiosity]\npatch_size = -1", "is not a positive number"),
    ],
)
def test_bad_keys_are_reported_with_their_line(snippet, message, tmp_path):
    text = f'[camera]\neye = [0, 0, 3]\ntarget = [0, 0, 0]\n{snippet}\n'
    with pytest.raises(SceneFileError, match=message) as error:
        load_scene(text, source="bad.toml", base_dir=tmp_path)
    assert "bad.toml:" in str(error.value)


def run(*arguments: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "frustum", *arguments], capture_output=True, text=True, timeout=600,
                          check=False)  # fmt: skip


def test_the_radiosity_command_writes_the_lit_picture(tmp_path):
    out = tmp_path / "box.png"
    result = run("radiosity", str(EXAMPLES / "cornell_box.toml"), "-o", str(out), "--patch-size", "0.2",
                 "--size", "40x40")  # fmt: skip
    assert result.returncode == 0, result.stderr
    assert "patches" in result.stdout and out.is_file()
    bad = run("radiosity", str(EXAMPLES / "cornell_box.toml"), "-o", str(tmp_path / "box.svg"))
    assert bad.returncode != 0
    assert len(bad.stderr.strip().splitlines()) == 1 and "PNG" in bad.stderr
