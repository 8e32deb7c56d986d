"""A node's ``geometry`` table: the registry of geometry types (``GEOMETRY_TYPES``) and their builders: meshes from
functions, mesh files, patch models, surfaces, curves (tubes or polylines, with their control polygons), point
fractals, terrain, L-systems, CSG and octrees."""

from __future__ import annotations

import importlib
import math
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import numpy as np

from frustum.errors import FrustumError
from frustum.geometry import Mesh
from frustum.scene import Node
from frustum.scenefile.checks import (
    _MAX_INTEGER_PARAMETER,
    _boolean,
    _call,
    _choice,
    _input_file,
    _number,
    _resolve,
    _table,
    _unknown_keys,
    _vector,
)
from frustum.scenefile.lights_materials import _material_reference
from frustum.scenefile.report import _BAD, _bad, _Report
from frustum.scenefile.transforms import _transform
from frustum.shading import Material
from frustum.transforms import rotate_x, translate

_CURVE_KEYS = ("samples", "radius", "sides", "style", "closed", "control_polygon", "control_markers",
               "control_radius", "control_material")  # fmt: skip


_CURVE_STYLES = ("tube", "line")


GEOMETRY_TYPES: dict[str, tuple[str, str, str]] = {
    "mesh": ("file", "frustum.geometry.io", "load"),
    # primitives
    "box": ("mesh", "frustum.geometry.primitives", "box"),
    "plane": ("mesh", "frustum.geometry.primitives", "plane"),
    "grid": ("mesh", "frustum.geometry.primitives", "grid"),
    "uv_sphere": ("mesh", "frustum.geometry.primitives", "uv_sphere"),
    "icosphere": ("mesh", "frustum.geometry.primitives", "icosphere"),
    "cylinder": ("mesh", "frustum.geometry.primitives", "cylinder"),
    "cone": ("mesh", "frustum.geometry.primitives", "cone"),
    "torus": ("mesh", "frustum.geometry.primitives", "torus"),
    "disk": ("mesh", "frustum.geometry.primitives", "disk"),
    "arrow": ("mesh", "frustum.geometry.primitives", "arrow"),
    "axes": ("mesh", "frustum.geometry.primitives", "axes"),
    # quadrics and superquadrics
    "sphere": ("mesh", "frustum.geometry.quadrics", "sphere"),
    "ellipsoid": ("mesh", "frustum.geometry.quadrics", "ellipsoid"),
    "superellipsoid": ("mesh", "frustum.geometry.quadrics", "superellipsoid"),
    "supertoroid": ("mesh", "frustum.geometry.quadrics", "supertoroid"),
    # Bézier patch models
    "teapot": ("patches", "frustum.geometry.teapot", "teapot"),
    "teacup": ("patches", "frustum.geometry.teapot", "teacup"),
    "teaspoon": ("patches", "frustum.geometry.teapot", "teaspoon"),
    # surfaces
    "bezier_surface": ("surface", "frustum.geometry.surfaces", "BezierSurface"),
    "bspline_surface": ("surface", "frustum.geometry.surfaces", "BSplineSurface"),
    "nurbs_surface": ("surface", "frustum.geometry.surfaces", "NURBSSurface"),
    # curves
    "bezier_curve": ("curve", "frustum.geometry.curves", "BezierCurve"),
    "bspline_curve": ("curve", "frustum.geometry.curves", "BSpline"),
    "nurbs_curve": ("curve", "frustum.geometry.curves", "NURBSCurve"),
    "cubic_spline": ("curve", "frustum.geometry.curves", "CubicSpline"),
    "catmull_rom": ("curve", "frustum.geometry.curves", "catmull_rom"),
    "cardinal_spline": ("curve", "frustum.geometry.curves", "cardinal_spline"),
    # fractals
    "terrain": ("terrain", "frustum.geometry.fractals", "fbm_terrain"),
    "menger_sponge": ("mesh", "frustum.geometry.fractals", "menger_sponge"),
    "sierpinski_tetrahedron": ("mesh", "frustum.geometry.fractals", "sierpinski_tetrahedron"),
    "koch_snowflake": ("points", "frustum.geometry.fractals", "koch_snowflake"),
    "hilbert_curve_3d": ("points", "frustum.geometry.fractals", "hilbert_curve_3d"),
    "quaternion_julia": ("mesh", "frustum.geometry.escape_time", "quaternion_julia_mesh"),
    "lsystem": ("lsystem", "frustum.geometry.lsystem", "LSystem"),
    # constructive solid geometry over other geometry tables
    "union": ("csg", "frustum.geometry.csg", "union"),
    "difference": ("csg", "frustum.geometry.csg", "difference"),
    "intersection": ("csg", "frustum.geometry.csg", "intersection"),
    # point clouds (path, style, point_size, radius) and 3D Gaussian splats (path) from files
    "point_cloud": ("point_file", "frustum.geometry.points", "load_points"),
    "splats": ("file", "frustum.geometry.splats", "load_splats"),
    # a solid as an octree of the cells of another geometry table (drawn by [render] method = "octree")
    "octree": ("octree", "frustum.geometry.octree", "Octree"),
}
"""``geometry.type`` values: (kind, module, attribute) of the function or class that builds each one."""


