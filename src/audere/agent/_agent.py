"""``Agent(task).solve()``: a model chooses among the APIs, writes the glue code, and repairs it."""

from __future__ import annotations

import asyncio
import atexit
import logging
import os
import sys
import threading
import time
from collections.abc import Callable, Generator
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

from audere.agent import _loop
from audere.agent._result import SolveResult, SolveStatus
from audere.agent.prompts import PROMPT_VERSION
from audere.errors import InvalidArgumentError

__all__ = ["DEFAULT_MODEL", "Agent", "Method", "SandboxSetup", "hidden_modules", "sandbox_setup"]

_log = logging.getLogger(__name__)

Method = Literal["use-api", "code", "predict"]
Provision = Literal["on-demand", "all"]

DEFAULT_MODEL = "audere/expert"
"""The model when none is given and ``AUDERE_MODEL`` is not set: the offline expert (not an LLM)."""

_METHODS: dict[str, str] = {"use-api": "use_api", "code": "code", "predict": "predict"}
_PROVISIONS = ("on-demand", "all")
_TASK_SUFFIXES = (".json", ".yaml", ".yml")
# the code baseline writes its own solver: the registry, planners and controllers are hidden from it
_CODE_HIDDEN = ("audere.apis", "audere.planners", "audere.controllers")

_executors: dict[SandboxSetup, Any] = {}
_executors_lock = threading.Lock()


def _shared_executor(setup: SandboxSetup) -> Any:
    """One warm sandbox per set-up, shared by every agent of this process."""
    from audere.agent.sandbox import SandboxExecutor

    with _executors_lock:
        executor = _executors.get(setup)
        if executor is None:
            executor = _executors[setup] = SandboxExecutor(
                hidden=setup.hidden, preload=setup.preload, paths=setup.paths
            )
            if len(_executors) == 1:
                atexit.register(_close_executors)
        return executor


@dataclass(frozen=True)
class SandboxSetup:
    """What the sandbox of a method imports, hides and may read."""

    hidden: tuple[str, ...]
    preload: tuple[str, ...]
    paths: tuple[str, ...]


def sandbox_setup(method: str) -> SandboxSetup:
    """The sandbox set-up for ``method``: audere's APIs, and the modules of APIs you registered.

    An API registered from a module file (``my_planners.py``, a package) is imported in the sandbox
    too, with the directory holding it readable there, so that the model's code can call it. An API
    defined in ``__main__`` (a script, a notebook cell) cannot be: it is left out, with a warning in
    the log.
    """
    from audere.agent.sandbox import DEFAULT_PRELOAD

    hidden = hidden_modules(method)
    if method.replace("-", "_") == "code":
        return SandboxSetup(hidden=hidden, preload=tuple(DEFAULT_PRELOAD), paths=())
    modules, paths = _user_api_modules()
    return SandboxSetup(hidden=hidden, preload=(*DEFAULT_PRELOAD, *modules), paths=paths)


def _user_api_modules() -> tuple[tuple[str, ...], tuple[str, ...]]:
    from audere.agent.sandbox._harden import broad_dirs
    from audere.apis import list_apis

    modules: list[str] = []
    paths: list[str] = []
    for info in list_apis():
        name = str(getattr(info.function, "__module__", "") or "")
        if name == "audere" or name.startswith("audere.") or name in modules:
            continue
        top = sys.modules.get(name.partition(".")[0])
        top_file = getattr(top, "__file__", None)
        if name == "__main__" or not top_file:
            _log.warning(
                "the API %r is defined in %s, which the sandbox cannot import; put it in a module file",
                info.name,
                name or "an unknown module",
            )
            continue
        location = Path(top_file).resolve()
        root = location.parent.parent if location.name == "__init__.py" else location.parent
        if str(root) in broad_dirs():
            _log.warning(
                "the API %r lives directly in %s, too broad a directory to expose to the sandbox; "
                "put its module in a directory of its own",
                info.name,
                root,
            )
            continue
        modules.append(name)
        paths.append(str(root))
    return tuple(modules), tuple(dict.fromkeys(paths))


def _close_executors() -> None:
    with _executors_lock:
        for executor in _executors.values():
            executor.close()
        _executors.clear()


