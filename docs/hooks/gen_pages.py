"""MkDocs hook: the pages generated from the code at build time (``mkdocs.yml`` names it under ``hooks:``).

- ``reference/api/<group>.md``: every public name of ``frustum`` (``dir(frustum)``, ``__all__`` and the lazy
  names), grouped by the module that defines it, each rendered by mkdocstrings from its docstring. A public
  function or class without a docstring is logged as a warning, so ``mkdocs build --strict`` fails.
- ``reference/scene-file.md``: the scene-file format, from ``src/frustum/scene.schema.json``.
- ``reference/cli.md``: the command line, from the Typer app's ``--help`` of every command.
- ``tutorials/notebooks/<stem>.md``, ``lessons/<stem>.md``: the notebooks of ``notebooks/`` and ``docs/lessons/``.
- ``gallery.md``: every ``examples/*.toml`` with its picture ``docs/gallery/<name>.png`` (when one is there)
  and the scene file itself.

The Reference entries of the navigation are filled in here too (``on_config``), and the notebooks and any topic
page ``docs/*.md`` that ``mkdocs.yml`` does not list (under Explanation), so a name, command, schema key, example,
notebook or topic page added to the code shows up at the next build with no edit to ``mkdocs.yml``.
"""

from __future__ import annotations

import ast
import contextlib
import importlib
import inspect
import json
import logging
import pkgutil
import re
import sys
import types
from pathlib import Path

from mkdocs.structure.files import File

log = logging.getLogger("mkdocs.plugins.frustum_docs")

ROOT = Path(__file__).resolve().parents[2]
SRC = ROOT / "src"

# Titles of the API pages, by the first two components of the defining module (``frustum.<group>``); a group
# not listed here gets its module name as title, so new modules need no edit.
GROUP_TITLES = {
    "budgets": "Budgets", "errors": "Errors", "transforms": "Transformations", "quaternion": "Quaternions",
    "camera": "Cameras", "projection": "Projections", "clipping": "Clipping", "geometry": "Geometry",
    "shading": "Lights and materials", "scene": "Scenes", "frame": "Frames", "render": "Rendering",
    "output": "Output: SVG, sheets, stereo, animation", "batch": "Many views and datasets",
    "scenefile": "Scene files", "visibility": "Visibility", "bsp": "BSP trees and depth sort",
    "hidden_lines": "Hidden lines", "trace": "Tracing the pipeline", "simulation": "Simulation",
    "stereo": "Stereo", "viewer": "Viewer", "warmup": "Warm-up", "raster": "Kernels and threads",
    "radiosity": "Radiosity", "environment": "Environment maps",
}


def _frustum():
    if str(SRC) not in sys.path:
        sys.path.insert(0, str(SRC))
    return importlib.import_module("frustum")


def public_names(module: types.ModuleType) -> list[str]:
    """The public names of `module`: its ``__all__``, its lazy names and ``dir()``, without leading underscores,
    without what it merely imports from outside frustum (``sys``, ``typing.Any``, ``TYPE_CHECKING``)."""
    names = set(getattr(module, "__all__", ())) | set(dir(module))
    names |= set(getattr(module, "_LAZY", {}))
    out = []
    for name in sorted(names):
        if name.startswith("_") or name == "TYPE_CHECKING":
            continue
        try:
            obj = getattr(module, name)
        except ImportError:  # a lazy name whose extra is missing: still public
            out.append(name)
            continue
        if isinstance(obj, types.ModuleType) and not obj.__name__.startswith("frustum"):
            continue
        owner = getattr(obj, "__module__", None)
        if (inspect.isclass(obj) or inspect.isfunction(obj)) and owner and not owner.startswith("frustum"):
            continue
        if obj is getattr(module, "TYPE_CHECKING", None) or (
            not isinstance(obj, types.ModuleType) and getattr(obj, "__module__", "") == "typing"
        ):
            continue
        out.append(name)
    return out


