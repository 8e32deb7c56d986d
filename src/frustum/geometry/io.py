"""Mesh files: load and save OBJ, STL (ASCII and binary), PLY, OFF and glTF/GLB through trimesh.

trimesh reads and writes the formats, and this module turns its objects into frozen ``Mesh`` objects (and
back), keeping vertex normals, UVs, vertex colors and texture images where the format has them. Every failure
(missing file, unknown suffix, truncated or corrupt data) is raised as a ``GeometryError`` naming the path and
the reason, never as an exception from inside the parser.

Files are read without trimesh's "processing" (no vertex merging, no reordering), so vertex and face counts are
those of the file, except that vertices are split where a vertex carries several UVs or normals (OBJ) and
polygons are triangulated. Use ``Mesh.welded()`` to merge the seam copies again.

The plain, well-formed cases of each format (binary STL, triangle PLY/OFF/OBJ, glTF without extensions; see
``frustum.geometry.readers``) are read by frustum's own readers, giving exactly what trimesh gives, without
importing trimesh (0.7-1.1 s of a one-command render); everything else goes through trimesh.

References
----------
[seed] "Polygon Mesh Models" (object description stored as sets of surface polygons).
"""

from __future__ import annotations

import base64
import binascii
import io
import json
import re
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from frustum._arrays import describe
from frustum._files import file_kind
from frustum.budgets import check_memory, format_bytes, get_budget
from frustum.errors import GeometryError
from frustum.geometry.mesh import Mesh
from frustum.geometry.mesh_writer import SUPPORTED_SUFFIXES, _suffix, write_mesh

__all__ = ["SUPPORTED_SUFFIXES", "MeshPart", "load", "load_parts", "save", "scene_parts"]

_IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg")


class MeshPart(NamedTuple):
    """One object of a mesh file, as placed in the file.

    Attributes
    ----------
    name : str
        The node (or object) name from the file; unique within one `load_parts` result.
    mesh : Mesh
        The geometry in its own model coordinates.
    world_from_model : (4, 4) float64 ndarray
        The file's placement of the part (identity for formats without a scene graph).
    texture : (H, W, 3 | 4) uint8 ndarray or None
        The texture image the part's UVs index, row 0 at the top of the image (so v = 1 is row 0).
    color : tuple of 4 floats in [0, 1] or None
        The material's base (diffuse) RGBA color, when the file gives one.
    normal_map : (H, W, 3) uint8 ndarray or None
        A glTF material's ``normalTexture`` (tangent-space normals, OpenGL convention): ``Material(normal_map=)``.
    """

    name: str
    mesh: Mesh
    world_from_model: NDArray[np.float64]
    texture: NDArray[np.uint8] | None
    color: tuple[float, float, float, float] | None
    normal_map: NDArray[np.uint8] | None = None
    emissive: tuple[float, float, float] | None = None
    """A glTF material's ``emissiveFactor`` (linear RGB), when not black: ``Material(emissive=)``."""
    alpha_mode: str | None = None
    """A glTF material's ``alphaMode`` ("OPAQUE", "MASK" or "BLEND"); None for other formats."""
    metallic: float | None = None
    """A glTF material's ``metallicFactor`` (None when the file gives none: the specification's default is 1), or
    an MTL material's ``Pm`` (``frustum.geometry.mtl_pbr``)."""
    roughness: float | None = None
    """A glTF material's ``roughnessFactor`` (None when the file gives none: the specification's default is 1), or
    an MTL material's ``Pr``."""
    metallic_roughness_texture: NDArray[np.uint8] | None = None
    """A glTF material's ``metallicRoughnessTexture`` as (H, W, 3) bytes: B metallic, G roughness."""
    occlusion_texture: NDArray[np.uint8] | None = None
    """A glTF material's ``occlusionTexture`` as (H, W, 3) bytes: R the occlusion."""
    physical: bool = False
    """Whether the file describes the material by glTF's metallic–roughness model (a glTF or GLB file, or an OBJ
    whose MTL material has PBR statements: ``frustum.geometry.mtl_pbr``)."""
    emissive_texture: NDArray[np.uint8] | None = None
    """A glTF material's ``emissiveTexture`` as (H, W, 3) sRGB bytes (emission = ``emissive`` × the texture)."""

    def __repr__(self) -> str:
        def image(array: Any) -> str:
            return "None" if array is None else f"<{'x'.join(map(str, np.shape(array)))} image>"

        physical = (f", metallic={self.metallic!r}, roughness={self.roughness!r}, metallic_roughness_texture="
                    f"{image(self.metallic_roughness_texture)}, occlusion_texture={image(self.occlusion_texture)}, "
                    f"physical=True, emissive_texture={image(self.emissive_texture)}") if self.physical else ""
        return (f"MeshPart(name={self.name!r}, mesh={self.mesh!r}, texture={image(self.texture)}, "
                f"color={self.color!r}, normal_map={image(self.normal_map)}, emissive={self.emissive!r}, "
                f"alpha_mode={self.alpha_mode!r}{physical})")  # fmt: skip


