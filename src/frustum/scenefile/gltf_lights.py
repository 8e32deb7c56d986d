"""The lights a glTF file carries: the ``KHR_lights_punctual`` extension, as frustum lights in glTF's units.

Each node of the file's scene whose ``extensions.KHR_lights_punctual.light`` names a light places that light by
its world transform (the product of the nodes' ``matrix`` or translation · rotation · scale down the tree): the
light sits at the node's origin and shines along the node's −Z axis. The light types map one to one onto the
light classes, whose intensities the metallic–roughness model reads in glTF's units (``frustum.shading.pbr``):

- ``directional`` (illuminance in lux) → ``DirectionalLight(direction, color, intensity)``;
- ``point`` (luminous intensity in candela) → ``PointLight(position, color, intensity, range=)``: inverse-square
  falloff with the ``range`` window;
- ``spot`` (candela) → ``SpotLight(position, direction, color, intensity, inner_angle=innerConeAngle,
  outer_angle=outerConeAngle, range=)`` (defaults 0 and π/4; an outer angle of π/2 is taken just below it, where
  ``SpotLight`` requires a cone narrower than a half-space).

``color`` defaults to white and ``intensity`` to 1, as the extension says. A file without the extension has no
lights (``[]``); ``frustum.scenefile.models.model_scene`` then adds its default lights.

References: Khronos, "KHR_lights_punctual" (glTF 2.0 extension), "Transformations" (glTF 2.0 specification 3.5.3).
"""

from __future__ import annotations

import json
import math
import struct
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from frustum.errors import FrustumError, GeometryError
from frustum.shading import DirectionalLight, PointLight, SpotLight

__all__ = ["EXTENSION", "gltf_lights", "node_matrix"]

EXTENSION = "KHR_lights_punctual"
_BELOW_HALF_SPACE = math.pi / 2 - 1e-6


def gltf_lights(path: str | Path) -> list[Any]:
    """The punctual lights of the glTF or GLB file at `path`, placed in world space (module docstring).

    Raises
    ------
    GeometryError
        The file is not readable glTF, or a light or node is malformed (the message names which).
    """
    file = Path(path)
    try:
        return _placed_lights(file, _document(file))
    except (AttributeError, TypeError, KeyError, IndexError) as error:
        raise GeometryError(f"load: {file.name}: its {EXTENSION} lights or nodes are malformed ({error})") from None


def _placed_lights(file: Path, gltf: dict[str, Any]) -> list[Any]:
    table = gltf.get("extensions", {}).get(EXTENSION, {}).get("lights", [])
    if not table:
        return []
    nodes = gltf.get("nodes", [])
    scenes = gltf.get("scenes", [{"nodes": list(range(len(nodes)))}])
    roots = scenes[gltf.get("scene", 0)].get("nodes", []) if scenes else []
    lights: list[Any] = []
    stack = [(int(index), np.eye(4)) for index in reversed(roots)]  # depth first, in the order of the file
    seen: set[int] = set()
    while stack:
        index, parent = stack.pop()
        if index in seen or not 0 <= index < len(nodes):
            raise GeometryError(f"load: {file.name}: node {index} is repeated or missing in the node tree")
        seen.add(index)
        node = nodes[index]
        world = parent @ node_matrix(node, f"load: {file.name}: node {index}")
        reference = node.get("extensions", {}).get(EXTENSION)
        if reference is not None:
            number = reference.get("light")
            if not isinstance(number, int) or not 0 <= number < len(table):
                raise GeometryError(f"load: {file.name}: node {index} names light {number!r}, which the file lacks")
            lights.append(_light(table[number], world, f"load: {file.name}: light {number}"))
        stack.extend((int(child), world) for child in reversed(node.get("children", [])))
    return lights


def node_matrix(node: dict[str, Any], where: str) -> NDArray[np.float64]:
    """A glTF node's local transform (4, 4): its column-major ``matrix``, or $T·R·S$ from ``translation``,
    ``rotation`` (a unit quaternion x, y, z, w) and ``scale``."""
    try:
        if "matrix" in node:
            matrix = np.asarray(node["matrix"], dtype=np.float64).reshape(4, 4).T
        else:
            t = np.asarray(node.get("translation", (0.0, 0.0, 0.0)), dtype=np.float64).reshape(3)
            x, y, z, w = np.asarray(node.get("rotation", (0.0, 0.0, 0.0, 1.0)), dtype=np.float64).reshape(4)
            s = np.asarray(node.get("scale", (1.0, 1.0, 1.0)), dtype=np.float64).reshape(3)
            rotation = np.array([
                [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
            ])  # fmt: skip
            matrix = np.eye(4)
            matrix[:3, :3] = rotation * s[None, :]
            matrix[:3, 3] = t
    except (TypeError, ValueError):
        raise GeometryError(f"{where}: its matrix or translation, rotation, scale are not numbers") from None
    if not np.isfinite(matrix).all():
        raise GeometryError(f"{where}: its transform is not finite")
    return matrix


def _light(spec: Any, world: NDArray[np.float64], where: str) -> Any:
    """One KHR_lights_punctual light placed by `world` (module docstring)."""
    if not isinstance(spec, dict) or spec.get("type") not in ("directional", "point", "spot"):
        kind = spec.get("type") if isinstance(spec, dict) else spec
        raise GeometryError(f"{where}: type = {kind!r} is not 'directional', 'point' or 'spot'")
    position = world[:3, 3]
    direction = world[:3, :3] @ np.array([0.0, 0.0, -1.0])
    common = {"color": tuple(spec.get("color", (1.0, 1.0, 1.0))), "intensity": spec.get("intensity", 1.0)}
    try:
        if spec["type"] == "directional":
            return DirectionalLight(direction, **common)
        if spec["type"] == "point":
            return PointLight(position, **common, range=spec.get("range"))
        cone = spec.get("spot", {})
        inner = float(cone.get("innerConeAngle", 0.0))
        outer = min(float(cone.get("outerConeAngle", math.pi / 4)), _BELOW_HALF_SPACE)
        return SpotLight(position, direction, **common, inner_angle=min(inner, outer), outer_angle=outer,
                         range=spec.get("range"))  # fmt: skip
    except (FrustumError, TypeError, ValueError) as error:
        raise GeometryError(f"{where}: {error}") from None


def _document(file: Path) -> dict[str, Any]:
    """The JSON of a .gltf file, or of a .glb file's first chunk."""
    try:
        data = file.read_bytes()
        if data[:4] == b"glTF":
            (length,) = struct.unpack_from("<I", data, 12)
            data = data[20 : 20 + length]
        document = json.loads(data)
    except (OSError, ValueError, struct.error) as error:
        raise GeometryError(f"load: {file.name} is not a readable glTF file ({error})") from None
    if not isinstance(document, dict):
        raise GeometryError(f"load: {file.name} is not a glTF document (its JSON is not an object)")
    return document
