"""The `frustum` command: compose, trace, info, turntable, --version, and one-line errors (exit 1, usage 2)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import imageio.v3 as iio
import numpy as np
import pytest
import trimesh

from frustum import Camera, Perspective, __version__, compose, rotate_z, translate
from frustum.app.cli import main, parse_step
from frustum.trace import trace
from testdata import DATA

BUNNY = DATA / "bunny"


def run(*arguments: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "frustum", *arguments], capture_output=True, text=True, timeout=120, check=False
    )


def test_version():
    result = run("--version")
    assert result.returncode == 0
    assert result.stdout.strip() == f"frustum {__version__}"


def test_compose_prints_steps_composite_and_moved_point():
    result = run("compose", "translate=-1,0,0", "rotate_z_deg=90", "translate=1,0,0", "--point", "2,0,0")
    assert result.returncode == 0, result.stderr
    assert "composite M = M3 · M2 · M1" in result.stdout
    # rotating (2, 0, 0) by 90° about the vertical line through (1, 0, 0) gives (1, 1, 0)
    assert "M · (2, 0, 0, 1) = (1, 1, 0, 1)" in result.stdout


def test_parse_step_builds_the_same_matrices_as_the_api():
    np.testing.assert_allclose(parse_step("rotate_z_deg=30").matrix, rotate_z(np.radians(30)))
    np.testing.assert_allclose(parse_step("translate=1,2,3").matrix, translate(1, 2, 3))
    np.testing.assert_allclose(parse_step("scale=2").matrix, np.diag([2.0, 2, 2, 1]))
    np.testing.assert_allclose(parse_step("reflect=xy").matrix, np.diag([1.0, 1, -1, 1]))
    np.testing.assert_allclose(parse_step("shear=z,1,2,3").matrix[:2, 2:], [[1, -3], [2, -6]])
    np.testing.assert_allclose(
        parse_step("rotate_deg=0,0,1,90,1,0,0").matrix,
        compose(translate(-1, 0, 0), rotate_z(np.pi / 2), translate(1, 0, 0)),
        atol=1e-15,
    )
    np.testing.assert_allclose(parse_step("quaternion=0,0,0,1").matrix, np.diag([-1.0, -1, 1, 1]), atol=1e-15)


@pytest.mark.parametrize(
    ("arguments", "status", "message"),
    [
        (("compose", "rotate_deg=0,0,0,90"), 1, "error: rotate: axis = (0.0, 0.0, 0.0) has zero length"),
        (("compose", "spin=1"), 2, "error: step 'spin=1': 'spin' is not a transformation; expected one of"),
        (("compose", "translate=1,2"), 2, "error: step 'translate=1,2': got 2 numbers; expected 3"),
        (("compose", "translate"), 2, "error: step 'translate' has no '='"),
        (("compose", "scale=a,b,c"), 2, "is not a comma-separated list of numbers"),
        (("compose", "scale=1", "--point", "1,2"), 2, "got 2 numbers; expected 3"),
        (
            ("trace", "--point", "0,0,0", "--eye", "0,0,5", "--up", "0,0,1"),
            1,
            "error: ViewFrame: up = (0.0, 0.0, 1.0) is parallel",
        ),
        (("trace", "--point", "0,0,0", "--fovy-deg", "0"), 1, "error: perspective: fovy = 0.0"),
        (("trace", "--point", "1,2"), 2, "error: --point = '1,2' has 2 numbers; expected 3"),
        (("trace", "--point", "a,b,c"), 2, "error: --point = 'a,b,c' is not a comma-separated list of numbers"),
        (("trace", "--point", "0,0,0", "--size", "64"), 2, "error: --size = '64' is not WIDTHxHEIGHT"),
        (("trace", "--point", "0,0,0", "--markdown", "--latex"), 2, "error: --markdown and --latex were both given"),
        (("trace",), 2, "error: Missing option '--point'"),
        (("trace", "--point", "0,0,0", "--bogus"), 2, "error: No such option: --bogus"),
        (("info", "/nonexistent/mesh.ply"), 1, "error: info: mesh = '/nonexistent/mesh.ply' does not exist"),
        (("info",), 2, "error: Missing argument 'mesh'"),
        (("turntable", "/nonexistent/mesh.ply", "-o", "x.gif"), 1, "error: turntable: mesh = '/nonexistent/mesh.ply'"),
        (("turntable", "mesh.ply"), 2, "error: Missing option '--output'"),
    ],
)
def test_bad_input_prints_one_line_and_exits_1_or_2_for_usage(arguments, status, message, capsys):
    with pytest.raises(SystemExit) as exit_info:
        main(list(arguments))
    captured = capsys.readouterr()
    assert exit_info.value.code == status, captured.err
    assert captured.err.count("\n") == 1, captured.err
    assert message in captured.err
    assert "Traceback" not in captured.err


def test_errors_print_no_traceback_in_a_real_process_unless_debug():
    result = run("trace", "--point", "0,0,0", "--up", "0,0,1")
    assert result.returncode == 1
    assert result.stderr.startswith("error: ViewFrame: up = (0.0, 0.0, 1.0) is parallel")
    assert result.stderr.count("\n") == 1 and "Traceback" not in result.stderr
    debug = run("--debug", "trace", "--point", "0,0,0", "--up", "0,0,1")
    assert debug.returncode == 1
    assert "Traceback" in debug.stderr and "CameraError" in debug.stderr


# --- trace ----------------------------------------------------------------------------------------------------


def _trace_arguments(*extra: str) -> list[str]:
    return ["trace", "--eye", "1,2,5", "--target", "0,0,0", "--up", "0,1,0", "--fovy-deg", "50", "--size", "64x48",
            "--point", "0.2,0.1,-0.3", "--point", "0,0,50", *extra]  # fmt: skip


def _camera() -> Camera:
    return Camera.look_at((1, 2, 5), (0, 0, 0), (0, 1, 0), Perspective(np.radians(50), 0.1, 100.0), 64, 48)


def test_trace_prints_every_stage_with_both_matrix_forms(capsys):
    main(_trace_arguments())
    out = capsys.readouterr().out
    words = " ".join(out.split())  # Rich wraps long lines at the console width
    for stage in trace([[0.2, 0.1, -0.3], [0, 0, 50]], _camera()).stages:
        assert " ".join(stage.title.split()) in words
    assert out.count("Mᵀ (P' = P·Mᵀ)") == 5  # world, translate, rotate, perspective, viewport
    assert "outside:" in words  # (0, 0, 50) lies behind the eye: w < 0


def test_trace_markdown_window_row_equals_camera_project(capsys):
    main(_trace_arguments("--markdown"))
    out = capsys.readouterr().out
    assert "### 9. Viewport transformation" in out
    viewport = out[out.index("### 9. Viewport") :]
    row = next(line for line in viewport.splitlines() if line.startswith("| p0 |"))
    window = [float(v) for v in row.strip("| ").split(" | ")[1:]]
    np.testing.assert_allclose(window, _camera().project([0.2, 0.1, -0.3]), rtol=1e-5)  # printed to 6 digits


def test_trace_latex_has_a_bmatrix_pair_per_matrix(capsys):
    main(_trace_arguments("--latex"))
    out = capsys.readouterr().out
    assert out.count(r"\begin{bmatrix}") == 10  # five matrices (normalization is inside the perspective one)
    assert out.count(r"\subsubsection*") == 9


def test_trace_orthographic(capsys):
    main(["trace", "--point", "0,0,0", "--ortho-height", "4", "--near", "-1", "--markdown"])
    out = capsys.readouterr().out
    assert "orthogonal normalization M\\_ortho,norm" in out


# --- info -----------------------------------------------------------------------------------------------------


def _facts(table: str) -> dict[str, str]:
    """The rows of `frustum info`'s two-column table as a dict."""
    facts = {}
    for line in table.splitlines():
        cells = [cell.strip() for cell in line.strip().strip("│").split("│")]
        if len(cells) == 2:
            facts[cells[0]] = cells[1]
    return facts


