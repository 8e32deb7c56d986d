"""The public API is the same as before the house was split into packages (issue 35): every name of ``frustum`` and
``frustum.geometry``, what ``dir`` shows, every public signature, and every public class's members.

``tests/data/public_api.json`` was captured from the code before the split by ``tests/data/capture_public_api.py``
(run it again only for a deliberate change of the public API)."""

import importlib.util
import inspect
import json
import subprocess
import sys
from pathlib import Path

import pytest

import frustum
import frustum.geometry

SNAPSHOT = json.loads((Path(__file__).parent / "data" / "public_api.json").read_text())


def _describe(module, names):
    spec = importlib.util.spec_from_file_location(
        "capture_public_api", Path(__file__).parent / "data" / "capture_public_api.py"
    )
    assert spec is not None and spec.loader is not None
    capture = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(capture)
    return capture.describe(module, names)


def test_all_lists_the_same_names():
    assert sorted(frustum.__all__) == SNAPSHOT["frustum.__all__"]
    assert sorted(frustum.geometry.__all__) == SNAPSHOT["frustum.geometry.__all__"]


@pytest.mark.parametrize("module_name", ["frustum", "frustum.geometry"])
def test_dir_shows_every_public_name(module_name):
    module = importlib.import_module(module_name)
    shown = set(dir(module))
    expected = set(SNAPSHOT[f"{module_name}.__all__"])
    if module_name == "frustum":
        expected.add("Viewer")
    assert expected - shown == set()


@pytest.mark.parametrize("module_name", ["frustum", "frustum.geometry"])
def test_every_public_signature_is_unchanged(module_name):
    module = importlib.import_module(module_name)
    before = SNAPSHOT[module_name]
    names = sorted(before)
    if module_name == "frustum" and importlib.util.find_spec("anywidget") is None:
        names.remove("Viewer")
    now = _describe(module, names)
    changed = {name: (before[name], now[name]) for name in names if before[name] != now[name]}
    assert changed == {}


def test_render_is_the_function_and_the_package_imports():
    """``frustum.render`` is the function at the top level, while ``frustum.render`` the package (the driver and its
    passes) imports as a module, in either order."""
    from frustum import render

    assert callable(render) and inspect.isfunction(render)
    import frustum.render as render_package  # noqa: F401  (the package, by the import system)

    assert inspect.isfunction(frustum.render)
    assert frustum.render is render
    assert str(inspect.signature(frustum.render)) == SNAPSHOT["frustum"]["render"]["signature"]


@pytest.mark.parametrize("package", ["frustum", "frustum.geometry"])
def test_the_stub_lists_every_public_name_once(package):
    """SPEC 1: ``__init__.pyi`` is the one list of public names (``lazy_loader.attach_stub`` reads it)."""
    import ast

    module = importlib.import_module(package)
    stub = Path(module.__file__).with_suffix(".pyi")
    listed = [alias.name for node in ast.parse(stub.read_text()).body if isinstance(node, ast.ImportFrom)
              for alias in node.names]  # fmt: skip
    assert len(listed) == len(set(listed)), sorted(n for n in listed if listed.count(n) > 1)
    public = set(module.__all__) - {"__version__"} | ({"Viewer"} if package == "frustum" else set())
    assert public - set(listed) == set()
    assert set(listed) - public == set(module._SUBMODULES)


@pytest.mark.parametrize(
    "first",
    ["import frustum.render", "import frustum.trace", "import frustum.warmup", "import frustum.geometry.teapot",
     "from frustum.render import surfaces", "import frustum"],
)  # fmt: skip
def test_a_submodule_import_never_hides_the_function_of_its_name(first):
    """``frustum.render``, ``trace``, ``warmup`` and ``geometry.teapot`` are functions, whatever was imported first."""
    code = (
        f"{first}\n"
        "import inspect, frustum, frustum.render, frustum.trace, frustum.warmup, frustum.geometry.teapot\n"
        "names = [frustum.render, frustum.trace, frustum.warmup, frustum.teapot, frustum.geometry.teapot]\n"
        "assert all(inspect.isfunction(f) for f in names), names\n"
        "assert frustum.render.__module__ == 'frustum.render' and frustum.geometry.teapot is frustum.teapot\n"
        "print('ok')\n"
    )
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert proc.stdout.strip() == "ok", proc.stderr


def test_import_frustum_imports_no_module_of_the_package():
    code = "import sys, frustum; print(sorted(m for m in sys.modules if m.startswith(('frustum.', 'numpy', 'numba'))))"
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert proc.stdout.strip() == "[]", proc.stderr
