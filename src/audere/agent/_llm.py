"""Model access: one client for every language model, real or offline, through LiteLLM.

:class:`ModelClient` sends chat requests with :func:`litellm.completion` (or
:func:`litellm.acompletion`), retries transient provider trouble with exponential backoff, and
returns a :class:`Reply` carrying the text, the tool calls, the token counts, the cost and the
latency. Offline models (``"audere/<name>"``, see :mod:`audere.agent._offline`) go through the very
same LiteLLM code path as a hosted model, so that tests exercise what production runs.

LiteLLM is imported on first use, never by ``import audere.agent``.
"""

from __future__ import annotations

import asyncio
import json
import logging
import math
import os
import random
import threading
import time
from collections.abc import Awaitable, Callable, Mapping
from dataclasses import dataclass
from types import ModuleType
from typing import Any, Final, Literal, Protocol, cast, get_args

from audere.errors import AudereError, InvalidArgumentError

__all__ = [
    "MODEL_ERROR_KINDS",
    "ErrorKind",
    "ModelClient",
    "ModelError",
    "Reply",
    "ToolCall",
]

_log = logging.getLogger(__name__)

ErrorKind = Literal[
    "rate_limit", "timeout", "connection", "server", "auth", "bad_request", "not_found", "other"
]
"""What went wrong with a model call (the ``kind`` of a :class:`ModelError`)."""

MODEL_ERROR_KINDS: Final[tuple[str, ...]] = get_args(ErrorKind)
"""Every :data:`ErrorKind`, in a fixed order."""

RETRYABLE_KINDS: Final[frozenset[str]] = frozenset({"rate_limit", "timeout", "connection", "server"})
"""The kinds of trouble :class:`ModelClient` retries; the others are raised at once."""

OFFLINE_PREFIX: Final = "audere/"
REPLAY_MODEL: Final = "audere/replay"
EXPERT_MODEL: Final = "audere/expert"

# Keys the client passes to the offline provider in LiteLLM's ``metadata`` (never sent to a hosted model).
METADATA_REQUEST_KEY: Final = "audere_request_key"
METADATA_CASSETTE: Final = "audere_cassette"
# Where the offline provider puts a replayed reply's recorded cost, in the response's ``_hidden_params``.
HIDDEN_COST: Final = "audere_cost"

_JITTER: Final = 0.1  # backoff jitter, as a fraction of backoff_s


# --------------------------------------------------------------------------------------------------
# Replies and errors
# --------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class ToolCall:
    """One tool call a model asked for.

    Parameters
    ----------
    id
        The call's id, given back in the ``tool`` message that answers it.
    name
        The tool (function) name.
    arguments
        The arguments exactly as the model wrote them: JSON text, not parsed (a model may write
        invalid JSON, which is the caller's to diagnose).
    """

    id: str
    name: str
    arguments: str

    def to_dict(self) -> dict[str, str]:
        """Return the call as a JSON-ready dictionary.

        Returns
        -------
        dict
            ``{"id": ..., "name": ..., "arguments": ...}``.
        """
        return {"id": self.id, "name": self.name, "arguments": self.arguments}

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> ToolCall:
        """Build a call from :meth:`to_dict`'s output.

        Parameters
        ----------
        data
            The dictionary.

        Returns
        -------
        ToolCall
            The call.

        Raises
        ------
        InvalidArgumentError
            If a field is missing or not a string.
        """
        if not isinstance(data, Mapping):
            raise InvalidArgumentError(f"tool call: expected a mapping, got {type(data).__name__}")
        values = {}
        for name in ("id", "name", "arguments"):
            value = data.get(name)
            if not isinstance(value, str):
                raise InvalidArgumentError(f"tool call {name}: expected a string, got {value!r}")
            values[name] = value
        return cls(**values)


