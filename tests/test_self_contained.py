"""The repository holds everything its tests read: no test names a path outside it (an absolute path such as
``/work/...``, a ``../shared`` folder beside the clone, ``Path(__file__).parents[k]`` above the repository root),
and every reference-data file a test names through ``DATA`` is in ``tests/data/``.

The check reads the tests' sources with ``ast`` (every ``*.py`` under ``tests/`` but this one, whose strings are
the patterns it looks for), so it also covers modules whose tests are skipped or deselected in a run."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

from testdata import DATA

TESTS = Path(__file__).resolve().parent
ROOT = TESTS.parent
SOURCES = sorted(TESTS.rglob("*.py"))
SCANNED = [path for path in SOURCES if path != Path(__file__).resolve()]  # this file names such paths as examples

# An absolute path is flagged when its first folder exists at the file system's root (so a deliberately missing
# '/nonexistent/x.ply' or a URL path '/ws' is not), except these: devices and process information, and the
# temporary folder (outputs of the hostile-path tests, never data to read).
SYSTEM_ROOTS = ("dev", "proc", "sys", "tmp")
# `../` in a string is allowed only in the hostile-input tests, which check that such output paths are refused, and
# on a line marked with this comment (a test that such a path is refused, never read)
PARENT_ALLOWED_UNDER = TESTS / "hostile"
REFUSED_MARK = "# outside: refused"


def _mentions_file(node: ast.AST) -> bool:
    return any(isinstance(sub, ast.Name) and sub.id == "__file__" for sub in ast.walk(node))


def _offences(path: Path, root: Path = ROOT) -> list[str]:
    """The places in one test module (somewhere below `root`) that name a path outside the repository."""
    source = path.read_text(encoding="utf-8")
    tree = ast.parse(source, filename=str(path))
    lines = source.splitlines()
    depth = len(path.relative_to(root).parts) - 1  # parents[depth] of this file is the repository root
    docstring = tree.body[0].value if tree.body and isinstance(tree.body[0], ast.Expr) else None
    found, chained = [], set()
    for node in ast.walk(tree):
        where = f"{path.relative_to(root)}:{getattr(node, 'lineno', '?')}"
        if isinstance(node, ast.Constant) and isinstance(node.value, str) and node is not docstring:
            text = node.value
            first = text[1:].split("/", 1)[0]
            if (
                text.startswith("/")
                and first
                and first not in SYSTEM_ROOTS
                and Path("/", first).is_dir()
                and not text.startswith("//")
            ):
                found.append(f"{where}: absolute path {text!r}")
            elif "/work/" in text or "shared/data" in text or "shared/bench" in text or text == "shared":
                found.append(f"{where}: a folder outside the repository in {text!r}")
            elif (
                ("../" in text or text == "..")
                and not path.is_relative_to(PARENT_ALLOWED_UNDER)
                and REFUSED_MARK not in lines[node.lineno - 1]
            ):
                found.append(f"{where}: parent-folder path {text!r}")
        elif (
            isinstance(node, ast.Subscript)
            and isinstance(node.value, ast.Attribute)
            and node.value.attr == "parents"
            and isinstance(node.slice, ast.Constant)
            and isinstance(node.slice.value, int)
            and _mentions_file(node.value)
            and node.slice.value > depth
        ):
            found.append(f"{where}: Path(__file__).parents[{node.slice.value}] is above the repository root")
        elif isinstance(node, ast.Attribute) and node.attr == "parent" and _mentions_file(node):
            chain, inner = 0, node
            while isinstance(inner, ast.Attribute) and inner.attr == "parent":
                chain, inner = chain + 1, inner.value
                chained.add(inner)  # the inner links of this chain are not reported again
            if chain > depth + 1 and node not in chained:
                found.append(f"{where}: {chain} x .parent of __file__ is above the repository root")
    return found


def test_the_scan_sees_the_test_sources():
    assert TESTS / "test_io.py" in SOURCES and TESTS / "hostile" / "test_hostile_inputs.py" in SOURCES


def test_the_scan_finds_paths_outside_the_repository(tmp_path):
    module = tmp_path / "tests" / "test_bad.py"  # as if at tests/test_bad.py of a repository at tmp_path
    module.parent.mkdir()
    module.write_text(
        "from pathlib import Path\n"
        "A = Path('/work/shared/data/bunny')\n"
        "B = Path(__file__).resolve().parents[2] / 'shared' / 'data'\n"
        "C = Path(__file__).parent.parent.parent\n"
        "D = '../shared/data/teapot_n10.obj'\n"
        "E = Path(__file__).resolve().parents[1] / 'examples'\n"
        "F = '../refused.png'  # outside: refused\n"
    )
    offences = _offences(module, root=tmp_path)
    assert sorted(line.split(":")[1] for line in offences) == ["2", "3", "3", "4", "5"], offences


@pytest.mark.parametrize("path", SCANNED, ids=lambda path: str(path.relative_to(TESTS)))
def test_no_test_names_a_path_outside_the_repository(path):
    assert _offences(path) == []


def _data_paths(path: Path) -> list[tuple[int, Path]]:
    """Constant paths built as ``DATA / "a" / "b"`` (or through a name bound to such a path) in one module."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    known: dict[str, Path] = {"DATA": DATA}

    def evaluate(node: ast.AST) -> Path | None:
        if isinstance(node, ast.Name):
            return known.get(node.id)
        if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Div):
            left = evaluate(node.left)
            if left is not None and isinstance(node.right, ast.Constant) and isinstance(node.right.value, str):
                return left / node.right.value
        return None

    for node in tree.body:  # module-level names first (BUNNY = DATA / "bunny")
        if isinstance(node, ast.Assign) and len(node.targets) == 1 and isinstance(node.targets[0], ast.Name):
            value = evaluate(node.value)
            if value is not None:
                known[node.targets[0].id] = value
    return [
        (node.lineno, value)
        for node in ast.walk(tree)
        if isinstance(node, ast.BinOp) and (value := evaluate(node)) is not None
    ]


def test_every_named_reference_file_is_in_the_repository():
    named = [(path, line, file) for path in SOURCES for line, file in _data_paths(path)]
    assert len(named) >= 10  # the scan does see the tests' data paths
    missing = [f"{path.relative_to(ROOT)}:{line}: {file}" for path, line, file in named if not file.exists()]
    assert missing == []
    assert all(file.resolve().is_relative_to(ROOT) for _, _, file in named)
