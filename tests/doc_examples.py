"""Helpers for the tests that run the Python examples of a docs page and compare what they print.

A page shows the output of a ``print(...)`` line as the ``# `` comment lines right after it.
"""

from __future__ import annotations

import re
from pathlib import Path

DOCS = Path(__file__).resolve().parents[1] / "docs"


def python_blocks(page: Path) -> list[str]:
    """The sources of the ```` ```python ```` blocks of a Markdown page, in order."""
    return re.findall(r"```python\n(.*?)```", page.read_text(encoding="utf-8"), re.S)


def expected_output(source: str, *, loops_print: bool = True) -> list[str]:
    """The comment lines that directly follow a ``print(`` line (or each other): the output shown.

    With ``loops_print=False``, a ``for ...: print(...)`` one-liner shows no output (its comments
    describe the loop instead).
    """
    out: list[str] = []
    showing = False
    for line in source.splitlines():
        if line.startswith("# ") and showing:
            out.append(line[2:])
        else:
            showing = "print(" in line and (loops_print or not line.lstrip().startswith("for "))
    return out
