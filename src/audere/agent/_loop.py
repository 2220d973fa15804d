"""The agent loop, written once as a generator of effects; :mod:`audere.agent._agent` drives it.

The loop never calls a model or runs code itself: it yields :class:`CallModel` and :class:`RunCode`
requests and receives a ``Reply`` (or the ``ModelError``) and an ``Execution`` back. The synchronous
and the asynchronous ``solve`` are two small drivers over the same loop.
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable, Generator, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from audere.agent import _parse
from audere.agent._categories import ErrorCategory
from audere.agent._result import ModelCall, Round
from audere.agent.prompts import render
from audere.agent.sandbox import Execution, ExecutionStatus

__all__ = ["CallModel", "Event", "LoopConfig", "RunCode", "parse_loop", "solve_loop"]

_MAX_CALLS_PER_ROUND = 3  # select, code, and one change of APIs
_FEEDBACK_CHARS = 2500
_OUTPUT_TAIL_CHARS = 800
_SOLUTION_FIELDS = ("inputs", "states", "waypoints", "times")


@dataclass(frozen=True)
class CallModel:
    """Effect: send ``messages`` (with ``tools``, in tool mode) to the model."""

    messages: list[dict[str, Any]]
    tools: list[dict[str, Any]] | None
    purpose: str


@dataclass(frozen=True)
class RunCode:
    """Effect: run ``code`` in the sandbox with ``inputs``."""

    code: str
    inputs: dict[str, Any]
    timeout_s: float
    method: str


@dataclass(frozen=True)
class Event:
    """What the loop reports as it goes (for progress displays): a finished model call or round."""

    kind: str  # "call" | "round" | "task"
    call: ModelCall | None = None
    round: Round | None = None
    task: Any = None


@dataclass
class LoopConfig:
    """What the loop needs to know besides the task."""

    method: str
    max_rounds: int
    api_provision: str
    timeout_s: float
    tool_mode: bool
    max_apis: int = 3
    on_event: Callable[[Event], None] | None = None
    api_names: tuple[str, ...] = field(default_factory=tuple)


# --- tools ------------------------------------------------------------------------------------------


def _tool(name: str, description: str, properties: dict[str, Any], required: Sequence[str]) -> dict[str, Any]:
    return {
        "type": "function",
        "function": {
            "name": name,
            "description": description,
            "parameters": {"type": "object", "properties": properties, "required": list(required)},
        },
    }


def select_tool(api_names: Sequence[str], max_apis: int) -> dict[str, Any]:
    """The ``select_apis`` tool: 1 to ``max_apis`` registered API names and a reason."""
    return _tool(
        "select_apis",
        "Choose the registered APIs that solve the task.",
        {
            "apis": {
                "type": "array",
                "items": {"type": "string", "enum": list(api_names)},
                "minItems": 1,
                "maxItems": max_apis,
                "description": "API names from the catalog.",
            },
            "reason": {"type": "string", "description": "One sentence: why these APIs."},
        },
        ["apis"],
    )


CODE_TOOL = _tool(
    "submit_code",
    "Submit the plan and the Python code that defines solve(task) -> audere.tasks.Solution.",
    {
        "plan": {"type": "string", "description": "How the pieces connect: inputs, outputs, shapes, types."},
        "code": {"type": "string", "description": "Python source defining solve(task)."},
    },
    ["code"],
)


def prediction_tool(fields: Sequence[str]) -> dict[str, Any]:
    """The ``submit_solution`` tool of the predict method, with the fields the task accepts."""
    matrix = {"type": "array", "items": {"type": "array", "items": {"type": "number"}}}
    properties: dict[str, Any] = {}
    for name in fields:
        properties[name] = {"type": "array", "items": {"type": "number"}} if name == "times" else matrix
    return _tool("submit_solution", "Submit the solution as numbers.", properties, [])


def parse_tool() -> dict[str, Any]:
    """The ``define_task`` tool: the task file under the Task JSON schema."""
    from audere.tasks import TaskAdapter

    schema = TaskAdapter.json_schema()
    defs = schema.pop("$defs", {})
    tool = _tool("define_task", "Define the task file.", {"task": schema}, ["task"])
    tool["function"]["parameters"]["$defs"] = defs
    return tool


# --- messages ------------------------------------------------------------------------------------


def _assistant(reply: Any) -> dict[str, Any]:
    message: dict[str, Any] = {"role": "assistant", "content": reply.content or None}
    if reply.tool_calls:
        message["tool_calls"] = [
            {"id": c.id, "type": "function", "function": {"name": c.name, "arguments": c.arguments}}
            for c in reply.tool_calls
        ]
    if message["content"] is None and "tool_calls" not in message:
        message["content"] = ""
    return message


def _send(messages: list[dict[str, Any]], text: str) -> None:
    """Send ``text``: as the answer to the last reply's tool calls, else as a user message."""
    last = messages[-1] if messages else {}
    pending = [c["id"] for c in last.get("tool_calls") or ()] if last.get("role") == "assistant" else []
    if not pending:
        messages.append({"role": "user", "content": text})
        return
    for i, call_id in enumerate(pending):
        content = text if i == 0 else "Ignored: make one tool call at a time."
        messages.append({"role": "tool", "tool_call_id": call_id, "content": content})


