"""The code examples in docs/apis/index.md, docs/apis/register.md and docs/apis/pid.md run."""

from __future__ import annotations

import re
from collections.abc import Iterator
from pathlib import Path

import pytest

from audere.apis import _registry

DOCS = Path(__file__).resolve().parents[2] / "docs" / "apis"
PAGES = ["index.md", "register.md", "pid.md"]
BLOCKS = [
    (page, i, block)
    for page in PAGES
    for i, block in enumerate(
        re.findall(r"```python\n(.*?)```", (DOCS / page).read_text(encoding="utf-8"), re.S)
    )
]


@pytest.fixture
def isolated_registry() -> Iterator[None]:
    """APIs registered by a doc example are removed afterwards."""
    _registry.list_apis()  # built-ins loaded first, so restoring keeps them
    saved = dict(_registry._REGISTRY)
    try:
        yield
    finally:
        _registry._REGISTRY.clear()
        _registry._REGISTRY.update(saved)


def test_every_page_has_examples() -> None:
    assert {page for page, _, _ in BLOCKS} == set(PAGES)


@pytest.mark.parametrize(("page", "index", "source"), BLOCKS, ids=[f"{p}-{i}" for p, i, _ in BLOCKS])
def test_doc_example_runs(isolated_registry: None, page: str, index: int, source: str) -> None:
    namespace: dict[str, object] = {"__name__": f"docs_apis_{page[:-3]}_{index}"}
    exec(compile(source, str(DOCS / page), "exec", dont_inherit=True), namespace)


def test_index_table_matches_the_registry() -> None:
    text = (DOCS / "index.md").read_text(encoding="utf-8")
    rows = re.findall(r"^\| \[`(\w+)`\]\(\w+\.md\) \| .*? \| (.*?) \| (.*?) \|$", text, re.M)
    table = {name: tuple(t.strip() for t in tags.split(",")) for name, tags, _ in rows}
    assert sorted(table) == sorted(m.rsplit("._", 1)[1] for m in _registry._BUILTIN_MODULES)
    from audere.apis import list_apis

    for info in list_apis():
        if info.name in table:
            assert table[info.name] == info.tags, info.name


def test_index_table_natural_scenarios_match_the_scenarios() -> None:
    from audere.scenarios import list_scenarios

    text = (DOCS / "index.md").read_text(encoding="utf-8")
    rows = re.findall(r"^\| \[`(\w+)`\]\(\w+\.md\) \| .*? \| .*? \| (.*?) \|$", text, re.M)
    listed = {name: {s.strip() for s in scenarios.split(",")} for name, scenarios in rows}
    expected: dict[str, set[str]] = {name: set() for name in listed}
    for scenario in list_scenarios():
        for api in scenario.natural_apis:
            expected[api].add(scenario.name)
    assert listed == expected
