"""The README's quick start runs as written."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
from tests.doc_examples import DOCS, python_blocks

README = DOCS.parent / "README.md"
BLOCKS = python_blocks(README)


def test_the_readme_has_a_quick_start() -> None:
    assert len(BLOCKS) >= 2


@pytest.mark.skipif(sys.platform != "linux", reason="the agent's sandbox runs on Linux only")
@pytest.mark.parametrize("source", BLOCKS, ids=[f"block{i}" for i in range(len(BLOCKS))])
def test_quick_start_runs(source: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)  # the quick start writes a figure into the current directory
    exec(compile(source, str(README), "exec", dont_inherit=True), {"__name__": "readme"})
