"""Hostile and huge input (issue 17): every case runs in a subprocess with a memory cap and a timeout, so a
regression (a kernel that runs for minutes, gigabytes allocated before a MemoryError) fails fast instead of
hanging CI. Each case states the error class and a fragment of the message it must raise."""

from __future__ import annotations

import json
import os
import struct
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

HERE = Path(__file__).parent
SCENES = HERE / "scenes"
MEMORY_CAP = 3 * 2**30  # address space of one case: far below what the unguarded requests used to take
TIMEOUT_S = 60  # one case; each takes well under a second once the kernels are compiled

_PRELUDE = """
import json, resource, sys
resource.setrlimit(resource.RLIMIT_AS, ({cap}, {cap}))
try:
    exec(compile(sys.argv[1], "<case>", "exec"), {{"__name__": "__case__"}})
except BaseException as error:
    print(json.dumps({{"type": type(error).__name__, "message": str(error)}}))
else:
    print(json.dumps({{"type": None, "message": ""}}))
"""


def run_case(code: str, *, env: dict[str, str] | None = None, cwd: Path | None = None) -> dict:
    """Run `code` in a fresh interpreter under the memory cap and timeout; return the error it raised."""
    environment = {**os.environ, **(env or {})}
    result = subprocess.run(
        [sys.executable, "-c", _PRELUDE.format(cap=MEMORY_CAP), textwrap.dedent(code)],
        capture_output=True, text=True, timeout=TIMEOUT_S, env=environment, cwd=cwd,
    )  # fmt: skip
    lines = [line for line in result.stdout.splitlines() if line.startswith("{")]
    assert lines, f"no result (exit {result.returncode}): {result.stderr[-2000:]}"
    return json.loads(lines[-1])


def run_cli(*arguments: str, env: dict[str, str] | None = None, cwd: Path | None = None):
    """The frustum command in a subprocess under the memory cap and timeout."""
    code = f"import sys; sys.argv = ['frustum', *{list(arguments)!r}]; from frustum.app.cli import main; main()"
    environment = {**os.environ, **(env or {})}
    return subprocess.run(
        [sys.executable, "-c", f"import resource; resource.setrlimit(resource.RLIMIT_AS, ({MEMORY_CAP}, "
         f"{MEMORY_CAP}))\n{code}"],
        capture_output=True, text=True, timeout=TIMEOUT_S, env=environment, cwd=cwd,
    )  # fmt: skip


# --- 1. one work budget, checked before the work starts -----------------------------------------------------

