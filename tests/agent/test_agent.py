"""The agent loop end to end with scripted models: real LiteLLM calls, the real sandbox, the real checker.

Each scripted model makes specific mistakes, so that every error category is produced and then
recovered from: a syntax error fixed in round 2, a collision fixed in round 3, a timeout, a
malformed tool call, a provider error.
"""

from __future__ import annotations

import asyncio
import itertools
import json
import sys
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

pytestmark = pytest.mark.skipif(sys.platform != "linux", reason="the sandbox runs on Linux only")

from audere import scenarios  # noqa: E402
from audere.agent import (  # noqa: E402
    Agent,
    ErrorCategory,
    Event,
    OfflineReply,
    ProviderError,
    ScriptedModel,
    SolveResult,
)
from audere.agent._expert import recipe_code  # noqa: E402
from audere.errors import InvalidArgumentError  # noqa: E402

_names = (f"scripted-{i}" for i in itertools.count())

RRT_CODE = recipe_code("plan-easy")
STRAIGHT_LINE = """\
import numpy as np
from audere.tasks import Solution

def solve(task):
    return Solution(waypoints=np.array([task.x0, task.goal]))
"""
INDEX_ERROR = """\
import numpy as np

def solve(task):
    points = [task.x0]
    return points[3]
"""


def text(content: str) -> OfflineReply:
    return OfflineReply(content=content)


def code_reply(code: str, plan: str = "Plan: call rrt on the task's world.") -> OfflineReply:
    return OfflineReply(content=f"{plan}\n\n```python\n{code}```\n")


def tool(name: str, **arguments: object) -> OfflineReply:
    return OfflineReply(tool_calls=((name, json.dumps(arguments)),))


@pytest.fixture
def scripted() -> Iterator[list[ScriptedModel]]:
    made: list[ScriptedModel] = []
    yield made
    for model in made:
        model.unregister()


def script(made: list[ScriptedModel], *replies: object) -> ScriptedModel:
    model = ScriptedModel(next(_names), list(replies))  # type: ignore[arg-type]
    made.append(model)
    return model


def test_syntax_error_fixed_in_round_2(scripted: list[ScriptedModel]) -> None:
    model = script(
        scripted,
        text("APIs: rrt\nA sampling planner fits a point path among obstacles."),
        code_reply("def solve(task)\n    return None\n"),
        code_reply(RRT_CODE),
    )
    result = Agent("plan-easy", seed=2, model=model.model, tool_calls=False).solve()
    assert result.success, result
    assert result.categories == [ErrorCategory.SYNTAX, ErrorCategory.SUCCESS]
    first = result.rounds[0]
    assert "SyntaxError at line 1" in first.feedback
    assert first.execution is None  # a syntax error never reaches the sandbox
    assert result.rounds_to_success == 2
    assert len(result.calls) == 3  # the selection call counts
    assert result.selected_apis == ["rrt"]
    assert result.apis_called == ["rrt"]
    # the feedback went back to the model, in the prompt of round 2
    revise = model.requests[2].messages[-1]["content"]
    assert "# Round 2 of 6" in revise
    assert "SyntaxError at line 1" in revise


def test_collision_fixed_in_round_3(scripted: list[ScriptedModel]) -> None:
    model = script(
        scripted,
        text("APIs: rrt"),
        code_reply(STRAIGHT_LINE, plan="Plan: a straight line."),
        code_reply(INDEX_ERROR),
        code_reply(RRT_CODE),
    )
    result = Agent("plan-easy", seed=3, model=model.model, tool_calls=False).solve()
    assert result.categories == [ErrorCategory.TASK_FAILURE, ErrorCategory.RUNTIME, ErrorCategory.SUCCESS]
    failure, crash, _ = result.rounds
    assert failure.report is not None
    assert not failure.report.success
    assert "collision" in failure.feedback
    assert failure.apis_called == []  # the straight line called no API
    assert "IndexError" in crash.feedback
    assert 'File "<agent_code>", line 5' in crash.feedback
    assert result.apis_called == ["rrt"]
    assert result.report is not None
    assert result.report.success


def test_timeout_then_fixed(scripted: list[ScriptedModel]) -> None:
    model = script(
        scripted,
        text("APIs: rrt"),
        code_reply("def solve(task):\n    while True:\n        pass\n"),
        code_reply(RRT_CODE),
    )
    result = Agent("plan-easy", seed=4, model=model.model, tool_calls=False, timeout_s=1.0).solve()
    assert result.categories == [ErrorCategory.TIMEOUT, ErrorCategory.SUCCESS]
    assert "timed out after 1 s" in result.rounds[0].feedback