def load(path: str | Path, texture: str | Path | None = None) -> Mesh:
    """Read a mesh file as one ``Mesh``; a file with several objects is joined into one, transforms baked in.

    Parameters
    ----------
    path : str or Path
        An OBJ, STL, PLY, OFF, glTF or GLB file (see ``SUPPORTED_SUFFIXES``).
    texture : str or Path, optional
        Ignored here (a ``Mesh`` carries UVs, not images); accepted so ``load`` and ``load_parts`` take the same
        arguments. Use ``load_parts`` to get texture images.

    Raises
    ------
    GeometryError
        Unknown suffix (the message lists the supported ones), missing file, unreadable or corrupt data, or a
        file without triangles. A PLY without faces (a point cloud, or 3DGS splats) is refused with the reader
        that takes it: ``frustum.load_points`` (a ``PointCloud``) or ``GaussianSplats.load``; ``load`` always
        returns a ``Mesh``.
    """
    parts = load_parts(path, texture=texture)
    placed = [
        part.mesh if _is_identity(part.world_from_model) else part.mesh.transformed(part.world_from_model)
        for part in parts
    ]
    return placed[0].merged(*placed[1:])


def load_parts(path: str | Path, texture: str | Path | None = None) -> list[MeshPart]:
    """Read every triangle mesh of a file with its name, placement, texture image and base color.

    Parts come sorted by name, so the result does not depend on the parser's internal order. Single-mesh
    formats (OBJ without groups, STL, PLY, OFF) give one part with the identity placement.

    Parameters
    ----------
    path : str or Path
    texture : str or Path, optional
        An image to use as the texture of every part with UVs, for files that do not name one (an OBJ without
        a ``.mtl``). Without it, an OBJ/PLY whose material has no image looks next to the file for
        ``<stem>.png``, ``<stem>_texture.png`` or ``<first word of stem>_texture.png`` (also ``.jpg``, ``.jpeg``),
        e.g. ``spot_texture.png`` for ``spot_triangulated.obj``.

    Raises
    ------
    GeometryError
        As for ``load``.
    """
    file = _checked_path(path, "load")
    explicit = None if texture is None else _read_image(Path(texture), "load")
    if file.suffix.lower() == ".stl":
        _check_binary_stl_size(file)
    if file.suffix.lower() == ".glb":
        _check_glb_chunks(file)
    if file.suffix.lower() in (".gltf", ".glb"):
        _check_gltf_layout(file)
    _check_file_memory(file)
    text = _text_bytes(file)
    if file.suffix.lower() == ".obj":
        _warn_unreadable_textures(file, text)
    try:
        native = _native_parts(file, text)
    except MemoryError:
        raise _memory_error(file) from None
    if native is not None:
        return _with_textures(native, file, explicit)
    import trimesh

    try:
        if text is not None:
            scene = trimesh.load_scene(io.BytesIO(text), file_type=file.suffix.lower()[1:], process=False,
                                       resolver=trimesh.resolvers.FilePathResolver(str(file)))  # fmt: skip
        else:
            scene = trimesh.load_scene(str(file), process=False)
    except MemoryError:
        raise _memory_error(file) from None
    except Exception as error:  # trimesh raises many types (ValueError, KeyError, struct.error, ...)
        raise _read_error(file, error) from None
    try:
        parts = scene_parts(scene, file)
    except GeometryError as error:
        raise GeometryError(f"load: path = {str(file)!r} holds invalid geometry ({error}); check the file") from None
    except MemoryError:
        raise _memory_error(file) from None
    except Exception as error:
        raise _read_error(file, error) from None
    if not parts:
        _refuse_points(file)
        raise GeometryError(
            f"load: path = {str(file)!r} contains no triangles; give a file with at least one triangle mesh"
        )
    return _with_textures(parts, file, explicit)


def scene_parts(scene: Any, file: Path | None = None) -> list[MeshPart]:
    """Every non-empty triangle mesh of a ``trimesh.Scene`` as a ``MeshPart``, placed by its graph node (world
    transform from one walk of the graph), sorted by node name: what ``load_parts`` returns for a file's scene and
    ``Scene.from_trimesh`` for a scene in memory. Other geometry (point clouds, paths) is left out. The parts of a
    glTF `file` carry its metallic–roughness materials (``MeshPart.physical``)."""
    import trimesh

    parts: list[MeshPart] = []
    placements = _world_placements(scene.graph)
    for node in sorted(scene.graph.nodes_geometry):
        world_from_model, geometry_name = placements[node] if node in placements else scene.graph[node]
        geometry = scene.geometry.get(geometry_name)
        if not isinstance(geometry, trimesh.Trimesh) or len(geometry.faces) == 0:
            continue
        mesh, image, color = _from_trimesh(geometry)
        matrix = np.array(world_from_model, dtype=np.float64)
        emissive, alpha_mode = _emission_and_alpha(geometry)
        parts.append(MeshPart(str(node), mesh, matrix, image, color, _normal_texture(geometry), emissive,
                              alpha_mode, *_metallic_roughness(geometry, file),
                              _normal_texture(geometry, "emissiveTexture")))  # fmt: skip
    return parts