API_CASES = {
    "uv_sphere_7GB": (
        "import frustum as fr; fr.geometry.uv_sphere(1.0, 100000, 1000)",
        "GeometryError",
        "uv_sphere: segments = 100000, rings = 1000 (100101001 vertices) needs about",
    ),
    "camera_100000_pixels": (
        "import frustum as fr; fr.Camera.look_at((0, 0, 5), (0, 0, 0), width=100000, height=100000)",
        "CameraError",
        "width = 100000 is above the limit of 65536 pixels a side",
    ),
    "render_86GB_image": (
        """
        import frustum as fr
        scene = fr.Scene(); scene.add(fr.geometry.uv_sphere())
        fr.render(scene, fr.Camera.look_at((0, 0, 5), (0, 0, 0), width=8192, height=8192), samples=64)
        """,
        "FrustumError",
        "render: a 8192 x 8192 image x samples = 64 needs about 48.0 GiB, over the memory budget",
    ),
    "mandelbrot_1e12_iterations": (
        "import frustum as fr; fr.mandelbrot(width=64, height=64, max_iter=10**12)",
        "GeometryError",
        "64 x 64 pixels x max_iter = 1000000000000 needs about 4.1e+15 operations, over the work",
    ),
    "wireframe_line_width_1e8": (
        """
        import frustum as fr
        scene = fr.Scene(); scene.add(fr.geometry.uv_sphere())
        fr.render(scene, fr.Camera.look_at((0, 0, 5), (0, 0, 0), width=64, height=64), mode="wireframe",
                  line_width=1e8)
        """,
        "FrustumError",
        "line_width = 100000000.0 is above 256",
    ),
    "flatness_resolution_1e-300": (
        """
        import numpy as np, frustum as fr
        fr.geometry.BezierSurface(np.random.default_rng(0).random((4, 4, 3))).flatness_resolution(1e-300)
        """,
        "GeometryError",
        "tolerance = 1e-300 is below 1e-10 of the surface's extent",
    ),
    "curve_flatten_1e-300": (
        """
        import frustum as fr
        fr.geometry.BezierCurve([[0, 0, 0], [1, 2, 0], [3, -1, 0], [4, 0, 0]]).flatten(1e-300)
        """,
        "GeometryError",
        "BezierCurve.flatten: tolerance = 1e-300 is below 1e-10 of the curve's extent",
    ),
    "tessellate_adaptive_1e-9": (
        """
        import numpy as np, frustum as fr
        fr.geometry.BezierSurface(np.random.default_rng(0).random((4, 4, 3))).tessellate_adaptive(1e-9)
        """,
        "GeometryError",
        "BezierSurface.tessellate: nu = ",
    ),
    "fractal_default_budget": (
        "import frustum as fr; fr.geometry.menger_sponge(9)",
        "GeometryError",
        "menger_sponge: level = 9 needs about",
    ),
    "fractal_max_bytes_override": (
        "import frustum as fr; fr.geometry.koch_curve(3, max_bytes=1000)",
        "GeometryError",
        "level = 3 would need 4680 bytes (4.6 KiB), over the memory budget max_bytes = 1000",
    ),
    # --- 4. honest, safe error messages -----------------------------------------------------------------------
    "singular_modeling_transform": (
        "import frustum as fr; fr.Scene().add(fr.geometry.uv_sphere(), transform=fr.scale(0, 0, 0))",
        "FrustumError",
        "is singular (determinant 0)",
    ),
    "polyline_negative_samples": (
        """
        import frustum as fr
        curve = fr.geometry.BezierCurve([[0, 0, 0], [1, 1, 0], [2, 0, 0]])
        fr.geometry.Polyline.from_curve(curve, samples=-3)
        """,
        "GeometryError",
        "Polyline.from_curve: samples = -3 is below 2",
    ),
    "complex_vertices": (
        "import numpy as np, frustum as fr; fr.geometry.Mesh(np.eye(3) * (1 + 2j), [[0, 1, 2]])",
        "GeometryError",
        "Mesh: vertices = ",
    ),
    "complex_eye": (
        "import frustum as fr; fr.Camera.look_at((0, 0, 5 + 1j), (0, 0, 0))",
        "CameraError",
        "is complex",
    ),
}


@pytest.mark.parametrize("name", sorted(API_CASES))
def test_api_case(name):
    code, error_type, fragment = API_CASES[name]
    result = run_case(code)
    assert result["type"] == error_type, result
    assert fragment in result["message"], result["message"]


def test_complex_vertices_are_named_complex():
    assert "is complex" in run_case(API_CASES["complex_vertices"][0])["message"]


def test_budget_from_the_environment_and_the_cli(tmp_path):
    result = run_case("import frustum as fr; fr.geometry.uv_sphere(1.0, 64, 32)", env={"FRUSTUM_MAX_BYTES": "64K"})
    assert result["type"] == "GeometryError"
    assert "over the memory budget of 64.0 KiB" in result["message"]
    scene = tmp_path / "s.toml"
    scene.write_text('[camera]\neye = [0, 0, 5]\ntarget = [0, 0, 0]\n[[nodes]]\ngeometry = { type = "uv_sphere" }\n')
    refused = run_cli("--max-bytes", "64K", "render", str(scene), "-o", str(tmp_path / "a.png"))
    assert refused.returncode == 1
    assert "s.toml:6: nodes[0].geometry" in refused.stderr or "over the memory budget of 64.0 KiB" in refused.stderr
    assert not (tmp_path / "a.png").exists()
    bad = run_cli("--max-operations", "lots", "render", str(scene))
    assert bad.returncode == 2 and "--max-operations = 'lots' is not a positive number" in bad.stderr


SCENE_CASES = {
    "quaternion_julia_forever.toml": "quaternion_julia_forever.toml:7: nodes[0].geometry.resolution = 300 is not "
    "accepted: quaternion_julia: resolution = 300",
    "huge_sphere.toml": "huge_sphere.toml:6: nodes[0].geometry",
    "huge_image.toml": "huge_image.toml:3: render.samples = 64 is over the memory budget",
    "escape_parent.toml": "escape_parent.toml:9: output.files[0] = '../../escaped.png' is outside the scene file's",
    "escape_absolute.toml": "escape_absolute.toml:9: output.files[0] = '/tmp/frustum-hostile-absolute.png' is outside",
}


@pytest.mark.parametrize("name", sorted(SCENE_CASES))
def test_scene_file_case(name, tmp_path):
    result = run_cli("render", str(SCENES / name), cwd=tmp_path)
    assert result.returncode == 1, result.stderr
    assert SCENE_CASES[name] in result.stderr, result.stderr
    assert list(tmp_path.iterdir()) == []


