"""The model-access layer: ModelClient over real LiteLLM calls to offline models, retries, record and replay.

No mock of LiteLLM: every call goes through ``litellm.completion`` / ``litellm.acompletion`` to the
``audere`` custom provider, the code path a hosted model takes.
"""

from __future__ import annotations

import asyncio
import json
import math
import os
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from audere.agent._cassette import (
    CASSETTE_FORMAT,
    Cassette,
    CassetteError,
    forget_cassettes,
    request_key,
)
from audere.agent._llm import ModelClient, ModelError, Reply, ToolCall
from audere.agent._offline import (
    OfflineReply,
    OfflineRequest,
    ProviderError,
    ScriptedModel,
    ScriptItem,
    install_provider,
    register_model,
    registered_models,
    unregister_model,
)
from audere.errors import AudereError, InvalidArgumentError

USER = [{"role": "user", "content": "Plan a path from (0, 0) to (1, 1)."}]

TOOLS = [
    {
        "type": "function",
        "function": {
            "name": "select_apis",
            "description": "Choose the APIs to read.",
            "parameters": {
                "type": "object",
                "properties": {"names": {"type": "array", "items": {"type": "string"}}},
                "required": ["names"],
            },
        },
    },
    {
        "type": "function",
        "function": {
            "name": "submit_code",
            "description": "Submit the integration code.",
            "parameters": {
                "type": "object",
                "properties": {"code": {"type": "string"}},
                "required": ["code"],
            },
        },
    },
]


@pytest.fixture(autouse=True)
def _no_cassettes_left() -> Iterator[None]:
    yield
    forget_cassettes()


def _client(model: str, **kwargs: Any) -> tuple[ModelClient, list[float]]:
    """A client whose backoff sleeps are recorded instead of waited."""
    client = ModelClient(model, **kwargs)
    delays: list[float] = []
    client.sleep = delays.append
    return client, delays


# --------------------------------------------------------------------------------------------------
# Replies
# --------------------------------------------------------------------------------------------------


def test_text_reply_carries_content_usage_and_request() -> None:
    with ScriptedModel("t-text", [OfflineReply("hello", prompt_tokens=11, completion_tokens=3)]) as model:
        client = ModelClient(model.model, temperature=0.3, seed=7)
        reply = client.complete(USER)
    assert reply.content == "hello"
    assert reply.tool_calls == ()
    assert (reply.prompt_tokens, reply.completion_tokens) == (11, 3)
    assert reply.cost is None  # LiteLLM has no price for an offline model
    assert reply.finish_reason == "stop"
    assert reply.model == "audere/t-text"
    assert reply.attempts == 1
    assert reply.latency_s >= 0.0
    (request,) = model.requests
    assert isinstance(request, OfflineRequest)
    assert request.model == "t-text"
    assert request.messages == USER
    assert request.tools is None
    assert request.temperature == pytest.approx(0.3)
    assert request.seed == 7


def test_tool_call_reply_round_trips_arguments_verbatim() -> None:
    arguments = '{"names": ["planners.rrt", "controllers.lqr"], "why": "ünïcode \\"quoted\\""}'
    not_json = '{"code": "x = 1'  # a model may write invalid JSON: it must reach the caller untouched
    script = [OfflineReply(tool_calls=(("select_apis", arguments), ("submit_code", not_json)))]
    with ScriptedModel("t-tools", script) as model:
        reply = ModelClient(model.model).complete(USER, tools=TOOLS, tool_choice="required")
    assert reply.tool_calls == (
        ToolCall(id="call_0", name="select_apis", arguments=arguments),
        ToolCall(id="call_1", name="submit_code", arguments=not_json),
    )
    assert reply.content == ""
    assert reply.finish_reason == "tool_calls"
    (request,) = model.requests
    assert request.tools == TOOLS
    assert request.tool_choice == "required"


