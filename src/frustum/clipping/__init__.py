"""Clipping in homogeneous clip space, before the perspective divide: points, lines, polygons, triangle batches.

The view volume is the symmetric cube $−w <= x, y, z <= w$ of clip space (NDC $[−1, 1]³$ before the
divide). Clipping here, not after the divide, is what handles points behind the eye ($w < 0$) correctly: a
segment from in front of the eye to behind it keeps only its visible part and never wraps around through
infinity, because the divide is done only on what survives.

**Planes.** A clip-space plane is a 4-vector ``(a, b, c, d)``; a point ``(x, y, z, w)`` is inside when
$a·x + b·y + c·z + d·w >= 0$ (exact sign test, no tolerance). ``VIEW_VOLUME_PLANES`` holds the cube's six, in
region-code order. User planes (a cutaway) take the same form and are always applied *in addition* to the
cube; ``plane_from_point_normal`` builds one in world space and ``transform_plane`` carries it to clip space.
In clip space the plane's normal is the whole 4-vector (``(0, 0, 0, 1)``, i.e. $w >= 0$, is a real plane), so
only the zero 4-vector is degenerate; for Cartesian points (``clip_line_convex`` with (3,) points) the normal
is ``(a, b, c)`` and must be nonzero.

**Region codes** (the seed's six bits, bit 1 the lowest-order bit, written right to left as in its tables):

====  =====  ==========  ========================
bit   value  name        set when
====  =====  ==========  ========================
1     1      left        $w + x < 0$
2     2      right       $w − x < 0$
3     4      bottom      $w + y < 0$
4     8      top         $w − y < 0$
5     16     near        $w + z < 0$
6     32     far         $w − z < 0$
====  =====  ==========  ========================

The seed's transcription prints these inequalities with x and z swapped ($h + z_n < 0 (left)$, ...,
$h − x_n < 0 (far)$); its own tables decide: ``010000`` is the centre of "in front of near plane" and
``011001`` its top-left corner, so bit 5 is near and bits 1 and 4 are left and top. That is Hearn & Baker's
order, used here.

**Nothing with w <= 0 survives.** The near and far planes together give $2w >= 0$ for every kept point, and
$w = 0$ only at the clip-space origin ``(0, 0, 0, 0)``, which is the image of no point under an invertible
``clip_from_world``. So the divide after clipping is safe without an extra $w > ε$ plane (which would not be
homogeneous); for a point exactly on the near plane the divide gives $z_ndc = −1$.

Why one package: every clipping algorithm of the chapter on the one homogeneous region-code and plane convention.

References are resolved in ``docs/references.md``: [HB 10] is Hearn & Baker chapter 10, "Three-Dimensional
Viewing", which holds 3D clipping; [seed] is the lecture notes.
"""

from frustum.clipping.codes import (
    MAX_KERNEL_PLANES,
    REGION_BOTTOM,
    REGION_FAR,
    REGION_LEFT,
    REGION_NEAR,
    REGION_RIGHT,
    REGION_TOP,
    VIEW_VOLUME_PLANES,
    inside_view_volume,
    plane_from_point_normal,
    region_code,
    transform_plane,
    trivially_accepted,
    trivially_rejected,
)
from frustum.clipping.lines import ClippedLines, ClippedSegment, clip_line, clip_line_convex, clip_lines
from frustum.clipping.polygons import ClippedPolygon, ClippedTriangles, clip_polygon, clip_triangles

__all__ = [
    "MAX_KERNEL_PLANES",
    "REGION_BOTTOM",
    "REGION_FAR",
    "REGION_LEFT",
    "REGION_NEAR",
    "REGION_RIGHT",
    "REGION_TOP",
    "VIEW_VOLUME_PLANES",
    "ClippedLines",
    "ClippedPolygon",
    "ClippedSegment",
    "ClippedTriangles",
    "clip_line",
    "clip_line_convex",
    "clip_lines",
    "clip_polygon",
    "clip_triangles",
    "inside_view_volume",
    "plane_from_point_normal",
    "region_code",
    "transform_plane",
    "trivially_accepted",
    "trivially_rejected",
]
