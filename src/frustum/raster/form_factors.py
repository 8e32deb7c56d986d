"""Point-to-polygon form factors for radiosity (Numba): the exact unoccluded form factor from a differential area to
a triangle, by Lambert's contour formula, after clipping the triangle to the receiver's upper half-space.

$$F_{dA→A} = \\frac{1}{2π} \\Bigl|Σ_k n · \\widehat{a_k × a_{k+1}} \\, ∠(a_k, a_{k+1})\\Bigr|$$

(a_k the polygon's corners relative to the receiving point, n the receiver's unit normal [Baum, Rushmeier &
Winget 1989, eq. 1]). A triangle is seen only from its front side (where its corners run counter-clockwise), and
only its part above the receiver's tangent plane counts (Sutherland–Hodgman clipping against that plane). Occlusion
is not part of these kernels: the caller casts shadow rays (``raster.rays.any_hits``).

Over a connected piece of surface whose every triangle faces the point and lies wholly above its tangent plane, the
terms of an edge shared by two triangles cancel (the term is odd in the edge's direction), so the piece's factor is
the sum over its boundary edges alone (``point_group_factors``): a group of 80 patches costs its ~20 boundary edges.

References
----------
D. R. Baum, H. E. Rushmeier, J. M. Winget, "Improving Radiosity Solutions Through the Use of Analytically
Determined Form-Factors", SIGGRAPH 1989; J. R. Wallace, K. A. Elmquist, E. A. Haines, "A Ray Tracing Algorithm
for Progressive Radiosity", SIGGRAPH 1989.
"""

from __future__ import annotations

import math

import numpy as np

from frustum.raster._jit import kernel, parallel_kernel

__all__ = ["point_group_factors", "point_triangle_factors", "triangle_factor"]


@kernel
def _edge(ax, ay, az, bx, by, bz, nx, ny, nz):
    """One edge's term of Lambert's formula: $n · \\widehat{a × b} · ∠(a, b)$ (0 for an edge through the point)."""
    cx, cy, cz = ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx
    cross = math.sqrt(cx * cx + cy * cy + cz * cz)
    if cross == 0.0:
        return 0.0
    angle = math.atan2(cross, ax * bx + ay * by + az * bz)  # ∠(a, b), accurate for small and large angles alike
    return (nx * cx + ny * cy + nz * cz) / cross * angle


@kernel
def triangle_factor(px, py, pz, nx, ny, nz, tri, corners):
    """F from the differential area at p with unit normal n to the triangle ``tri`` (3, 3): 0 when p lies behind the
    triangle or the triangle lies below p's tangent plane. ``corners`` (4, 3) is scratch space."""
    e1x, e1y, e1z = tri[1, 0] - tri[0, 0], tri[1, 1] - tri[0, 1], tri[1, 2] - tri[0, 2]
    e2x, e2y, e2z = tri[2, 0] - tri[0, 0], tri[2, 1] - tri[0, 1], tri[2, 2] - tri[0, 2]
    mx, my, mz = e1y * e2z - e1z * e2y, e1z * e2x - e1x * e2z, e1x * e2y - e1y * e2x
    if mx * (px - tri[0, 0]) + my * (py - tri[0, 1]) + mz * (pz - tri[0, 2]) <= 0.0:
        return 0.0  # p behind (or in) the triangle's plane: its front does not face p
    # corners relative to p and their heights above p's tangent plane
    count = 0
    for k in range(3):
        j = (k + 1) % 3
        ux, uy, uz = tri[k, 0] - px, tri[k, 1] - py, tri[k, 2] - pz
        vx, vy, vz = tri[j, 0] - px, tri[j, 1] - py, tri[j, 2] - pz
        hu = nx * ux + ny * uy + nz * uz
        hv = nx * vx + ny * vy + nz * vz
        if hu >= 0.0:
            corners[count, 0], corners[count, 1], corners[count, 2] = ux, uy, uz
            count += 1
        if (hu >= 0.0) != (hv >= 0.0):  # the edge crosses the plane: keep the crossing point
            s = hu / (hu - hv)
            corners[count, 0] = ux + s * (vx - ux)
            corners[count, 1] = uy + s * (vy - uy)
            corners[count, 2] = uz + s * (vz - uz)
            count += 1
    if count < 3:
        return 0.0
    total = 0.0
    for k in range(count):
        j = (k + 1) % count
        total += _edge(corners[k, 0], corners[k, 1], corners[k, 2], corners[j, 0], corners[j, 1], corners[j, 2],
                       nx, ny, nz)  # fmt: skip
    return abs(total) / (2.0 * math.pi)


