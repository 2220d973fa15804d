"""The Python examples in docs/tasks.md run and print what the page says they print."""

from __future__ import annotations

import os
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
DOC = ROOT / "docs" / "tasks.md"
BLOCKS = re.findall(r"```python\n(.*?)```", DOC.read_text(encoding="utf-8"), re.S)


def _expected_output(source: str) -> list[str]:
    """The comment lines right after a print() call (or after each other): the output shown."""
    out: list[str] = []
    showing = False
    for line in source.splitlines():
        if line.startswith("# ") and showing:
            out.append(line[2:])
        else:
            showing = "print(" in line
    return out


def test_the_page_has_examples() -> None:
    assert len(BLOCKS) >= 4


@pytest.mark.parametrize("source", BLOCKS, ids=[f"block{i}" for i in range(len(BLOCKS))])
def test_doc_example_prints_what_it_says(
    source: str, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(ROOT)  # the examples load tests/tasks/data/*.yaml by relative path
    assert os.getcwd() == str(ROOT)
    exec(compile(source, str(DOC), "exec", dont_inherit=True), {"__name__": "docs_tasks"})
    assert capsys.readouterr().out.splitlines() == _expected_output(source)
