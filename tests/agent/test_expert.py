"""The offline expert through the full agent loop: LiteLLM call, sandbox, checker, on every scenario.

Done means the expert solves every scenario's 20 test seeds in one round, calling the APIs it
selected (the sandbox records the calls).
"""

from __future__ import annotations

import sys

import pytest

pytestmark = pytest.mark.skipif(sys.platform != "linux", reason="the sandbox runs on Linux only")

from audere import recipes, scenarios  # noqa: E402
from audere.agent import Agent, ErrorCategory  # noqa: E402
from audere.agent._expert import EXPERT_LABEL, choose_recipe, recipe_code  # noqa: E402

SCENARIOS = [info.name for info in scenarios.list_scenarios()]
FAST_SEEDS = range(20)


@pytest.mark.parametrize("seed", FAST_SEEDS)
@pytest.mark.parametrize("name", SCENARIOS)
def test_expert_solves_in_one_round(name: str, seed: int) -> None:
    result = Agent(name, seed=seed).solve()
    assert result.status == "solved", str(result)
    assert result.categories == [ErrorCategory.SUCCESS]
    expected = list(recipes.get_recipe(name).apis)
    assert result.selected_apis == expected
    assert set(result.apis_called) <= set(expected)
    assert result.apis_called  # the code really called an API
    assert len(result.calls) == 2  # the selection and the code
    assert result.model_label == EXPERT_LABEL
    assert result.tool_calls


@pytest.mark.parametrize("name", ["track-lin", "plan-hard", "plan-stl"])
def test_expert_answers_in_plain_text_too(name: str) -> None:
    result = Agent(name, seed=21, tool_calls=False).solve()
    assert result.success, str(result)
    assert not result.tool_calls
    assert result.calls[0].tool_calls == []
    assert result.calls[0].response.startswith("APIs: ")


@pytest.mark.parametrize("name", SCENARIOS)
def test_expert_chooses_by_structure_not_by_name(name: str) -> None:
    task = scenarios.make(name, seed=0).model_copy(update={"name": ""})
    assert choose_recipe(task).scenario == name


@pytest.mark.parametrize("name", SCENARIOS)
def test_recipe_code_stands_alone(name: str) -> None:
    code = recipe_code(name)
    assert "audere.recipes" not in code
    assert "@recipe" not in code
    assert code.rstrip().endswith("(task)")
    compile(code, "<agent_code>", "exec")


def test_baselines_with_the_expert() -> None:
    """The expert's baselines are plain heuristics: they solve the easiest task only."""
    easy = Agent("track-lin", seed=0, method="predict").solve()
    assert easy.success, str(easy)
    code = Agent("track-lin", seed=0, method="code").solve()
    assert code.success, str(code)
    assert code.apis_called == []
    hard = Agent("plan-hard", seed=0, method="predict", max_rounds=2).solve()
    assert hard.status == "failed"
    assert hard.categories == [ErrorCategory.TASK_FAILURE, ErrorCategory.TASK_FAILURE]


def test_expert_cannot_read_free_text() -> None:
    result = Agent("Drive the robot from the left to the right side of the room.").solve()
    assert result.status == "invalid_task"
    assert "cannot read free text" in result.message
    assert len(result.calls) == 1
    assert result.rounds == []