def test_forged_key_cannot_forge_lines_or_colors():
    result = run_cli("render", str(SCENES / "forged_key.toml"))
    assert result.returncode == 1
    assert "\x1b" not in result.stderr
    assert '"x\\nerror: all good\\x1b[31m" = 1 is not a known key' in result.stderr
    assert [line for line in result.stderr.splitlines() if line.startswith("error:")] == [result.stderr.splitlines()[0]]


def test_deep_nesting_and_long_dotted_keys_are_refused_early(tmp_path):
    deep = tmp_path / "deep.toml"
    deep.write_text("[camera]\neye = [0, 0, 5]\n\nx = " + "[" * 100_000 + "\n")
    result = run_cli("render", str(deep))
    assert result.returncode == 1
    assert "deep.toml:4: arrays or tables nest more than 64 deep here" in result.stderr
    dotted = tmp_path / "dotted.toml"
    dotted.write_text("\n" + ".".join(["a"] * 20_000) + " = 1\n")
    result = run_cli("render", str(dotted))
    assert result.returncode == 1
    assert "dotted.toml:2: a dotted key has more than 64 parts" in result.stderr


def test_dev_zero_is_not_read_to_the_end():
    result = run_cli("render", "/dev/zero")
    assert result.returncode == 1
    assert "/dev/zero: is larger than 16 MiB" in result.stderr


def test_size_option_names_the_limit(tmp_path):
    result = run_cli("turntable", str(tmp_path / "m.obj"), "-o", str(tmp_path / "t.gif"), "--size", "9000x9000")
    assert result.returncode == 2
    assert "--size = '9000x9000' is over the limit of 8192 pixels a side" in result.stderr


# --- mesh files -------------------------------------------------------------------------------------------------

_TRIANGLE = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"


def test_obj_latin1_loads_without_a_charset_detector(tmp_path):
    path = tmp_path / "caf\u00e9.obj"
    path.write_bytes(b"# caf\xe9 (Latin-1)\no caf\xe9\n" + _TRIANGLE.encode() + b"f 1 2 3\n")
    result = run_case(f"""
        import sys
        sys.modules["charset_normalizer"] = None  # as if neither detector were installed
        sys.modules["chardet"] = None
        from frustum.geometry.io import load
        assert load({str(path)!r}).face_count == 1
    """)
    assert result["type"] is None, result


def test_obj_face_index_zero_is_refused_with_its_line(tmp_path):
    path = tmp_path / "zero.obj"
    path.write_text(_TRIANGLE + "f 0 1 2\nf 1 2 3\n")
    result = run_case(f"from frustum.geometry.io import load; load({str(path)!r})")
    assert result["type"] == "GeometryError"
    assert "zero.obj', line 5: face 'f 0'... uses vertex index 0; OBJ indices start at 1" in result["message"]


def test_large_valid_stl_is_a_memory_error_not_corrupt(tmp_path):
    path = tmp_path / "big.stl"
    count = 20_000
    record = struct.pack("<12fH", *([0.0] * 3 + [0, 0, 0, 1, 0, 0, 0, 1, 0]), 0)
    path.write_bytes(b"\0" * 80 + struct.pack("<I", count) + record * count)
    result = run_case(f"from frustum.geometry.io import load; load({str(path)!r})", env={"FRUSTUM_MAX_BYTES": "1M"})
    assert result["type"] == "GeometryError"
    assert "with 20000 triangles needs about 7.6 MiB, over the memory budget of 1.0 MiB" in result["message"]
    assert "corrupt" not in result["message"]


# --- outputs: full disk, caller arrays --------------------------------------------------------------------------

_FULL_DISK = """
import resource, signal
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # writes past the limit fail with EFBIG, as on a full disk
resource.setrlimit(resource.RLIMIT_FSIZE, (20000, 20000))
"""


def test_mp4_on_a_full_disk_is_one_line_without_the_ffmpeg_command(tmp_path):
    pytest.importorskip("imageio_ffmpeg")
    target = tmp_path / "spin.mp4"
    target.write_bytes(b"old")
    result = run_case(
        _FULL_DISK
        + f"""
import numpy as np
from frustum.output.animation import write_animation
rng = np.random.default_rng(0)
write_animation((rng.integers(0, 255, (256, 256, 3), dtype=np.uint8) for _ in range(30)), {str(target)!r})
"""
    )
    assert result["type"] == "OutputError", result
    assert "write_animation: path = " in result["message"] and "cannot be written" in result["message"]
    assert "FFMPEG" not in result["message"].upper() or "imageio-ffmpeg" in result["message"]
    assert "-vcodec" not in result["message"] and "\n" not in result["message"]
    assert target.read_bytes() == b"old"
    assert [p.name for p in tmp_path.iterdir()] == ["spin.mp4"]


