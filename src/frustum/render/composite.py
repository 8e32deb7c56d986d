"""What is composited over the drawn surfaces and lines: placed volumes ray cast into the frame, each ray stopped at
the depth already there (``frustum.volume_pass``), and particle layers, depth-tested without writing depth
(``frustum.particle_pass``). Where each goes in the order of passes is the driver's (``frustum.render``)."""

from __future__ import annotations

from frustum.camera import Camera
from frustum.render.buffers import Buffers
from frustum.scene import Scene


def draw_volumes(scene: Scene, camera: Camera, buffers: Buffers) -> None:
    """Every placed volume ray cast over the buffers, rays stopped at their depth (docs/rendering.md)."""
    if scene.volumes:
        from frustum.volume_pass import draw_volumes as cast

        cast(scene, camera, buffers.depth, buffers.color)


def draw_particles(scene: Scene, camera: Camera, buffers: Buffers) -> None:
    """Particle layers over the finished surfaces: depth-tested, depth not written (``frustum.particle_pass``)."""
    if getattr(scene, "particle_layers", None):
        from frustum.particle_pass import draw_particles as draw

        draw(scene.particle_layers, camera, buffers.depth, buffers.color)
