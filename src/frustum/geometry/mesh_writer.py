"""Writing mesh files (OBJ, STL, PLY, OFF, glTF/GLB) through trimesh: ``write_mesh``, behind ``io.save`` and
``Mesh.save``. It reads a mesh only through its arrays (vertices, faces, normals, UVs, vertex colors), so it
imports neither ``mesh`` nor ``io``: both import it, and there is no import circle between them."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from frustum._files import atomic_path, os_reason
from frustum.errors import GeometryError

SUPPORTED_SUFFIXES: tuple[str, ...] = (".obj", ".stl", ".ply", ".off", ".gltf", ".glb")
"""File suffixes `load` and `save` understand (case-insensitive)."""


def write_mesh(mesh: Any, path: str | Path, binary: bool = True, texture: Any = None) -> Path:
    """Write the ``Mesh`` `mesh` to `path` (``io.save`` checks that it is one and documents the formats)."""
    import trimesh

    file = Path(path)
    suffix = _suffix(file, "save")
    geometry = trimesh.Trimesh(
        vertices=np.array(mesh.vertices),
        faces=np.array(mesh.faces),
        vertex_normals=np.array(mesh.vertex_normals),
        process=False,
    )
    use_uvs = mesh.uvs is not None and suffix not in (".stl", ".off")
    if use_uvs and (texture is not None or mesh.vertex_colors is None):
        image = None
        if texture is not None:
            from PIL import Image

            image = Image.fromarray(_as_image(texture))
        # white diffuse, so readers that multiply the texture by the material color see the texture unchanged
        material = trimesh.visual.material.SimpleMaterial(image=image, diffuse=(255, 255, 255, 255))
        geometry.visual = trimesh.visual.TextureVisuals(uv=np.array(mesh.uvs), material=material)
    elif mesh.vertex_colors is not None and suffix != ".stl":
        colors = np.round(np.asarray(mesh.vertex_colors) * 255.0).astype(np.uint8)
        geometry.visual = trimesh.visual.ColorVisuals(geometry, vertex_colors=colors)
    file_type = suffix[1:]
    options: dict[str, Any] = {}
    if suffix == ".stl" and not binary:
        file_type = "stl_ascii"
    if suffix == ".ply":
        options["encoding"] = "binary" if binary else "ascii"
    try:
        if suffix == ".gltf":  # one self-contained JSON file, buffers embedded as data URIs
            from trimesh.exchange.gltf import export_gltf

            data = next(iter(export_gltf(trimesh.Scene(geometry), embed_buffers=True).values()))
        else:
            data = geometry.export(file_type=file_type, **options)
        if isinstance(data, str):
            data = data.encode("utf-8")
        if suffix == ".obj" and isinstance(data, bytes) and texture is not None:
            data = _obj_with_texture(geometry, file)
        _write_atomically(file, data)
    except OSError as error:
        raise GeometryError(
            f"save: path = {str(file)!r} cannot be written ({os_reason(error)}); check the folder"
        ) from None
    except GeometryError:
        raise
    except Exception as error:
        raise GeometryError(
            f"save: path = {str(file)!r} could not be written as {suffix} ({type(error).__name__}: {error})"
        ) from None
    return file


def _suffix(file: Path, where: str) -> str:
    suffix = file.suffix.lower()
    if suffix not in SUPPORTED_SUFFIXES:
        raise GeometryError(
            f"{where}: path = {str(file)!r} has suffix {suffix or '(none)'!r}, which is not a mesh format; "
            f"give one of {', '.join(SUPPORTED_SUFFIXES)}"
        )
    return suffix


def _as_image(texture: Any) -> NDArray[np.uint8]:
    image = np.asarray(texture)
    if image.ndim != 3 or image.shape[2] not in (3, 4) or image.dtype != np.uint8:
        raise GeometryError(
            f"save: texture has shape {image.shape} and dtype {image.dtype}; expected an (H, W, 3 or 4) uint8 image"
        )
    return image


def _obj_with_texture(geometry: Any, file: Path) -> bytes:
    from trimesh.exchange.obj import export_obj

    text, files = export_obj(geometry, return_texture=True, mtl_name=file.stem + ".mtl")
    for name, data in files.items():
        _write_atomically(file.parent / name, data)
    return text.encode("utf-8")


def _write_atomically(file: Path, data: bytes) -> None:
    """Write `data` to a temporary beside `file` and rename it: an existing file survives a failed write."""
    with atomic_path(file, where="save", error=GeometryError) as temporary:
        temporary.write_bytes(data)
