"""The public API is the same as before the house was split into packages (issue 35): every name of ``frustum`` and
``frustum.geometry``, what ``dir`` shows, every public signature, and every public class's members.

``tests/data/public_api.json`` was captured from the code before the split by ``tests/data/capture_public_api.py``
(run it again only for a deliberate change of the public API)."""

import importlib.util
import inspect
import json
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