def test_acomplete_answers_text_and_tool_calls_on_one_event_loop() -> None:
    script = [OfflineReply("first"), OfflineReply(tool_calls=(("submit_code", '{"code": "pass"}'),))]
    with ScriptedModel("t-async", script) as model:
        client = ModelClient(model.model)

        async def both() -> tuple[Reply, Reply]:
            first = await client.acomplete(USER)
            second = await client.acomplete(USER, tools=TOOLS)
            return first, second

        first, second = asyncio.run(both())
    assert first.content == "first"
    assert second.tool_calls == (ToolCall("call_0", "submit_code", '{"code": "pass"}'),)
    assert second.finish_reason == "tool_calls"


def test_missing_token_counts_are_estimated_from_characters() -> None:
    messages: list[dict[str, Any]] = [
        {"role": "system", "content": "You plan."},  # 9 characters
        {"role": "user", "content": [{"type": "text", "text": "Go to the goal"}]},  # 14
    ]
    reply_text = "Sure, here is the plan"  # 22
    with ScriptedModel("t-estimate", [OfflineReply(reply_text)]) as model:
        reply = ModelClient(model.model).complete(messages)
    assert reply.prompt_tokens == math.ceil((9 + 14) / 4)
    assert reply.completion_tokens == math.ceil(22 / 4)


def test_reply_to_dict_from_dict_round_trip_through_json() -> None:
    reply = Reply("text", (ToolCall("call_0", "f", "{}"),), 3, 4, 0.25, 1.5, "gpt-4o", "tool_calls", 2)
    assert Reply.from_dict(json.loads(json.dumps(reply.to_dict()))) == reply
    with pytest.raises(InvalidArgumentError, match="reply prompt_tokens: expected an integer >= 0, got -1"):
        Reply.from_dict({**reply.to_dict(), "prompt_tokens": -1})


# --------------------------------------------------------------------------------------------------
# Provider errors and retries
# --------------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("kind", "exception"),
    [
        ("rate_limit", "RateLimitError"),
        ("timeout", "Timeout"),
        ("connection", "APIConnectionError"),
        ("server", "ServiceUnavailableError"),
        ("auth", "AuthenticationError"),
        ("bad_request", "BadRequestError"),
        ("not_found", "NotFoundError"),
        ("other", "APIResponseValidationError"),
    ],
)
def test_provider_error_reaches_litellm_caller_as_the_litellm_exception(kind: str, exception: str) -> None:
    install_provider()
    import litellm

    with (
        ScriptedModel(f"t-raw-{kind.replace('_', '-')}", [ProviderError(kind, "trouble")]) as model,  # type: ignore[arg-type]
        pytest.raises(getattr(litellm, exception)) as caught,
    ):
        litellm.completion(model=model.model, messages=USER, num_retries=0)
    assert "trouble" in str(caught.value)


def test_rate_limit_is_retried_then_succeeds() -> None:
    script: list[ScriptItem] = [ProviderError("rate_limit", "slow down"), OfflineReply("done")]
    with ScriptedModel("t-rate", script) as model:
        client, delays = _client(model.model, backoff_s=0.5)
        reply = client.complete(USER)
    assert reply.content == "done"
    assert reply.attempts == 2
    assert len(model.requests) == 2
    assert len(delays) == 1
    assert 0.5 <= delays[0] <= 0.5 * 1.1


def test_timeouts_exhaust_retries_with_exponential_backoff() -> None:
    with ScriptedModel("t-timeout", [ProviderError("timeout", "took too long")] * 3) as model:
        client, delays = _client(model.model, max_retries=2, backoff_s=1.0)
        with pytest.raises(ModelError) as caught:
            client.complete(USER)
    error = caught.value
    assert error.kind == "timeout"
    assert error.attempts == client.max_retries + 1 == 3
    assert "audere/t-timeout" in str(error)
    assert "took too long" in str(error)
    assert isinstance(error, AudereError)
    assert len(delays) == 2
    assert 1.0 <= delays[0] <= 1.1
    assert 2.0 <= delays[1] <= 2.1


@pytest.mark.parametrize("kind", ["connection", "server"])
def test_connection_and_server_errors_are_retried(kind: str) -> None:
    with ScriptedModel(f"t-retry-{kind}", [ProviderError(kind), OfflineReply("ok")]) as model:  # type: ignore[arg-type]
        client, delays = _client(model.model)
        assert client.complete(USER).attempts == 2
    assert len(delays) == 1