def _tube(points: np.ndarray, radius: float, sides: int, closed: bool) -> Mesh:
    """A thin polygonal tube along a polyline: one prism per segment plus an octahedron at every joint.

    Each segment gets its own frame (the tangent and the coordinate axis least parallel to it), so no frame has
    to be carried along the curve; the joint octahedra hide the small gaps at bends.
    """
    if closed:
        points = np.concatenate([points, points[:1]])
    start, end = points[:-1], points[1:]
    keep = np.linalg.norm(end - start, axis=1) > 0.0
    start, end = start[keep], end[keep]
    tangent = end - start
    tangent /= np.linalg.norm(tangent, axis=1)[:, None]
    helper = np.eye(3)[np.argmin(np.abs(tangent), axis=1)]
    u = np.cross(tangent, helper)
    u /= np.linalg.norm(u, axis=1)[:, None]
    w = np.cross(tangent, u)
    angles = 2.0 * math.pi * np.arange(sides) / sides
    ring = np.cos(angles)[None, :, None] * u[:, None, :] + np.sin(angles)[None, :, None] * w[:, None, :]
    bottom = start[:, None, :] + radius * ring
    top = end[:, None, :] + radius * ring
    segments = start.shape[0]
    vertices = np.concatenate([bottom, top], axis=1).reshape(-1, 3)
    base = (2 * sides * np.arange(segments))[:, None]
    j = np.arange(sides)[None, :]
    a, b = base + j, base + (j + 1) % sides
    c, d = b + sides, a + sides
    faces = np.concatenate([np.stack([a, b, c], -1), np.stack([a, c, d], -1)], axis=1).reshape(-1, 3)
    # octahedra at the joints (every polyline point)
    joints = np.unique(np.concatenate([start, end]), axis=0)
    offsets = radius * np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], dtype=float)
    octa_faces = np.array(
        [[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]], dtype=np.int64
    )
    octa_vertices = (joints[:, None, :] + offsets[None]).reshape(-1, 3)
    octa = (octa_faces[None] + 6 * np.arange(joints.shape[0])[:, None, None]).reshape(-1, 3) + vertices.shape[0]
    return Mesh(np.concatenate([vertices, octa_vertices]), np.concatenate([faces.astype(np.int64), octa]))


def _as_points3(points: Any) -> np.ndarray:
    array = np.asarray(points, dtype=np.float64)
    if array.ndim == 2 and array.shape[1] == 2:
        array = np.column_stack([array, np.zeros(array.shape[0])])
    return array


