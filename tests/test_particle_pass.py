"""Drawing particles in ``render``: sprites, points and streaks against an independent numpy reference, depth
testing against meshes, blending, thread-count independence, and ``Scene.add_particles`` bad input."""

from __future__ import annotations

import math

import numba
import numpy as np
import pytest

import frustum as fr
from frustum.errors import FrustumError
from frustum.scene import Scene
from frustum.simulation import Gravity, ParticleSystem, PointEmitter, SphereEmitter

WIDTH, HEIGHT = 48, 40
BACKGROUND = (0.1, 0.2, 0.3, 1.0)


def camera() -> fr.Camera:
    return fr.Camera.look_at((0.3, 0.4, 5.0), (0, 0, 0), (0, 1, 0), fr.Perspective(math.radians(50), 0.5, 20.0),
                             WIDTH, HEIGHT)  # fmt: skip


def cloud(seed: int = 3, count: int = 60, opacity=0.6, speed: float = 0.8) -> ParticleSystem:
    """Particles scattered through the view, with colors and sizes over life."""
    system = ParticleSystem(
        emitter=SphereEmitter((0, 0, 0), radius=1.2, speed=speed, spread=0.8), rate=0.0, lifetime=2.0, seed=seed,
        forces=[Gravity((0, -1.0, 0))], size=[(0.0, 0.05), (1.0, 0.25)],
        color=[(0.0, (1.0, 0.9, 0.2)), (1.0, (0.8, 0.1, 0.0))], opacity=opacity,
    )  # fmt: skip
    system.emit(count)
    for _ in range(6):
        system.step(0.1)
    return system


