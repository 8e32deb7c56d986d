"""Iterated function systems: affine maps with probabilities, the chaos game, Barnsley's fern, Sierpinski's IFS."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from frustum._arrays import Points, describe, read_only
from frustum.errors import GeometryError
from frustum.geometry.fractals.checks import (
    SQRT3,
    byte_budget,
    check_fractal_memory,
    check_level,
    check_positive_int,
    check_seed,
    kernels,
)

__all__ = ["IFS", "barnsley_fern", "sierpinski_ifs"]


@dataclass(frozen=True, eq=False)
class IFS:
    """An iterated function system: contractive affine maps $wᵢ(P) = Aᵢ·P + bᵢ$ chosen with probabilities $pᵢ$.

    The attractor is the unique set with $S = ∪ᵢ wᵢ(S)$ (Hutchinson); ``points`` iterates that union
    deterministically, ``chaos_game`` walks it at random (Barnsley).

    Parameters
    ----------
    affine_maps : (k, 3, 3) or (k, 4, 4) array_like
        Homogeneous affine matrices, column-vector convention (last row (0, …, 0, 1)): 2D maps as 3×3,
        3D maps as 4×4. Each linear part must be a contraction (largest singular value < 1).
    probabilities : (k,) array_like, optional
        Nonnegative, summing to 1 (within 1e-9). Default: proportional to |det Aᵢ| (2D or 3D part), each at
        least 1 % of the total, the usual choice that fills the attractor evenly.

    Attributes
    ----------
    linear : (k, 3, 3) float64  ·  offset : (k, 3) float64  ·  probabilities : (k,) float64  ·  dim : 2 or 3.

    References
    ----------
    [HB 15] "Fractal-Geometry Methods" ("Affine Fractal-Construction Methods"); M. Barnsley, *Fractals
    Everywhere*, 1988, ch. III.
    """

    affine_maps: Any
    probabilities: Any = None

    def __post_init__(self) -> None:
        where = "IFS"
        try:
            maps = np.asarray(self.affine_maps, dtype=np.float64)
        except (TypeError, ValueError):
            raise GeometryError(
                f"{where}: affine_maps = {describe(self.affine_maps)} is not numeric; give (k, 3, 3) or (k, 4, 4)"
            ) from None
        if maps.ndim != 3 or maps.shape[0] < 1 or maps.shape[1:] not in ((3, 3), (4, 4)):
            raise GeometryError(
                f"{where}: affine_maps has shape {maps.shape}; give (k, 3, 3) 2D or (k, 4, 4) 3D homogeneous maps"
            )
        if not np.isfinite(maps).all():
            raise GeometryError(f"{where}: affine_maps has non-finite entries; give finite matrices")
        k, d = maps.shape[0], maps.shape[1] - 1
        bottom = np.zeros(d + 1)
        bottom[-1] = 1.0
        bad = np.flatnonzero(np.abs(maps[:, d, :] - bottom).max(axis=1) > 0.0)
        if bad.size:
            i = int(bad[0])
            raise GeometryError(
                f"{where}: affine_maps[{i}] has last row {describe(maps[i, d])}; an affine map's last row is "
                f"{describe(bottom)}"
            )
        linear = np.zeros((k, 3, 3))
        offset = np.zeros((k, 3))
        linear[:, :d, :d] = maps[:, :d, :d]
        offset[:, :d] = maps[:, :d, d]
        sigma = np.linalg.svd(maps[:, :d, :d], compute_uv=False)[:, 0]
        bad = np.flatnonzero(sigma >= 1.0)
        if bad.size:
            i = int(bad[0])
            raise GeometryError(
                f"{where}: affine_maps[{i}] stretches by {float(sigma[i])!r}; each map must be a contraction "
                "(largest singular value < 1)"
            )
        if self.probabilities is None:
            det = np.abs(np.linalg.det(maps[:, :d, :d]))
            det = det / det.sum() if det.sum() > 0 else np.full(k, 1.0 / k)
            p = np.maximum(det, 0.01)
            p = p / p.sum()
        else:
            try:
                p = np.asarray(self.probabilities, dtype=np.float64)
            except (TypeError, ValueError):
                raise GeometryError(
                    f"{where}: probabilities = {describe(self.probabilities)} is not numeric; give k numbers"
                ) from None
            if p.shape != (k,):
                raise GeometryError(
                    f"{where}: probabilities = {describe(self.probabilities)} has shape {p.shape}; give {k} "
                    "numbers, one per map"
                )
            if not np.isfinite(p).all() or (p < 0).any():
                raise GeometryError(
                    f"{where}: probabilities = {describe(p)} has a negative or non-finite entry; give numbers >= 0"
                )
            total = float(p.sum())
            if abs(total - 1.0) > 1e-9:
                raise GeometryError(f"{where}: probabilities = {describe(p)} sum to {total!r}; they must sum to 1")
        object.__setattr__(self, "affine_maps", read_only(maps))
        object.__setattr__(self, "probabilities", read_only(np.ascontiguousarray(p)))
        object.__setattr__(self, "linear", read_only(linear))
        object.__setattr__(self, "offset", read_only(offset))
        object.__setattr__(self, "dim", d)

    @property
    def map_count(self) -> int:
        """k, the number of maps."""
        return int(self.affine_maps.shape[0])

    def fixed_point(self, i: int = 0) -> Points:
        """(3,) the fixed point of map i, $P = Aᵢ·P + bᵢ$ (it lies on the attractor)."""
        d = self.dim
        point = np.zeros(3)
        point[:d] = np.linalg.solve(np.eye(d) - self.linear[i, :d, :d], self.offset[i, :d])
        return point

    def points(self, level: int, *, max_bytes: int | None = None) -> Points:
        """Deterministic algorithm: apply every map to the point set `level` times, from map 0's fixed point.

        $S_{n+1} = ∪ᵢ wᵢ(S_n)$, $S_0$ = {fixed point of $w₀$}; every point lies on the attractor.

        Returns
        -------
        (k^level, 3) float64, in map order (point j's base-k digits name the maps, outermost first).
        """
        where = "IFS.points"
        n = check_level(level, where)
        check_fractal_memory(
            self.map_count**n * 3 * 8 * 3, byte_budget(max_bytes, where), where=where, name="level", value=n
        )
        pts = self.fixed_point(0)[None]
        for _ in range(n):
            # (k, N, 3): map i applied to every point; outer index = map
            pts = (np.einsum("kab,nb->kna", self.linear, pts) + self.offset[:, None, :]).reshape(-1, 3)
        return pts

    def chaos_game(self, n_points: int, *, seed: int, skip: int = 100,
                   max_bytes: int | None = None) -> Points:  # fmt: skip
        """Random iteration (chaos game): x ← w_k(x) with k drawn with the map probabilities.

        Starts at map 0's fixed point; the first `skip` iterates are dropped. Same seed, same bytes.

        Returns
        -------
        (n_points, 3) float64.
        """
        where = "IFS.chaos_game"
        count = check_positive_int(n_points, where, "n_points")
        skip = check_positive_int(skip, where, "skip", minimum=0)
        check_fractal_memory((count + skip) * (3 * 8 + 16), byte_budget(max_bytes, where), where=where, name="n_points",
                     value=count)  # fmt: skip
        rng = np.random.default_rng(check_seed(seed, where))
        cumulative = np.cumsum(self.probabilities)
        cumulative[-1] = 1.0
        choices = np.searchsorted(cumulative, rng.random(count + skip), side="right").astype(np.int64)
        choices = np.minimum(choices, self.map_count - 1)
        out = np.empty((count, 3))
        kernels()._chaos_game_kernel(np.ascontiguousarray(self.linear), np.ascontiguousarray(self.offset), choices,
                           self.fixed_point(0), skip, out)  # fmt: skip
        return out


def barnsley_fern() -> IFS:
    """Barnsley's fern: four 2D maps with probabilities 0.01, 0.85, 0.07, 0.07 (Fractals Everywhere, 1988)."""
    maps = np.array(
        [
            [[0.0, 0.0, 0.0], [0.0, 0.16, 0.0], [0, 0, 1]],
            [[0.85, 0.04, 0.0], [-0.04, 0.85, 1.6], [0, 0, 1]],
            [[0.2, -0.26, 0.0], [0.23, 0.22, 1.6], [0, 0, 1]],
            [[-0.15, 0.28, 0.0], [0.26, 0.24, 0.44], [0, 0, 1]],
        ]
    )
    return IFS(maps, [0.01, 0.85, 0.07, 0.07])


def sierpinski_ifs(corners: ArrayLike = ((0.0, 0.0), (1.0, 0.0), (0.5, SQRT3 / 2.0))) -> IFS:
    """The Sierpinski triangle as an IFS: $wᵢ(P) = (P + cᵢ)/2$ for the three corners $cᵢ$, probabilities 1/3."""
    tri = np.asarray(corners, dtype=np.float64)
    if tri.shape != (3, 2) or not np.isfinite(tri).all():
        raise GeometryError(f"sierpinski_ifs: corners = {describe(corners)} is not (3, 2) finite numbers")
    maps = np.zeros((3, 3, 3))
    maps[:, 0, 0] = maps[:, 1, 1] = 0.5
    maps[:, :2, 2] = tri / 2.0
    maps[:, 2, 2] = 1.0
    return IFS(maps, [1 / 3, 1 / 3, 1 - 2 / 3])
