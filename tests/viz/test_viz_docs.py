"""The examples of docs/viz.md run in order (later blocks use names from earlier ones), writing files."""

from __future__ import annotations

from pathlib import Path

import pytest
from tests.doc_examples import DOCS, python_blocks

BLOCKS = python_blocks(DOCS / "viz.md")


def test_viz_page_examples_run(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    assert len(BLOCKS) >= 4
    monkeypatch.chdir(tmp_path)  # the examples save figures into the current directory
    namespace: dict[str, object] = {"__name__": "docs_viz"}
    for i, source in enumerate(BLOCKS):
        exec(compile(source, f"viz.md#block{i}", "exec", dont_inherit=True), namespace)
    written = sorted(p.name for p in tmp_path.glob("*.png"))
    assert "straight-line.png" in written
    assert "side-by-side.png" in written