@parallel_kernel(lambda points, *_: points.shape[0], grain=16)
def point_triangle_factors(points, normals, triangles, subset, out, start, stop):
    """``out[i, subset[t]] += F(points[i], normals[i] → triangles[t])`` for receivers i in [start, stop): the
    unoccluded form factors from each receiving point to the triangles (T, 3, 3), summed per subset (out (N, S))."""
    corners = np.empty((4, 3))
    for i in range(start, stop):
        px, py, pz = points[i, 0], points[i, 1], points[i, 2]
        nx, ny, nz = normals[i, 0], normals[i, 1], normals[i, 2]
        for t in range(triangles.shape[0]):
            out[i, subset[t]] += triangle_factor(px, py, pz, nx, ny, nz, triangles[t], corners)


@parallel_kernel(lambda points, *_: points.shape[0], grain=16)
def point_group_factors(points, normals, triangles, facing, first, edges, edge_first, planes, out, start, stop):
    """``out[i, q]`` = F from the differential area at points[i] (unit normal normals[i]) to piece q of a group, for
    receivers i in [start, stop). Piece q is triangles ``[first[q], first[q + 1])`` (T, 3, 3) with (unnormalized)
    normals ``facing`` (T, 3), and its boundary edges ``[edge_first[q], edge_first[q + 1])`` of ``edges`` (E, 2, 3),
    each running as in its triangle; ``planes[q]`` = (m, d) with the piece on the plane m·x = d when it is flat,
    NaN otherwise. A piece that faces the point and lies above its plane throughout takes the boundary sum (a flat
    piece is tested at its boundary's corners alone); any other is summed triangle by triangle
    (``triangle_factor``)."""
    corners = np.empty((4, 3))
    pieces = first.shape[0] - 1
    for i in range(start, stop):
        px, py, pz = points[i, 0], points[i, 1], points[i, 2]
        nx, ny, nz = normals[i, 0], normals[i, 1], normals[i, 2]
        for q in range(pieces):
            whole = True
            if planes[q, 3] == planes[q, 3]:  # flat: one facing test, heights at the boundary's corners
                if planes[q, 0] * px + planes[q, 1] * py + planes[q, 2] * pz <= planes[q, 3]:
                    whole = False
                else:
                    for e in range(edge_first[q], edge_first[q + 1]):
                        if nx * (edges[e, 0, 0] - px) + ny * (edges[e, 0, 1] - py) + nz * (edges[e, 0, 2] - pz) < 0.0:
                            whole = False
                            break
            else:
                for t in range(first[q], first[q + 1]):
                    if facing[t, 0] * (px - triangles[t, 0, 0]) + facing[t, 1] * (py - triangles[t, 0, 1]) \
                            + facing[t, 2] * (pz - triangles[t, 0, 2]) <= 0.0:  # fmt: skip
                        whole = False
                        break
                    for k in range(3):
                        if nx * (triangles[t, k, 0] - px) + ny * (triangles[t, k, 1] - py) \
                                + nz * (triangles[t, k, 2] - pz) < 0.0:  # fmt: skip
                            whole = False
                    if not whole:
                        break
            if whole:
                total = 0.0
                for e in range(edge_first[q], edge_first[q + 1]):
                    total += _edge(edges[e, 0, 0] - px, edges[e, 0, 1] - py, edges[e, 0, 2] - pz, edges[e, 1, 0] - px,
                                   edges[e, 1, 1] - py, edges[e, 1, 2] - pz, nx, ny, nz)  # fmt: skip
                out[i, q] = abs(total) / (2.0 * math.pi)
            elif planes[q, 3] == planes[q, 3] and planes[q, 0] * px + planes[q, 1] * py + planes[q, 2] * pz \
                    <= planes[q, 3]:  # fmt: skip
                out[i, q] = 0.0  # behind a flat piece
            else:
                total = 0.0
                for t in range(first[q], first[q + 1]):
                    total += triangle_factor(px, py, pz, nx, ny, nz, triangles[t], corners)
                out[i, q] = total
