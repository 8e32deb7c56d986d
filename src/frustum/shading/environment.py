"""Environment maps: a picture of the surroundings, looked up by direction (background and reflection mapping).

[HB "Environment Mapping"]: the surroundings are painted on a sphere (or a cube) around the scene, far enough that
only the direction of a ray matters. A shiny surface shows the map where its reflected view vector points,

$$R = V − 2 (N·V) N$$

with V the unit view vector from the eye to the surface point and N the unit normal, and a pixel where nothing
is drawn shows the map along its own viewing ray. Two layouts:

* ``kind="equirect"``: a (H, 2H) latitude–longitude image, y up. A unit direction (x, y, z) maps to
  $u = 1/2 + atan2(x, −z) / 2π$ (columns left to right: −z at the centre, +x at three quarters) and
  $v = acos(y) / π$ (rows top to bottom: +y at the top row). This is the layout of most HDR panoramas
  (Poly Haven's, Blender's) seen from inside with −z forward.
* ``kind="cube"``: six square faces (6, S, S, 3) in OpenGL's order +x, −x, +y, −y, +z, −z, each as seen from the
  centre by the OpenGL cube-map rules (the major axis picks the face; $s = (sc/|ma| + 1)/2$,
  $t = (tc/|ma| + 1)/2$ with sc, tc from the GL specification's table, t down the rows).

Lookups are bilinear (equirect wraps in u); ``intensity`` scales the map (an HDR map may exceed 1; the renderer
clamps when it writes bytes). Images load with ``EnvironmentMap.load``: PNG/JPEG through imageio (bytes / 255,
taken as linear values as textures are), Radiance ``.hdr`` (RGBE, run-length encoded or flat) read here.

References
----------
[HB] "Environment Mapping" (reflection mapping); Blinn & Newell, "Texture and Reflection in Computer Generated
Images", CACM 1976; the OpenGL 4.6 specification, §8.13 "Cube Map Texture Selection"; Ward, "Real Pixels"
(RGBE), Graphics Gems II.
"""

from __future__ import annotations

import math
import os
import re
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import as_scalar, describe, read_only
from frustum.errors import ShadingError

__all__ = ["ENVIRONMENT_KINDS", "EnvironmentMap", "read_hdr", "reflect_directions"]

ENVIRONMENT_KINDS = ("equirect", "cube")


def reflect_directions(view: ArrayLike, normal: ArrayLike) -> NDArray[np.float64]:
    """(N, 3) reflected view vectors $R = V − 2 (N·V) N$ for unit view vectors V (eye → surface) and unit N."""
    v = np.asarray(view, dtype=np.float64)
    n = np.asarray(normal, dtype=np.float64)
    return v - 2.0 * (v * n).sum(axis=-1, keepdims=True) * n


def _as_image(value: Any, where: str) -> NDArray[np.float32]:
    raw = np.asarray(value)
    if raw.dtype == np.uint8:
        image = raw.astype(np.float32) / np.float32(255.0)
    elif raw.dtype == np.uint16:
        image = raw.astype(np.float32) / np.float32(65535.0)
    elif np.issubdtype(raw.dtype, np.number) and not np.issubdtype(raw.dtype, np.complexfloating):
        image = raw.astype(np.float32)
    else:
        raise ShadingError(f"{where}: image = {describe(value)} is not numeric; give an (H, W, 3) array or a file")
    if image.ndim == 2:
        image = np.repeat(image[..., None], 3, axis=-1)
    if image.ndim >= 3 and image.shape[-1] == 4:
        image = image[..., :3]
    if not np.isfinite(image).all() or (image < 0).any():
        raise ShadingError(f"{where}: image has negative or non-finite values; radiance must be finite and >= 0")
    return np.ascontiguousarray(image)