def _with_textures(parts: list[MeshPart], file: Path, explicit: NDArray[np.uint8] | None) -> list[MeshPart]:
    """`parts` with the `explicit` texture, or the one beside the file, on each part with UVs and no image."""
    missing = [i for i, part in enumerate(parts) if part.texture is None and part.mesh.uvs is not None]
    if not missing:
        return parts
    image = explicit if explicit is not None else _sibling_texture(file)
    return [part._replace(texture=image) if i in missing else part for i, part in enumerate(parts)]


def _native_parts(file: Path, text: bytes | None) -> list[MeshPart] | None:
    """The parts read by frustum's own readers (``frustum.geometry.readers``: the plain cases of each format,
    without importing trimesh), or None when trimesh must read the file."""
    from frustum.geometry.readers import read_parts

    raw = read_parts(file, text)
    if raw is None:
        return None
    parts = []
    try:
        for part in raw:
            mesh = Mesh(part.vertices, part.faces, part.normals, part.uvs)
            image = None if part.image is None else _pil_array(part.image)
            color = part.color
            if part.image is not None and image is None:  # a placeholder image: trimesh drops the colour too
                color = None
            normal_map = None
            if part.normal_image is not None and part.uvs is not None:
                normal_map = np.asarray(part.normal_image.convert("RGB"), dtype=np.uint8)
            physical = [None, None, None]
            for k, image_k in enumerate((part.metallic_roughness_image, part.occlusion_image, part.emissive_image)):
                if image_k is not None and part.uvs is not None:
                    physical[k] = np.asarray(image_k.convert("RGB"), dtype=np.uint8)
            pbr = file.suffix.lower() in (".glb", ".gltf") or part.metallic is not None  # glTF, or an MTL's Pr/Pm
            parts.append(MeshPart(part.name, mesh, np.asarray(part.world_from_model, dtype=np.float64), image, color,
                                  normal_map, part.emissive, part.alpha_mode, part.metallic, part.roughness,
                                  physical[0], physical[1], pbr, physical[2]))  # fmt: skip
    except MemoryError:
        raise
    except Exception:  # invalid geometry or an unreadable image: trimesh's path says what is wrong
        return None
    return parts


def save(mesh: Mesh, path: str | Path, binary: bool = True, texture: Any = None) -> Path:
    """Write `mesh` to `path`; the suffix picks the format. Returns the path written.

    What each format keeps: OBJ — normals, UVs (and the `texture` image with a ``.mtl`` when given) or vertex
    colors; PLY and glTF/GLB — normals, UVs or vertex colors; OFF — positions only; STL — positions
    and face normals only (vertices are split per face, as the format stores them). A format can hold UVs or
    vertex colors, not both: with a `texture` the UVs are written, otherwise vertex colors win over UVs.

    Parameters
    ----------
    binary : bool
        Binary STL or PLY (default) or ASCII.
    texture : (H, W, 3 | 4) uint8 array_like, optional
        An image to store with the UVs (OBJ: a PNG beside the file; GLB/glTF: embedded).

    Raises
    ------
    GeometryError
        Not a Mesh, unknown suffix, or the file cannot be written.
    """
    if not isinstance(mesh, Mesh):
        raise GeometryError(f"save: mesh = {describe(mesh)} is not a Mesh; give a frustum Mesh")
    return write_mesh(mesh, path, binary, texture)


# --- helpers ------------------------------------------------------------------------------------------------


def _refuse_points(file: Path) -> None:
    """A PLY that holds no triangles refused with the loader that reads it, where its header says it is a point
    cloud or 3DGS splats (``frustum.geometry.points.point_file_kind``)."""
    if file.suffix.lower() != ".ply":
        return
    from frustum.geometry.points import point_file_kind

    kind = point_file_kind(file)
    if kind == "points":
        raise GeometryError(
            f"load: path = {str(file)!r} is a PLY without faces: a point cloud, not a triangle mesh; read it with "
            "frustum.load_points(path), a PointCloud that Scene.add draws (style='square', 'disk', 'sphere', "
            "'surfel')"
        )
    if kind == "splats":
        raise GeometryError(
            f"load: path = {str(file)!r} holds 3D Gaussian splats (the 3DGS PLY layout), not a triangle mesh; read "
            "it with frustum.GaussianSplats.load(path), which Scene.add draws"
        )


