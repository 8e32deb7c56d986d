"""DXF sheets (``drawing_sheet(..., path="*.dxf")``, ``output/sheet/dxf.py``) read back by ezdxf.

Oracles: ``ezdxf.readfile`` and ``doc.audit()``; the SVG sheet of the same scene (entity counts per layer); the
model's radii and part extents; ezdxf's own drawing add-on (matplotlib backend) rendering the DXF, compared
pixel by pixel with cairosvg's rendering of the SVG's lines.
"""

from __future__ import annotations

import io
import re
import xml.etree.ElementTree as ET
from collections import Counter
from pathlib import Path

import cairosvg
import numpy as np
import pytest
from PIL import Image
from scipy import ndimage

from frustum import Scene, rotate_x, translate
from frustum.geometry import box, cylinder
from frustum.output.sheet import drawing_sheet
from frustum.scenefile import load_scene_file
from sheet_scenes import plate

ezdxf = pytest.importorskip("ezdxf")

SVG = "{http://www.w3.org/2000/svg}"
NUMBER = re.compile(r"-?\d+(?:\.\d+)?(?:e-?\d+)?")
EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def _scene() -> Scene:
    scene = plate()
    scene.add(cylinder(6.0, 10.0, 40), transform=translate(0.0, -8.0, 0.0) @ rotate_x(0.6))  # ellipses
    return scene


def _sheet(tmp_path: Path, scene: Scene, **options) -> tuple[ET.Element, object, str]:
    path = tmp_path / "sheet.dxf"
    text = drawing_sheet(scene, path=path, **options)
    return ET.fromstring(text.encode()), ezdxf.readfile(path), text


