"""3-D Gaussian splats (Kerbl et al. 2023): ``GaussianSplats`` and the reader and writer of the 3DGS PLY layout.

Splat i is the Gaussian $G_i(x) = exp(−½ (x − μ_i)ᵀ Σ_i⁻¹ (x − μ_i))$ with covariance $Σ = R S Sᵀ Rᵀ$ (R the
rotation of the unit quaternion q = (w, x, y, z), S = diag(scale)), an opacity o in [0, 1] and a view-dependent
colour given by real spherical-harmonic coefficients of degree 0–3: $c(d) = 0.5 + Σ_lm SH_lm(d)·k_lm$, clamped
at 0, d the unit direction from the eye to μ. ``frustum.render.splats`` draws them.

The PLY layout (what the 3DGS training code writes): vertex properties ``x y z``, ``nx ny nz`` (unused),
``f_dc_0..2`` (degree-0 coefficient per channel), ``f_rest_*`` (3(K − 1) values: the other K − 1 coefficients,
**channel-major**: all of red's, then green's, then blue's; K = (degree + 1)²), ``opacity`` (a logit: o =
1/(1 + e^−v)), ``scale_0..2`` (natural logarithms) and ``rot_0..3`` (a quaternion w, x, y, z, not necessarily
unit). ``GaussianSplats.load`` checks the fields and the memory budget from the header before it reads any data.

References
----------
Kerbl, Kopanas, Leimkühler, Drettakis, "3D Gaussian Splatting for Real-Time Radiance Field Rendering",
SIGGRAPH 2023, §4 (Σ = R S Sᵀ Rᵀ) and the reference code's ``save_ply``; Zwicker et al., "EWA Splatting", 2002.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import Points, as_points, describe, read_only
from frustum.errors import GeometryError
from frustum.geometry.points import read_ply_vertices

__all__ = ["SH_C0", "GaussianSplats", "load_splats"]

SH_C0 = 0.28209479177387814
"""$Y_0^0 = 1/(2√π)$: a 3DGS file's base colour is $0.5 + SH_C0·f_dc$."""
_BYTES_PER_SPLAT = 8 * 62 * 3
"""Peak memory per splat while loading (62 float properties at most, read as float32 then copied to float64)."""
_REQUIRED = ("x", "y", "z", "f_dc_0", "f_dc_1", "f_dc_2", "opacity", "scale_0", "scale_1", "scale_2",
             "rot_0", "rot_1", "rot_2", "rot_3")  # fmt: skip