def hidden_modules(method: str) -> tuple[str, ...]:
    """The modules the code of ``method`` (``"use_api"``, ``"code"``...) cannot import in the sandbox."""
    from audere.agent.sandbox import DEFAULT_HIDDEN

    return tuple(DEFAULT_HIDDEN) + (_CODE_HIDDEN if method.replace("-", "_") == "code" else ())


def _resolve_task(task: object, seed: int | None) -> tuple[Any, str | None]:
    """The task object (or ``None`` for free text) and the free text (or ``None``)."""
    from audere.tasks._models import _TaskBase

    if isinstance(task, _TaskBase):
        if seed is not None:
            raise InvalidArgumentError(
                f"seed: expected None with a Task (it is for scenario names), got {seed!r}"
            )
        return task, None
    if isinstance(task, os.PathLike):
        task = os.fspath(task)
    if not isinstance(task, str) or not task.strip():
        raise InvalidArgumentError(
            "task: expected a Task, a scenario name (with seed=), a task file or a description in words, "
            f"got {task!r}"
        )
    text = task.strip()
    from audere import scenarios

    names = {info.name for info in scenarios.list_scenarios()}
    name, _, rest = text.partition("/seed=")
    if name in names:
        if rest:
            if seed is not None:
                raise InvalidArgumentError(f"seed: given twice, in {text!r} and as seed={seed!r}")
            if not rest.isdigit():
                raise InvalidArgumentError(
                    f"task: expected '<scenario>/seed=<n>' with an integer n, got {text!r}"
                )
            seed = int(rest)
        if seed is None:
            raise InvalidArgumentError(f"seed: expected an integer seed for the scenario {name!r}, got None")
        return scenarios.make(name, seed), None
    if "\n" not in text and text.lower().endswith(_TASK_SUFFIXES):
        from audere.tasks import load_task

        if not Path(text).is_file():
            raise InvalidArgumentError(f"task: the task file {text!r} does not exist")
        return load_task(text), None
    if seed is not None:
        raise InvalidArgumentError(f"seed: expected None with a description in words, got {seed!r}")
    return None, text


def _positive_int(name: str, value: object) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < 1:
        raise InvalidArgumentError(f"{name}: expected a positive integer, got {value!r}")
    return value


