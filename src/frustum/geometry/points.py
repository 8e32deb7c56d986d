"""Point clouds: ``PointCloud(points, colors=None, normals=None, radii=None)`` and the readers of point files.

A ``PointCloud`` is frozen like ``Mesh``: its arrays are read-only copies, derived data (bounds) is cached, and
``transformed`` returns a new cloud. ``load_points`` reads

- PLY files whose ``vertex`` element has x, y, z (and optionally nx, ny, nz, red, green, blue[, alpha] as uchar
  0–255 or float 0–1, and a ``radius``) and no faces, ASCII or binary (a PLY *with* faces is read as its
  vertices);
- text files: ``.xyz`` / ``.txt`` / ``.csv`` rows ``x y z [r g b]`` or ``x y z [nx ny nz] [r g b]``, and Leica
  ``.pts`` (a first line holding the count, then ``x y z intensity r g b``): colours above 1 are read as 0–255;
- a COLMAP model's ``points3D.txt`` (or the folder holding it, or ``points3D.bin`` through pycolmap);

``PointCloud.from_trimesh`` takes a ``trimesh.PointCloud`` and ``PointCloud.from_colmap`` a
``pycolmap.Reconstruction``. Every failure is a ``GeometryError`` naming the path and what is wrong; the memory
budget (``frustum.budgets``) is checked from the file's size (or its announced count) before anything is read.

References
----------
Gross & Pfister, "Point-Based Graphics" (2007), ch. 1 (point clouds, surfels); Schönberger & Frahm 2016
(COLMAP's sparse model: ``points3D.txt`` rows ``POINT3D_ID X Y Z R G B ERROR TRACK[]``).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import Any, ClassVar, NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import Points, as_matrix, as_points, describe, read_only
from frustum.budgets import check_memory, format_bytes
from frustum.errors import GeometryError
from frustum.geometry.readers import ply_header
from frustum.transforms import apply, apply_to_normals

__all__ = [
    "DEFAULT_POINT_SIZE", "POINT_STYLES", "POINT_SUFFIXES", "PointCloud", "PointStyle", "load_points",
    "point_file_kind", "point_style", "read_ply_header", "read_ply_vertices",
]  # fmt: skip

POINT_SUFFIXES = (".ply", ".xyz", ".txt", ".csv", ".pts")
"""File suffixes ``load_points`` reads (and a COLMAP model folder)."""

_BYTES_PER_POINT = 160
"""Peak memory per point while reading (file columns as float64, points, colours, normals, radii, temporaries)."""
_TEXT_BYTES_PER_FILE_BYTE = 24
"""Peak memory per byte of a text point file (the split words and their float64 table)."""


@dataclass(frozen=True, eq=False, repr=False)
class PointCloud:
    """N points in model coordinates, with optional per-point colours, normals and radii.

    Parameters
    ----------
    points : (N, 3) array_like
        Finite model coordinates, stored float64 (float32 input stays float32: half the memory, exact in float64).
    colors : (N, 3) or (N, 4) array_like, optional
        RGB(A) per point in [0, 1]; a uint8 array is divided by 255. Stored float64.
    normals : (N, 3) array_like, optional
        Per-point normals (finite, nonzero), normalized on construction: the ``"surfel"`` style's disk
        orientation and the lit styles' shading normal.
    radii : (N,) array_like or a number, optional
        World radius of each point (``"sphere"`` and ``"surfel"`` styles), > 0.

    Raises
    ------
    GeometryError
        Wrong shapes, non-finite values, colours outside [0, 1], zero normals, radii <= 0.
    """

    scene_geometry: ClassVar[str] = "points"
    """What a scene places (``scene.graph`` checks this mark and need not import this module)."""

    points: Points
    colors: NDArray[np.float64] | None = None
    normals: Points | None = None
    radii: NDArray[np.float64] | None = None

    def __post_init__(self) -> None:
        where = "PointCloud"
        points = as_points(self.points, "points", where=where, keep_float32=True)
        count = points.shape[0]
        object.__setattr__(self, "points", read_only(points))
        if self.colors is not None:
            object.__setattr__(self, "colors", read_only(_as_colors(self.colors, count, where)))
        if self.normals is not None:
            normals = as_points(self.normals, "normals", where=where)
            if normals.shape[0] != count:
                raise GeometryError(f"{where}: normals has {normals.shape[0]} rows; expected one per point ({count})")
            lengths = np.sqrt((normals * normals).sum(axis=1))
            zero = np.flatnonzero(lengths == 0.0)
            if zero.size:
                raise GeometryError(f"{where}: normals[{int(zero[0])}] is zero; give nonzero normals (or none)")
            object.__setattr__(self, "normals", read_only(normals / lengths[:, None]))
        if self.radii is not None:
            object.__setattr__(self, "radii", read_only(_as_radii(self.radii, count, where)))

    def __repr__(self) -> str:
        extras = "".join(f", {name}" for name in ("colors", "normals", "radii") if getattr(self, name) is not None)
        return f"PointCloud(point_count={self.point_count}{extras})"

    @property
    def point_count(self) -> int:
        """N, the number of points."""
        return int(self.points.shape[0])

    @cached_property
    def bounds(self) -> NDArray[np.float64]:
        """(2, 3) the corners (min, max) of the axis-aligned box around the points (radii not included); zeros if
        empty."""
        if self.point_count == 0:
            return read_only(np.zeros((2, 3)))
        return read_only(np.array([self.points.min(axis=0), self.points.max(axis=0)], dtype=np.float64))

    def transformed(self, matrix: ArrayLike) -> PointCloud:
        """The cloud with points mapped by the 4x4 `matrix` (``apply``), normals by its inverse transpose; radii
        scaled by the cube root of |det| of its 3x3 part (exact for similarities)."""
        m = as_matrix(matrix, where="PointCloud.transformed", error=GeometryError)
        normals = None if self.normals is None else apply_to_normals(m, self.normals)
        radii = None if self.radii is None else self.radii * abs(float(np.linalg.det(m[:3, :3]))) ** (1.0 / 3.0)
        return PointCloud(apply(m, np.asarray(self.points, dtype=np.float64)), self.colors, normals, radii)

    @classmethod
    def from_trimesh(cls, cloud: Any) -> PointCloud:
        """A ``trimesh.PointCloud`` (its ``vertices`` and, where set, ``colors`` as uint8 RGBA) as a PointCloud."""
        vertices = getattr(cloud, "vertices", None)
        faces = getattr(cloud, "faces", None)
        if vertices is None or (faces is not None and len(faces) > 0):
            raise GeometryError(f"PointCloud.from_trimesh: cloud = {describe(cloud)} is not a trimesh.PointCloud")
        colors = None
        raw = getattr(cloud, "colors", None)
        if raw is not None and len(raw) == len(vertices):
            colors = np.asarray(raw)
        return cls(np.asarray(vertices, dtype=np.float64), colors)

    @classmethod
    def from_colmap(cls, reconstruction: Any) -> PointCloud:
        """The 3-D points of a ``pycolmap.Reconstruction`` (``points3D``: xyz and uint8 colour), in point-id order."""
        points3d = getattr(reconstruction, "points3D", None)
        if points3d is None:
            raise GeometryError(
                f"PointCloud.from_colmap: reconstruction = {describe(reconstruction)} has no points3D; give a "
                "pycolmap.Reconstruction (or load_points(folder) for a model folder)"
            )
        ids = sorted(points3d.keys()) if hasattr(points3d, "keys") else list(range(len(points3d)))
        xyz = np.array([np.asarray(points3d[i].xyz, dtype=np.float64) for i in ids]).reshape(-1, 3)
        rgb = np.array([np.asarray(points3d[i].color, dtype=np.uint8) for i in ids]).reshape(-1, 3)
        return cls(xyz, rgb)


def _as_colors(value: ArrayLike, count: int, where: str) -> NDArray[np.float64]:
    raw = np.asarray(value)
    colors = raw.astype(np.float64) / 255.0 if raw.dtype == np.uint8 else np.asarray(raw, dtype=np.float64)
    if colors.ndim != 2 or colors.shape[1] not in (3, 4) or colors.shape[0] != count:
        raise GeometryError(f"{where}: colors has shape {colors.shape}; expected ({count}, 3) or ({count}, 4) RGB(A)")
    bad = np.flatnonzero(~((colors >= 0.0) & (colors <= 1.0)).all(axis=1))
    if bad.size:
        i = int(bad[0])
        raise GeometryError(f"{where}: colors[{i}] = {describe(colors[i])} is outside [0, 1]; give floats in [0, 1]"
                            " or uint8")  # fmt: skip
    return np.ascontiguousarray(colors)


def _as_radii(value: ArrayLike, count: int, where: str) -> NDArray[np.float64]:
    try:
        radii = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise GeometryError(f"{where}: radii = {describe(value)} is not numeric; give one radius or N") from None
    if radii.ndim == 0:
        radii = np.full(count, float(radii))
    if radii.shape != (count,):
        raise GeometryError(f"{where}: radii has shape {radii.shape}; expected ({count},) or one number")
    bad = np.flatnonzero(~(np.isfinite(radii) & (radii > 0.0)))
    if bad.size:
        i = int(bad[0])
        raise GeometryError(f"{where}: radii[{i}] = {radii[i]!r} is not a positive finite number")
    return np.ascontiguousarray(radii)


POINT_STYLES = ("square", "disk", "sphere", "surfel")
"""How a placed PointCloud is drawn (``frustum.render.points``): squares or disks of a size in pixels (or of a world
radius), sphere impostors or oriented disks (surfels, from the normals) of a world radius."""
DEFAULT_POINT_SIZE = 2.0
"""Pixels on a side of a ``"square"`` or ``"disk"`` point when neither `point_size` nor a radius is given."""


class PointStyle(NamedTuple):
    """How a placed cloud is drawn: ``style`` (``POINT_STYLES``; ``"splats"`` for ``GaussianSplats``),
    ``point_size`` pixels (squares and disks; None: sized by the world ``radius``), ``radius`` world units (one for
    all points; None: the cloud's ``radii``)."""

    style: str
    point_size: float | None
    radius: float | None


def point_style(geometry: Any, style: Any, point_size: Any, radius: Any, where: str) -> PointStyle:
    """The checked drawing style of `geometry` in a scene (``Scene.add``): defaults, names and ranges.

    Defaults: ``"square"``; squares and disks of ``DEFAULT_POINT_SIZE`` pixels unless a `radius` is given (or the
    cloud has radii and no `point_size` is given); spheres and surfels of the cloud's radii, or `radius`, or half
    the mean spacing $diagonal / N^{1/3} / 2$ when neither is given.
    """
    from frustum._arrays import as_scalar

    splats = type(geometry).__name__ == "GaussianSplats"
    if not isinstance(geometry, PointCloud) and not splats:
        raise GeometryError(f"{where}: style, point_size and radius are for a PointCloud; got {describe(geometry)}")
    if splats:
        if (style not in (None, "splats")) or point_size is not None or radius is not None:
            raise GeometryError(f"{where}: GaussianSplats are drawn by their own covariances; give no style "
                                f"({describe(style)}), point_size or radius")  # fmt: skip
        return PointStyle("splats", None, None)
    name = "square" if style is None else style
    if not isinstance(name, str) or name not in POINT_STYLES:
        raise GeometryError(f"{where}: style = {describe(style)} is unknown; expected one of "
                            + ", ".join(repr(s) for s in POINT_STYLES))  # fmt: skip
    size = None
    if point_size is not None:
        size = as_scalar(point_size, "point_size", where=where, error=GeometryError)
        if not 0.0 < size <= 256.0:
            raise GeometryError(f"{where}: point_size = {size!r} is outside (0, 256]; give a size in pixels")
        if name in ("sphere", "surfel"):
            raise GeometryError(f"{where}: point_size is for 'square' and 'disk'; style {name!r} takes radius "
                                "(world units)")  # fmt: skip
    world = None
    if radius is not None:
        world = as_scalar(radius, "radius", where=where, error=GeometryError)
        if not world > 0.0:
            raise GeometryError(f"{where}: radius = {world!r} is not positive; give a world radius > 0")
        if size is not None:
            raise GeometryError(f"{where}: give point_size (pixels) or radius (world units), not both")
    if name == "surfel" and geometry.normals is None:
        raise GeometryError(f"{where}: style 'surfel' orients each disk by its normal; this cloud has no normals "
                            "(give PointCloud(..., normals=...) or use 'disk' or 'sphere')")  # fmt: skip
    if name in ("square", "disk") and size is None and world is None and geometry.radii is None:
        size = DEFAULT_POINT_SIZE
    if name in ("sphere", "surfel") and world is None and geometry.radii is None:
        low, high = geometry.bounds
        diagonal = float(np.linalg.norm(high - low))
        world = 0.5 * diagonal / max(geometry.point_count, 1) ** (1.0 / 3.0) if diagonal > 0 else 0.5
    return PointStyle(name, size, world)


def point_file_kind(path: str | Path) -> str | None:
    """What a file holds for the commands that take "a model file": ``"splats"`` (a PLY with the 3DGS vertex
    properties), ``"points"`` (a PLY without faces, a text point file, a COLMAP model folder) or None (a mesh file,
    or something unreadable: the mesh loader reports it)."""
    file = Path(path)
    if file.is_dir():
        return "points" if (file / "points3D.txt").is_file() or (file / "points3D.bin").is_file() else None
    suffix = file.suffix.lower()
    if suffix in (".xyz", ".pts", ".csv") or file.name in ("points3D.txt", "points3D.bin"):
        return "points"
    if suffix != ".ply" or not file.is_file():
        return None
    try:
        header = read_ply_header(file, "point_file_kind")
    except (GeometryError, OSError):
        return None
    vertex = header.element("vertex")
    if vertex is None:
        return None
    names = {p[-1] for p in vertex[2]}
    if {"f_dc_0", "opacity", "scale_0", "rot_0"} <= names:
        return "splats"
    face = header.element("face")
    return "points" if face is None or face[1] == 0 else None


# --- files ----------------------------------------------------------------------------------------------------


def load_points(path: str | Path) -> PointCloud:
    """Read a point file (``POINT_SUFFIXES``) or a COLMAP model (folder or ``points3D.txt``/``.bin``) as a cloud.

    Raises
    ------
    GeometryError
        Missing file, unknown suffix (the message lists the supported ones), malformed data, or a file whose
        reading would exceed the memory budget (checked before it is read).
    """
    file = Path(path)
    where = "load_points"
    if file.is_dir():
        if (file / "points3D.txt").is_file():
            file = file / "points3D.txt"
        elif (file / "points3D.bin").is_file():
            return _colmap_binary(file)
        else:
            raise GeometryError(f"{where}: path = {str(path)!r} is a folder without points3D.txt or points3D.bin; "
                                "give a point file or a COLMAP model folder")  # fmt: skip
    if not file.is_file():
        raise GeometryError(f"{where}: path = {str(path)!r} does not exist; give a point file "
                            f"({', '.join(POINT_SUFFIXES)}) or a COLMAP model folder")  # fmt: skip
    if file.name == "points3D.bin":
        return _colmap_binary(file.parent)
    suffix = file.suffix.lower()
    if suffix not in POINT_SUFFIXES:
        raise GeometryError(f"{where}: path = {str(path)!r} has an unknown suffix {suffix!r}; expected one of "
                            f"{', '.join(POINT_SUFFIXES)} or a COLMAP model folder")  # fmt: skip
    if suffix == ".ply":
        return _read_ply(file)
    size = file.stat().st_size
    check_memory(size * _TEXT_BYTES_PER_FILE_BYTE, where=where, cause=f"path = {str(file)!r} ({format_bytes(size)})",
                 error=GeometryError)  # fmt: skip
    if file.name == "points3D.txt":
        return _colmap_text(file)
    return _read_text(file, suffix)


def _read_text(file: Path, suffix: str) -> PointCloud:
    where = "load_points"
    lines = [ln for ln in file.read_text(encoding="utf-8", errors="replace").splitlines()
             if ln.strip() and not ln.lstrip().startswith(("#", "//"))]  # fmt: skip
    if suffix == ".pts" and lines and len(lines[0].split()) == 1:
        lines = lines[1:]  # the count line
    if not lines:
        raise GeometryError(f"{where}: path = {str(file)!r} holds no points; expected rows of x y z [...]")
    text = "\n".join(lines).replace(",", " ")
    try:
        table = np.array(text.split(), dtype=np.float64)
    except ValueError:
        raise GeometryError(f"{where}: path = {str(file)!r} holds a value that is not a number; expected rows of "
                            "numbers x y z [...]") from None  # fmt: skip
    width = len(lines[0].replace(",", " ").split())
    if width < 3 or table.size != width * len(lines):
        raise GeometryError(f"{where}: path = {str(file)!r} has rows of different lengths (first row: {width} "
                            "values); expected the same number of columns (at least x y z) on every row")  # fmt: skip
    table = table.reshape(len(lines), width)
    normals = colors = None
    if suffix == ".pts" and width in (7, 4):  # x y z intensity [r g b]
        colors = table[:, 4:7] if width == 7 else None
    elif width == 6:
        colors = table[:, 3:6]
    elif width == 9:
        normals, colors = table[:, 3:6], table[:, 6:9]
    elif width not in (3,):
        raise GeometryError(f"{where}: path = {str(file)!r} has {width} columns; expected x y z, x y z r g b, "
                            "x y z nx ny nz r g b, or .pts x y z intensity r g b")  # fmt: skip
    if colors is not None and colors.size and colors.max() > 1.0:
        colors = colors / 255.0
    return _cloud(table[:, :3], colors, normals, None, file)


def _cloud(points: Any, colors: Any, normals: Any, radii: Any, file: Path) -> PointCloud:
    try:
        return PointCloud(points, colors, normals, radii)
    except GeometryError as error:
        raise GeometryError(f"load_points: path = {str(file)!r} holds invalid points ({error})") from None


def _colmap_text(file: Path) -> PointCloud:
    """``points3D.txt``: ``POINT3D_ID X Y Z R G B ERROR TRACK[] as (IMAGE_ID, POINT2D_IDX)``, sorted by id."""
    rows = []
    for number, line in enumerate(file.read_text(encoding="utf-8", errors="replace").splitlines(), 1):
        words = line.split()
        if not words or words[0].startswith("#"):
            continue
        if len(words) < 8:
            raise GeometryError(f"load_points: {file}:{number}: a points3D row needs POINT3D_ID X Y Z R G B ERROR "
                                f"(got {len(words)} values)")  # fmt: skip
        try:
            rows.append([float(w) for w in words[:7]])
        except ValueError:
            raise GeometryError(f"load_points: {file}:{number}: {line[:60]!r} is not numeric") from None
    table = np.array(rows, dtype=np.float64).reshape(-1, 7)
    table = table[np.argsort(table[:, 0], kind="stable")]
    return _cloud(table[:, 1:4], table[:, 4:7] / 255.0, None, None, file)


def _colmap_binary(folder: Path) -> PointCloud:
    try:
        import pycolmap
    except ImportError:
        raise GeometryError(f"load_points: path = {str(folder)!r} is a binary COLMAP model; reading it needs "
                            "pycolmap (pip install pycolmap), or export it as text (colmap model_converter)") from None
    try:
        reconstruction = pycolmap.Reconstruction(str(folder))
    except Exception as error:
        raise GeometryError(f"load_points: path = {str(folder)!r} could not be read by pycolmap ({error})") from None
    return PointCloud.from_colmap(reconstruction)


# --- PLY ------------------------------------------------------------------------------------------------------

_PLY_TYPES = {
    "char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1", "short": "i2", "int16": "i2", "ushort": "u2",
    "uint16": "u2", "int": "i4", "int32": "i4", "uint": "u4", "uint32": "u4", "float": "f4", "float32": "f4",
    "double": "f8", "float64": "f8",
}  # fmt: skip


class PlyHeader:
    """A PLY header: ``format``, ``elements`` [(name, count, [(type, name) or ("list", count type, item type,
    name)])] and ``body`` (the byte offset of the data)."""

    def __init__(self, fmt: str, elements: list[tuple[str, int, list[tuple[str, ...]]]], body: int) -> None:
        self.format, self.elements, self.body = fmt, elements, body

    def element(self, name: str) -> tuple[str, int, list[tuple[str, ...]]] | None:
        return next((e for e in self.elements if e[0] == name), None)


def read_ply_header(file: Path, where: str) -> PlyHeader:
    """The header of the PLY `file` (read alone, the data untouched); raises ``GeometryError`` naming the file."""
    with open(file, "rb") as stream:
        head = stream.read(1 << 16)
    end = head.find(b"end_header")
    if not head.startswith(b"ply") or end < 0:
        raise GeometryError(f"{where}: path = {str(file)!r} is not a PLY file (no 'ply' … 'end_header' header)")
    newline = head.find(b"\n", end)
    body = newline + 1 if newline >= 0 else len(head)
    try:  # comments and unknown keywords are passed over
        fmt, elements, _ = ply_header(head[:end].decode("ascii", errors="replace").splitlines()[1:])
    except ValueError as error:
        raise GeometryError(f"{where}: path = {str(file)!r} has a malformed header line {error.args[0]!r}") from None
    if fmt not in ("ascii", "binary_little_endian", "binary_big_endian"):
        raise GeometryError(f"{where}: path = {str(file)!r} has format {fmt!r}; expected ascii, "
                            "binary_little_endian or binary_big_endian")  # fmt: skip
    return PlyHeader(fmt, elements, body)


def read_ply_vertices(file: Path, where: str, bytes_per_vertex: int) -> dict[str, NDArray[Any]]:
    """The ``vertex`` element of the PLY `file` as {property name: (N,) array}, after checking the memory budget
    for its announced count (`bytes_per_vertex` each) before reading any data. Elements after ``vertex`` (faces)
    are not read."""
    header = read_ply_header(file, where)
    vertex = header.element("vertex")
    if vertex is None:
        raise GeometryError(f"{where}: path = {str(file)!r} has no 'vertex' element")
    _, count, properties = vertex
    check_memory(count * bytes_per_vertex, where=where, cause=f"path = {str(file)!r} ({count} vertices)",
                 error=GeometryError)  # fmt: skip
    before = header.elements[: header.elements.index(vertex)]
    if any(e[1] for e in before):
        raise GeometryError(f"{where}: path = {str(file)!r} has data before its vertex element; not supported")
    if any(p[0] == "list" or p[0] not in _PLY_TYPES or len(p) != 2 for p in properties):
        raise GeometryError(f"{where}: path = {str(file)!r} has vertex properties that are not scalars of a PLY "
                            "type (char … double)")  # fmt: skip
    names = [p[1] for p in properties]
    with open(file, "rb") as stream:
        stream.seek(header.body)
        if header.format == "ascii":
            rows = []
            for _ in range(count):
                line = stream.readline()
                if not line:
                    break
                rows.append(line)
            try:
                table = np.array(b" ".join(rows).split(), dtype=np.float64)
            except ValueError:
                raise GeometryError(f"{where}: path = {str(file)!r} has a vertex value that is not a number") from None
            if table.size != count * len(names):
                raise GeometryError(f"{where}: path = {str(file)!r} announces {count} vertices of {len(names)} "
                                    f"values but holds {table.size} values; the file is truncated")  # fmt: skip
            table = table.reshape(count, len(names))
            return {name: table[:, i] for i, name in enumerate(names)}
        order = "<" if header.format == "binary_little_endian" else ">"
        dtype = np.dtype([(name, order + _PLY_TYPES[p[0]]) for name, p in zip(names, properties, strict=True)])
        data = stream.read(count * dtype.itemsize)
    if len(data) < count * dtype.itemsize:
        raise GeometryError(f"{where}: path = {str(file)!r} announces {count} vertices of {dtype.itemsize} bytes but "
                            f"holds {len(data)} bytes of data; the file is truncated")  # fmt: skip
    table = np.frombuffer(data, dtype=dtype, count=count)
    return {name: table[name] for name in names}


def _read_ply(file: Path) -> PointCloud:
    columns = read_ply_vertices(file, "load_points", _BYTES_PER_POINT)
    missing = [c for c in "xyz" if c not in columns]
    if missing:
        raise GeometryError(f"load_points: path = {str(file)!r} has no vertex properties {', '.join(missing)}")
    points = np.column_stack([columns[c] for c in "xyz"])
    normals = np.column_stack([columns[c] for c in ("nx", "ny", "nz")]) if {"nx", "ny", "nz"} <= set(columns) else None
    if normals is not None and not (np.sqrt((normals.astype(np.float64) ** 2).sum(axis=1)) > 0).all():
        normals = None  # scanners write zero normals for points without one: keep none rather than refuse
    colors = None
    names = ("red", "green", "blue", "alpha") if "red" in columns else ("r", "g", "b", "a")
    if all(n in columns for n in names[:3]):
        used = [n for n in names if n in columns]
        raw = np.column_stack([columns[n] for n in used])
        integer = all(columns[n].dtype.kind in "ui" for n in used)
        colors = raw.astype(np.float64) / 255.0 if integer or raw.max(initial=0.0) > 1.0 else raw.astype(np.float64)
    radii = columns.get("radius")
    return _cloud(points, colors, normals, radii, file)