@dataclass(frozen=True, eq=False)
class EnvironmentMap:
    """The surroundings as an image, looked up by direction (module docstring for the layouts).

    Parameters
    ----------
    image : array_like
        ``kind="equirect"``: (H, W, 3|4) or (H, W) with W = 2·H; ``kind="cube"``: (6, S, S, 3|4) faces in the order
        +x, −x, +y, −y, +z, −z. uint8 (/ 255), uint16 (/ 65535) or float (linear radiance, may exceed 1).
    kind : {"equirect", "cube"}
    intensity : float
        Scale of the map, >= 0.

    Raises
    ------
    ShadingError
        An unknown kind, an equirect image that is not 2:1, cube faces that are not six squares, negative or
        non-finite values.
    """

    image: NDArray[np.float32]
    kind: str = "equirect"
    intensity: float = 1.0

    def __post_init__(self) -> None:
        where = "EnvironmentMap"
        if self.kind not in ENVIRONMENT_KINDS:
            raise ShadingError(f"{where}: kind = {self.kind!r} is unknown; expected one of {ENVIRONMENT_KINDS}")
        image = _as_image(self.image, where)
        if self.kind == "equirect":
            if image.ndim != 3 or image.shape[1] != 2 * image.shape[0] or image.shape[0] < 2:
                raise ShadingError(
                    f"{where}: an equirect image must be 2:1 (H, 2H) with H >= 2; got shape {image.shape}; use "
                    "kind='cube' for six faces"
                )
        elif image.ndim != 4 or image.shape[0] != 6 or image.shape[1] != image.shape[2] or image.shape[1] < 1:
            raise ShadingError(
                f"{where}: a cube map must be six square faces (6, S, S, 3) in the order +x, -x, +y, -y, +z, -z; "
                f"got shape {image.shape}"
            )
        object.__setattr__(self, "image", read_only(image))
        intensity = as_scalar(self.intensity, "intensity", where=where, error=ShadingError)
        if intensity < 0.0:
            raise ShadingError(f"{where}: intensity = {intensity!r} is negative; expected a number >= 0")
        object.__setattr__(self, "intensity", intensity)

    def __repr__(self) -> str:
        return f"EnvironmentMap(kind={self.kind!r}, shape={self.image.shape}, intensity={self.intensity!r})"

    @classmethod
    def load(cls, path: str | os.PathLike, kind: str = "equirect", intensity: float = 1.0) -> EnvironmentMap:
        """An environment map from an image file: ``.hdr`` (Radiance RGBE) or anything imageio reads (PNG, JPEG,
        EXR where the plugin exists). A cube map file holds the six faces side by side (6S × S) or stacked
        (S × 6S), in the order +x, −x, +y, −y, +z, −z."""
        where = "EnvironmentMap.load"
        name = os.fspath(path)
        if not os.path.isfile(name):
            raise ShadingError(f"{where}: {name!r} is not a file")
        if name.lower().endswith(".hdr"):
            image = read_hdr(name)
        else:
            import imageio.v3 as iio

            from frustum._images import open_image

            try:
                open_image(name, where=where, name=repr(name), error=ShadingError).close()  # the size, first
            except ShadingError:
                raise
            except Exception:  # not an image Pillow knows (EXR): imageio's plugins may
                pass
            try:
                image = iio.imread(name)
            except Exception as error:  # imageio raises many types for unreadable files
                raise ShadingError(f"{where}: {name!r} could not be read as an image ({error})") from None
        if kind == "cube":
            image = _as_image(image, where)
            height, width = image.shape[:2]
            if width == 6 * height:
                image = np.stack(np.split(image, 6, axis=1))
            elif height == 6 * width:
                image = np.stack(np.split(image, 6, axis=0))
            else:
                raise ShadingError(
                    f"{where}: a cube map file must hold six square faces side by side (6S x S) or stacked (S x 6S); "
                    f"got {width} x {height} pixels"
                )
        return cls(image, kind, intensity)

    def lookup(self, directions: ArrayLike) -> NDArray[np.float64]:
        """(N, 3) linear RGB of the map along each direction (any nonzero length), times ``intensity``."""
        d = np.asarray(directions, dtype=np.float64).reshape(-1, 3)
        length = np.sqrt((d * d).sum(axis=1))
        d = d / np.where(length > 0.0, length, 1.0)[:, None]
        if self.kind == "equirect":
            height, width = self.image.shape[:2]
            u = 0.5 + np.arctan2(d[:, 0], -d[:, 2]) / (2.0 * math.pi)
            v = np.arccos(np.clip(d[:, 1], -1.0, 1.0)) / math.pi
            color = _bilinear(self.image, u * width - 0.5, v * height - 0.5, wrap=True)
        else:
            face, s, t = cube_coordinates(d)
            size = self.image.shape[1]
            color = np.empty((d.shape[0], 3))
            for k in range(6):
                chosen = face == k
                if chosen.any():
                    color[chosen] = _bilinear(self.image[k], s[chosen] * size - 0.5, t[chosen] * size - 0.5,
                                              wrap=False)  # fmt: skip
        return color * self.intensity


def cube_coordinates(directions: NDArray[np.float64]) -> tuple[NDArray[np.int64], NDArray, NDArray]:
    """OpenGL cube-map selection: (face 0…5 in the order +x, −x, +y, −y, +z, −z, s, t in [0, 1]), t down the rows."""
    x, y, z = directions[:, 0], directions[:, 1], directions[:, 2]
    ax, ay, az = np.abs(x), np.abs(y), np.abs(z)
    face = np.where((ax >= ay) & (ax >= az), np.where(x >= 0, 0, 1),
                    np.where(ay >= az, np.where(y >= 0, 2, 3), np.where(z >= 0, 4, 5)))  # fmt: skip
    # (sc, tc, ma) per face from the GL table
    sc = np.choose(face, [-z, z, x, x, x, -x])
    tc = np.choose(face, [-y, -y, z, -z, -y, -y])
    ma = np.choose(face, [ax, ax, ay, ay, az, az])
    return face, 0.5 * (sc / ma + 1.0), 0.5 * (tc / ma + 1.0)


