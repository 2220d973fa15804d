"""The example notebook runs end to end (offline models only) and renders its results."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.skipif(sys.platform != "linux", reason="the agent's sandbox runs on Linux only")

NOTEBOOK = Path(__file__).resolve().parents[1] / "examples" / "agent.ipynb"


def test_notebook_runs(tmp_path: Path) -> None:
    nbformat = pytest.importorskip("nbformat")
    nbclient = pytest.importorskip("nbclient")
    notebook = nbformat.read(NOTEBOOK, as_version=4)
    client = nbclient.NotebookClient(
        notebook, timeout=300, kernel_name="python3", resources={"metadata": {"path": str(tmp_path)}}
    )
    client.execute()
    outputs = [o for cell in notebook.cells if cell.cell_type == "code" for o in cell.get("outputs", [])]
    assert not [o for o in outputs if o.get("output_type") == "error"]
    pages = [o["data"]["text/html"] for o in outputs if "text/html" in o.get("data", {})]
    assert len(pages) == 2  # the free-text solve and the expert's solve, rendered
    assert all("data:image/png;base64," in page for page in pages)
    assert all("solved" in page for page in pages)
    assert (tmp_path / "notebook.cassette.json").exists()