@pytest.mark.parametrize("kind", ["auth", "bad_request", "not_found", "other"])
def test_non_retryable_errors_are_raised_at_once(kind: str) -> None:
    script: list[ScriptItem] = [ProviderError(kind, "no way"), OfflineReply("never reached")]  # type: ignore[arg-type]
    with ScriptedModel(f"t-fatal-{kind.replace('_', '-')}", script) as model:
        client, delays = _client(model.model, max_retries=5)
        with pytest.raises(ModelError) as caught:
            client.complete(USER)
        assert model.remaining == 1
    assert caught.value.kind == kind
    assert caught.value.attempts == 1
    assert "no way" in str(caught.value)
    assert delays == []


def test_async_retry_uses_the_async_sleep() -> None:
    with ScriptedModel("t-async-retry", [ProviderError("rate_limit"), OfflineReply("late")]) as model:
        client = ModelClient(model.model, backoff_s=2.0)
        delays: list[float] = []

        async def no_wait(delay: float) -> None:
            delays.append(delay)

        client.async_sleep = no_wait
        reply = asyncio.run(client.acomplete(USER))
    assert (reply.content, reply.attempts) == ("late", 2)
    assert len(delays) == 1
    assert 2.0 <= delays[0] <= 2.2


def test_unknown_offline_model_is_not_found_and_lists_the_registered_ones() -> None:
    with ScriptedModel("t-present", [OfflineReply("x")]):
        client, delays = _client("audere/t-absent")
        with pytest.raises(ModelError) as caught:
            client.complete(USER)
    error = caught.value
    assert error.kind == "not_found"
    assert error.attempts == 1
    message = str(error)
    assert "t-absent" in message
    assert "'t-present'" in message
    assert "'replay'" in message
    assert delays == []


def test_a_responder_bug_is_kind_other_and_not_retried() -> None:
    def broken(request: OfflineRequest) -> OfflineReply:
        raise KeyError("oops")

    with ScriptedModel("t-bug", [broken]) as model:
        client, delays = _client(model.model)
        with pytest.raises(ModelError, match="KeyError") as caught:
            client.complete(USER)
    assert caught.value.kind == "other"
    assert delays == []


def test_a_script_that_runs_out_says_so() -> None:
    with ScriptedModel("t-short", [OfflineReply("only")]) as model:
        client = ModelClient(model.model)
        client.complete(USER)
        with pytest.raises(
            ModelError, match="run out of replies: it was given 1 and this is call 2"
        ) as caught:
            client.complete(USER)
    assert caught.value.kind == "other"


# --------------------------------------------------------------------------------------------------
# Registry
# --------------------------------------------------------------------------------------------------


def test_registry_register_unregister_and_names() -> None:
    def echo(request: OfflineRequest) -> OfflineReply:
        return OfflineReply(request.last_user_text.upper())

    assert register_model("t-echo", echo) == "audere/t-echo"
    try:
        assert "t-echo" in registered_models()
        assert register_model("t-echo", echo) == "audere/t-echo"  # the same responder again: fine
        with pytest.raises(InvalidArgumentError, match="name: expected a name not yet registered"):
            register_model("t-echo", lambda request: OfflineReply("other"))
        assert ModelClient("audere/t-echo").complete(USER).content == USER[0]["content"].upper()
    finally:
        unregister_model("t-echo")
    assert "t-echo" not in registered_models()
    assert "replay" in registered_models()
    with pytest.raises(InvalidArgumentError, match="name: expected a registered offline model"):
        unregister_model("t-echo")


@pytest.mark.parametrize(
    ("name", "message"),
    [
        ("replay", "reserved"),
        ("Upper", r"expected an offline model name matching \[a-z0-9\]\[a-z0-9_.-\]\*, got 'Upper'"),
        ("-dash", "got '-dash'"),
        ("", "got ''"),
        ("a/b", "got 'a/b'"),
    ],
)
def test_bad_model_names_are_refused(name: str, message: str) -> None:
    with pytest.raises(InvalidArgumentError, match=message):
        ScriptedModel(name, [])