def _bilinear(image: NDArray[np.float32], x: NDArray, y: NDArray, wrap: bool) -> NDArray[np.float64]:
    """Bilinear samples of an (H, W, 3) image at continuous pixel coordinates (centres at integers); columns wrap
    around when `wrap`, rows (and columns otherwise) clamp at the edge."""
    height, width = image.shape[:2]
    x0 = np.floor(x)
    y0 = np.floor(y)
    fx = (x - x0)[:, None]
    fy = (y - y0)[:, None]
    x0 = x0.astype(np.int64)
    y0 = y0.astype(np.int64)
    if wrap:
        xa, xb = x0 % width, (x0 + 1) % width
    else:
        xa, xb = np.clip(x0, 0, width - 1), np.clip(x0 + 1, 0, width - 1)
    ya, yb = np.clip(y0, 0, height - 1), np.clip(y0 + 1, 0, height - 1)
    top = image[ya, xa] * (1.0 - fx) + image[ya, xb] * fx
    bottom = image[yb, xa] * (1.0 - fx) + image[yb, xb] * fx
    return top * (1.0 - fy) + bottom * fy


def read_hdr(path: str | os.PathLike) -> NDArray[np.float32]:
    """(H, W, 3) float32 radiance of a Radiance ``.hdr`` file (RGBE, ``-Y H +X W`` orientation; new-style run-length
    encoded scanlines or flat RGBE pixels). Raises ``ShadingError`` for anything else."""
    where = "read_hdr"
    with open(path, "rb") as handle:
        data = handle.read()
    if not (data.startswith(b"#?RADIANCE") or data.startswith(b"#?RGBE")):
        raise ShadingError(f"{where}: {os.fspath(path)!r} is not a Radiance HDR file (no '#?RADIANCE' header)")
    end = data.find(b"\n\n")
    if end < 0:
        raise ShadingError(f"{where}: {os.fspath(path)!r} has no end of header")
    header = data[:end].decode("latin-1")
    if "FORMAT=" in header and "32-bit_rle_rgbe" not in header:
        raise ShadingError(f"{where}: {os.fspath(path)!r} is not in RGBE format (XYZE is not supported)")
    line_end = data.find(b"\n", end + 2)
    match = re.fullmatch(rb"-Y (\d+) \+X (\d+)", data[end + 2 : line_end].strip())
    if match is None:
        raise ShadingError(f"{where}: {os.fspath(path)!r} has an unsupported resolution line; expected '-Y H +X W'")
    height, width = int(match.group(1)), int(match.group(2))
    from frustum.budgets import check_memory

    check_memory(height * width * 16.0, where=where, cause=f"a {width} x {height} image", error=ShadingError)
    body = np.frombuffer(data, dtype=np.uint8, offset=line_end + 1)
    rgbe = _decode_rgbe(body, height, width, os.fspath(path))
    exponent = rgbe[..., 3].astype(np.int32)
    scale = np.where(exponent > 0, np.ldexp(1.0, exponent - 136), 0.0).astype(np.float32)
    return rgbe[..., :3].astype(np.float32) * scale[..., None]


def _decode_rgbe(body: NDArray[np.uint8], height: int, width: int, name: str) -> NDArray[np.uint8]:
    """(H, W, 4) RGBE bytes from the pixel data: each scanline run-length encoded per channel or flat."""
    where = "read_hdr"
    out = np.empty((height, width, 4), dtype=np.uint8)
    at = 0
    try:
        for row in range(height):
            rle = 8 <= width < 32768 and body[at] == 2 and body[at + 1] == 2 and (body[at + 2] & 0x80) == 0
            if not rle:  # flat: W pixels of four bytes (old-style runs are not supported)
                out[row] = body[at : at + 4 * width].reshape(width, 4)
                at += 4 * width
                continue
            if (int(body[at + 2]) << 8 | int(body[at + 3])) != width:
                raise ShadingError(f"{where}: {name!r} has a scanline of the wrong length; the file is corrupt")
            at += 4
            for channel in range(4):
                column = 0
                while column < width:
                    count = int(body[at])
                    at += 1
                    if count > 128:  # a run of one value
                        count -= 128
                        if column + count > width:
                            raise ShadingError(f"{where}: {name!r} has a run past the end of a scanline")
                        out[row, column : column + count, channel] = body[at]
                        at += 1
                    else:  # count literal values
                        if count == 0 or column + count > width:
                            raise ShadingError(f"{where}: {name!r} has a bad literal count; the file is corrupt")
                        out[row, column : column + count, channel] = body[at : at + count]
                        at += count
                    column += count
    except (IndexError, ValueError):
        raise ShadingError(f"{where}: {name!r} ends before its {width} x {height} pixels; truncated") from None
    return out
