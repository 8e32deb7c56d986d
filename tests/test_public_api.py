"""The public API is the same as before the house was split into packages (issue 35): every name of ``frustum`` and
``frustum.geometry``, what ``dir`` shows, every public signature, and every public class's members.

``tests/data/public_api.json`` was captured from the code before the split (commit d8bb076) by
``tests/data/capture_public_api.py``. Later issues may add names, members and keyword parameters with defaults;
nothing of the snapshot may go or change (a deliberate break: capture the snapshot again)."""

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


def test_all_still_lists_every_name():
    assert set(SNAPSHOT["frustum.__all__"]) - set(frustum.__all__) == set()
    assert set(SNAPSHOT["frustum.geometry.__all__"]) - set(frustum.geometry.__all__) == set()
    assert "Viewer" not in frustum.__all__  # (it needs the viewer extra: `from frustum import *` works without it)


def _compatible(before, now):
    """Whether `now` (a ``describe`` entry) keeps everything of `before`: the kind, every parameter in order with its
    kind and default (added parameters need a default), every member (added members are fine)."""
    if before is None or now is None or before.keys() - now.keys() or before["kind"] != now["kind"]:
        return before == now
    if "signature" in before and not _compatible_signature(before["signature"], now["signature"]):
        return False
    members = before.get("members", {})
    return all(
        name in now["members"] and (value == now["members"][name] or _compatible_signature(value, now["members"][name]))
        for name, value in members.items()
    )


def _compatible_signature(before, now):
    if not isinstance(before, dict) or not isinstance(now, dict):
        return before == now
    old, new = before["parameters"], now["parameters"]
    kept = [p for p in new if p[0] in {q[0] for q in old}]
    added = [p for p in new if p[0] not in {q[0] for q in old}]
    return kept == old and all(p[2] is not None or p[1] in ("VAR_POSITIONAL", "VAR_KEYWORD") for p in added)


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
    changed = {name: (before[name], now[name]) for name in names if not _compatible(before[name], now[name])}
    assert changed == {}


def test_a_changed_default_or_a_dropped_parameter_is_caught():
    """The comparison itself: adding keywords with defaults is compatible, changing or dropping one is not."""
    before = {"kind": "function", "signature": {"text": "", "parameters": [["a", "POSITIONAL_OR_KEYWORD", None],
                                                                           ["b", "KEYWORD_ONLY", "1"]]}}  # fmt: skip
    added = {"kind": "function", "signature": {"text": "", "parameters": [*before["signature"]["parameters"],
                                                                          ["c", "KEYWORD_ONLY", "None"]]}}  # fmt: skip
    changed = {"kind": "function", "signature": {"text": "", "parameters": [["a", "POSITIONAL_OR_KEYWORD", None],
                                                                            ["b", "KEYWORD_ONLY", "2"]]}}  # fmt: skip
    dropped = {"kind": "function", "signature": {"text": "", "parameters": [["a", "POSITIONAL_OR_KEYWORD", None]]}}
    required = {"kind": "function", "signature": {"text": "", "parameters": [*before["signature"]["parameters"],
                                                                             ["c", "KEYWORD_ONLY", None]]}}  # fmt: skip
    assert _compatible(before, added)
    assert not any(_compatible(before, other) for other in (changed, dropped, required))


def test_render_is_the_function_and_the_package_imports():
    """``frustum.render`` is the function at the top level, while ``frustum.render`` the package (the driver and its
    passes) imports as a module, in either order."""
    from frustum import render

    assert callable(render) and inspect.isfunction(render)
    import frustum.render as render_package  # noqa: F401  (the package, by the import system)

    assert inspect.isfunction(frustum.render)
    assert frustum.render is render


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
    ["import frustum.render", "import frustum.trace", "import frustum.app.warmup", "import frustum.geometry.teapot",
     "from frustum.render import surfaces", "import frustum"],
)  # fmt: skip
def test_a_submodule_import_never_hides_the_function_of_its_name(first):
    """``frustum.render``, ``trace``, ``warmup`` and ``geometry.teapot`` are functions, whatever was imported first."""
    code = (
        f"{first}\n"
        "import inspect, frustum, frustum.render, frustum.trace, frustum.app.warmup, frustum.geometry.teapot\n"
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