def test_script_items_and_provider_errors_are_validated() -> None:
    with pytest.raises(InvalidArgumentError, match=r"replies\[1\]: expected an OfflineReply"):
        ScriptedModel("t-bad-item", [OfflineReply("ok"), 42])  # type: ignore[list-item]
    assert "t-bad-item" not in registered_models()
    with pytest.raises(InvalidArgumentError, match="kind: expected one of"):
        ProviderError("overloaded")  # type: ignore[arg-type]
    with pytest.raises(
        InvalidArgumentError, match=r"tool_calls\[0\]: expected a \(name, arguments JSON text\)"
    ):
        OfflineReply(tool_calls=(("only-a-name",),))  # type: ignore[arg-type]
    with pytest.raises(InvalidArgumentError, match="prompt_tokens: expected an integer >= 0 or None, got -3"):
        OfflineReply("x", prompt_tokens=-3)


# --------------------------------------------------------------------------------------------------
# Record and replay
# --------------------------------------------------------------------------------------------------


def _conversation(client: ModelClient) -> list[Reply]:
    """Two rounds: a tool call, then its result and a text answer."""
    messages: list[dict[str, Any]] = [{"role": "system", "content": "You plan."}, *USER]
    first = client.complete(messages, tools=TOOLS)
    call = first.tool_calls[0]
    messages += [
        {
            "role": "assistant",
            "content": None,  # LiteLLM drops this on the way to a provider; keys must not depend on it
            "tool_calls": [
                {
                    "id": call.id,
                    "type": "function",
                    "function": {"name": call.name, "arguments": call.arguments},
                }
            ],
        },
        {"role": "tool", "tool_call_id": call.id, "content": "planners.rrt: def plan(...)"},
    ]
    second = client.complete(messages, tools=TOOLS)
    return [first, second]


def test_record_then_replay_gives_identical_replies(tmp_path: Path) -> None:
    path = tmp_path / "run.cassette.json"
    script = [
        OfflineReply(tool_calls=(("select_apis", '{"names": ["planners.rrt"]}'),), prompt_tokens=120),
        OfflineReply("Here is the code.", prompt_tokens=200, completion_tokens=40),
    ]
    with ScriptedModel("t-record", script) as model:
        recorded = _conversation(ModelClient(model.model, seed=3, record=path))
    data = json.loads(path.read_text(encoding="utf-8"))
    assert (data["format"], data["version"]) == (CASSETTE_FORMAT, 1)
    assert [entry["model"] for entry in data["entries"]] == ["audere/t-record"] * 2
    for entry in data["entries"]:
        request = entry["request"]
        assert entry["key"] == request_key(request["messages"], request["tools"], request["temperature"], 3)
    assert not [name for name in os.listdir(tmp_path) if name != path.name]  # no temporary file left

    replayed = _conversation(ModelClient("audere/replay", cassette=path, seed=3))

    def metrics(reply: Reply) -> tuple[object, ...]:
        return (reply.content, reply.tool_calls, reply.prompt_tokens, reply.completion_tokens, reply.cost)

    assert [metrics(reply) for reply in replayed] == [metrics(reply) for reply in recorded]
    assert [reply.finish_reason for reply in replayed] == ["tool_calls", "stop"]
    assert all(reply.model == "audere/replay" for reply in replayed)


def test_replay_keeps_a_hosted_models_recorded_cost_and_tool_call_ids(tmp_path: Path) -> None:
    path = tmp_path / "hosted.json"
    recorded = Reply(
        content="thinking",
        tool_calls=(ToolCall("call_9xYz", "submit_code", '{"code": "pass"}'),),
        prompt_tokens=1234,
        completion_tokens=56,
        cost=0.0123,
        latency_s=2.5,
        model="gpt-4o",
        finish_reason="tool_calls",
        attempts=1,
    )
    request = {"messages": USER, "tools": TOOLS, "temperature": 0.1, "seed": None}
    Cassette.append(path, request_key(USER, TOOLS, 0.1, None), "gpt-4o", request, recorded)
    reply = ModelClient("audere/replay", cassette=path).complete(USER, tools=TOOLS)
    assert reply.cost == pytest.approx(0.0123)
    assert (reply.prompt_tokens, reply.completion_tokens) == (1234, 56)
    assert reply.tool_calls == recorded.tool_calls
    assert reply.content == "thinking"


