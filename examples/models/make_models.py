"""Write the glTF model of the ``spot_pbr`` example (run from the repository root:
``python examples/models/make_models.py``; the bytes are the same on every run).

- ``spot_pbr.glb``: Keenan Crane's Spot (``tests/data/spot``, see its README for the licence) as a glTF 2.0
  binary with metallic–roughness materials: the cow's texture as ``baseColorTexture`` and a 256² packed
  ``metallicRoughnessTexture`` (G roughness: 0.75 on the light hide, 0.3 where the map is dark: patches, eyes,
  hooves; B metallic: 1 on the brown horns, which become polished copper), on a gold plinth (metallic 1, roughness
  0.3, a flat cylinder); one ``KHR_lights_punctual`` directional light of 3 lux from the upper left front, so
  ``frustum render examples/models/spot_pbr.glb`` draws it lit as the file says.
"""

from __future__ import annotations

import json
import struct
from pathlib import Path

import numpy as np
import trimesh
from PIL import Image

HERE = Path(__file__).parent
ROOT = HERE.parent.parent


def metallic_roughness(texture: Image.Image) -> Image.Image:
    """The packed texture (R unused 255, G roughness, B metallic) from the base colour's luminance and place."""
    small = np.asarray(texture.convert("RGB").resize((256, 256), Image.Resampling.BILINEAR), dtype=np.float64)
    luminance = small @ np.array([0.2126, 0.7152, 0.0722]) / 255.0
    red, green = small[..., 0], small[..., 1]
    horns = (red > 120) & (red - green > 50)  # the two brown ovals of the map
    roughness = np.where(luminance < 0.6, 0.3, 0.75)
    metallic = np.where(horns, 1.0, 0.0)
    packed = np.stack([np.ones_like(luminance), roughness, metallic], axis=-1)
    return Image.fromarray(np.round(packed * 255).astype(np.uint8))


def spot_scene() -> trimesh.Scene:
    folder = ROOT / "tests" / "data" / "spot"
    cow = trimesh.load(folder / "spot_triangulated.obj", process=False)
    cow.apply_transform(trimesh.transformations.rotation_matrix(np.pi, [0, 1, 0]))  # facing a fitted 3/4 view
    base = Image.open(folder / "spot_texture.png").convert("RGB")
    cow.visual = trimesh.visual.TextureVisuals(uv=cow.visual.uv, material=trimesh.visual.material.PBRMaterial(
        name="hide", baseColorTexture=base, metallicRoughnessTexture=metallic_roughness(base),
        metallicFactor=1.0, roughnessFactor=1.0))  # fmt: skip
    plinth = trimesh.creation.cylinder(radius=0.95, height=0.12, sections=64)
    plinth.apply_transform(trimesh.transformations.rotation_matrix(np.pi / 2, [1, 0, 0]))
    plinth.apply_translation([0.0, cow.bounds[0, 1] - 0.06, -0.18])
    plinth.visual = trimesh.visual.TextureVisuals(material=trimesh.visual.material.PBRMaterial(
        name="gold", baseColorFactor=[255, 200, 87, 255], metallicFactor=1.0, roughnessFactor=0.3))  # fmt: skip
    scene = trimesh.Scene()
    scene.add_geometry(cow, node_name="spot", geom_name="spot")
    scene.add_geometry(plinth, node_name="plinth", geom_name="plinth")
    return scene


def with_light(glb: bytes) -> bytes:
    """`glb` with a KHR_lights_punctual directional light (3 lux) on a node turned toward the model."""
    (length,) = struct.unpack_from("<I", glb, 12)
    gltf = json.loads(glb[20 : 20 + length])
    gltf["extensionsUsed"] = ["KHR_lights_punctual"]
    gltf["extensions"] = {"KHR_lights_punctual": {"lights": [{"type": "directional", "name": "sun", "intensity": 3.0}]}}
    # −Z of the node turned to (0.45, −0.6, −0.66): a unit quaternion (x, y, z, w) rotating −Z onto it
    target = np.array([0.45, -0.6, -0.66]) / np.linalg.norm([0.45, -0.6, -0.66])
    axis = np.cross([0.0, 0.0, -1.0], target)
    half = np.arccos(np.clip(-target[2], -1.0, 1.0)) / 2.0
    rotation = [*(axis / np.linalg.norm(axis) * np.sin(half)), np.cos(half)]
    gltf["nodes"].append({"name": "sun", "rotation": [round(float(c), 6) for c in rotation],
                          "extensions": {"KHR_lights_punctual": {"light": 0}}})  # fmt: skip
    gltf["scenes"][gltf.get("scene", 0)]["nodes"].append(len(gltf["nodes"]) - 1)
    text = json.dumps(gltf, separators=(",", ":")).encode()
    text += b" " * (-len(text) % 4)
    body = struct.pack("<I4s", len(text), b"JSON") + text + glb[20 + length :]
    return struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body


if __name__ == "__main__":
    data = with_light(spot_scene().export(file_type="glb"))
    (HERE / "spot_pbr.glb").write_bytes(data)
    print(f"wrote {HERE / 'spot_pbr.glb'} ({len(data) // 1024} KiB)")
