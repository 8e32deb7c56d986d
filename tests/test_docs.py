"""The documentation site (mkdocs.yml, docs/): it builds with warnings as errors, a broken link makes it fail,
every public name of frustum is in the generated API reference, the docstrings' formulas are math that typesets
(docs/contributing.md), every Python block of the how-to guides runs, and every tutorial runs as a reader follows
it (Python, the files it saves, its ``frustum`` commands).

The two builds (the real docs and a copy with broken references) run at the same time in subprocesses, into
temporary folders; nothing is cached outside them.
"""

from __future__ import annotations

import ast
import importlib.util
import inspect
import json
import os
import re
import shutil
import subprocess
import sys
import types
from pathlib import Path

import pytest

import frustum

ROOT = Path(__file__).resolve().parents[1]
HOWTO = ROOT / "docs" / "how-to"
TUTORIALS = ROOT / "docs" / "tutorials"
BLOCK = re.compile(r"(?P<skip><!--\s*not run:[^>]*-->\s*\n)?```python\n(?P<code>.*?)^```", re.S | re.M)


def _build(config_dir: Path, site: Path) -> subprocess.Popen:
    env = dict(os.environ, NO_MKDOCS_2_WARNING="1", PYTHONPATH=str(ROOT / "src"))
    return subprocess.Popen(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "-f", str(config_dir / "mkdocs.yml"), "-d", str(site)],
        cwd=config_dir, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
    )


@pytest.fixture(scope="module")
def builds(tmp_path_factory):
    """(good build, broken build): each (return code, output, site folder)."""
    tmp = tmp_path_factory.mktemp("docs")
    broken = tmp / "broken"
    broken.mkdir()
    shutil.copy(ROOT / "mkdocs.yml", broken / "mkdocs.yml")
    shutil.copytree(ROOT / "docs", broken / "docs", ignore=shutil.ignore_patterns("__pycache__"))
    for name in ("src", "examples", "notebooks"):  # what the hook and mkdocstrings read, relative to the config
        (broken / name).symlink_to(ROOT / name, target_is_directory=True)
    page = broken / "docs" / "how-to" / "index.md"
    page.write_text(
        page.read_text(encoding="utf-8")
        + "\nSee [a page that is not there](no-such-page.md) and [`frustum.no_such_name`][frustum.no_such_name].\n",
        encoding="utf-8",
    )
    procs = [_build(ROOT, tmp / "site"), _build(broken, tmp / "broken-site")]
    results = []
    for proc, site in zip(procs, (tmp / "site", tmp / "broken-site"), strict=True):
        output, _ = proc.communicate(timeout=600)
        results.append((proc.returncode, output, site))
    return results


def test_site_builds_strict(builds):
    code, output, site = builds[0]
    assert code == 0, output[-4000:]
    for page in ("index.html", "gallery/index.html", "reference/cli/index.html", "reference/scene-file/index.html",
                 "how-to/textures/index.html", "tutorials/first-picture/index.html", "conventions/index.html"):
        assert (site / page).is_file(), page
    gallery = (site / "gallery" / "index.html").read_text(encoding="utf-8")
    for toml in sorted((ROOT / "examples").glob("*.toml")):
        assert f"examples/{toml.name}" in gallery, toml.name
    cli = (site / "reference" / "cli" / "index.html").read_text(encoding="utf-8")
    assert "frustum render" in cli and "frustum dataset" in cli
    # the scene-file tables named in `frustum view` and `frustum radiosity --help` (rich markup used to swallow them)
    assert "[sheet] table" in cli and "[radiosity]" in cli


# formulas of the docstrings, as the built reference carries them: arithmatex spans that assets/math.js typesets
FORMULAS = {
    "projection": "x_c = (f/aspect)·x",
    "camera": "u = V×n/|V×n|",
    "shading": "f(d) = f_min + (f_max − f_min)·(d_far − d)/(d_far − d_near)",
    "transforms": "x' = x + tx, y' = y + ty, z' = z + tz",
    "clipping": "−w &lt;= x, y, z &lt;= w",
}


