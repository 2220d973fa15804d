"""A task described in words: the model turns it into a validated task, then solves it.

The model here is scripted, recorded to a cassette on the first run, and the cassette then replayed
through ``audere/replay``: the replay reproduces the recorded run exactly.
"""

from __future__ import annotations

import itertools
import json
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.skipif(sys.platform != "linux", reason="the sandbox runs on Linux only")

from audere.agent import Agent, ErrorCategory, OfflineReply, ScriptedModel  # noqa: E402
from audere.agent._expert import recipe_code  # noqa: E402

_names = (f"writer-{i}" for i in itertools.count())

TEXT = (
    "A point robot starts at (1, 1) in a 10 m by 10 m room and must get within 0.1 m of (9, 9). "
    "A round pillar of radius 1.5 m stands at (5, 5); keep 0.05 m away from it."
)
TASK = {
    "kind": "reach_avoid",
    "x0": [1.0, 1.0],
    "goal": [9.0, 9.0],
    "goal_tolerance": 0.1,
    "margin": 0.05,
    "workspace": {"xmin": 0, "xmax": 10, "ymin": 0, "ymax": 10},
    "obstacles": [{"kind": "circle", "center": [5.0, 5.0], "radius": 1.5}],
}


def fenced(value: object) -> OfflineReply:
    return OfflineReply(content="```json\n" + json.dumps(value) + "\n```")


def code_reply(code: str) -> OfflineReply:
    return OfflineReply(content=f"Plan: rrt on task.world().\n\n```python\n{code}```\n")


def test_free_text_recorded_then_replayed(tmp_path: Path) -> None:
    bad = {**TASK, "obstacles": [{"type": "circle", "center": [5, 5], "radius": 1.5}]}
    cassette = tmp_path / "cassette.json"
    replies = [
        fenced(bad),
        fenced(TASK),
        OfflineReply(content="APIs: rrt"),
        code_reply(recipe_code("plan-easy")),
    ]
    with ScriptedModel(next(_names), replies) as model:
        recorded = Agent(TEXT, model=model.model, tool_calls=False, record=cassette).solve()
        retry = model.requests[1].messages[-1]["content"]
    assert recorded.success, str(recorded)
    assert recorded.task is not None
    assert recorded.task.kind == "reach_avoid"
    assert recorded.task.goal == (9.0, 9.0)
    assert recorded.task_text == TEXT
    assert len(recorded.parse_calls) == 2  # the first task file did not validate
    assert "obstacles.0" in retry  # the validation error named the field
    assert "attempt 2 of 3" in retry
    assert len(recorded.calls) == 4  # parsing counts: 2 + selection + code

    replayed = Agent(TEXT, model="audere/replay", cassette=cassette, tool_calls=False).solve()
    assert replayed.success
    assert replayed.task == recorded.task
    assert [c.response for c in replayed.calls] == [c.response for c in recorded.calls]
    assert [(c.prompt_tokens, c.completion_tokens, c.cost) for c in replayed.calls] == [
        (c.prompt_tokens, c.completion_tokens, c.cost) for c in recorded.calls
    ]
    assert replayed.categories == recorded.categories == [ErrorCategory.SUCCESS]
    assert replayed.apis_called == recorded.apis_called == ["rrt"]


def test_replay_of_another_conversation_is_a_model_error(tmp_path: Path) -> None:
    cassette = tmp_path / "cassette.json"
    with ScriptedModel(next(_names), [fenced(TASK), OfflineReply(content="APIs: rrt")]) as model:
        Agent(TEXT, model=model.model, tool_calls=False, record=cassette, max_rounds=1).solve()
    other = Agent(
        TEXT.replace("(9, 9)", "(8, 8)"), model="audere/replay", cassette=cassette, tool_calls=False
    )
    result = other.solve()
    assert result.status == "model_error"
    assert "no reply" in result.message.lower() or "no recorded" in result.message.lower()


def test_missing_goal_ends_with_a_clear_message() -> None:
    reply = OfflineReply(
        content="MISSING: goal: the description says where the robot starts, not where to go."
    )
    with ScriptedModel(next(_names), [reply]) as model:
        result = Agent(
            "A robot starts at (1, 1) in a 10 m room.", model=model.model, tool_calls=False
        ).solve()
    assert result.status == "invalid_task"
    assert not result.success
    assert "missing something a task needs: goal" in result.message
    assert result.rounds == []
    assert result.task is None


def test_contradictory_numbers_end_after_bounded_retries() -> None:
    outside = {**TASK, "x0": [12.0, 1.0]}  # the start is outside the 10 m room
    with ScriptedModel(next(_names), [fenced(outside)] * 3) as model:
        result = Agent(TEXT, model=model.model, tool_calls=False, parse_attempts=3).solve()
        feedback = model.requests[-1].messages[-1]["content"]
    assert result.status == "invalid_task"
    assert "after 3 attempt(s)" in result.message
    assert "x0" in result.message
    assert len(result.calls) == 3
    assert "x0" in feedback


def test_free_text_with_tool_calls() -> None:
    replies = [
        OfflineReply(tool_calls=(("define_task", json.dumps({"task": TASK})),)),
        OfflineReply(tool_calls=(("select_apis", json.dumps({"apis": ["rrt"]})),)),
        OfflineReply(tool_calls=(("submit_code", json.dumps({"code": recipe_code("plan-easy")})),)),
    ]
    with ScriptedModel(next(_names), replies) as model:
        result = Agent(TEXT, model=model.model, tool_calls=True).solve()
        tools = model.requests[0].tools or []
    assert result.success, str(result)
    assert [t["function"]["name"] for t in tools] == ["define_task"]
    assert "$defs" in tools[0]["function"]["parameters"]
