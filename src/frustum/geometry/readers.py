"""frustum's own readers for the plain, well-formed cases of the mesh formats, so that rendering a mesh file does not
import trimesh (about 0.7-1.1 s: it imports SciPy's spatial and optimize modules and NetworkX on the way).

``read_parts`` returns exactly what ``frustum.geometry.io.load_parts`` builds through trimesh (``process=False``)
for the same file: the same vertices in the same order, faces, file normals, UVs, texture image, base colour and
part name; ``tests/test_io.py`` checks this against trimesh on every test file and on generated ones. Anything
outside the plain subset below returns None and the caller reads the file through trimesh as before, so unusual
files and every error message stay trimesh's (and ``load_parts``'s):

- binary STL (the exact size ``84 + 50 n``; ASCII STL goes to trimesh);
- PLY, ASCII or binary: a ``vertex`` element of scalar x, y, z (optional nx, ny, nz and ignored confidence /
  intensity / quality values), then a ``face`` element holding only the vertex index list, all triangles;
  no colours, texture coordinates or texture-file comments;
- OFF: triangles, no comments or colours;
- OBJ: ``v`` (x y z), ``vt``, ``vn``, triangle ``f`` lines of one form with positive indices, at most one
  ``mtllib`` and one ``usemtl`` before the faces (the MTL's ``Kd`` and ``map_Kd``, and its PBR statements:
  ``frustum.geometry.mtl_pbr``), no ``o``/``g`` lines;
- glTF 2.0 binary (GLB) and JSON (``.gltf``, buffers in files beside it or embedded as base64 data URIs):
  nodes without placements (no matrix or TRS: trimesh repairs those), one indexed triangle primitive per mesh
  with POSITION, NORMAL and TEXCOORD_0, materials' base colour factor and texture (an image in a buffer view),
  metallic and roughness factors, metallic–roughness and occlusion textures,
  normal texture, emissive factor and alpha mode; no extensions, sparse accessors, vertex colours, skins,
  cameras or morph targets.
"""

from __future__ import annotations

import base64
import io
import json
import re
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from frustum.errors import FrustumError, GeometryError

__all__ = ["RawPart", "read_parts"]


class RawPart(NamedTuple):
    """One part as read: what ``MeshPart`` holds, with the mesh still as arrays."""

    name: str
    vertices: NDArray[np.float64]
    faces: NDArray[np.int64]
    normals: NDArray[np.float64] | None
    uvs: NDArray[np.float64] | None
    world_from_model: NDArray[np.float64]
    image: Any  # a PIL image or None
    color: tuple[float, float, float, float] | None
    normal_image: Any = None
    emissive: tuple[float, float, float] | None = None
    alpha_mode: str | None = None
    metallic: float | None = None
    roughness: float | None = None
    metallic_roughness_image: Any = None
    occlusion_image: Any = None
    emissive_image: Any = None


class UnsupportedError(Exception):
    """The file uses something outside the plain subset: trimesh reads it."""


def read_parts(file: Path, data: bytes | None = None) -> list[RawPart] | None:
    """The parts of `file` (its bytes in `data`, or read here), or None when trimesh must read it."""
    suffix = file.suffix.lower()
    reader = _READERS.get(suffix)
    if reader is None:
        return None
    try:
        return reader(file, file.read_bytes() if data is None else data)
    except (MemoryError, FrustumError):  # out of memory, or an image over the budget: not trimesh's to retry
        raise
    except Exception:  # anything unusual or malformed: trimesh reads it and reports what is wrong
        return None


_IDENTITY = np.eye(4)


def _single(file: Path, vertices: Any, faces: Any, normals: Any = None) -> list[RawPart]:
    vertices = np.asarray(vertices, dtype=np.float64)
    faces = np.asarray(faces, dtype=np.int64)
    if faces.ndim != 2 or faces.shape[1] != 3 or len(faces) == 0 or vertices.ndim != 2 or vertices.shape[1] != 3:
        raise UnsupportedError("shape")
    if faces.min() < 0 or faces.max() >= len(vertices):
        raise UnsupportedError("index range")
    if normals is not None:
        normals = _file_normals(normals, vertices)
    return [RawPart(file.name, vertices, faces, normals, None, _IDENTITY.copy(), None, None)]