def test_formulas_are_math_in_the_reference(builds):
    code, output, site = builds[0]
    assert code == 0, output[-4000:]
    for page, formula in FORMULAS.items():
        html = (site / "reference" / "api" / page / "index.html").read_text(encoding="utf-8")
        assert f'<span class="arithmatex">\\({formula}\\)</span>' in html, (page, formula)
    shading = (site / "reference" / "api" / "shading" / "index.html").read_text(encoding="utf-8")
    assert '<div class="arithmatex">\\[I = C·(k_a·I_a + Σ_l f_l·k_d·I_l·max(N·L_l, 0))' in shading  # displayed
    index = (site / "index.html").read_text(encoding="utf-8")
    # KaTeX and the typesetting script come from the site itself (offline), with KaTeX's licence beside them
    assert 'src="assets/katex/katex.min.js"' in index and 'src="assets/math.js"' in index
    assert 'href="assets/katex/katex.min.css"' in index
    assert (site / "assets" / "katex" / "LICENSE").is_file()
    assert (site / "assets" / "katex" / "fonts" / "KaTeX_Main-Regular.woff2").is_file()


def test_broken_reference_fails_the_build(builds):
    code, output, _ = builds[1]
    assert code != 0, "a strict build with broken references passed"
    assert "no-such-page.md" in output, output[-4000:]
    assert "frustum.no_such_name" in output, output[-4000:]


def _public_names() -> list[str]:
    """``dir(frustum)`` and ``__all__`` (lazy names included) without what frustum merely imports."""
    names = set(dir(frustum)) | set(frustum.__all__) | set(getattr(frustum, "_LAZY", {}))
    public = []
    for name in sorted(names):
        if name.startswith("_") or name == "TYPE_CHECKING":
            continue
        obj = getattr(frustum, name)
        if isinstance(obj, types.ModuleType) and not obj.__name__.startswith("frustum"):
            continue  # sys, importlib, types
        if getattr(obj, "__module__", None) == "typing" and not isinstance(obj, types.ModuleType):
            continue  # typing.Any
        public.append(name)
    return public


def test_every_public_name_is_in_the_reference(builds):
    code, output, site = builds[0]
    assert code == 0, output[-4000:]
    html = "".join(p.read_text(encoding="utf-8") for p in (site / "reference" / "api").rglob("index.html"))
    anchors = set(re.findall(r'id="([\w.]+)"', html))
    tails = {anchor.rsplit(".", 1)[-1] for anchor in anchors}
    names = _public_names()
    assert len(names) > 250
    missing = [n for n in names if n not in tails and f"frustum.{n}" not in anchors]
    assert not missing, f"public names missing from the API reference: {missing}"
    # each documented with its docstring's first line
    for name in ("render", "load_parts", "Camera", "drawing_sheet"):
        first = inspect.getdoc(getattr(frustum, name)).splitlines()[0][:30]
        assert first.split("`")[0][:20] in html, name


def test_a_name_without_docstring_warns(monkeypatch, caplog):
    spec = importlib.util.spec_from_file_location("frustum_docs_hook", ROOT / "docs" / "hooks" / "gen_pages.py")
    hook = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(hook)

    def undocumented_thing():
        pass

    undocumented_thing.__module__ = "frustum.render"
    monkeypatch.setattr(frustum, "undocumented_thing", undocumented_thing, raising=False)
    # dir(frustum) lists the lazy stub's names; __all__ is what a new public name would join
    monkeypatch.setattr(frustum, "__all__", [*frustum.__all__, "undocumented_thing"])
    with caplog.at_level("WARNING"):
        hook.api_entries()
    assert any("undocumented_thing" in r.getMessage() and r.levelname == "WARNING" for r in caplog.records)


MATH = re.compile(r"(?<!\\)\$(?!\s)((?:\\.|[^\\$])+?)(?<!\s)\$")  # arithmatex's inline $...$
CODE = re.compile(r"\bfr\.|\bnp\.|\"|\w\(\w+=|==|[A-Za-z_]\.[A-Za-z_]|\(\)|<\w+>|[A-Z][a-z]{2,}\w*\(|\bif\b|\bfor\b")


