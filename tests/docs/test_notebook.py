"""The example notebook runs from top to bottom and renders as it should (issue 39)."""

from __future__ import annotations

import os

import pytest

from tests.conftest import ROOT

nbformat = pytest.importorskip("nbformat", reason="the docs extra: pip install -e '.[docs]'")
nbclient = pytest.importorskip("nbclient", reason="the docs extra: pip install -e '.[docs]'")
pytest.importorskip("ipykernel", reason="the docs extra: pip install -e '.[docs]'")

NOTEBOOK = ROOT / "docs" / "examples" / "first_cam.ipynb"


def test_the_example_notebook_runs_and_shows_the_cam(monkeypatch):
    monkeypatch.setenv("PYTHONPATH", str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    notebook = nbformat.read(NOTEBOOK, as_version=4)
    client = nbclient.NotebookClient(
        notebook, timeout=300, kernel_name="python3", resources={"metadata": {"path": str(NOTEBOOK.parent)}}
    )
    client.execute()  # raises CellExecutionError on any failing cell
    outputs = [o for cell in notebook.cells if cell.cell_type == "code" for o in cell.outputs]
    kinds = [set(o.get("data", {})) for o in outputs]
    assert sum({"text/html", "image/svg+xml"} <= k for k in kinds) == 2  # the Design and the Result
    assert sum("image/png" in k for k in kinds) == 2  # the two plots
    assert not [o for o in outputs if o.output_type == "error"]
    printed = "".join(o.get("text", "") for o in outputs if o.output_type == "stream")
    assert "limit 25.000°" in printed
