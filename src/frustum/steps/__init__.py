"""Watch the algorithms of the lecture notes work, step by step (the teaching layer).

Each function takes the same inputs as the production function it records and returns a ``Steps``: a sequence
of ``Step(title, text, values)`` taken from the real computation (a ``record=`` hook of the production
function, or a recording mode of a kernel's Python twin that is tested equal to it), with ``Steps.result``
equal to the production result. ``Steps.figure(i)`` draws step i as SVG; ``Steps.save(path)`` writes ``.svg``,
``.gif``/``.mp4``, ``.html`` (a slider) or ``.md``; in Jupyter a ``Steps`` shows as a slider.

One module per chapter of the notes: ``modeling``, ``viewing``, ``clipping``, ``visible_surfaces``, ``curves``,
``fractals``.
"""

from frustum.steps._record import SAVE_FORMATS, Step, Steps
from frustum.steps.clipping import cohen_sutherland, liang_barsky, sutherland_hodgman
from frustum.steps.curves import b_spline_basis, de_casteljau, hermite
from frustum.steps.fractals import box_counting, koch, midpoint_displacement
from frustum.steps.modeling import rotation_about_axis
from frustum.steps.viewing import viewing_pipeline
from frustum.steps.visible_surfaces import (
    a_buffer,
    area_subdivision,
    back_faces,
    bsp_tree,
    depth_buffer,
    depth_sort,
    octree,
    ray_casting,
    scan_line,
)

__all__ = [
    "SAVE_FORMATS",
    "Step",
    "Steps",
    "a_buffer",
    "area_subdivision",
    "b_spline_basis",
    "back_faces",
    "box_counting",
    "bsp_tree",
    "cohen_sutherland",
    "de_casteljau",
    "depth_buffer",
    "depth_sort",
    "hermite",
    "koch",
    "liang_barsky",
    "midpoint_displacement",
    "octree",
    "ray_casting",
    "rotation_about_axis",
    "scan_line",
    "sutherland_hodgman",
    "viewing_pipeline",
]
