"""Outputs stay where asked (issue 17): a scene file's ``[output] files`` resolve inside its folder (no ``..``,
no absolute path, no symlink out) for every output kind; ``-o`` goes anywhere; every writer replaces a file
only when the new one is complete."""

from __future__ import annotations

import os

import numpy as np
import pytest

import frustum as fr
from frustum.errors import OutputError, SceneFileError
from frustum.scenefile import OUTPUT_SUFFIXES, load_scene_file, render_scene_file

_SCENE = """[render]
size = [16, 12]

[camera]
eye = [0, 0, 5]
target = [0, 0, 0]

[[nodes]]
geometry = {{ type = "uv_sphere", segments = 8, rings = 4 }}

[output]
files = [{files}]
"""


def _scene_file(folder, *files: str):
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / "scene.toml"
    path.write_text(_SCENE.format(files=", ".join(repr(f).replace("'", '"') for f in files)))
    return path


@pytest.fixture
def layout(tmp_path):
    """tmp/scenes (the scene file's folder, with symlinks pointing out) and tmp/outside."""
    scenes, outside = tmp_path / "scenes", tmp_path / "outside"
    scenes.mkdir()
    outside.mkdir()
    (scenes / "link").symlink_to(outside, target_is_directory=True)
    for suffix in OUTPUT_SUFFIXES:
        (scenes / f"file_link{suffix}").symlink_to(outside / f"victim{suffix}")
    return scenes, outside


@pytest.mark.parametrize("suffix", OUTPUT_SUFFIXES)
@pytest.mark.parametrize("kind", ["parent", "nested_parent", "absolute", "folder_symlink", "file_symlink"])
def test_scene_file_outputs_cannot_escape_its_folder(layout, suffix, kind):
    scenes, outside = layout
    name = {
        "parent": f"../outside/x{suffix}",
        "nested_parent": f"out/../../outside/x{suffix}",
        "absolute": str(outside / f"x{suffix}"),
        "folder_symlink": f"link/x{suffix}",
        "file_symlink": f"file_link{suffix}",
    }[kind]
    path = _scene_file(scenes, name)
    with pytest.raises(SceneFileError) as caught:
        load_scene_file(path)
    message = str(caught.value)
    assert f"scene.toml:12: output.files[0] = {name!r} is outside the scene file's folder" in message
    assert "use -o on the command line" in message
    assert list(outside.iterdir()) == []


def test_inside_outputs_and_command_line_outputs_are_written(layout):
    scenes, outside = layout
    path = _scene_file(scenes, "out/a.png", "b.svg")
    assert render_scene_file(path) == [scenes / "out" / "a.png", scenes / "b.svg"]
    assert (scenes / "out" / "a.png").stat().st_size > 0 and (scenes / "b.svg").stat().st_size > 0
    anywhere = outside / "deeper" / "c.png"  # the user typed it: it may go anywhere
    assert render_scene_file(path, anywhere) == anywhere
    assert anywhere.stat().st_size > 0


# --- atomic writers -------------------------------------------------------------------------------------------


def _frame() -> fr.Frame:
    return fr.Frame(color=np.zeros((4, 4, 4), np.uint8), depth=np.ones((4, 4), np.float32))


def _no_space(*args, **kwargs):
    raise OSError(28, "No space left on device")


def _only(folder, name: str) -> None:
    assert sorted(p.name for p in folder.iterdir()) == [name]


def test_png_failure_keeps_the_old_file(tmp_path, monkeypatch):
    from PIL import Image

    target = tmp_path / "a.png"
    target.write_bytes(b"old")

    def failing_save(self, fp, *args, **kwargs):
        with open(fp, "wb") as file:
            file.write(b"half a PNG")
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(Image.Image, "save", failing_save)
    with pytest.raises(OutputError, match=r"Frame.save: path = .*a.png' cannot be written \(No space left on device\)"):
        _frame().save(target)
    assert target.read_bytes() == b"old"
    _only(tmp_path, "a.png")


def test_png_success_replaces_the_file_with_normal_permissions(tmp_path):
    target = tmp_path / "a.png"
    target.write_bytes(b"old")
    _frame().save(target)
    assert target.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    mask = os.umask(0)
    os.umask(mask)
    assert target.stat().st_mode & 0o777 == 0o666 & ~mask
    _only(tmp_path, "a.png")


@pytest.mark.parametrize("suffix", [".gif", ".mp4"])
def test_interrupted_animation_keeps_the_old_file(tmp_path, suffix):
    if suffix == ".mp4":
        pytest.importorskip("imageio_ffmpeg")
    from frustum.output.animation import write_animation

    target = tmp_path / f"spin{suffix}"
    target.write_bytes(b"old")

    def frames():
        yield np.zeros((16, 16, 3), np.uint8)
        yield np.ones((16, 16, 3), np.uint8)
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        write_animation(frames(), target)
    assert target.read_bytes() == b"old"
    _only(tmp_path, target.name)


def test_unwritable_folder_fails_before_any_frame_is_rendered(tmp_path):
    from frustum.output.animation import write_animation

    rendered = []

    def frames():
        rendered.append(1)
        yield np.zeros((4, 4, 3), np.uint8)

    with pytest.raises(OutputError, match=r"write_animation: path = .*missing/spin.gif' cannot be written"):
        write_animation(frames(), tmp_path / "missing" / "spin.gif")
    assert rendered == []


@pytest.mark.parametrize("suffix", [".svg", ".pdf"])
def test_vector_failure_keeps_the_old_file(tmp_path, suffix, monkeypatch):
    from frustum.output import svg

    target = tmp_path / f"drawing{suffix}"
    target.write_bytes(b"old")
    if suffix == ".pdf":
        cairosvg = pytest.importorskip("cairosvg")

        class CairoError(Exception):
            pass

        def failing(bytestring, write_to):
            with open(write_to, "wb") as file:
                file.write(b"%PDF half")
            raise CairoError("cairo returned CAIRO_STATUS_WRITE_ERROR", 11)

        monkeypatch.setattr(cairosvg, "svg2pdf", failing)
        expected = r"cairo failed \(write error: the disk is full or the file cannot be written\)"
    else:
        monkeypatch.setattr(type(target), "write_text", _no_space)
        expected = r"cannot be written \(No space left on device\)"
    with pytest.raises(OutputError, match=expected):
        svg.save_svg(svg.svg_document(10, 10, []), target)
    assert target.read_bytes() == b"old"
    _only(tmp_path, target.name)


def test_mesh_save_failure_keeps_the_old_file(tmp_path, monkeypatch):
    from frustum.errors import GeometryError
    from frustum.geometry import io

    target = tmp_path / "m.stl"
    target.write_bytes(b"old")
    monkeypatch.setattr(type(target), "write_bytes", _no_space)
    with pytest.raises(GeometryError, match=r"save: path = .*m.stl' cannot be written \(No space left on device\)"):
        io.save(fr.geometry.uv_sphere(1.0, 8, 4), target)
    assert target.read_bytes() == b"old"
    _only(tmp_path, "m.stl")
