"""The indexed triangle mesh: vertices, faces, per-vertex normals, UVs and colors in model coordinates.

A ``Mesh`` is frozen: its arrays are read-only, derived data (face normals, bounds, centroid, edges, area,
volume, watertightness) is computed once on first use and cached, and every operation (``transformed``,
``merged``, ``welded``, ``flipped``, ...) returns a new mesh. The seed's constructors for connected meshes
(triangle strips and fans, the n × m quadrilateral grid) and for polygon lists live here as class methods.

References
----------
[seed] "Polygon Meshes", "Triangular Mesh", "Quadrilateral Mesh".
[HB 4] "OpenGL Polygon Fill-Area Functions" (GL_TRIANGLE_STRIP, GL_TRIANGLE_FAN, GL_QUAD_STRIP).
[HB 13] "Polyhedra".
"""

from __future__ import annotations

from dataclasses import InitVar, dataclass
from functools import cached_property
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import Points, as_faces, as_matrix, as_points, as_scalar, describe, is_numeric, read_only
from frustum.errors import GeometryError
from frustum.transforms import apply, apply_to_normals, swaps_handedness

if TYPE_CHECKING:
    from collections.abc import Sequence

__all__ = ["Mesh"]


@dataclass(frozen=True, eq=False, repr=False)
class Mesh:
    """An indexed triangle mesh: ``vertices`` (N, 3), ``faces`` (M, 3), unit ``vertex_normals`` (N, 3).

    Faces list vertex indices **counter-clockwise seen from the front** (the side the normals point to), so
    the face normal is $(v1 − v0) × (v2 − v0)$. Without given normals, each vertex normal is the
    area-weighted average of the normals of the faces around it: the sum of the unnormalized cross products
    $(v1 − v0) × (v2 − v0)$ (whose length is twice the face area), normalized. A vertex that no face uses, or
    whose faces cancel, gets the normal (0, 0, 1), so shading stays finite.

    Parameters
    ----------
    vertices : (N, 3) array_like
        Finite model coordinates, stored float64, or float32 when given as a float32 array (mesh files, GPU-style
        buffers: kept as given, half the memory; everything computed from them is float64, float32 → float64
        being exact). Other inputs are never narrowed.
    faces : (M, 3) array_like of int
        Vertex indices in [0, N), stored int32 (N <= 2**31: every index fits; code that combines indices, such as
        an edge key $i·N + j$, widens to int64 first). An empty mesh (M = 0) is valid.
    vertex_normals : (N, 3) array_like, optional
        Finite, nonzero per-vertex normals; normalized on construction (in float64; a float32 array is stored
        float32 again, the nearest float32 of the unit vector). Computed normals are float64.
    uvs : (N, 2) array_like, optional
        Finite texture coordinates (u, v) per vertex, v up (OpenGL/OBJ convention: (0, 0) is the image's
        bottom-left corner). Values outside [0, 1] are allowed (textures repeat).
    vertex_colors : (N, 3) or (N, 4) array_like, optional
        RGB or RGBA per vertex, floats in [0, 1]; a uint8 array is divided by 255. Stored float64.
    copy : bool, keyword
        True (default): the mesh stores copies, so later changes to the caller's arrays do not reach it. False:
        a `vertices` array that is already C-contiguous float32 or float64, and a `faces` array already
        C-contiguous int32, are validated and kept, not copied (the mesh holds read-only views of them), the way
        a GPU driver takes a buffer: for meshes of millions of triangles (the 10⁷-triangle benchmark scene: 180 MiB
        less). The caller must not change them afterwards (the mesh's cached normals and areas would not follow).
        Normals, UVs and colors are copied either way.

    Raises
    ------
    GeometryError
        Wrong shapes, non-finite coordinates, indices out of range, zero-length normals, colors outside [0, 1].

    The arrays are read-only; operations return new meshes.
    """

    vertices: Points
    faces: NDArray[np.int32]
    vertex_normals: Points | None = None
    uvs: NDArray[np.float64] | None = None
    vertex_colors: NDArray[np.float64] | None = None
    copy: InitVar[bool] = True

    def __post_init__(self, copy: bool) -> None:
        where = "Mesh"
        share = not copy
        vertices = as_points(self.vertices, "vertices", where=where, keep_float32=True, share=share)
        faces = as_faces(self.faces, vertices.shape[0], "faces", where=where, compact=True, share=share)
        object.__setattr__(self, "vertices", read_only(vertices))
        object.__setattr__(self, "faces", read_only(faces))
        if self.vertex_normals is None:
            normals = _area_weighted_normals(vertices, faces)
        else:
            normals = as_points(self.vertex_normals, "vertex_normals", where=where, keep_float32=True)
            _check_rows(normals, vertices.shape[0], "vertex_normals", where)
            _normalize_rows(normals, where)
        object.__setattr__(self, "vertex_normals", read_only(np.ascontiguousarray(normals)))
        if self.uvs is not None:
            object.__setattr__(self, "uvs", read_only(_as_uvs(self.uvs, vertices.shape[0], where)))
        if self.vertex_colors is not None:
            colors = _as_vertex_colors(self.vertex_colors, vertices.shape[0], where)
            object.__setattr__(self, "vertex_colors", read_only(colors))

    def __repr__(self) -> str:
        extras = "".join(
            f", {name}=({len(value)}, {value.shape[1]})"
            for name, value in (("uvs", self.uvs), ("vertex_colors", self.vertex_colors))
            if value is not None
        )
        return f"Mesh(vertex_count={self.vertex_count}, face_count={self.face_count}{extras})"

    # --- counts and cached derived data -------------------------------------------------------------------

    @property
    def vertex_count(self) -> int:
        """N, the number of vertices."""
        return int(self.vertices.shape[0])

    @property
    def face_count(self) -> int:
        """M, the number of triangles."""
        return int(self.faces.shape[0])

    @cached_property
    def face_normals(self) -> Points:
        """(M, 3) unit face normals $(v1 − v0) × (v2 − v0)$ normalized; (0, 0, 0) for a zero-area face."""
        cross = _face_cross_products(self.vertices, self.faces)
        lengths = np.sqrt((cross * cross).sum(axis=1))
        with np.errstate(invalid="ignore", divide="ignore"):
            normals = np.where(lengths[:, None] > 0.0, cross / lengths[:, None], 0.0)
        return read_only(normals)

    @cached_property
    def face_areas(self) -> NDArray[np.float64]:
        """(M,) triangle areas $A = ½ |(v1 − v0) × (v2 − v0)|$."""
        cross = _face_cross_products(self.vertices, self.faces)
        return read_only(0.5 * np.sqrt((cross * cross).sum(axis=1)))

    @cached_property
    def bounds(self) -> Points:
        """(2, 3): the minimum and maximum corner of the axis-aligned bounding box (NaN for no vertices)."""
        if self.vertex_count == 0:
            return read_only(np.full((2, 3), np.nan))
        return read_only(np.stack([self.vertices.min(axis=0), self.vertices.max(axis=0)]).astype(np.float64))

    @cached_property
    def area(self) -> float:
        """Total surface area, the sum of the triangle areas $½ |(v1 − v0) × (v2 − v0)|$ (0 for no faces)."""
        return float(self.face_areas.sum())

    @cached_property
    def centroid(self) -> NDArray[np.float64]:
        """(3,) area-weighted centroid of the surface: $Σ A_f·(v0 + v1 + v2)/3 / Σ A_f$.

        This is the centre of a thin shell of uniform density (trimesh's ``centroid``); it does not move when a
        region is tessellated more finely. A mesh whose faces all have zero area falls back to the mean of the
        vertices the faces use, then to the mean of all vertices; a mesh without vertices gives (nan, nan, nan).
        """
        if self.vertex_count == 0:
            return read_only(np.full(3, np.nan))
        areas = self.face_areas
        total = areas.sum()
        if total > 0.0:
            centers = _float64(self.vertices[self.faces]).mean(axis=1)
            return read_only((areas @ centers) / total)
        used = np.unique(self.faces) if self.face_count else np.arange(self.vertex_count)
        return read_only(_float64(self.vertices[used]).mean(axis=0))

    @cached_property
    def edges(self) -> NDArray[np.int64]:
        """(E, 2) the unique undirected edges, each row ``(i, j)`` with $i < j$, sorted lexicographically."""
        pairs = np.sort(_directed_edges(self.faces), axis=1).astype(np.int64)  # int32 faces: i·n + j needs int64
        n = max(self.vertex_count, 1)
        keys = np.sort(pairs[:, 0] * n + pairs[:, 1])  # one int64 key per edge; sort + diff beats np.unique
        keys = keys[np.r_[True, keys[1:] != keys[:-1]]] if keys.size else keys
        return read_only(np.ascontiguousarray(np.stack([keys // n, keys % n], axis=1)))

    @cached_property
    def is_watertight(self) -> bool:
        """True when the surface is closed and consistently oriented (so it bounds a volume).

        Vertices at the same position count as one (meshes split vertices at UV or normal seams); then every
        directed edge ``(a, b)`` of a face must be matched by exactly one opposite edge ``(b, a)`` of another face,
        and no directed edge may repeat. An empty mesh is not watertight. Degenerate (zero-area) faces take part.
        """
        if self.face_count == 0:
            return False
        directed = _position_ids(self.vertices)[_directed_edges(self.faces)]  # int64 ids: the keys below fit
        if (directed[:, 0] == directed[:, 1]).any():
            return False
        n = self.vertex_count
        keys = np.sort(directed[:, 0] * n + directed[:, 1])
        if (keys[1:] == keys[:-1]).any():  # a directed edge used twice: inconsistent winding or non-manifold
            return False
        opposite = directed[:, 1] * n + directed[:, 0]
        found = np.searchsorted(keys, opposite)
        return bool((keys[np.minimum(found, keys.size - 1)] == opposite).all())

    @cached_property
    def volume(self) -> float:
        """Signed enclosed volume by the divergence theorem: $V = Σ_f v0 · (v1 × v2) / 6$.

        Positive when the faces wind counter-clockwise seen from outside (outward normals), negative when they
        all point inward. The sum is independent of the origin only for a closed surface.

        Raises
        ------
        GeometryError
            If the mesh is not watertight (see ``is_watertight``): an open surface encloses no volume. An
            empty mesh (no faces, e.g. a disjoint CSG intersection) encloses volume 0.
        """
        if self.face_count == 0:
            return 0.0
        if not self.is_watertight:
            raise GeometryError(
                f"Mesh.volume: mesh with {self.face_count} faces is not watertight (open or inconsistently "
                "wound); volume is defined only for closed, consistently oriented meshes (weld seams first)"
            )
        v = _float64(self.vertices[self.faces])
        # subtract a point on the mesh first: same result for a closed surface, less cancellation far from 0
        v = v - _float64(self.vertices[self.faces[0, 0]])
        return float(np.einsum("ij,ij->i", v[:, 0], np.cross(v[:, 1], v[:, 2])).sum() / 6.0)

    # --- operations returning new meshes ------------------------------------------------------------------

    def transformed(self, matrix: ArrayLike) -> Mesh:
        """The mesh with $P' = M·P$ applied to its vertices and $n' = (A⁻¹)ᵀ·n$ to its normals.

        When `matrix` swaps handedness ($det < 0$: a reflection or an odd number of negative scales), the
        winding of every face is reversed, so faces stay counter-clockwise seen from the (mirrored) outside
        and a closed mesh keeps a positive volume. UVs and colors are carried over.

        Raises
        ------
        TransformError
            If `matrix` is not a finite (4, 4) affine matrix with an invertible 3x3 block.
        """
        m = as_matrix(matrix, where="Mesh.transformed")
        vertices = apply(m, self.vertices) if self.vertex_count else self.vertices.copy()
        normals = apply_to_normals(m, self.vertex_normals) if self.vertex_count else self.vertex_normals.copy()
        faces = self.faces[:, ::-1] if swaps_handedness(m) else self.faces
        return Mesh(vertices, np.ascontiguousarray(faces), normals, self.uvs, self.vertex_colors)

    def merged(self, *others: Mesh) -> Mesh:
        """One mesh holding this one and `others`, faces re-indexed (``Mesh.merged(a, b, c)`` also works).

        UVs are kept when every part has them. Colors are kept when any part has them: RGB becomes RGBA when
        some part is RGBA, and parts without colors get opaque white.
        """
        meshes = (self, *others)
        for i, mesh in enumerate(meshes):
            if not isinstance(mesh, Mesh):
                raise GeometryError(f"Mesh.merged: meshes[{i}] = {describe(mesh)} is not a Mesh; give Mesh objects")
        offsets = np.cumsum([0] + [m.vertex_count for m in meshes[:-1]])
        vertices = np.concatenate([m.vertices for m in meshes])
        faces = np.concatenate([m.faces + offset for m, offset in zip(meshes, offsets, strict=True)])
        normals = np.concatenate([m.vertex_normals for m in meshes])
        uvs = np.concatenate([m.uvs for m in meshes]) if all(m.uvs is not None for m in meshes) else None
        colors = None
        if any(m.vertex_colors is not None for m in meshes):
            width = max(m.vertex_colors.shape[1] for m in meshes if m.vertex_colors is not None)
            colors = np.concatenate([_color_block(m, width) for m in meshes])
        return Mesh(vertices, faces.reshape(-1, 3), normals, uvs, colors)

    def flipped(self) -> Mesh:
        """The mesh seen from the other side: every face's winding reversed and every normal negated."""
        return Mesh(
            self.vertices, np.ascontiguousarray(self.faces[:, ::-1]), -self.vertex_normals, self.uvs, self.vertex_colors
        )

    def without_degenerate_faces(self, area_tolerance: float = 0.0) -> Mesh:
        """The mesh without faces of area ``<= area_tolerance`` (repeated indices, collinear corners).

        Vertices are kept unchanged (indices stay valid), including any that no face uses any more.
        """
        tolerance = as_scalar(
            area_tolerance, "area_tolerance", where="Mesh.without_degenerate_faces", error=GeometryError
        )
        if tolerance < 0.0:
            raise GeometryError(
                f"Mesh.without_degenerate_faces: area_tolerance = {tolerance!r} is negative; give a value >= 0"
            )
        f = self.faces
        repeated = (f[:, 0] == f[:, 1]) | (f[:, 1] == f[:, 2]) | (f[:, 0] == f[:, 2])
        keep = ~repeated & (self.face_areas > tolerance)
        return Mesh(self.vertices, f[keep], self.vertex_normals, self.uvs, self.vertex_colors)

    def welded(self, tolerance: float = 0.0) -> Mesh:
        """Vertices closer than `tolerance` (transitively) merged into one; faces that collapse are dropped.

        Each group of merged vertices keeps the position, UV and color of its lowest-index member, and groups
        are numbered in order of that member, so the result is deterministic. Vertex normals are recomputed
        (area-weighted) on the welded mesh: welding joins the surface across seams, so shading becomes smooth
        there. $tolerance = 0$ merges only exactly coincident vertices.
        """
        where = "Mesh.welded"
        tol = as_scalar(tolerance, "tolerance", where=where, error=GeometryError)
        if tol < 0.0:
            raise GeometryError(f"{where}: tolerance = {tol!r} is negative; give a distance >= 0")
        n = self.vertex_count
        if n == 0:
            return self
        if tol == 0.0:
            label = _position_ids(self.vertices)
        else:
            from scipy.sparse import coo_matrix
            from scipy.sparse.csgraph import connected_components
            from scipy.spatial import cKDTree

            pairs = cKDTree(self.vertices).query_pairs(tol, output_type="ndarray")
            graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
            _, label = connected_components(graph, directed=False)
        # representative = lowest index of each group; new ids in order of representatives
        representative = np.full(label.max() + 1, n, dtype=np.int64)
        np.minimum.at(representative, label, np.arange(n))
        order = np.argsort(representative, kind="stable")
        new_id = np.empty_like(order)
        new_id[order] = np.arange(order.size)
        keep = representative[order]
        faces = new_id[label][self.faces]
        f = faces
        faces = faces[(f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 0] != f[:, 2])]
        return Mesh(
            self.vertices[keep],
            faces.reshape(-1, 3),
            None,
            None if self.uvs is None else self.uvs[keep],
            None if self.vertex_colors is None else self.vertex_colors[keep],
        )

    def save(self, path: str | Path) -> Path:
        """Write the mesh to `path`; the suffix picks the format (see ``frustum.geometry.io.save``)."""
        from frustum.geometry.mesh_writer import write_mesh  # (trimesh and PIL load only when a mesh is written)

        return write_mesh(self, path)

    # --- constructors -------------------------------------------------------------------------------------

    @classmethod
    def from_triangle_strip(cls, vertices: ArrayLike) -> Mesh:
        """A triangle strip: n vertices give the n − 2 connected triangles ``(v_k, v_k+1, v_k+2)``.

        Every second triangle is listed as ``(v_k+1, v_k, v_k+2)`` so all triangles share the winding of the
        first (as OpenGL's ``GL_TRIANGLE_STRIP`` does): the strip's front is the side from which its first
        triangle is counter-clockwise.

        References
        ----------
        [seed] "Triangular Mesh" ("for n vertices, there are n − 2 connected triangles").
        [HB 4] "OpenGL Polygon Fill-Area Functions".
        """
        points = _at_least(vertices, 3, "Mesh.from_triangle_strip")
        k = np.arange(points.shape[0] - 2)
        faces = np.stack([k, k + 1, k + 2], axis=1)
        odd = k % 2 == 1
        faces[odd, 0], faces[odd, 1] = k[odd] + 1, k[odd]
        return cls(points, faces)

    @classmethod
    def from_triangle_fan(cls, vertices: ArrayLike) -> Mesh:
        """A triangle fan around the first vertex: n vertices give the n − 2 triangles ``(v_0, v_k, v_k+1)``.

        References
        ----------
        [HB 4] "OpenGL Polygon Fill-Area Functions" (``GL_TRIANGLE_FAN``).
        """
        points = _at_least(vertices, 3, "Mesh.from_triangle_fan")
        k = np.arange(1, points.shape[0] - 1)
        return cls(points, np.stack([np.zeros_like(k), k, k + 1], axis=1))

    @classmethod
    def from_grid(cls, points: ArrayLike, uvs: ArrayLike | None = None) -> Mesh:
        """A quadrilateral mesh: an (n, m) grid of points gives (n − 1)(m − 1) quads, two triangles each.

        Quad ``(i, j)`` has corners ``P[i, j], P[i+1, j], P[i+1, j+1], P[i, j+1]`` and is split into the
        triangles ``(P[i,j], P[i+1,j], P[i+1,j+1])`` and ``(P[i,j], P[i+1,j+1], P[i,j+1])``, so the front side is
        the one where $∂P/∂i × ∂P/∂j$ points.

        Parameters
        ----------
        points : (n, m, 3) array_like
            n, m >= 2.
        uvs : (n, m, 2) array_like, optional
            Texture coordinates per grid point.

        References
        ----------
        [seed] "Quadrilateral Mesh" ("for n by m array of vertices, (n − 1) by (m − 1) quadrilaterals").
        """
        where = "Mesh.from_grid"
        grid = np.asarray(points, dtype=np.float64) if is_numeric(points) else None
        if grid is None or grid.ndim != 3 or grid.shape[2] != 3:
            shape = None if grid is None else grid.shape
            raise GeometryError(f"{where}: points has shape {shape}; expected an (n, m, 3) grid of points")
        n, m = grid.shape[:2]
        if n < 2 or m < 2:
            raise GeometryError(f"{where}: points has shape {grid.shape}; a grid needs n >= 2 rows and m >= 2 columns")
        flat_uvs = None
        if uvs is not None:
            uv = np.asarray(uvs, dtype=np.float64) if is_numeric(uvs) else None
            if uv is None or uv.shape != (n, m, 2):
                shape = None if uv is None else uv.shape
                raise GeometryError(f"{where}: uvs has shape {shape}; expected ({n}, {m}, 2), one (u, v) per point")
            flat_uvs = uv.reshape(-1, 2)
        return cls(grid.reshape(-1, 3), _grid_faces(n, m), None, flat_uvs)

    @classmethod
    def from_polygons(cls, vertices: ArrayLike, polygons: ArrayLike | Sequence[Sequence[int]]) -> Mesh:
        """Triangulate polygons (quads, or a ragged list of k-gons) into a triangle mesh.

        Each polygon $(p_0, …, p_k−1)$ becomes the fan ``(p_0, p_i, p_i+1)``, i = 1 … k − 2, which keeps its
        winding and is exact for convex polygons (and any polygon star-shaped from its first vertex); k − 2
        triangles per polygon.

        Parameters
        ----------
        vertices : (N, 3) array_like
        polygons : (M, k) array_like of int, or a sequence of index sequences of length >= 3

        References
        ----------
        [seed] "Polygon Mesh Models"; [HB 4] "Polygon Fill Areas" (splitting a convex polygon into triangles).
        """
        where = "Mesh.from_polygons"
        points = as_points(vertices, "vertices", where=where)
        rows = _polygon_rows(polygons, where)
        faces = []
        for i, row in enumerate(rows):
            if row.size < 3:
                raise GeometryError(
                    f"{where}: polygons[{i}] = {describe(row)} has {row.size} vertices; a polygon needs at least 3"
                )
            k = np.arange(1, row.size - 1)
            faces.append(np.stack([np.full_like(k, row[0]), row[k], row[k + 1]], axis=1))
        stacked = np.concatenate(faces) if faces else np.empty((0, 3), dtype=np.int64)
        return cls(points, stacked)


# --- helpers ------------------------------------------------------------------------------------------------


def _float64(array: np.ndarray) -> np.ndarray:
    """`array` in float64 (itself when it already is): float32 storage computes exactly as its float64 copy."""
    return np.asarray(array, dtype=np.float64)


def _row_lengths(rows: np.ndarray) -> np.ndarray:
    """(N,) Euclidean lengths of (N, 3) float64 rows, $sqrt((x² + y²) + z²)$: the same sums as
    ``(rows * rows).sum(axis=1)`` without its (N, 3) temporary."""
    squares = rows[:, 0] * rows[:, 0]
    squares += rows[:, 1] * rows[:, 1]
    squares += rows[:, 2] * rows[:, 2]
    return np.sqrt(squares, out=squares)


_BLOCK_ROWS = 1 << 16
"""Rows per block of ``_normalize_rows`` (its float64 temporaries stay a few MiB whatever the mesh size)."""


def _normalize_rows(rows: np.ndarray, where: str) -> None:
    """Divide the (N, 3) rows (our own copy) by their lengths in place, computing in float64 block by block: float64
    rows as ``rows / |rows|``, float32 rows normalized in float64 and rounded once (|n| = 1 within 2⁻²⁴).

    Raises GeometryError naming the first zero-length row."""
    for start in range(0, rows.shape[0], _BLOCK_ROWS):
        block = np.asarray(rows[start : start + _BLOCK_ROWS], dtype=np.float64)  # a view when rows are float64
        lengths = _row_lengths(block)
        zero = np.flatnonzero(lengths == 0.0)
        if zero.size:
            i = start + int(zero[0])
            raise GeometryError(
                f"{where}: vertex_normals[{i}] = {rows[i].tolist()} has zero length; normals must be nonzero"
            )
        block /= lengths[:, None]
        if block.dtype != rows.dtype:
            rows[start : start + _BLOCK_ROWS] = block


def _face_cross_products(vertices: Points, faces: NDArray[np.int64]) -> Points:
    v0, v1, v2 = (_float64(vertices[faces[:, k]]) for k in range(3))
    return np.cross(v1 - v0, v2 - v0)


def _area_weighted_normals(vertices: Points, faces: NDArray[np.int64]) -> Points:
    # sum of each face's (v1 − v0) × (v2 − v0) (length 2·area) over the faces at a vertex, then normalize
    cross = _face_cross_products(vertices, faces)
    sums = np.zeros(vertices.shape, dtype=np.float64)
    for corner in range(3):
        np.add.at(sums, faces[:, corner], cross)
    lengths = np.sqrt((sums * sums).sum(axis=1))
    normals = np.empty(vertices.shape, dtype=np.float64)
    ok = lengths > 0.0
    normals[ok] = sums[ok] / lengths[ok, None]
    normals[~ok] = (0.0, 0.0, 1.0)
    return normals


def _directed_edges(faces: NDArray[np.int64]) -> NDArray[np.int64]:
    return faces[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2)


def _position_ids(vertices: Points) -> NDArray[np.int64]:
    """One id per distinct position (exact equality, −0.0 == 0.0), numbered in sorted order of the positions."""
    order = np.lexsort(vertices.T[::-1])
    ordered = vertices[order]
    new = np.empty(order.size, dtype=bool)
    new[:1] = True
    new[1:] = (ordered[1:] != ordered[:-1]).any(axis=1)
    ids = np.empty(order.size, dtype=np.int64)
    ids[order] = np.cumsum(new) - 1
    return ids


def _grid_faces(n: int, m: int) -> NDArray[np.int64]:
    index = np.arange(n * m).reshape(n, m)
    a, b = index[:-1, :-1].ravel(), index[1:, :-1].ravel()
    c, d = index[1:, 1:].ravel(), index[:-1, 1:].ravel()
    return np.stack([np.stack([a, b, c], axis=1), np.stack([a, c, d], axis=1)], axis=1).reshape(-1, 3)


def _check_rows(array: np.ndarray, count: int, name: str, where: str) -> None:
    if array.shape[0] != count:
        what = "normal" if name == "vertex_normals" else "row"
        raise GeometryError(
            f"{where}: {name} has {array.shape[0]} rows for {count} vertices; give one {what} per vertex"
        )


def _as_uvs(value: ArrayLike, count: int, where: str) -> NDArray[np.float64]:
    uv = np.asarray(value, dtype=np.float64) if is_numeric(value) else None
    if uv is None:
        raise GeometryError(f"{where}: uvs = {describe(value)} is not numeric; expected (N, 2) texture coordinates")
    if uv.size == 0 and count == 0:
        return np.empty((0, 2))
    if uv.ndim != 2 or uv.shape[1] != 2:
        raise GeometryError(f"{where}: uvs has shape {uv.shape}; expected (N, 2) texture coordinates (u, v)")
    _check_rows(uv, count, "uvs", where)
    bad = np.flatnonzero(~np.isfinite(uv).all(axis=1))
    if bad.size:
        i = int(bad[0])
        raise GeometryError(f"{where}: uvs[{i}] = {describe(uv[i])} is not finite; texture coordinates must be finite")
    return np.ascontiguousarray(uv)


def _as_vertex_colors(value: ArrayLike, count: int, where: str) -> NDArray[np.float64]:
    raw = np.asarray(value) if is_numeric(value) else None
    if raw is None:
        raise GeometryError(f"{where}: vertex_colors = {describe(value)} is not numeric; expected (N, 3) or (N, 4)")
    colors = raw / 255.0 if raw.dtype == np.uint8 else raw.astype(np.float64)
    if colors.size == 0 and count == 0:
        return np.empty((0, 3))
    if colors.ndim != 2 or colors.shape[1] not in (3, 4):
        raise GeometryError(f"{where}: vertex_colors has shape {colors.shape}; expected (N, 3) RGB or (N, 4) RGBA")
    _check_rows(colors, count, "vertex_colors", where)
    bad = np.flatnonzero(~(np.isfinite(colors) & (colors >= 0.0) & (colors <= 1.0)).all(axis=1))
    if bad.size:
        i = int(bad[0])
        raise GeometryError(
            f"{where}: vertex_colors[{i}] = {describe(colors[i])} is outside [0, 1]; give floats in [0, 1] "
            "or a uint8 array"
        )
    return np.ascontiguousarray(colors)


def _color_block(mesh: Mesh, width: int) -> NDArray[np.float64]:
    if mesh.vertex_colors is None:
        return np.ones((mesh.vertex_count, width))
    if mesh.vertex_colors.shape[1] == width:
        return mesh.vertex_colors
    return np.concatenate([mesh.vertex_colors, np.ones((mesh.vertex_count, 1))], axis=1)


def _at_least(vertices: ArrayLike, count: int, where: str) -> Points:
    points = as_points(vertices, "vertices", where=where)
    if points.shape[0] < count:
        raise GeometryError(
            f"{where}: vertices has {points.shape[0]} rows; give at least {count} vertices (n vertices make n − 2 "
            "triangles)"
        )
    return points


def _polygon_rows(polygons: object, where: str) -> list[NDArray[np.int64]]:
    try:
        array = np.asarray(polygons)
    except ValueError:
        array = None
    if array is not None and array.dtype != object:
        if array.size == 0:
            return []
        if array.ndim != 2:
            raise GeometryError(f"{where}: polygons has shape {array.shape}; expected (M, k) or a list of index lists")
        if array.dtype == np.bool_ or not np.issubdtype(array.dtype, np.integer):
            raise GeometryError(f"{where}: polygons has dtype {array.dtype}; expected integer vertex indices")
        return list(array.astype(np.int64))
    rows = []
    for i, polygon in enumerate(polygons):  # type: ignore[attr-defined]
        row = np.asarray(polygon)
        if row.ndim != 1 or (row.size and (row.dtype == np.bool_ or not np.issubdtype(row.dtype, np.integer))):
            raise GeometryError(f"{where}: polygons[{i}] = {describe(polygon)} is not a list of integer vertex indices")
        rows.append(row.astype(np.int64))
    return rows