def _polyline_type() -> Any:
    """``frustum.geometry.polyline.Polyline``, or None where this version has no polylines."""
    try:
        return importlib.import_module("frustum.geometry.polyline").Polyline
    except (ImportError, AttributeError):
        return None


def _line_geometry(report: _Report, path: tuple, points: np.ndarray, options: dict, closed: bool) -> Any:
    """A polyline as a depth-tested line (``Polyline``) or as a thin tube mesh (``style = "tube"``, or a ``radius``).

    Without ``style``, a curve with a ``radius`` is a tube and one without is a line (a tube where this version
    has no ``Polyline``).
    """
    polyline = _polyline_type()
    default = "tube" if "radius" in options or polyline is None else "line"
    if options.get("style", default) == "line":
        if polyline is None:
            report.add((*path, "style"), "line", "is not available in this version",
                       "frustum.geometry.polyline.Polyline is missing; use style = 'tube'")  # fmt: skip
            return _BAD
        return polyline(points, closed=closed, markers=bool(options.get("markers", False)))
    if points.shape[0] < 2:
        report.add(path, points.tolist(), "has fewer than 2 points", "a curve needs at least two points")
        return _BAD
    return _tube(points, options.get("radius", 0.02), options.get("sides", 8), closed)


def _control_node(report: _Report, path: tuple, geometry: Any, options: dict, materials: dict, name: str) -> Any:
    """A child node drawing control points or a control net, in ``control_material`` (default gray)."""
    material = None
    if "control_material" in options:
        material = _material_reference(report, (*path, "control_material"), options["control_material"], materials)
    if _bad(geometry, material):
        return _BAD
    return Node(name, None, geometry, material or Material((0.45, 0.45, 0.45)))


def _curve_options(report: _Report, path: tuple, params: dict) -> dict:
    options: dict[str, Any] = {}
    checks: dict[str, Callable[[tuple, Any], Any]] = {
        "samples": lambda p, v: _number(report, p, v, low=2, high=_MAX_INTEGER_PARAMETER, integer=True),
        "radius": lambda p, v: _number(report, p, v, low=0.0, low_open=True),
        "control_radius": lambda p, v: _number(report, p, v, low=0.0, low_open=True),
        "sides": lambda p, v: _number(report, p, v, low=3, high=64, integer=True),
        "style": lambda p, v: _choice(report, p, v, _CURVE_STYLES),
        "closed": lambda p, v: _boolean(report, p, v),
        "control_polygon": lambda p, v: _boolean(report, p, v),
        "control_markers": lambda p, v: _boolean(report, p, v),
        "control_material": lambda p, v: v,
    }
    for key in _CURVE_KEYS:
        if key in params:
            value = checks[key]((*path, key), params[key])
            if value is _BAD:
                options["bad"] = True
            options[key] = value
    return options


