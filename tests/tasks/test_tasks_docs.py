"""The Python examples in docs/tasks.md run and print what the page says they print."""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from tests.doc_examples import expected_output, python_blocks

ROOT = Path(__file__).resolve().parents[2]
DOC = ROOT / "docs" / "tasks.md"
BLOCKS = python_blocks(DOC)


def test_the_page_has_examples() -> None:
    assert len(BLOCKS) >= 4


@pytest.mark.parametrize("source", BLOCKS, ids=[f"block{i}" for i in range(len(BLOCKS))])
def test_doc_example_prints_what_it_says(
    source: str, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(ROOT)  # the examples load tests/tasks/data/*.yaml by relative path
    assert os.getcwd() == str(ROOT)
    exec(compile(source, str(DOC), "exec", dont_inherit=True), {"__name__": "docs_tasks"})
    assert capsys.readouterr().out.splitlines() == expected_output(source)
