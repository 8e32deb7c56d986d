"""The Utah teaset (Newell 1975): teapot, teacup and teaspoon as sets of bicubic Bézier patches.

The patch data ships with frustum as package data (``frustum/geometry/data/*.txt``, the Newell/Kouhia text
format: a patch count, one line of 16 one-based control-point indices per patch, a point count, one ``x,y,z``
line per point). Newell's data is public domain.

Each patch's 16 indices form a 4 × 4 grid in row-major order, $P(s, t) = Σ_r Σ_c B_r(s)·B_c(t)·V[idx[4r + c]]$.
frustum stores the patch with its grid transposed, ``grid[c, r]``, so that u = t and v = s: then
$S_u × S_v = ∂P/∂t × ∂P/∂s$ is the outward normal on the teapot's body, lid, bottom, handle and spout (the
choice three.js makes), and ``tessellate`` turns the faces counter-clockwise from outside.

References
----------
[seed] "Bézier Surfaces"; M. Newell's teaset (1975); F. Crow, "The origins of the teapot", IEEE CG&A 7(1), 1987.
"""

from __future__ import annotations

from collections.abc import Iterator
from importlib import resources

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import as_count, describe, read_only
from frustum.errors import GeometryError
from frustum.geometry.mesh import Mesh
from frustum.geometry.surfaces import BezierSurface, _tessellate_bezier_grids

__all__ = ["BezierPatchSet", "teacup", "teapot", "teaspoon"]


class BezierPatchSet:
    """A named set of bicubic Bézier patches (one model made of many patches).

    Parameters
    ----------
    grids : (P, m + 1, n + 1, 3) array_like
        The control grids, ``grids[p, i, j]`` with i along u and j along v (4 × 4 for the teaset).
    name : str

    Attributes
    ----------
    grids : (P, m + 1, n + 1, 3) float64, read-only
    patches : tuple of BezierSurface
    """

    __slots__ = ("grids", "name", "patches")
    grids: NDArray[np.float64]
    patches: tuple[BezierSurface, ...]
    name: str

    def __init__(self, grids: ArrayLike, name: str = "patches") -> None:
        where = "BezierPatchSet"
        try:
            array = np.asarray(grids, dtype=np.float64)
        except (TypeError, ValueError):
            raise GeometryError(
                f"{where}: grids = {describe(grids)} is not numeric; expected a (P, m + 1, n + 1, 3) array"
            ) from None
        if array.ndim != 4 or array.shape[0] < 1:
            raise GeometryError(
                f"{where}: grids has shape {array.shape}; expected (P, m + 1, n + 1, 3) control grids, P >= 1"
            )
        self.patches = tuple(BezierSurface(g) for g in array)
        self.grids = read_only(np.ascontiguousarray(np.stack([p.grid for p in self.patches])))
        self.name = str(name)

    def __repr__(self) -> str:
        return f"BezierPatchSet({self.name!r}, patches={len(self)})"

    def __len__(self) -> int:
        return len(self.patches)

    def __iter__(self) -> Iterator[BezierSurface]:
        return iter(self.patches)

    def __getitem__(self, index: int) -> BezierSurface:
        return self.patches[index]

    def tessellate(self, resolution: int = 10) -> Mesh:
        """One ``Mesh`` of every patch tessellated ``resolution`` × ``resolution`` (vertices not welded).

        Patch p contributes vertices $p·(resolution + 1)² + i·(resolution + 1) + j$ at (u_i, v_j), with analytic
        normals (limits at the lid's and bottom's collapsed edges); triangles with coincident corners are
        dropped, as three.js does.
        """
        n = as_count(resolution, "resolution", 1, where="BezierPatchSet.tessellate")
        return _tessellate_bezier_grids(self.patches, self.grids, n, n, where="BezierPatchSet.tessellate")

    def tessellate_adaptive(self, tolerance: float) -> Mesh:
        """Every patch at the finest resolution any patch needs for `tolerance` (so no cracks between patches)."""
        n = max(max(patch.flatness_resolution(tolerance)) for patch in self.patches)
        return self.tessellate(n)

    def control_net(self) -> NDArray[np.float64]:
        """(S, 2, 3) line segments of every patch's control grid (rows and columns), for drawing the net."""
        g = self.grids
        along_u = np.stack([g[:, :-1, :], g[:, 1:, :]], axis=3).reshape(-1, 2, 3)
        along_v = np.stack([g[:, :, :-1], g[:, :, 1:]], axis=3).reshape(-1, 2, 3)
        return np.concatenate([along_u, along_v])


def _read_patches(text: str, where: str) -> NDArray[np.float64]:
    """(P, 4, 4, 3) grids ``[p, r, c]`` (row-major, as the file lists them) from the Newell/Kouhia text format."""
    lines = [line.strip() for line in text.splitlines() if line.strip()]
    try:
        count = int(lines[0])
        indices = np.array([[int(x) for x in line.split(",")] for line in lines[1 : 1 + count]]) - 1
        points_count = int(lines[1 + count])
        points = np.array([[float(x) for x in line.split(",")] for line in lines[2 + count : 2 + count + points_count]])
    except (IndexError, ValueError) as error:
        raise GeometryError(
            f"{where}: the patch data is malformed ({error}); expected the Newell text format"
        ) from None
    if indices.shape != (count, 16) or points.shape != (points_count, 3) or indices.min() < 0:
        raise GeometryError(
            f"{where}: the patch data has shapes {indices.shape}, {points.shape}; expected "
            f"({count}, 16) indices and ({points_count}, 3) points"
        )
    return points[indices].reshape(count, 4, 4, 3)


def _load(name: str) -> BezierPatchSet:
    text = resources.files("frustum.geometry").joinpath("data", f"{name}.txt").read_text(encoding="ascii")
    grids = _read_patches(text, name)
    return BezierPatchSet(grids.transpose(0, 2, 1, 3), name)  # grid[c, r]: u = t (column), v = s (row)


def teapot() -> BezierPatchSet:
    """The Utah teapot: 32 bicubic patches (rim, body, handle, spout, lid, bottom), z up, 306 control points.

    Bounds x in [−3, 3.525] (spout at +x), y in [−2, 2], z in [0, 3.15] (Blinn's squashed version). The
    surface is not closed (the lid leaves a gap; handle and spout pierce the body): render it double-sided.
    """
    return _load("teapot")


def teacup() -> BezierPatchSet:
    """Newell's teacup: 26 bicubic patches, y up."""
    return _load("teacup")


def teaspoon() -> BezierPatchSet:
    """Newell's teaspoon: 16 bicubic patches, y up."""
    return _load("teaspoon")
