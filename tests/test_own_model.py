"""Issue 36: your own model in one command — mesh files where scene files go, Camera.fit, default lights,
the file's materials and textures."""

from __future__ import annotations

import json
import math
import shutil
from pathlib import Path

import numpy as np
import pytest
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st
from PIL import Image

import frustum
from frustum import Camera
from frustum.app.cli import main
from frustum.errors import CameraError, SceneFileError
from frustum.scenefile import load_scene, load_scene_file

DATA = Path(__file__).parent / "data"
BUNNY = DATA / "bunny" / "bun_zipper_res2.ply"
SPOT = DATA / "spot" / "spot_triangulated.obj"
TEXTURE = DATA / "spot" / "spot_texture.png"
TEAPOT = DATA / "teapot_n10.obj"


def _spot_glb(folder: Path) -> Path:
    """Spot as a GLB with its texture embedded (base colour factor white, so the texture shows as it is; a
    dielectric: without a metallic factor glTF's default is a metal, dark without an environment)."""
    mesh = trimesh.load(SPOT, process=False)
    image = Image.open(TEXTURE)
    material = trimesh.visual.material.PBRMaterial(baseColorTexture=image, baseColorFactor=[255, 255, 255, 255],
                                                   metallicFactor=0.0, roughnessFactor=0.6)  # fmt: skip
    mesh.visual = trimesh.visual.TextureVisuals(uv=mesh.visual.uv, material=material)
    path = folder / "spot.glb"
    mesh.export(path)
    return path


def _spot_with_mtl(folder: Path) -> Path:
    """Spot's OBJ with a .mtl naming the texture (map_Kd), in a folder of its own."""
    text = SPOT.read_text()
    (folder / "spot.mtl").write_text("newmtl cow\nKd 1 1 1\nmap_Kd cow.png\n")
    (folder / "spot.obj").write_text("mtllib spot.mtl\nusemtl cow\n" + text)
    shutil.copy(TEXTURE, folder / "cow.png")
    return folder / "spot.obj"


def _gallery(folder: Path) -> dict[str, tuple[Path, str]]:
    bunny = trimesh.load(BUNNY, process=False)
    stl, off = folder / "bunny.stl", folder / "bunny.off"
    bunny.export(stl)
    bunny.export(off)
    mtl_folder = folder / "mtl"
    mtl_folder.mkdir()
    return {
        "bunny_ply": (BUNNY, "y"),
        "spot_obj_mtl": (_spot_with_mtl(mtl_folder), "y"),
        "spot_glb": (_spot_glb(folder), "y"),
        "teapot_obj": (TEAPOT, "z"),
        "bunny_stl": (stl, "y"),
        "bunny_off": (off, "y"),
    }


def _model_pixels(frame: frustum.Frame) -> tuple[np.ndarray, np.ndarray]:
    mask = frame.depth < 1.0
    rgb = frame.color[..., :3].astype(np.float64) / 255.0
    luminance = rgb @ np.array([0.2126, 0.7152, 0.0722])
    return mask, luminance


def test_gallery_of_real_files_rendered_with_no_options(tmp_path):
    for name, (path, up) in _gallery(tmp_path).items():
        scene_file = load_scene_file(path, up=up)
        frame = scene_file.render()
        mask, luminance = _model_pixels(frame)
        rows, columns = np.nonzero(mask.any(axis=1))[0], np.nonzero(mask.any(axis=0))[0]
        fill_h = (rows[-1] - rows[0] + 1) / frame.height
        fill_w = (columns[-1] - columns[0] + 1) / frame.width
        assert 0.4 <= fill_h <= 0.9 or 0.4 <= fill_w <= 0.9, (name, fill_h, fill_w)
        lit = float(luminance[mask].mean())
        assert 0.25 <= lit <= 0.8, (name, lit)
        if name.startswith("spot"):  # the texture shows: its black patches and white hide both appear
            # a glTF file is written sRGB-encoded (as glTF viewers show it), which lifts dark values: 0.12 → 0.38
            dark_limit = 0.38 if scene_file.options.get("color_space") == "srgb" else 0.12
            dark = float((luminance[mask] < dark_limit).mean())
            bright = float((luminance[mask] > 0.55).mean())
            assert dark > 0.03 and bright > 0.1, (name, dark, bright)


