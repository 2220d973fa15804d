"""The examples in docs/stl.md run, and print what the page says they print."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

DOC = Path(__file__).resolve().parents[2] / "docs" / "stl.md"
BLOCKS = re.findall(r"```python\n(.*?)```", DOC.read_text(encoding="utf-8"), re.S)


def _expected_output(source: str) -> list[str]:
    """The comment lines that directly follow a print() call (or each other): the shown output."""
    out: list[str] = []
    showing = False
    for line in source.splitlines():
        if line.startswith("# ") and showing:
            out.append(line[2:])
        else:
            showing = "print(" in line
            if showing and line.lstrip().startswith("for "):
                showing = False
    return out


def test_the_page_has_examples() -> None:
    assert len(BLOCKS) >= 4


@pytest.mark.parametrize("source", BLOCKS, ids=[f"block{i}" for i in range(len(BLOCKS))])
def test_doc_example_runs_and_prints_what_it_says(source: str, capsys: pytest.CaptureFixture[str]) -> None:
    exec(compile(source, str(DOC), "exec", dont_inherit=True), {"__name__": "docs_stl"})
    printed = capsys.readouterr().out.splitlines()
    assert printed == _expected_output(source)