@dataclass(frozen=True, eq=False, repr=False)
class GaussianSplats:
    """N 3-D Gaussians in model coordinates.

    Parameters
    ----------
    positions : (N, 3) array_like
        Means μ.
    scales : (N, 3) array_like
        Standard deviations along the Gaussian's own axes (linear, > 0; the PLY stores their logarithms).
    rotations : (N, 4) array_like
        Quaternions (w, x, y, z), normalized on construction (nonzero).
    opacities : (N,) array_like
        o in [0, 1] (the PLY stores logits).
    sh : (N, K, 3) array_like
        Spherical-harmonic coefficients, K = 1, 4, 9 or 16 (degree 0–3), coefficient k of channel c at
        ``sh[:, k, c]``; stored float32.

    Raises
    ------
    GeometryError
        Wrong shapes, non-finite values, scales <= 0, zero quaternions, opacities outside [0, 1].
    """

    scene_geometry: ClassVar[str] = "splats"
    """What a scene places (``scene.graph`` checks this mark and need not import this module)."""

    positions: Points
    scales: NDArray[np.float64]
    rotations: NDArray[np.float64]
    opacities: NDArray[np.float64]
    sh: NDArray[np.float32]

    def __post_init__(self) -> None:
        where = "GaussianSplats"
        positions = as_points(self.positions, "positions", where=where)
        count = positions.shape[0]
        scales = as_points(self.scales, "scales", where=where)
        if scales.shape[0] != count or not (scales > 0.0).all():
            raise GeometryError(f"{where}: scales must be ({count}, 3) positive standard deviations; got shape "
                                f"{scales.shape}" + ("" if scales.shape[0] != count else
                                f", scales[{int(np.argwhere(~(scales > 0))[0, 0])}] not positive"))  # fmt: skip
        rotations = _rows(self.rotations, (count, 4), "rotations", where)
        norms = np.sqrt((rotations * rotations).sum(axis=1))
        if count and not (norms > 0.0).all():
            raise GeometryError(f"{where}: rotations[{int(np.argmin(norms))}] is zero; give nonzero quaternions")
        opacities = _rows(self.opacities, (count,), "opacities", where)
        if count and not ((opacities >= 0.0) & (opacities <= 1.0)).all():
            bad = int(np.flatnonzero(~((opacities >= 0.0) & (opacities <= 1.0)))[0])
            raise GeometryError(f"{where}: opacities[{bad}] = {opacities[bad]!r} is outside [0, 1]")
        sh = np.ascontiguousarray(np.asarray(self.sh, dtype=np.float32))
        if sh.ndim != 3 or sh.shape[0] != count or sh.shape[1] not in (1, 4, 9, 16) or sh.shape[2] != 3:
            raise GeometryError(f"{where}: sh has shape {sh.shape}; expected ({count}, K, 3) with K = 1, 4, 9 or 16 "
                                "(degree 0–3)")  # fmt: skip
        if not np.isfinite(sh).all():
            raise GeometryError(f"{where}: sh holds a value that is not finite")
        object.__setattr__(self, "positions", read_only(positions))
        object.__setattr__(self, "scales", read_only(scales))
        object.__setattr__(self, "rotations", read_only(rotations / norms[:, None] if count else rotations))
        object.__setattr__(self, "opacities", read_only(opacities))
        object.__setattr__(self, "sh", read_only(sh))

    def __repr__(self) -> str:
        return f"GaussianSplats(count={self.count}, degree={self.degree})"

    @property
    def count(self) -> int:
        """N, the number of splats."""
        return int(self.positions.shape[0])

    @property
    def degree(self) -> int:
        """The spherical-harmonic degree, 0–3."""
        return round(float(np.sqrt(self.sh.shape[1]))) - 1

    @cached_property
    def bounds(self) -> NDArray[np.float64]:
        """(2, 3) the corners of the box around the means (zeros if empty)."""
        if self.count == 0:
            return read_only(np.zeros((2, 3)))
        return read_only(np.array([self.positions.min(axis=0), self.positions.max(axis=0)]))

    @cached_property
    def covariances(self) -> NDArray[np.float64]:
        """(N, 3, 3) model-space covariances $Σ = R S Sᵀ Rᵀ$."""
        rotation = rotation_matrices(self.rotations)
        m = rotation * self.scales[:, None, :]
        return read_only(m @ np.transpose(m, (0, 2, 1)))

    @classmethod
    def load(cls, path: str | Path) -> GaussianSplats:
        """Read a 3DGS PLY file (this module's docstring gives the layout).

        Raises
        ------
        GeometryError
            Missing file, not a PLY, missing fields (all named), an f_rest count that is not 3·(K − 1) for
            K = 1, 4, 9, 16, or a splat count whose reading would exceed the memory budget (checked from the
            header, before any data is read).
        """
        file = Path(path)
        where = "GaussianSplats.load"
        if not file.is_file():
            raise GeometryError(f"{where}: path = {str(path)!r} does not exist; give a 3DGS .ply file")
        columns = read_ply_vertices(file, where, _BYTES_PER_SPLAT)
        missing = [name for name in _REQUIRED if name not in columns]
        if missing:
            raise GeometryError(f"{where}: path = {str(file)!r} lacks the 3DGS vertex properties "
                                f"{', '.join(missing)}; a 3DGS PLY has x y z, f_dc_0..2, f_rest_*, opacity, "
                                "scale_0..2, rot_0..3")  # fmt: skip
        rest = sorted((name for name in columns if name.startswith("f_rest_")), key=lambda n: int(n[7:]))
        expected = [f"f_rest_{i}" for i in range(len(rest))]
        if len(rest) % 3 or len(rest) // 3 + 1 not in (1, 4, 9, 16) or rest != expected:
            raise GeometryError(f"{where}: path = {str(file)!r} has {len(rest)} f_rest_* properties; expected "
                                "f_rest_0 … f_rest_{3(K−1)−1} with K = 1, 4, 9 or 16 (0, 9, 24 or 45)")  # fmt: skip
        count = columns["x"].shape[0]
        k = len(rest) // 3 + 1
        sh = np.empty((count, k, 3), dtype=np.float32)
        for channel in range(3):
            sh[:, 0, channel] = columns[f"f_dc_{channel}"]
            for j in range(k - 1):
                sh[:, j + 1, channel] = columns[f"f_rest_{channel * (k - 1) + j}"]
        positions = np.column_stack([columns[c] for c in "xyz"]).astype(np.float64)
        scales = np.exp(np.column_stack([columns[f"scale_{i}"] for i in range(3)]).astype(np.float64))
        rotations = np.column_stack([columns[f"rot_{i}"] for i in range(4)]).astype(np.float64)
        opacities = 1.0 / (1.0 + np.exp(-columns["opacity"].astype(np.float64)))
        try:
            return cls(positions, scales, rotations, opacities, sh)
        except GeometryError as error:
            raise GeometryError(f"{where}: path = {str(file)!r} holds invalid splats ({error})") from None

    def save(self, path: str | Path) -> Path:
        """Write the splats as a binary little-endian 3DGS PLY (float32: log-scales, logit opacities, normals 0);
        ``load`` reads it back to float32 precision."""
        file = Path(path)
        k = self.sh.shape[1]
        names = ["x", "y", "z", "nx", "ny", "nz", "f_dc_0", "f_dc_1", "f_dc_2"]
        names += [f"f_rest_{i}" for i in range(3 * (k - 1))]
        names += ["opacity", "scale_0", "scale_1", "scale_2", "rot_0", "rot_1", "rot_2", "rot_3"]
        table = np.zeros((self.count, len(names)), dtype="<f4")
        table[:, 0:3] = self.positions
        table[:, 6:9] = self.sh[:, 0, :]
        for channel in range(3):
            table[:, 9 + channel * (k - 1) : 9 + (channel + 1) * (k - 1)] = self.sh[:, 1:, channel]
        base = 9 + 3 * (k - 1)
        with np.errstate(divide="ignore"):
            clipped = np.clip(self.opacities, 1e-7, 1.0 - 1e-7)
            table[:, base] = np.log(clipped / (1.0 - clipped))
        table[:, base + 1 : base + 4] = np.log(self.scales)
        table[:, base + 4 : base + 8] = self.rotations
        header = "ply\nformat binary_little_endian 1.0\n" + f"element vertex {self.count}\n"
        header += "".join(f"property float {name}\n" for name in names) + "end_header\n"
        file.write_bytes(header.encode("ascii") + table.tobytes())
        return file