def _checked_path(path: Any, where: str) -> Path:
    if not isinstance(path, str | Path):
        raise GeometryError(f"{where}: path = {describe(path)} is not a path; give a file name")
    file = Path(path)
    _suffix(file, where)
    if not file.is_file():
        problem = "does not exist" if not file.exists() else f"is not a regular file ({file_kind(file)})"
        raise GeometryError(f"{where}: path = {str(file)!r} {problem}; give the path of an existing mesh file")
    if file.stat().st_size == 0:
        raise GeometryError(f"{where}: path = {str(file)!r} is empty (0 bytes); the file is truncated or not written")
    return file


def _check_binary_stl_size(file: Path) -> None:
    """A binary STL is an 80-byte header, a uint32 count n and n 50-byte records: catch truncation early."""
    with file.open("rb") as stream:
        head = stream.read(84)
    if head[:5].lower() == b"solid" and b"facet" in file.read_bytes()[:1024]:
        return  # ASCII STL
    size = file.stat().st_size
    if len(head) < 84:
        raise GeometryError(
            f"load: path = {str(file)!r} has {size} bytes, fewer than the 84-byte binary STL header; the file is "
            "truncated or not an STL file"
        )
    count = int(np.frombuffer(head[80:84], dtype="<u4")[0])
    if size < 84 + 50 * count:  # before the memory budget: a truncated or random file is not a huge one
        raise GeometryError(
            f"load: path = {str(file)!r} has {size} bytes but its header announces {count} triangles "
            f"({84 + 50 * count} bytes); the file is truncated or not an STL file"
        )
    check_memory(count * _LOAD_BYTES_PER_TRIANGLE, where="load",
                 cause=f"path = {str(file)!r} with {count} triangles", error=GeometryError)  # fmt: skip


def _check_glb_chunks(file: Path) -> None:
    """A GLB is a 12-byte header ("glTF", version, length) and chunks of (uint32 length, uint32 type, data):
    refuse a chunk that announces more bytes than the file holds (trimesh would ask for all of them)."""
    size = file.stat().st_size
    with file.open("rb") as stream:
        head = stream.read(12)
        if len(head) < 12 or head[:4] != b"glTF":
            return  # not a binary glTF: trimesh says what it is not
        offset, index = 12, 0
        while offset < size:
            stream.seek(offset)
            chunk = stream.read(8)
            if len(chunk) < 8:
                return  # trimesh reports a chunk header cut short
            length = int.from_bytes(chunk[:4], "little")
            if offset + 8 + length > size:
                raise GeometryError(
                    f"load: path = {str(file)!r}: GLB chunk {index} announces {length} bytes at byte {offset}, but "
                    f"the file has {size - offset - 8} more; the file is corrupt or truncated"
                )
            offset, index = offset + 8 + length, index + 1


def _check_gltf_layout(file: Path) -> None:
    """Every buffer view inside its buffer and every accessor inside its view, counts and offsets non-negative
    integers, buffers read only from the file's own folder: refused here with the byte offset, before frustum's
    reader or trimesh sees the file (a negative count was drawn; a view past the BIN chunk gave an
    ``AssertionError``). glTF 2.0 §3.6.2 "Buffers and Buffer Views", §3.6.2.4 "Data Alignment"."""
    from frustum.geometry.readers import _COMPONENTS, _WIDTHS

    where = f"load: path = {str(file)!r}"
    data = file.read_bytes()
    binary: tuple[int, int] | None = None  # (offset in the file, length) of the GLB's BIN chunk
    try:
        if data[:4] == b"glTF":
            length = int.from_bytes(data[12:16], "little")
            gltf = json.loads(data[20 : 20 + length])
            if len(data) >= 28 + length and data[24 + length : 28 + length] == b"BIN\x00":
                binary = (28 + length, int.from_bytes(data[20 + length : 24 + length], "little"))
        else:
            gltf = json.loads(data)
    except (ValueError, RecursionError):
        return  # not JSON: the readers say what it is not
    if not isinstance(gltf, dict):
        return

    def fail(problem: str) -> GeometryError:
        return GeometryError(f"{where}: {problem}; the file is corrupt")

    def natural(table: dict, key: str, what: str, default: int | None = None, least: int = 0) -> int:
        value = table.get(key, default)
        if isinstance(value, bool) or not isinstance(value, int) or value < least:
            raise fail(f"{what} has {key} = {describe(value)}, not an integer >= {least}")
        return value

    lengths = []
    for i, buffer in enumerate(_gltf_list(gltf, "buffers")):
        uri = buffer.get("uri")
        if uri is None:
            lengths.append(binary[1] if binary else 0)
        elif isinstance(uri, str) and uri.startswith("data:"):
            try:
                lengths.append(len(base64.b64decode(uri.split(",", 1)[-1])))
            except (binascii.Error, ValueError):
                raise fail(f"buffer {i} has a data: URI that is not base64") from None
        elif isinstance(uri, str):
            target = (file.parent / uri).resolve()
            if not target.is_relative_to(file.parent.resolve()):
                raise GeometryError(f"{where}: buffer {i} names {uri!r}, outside the glTF file's folder; a glTF "
                                    "file reads its buffers only beside it (copy the .bin there)")  # fmt: skip
            lengths.append(target.stat().st_size if target.is_file() else 0)
        else:
            raise fail(f"buffer {i} has uri = {describe(uri)}, not a string")
    views = _gltf_list(gltf, "bufferViews")
    for i, view in enumerate(views):
        what = f"bufferView {i}"
        index = natural(view, "buffer", what)
        start, length = natural(view, "byteOffset", what, 0), natural(view, "byteLength", what, least=1)
        if index >= len(lengths) or start + length > lengths[index]:
            held = f"{lengths[index]} bytes" if index < len(lengths) else "no such buffer"
            at = f" (the BIN chunk at byte {binary[0]} of the file)" if binary and index == 0 else ""
            raise fail(f"{what} spans bytes {start}…{start + length} of buffer {index}, which holds {held}{at}")
    for i, accessor in enumerate(_gltf_list(gltf, "accessors")):
        what = f"accessor {i}"
        count = natural(accessor, "count", what, least=1)
        offset = natural(accessor, "byteOffset", what, 0)
        if "bufferView" not in accessor:
            continue  # all zeros (or sparse): nothing read from a view
        index = natural(accessor, "bufferView", what)
        if index >= len(views):
            raise fail(f"{what} names bufferView {index}, but the file has {len(views)}")
        component = _COMPONENTS.get(accessor.get("componentType"))
        width = _WIDTHS.get(accessor.get("type"), 0)
        if component is None or not width:
            continue  # an unknown type: the readers refuse it by name
        element = np.dtype(component).itemsize * width
        stride = views[index].get("byteStride") or element
        end = offset + (count - 1) * stride + element
        if end > views[index]["byteLength"]:
            raise fail(f"{what} reads bytes {offset}…{end} of bufferView {index}, which holds "
                       f"{views[index]['byteLength']} ({count} elements of {element} bytes)")  # fmt: skip