def test_pdf_failure_names_the_cause_not_a_status_number(tmp_path):
    pytest.importorskip("cairosvg")
    target = tmp_path / "sheet.pdf"
    result = run_case(
        _FULL_DISK
        + f"""
from frustum.output.svg import save_svg
body = "".join(f'<path d="M {{i % 50}} {{i // 50}} L {{i % 37}} {{i % 23}}" stroke="black"/>' for i in range(5000))
save_svg('<svg xmlns="http://www.w3.org/2000/svg" width="100" height="100">' + body + '</svg>', {str(target)!r})
"""
    )
    assert result["type"] == "OutputError", result
    assert "save_svg: path = " in result["message"]
    assert "cannot be written (cairo could not write it: the disk is full" in result["message"]
    assert "(11)" not in result["message"]
    assert list(tmp_path.iterdir()) == []


def test_mesh_and_camera_leave_caller_arrays_writable():
    result = run_case("""
        import numpy as np, frustum as fr
        vertices, faces, eye = np.eye(3), np.array([[0, 1, 2]]), np.array([0.0, 0.0, 5.0])
        mesh = fr.geometry.Mesh(vertices, faces)
        camera = fr.Camera.look_at(eye, (0, 0, 0))
        assert vertices.flags.writeable and faces.flags.writeable and eye.flags.writeable
        vertices[0, 0] = 7.0
        eye[2] = 9.0
        assert mesh.vertices[0, 0] == 1.0 and camera.frame.eye[2] == 5.0
        assert not mesh.vertices.flags.writeable
    """)
    assert result["type"] is None, result


def test_gif_frames_are_streamed_to_the_file(tmp_path):
    target = tmp_path / "stream.gif"
    result = run_case(f"""
        import numpy as np
        from pathlib import Path
        from frustum.output.animation import write_animation
        folder = Path({str(tmp_path)!r})
        sizes = []
        def frames():
            for k in range(6):
                partial = [p for p in folder.iterdir() if p.name.endswith(".part.gif")]
                sizes.append(partial[0].stat().st_size if partial else -1)
                yield np.random.default_rng(k).integers(0, 255, (128, 128, 3), dtype=np.uint8)
        assert write_animation(frames(), folder / "stream.gif", fps=10) == 6
        assert sizes[0] >= 0 and sizes[-1] > sizes[1] > 0, sizes  # written while the frames come
    """)
    assert result["type"] is None, result
    from PIL import Image

    with Image.open(target) as image:
        assert image.n_frames == 6


def test_many_large_cameras_count_in_the_image_budget(tmp_path):
    cameras = "".join(f"[[cameras]]\neye = [0, 0, {5 + k}]\ntarget = [0, 0, 0]\n\n" for k in range(64))
    scene = tmp_path / "wall.toml"
    scene.write_text("[render]\nsize = [8192, 8192]\n\n" + cameras + '[[nodes]]\ngeometry = { type = "uv_sphere" }\n')
    result = run_cli("render", str(scene), cwd=tmp_path)
    assert result.returncode == 1
    expected = (
        "wall.toml:2: render.size = (8192.0, 8192.0) is over the memory budget; 8192 x 8192 pixels x "
        "samples = 1 x 64 cameras needs about 32.8 GiB"
    )
    assert expected in result.stderr, result.stderr


def test_brackets_and_dots_inside_strings_are_not_nesting():
    from frustum.scenefile import load_scene

    text = ('title = "' + "[" * 200 + "a.b." * 100 + '"\n'
            "description = '''\n" + "{" * 200 + "\n'''\n"
            '[camera]\neye = [0, 0, 5]\ntarget = [0, 0, 0]\n'
            '[[nodes]]\ngeometry = { type = "uv_sphere" }\n')  # fmt: skip
    assert load_scene(text).title.startswith("[[[")


def test_escape_control_covers_c0_c1_and_bidi_overrides():
    from frustum._arrays import describe, escape_control

    assert escape_control("a\nb\x1b[31m\x7f\x85\u202e\u2066c") == "a\\nb\\x1b[31m\\x7f\\u0085\\u202e\\u2066c"
    assert escape_control("a\nb\tc", keep_newlines=True) == "a\nb\\tc"
    assert "\x1b" not in describe(["\x1b[2J"]) and "\n" not in describe({"k\n": 1})
    assert describe(list(range(1000))) == "<list of 1000 items>"