def test_malformed_tool_call_then_fixed(scripted: list[ScriptedModel]) -> None:
    model = script(
        scripted,
        tool("select_apis", apis=["rrt"], reason="point path"),
        OfflineReply(tool_calls=(("submit_code", '{"code": "def solve(task):'),)),  # truncated JSON
        tool("submit_code", plan="rrt on the world", code=RRT_CODE),
    )
    result = Agent("plan-easy", seed=5, model=model.model, tool_calls=True).solve()
    assert result.categories == [ErrorCategory.PARSING, ErrorCategory.SUCCESS]
    assert "not valid JSON" in result.rounds[0].feedback
    # the feedback answered the failed tool call (OpenAI message rules), and the tools were offered
    request = model.requests[2]
    assert request.messages[-1]["role"] == "tool"
    assert {t["function"]["name"] for t in request.tools or ()} == {"submit_code", "select_apis"}


def test_provider_error_is_kept_apart(scripted: list[ScriptedModel]) -> None:
    model = script(scripted, text("APIs: rrt"), ProviderError("auth", "invalid API key"))
    result = Agent("plan-easy", seed=6, model=model.model, tool_calls=False).solve()
    assert result.status == "model_error"
    assert not result.success
    assert result.categories == [ErrorCategory.MODEL_ERROR]
    assert result.rounds[0].category.is_infrastructure
    assert "invalid API key" in result.message
    assert result.calls[-1].error is not None


def test_rate_limit_is_retried(scripted: list[ScriptedModel]) -> None:
    model = script(scripted, ProviderError("rate_limit"), text("APIs: rrt"), code_reply(RRT_CODE))
    agent = Agent("plan-easy", seed=7, model=model.model, tool_calls=False)
    agent._client.sleep = lambda seconds: None  # no real backoff in tests
    result = agent.solve()
    assert result.success
    assert result.calls[0].attempts == 2


def test_no_code_is_a_parsing_error_and_apis_can_change(scripted: list[ScriptedModel]) -> None:
    model = script(
        scripted,
        text("I would use a planner."),  # no APIs line
        text("APIs: astar"),
        text("Here is my thinking, but no code."),
        text("APIs: rrt"),  # a new choice in the revision: its documentation comes next, same round
        code_reply(RRT_CODE),
    )
    result = Agent("plan-easy", seed=8, model=model.model, tool_calls=False).solve()
    assert result.categories == [ErrorCategory.PARSING, ErrorCategory.PARSING, ErrorCategory.SUCCESS]
    assert "selects no APIs" in result.rounds[0].feedback
    assert "no fenced ```python block" in result.rounds[1].feedback
    assert result.rounds[1].selected_apis == ["astar"]
    assert result.rounds[2].selected_apis == ["rrt"]
    assert len(result.rounds[2].calls) == 2
    assert "# rrt:" in model.requests[4].messages[-1]["content"]  # the card of the new choice


def test_unknown_api_is_a_parsing_error(scripted: list[ScriptedModel]) -> None:
    model = script(scripted, text("APIs: dijkstra"), text("APIs: rrt"), code_reply(RRT_CODE))
    result = Agent("plan-easy", seed=9, model=model.model, tool_calls=False).solve()
    assert result.categories == [ErrorCategory.PARSING, ErrorCategory.SUCCESS]
    assert "unknown API(s) ['dijkstra']" in result.rounds[0].feedback


def test_wrong_shape_is_a_task_failure_with_the_checkers_words(scripted: list[ScriptedModel]) -> None:
    bad = "import numpy as np\nfrom audere.tasks import Solution\n\ndef solve(task):\n"
    bad += "    return Solution(waypoints=np.zeros((4, 3)))\n"
    model = script(
        scripted, text("APIs: rrt"), code_reply(bad), code_reply("def solve(task):\n    return 3\n")
    )
    result = Agent("plan-easy", seed=10, model=model.model, tool_calls=False, max_rounds=2).solve()
    assert result.status == "failed"
    assert result.categories == [ErrorCategory.TASK_FAILURE, ErrorCategory.TASK_FAILURE]
    assert "(4, 3)" in result.rounds[0].feedback
    assert "not solved in 2 round(s)" in result.message