def _geometry(report: _Report, path: tuple, value: Any, base: Path, materials: dict) -> tuple[Any, list[Node]]:
    """The node's geometry and any extra child nodes (a curve's control polygon)."""
    params = _table(report, path, value)
    if params is _BAD:
        return _BAD, []
    if "type" not in params:
        report.missing((*path, "type"), f"give geometry.type, one of {', '.join(sorted(GEOMETRY_TYPES))}")
        return _BAD, []
    kind_name = _choice(report, (*path, "type"), params.pop("type"), sorted(GEOMETRY_TYPES))
    if kind_name is _BAD:
        return _BAD, []
    kind, module, attribute = GEOMETRY_TYPES[kind_name]
    builder = _resolve(report, (*path, "type"), kind_name, module, attribute)
    if builder is _BAD:
        return _BAD, []
    if kind == "file":
        return _mesh_file(report, path, params, base, builder), []
    if kind == "mesh":
        return _as_mesh(report, path, _call(report, path, builder, params, label=kind_name), kind_name), []
    if kind == "patches":
        return _patches(report, path, params, builder, materials)
    if kind == "surface":
        resolution = params.pop("resolution", [16, 16])
        counts = _vector(report, (*path, "resolution"), resolution, 2, "nu, nv")
        if counts is not _BAD and not all(float(c).is_integer() and 1 <= c <= 512 for c in counts):
            report.add((*path, "resolution"), resolution, "is out of range", "give [nu, nv], integers in [1, 512]")
            counts = _BAD
        surface = _call(report, path, builder, params, label=kind_name)
        if _bad(surface, counts):
            return _BAD, []
        return _call(report, path, surface.tessellate, {"nu": int(counts[0]), "nv": int(counts[1])},
                     label=kind_name), []  # fmt: skip
    if kind == "terrain":
        return _terrain(report, path, params, builder), []
    if kind == "csg":
        return _csg(report, path, params, builder, base, materials), []
    if kind == "lsystem":
        return _lsystem(report, path, params, builder), []
    if kind == "octree":
        return _octree(report, path, params, builder, base, materials), []
    if kind == "point_file":
        node = _point_cloud(report, path, params, base, builder)
        return (_BAD, []) if node is _BAD else (None, [node])
    # curves and point fractals: sampled into a polyline, drawn as a tube or line
    options = _curve_options(report, path, params)
    rest = {k: v for k, v in params.items() if k not in _CURVE_KEYS}
    built = _call(report, path, builder, rest, label=kind_name)
    if built is _BAD or options.get("bad"):
        return _BAD, []
    if kind == "points":
        points = _as_points3(built)
        control = None
        closed = bool(options.get("closed", kind_name == "koch_snowflake"))
    else:
        low, high = built.domain
        samples = options.get("samples", 64)
        points = _as_points3(built.evaluate(np.linspace(low, high, samples)))
        # interpolating splines show the points they pass through; approximating ones their control points
        control = rest["points"] if "points" in rest else getattr(built, "control_points", None)
        closed = bool(options.get("closed", False))
    geometry = _line_geometry(report, path, points, options, closed)
    extras: list[Node] = []
    if control is None:
        return geometry, extras
    polygon = _as_points3(control).reshape(-1, 3)
    if options.get("control_polygon"):
        control_options = {k: v for k, v in options.items() if k != "radius"}
        if "control_radius" in options or ("radius" in options and "style" not in options):
            control_options["radius"] = options.get("control_radius", 0.5 * options.get("radius", 0.02))
        drawn = _line_geometry(report, path, polygon, control_options, False)
        extras.append(_control_node(report, path, drawn, options, materials, "control polygon"))
    if options.get("control_markers"):
        drawn = _line_geometry(report, (*path, "control_markers"), polygon, {"style": "line", "markers": True}, False)
        extras.append(_control_node(report, path, drawn, options, materials, "control points"))
    return (_BAD, []) if _bad(*extras) else (geometry, extras)


def _patches(report: _Report, path: tuple, params: dict, builder: Callable, materials: dict) -> tuple[Any, list]:
    """A Bézier patch model tessellated ``resolution`` × ``resolution`` per patch, with its control net if asked."""
    _unknown_keys(report, path, params, ("resolution", "control_net", "control_material"))
    resolution = _number(report, (*path, "resolution"), params.get("resolution", 8), low=1, high=64, integer=True)
    net = _boolean(report, (*path, "control_net"), params.get("control_net", False))
    if _bad(resolution, net) or any(key not in ("resolution", "control_net", "control_material") for key in params):
        return _BAD, []
    patches = builder()
    mesh = _call(report, path, patches.tessellate, {"resolution": resolution}, label="tessellate")
    extras = []
    if net:
        polyline = _polyline_type()
        if polyline is None:
            report.add((*path, "control_net"), True, "is not available in this version", "Polyline is missing")
            return _BAD, []
        extras.append(_control_node(report, path, polyline.from_segments(patches.control_net()), params, materials,
                                    "control net"))  # fmt: skip
    return (_BAD, []) if _bad(mesh, *extras) else (mesh, extras)


