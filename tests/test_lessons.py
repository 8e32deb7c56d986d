"""The lessons (docs/lessons/, one notebook per chapter of the notes) run top to bottom without errors (nbclient)
and show the Steps sliders."""

from __future__ import annotations

from pathlib import Path

import pytest

LESSONS = sorted((Path(__file__).resolve().parents[1] / "docs" / "lessons").glob("*.ipynb"))


def test_there_is_a_lesson_per_chapter() -> None:
    assert {p.stem for p in LESSONS} == {"viewing", "clipping", "visible_surfaces", "curves", "fractals", "modeling"}


@pytest.mark.parametrize("path", LESSONS, ids=[p.stem for p in LESSONS])
def test_lesson_executes_and_shows_sliders(path: Path) -> None:
    nbclient = pytest.importorskip("nbclient")
    nbformat = pytest.importorskip("nbformat")
    pytest.importorskip("ipykernel")
    notebook = nbformat.read(path, as_version=4)
    assert all(not cell.get("outputs") for cell in notebook.cells if cell.cell_type == "code")  # committed clean
    client = nbclient.NotebookClient(
        notebook, timeout=300, kernel_name="python3", resources={"metadata": {"path": str(path.parent)}}
    )
    client.execute()
    outputs = [output for cell in notebook.cells if cell.cell_type == "code" for output in cell.get("outputs", [])]
    assert not [output for output in outputs if output.get("output_type") == "error"]
    pages = [output["data"]["text/html"] for output in outputs if "text/html" in output.get("data", {})]
    assert pages and all('type="range"' in page for page in pages)
    texts = "".join(output.get("text", "") for output in outputs
                    if output.get("output_type") == "stream" and output.get("name") == "stdout")  # fmt: skip
    assert "False" not in texts  # every printed check in the lessons is True (stderr: the compile notice)