def _defining_module(name: str, obj, fr) -> str:
    """The dotted module where `name` is defined (for constants: the frustum module assigning it)."""
    if isinstance(obj, types.ModuleType):
        return obj.__name__
    owner = getattr(obj, "__module__", None)
    if (inspect.isclass(obj) or inspect.isroutine(obj)) and owner and owner.startswith("frustum"):
        return owner
    lazy = getattr(fr, "_LAZY", {})
    if name in lazy:
        return lazy[name]
    for module_name, module in sorted(sys.modules.items()):
        if not module_name.startswith("frustum.") or getattr(module, "__file__", None) is None:
            continue
        if module.__dict__.get(name, _MISSING) is not obj:
            continue
        try:
            tree = ast.parse(Path(module.__file__).read_text(encoding="utf-8"))
        except (OSError, SyntaxError):  # pragma: no cover
            continue
        for node in tree.body:
            targets = []
            if isinstance(node, ast.Assign):
                targets = [t.id for t in node.targets if isinstance(t, ast.Name)]
            elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
                targets = [node.target.id]
            if name in targets:
                return module_name
    return "frustum"


_MISSING = object()


def _stub_module(fr: types.ModuleType, name: str) -> str:
    """The module that defines lazy name `name`, from the package's ``__init__.pyi`` stub (``from .x import (y as
    y)``), without importing it."""
    stub = Path(fr.__file__).with_suffix(".pyi").read_text(encoding="utf-8")
    for match in re.finditer(r"from \.([\w.]+) import \(([^)]*)\)", stub):
        if re.search(rf"\b{re.escape(name)} as {re.escape(name)}\b", match.group(2)):
            return f"frustum.{match.group(1)}"
    return getattr(fr, "_LAZY", {}).get(name, "frustum")


def api_entries() -> dict[str, list[tuple[str, str, str]]]:
    """{group: [(name, identifier for mkdocstrings, kind)]} for every public name of frustum."""
    fr = _frustum()
    groups: dict[str, list[tuple[str, str, str]]] = {}
    for name in getattr(fr, "_LAZY", {}):  # load the lazy names first: their modules become attributes too
        with contextlib.suppress(ImportError):
            getattr(fr, name)
    # every public top-level module, imported or not: which of them dir(frustum) lists depends on what ran before
    modules = {m.name for m in pkgutil.iter_modules(fr.__path__) if not m.name.startswith("_")}
    listed = set()
    for name in public_names(fr):
        listed.add(name)
        try:
            obj = getattr(fr, name)
        except ImportError:  # a lazy name whose extra is missing (Viewer without anywidget): read statically
            module = _stub_module(fr, name)
            groups.setdefault(module.split(".")[1], []).append((name, f"{module}.{name}", "lazy"))
            continue
        module = _defining_module(name, obj, fr)
        if isinstance(obj, types.ModuleType):
            kind, ident = "module", module
        elif inspect.isclass(obj) or inspect.isroutine(obj):
            kind = "class" if inspect.isclass(obj) else "function"
            ident = f"{obj.__module__}.{obj.__qualname__}"
        else:
            kind, ident = "constant", f"{module}.{name}"
        parts = module.split(".")
        group = parts[1] if len(parts) > 1 else "frustum"
        groups.setdefault(group, []).append((name, ident, kind))
        if kind in ("class", "function") and not inspect.getdoc(obj):
            log.warning("frustum.%s (%s) has no docstring: every public name needs one", name, ident)
    for name in sorted(modules - listed):
        groups.setdefault(name, []).append((name, f"frustum.{name}", "module"))
    for name in EXTRA_MODULES:  # documented whole on their own page
        groups.pop(name, None)
    for entries in groups.values():
        entries[:] = [e for e in entries if not (e[2] == "module" and e[0] in EXTRA_MODULES)]
    return {group: entries for group, entries in groups.items() if entries}


# Public subpackages whose names are used as ``frustum.<module>.<name>`` rather than re-exported: documented whole
# (module docstring and every public member) on a page of their own, when they exist.
EXTRA_MODULES = {"steps": "Step by step (frustum.steps)"}


def _module_page(module: str, title: str) -> str:
    return "\n".join([f"# {title}", "", "Generated at build time from the docstrings.", "", f"::: frustum.{module}",
                       "    options:", "      show_root_heading: true", "      show_submodules: true", ""])


