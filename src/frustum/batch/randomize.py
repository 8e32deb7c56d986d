"""Scene randomisation for synthetic datasets: object poses on a support plane, cameras on a shell, light and
material jitter. Every function draws from the ``numpy.random.Generator`` it is given and from nothing else (no
global state), so a dataset is reproduced from its seed: ``rng = np.random.default_rng(seed)``, the same calls in
the same order, and ``render_dataset(..., seed=seed)`` writes the seed into the dataset's metadata.

- ``drop_on_plane``: each node turned by a random angle about the plane's normal (y) and moved to a uniform
  point of a rectangle, its lowest point on the plane $y = h$; a pose whose surfaces cross an object placed before
  (every edge of each tested as a segment against the other's triangles through the scene's ray index,
  ``Scene.occluded``) or whose bounding box holds or sits inside another's is rejected and drawn again.
- ``cameras_on_shell``: eyes uniform in the volume of a spherical shell $r ∈ [r_0, r_1]$ (radius
  $r = (r_0^3 + u·(r_1^3 − r_0^3))^{1/3}$), directions uniform on the sphere's band of elevations
  ($sin(e)$ uniform), each looking at the target; a sphere when $r_0 = r_1$.
- ``jitter_lights``, ``jitter_materials``: intensities scaled by $1 + U(−a, a)$, directions and positions moved by
  Gaussian noise, material colors moved by $U(−a, a)$ per channel and clipped to [0, 1].
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from frustum._arrays import describe
from frustum.camera import Camera
from frustum.errors import FrustumError
from frustum.geometry import Mesh
from frustum.scene import Node, Scene
from frustum.transforms import rotate_y, translate

__all__ = ["cameras_on_shell", "drop_on_plane", "jitter_lights", "jitter_materials"]


def _generator(rng: Any, where: str) -> np.random.Generator:
    if not isinstance(rng, np.random.Generator):
        raise FrustumError(
            f"{where}: rng = {describe(rng)} is not a numpy.random.Generator; give np.random.default_rng(seed)"
        )
    return rng


def _world_vertices(node: Node, transform: np.ndarray) -> np.ndarray:
    mesh = node.geometry
    return np.asarray(mesh.vertices, dtype=np.float64) @ transform[:3, :3].T + transform[:3, 3]


def _edges(mesh: Mesh) -> np.ndarray:
    """(E, 2) unique vertex pairs of the mesh's triangle edges."""
    faces = np.asarray(mesh.faces, dtype=np.int64)
    pairs = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    return np.unique(np.sort(pairs, axis=1), axis=0)


def _crossing(first: tuple[Node, np.ndarray, np.ndarray], second: tuple[Node, np.ndarray, np.ndarray]) -> bool:
    """Whether an edge of one placed mesh (node, world vertices, edges) meets a triangle of the other."""
    for (node, _, _), (_, points, edges) in ((first, second), (second, first)):
        probe = Scene()
        probe.add(node.geometry, transform=node.transform)
        origins = points[edges[:, 0]]
        directions = points[edges[:, 1]] - origins
        keep = np.linalg.norm(directions, axis=1) > 0
        if keep.any() and probe.occluded(origins[keep], directions[keep], 1.0).any():
            return True
    return False


def drop_on_plane(
    scene: Scene, nodes: Sequence[Node], rng: np.random.Generator, *, area: Any = ((-0.25, -0.25), (0.25, 0.25)),
    height: float = 0.0, attempts: int = 200,
) -> list[Node]:  # fmt: skip
    """Place `nodes` (each holding a Mesh) one after the other on the plane $y$ = `height` at random poses without
    interpenetration (module docstring), add them to `scene`'s root and return them.

    Parameters
    ----------
    area : ((x0, z0), (x1, z1))
        The rectangle of the plane the objects' origins are drawn from.
    attempts : int
        Poses tried per object before giving up.

    Raises
    ------
    FrustumError
        `rng` not a Generator, a node without a mesh, a bad area, or an object that found no free pose in
        `attempts` tries (the message names it).
    """
    where = "drop_on_plane"
    rng = _generator(rng, where)
    try:
        (x0, z0), (x1, z1) = np.asarray(area, dtype=np.float64)
    except (TypeError, ValueError):
        raise FrustumError(f"{where}: area = {describe(area)} is not ((x0, z0), (x1, z1))") from None
    if not (np.isfinite([x0, z0, x1, z1]).all() and x0 <= x1 and z0 <= z1):
        raise FrustumError(f"{where}: area = {describe(area)} is not a rectangle with x0 <= x1 and z0 <= z1")
    placed: list[tuple[Node, np.ndarray, np.ndarray]] = []
    boxes: list[np.ndarray] = []
    for node in nodes:
        if not isinstance(node, Node) or not isinstance(node.geometry, Mesh):
            raise FrustumError(f"{where}: {describe(node)} is not a Node holding a Mesh")
        edges = _edges(node.geometry)
        for _ in range(int(attempts)):
            angle = rng.uniform(0.0, 2.0 * math.pi)
            x, z = rng.uniform(x0, x1), rng.uniform(z0, z1)
            turned = rotate_y(angle)
            low = float(_world_vertices(node, turned)[:, 1].min())
            transform = translate(x, height - low, z) @ turned
            points = _world_vertices(node, transform)
            bounds = np.array([points.min(axis=0), points.max(axis=0)])
            node.transform = transform
            candidate = (node, points, edges)
            if all(not _overlap(bounds, other) for other in boxes):
                break
            if any(_overlap(bounds, b) and (_inside(bounds, b) or _inside(b, bounds) or _crossing(candidate, p))
                   for p, b in zip(placed, boxes, strict=True)):  # fmt: skip
                continue
            break
        else:
            raise FrustumError(
                f"{where}: node {node.name!r} found no pose free of the {len(placed)} objects placed before it in "
                f"{attempts} tries; give a larger area or fewer objects"
            )
        placed.append(candidate)
        boxes.append(bounds)
        scene.add(node)
    return list(nodes)


