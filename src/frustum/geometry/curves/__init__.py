"""Parametric curves: Bézier, piecewise Bézier, Hermite, cardinal/Catmull–Rom, cubic splines, B-splines, NURBS.

Every curve is immutable, lives in 2D or 3D (control points ``(N, 2)`` or ``(N, 3)`` float64, one per row) and
evaluates whole arrays of parameters at once. Parameters outside a curve's domain raise ``GeometryError``
instead of extrapolating silently. ``docs/curves.md`` maps each section of the seed's "Curves and Surfaces"
notes to the functions here.

One module per family: ``bezier`` (Bernstein polynomials, the matrix form, ``BezierCurve``), ``piecewise``
(``PiecewiseBezier`` and the continuity of its joins), ``splines`` (Hermite, cardinal/Catmull–Rom, cubic
interpolating splines), ``bspline`` (B-splines and NURBS); ``_validation`` holds the checks they share.

References
----------
[seed] "Bezier Curves & surfaces", "Piecewise Cubic Bezier Curves", "Recursive Subdivision approach",
"Properties of Bezier Curves", "Cubic-splines Interpolation methods", "Hermite Spline", "B-Spline Curve".
[HB 14] "Spline Representations", "Cubic-Spline Interpolation Methods", "Bézier Spline Curves",
"B-Spline Curves", "Rational Splines".
"""

from frustum.geometry.curves.bezier import M_B, BezierCurve, bernstein, bezier_matrix_form
from frustum.geometry.curves.bspline import BSpline, NURBSCurve, cox_de_boor, open_uniform_knots
from frustum.geometry.curves.piecewise import (
    M_H,
    Continuity,
    CubicSpline,
    HermiteCurve,
    PiecewiseBezier,
    cardinal_spline,
    catmull_rom,
    continuity,
    hermite_blending,
)

__all__ = [
    "M_B",
    "M_H",
    "BSpline",
    "BezierCurve",
    "Continuity",
    "CubicSpline",
    "HermiteCurve",
    "NURBSCurve",
    "PiecewiseBezier",
    "bernstein",
    "bezier_matrix_form",
    "cardinal_spline",
    "catmull_rom",
    "continuity",
    "cox_de_boor",
    "hermite_blending",
    "open_uniform_knots",
]