@dataclass(frozen=True)
class Reply:
    """A model's answer to one request, with what it cost.

    Parameters
    ----------
    content
        The reply text; an empty string when the model wrote none (e.g. only tool calls).
    tool_calls
        The tool calls, in the order the model wrote them.
    prompt_tokens, completion_tokens
        Token counts as the provider reported them (offline models may estimate them, see
        :class:`audere.agent._offline.OfflineReply`).
    cost
        The cost in US dollars, from LiteLLM's price table; None when LiteLLM does not know the
        model's price (offline models, local servers). A replayed reply keeps its recorded cost.
    latency_s
        Wall-clock seconds from the call to the reply, retries and backoff included.
    model
        The model string the client called (``"audere/replay"`` for a replay).
    finish_reason
        Why the model stopped: ``"stop"``, ``"tool_calls"``, ``"length"``...
    attempts
        1 plus the number of retries used.
    """

    content: str
    tool_calls: tuple[ToolCall, ...]
    prompt_tokens: int
    completion_tokens: int
    cost: float | None
    latency_s: float
    model: str
    finish_reason: str
    attempts: int = 1

    def to_dict(self) -> dict[str, Any]:
        """Return the reply as a JSON-ready dictionary.

        Returns
        -------
        dict
            Every field; ``tool_calls`` as a list of :meth:`ToolCall.to_dict` dictionaries.
        """
        return {
            "content": self.content,
            "tool_calls": [call.to_dict() for call in self.tool_calls],
            "prompt_tokens": self.prompt_tokens,
            "completion_tokens": self.completion_tokens,
            "cost": self.cost,
            "latency_s": self.latency_s,
            "model": self.model,
            "finish_reason": self.finish_reason,
            "attempts": self.attempts,
        }

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> Reply:
        """Build a reply from :meth:`to_dict`'s output.

        Parameters
        ----------
        data
            The dictionary (e.g. read back from JSON).

        Returns
        -------
        Reply
            The reply.

        Raises
        ------
        InvalidArgumentError
            If a field is missing or has the wrong type; the message names the field.
        """
        if not isinstance(data, Mapping):
            raise InvalidArgumentError(f"reply: expected a mapping, got {type(data).__name__}")

        def text(name: str) -> str:
            value = data.get(name)
            if not isinstance(value, str):
                raise InvalidArgumentError(f"reply {name}: expected a string, got {value!r}")
            return value

        def count(name: str) -> int:
            value = data.get(name)
            if isinstance(value, bool) or not isinstance(value, int) or value < 0:
                raise InvalidArgumentError(f"reply {name}: expected an integer >= 0, got {value!r}")
            return value

        def number(name: str, *, optional: bool) -> float | None:
            value = data.get(name)
            if value is None and optional:
                return None
            if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
                expected = "a finite number or null" if optional else "a finite number"
                raise InvalidArgumentError(f"reply {name}: expected {expected}, got {value!r}")
            return float(value)

        calls = data.get("tool_calls")
        if not isinstance(calls, list | tuple):
            raise InvalidArgumentError(f"reply tool_calls: expected a list, got {calls!r}")
        attempts = count("attempts")
        if attempts < 1:
            raise InvalidArgumentError(f"reply attempts: expected an integer >= 1, got {attempts}")
        latency = number("latency_s", optional=False)
        return cls(
            content=text("content"),
            tool_calls=tuple(ToolCall.from_dict(call) for call in calls),
            prompt_tokens=count("prompt_tokens"),
            completion_tokens=count("completion_tokens"),
            cost=number("cost", optional=True),
            latency_s=0.0 if latency is None else latency,
            model=text("model"),
            finish_reason=text("finish_reason"),
            attempts=attempts,
        )


class ModelError(AudereError):
    """A model call failed: retries exhausted, or an error not worth retrying.

    Parameters
    ----------
    message
        What happened; names the model and carries the provider's message.
    kind
        One of :data:`MODEL_ERROR_KINDS`: ``"rate_limit"``, ``"timeout"``, ``"connection"``,
        ``"server"`` (these four are retried first), ``"auth"``, ``"bad_request"``, ``"not_found"``,
        ``"other"``.
    attempts
        How many calls were made (1 plus the retries).
    model
        The model string called.
    """

    def __init__(self, message: str, *, kind: ErrorKind, attempts: int, model: str) -> None:
        super().__init__(message)
        self.kind: ErrorKind = kind
        self.attempts = attempts
        self.model = model


# --------------------------------------------------------------------------------------------------
# LiteLLM, lazily
# --------------------------------------------------------------------------------------------------

_setup_lock = threading.Lock()
_litellm_module: ModuleType | None = None