def _docstrings():
    """(where, docstring) of every module, class and function of the package, read statically."""
    out = []
    for path in sorted((ROOT / "src" / "frustum").rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
                doc = ast.get_docstring(node)
                if doc:
                    out.append((f"{path.relative_to(ROOT)}:{getattr(node, 'name', '')}", doc))
    return out


_KATEX_CHECK = """
const katex = require(process.argv[1] + "/docs/assets/katex/katex.min.js");
const {toTex} = require(process.argv[1] + "/docs/assets/math.js");
const bad = [];
for (const [where, formula] of JSON.parse(require("fs").readFileSync(0, "utf8"))) {
  try { katex.renderToString(toTex(formula), {throwOnError: true, strict: "error"}); }
  catch (e) { bad.push([where, formula, e.message.slice(0, 200)]); }
}
console.log(JSON.stringify(bad));
"""


@pytest.mark.skipif(shutil.which("node") is None, reason="Node.js runs KaTeX (the site's own copy) for this check")
def test_docstring_formulas_typeset():
    """Every $...$ formula of the docstrings and the pages typesets with the site's KaTeX after assets/math.js's
    toTex (KaTeX in strict mode: an unknown symbol fails too), and a broken formula is reported."""
    formulas = [(where, m.group(1)) for where, doc in _docstrings()
                for m in MATH.finditer(re.sub(r"``.*?``", "", doc, flags=re.S))]
    assert len(formulas) > 500
    on_pages = []
    for page in sorted((ROOT / "docs").rglob("*.md")):
        text = re.sub(r"^```.*?^```", "", page.read_text(encoding="utf-8"), flags=re.S | re.M)  # code blocks
        text = re.sub(r"(`+)(?s:.+?)\1", "", text)  # code spans
        on_pages += [(str(page.relative_to(ROOT)), m.group(1)) for m in MATH.finditer(text)]
    assert len(on_pages) > 100
    formulas += on_pages
    broken = [("broken", "x_{(1 − t"), ("unknown symbol", "a ⍰ b")]
    result = subprocess.run(["node", "-e", _KATEX_CHECK, str(ROOT)], input=json.dumps(formulas + broken),
                            capture_output=True, text=True, timeout=120, check=True)
    bad = json.loads(result.stdout)
    assert [b[0] for b in bad] == ["broken", "unknown symbol"], bad


def test_formulas_are_not_code_spans():
    """The convention (docs/contributing.md): a formula is written $...$, not as a ``literal``; a literal with
    a math operator and no code in it is a formula left behind."""
    left = [(where, m.group(1)) for where, doc in _docstrings() for m in re.finditer(r"``(.+?)``", doc, re.S)
            if re.search("[·×−²³√≤≥∑Σ]", m.group(1)) and not CODE.search(m.group(1))]
    assert not left, left


def _blocks():
    out = []
    for page in sorted(HOWTO.glob("*.md")):
        for number, match in enumerate(BLOCK.finditer(page.read_text(encoding="utf-8"))):
            marks = [pytest.mark.skip(reason=match.group("skip").strip())] if match.group("skip") else []
            out.append(pytest.param(page.name, match.group("code"), id=f"{page.stem}-{number}", marks=marks))
    return out


def test_howto_pages_have_blocks():
    pages = {p.name for p in HOWTO.glob("*.md")} - {"index.md"}
    with_blocks = {p for p, *_ in (b.values for b in _blocks())}
    assert pages <= with_blocks, f"how-to pages without a runnable Python block: {pages - with_blocks}"


@pytest.mark.parametrize(("page", "code"), _blocks())
def test_howto_block_runs(page, code, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    budget = frustum.get_budget()
    try:
        exec(compile(code, f"docs/how-to/{page}", "exec"), {"__name__": "__docs__"})
    finally:
        frustum.set_budget(budget.bytes, budget.operations)
        frustum.set_threads(None)


# --- tutorials: every code block runs, in page order, in one folder and one namespace per page --------------------

FENCE = re.compile(r"(?P<marks>(?:<!--[^>]*-->[ \t]*\n)*)```(?P<lang>\w+)\n(?P<code>.*?)^```", re.S | re.M)
MARK = re.compile(r"<!--\s*(not run|save as|append to):\s*([^>]*?)\s*-->")
# shell steps a tutorial shows but the test does not repeat: the reader's own install, done once for the tests
SETUP = (("python3", "-m", "venv"), (".venv/bin/pip", "install"))


def _tutorial_blocks(page: Path) -> list[tuple[str, str, dict[str, str]]]:
    """(language, code, {mark: value}) of every fenced block of `page`, in order. A block may be preceded by
    HTML comments (invisible on the site): ``<!-- save as: NAME -->`` / ``<!-- append to: NAME -->`` write the
    block to that file of the tutorial's folder (a TOML scene, say), ``<!-- not run: REASON -->`` skips it."""
    return [(m.group("lang"), m.group("code"), dict(MARK.findall(m.group("marks"))))
            for m in FENCE.finditer(page.read_text(encoding="utf-8"))]


def _shell_commands(code: str) -> list[tuple[list[str], str | None]]:
    """(argv, expected error or None) for each command of a shell block; a ``# error: TEXT`` line right after a
    command says it fails with TEXT (up to a trailing "...") in its output."""
    import shlex

    commands: list[tuple[list[str], str | None]] = []
    for line in code.splitlines():
        line = line.strip()
        if line.startswith("# error:"):
            argv, _ = commands[-1]
            commands[-1] = (argv, line[len("# error:"):].strip().removesuffix("...").strip())
        elif line and not line.startswith("#"):
            for part in line.split("&&"):
                commands.append((shlex.split(part, comments=True), None))
    return commands


def _run_shell(code: str, where: str) -> None:
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"), NO_COLOR="1", COLUMNS="100")
    for argv, error in _shell_commands(code):
        if any(tuple(argv[: len(s)]) == s for s in SETUP):
            continue
        assert Path(argv[0]).name == "frustum", f"{where}: a shell command the test cannot run: {argv}"
        result = subprocess.run([sys.executable, "-m", "frustum", *argv[1:]], env=env, capture_output=True,
                                text=True, timeout=300)
        output = result.stdout + result.stderr
        if error is None:
            assert result.returncode == 0, f"{where}: {' '.join(argv)} failed:\n{output[-2000:]}"
            if "-o" in argv:
                assert Path(argv[argv.index("-o") + 1]).is_file(), f"{where}: {' '.join(argv)} wrote nothing"
        else:
            assert result.returncode != 0, f"{where}: {' '.join(argv)} should fail"
            assert error in output, f"{where}: {' '.join(argv)}: expected {error!r} in:\n{output[-2000:]}"


def _tutorial_pages():
    return sorted(TUTORIALS.glob("*.md"))


@pytest.mark.parametrize("page", _tutorial_pages(), ids=lambda p: p.stem)
def test_tutorial_runs(page, tmp_path, monkeypatch):
    """Each tutorial as a reader follows it: its blocks in order, in a fresh folder (with the repository's
    ``examples/`` beside it), Python blocks in one namespace, ``frustum`` commands as subprocesses."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "examples").symlink_to(ROOT / "examples", target_is_directory=True)
    namespace = {"__name__": "__docs__"}
    ran = 0
    for number, (lang, code, marks) in enumerate(_tutorial_blocks(page)):
        where = f"docs/tutorials/{page.name} block {number}"
        if "not run" in marks:
            continue
        if "save as" in marks or "append to" in marks:
            target = tmp_path / (marks.get("save as") or marks["append to"])
            with target.open("w" if "save as" in marks else "a", encoding="utf-8") as out:
                out.write(code if "save as" in marks else "\n" + code)
        elif lang == "python":
            exec(compile(code, where, "exec"), namespace)
        elif lang in ("bash", "sh", "console", "shell"):
            _run_shell(code, where)
        else:
            pytest.fail(f"{where}: a {lang} block neither run nor saved (mark it <!-- save as: NAME --> or "
                        "<!-- not run: REASON -->)")
        ran += 1
    assert ran, f"{page.name}: no block ran"


def test_tutorials_are_tested():
    pages = {p.name for p in _tutorial_pages()}
    assert {"first-picture.md", "your-own-model.md", "scene-file.md"} <= pages
    for page in _tutorial_pages():
        blocks = _tutorial_blocks(page)
        assert any(lang == "python" and "not run" not in marks for lang, _, marks in blocks), page.name


def test_shell_blocks_parse():
    commands = _shell_commands("a && .venv/bin/frustum render x.toml -o y.png   # note\n"
                               "frustum render broken.toml\n# error: broken.toml:3: bad ...\n")
    assert commands == [(["a"], None), ([".venv/bin/frustum", "render", "x.toml", "-o", "y.png"], None),
                        (["frustum", "render", "broken.toml"], "broken.toml:3: bad")]
