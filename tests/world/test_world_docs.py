"""The examples in docs/world.md run, and print what the page says they print."""

from __future__ import annotations

from pathlib import Path

import pytest
from tests.doc_examples import expected_output, python_blocks

DOC = Path(__file__).resolve().parents[2] / "docs" / "world.md"
BLOCKS = python_blocks(DOC)


def test_the_page_has_examples() -> None:
    assert len(BLOCKS) >= 4


def test_doc_examples_run_and_print_what_they_say(capsys: pytest.CaptureFixture[str]) -> None:
    namespace: dict[str, object] = {"__name__": "docs_world"}
    for i, source in enumerate(BLOCKS):  # later blocks use names from earlier ones, as a reader would
        exec(compile(source, f"{DOC}#block{i}", "exec", dont_inherit=True), namespace)
        printed = capsys.readouterr().out.splitlines()
        assert printed == expected_output(source), f"block {i}"