def _svg_counts(root: ET.Element) -> Counter:
    counts: Counter = Counter()
    for group in root.iter(f"{SVG}g"):
        name, kind = group.get("id", ""), group.get("class")
        if name.startswith("view-") or name.startswith("title-block") or name == "scale-bar":
            continue
        paths = [p for p in group.findall(f"{SVG}path")]
        if name.endswith("-visible") or name.endswith("-hidden") or kind == "centre":
            layer = "VISIBLE" if name.endswith("-visible") else "HIDDEN" if name.endswith("-hidden") else "CENTER"
            counts[("LINE", layer)] += sum(len(NUMBER.findall(p.get("d"))) // 4 for p in paths)
        elif name.endswith("-curves"):
            layer = "VISIBLE" if "-visible" in name else "HIDDEN"
            counts[("CURVE", layer)] += len(group.findall(f"{SVG}circle")) + len(group.findall(f"{SVG}ellipse"))
            counts[("CURVE", layer)] += len(paths)
        elif kind in ("dimension", "diameter"):
            counts[("DIMENSION", "DIMENSIONS")] += 1
    title = next(g for g in root.iter(f"{SVG}g") if g.get("id") == "title-block")
    labels = [g for g in root.iter(f"{SVG}g") if g.get("class") == "label"]
    bar = next(g for g in root.iter(f"{SVG}g") if g.get("id") == "scale-bar")
    counts[("TEXT", "TITLE")] = sum(len(list(g.iter(f"{SVG}text"))) for g in (title, bar, *labels))
    counts[("CIRCLE", "TITLE")] = len(list(title.iter(f"{SVG}circle")))
    return counts


def _dxf_counts(document) -> Counter:
    counts: Counter = Counter()
    for entity in document.modelspace():
        kind = entity.dxftype()
        if kind in ("CIRCLE", "ARC", "ELLIPSE") and entity.dxf.layer in ("VISIBLE", "HIDDEN"):
            kind = "CURVE"
        counts[(kind, entity.dxf.layer)] += 1
    return counts


@pytest.mark.parametrize("angle", ["third", "first"])
def test_dxf_reads_back_audits_clean_and_matches_the_svg(tmp_path, angle):
    root, document, _ = _sheet(tmp_path, _scene(), projection_angle=angle, title="Plate")
    auditor = document.audit()
    assert not auditor.has_errors and len(auditor.errors) == 0
    assert document.header["$INSUNITS"] == 4 and document.units == 4
    assert {"VISIBLE", "HIDDEN", "CENTER", "DIMENSIONS", "TITLE"} <= {layer.dxf.name for layer in document.layers}
    assert document.layers.get("HIDDEN").dxf.linetype == "DASHED"
    svg, dxf = _svg_counts(root), _dxf_counts(document)
    for key in svg:
        assert dxf[key] == svg[key], key
    for key in (("LINE", "VISIBLE"), ("LINE", "HIDDEN"), ("LINE", "CENTER"), ("CURVE", "VISIBLE"),
                ("CURVE", "HIDDEN"), ("DIMENSION", "DIMENSIONS"), ("TEXT", "TITLE"), ("CIRCLE", "TITLE")):  # fmt: skip
        assert svg[key] > 0, key
    kinds = Counter(e.dxftype() for e in document.modelspace() if e.dxf.layer == "VISIBLE")
    assert kinds["CIRCLE"] >= 2 and kinds["ELLIPSE"] >= 1


def test_dxf_radii_and_dimensions_are_model_values(tmp_path):
    scene = _scene()
    _, document, _ = _sheet(tmp_path, scene, views=("front", "top", "right"))
    radii = sorted({round(e.dxf.radius, 9) for e in document.modelspace().query("CIRCLE[layer=='VISIBLE']")})
    # the post (r 8), the ball (r 5), the tilted cylinder's rims seen end-on in no view: 8 and 5 only
    assert radii == pytest.approx([5.0, 8.0], abs=1e-9)
    for ellipse in document.modelspace().query("ELLIPSE"):
        major = np.linalg.norm(np.asarray(ellipse.dxf.major_axis))
        assert major == pytest.approx(6.0, abs=1e-9)  # the tilted cylinder: major axis = its radius
    extents = {
        round(float(v), 9)
        for item in scene.items
        for v in np.ptp(item.mesh.vertices @ item.world_from_model[:3, :3].T + item.world_from_model[:3, 3], axis=0)
    }
    dimensions = list(document.modelspace().query("DIMENSION"))
    assert dimensions
    for dimension in dimensions:
        measured = dimension.get_measurement()
        if dimension.dimtype == 3:  # diameter
            assert any(abs(measured - 2 * r) <= 1e-9 for r in (8.0, 5.0, 6.0)), measured
        else:
            assert any(abs(measured - e) <= 1e-9 for e in extents), measured


def _render_dxf(document, width_mm: float, height_mm: float, scale: float, pixels: int) -> np.ndarray:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from ezdxf.addons.drawing import Frontend, RenderContext
    from ezdxf.addons.drawing.config import BackgroundPolicy, ColorPolicy, Configuration
    from ezdxf.addons.drawing.matplotlib import MatplotlibBackend

    dpi = 100
    figure = plt.figure(figsize=(pixels / dpi, pixels * height_mm / width_mm / dpi), dpi=dpi)
    axes = figure.add_axes((0, 0, 1, 1))
    config = Configuration(background_policy=BackgroundPolicy.WHITE, color_policy=ColorPolicy.BLACK)
    Frontend(RenderContext(document), MatplotlibBackend(axes), config=config).draw_layout(
        document.modelspace(), finalize=False
    )
    axes.set_xlim(0, width_mm / scale)
    axes.set_ylim(0, height_mm / scale)
    axes.set_axis_off()
    buffer = io.BytesIO()
    figure.savefig(buffer, dpi=dpi, facecolor="white")
    plt.close(figure)
    return np.asarray(Image.open(buffer).convert("L"))


@pytest.mark.parametrize("source", ["exploded", "plate"])
def test_dxf_rendered_by_ezdxf_overlaps_the_svg_lines(tmp_path, source):
    scene = load_scene_file(EXAMPLES / "exploded_assembly.toml").scene if source == "exploded" else _scene()
    root, document, text = _sheet(tmp_path, scene)
    width, height = (float(root.get(k).removesuffix("mm")) for k in ("width", "height"))
    scale = float(next(g for g in root.iter(f"{SVG}g") if g.get("id") == "view-front").get("data-scale"))
    pixels = 1680  # 4 px per paper mm on A3
    ours = _render_dxf(document, width, height, scale, pixels) < 128
    # the SVG's lines (its text left out: the fonts differ)
    lines_only = re.sub(r"<text [^>]*>[^<]*</text>", "", text)
    picture = Image.open(io.BytesIO(cairosvg.svg2png(bytestring=lines_only.encode(), output_width=pixels)))
    white = Image.new("RGBA", picture.size, (255, 255, 255, 255))
    svg = np.asarray(Image.alpha_composite(white, picture.convert("RGBA")).convert("L"))

    assert svg.shape == ours.shape
    line_pixels = svg < 128
    near = ndimage.binary_dilation(ours, structure=np.ones((5, 5), bool))  # within 2 px
    share = float((near & line_pixels).sum() / line_pixels.sum())
    print(f"{source}: {share:.4f} of {int(line_pixels.sum())} SVG line pixels within 2 px of the DXF's")
    assert line_pixels.sum() > 5000 and share >= 0.97, share


def test_dxf_without_ezdxf_names_the_extra(tmp_path, monkeypatch):
    import builtins

    from frustum import OutputError

    real_import = builtins.__import__

    def no_ezdxf(name, *args, **kwargs):
        if name == "ezdxf" or name.startswith("ezdxf."):
            raise ImportError(name)
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_ezdxf)
    scene = Scene()
    scene.add(box((10.0, 10.0, 10.0)))
    with pytest.raises(OutputError, match=r"needs the ezdxf package, the 'dxf' extra: pip install 'frustum\[dxf\]'"):
        drawing_sheet(scene, path=tmp_path / "a.dxf")
    assert not (tmp_path / "a.dxf").exists()