def test_textured_cube_shows_both_checker_colours_on_every_visible_face(tmp_path):
    checker = np.zeros((64, 64, 3), dtype=np.uint8)
    checker[:32, :32] = checker[32:, 32:] = (230, 40, 40)
    checker[:32, 32:] = checker[32:, :32] = (40, 40, 230)
    # a cube of 6 separate quads, each face mapped to the whole checker image
    faces_v, faces_uv, tris = [], [], []
    for axis in range(3):
        for sign in (-1.0, 1.0):
            a, b = [(axis + 1) % 3, (axis + 2) % 3]
            corners = []
            for u, v in ((0, 0), (1, 0), (1, 1), (0, 1)):
                p = np.zeros(3)
                p[axis], p[a], p[b] = sign, 2 * u - 1, 2 * v - 1
                corners.append(p)
            base = len(faces_v)
            faces_v.extend(corners)
            faces_uv.extend([(0, 0), (1, 0), (1, 1), (0, 1)])
            quad = [[base, base + 1, base + 2], [base, base + 2, base + 3]]
            if sign < 0:
                quad = [q[::-1] for q in quad]
            tris.extend(quad)
    mesh = trimesh.Trimesh(np.array(faces_v), np.array(tris), process=False)
    material = trimesh.visual.material.PBRMaterial(baseColorTexture=Image.fromarray(checker),
                                                   baseColorFactor=[255, 255, 255, 255])  # fmt: skip
    mesh.visual = trimesh.visual.TextureVisuals(uv=np.array(faces_uv, dtype=float), material=material)
    path = tmp_path / "checker.glb"
    mesh.export(path)
    scene_file = load_scene_file(path)
    frame = scene_file.render()
    # the 3/4 view from +x, +y, +z sees the three faces x = 1, y = 1, z = 1; find each face's pixels by its normal
    camera = scene_file.camera
    rgb = frame.color[..., :3].astype(int)
    for axis in range(3):
        samples = []
        for u in np.linspace(-0.8, 0.8, 9):
            for v in np.linspace(-0.8, 0.8, 9):
                p = np.zeros(3)
                p[axis], p[(axis + 1) % 3], p[(axis + 2) % 3] = 1.0, u, v
                x, y, _ = camera.project(p)
                samples.append(rgb[frame.height - 1 - int(y), int(x)])
        samples = np.array(samples)
        reds = (samples[:, 0] > samples[:, 2] + 30).sum()
        blues = (samples[:, 2] > samples[:, 0] + 30).sum()
        assert reds >= 20 and blues >= 20, (axis, reds, blues)


def _silhouette(camera: Camera, center: np.ndarray, radius: float, perspective: bool) -> np.ndarray:
    eye = camera.frame.eye
    axis = center - eye
    distance = float(np.linalg.norm(axis))
    axis = axis / distance
    u, v = camera.frame.u, camera.frame.v
    if perspective:  # the circle where the cone from the eye touches the sphere
        at = eye + axis * (distance - radius**2 / distance)
        ring = radius * math.sqrt(distance**2 - radius**2) / distance
    else:
        at, ring = center, radius
    t = np.linspace(0.0, 2.0 * math.pi, 2000, endpoint=False)
    points = at + ring * (np.cos(t)[:, None] * u + np.sin(t)[:, None] * v)
    return camera.project(points)


@settings(max_examples=60, deadline=None)
@given(
    low=st.tuples(*[st.floats(-100, 100)] * 3),
    extent=st.tuples(*[st.floats(0.01, 50)] * 3),
    direction=st.tuples(*[st.floats(-1, 1)] * 3).filter(lambda d: np.linalg.norm(d) > 0.1),
    perspective=st.booleans(),
    width=st.integers(32, 800),
    height=st.integers(32, 800),
    margin=st.floats(0.0, 0.3),
    fovy_deg=st.floats(10, 120),
)
def test_camera_fit_touches_the_image_edge_at_the_margin(low, extent, direction, perspective, width, height, margin,
                                                        fovy_deg):  # fmt: skip
    low = np.array(low)
    high = low + np.array(extent)
    camera = Camera.fit([low, high], direction, math.radians(fovy_deg), margin,
                        projection="perspective" if perspective else "orthographic",
                        width=width, height=height)  # fmt: skip
    window = _silhouette(camera, (low + high) / 2, float(np.linalg.norm(high - low)) / 2, perspective)
    gaps = [window[:, 0].min(), width - window[:, 0].max(), window[:, 1].min(), height - window[:, 1].max()]
    expected = margin * min(width, height)
    assert abs(min(gaps) - expected) <= 1.0, (gaps, expected)
    assert min(gaps[:2]) >= expected - 1.0 and min(gaps[2:]) >= expected - 1.0