def _api_page(group: str, entries: list[tuple[str, str, str]]) -> str:
    title = GROUP_TITLES.get(group, group)
    lines = [f"# {title}", ""]
    modules = [e for e in entries if e[2] == "module"]
    others = [e for e in entries if e[2] != "module"]
    lines.append(
        "Generated at build time from the docstrings. Every name here is importable from `frustum` "
        "(`import frustum as fr; fr.<name>`)."
    )
    lines.append("")
    for name, ident, _ in modules:
        lines += [f"## Module `frustum.{name}` {{ #frustum.{name} }}", "", f"::: {ident}",
                  "    options:", "      members: false", "      show_root_heading: false", ""]
    for name, ident, kind in others:
        lines += [f"::: {ident}", "    options:", "      show_root_heading: true",
                  "      show_root_full_path: false", f"      heading: \"{name}\"" if kind == "constant" else "", ""]
    return "\n".join(lines)


def _extra_modules() -> dict[str, str]:
    return {m: t for m, t in EXTRA_MODULES.items()
            if (SRC / "frustum" / m).is_dir() or (SRC / "frustum" / f"{m}.py").is_file()}


def _api_index(groups: dict[str, list[tuple[str, str, str]]]) -> str:
    lines = ["# API reference", "",
             "Every public name of `frustum`, from its docstring, by the module that defines it. "
             "Conventions (column vectors, radians, right-handed world) are in "
             "[Conventions](../../conventions.md).", "",
             "| name | kind | page |", "|---|---|---|"]
    rows = []
    for group, entries in groups.items():
        for name, _, kind in entries:
            rows.append((name.lower(), f"| `{name}` | {kind} | [{GROUP_TITLES.get(group, group)}]({group}.md) |"))
    lines += [row for _, row in sorted(rows)]
    return "\n".join(lines) + "\n"


# --- scene file ------------------------------------------------------------------------------------------------

def _type_of(node: dict) -> str:
    if "$ref" in node:
        target = node["$ref"].rsplit("/", 1)[-1]
        return f"[{target}](#def-{target})"
    if "enum" in node:
        return " \\| ".join(f"`{json.dumps(v)}`" for v in node["enum"])
    if "const" in node:
        return f"`{json.dumps(node['const'])}`"
    for key in ("oneOf", "anyOf"):
        if key in node:
            return " or ".join(_type_of(n) for n in node[key] if "required" not in n or len(n) > 1) or "object"
    kind = node.get("type", "any")
    if isinstance(kind, list):
        kind = " or ".join(kind)
    if kind == "array" and "items" in node:
        items = node["items"]
        inner = _type_of(items) if isinstance(items, dict) else "any"
        size = ""
        if "minItems" in node and node.get("minItems") == node.get("maxItems"):
            size = f" of {node['minItems']}"
        return f"array{size} of {inner}"
    bounds = []
    for key, sign in (("minimum", "≥"), ("exclusiveMinimum", ">"), ("maximum", "≤"), ("exclusiveMaximum", "<")):
        if key in node:
            bounds.append(f"{sign} {node[key]}")
    return kind + (f" ({', '.join(bounds)})" if bounds else "")


def _properties_table(node: dict) -> list[str]:
    props = node.get("properties")
    if not props:
        return []
    required = set(node.get("required", ()))
    lines = ["| key | type | required | description |", "|---|---|---|---|"]
    for key, sub in props.items():
        desc = " ".join(str(sub.get("description", "")).split()).replace("|", "\\|")
        lines.append(f"| `{key}` | {_type_of(sub)} | {'yes' if key in required else ''} | {desc} |")
    return [*lines, ""]


