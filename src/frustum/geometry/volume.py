"""Scalar volumes and transfer functions: 3D grids of values placed in model coordinates, classified to RGBA.

A ``Volume`` holds ``data[i, j, k]``, the value at the grid point

$$P_model = origin + direction · ((i, j, k) ⊙ spacing)$$

(ITK / NIfTI "index to physical" mapping),

so axis 0 of the array runs along model x, axis 1 along y, axis 2 along z (with the default identity
`direction`). ``model_from_grid`` is that map as a 4x4 matrix. Values between grid points are trilinear
interpolations of the eight around them; the volume's box is the hull of the grid points, index 0 … n − 1
per axis (no half-voxel border). Sources: arrays, ``.npy`` and NIfTI files (``Volume.load``, nibabel as the
``nifti`` extra, its affine honoured), implicit functions sampled on a grid (``Volume.from_function``, e.g. with
``quadrics.sphere_implicit``), blobby objects (``blobby_volume``), fBm clouds (``fbm_cloud``) and the
quaternion Julia set (``quaternion_julia_volume``).

A ``TransferFunction`` maps a scalar s to color and opacity, both piecewise linear in s [HB 15] "Visual
Representations for Scalar Fields": $(r, g, b, α)(s)$ interpolates the control rows around s and is constant
past the first and last control value. The renderer samples it into a lookup table (``TransferFunction.table``).

References
----------
[HB 15] "Visualization of Data Sets" (scalar fields: isosurfaces, volume rendering); [HB 13] "Blobby Objects";
[HB 15] "Fractal-Geometry Methods"; [seed] "other modeling techniques" (volume rendering), fractal clouds.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from functools import cached_property
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import Matrix4, as_count, as_scalar, as_vector3, describe, read_only
from frustum.budgets import check_memory, check_operations
from frustum.errors import GeometryError
from frustum.geometry.mesh import Mesh

__all__ = [
    "TRANSFER_PRESETS",
    "VOLUME_MODES",
    "VOLUME_SAMPLINGS",
    "TransferFunction",
    "Volume",
    "blobby_volume",
    "fbm_cloud",
    "head_phantom",
    "quaternion_julia_volume",
]

TRANSFER_PRESETS = ("grayscale", "bone", "fire")
"""Names ``TransferFunction.preset`` knows (any Matplotlib colormap name works through ``.colormap``)."""

_SLAB_VOXELS = 1 << 20
"""Voxels per slab of the work done in pieces (finiteness check, reading a .npy): 4 MiB of float32."""


def volume_bytes(shape: Any) -> float:
    """Peak memory of making a ``Volume`` of `shape` beside its source: the float32 copy (4 bytes a voxel) and
    one slab of work (``_SLAB_VOXELS``: a slab's finiteness flags, or a slab read from a file and converted)."""
    voxels = math.prod(int(n) for n in shape)
    return voxels * 4.0 + min(voxels, _SLAB_VOXELS) * 9.0


class _Owned:
    """A float32 C-ordered array a loader has just made: ``Volume`` keeps it instead of copying it."""

    def __init__(self, array: np.ndarray) -> None:
        self.array = array


def _slabs(shape: tuple[int, ...]) -> Any:
    """(start, stop) along axis 0 covering it in slabs of about ``_SLAB_VOXELS`` voxels."""
    per_row = max(1, math.prod(shape[1:]))
    step = max(1, _SLAB_VOXELS // per_row)
    return ((start, min(start + step, shape[0])) for start in range(0, shape[0], step))


def _check_finite(array: np.ndarray, where: str) -> None:
    """GeometryError naming the first voxel that is NaN or infinite; checked slab by slab (no full-size flags)."""
    for start, stop in _slabs(array.shape):
        finite = np.isfinite(array[start:stop])
        if not finite.all():
            index = tuple(int(i) for i in np.argwhere(~finite)[0])
            index = (index[0] + start, *index[1:])
            count = sum(int(np.count_nonzero(~np.isfinite(array[a:b]))) for a, b in _slabs(array.shape))
            raise GeometryError(f"{where}: data[{', '.join(map(str, index))}] = {float(array[index])!r} is not "
                                f"finite ({count} such voxels); voxels must be finite numbers, replace them first, "
                                "e.g. np.nan_to_num(data, nan=0.0)")  # fmt: skip


def _read_npy(name: str, where: str) -> np.ndarray:
    """A .npy file's 3D array as float32, read slab by slab into its one float32 array (no full-size copy of
    the file's data in memory: a float32 file is read straight into place)."""
    from numpy.lib import format as npy

    with open(name, "rb") as stream:
        try:
            version = npy.read_magic(stream)
            read_header = npy.read_array_header_1_0 if version == (1, 0) else npy.read_array_header_2_0
            shape, fortran, dtype = read_header(stream)
        except (ValueError, OSError, SyntaxError, UnicodeError) as error:
            raise GeometryError(f"{where}: path = {name!r} is not a readable .npy array ({error})") from None
        if len(shape) != 3 or fortran or dtype.hasobject or dtype.kind not in "biuf":
            return np.load(name, allow_pickle=False, mmap_mode="r")  # Volume says what is wrong, or copies it
        check_memory(volume_bytes(shape), where=where, cause=f"path = {name!r} with data of shape {shape}",
                     error=GeometryError)  # fmt: skip
        array = np.empty(shape, dtype=np.float32)
        for start, stop in _slabs(shape):
            count = (stop - start) * math.prod(shape[1:])
            if dtype == np.dtype("<f4") or (dtype == np.dtype("=f4") and np.little_endian):
                target = memoryview(array[start:stop].reshape(-1)).cast("B")
                read = stream.readinto(target)
                if read != target.nbytes:
                    raise GeometryError(f"{where}: path = {name!r} ends after {read} of the {target.nbytes} bytes of "
                                        f"rows {start}..{stop - 1}; the file is truncated")  # fmt: skip
            else:
                raw = stream.read(count * dtype.itemsize)
                if len(raw) != count * dtype.itemsize:
                    raise GeometryError(f"{where}: path = {name!r} ends inside rows {start}..{stop - 1}; the file is "
                                        "truncated")  # fmt: skip
                array[start:stop] = np.frombuffer(raw, dtype=dtype).reshape((stop - start, *shape[1:]))
    return array


_PRESET_COLORS = {
    "grayscale": ((0.0, 0.0, 0.0, 0.0), (1.0, 1.0, 1.0, 1.0)),
    # bone: black through blue-gray to white, as Matplotlib's "bone" (gray with a cold tint)
    "bone": ((0.0, 0.0, 0.0, 0.0), (0.375, 0.319, 0.319, 0.444), (0.75, 0.652, 0.777, 0.777), (1.0, 1.0, 1.0, 1.0)),
    # fire: black, red, orange, yellow, white (black-body ramp)
    "fire": ((0.0, 0.0, 0.0, 0.0), (0.35, 0.8, 0.05, 0.0), (0.6, 1.0, 0.45, 0.0), (0.85, 1.0, 0.9, 0.2),
             (1.0, 1.0, 1.0, 1.0)),
}  # fmt: skip


def _range(value: Any, where: str) -> tuple[float, float]:
    try:
        low, high = (float(v) for v in value)
    except (TypeError, ValueError):
        raise GeometryError(f"{where}: range = {describe(value)} is not two numbers; give (low, high)") from None
    if not (math.isfinite(low) and math.isfinite(high) and low < high):
        raise GeometryError(f"{where}: range = {describe(value)} is not finite with low < high; give (low, high)")
    return low, high


class TransferFunction:
    """Piecewise-linear color and opacity over the scalar range: ``TransferFunction(values, colors, opacities)``.

    ``rgba(s)`` interpolates linearly between the control rows whose `values` bracket s; below the first value
    it is the first row, above the last the last row. Opacity is per unit distance $Δ₀$ (the volume's
    smallest spacing): a ray step Δ uses $α' = 1 − (1 − α)^(Δ/Δ₀)$ (the renderer's opacity correction).

    Parameters
    ----------
    values : (K,) array_like
        Scalar values of the control points, finite and strictly increasing, K >= 2.
    colors : (K, 3) array_like
        Linear RGB in [0, 1] at each control value.
    opacities : (K,) array_like
        Opacity in [0, 1] at each control value.
    range : (2,) array_like, optional
        The scalar range the function covers, $low < high$; every control value must lie inside. Default
        ``(values[0], values[-1])``. The renderer's lookup table spans this range.

    Raises
    ------
    GeometryError
        Shapes that do not match, non-finite numbers, values not strictly increasing or outside `range`,
        colors or opacities outside [0, 1].

    References
    ----------
    [HB 15] "Visual Representations for Scalar Fields" (color and opacity assigned to scalar values).
    """

    def __init__(self, values: ArrayLike, colors: ArrayLike, opacities: ArrayLike, range: Any = None) -> None:
        where = "TransferFunction"
        v = _float_array(values, "values", where)
        c = _float_array(colors, "colors", where)
        a = _float_array(opacities, "opacities", where)
        if v.ndim != 1 or v.size < 2:
            raise GeometryError(f"{where}: values has shape {v.shape}; expected (K,) with K >= 2 control values")
        if c.shape != (v.size, 3):
            raise GeometryError(f"{where}: colors has shape {c.shape}; expected ({v.size}, 3), one RGB per value")
        if a.shape != (v.size,):
            raise GeometryError(f"{where}: opacities has shape {a.shape}; expected ({v.size},), one per value")
        for name, array in (("values", v), ("colors", c), ("opacities", a)):
            bad = np.argwhere(~np.isfinite(array))
            if bad.size:
                index = tuple(int(i) for i in bad[0])
                raise GeometryError(f"{where}: {name}[{', '.join(map(str, index))}] = {float(array[index])!r} is not "
                                    "finite; expected finite numbers")  # fmt: skip
        steps = np.flatnonzero(np.diff(v) <= 0.0)
        if steps.size:
            i = int(steps[0])
            after, before = float(v[i + 1]), float(v[i])
            raise GeometryError(f"{where}: values[{i + 1}] = {after!r} is not above values[{i}] = {before!r}; "
                                "control values must be sorted, strictly increasing")  # fmt: skip
        for name, array in (("colors", c), ("opacities", a)):
            bad = np.argwhere((array < 0.0) | (array > 1.0))
            if bad.size:
                index = tuple(int(i) for i in bad[0])
                label = ", ".join(map(str, index))
                raise GeometryError(f"{where}: {name}[{label}] = {float(array[index])!r} is outside "
                                    "[0, 1]; colors and opacities are fractions in [0, 1]")  # fmt: skip
        low, high = (float(v[0]), float(v[-1])) if range is None else _range(range, where)
        outside = np.flatnonzero((v < low) | (v > high))
        if outside.size:
            i = int(outside[0])
            raise GeometryError(f"{where}: values[{i}] = {float(v[i])!r} is outside range = ({low!r}, {high!r}); "
                                "control values must lie in the range")  # fmt: skip
        self.values, self.colors, self.opacities = read_only(v), read_only(c), read_only(a)
        self.range = (low, high)

    def __repr__(self) -> str:
        return f"TransferFunction({self.values.size} control points, range={self.range})"

    def __call__(self, scalars: ArrayLike) -> NDArray[np.float64]:
        """(..., 4) float64 RGBA of `scalars` (any shape), the exact piecewise-linear function."""
        s = np.asarray(scalars, dtype=np.float64)
        out = np.empty((*s.shape, 4))
        for channel in range(3):
            out[..., channel] = np.interp(s, self.values, self.colors[:, channel])
        out[..., 3] = np.interp(s, self.values, self.opacities)
        return out

    def table(self, size: int = 4096) -> NDArray[np.float64]:
        """(size, 4) float64: the function at ``size`` evenly spaced values over ``range`` (the kernel's table).

        Entry t holds $rgba(low + t·(high − low)/(size − 1))$; the kernel interpolates linearly between
        entries, so the table is exact wherever no control value falls strictly between two entries.
        """
        size = as_count(size, "size", 2, where="TransferFunction.table")
        return self(np.linspace(self.range[0], self.range[1], size))

    @classmethod
    def preset(cls, name: str, range: Any, opacity: Any = None) -> TransferFunction:
        """A named color ramp over $range = (low, high)$: one of ``TRANSFER_PRESETS``.

        `opacity`: None for a linear ramp 0 → 1 over the range, a number for a constant, or (M,) opacities at
        M evenly spaced values (M >= 2).
        """
        where = "TransferFunction.preset"
        if not isinstance(name, str) or name not in _PRESET_COLORS:
            raise GeometryError(f"{where}: name = {describe(name)} is unknown; expected one of "
                                + ", ".join(repr(n) for n in TRANSFER_PRESETS)
                                + " (or TransferFunction.colormap for Matplotlib names)")  # fmt: skip
        rows = np.array(_PRESET_COLORS[name])
        return cls._ramp(rows[:, 0], rows[:, 1:], range, opacity, where)

    @classmethod
    def colormap(cls, name: str, range: Any, opacity: Any = None, samples: int = 256) -> TransferFunction:
        """Matplotlib's colormap `name` (``"viridis"``, ``"magma"``, …) sampled at `samples` points over `range`.

        `opacity` as in ``preset``. Needs Matplotlib (``pip install 'frustum[colormaps]'``).
        """
        where = "TransferFunction.colormap"
        try:
            import matplotlib
        except ImportError:
            raise GeometryError(f"{where}: name = {name!r} needs Matplotlib, which is not installed; "
                                "pip install 'frustum[colormaps]', or use TransferFunction.preset"
                                ) from None  # fmt: skip
        try:
            cmap = matplotlib.colormaps[name]
        except (KeyError, TypeError):
            raise GeometryError(f"{where}: name = {describe(name)} is not a Matplotlib colormap; e.g. 'viridis', "
                                "'magma', 'bone', 'hot'") from None  # fmt: skip
        count = as_count(samples, "samples", 2, where=where)
        fractions = np.linspace(0.0, 1.0, count)
        return cls._ramp(fractions, np.asarray(cmap(fractions))[:, :3], range, opacity, where)

    @classmethod
    def _ramp(cls, knots: NDArray, colors: NDArray, span: Any, opacity: Any, where: str) -> TransferFunction:
        """Colors at fractions `knots` of the range `span`, with `opacity` as ``preset`` takes it."""
        low, high = _range(span, where)
        fractions = knots
        if opacity is None:
            alphas = knots.copy()
        elif np.ndim(opacity) == 0:
            value = as_scalar(opacity, "opacity", where=where, error=GeometryError)
            if not 0.0 <= value <= 1.0:
                raise GeometryError(f"{where}: opacity = {value!r} is outside [0, 1]; give an opacity in [0, 1]")
            alphas = np.full(knots.size, value)
        else:
            given = _float_array(opacity, "opacity", where)
            if given.ndim != 1 or given.size < 2 or not np.isfinite(given).all():
                raise GeometryError(f"{where}: opacity = {describe(opacity)} is not a number or (M,) finite "
                                    "opacities with M >= 2")  # fmt: skip
            opacity_knots = np.linspace(0.0, 1.0, given.size)
            fractions = np.union1d(knots, opacity_knots)  # both functions stay exact: control rows at both knots
            colors = np.column_stack([np.interp(fractions, knots, colors[:, c]) for c in (0, 1, 2)])
            alphas = np.interp(fractions, opacity_knots, given)
        values = low + fractions * (high - low)
        values[0], values[-1] = low, high  # exact ends despite rounding
        return cls(values, colors, alphas, range=(low, high))


def _float_array(value: Any, name: str, where: str) -> NDArray[np.float64]:
    try:
        return np.ascontiguousarray(np.asarray(value, dtype=np.float64))
    except (TypeError, ValueError):
        raise GeometryError(f"{where}: {name} = {describe(value)} is not numeric; expected numbers") from None


def _direction(value: Any, where: str) -> NDArray[np.float64]:
    if value is None:
        return np.eye(3)
    matrix = _float_array(value, "direction", where)
    if matrix.shape != (3, 3) or not np.isfinite(matrix).all():
        raise GeometryError(f"{where}: direction = {describe(value)} is not a finite (3, 3) matrix; give the "
                            "grid axes' unit directions as columns (default identity)")  # fmt: skip
    if not abs(np.linalg.det(matrix)) > 1e-12:
        raise GeometryError(f"{where}: direction = {describe(value)} is singular; its columns must be independent")
    return matrix


class Volume:
    """A 3D scalar grid placed in model coordinates: ``Volume(data, spacing=(1, 1, 1), origin=(0, 0, 0))``.

    ``data[i, j, k]`` is the value at $origin + direction · ((i, j, k) ⊙ spacing)$: axis 0 along x, axis 1
    along y, axis 2 along z for the default identity `direction`.

    Parameters
    ----------
    data : (nx, ny, nz) array_like
        Finite real values, at least 2 points per axis. Stored as a read-only float32 copy (the kernels' type).
    spacing : (3,) array_like
        Distance between neighbouring grid points along each axis, finite and > 0 (model units).
    origin : (3,) array_like
        Model position of ``data[0, 0, 0]``.
    direction : (3, 3) array_like, optional
        Columns: the model directions of the grid axes (ITK's direction cosines; from a NIfTI affine). Default
        identity.

    Raises
    ------
    GeometryError
        Data not 3D or with an axis shorter than 2, not numeric, NaN or infinite voxels (the first one is named;
        NaN has no place in a transfer function or a gradient: replace it, e.g. ``np.nan_to_num(data, nan=v)``),
        non-finite or non-positive spacing, a singular direction, data over the memory budget.

    References
    ----------
    [HB 15] "Visualization of Data Sets"; ITK "Image" (origin, spacing, direction).
    """

    def __init__(self, data: ArrayLike, spacing: ArrayLike = (1.0, 1.0, 1.0), origin: ArrayLike = (0.0, 0.0, 0.0),
                 *, direction: ArrayLike | None = None) -> None:  # fmt: skip
        where = "Volume"
        if isinstance(data, _Owned):  # a float32 array Volume.load has just read: kept, not copied
            array = data.array
        else:
            if isinstance(data, np.ndarray):
                check_memory(volume_bytes(data.shape), where=where, cause=f"data of shape {data.shape}",
                             error=GeometryError)  # fmt: skip
            try:
                array = np.array(data, dtype=np.float32, order="C")
            except (TypeError, ValueError):
                raise GeometryError(f"{where}: data = {describe(data)} is not numeric; expected a 3D array of "
                                    "numbers") from None  # fmt: skip
        if array.ndim != 3:
            raise GeometryError(f"{where}: data has shape {array.shape} ({array.ndim}D); expected a 3D array "
                                "(nx, ny, nz)")  # fmt: skip
        if min(array.shape) < 2:
            raise GeometryError(f"{where}: data has shape {array.shape}; every axis needs at least 2 grid points")
        _check_finite(array, where)
        self.spacing = read_only(as_vector3(spacing, "spacing", where=where, error=GeometryError))
        if not (self.spacing > 0.0).all():
            raise GeometryError(f"{where}: spacing = {describe(self.spacing)} is not positive; give three "
                                "distances > 0")  # fmt: skip
        self.origin = read_only(as_vector3(origin, "origin", where=where, error=GeometryError))
        self.direction = read_only(_direction(direction, where))
        array.flags.writeable = False
        self.data = array

    def __repr__(self) -> str:
        spacing, origin = tuple(self.spacing.tolist()), tuple(self.origin.tolist())
        return f"Volume(shape={self.shape}, spacing={spacing}, origin={origin})"

    @property
    def shape(self) -> tuple[int, int, int]:
        """(nx, ny, nz), grid points per axis."""
        return self.data.shape  # type: ignore[return-value]

    @cached_property
    def model_from_grid(self) -> Matrix4:
        """4x4: grid index (i, j, k) → model point $origin + direction · ((i, j, k) ⊙ spacing)$."""
        matrix = np.eye(4)
        matrix[:3, :3] = self.direction * self.spacing
        matrix[:3, 3] = self.origin
        return read_only(matrix)

    @cached_property
    def value_range(self) -> tuple[float, float]:
        """(min, max) of the data."""
        return float(self.data.min()), float(self.data.max())

    @cached_property
    def bounds(self) -> NDArray[np.float64]:
        """(2, 3): model-space min and max corner of the box of the grid (the hull of its 8 corners)."""
        corners = np.array([[i, j, k] for i in (0, 1) for j in (0, 1) for k in (0, 1)], dtype=np.float64)
        corners *= np.array(self.shape, dtype=np.float64) - 1.0
        model = corners @ self.model_from_grid[:3, :3].T + self.model_from_grid[:3, 3]
        return read_only(np.array([model.min(axis=0), model.max(axis=0)]))

    @property
    def unit_distance(self) -> float:
        """Δ₀, the distance an opacity of the transfer function refers to: the smallest spacing (model units)."""
        return float(self.spacing.min())

    # --- sources ------------------------------------------------------------------------------------------

    @classmethod
    def load(cls, path: str | os.PathLike) -> Volume:
        """A volume from a ``.npy`` file (spacing 1, origin 0) or a NIfTI ``.nii`` / ``.nii.gz`` file.

        NIfTI: ``data[i, j, k]`` lies at $affine · (i, j, k, 1)$ (the file's voxel-to-world affine; sform or
        qform as nibabel chooses), split into spacing (column lengths), direction (unit columns) and origin.
        Needs nibabel (``pip install 'frustum[nifti]'``). A 4D file keeps its first volume only if the extra
        axes have length 1.
        """
        where = "Volume.load"
        name = os.fspath(path)
        lower = name.lower()
        if not os.path.isfile(name):
            raise GeometryError(f"{where}: path = {name!r} is not a file; give an existing .npy, .nii or .nii.gz")
        if lower.endswith(".npy"):
            try:
                array = _read_npy(name, where)
            except (ValueError, OSError) as error:
                raise GeometryError(f"{where}: path = {name!r} is not a readable .npy array ({error})") from None
            return cls(_Owned(array) if array.dtype == np.float32 and array.flags.writeable else array)
        if lower.endswith((".nii", ".nii.gz")):
            try:
                import nibabel
            except ImportError:
                raise GeometryError(f"{where}: path = {name!r} is NIfTI, which needs nibabel; "
                                    "pip install 'frustum[nifti]'") from None  # fmt: skip
            try:
                image = nibabel.load(name)
                data = np.asanyarray(image.dataobj)
            except Exception as error:  # nibabel raises many types for broken files
                raise GeometryError(f"{where}: path = {name!r} is not a readable NIfTI file ({error})") from None
            if data.ndim > 3 and all(n == 1 for n in data.shape[3:]):
                data = data.reshape(data.shape[:3])
            affine = np.asarray(image.affine, dtype=np.float64)
            spacing = np.linalg.norm(affine[:3, :3], axis=0)
            if not (spacing > 0.0).all():
                raise GeometryError(f"{where}: path = {name!r} has an affine with a zero column; the file's "
                                    "voxel-to-world map must be invertible")  # fmt: skip
            return cls(data, spacing, affine[:3, 3], direction=affine[:3, :3] / spacing)
        raise GeometryError(f"{where}: path = {name!r} has an unknown suffix; expected .npy, .nii or .nii.gz")

    @classmethod
    def from_function(cls, function: Callable[[NDArray], ArrayLike], bounds: ArrayLike, shape: Any) -> Volume:
        """Sample an implicit function on a regular grid over the model box $bounds = (min, max)$.

        ``function(points)`` takes (N, 3) model points and returns (N,) values, as
        ``quadrics.sphere_implicit`` or ``superellipsoid_implicit`` do; ``shape`` (nx, ny, nz) grid points,
        each >= 2, with $data[i, j, k] = function(min + (i, j, k) ⊙ (max − min) / (shape − 1))$.
        """
        where = "Volume.from_function"
        low, high, counts = _grid(bounds, shape, where)
        points = _grid_points(low, high, counts)
        try:
            values = np.asarray(function(points), dtype=np.float64)
        except (TypeError, ValueError) as error:
            raise GeometryError(f"{where}: function = {describe(function)} failed on (N, 3) points ({error}); "
                                "give a function of (N, 3) points returning (N,) values") from None  # fmt: skip
        if values.shape != (points.shape[0],):
            raise GeometryError(f"{where}: function returned shape {values.shape}; expected ({points.shape[0]},), "
                                "one value per point")  # fmt: skip
        return cls(values.reshape(counts), (high - low) / (np.array(counts) - 1.0), low)

    # --- sampling -----------------------------------------------------------------------------------------

    def sample(self, points: ArrayLike, outside: float = 0.0) -> NDArray[np.float64]:
        """Trilinear values at model points (N, 3); `outside` where a point lies outside the grid's box."""
        from scipy.ndimage import map_coordinates

        where = "Volume.sample"
        rows = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        if not np.isfinite(rows).all():
            raise GeometryError(f"{where}: points are not all finite; give finite model coordinates")
        grid = (rows - self.model_from_grid[:3, 3]) @ np.linalg.inv(self.model_from_grid[:3, :3]).T
        limit = np.array(self.shape, dtype=np.float64) - 1.0
        inside = ((grid >= -1e-9) & (grid <= limit + 1e-9)).all(axis=1)
        grid = np.clip(grid, 0.0, limit)
        values = map_coordinates(self.data.astype(np.float64), grid.T, order=1, mode="nearest")
        return np.where(inside, values, float(outside))

    def slice(self, axis: Any = None, position: Any = None, *, point: ArrayLike | None = None,
              normal: ArrayLike | None = None, up: ArrayLike | None = None, size: Any = None,
              resolution: Any = None, outside: float = 0.0) -> NDArray[np.float64]:  # fmt: skip
        """A planar slice of the volume as a 2D image of trilinear values.

        Axis-aligned: ``slice(axis, position)`` with axis 0/1/2 (or "x"/"y"/"z") and a model coordinate along
        it (default the middle of the box) returns the (n_a, n_b) image over the other two model axes in
        order (for axis "z": ``image[a, b]`` at x_a, y_b over the box's x and y extent, at the grid's
        resolution along them). Oblique: ``slice(point=p, normal=n, size=(w, h), resolution=(nu, nv))``
        samples the plane through p with normal n on an (nu, nv) grid $image[a, b] = p + (a/(nu−1) − ½)·w·u
        + (b/(nv−1) − ½)·h·v$, where v is `up` (default the model axis least parallel to n) made
        perpendicular to n and u = v × n. Points outside the box get `outside`.
        """
        where = "Volume.slice"
        low, high = self.bounds
        if point is None and normal is None:
            names = {"x": 0, "y": 1, "z": 2, 0: 0, 1: 1, 2: 2}
            if isinstance(axis, bool) or not isinstance(axis, str | int) or axis not in names:
                raise GeometryError(f"{where}: axis = {describe(axis)} is not an axis; give 0, 1, 2 or 'x', 'y', 'z' "
                                    "(or point= and normal= for an oblique slice)")  # fmt: skip
            a = names[axis]
            value = 0.5 * (low[a] + high[a]) if position is None else as_scalar(position, "position", where=where,
                                                                                  error=GeometryError)  # fmt: skip
            others = [b for b in range(3) if b != a]
            counts = [self.shape[b] for b in others]
            axes_ = [np.linspace(low[b], high[b], n) for b, n in zip(others, counts, strict=True)]
            grid_a, grid_b = np.meshgrid(*axes_, indexing="ij")
            points = np.empty((grid_a.size, 3))
            points[:, a] = value
            points[:, others[0]], points[:, others[1]] = grid_a.ravel(), grid_b.ravel()
            return self.sample(points, outside).reshape(counts)
        if point is None or normal is None or axis is not None or position is not None:
            raise GeometryError(f"{where}: give either axis (and position) or both point and normal, not a mix")
        p = as_vector3(point, "point", where=where, error=GeometryError)
        n = as_vector3(normal, "normal", where=where, error=GeometryError)
        if not np.linalg.norm(n) > 0.0:
            raise GeometryError(f"{where}: normal = {describe(n)} has zero length; give a nonzero normal")
        n = n / np.linalg.norm(n)
        v = np.eye(3)[int(np.argmin(np.abs(n)))] if up is None else as_vector3(up, "up", where=where,
                                                                               error=GeometryError)  # fmt: skip
        v = v - (v @ n) * n
        if not np.linalg.norm(v) > 1e-12:
            raise GeometryError(f"{where}: up = {describe(up)} is parallel to normal; give an up not along it")
        v /= np.linalg.norm(v)
        u = np.cross(v, n)
        diagonal = float(np.linalg.norm(high - low))
        width, height = (diagonal, diagonal) if size is None else _pair(size, "size", where, float)
        nu, nv = (max(self.shape),) * 2 if resolution is None else _pair(resolution, "resolution", where, int)
        check_memory(nu * nv * 8.0 * 6, where=where, cause=f"resolution = ({nu}, {nv})", error=GeometryError)
        fa = (np.arange(nu) / (nu - 1) - 0.5) * width
        fb = (np.arange(nv) / (nv - 1) - 0.5) * height
        points = p + fa[:, None, None] * u + fb[None, :, None] * v
        return self.sample(points.reshape(-1, 3), outside).reshape(nu, nv)

    # --- isosurfaces --------------------------------------------------------------------------------------

    def isosurface(self, level: float, step: int = 1, *, inside: str = "above") -> Mesh:
        """The surface $value = level$ as a Mesh in model units, by marching cubes (scikit-image).

        ``verts, faces = skimage.measure.marching_cubes(data[::step, ::step, ::step], level,
        spacing=step·spacing)``, then $P = origin + direction · verts$ (the documented coordinate map). The
        winding is made counter-clockwise seen from outside, so normals point out of the region `inside`
        ("above": values above `level` are inside, as dense tissue in CT; "below": values below are inside, as
        a distance field). Vertex normals are the area-weighted face normals.

        Raises
        ------
        GeometryError
            `level` not finite or outside the data's range (no surface), `step` not a positive integer or
            leaving fewer than 2 points per axis, `inside` unknown.

        References
        ----------
        [HB 15] "Visual Representations for Scalar Fields" (isosurfaces); Lorensen & Cline, "Marching cubes",
        SIGGRAPH 1987 (scikit-image implements Lewiner et al. 2003).
        """
        from skimage.measure import marching_cubes

        where = "Volume.isosurface"
        value = as_scalar(level, "level", where=where, error=GeometryError)
        low, high = self.value_range
        if not low < value < high:
            raise GeometryError(f"{where}: level = {value!r} is outside the data's range ({low!r}, {high!r}); "
                                "no surface crosses it")  # fmt: skip
        stride = as_count(step, "step", 1, where=where)
        if min(self.shape) < 2 * stride:
            raise GeometryError(f"{where}: step = {stride} leaves fewer than 2 points along an axis of {self.shape}")
        if inside not in ("above", "below"):
            raise GeometryError(f"{where}: inside = {describe(inside)} is unknown; expected 'above' or 'below'")
        data = np.ascontiguousarray(self.data[::stride, ::stride, ::stride])  # skimage wants a writable buffer
        if not data.flags.writeable:
            data = data.copy()
        check_memory(data.size * 40.0, where=where, cause=f"a grid of {data.shape}", error=GeometryError)
        gradient = "descent" if inside == "above" else "ascent"
        verts, faces, _, _ = marching_cubes(data, value, spacing=tuple(stride * self.spacing),
                                            gradient_direction=gradient)  # fmt: skip
        points = verts.astype(np.float64) @ self.direction.T + self.origin
        faces = faces.astype(np.int64)
        # skimage winds the faces clockwise seen from the side its gradient direction calls outside; the
        # direction matrix may flip handedness too (det < 0)
        if np.linalg.det(self.direction) > 0.0:
            faces = faces[:, [0, 2, 1]]
        return Mesh(points, np.ascontiguousarray(faces))


def _pair(value: Any, name: str, where: str, kind: type) -> tuple:
    try:
        first, second = value
    except (TypeError, ValueError):
        raise GeometryError(f"{where}: {name} = {describe(value)} is not a pair; give two numbers") from None
    if kind is int:
        return (as_count(first, name, 2, where=where), as_count(second, name, 2, where=where))
    pair = (as_scalar(first, name, where=where, error=GeometryError), as_scalar(second, name, where=where,
                                                                                 error=GeometryError))  # fmt: skip
    if not (pair[0] > 0 and pair[1] > 0):
        raise GeometryError(f"{where}: {name} = {describe(value)} is not positive; give two sizes > 0")
    return pair


def _grid(bounds: Any, shape: Any, where: str) -> tuple[NDArray, NDArray, tuple[int, int, int]]:
    try:
        low_value, high_value = bounds
    except (TypeError, ValueError):
        raise GeometryError(f"{where}: bounds = {describe(bounds)} is not (min, max); give two corners") from None
    low = as_vector3(low_value, "bounds min", where=where, error=GeometryError)
    high = as_vector3(high_value, "bounds max", where=where, error=GeometryError)
    if not (low < high).all():
        raise GeometryError(f"{where}: bounds = {describe(low)}, {describe(high)} is empty; need min < max per axis")
    if isinstance(shape, int | np.integer) and not isinstance(shape, bool):
        shape = (shape, shape, shape)
    try:
        counts = tuple(as_count(n, "shape", 2, where=where) for n in shape)
    except TypeError:
        raise GeometryError(f"{where}: shape = {describe(shape)} is not three counts; give (nx, ny, nz)") from None
    if len(counts) != 3:
        raise GeometryError(f"{where}: shape = {describe(shape)} is not three counts; give (nx, ny, nz)")
    total = float(np.prod(counts))
    check_memory(total * 8.0 * 5, where=where, cause=f"shape = {counts}", error=GeometryError)
    return low, high, counts  # type: ignore[return-value]


def _grid_points(low: NDArray, high: NDArray, counts: tuple[int, int, int]) -> NDArray[np.float64]:
    """(nx·ny·nz, 3) grid points in C order (k fastest)."""
    axes = [np.linspace(low[a], high[a], counts[a]) for a in range(3)]
    x, y, z = np.meshgrid(*axes, indexing="ij")
    return np.column_stack([x.ravel(), y.ravel(), z.ravel()])


def blobby_volume(centers: ArrayLike, radii: ArrayLike, shape: Any = 64, *, strengths: ArrayLike | None = None,
                  bounds: ArrayLike | None = None) -> Volume:  # fmt: skip
    """Blobby objects (metaballs): $f(P) = Σ_k b_k · exp(−a_k·r_k²)$ with $a_k = 1/R_k²$ [HB 13] "Blobby Objects".

    `centers` (K, 3), `radii` (K,) R_k > 0, `strengths` (K,) b_k (default 1). The field is sampled on `shape`
    grid points over `bounds` (default the centres' box grown by 2·R). A blobby surface is its isosurface
    $f = T$ (e.g. T = 0.5): ``volume.isosurface(0.5)`` or the renderer's isosurface mode.
    """
    where = "blobby_volume"
    c = _float_array(centers, "centers", where).reshape(-1, 3) if np.size(centers) % 3 == 0 else None
    if c is None or c.shape[0] == 0 or not np.isfinite(c).all():
        raise GeometryError(f"{where}: centers = {describe(centers)} is not (K, 3) finite points, K >= 1")
    r = np.broadcast_to(_float_array(radii, "radii", where), (c.shape[0],)) if np.size(radii) in (1, c.shape[0]) \
        else None  # fmt: skip
    if r is None or not (np.isfinite(r) & (r > 0)).all():
        raise GeometryError(f"{where}: radii = {describe(radii)} is not one or {c.shape[0]} finite radii > 0")
    b = np.ones(c.shape[0]) if strengths is None else _float_array(strengths, "strengths", where)
    if b.shape != (c.shape[0],) or not np.isfinite(b).all():
        raise GeometryError(f"{where}: strengths = {describe(strengths)} is not {c.shape[0]} finite numbers")
    if bounds is None:
        bounds = (c.min(axis=0) - 2 * r.max(), c.max(axis=0) + 2 * r.max())
    low, high, counts = _grid(bounds, shape, where)
    check_operations(float(np.prod(counts)) * c.shape[0], where=where, cause=f"{c.shape[0]} blobs on {counts}",
                     error=GeometryError)  # fmt: skip
    points = _grid_points(low, high, counts)
    field = np.zeros(points.shape[0])
    for center, radius, strength in zip(c, r, b, strict=True):
        d2 = ((points - center) ** 2).sum(axis=1)
        field += strength * np.exp(-d2 / (radius * radius))
    return Volume(field.reshape(counts), (high - low) / (np.array(counts) - 1.0), low)


def fbm_cloud(shape: Any = 64, *, octaves: int = 5, hurst: float = 0.5, frequency: float = 4.0, seed: int = 0,
              size: float = 1.0) -> Volume:  # fmt: skip
    """A fractional-Brownian-motion cloud: $f(P) = Σ_o 2^(−H·o) · noise(2^o · frequency · P)$, rescaled to [0, 1].

    `noise` is trilinear value noise on an integer lattice of seeded uniform values (periodic), so each octave
    doubles the frequency and scales the amplitude by 2^(−H) (H = `hurst`, 0 < H <= 1; spectral exponent
    β = 2H + 1 as for fBm terrain). The volume spans the cube [0, size]³.

    References
    ----------
    [HB 15] "Fractal-Geometry Methods" (fractional Brownian motion); Perlin, "An image synthesizer", 1985.
    """
    where = "fbm_cloud"
    counts = _grid(((0, 0, 0), (1, 1, 1)), shape, where)[2]
    count = as_count(octaves, "octaves", 1, where=where)
    h = as_scalar(hurst, "hurst", where=where, error=GeometryError)
    if not 0.0 < h <= 1.0:
        raise GeometryError(f"{where}: hurst = {h!r} is outside (0, 1]; give a Hurst exponent in (0, 1]")
    base = as_scalar(frequency, "frequency", where=where, error=GeometryError)
    if not 1.0 <= base <= 256.0:
        raise GeometryError(f"{where}: frequency = {base!r} is outside [1, 256]; give lattice cells across the cube")
    extent = as_scalar(size, "size", where=where, error=GeometryError)
    if not extent > 0.0:
        raise GeometryError(f"{where}: size = {extent!r} is not positive; give the cube's edge length > 0")
    if isinstance(seed, bool) or not isinstance(seed, int | np.integer):
        raise GeometryError(f"{where}: seed = {describe(seed)} is not an integer; give e.g. seed=0")
    check_operations(float(np.prod(counts)) * count * 8, where=where, cause=f"shape = {counts}, octaves = {count}",
                     error=GeometryError)  # fmt: skip
    rng = np.random.default_rng(int(seed))
    axes = [np.linspace(0.0, 1.0, n) for n in counts]
    field = np.zeros(counts)
    for octave in range(count):
        cells = round(base * 2**octave)
        lattice = rng.random((cells, cells, cells))
        coords = [a * cells for a in axes]
        index = [np.floor(c).astype(np.int64) for c in coords]
        frac = [c - i for c, i in zip(coords, index, strict=True)]
        i0 = [i % cells for i in index]
        i1 = [(i + 1) % cells for i in index]
        fx, fy, fz = np.meshgrid(*frac, indexing="ij", sparse=True)
        noise = np.zeros(counts)
        for dx, ix in ((0, i0[0]), (1, i1[0])):
            wx = fx if dx else 1.0 - fx
            for dy, iy in ((0, i0[1]), (1, i1[1])):
                wy = fy if dy else 1.0 - fy
                for dz, iz in ((0, i0[2]), (1, i1[2])):
                    wz = fz if dz else 1.0 - fz
                    noise += wx * wy * wz * lattice[np.ix_(ix, iy, iz)]
        field += 2.0 ** (-h * octave) * noise
    field -= field.min()
    field /= max(float(field.max()), 1e-300)
    return Volume(field, extent / (np.array(counts) - 1.0))


def quaternion_julia_volume(c: ArrayLike = (-0.2, 0.6, 0.2, 0.0), *, resolution: int = 64, bound: float = 1.5,
                            slice_w: float = 0.0, max_iter: int = 12) -> Volume:  # fmt: skip
    """The smooth escape-time field of the quaternion Julia set (``escape_time.quaternion_julia``) as a Volume
    over the cube [−bound, bound]³; inside points have the value `max_iter`, so $isosurface(max_iter − 0.5)$
    or a transfer function rising near `max_iter` shows the set."""
    from frustum.geometry.escape_time import quaternion_julia

    field = quaternion_julia(c, resolution=resolution, bound=bound, slice_w=slice_w, max_iter=max_iter)
    step = 2.0 * float(bound) / (field.shape[0] - 1)
    return Volume(field, (step, step, step), (-float(bound),) * 3)


VOLUME_MODES = ("composite", "mip", "minip", "average", "isosurface")
"""How a placed volume is drawn: front-to-back compositing, maximum / minimum intensity projection, the mean
along the ray, or the first crossing of a level (shaded)."""
VOLUME_SAMPLINGS = ("entry", "near")
"""Where a ray's samples lie (``Scene.add_volume(sampling=...)``): the middles of segments Δ from the ray's entry
into the volume, or the whole multiples of Δ from its point on the near plane."""


# (x0, y0, z0, a, b, c, rotation about z in degrees, added density): ellipsoids after the 3D Shepp–Logan head
# phantom of Kak & Slaney, with the higher contrasts of Toft's "modified" 2D version
_HEAD_ELLIPSOIDS = (
    (0.0, 0.0, 0.0, 0.69, 0.92, 0.9, 0.0, 1.0),
    (0.0, 0.0, 0.0, 0.6624, 0.874, 0.88, 0.0, -0.8),
    (-0.22, 0.0, -0.25, 0.41, 0.16, 0.21, 108.0, -0.2),
    (0.22, 0.0, -0.25, 0.31, 0.11, 0.22, 72.0, -0.2),
    (0.0, 0.35, -0.25, 0.21, 0.25, 0.5, 0.0, 0.1),
    (0.0, 0.1, -0.25, 0.046, 0.046, 0.046, 0.0, 0.1),
    (-0.08, -0.65, -0.25, 0.046, 0.023, 0.02, 0.0, 0.1),
    (0.06, -0.065, -0.25, 0.046, 0.023, 0.02, 90.0, 0.1),
    (0.06, -0.105, 0.625, 0.56, 0.04, 0.1, 90.0, 0.1),
    (0.0, 0.1, 0.625, 0.056, 0.056, 0.1, 0.0, -0.1),
)


def head_phantom(shape: Any = 64) -> Volume:
    """A synthetic CT-like head phantom over the cube [−1, 1]³: a sum of constant-density ellipsoids.

    The ellipsoids follow the 3D Shepp–Logan phantom (Kak & Slaney, "Principles of Computerized Tomographic
    Imaging", 1988, table 3.2) with the contrasts of the modified phantom (skull 1, brain 0.2, ventricles 0,
    small features 0.3), for pictures and tests, not as a reference standard. Values lie in [0, 1]; each
    ellipsoid's edge ramps linearly over about one voxel (a band-limited phantom, as a scanner would see it).
    """
    where = "head_phantom"
    low, high, counts = _grid(((-1, -1, -1), (1, 1, 1)), shape, where)
    axes = [np.linspace(low[a], high[a], counts[a]) for a in range(3)]
    y, z = np.meshgrid(axes[1], axes[2], indexing="ij")  # one x-slice at a time: memory of a few slices
    field = np.zeros(counts, dtype=np.float32)
    voxel = 2.0 / (min(counts) - 1)
    for i, x in enumerate(axes[0]):
        for x0, y0, z0, a, b, c, degrees, density in _HEAD_ELLIPSOIDS:
            angle = math.radians(degrees)
            dx, dy, dz = x - x0, y - y0, z - z0
            u = dx * math.cos(angle) + dy * math.sin(angle)
            v = -dx * math.sin(angle) + dy * math.cos(angle)
            radius = np.sqrt((u / a) ** 2 + (v / b) ** 2 + (dz / c) ** 2)
            # edges ramp over one voxel (distance ≈ (1 − radius)·smallest semi-axis): no staircase in the gradient
            field[i] += density * np.clip(0.5 + (1.0 - radius) * min(a, b, c) / voxel, 0.0, 1.0)
    return Volume(np.clip(field, 0.0, 1.0), (high - low) / (np.array(counts) - 1.0), low)
