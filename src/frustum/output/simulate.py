"""Animating simulations: step the scene's particle and mass–spring systems between frames, render each frame.

``simulate(scene, camera, frames, fps=30, substeps=2)`` yields ``Frame`` objects; with ``path=`` it writes them
as a GIF or MP4 through ``write_animation`` (with a progress bar on a terminal) and returns the frame count.
Frame k shows the state at $t = warmup + k/fps$: frame 0 is rendered first, then every system advances by
``substeps`` steps of $dt = 1/(fps·substeps)$ (in the order they were added), and every mass–spring node
gets its system's new mesh (normals recomputed).
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from typing import Any

from frustum._arrays import as_count, as_scalar, describe
from frustum.camera import Camera
from frustum.errors import OutputError
from frustum.frame import Frame
from frustum.output.animation import _fps, _suffix, _with_progress, write_animation
from frustum.render import render
from frustum.scene import Scene

__all__ = ["simulate", "step_scene"]


def step_scene(scene: Scene, dt: float, steps: int = 1) -> None:
    """Advance every particle layer's and mass–spring node's system of `scene` by `steps` steps of `dt` seconds,
    then give each mass–spring node its system's current mesh."""
    systems = [layer.system for layer in scene.particle_layers] + [system for _, system in scene.mass_springs]
    unique = list({id(system): system for system in systems}.values())  # a system drawn twice steps once
    for _ in range(steps):
        for system in unique:
            system.step(dt)
    for node, system in scene.mass_springs:
        node.geometry = system.mesh


def _frames(scene: Scene, camera: Camera, frames: int, dt: float, substeps: int, render_options: dict
            ) -> Iterator[Frame]:  # fmt: skip
    for k in range(frames):
        yield render(scene, camera, **render_options)
        if k + 1 < frames:
            step_scene(scene, dt, substeps)


def simulate(
    scene: Scene,
    camera: Camera,
    frames: int = 120,
    *,
    fps: float = 30.0,
    substeps: int = 1,
    warmup: float = 0.0,
    path: str | os.PathLike | None = None,
    progress: Any = True,
    **render_options: Any,
) -> Iterator[Frame] | int:
    """Render `frames` frames of `scene`'s simulations seen by `camera`, stepping them ``1/fps`` seconds apart.

    Parameters
    ----------
    scene : Scene
        With particle systems (``Scene.add_particles``) and mass–spring systems (``Scene.add_mass_spring``).
        The systems are stepped in place.
    camera : Camera
    frames : int
        Number of frames, >= 1.
    fps : float
        Frames per second of simulated time (and of the file), in (0, 100].
    substeps : int
        Simulation steps per frame, >= 1 ($dt = 1/(fps·substeps)$): more for stiff springs or fast particles.
    warmup : float
        Seconds simulated before the first frame (a fountain already running), >= 0.
    path : str or PathLike, optional
        A ``.gif`` or ``.mp4`` file: the frames are written as they are rendered and the count is returned.
    progress : bool or rich.console.Console
        A Rich progress bar on a terminal while writing `path` (as ``turntable``).
    **render_options
        Passed to ``render``.

    Returns
    -------
    iterator of Frame, or int
        The frames (lazily: each is rendered when asked for), or with `path` the number written.

    Raises
    ------
    OutputError
        Bad frames, fps, substeps, warmup or path; SimulationError when a system blows up.
    """
    where = "simulate"
    if not isinstance(scene, Scene):
        raise OutputError(f"{where}: scene = {describe(scene)} is not a Scene; build one with Scene()")
    if not isinstance(camera, Camera):
        raise OutputError(f"{where}: camera = {describe(camera)} is not a Camera; build one with Camera.look_at(...)")
    count = as_count(frames, "frames", 1, where=where, error=OutputError)
    rate = _fps(fps, where)
    steps = as_count(substeps, "substeps", 1, where=where, error=OutputError)
    lead = as_scalar(warmup, "warmup", where=where, error=OutputError)
    if lead < 0.0:
        raise OutputError(f"{where}: warmup = {lead!r} is negative; give seconds >= 0")
    if path is not None:
        _suffix(path, where)
    dt = 1.0 / (rate * steps)
    warmup_steps = round(lead / dt)
    if warmup_steps:
        step_scene(scene, dt, warmup_steps)
    elif scene.mass_springs:
        step_scene(scene, dt, 0)
    rendered = _frames(scene, camera, count, dt, steps, render_options)
    if path is None:
        return rendered
    return write_animation(_with_progress(rendered, count, progress, label="simulate"), path, rate)
