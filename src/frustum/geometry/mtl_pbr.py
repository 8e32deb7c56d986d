"""The PBR extension of MTL files: ``Pr`` (roughness), ``Pm`` (metallic), ``map_Pr`` and ``map_Pm``.

An OBJ whose material carries any of these four statements loads as a glTF-style metallic–roughness material
(``MeshPart.physical``, then ``Material(model="pbr")``); one without them stays a classical (Phong) material,
read exactly as before. The values follow glTF's convention so that one shading path serves both formats:

- ``Pm`` is the metallic factor (0 when only the others are given), ``Pr`` the roughness factor (0.5, the
  ``Material`` default, when only the others are given), both clamped to [0, 1];
- ``map_Pr`` and ``map_Pm`` are gray images packed into one metallic–roughness texture as glTF's
  ``metallicRoughnessTexture`` (G = roughness, B = metallic; a channel without an image is 255), which multiplies
  the factors; a texture given without its factor gets the factor 1 (the image alone decides, as Blender's
  importer reads it). Where both images are given at different sizes the metallic one is resized to the
  roughness one's. Options before a texture's name (``-bm 0.5``) are skipped; a texture that cannot be read is
  left out (``io.load_parts`` warns about it).

References: the "PBR extension" of the MTL format (Exocortex, 2016), as Blender and tinyobjloader read it.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, NamedTuple

__all__ = ["MtlPhysical", "physical_materials"]

_KEYS = ("pr", "pm", "map_pr", "map_pm")


class MtlPhysical(NamedTuple):
    """One MTL material's metallic–roughness description."""

    metallic: float
    roughness: float
    texture: Any  # a PIL "RGB" image (G roughness, B metallic) or None


def physical_materials(library: Path) -> dict[str, MtlPhysical]:
    """name -> ``MtlPhysical`` for each material of the MTL file `library` with a PBR statement (module docstring);
    materials without one, or a library that is not a readable file, give nothing."""
    if not library.is_file():
        return {}
    found: dict[str, dict[str, Any]] = {}
    name = None
    for line in library.read_text("utf-8", "replace").splitlines():
        words = line.split()
        if len(words) < 2 or words[0].startswith("#"):
            continue
        key = words[0].lower()
        if key == "newmtl":
            name = " ".join(words[1:])
        elif key in _KEYS and name is not None:
            found.setdefault(name, {})[key] = words[-1] if key.startswith("map_") else words[1]
    return {material: _physical(library, values) for material, values in found.items()}


def _physical(library: Path, values: dict[str, str]) -> MtlPhysical:
    images = {key: _gray(library, values[key]) for key in ("map_pr", "map_pm") if key in values}
    images = {key: image for key, image in images.items() if image is not None}
    metallic = _factor(values.get("pm"), 1.0 if "map_pm" in images else 0.0)
    roughness = _factor(values.get("pr"), 1.0 if "map_pr" in images else 0.5)
    return MtlPhysical(metallic, roughness, _packed(images.get("map_pr"), images.get("map_pm")))


def _factor(text: str | None, default: float) -> float:
    if text is None:
        return default
    try:
        value = float(text)
    except ValueError:
        return default
    return min(max(value, 0.0), 1.0) if value == value else default


def _gray(library: Path, name: str) -> Any:
    """The image `name` beside `library` as a PIL "L" image, or None when it is missing or unreadable (or lies
    outside the library's folder)."""
    from PIL import Image, UnidentifiedImageError

    from frustum._images import open_image
    from frustum.errors import GeometryError

    file = (library.parent / name).resolve()
    if not file.is_relative_to(library.parent.resolve()) or not file.is_file():
        return None
    try:
        with open_image(file, where=f"load: {library.name}", name=name, error=GeometryError) as image:
            gray: Image.Image = image.convert("L")
            return gray
    except (OSError, UnidentifiedImageError):
        return None


def _packed(roughness: Any, metallic: Any) -> Any:
    """One RGB image: R 255, G `roughness`, B `metallic` (255 where an image is None); None without images."""
    from PIL import Image

    if roughness is None and metallic is None:
        return None
    size = (roughness or metallic).size
    if metallic is not None and metallic.size != size:
        metallic = metallic.resize(size, Image.Resampling.BILINEAR)
    full = Image.new("L", size, 255)
    return Image.merge("RGB", (full, roughness or full, metallic or full))