def _prompt_text(messages: Sequence[Mapping[str, Any]], since: int) -> str:
    parts = [str(m.get("content") or "") for m in messages[since:] if m.get("role") != "assistant"]
    return "\n\n".join(p for p in parts if p)


def _task_block(task: Any) -> str:
    return render("task", description=task.describe().rstrip(), task_json=task.model_dump_json(indent=1))


def _solution_fields(task: Any) -> list[str]:
    out: list[str] = []
    for kind in task.solution_kinds:
        out += ["waypoints", "times"] if kind == "timed_waypoints" else [kind]
    return list(dict.fromkeys(out))


def _shapes(task: Any) -> str:
    model = task.model
    shapes = {
        "inputs": f"inputs ({task.horizon}, {model.n_u if model else 'n_u'})",
        "states": f"states ({task.horizon + 1}, {model.n_x if model else 'n_x'})",
        "waypoints": "waypoints (k, 2), from x0 to the goal",
        "times": "times (k,), seconds, one per waypoint",
    }
    return "; ".join(shapes[name] for name in _solution_fields(task))


def _kinds_text(task: Any) -> str:
    return ", ".join(f"`{kind}`" for kind in task.solution_kinds)


# --- judging -------------------------------------------------------------------------------------


def _tail(text: str, limit: int = _OUTPUT_TAIL_CHARS) -> str:
    text = text.rstrip()
    return text if len(text) <= limit else "[...]\n" + text[-limit:]


def _stderr_for_model(text: str) -> str:
    """stderr without the noise of a native crash dump: library frames and the extension list."""
    kept = [
        line
        for line in text.splitlines()
        if not line.startswith("Extension modules:") and not line.lstrip().startswith('File "/')
    ]
    return "\n".join(kept)


def _with_output(message: str, execution: Execution) -> str:
    parts = [message]
    if execution.stdout.strip():
        parts.append(f"Last lines of stdout:\n{_tail(execution.stdout)}")
    stderr = _stderr_for_model(execution.stderr)
    if stderr.strip():
        parts.append(f"Last lines of stderr:\n{_tail(stderr)}")
    return "\n\n".join(parts)[:_FEEDBACK_CHARS]


def _solution_from(result: Mapping[str, np.ndarray] | None) -> Any:
    """The code's result as what ``Task.check`` accepts, or a message saying why not."""
    from audere.tasks import Solution

    if not result:
        return None, "solve(task) returned nothing usable: return an audere.tasks.Solution"
    if set(result) == {"result"}:
        return result["result"], None
    unknown = [k for k in result if k not in _SOLUTION_FIELDS]
    if unknown:
        return None, f"the result has fields {unknown}; a Solution has {list(_SOLUTION_FIELDS)}"
    try:
        return Solution(**dict(result)), None
    except ValueError as error:
        return None, f"the result is not a valid Solution: {error}"