def _csg(report: _Report, path: tuple, params: dict, boolean: Callable, base: Path, materials: dict) -> Any:
    """``union`` / ``difference`` / ``intersection`` of the solids in ``operands`` (each a geometry table that may
    carry its own ``transform`` list), with ``sharp_angle_deg`` for the result's normals."""
    _unknown_keys(report, path, params, ("operands", "sharp_angle_deg"))
    operands = params.get("operands")
    if not isinstance(operands, list) or len(operands) < 2 or not all(isinstance(o, Mapping) for o in operands):
        report.add((*path, "operands"), operands, "is not a list of two or more geometry tables",
                   "write operands = [{ type = 'box' }, { type = 'sphere', transform = [...] }]")  # fmt: skip
        return _BAD
    angle = _number(report, (*path, "sharp_angle_deg"), params.get("sharp_angle_deg", 60.0), low=0.0, high=180.0)
    meshes = []
    for i, operand in enumerate(operands):
        where = (*path, "operands", i)
        table = dict(operand)
        steps = table.pop("transform", None)
        mesh, _ = _geometry(report, where, table, base, materials)
        if mesh is not _BAD and not isinstance(mesh, Mesh):
            report.add((*where, "type"), table.get("type"), "is not a solid", "CSG operands are closed meshes")
            mesh = _BAD
        matrix = None if steps is None else _transform(report, (*where, "transform"), steps)
        if matrix is _BAD:
            mesh = _BAD
        elif mesh is not _BAD and matrix is not None:
            mesh = mesh.transformed(matrix)
        meshes.append(mesh)
    if _bad(angle, *meshes) or any(key not in ("operands", "sharp_angle_deg") for key in params):
        return _BAD
    try:
        return boolean(*meshes, sharp_angle=angle)
    except (FrustumError, ValueError, RuntimeError) as error:
        report.refused(path, {"operands": "..."}, error)
        return _BAD


def _octree(report: _Report, path: tuple, params: dict, octree: Any, base: Path, materials: dict) -> Any:
    """``Octree.from_mesh`` of the closed mesh the ``source`` geometry table builds (a mesh file, a primitive or a
    CSG expression, with its own ``transform`` list), down to ``depth`` levels (``shell`` for a surface)."""
    keys = ("source", "depth", "shell")
    _unknown_keys(report, path, params, keys)
    if "source" not in params:
        report.missing((*path, "source"), "give the solid as a geometry table, e.g. source = { type = 'sphere' }")
        return _BAD
    depth = _number(report, (*path, "depth"), params.get("depth", 6), low=0, high=12, integer=True)
    shell = _boolean(report, (*path, "shell"), params.get("shell", False))
    table = _table(report, (*path, "source"), params["source"])
    mesh = _BAD
    if table is not _BAD:
        table = dict(table)
        steps = table.pop("transform", None)
        mesh, _ = _geometry(report, (*path, "source"), table, base, materials)
        if mesh is not _BAD and not isinstance(mesh, Mesh):
            report.add((*path, "source", "type"), table.get("type"), "is not a solid", "give a closed mesh geometry")
            mesh = _BAD
        matrix = None if steps is None else _transform(report, (*path, "source", "transform"), steps)
        if matrix is _BAD:
            mesh = _BAD
        elif mesh is not _BAD and matrix is not None:
            mesh = mesh.transformed(matrix)
    if _bad(depth, shell, mesh) or any(key not in keys for key in params):
        return _BAD
    try:
        return octree.from_mesh(mesh, int(depth), shell=bool(shell))
    except FrustumError as error:
        report.refused(path, {"source": "...", "depth": depth}, error)
        return _BAD


def _as_mesh(report: _Report, path: tuple, value: Any, label: str) -> Any:
    if value is _BAD or isinstance(value, Mesh):
        return value
    report.add(path, label, "did not build a mesh", f"{label} returned {type(value).__name__}")
    return _BAD


