"""Engineering drawing sheets: multiview orthographic projections laid out in first- or third-angle projection.

A multiview drawing shows an object by orthogonal projections along its principal axes, "that show accurate
dimensions": the front, side and rear *elevations* and the *plan* (top) view, here with an isometric view
beside them. The sheet is an SVG whose user unit is one millimetre of paper; model units are millimetres and
a model length L is drawn L × scale long in every orthographic view (an edge parallel to the view plane keeps
its length under an orthogonal projection). Hidden edges are dashed, as engineering drawings use.

Layout (the views stay aligned: the top view shares the front view's x axis, the side views its y axis):

========================  ===========================  ===========================
view                      third angle (ISO E, US)      first angle (ISO, Europe)
========================  ===========================  ===========================
top (plan)                above the front view         below the front view
bottom                    below                        above
right                     right of the front view      left of the front view
left                      left                         right
rear                      far right                    far right
isometric                 upper right (top's row)      lower right (top's row)
========================  ===========================  ===========================

The package: ``model`` (paper, scales, a view, an annotation), ``views`` (cameras, hidden lines and circles per
view), ``dimensions`` (ISO 129-1), ``layout`` (the grid of views), ``title_block`` (ISO 7200, projection symbol,
scale bar), ``svg`` (``drawing_sheet``) and ``dxf`` (the same drawing for CAD).

References
----------
[HB 10] "Orthogonal Projections" (front, side and rear elevations; plan view), "Axonometric and Isometric
Orthogonal Projections"; [seed] "Elevation and Plan View", "engineering and architectural drawings".
"""

from frustum.output.sheet.dimensions import dimension_text
from frustum.output.sheet.model import DIMENSION_MODES, ORIENTATIONS, PAPER_SIZES, SHEET_VIEWS, STANDARD_SCALES
from frustum.output.sheet.svg import drawing_sheet
from frustum.output.sheet.title_block import TITLE_BLOCK_FIELDS, scale_label

__all__ = [
    "DIMENSION_MODES", "ORIENTATIONS", "PAPER_SIZES", "SHEET_VIEWS", "STANDARD_SCALES", "TITLE_BLOCK_FIELDS",
    "dimension_text", "drawing_sheet", "scale_label",
]  # fmt: skip