def test_replay_miss_is_not_found_and_says_how_many_entries_there_are(tmp_path: Path) -> None:
    path = tmp_path / "one.json"
    with ScriptedModel("t-miss", [OfflineReply("recorded")]) as model:
        ModelClient(model.model, record=path).complete(USER)
    client, delays = _client("audere/replay", cassette=path)
    with pytest.raises(ModelError) as caught:
        client.complete([{"role": "user", "content": "something never recorded"}])
    error = caught.value
    assert error.kind == "not_found"
    assert error.attempts == 1
    assert "has no reply for this request" in str(error)
    assert "holds 1 entry" in str(error)
    assert str(path.name) in str(error)
    assert delays == []
    # The temperature is part of the key: the same messages at another temperature miss too.
    with pytest.raises(ModelError, match="has no reply"):
        ModelClient("audere/replay", cassette=path, temperature=0.7).complete(USER)


def test_append_keeps_existing_entries(tmp_path: Path) -> None:
    path = tmp_path / "grow.json"
    reply = Reply("a", (), 1, 1, None, 0.1, "m", "stop", 1)
    for index in range(3):
        messages = [{"role": "user", "content": f"question {index}"}]
        request = {"messages": messages, "tools": None, "temperature": 0.0, "seed": None}
        Cassette.append(path, request_key(messages, None, 0.0, None), "m", request, reply)
    cassette = Cassette.load(path)
    assert len(cassette) == 3
    assert cassette.lookup(request_key([{"role": "user", "content": "question 1"}], None, 0.0, None)) == reply
    assert cassette.lookup("0" * 64) is None


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("{not json", "expected JSON, got invalid JSON at line 1 column 2"),
        ('{"format": "vcr", "version": 1, "entries": []}', "expected format 'audere-cassette', got 'vcr'"),
        ('{"format": "audere-cassette", "version": 2, "entries": []}', "expected version 1, got 2"),
        ('{"format": "audere-cassette", "version": 1, "entries": {}}', "expected 'entries' to be a list"),
        (
            '{"format": "audere-cassette", "version": 1, "entries": [{"key": "abc"}]}',
            "entry 0: key: expected 64",
        ),
    ],
)
def test_corrupted_cassette_is_a_clear_error_naming_the_file(tmp_path: Path, text: str, message: str) -> None:
    path = tmp_path / "broken.json"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(CassetteError, match=message) as caught:
        ModelClient("audere/replay", cassette=path)
    assert str(path) in str(caught.value)


def test_edited_or_missing_cassette_is_refused(tmp_path: Path) -> None:
    path = tmp_path / "edited.json"
    with ScriptedModel("t-edit", [OfflineReply("x")]) as model:
        ModelClient(model.model, record=path).complete(USER)
    data = json.loads(path.read_text(encoding="utf-8"))
    data["entries"][0]["request"]["messages"][0]["content"] = "changed by hand"
    path.write_text(json.dumps(data), encoding="utf-8")
    with pytest.raises(CassetteError, match="entry 0: key: expected the request's key"):
        ModelClient("audere/replay", cassette=path)
    data["entries"][0]["request"]["messages"][0]["content"] = USER[0]["content"]
    data["entries"][0]["reply"]["prompt_tokens"] = "many"
    path.write_text(json.dumps(data), encoding="utf-8")
    with pytest.raises(
        CassetteError, match="entry 0: reply prompt_tokens: expected an integer >= 0, got 'many'"
    ):
        ModelClient("audere/replay", cassette=path)
    with pytest.raises(CassetteError, match="expected an existing file"):
        ModelClient("audere/replay", cassette=tmp_path / "absent.json")


def test_request_key_ignores_the_model_and_key_order() -> None:
    key = request_key([{"role": "user", "content": "hi"}], None, 0.1, None)
    assert key == request_key([{"content": "hi", "role": "user"}], None, 0.1, None)
    assert key != request_key([{"role": "user", "content": "hi"}], None, 0.1, 0)
    assert request_key(USER, None, 1, None) == request_key(USER, None, 1.0, None)
    assert len(key) == 64