def scene_file_page() -> str:
    schema = json.loads((SRC / "frustum" / "scene.schema.json").read_text(encoding="utf-8"))
    lines = ["# Scene file format", "",
             "Generated at build time from `src/frustum/scene.schema.json` (the JSON Schema that editors can use "
             "for completion; the loader checks more than the schema, with `file:line` in every message). "
             "A tutorial: [A scene file from scratch](../tutorials/scene-file.md).", "",
             " ".join(str(schema.get("description", "")).split()), "",
             "## Top-level tables", ""]
    lines += _properties_table(schema)
    if "oneOf" in schema:
        alternatives = [", ".join(f"`{k}`" for k in alt.get("required", ())) for alt in schema["oneOf"]]
        lines += ["A file has exactly one of: " + "; ".join(alternatives) + ".", ""]
    for key, sub in schema.get("properties", {}).items():
        if sub.get("type") == "object" and sub.get("properties"):
            lines += [f"### `[{key}]`", ""]
            if sub.get("description"):
                lines += [" ".join(str(sub["description"]).split()), ""]
            lines += _properties_table(sub)
            for inner_key, inner in sub["properties"].items():
                if inner.get("type") == "object" and inner.get("properties"):
                    lines += [f"#### `[{key}.{inner_key}]`", "", *_properties_table(inner)]
    lines += ["## Definitions", ""]
    for name, sub in schema.get("$defs", {}).items():
        lines += [f"### {name} {{ #def-{name} }}", ""]
        if sub.get("description"):
            lines += [" ".join(str(sub["description"]).split()), ""]
        table = _properties_table(sub)
        lines += table or [f"Type: {_type_of(sub)}", ""]
    return "\n".join(lines) + "\n"


# --- command line ----------------------------------------------------------------------------------------------

def cli_page() -> str:
    import typer

    _frustum()
    from frustum.app.cli import app

    command = typer.main.get_command(app)
    lines = ["# Command line", "",
             "Generated at build time from the Typer app (`frustum.app.cli`): the `--help` of every command. "
             "Errors print one line and exit non-zero.", ""]

    from typer.testing import CliRunner

    runner = CliRunner()
    env = {"NO_COLOR": "1", "TERMINAL_WIDTH": "100", "COLUMNS": "100", "_TYPER_FORCE_DISABLE_TERMINAL": "1"}

    def walk(cmd, path: list[str]) -> None:
        result = runner.invoke(app, [*path[1:], "--help"], env=env, terminal_width=100)
        if result.exit_code != 0:  # pragma: no cover
            log.warning("`%s --help` failed: %s", " ".join(path), result.output)
        lines.extend([f"## `{' '.join(path)}`", "", "```text", result.output.rstrip(), "```", ""])
        if hasattr(cmd, "list_commands"):  # a group (Typer vendors its own click: no isinstance)
            ctx = cmd.context_class(cmd, info_name=path[-1])
            for sub_name in cmd.list_commands(ctx):
                walk(cmd.get_command(ctx, sub_name), [*path, sub_name])

    walk(command, ["frustum"])
    return "\n".join(lines) + "\n"


# --- gallery ---------------------------------------------------------------------------------------------------

def gallery_page(docs_dir: Path) -> str:
    lines = ["# Gallery", "",
             "Every scene file of `examples/`, generated at build time: the picture (`docs/gallery/<name>.png`) "
             "and the file that makes it. Render one with `frustum render examples/<name>.toml -o <name>.png`, "
             "all of them with `frustum examples`.", ""]
    for toml in sorted((ROOT / "examples").glob("*.toml")):
        name = toml.stem
        text = toml.read_text(encoding="utf-8")
        title = ""
        for line in text.splitlines():
            if line.strip().startswith("title"):
                title = line.split("=", 1)[1].strip().strip('"')
                break
        lines += [f"## {name}", ""]
        if title:
            lines += [title, ""]
        if (docs_dir / "gallery" / f"{name}.png").exists():
            lines += [f"![{name}](gallery/{name}.png)", ""]
        else:
            lines += [f"*No picture in `docs/gallery/` yet: `frustum render examples/{name}.toml -o "
                      f"docs/gallery/{name}.png` makes it.*", ""]
        lines += [f'??? example "examples/{name}.toml"', "", "    ```toml"]
        lines += [("        " + row) if row else "" for row in text.rstrip().splitlines()]
        lines += ["    ```", ""]
    return "\n".join(lines) + "\n"


# --- notebooks -----------------------------------------------------------------------------------------------

NOTEBOOK_FOLDERS = (("notebooks", "tutorials/notebooks"), ("docs/lessons", "lessons"))