def test_camera_fit_default_is_a_three_quarter_view_and_refuses_bad_input():
    camera = Camera.fit([[-1, -1, -1], [1, 1, 1]])
    eye = camera.frame.eye
    assert eye[0] > 0 and eye[1] > 0 and eye[2] > 0 and math.isclose(eye[0], eye[2])
    with pytest.raises(CameraError, match="margin"):
        Camera.fit([[0, 0, 0], [1, 1, 1]], margin=0.5)
    with pytest.raises(CameraError, match="direction"):
        Camera.fit([[0, 0, 0], [1, 1, 1]], (0, 0, 0))
    with pytest.raises(CameraError, match="scene_or_bounds"):
        Camera.fit("bunny")
    looking_down = Camera.fit([[0, 0, 0], [1, 1, 1]], (0, -1, 0))
    assert np.allclose(looking_down.frame.eye, [0.5, 0.5 + np.linalg.norm(looking_down.frame.eye - 0.5), 0.5])


def test_load_scene_takes_a_path_of_either_kind_and_still_takes_toml_text(tmp_path):
    model = load_scene(BUNNY)
    assert model.camera is not None and len(model.scene.items) == 1 and model.scene.lights
    assert load_scene(str(BUNNY)).scene.items[0].mesh.vertex_count == model.scene.items[0].mesh.vertex_count
    toml = f'[camera]\neye = [0, 0, 1]\n[[nodes]]\ngeometry = {{ type = "mesh", path = "{BUNNY.resolve()}" }}\n'
    (tmp_path / "s.toml").write_text(toml)
    from_text = load_scene(toml, allow_read=[BUNNY.parent])  # an absolute path outside the folder: allowed by name
    from_file = load_scene(tmp_path / "s.toml", allow_read=[BUNNY.parent])
    assert from_text.scene.items[0].mesh.vertex_count == from_file.scene.items[0].mesh.vertex_count
    with pytest.raises(SceneFileError, match="up"):
        load_scene_file(BUNNY, up="x")


def test_z_up_turns_the_teapot_upright():
    upright = load_scene_file(TEAPOT, up="z").scene
    lying = load_scene_file(TEAPOT, up="y").scene
    heights = [np.ptp(frustum.apply(s.items[0].world_from_model, s.items[0].mesh.vertices), axis=0) for s in
               (upright, lying)]  # fmt: skip
    assert heights[0][1] < heights[0][2] * 1.2 and heights[1][1] > heights[0][1]  # y is the short axis when upright


@pytest.fixture(scope="module")
def glb(tmp_path_factory):
    return _spot_glb(tmp_path_factory.mktemp("glb"))


def test_cli_render_a_glb(glb, tmp_path, capsys):
    out = tmp_path / "spot.png"
    main(["render", str(glb), "-o", str(out), "--size", "200x150"])
    image = np.asarray(Image.open(out))
    assert image.shape[:2] == (150, 200) and (image[..., :3] > 20).any()
    assert "wrote" in capsys.readouterr().out


def test_cli_turntable_explain_view_and_dataset_on_a_glb(glb, tmp_path, capsys):
    gif = tmp_path / "t.gif"
    main(["turntable", str(glb), "-o", str(gif), "--frames", "3", "--size", "64x64"])
    with Image.open(gif) as animation:
        assert animation.n_frames == 3
        assert np.asarray(animation.convert("RGB")).std() > 5  # a coloured cow, not an empty frame
    main(["explain", str(glb), "--point", "0,0,0"])
    assert "clip" in capsys.readouterr().out.lower()
    sheet = tmp_path / "sheet.svg"
    main(["view", str(glb), "-o", str(sheet), "--views", "front,iso"])
    assert sheet.read_text().lstrip().startswith("<")
    data = tmp_path / "data"
    main(["dataset", str(glb), "--out", str(data), "--views", "2", "--size", "48x32", "--executor", "serial",
          "--no-progress"])  # fmt: skip
    transforms = json.loads((data / "transforms.json").read_text())
    assert len(transforms["frames"]) == 2


