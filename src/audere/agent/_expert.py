"""The offline expert: a rule-based strategist answering the agent's prompts like an expert would.

It is **not** a language model. Served as the offline model ``audere/expert`` (through LiteLLM, the
same code path as any real model), it reads the structured task from the prompt, picks the APIs an
expert would pick by the task's kind and dynamics, and answers with the integration code of the
matching recipe (:mod:`audere.recipes`), rewritten to stand alone: the code runs in the sandbox,
where :mod:`audere.recipes` cannot be imported. It is the default model when none is configured,
and the ceiling real models are compared against.

For the two baselines it answers as a careful engineer without the APIs would, with simple
heuristics: feed-forward inputs along a tracking reference, or a straight line to the goal. Those
solve only the easiest tasks, by design.
"""

from __future__ import annotations

import ast
import functools
import inspect
import json
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from audere.agent import _parse
from audere.agent.prompts import render

__all__ = ["EXPERT_LABEL", "ExpertAnswer", "answer", "choose_recipe", "recipe_code"]

EXPERT_LABEL = "audere/expert (offline rule-based expert, not an LLM)"

# (task kind, dynamics) -> the scenario whose recipe an expert would follow
_RULES: dict[tuple[str, str | None], str] = {
    ("tracking", "single_integrator"): "track-lin",
    ("tracking", "double_integrator"): "track-double",
    ("tracking", "unicycle"): "track-car",
    ("reach_avoid", None): "plan-easy",
    ("reach_avoid", "pendulum"): "pendulum-swingup",
    ("reach_avoid", "two_link_arm"): "arm-reach",
    ("reach_avoid", "unicycle"): "reach-unicycle",
    ("maze", None): "plan-hard",
    ("stl", "single_integrator"): "plan-stl",
}

_TASK_JSON = re.compile(r"## The task as data.*?```json\n(.*?)```", re.S)


@dataclass(frozen=True)
class ExpertAnswer:
    """What the expert says: text, or one tool call ``(name, arguments JSON)``."""

    content: str | None = None
    tool_call: tuple[str, str] | None = None


def choose_recipe(task: Any) -> Any:
    """The recipe an expert would follow for ``task``, by its kind and dynamics, or ``None``."""
    from audere import recipes

    scenario = _RULES.get((task.kind, task.dynamics))
    return None if scenario is None else recipes.get_recipe(scenario)


@functools.cache
def recipe_code(scenario: str) -> str:
    """The source of a recipe's module as stand-alone code that defines ``solve(task)``.

    The registration (``from audere.recipes import recipe`` and the ``@recipe(...)`` decorator) is
    removed; everything else (docstrings, comments, helpers) is kept as written.
    """
    from audere import recipes

    found = recipes.get_recipe(scenario)
    module = inspect.getmodule(found.function)
    source = inspect.getsource(module)  # type: ignore[arg-type]
    tree = ast.parse(source)
    drop: set[int] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module == "audere.recipes":
            drop.update(range(node.lineno, (node.end_lineno or node.lineno) + 1))
        if isinstance(node, ast.FunctionDef):
            for decorator in node.decorator_list:
                target = decorator.func if isinstance(decorator, ast.Call) else decorator
                if isinstance(target, ast.Name) and target.id == "recipe":
                    drop.update(range(decorator.lineno, (decorator.end_lineno or decorator.lineno) + 1))
    lines = [line for number, line in enumerate(source.splitlines(), start=1) if number not in drop]
    name = found.function.__name__
    entry = f"\n\ndef {_parse.ENTRY_POINT}(task):\n    return {name}(task)\n"
    return "\n".join(lines).rstrip() + "\n" + entry


def _plan(scenario: str, apis: Sequence[str]) -> str:
    from audere import recipes

    doc = inspect.getdoc(inspect.getmodule(recipes.get_recipe(scenario).function)) or ""
    return f"Follow the expert recipe for {scenario} with {', '.join(apis)}.\n\n{doc}".strip()


def _task_from(messages: Sequence[Mapping[str, Any]]) -> Any:
    from audere.tasks import parse_task

    for message in messages:
        found = _TASK_JSON.search(str(message.get("content") or ""))
        if found:
            return parse_task(found.group(1), format="json")
    return None


def _last_prompt(messages: Sequence[Mapping[str, Any]]) -> str:
    for message in reversed(messages):
        if message.get("role") in ("user", "tool"):
            return str(message.get("content") or "")
    return ""


def _method(messages: Sequence[Mapping[str, Any]]) -> str | None:
    system = str(messages[0].get("content") or "") if messages else ""
    for method in ("use_api", "code", "predict", "parse"):
        if system == render(f"system_{method}"):
            return method
    return None


