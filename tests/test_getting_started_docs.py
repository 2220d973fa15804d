"""The Python examples of docs/getting-started.md run and print what the page says."""

from __future__ import annotations

import sys

import pytest
from tests.doc_examples import DOCS, expected_output, python_blocks

pytestmark = pytest.mark.skipif(sys.platform != "linux", reason="the agent's sandbox runs on Linux only")

BLOCKS = python_blocks(DOCS / "getting-started.md")


@pytest.mark.parametrize("source", BLOCKS, ids=[f"block{i}" for i in range(len(BLOCKS))])
def test_example_runs(source: str, capsys: pytest.CaptureFixture[str]) -> None:
    exec(compile(source, "getting-started.md", "exec", dont_inherit=True), {"__name__": "docs_start"})
    assert capsys.readouterr().out.splitlines() == expected_output(source)