def judge_execution(task: Any, execution: Execution) -> tuple[ErrorCategory, str, Any, Any]:
    """Category, feedback, solution and check report for one execution of the model's code."""
    status = execution.status
    if status is ExecutionStatus.OK:
        solution, problem = _solution_from(execution.result)
        if problem is not None:
            return ErrorCategory.TASK_FAILURE, _with_output(problem, execution), None, None
        report = task.check(solution)
        if report.success:
            return ErrorCategory.SUCCESS, "", solution, report
        from audere.tasks import Solution

        kept = solution if isinstance(solution, Solution) else None
        feedback = _with_output(report.feedback(max_chars=_FEEDBACK_CHARS - 600), execution)
        return ErrorCategory.TASK_FAILURE, feedback, kept, report
    if status is ExecutionStatus.TIMEOUT:
        return ErrorCategory.TIMEOUT, _with_output(f"The code {execution.message}.", execution), None, None
    if status is ExecutionStatus.SYNTAX_ERROR:
        return ErrorCategory.SYNTAX, _with_output(execution.message, execution), None, None
    if status is ExecutionStatus.BAD_RESULT:
        hint = f"{execution.message}. solve(task) must return an audere.tasks.Solution."
        return ErrorCategory.TASK_FAILURE, _with_output(hint, execution), None, None
    if status is ExecutionStatus.SANDBOX_ERROR:
        text = f"The sandbox failed while running the code ({execution.message})."
        return ErrorCategory.SANDBOX_ERROR, text, None, None
    if status is ExecutionStatus.EXCEPTION and execution.exception is not None:
        trace = execution.exception.formatted.strip() or execution.message
        return ErrorCategory.RUNTIME, _with_output(f"The code raised:\n{trace}", execution), None, None
    return (
        ErrorCategory.RUNTIME,
        _with_output(f"The code failed: {execution.message}.", execution),
        None,
        None,
    )


def _runnable(code: str) -> str:
    return f"{code.rstrip()}\n\nresult = {_parse.ENTRY_POINT}(task)\n"


# --- the loop ------------------------------------------------------------------------------------


@dataclass
class _RoundState:
    calls: list[ModelCall] = field(default_factory=list)
    selected: list[str] = field(default_factory=list)
    model_s: float = 0.0


def _call(
    state: _RoundState,
    messages: list[dict[str, Any]],
    tools: list[dict[str, Any]] | None,
    purpose: str,
    since: int,
    config: LoopConfig,
) -> Generator[CallModel, Any, Any]:
    """Yield one model call; record it; return the reply, or the ModelError."""
    outcome = yield CallModel(messages=list(messages), tools=tools, purpose=purpose)
    prompt = _prompt_text(messages, since)
    if isinstance(outcome, Exception):
        call = ModelCall(
            purpose=purpose, prompt=prompt, error=str(outcome), attempts=getattr(outcome, "attempts", 1)
        )
    else:
        state.model_s += outcome.latency_s
        call = ModelCall(
            purpose=purpose,
            prompt=prompt,
            response=outcome.content,
            tool_calls=[(c.name, c.arguments) for c in outcome.tool_calls],
            prompt_tokens=outcome.prompt_tokens,
            completion_tokens=outcome.completion_tokens,
            cost=outcome.cost,
            latency_s=outcome.latency_s,
            attempts=outcome.attempts,
        )
    state.calls.append(call)
    if config.on_event is not None:
        config.on_event(Event(kind="call", call=call))
    return outcome


def _reading(reply: Any, tool_name: str) -> tuple[str | None, dict[str, Any] | None]:
    """The text of a reply and the arguments of its first call to ``tool_name`` (if any)."""
    for call in reply.tool_calls:
        if call.name == tool_name:
            return reply.content, _parse.parse_arguments(call.name, call.arguments)
    if reply.tool_calls:
        names = ", ".join(f"`{c.name}`" for c in reply.tool_calls)
        raise _parse.ReplyError(f"expected a call of the tool `{tool_name}`, got {names}")
    return reply.content, None


