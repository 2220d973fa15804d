"""The examples in docs/scenarios.md run and print what the page says; the page covers every scenario."""

from __future__ import annotations

from pathlib import Path

import pytest
from tests.doc_examples import expected_output, python_blocks

from audere.scenarios import ScenarioInfo, list_scenarios

DOC = Path(__file__).resolve().parents[2] / "docs" / "scenarios.md"
TEXT = DOC.read_text(encoding="utf-8")
BLOCKS = python_blocks(DOC)


def test_the_page_has_examples() -> None:
    assert len(BLOCKS) >= 2


def test_doc_examples_run_and_print_what_they_say(capsys: pytest.CaptureFixture[str]) -> None:
    namespace: dict[str, object] = {"__name__": "docs_scenarios"}
    for i, source in enumerate(BLOCKS):  # later blocks use names from earlier ones, as a reader would
        exec(compile(source, f"{DOC}#block{i}", "exec", dont_inherit=True), namespace)
        printed = capsys.readouterr().out.splitlines()
        assert printed == expected_output(source), f"block {i}"


@pytest.mark.parametrize("info", list_scenarios(), ids=lambda s: s.name)
def test_every_scenario_has_a_section(info: ScenarioInfo) -> None:
    heading = f"### `{info.name}`" + (f" ({info.paper_label})" if info.paper_label else "")
    assert heading + "\n" in TEXT
