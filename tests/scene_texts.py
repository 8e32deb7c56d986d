"""Scene-file texts that several test modules write: one small lit scene, a ball and (optionally) a cube."""

from __future__ import annotations


def ball_scene(title: str, *, size: tuple[int, int] = (64, 48), subdivisions: int = 2, cube: bool = True) -> str:
    """The TOML text of a scene: an icosphere (and a half-size box beside it) under one directional light."""
    text = f"""
title = "{title}"
[render]
size = [{size[0]}, {size[1]}]
[camera]
eye = [0.3, 1.0, 4.0]
target = [0.0, 0.0, 0.0]
fovy_deg = 45
near = 1.0
far = 10.0
[[lights]]
type = "directional"
direction = [-0.5, -1.0, -0.6]
[[nodes]]
name = "ball"
geometry = {{ type = "icosphere", subdivisions = {subdivisions} }}
"""
    if cube:
        text += """[[nodes]]
name = "cube"
geometry = { type = "box" }
transform = [{ scale = 0.5 }, { translate = [0.9, 0.0, 0.3] }]
"""
    return text