def _file_normals(normals: Any, vertices: NDArray[np.float64]) -> NDArray[np.float64] | None:
    """As ``io._from_trimesh``: file normals are kept when finite and nonzero everywhere."""
    normals = np.asarray(normals, dtype=np.float64)
    if normals.shape == vertices.shape and np.isfinite(normals).all() and (np.abs(normals).sum(1) > 0).all():
        return normals
    return None


# --- STL ----------------------------------------------------------------------------------------------------

_STL_RECORD = np.dtype([("normals", "<f4", (3,)), ("vertices", "<f4", (3, 3)), ("attributes", "<u2")])


def _read_stl(file: Path, data: bytes) -> list[RawPart]:
    if len(data) < 84:
        raise UnsupportedError("short")
    count = int.from_bytes(data[80:84], "little")
    if len(data) != 84 + 50 * count or count == 0:
        raise UnsupportedError("not a binary STL of the announced size (ASCII STL, or truncated)")
    records = np.frombuffer(data, dtype=_STL_RECORD, offset=84)
    vertices = records["vertices"].reshape(-1, 3)
    return _single(file, vertices, np.arange(3 * count).reshape(-1, 3))


# --- PLY ----------------------------------------------------------------------------------------------------

_PLY_TYPES = {
    "char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1", "short": "i2", "int16": "i2", "ushort": "u2",
    "uint16": "u2", "int": "i4", "int32": "i4", "uint": "u4", "uint32": "u4", "float": "f4", "float32": "f4",
    "double": "f8", "float64": "f8",
}  # fmt: skip
_PLY_INDEX_NAMES = ("vertex_indices", "vertex_index")
_PLY_VERTEX_NAMES = {"x", "y", "z", "nx", "ny", "nz", "confidence", "intensity", "quality"}


def ply_header(lines: list[str]) -> tuple[str, list[tuple[str, int, list[tuple[str, ...]]]], list[str]]:
    """(format, elements as (name, count, property words), the other lines: comments and unknown keywords) of a
    PLY header's lines after ``ply`` (``obj_info`` lines skipped); a malformed line raises ValueError(line)."""
    fmt = ""
    elements: list[tuple[str, int, list[tuple[str, ...]]]] = []
    others: list[str] = []
    for line in lines:
        words = line.split()
        if not words or words[0] == "obj_info":
            continue
        try:
            if words[0] == "format":
                fmt = words[1]
            elif words[0] == "element":
                elements.append((words[1], int(words[2]), []))
            elif words[0] == "property":
                elements[-1][2].append(tuple(words[1:]))
            else:
                others.append(line)
        except (IndexError, ValueError):
            raise ValueError(line) from None
    return fmt, elements, others