def test_missing_entry_point_is_a_syntax_error(scripted: list[ScriptedModel]) -> None:
    model = script(scripted, text("APIs: rrt"), code_reply("x = 1\n"))
    result = Agent("plan-easy", seed=11, model=model.model, tool_calls=False, max_rounds=1).solve()
    assert result.categories == [ErrorCategory.SYNTAX]
    assert "does not define the entry point `def solve(task):`" in result.rounds[0].feedback


def test_the_code_cannot_use_the_checker_or_the_generator(scripted: list[ScriptedModel]) -> None:
    cheat = "def solve(task):\n    import audere.scenarios\n    return None\n"
    model = script(scripted, text("APIs: rrt"), code_reply(cheat))
    result = Agent("plan-easy", seed=12, model=model.model, tool_calls=False, max_rounds=1).solve()
    assert result.categories == [ErrorCategory.RUNTIME]
    assert "not available inside the sandbox" in result.rounds[0].feedback


def test_predict_parses_numbers_and_reports_bad_ones(scripted: list[ScriptedModel]) -> None:
    task = scenarios.make("track-lin", seed=1)
    reference = np.asarray(task.reference)
    inputs = np.clip(np.diff(reference, axis=0) / task.dt, task.u_min, task.u_max)
    model = script(
        scripted,
        text("The inputs are small."),  # no JSON
        text('```json\n{"inputs": [[1, "a"]]}\n```'),
        text("```json\n" + json.dumps({"inputs": inputs.tolist()}) + "\n```"),
    )
    result = Agent(task, model=model.model, method="predict", tool_calls=False).solve()
    assert result.categories == [ErrorCategory.PARSING, ErrorCategory.PARSING, ErrorCategory.SUCCESS]
    assert "no JSON object" in result.rounds[0].feedback
    assert "array of numbers" in result.rounds[1].feedback
    assert result.rounds[2].prediction is not None
    assert result.rounds[2].execution is None  # nothing is run for predict


def test_code_method_hides_the_apis(scripted: list[ScriptedModel]) -> None:
    uses_api = "from audere.planners import rrt\n\ndef solve(task):\n    return None\n"
    model = script(scripted, code_reply(uses_api))
    result = Agent(
        "plan-easy", seed=1, model=model.model, method="code", tool_calls=False, max_rounds=1
    ).solve()
    assert result.categories == [ErrorCategory.RUNTIME]
    assert "not available inside the sandbox" in result.rounds[0].feedback
    system = model.requests[0].messages[0]["content"]
    assert "numpy and scipy only" in system


def test_provision_all_sends_every_api_up_front(scripted: list[ScriptedModel]) -> None:
    model = script(scripted, text("APIs: rrt"), code_reply(RRT_CODE))
    result = Agent("plan-easy", seed=1, model=model.model, tool_calls=False, api_provision="all").solve()
    assert result.success
    first = model.requests[0].messages[-1]["content"]
    for name in ("astar", "cem", "grad", "lqr", "milp", "mpc", "pid", "rrt"):
        assert f"Source of `{name}`" in first


def test_events_and_async(scripted: list[ScriptedModel]) -> None:
    model = script(scripted, text("APIs: rrt"), code_reply(RRT_CODE))
    events: list[Event] = []
    agent = Agent("plan-easy", seed=13, model=model.model, tool_calls=False, on_event=events.append)
    result = asyncio.run(agent.asolve())
    assert result.success
    assert [e.kind for e in events] == ["task", "call", "call", "round"]


def test_result_round_trips_and_renders(scripted: list[ScriptedModel], tmp_path: Path) -> None:
    model = script(scripted, text("APIs: rrt"), code_reply(STRAIGHT_LINE), code_reply(RRT_CODE))
    result = Agent("plan-easy", seed=14, model=model.model, tool_calls=False).solve()
    again = SolveResult.load(result.save(tmp_path / "result.json"))
    assert again == result
    assert again.categories == [ErrorCategory.TASK_FAILURE, ErrorCategory.SUCCESS]
    assert again.solution is not None
    rendered = str(again)
    assert "round 1: task_failure" in rendered
    assert "round 2: success apis=rrt called=rrt" in rendered
    page = again._repr_html_()
    assert "<table>" in page
    assert "data:image/png;base64," in page


