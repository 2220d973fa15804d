"""The examples in docs/agent.md run, and print what the page says they print."""

from __future__ import annotations

import sys

import pytest
from tests.doc_examples import DOCS, expected_output, python_blocks

pytestmark = pytest.mark.skipif(sys.platform != "linux", reason="the sandbox runs on Linux only")

DOC = DOCS / "agent.md"
BLOCKS = python_blocks(DOC)


def test_the_page_has_examples() -> None:
    assert len(BLOCKS) >= 3


@pytest.mark.parametrize("source", BLOCKS, ids=[f"block{i}" for i in range(len(BLOCKS))])
def test_doc_example_runs_and_prints_what_it_says(source: str, capsys: pytest.CaptureFixture[str]) -> None:
    exec(compile(source, str(DOC), "exec", dont_inherit=True), {"__name__": "docs_agent"})
    assert capsys.readouterr().out.splitlines() == expected_output(source)