def _read_ply(file: Path, data: bytes) -> list[RawPart]:
    end = data.find(b"end_header")
    if end < 0 or not data.startswith(b"ply"):
        raise UnsupportedError("no header")
    body = data.index(b"\n", end) + 1
    lines = data[:end].decode("utf-8").splitlines()[1:]
    fmt, elements, others = ply_header(lines)
    if any(line.split()[0] != "comment" or "texturefile" in line.lower() for line in others):
        raise UnsupportedError("header line")  # a texture file, or a keyword trimesh knows
    if [e[0] for e in elements] != ["vertex", "face"]:
        raise UnsupportedError("elements")
    (_, vertex_count, vertex_props), (_, face_count, face_props) = elements
    names = [p[-1] for p in vertex_props]
    if not {"x", "y", "z"} <= set(names) or not set(names) <= _PLY_VERTEX_NAMES or len(set(names)) != len(names):
        raise UnsupportedError("vertex properties")
    if any(len(p) != 2 or p[0] not in _PLY_TYPES for p in vertex_props):
        raise UnsupportedError("vertex property types")
    if len(face_props) != 1 or face_props[0][0] != "list" or face_props[0][-1] not in _PLY_INDEX_NAMES:
        raise UnsupportedError("face properties")
    count_type, index_type = (_PLY_TYPES[t] for t in face_props[0][1:3])
    if index_type[0] == "f" or count_type[0] == "f" or face_count == 0 or vertex_count == 0:
        raise UnsupportedError("face types")
    if fmt == "ascii":
        numbers = np.array(data[body:].split(), dtype=np.float64)
        width = len(vertex_props)
        if numbers.size != vertex_count * width + face_count * 4:
            raise UnsupportedError("not all triangles, or extra data")
        table = numbers[: vertex_count * width].reshape(vertex_count, width)
        types = [_PLY_TYPES[p[0]] for p in vertex_props]  # parsed as float64, then stored as declared (as trimesh)
        columns = {name: table[:, i].astype(types[i]) for i, name in enumerate(names)}
        rows = numbers[vertex_count * width :].reshape(face_count, 4)
        if (rows[:, 0] != 3).any() or (rows[:, 1:] != np.round(rows[:, 1:])).any():
            raise UnsupportedError("not all triangles")
        faces = rows[:, 1:].astype(np.int64)
    elif fmt in ("binary_little_endian", "binary_big_endian"):
        order = "<" if fmt == "binary_little_endian" else ">"
        vertex_type = np.dtype([(name, order + _PLY_TYPES[p[0]]) for name, p in zip(names, vertex_props, strict=True)])
        face_type = np.dtype([("count", order + count_type), ("indices", order + index_type, (3,))])
        if len(data) - body != vertex_count * vertex_type.itemsize + face_count * face_type.itemsize:
            raise UnsupportedError("not all triangles, or extra data")
        table = np.frombuffer(data, dtype=vertex_type, count=vertex_count, offset=body)
        columns = {name: table[name] for name in names}
        rows = np.frombuffer(data, dtype=face_type, count=face_count, offset=body + vertex_count * vertex_type.itemsize)
        if (rows["count"] != 3).any():
            raise UnsupportedError("not all triangles")
        faces = rows["indices"].astype(np.int64)
    else:
        raise UnsupportedError("format")
    vertices = np.column_stack([columns[c] for c in "xyz"])
    normals = np.column_stack([columns[c] for c in ("nx", "ny", "nz")]) if "nx" in columns else None
    if normals is not None and not {"ny", "nz"} <= set(columns):
        raise UnsupportedError("partial normals")
    return _single(file, vertices, faces, normals)


# --- OFF ----------------------------------------------------------------------------------------------------


def _read_off(file: Path, data: bytes) -> list[RawPart]:
    text = data.decode("utf-8")
    if "#" in text:
        raise UnsupportedError("comments")
    lines = [line.split() for line in text.strip().splitlines()]
    lines = [words for words in lines if words]
    if lines[0] != ["OFF"]:
        raise UnsupportedError("header")
    vertex_count, face_count = int(lines[1][0]), int(lines[1][1])
    vertex_lines = lines[2 : 2 + vertex_count]
    face_lines = lines[2 + vertex_count : 2 + vertex_count + face_count]
    if len(vertex_lines) != vertex_count or len(face_lines) != face_count or face_count == 0:
        raise UnsupportedError("counts")
    if any(len(words) != 3 for words in vertex_lines) or any(len(w) != 4 or w[0] != "3" for w in face_lines):
        raise UnsupportedError("not plain triangles")
    vertices = np.array(vertex_lines, dtype=np.float64)
    faces = np.array([w[1:] for w in face_lines], dtype=np.int64)
    return _single(file, vertices, faces)


# --- OBJ ----------------------------------------------------------------------------------------------------

_OBJ_KEYWORDS = {"v", "vt", "vn", "f", "s", "usemtl", "mtllib"}
_DEFAULT_OBJ_COLOR = (102 / 255, 102 / 255, 102 / 255, 1.0)  # trimesh's default diffuse for a material without Kd


