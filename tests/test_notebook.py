"""The tutorial notebook runs top to bottom without errors (nbclient), and shows the pipeline's pictures."""

from __future__ import annotations

from pathlib import Path

import pytest

NOTEBOOK = Path(__file__).resolve().parents[1] / "notebooks" / "pipeline_tutorial.ipynb"


def test_pipeline_tutorial_notebook_executes() -> None:
    nbclient = pytest.importorskip("nbclient")
    nbformat = pytest.importorskip("nbformat")
    pytest.importorskip("ipykernel")
    notebook = nbformat.read(NOTEBOOK, as_version=4)
    client = nbclient.NotebookClient(
        notebook, timeout=300, kernel_name="python3", resources={"metadata": {"path": str(NOTEBOOK.parent)}}
    )
    client.execute()
    outputs = [output for cell in notebook.cells if cell.cell_type == "code" for output in cell.get("outputs", [])]
    assert not [output for output in outputs if output.get("output_type") == "error"]
    # the Frame cells display as PNG pictures, the trace as Markdown
    kinds = {key for output in outputs for key in output.get("data", {})}
    assert "image/png" in kinds
    assert "text/markdown" in kinds
    texts = [output.get("text", "") for output in outputs if output.get("output_type") == "stream"]
    assert any("trace and render agree: True" in text for text in texts)


def test_notebook_is_committed_without_outputs() -> None:
    nbformat = pytest.importorskip("nbformat")
    notebook = nbformat.read(NOTEBOOK, as_version=4)
    assert all(not cell.get("outputs") for cell in notebook.cells if cell.cell_type == "code")
