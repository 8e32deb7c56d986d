"""Modeling transformations, step by step: the seven matrices of a rotation about an arbitrary axis.

References: [HB 9] "General Three-Dimensional Rotations"; [seed] "Rotation about an arbitrary axis".
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from frustum._arrays import as_points
from frustum.errors import TransformError
from frustum.steps._draw import bounds_of, oblique
from frustum.steps._record import Step, Steps, _Canvas
from frustum.transforms import apply, compose, rotate_steps

__all__ = ["HOUSE_EDGES", "HOUSE_POINTS", "rotation_about_axis"]

# a small house (the textbooks' favourite object): a unit cube with a roof ridge, and its edges
HOUSE_POINTS = np.array(
    [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1], [0.5, 1.5, 0],
     [0.5, 1.5, 1]], dtype=float,
)  # fmt: skip
HOUSE_EDGES = [(0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4), (0, 4), (1, 5), (2, 6), (3, 7),
               (2, 8), (3, 8), (6, 9), (7, 9), (8, 9)]  # fmt: skip

_TEXTS = (
    "T(−P1): translate so that the axis passes through the origin (P1, the given point on the axis, moves to "
    "the origin).",
    "Rx(α): rotate about x so that the axis lies in the xz plane; cos α = c/d, sin α = b/d with d = √(b² + c²) "
    "for the unit axis u = (a, b, c).",
    "Ry(β): rotate about y so that the axis lies along z; cos β = d, sin β = −a.",
    "Rz(θ): the rotation itself, by θ about the z axis (now the rotation axis).",
    "Ry⁻¹(β): undo the y rotation.",
    "Rx⁻¹(α): undo the x rotation.",
    "T(P1): translate back; the composite R(θ) = T⁻¹·Rx⁻¹(α)·Ry⁻¹(β)·Rz(θ)·Ry(β)·Rx(α)·T.",
)


def rotation_about_axis(
    axis: ArrayLike, angle: float, point: ArrayLike = (0.0, 0.0, 0.0), points: ArrayLike | None = None
) -> Steps:
    """The seven steps of a rotation by `angle` radians about the axis through `point` along `axis`.

    The matrices are ``frustum.rotate_steps(axis, angle, point)`` (the production decomposition); each step
    shows the object (`points`, default a small house) after the product of the steps so far. ``result`` is
    ``compose(*matrices)``, which equals ``rotate(axis, angle, point)`` up to round-off.
    """
    where = "steps.rotation_about_axis"
    matrices = [step.matrix for step in rotate_steps(axis, angle, point)]
    names = [step.name for step in rotate_steps(axis, angle, point)]
    if points is None:
        object_points, edges = HOUSE_POINTS, HOUSE_EDGES
    else:
        object_points = as_points(points, "points", where=where, error=TransformError)
        edges = [(i, i + 1) for i in range(len(object_points) - 1)]
    result = compose(*matrices)
    axis_unit = np.asarray(axis, dtype=float) / np.linalg.norm(np.asarray(axis, dtype=float))
    start = np.asarray(point, dtype=float)
    axis_line = np.array([start - 1.5 * axis_unit, start + 1.5 * axis_unit])
    shapes = [(object_points, axis_line)]
    steps = [Step(
        "The object and the rotation axis",
        "Rotate by θ about the line through P1 along the unit vector u = (a, b, c): move the axis onto a "
        "coordinate axis, rotate there, and move it back (seven matrices, first applied first).",
        {"u": axis_unit, "P1": start, "theta (deg)": math.degrees(float(angle))},
    )]  # fmt: skip
    so_far = np.eye(4)
    for k, (matrix, name) in enumerate(zip(matrices, names, strict=True)):
        so_far = matrix @ so_far
        shapes.append((apply(so_far, object_points), apply(so_far, axis_line)))
        steps.append(Step(f"Step {k + 1}: {name}", _TEXTS[k], {"matrix": np.round(matrix, 4)}))
    steps.append(Step(
        "The composite matrix",
        "The product of the seven, first applied rightmost, is the rotation about the arbitrary axis.",
        {"R": np.round(result, 4)},
    ))  # fmt: skip
    shapes.append((apply(result, object_points), apply(result, axis_line)))
    everything = np.vstack([np.vstack(s) for s in shapes] + [np.eye(3) * 1.2, np.zeros((1, 3))])

    def paint(index: int, canvas: _Canvas) -> None:
        origin = oblique(np.zeros(3))[0]
        for j, name in enumerate("xyz"):
            tip = oblique(np.eye(3)[j] * 1.2)[0]
            canvas.line(origin, tip, color="faint")
            canvas.label(tip, name, color="faint")
        drawn, line = shapes[index]
        if index > 0:
            for a, b in edges:
                canvas.line(*oblique(object_points[[a, b]]), color="faint", dash=True, width=1.0)
        projected = oblique(drawn)
        for a, b in edges:
            canvas.line(projected[a], projected[b], color="blue", width=2.0)
        ends = oblique(line)
        canvas.line(ends[0], ends[1], color="highlight", width=2.0)
        canvas.label(ends[1], "axis", color="highlight")

    return Steps("Rotation about an arbitrary axis", steps, result, paint, bounds_of(oblique(everything)))