def _overlap(a: np.ndarray, b: np.ndarray) -> bool:
    return bool((a[0] <= b[1]).all() and (b[0] <= a[1]).all())


def _inside(a: np.ndarray, b: np.ndarray) -> bool:
    """Whether box a lies within box b."""
    return bool((a[0] >= b[0]).all() and (a[1] <= b[1]).all())


def cameras_on_shell(
    rng: np.random.Generator, count: int, target: Any = (0.0, 0.0, 0.0), *, radius: Any = (0.5, 0.8),
    elevation: Any = (0.25, 1.3), width: int = 640, height: int = 480,
    projection: Any = None,
) -> list[Camera]:  # fmt: skip
    """`count` cameras looking at `target` from eyes drawn uniformly in a spherical shell (module docstring).

    Parameters
    ----------
    radius : float or (r0, r1)
        The shell's radii (one number: a sphere).
    elevation : (e0, e1)
        Elevations in radians above the horizontal plane through the target, in [−π/2, π/2] (default about
        14° to 74°).
    projection : Projection or None
        The cameras' projection (``Camera.look_at``'s default when None).
    """
    where = "cameras_on_shell"
    rng = _generator(rng, where)
    if isinstance(count, bool) or not isinstance(count, int | np.integer) or count < 1:
        raise FrustumError(f"{where}: count = {describe(count)} is not a positive integer")
    r0, r1 = (float(radius), float(radius)) if np.ndim(radius) == 0 else map(float, radius)
    e0, e1 = map(float, elevation)
    if not (0.0 < r0 <= r1 and -math.pi / 2 <= e0 <= e1 <= math.pi / 2):
        raise FrustumError(f"{where}: radius = {describe(radius)} or elevation = {describe(elevation)} is not a "
                           "shell: give 0 < r0 <= r1 and -pi/2 <= e0 <= e1 <= pi/2")  # fmt: skip
    center = np.asarray(target, dtype=np.float64)
    cameras = []
    for _ in range(int(count)):
        azimuth = rng.uniform(0.0, 2.0 * math.pi)
        rise = rng.uniform(math.sin(e0), math.sin(e1))
        distance = (r0**3 + rng.uniform() * (r1**3 - r0**3)) ** (1.0 / 3.0)
        ring = math.sqrt(max(0.0, 1.0 - rise * rise))
        eye = center + distance * np.array([ring * math.sin(azimuth), rise, ring * math.cos(azimuth)])
        up = (0.0, 1.0, 0.0) if ring > 1e-3 else (0.0, 0.0, -1.0)
        cameras.append(Camera.look_at(eye, center, up, projection, width, height))
    return cameras


def jitter_lights(lights: Sequence[Any], rng: np.random.Generator, *, intensity: float = 0.2,
                  direction: float = 0.2, position: float = 0.1) -> list[Any]:  # fmt: skip
    """New lights: each intensity times $1 + U(−a, a)$ (a = `intensity`), directions turned by Gaussian noise of
    `direction` (per component of the unit vector, renormalized), positions moved by Gaussian noise of `position`
    scene units."""
    rng = _generator(rng, "jitter_lights")
    result = []
    for light in lights:
        changes: dict[str, Any] = {"intensity": float(light.intensity) * (1.0 + rng.uniform(-intensity, intensity))}
        if hasattr(light, "direction"):
            d = np.asarray(light.direction, dtype=np.float64)
            d = d / np.linalg.norm(d) + rng.normal(0.0, direction, 3)
            changes["direction"] = tuple(float(v) for v in d / np.linalg.norm(d))
        if hasattr(light, "position"):
            changes["position"] = tuple(float(v) for v in np.asarray(light.position) + rng.normal(0.0, position, 3))
        result.append(dataclasses.replace(light, **changes))
    return result


def jitter_materials(scene: Scene, rng: np.random.Generator, *, color: float = 0.1) -> Scene:
    """Give every node of `scene` that has a material a copy with its color moved by $U(−a, a)$ per channel
    (a = `color`), clipped to [0, 1]; in ``Scene.walk`` order. Returns the scene."""
    rng = _generator(rng, "jitter_materials")
    for node, _ in scene.walk():
        if node.material is not None:
            moved = np.clip(np.asarray(node.material.color, dtype=np.float64) + rng.uniform(-color, color, 3), 0, 1)
            node.material = node.material.with_(color=tuple(float(v) for v in moved))
    return scene