def test_cli_render_a_missing_or_broken_mesh_file_is_one_line_and_non_zero(tmp_path):
    broken = tmp_path / "broken.glb"
    broken.write_bytes(b"glTF not really")
    for path in (broken, tmp_path / "missing.obj"):
        with pytest.raises(SystemExit) as stopped:
            main(["render", str(path), "-o", str(tmp_path / "x.png")])
        assert stopped.value.code != 0


def test_scene_file_camera_fit_view_iso_and_default_lights(tmp_path):
    node = f'[[nodes]]\ngeometry = {{ type = "mesh", path = "{BUNNY.resolve()}" }}\n'
    fitted = load_scene("[camera]\nfit = true\n" + node)
    assert len(fitted.scene.world_lights()) == 4  # key, fill, rim and ambient when the file names none
    model = load_scene_file(BUNNY)
    assert np.allclose(fitted.camera.frame.eye, model.camera.frame.eye)
    iso = load_scene('[camera]\nfit = true\nview = "iso"\n' + node)
    assert type(iso.camera.projection).__name__ == "Orthographic"
    eye = iso.camera.frame.eye - iso.camera.frame.target
    assert np.allclose(eye / np.linalg.norm(eye), np.ones(3) / math.sqrt(3))
    turned = load_scene("[camera]\nfit = true\nazimuth_deg = 0\nelevation_deg = 0\nmargin = 0.2\n" + node)
    assert abs(turned.camera.frame.n[2] - 1.0) < 1e-9
    placed = load_scene('[camera]\nview = "iso"\ndistance = 5\n' + node)  # iso also without fit
    assert np.allclose(placed.camera.frame.eye, np.full(3, 5 / math.sqrt(3)))
    lit = load_scene('[camera]\nfit = true\n[[lights]]\ntype = "ambient"\n' + node)
    assert len(lit.scene.world_lights()) == 1
    with pytest.raises(SceneFileError, match=r"eye = .* does not apply to fit"):
        load_scene("[camera]\nfit = true\neye = [0, 0, 5]\n" + node)
    with pytest.raises(SceneFileError, match="nothing to frame"):
        load_scene("[camera]\nfit = true\n")
    with pytest.raises(SceneFileError, match="margin"):
        load_scene("[camera]\nfit = true\nmargin = 0.7\n" + node)


def test_scene_file_meshes_bring_their_materials_and_textures(tmp_path):
    obj = _spot_with_mtl(tmp_path)
    glb = _spot_glb(tmp_path)
    for path in (obj, glb):
        scene_file = load_scene(f'[camera]\nfit = true\n[[nodes]]\ngeometry = {{ type = "mesh", path = "{path}" }}\n',
                                allow_read=[tmp_path])  # fmt: skip
        item = scene_file.scene.items[0]
        assert item.material.texture is not None and item.material.texture.shape[:2] == (1024, 1024)
        mask, luminance = _model_pixels(scene_file.render())
        assert (luminance[mask] < 0.12).mean() > 0.03 and (luminance[mask] > 0.55).mean() > 0.1
    mine = load_scene(f'[camera]\nfit = true\n[[nodes]]\nmaterial = {{ color = [1, 0, 0] }}\n'
                      f'geometry = {{ type = "mesh", path = "{obj}" }}\n', allow_read=[tmp_path])  # fmt: skip
    assert mine.scene.items[0].material.texture is None  # the node's own material wins
    plain = load_scene(f'[camera]\nfit = true\n[[nodes]]\ngeometry = {{ type = "mesh", path = "{BUNNY}" }}\n',
                       allow_read=[BUNNY.parent])  # fmt: skip
    assert plain.scene.root.children[0].material is None  # nothing in the file: the default Material, as before


def test_short_reprs_of_array_holders():
    from frustum.geometry.io import load_parts

    part = load_parts(SPOT)[0]
    assert part.texture.shape == (1024, 1024, 3)
    assert len(repr(part)) < 400 and "<1024x1024x3 image>" in repr(part)
    material = frustum.Material(texture=part.texture, normal_map=np.zeros((8, 8, 3), np.uint8))
    assert len(repr(material)) < 400 and "normal_map=<8x8x" in repr(material)


def test_random_stl_bytes_are_reported_truncated_not_as_a_memory_need(tmp_path):
    noise = tmp_path / "noise.stl"
    noise.write_bytes(np.random.default_rng(5).integers(0, 256, 5000, dtype=np.uint8).tobytes())
    with pytest.raises(frustum.GeometryError, match="truncated") as caught:
        frustum.load(noise)
    assert "GiB" not in str(caught.value)