def _litellm() -> ModuleType:
    """Import and configure LiteLLM once, with the offline provider registered; return the module.

    The provider entry is checked on every call (a scan of a short list), so that code replacing
    ``litellm.custom_provider_map`` wholesale does not lose the offline models.
    """
    global _litellm_module
    from audere.agent import _offline

    if _litellm_module is None:
        with _setup_lock:
            if _litellm_module is None:
                # Without this, importing litellm fetches its model price map from the network.
                os.environ.setdefault("LITELLM_LOCAL_MODEL_COST_MAP", "True")
                import litellm

                litellm.suppress_debug_info = True  # no "Give Feedback / Get Help" banners on stdout
                _litellm_module = litellm
    _offline._install(_litellm_module)
    return _litellm_module


def _classify(exc: BaseException, litellm: ModuleType) -> ErrorKind:
    """Map an exception raised by ``litellm.completion`` to an :data:`ErrorKind`."""
    # Order matters: several classes derive from one another through their openai bases.
    table: tuple[tuple[str, ErrorKind], ...] = (
        ("RateLimitError", "rate_limit"),
        ("Timeout", "timeout"),
        ("APIConnectionError", "connection"),
        ("ServiceUnavailableError", "server"),
        ("InternalServerError", "server"),
        ("BadGatewayError", "server"),
        ("AuthenticationError", "auth"),
        ("PermissionDeniedError", "auth"),
        ("NotFoundError", "not_found"),
        ("BadRequestError", "bad_request"),  # ContextWindowExceededError, ContentPolicyViolationError...
        ("UnprocessableEntityError", "bad_request"),
    )
    for name, kind in table:
        cls = getattr(litellm, name, None)
        if isinstance(cls, type) and isinstance(exc, cls):
            return kind
    if isinstance(exc, litellm.APIError):
        status = getattr(exc, "status_code", None)
        if isinstance(status, int):
            if status == 429:
                return "rate_limit"
            if status == 408:
                return "timeout"
            if status >= 500:
                return "server"
    return "other"


def _response_cost(response: Any, model: str, litellm: ModuleType) -> float | None:
    """The cost of ``response`` in US dollars, or None when unknown. Never raises."""
    hidden = getattr(response, "_hidden_params", None) or {}
    if model.startswith(OFFLINE_PREFIX):
        recorded = hidden.get(HIDDEN_COST)
        return float(recorded) if isinstance(recorded, int | float) else None
    computed = hidden.get("response_cost")
    if isinstance(computed, int | float) and not isinstance(computed, bool):
        return float(computed)
    try:
        cost: object = litellm.completion_cost(completion_response=response)
    except Exception as exc:  # LiteLLM raises for models missing from its price table
        _log.debug("no cost for model %s: %s", model, exc)
        return None
    return float(cost) if isinstance(cost, int | float) and math.isfinite(cost) else None


def _field(obj: Any, name: str) -> Any:
    """``obj.name`` or ``obj[name]``: LiteLLM objects allow both, but be safe with plain dicts."""
    if isinstance(obj, Mapping):
        return obj.get(name)
    return getattr(obj, name, None)


# --------------------------------------------------------------------------------------------------
# The client
# --------------------------------------------------------------------------------------------------


def _check_number(name: str, value: object, *, low: float, high: float | None, low_open: bool) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        ok = False
    else:
        ok = (value > low if low_open else value >= low) and (high is None or value <= high)
    if not ok:
        if high is None:
            expected = f"a finite number {'>' if low_open else '>='} {low:g}"
        else:
            expected = f"a number in [{low:g}, {high:g}]"
        raise InvalidArgumentError(f"{name}: expected {expected}, got {value!r}")
    return float(cast(float, value))


def _check_optional_text(name: str, value: object, *, secret: bool = False) -> str | None:
    if value is None:
        return None
    if not isinstance(value, str) or not value.strip():
        if isinstance(value, str):
            shown = repr(value)  # blank: nothing secret to hide
        else:
            shown = f"a value of type {type(value).__name__}" if secret else repr(value)
        raise InvalidArgumentError(f"{name}: expected a non-empty string or None, got {shown}")
    return value