def test_info_on_the_bunny_counts_bounds_and_open_edges(capsys):
    path = BUNNY / "bun_zipper_res4.ply"
    reference = trimesh.load(path, process=False)
    main(["info", str(path)])
    facts = _facts(capsys.readouterr().out)
    assert facts["vertices"] == str(len(reference.vertices))
    assert facts["triangles"] == str(len(reference.faces))
    assert facts["bounds min"] == "(" + ", ".join(f"{v:.6g}" for v in reference.vertices.min(axis=0)) + ")"
    assert facts["bounds max"] == "(" + ", ".join(f"{v:.6g}" for v in reference.vertices.max(axis=0)) + ")"
    assert facts["watertight"].startswith("no (")  # the scanned bunny has holes in its base
    assert facts["vertex normals"] == "computed (area-weighted face normals)"


def test_info_on_a_generated_closed_box(tmp_path, capsys):
    path = tmp_path / "box.ply"
    trimesh.creation.box(extents=(1.0, 2.0, 3.0)).export(path)
    main(["info", str(path)])
    facts = _facts(capsys.readouterr().out)
    expected = {
        "vertices": "8", "triangles": "12", "bounds min": "(-0.5, -1, -1.5)", "bounds max": "(0.5, 1, 1.5)",
        "watertight": "yes", "winding consistent": "yes", "surface area": "22", "volume": "6",
        "Euler characteristic": "2", "face normals": "outward", "zero-area triangles": "0",
    }  # fmt: skip
    assert {name: facts.get(name) for name in expected} == expected


