"""The algorithms by name, for ``frustum steps ALGORITHM`` (and ``--list``): each builds its ``Steps`` from the
command line's option texts.

Options (each algorithm reads the ones it needs; defaults give the chapter's worked example):
``from`` / ``to`` (``x,y,z[,w]``), ``points`` (``x,y[,z];x,y[,z];...``), ``t``, ``level``, ``axis``, ``point``,
``angle_deg``, ``knots`` (``0,0,0,1,2,2,2``), ``order``, ``u``, ``seed``; and ``scene``, ``camera`` (objects, from a
scene file the command loaded).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from frustum.errors import FrustumError
from frustum.steps import clipping, curves, fractals, modeling, viewing, visible_surfaces
from frustum.steps._record import Steps

__all__ = ["ALGORITHMS", "build", "describe_algorithms"]

Options = Mapping[str, Any]  # option texts (str or None); "scene" and "camera" are objects the CLI loaded


def _vector(options: Options, name: str, default: Any, widths: tuple[int, ...] = (3,)) -> np.ndarray:
    text = options.get(name)
    if text is None:
        return np.asarray(default, dtype=float)
    try:
        values = np.array([float(part) for part in text.split(",")])
    except ValueError:
        values = None
    if values is None or values.size not in widths or not np.isfinite(values).all():
        sizes = " or ".join(str(w) for w in widths)
        raise FrustumError(f"frustum steps: --{name.replace('_', '-')} = {text!r} is not {sizes} comma-separated "
                           "finite numbers")  # fmt: skip
    return values


def _points(options: Options, default: Any, widths: tuple[int, ...] = (2, 3)) -> np.ndarray:
    text = options.get("points")
    if text is None:
        return np.asarray(default, dtype=float)
    rows = [_vector({"points": row}, "points", None, widths) for row in text.split(";") if row.strip()]
    if len({row.size for row in rows}) != 1:
        raise FrustumError(f"frustum steps: --points = {text!r} mixes points of different widths")
    return np.array(rows)


def _number(options: Options, name: str, default: float) -> float:
    text = options.get(name)
    if text is None:
        return default
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        raise FrustumError(f"frustum steps: --{name.replace('_', '-')} = {text!r} is not a finite number")
    return value


def _integer(options: Options, name: str, default: int) -> int:
    text = options.get(name)
    if text is None:
        return default
    try:
        return int(text)
    except ValueError:
        raise FrustumError(f"frustum steps: --{name.replace('_', '-')} = {text!r} is not an integer") from None


_SQUARE_CONTROL = ((0.0, 0.0), (1.0, 2.0), (3.0, 2.0), (4.0, 0.0))
_TRIANGLE = ((-1.5, -0.5, 0.0), (1.5, -0.2, 0.3), (0.2, 1.6, -0.2))

ALGORITHMS: dict[str, tuple[str, Callable[[Options], Steps]]] = {
    "rotation": ("rotation about an arbitrary axis, the seven matrices (--axis, --point, --angle-deg)",
                 lambda o: modeling.rotation_about_axis(_vector(o, "axis", (1.0, 1.0, 0.5)),
                                                        math.radians(_number(o, "angle_deg", 60.0)),
                                                        _vector(o, "point", (0.5, 0.0, 0.0)))),
    "viewing-pipeline": ("world → view → projection → normalization → viewport, for a small house",
                         lambda o: viewing.viewing_pipeline()),
    "back-faces": ("back-face detection by the plane equation, face by face",
                   lambda o: visible_surfaces.back_faces()),
    "depth-buffer": ("depth buffer, surface by surface: depth and frame buffers after each (SCENE.toml, --size)",
                     lambda o: visible_surfaces.depth_buffer(o.get("scene"), o.get("camera"))),
    "scan-line": ("scan-line method: the edge table, then per row the active list and the spans (SCENE.toml, --size)",
                  lambda o: visible_surfaces.scan_line(o.get("scene"), o.get("camera"))),
    "warnock": ("area subdivision (Warnock): the quadtree of areas level by level and the test that decided each "
                "(SCENE.toml, --size)",
                lambda o: visible_surfaces.area_subdivision(o.get("scene"), o.get("camera"))),
    "depth-sort": ("depth sort (painter's algorithm): overlap tests 1–4, moves, the split of a cyclic overlap, paints",
                   lambda o: visible_surfaces.depth_sort()),
    "a-buffer": ("A-buffer: one pixel's fragment list with coverage masks, then the resolved color (SCENE.toml, "
                 "--size)", lambda o: visible_surfaces.a_buffer(o.get("scene"), o.get("camera"))),
    "ray-casting": ("ray casting: one pixel's ray through the bounding-volume hierarchy (SCENE.toml, --size)",
                    lambda o: visible_surfaces.ray_casting(o.get("scene"), o.get("camera"))),
    "octree": ("octree method: the subdivision by level, then the front-to-back traversal of a ball's octree",
               lambda o: visible_surfaces.octree()),
    "bsp": ("BSP tree: the splits while building, then the back-to-front order from the eye",
            lambda o: visible_surfaces.bsp_tree()),
    "cohen-sutherland": ("Cohen–Sutherland 3D line clipping: region codes, accept/reject, intersections "
                         "(--from, --to)",
                         lambda o: clipping.cohen_sutherland(_vector(o, "from", (-2.0, 0.5, 0.0), (3, 4)),
                                                             _vector(o, "to", (2.0, 0.3, -3.0), (3, 4)))),
    "liang-barsky": ("Liang–Barsky line clipping: p_k, q_k, u1, u2 per boundary (--from, --to)",
                     lambda o: clipping.liang_barsky(_vector(o, "from", (-2.0, 0.5, 0.0), (3, 4)),
                                                     _vector(o, "to", (2.0, 0.3, -3.0), (3, 4)))),
    "sutherland-hodgman": ("Sutherland–Hodgman polygon clipping, the polygon after each plane (--points)",
                           lambda o: clipping.sutherland_hodgman(_points(o, _TRIANGLE, (3, 4)))),
    "de-casteljau": ("de Casteljau's construction at t and the subdivision (--points, --t)",
                     lambda o: curves.de_casteljau(_points(o, _SQUARE_CONTROL), _number(o, "t", 0.5))),
    "b-spline": ("B-spline basis by Cox–de Boor, level by level, and the knot span of u (--knots, --order, --u)",
                 lambda o: curves.b_spline_basis(_vector(o, "knots", (0, 0, 0, 1, 2, 3, 3, 3), tuple(range(2, 65))),
                                                 _integer(o, "order", 3),
                                                 None if o.get("u") is None else _number(o, "u", 0.0))),
    "hermite": ("Hermite blending functions and the curve point at t (--points P0;P1;R0;R1, --t)",
                lambda o: curves.hermite(*_points(o, ((0.0, 0.0), (3.0, 0.0), (3.0, 3.0), (3.0, -3.0))),
                                         t=_number(o, "t", 0.5))),
    "koch": ("the Koch curve, iteration by iteration (--level)", lambda o: fractals.koch(_integer(o, "level", 4))),
    "midpoint-displacement": ("random midpoint displacement of a segment (--level, --seed)",
                              lambda o: fractals.midpoint_displacement(level=_integer(o, "level", 6),
                                                                       seed=_integer(o, "seed", 1))),
    "box-counting": ("box-counting dimension of a Koch curve: counts per box size and the fit",
                     lambda o: fractals.box_counting()),
}  # fmt: skip
"""name → (one-line description, builder from option texts)."""


def describe_algorithms() -> str:
    """One line per algorithm: its name and what it shows."""
    width = max(len(name) for name in ALGORITHMS)
    return "\n".join(f"{name:<{width}}  {text}" for name, (text, _) in ALGORITHMS.items())


def build(algorithm: str, options: Options) -> Steps:
    """The ``Steps`` of `algorithm` (a name of ``ALGORITHMS``) from option texts; unknown names list the known."""
    entry = ALGORITHMS.get(algorithm)
    if entry is None:
        raise FrustumError(f"frustum steps: algorithm = {algorithm!r} is unknown; expected one of "
                           + ", ".join(ALGORITHMS))  # fmt: skip
    return entry[1](options)