def notebook_pages(source: str = "notebooks", target: str = "tutorials/notebooks") -> dict[str, tuple[str, str]]:
    """{page path: (title, Markdown)} for every notebook in `source` (relative to the repository): its Markdown
    cells as they are, its code cells as Python blocks (the notebooks are executed by the tests, not by the
    build). The page goes to `target`/<stem>.md (for ``docs/lessons`` beside the notebook, so its relative links
    hold)."""
    pages = {}
    for path in sorted((ROOT / source).glob("*.ipynb")):
        notebook = json.loads(path.read_text(encoding="utf-8"))
        chunks, title = [], path.stem.replace("_", " ")
        for cell in notebook.get("cells", []):
            source = "".join(cell.get("source", ""))
            if cell.get("cell_type") == "markdown":
                if not chunks and source.startswith("# "):
                    title = source.splitlines()[0][2:].strip()
                chunks.append(source)
            elif cell.get("cell_type") == "code" and source.strip():
                chunks.append("```python\n" + source.rstrip() + "\n```")
        note = (f"*From the notebook `{source}/{path.name}` (open it in Jupyter to run it; the tests execute "
                "it).*")
        text = "\n\n".join(chunks) + "\n"
        if text.startswith("# "):
            first, _, rest = text.partition("\n")
            text = first + "\n\n" + note + "\n" + rest
        else:
            text = f"# {title}\n\n{note}\n\n" + text
        pages[f"{target}/{path.stem}.md"] = (title, text)
    return pages


# --- hooks -----------------------------------------------------------------------------------------------------

_STATE: dict = {}


def _nav_files(nav) -> list[str]:
    out = []
    for item in nav:
        if isinstance(item, str):
            out.append(item)
        elif isinstance(item, dict):
            for value in item.values():
                out += _nav_files(value) if isinstance(value, list) else [value]
    return out


def on_config(config, **kwargs):
    groups = api_entries()
    _STATE["groups"] = groups
    api_nav = [{"Index": "reference/api/index.md"}]
    ordered = sorted(groups, key=lambda g: GROUP_TITLES.get(g, g))
    api_nav += [{GROUP_TITLES.get(g, g): f"reference/api/{g}.md"} for g in ordered]
    api_nav += [{title: f"reference/api/{m}.md"} for m, title in _extra_modules().items()]
    _STATE["notebooks"] = {source: notebook_pages(source, target) for source, target in NOTEBOOK_FOLDERS}
    listed = set(_nav_files(config["nav"] or []))
    for item in config["nav"] or []:
        if isinstance(item, dict) and "Explanation" in item:
            # a topic page added to docs/ (another engineer's feature) joins the Explanation part by itself
            for page in sorted(Path(config["docs_dir"]).glob("*.md")):
                if page.name not in listed and page.name != "index.md":
                    first = page.read_text(encoding="utf-8").splitlines()[:1] or [page.stem]
                    title = first[0].lstrip("# ").strip() or page.stem
                    item["Explanation"] = [*item["Explanation"], {title: page.name}]
        if isinstance(item, dict) and "Tutorials" in item:
            entries = list(item["Tutorials"])
            entries += [{title: page} for page, (title, _) in _STATE["notebooks"]["notebooks"].items()]
            lessons = [{title: page} for page, (title, _) in _STATE["notebooks"]["docs/lessons"].items()]
            if lessons:
                entries.append({"Lessons, step by step": lessons})
            item["Tutorials"] = entries
        if isinstance(item, dict) and "Reference" in item:
            item["Reference"] = [
                "reference/index.md",
                {"Python API": api_nav},
                {"Scene file format": "reference/scene-file.md"},
                {"Command line": "reference/cli.md"},
            ]
    return config


def on_files(files, config, **kwargs):
    docs_dir = Path(config["docs_dir"])
    groups = _STATE.get("groups") or api_entries()
    pages = {"reference/api/index.md": _api_index(groups),
             "reference/scene-file.md": scene_file_page(),
             "reference/cli.md": cli_page(),
             "gallery.md": gallery_page(docs_dir)}
    notebooks = _STATE.get("notebooks") or {src: notebook_pages(src, dst) for src, dst in NOTEBOOK_FOLDERS}
    for found in notebooks.values():
        for page, (_, text) in found.items():
            pages[page] = text
    for module, title in _extra_modules().items():
        pages[f"reference/api/{module}.md"] = _module_page(module, title)
    for group, entries in groups.items():
        pages[f"reference/api/{group}.md"] = _api_page(group, entries)
    for path, content in pages.items():
        existing = files.get_file_from_path(path)
        if existing is not None:
            files.remove(existing)
        files.append(File.generated(config, path, content=content))
    return files