def _gltf_list(gltf: dict, key: str) -> list[dict]:
    value = gltf.get(key, [])
    if not isinstance(value, list) or not all(isinstance(entry, dict) for entry in value):
        raise GeometryError(f"load: {key} = {describe(value)} is not a list of objects; the glTF file is corrupt")
    return value


_LOAD_BYTES_PER_FILE_BYTE = 12
"""Peak memory of trimesh's loaders per byte of a text mesh file (OBJ, PLY, OFF), a generous estimate."""
_LOAD_BYTES_PER_TRIANGLE = 400
"""Peak memory of loading one binary STL triangle (50 bytes on disk): float64 copies, merging, normals."""


def _check_file_memory(file: Path) -> None:
    """Refuse, through the work budget, a mesh file whose loading would take more memory than allowed."""
    size = file.stat().st_size
    check_memory(size * _LOAD_BYTES_PER_FILE_BYTE, where="load",
                 cause=f"path = {str(file)!r} ({format_bytes(size)})", error=GeometryError)  # fmt: skip


_OBJ_BYTES_PER_FILE_BYTE = 20
"""Peak memory of trimesh's OBJ reader per byte of the file (measured: 18.4–19.2 for triangle lines)."""
_OBJ_BYTES_PER_POLYGON_INDEX = 240
"""Peak memory per vertex index of a face line of more than four (measured: 209–225 bytes beyond the file's
own, whatever the index text: such lines are split and fan-triangulated in Python lists)."""
_OBJ_POLYGON_LINE = re.compile(rb"^[ \t]*f(?:[ \t]+\S+){5,}", re.MULTILINE)


def _check_obj_memory(file: Path, data: bytes) -> None:
    """Refuse, through the work budget and before parsing, an OBJ whose reading would take more memory than
    allowed: the file's bytes and the vertex indices of every polygon line (counted line by line)."""
    indices, longest, longest_at = 0, 0, 0
    for match in _OBJ_POLYGON_LINE.finditer(data):
        end = data.find(b"\n", match.start())
        count = len(data[match.start() : end if end >= 0 else len(data)].split()) - 1
        indices += count
        if count > longest:
            longest, longest_at = count, match.start()
    estimate = len(data) * _OBJ_BYTES_PER_FILE_BYTE + indices * _OBJ_BYTES_PER_POLYGON_INDEX
    cause = f"path = {str(file)!r} ({format_bytes(len(data))})"
    if longest:
        line = data.count(b"\n", 0, longest_at) + 1
        cause += (f" with {indices} vertex indices in polygons of more than 4 (the longest, line {line}, has "
                  f"{longest})")  # fmt: skip
    check_memory(estimate, where="load", cause=cause, error=GeometryError)


_OBJ_ZERO_INDEX = re.compile(rb"^[ \t]*f[ \t].*?(?<![\w./+-])[+]?0+(?=[/\s]|$)", re.MULTILINE)


