"""``[[nodes]]``: the node hierarchy (name, geometry, material, transform, children, lights), and the
``[exploded]`` and ``[cutaway]`` views of the built scene."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from frustum.errors import FrustumError
from frustum.scene import Node, Scene, cutaway, exploded
from frustum.scenefile.checks import _boolean, _number, _table, _table_list, _unknown_keys, _vector
from frustum.scenefile.geometry import _geometry, _mesh_file
from frustum.scenefile.lights_materials import _lights, _material_reference
from frustum.scenefile.models import part_material, part_nodes
from frustum.scenefile.report import _BAD, _bad, _Report
from frustum.scenefile.transforms import _transform

_NODE_KEYS = ("name", "geometry", "material", "transform", "children", "lights", "label")


def _node(report: _Report, path: tuple, value: dict, base: Path, materials: dict, names: set) -> Any:
    _unknown_keys(report, path, value, _NODE_KEYS)
    name = value.get("name", "")
    if not isinstance(name, str) or "/" in name:
        report.add((*path, "name"), name, "is not a name", "give a string without '/' ('/' separates node paths)")
        name = ""
    label = value.get("label")
    if label is not None and (not isinstance(label, str) or not label):
        report.add((*path, "label"), label, "is not a class name", "give a non-empty string such as 'mug'")
        label = None
    transform = _transform(report, (*path, "transform"), value["transform"]) if "transform" in value else None
    material = None
    if "material" in value:
        material = _material_reference(report, (*path, "material"), value["material"], materials)
    geometry, extras = (None, [])
    table = value.get("geometry")
    if isinstance(table, dict) and table.get("type") == "mesh":  # a mesh file: its parts with their materials
        geometry, extras, own = _mesh_file_parts(report, (*path, "geometry"), table, base)
        if material is None:
            material = own
        elif extras:  # the node's material replaces the file's on every part
            for child in extras:
                child.material = None
    elif "geometry" in value:
        geometry, extras = _geometry(report, (*path, "geometry"), value["geometry"], base, materials)
    lights = _lights(report, (*path, "lights"), value["lights"]) if "lights" in value else []
    children = []
    for i, child in enumerate(_table_list(report, (*path, "children"), value.get("children", []))):
        built = _node(report, (*path, "children", i), dict(child), base, materials, names)
        if built is not _BAD:
            children.append(built)
    if _bad(transform, material, geometry):
        return _BAD
    try:
        return Node(name, transform, geometry, material, [*extras, *children], lights, label=label)
    except FrustumError as error:
        report.refused(path, name, error)
        return _BAD


def _mesh_file_parts(report: _Report, path: tuple, table: dict, base: Path) -> tuple[Any, list[Node], Any]:
    """A ``type = "mesh"`` file as (mesh, [], its material or None) for one part at the file's origin, else
    (None, a node per part with its own material, None): base colours, textures and normal maps from OBJ/MTL and
    glTF (``frustum.geometry.io.load_parts``) reach scene files."""
    from frustum.geometry.io import load_parts

    params = {key: item for key, item in table.items() if key != "type"}
    parts = _mesh_file(report, path, params, base, load_parts)
    if parts is _BAD:
        return _BAD, [], None
    if len(parts) == 1 and np.allclose(parts[0].world_from_model, np.eye(4)):
        part = parts[0]
        own = (part.texture, part.color, part.normal_map, part.emissive)
        has_own = part.physical or any(x is not None for x in own)
        return part.mesh, [], part_material(part) if has_own else None
    return None, part_nodes(parts), None


def _explode_and_cut(report: _Report, data: dict, scene: Scene) -> Scene:
    if "exploded" in data:
        path = ("exploded",)
        params = _table(report, path, data["exploded"])
        if params is not _BAD:
            _unknown_keys(report, path, params, ("factor", "center", "node"))
            factor = _number(report, (*path, "factor"), params.get("factor", 0.5), low=0.0)
            center = None
            if "center" in params:
                center = _vector(report, (*path, "center"), params["center"])
            node_path = params.get("node")
            if factor is not _BAD and center is not _BAD:
                try:
                    if node_path is None:
                        scene = exploded(scene, factor, center)  # type: ignore[assignment]
                    else:
                        _explode_node(scene, str(node_path), factor, center)
                except FrustumError as error:
                    report.refused((*path, "node") if node_path is not None else path, node_path, error)
    if "cutaway" in data:
        path = ("cutaway",)
        params = _table(report, path, data["cutaway"])
        if params is not _BAD:
            scene = _cut(report, path, params, scene)
    return scene


def _explode_node(scene: Scene, node_path: str, factor: float, center: Any) -> None:
    node = scene.find(node_path)
    parent_path = node_path.strip("/").rsplit("/", 1)[0] if "/" in node_path.strip("/") else ""
    parent = scene.find(parent_path) if parent_path else scene.root
    replacement = exploded(node, factor, center)
    parent.children[parent.children.index(node)] = replacement  # type: ignore[assignment]


def _cut(report: _Report, path: tuple, params: dict, scene: Scene) -> Scene:
    _unknown_keys(report, path, params, ("plane_point", "plane_normal", "box_min", "box_max", "cap", "ghost"))
    has_plane = "plane_point" in params or "plane_normal" in params
    has_box = "box_min" in params or "box_max" in params
    if has_plane == has_box:
        report.add(path, params, "needs exactly one cut", "give plane_point and plane_normal, or box_min and box_max")
        return scene
    keys = ("plane_point", "plane_normal") if has_plane else ("box_min", "box_max")
    values = []
    for key in keys:
        if key not in params:
            report.missing((*path, key), f"give both {keys[0]} and {keys[1]}")
            values.append(_BAD)
        else:
            values.append(_vector(report, (*path, key), params[key]))
    cap = _boolean(report, (*path, "cap"), params.get("cap", True))
    ghost = None
    if "ghost" in params:
        ghost = _number(report, (*path, "ghost"), params["ghost"], low=0.0, high=1.0, low_open=True)
        if ghost == 1.0:
            report.add((*path, "ghost"), ghost, "is out of range", "expected an opacity in (0, 1)")
            ghost = _BAD
    if _bad(*values, cap, ghost):
        return scene
    try:
        if has_plane:
            return cutaway(scene, plane=(values[0], values[1]), cap=cap, ghost=ghost)
        return cutaway(scene, box=(values[0], values[1]), cap=cap, ghost=ghost)
    except (FrustumError, ImportError, ValueError, IndexError) as error:  # trimesh's capping may need rtree
        report.refused(path, params, error)
        return scene