def _selection(reply: Any, config: LoopConfig) -> list[str] | None:
    """The APIs a reply selects (tool call or ``APIs:`` line); ``None`` when it selects none."""
    chosen: list[str] | None = None
    for call in reply.tool_calls:
        if call.name == "select_apis":
            args = _parse.parse_arguments(call.name, call.arguments)
            raw = args.get("apis")
            if not isinstance(raw, list) or not all(isinstance(a, str) for a in raw):
                raise _parse.ReplyError("`select_apis` needs `apis`: a list of API names")
            chosen = [a.strip().lower() for a in raw]
    if chosen is None and not any(c.name == "submit_code" for c in reply.tool_calls):
        chosen = _parse.extract_apis(reply.content)
    if chosen is None:
        return None
    valid, unknown = _parse.known_apis(config.api_names, chosen)
    if unknown:
        raise _parse.ReplyError(f"unknown API(s) {unknown}; choose from {list(config.api_names)}")
    if not 1 <= len(valid) <= config.max_apis:
        raise _parse.ReplyError(f"choose 1 to {config.max_apis} APIs, got {len(valid)}")
    return valid


def _has_code(reply: Any) -> bool:
    """Whether a reply submits code (a ``submit_code`` call or a fenced python block)."""
    if any(call.name == "submit_code" for call in reply.tool_calls):
        return True
    return _parse.extract_code(reply.content or "") is not None


def _code(reply: Any) -> tuple[str | None, str]:
    """The plan and code of a reply (tool call ``submit_code`` or a fenced block)."""
    content, args = _reading(reply, "submit_code")
    if args is not None:
        code = args.get("code")
        if not isinstance(code, str) or not code.strip():
            raise _parse.ReplyError("`submit_code` needs `code`: the Python source as a string")
        plan = args.get("plan")
        return (plan if isinstance(plan, str) else None), code
    code = _parse.extract_code(content or "")
    if code is None:
        raise _parse.ReplyError("the reply holds no fenced ```python block defining solve(task)")
    plan = (content or "").split("```", 1)[0].strip() or None
    return plan, code


def _api_docs(names: Sequence[str], provision: str) -> str:
    from audere.apis import api_card, api_source

    parts = []
    for name in names:
        parts.append(f"### `{name}`\n\n```python\n{api_card(name).rstrip()}\n```")
        if provision == "on-demand":
            parts.append(f"Source of `{name}`:\n\n```python\n{api_source(name).rstrip()}\n```")
    return "\n\n".join(parts)


def _all_api_docs(config: LoopConfig) -> str:
    return "\n\n## The APIs, documentation and source\n\n" + _api_docs(config.api_names, "on-demand")


def _tools_for(stage: str, task: Any, config: LoopConfig) -> list[dict[str, Any]]:
    select = select_tool(config.api_names, config.max_apis)
    if stage == "select":
        return [select]
    if stage == "predict":
        return [prediction_tool(_solution_fields(task))]
    if config.method == "use_api" and stage == "revise":
        return [CODE_TOOL, select]
    return [CODE_TOOL]


def _judge_prediction(task: Any, arrays: Mapping[str, np.ndarray]) -> tuple[ErrorCategory, str, Any, Any]:
    solution, problem = _solution_from(arrays)
    if problem is not None:
        return ErrorCategory.PARSING, f"Your answer could not be used: {problem}.", None, None
    report = task.check(solution)
    if report.success:
        return ErrorCategory.SUCCESS, "", solution, report
    return ErrorCategory.TASK_FAILURE, report.feedback(max_chars=_FEEDBACK_CHARS), solution, report


def _first_prompt(task: Any, config: LoopConfig, suffix: str) -> tuple[str, str]:
    """The first user prompt of a method, and the stage it opens."""
    task_text = _task_block(task)
    if config.method == "use_api":
        from audere.apis import catalog

        extra = _all_api_docs(config) if config.api_provision == "all" else ""
        text = render(
            "use_api_select",
            task=task_text + extra,
            catalog=catalog(),
            max_apis=config.max_apis,
            answer=render(f"answer_select_{suffix}"),
        )
        return text, "select"
    if config.method == "code":
        text = render(
            "code_task",
            task=task_text,
            solution_kinds=_kinds_text(task),
            timeout_s=f"{config.timeout_s:g}",
            answer=render(f"answer_code_{suffix}"),
        )
        return text, "code"
    text = render(
        "predict_task",
        task=task_text,
        solution_kinds=_kinds_text(task),
        shapes=_shapes(task),
        answer=_predict_answer(task, suffix),
    )
    return text, "predict"


def _predict_answer(task: Any, suffix: str) -> str:
    return render(f"answer_predict_{suffix}", example_field=_solution_fields(task)[0])