def _obj_text(file: Path) -> bytes:
    """An OBJ file's bytes as UTF-8: decoded as UTF-8, else as Latin-1 (any byte is a character; names and
    comments are all an OBJ keeps as text), so no charset detector is needed. Face index 0 is refused: OBJ
    indices start at 1 (negative ones count back from the last vertex)."""
    data = file.read_bytes()
    _check_obj_memory(file, data)
    zero = _OBJ_ZERO_INDEX.search(data)
    if zero:
        line = data.count(b"\n", 0, zero.start()) + 1
        text = data[zero.start() : zero.end()].decode("latin-1").strip()
        raise GeometryError(
            f"load: path = {str(file)!r}, line {line}: face {text!r}... uses vertex index 0; OBJ indices start at 1 "
            "(negative ones count back from the last vertex), so the file is malformed"
        )
    return _utf8(data)


def _utf8(data: bytes) -> bytes:
    """`data` if it is UTF-8, else its Latin-1 reading (every byte is a character) encoded as UTF-8."""
    try:
        data.decode("utf-8")
        return data
    except UnicodeDecodeError:
        return data.decode("latin-1").encode("utf-8")


def _text_bytes(file: Path) -> bytes | None:
    """The bytes trimesh should parse, when they differ from the file's: OBJ always (see ``_obj_text``); an
    ASCII STL, an OFF file or a PLY header that is not UTF-8, read as Latin-1 and given as UTF-8, so trimesh
    never asks an optional charset detector (``charset_normalizer``) and a Latin-1 name or comment loads.
    None: parse the file itself."""
    suffix = file.suffix.lower()
    if suffix == ".obj":
        return _obj_text(file)
    if suffix not in (".stl", ".off", ".ply"):
        return None
    data = file.read_bytes()
    if suffix == ".stl":
        if not (data[:5].lower() == b"solid" and b"facet" in data[:1024]):
            return None  # binary STL: an 80-byte header trimesh does not decode, then numbers
        if len(data) >= 84 and len(data) == 84 + 50 * int.from_bytes(data[80:84], "little"):
            return None  # a binary STL whose header happens to start with "solid"
    if suffix == ".ply":
        end = data.find(b"end_header")
        if end < 0:
            return None  # no header: trimesh says what is wrong
        header = data[:end]
        converted = _utf8(header)
        return None if converted is header else converted + data[end:]
    converted = _utf8(data)
    return None if converted is data else converted


def _world_placements(graph: Any) -> dict[Any, tuple[NDArray[np.float64], Any]]:
    """(world_from_model, geometry name) of every node of a trimesh scene graph that holds a geometry, in one
    walk from the root.

    $world_from_child = world_from_node · node_from_child$ down each edge, so the walk is linear in the node
    count (trimesh's ``graph[node]`` finds each node's path and multiplies it with ``multi_dot``, whose
    matrix-chain ordering is cubic in the depth: 3,000 chained glTF nodes took minutes). As trimesh does,
    identity edges are skipped and the result is repaired to a rigid transform within ``graph.repair_rigid``.
    """
    from trimesh.scene.transforms import fix_rigid

    forest = graph.transforms
    identity = np.eye(4)
    placements: dict[Any, tuple[NDArray[np.float64], Any]] = {}
    stack = [(graph.base_frame, identity)]
    seen = set()
    while stack:
        node, world_from_node = stack.pop()
        if node in seen:  # a node listed twice (or a cycle in a broken file) is walked once
            continue
        seen.add(node)
        geometry = forest.node_data.get(node, {}).get("geometry")
        if geometry is not None:
            matrix = world_from_node
            if graph.repair_rigid is not None:
                matrix = fix_rigid(matrix, max_deviance=graph.repair_rigid)
            placements[node] = (matrix, geometry)
        for child in forest.children.get(node, ()):
            node_from_child = forest.edge_data.get((node, child), {}).get("matrix")
            world_from_child = world_from_node
            if node_from_child is not None and np.abs(node_from_child - identity).max() > 1e-8:
                world_from_child = node_from_child if world_from_node is identity else world_from_node @ node_from_child
            stack.append((child, world_from_child))
    return placements


def _memory_error(file: Path) -> GeometryError:
    """A MemoryError while loading `file`, said truthfully: corrupt if a valid file of its size fits the budget."""
    size = file.stat().st_size
    if size * _LOAD_BYTES_PER_FILE_BYTE < get_budget().bytes:  # a file this small should load: a bad count
        return GeometryError(
            f"load: path = {str(file)!r} ({format_bytes(size)}) ran out of memory while loading, although a "
            f"valid file of this size needs about {format_bytes(size * _LOAD_BYTES_PER_FILE_BYTE)}; the file is "
            "corrupt (a length or count in it far beyond its data)"
        )
    return GeometryError(
        f"load: path = {str(file)!r} ({format_bytes(size)}) ran out of memory while loading; "
        "the file is valid but too large for this machine: free memory or lower the budget with "
        "frustum.set_budget(bytes=...) so such files are refused up front"
    )