def _mesh_file(report: _Report, path: tuple, params: dict, base: Path, loader: Callable) -> Any:
    _unknown_keys(report, path, params, ("path",))
    if "path" not in params:
        report.missing((*path, "path"), "give the mesh file, relative to the scene file")
        return _BAD
    name = params["path"]
    file = _input_file(report, (*path, "path"), name, what="a mesh file")
    if file is _BAD:
        return _BAD
    if len(params) > 1:
        return _BAD
    try:
        return loader(file)
    except FrustumError as error:
        report.refused((*path, "path"), name, error)
    except (OSError, ValueError, TypeError, IndexError, KeyError) as error:
        report.refused((*path, "path"), name, error)
    return _BAD


def _point_cloud(report: _Report, path: tuple, params: dict, base: Path, loader: Callable) -> Any:
    """A point file (``load_points``) drawn in ``style`` with ``point_size`` pixels or ``radius`` world units: one
    child node holding the cloud and its style (the node's transform and material apply to it)."""
    from frustum.geometry.points import point_style

    style = {key: params.pop(key) for key in ("style", "point_size", "radius") if key in params}
    cloud = _mesh_file(report, path, params, base, loader)
    if cloud is _BAD:
        return _BAD
    try:
        node = Node("points", None, cloud)
        node.point_style = point_style(cloud, style.get("style"), style.get("point_size"), style.get("radius"),
                                       "point_cloud")  # fmt: skip
    except FrustumError as error:
        report.refused(path, style, error)
        return _BAD
    return node


def _terrain(report: _Report, path: tuple, params: dict, fbm_terrain: Callable) -> Any:
    """fbm_terrain heights (times ``height_scale``) as a heightfield mesh ``size`` wide, centred, heights along +y."""
    size = params.pop("size", 1.0)
    height_scale = params.pop("height_scale", 1.0)
    size = _number(report, (*path, "size"), size, low=0.0, low_open=True)
    height_scale = _number(report, (*path, "height_scale"), height_scale)
    if "level" in params and _number(report, (*path, "level"), params["level"], low=0, high=10, integer=True) is _BAD:
        return _BAD
    heights = _call(report, path, fbm_terrain, params, label="terrain")
    if _bad(heights, size, height_scale):
        return _BAD
    try:
        mesh_builder = importlib.import_module("frustum.geometry.fractals").heightfield_mesh
        mesh = mesh_builder(np.asarray(heights) * height_scale, size)
        # heightfield_mesh is z-up over [0, size]²: centre it and turn the heights to +y (world up in scene files)
        return mesh.transformed(rotate_x(-math.pi / 2) @ translate(-size / 2, -size / 2, 0.0))
    except FrustumError as error:
        report.refused(path, params, error)
        return _BAD


def _lsystem(report: _Report, path: tuple, params: dict, lsystem_type: Any) -> Any:
    """An L-system (a ``preset`` from CLASSIC_LSYSTEMS or axiom/rules/angle_deg) expanded and swept into tubes."""
    module = importlib.import_module("frustum.geometry.lsystem")
    level = params.pop("level", 3)
    radius = params.pop("radius", 0.05)
    level = _number(report, (*path, "level"), level, low=0, high=12, integer=True)
    radius = _number(report, (*path, "radius"), radius, low=0.0, low_open=True)
    if "preset" in params:
        preset = _choice(report, (*path, "preset"), params.pop("preset"), sorted(module.CLASSIC_LSYSTEMS))
        _unknown_keys(report, path, params, ("level", "radius", "preset"))
        system = _BAD if preset is _BAD or params else module.CLASSIC_LSYSTEMS[preset]
    else:
        system = _call(report, path, lsystem_type, params, label="LSystem")
    if _bad(system, level, radius):
        return _BAD
    try:
        return module.tube_mesh(system.path(level), radius)
    except FrustumError as error:
        report.refused(path, params, error)
        return _BAD