OBJ_NATIVE_BYTES = 16 * 2**20
"""Largest OBJ file read here (bytes). This reader walks the lines in Python (about 6 µs a face against trimesh's
2.5 µs); past ~25 MB trimesh's faster parser repays its import (0.7-1.1 s), so larger files go to trimesh."""


def _read_obj(file: Path, data: bytes) -> list[RawPart]:
    if len(data) > OBJ_NATIVE_BYTES:
        raise UnsupportedError("a large file: trimesh's parser is faster")
    text = data.decode("utf-8")
    if "\\\n" in text or "+e" in text or "-e" in text or "\r" in text:
        raise UnsupportedError("continuations, odd exponents or CR line ends")
    lines = text.splitlines()
    groups: dict[str, list[str]] = {"v": [], "vt": [], "vn": [], "f": []}
    material = library = None
    for line in lines:
        words = line.split(None, 1)
        if not words or words[0].startswith("#"):
            continue
        key = words[0]
        if key not in _OBJ_KEYWORDS or len(words) < 2:
            raise UnsupportedError(key)
        if key in groups:
            groups[key].append(words[1])
        elif key == "usemtl":
            if material is not None or groups["f"]:
                raise UnsupportedError("several materials, or faces before the material")
            material = words[1].strip()
        elif key == "mtllib":
            if library is not None:
                raise UnsupportedError("several material libraries")
            library = words[1].strip()
    if not groups["v"] or not groups["f"]:
        raise UnsupportedError("no vertices or faces")
    if library is not None and text.find("mtllib") != text.find("\nmtllib") + 1 and not text.startswith("mtllib"):
        raise UnsupportedError("'mtllib' before the library line")  # trimesh takes the first 'mtllib' anywhere
    v = _obj_table(groups["v"], (3,))
    vt = _obj_table(groups["vt"], (2, 3))[:, :2] if groups["vt"] else None
    vn = _obj_table(groups["vn"], (3,)) if groups["vn"] else None
    faces, faces_tex, faces_norm = _obj_faces(groups["f"])
    for indices, table in ((faces, v), (faces_tex, vt), (faces_norm, vn)):
        if indices is not None and (table is None or indices.min() < 0 or indices.max() >= len(table)):
            raise UnsupportedError("index out of range")
    uv = normals = None
    if faces_tex is not None:
        if faces_norm is not None:
            new_faces, mask_v, mask_vt, mask_vn = _unmerge_faces(faces, faces_tex, faces_norm)
            normals = vn[mask_vn]
        else:
            new_faces, mask_v, mask_vt = _unmerge_faces(faces, faces_tex)
        uv = vt[mask_vt]
    elif faces_norm is not None:
        new_faces, mask_v, mask_vn = _unmerge_faces(faces, faces_norm)
        normals = vn[mask_vn]
    else:
        used = np.zeros(len(v), dtype=bool)
        used[faces] = True
        inverse = np.zeros(len(v), dtype=np.int64)
        inverse[used] = np.arange(used.sum())
        new_faces, mask_v = inverse[faces], used
    vertices = v[mask_v]
    if library is not None and not _plain_name(library):
        raise UnsupportedError("a path in the library name")
    materials = _read_mtl(file.parent / library) if library is not None else {}
    name = file.name
    if len(materials) > 1 and material is not None:
        name = material
    image = color = None  # no material: no texture, no colour (UVs alone get trimesh's placeholder: the same)
    if material in materials:
        image, color = materials[material]
    if normals is not None:
        normals = _file_normals(normals, vertices)
    physical = None  # the MTL's PBR statements (frustum.geometry.mtl_pbr), when the material has any
    if material in materials:
        from frustum.geometry.mtl_pbr import physical_materials

        physical = physical_materials(file.parent / library).get(material)  # type: ignore[operator]
    if physical is None:
        return [RawPart(name, vertices, new_faces, normals, uv, _IDENTITY.copy(), image, color)]
    texture = physical.texture if uv is not None else None
    return [RawPart(name, vertices, new_faces, normals, uv, _IDENTITY.copy(), image, color, metallic=physical.metallic,
                    roughness=physical.roughness, metallic_roughness_image=texture)]  # fmt: skip