def _read_error(file: Path, error: BaseException) -> GeometryError:
    reason = str(error).strip().splitlines()[0] if str(error).strip() else "no details"
    if len(reason) > 160:
        reason = reason[:157] + "..."
    return GeometryError(
        f"load: path = {str(file)!r} could not be read as {file.suffix.lower()} ({type(error).__name__}: {reason}); "
        "the file is corrupt, truncated or not in that format"
    )


def _from_trimesh(geometry: Any) -> tuple[Mesh, NDArray[np.uint8] | None, tuple | None]:
    vertices = np.asarray(geometry.vertices, dtype=np.float64)
    faces = np.asarray(geometry.faces, dtype=np.int64)
    normals = None
    if "vertex_normals" in geometry._cache.cache:  # normals that came from the file, not computed by trimesh
        candidate = np.asarray(geometry.vertex_normals, dtype=np.float64)
        if candidate.shape == vertices.shape and np.isfinite(candidate).all() and (np.abs(candidate).sum(1) > 0).all():
            normals = candidate
    uvs = colors = image = base = None
    visual = geometry.visual
    kind = getattr(visual, "kind", None)
    if kind == "texture":
        uv = getattr(visual, "uv", None)
        if uv is not None and len(uv) == len(vertices):
            uvs = np.asarray(uv, dtype=np.float64)
        material = getattr(visual, "material", None)
        image = _material_image(material)
        placeholder = image is None and getattr(material, "image", None) is not None
        base = None if placeholder else _material_color(material)
    elif kind == "vertex":
        colors = np.asarray(visual.vertex_colors, dtype=np.uint8)
        if (colors[:, 3] == 255).all():
            colors = colors[:, :3]
    elif kind == "face":
        base = None  # per-face colors have no per-vertex form without splitting vertices; dropped
    return Mesh(vertices, faces, normals, uvs, colors), image, base


def _normal_texture(geometry: Any, name: str = "normalTexture") -> NDArray[np.uint8] | None:
    """The glTF material's texture `name` (``normalTexture``, ``emissiveTexture``) as (H, W, 3) bytes, or None."""
    image = getattr(getattr(geometry.visual, "material", None), name, None)
    if image is None or getattr(geometry.visual, "uv", None) is None:
        return None
    return np.asarray(image.convert("RGB"), dtype=np.uint8)


def _metallic_roughness(geometry: Any, file: Path | None) -> tuple[Any, ...]:
    """A glTF material's (metallicFactor, roughnessFactor, metallicRoughnessTexture, occlusionTexture, True), the
    textures as (H, W, 3) bytes (None without UVs); an OBJ material's from its MTL's PBR statements
    (``frustum.geometry.mtl_pbr``); (None, None, None, None, False) for other formats and other OBJ materials."""
    material = getattr(geometry.visual, "material", None)
    if file is not None and file.suffix.lower() == ".obj":
        return _mtl_physical(file, getattr(material, "name", None), getattr(geometry.visual, "uv", None) is not None)
    if file is None or file.suffix.lower() not in (".glb", ".gltf"):
        return None, None, None, None, False
    factors = []
    for name in ("metallicFactor", "roughnessFactor"):
        value = getattr(material, name, None)
        factors.append(None if value is None else float(np.clip(float(value), 0.0, 1.0)))
    images = []
    for name in ("metallicRoughnessTexture", "occlusionTexture"):
        image = getattr(material, name, None)
        has_uvs = getattr(geometry.visual, "uv", None) is not None
        images.append(None if image is None or not has_uvs else np.asarray(image.convert("RGB"), dtype=np.uint8))
    return (*factors, *images, True)


def _mtl_physical(file: Path, name: str | None, has_uvs: bool) -> tuple[Any, ...]:
    """``_metallic_roughness`` of the OBJ material `name` (trimesh's reading), from the MTL libraries `file` names."""
    from frustum.geometry.mtl_pbr import physical_materials

    folder = file.parent.resolve()
    for library in _MTL_LIBRARY.findall(file.read_bytes()) if name is not None else []:
        mtl = file.parent / library.decode("utf-8", "replace").strip()
        found = physical_materials(mtl).get(name) if mtl.resolve().is_relative_to(folder) else None
        if found is not None:
            texture = None if found.texture is None or not has_uvs else np.asarray(found.texture, dtype=np.uint8)
            return found.metallic, found.roughness, texture, None, True
    return None, None, None, None, False


