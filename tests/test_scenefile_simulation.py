"""Scene files with ``[[particles]]`` and ``[[cloth]]``: building, warmup, animation output, errors with file:line."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from frustum.errors import SceneFileError
from frustum.scenefile import EXAMPLES_DIR, load_scene, render_scene_file

SCENE = """
[camera]
eye = [0, 1.2, 4]
target = [0, 0.8, 0]

[animation]
frames = 3
fps = 10
substeps = 2
warmup = 0.5

[[particles]]
emitter = { type = "disk", center = [0, 0, 0], radius = 0.3, spread_deg = 10, speed = 1.5 }
rate = 400
lifetime = 1.0
forces = [{ type = "gravity", acceleration = [0, 1.5, 0] }, { type = "drag", coefficient = 0.5 }]
colliders = [{ type = "plane", point = [0, -1, 0] }]
color = [[0.0, [1.0, 0.9, 0.4]], [1.0, [0.4, 0.05, 0.0]]]
style = "streaks"
seed = 3

[[cloth]]
width = 1.0
height = 1.0
nx = 5
ny = 5
center = [0, 2, -1]
plane = "xy"
pinned = [20, 24]
"""


def test_particles_and_cloth_are_built_and_warmed_up():
    scene_file = load_scene(SCENE)
    layer = scene_file.scene.particle_layers[0]
    assert layer.style == "streaks" and layer.blending == "additive"
    assert layer.system.steps == 10 and layer.system.count > 100  # warmup 0.5 s at dt = 1/(10·2)
    spread = layer.system.emitter.spread
    assert spread == pytest.approx(np.radians(10))
    node, cloth = scene_file.scene.mass_springs[0]
    assert cloth.steps == 10 and cloth.count == 25 and cloth.integrator == "implicit-euler"
    np.testing.assert_array_equal(node.geometry.vertices, cloth.positions)
    assert scene_file.animation == {"frames": 3, "fps": 10, "substeps": 2, "warmup": 0.5}


def test_render_writes_the_simulation_as_a_gif(tmp_path: Path):
    source = tmp_path / "fire.toml"
    source.write_text(SCENE)
    written = render_scene_file(source, tmp_path / "fire.gif", size=(64, 48))
    with Image.open(written) as image:
        assert image.n_frames == 3 and image.size == (64, 48)


@pytest.mark.parametrize("name", ["fountain", "fire", "cloth_sphere"])
def test_gallery_examples_load(name):
    scene_file = load_scene((EXAMPLES_DIR / f"{name}.toml").read_text(), base_dir=EXAMPLES_DIR)
    assert scene_file.scene.particle_layers or scene_file.scene.mass_springs


@pytest.mark.parametrize(
    ("change", "match"),
    [
        (('type = "disk"', 'type = "cone"'), r"<scene>:13: particles\[0\]\.emitter\.type = 'cone' is unknown; "
                                             r"expected one of 'point', 'line', 'disk', 'sphere'"),
        (("spread_deg = 10", "spread = 0.2"), r":13: particles\[0\]\.emitter\.spread = 0.2 is an angle in radians; "
                                              r"scene files take degrees: write spread_deg"),
        (("rate = 400", "rate = -4.0"), r":14: particles\[0\]\.rate = -4.0 is not accepted: .*rate = -4.0 is negative"),
        (('style = "streaks"', 'style = "blobs"'), r":19: particles\[0\]\.style = 'blobs' is unknown"),
        (('type = "drag"', 'type = "friction"'), r"particles\[0\]\.forces\[1\]\.type = 'friction' is unknown"),
        (("nx = 5", "nx = 1"), r":25: cloth\[0\]\.nx = 1 is not accepted: cloth: nx = 1 is below 2"),
        (("pinned = [20, 24]", "pinned = [20, 99]"), r":29: cloth\[0\]\.pinned = .* is not accepted: "
                                                     r"MassSpringSystem: pinned\[1\] = 99 names a missing point"),
        (("substeps = 2", "substeps = 0"), r"animation\.substeps = 0"),
        (('plane = "xy"', 'plane = "yz"'), r"cloth\[0\]\.plane = 'yz' is not accepted"),
    ],
)  # fmt: skip
def test_bad_simulation_keys_name_file_line_and_what_is_valid(change, match):
    old, new = change
    assert old in SCENE
    with pytest.raises(SceneFileError, match=match):
        load_scene(SCENE.replace(old, new))
