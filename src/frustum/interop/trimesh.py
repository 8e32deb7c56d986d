"""trimesh scenes and meshes drawn by frustum: ``Scene.from_trimesh`` and ``render_trimesh``.

``scene_from_trimesh`` reads a ``trimesh.Scene`` (or one ``trimesh.Trimesh``) the way ``frustum.load_parts`` reads
a mesh file (``geometry.io.scene_parts``): every node's world transform, its geometry, its visual — vertex
colours, face colours (each face's corners split off, as pyrender does), a texture's image and UVs, a PBR
material's base colour, emissive factor and normal map — turned into ``Material``s as for mesh files
(``scenefile.models.part_material``). Its camera: ``scene.camera`` with ``scene.camera_transform`` (trimesh's K,
principal point in pixels with the top-left pixel's centre at (0.5, 0.5), OpenGL axes: ``Camera.from_intrinsics``)
when the scene has one, else ``Camera.fit``; the lights: frustum's default three-point setup around that camera
(``scenefile.models.default_lights``: trimesh scenes carry no lights until a viewer makes some).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from frustum._arrays import describe
from frustum.camera import Camera
from frustum.errors import FrustumError
from frustum.frame import Frame
from frustum.geometry.io import scene_parts
from frustum.scene import Scene
from frustum.scenefile.models import default_lights, part_nodes

__all__ = ["render_trimesh", "scene_from_trimesh"]

_DEFAULT_RESOLUTION = (640, 480)


def _trimesh() -> Any:
    import trimesh  # a dependency of frustum itself

    return trimesh


def _size(resolution: Any, where: str) -> tuple[int, int] | None:
    if resolution is None:
        return None
    try:
        width, height = (int(v) for v in resolution)
        valid = all(float(v) == int(v) for v in resolution)
    except (TypeError, ValueError):
        valid = False
    if not valid or width <= 0 or height <= 0:
        raise FrustumError(f"{where}: resolution = {describe(resolution)} is not (width, height) in pixels")
    return width, height


def _with_vertex_colors(scene: Any) -> Any:
    """`scene`, or a copy whose face-coloured meshes have each face's corners split off and coloured by the face
    (trimesh's face colours have no per-vertex form otherwise)."""
    trimesh = _trimesh()
    face_colored = [
        name
        for name, geometry in scene.geometry.items()
        if isinstance(geometry, trimesh.Trimesh) and getattr(geometry.visual, "kind", None) == "face"
    ]
    if not face_colored:
        return scene
    copy = scene.copy()
    for name in face_colored:
        geometry = copy.geometry[name]
        colors = np.asarray(geometry.visual.face_colors)
        split = trimesh.Trimesh(geometry.vertices[geometry.faces].reshape(-1, 3),
                                np.arange(3 * len(geometry.faces)).reshape(-1, 3), process=False)  # fmt: skip
        split.visual = trimesh.visual.ColorVisuals(split, vertex_colors=np.repeat(colors, 3, axis=0))
        copy.geometry[name] = split
    return copy


def _part(part: Any) -> Any:
    """A part with a node name frustum accepts ('/' separates node paths) and, when its colours are per vertex,
    a white base colour for them to multiply (``part_material`` gives colourless parts a light gray)."""
    part = part._replace(name=str(part.name).replace("/", "_"))
    if part.color is None and part.mesh.vertex_colors is not None:
        part = part._replace(color=(1.0, 1.0, 1.0, 1.0))
    return part


def scene_from_trimesh(scene_or_mesh: Any, *, resolution: Any = None) -> tuple[Scene, Camera]:
    """frustum's ``(Scene, Camera)`` for a ``trimesh.Scene`` or ``trimesh.Trimesh`` (module docstring).

    Parameters
    ----------
    scene_or_mesh : trimesh.Scene or trimesh.Trimesh
    resolution : (width, height), optional
        Image size; default the scene camera's resolution, or 640 x 480 without a camera.

    Raises
    ------
    FrustumError
        If the argument is not a trimesh scene or mesh, or holds no triangles.
    """
    trimesh = _trimesh()
    where = "Scene.from_trimesh"
    if isinstance(scene_or_mesh, trimesh.Trimesh):
        source = trimesh.Scene(scene_or_mesh)
    elif isinstance(scene_or_mesh, trimesh.Scene):
        source = scene_or_mesh
    else:
        raise FrustumError(f"{where}: scene_or_mesh = {describe(scene_or_mesh)} is not a trimesh.Scene or Trimesh")
    size = _size(resolution, where)
    parts = [_part(part) for part in scene_parts(_with_vertex_colors(source))]
    if not parts:
        raise FrustumError(f"{where}: the trimesh scene holds no triangle mesh; add a Trimesh with faces")
    scene = Scene()
    for node in part_nodes(parts):
        scene.add(node)
    if source.has_camera:
        lens = source.camera
        width, height = size if size is not None else (int(lens.resolution[0]), int(lens.resolution[1]))
        # trimesh's K for its own resolution, scaled to the image asked for
        k = np.array(lens.K, dtype=np.float64) * [[width / lens.resolution[0]], [height / lens.resolution[1]], [1.0]]
        pose = np.asarray(source.camera_transform, dtype=np.float64)
        near, far = float(lens.z_near), float(lens.z_far)
        camera = Camera.from_intrinsics(k, width, height, camera_to_world=pose, convention="opengl", near=near, far=far)
    else:
        width, height = size if size is not None else _DEFAULT_RESOLUTION
        camera = Camera.fit(scene, width=width, height=height)
    for light in default_lights(camera):
        scene.root.add_light(light)
    return scene, camera


def render_trimesh(scene_or_mesh: Any, *, resolution: Any = None, **options: Any) -> Frame:
    """Render a ``trimesh.Scene`` or ``Trimesh`` with frustum: ``render(*Scene.from_trimesh(...), **options)``.

    A ``Frame`` shows itself in a notebook, so ``frustum.render_trimesh(mesh)`` is the headless
    ``mesh.show()``. `options` are ``frustum.render``'s keywords.
    """
    from frustum.render import render

    scene, camera = scene_from_trimesh(scene_or_mesh, resolution=resolution)
    return render(scene, camera, **options)
