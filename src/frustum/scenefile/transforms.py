"""A node's ``transform``: a list of named steps (``TRANSFORM_STEPS``) composed first to last."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from frustum.quaternion import Quaternion
from frustum.scenefile.checks import _choice, _is_number, _number, _unknown_keys, _vector
from frustum.scenefile.report import _BAD, _bad, _Report
from frustum.transforms import compose, reflect, rotate, rotate_x, rotate_y, rotate_z, scale, shear, translate

TRANSFORM_STEPS = (
    "translate", "rotate_x_deg", "rotate_y_deg", "rotate_z_deg", "rotate_deg", "scale", "reflect", "shear",
    "quaternion", "matrix",
)  # fmt: skip
"""The named steps a node's ``transform`` list may hold (each step is a table with one of these keys)."""


_STEP_MODIFIERS = {
    "translate": (),
    "rotate_x_deg": (),
    "rotate_y_deg": (),
    "rotate_z_deg": (),
    "rotate_deg": ("axis", "point"),
    "scale": ("fixed",),
    "reflect": ("point",),
    "shear": ("a", "b", "ref"),
    "quaternion": (),
    "matrix": (),
}


def _transform(report: _Report, path: tuple, value: Any) -> Any:
    """A list of named steps → ``compose(*steps)`` (first listed, first applied)."""
    if not isinstance(value, list):
        report.add(path, value, "is not a list of steps", "write transform = [{ translate = [x, y, z] }, ...]")
        return _BAD
    matrices = []
    for index, step in enumerate(value):
        where = (*path, index)
        if not isinstance(step, Mapping):
            report.add(where, step, "is not a step table", f"write {{ name = value }} with name one of "
                       f"{', '.join(TRANSFORM_STEPS)}")  # fmt: skip
            continue
        names = [key for key in step if key in _STEP_MODIFIERS]
        if not names:
            _unknown_keys(report, where, step, TRANSFORM_STEPS)
            if step:
                continue
        if len(names) != 1:
            report.add(where, dict(step), f"names {len(names)} operations",
                       f"give exactly one of {', '.join(TRANSFORM_STEPS)} per step")  # fmt: skip
            continue
        name = names[0]
        allowed = (name, *_STEP_MODIFIERS[name])
        _unknown_keys(report, where, step, allowed)
        if any(key not in allowed for key in step):
            continue
        matrix = _step_matrix(report, where, name, step)
        if matrix is not _BAD:
            matrices.append(matrix)
    if len(matrices) != len(value):
        return _BAD
    return compose(*matrices) if matrices else np.eye(4)


def _step_matrix(report: _Report, where: tuple, name: str, step: Mapping) -> Any:
    value = step[name]
    at = (*where, name)
    if name == "translate":
        v = _vector(report, at, value)
        return _BAD if v is _BAD else translate(*v)
    if name in ("rotate_x_deg", "rotate_y_deg", "rotate_z_deg"):
        angle = _number(report, at, value)
        builder = {"rotate_x_deg": rotate_x, "rotate_y_deg": rotate_y, "rotate_z_deg": rotate_z}[name]
        return _BAD if angle is _BAD else builder(math.radians(angle))
    if name == "rotate_deg":
        angle = _number(report, at, value)
        if "axis" not in step:
            report.missing((*where, "axis"), "rotate_deg needs axis = [ax, ay, az] (and optionally point)")
            return _BAD
        axis = _vector(report, (*where, "axis"), step["axis"], what="ax, ay, az")
        point = _vector(report, (*where, "point"), step.get("point", [0.0, 0.0, 0.0]))
        if _bad(angle, axis, point):
            return _BAD
        if not any(axis):
            report.add((*where, "axis"), axis, "has zero length", "give a nonzero rotation axis")
            return _BAD
        return rotate(axis, math.radians(angle), point)
    if name == "scale":
        if _is_number(value):
            factors = _number(report, at, value)
            factors = _BAD if factors is _BAD else [factors] * 3
        else:
            factors = _vector(report, at, value, what="sx, sy, sz")
        fixed = _vector(report, (*where, "fixed"), step.get("fixed", [0.0, 0.0, 0.0]))
        if _bad(factors, fixed):
            return _BAD
        if 0.0 in factors:
            report.add(at, value, "has a zero factor", "give nonzero scale factors (a zero flattens the object)")
            return _BAD
        return scale(*factors, fixed=fixed)
    if name == "reflect":
        point = _vector(report, (*where, "point"), step.get("point", [0.0, 0.0, 0.0]))
        if isinstance(value, str):
            normal = _choice(report, at, value, ("xy", "yz", "zx", "xz"))
        else:
            normal = _vector(report, at, value, what="nx, ny, nz")
            if normal is not _BAD and not any(normal):
                report.add(at, value, "has zero length", "give a nonzero plane normal or 'xy', 'yz', 'zx'")
                normal = _BAD
        return _BAD if _bad(normal, point) else reflect(normal, point)
    if name == "shear":
        axis = _choice(report, at, value, ("x", "y", "z"))
        numbers = [_number(report, (*where, key), step.get(key, 0.0)) for key in ("a", "b", "ref")]
        return _BAD if axis is _BAD or _bad(*numbers) else shear(axis, *numbers)
    if name == "quaternion":
        q = _vector(report, at, value, 4, "w, x, y, z")
        if q is not _BAD and not any(q):
            report.add(at, value, "is the zero quaternion", "give [w, x, y, z] with a nonzero norm (a rotation)")
            return _BAD
        return _BAD if q is _BAD else Quaternion(*q).to_matrix()
    rows = value if isinstance(value, list) and len(value) == 4 else None
    checked = [_vector(report, (*at, i), row, 4, "m0, m1, m2, m3") for i, row in enumerate(rows or [])]
    if rows is None:
        report.add(at, value, "is not 4 rows", "give a 4x4 matrix as four rows of four numbers")
        return _BAD
    if _bad(*checked):
        return _BAD
    matrix = np.array(checked)
    if not np.array_equal(matrix[3], [0.0, 0.0, 0.0, 1.0]):
        report.add(at, value, "is not affine", "a modeling matrix has the bottom row [0, 0, 0, 1]")
        return _BAD
    return matrix
