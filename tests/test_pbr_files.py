"""Metallic–roughness materials and lights as files carry them: the PBR statements of MTL files (``Pr``, ``Pm``,
``map_Pr``, ``map_Pm``), glTF's ``KHR_lights_punctual`` lights, the ray tracer's mirror for smooth metals, and the
output transform where the viewer, datasets and turntables render."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from PIL import Image

from frustum.geometry.io import load_parts
from frustum.scenefile.models import part_material

# --- MTL PBR statements -------------------------------------------------------------------------------------

_OBJ = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl a\nf 1/1 2/2 3/3\n"


def _obj_pair(folder: Path, mtl: str) -> tuple[Path, Path]:
    """The same triangle twice: a plain OBJ (frustum's own reader) and one with an ``o`` line (trimesh's)."""
    (folder / "m.mtl").write_text(mtl)
    (folder / "plain.obj").write_text(_OBJ)
    (folder / "object.obj").write_text("o thing\n" + _OBJ)
    return folder / "plain.obj", folder / "object.obj"


def test_an_mtl_with_pr_and_pm_loads_as_a_pbr_material(tmp_path):
    for path in _obj_pair(tmp_path, "newmtl a\nKd 0.8 0.2 0.1\nPr 0.3\nPm 0.75\n"):
        (part,) = load_parts(path)
        assert part.physical and (part.metallic, part.roughness) == (0.75, 0.3)
        material = part_material(part)
        assert material.model == "pbr" and (material.metallic, material.roughness) == (0.75, 0.3)
        assert np.allclose(material.color, np.round(np.array([0.8, 0.2, 0.1]) * 255) / 255)


def test_one_pbr_statement_gives_the_other_factor_its_default(tmp_path):
    for mtl, expected in (("Pr 0.2\n", (0.0, 0.2)), ("Pm 1\n", (1.0, 0.5)), ("Pm 7\nPr -1\n", (1.0, 0.0))):
        for path in _obj_pair(tmp_path, "newmtl a\nKd 1 1 1\n" + mtl):
            (part,) = load_parts(path)
            assert (part.metallic, part.roughness) == expected, (mtl, path.name)


def test_map_pr_and_map_pm_pack_into_green_and_blue(tmp_path):
    Image.fromarray(np.arange(16, dtype=np.uint8).reshape(4, 4) * 10).save(tmp_path / "r.png")
    Image.fromarray(np.full((2, 2), 200, np.uint8)).save(tmp_path / "m.png")
    for path in _obj_pair(tmp_path, "newmtl a\nKd 1 1 1\nPr 0.5\nmap_Pr r.png\nmap_Pm -bm 1 m.png\n"):
        (part,) = load_parts(path)
        texture = part.metallic_roughness_texture
        assert texture.shape == (4, 4, 3)
        assert (texture[..., 0] == 255).all() and (texture[..., 2] == 200).all()
        assert np.array_equal(texture[..., 1], np.arange(16).reshape(4, 4) * 10)
        assert (part.metallic, part.roughness) == (1.0, 0.5)  # the map alone decides the metallic factor
        assert part_material(part).metallic_roughness_texture is not None


def test_an_mtl_without_pbr_statements_stays_phong(tmp_path):
    for path in _obj_pair(tmp_path, "newmtl a\nKd 0.8 0.2 0.1\nKs 0.5 0.5 0.5\nNs 20\n"):
        (part,) = load_parts(path)
        assert not part.physical and part.metallic is None and part.roughness is None
        assert part.metallic_roughness_texture is None
        material = part_material(part)
        assert material.model == "phong" and material.metallic == 0.0
