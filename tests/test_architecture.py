"""The rules of docs/architecture.md, read from the code itself: no import circle among the modules of ``src/``
(imports inside functions count), no module over 800 lines but the Numba kernel modules that say why at their top,
no function over 120 lines outside the kernels, the generated import diagram up to date, the code citing the
architecture page and not documents outside the repository, and the re-export shims of moved modules used by no
module of the package."""

from __future__ import annotations

import ast
import importlib.util
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SRC = ROOT / "src" / "frustum"
SCRIPT = ROOT / "docs" / "hooks" / "architecture.py"
MAX_MODULE_LINES = 800
MAX_FUNCTION_LINES = 120
KERNEL_NOTE = "kernel module:"  # a kernel module longer than the limit says why, in a comment near its top
SHIMS = ("frustum.bsp", "frustum.hidden_lines", "frustum.radiosity", "frustum.shadow_pass")


def _architecture():
    spec = importlib.util.spec_from_file_location("architecture", SCRIPT)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan, iterative)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []
    counter = 0
    for root in graph:
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = counter
        counter += 1
        stack.append(root)
        on_stack.add(root)
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is not None:
                if child not in index:
                    index[child] = low[child] = counter
                    counter += 1
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(graph[child]))))
                elif child in on_stack:
                    low[node] = min(low[node], index[child])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                component = []
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component.append(member)
                    if member == node:
                        break
                if len(component) > 1:
                    found.append(sorted(component))
    return found


def test_the_cycle_finder_finds_a_circle():
    assert _cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
    assert _cycles({"a": {"b"}, "b": set()}) == []


def test_the_import_reader_counts_imports_inside_functions_and_not_type_checking_ones(tmp_path):
    architecture = _architecture()
    tree = ast.parse(
        "from typing import TYPE_CHECKING\n"
        "if TYPE_CHECKING:\n    from frustum.scene import Scene\n"
        "def f():\n    from frustum.render import lines\n    import frustum.camera\n"
        "from . import errors\n"
    )
    modules = {"frustum.render.lines", "frustum.camera", "frustum.scene", "frustum.output.errors", "frustum.render"}
    found = architecture._imports(tree, "frustum.output.thing", False, modules)
    assert found == {"frustum.render.lines", "frustum.camera", "frustum.output.errors"}


def test_no_import_circle_among_the_modules():
    graph = _architecture().module_imports()
    assert len(graph) > 150
    assert _cycles(graph) == []


def test_no_module_over_800_lines_but_kernel_modules_that_say_why():
    long = []
    for path in sorted(SRC.rglob("*.py")):
        lines = path.read_text(encoding="utf-8").splitlines()
        if len(lines) <= MAX_MODULE_LINES:
            continue
        kernel = path.parent.name == "raster" and any(KERNEL_NOTE in line for line in lines[:40])
        if not kernel:
            long.append(f"{path.relative_to(SRC)}: {len(lines)} lines")
    assert long == []


def _function_lines(node: ast.FunctionDef | ast.AsyncFunctionDef) -> int:
    """Lines of a function without its docstring (a long parameter list documented is not a long function)."""
    lines = node.end_lineno - node.lineno + 1
    first = node.body[0]
    if isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant) and isinstance(first.value.value, str):
        lines -= first.end_lineno - first.lineno + 1
    return lines


def test_no_function_over_120_lines_outside_the_kernels():
    long = []
    for path in sorted(SRC.rglob("*.py")):
        if path.parent.name == "raster":  # Numba kernels: one algorithm's flat loops (STYLE of raster/)
            continue
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef) and _function_lines(node) > MAX_FUNCTION_LINES:
                long.append(f"{path.relative_to(SRC)}:{node.lineno} {node.name}: {_function_lines(node)} lines")
    assert long == []


def test_the_import_diagram_of_docs_architecture_is_up_to_date():
    result = subprocess.run([sys.executable, str(SCRIPT), "--check"], capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr


def test_the_code_cites_the_architecture_page_not_documents_outside_the_repository():
    outside = [
        f"{path.relative_to(SRC)}:{number}"
        for path in sorted(SRC.rglob("*.py"))
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1)
        if "DESIGN.md" in line or "STYLE.md" in line
    ]
    assert outside == []
    assert (ROOT / "docs" / "architecture.md").is_file()
    assert "docs/architecture.md" in (ROOT / "CONTRIBUTING.md").read_text(encoding="utf-8")


def test_no_module_of_the_package_imports_a_re_export_shim():
    graph = _architecture().module_imports()
    users = sorted(f"{module} → {shim}" for module, imported in graph.items() for shim in SHIMS if shim in imported)
    assert users == []


def test_the_moved_modules_keep_their_public_paths():
    code = (
        "import frustum.bsp, frustum.hidden_lines, frustum.radiosity, frustum.shadow_pass\n"
        "from frustum.visibility import bsp, depth_sort, hidden_lines\n"
        "from frustum.render.shadows import fractions\n"
        "assert frustum.bsp.BSPTree is bsp.BSPTree and frustum.bsp.depth_sort is depth_sort.depth_sort\n"
        "assert frustum.hidden_lines.remove_hidden_lines is hidden_lines.remove_hidden_lines\n"
        "assert frustum.shadow_pass.set_map_reuse is fractions.set_map_reuse\n"
        "from frustum.radiosity import radiosity\n"
        "from frustum.scene import Scene, cutaway, exploded\n"
        "from frustum.output.sheet import drawing_sheet\n"
        "from frustum.geometry.octree import Octree, morton_encode\n"
        "from frustum.camera import Camera\n"
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300, cwd=ROOT)
    assert result.returncode == 0, result.stderr