def _emission_and_alpha(geometry: Any) -> tuple[tuple[float, float, float] | None, str | None]:
    """A glTF material's ``emissiveFactor`` (None when black or absent) and ``alphaMode`` (None when absent)."""
    material = getattr(geometry.visual, "material", None)
    factor = getattr(material, "emissiveFactor", None)
    emissive = None
    if factor is not None:
        rgb = np.asarray(factor, dtype=np.float64).ravel()[:3]
        if rgb.size == 3 and np.isfinite(rgb).all() and rgb.max() > 0.0:
            emissive = tuple(float(c) for c in np.clip(rgb, 0.0, 1.0))
    mode = getattr(material, "alphaMode", None)
    return emissive, (str(mode).upper() if mode is not None else None)


def _material_image(material: Any) -> NDArray[np.uint8] | None:
    if material is None:
        return None
    image = getattr(material, "image", None)
    if image is None:
        image = getattr(material, "baseColorTexture", None)
    if image is None:
        return None
    return _pil_array(image)


def _pil_array(image: Any) -> NDArray[np.uint8] | None:
    """A PIL image's pixels as RGB or RGBA bytes; None for trimesh's placeholder image."""
    array = np.asarray(image.convert("RGBA" if "A" in image.mode else "RGB"), dtype=np.uint8)
    if _is_placeholder(array):
        return None
    return array


def _is_placeholder(array: NDArray[np.uint8]) -> bool:
    # trimesh gives an OBJ with UVs but no material a uniform 2x2 placeholder image: that is no texture
    return array.shape[:2] == (2, 2) and bool((array == array[0, 0]).all())


def _material_color(material: Any) -> tuple[float, float, float, float] | None:
    if material is None:
        return None
    color = getattr(material, "baseColorFactor", None)
    if color is None:
        color = getattr(material, "diffuse", None)
    if color is None:
        return None
    rgba = np.asarray(color, dtype=np.float64).ravel()
    if rgba.size == 3:
        rgba = np.append(rgba, 255.0 if rgba.max() > 1.0 else 1.0)
    if rgba.size != 4 or not np.isfinite(rgba).all():
        return None
    if rgba.max() > 1.0:
        rgba = rgba / 255.0
    return tuple(float(c) for c in np.clip(rgba, 0.0, 1.0))  # type: ignore[return-value]


_MTL_LIBRARY = re.compile(rb"^[ \t]*mtllib[ \t]+([^\r\n#]+)", re.MULTILINE)
_MTL_TEXTURE = re.compile(r"^[ \t]*(map_\w+|bump|disp|decal|norm|refl)[ \t]+([^\r\n#]+)", re.MULTILINE | re.IGNORECASE)


def _warn_unreadable_textures(file: Path, text: bytes | None) -> None:
    """A ``FrustumWarning`` for each texture an OBJ's MTL files name that cannot be read: missing, not a regular
    file, or outside the OBJ's folder (never read from there). The material is drawn without it, as before, but no
    longer silently."""
    import warnings

    from frustum.errors import FrustumWarning

    data = text if text is not None else file.read_bytes()
    folder = file.parent.resolve()
    for library in _MTL_LIBRARY.findall(data):
        mtl = file.parent / library.decode("utf-8", "replace").strip()
        if not mtl.resolve().is_relative_to(folder) or not mtl.is_file():
            continue  # a missing library: the model loads without materials, as trimesh does
        for key, value in _MTL_TEXTURE.findall(mtl.read_text("utf-8", "replace")):
            name = value.split()[-1] if value.split() else value  # options such as -bm 0.5 come before the name
            texture = (mtl.parent / name).resolve()
            if not texture.is_relative_to(folder):
                problem = "lies outside the model's folder (never read from there)"
            elif not texture.exists():
                problem = "does not exist"
            elif not texture.is_file():
                problem = f"is not a regular file ({file_kind(texture)})"
            else:
                continue
            warnings.warn(f"load: {mtl.name} ({key}) names the texture {name!r}, which {problem}; "
                          f"{file.name} is drawn without it", FrustumWarning, stacklevel=3)  # fmt: skip


def _sibling_texture(file: Path) -> NDArray[np.uint8] | None:
    stem = file.stem
    names = [stem, f"{stem}_texture", f"{stem.split('_')[0]}_texture"]
    for name in names:
        for suffix in _IMAGE_SUFFIXES:
            candidate = file.with_name(name + suffix)
            if candidate.is_file():
                return _read_image(candidate, "load")
    return None


def _read_image(file: Path, where: str) -> NDArray[np.uint8]:
    from PIL import UnidentifiedImageError

    if not file.is_file():
        raise GeometryError(f"{where}: texture = {str(file)!r} does not exist; give the path of an image file")
    from frustum._images import open_image

    try:
        with open_image(file, where=where, name=f"texture = {str(file)!r}", error=GeometryError) as image:
            return np.asarray(image.convert("RGBA" if "A" in image.mode else "RGB"), dtype=np.uint8)
    except (OSError, UnidentifiedImageError) as error:
        raise GeometryError(f"{where}: texture = {str(file)!r} is not a readable image ({error})") from None


def _is_identity(matrix: NDArray[np.float64]) -> bool:
    return bool(np.array_equal(matrix, np.eye(4)))