def _plain_name(name: str) -> bool:
    """A file name without folders, options or odd characters: resolved beside the OBJ file, as trimesh does."""
    return bool(re.fullmatch(r"[\w.+-]+", name)) and name not in (".", "..")


def _obj_table(rows: list[str], widths: tuple[int, ...]) -> NDArray[np.float64]:
    first = len(rows[0].split())
    if first not in widths:
        raise UnsupportedError("row width")
    numbers = np.array(" ".join(rows).split(), dtype=np.float64)
    if numbers.size != first * len(rows) or any(len(row.split()) != first for row in rows):
        raise UnsupportedError("rows of different widths")
    return numbers.reshape(len(rows), first)


_OBJ_CORNER_FORMS = {
    re.compile(r"\d+"): 1, re.compile(r"\d+/\d+"): 2, re.compile(r"\d+//\d+"): 2, re.compile(r"\d+/\d+/\d+"): 3,
}  # fmt: skip


def _obj_faces(rows: list[str]) -> tuple[NDArray[np.int64], NDArray[np.int64] | None, NDArray[np.int64] | None]:
    sample = rows[0].split()
    if len(sample) != 3:
        raise UnsupportedError("not triangles")
    form = next((pattern for pattern in _OBJ_CORNER_FORMS if pattern.fullmatch(sample[0])), None)
    if form is None:
        raise UnsupportedError("corner form")
    joined = " ".join(rows)
    corners = joined.split()
    if len(corners) != 3 * len(rows) or any(len(row.split()) != 3 for row in rows):
        raise UnsupportedError("not all triangles")
    if not all(form.fullmatch(corner) for corner in corners):
        raise UnsupportedError("mixed corner forms")
    per = _OBJ_CORNER_FORMS[form]
    numbers = np.array(joined.replace("/", " ").split(), dtype=np.int64).reshape(len(rows), 3, per) - 1
    if per == 1:
        return numbers[:, :, 0], None, None
    if per == 2:
        second = numbers[:, :, 1]
        return (numbers[:, :, 0], None, second) if "//" in sample[0] else (numbers[:, :, 0], second, None)
    return numbers[:, :, 0], numbers[:, :, 1], numbers[:, :, 2]


def _unmerge_faces(faces: NDArray[np.int64], *others: NDArray[np.int64]) -> list[NDArray[np.int64]]:
    """trimesh's ``visual.texture.unmerge_faces``: one vertex per distinct (v, vt[, vn]) corner, ordered as
    trimesh orders them (rows hashed as trimesh's ``grouping.hashable_rows``, ``np.unique``, then a quicksort of
    the vertex index), so vertex order and faces are identical."""
    stack = np.column_stack([faces.reshape(-1), *(o.reshape(-1) for o in others)])
    unique, inverse = np.unique(_hashable_rows(stack), return_index=True, return_inverse=True)[1:]
    pairs = stack[unique]
    order = pairs[:, 0].argsort()
    pairs = pairs[order]
    remap = np.zeros(len(order), dtype=np.int64)
    remap[order] = np.arange(len(order))
    return [remap[inverse].reshape((-1, faces.shape[1])), *pairs.T]


def _hashable_rows(rows: NDArray[np.int64]) -> NDArray[Any]:
    """trimesh's ``grouping.hashable_rows`` for integer rows."""
    precision = int(np.floor(64 / rows.shape[1]))
    low, high = rows.min(), rows.max()
    threshold = (2 ** (precision - 1)) - 1
    if rows.shape[1] <= 4 and high < threshold and low > -threshold:
        hashable = np.zeros(len(rows), dtype=np.uint64)
        bits = (rows.T + (threshold + 1)).astype(np.uint64)
        for offset, column in enumerate(bits):
            np.bitwise_xor(hashable, column << np.uint64(offset * precision), out=hashable)
        return hashable
    return np.ascontiguousarray(rows).view(np.dtype((np.void, rows.dtype.itemsize * rows.shape[1]))).reshape(-1)