def load_splats(path: str | Path) -> GaussianSplats:
    """``GaussianSplats.load(path)`` as a function (the scene files' ``type = "splats"``)."""
    return GaussianSplats.load(path)


def _rows(value: ArrayLike, shape: tuple[int, ...], name: str, where: str) -> NDArray[np.float64]:
    try:
        array = np.ascontiguousarray(np.asarray(value, dtype=np.float64))
    except (TypeError, ValueError):
        raise GeometryError(f"{where}: {name} = {describe(value)} is not numeric") from None
    if array.shape != shape:
        raise GeometryError(f"{where}: {name} has shape {array.shape}; expected {shape}")
    if not np.isfinite(array).all():
        raise GeometryError(f"{where}: {name} holds a value that is not finite")
    return array


def rotation_matrices(quaternions: Any) -> NDArray[np.float64]:
    """(N, 3, 3) rotation matrices of unit quaternions (w, x, y, z) (the ``Quaternion.to_matrix`` formula)."""
    q = np.asarray(quaternions, dtype=np.float64)
    w, x, y, z = q[:, 0], q[:, 1], q[:, 2], q[:, 3]
    m = np.empty((q.shape[0], 3, 3))
    m[:, 0, 0] = 1 - 2 * (y * y + z * z)
    m[:, 0, 1] = 2 * (x * y - w * z)
    m[:, 0, 2] = 2 * (x * z + w * y)
    m[:, 1, 0] = 2 * (x * y + w * z)
    m[:, 1, 1] = 1 - 2 * (x * x + z * z)
    m[:, 1, 2] = 2 * (y * z - w * x)
    m[:, 2, 0] = 2 * (x * z - w * y)
    m[:, 2, 1] = 2 * (y * z + w * x)
    m[:, 2, 2] = 1 - 2 * (x * x + y * y)
    return m