def _check_path(name: str, value: object) -> str | None:
    if value is None:
        return None
    if not isinstance(value, str | os.PathLike) or not os.fspath(value):
        raise InvalidArgumentError(f"{name}: expected a file path or None, got {value!r}")
    path = os.fspath(value)
    if not isinstance(path, str):
        raise InvalidArgumentError(f"{name}: expected a text file path, got bytes {path!r}")
    return path


class ResponseCacheLike(Protocol):
    """What :class:`ModelClient` needs of a response cache."""

    def get(self, key: str) -> Reply | None:
        """The reply stored under ``key``, or None."""
        ...

    def put(self, key: str, model: str, request: dict[str, Any], reply: Reply) -> None:
        """Store ``reply`` under ``key``."""
        ...


class ModelClient:
    """Send chat requests to one model through LiteLLM, with retries, metrics, record and replay.

    Parameters
    ----------
    model
        A LiteLLM model string (``"gpt-4o"``, ``"anthropic/claude-3-5-sonnet-20241022"``,
        ``"ollama/llama3"``...) or an offline model ``"audere/<name>"``: ``"audere/expert"``,
        a model registered with :func:`audere.agent._offline.register_model` (such as a
        :class:`~audere.agent._offline.ScriptedModel`), or ``"audere/replay"`` with ``cassette``.
    temperature
        Sampling temperature, in [0, 2].
    seed
        Sampling seed passed to providers that accept one; None passes none.
    api_base, api_key
        Endpoint and key for the provider, when not taken from the environment.
    max_retries
        Retries after the first call on rate limits, timeouts, connection and server errors.
    timeout_s
        Per-call timeout in seconds, passed to LiteLLM.
    backoff_s
        Base delay: retry ``k`` (from 0) waits ``backoff_s * 2**k`` seconds plus up to 10 % jitter.
    record
        A cassette file: every successful request and reply is appended to it (created if missing).
    cassette
        A cassette file to answer from; only with ``model="audere/replay"``, which needs one.
    cache
        A response cache (any object with ``get(key) -> Reply | None`` and
        ``put(key, model, request, reply)``, such as :class:`audere.bench.ResponseCache`): a request
        whose key it holds is answered from it, never sent again; every new reply is put in it.

    Attributes
    ----------
    sleep
        The function :meth:`complete` waits with between retries (default :func:`time.sleep`);
        tests replace it so as not to wait.
    async_sleep
        The coroutine function :meth:`acomplete` waits with (default :func:`asyncio.sleep`).

    Raises
    ------
    InvalidArgumentError
        If an argument is invalid; the message names it, the expectation and the value.
    audere.agent._cassette.CassetteError
        If ``cassette`` cannot be read or is not a valid cassette.

    Examples
    --------
    >>> from audere.agent._llm import ModelClient
    >>> client = ModelClient("audere/expert")
    >>> client.label
    'audere/expert (offline rule-based expert, not an LLM)'
    """

    def __init__(
        self,
        model: str,
        *,
        temperature: float = 0.1,
        seed: int | None = None,
        api_base: str | None = None,
        api_key: str | None = None,
        max_retries: int = 3,
        timeout_s: float = 120.0,
        backoff_s: float = 1.0,
        record: str | os.PathLike[str] | None = None,
        cassette: str | os.PathLike[str] | None = None,
        cache: ResponseCacheLike | None = None,
    ) -> None:
        if not isinstance(model, str) or not model.strip():
            raise InvalidArgumentError(f"model: expected a non-empty model string, got {model!r}")
        if model != model.strip():
            raise InvalidArgumentError(f"model: expected no leading or trailing spaces, got {model!r}")
        if model.startswith(OFFLINE_PREFIX):
            from audere.agent._offline import check_model_name

            check_model_name(model.removeprefix(OFFLINE_PREFIX), argument="model", allow_reserved=True)
        self._temperature = _check_number("temperature", temperature, low=0.0, high=2.0, low_open=False)
        if seed is not None and (isinstance(seed, bool) or not isinstance(seed, int)):
            raise InvalidArgumentError(f"seed: expected an integer or None, got {seed!r}")
        self._api_base = _check_optional_text("api_base", api_base)
        self._api_key = _check_optional_text("api_key", api_key, secret=True)
        if isinstance(max_retries, bool) or not isinstance(max_retries, int) or max_retries < 0:
            raise InvalidArgumentError(f"max_retries: expected an integer >= 0, got {max_retries!r}")
        self._timeout_s = _check_number("timeout_s", timeout_s, low=0.0, high=None, low_open=True)
        self._backoff_s = _check_number("backoff_s", backoff_s, low=0.0, high=None, low_open=False)
        self._record = _check_path("record", record)
        self._cassette = _check_path("cassette", cassette)
        if self._cassette is not None and model != REPLAY_MODEL:
            raise InvalidArgumentError(
                f"cassette: expected only with model {REPLAY_MODEL!r} (which replays it), "
                f"got it with {model!r}"
            )
        if model == REPLAY_MODEL and self._cassette is None:
            raise InvalidArgumentError(
                f"cassette: expected a cassette file to replay with {model!r}, got None"
            )
        if model == REPLAY_MODEL and self._record is not None:
            raise InvalidArgumentError(
                f"record: expected None with {model!r} (a replay would copy the cassette), "
                f"got {self._record!r}"
            )
        if cache is not None and not (
            callable(getattr(cache, "get", None)) and callable(getattr(cache, "put", None))
        ):
            raise InvalidArgumentError(
                f"cache: expected an object with get() and put(), got {type(cache).__name__}"
            )
        self._cache = cache
        self._model = model
        self._seed = seed
        self._max_retries = max_retries
        if self._cassette is not None:
            from audere.agent._cassette import use_cassette

            self._cassette = use_cassette(self._cassette).path
        self.sleep: Callable[[float], object] = time.sleep
        self.async_sleep: Callable[[float], Awaitable[object]] = asyncio.sleep
        self._rng = random.Random()

    # -- properties -------------------------------------------------------------------------------

    @property
    def model(self) -> str:
        """The model string."""
        return self._model

    @property
    def temperature(self) -> float:
        """The sampling temperature."""
        return self._temperature

    @property
    def seed(self) -> int | None:
        """The sampling seed, or None."""
        return self._seed

    @property
    def max_retries(self) -> int:
        """Retries after the first call on transient errors."""
        return self._max_retries

    @property
    def record(self) -> str | None:
        """The cassette file replies are recorded to, or None."""
        return self._record

    @property
    def cassette(self) -> str | None:
        """The cassette file replies are replayed from, or None."""
        return self._cassette

    @property
    def supports_tools(self) -> bool:
        """Whether the model accepts tool (function) definitions.

        True for offline ``audere/...`` models; otherwise LiteLLM's model table decides, and a model
        it does not know counts as not supporting tools.
        """
        if self._model.startswith(OFFLINE_PREFIX):
            return True
        litellm = _litellm()
        try:
            return bool(litellm.supports_function_calling(self._model))
        except Exception as exc:  # unknown model or provider
            _log.debug("supports_function_calling(%s) failed: %s", self._model, exc)
            return False

    @property
    def label(self) -> str:
        """A human label for reports: the model string, and what it is when that is not obvious."""
        if self._model == EXPERT_MODEL:
            return f"{EXPERT_MODEL} (offline rule-based expert, not an LLM)"
        if self._model == REPLAY_MODEL:
            return f"{REPLAY_MODEL} (replay of recorded replies from {self._cassette})"
        if self._model.startswith(OFFLINE_PREFIX):
            return f"{self._model} (offline scripted model, not an LLM)"
        return self._model

    def __repr__(self) -> str:
        return f"ModelClient({self._model!r}, temperature={self._temperature:g}, seed={self._seed!r})"

    # -- calls ------------------------------------------------------------------------------------

    def complete(
        self,
        messages: list[dict[str, Any]],
        *,
        tools: list[dict[str, Any]] | None = None,
        tool_choice: str | None = None,
    ) -> Reply:
        """Send one chat request and return the model's reply.

        Parameters
        ----------
        messages
            The conversation, as OpenAI-style message dictionaries (``{"role": ..., "content": ...}``).
        tools
            OpenAI-style tool definitions (``{"type": "function", "function": {...}}``), or None.
        tool_choice
            ``"auto"``, ``"none"`` or ``"required"``, or None to leave the provider's default.

        Returns
        -------
        Reply
            The reply, with tokens, cost, latency and the number of attempts.

        Raises
        ------
        InvalidArgumentError
            If ``messages``, ``tools`` or ``tool_choice`` is malformed.
        ModelError
            When retries are exhausted or the error is not worth retrying (authentication, bad
            request, unknown model...).
        """
        litellm = _litellm()
        kwargs, recording = self._request(messages, tools, tool_choice)
        cached = self._cached(recording)
        if cached is not None:
            return cached
        start = time.perf_counter()
        attempt = 0
        while True:
            attempt += 1
            try:
                response = litellm.completion(**kwargs)
            except Exception as exc:
                delay = self._after_failure(exc, attempt, litellm)
                self.sleep(delay)
                continue
            return self._finish(response, recording, attempt, start, litellm)

    async def acomplete(
        self,
        messages: list[dict[str, Any]],
        *,
        tools: list[dict[str, Any]] | None = None,
        tool_choice: str | None = None,
    ) -> Reply:
        """Send one chat request without blocking the event loop; see :meth:`complete`.

        Parameters
        ----------
        messages
            The conversation, as OpenAI-style message dictionaries.
        tools
            OpenAI-style tool definitions, or None.
        tool_choice
            ``"auto"``, ``"none"`` or ``"required"``, or None.

        Returns
        -------
        Reply
            The reply.

        Raises
        ------
        InvalidArgumentError
            If ``messages``, ``tools`` or ``tool_choice`` is malformed.
        ModelError
            When retries are exhausted or the error is not worth retrying.
        """
        litellm = _litellm()
        kwargs, recording = self._request(messages, tools, tool_choice)
        cached = self._cached(recording)
        if cached is not None:
            return cached
        start = time.perf_counter()
        attempt = 0
        while True:
            attempt += 1
            try:
                response = await litellm.acompletion(**kwargs)
            except Exception as exc:
                delay = self._after_failure(exc, attempt, litellm)
                await self.async_sleep(delay)
                continue
            return self._finish(response, recording, attempt, start, litellm)

    # -- internals --------------------------------------------------------------------------------

    def _request(
        self,
        messages: list[dict[str, Any]],
        tools: list[dict[str, Any]] | None,
        tool_choice: str | None,
    ) -> tuple[dict[str, Any], tuple[str, dict[str, Any]] | None]:
        """Validate a request; return the keyword arguments for ``litellm.completion`` and what to record.

        What to record is ``(key, request)``, the request copied now (the caller may go on changing
        its message list while the call runs), or None when the client does not record.
        """
        if not isinstance(messages, list) or not messages:
            raise InvalidArgumentError(
                f"messages: expected a non-empty list of message dicts, got {messages!r}"
            )
        for index, message in enumerate(messages):
            if not isinstance(message, dict) or not isinstance(message.get("role"), str):
                raise InvalidArgumentError(
                    f"messages[{index}]: expected a dict with a string 'role', got {message!r}"
                )
        if tools is not None:
            if not isinstance(tools, list):
                raise InvalidArgumentError(f"tools: expected a list of tool dicts or None, got {tools!r}")
            for index, tool in enumerate(tools):
                if not isinstance(tool, dict):
                    raise InvalidArgumentError(f"tools[{index}]: expected a tool dict, got {tool!r}")
        if tool_choice is not None and (not isinstance(tool_choice, str) or not tool_choice):
            raise InvalidArgumentError(
                f"tool_choice: expected a non-empty string or None, got {tool_choice!r}"
            )
        if tool_choice is not None and not tools:
            raise InvalidArgumentError(
                f"tool_choice: expected tools to choose from, got {tool_choice!r} and no tools"
            )
        kwargs: dict[str, Any] = {
            "model": self._model,
            "messages": messages,
            "temperature": self._temperature,
            "timeout": self._timeout_s,
            # We retry ourselves; 0 also turns off the provider SDK's own hidden retries.
            "num_retries": 0,
        }
        if self._seed is not None:
            kwargs["seed"] = self._seed
        if self._api_base is not None:
            kwargs["api_base"] = self._api_base
        if self._api_key is not None:
            kwargs["api_key"] = self._api_key
        if tools is not None:
            kwargs["tools"] = tools
        if tool_choice is not None:
            kwargs["tool_choice"] = tool_choice
        if self._model == REPLAY_MODEL or self._record is not None or self._cache is not None:
            from audere.agent._cassette import request_key

            try:
                key = request_key(messages, tools, self._temperature, self._seed)
            except (TypeError, ValueError) as exc:
                raise InvalidArgumentError(
                    f"messages: expected JSON-serializable messages and tools to record or replay, got {exc}"
                ) from exc
            if self._model == REPLAY_MODEL:
                # LiteLLM rewrites messages on the way (it drops ``"content": None``, for one), so the
                # provider is given the key computed here, from the messages exactly as recorded.
                kwargs["metadata"] = {METADATA_REQUEST_KEY: key, METADATA_CASSETTE: self._cassette}
                return kwargs, None
            request = {
                "messages": messages,
                "tools": tools,
                "temperature": self._temperature,
                "seed": self._seed,
            }
            return kwargs, (key, json.loads(json.dumps(request)))
        return kwargs, None

    def _after_failure(self, exc: Exception, attempt: int, litellm: ModuleType) -> float:
        """Raise :class:`ModelError` unless ``exc`` is retryable and retries remain; else return the delay."""
        kind = _classify(exc, litellm)
        if kind not in RETRYABLE_KINDS or attempt > self._max_retries:
            why = "not retried" if kind not in RETRYABLE_KINDS else "retries exhausted"
            raise ModelError(
                f"model {self._model!r}: {kind} error after {attempt} attempt(s) ({why}): {exc}",
                kind=kind,
                attempts=attempt,
                model=self._model,
            ) from exc
        delay = self._backoff_s * 2.0 ** (attempt - 1)
        delay += self._rng.uniform(0.0, _JITTER * self._backoff_s)
        _log.debug(
            "model %s: %s error on attempt %d, retrying in %.2f s: %s", self._model, kind, attempt, delay, exc
        )
        return delay

    def _finish(
        self,
        response: Any,
        recording: tuple[str, dict[str, Any]] | None,
        attempts: int,
        start: float,
        litellm: ModuleType,
    ) -> Reply:
        """Turn a LiteLLM response into a :class:`Reply`, and record it when asked to."""
        latency = time.perf_counter() - start
        choices = _field(response, "choices") or []
        if not choices:
            raise ModelError(
                f"model {self._model!r}: other error: the response has no choices: {response!r}",
                kind="other",
                attempts=attempts,
                model=self._model,
            )
        choice = choices[0]
        message = _field(choice, "message")
        calls = []
        for call in _field(message, "tool_calls") or ():
            function = _field(call, "function")
            calls.append(
                ToolCall(
                    id=str(_field(call, "id") or ""),
                    name=str(_field(function, "name") or ""),
                    arguments=str(_field(function, "arguments") or ""),
                )
            )
        usage = _field(response, "usage")
        prompt_tokens = _field(usage, "prompt_tokens") if usage is not None else None
        completion_tokens = _field(usage, "completion_tokens") if usage is not None else None
        reply = Reply(
            content=str(_field(message, "content") or ""),
            tool_calls=tuple(calls),
            prompt_tokens=int(prompt_tokens or 0),
            completion_tokens=int(completion_tokens or 0),
            cost=_response_cost(response, self._model, litellm),
            latency_s=latency,
            model=self._model,
            finish_reason=str(_field(choice, "finish_reason") or ("tool_calls" if calls else "stop")),
            attempts=attempts,
        )
        if self._record is not None and recording is not None:
            from audere.agent._cassette import Cassette

            key, request = recording
            Cassette.append(self._record, key, self._model, request, reply)
        if self._cache is not None and recording is not None:
            self._cache.put(recording[0], self._model, recording[1], reply)
        return reply

    def _cached(self, recording: tuple[str, dict[str, Any]] | None) -> Reply | None:
        """The cached reply to this request, if the client has a cache that holds it."""
        if self._cache is None or recording is None:
            return None
        reply = self._cache.get(recording[0])
        if reply is not None and not isinstance(reply, Reply):
            raise InvalidArgumentError(
                f"cache: get() must return a Reply or None, got {type(reply).__name__}"
            )
        return reply
