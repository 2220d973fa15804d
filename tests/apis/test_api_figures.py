"""Every API page shows its figure (made by examples/api_figures.py), and the figure exists."""

from __future__ import annotations

from pathlib import Path

import pytest

from audere.apis import list_apis

DOCS = Path(__file__).resolve().parents[2] / "docs"


@pytest.mark.parametrize("name", [info.name for info in list_apis()])
def test_api_page_has_its_figure(name: str) -> None:
    page = (DOCS / "apis" / f"{name}.md").read_text(encoding="utf-8")
    assert f"](../images/api-{name}.png)" in page
    assert (DOCS / "images" / f"api-{name}.png").stat().st_size > 10_000