# --------------------------------------------------------------------------------------------------
# Construction, properties
# --------------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"model": ""}, "model: expected a non-empty model string, got ''"),
        ({"model": 3}, "model: expected a non-empty model string, got 3"),
        ({"model": "audere/Bad Name"}, "model: expected an offline model name matching"),
        ({"temperature": -1}, r"temperature: expected a number in \[0, 2\], got -1"),
        ({"temperature": 2.5}, r"temperature: expected a number in \[0, 2\], got 2.5"),
        ({"temperature": float("nan")}, r"temperature: expected a number in \[0, 2\], got nan"),
        ({"temperature": True}, r"temperature: expected a number in \[0, 2\], got True"),
        ({"seed": 1.5}, "seed: expected an integer or None, got 1.5"),
        ({"seed": "7"}, "seed: expected an integer or None, got '7'"),
        ({"api_base": ""}, "api_base: expected a non-empty string or None, got ''"),
        ({"api_key": 12345}, "api_key: expected a non-empty string or None, got a value of type int"),
        ({"max_retries": -1}, "max_retries: expected an integer >= 0, got -1"),
        ({"max_retries": 2.0}, "max_retries: expected an integer >= 0, got 2.0"),
        ({"timeout_s": 0}, "timeout_s: expected a finite number > 0, got 0"),
        ({"backoff_s": -0.5}, "backoff_s: expected a finite number >= 0, got -0.5"),
        ({"record": 5}, "record: expected a file path or None, got 5"),
        ({"cassette": "x.json"}, "cassette: expected only with model 'audere/replay'"),
        (
            {"model": "audere/replay"},
            "cassette: expected a cassette file to replay with 'audere/replay', got None",
        ),
    ],
)
def test_invalid_arguments_name_the_argument_expectation_and_value(
    kwargs: dict[str, Any], message: str
) -> None:
    arguments = {"model": "audere/expert", **kwargs}
    model = arguments.pop("model")
    with pytest.raises(InvalidArgumentError, match=message):
        ModelClient(model, **arguments)


@pytest.mark.parametrize(
    ("messages", "options", "message"),
    [
        ([], {}, r"messages: expected a non-empty list of message dicts, got \[\]"),
        ([{"content": "no role"}], {}, r"messages\[0\]: expected a dict with a string 'role'"),
        (USER, {"tools": {"type": "function"}}, "tools: expected a list of tool dicts or None"),
        (USER, {"tool_choice": "auto"}, "tool_choice: expected tools to choose from"),
    ],
)
def test_invalid_requests_are_refused_before_any_call(
    messages: list[dict[str, Any]], options: dict[str, Any], message: str
) -> None:
    with ScriptedModel("t-invalid", [OfflineReply("x")]) as model:
        with pytest.raises(InvalidArgumentError, match=message):
            ModelClient(model.model).complete(messages, **options)
        assert model.requests == []


def test_label_and_supports_tools() -> None:
    expert = ModelClient("audere/expert")
    assert expert.label == "audere/expert (offline rule-based expert, not an LLM)"
    assert expert.supports_tools
    assert ModelClient("gpt-4o").supports_tools
    assert not ModelClient("some-provider-nobody-knows/model-x").supports_tools
    assert ModelClient("gpt-4o").label == "gpt-4o"


def test_import_audere_agent_does_not_import_litellm(tmp_path: Path) -> None:
    env = {**os.environ, "LITELLM_LOCAL_MODEL_COST_MAP": "True"}
    code = (
        "import sys, audere.agent, audere.agent._llm, audere.agent._offline, audere.agent._cassette\n"
        "from audere.agent._offline import ScriptedModel, OfflineReply\n"
        "ScriptedModel('t-sub', [OfflineReply('x')])\n"
        "assert 'litellm' not in sys.modules, 'litellm was imported'\n"
    )
    done = subprocess.run(
        [sys.executable, "-W", "error", "-c", code],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        env=env,
        timeout=60,
        check=False,
    )
    assert done.returncode == 0, done.stderr