class Agent:
    """Solve a robot planning or control task with a language model and audere's APIs.

    The model chooses among the registered APIs, reads the chosen APIs' documentation and source,
    writes the integration code, which runs in the sandbox (:mod:`audere.agent.sandbox`) with the
    task's data but not its checker; the task's checker judges the result, and on failure its
    bounded diagnostics go back to the model, for at most ``max_rounds`` rounds.

    Parameters
    ----------
    task
        A :class:`audere.tasks.Task`; a scenario name with ``seed`` (``"plan-easy", seed=3``, or
        ``"plan-easy/seed=3"``); the path of a task file (``.json``, ``.yaml``); or the task
        described in words, which the model first turns into a validated task.
    model
        A LiteLLM model string (``"gpt-4o"``, ``"anthropic/claude-sonnet-4-5"``, ``"ollama/llama3"``,
        ``"openai/<name>"`` with ``api_base`` for any OpenAI-compatible server) or an offline model
        (``"audere/expert"``, ``"audere/replay"`` with ``cassette``). Default: the environment
        variable ``AUDERE_MODEL``, else the offline expert, a rule-based strategist that is not an LLM.
    method
        ``"use-api"`` (the paper's LLM-use-API), ``"code"`` (the model writes the whole solver with
        numpy and scipy only) or ``"predict"`` (the model writes the solution down as numbers).
    max_rounds
        Most rounds of answer, run, check and feedback.
    temperature
        Sampling temperature, in [0, 2].
    api_provision
        ``"on-demand"``: the model sees the catalog, then the cards and source of the APIs it
        selects; ``"all"``: every API's card and source up front (the paper's ablation).
    timeout_s
        Wall-clock limit for each run of the model's code, seconds.
    seed
        The scenario seed, when ``task`` is a scenario name.
    model_seed
        Sampling seed passed to the model, where the provider supports one.
    tool_calls
        Answers as typed tool calls (``True``) or as plain text with fenced code and answer lines
        (``False``); ``None`` decides by whether LiteLLM says the model supports function calling.
    api_base, api_key
        Passed to LiteLLM (an OpenAI-compatible server, a key other than the environment's).
    max_retries
        Retries of a model call on rate limits, timeouts and provider errors, with backoff.
    record
        A cassette file to append every model call to (replay it with ``model="audere/replay"``).
    cassette
        The cassette to replay, with ``model="audere/replay"``.
    parse_attempts
        Attempts at turning a description in words into a valid task.
    max_apis
        Most APIs the model may select at once.
    executor
        The sandbox to run code in (any :class:`audere.agent.sandbox.Executor`); default: a warm
        :class:`~audere.agent.sandbox.SandboxExecutor` shared by the agents of this process.
    cache
        A response cache shared between runs (e.g. :class:`audere.bench.ResponseCache`): an identical
        request is answered from it and never sent (paid for) twice.
    on_event
        Called with an :class:`audere.agent.Event` after every model call, every round, and once the
        task is known (for progress displays).

    Examples
    --------
    >>> from audere.agent import Agent
    >>> result = Agent("plan-easy", seed=3).solve()  # doctest: +SKIP
    >>> result.success, result.selected_apis, result.apis_called  # doctest: +SKIP
    (True, ['rrt'], ['rrt'])
    """

    def __init__(
        self,
        task: object,
        *,
        model: str | None = None,
        method: Method = "use-api",
        max_rounds: int = 6,
        temperature: float = 0.1,
        api_provision: Provision = "on-demand",
        timeout_s: float = 30.0,
        seed: int | None = None,
        model_seed: int | None = None,
        tool_calls: bool | None = None,
        api_base: str | None = None,
        api_key: str | None = None,
        max_retries: int = 3,
        record: str | os.PathLike[str] | None = None,
        cassette: str | os.PathLike[str] | None = None,
        parse_attempts: int = 3,
        max_apis: int = 3,
        executor: Any = None,
        cache: Any = None,
        on_event: Callable[[_loop.Event], None] | None = None,
    ) -> None:
        if method not in _METHODS:
            raise InvalidArgumentError(f"method: expected one of {list(_METHODS)}, got {method!r}")
        if api_provision not in _PROVISIONS:
            raise InvalidArgumentError(
                f"api_provision: expected one of {list(_PROVISIONS)}, got {api_provision!r}"
            )
        self.max_rounds = _positive_int("max_rounds", max_rounds)
        self.parse_attempts = _positive_int("parse_attempts", parse_attempts)
        self.max_apis = _positive_int("max_apis", max_apis)
        if isinstance(timeout_s, bool) or not isinstance(timeout_s, int | float) or not 0 < timeout_s < 1e6:
            raise InvalidArgumentError(f"timeout_s: expected a positive number of seconds, got {timeout_s!r}")
        if tool_calls is not None and not isinstance(tool_calls, bool):
            raise InvalidArgumentError(f"tool_calls: expected True, False or None, got {tool_calls!r}")
        if executor is not None and not callable(getattr(executor, "run", None)):
            raise InvalidArgumentError(
                f"executor: expected an Executor (with run()), got {type(executor).__name__}"
            )
        if on_event is not None and not callable(on_event):
            raise InvalidArgumentError(f"on_event: expected a callable or None, got {on_event!r}")
        from audere.agent._llm import ModelClient

        self.method: Method = method
        self.api_provision: Provision = api_provision
        self.timeout_s = float(timeout_s)
        self.model = model or os.environ.get("AUDERE_MODEL") or DEFAULT_MODEL
        self._client = ModelClient(
            self.model,
            temperature=temperature,
            seed=model_seed,
            api_base=api_base,
            api_key=api_key,
            max_retries=max_retries,
            record=record,
            cassette=cassette,
            cache=cache,
        )
        self.temperature = float(temperature)
        self._task, self.task_text = _resolve_task(task, seed)
        self._tool_calls = tool_calls
        self._executor = executor
        self._on_event = on_event

    # --- what it is working on --------------------------------------------------------------------

    @property
    def task(self) -> Any:
        """The task: as given, or as parsed from the text (``None`` until a text has been parsed)."""
        return self._task

    @property
    def model_label(self) -> str:
        """The model, for people (the offline expert says it is not an LLM)."""
        return str(self._client.label)

    @property
    def tool_mode(self) -> bool:
        """Whether answers come as typed tool calls."""
        return bool(self._client.supports_tools) if self._tool_calls is None else self._tool_calls

    def __repr__(self) -> str:
        what = self._task.name if self._task is not None else f"text ({len(self.task_text or '')} chars)"
        return f"Agent({what!r}, model={self.model!r}, method={self.method!r}, max_rounds={self.max_rounds})"

    # --- solving ------------------------------------------------------------------------------------

    def solve(self) -> SolveResult:
        """Run the loop until the checker accepts a solution or ``max_rounds`` are used.

        Returns
        -------
        SolveResult
            The verdict, the final solution and report, and every round. Never raises for what the
            model or its code does; a provider failing after retries ends with ``model_error``.
        """
        steps = self._steps()
        value: Any = None
        while True:
            try:
                effect = steps.send(value)
            except StopIteration as stop:
                result: SolveResult = stop.value
                return result
            value = self._do(effect)

    async def asolve(self) -> SolveResult:
        """:meth:`solve` for asyncio: model calls are awaited, the sandbox runs in a worker thread."""
        steps = self._steps()
        value: Any = None
        while True:
            try:
                effect = steps.send(value)
            except StopIteration as stop:
                result: SolveResult = stop.value
                return result
            value = await self._ado(effect)

    def _do(self, effect: Any) -> Any:
        from audere.agent._llm import ModelError

        if isinstance(effect, _loop.CallModel):
            try:
                return self._client.complete(effect.messages, tools=effect.tools)
            except ModelError as error:
                return error
        return self._executor_for(effect.method).run(
            effect.code, inputs=effect.inputs, timeout_s=effect.timeout_s
        )

    async def _ado(self, effect: Any) -> Any:
        from audere.agent._llm import ModelError

        if isinstance(effect, _loop.CallModel):
            try:
                return await self._client.acomplete(effect.messages, tools=effect.tools)
            except ModelError as error:
                return error
        executor = self._executor_for(effect.method)
        return await asyncio.to_thread(
            executor.run, effect.code, inputs=effect.inputs, timeout_s=effect.timeout_s
        )

    def _executor_for(self, method: str) -> Any:
        if self._executor is not None:
            return self._executor
        return _shared_executor(sandbox_setup(method))

    def _steps(self) -> Generator[Any, Any, SolveResult]:
        started = time.monotonic()
        tool_mode = self.tool_mode
        parse_calls: list[Any] = []
        if self._task is None:
            text = self.task_text or ""
            task, parse_calls, message = yield from _loop.parse_loop(
                text, attempts=self.parse_attempts, tool_mode=tool_mode, on_event=self._on_event
            )
            if task is None:
                status: SolveStatus = "model_error" if "model failed" in message else "invalid_task"
                return self._result(status, message, None, parse_calls, [], started, tool_mode)
            self._task = task
        if self._on_event is not None:
            self._on_event(_loop.Event(kind="task", task=self._task))
        from audere.apis import list_apis

        config = _loop.LoopConfig(
            method=_METHODS[self.method],
            max_rounds=self.max_rounds,
            api_provision=self.api_provision,
            timeout_s=self.timeout_s,
            tool_mode=tool_mode,
            max_apis=self.max_apis,
            on_event=self._on_event,
            api_names=tuple(info.name for info in list_apis()),
        )
        rounds, model_failed = yield from _loop.solve_loop(self._task, config)
        last = rounds[-1] if rounds else None
        if last is not None and last.category.value == "success":
            status, message = "solved", f"solved in round {last.index}"
        elif model_failed:
            status, message = "model_error", f"the model provider failed: {last.feedback if last else ''}"
        else:
            what = last.category.value.replace("_", " ") if last else "no round"
            status, message = "failed", f"not solved in {len(rounds)} round(s); last outcome: {what}"
        return self._result(status, message, self._task, parse_calls, rounds, started, tool_mode)

    def _result(
        self,
        status: SolveStatus,
        message: str,
        task: Any,
        parse_calls: list[Any],
        rounds: list[Any],
        started: float,
        tool_mode: bool,
    ) -> SolveResult:
        last = rounds[-1] if rounds else None
        solved = status == "solved" and last is not None
        return SolveResult(
            status=status,
            message=message,
            task=task,
            task_text=self.task_text,
            method=self.method,
            model=self.model,
            model_label=self.model_label,
            temperature=self.temperature,
            api_provision=self.api_provision,
            max_rounds=self.max_rounds,
            prompt_version=PROMPT_VERSION,
            tool_calls=tool_mode,
            parse_calls=parse_calls,
            rounds=rounds,
            solution=last.solution if solved and last is not None else None,
            report=last.report if last is not None else None,
            wall_s=time.monotonic() - started,
        )