def project_reference(cam: fr.Camera, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Window coordinates (Camera.project, the textbook path) and view distances (eye − P)·n."""
    window = cam.project(points)
    distance = (cam.frame.eye - points) @ cam.frame.n
    return window, distance


def reference_sprites(cam, system, style: str, blending: str, background_bytes: np.ndarray) -> np.ndarray:
    """Straightforward numpy version of the particle pass: one sprite at a time over the whole image."""
    window, distance = project_reference(cam, np.asarray(system.positions))
    focal = 1.0 / math.tan(cam.projection.fovy / 2.0)
    radius = np.asarray(system.sizes) * focal * HEIGHT / 2.0 / distance
    alpha = np.asarray(system.opacities).copy()
    minimum = 1.0 if style == "sprites" else 0.5
    alpha = np.where(radius < minimum, alpha * (radius / minimum) ** 2, alpha)
    radius = np.maximum(radius, minimum)
    order = np.arange(len(radius))
    if blending == "alpha":
        order = np.argsort(-distance, kind="stable")
    image = np.tile(background_bytes[:3].astype(np.float64), (HEIGHT, WIDTH, 1))
    cols, wys = np.meshgrid(np.arange(WIDTH) + 0.5, np.arange(HEIGHT) + 0.5)  # window y up
    for k in order:
        if not (distance[k] > cam.projection.near and distance[k] < cam.projection.far):
            continue
        x, y = window[k, 0], window[k, 1]
        if style == "sprites":
            fall = 1.0 - ((cols - x) ** 2 + (wys - y) ** 2) / radius[k] ** 2
            weight = np.where(fall > 0.0, fall * fall, 0.0)
        else:
            inside = (cols >= x - radius[k]) & (cols < x + radius[k]) & (wys >= y - radius[k]) & (wys < y + radius[k])
            weight = inside.astype(float)
        a = (alpha[k] * weight)[::-1][:, :, None]  # window rows bottom-up → image rows top-down
        color = 255.0 * np.asarray(system.colors)[k]
        image = image + a * color if blending == "additive" else a * color + (1.0 - a) * image
    return np.floor(np.minimum(image, 255.0) + 0.5)


@pytest.mark.parametrize(("style", "blending"), [("sprites", "additive"), ("sprites", "alpha"),
                                                  ("points", "additive"), ("points", "alpha")])  # fmt: skip
def test_sprites_and_points_equal_a_numpy_reference(style, blending):
    cam = camera()
    system = cloud()
    scene = Scene()
    scene.add_particles(system, style=style, blending=blending)
    frame = fr.render(scene, cam, background=BACKGROUND)
    background = np.floor(np.asarray(BACKGROUND) * 255 + 0.5)
    expected = reference_sprites(cam, system, style, blending, background)
    difference = np.abs(frame.color[:, :, :3].astype(int) - expected.astype(int))
    # ±1 level: the kernel accumulates in float32, the reference in float64
    assert difference.max() <= 1
    assert (frame.color[:, :, :3] != background[:3]).any(axis=2).sum() > 50  # the particles are there
    assert (frame.depth == 1.0).all()  # particles never write depth


def test_streaks_equal_a_numpy_reference():
    cam = camera()
    system = ParticleSystem(emitter=SphereEmitter((0, 0, 0), radius=0.8, speed=3.0, spread=0.8), rate=0.0,
                            lifetime=2.0, seed=4, color=(1.0, 0.6, 0.1), opacity=[(0.0, 1.0), (1.0, 0.0)])  # fmt: skip
    system.emit(60)
    for _ in range(2):
        system.step(0.1)
    scene = Scene()
    scene.add_particles(system, style="streaks", blending="additive")
    frame = fr.render(scene, cam, background=BACKGROUND)
    background = np.floor(np.asarray(BACKGROUND) * 255 + 0.5)
    head, _ = project_reference(cam, np.asarray(system.positions))
    tail, _ = project_reference(cam, np.asarray(system.previous_positions))
    image = np.tile(background[:3], (HEIGHT, WIDTH, 1))
    drawn = 0
    for k in range(system.count):
        if not (0.0 <= head[k, 2] <= 1.0 and 0.0 <= tail[k, 2] <= 1.0):
            continue  # an end outside the near/far planes (or behind the eye): the streak is not drawn
        delta = head[k, :2] - tail[k, :2]
        n = max(math.ceil(np.abs(delta).max()), 1)
        for t in np.arange(n + 1) / n:  # sample the segment at n + 1 points, each in the pixel containing it
            col, wy = np.floor(tail[k, :2] + t * delta).astype(int)
            if 0 <= col < WIDTH and 0 <= wy < HEIGHT:
                drawn += 1
                image[HEIGHT - 1 - wy, col] += 255.0 * system.opacities[k] * system.colors[k]
    expected = np.floor(np.minimum(image, 255.0) + 0.5)
    assert np.abs(frame.color[:, :, :3].astype(int) - expected.astype(int)).max() <= 1
    lit = (frame.color[:, :, :3] != background[:3]).any(axis=2).sum()
    assert drawn > 3 * 60 and lit > drawn / 2  # streaks, not dots: they moved several pixels in the last step


def test_particles_behind_a_mesh_are_hidden_and_in_front_are_seen():
    cam = camera()
    wall = fr.Mesh([[-5, -5, 1.0], [5, -5, 1.0], [5, 5, 1.0], [-5, 5, 1.0]], [[0, 1, 2], [0, 2, 3]])
    light = fr.DirectionalLight((0, 0, -1))
    behind = ParticleSystem(emitter=SphereEmitter((0, 0, -1), radius=0.5), rate=0, lifetime=1, seed=1, size=0.2)
    behind.emit(200)
    scene = Scene(lights=[light])
    scene.add(wall, fr.Material(color=(0.2, 0.6, 0.2)))
    plain = fr.render(scene, cam, background=BACKGROUND)
    scene.add_particles(behind)
    hidden = fr.render(scene, cam, background=BACKGROUND)
    np.testing.assert_array_equal(hidden.color, plain.color)
    np.testing.assert_array_equal(hidden.depth, plain.depth)
    in_front = ParticleSystem(emitter=SphereEmitter((0, 0, 2.5), radius=0.3), rate=0, lifetime=1, seed=1, size=0.1)
    in_front.emit(50)
    scene.add_particles(in_front)
    seen = fr.render(scene, cam, background=BACKGROUND)
    assert (seen.color != plain.color).any(axis=2).sum() > 20
    np.testing.assert_array_equal(seen.depth, plain.depth)  # the depth buffer is not written


def test_the_image_does_not_depend_on_the_thread_count():
    cam = fr.Camera.look_at((0, 1, 6), (0, 0.5, 0), (0, 1, 0), None, 160, 120)
    system = cloud(count=3000)
    scene = Scene()
    scene.add_particles(system, blending="alpha")
    scene.add_particles(system, style="streaks")
    before = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = fr.render(scene, cam).color.tobytes()
        numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
        many = fr.render(scene, cam).color.tobytes()
    finally:
        numba.set_num_threads(before)
    assert one == many


def test_supersampling_keeps_sprites():
    cam = camera()
    scene = Scene()
    scene.add_particles(cloud())
    frame = fr.render(scene, cam, samples=4)
    assert frame.color[:, :, :3].max() > 100


def test_particles_behind_the_eye_are_not_drawn():
    cam = camera()
    system = ParticleSystem(emitter=PointEmitter((0.3, 0.4, 6.0)), rate=0, lifetime=1, seed=0, size=5.0)
    system.emit(5)
    scene = Scene()
    scene.add_particles(system)
    frame = fr.render(scene, cam, background=(0, 0, 0, 1))
    assert frame.color[:, :, :3].max() == 0


@pytest.mark.parametrize(
    ("arguments", "match"),
    [
        ({"style": "blobs"}, r"style = 'blobs' is unknown; expected one of 'sprites', 'points', 'streaks'"),
        ({"blending": "multiply"}, r"blending = 'multiply' is unknown; expected one of 'additive', 'alpha'"),
    ],
)
def test_add_particles_rejects_bad_styles(arguments, match):
    with pytest.raises(FrustumError, match=match):
        Scene().add_particles(cloud(), **arguments)
    with pytest.raises(FrustumError, match=r"is not a ParticleSystem"):
        Scene().add_particles(np.zeros((3, 3)))