def test_dxf_is_deterministic(tmp_path):
    scene = _scene()
    first, second = tmp_path / "a.dxf", tmp_path / "b.dxf"
    drawing_sheet(scene, path=first)
    drawing_sheet(scene, path=second)
    assert first.read_bytes() == second.read_bytes()


def test_view_command_writes_dxf_and_reads_the_sheet_table(tmp_path):
    from frustum.app.cli import main

    dxf, svg = tmp_path / "sheet.dxf", tmp_path / "sheet.svg"
    arguments = ["view", str(EXAMPLES / "exploded_assembly.toml")]
    main([*arguments, "-o", str(dxf), "--date", "2026-12-02"])
    document = ezdxf.readfile(dxf)
    texts = {e.dxf.text for e in document.modelspace().query("TEXT")}
    # the file's [sheet] table (drawing number, author) and the command line's date
    assert {"FR-EX-0001", "frustum examples", "2026-12-02", "Exploded assembly"} <= texts
    assert len(document.modelspace().query("DIMENSION")) > 0
    main([*arguments, "-o", str(svg), "--author", "someone else", "--angle", "first"])
    root = ET.fromstring(svg.read_bytes())
    block = next(g for g in root.iter(f"{SVG}g") if g.get("id") == "title-block")
    assert block.get("data-author") == "someone else" and block.get("data-projection") == "first"


def test_dxf_dimension_texts_read_as_the_svg_ones(tmp_path):
    root, document, _ = _sheet(tmp_path, load_scene_file(EXAMPLES / "exploded_assembly.toml").scene)
    svg = sorted(
        g.find(f"{SVG}text").text for g in root.iter(f"{SVG}g") if g.get("class") in ("dimension", "diameter", "radius")
    )
    dxf = []
    for dimension in document.modelspace().query("DIMENSION"):
        block = dimension.get_geometry_block()
        (text,) = [e.dxf.text if e.dxftype() == "TEXT" else e.text for e in block if e.dxftype() in ("TEXT", "MTEXT")]
        dxf.append(text.replace("%%c", "⌀"))
    assert sorted(dxf) == svg
