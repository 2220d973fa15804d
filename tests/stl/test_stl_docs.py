"""The examples in docs/stl.md run, and print what the page says they print."""

from __future__ import annotations

from pathlib import Path

import pytest
from tests.doc_examples import expected_output, python_blocks

DOC = Path(__file__).resolve().parents[2] / "docs" / "stl.md"
BLOCKS = python_blocks(DOC)


def test_the_page_has_examples() -> None:
    assert len(BLOCKS) >= 4


@pytest.mark.parametrize("source", BLOCKS, ids=[f"block{i}" for i in range(len(BLOCKS))])
def test_doc_example_runs_and_prints_what_it_says(source: str, capsys: pytest.CaptureFixture[str]) -> None:
    exec(compile(source, str(DOC), "exec", dont_inherit=True), {"__name__": "docs_stl"})
    printed = capsys.readouterr().out.splitlines()
    assert printed == expected_output(source, loops_print=False)
