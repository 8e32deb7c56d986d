"""Many files in one command (``frustum.app.many``): ``frustum render a.ply b.obj ... -o out/{stem}.png`` writes what
one command per file writes, byte for byte; a failed input is one line and the others are still rendered; output
patterns, folders and glob patterns; ``--jobs``; ``turntable``, ``view`` and ``info`` take several files too. And the
program's modules import one way (no circle, imports inside functions counted)."""

from __future__ import annotations

import ast
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from frustum.app.many import expand_inputs, output_paths
from frustum.app.runtime import UsageError
from testdata import DATA

ROOT = Path(__file__).resolve().parents[1]
SIX = [DATA / "bunny" / "bun_zipper_res2.ply", DATA / "bunny" / "bun_zipper_res3.ply",
       DATA / "bunny" / "bun_zipper_res4.ply", DATA / "spot" / "spot_triangulated.obj",
       DATA / "spot" / "spot_quadrangulated.obj", DATA / "teapot_n10.obj"]  # fmt: skip


def _program(*arguments: str, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "frustum", *arguments], cwd=cwd, capture_output=True, text=True,
                          timeout=600, check=False)  # fmt: skip


@pytest.fixture(scope="module")
def singles(tmp_path_factory) -> dict[str, bytes]:
    """The six files rendered one command each (the plain program path)."""
    folder = tmp_path_factory.mktemp("singles")
    pictures = {}
    for path in SIX:
        result = _program("render", str(path), "-o", f"{path.stem}.png", "--size", "64x48", cwd=folder)
        assert result.returncode == 0, result.stderr
        pictures[path.stem] = (folder / f"{path.stem}.png").read_bytes()
    return pictures


