"""A mesh file where a scene file goes: the scene a ``[[nodes]] geometry = { type = "mesh", path = ... }`` file
gives, with the file's own materials (base colours, textures, normal maps; glTF's metallic–roughness materials as
``model="pbr"``, rendered tone mapped and sRGB-encoded as glTF viewers do: ``physical_options``), a camera framing
the model from a 3/4 view (``Camera.fit``) and the default lights (``default_lights``) when nothing else names
lights (a glTF file's own ``KHR_lights_punctual`` lights replace them: ``frustum.scenefile.gltf_lights``). Scene files
that name no lights get the same default lights around their camera when they draw lit surfaces (see
``frustum.scenefile.loader._wants_default_lights``; ``lights = []`` keeps a scene unlit on purpose).

Default lights (a three-point setup placed relative to the camera, so every view of a fitted model reads well):

- key: a white directional light from the camera's upper left, in front (intensity 0.85);
- fill: from the right, a little below the key, at about half its strength (0.35), softening the key's shadows;
- rim: from behind and above (0.45), separating the silhouette from a dark background;
- ambient: 0.35, so faces turned away from every light keep their colour instead of going black.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from frustum.camera import Camera
from frustum.scene import Node, Scene
from frustum.shading import AmbientLight, DirectionalLight, Material

MODEL_UP_AXES = ("y", "z")
"""``up`` values for a mesh file: the model axis that points up in the picture (glTF is always y-up)."""

_Z_UP_TO_Y_UP = np.array([[1.0, 0, 0, 0], [0, 0, 1.0, 0], [0, -1.0, 0, 0], [0, 0, 0, 1.0]])  # rotate_x(-90°)


PHYSICAL_AMBIENT = 0.25
"""The default ambient radiance of a scene of metallic–roughness materials (its uniform surroundings)."""


def default_lights(camera: Camera, physical: bool = False) -> list[Any]:
    """The key, fill and rim directional lights and an ambient light, placed in world space around `camera`'s view
    (see the module docstring); each ``direction`` is where the light travels. `physical`: for metallic–roughness
    materials, the directional lights in lux, π times the intensities above (a white Lambertian surface facing
    the key then shows 0.85, as under the classical model), and ambient radiance ``PHYSICAL_AMBIENT``."""
    u, v, n = camera.frame.u, camera.frame.v, camera.frame.n  # right, up, back toward the eye

    def towards_model(source: np.ndarray) -> tuple[float, ...]:
        direction = -source / np.linalg.norm(source)
        return tuple(float(x) for x in direction)

    scale = math.pi if physical else 1.0
    return [
        DirectionalLight(towards_model(-0.6 * u + 0.8 * v + 0.7 * n), intensity=0.85 * scale),
        DirectionalLight(towards_model(0.9 * u + 0.1 * v + 0.5 * n), intensity=0.35 * scale),
        DirectionalLight(towards_model(0.3 * u + 0.6 * v - 1.0 * n), intensity=0.45 * scale),
        AmbientLight(intensity=PHYSICAL_AMBIENT if physical else 0.35),
    ]


def physical_options(scene: Scene, tone_map: str | None = None, exposure: float | None = None) -> dict[str, Any]:
    """Render options for a model: a scene with a metallic–roughness material is written as a glTF viewer writes
    it, tone mapped (Khronos PBR Neutral) and sRGB-encoded; others get none (the library's defaults). A command's
    `tone_map` and `exposure` (None: these defaults) go over them (``render`` checks them)."""
    options: dict[str, Any] = {}
    if any(item.material.model == "pbr" for item in scene.items):
        options = {"tone_map": "khronos-neutral", "color_space": "srgb"}
    chosen = {"tone_map": tone_map, "exposure": exposure}
    return {**options, **{key: value for key, value in chosen.items() if value is not None}}


def part_material(part: Any) -> Material:
    """The ``Material`` a loaded ``MeshPart`` carries: its base colour (white under a texture, which it multiplies),
    its texture, its normal map, glTF's emissive factor, its alpha as opacity (not for glTF's alphaMode OPAQUE);
    a part with none of them gets a light neutral gray. A glTF part's material is ``model="pbr"`` with the file's
    metallic and roughness factors (the specification's default 1 where it gives none), its metallic–roughness and
    occlusion textures, and its base colour texture decoded from sRGB (``Material(base_color_texture=)``); so is an
    OBJ part whose MTL material has PBR statements (``Pr``, ``Pm``: ``frustum.geometry.mtl_pbr``)."""
    color = part.color
    texture = part.texture
    normal_map = getattr(part, "normal_map", None)
    if color is None:
        rgb, opacity = ((1.0, 1.0, 1.0) if texture is not None else (0.8, 0.8, 0.78)), 1.0
    else:
        rgb, opacity = tuple(float(c) for c in color[:3]), float(color[3]) if len(color) > 3 else 1.0
    if getattr(part, "alpha_mode", None) == "OPAQUE":  # glTF: alpha is ignored unless the mode is BLEND (or MASK)
        opacity = 1.0
    emissive = getattr(part, "emissive", None) or (0.0, 0.0, 0.0)
    if getattr(part, "physical", False):
        return Material(color=rgb, base_color_texture=texture, normal_map=normal_map, opacity=opacity, specular=0.2,
                        emissive=emissive, model="pbr", metallic=1.0 if part.metallic is None else part.metallic,
                        roughness=1.0 if part.roughness is None else part.roughness,
                        metallic_roughness_texture=part.metallic_roughness_texture,
                        occlusion_texture=part.occlusion_texture,
                        emissive_texture=getattr(part, "emissive_texture", None))  # fmt: skip
    return Material(color=rgb, texture=texture, normal_map=normal_map, opacity=opacity, specular=0.2,
                    emissive=emissive)  # fmt: skip


def part_nodes(parts: list[Any], transform: np.ndarray | None = None) -> list[Node]:
    """One ``Node`` per part, placed by its matrix (then `transform`), with its ``part_material``."""
    nodes = []
    for part in parts:
        matrix = np.asarray(part.world_from_model, dtype=np.float64)
        if transform is not None:
            matrix = transform @ matrix
        placed = None if np.allclose(matrix, np.eye(4)) else matrix
        nodes.append(Node(part.name or "part", placed, part.mesh, part_material(part)))
    return nodes


def model_scene(path: str | Path, *, up: str = "y", size: tuple[int, int] = (640, 480)) -> tuple[Scene, Camera]:
    """The scene (the file's parts with their materials, default lights) and the fitted 3/4-view camera of the mesh
    file at `path`. `up` = "z" turns a z-up model (STL/OBJ from CAD tools) so that +z points up; glTF files are
    y-up by specification and ignore it.

    Raises
    ------
    GeometryError
        If the file cannot be read as a mesh (``frustum.geometry.io.load_parts``).
    SceneFileError
        If `up` is not "y" or "z".
    """
    from frustum.errors import SceneFileError
    from frustum.geometry.io import load_parts

    if up not in MODEL_UP_AXES:
        raise SceneFileError(f"up = {up!r} is not an axis; give 'y' or 'z'")
    file = Path(path)
    turn = _Z_UP_TO_Y_UP if up == "z" and file.suffix.lower() not in (".glb", ".gltf") else None
    scene = Scene()
    if not _add_points(scene, file, turn):
        for node in part_nodes(load_parts(file), turn):
            scene.add(node)
    width, height = size
    camera = Camera.fit(scene, width=width, height=height)
    physical = any(item.material.model == "pbr" for item in scene.items)
    for light in _file_lights(file) or default_lights(camera, physical):
        scene.root.add_light(light)
    return scene, camera


def _file_lights(file: Path) -> list[Any]:
    """A glTF file's own punctual lights (``frustum.scenefile.gltf_lights``, glTF units) with the ambient light of
    ``default_lights`` (the uniform surroundings a viewer's environment gives), or [] when it carries none."""
    if file.suffix.lower() not in (".glb", ".gltf"):
        return []
    from frustum.scenefile.gltf_lights import gltf_lights

    lights = gltf_lights(file)
    return [*lights, AmbientLight(intensity=PHYSICAL_AMBIENT)] if lights else []


def _add_points(scene: Scene, file: Path, turn: np.ndarray | None) -> bool:
    """Place the point cloud or Gaussian splats of `file` in `scene` (squares of 2 pixels; white where the cloud has
    no colors); False for a mesh file."""
    from frustum.geometry.points import point_file_kind

    kind = point_file_kind(file)
    if kind is None:
        return False
    if kind == "splats":
        from frustum.geometry.splats import GaussianSplats

        scene.add(GaussianSplats.load(file), transform=turn, name=file.stem)
        return True
    from frustum.geometry.points import load_points

    scene.add(load_points(file), Material(color=(1.0, 1.0, 1.0), specular=0.2), turn, name=file.stem)
    return True


def model_options(scene: Scene) -> dict[str, Any]:
    """Render options of a model file's scene: eye-dome lighting for a point cloud without normals (a scan, drawn
    unlit in its colors: EDL gives it shape)."""
    clouds = scene.point_clouds
    unlit = [p for p in clouds if p.style.style in ("square", "disk") and p.geometry.normals is None]
    return {"eye_dome": True} if unlit else {}
