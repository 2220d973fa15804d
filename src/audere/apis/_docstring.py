"""A small numpydoc parser: the summary, the sections, and each parameter's type and description.

Only what the registry needs: section headers are a title line underlined with dashes; in
``Parameters`` an entry starts at the section's indentation (``name``, ``name : type`` or
``a, b : type``) and its description is the indented block under it.
"""

from __future__ import annotations

import inspect
import re
import textwrap
from dataclasses import dataclass, field

__all__ = ["Docstring", "ParamDoc", "parse_docstring"]

_UNDERLINE = re.compile(r"^\s*-{3,}\s*$")


@dataclass(frozen=True)
class ParamDoc:
    """One documented parameter: its written type (may be empty) and its description."""

    name: str
    type: str
    description: str


@dataclass(frozen=True)
class Docstring:
    """A parsed numpydoc docstring."""

    summary: str
    """The text before the first section (short and extended summary), paragraphs kept."""
    sections: dict[str, str] = field(default_factory=dict)
    """Section title (as written, e.g. ``"Returns"``) -> its raw body, dedented."""
    params: dict[str, ParamDoc] = field(default_factory=dict)
    """Entries of the ``Parameters`` section, in order."""

    @property
    def short_summary(self) -> str:
        """The first paragraph of the summary, on one line."""
        return _one_line(self.summary.split("\n\n", 1)[0])


def _one_line(text: str) -> str:
    return " ".join(text.split())


def parse_docstring(doc: str | None) -> Docstring:
    """Parse a numpydoc docstring.

    Parameters
    ----------
    doc
        The raw docstring (``function.__doc__``); ``None`` gives an empty result.

    Returns
    -------
    Docstring
        Summary, sections and parameter entries. Descriptions are joined into single lines
        paragraph by paragraph (blank lines separate paragraphs).
    """
    if not doc:
        return Docstring(summary="")
    lines = inspect.cleandoc(doc).splitlines()
    headers = [
        i
        for i in range(len(lines) - 1)
        if lines[i].strip() and _UNDERLINE.match(lines[i + 1]) and not _UNDERLINE.match(lines[i])
    ]
    summary_end = headers[0] if headers else len(lines)
    summary = "\n".join(lines[:summary_end]).strip()
    sections: dict[str, str] = {}
    for n, start in enumerate(headers):
        end = headers[n + 1] if n + 1 < len(headers) else len(lines)
        body = textwrap.dedent("\n".join(lines[start + 2 : end])).strip("\n")
        sections[lines[start].strip()] = body
    params: dict[str, ParamDoc] = {}
    for title in ("Parameters", "Other Parameters"):
        if title in sections:
            params.update(_entries(sections[title]))
    return Docstring(summary=summary, sections=sections, params=params)


def _entries(body: str) -> dict[str, ParamDoc]:
    entries: dict[str, ParamDoc] = {}
    names: list[str] = []
    kind = ""
    description: list[str] = []

    def flush() -> None:
        paragraphs = "\n".join(description).strip().split("\n\n")
        text = "\n\n".join(_one_line(p) for p in paragraphs if p.strip())
        for name in names:
            entries[name] = ParamDoc(name=name, type=kind, description=text)

    for line in body.splitlines():
        if line and not line[0].isspace():
            flush()
            head, _, kind = line.partition(":")
            kind = kind.strip()
            names = [n.strip().lstrip("*") for n in head.split(",") if n.strip()]
            description = []
        else:
            description.append(line.strip())
    flush()
    return entries
