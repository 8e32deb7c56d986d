"""Issue 36, second round: ``--up z|y`` on every command that takes a mesh file (render, turntable, explain, view,
dataset, serve, steps, radiosity), and ``frustum serve`` on a mesh file (a real server and WebSocket client)."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import frustum.scenefile
import frustum.scenefile.commands
from frustum.app.cli import main
from frustum.geometry import Mesh
from frustum.geometry import primitives as prim
from frustum.scenefile import explain_scene_file, load_scene_file, render_view_sheet
from testdata import DATA

SPOT = DATA / "spot"


@pytest.fixture(scope="module")
def tower(tmp_path_factory) -> Path:
    """A z-up model: a box three times taller along z than across (what CAD tools and STL files give)."""
    box = prim.box()
    tall = Mesh(box.vertices * np.array([1.0, 1.0, 3.0]), box.faces)
    return tall.save(tmp_path_factory.mktemp("tower") / "tower.obj")


def _height(path: Path, up: str) -> float:
    scene = load_scene_file(path, up=up).scene
    low, high = np.inf, -np.inf
    for item in scene.items:
        world = item.world_from_model[:3, :3] @ item.mesh.vertices.T + item.world_from_model[:3, 3:4]
        low, high = min(low, world[1].min()), max(high, world[1].max())
    return float(high - low)


def test_up_z_stands_a_z_up_model_upright(tower):
    assert _height(tower, "y") == pytest.approx(1.0) and _height(tower, "z") == pytest.approx(3.0)


def test_explain_takes_up(tower, capsys):
    main(["explain", str(tower), "--up", "z", "--markdown"])
    shown = " ".join(capsys.readouterr().out.split())  # the console wraps long lines
    assert shown == " ".join(explain_scene_file(tower, up="z").to_markdown().split())
    assert shown != " ".join(explain_scene_file(tower, up="y").to_markdown().split())


def test_view_takes_up(tower, tmp_path):
    main(["view", str(tower), "-o", str(tmp_path / "z.svg"), "--up", "z", "--views", "front"])
    expected = render_view_sheet(tower, tmp_path / "api.svg", ("front",), up="z")
    assert (tmp_path / "z.svg").read_bytes() == expected.read_bytes()
    main(["view", str(tower), "-o", str(tmp_path / "y.svg"), "--views", "front"])
    assert (tmp_path / "y.svg").read_bytes() != expected.read_bytes()


def test_dataset_takes_up(tower, tmp_path):
    for up in ("y", "z"):
        main(["dataset", str(tower), "--out", str(tmp_path / up), "--views", "2", "--size", "32x24",
              "--executor", "serial", "--up", up, "--no-progress", "--format", "files"])  # fmt: skip
    depth = {up: sorted((tmp_path / up).glob("depth/*.npy")) for up in ("y", "z")}
    assert depth["y"] and len(depth["y"]) == len(depth["z"])
    from frustum.batch import render_dataset

    render_dataset(load_scene_file(tower, up="z"), tmp_path / "api", views=2, size=(32, 24), executor="serial",
                   progress=False, format="files")  # fmt: skip
    api = sorted((tmp_path / "api").glob("depth/*.npy"))
    for ours, theirs in zip(depth["z"], api, strict=True):
        np.testing.assert_array_equal(np.load(ours), np.load(theirs))
    assert not all(np.array_equal(np.load(a), np.load(b)) for a, b in zip(depth["y"], depth["z"], strict=True))


@pytest.mark.parametrize("command", [["steps", "depth-buffer"], ["radiosity"], ["serve"], ["explain"]])
def test_the_up_axis_reaches_the_loader(tower, tmp_path, monkeypatch, command):
    """Every command that loads a model file hands it its --up (a spy on load_scene_file stops the command)."""
    seen = []

    class StopError(Exception):
        pass

    def spy(path, *args, **kwargs):
        seen.append((Path(path), kwargs.get("up")))
        raise StopError

    monkeypatch.setattr(frustum.scenefile, "load_scene_file", spy)
    monkeypatch.setattr(frustum.scenefile.commands, "load_scene_file", spy)
    import frustum.viewer.server as server_module

    monkeypatch.setattr(server_module, "load_scene_file", spy)
    monkeypatch.setattr(server_module, "open_socket", lambda *a: (_ for _ in ()).throw(StopError()))
    monkeypatch.setattr(server_module.SceneSource, "__init__", lambda self, path, up="y": seen.append((path, up)))
    outputs = {"steps": ["-o", str(tmp_path / "s.md")], "radiosity": ["-o", str(tmp_path / "r.png")]}
    with pytest.raises(StopError):
        main([*command, str(tower), "--up", "z", *outputs.get(command[0], [])])
    assert seen == [(tower, "z")]


@pytest.mark.parametrize(
    "command", [["explain"], ["view", "-o", "v.svg"], ["dataset", "--out", "d", "--no-progress"], ["serve"],
                ["steps", "depth-buffer", "-o", "s.md"], ["radiosity", "-o", "r.png"], ["render", "-o", "r.png"]],
)  # fmt: skip
def test_a_bad_up_axis_is_one_line_and_exit_1(tower, tmp_path, command):
    name, *rest = command
    words = [name, *(rest[:1] if name == "steps" else []), str(tower), *(rest[1:] if name == "steps" else rest)]
    result = subprocess.run([sys.executable, "-m", "frustum", *words, "--up", "x"], cwd=tmp_path,
                            capture_output=True, text=True, timeout=300, check=False)  # fmt: skip
    assert result.returncode == 1, result.stderr
    assert result.stderr == "error: up = 'x' is not an axis; give 'y' or 'z'\n"


# --- frustum serve on a mesh file ------------------------------------------------------------------------------


def _served_frame(model: Path, *options: str) -> np.ndarray:
    """The first full-quality frame `frustum serve MODEL` sends a page that says hello (a real server process)."""
    pytest.importorskip("uvicorn")
    client = pytest.importorskip("websockets.sync.client")
    process = subprocess.Popen([sys.executable, "-m", "frustum", "serve", str(model), "--port", "0", *options],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)  # fmt: skip
    try:
        line = process.stdout.readline()
        address = re.search(r"at http://([^/\s]+)/", line)
        assert address, line + process.stderr.read() if process.poll() is not None else line
        with client.connect(f"ws://{address.group(1)}/ws", open_timeout=60, max_size=None) as socket:
            socket.send(json.dumps({"type": "hello"}))
            while True:
                data = socket.recv(timeout=300)
                length = int.from_bytes(data[:4], "big")
                header = json.loads(data[4 : 4 + length])
                assert header["type"] != "error" or header.get("message") is None, header
                if header["type"] == "frame":
                    pixels = np.frombuffer(data[4 + length :], dtype=np.uint8)
                    return pixels.reshape(header["height"], header["width"], 4)
    finally:
        process.terminate()
        process.wait(30)


def _mask(image: np.ndarray) -> np.ndarray:
    return (image != image[0, 0]).any(axis=-1)


def _spot_glb(folder: Path) -> Path:
    import trimesh
    from PIL import Image

    mesh = trimesh.load(SPOT / "spot_triangulated.obj", process=False)
    material = trimesh.visual.material.PBRMaterial(baseColorTexture=Image.open(SPOT / "spot_texture.png"))
    mesh.visual = trimesh.visual.TextureVisuals(uv=mesh.visual.uv, material=material)
    mesh.export(folder / "spot.glb")
    return folder / "spot.glb"


def test_serve_shows_a_mesh_file_framed_lit_and_textured(tmp_path):
    model = _spot_glb(tmp_path)
    frame = _served_frame(model)
    picture = np.asarray(load_scene_file(model).render().color)
    assert frame.shape == picture.shape
    ours, theirs = _mask(frame), _mask(picture)
    assert (ours & theirs).sum() / (ours | theirs).sum() > 0.95  # the same framing as `frustum render`
    rows, cols = np.nonzero(ours)
    assert 0.4 <= max((np.ptp(rows) + 1) / frame.shape[0], (np.ptp(cols) + 1) / frame.shape[1]) <= 0.95
    luminance = frame[ours][:, :3].astype(float) @ [0.2126, 0.7152, 0.0722] / 255
    assert 0.2 < luminance.mean() < 0.85  # lit by the default lights
    assert np.percentile(luminance, 5) < 0.2 and np.percentile(luminance, 95) > 0.5  # the texture's dark and bright


def test_serve_takes_up_for_a_z_up_model(tower):
    standing = _served_frame(tower, "--up", "z")
    lying = _served_frame(tower)
    height = {name: np.ptp(np.nonzero(_mask(image))[0]) for name, image in (("z", standing), ("y", lying))}
    width = {name: np.ptp(np.nonzero(_mask(image))[1]) for name, image in (("z", standing), ("y", lying))}
    assert height["z"] > width["z"]  # the tower stands: taller than wide on the screen
    assert height["y"] < width["y"]


# --- default lights for every scene file that names none -------------------------------------------------------

PLACED = "[camera]\neye = [2.5, 2.0, 3.5]\ntarget = [0, 0, 0]\nfovy_deg = 40\n[render]\nsize = [96, 72]\n"
SPHERE = '[[nodes]]\ngeometry = { type = "uv_sphere", radius = 1.0, segments = 24, rings = 12 }\n'


def _model_luminance(scene_file) -> float:
    color = np.asarray(scene_file.render().color)
    mask = (color != color[0, 0]).any(axis=-1)
    return float((color[mask][:, :3].astype(float) @ [0.2126, 0.7152, 0.0722] / 255).mean())


def test_a_scene_file_without_lights_and_a_placed_camera_gets_the_default_lights():
    from frustum.scenefile import load_scene
    from frustum.scenefile.models import default_lights

    scene_file = load_scene(PLACED + SPHERE)
    lights = scene_file.scene.world_lights()
    expected = default_lights(scene_file.camera)
    assert len(lights) == len(expected) == 4
    for light, want in zip(lights, expected, strict=True):
        assert type(light) is type(want) and light.intensity == want.intensity
        assert np.allclose(getattr(light, "direction", 0.0), getattr(want, "direction", 0.0))
    assert 0.25 < _model_luminance(scene_file) < 0.8  # lit, not the near-black silhouette of an unlit scene


@pytest.mark.parametrize(
    "extra",
    [
        "lights = []\n",  # unlit on purpose
        '[[lights]]\ntype = "ambient"\nintensity = 0.2\n',  # lights of its own
        '[render]\nmode = "wireframe"\n',
        '[render]\nmode = "hidden-line"\n',
        '[render]\nshading = "none"\n',
        '[render]\nshading = "normals"\n',
    ],
)
def test_files_that_name_lights_or_draw_unlit_pictures_get_no_default_lights(extra):
    from frustum.scenefile import load_scene

    text = PLACED + SPHERE
    text = text.replace("[render]\n", extra) if extra.startswith("[render]") else extra + text
    lights = load_scene(text).scene.world_lights()
    assert len(lights) == (1 if "ambient" in extra else 0)


def test_lights_in_nodes_count_as_named():
    from frustum.scenefile import load_scene

    node_light = SPHERE + '[[nodes.lights]]\ntype = "point"\nposition = [2, 2, 2]\n'
    assert len(load_scene(PLACED + node_light).scene.world_lights()) == 1


def test_no_example_changes_its_lights(monkeypatch):
    """Every example keeps exactly its own lights (those naming lights, and the seven unlit on purpose: a
    radiosity box, a wireframe, two hidden-line drawings, a volume, two point scans drawn with their own colours
    and eye-dome lighting), so no example picture changes."""
    import frustum.scenefile.loader as loader
    from frustum.scenefile.commands import EXAMPLES_DIR

    def lights(path: Path) -> list:
        return [repr(light) for light in load_scene_file(path).scene.world_lights()]

    examples = sorted(EXAMPLES_DIR.glob("*.toml"))
    assert len(examples) > 20
    now = {path.name: lights(path) for path in examples}
    unlit = {name for name, named in now.items() if not named}
    assert unlit == {"cornell_box.toml", "depth_cueing.toml", "hidden_lines.toml", "multiview.toml",
                     "points_scan.toml", "points_scan_edl.toml", "volume_phantom_mip.toml"}  # fmt: skip
    monkeypatch.setattr(loader, "default_lights", lambda camera: [])
    assert now == {path.name: lights(path) for path in examples}


def test_dataset_resume_refuses_another_up_axis(tower, tmp_path):
    """The up axis turns the model: resuming a mesh file's dataset with another --up would mix two scenes."""
    args = ["dataset", str(tower), "--out", str(tmp_path / "d"), "--views", "2", "--size", "16x12",
            "--executor", "serial", "--no-progress", "--format", "files"]  # fmt: skip
    main([*args, "--up", "z"])
    manifest = json.loads((tmp_path / "d" / "manifest.jsonl").read_text().splitlines()[0])
    assert manifest["config"]["up"] == "z"
    main([*args, "--up", "z"])  # the same axis resumes: nothing to do
    result = subprocess.run([sys.executable, "-m", "frustum", *args, "--up", "y"], capture_output=True, text=True)
    assert result.returncode != 0 and "another configuration (up = 'z' → 'y')" in result.stderr
