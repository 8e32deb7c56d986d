"""The world: meshes placed by a modeling transform, each with a material, and the lights that shine on them."""

from __future__ import annotations

from collections.abc import Iterable
from typing import NamedTuple

from numpy.typing import ArrayLike

from frustum._arrays import Matrix4, as_matrix, describe
from frustum.errors import FrustumError
from frustum.geometry import Mesh
from frustum.shading import DirectionalLight, Material

__all__ = ["Scene", "SceneItem"]


class SceneItem(NamedTuple):
    """One placed mesh: ``world = world_from_model · model``."""

    mesh: Mesh
    material: Material
    world_from_model: Matrix4


class Scene:
    """A list of placed meshes and a list of lights: ``Scene(lights=[light]); scene.add(mesh, material=m)``.

    Items render in the order they were added (the depth buffer makes the image independent of that order,
    except for exactly equal depths, where the first drawn wins under the "less" test).
    """

    def __init__(self, lights: Iterable[DirectionalLight] = ()) -> None:
        self.lights: list[DirectionalLight] = []
        self.items: list[SceneItem] = []
        for light in lights:
            self.add_light(light)

    def add_light(self, light: DirectionalLight) -> Scene:
        """Append a light; returns the scene."""
        if not isinstance(light, DirectionalLight):
            raise FrustumError(
                f"Scene.add_light: light = {describe(light)} is not a DirectionalLight; build one with "
                "DirectionalLight(direction=(dx, dy, dz))"
            )
        self.lights.append(light)
        return self

    def add(self, mesh: Mesh, material: Material | None = None, transform: ArrayLike | None = None) -> Scene:
        """Place `mesh` with `material` (default ``Material()``) by ``world_from_model = transform``; returns self."""
        where = "Scene.add"
        if not isinstance(mesh, Mesh):
            raise FrustumError(f"{where}: mesh = {describe(mesh)} is not a Mesh; build one with Mesh(vertices, faces)")
        material = Material() if material is None else material
        if not isinstance(material, Material):
            raise FrustumError(f"{where}: material = {describe(material)} is not a Material; build one with Material()")
        matrix = as_matrix(
            [[1.0, 0, 0, 0], [0, 1.0, 0, 0], [0, 0, 1.0, 0], [0, 0, 0, 1.0]] if transform is None else transform,
            "transform",
            where=where,
        )
        if abs(matrix[3] - (0.0, 0.0, 0.0, 1.0)).max() != 0.0:
            raise FrustumError(
                f"{where}: transform bottom row = {describe(matrix[3])} makes it projective; a modeling transform "
                "is affine (bottom row 0, 0, 0, 1)"
            )
        matrix.flags.writeable = False
        self.items.append(SceneItem(mesh, material, matrix))
        return self

    def __len__(self) -> int:
        return len(self.items)