def test_info_reports_inward_normals_of_a_flipped_box(tmp_path, capsys):
    box = trimesh.creation.box()
    path = tmp_path / "inside_out.ply"
    trimesh.Trimesh(box.vertices, box.faces[:, ::-1], process=False).export(path)
    main(["info", str(path)])
    assert _facts(capsys.readouterr().out)["face normals"].startswith("inward")


def test_info_on_a_corrupt_file_is_one_line(tmp_path, capsys):
    path = tmp_path / "broken.ply"
    path.write_text("this is not a ply file\n")
    with pytest.raises(SystemExit) as exit_info:
        main(["info", str(path)])
    err = capsys.readouterr().err
    assert exit_info.value.code == 1 and err.count("\n") == 1 and "broken.ply" in err


# --- turntable ------------------------------------------------------------------------------------------------


def test_turntable_writes_the_requested_frames(tmp_path, capsys):
    mesh_path = tmp_path / "box.ply"
    trimesh.creation.box(extents=(1.0, 0.5, 0.3)).export(mesh_path)
    output = tmp_path / "spin.gif"
    main(["turntable", str(mesh_path), "-o", str(output), "--frames", "5", "--size", "32x24"])
    captured = capsys.readouterr()
    assert captured.err == ""  # no progress bar when stderr is not a terminal
    assert f"wrote {output} (5 frames, 32x24)" in captured.out
    frames = list(iio.imiter(output))
    assert len(frames) == 5 and frames[0].shape[:2] == (24, 32)


def test_turntable_bad_suffix_is_one_line(tmp_path, capsys):
    mesh_path = tmp_path / "box.ply"
    trimesh.creation.box().export(mesh_path)
    with pytest.raises(SystemExit) as exit_info:
        main(["turntable", str(mesh_path), "-o", str(tmp_path / "spin.avi"), "--frames", "2", "--size", "8x8"])
    err = capsys.readouterr().err
    assert exit_info.value.code == 1 and err.count("\n") == 1
    assert "turntable: path = " in err and "has suffix '.avi'" in err


# --- scene-file commands --------------------------------------------------------------------------------------

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def test_render_explain_and_view_commands(tmp_path, capsys):
    out = tmp_path / "teapot.png"
    main(["render", str(EXAMPLES / "teapot.toml"), "-o", str(out), "--size", "64x48"])
    assert f"wrote {out}" in capsys.readouterr().out
    assert iio.imread(out).shape[:2] == (48, 64)
    main(["explain", str(EXAMPLES / "transformations.toml"), "--point", "0,0,0", "--markdown"])
    assert "viewport" in capsys.readouterr().out.lower()
    sheet = tmp_path / "sheet.svg"
    main(["view", str(EXAMPLES / "exploded_assembly.toml"), "-o", str(sheet), "--views", "front,top"])
    assert sheet.read_text().lstrip().startswith("<")


def test_view_command_sheet_options(tmp_path, capsys):
    sheet = tmp_path / "sheet.svg"
    arguments = ["view", str(EXAMPLES / "exploded_assembly.toml"), "-o", str(sheet), "--views", "front,top"]
    main([*arguments, "--paper", "a4", "--orientation", "portrait", "--angle", "first", "--dimensions", "none"])
    text = sheet.read_text()
    assert 'width="210mm" height="297mm"' in text and "FIRST ANGLE PROJECTION" in text
    assert 'class="dimension"' not in text
    main([*arguments, "--paper", "Tabloid"])
    text = sheet.read_text()
    assert 'width="431.8mm"' in text and 'class="dimension"' in text
    result = run(*arguments, "--orientation", "sideways")
    assert result.returncode == 1 and "orientation = 'sideways' is unknown" in result.stderr