def test_gltf_emissive_factor_and_alpha_mode_reach_the_material(tmp_path):
    box = trimesh.creation.box()
    box.visual = trimesh.visual.TextureVisuals(
        uv=np.zeros((len(box.vertices), 2)),
        material=trimesh.visual.material.PBRMaterial(
            baseColorFactor=[255, 0, 0, 128], emissiveFactor=[0, 0.5, 0], alphaMode="OPAQUE"
        ),
    )
    path = tmp_path / "glow.glb"
    box.export(path)
    material = load_scene_file(path).scene.items[0].material
    assert np.allclose(material.emissive, [0, 0.5, 0], atol=0.01)
    assert material.opacity == 1.0  # alphaMode OPAQUE ignores alpha
    assert np.allclose(material.color, [1, 0, 0], atol=0.01)


def test_library_compile_notice_once_and_silenced(monkeypatch, capsys):
    import frustum.raster as raster
    from frustum.raster import _jit

    monkeypatch.setattr(raster, "_noticed", [False])
    monkeypatch.setattr(raster, "compile_notice", raster._library_notice)
    monkeypatch.setattr(_jit, "NOTICE_AFTER", 0.05)
    watch = _jit._CompileWatch()
    watch.on_start(None)  # a compilation that goes on past NOTICE_AFTER
    import time

    time.sleep(0.3)
    watch.on_end(None)
    watch.on_start(None)
    watch.on_end(None)
    raster.compile_notice()  # once per process, however often asked
    lines = [line for line in capsys.readouterr().err.splitlines() if "compiling render kernels" in line]
    assert len(lines) == 1
    monkeypatch.setattr(raster, "_noticed", [False])
    frustum.set_compile_notice(False)
    assert raster.compile_notice is None
    frustum.set_compile_notice(True)
    monkeypatch.setenv("FRUSTUM_COMPILE_NOTICE", "0")
    raster.compile_notice()
    assert "compiling" not in capsys.readouterr().err


def test_examples_render_what_they_can_and_list_what_needs_an_extra(tmp_path, monkeypatch, capsys):
    import sys

    gallery = tmp_path / "examples"
    gallery.mkdir()
    root = Path(__file__).parents[1] / "examples"
    shutil.copy(root / "volume_julia.toml", gallery / "a_volume_julia.toml")
    (gallery / "b_box.toml").write_text('[camera]\nfit = true\n[[nodes]]\ngeometry = { type = "box" }\n')
    monkeypatch.setitem(sys.modules, "matplotlib", None)  # the colormaps extra is not installed
    from frustum.scenefile import render_examples

    skipped: list = []
    written = render_examples(tmp_path / "out", (64, 48), examples_dir=gallery, skipped=skipped)
    assert [p.name for p in written] == ["b_box.png"] and skipped[0][0] == "a_volume_julia.toml"
    with pytest.raises(frustum.FrustumError, match="pip install"):
        render_examples(tmp_path / "out", (64, 48), examples_dir=gallery)  # without `skipped`: as before
    monkeypatch.setattr("frustum.scenefile.commands.EXAMPLES_DIR", gallery)
    main(["examples", "--out", str(tmp_path / "cli"), "--size", "64x48"])  # exit 0: no SystemExit
    out = capsys.readouterr().out
    assert "skipped a_volume_julia.toml" in out and "pip install 'frustum[colormaps]'" in out


def test_the_image_size_message_names_the_limit():
    with pytest.raises(SceneFileError, match="over the limit of 8192 pixels a side") as caught:
        load_scene('[render]\nsize = [100000, 100000]\n[camera]\neye = [0, 0, 5]\n')
    assert "not two positive integer" not in str(caught.value)
    with pytest.raises(SceneFileError, match="is not two positive integer pixel counts"):
        load_scene('[render]\nsize = [-3, 10]\n[camera]\neye = [0, 0, 5]\n')


def test_turntable_estimates_its_work_before_the_first_frame(tmp_path):
    with pytest.raises(SystemExit) as stopped:
        main(["turntable", str(BUNNY), "-o", str(tmp_path / "t.gif"), "--frames", "100000000"])
    assert stopped.value.code != 0
    assert not (tmp_path / "t.gif").exists()
    from frustum.output.animation import turntable

    with pytest.raises(frustum.OutputError, match=r"frames = 100000000 .* over the work budget"):
        turntable(load_scene_file(BUNNY).scene, frames=100_000_000, size=(480, 480))