def _revise_prompt(
    task: Any,
    config: LoopConfig,
    suffix: str,
    index: int,
    category: ErrorCategory,
    feedback: str,
    selected: bool,
) -> tuple[str, str]:
    """The prompt that opens round ``index`` after a failed round, and its stage."""
    common = {
        "round": index,
        "max_rounds": config.max_rounds,
        "category": category.value.replace("_", " "),
        "feedback": feedback,
    }
    if config.method == "use_api":
        if not selected:
            return render("use_api_revise", answer=render(f"answer_select_{suffix}"), **common), "select"
        return render("use_api_revise", answer=render(f"answer_revise_{suffix}"), **common), "revise"
    if config.method == "code":
        return render("code_revise", answer=render(f"answer_code_{suffix}"), **common), "code"
    return render("predict_revise", answer=_predict_answer(task, suffix), **common), "predict"


def _finish(
    index: int,
    state: _RoundState,
    category: ErrorCategory,
    feedback: str,
    started: float,
    fields: Mapping[str, Any],
) -> Round:
    return Round(
        index=index,
        calls=state.calls,
        selected_apis=state.selected,
        category=category,
        feedback=feedback if category is not ErrorCategory.SUCCESS else "",
        wall_s=time.monotonic() - started,
        model_s=state.model_s,
        **fields,
    )


def _report(config: LoopConfig, finished: Round) -> None:
    if config.on_event is not None:
        config.on_event(Event(kind="round", round=finished))


def _use_reply(
    reply: Any,
    stage: str,
    task: Any,
    config: LoopConfig,
    state: _RoundState,
    messages: list[dict[str, Any]],
    fields: dict[str, Any],
) -> Generator[RunCode, Any, tuple[ErrorCategory, str] | str]:
    """Act on one reply: a new stage to continue the round in, or the round's category and feedback."""
    suffix = "tool" if config.tool_mode else "text"
    if config.method == "use_api" and stage != "predict":
        # once the APIs are chosen, a reply with code is a submission, even if it repeats an APIs line
        choice = None if stage != "select" and _has_code(reply) else _selection(reply, config)
        if choice is not None:
            state.selected = choice
            text = render(
                "use_api_code",
                apis=_api_docs(choice, config.api_provision),
                solution_kinds=_kinds_text(task),
                timeout_s=f"{config.timeout_s:g}",
                answer=render(f"answer_code_{suffix}"),
            )
            _send(messages, text)
            return "code"
        if stage == "select":
            expected = (
                "call the tool `select_apis`" if config.tool_mode else "expected a line `APIs: name1, name2`"
            )
            raise _parse.ReplyError(f"the reply selects no APIs ({expected})")
    if stage == "predict":
        content, args = _reading(reply, "submit_solution")
        value = args if args is not None else _parse.extract_json(content or "")
        arrays = _parse.parse_prediction(value, accepted=_solution_fields(task))
        fields["prediction"] = {k: v.tolist() for k, v in arrays.items()}
        category, feedback, fields["solution"], fields["report"] = _judge_prediction(task, arrays)
        return category, feedback
    plan, code = _code(reply)
    fields.update(plan=plan, code=code)
    problem = _parse.check_entry_point(code)
    if problem is not None:
        return ErrorCategory.SYNTAX, problem
    execution = yield RunCode(
        code=_runnable(code), inputs={"task": task}, timeout_s=config.timeout_s, method=config.method
    )
    fields["execution"] = execution.to_dict()
    fields["apis_called"] = list(execution.apis_called)
    category, feedback, fields["solution"], fields["report"] = judge_execution(task, execution)
    return category, feedback


