"""Particles in SVG line drawings: sprites and points as dots (``<circle>``), streaks as line segments.

Each particle layer of the scene becomes one group ``particles<k>``, drawn over the mesh drawing in the order of
``frustum.render.particles`` (back to front for alpha blending): a dot of the projected radius R (pixels) filled
with the particle's color at its opacity, or a segment from the previous to the current position stroked
1 pixel wide. Additive layers ask the viewer for ``mix-blend-mode: plus-lighter`` (browsers honour it; cairosvg
draws them as ordinary alpha). SVG particles are not hidden by the faces: object-space hidden-line removal
covers edges only.
"""

from __future__ import annotations

import numpy as np

from frustum.camera import Camera
from frustum.render.particles import project_particles, project_streaks
from frustum.scene import Scene

__all__ = ["particle_elements"]


def _rgb(color: np.ndarray) -> str:
    r, g, b = (int(v) for v in np.floor(np.clip(color, 0.0, 1.0) * 255.0 + 0.5))
    return f"rgb({r},{g},{b})"


def particle_elements(scene: Scene, camera: Camera) -> list[str]:
    """One ``<g>`` element per particle layer of `scene` (dots or segments in SVG user units = pixels, y down)."""
    groups = []
    height = float(camera.height)
    for k, layer in enumerate(getattr(scene, "particle_layers", ())):
        if layer.system.count == 0:
            continue
        style = ' style="mix-blend-mode:plus-lighter"' if layer.blending == "additive" else ""
        items = []
        if layer.style == "streaks":
            streaks, _ = project_streaks(layer.system, camera, layer.blending)
            for x0, y0, _z0, x1, y1, _z1, r, g, b, alpha in streaks:
                items.append(f'<line x1="{x0:.2f}" y1="{height - y0:.2f}" x2="{x1:.2f}" y2="{height - y1:.2f}" '
                             f'stroke="{_rgb(np.array([r, g, b]))}" stroke-opacity="{alpha:.3f}"/>')  # fmt: skip
        else:
            sprites, _ = project_particles(layer.system, camera, layer.style, layer.blending)
            for x, y, _z, radius, r, g, b, alpha in sprites:
                items.append(f'<circle cx="{x:.2f}" cy="{height - y:.2f}" r="{radius:.2f}" '
                             f'fill="{_rgb(np.array([r, g, b]))}" fill-opacity="{alpha:.3f}"/>')  # fmt: skip
        groups.append(f'<g id="particles{k}"{style}>' + "".join(items) + "</g>")
    return groups