def _read_mtl(file: Path) -> dict[str, tuple[Any, tuple[float, float, float, float]]]:
    """name -> (PIL image or None, base colour) of an MTL file, as trimesh's ``parse_mtl`` and ``SimpleMaterial``
    give them (``Kd`` rounded to bytes; no ``Kd``: trimesh's default gray)."""
    if not _plain_name(file.name):
        raise UnsupportedError("a path in the library name")  # trimesh's resolver tries several readings
    if not file.is_file():
        return {}  # as trimesh: the file reads on without materials
    materials: dict[str, tuple[Any, tuple[float, float, float, float]]] = {}
    name = None
    image: Any = None
    color = _DEFAULT_OBJ_COLOR
    for line in file.read_text("utf-8").strip().splitlines():
        words = line.strip().split()
        if len(words) <= 1:
            continue
        key = words[0].lower()
        if key == "newmtl":
            if name is not None:
                materials[name] = (image, color)
            name, image, color = " ".join(words[1:]), None, _DEFAULT_OBJ_COLOR
        elif key.startswith("#"):
            continue
        elif name is None:
            if key == "map_kd":
                raise UnsupportedError("a texture before newmtl")
            continue  # trimesh ignores statements before the first material
        elif key == "map_kd":
            index = line.lower().index("map_kd") + 6
            texture = file.parent / line[index:].strip()
            if not _plain_name(line[index:].strip()):
                raise UnsupportedError("a path or options in map_Kd")  # trimesh's resolver tries several readings
            image = _open_image(io.BytesIO(texture.read_bytes()), file, texture.name) if texture.is_file() else None
        elif key == "kd":
            values = [float(x) for x in words[1:]]
            if len(values) != 3:
                raise UnsupportedError("Kd")
            rgb = np.clip(np.asarray(values) * 255, 0.0, 255.0).round().astype(np.uint8)
            color = (*(float(c) / 255.0 for c in rgb), 1.0)  # type: ignore[assignment]
    if name is not None:
        materials[name] = (image, color)
    return materials


# --- glTF ---------------------------------------------------------------------------------------------------

_COMPONENTS = {5120: "i1", 5121: "u1", 5122: "i2", 5123: "u2", 5125: "u4", 5126: "f4"}
_GLTF_MATERIAL_KEYS = {"name", "pbrMetallicRoughness", "normalTexture", "occlusionTexture", "emissiveTexture",
                       "emissiveFactor", "alphaMode", "doubleSided"}  # fmt: skip
_GLTF_PBR_KEYS = {"baseColorFactor", "baseColorTexture", "metallicFactor", "roughnessFactor",
                  "metallicRoughnessTexture"}  # fmt: skip
_WIDTHS = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}


def _read_glb(file: Path, data: bytes) -> list[RawPart]:
    if data[:4] != b"glTF" or int.from_bytes(data[4:8], "little") != 2:
        raise UnsupportedError("not GLB 2")
    offset, chunks = 12, []
    while offset + 8 <= len(data):
        length = int.from_bytes(data[offset : offset + 4], "little")
        chunks.append((data[offset + 4 : offset + 8], data[offset + 8 : offset + 8 + length]))
        offset += 8 + length
    if not chunks or chunks[0][0] != b"JSON":
        raise UnsupportedError("no JSON chunk")
    binary = chunks[1][1] if len(chunks) > 1 and chunks[1][0] == b"BIN\x00" else None
    return _gltf_parts(file, json.loads(chunks[0][1]), binary)


def _read_gltf(file: Path, data: bytes) -> list[RawPart]:
    return _gltf_parts(file, json.loads(data), None)