def solve_loop(
    task: Any, config: LoopConfig
) -> Generator[CallModel | RunCode, Any, tuple[list[Round], bool]]:
    """The rounds of one solve; returns them and whether the loop ended on a model error."""
    suffix = "tool" if config.tool_mode else "text"
    first, stage = _first_prompt(task, config, suffix)
    messages: list[dict[str, Any]] = [
        {"role": "system", "content": render(f"system_{config.method}")},
        {"role": "user", "content": first},
    ]
    rounds: list[Round] = []
    selected: list[str] = []
    since = 0  # where the messages new to the next call begin (what it records as its prompt)
    for index in range(1, config.max_rounds + 1):
        started = time.monotonic()
        state = _RoundState(selected=list(selected))
        fields: dict[str, Any] = {}
        outcome: tuple[ErrorCategory, str] | None = None
        for _ in range(_MAX_CALLS_PER_ROUND):
            tools = _tools_for(stage, task, config) if config.tool_mode else None
            reply = yield from _call(state, messages, tools, stage, since, config)
            if isinstance(reply, Exception):
                rounds.append(_finish(index, state, ErrorCategory.MODEL_ERROR, str(reply), started, fields))
                _report(config, rounds[-1])
                return rounds, True
            messages.append(_assistant(reply))
            since = len(messages)
            try:
                step = yield from _use_reply(reply, stage, task, config, state, messages, fields)
            except _parse.ReplyError as error:
                outcome = (ErrorCategory.PARSING, f"Your answer could not be used: {error}.")
                break
            if isinstance(step, str):
                stage = step
                continue
            outcome = step
            break
        if outcome is None:
            outcome = (
                ErrorCategory.PARSING,
                f"No code after {_MAX_CALLS_PER_ROUND} replies: submit the code.",
            )
        category, feedback = outcome
        selected = state.selected
        rounds.append(_finish(index, state, category, feedback, started, fields))
        _report(config, rounds[-1])
        if category is ErrorCategory.SUCCESS or index == config.max_rounds:
            break
        text, stage = _revise_prompt(task, config, suffix, index + 1, category, feedback, bool(selected))
        since = len(messages)
        _send(messages, text)
    return rounds, False


def parse_loop(
    text: str, *, attempts: int, tool_mode: bool, on_event: Callable[[Event], None] | None = None
) -> Generator[CallModel, Any, tuple[Any, list[ModelCall], str]]:
    """Turn free text into a validated task with the model; returns (task or None, calls, message)."""
    from pydantic import ValidationError

    from audere.tasks import TaskAdapter

    suffix = "tool" if tool_mode else "text"
    schema = json.dumps(TaskAdapter.json_schema(), indent=1)
    messages: list[dict[str, Any]] = [
        {"role": "system", "content": render("system_parse")},
        {
            "role": "user",
            "content": render(
                "parse_task", text=text.strip(), schema=schema, answer=render(f"answer_parse_{suffix}")
            ),
        },
    ]
    config = LoopConfig(
        method="parse", max_rounds=1, api_provision="", timeout_s=0.0, tool_mode=tool_mode, on_event=on_event
    )
    state = _RoundState()
    tools = [parse_tool()] if tool_mode else None
    problem = "no attempt made"
    since = 0
    for attempt in range(1, attempts + 1):
        reply = yield from _call(state, messages, tools, "parse", since, config)
        if isinstance(reply, Exception):
            return None, state.calls, f"the model failed while reading the task: {reply}"
        messages.append(_assistant(reply))
        try:
            content, args = _reading(reply, "define_task")
            missing = _parse.extract_missing(content or "") if args is None else None
            if missing is not None:
                return None, state.calls, f"the description is missing something a task needs: {missing}"
            value = args.get("task") if args is not None else _parse.extract_json(content or "")
            task = TaskAdapter.validate_python(value)
        except _parse.ReplyError as error:
            problem = str(error)
        except ValidationError as error:
            problem = _validation_text(error)
        else:
            return task, state.calls, f"parsed a {task.kind} task in {attempt} attempt(s)"
        if attempt < attempts:
            since = len(messages)
            _send(
                messages,
                render(
                    "parse_retry",
                    attempt=attempt + 1,
                    attempts=attempts,
                    errors=problem,
                    answer=render(f"answer_parse_{suffix}"),
                ),
            )
    return None, state.calls, f"the text did not become a valid task after {attempts} attempt(s): {problem}"


def _validation_text(error: Any, limit: int = 12) -> str:
    lines = []
    for item in error.errors()[:limit]:
        where = ".".join(str(p) for p in item.get("loc", ())) or "(task)"
        lines.append(f"- {where}: {item.get('msg')}")
    more = len(error.errors()) - limit
    if more > 0:
        lines.append(f"- ... and {more} more")
    return "\n".join(lines)
