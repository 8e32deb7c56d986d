"""``simulate``: frames of stepped particle and mass–spring systems, GIF output, SVG dots and segments."""

from __future__ import annotations

import math

import numpy as np
import pytest
from PIL import Image

import frustum as fr
from frustum.errors import OutputError


def fountain_scene() -> tuple[fr.Scene, fr.ParticleSystem, fr.MassSpringSystem]:
    particles = fr.ParticleSystem(
        emitter=fr.PointEmitter((0, 0, 0), direction=(0, 1, 0), spread=0.3, speed=4.0), rate=400.0, lifetime=1.0,
        forces=[fr.Gravity()], seed=2, color=(0.4, 0.7, 1.0), size=0.05,
    )  # fmt: skip
    sheet = fr.cloth(1.0, 1.0, 6, 6, center=(0, 1.5, -1), plane="xy", pinned=[30, 35], gravity=(0, -9.81, 0),
                     integrator="implicit-euler")  # fmt: skip
    scene = fr.Scene(lights=[fr.DirectionalLight((-1, -1, -1))])
    scene.add_particles(particles)
    scene.add_mass_spring(sheet, fr.Material(color=(0.8, 0.2, 0.2)))
    return scene, particles, sheet


def camera(width: int = 64, height: int = 48) -> fr.Camera:
    return fr.Camera.look_at((0, 1, 5), (0, 1, 0), (0, 1, 0), fr.Perspective(math.radians(50), 0.1, 50), width,
                             height)  # fmt: skip


def test_simulate_steps_the_systems_between_frames():
    scene, particles, sheet = fountain_scene()
    frames = list(fr.simulate(scene, camera(), 5, fps=20, substeps=2, warmup=0.5))
    assert len(frames) == 5 and all(isinstance(f, fr.Frame) for f in frames)
    # warmup 0.5 s = 20 steps, then 2 steps between each of the 5 frames
    assert particles.steps == 20 + 2 * 4 and sheet.steps == particles.steps
    assert particles.time == pytest.approx(0.5 + 4 / 20)
    node = scene.mass_springs[0][0]
    np.testing.assert_array_equal(node.geometry.vertices, sheet.positions)  # the node shows the stepped cloth
    assert not np.array_equal(frames[0].color, frames[-1].color)


def test_simulate_writes_a_gif(tmp_path):
    scene, _, _ = fountain_scene()
    target = tmp_path / "fountain.gif"
    assert fr.simulate(scene, camera(), 4, fps=10, path=target, progress=False) == 4
    with Image.open(target) as image:
        assert image.n_frames == 4 and image.size == (64, 48)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [({"frames": 0}, r"frames = 0 is below 1"), ({"fps": 0.0}, r"fps = 0.0 is out of range"),
     ({"substeps": 0}, r"substeps = 0 is below 1"), ({"warmup": -1.0}, r"warmup = -1.0 is negative"),
     ({"path": "out.png"}, r"has suffix '.png'")],
)  # fmt: skip
def test_simulate_rejects_bad_settings(kwargs, match):
    scene, _, _ = fountain_scene()
    with pytest.raises(OutputError, match=match):
        fr.simulate(scene, camera(), **{"frames": 3, **kwargs})


def test_svg_draws_particles_as_dots_and_streaks_as_segments():
    scene, particles, _ = fountain_scene()
    for _ in range(20):
        particles.step(0.02)
    scene.add_particles(particles, style="streaks", blending="alpha")
    text = fr.render_svg(scene, camera(200, 150))
    assert text.count("<circle") > 0.5 * particles.count
    assert text.count("<line") >= text.count("<circle")
    assert 'id="particles0" style="mix-blend-mode:plus-lighter"' in text and 'id="particles1">' in text


def test_simulate_writes_an_mp4(tmp_path):
    pytest.importorskip("imageio_ffmpeg")
    import imageio.v2 as imageio

    scene, _, _ = fountain_scene()
    target = tmp_path / "fountain.mp4"
    assert fr.simulate(scene, camera(), 5, fps=10, path=target, progress=False) == 5
    reader = imageio.get_reader(target)
    assert reader.count_frames() == 5
    reader.close()


def test_turntable_keeps_the_particles():
    scene, particles, _ = fountain_scene()
    for _ in range(10):
        particles.step(0.05)
    frames = fr.turntable(scene, camera(), frames=2, progress=False)
    without = fr.Scene(lights=scene.lights)
    without.root = scene.root
    plain = fr.turntable(without, camera(), frames=2, progress=False)
    assert not np.array_equal(frames[0].color, plain[0].color)