def test_scene_file_errors_are_one_line_without_traceback(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text("[camera]\neye = [0, 0, 5]\nlens = 3\n")
    result = run("render", str(bad))
    assert result.returncode == 1, result.stderr
    assert "Traceback" not in result.stderr and result.stderr.count("\n") == 1  # one problem, one line
    assert "bad.toml:3: camera.lens = 3 is not a known key" in result.stderr
    bad.write_text("[camera]\nlens = 3\n[render]\nsize = [-4, 3]\n")
    result = run("render", str(bad))  # every problem at once, one line each
    assert result.returncode == 1 and "Traceback" not in result.stderr
    assert "bad.toml:1:" in result.stderr and "bad.toml:2:" in result.stderr and "bad.toml:4:" in result.stderr



@pytest.mark.parametrize("outside", ["../escaped.png", "/tmp/frustum-escaped-absolute.png"])  # outside: refused
def test_output_outside_the_folder_is_refused_without_o_and_ignored_with_o(tmp_path, outside):
    folder = tmp_path / "scenes"
    folder.mkdir()
    scene = folder / "escape.toml"
    scene.write_text(
        '[camera]\neye = [0, 0, 5]\ntarget = [0, 0, 0]\n[render]\nsize = [32, 24]\n'
        '[[nodes]]\ngeometry = { type = "uv_sphere" }\n'
        f'[output]\nfiles = ["{outside}"]\n'
    )
    # without -o the file's own outputs would be written: the one outside its folder is refused, nothing written
    result = run("render", str(scene))
    assert result.returncode == 1, result.stderr
    assert f"escape.toml:9: output.files[0] = {outside!r} is outside the scene file's folder" in result.stderr
    assert "use -o on the command line" in result.stderr
    assert sorted(p.name for p in tmp_path.rglob("*")) == ["escape.toml", "scenes"]
    # with -o they are not written, so they do not stop the render: the picture goes where -o says, only there
    target = tmp_path / "picture.png"
    result = run("render", str(scene), "-o", str(target))
    assert result.returncode == 0, result.stderr
    assert target.is_file() and sorted(p.name for p in tmp_path.rglob("*")) == ["escape.toml", "picture.png", "scenes"]
    assert not (tmp_path / "escaped.png").exists()

# --- the garbage collector of the short-lived program ------------------------------------------------------------

_GC_PROBE = """
import atexit, gc, sys
seen = {}
atexit.register(lambda: print("enabled-at-exit", seen.get("enabled"), "frozen", gc.get_freeze_count() > 0))
import frustum.app.cli as cli
original = cli._main
def probe(argv):
    seen["enabled"] = gc.isenabled()  # inside the command
    original(argv)
cli._main = probe
sys.argv = ["frustum", *sys.argv[1:]]
cli.main()
"""


def test_the_program_pauses_the_collector_and_freezes_its_objects_at_exit():
    # run as the program: no collection during the first seconds, everything frozen before interpreter shutdown
    proc = subprocess.run([sys.executable, "-c", _GC_PROBE, "compose", "translate=1,0,0"], capture_output=True,
                          text=True, timeout=120, check=False)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert "enabled-at-exit False frozen True" in proc.stdout


def test_main_called_from_python_leaves_the_collector_alone(capsys):
    import gc

    frozen = gc.get_freeze_count()
    main(["compose", "translate=1,0,0"])
    assert "composite" in capsys.readouterr().out
    assert gc.isenabled() and gc.get_freeze_count() == frozen


def test_the_collector_resumes_after_the_pause(monkeypatch):
    import gc
    import time

    from frustum.app import runtime

    gc.disable()
    try:
        monkeypatch.setitem(runtime._STATE, "resume_gc_at", time.monotonic() + 60.0)
        runtime._resume_gc_when_due()
        assert not gc.isenabled()  # not yet due
        monkeypatch.setitem(runtime._STATE, "resume_gc_at", time.monotonic() - 0.01)
        runtime._resume_gc_when_due()
        assert gc.isenabled() and runtime._STATE["resume_gc_at"] is None
    finally:
        gc.enable()