def _gltf_parts(file: Path, gltf: dict[str, Any], binary: bytes | None) -> list[RawPart]:
    if gltf.get("extensionsUsed") or gltf.get("extensionsRequired") or str(gltf["asset"]["version"]) != "2.0":
        raise UnsupportedError("extensions or version")
    if gltf.get("skins") or gltf.get("animations"):
        raise UnsupportedError("skins or animations")
    buffers = [_gltf_buffer(file, b, binary) for b in gltf.get("buffers", [])]
    views = gltf.get("bufferViews", [])

    def view_bytes(index: int) -> bytes:
        view = views[index]
        start = view.get("byteOffset", 0)
        return buffers[view["buffer"]][start : start + view["byteLength"]]

    def accessor(index: int) -> NDArray[Any]:
        spec = gltf["accessors"][index]
        if "sparse" in spec or "bufferView" not in spec or spec.get("normalized"):
            raise UnsupportedError("accessor")
        view = views[spec["bufferView"]]
        dtype = np.dtype("<" + _COMPONENTS[spec["componentType"]])
        width = _WIDTHS[spec["type"]]
        if view.get("byteStride", dtype.itemsize * width) != dtype.itemsize * width:
            raise UnsupportedError("interleaved")
        raw = view_bytes(spec["bufferView"])
        count = spec["count"]
        return np.frombuffer(raw, dtype=dtype, count=count * width, offset=spec.get("byteOffset", 0)).reshape(
            count, width
        )

    scene_index = gltf.get("scene", 0)
    roots = gltf["scenes"][scene_index]["nodes"]
    nodes = gltf.get("nodes", [])
    names = [str(node.get("name", str(i))) for i, node in enumerate(nodes)]
    if len(set(names)) != len(names) or "world" in names:
        raise UnsupportedError("node names")  # trimesh makes names unique its own way
    parts: list[RawPart] = []
    seen: set[int] = set()
    stack = list(roots)
    while stack:
        index = stack.pop()
        node = nodes[index]
        if index in seen or set(node) - {"name", "mesh", "children"}:
            raise UnsupportedError("node")  # placements (fixed up by trimesh), cameras, skins: trimesh reads them
        seen.add(index)
        if "mesh" in node:
            mesh = gltf["meshes"][node["mesh"]]
            if len(mesh["primitives"]) != 1:
                raise UnsupportedError("several primitives")
            parts.append(_gltf_part(gltf, mesh["primitives"][0], names[index], accessor, view_bytes))
        stack.extend(node.get("children", []))
    if not parts:
        raise UnsupportedError("no meshes")
    return sorted(parts, key=lambda part: part.name)


def _gltf_buffer(file: Path, buffer: dict[str, Any], binary: bytes | None) -> bytes:
    uri = buffer.get("uri")
    if uri is None:
        if binary is None:
            raise UnsupportedError("no binary chunk")
        return binary
    if uri.startswith("data:"):
        return base64.b64decode(uri.split(",", 1)[1])
    if "/" in uri.replace("\\", "/") or "%" in uri:
        raise UnsupportedError("buffer path")
    return (file.parent / uri).read_bytes()