@pytest.mark.parametrize(
    ("task", "kwargs", "match"),
    [
        ("plan-easy", {}, "seed: expected an integer seed for the scenario 'plan-easy'"),
        ("plan-easy/seed=x", {}, "expected '<scenario>/seed=<n>'"),
        ("plan-easy/seed=1", {"seed": 2}, "seed: given twice"),
        ("missing.yaml", {}, "the task file 'missing.yaml' does not exist"),
        ("", {}, "task: expected a Task"),
        (3, {}, "task: expected a Task"),
        ("go to the goal", {"seed": 1}, "seed: expected None with a description in words"),
        ("plan-easy/seed=1", {"method": "guess"}, "method: expected one of"),
        ("plan-easy/seed=1", {"api_provision": "some"}, "api_provision: expected one of"),
        ("plan-easy/seed=1", {"max_rounds": 0}, "max_rounds: expected a positive integer"),
        ("plan-easy/seed=1", {"timeout_s": -1}, "timeout_s: expected a positive number"),
        ("plan-easy/seed=1", {"tool_calls": "yes"}, "tool_calls: expected True, False or None"),
        ("plan-easy/seed=1", {"executor": object()}, "executor: expected an Executor"),
        ("plan-easy/seed=1", {"temperature": 5.0}, "temperature"),
    ],
)
def test_agent_rejects_bad_arguments(task: object, kwargs: dict[str, object], match: str) -> None:
    with pytest.raises(InvalidArgumentError, match=match):
        Agent(task, **kwargs)  # type: ignore[arg-type]


def test_task_forms(tmp_path: Path) -> None:
    from audere.tasks import save_task

    task = scenarios.make("plan-easy", seed=5)
    path = save_task(task, tmp_path / "task.yaml")
    for given in (task, "plan-easy/seed=5", str(path), path):
        assert Agent(given).task == task  # type: ignore[arg-type]
    assert Agent("plan-easy", seed=5).task == task
    assert Agent("go from (1, 1) to (9, 9)").task is None


def test_hostile_and_crashing_code_becomes_a_round(scripted: list[ScriptedModel]) -> None:
    kill_parent = (
        "import os, signal\n\ndef solve(task):\n    os.kill(os.getppid(), signal.SIGKILL)\n    return None\n"
    )
    segfault = "import ctypes\n\ndef solve(task):\n    return ctypes.string_at(0)\n"
    model = script(
        scripted, text("APIs: rrt"), code_reply(kill_parent), code_reply(segfault), code_reply(RRT_CODE)
    )
    result = Agent("plan-easy", seed=15, model=model.model, tool_calls=False).solve()
    assert result.success, str(result)
    first, second, _ = result.categories
    # Landlock refuses the signal (a runtime error); without it the supervisor dies (a sandbox error)
    assert first in (ErrorCategory.RUNTIME, ErrorCategory.SANDBOX_ERROR, ErrorCategory.TASK_FAILURE)
    assert second is ErrorCategory.RUNTIME
    assert "SIGSEGV" in result.rounds[1].feedback
    assert 'File "<agent_code>", line 4' in result.rounds[1].feedback


def test_code_with_an_apis_header_is_a_submission(scripted: list[ScriptedModel]) -> None:
    model = script(
        scripted,
        text("APIs: rrt"),
        code_reply(STRAIGHT_LINE, plan="APIs: rrt\nPlan: a straight line first."),  # repeats the APIs line
        code_reply(RRT_CODE, plan="APIs: rrt\nPlan: rrt after all."),
    )
    result = Agent("plan-easy", seed=16, model=model.model, tool_calls=False).solve()
    assert result.categories == [ErrorCategory.TASK_FAILURE, ErrorCategory.SUCCESS]
    assert [len(r.calls) for r in result.rounds] == [2, 1]


def test_each_call_records_the_prompt_it_was_sent(scripted: list[ScriptedModel]) -> None:
    model = script(
        scripted,
        tool("select_apis", apis=["rrt"]),
        OfflineReply(  # two tool calls at once: the feedback answers the first, the second is ignored
            tool_calls=(
                ("submit_code", json.dumps({"code": STRAIGHT_LINE})),
                ("select_apis", '{"apis": ["rrt"]}'),
            )
        ),
        tool("submit_code", code=RRT_CODE),
    )
    result = Agent("plan-easy", seed=17, model=model.model, tool_calls=True).solve()
    assert result.success, str(result)
    select, code, revise = result.calls
    assert select.prompt.startswith(model.requests[0].messages[0]["content"][:40])  # the system prompt first
    assert code.prompt.startswith("# Step 2 of 2")
    assert revise.prompt.startswith("# Round 2 of 6")
    assert "Ignored: make one tool call at a time." in revise.prompt
    assert model.requests[2].messages[-2]["role"] == model.requests[2].messages[-1]["role"] == "tool"
