"""The ``frustum`` program's own path for a plain ``frustum render FILE -o OUT`` (``frustum.app._program``, issue 36's
warm one-command render): it accepts exactly the plain command lines, gives the same files, output, messages and
exit statuses as the Typer command line, and imports neither Typer, Rich, Pydantic nor trimesh."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from frustum.app._program import plain_render, render_words
from testdata import DATA

ROOT = Path(__file__).resolve().parents[1]
BUNNY = DATA / "bunny" / "bun_zipper_res4.ply"
TYPER = "import sys; sys.argv[0] = 'frustum'; from frustum.app.cli import main; main()"


@pytest.mark.parametrize(
    ("argv", "expected"),
    [
        (["render", "a.ply"], {"scene": "a.ply", "output": [], "size": None, "up": None, "shadows": None}),
        (["render", "a.glb", "-o", "x.png", "--up", "z"], {"scene": "a.glb", "output": [Path("x.png")], "up": "z"}),
        (["render", "-o", "x.png", "a.toml", "--output=y.svg", "--size=64x48", "--shadows", "off"],
         {"scene": "a.toml", "output": [Path("x.png"), Path("y.svg")], "size": "64x48", "shadows": "off"}),
    ],
)  # fmt: skip
def test_plain_render_command_lines_are_taken(argv, expected):
    found = plain_render(argv)
    assert found is not None
    assert {key: found[key] for key in expected} == expected


@pytest.mark.parametrize(
    "argv",
    [
        [], ["view", "a.ply", "-o", "x.svg"], ["render"], ["render", "a.ply", "b.ply"], ["render", "a.ply", "--help"],
        ["--debug", "render", "a.ply"], ["render", "a.ply", "-o"], ["render", "a.ply", "-o", "-x.png"],
        ["render", "a.ply", "--up", "z", "--up", "y"], ["render", "a.ply", "--quality", "high"],
        ["render", "a.ply", "-o=x.png"], ["render", "", "-o", "x.png"], ["render", "a.ply", "--", "-b.ply"],
        ["render", "a.ply", "--size="], ["render", "models/*.ply", "-o", "{stem}.png"], ["render", "a.ply", "-o",
        "out/{stem}.png"], ["render", "a.ply", "b.ply", "-o", "{stem}.png"], ["render", "a.ply", "--jobs", "2"],
    ],
)  # fmt: skip
def test_other_command_lines_go_to_typer(argv):
    assert plain_render(argv) is None


@pytest.mark.parametrize(
    ("argv", "taken"),
    [
        (["render", "a.ply", "b.ply"], {"scenes": ["a.ply", "b.ply"], "jobs": None}),
        (["render", "models/*.ply", "-o", "{stem}.png", "-j", "4"], {"scenes": ["models/*.ply"], "jobs": "4"}),
        (["render", "a.ply", "--jobs=2", "--up", "z"], {"scenes": ["a.ply"], "jobs": "2", "up": "z"}),
        (["render", "a.ply", "--jobs", "x"], None), (["render", "a.ply", "--jobs", "2", "-j", "3"], None),
        (["render", "a.ply", "-j=2"], None), (["render", "-o", "x.png"], None), (["render", "a.ply", "--help"], None),
    ],
)  # fmt: skip
def test_the_many_files_command_lines_run_without_typer(argv, taken):
    found = render_words(argv)
    assert (found if taken is None else {key: found[key] for key in taken}) == taken


def _both(tmp_path: Path, *arguments: str) -> tuple[subprocess.CompletedProcess[str], ...]:
    """The command line run as the program (its own path) and through Typer, each writing into its own folder."""
    results = []
    for name, command in (("program", ["-m", "frustum"]), ("typer", ["-c", TYPER])):
        folder = tmp_path / name
        folder.mkdir()
        results.append(subprocess.run([sys.executable, *command, *arguments], cwd=folder, capture_output=True,
                                      text=True, timeout=300, check=False))  # fmt: skip
    return tuple(results)


def _quiet(stderr: str) -> str:
    """stderr without the compile notice (only the first process after a kernel changed compiles)."""
    return "".join(line for line in stderr.splitlines(keepends=True) if not line.startswith("compiling render"))


@pytest.mark.parametrize(
    "arguments",
    [
        (str(BUNNY), "-o", "out.png", "--size", "64x48"),
        (str(DATA / "teapot_n10.obj"), "--output=a.png", "-o", "b.svg", "--up", "z", "--size=48x32"),
        (str(ROOT / "examples" / "teapot.toml"), "-o", "t.png", "--size", "40x30", "--shadows", "off"),
        (str(BUNNY), str(DATA / "teapot_n10.obj"), "-o", "{index}-{stem}.png", "--size=40x30", "-j", "1"),
    ],
)
def test_the_program_writes_what_typer_writes(tmp_path, arguments):
    program, typer = _both(tmp_path, "render", *arguments)
    assert program.returncode == typer.returncode == 0, program.stderr + typer.stderr
    assert (program.stdout, _quiet(program.stderr)) == (typer.stdout, _quiet(typer.stderr))
    written = sorted(p.name for p in (tmp_path / "program").iterdir())
    assert written == sorted(p.name for p in (tmp_path / "typer").iterdir()) and written
    for name in written:
        assert (tmp_path / "program" / name).read_bytes() == (tmp_path / "typer" / name).read_bytes()


@pytest.mark.parametrize(
    ("arguments", "status", "fragment"),
    [
        (("missing.ply", "-o", "x.png"), 1, "does not exist"),
        ((str(BUNNY), "-o", "x.png", "--size", "64"), 2, "is not WIDTHxHEIGHT"),
        ((str(BUNNY), "-o", "x.png", "--size", "9000x10"), 2, "over the limit of 8192"),
        ((str(BUNNY), "-o", "x.png", "--shadows", "maybe"), 1, "--shadows 'maybe' is unknown"),
        ((str(BUNNY), "-o", "x.png", "--up", "x"), 1, "up = 'x' is not an axis"),
        ((str(BUNNY), "-o", "x.bmp"), 1, "has suffix '.bmp'"),
        ((str(BUNNY), str(BUNNY), "-o", "{stem}.png"), 2, "would both write"),
        ((str(BUNNY), str(DATA / "teapot_n10.obj"), "-o", "x.png"), 2, "names one file for 2 inputs"),
        ((str(BUNNY), str(DATA / "teapot_n10.obj"), "-o", "{stem}.png", "--jobs", "0"), 2, "--jobs = 0"),
        (("no-such-folder/*.ply", "-o", "{stem}.png"), 2, "matches no file"),
    ],
)
def test_the_program_fails_as_typer_does(tmp_path, arguments, status, fragment):
    program, typer = _both(tmp_path, "render", *arguments)
    assert program.returncode == typer.returncode == status
    assert program.stderr == typer.stderr and program.stderr.startswith("error: ") and fragment in program.stderr
    assert program.stderr.count("\n") == 1 and program.stdout == typer.stdout == ""


def test_a_plain_render_imports_no_command_line_library_nor_what_it_does_not_use(tmp_path):
    code = (
        "import atexit, sys\nfrom frustum.app._program import main\nsys.argv = ['frustum', *sys.argv[1:]]\n"
        "atexit.register(lambda: print(sorted({m.split('.')[0] for m in sys.modules} & {'typer', 'click', 'rich',\n"
        "     'pydantic', 'trimesh', 'skimage', 'imageio', 'cairosvg', 'manifold3d', 'multiprocessing'})))\n"
        "main()  # the program's end runs the exit handlers\n"
    )
    for arguments, written in ((["-o", "out.png"], ["out.png"]),  # one file, and two (a batch, not on a terminal)
                               ([str(DATA / "teapot_n10.obj"), "-o", "{stem}.png"], ["bun_zipper_res4.png",
                                                                                      "teapot_n10.png"])):  # fmt: skip
        result = subprocess.run([sys.executable, "-c", code, "render", str(BUNNY), *arguments, "--size", "32x24"],
                                cwd=tmp_path, capture_output=True, text=True, timeout=300, check=False)  # fmt: skip
        assert result.returncode == 0, result.stderr
        assert result.stdout.splitlines() == [*(f"wrote {name}" for name in written), "[]"]
        assert all((tmp_path / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" for name in written)


def test_frustum_profile_times_each_stage_and_changes_nothing(tmp_path):
    plain = subprocess.run([sys.executable, "-m", "frustum", "render", str(BUNNY), "-o", "plain.png", "--size",
                            "32x24"], cwd=tmp_path, capture_output=True, text=True, timeout=300,
                           check=False)  # fmt: skip
    profiled = subprocess.run([sys.executable, "-m", "frustum", "render", str(BUNNY), "-o", "timed.png", "--size",
                               "32x24"], cwd=tmp_path, capture_output=True, text=True, timeout=300, check=False,
                              env={**os.environ, "FRUSTUM_PROFILE": "1"})  # fmt: skip
    assert plain.returncode == profiled.returncode == 0, profiled.stderr
    assert profiled.stdout == "wrote timed.png\n" and "profile:" not in plain.stderr
    line = _quiet(profiled.stderr).strip()
    stages = ["python start-up", "import numpy and numba", "numba target setup", "import frustum", "file reading",
              "kernel loading", "render", "png write"]  # fmt: skip
    assert line.startswith("profile: ") and all(f"{stage} " in line for stage in stages), line
    seconds = [float(part.rsplit(" s", 1)[0].split()[-1]) for part in line.split(";")[0].split(", ")]
    total = float(line.split("; total ")[1].removesuffix(" s"))
    assert all(value >= 0 for value in seconds) and sum(seconds) <= total * 1.05 + 0.01
    assert (tmp_path / "plain.png").read_bytes() == (tmp_path / "timed.png").read_bytes()


def test_a_warm_plain_render_imports_neither_what_numba_only_probes_nor_its_compiler_registries(tmp_path):
    """``frustum.app.numba_start``: PyYAML, colorama and SciPy hidden while Numba imports, and cached kernels loaded
    without the CPU target's refresh (its registries: CFFI, the random generators) nor the extensions' entry points.
    The first run fills the cache (a cold one compiles, and a compile refreshes the target as Numba does)."""
    code = (
        "import sys\nfrom frustum.app._program import main\n"
        f"sys.argv = ['frustum', 'render', {str(BUNNY)!r}, '-o', 'out.png', '--size', '32x24']\nmain([*sys.argv[1:]])\n"
        "import numba.core.entrypoints as e\n"
        "print(sorted(m for m in sys.modules if m.split('.')[0] in ('yaml', 'colorama', 'scipy', 'cffi') or m in\n"
        "     ('numba.core.typing.cffi_utils', 'numba.np.random.generator_methods')), e._already_initialized)\n"
    )
    for _ in range(2):
        result = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True,
                                timeout=300, check=False)  # fmt: skip
        assert result.returncode == 0, result.stderr
    assert result.stdout.splitlines() == ["wrote out.png", "[] False"]


def test_numba_is_imported_with_the_probed_packages_hidden_meanwhile_only(tmp_path):
    code = ("import sys\nfrom frustum.app.numba_start import PROBED, import_numba\nimport_numba()\n"
            "print([name in sys.modules for name in PROBED])\nimport yaml, colorama, scipy\nprint('imported')\n")
    plain = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, timeout=300,
                           check=False)  # fmt: skip
    assert plain.stdout.splitlines() == ["[False, False, False]", "imported"], plain.stderr
    (tmp_path / ".numba_config.yaml").write_text("# read by Numba: PyYAML is imported for it\n")
    configured = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True,
                                timeout=300, check=False, env={**os.environ, "NUMBA_COLOR_SCHEME": "dark_bg"})
    assert configured.stdout.splitlines() == ["[True, True, False]", "imported"], configured.stderr


def test_the_program_ends_at_once_but_runs_its_exit_handlers(tmp_path):
    code = ("import atexit, sys\natexit.register(lambda: print('exit handler ran'))\n"
            "from frustum.app._program import main\nsys.argv = ['frustum'] + sys.argv[1:]\nmain()\n"
            "print('not reached: main ends the process')\n")  # fmt: skip
    for arguments, status in ((["render", "missing.ply", "-o", "x.png"], 1), (["render", str(BUNNY), "-o",
                              "x.png", "--size", "32x24"], 0), (["info", str(BUNNY)], 0)):  # fmt: skip
        result = subprocess.run([sys.executable, "-c", code, *arguments], cwd=tmp_path, capture_output=True,
                                text=True, timeout=300, check=False)  # fmt: skip
        assert result.returncode == status, result.stderr
        assert result.stdout.endswith("exit handler ran\n") and "not reached" not in result.stdout


def test_numbas_runtime_is_kept_compiled_beside_the_kernels_and_serves_a_later_compile(tmp_path):
    """``numba_start._initialize_runtime``: the runtime's object code left in the kernels' cache folder by one
    command is loaded by the next (a damaged file is compiled anew), and a kernel compiled afterwards links it."""
    code = (
        "import glob, os\nfrom pathlib import Path\nimport numpy as np\nfrom frustum.app.work import render_files\n"
        f"render_files(Path({str(BUNNY)!r}), [Path('out.png')], '32x24', 'y', None)\n"
        "from frustum.raster.tiles import fill_tiles\nimport numba\n"
        "print(len(glob.glob(os.path.join(fill_tiles.kernel._cache._cache_path, 'numba-runtime-*.nrt'))))\n"
        "allocating = numba.njit(lambda n: np.ones(n) * 2)\nprint(allocating(3).tolist())\n"
    )  # fmt: skip
    outputs = []
    for damage in (False, False, True, False):
        if damage:
            script = "from frustum.raster.tiles import fill_tiles as k; print(k.kernel._cache._cache_path)"
            folder = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True)
            for path in Path(folder.stdout.strip()).glob("numba-runtime-*.nrt"):
                path.write_bytes(b"not a pickle")
            continue
        result = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True,
                                timeout=300, check=False)  # fmt: skip
        assert result.returncode == 0, result.stderr
        outputs.append(((tmp_path / "out.png").read_bytes(), result.stdout.splitlines()))
    assert all(output == (outputs[0][0], ["1", "[2.0, 2.0, 2.0]"]) for output in outputs)