def _gltf_part(gltf: dict[str, Any], primitive: dict[str, Any], name: str, accessor: Any,
               view_bytes: Any) -> RawPart:  # fmt: skip
    if primitive.get("mode", 4) != 4 or primitive.get("targets") or primitive.get("extensions"):
        raise UnsupportedError("primitive")
    attributes = primitive["attributes"]
    if not set(attributes) <= {"POSITION", "NORMAL", "TEXCOORD_0"} or "indices" not in primitive:
        raise UnsupportedError("attributes")
    vertices = accessor(attributes["POSITION"]).astype(np.float64)
    faces = accessor(primitive["indices"]).astype(np.int64).reshape(-1, 3)
    if faces.min() < 0 or faces.max() >= len(vertices):
        raise UnsupportedError("index range")
    normals = _file_normals(accessor(attributes["NORMAL"]), vertices) if "NORMAL" in attributes else None
    uvs = None
    if "TEXCOORD_0" in attributes and "material" in primitive:  # trimesh keeps UVs with a material only
        uvs = accessor(attributes["TEXCOORD_0"]).copy()
        if uvs.dtype != np.float32 or uvs.shape != (len(vertices), 2):
            raise UnsupportedError("UVs")
        uvs[:, 1] = 1.0 - uvs[:, 1]  # glTF's v runs down the image (flipped in float32, as trimesh does)
        uvs = uvs.astype(np.float64)
    image = color = normal_image = emissive = alpha_mode = None
    metallic = roughness = metallic_roughness_image = occlusion_image = emissive_image = None
    if "material" in primitive:
        material = gltf["materials"][primitive["material"]]
        if material.get("extensions") or not set(material) <= _GLTF_MATERIAL_KEYS:
            raise UnsupportedError("material")
        pbr = material.get("pbrMetallicRoughness", {})
        if not set(pbr) <= _GLTF_PBR_KEYS:
            raise UnsupportedError("material")
        metallic, roughness = (None if key not in pbr else float(np.clip(float(pbr[key]), 0.0, 1.0))
                               for key in ("metallicFactor", "roughnessFactor"))  # fmt: skip
        if "metallicRoughnessTexture" in pbr:
            metallic_roughness_image = _gltf_image(gltf, pbr["metallicRoughnessTexture"], view_bytes)
        if "occlusionTexture" in material:
            occlusion_image = _gltf_image(gltf, material["occlusionTexture"], view_bytes)
        color = _gltf_color(pbr["baseColorFactor"]) if "baseColorFactor" in pbr else None
        if "baseColorTexture" in pbr:
            image = _gltf_image(gltf, pbr["baseColorTexture"], view_bytes)
        if "normalTexture" in material:
            normal_image = _gltf_image(gltf, material["normalTexture"], view_bytes)
        if "emissiveTexture" in material:
            emissive_image = _gltf_image(gltf, material["emissiveTexture"], view_bytes)
        rgb = np.asarray(material.get("emissiveFactor", [0.0, 0.0, 0.0]), dtype=np.float64)
        if rgb.size == 3 and np.isfinite(rgb).all() and rgb.max() > 0.0:
            emissive = tuple(float(c) for c in np.clip(rgb, 0.0, 1.0))
        alpha_mode = str(material["alphaMode"]).upper() if "alphaMode" in material else None
    return RawPart(name, vertices, faces, normals, uvs, _IDENTITY.copy(), image, color, normal_image,
                   emissive, alpha_mode, metallic, roughness, metallic_roughness_image,
                   occlusion_image, emissive_image)  # type: ignore[arg-type]  # fmt: skip


def _gltf_color(factor: Any) -> tuple[float, float, float, float]:
    """trimesh stores ``baseColorFactor`` as bytes (``round(255 x)``); ``io._material_color`` divides by 255."""
    rgba = np.asarray(factor, dtype=np.float64)
    if rgba.shape != (4,) or not np.isfinite(rgba).all():
        raise UnsupportedError("base colour")
    stored = np.clip(rgba * 255, 0.0, 255.0).round().astype(np.uint8)
    return tuple(float(c) for c in np.clip(stored / 255.0, 0.0, 1.0))  # type: ignore[return-value]


def _gltf_image(gltf: dict[str, Any], reference: dict[str, Any], view_bytes: Any) -> Any:
    if set(reference) - {"index", "texCoord", "scale", "strength"} or reference.get("texCoord", 0) != 0:
        raise UnsupportedError("texture reference")
    texture = gltf["textures"][reference["index"]]
    source = gltf["images"][texture["source"]]
    if "bufferView" not in source:
        raise UnsupportedError("image file")
    return _open_image(io.BytesIO(view_bytes(source["bufferView"])), None, f"image {source.get('name', '')!r}")


def _open_image(data: Any, file: Path | None, name: str) -> Any:
    """An embedded or MTL image, its size checked against the memory budget before it is decoded."""
    from frustum._images import open_image

    where = "load" if file is None else f"load: {file.name}"
    return open_image(data, where=where, name=name, error=GeometryError)


_READERS = {".stl": _read_stl, ".ply": _read_ply, ".off": _read_off, ".obj": _read_obj, ".glb": _read_glb,
            ".gltf": _read_gltf}  # fmt: skip