def _offered(tools: Sequence[Mapping[str, Any]] | None) -> set[str]:
    return {str(t.get("function", {}).get("name")) for t in tools or ()}


def answer(messages: Sequence[Mapping[str, Any]], tools: Sequence[Mapping[str, Any]] | None) -> ExpertAnswer:
    """The expert's reply to the agent's conversation so far.

    Parameters
    ----------
    messages
        The chat messages (OpenAI format) the agent sent.
    tools
        The tools offered, if any: the expert answers with a tool call when one fits.

    Returns
    -------
    ExpertAnswer
        Text or one tool call.
    """
    method = _method(messages)
    offered = _offered(tools)
    if method == "parse":
        return ExpertAnswer(
            content="MISSING: task: the offline expert (a rule-based strategist, not a language model) "
            "cannot read free text. Give a Task, a scenario name or a task file, or choose a real model."
        )
    task = _task_from(messages)
    if method is None or task is None:
        return ExpertAnswer(content="The offline expert only answers audere's own prompts about a task.")
    prompt = _last_prompt(messages)
    if method == "use_api":
        return _use_api(task, prompt, offered)
    if method == "code":
        code = _heuristic_code(task)
        if "submit_code" in offered:
            return ExpertAnswer(
                tool_call=("submit_code", json.dumps({"plan": _HEURISTIC_PLAN, "code": code}))
            )
        return ExpertAnswer(content=f"{_HEURISTIC_PLAN}\n\n```python\n{code}```\n")
    fields = _heuristic_prediction(task)
    if "submit_solution" in offered:
        return ExpertAnswer(tool_call=("submit_solution", json.dumps(fields)))
    return ExpertAnswer(content=f"```json\n{json.dumps(fields)}\n```\n")


def _use_api(task: Any, prompt: str, offered: set[str]) -> ExpertAnswer:
    found = choose_recipe(task)
    if found is None:
        return ExpertAnswer(
            content=f"The offline expert has no rule for a {task.kind} task with dynamics {task.dynamics!r}."
        )
    apis = list(found.apis)
    if prompt.startswith("# Step 1"):
        reason = f"This is how an expert solves a {task.kind} task with {task.dynamics or 'a point robot'}."
        if "select_apis" in offered:
            return ExpertAnswer(tool_call=("select_apis", json.dumps({"apis": apis, "reason": reason})))
        return ExpertAnswer(content=f"APIs: {', '.join(apis)}\n{reason}\n")
    plan, code = _plan(found.scenario, apis), recipe_code(found.scenario)
    if "submit_code" in offered:
        return ExpertAnswer(tool_call=("submit_code", json.dumps({"plan": plan, "code": code})))
    return ExpertAnswer(content=f"{plan}\n\n```python\n{code}```\n")


_HEURISTIC_PLAN = (
    "Without planning APIs: feed-forward inputs along the reference, clipped to the bounds, for "
    "tracking; a straight line to the goal for paths; zero inputs otherwise."
)

_HEURISTIC_CODE = """\
import numpy as np
from audere.tasks import Solution


def solve(task):
    kinds = task.solution_kinds
    if "waypoints" in kinds:
        goal = np.asarray(getattr(task, "goal", task.x0), dtype=float)[:2]
        return Solution(waypoints=np.array([task.x0[:2], goal]))
    n_u = len(task.u_max) if task.u_max is not None else 1
    inputs = np.zeros((task.horizon, n_u))
    if task.kind == "tracking" and task.dynamics == "single_integrator":
        reference = np.asarray(task.reference, dtype=float)
        inputs = np.diff(reference[:, :n_u], axis=0) / task.dt
    if task.u_min is not None and task.u_max is not None:
        inputs = np.clip(inputs, task.u_min, task.u_max)
    return Solution(inputs=inputs)
"""


def _heuristic_code(task: Any) -> str:
    return _HEURISTIC_CODE


def _heuristic_prediction(task: Any) -> dict[str, Any]:
    namespace: dict[str, Any] = {}
    exec(compile(_HEURISTIC_CODE, "<expert heuristic>", "exec"), namespace)  # our own code, not a model's
    solution = namespace["solve"](task)
    return {name: np.round(array, 6).tolist() for name, array in solution.arrays().items()}


def respond(request: Any) -> Any:
    """The expert as an offline model: an ``OfflineRequest`` in, an ``OfflineReply`` out."""
    from audere.agent._offline import OfflineReply

    said = answer(request.messages, request.tools)
    if said.tool_call is not None:
        return OfflineReply(tool_calls=(said.tool_call,))
    return OfflineReply(content=said.content or "")