def test_six_files_in_one_command_are_six_single_commands(singles, tmp_path):
    result = _program("render", *map(str, SIX), "-o", "out/{stem}.png", "--size", "64x48", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert result.stdout.splitlines() == [f"wrote out/{path.stem}.png" for path in SIX] and result.stderr == ""
    assert {path.stem: path.read_bytes() for path in (tmp_path / "out").iterdir()} == singles


def test_on_worker_processes_the_same_bytes(singles, tmp_path):
    result = _program("render", *map(str, SIX[:4]), "-o", "{index:02d}-{stem}.png", "--size", "64x48", "--jobs", "2",
                      cwd=tmp_path)  # fmt: skip
    assert result.returncode == 0, result.stderr
    assert sorted(result.stdout.splitlines()) == sorted(f"wrote {i:02d}-{p.stem}.png" for i, p in enumerate(SIX[:4], 1))
    for index, path in enumerate(SIX[:4], start=1):
        assert (tmp_path / f"{index:02d}-{path.stem}.png").read_bytes() == singles[path.stem]


def test_one_unreadable_file_is_one_line_and_the_others_are_rendered(singles, tmp_path):
    broken = tmp_path / "broken.ply"
    broken.write_text("ply\nformat nonsense\n")
    inputs = [*map(str, SIX[:3]), str(broken), *map(str, SIX[3:5])]
    result = _program("render", *inputs, "-o", "out/{stem}.png", "--size", "64x48", cwd=tmp_path)
    assert result.returncode == 1
    errors = result.stderr.splitlines()
    assert len(errors) == 1 and errors[0].startswith(f"error: {broken}: "), result.stderr
    written = sorted(path.name for path in (tmp_path / "out").iterdir())
    assert written == sorted(f"{path.stem}.png" for path in SIX[:5])
    assert all((tmp_path / "out" / f"{path.stem}.png").read_bytes() == singles[path.stem] for path in SIX[:5])


def test_colliding_outputs_are_an_error_before_any_work(tmp_path):
    for folder in ("a", "b"):
        (tmp_path / folder).mkdir()
        shutil.copy(SIX[2], tmp_path / folder / "model.ply")
    result = _program("render", "a/model.ply", "b/model.ply", "-o", "out/{stem}.png", cwd=tmp_path)
    assert result.returncode == 2 and result.stdout == ""
    assert result.stderr == ("error: the inputs 'a/model.ply' and 'b/model.ply' would both write 'out/model.png'; "
                             "tell them apart with {name} or {index} in -o\n")  # fmt: skip
    assert not (tmp_path / "out").exists()
    one = _program("render", "a/model.ply", "b/model.ply", "-o", "same.png", cwd=tmp_path)
    assert one.returncode == 2 and "names one file for 2 inputs" in one.stderr and not (tmp_path / "same.png").exists()


def test_a_folder_and_a_glob_pattern(singles, tmp_path):
    models = tmp_path / "models"
    models.mkdir()
    for path in SIX[:3]:
        shutil.copy(path, models / path.name)
    (models / "notes.txt").write_text("not a model")
    folder = _program("render", "models", "-o", "thumbs/{stem}.png", "--size", "64x48", cwd=tmp_path)
    assert folder.returncode == 0, folder.stderr
    assert sorted(path.name for path in (tmp_path / "thumbs").iterdir()) == sorted(f"{p.stem}.png" for p in SIX[:3])
    pattern = _program("render", "models/*res[34].ply", "-o", "glob/{name}{suffix}.png", "--size", "64x48",
                       cwd=tmp_path)  # fmt: skip
    assert pattern.returncode == 0, pattern.stderr
    assert sorted(path.name for path in (tmp_path / "glob").iterdir()) == [
        "bun_zipper_res3.ply.ply.png", "bun_zipper_res4.ply.ply.png"]  # fmt: skip
    assert (tmp_path / "glob" / "bun_zipper_res4.ply.ply.png").read_bytes() == singles["bun_zipper_res4"]


def test_patterns_and_inputs_are_checked(tmp_path):
    one = [SIX[0]]
    assert output_paths(one, [Path("x/{stem}-{index:03d}{suffix}.png")], False) == [
        [Path("x/bun_zipper_res2-001.ply.png")]]  # fmt: skip
    assert output_paths(one, [Path("plain.png")], False) == [[Path("plain.png")]]
    assert output_paths(SIX[:2], None, True) == [None, None]
    for bad, fragment in (("{colour}.png", "{colour} is not a field"), ("{stem.png", "is not a pattern"),
                          ("{0}.png", "is not a pattern")):  # fmt: skip
        for inputs, several in ((SIX[:2], True), (one, False)):
            with pytest.raises(UsageError) as caught:
                output_paths(inputs, [Path(bad)], several)
            assert str(caught.value).startswith(f"-o {bad!r}") and fragment in str(caught.value)
    (tmp_path / "empty").mkdir()
    with pytest.raises(UsageError, match="holds no input file"):
        expand_inputs([tmp_path / "empty"])
    with pytest.raises(UsageError, match="matches no file"):
        expand_inputs([tmp_path / "*.ply"])
    assert expand_inputs([SIX[0]]) == ([SIX[0]], False)
    assert expand_inputs([SIX[0], tmp_path / "missing.ply"]) == ([SIX[0], tmp_path / "missing.ply"], True)


def test_turntable_view_and_info_take_several_files(tmp_path):
    meshes = [str(SIX[2]), str(SIX[3])]
    turntable = _program("turntable", *meshes, "-o", "{stem}.gif", "--frames", "2", "--size", "32x32", cwd=tmp_path)
    assert turntable.returncode == 0, turntable.stderr
    assert sorted(turntable.stdout.splitlines()) == ["wrote bun_zipper_res4.gif (2 frames, 32x32)",
                                                     "wrote spot_triangulated.gif (2 frames, 32x32)"]  # fmt: skip
    view = _program("view", *meshes, "-o", "{stem}.svg", cwd=tmp_path)
    assert view.returncode == 0, view.stderr
    assert (tmp_path / "bun_zipper_res4.svg").stat().st_size > 0 and (tmp_path / "spot_triangulated.svg").exists()
    info = _program("info", *meshes, "missing.ply", cwd=tmp_path)
    assert info.returncode == 1
    assert info.stdout.count("vertices") == 2 and info.stderr.startswith("error: missing.ply: ")


APP = ROOT / "src" / "frustum" / "app"
ORDER = ["_program", "cli", "resident", "resident_identity", "mesh_info", "many", "work", "warmup", "timing",
         "numba_start", "runtime"]


def _imports(module: str) -> set[str]:
    """The modules of ``frustum.app`` that `module` imports, at the top or inside functions."""
    found = set()
    for node in ast.walk(ast.parse((APP / f"{module}.py").read_text())):
        if isinstance(node, ast.ImportFrom) and node.module:
            names = [node.module] + [f"{node.module}.{alias.name}" for alias in node.names]
        elif isinstance(node, ast.Import):
            names = [alias.name for alias in node.names]
        else:
            continue
        found |= {name.split(".")[2] for name in names if name.startswith("frustum.app.") and name.count(".") >= 2}
    return found - {module}


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="SIGKILL and /proc: Linux")
def test_a_worker_of_a_killed_command_ends_with_it(tmp_path):
    """``runtime.exit_with_parent`` (the ``--jobs`` and ``frustum warmup`` pool workers): the command's process
    killed outright (SIGKILL: no handler runs), its worker ends within a second or so instead of waiting on its
    pool's queue for ever."""
    import os
    import signal
    import time

    pid_file = tmp_path / "worker.pid"
    command = (
        "import multiprocessing, os, sys, time\n"
        "from frustum.app.runtime import exit_with_parent\n"
        "def work(path):\n"
        "    open(path, 'w').write(str(os.getpid()))\n"
        "    time.sleep(600)\n"
        "if __name__ == '__main__':\n"
        "    context = multiprocessing.get_context('spawn')\n"
        "    from concurrent.futures import ProcessPoolExecutor\n"
        "    pool = ProcessPoolExecutor(1, mp_context=context, initializer=exit_with_parent, initargs=(os.getpid(),))\n"
        f"    pool.submit(work, {str(pid_file)!r})\n"
        "    time.sleep(600)\n"
    )
    script = tmp_path / "command.py"
    script.write_text(command)
    parent = subprocess.Popen([sys.executable, str(script)])
    try:
        deadline = time.monotonic() + 60
        while not pid_file.exists() or not pid_file.read_text():
            assert time.monotonic() < deadline, "the worker did not start"
            time.sleep(0.1)
        worker = int(pid_file.read_text())
        parent.send_signal(signal.SIGKILL)
        parent.wait()
        deadline = time.monotonic() + 5
        while True:
            try:
                os.kill(worker, 0)
            except ProcessLookupError:
                break
            try:
                with open(f"/proc/{worker}/stat") as stat:
                    if stat.read().split(") ")[-1].startswith("Z"):  # ended, not yet reaped by its new parent
                        break
            except FileNotFoundError:
                break
            assert time.monotonic() < deadline, "the worker outlived its command by 5 s"
            time.sleep(0.1)
    finally:
        parent.kill()


def test_the_program_modules_import_one_way():
    modules = sorted(path.stem for path in APP.glob("*.py") if path.stem != "__init__")
    assert sorted(ORDER) == modules, "a module of frustum.app is missing from ORDER"
    for module in ORDER:
        below = set(ORDER[ORDER.index(module) + 1 :])
        assert _imports(module) <= below, f"{module} imports {_imports(module) - below} (not below it)"
    assert "import" not in (APP / "__init__.py").read_text().split('"""')[-1]  # the package imports nothing
