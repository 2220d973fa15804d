"""Offline models, served to LiteLLM as the custom provider ``"audere"``.

``litellm.completion(model="audere/<name>", ...)`` (and ``acompletion``) reaches a responder
registered here under ``<name>``, through the same LiteLLM code path as a hosted model, tool calls
included. A responder is a function from an :class:`OfflineRequest` to an :class:`OfflineReply`; it
raises :class:`ProviderError` to simulate provider trouble, which the provider turns into the LiteLLM
exception a hosted model would raise (``litellm.RateLimitError``...).

- :class:`ScriptedModel` answers from a list of replies, in order: tests use it to make a model
  that makes specific mistakes.
- ``"audere/replay"`` (reserved) answers from cassettes, see :mod:`audere.agent._cassette`.

Registering a model does not import LiteLLM; :class:`~audere.agent._llm.ModelClient` installs the
provider on first use, or call :func:`install_provider` before calling LiteLLM directly.
"""

from __future__ import annotations

import importlib
import importlib.util
import json
import logging
import math
import re
import threading
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from types import ModuleType, TracebackType
from typing import TYPE_CHECKING, Any, Final

from audere.agent._llm import (
    HIDDEN_COST,
    METADATA_CASSETTE,
    METADATA_REQUEST_KEY,
    MODEL_ERROR_KINDS,
    OFFLINE_PREFIX,
    ErrorKind,
    Reply,
)
from audere.errors import InvalidArgumentError

if TYPE_CHECKING:  # pragma: no cover
    from litellm.types.utils import ModelResponse

__all__ = [
    "BUILTIN_MODELS",
    "PROVIDER",
    "RESERVED_NAMES",
    "OfflineReply",
    "OfflineRequest",
    "ProviderError",
    "Responder",
    "ScriptItem",
    "ScriptedModel",
    "check_model_name",
    "install_provider",
    "register_model",
    "registered_models",
    "unregister_model",
]

_log = logging.getLogger(__name__)

PROVIDER: Final = "audere"
"""The LiteLLM provider name: offline models are called as ``"audere/<name>"``."""

RESERVED_NAMES: Final = frozenset({"replay"})
"""Model names that cannot be registered: ``"replay"`` answers from cassettes."""

BUILTIN_MODELS: Final[Mapping[str, tuple[str, str]]] = {"expert": ("audere.agent._expert", "respond")}
"""Offline models loaded on first call unless registered: name -> (module, responder function)."""

_NAME = re.compile(r"[a-z0-9][a-z0-9_.-]*\Z")
_CHARS_PER_TOKEN: Final = 4


def check_model_name(name: object, *, argument: str = "name", allow_reserved: bool = False) -> str:
    """Validate an offline model name (the part after ``"audere/"``).

    Parameters
    ----------
    name
        The name: lowercase letters, digits, ``_``, ``.`` and ``-``, starting with a letter or digit.
    argument
        The argument name used in the error message.
    allow_reserved
        Accept the reserved names (:data:`RESERVED_NAMES`).

    Returns
    -------
    str
        ``name``.

    Raises
    ------
    InvalidArgumentError
        If the name is malformed, or reserved and ``allow_reserved`` is false.
    """
    shown = f"{OFFLINE_PREFIX}{name}" if argument == "model" and isinstance(name, str) else name
    if not isinstance(name, str) or not _NAME.match(name):
        raise InvalidArgumentError(
            f"{argument}: expected an offline model name matching [a-z0-9][a-z0-9_.-]*, got {shown!r}"
        )
    if name in RESERVED_NAMES and not allow_reserved:
        raise InvalidArgumentError(
            f"{argument}: expected a name other than the reserved {sorted(RESERVED_NAMES)}, got {name!r} "
            "('replay' answers from cassettes)"
        )
    return name


# --------------------------------------------------------------------------------------------------
# Requests, replies, provider errors
# --------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class OfflineRequest:
    """A chat request as an offline model receives it.

    Parameters
    ----------
    model
        The model name, without ``"audere/"``.
    messages
        The messages as LiteLLM passes them on (it may drop ``"content": None`` and the like).
    tools
        The tool definitions, or None.
    tool_choice
        The tool choice (``"auto"``, ``"required"``...), or None.
    temperature
        The sampling temperature, or None when none was given.
    seed
        The sampling seed, or None.
    """

    model: str
    messages: list[dict[str, Any]]
    tools: list[dict[str, Any]] | None = None
    tool_choice: Any = None
    temperature: float | None = None
    seed: int | None = None

    @property
    def last_user_text(self) -> str:
        """The text of the last user message, or an empty string (a convenience for responders)."""
        for message in reversed(self.messages):
            if message.get("role") == "user":
                return _text(message.get("content"))
        return ""


@dataclass(frozen=True)
class OfflineReply:
    """What an offline model answers.

    Parameters
    ----------
    content
        The reply text, or None (e.g. with only tool calls).
    tool_calls
        ``(name, arguments)`` pairs, the arguments as JSON text (write invalid JSON on purpose to
        test a caller's diagnostics). They get the ids ``"call_0"``, ``"call_1"``...
    prompt_tokens, completion_tokens
        Token counts to report. None reports an *estimate*: ``ceil(characters / 4)`` of the prompt
        (message texts, tool-call arguments and the tool definitions' JSON) and of the reply (text,
        tool names and arguments). Estimates are not any tokenizer's counts.

    Raises
    ------
    InvalidArgumentError
        If a field has the wrong type.
    """

    content: str | None = None
    tool_calls: tuple[tuple[str, str], ...] = ()
    prompt_tokens: int | None = None
    completion_tokens: int | None = None

    def __post_init__(self) -> None:
        if self.content is not None and not isinstance(self.content, str):
            raise InvalidArgumentError(f"content: expected a string or None, got {self.content!r}")
        calls = tuple(self.tool_calls)
        for index, call in enumerate(calls):
            if (
                not isinstance(call, tuple | list)
                or len(call) != 2
                or not all(isinstance(part, str) for part in call)
            ):
                raise InvalidArgumentError(
                    f"tool_calls[{index}]: expected a (name, arguments JSON text) pair of strings, "
                    f"got {call!r}"
                )
            if not call[0]:
                raise InvalidArgumentError(
                    f"tool_calls[{index}]: expected a non-empty tool name, got {call[0]!r}"
                )
        object.__setattr__(self, "tool_calls", tuple((name, arguments) for name, arguments in calls))
        for name in ("prompt_tokens", "completion_tokens"):
            value = getattr(self, name)
            if value is not None and (isinstance(value, bool) or not isinstance(value, int) or value < 0):
                raise InvalidArgumentError(f"{name}: expected an integer >= 0 or None, got {value!r}")


class ProviderError(Exception):
    """Raised by a responder to simulate provider trouble.

    The provider raises the matching LiteLLM exception instead (``"rate_limit"`` becomes
    ``litellm.RateLimitError``, ``"timeout"`` ``litellm.Timeout``, ``"connection"``
    ``litellm.APIConnectionError``, ``"server"`` ``litellm.ServiceUnavailableError``, ``"auth"``
    ``litellm.AuthenticationError``, ``"bad_request"`` ``litellm.BadRequestError``, ``"not_found"``
    ``litellm.NotFoundError``, ``"other"`` ``litellm.APIResponseValidationError``), so the caller
    sees exactly what a hosted model would raise.

    Parameters
    ----------
    kind
        One of :data:`audere.agent._llm.MODEL_ERROR_KINDS`.
    message
        The provider's message.

    Raises
    ------
    InvalidArgumentError
        If ``kind`` is not a known kind.
    """

    def __init__(self, kind: ErrorKind, message: str = "simulated provider error") -> None:
        if kind not in MODEL_ERROR_KINDS:
            raise InvalidArgumentError(f"kind: expected one of {list(MODEL_ERROR_KINDS)}, got {kind!r}")
        super().__init__(message)
        self.kind: ErrorKind = kind
        self.message = message

    def __repr__(self) -> str:
        return f"ProviderError({self.kind!r}, {self.message!r})"


Responder = Callable[[OfflineRequest], OfflineReply]
"""An offline model: a function from a request to a reply."""


# --------------------------------------------------------------------------------------------------
# The registry
# --------------------------------------------------------------------------------------------------

_registry_lock = threading.RLock()
_registry: dict[str, Responder] = {}


def register_model(name: str, responder: Responder, *, replace: bool = False) -> str:
    """Register an offline model, callable as ``"audere/<name>"``.

    Parameters
    ----------
    name
        The model name: ``[a-z0-9][a-z0-9_.-]*``, not ``"replay"``.
    responder
        A function ``OfflineRequest -> OfflineReply``; it may raise :class:`ProviderError`.
    replace
        Replace a model already registered under ``name`` (registering the same responder again is
        always allowed).

    Returns
    -------
    str
        The model string, ``"audere/<name>"``.

    Raises
    ------
    InvalidArgumentError
        If the name is malformed or reserved, ``responder`` is not callable, or another responder is
        registered under ``name`` and ``replace`` is false.
    """
    check_model_name(name)
    if not callable(responder):
        raise InvalidArgumentError(
            f"responder: expected a callable (OfflineRequest -> OfflineReply), got {responder!r}"
        )
    with _registry_lock:
        current = _registry.get(name)
        if current is not None and current is not responder and not replace:
            raise InvalidArgumentError(
                f"name: expected a name not yet registered (or replace=True), got {name!r}, "
                f"registered to {current!r}"
            )
        _registry[name] = responder
    return f"{OFFLINE_PREFIX}{name}"


def unregister_model(name: str) -> None:
    """Remove an offline model.

    Parameters
    ----------
    name
        The model name, without ``"audere/"``.

    Raises
    ------
    InvalidArgumentError
        If no model is registered under ``name``.
    """
    with _registry_lock:
        if name not in _registry:
            raise InvalidArgumentError(
                f"name: expected a registered offline model ({_listing()}), got {name!r}"
            )
        del _registry[name]


def registered_models() -> tuple[str, ...]:
    """The names (without ``"audere/"``) of the offline models one can call.

    Those registered, the built-in ones (:data:`BUILTIN_MODELS`, e.g. ``"expert"``) and ``"replay"``.

    Returns
    -------
    tuple of str
        Sorted.
    """
    builtin = {name for name, (module, _) in BUILTIN_MODELS.items() if _module_exists(module)}
    with _registry_lock:
        return tuple(sorted({*_registry, *builtin, *RESERVED_NAMES}))


def _module_exists(name: str) -> bool:
    try:
        return importlib.util.find_spec(name) is not None
    except (ImportError, ValueError):
        return False


def _responder(name: str) -> Responder | None:
    """The responder registered under ``name``, or the built-in one (imported on first use), or None."""
    with _registry_lock:
        responder = _registry.get(name)
    if responder is not None or name not in BUILTIN_MODELS:
        return responder
    module_name, attribute = BUILTIN_MODELS[name]
    if not _module_exists(module_name):
        return None
    function = getattr(importlib.import_module(module_name), attribute, None)
    if not callable(function):
        return None
    with _registry_lock:
        return _registry.setdefault(name, function)


def _listing() -> str:
    return "registered: " + ", ".join(repr(name) for name in registered_models())


# --------------------------------------------------------------------------------------------------
# Scripted models
# --------------------------------------------------------------------------------------------------

ScriptItem = OfflineReply | ProviderError | Callable[[OfflineRequest], OfflineReply]
"""One item of a :class:`ScriptedModel`'s script."""


class ScriptedModel:
    """An offline model that answers each call with the next item of a script.

    It registers itself as ``"audere/<name>"`` on construction; as a context manager it unregisters
    on exit.

    Parameters
    ----------
    name
        The model name, without ``"audere/"``.
    replies
        The script, one item per call: an :class:`OfflineReply` is answered, a :class:`ProviderError`
        is raised (as the matching LiteLLM exception), a callable is called with the
        :class:`OfflineRequest` and its reply answered. A call past the end is an error (a
        ``litellm.APIResponseValidationError``, which :class:`~audere.agent._llm.ModelClient`
        reports as a :class:`~audere.agent._llm.ModelError` of kind ``"other"``).
    replace
        Replace a model already registered under ``name``.

    Attributes
    ----------
    requests
        Every request received, in order (those answered with errors included).

    Raises
    ------
    InvalidArgumentError
        If the name is malformed, reserved or taken, or a script item has the wrong type.

    Examples
    --------
    >>> from audere.agent._offline import OfflineReply, ProviderError, ScriptedModel
    >>> with ScriptedModel("flaky", [ProviderError("rate_limit"), OfflineReply("hello")]) as model:
    ...     model.model
    'audere/flaky'
    """

    def __init__(self, name: str, replies: Sequence[ScriptItem], *, replace: bool = False) -> None:
        check_model_name(name)
        if not isinstance(replies, Sequence):
            raise InvalidArgumentError(f"replies: expected a sequence of script items, got {replies!r}")
        items = list(replies)
        for index, item in enumerate(items):
            if not isinstance(item, OfflineReply | ProviderError) and not callable(item):
                raise InvalidArgumentError(
                    f"replies[{index}]: expected an OfflineReply, a ProviderError or a callable, got {item!r}"
                )
        self._name = name
        self._items = items
        self._next = 0
        self._lock = threading.Lock()
        self.requests: list[OfflineRequest] = []
        self.register(replace=replace)

    @property
    def name(self) -> str:
        """The model name, without ``"audere/"``."""
        return self._name

    @property
    def model(self) -> str:
        """The model string, ``"audere/<name>"``."""
        return f"{OFFLINE_PREFIX}{self._name}"

    @property
    def remaining(self) -> int:
        """How many script items are left."""
        return len(self._items) - self._next

    def register(self, *, replace: bool = False) -> str:
        """Register (again) under :attr:`name`.

        Parameters
        ----------
        replace
            Replace another model registered under the name.

        Returns
        -------
        str
            The model string.
        """
        return register_model(self._name, self, replace=replace)

    def unregister(self) -> None:
        """Unregister, if this script is what is registered under :attr:`name`."""
        with _registry_lock:
            if _registry.get(self._name) is self:
                del _registry[self._name]

    def __call__(self, request: OfflineRequest) -> OfflineReply:
        """Answer one request with the next script item.

        Parameters
        ----------
        request
            The request (recorded in :attr:`requests`).

        Returns
        -------
        OfflineReply
            The reply.

        Raises
        ------
        ProviderError
            When the item is one.
        RuntimeError
            When the script has run out.
        """
        with self._lock:
            self.requests.append(request)
            if self._next >= len(self._items):
                raise RuntimeError(
                    f"scripted model {self.model!r} has run out of replies: it was given {len(self._items)} "
                    f"and this is call {len(self.requests)}"
                )
            item = self._items[self._next]
            self._next += 1
        if isinstance(item, ProviderError):
            raise item
        if isinstance(item, OfflineReply):
            return item
        return item(request)

    def __enter__(self) -> ScriptedModel:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        traceback: TracebackType | None,
    ) -> None:
        self.unregister()

    def __repr__(self) -> str:
        return f"ScriptedModel({self._name!r}, {len(self._items)} replies, {self.remaining} left)"


# --------------------------------------------------------------------------------------------------
# The LiteLLM provider
# --------------------------------------------------------------------------------------------------


def _text(content: object) -> str:
    """The text of a message's content: a string, or the text parts of a list of parts."""
    if isinstance(content, str):
        return content
    if isinstance(content, list):
        return "".join(
            part["text"]
            for part in content
            if isinstance(part, Mapping) and isinstance(part.get("text"), str)
        )
    return ""


def _estimate_tokens(chars: int) -> int:
    return math.ceil(chars / _CHARS_PER_TOKEN)


def _prompt_chars(request: OfflineRequest) -> int:
    chars = 0
    for message in request.messages:
        chars += len(_text(message.get("content")))
        for call in message.get("tool_calls") or ():
            function = call.get("function") if isinstance(call, Mapping) else None
            if isinstance(function, Mapping):
                chars += len(str(function.get("name") or "")) + len(str(function.get("arguments") or ""))
    if request.tools:
        chars += len(json.dumps(request.tools, sort_keys=True, default=str))
    return chars


def _error_for(litellm: ModuleType, kind: str, message: str, model: str) -> Exception:
    """The LiteLLM exception a hosted model raises for ``kind``."""
    where = {"llm_provider": PROVIDER, "model": model}
    classes = {
        "rate_limit": litellm.RateLimitError,
        "timeout": litellm.Timeout,
        "connection": litellm.APIConnectionError,
        "server": litellm.ServiceUnavailableError,
        "auth": litellm.AuthenticationError,
        "bad_request": litellm.BadRequestError,
        "not_found": litellm.NotFoundError,
        # LiteLLM re-raises its own exception types as they are, but wraps any other exception of a
        # custom provider into APIConnectionError (which a client would retry): an unexpected failure
        # is reported as an invalid response, which no one retries.
        "other": litellm.APIResponseValidationError,
    }
    error: Exception = classes[kind](message=message, **where)
    return error


def _response(
    litellm: ModuleType,
    model: str,
    content: str | None,
    calls: Sequence[tuple[str, str, str]],
    prompt_tokens: int,
    completion_tokens: int,
    finish_reason: str,
) -> ModelResponse:
    from litellm.types.utils import (
        ChatCompletionMessageToolCall,
        Choices,
        Function,
        Message,
        ModelResponse,
        Usage,
    )

    tool_calls = [
        ChatCompletionMessageToolCall(
            id=call_id, type="function", function=Function(name=name, arguments=arguments)
        )
        for call_id, name, arguments in calls
    ]
    message = Message(role="assistant", content=content, tool_calls=tool_calls or None)
    return ModelResponse(
        model=model,
        choices=[Choices(index=0, finish_reason=finish_reason, message=message)],
        usage=Usage(
            prompt_tokens=prompt_tokens,
            completion_tokens=completion_tokens,
            total_tokens=prompt_tokens + completion_tokens,
        ),
    )


def _replay(litellm: ModuleType, request: OfflineRequest, metadata: Mapping[str, Any]) -> ModelResponse:
    from audere.agent._cassette import CassetteError, ReplayMissError, find_reply, request_key

    key = metadata.get(METADATA_REQUEST_KEY)
    if not isinstance(key, str):
        # Called without ModelClient: the key of the messages as LiteLLM passed them on.
        key = request_key(request.messages, request.tools, request.temperature, request.seed)
    path = metadata.get(METADATA_CASSETTE)
    try:
        reply: Reply = find_reply(key, path if isinstance(path, str) else None)
    except ReplayMissError as exc:
        raise _error_for(litellm, "not_found", str(exc), request.model) from exc
    except CassetteError as exc:
        raise _error_for(litellm, "other", str(exc), request.model) from exc
    response = _response(
        litellm,
        request.model,
        reply.content or None,
        [(call.id, call.name, call.arguments) for call in reply.tool_calls],
        reply.prompt_tokens,
        reply.completion_tokens,
        reply.finish_reason,
    )
    response._hidden_params[HIDDEN_COST] = reply.cost
    return response


def _answer(
    litellm: ModuleType,
    model: str,
    messages: list[dict[str, Any]],
    optional_params: Mapping[str, Any] | None,
    litellm_params: Mapping[str, Any] | None,
) -> ModelResponse:
    """Answer one LiteLLM call to ``audere/<model>``; every failure is a LiteLLM exception."""
    params = optional_params or {}
    name = model.removeprefix(OFFLINE_PREFIX)
    request = OfflineRequest(
        model=name,
        messages=messages,
        tools=params.get("tools"),
        tool_choice=params.get("tool_choice"),
        temperature=params.get("temperature"),
        seed=params.get("seed"),
    )
    if name in RESERVED_NAMES:
        metadata = (litellm_params or {}).get("metadata") or {}
        return _replay(litellm, request, metadata if isinstance(metadata, Mapping) else {})
    try:
        responder = _responder(name)
    except Exception as exc:  # a built-in model's module failed to import
        failure = f"offline model {name!r} could not be loaded: {type(exc).__name__}: {exc}"
        raise _error_for(litellm, "other", failure, name) from exc
    if responder is None:
        raise _error_for(litellm, "not_found", f"no offline model {name!r} ({_listing()})", name)
    try:
        reply = responder(request)
    except ProviderError as exc:
        raise _error_for(litellm, exc.kind, exc.message, name) from exc
    except Exception as exc:
        _log.debug("offline model %s failed", name, exc_info=True)
        raise _error_for(
            litellm, "other", f"offline model {name!r} failed: {type(exc).__name__}: {exc}", name
        ) from exc
    if not isinstance(reply, OfflineReply):
        raise _error_for(
            litellm,
            "other",
            f"offline model {name!r} returned {type(reply).__name__}, expected an OfflineReply",
            name,
        )
    prompt_tokens = reply.prompt_tokens
    if prompt_tokens is None:
        prompt_tokens = _estimate_tokens(_prompt_chars(request))
    completion_tokens = reply.completion_tokens
    if completion_tokens is None:
        chars = len(reply.content or "") + sum(
            len(call) + len(arguments) for call, arguments in reply.tool_calls
        )
        completion_tokens = _estimate_tokens(chars)
    calls = [(f"call_{index}", call, arguments) for index, (call, arguments) in enumerate(reply.tool_calls)]
    return _response(
        litellm,
        name,
        reply.content,
        calls,
        prompt_tokens,
        completion_tokens,
        "tool_calls" if calls else "stop",
    )


_install_lock = threading.Lock()
_handler: Any = None


def _make_handler(litellm: ModuleType) -> Any:
    """Build the provider object (a ``litellm.CustomLLM``), its class defined once LiteLLM is imported."""
    from litellm.llms.custom_llm import CustomLLM

    class AudereProvider(CustomLLM):
        """LiteLLM custom provider ``"audere"``: answers from offline models."""

        def completion(
            self, model: str, messages: list[dict[str, Any]], *args: Any, **kwargs: Any
        ) -> ModelResponse:
            return _answer(
                litellm, model, messages, kwargs.get("optional_params"), kwargs.get("litellm_params")
            )

        async def acompletion(
            self, model: str, messages: list[dict[str, Any]], *args: Any, **kwargs: Any
        ) -> ModelResponse:
            return _answer(
                litellm, model, messages, kwargs.get("optional_params"), kwargs.get("litellm_params")
            )

    return AudereProvider()


def _install(litellm: ModuleType) -> None:
    """Make sure ``litellm.custom_provider_map`` routes ``"audere/..."`` to this module's provider.

    Appends to the map (other providers are kept); an ``"audere"`` entry left by an earlier copy of
    this module is replaced. LiteLLM reads the map on every call (``litellm.utils.custom_llm_setup``),
    so appending at any time works; it is also called here so that the provider is listed at once.
    """
    global _handler
    with _install_lock:
        if _handler is None:
            _handler = _make_handler(litellm)
        entries = litellm.custom_provider_map
        for index, item in enumerate(entries):
            if item.get("provider") == PROVIDER:
                if item.get("custom_handler") is not _handler:
                    _log.debug("replacing a stale %r entry of litellm.custom_provider_map", PROVIDER)
                    entries[index] = {"provider": PROVIDER, "custom_handler": _handler}
                break
        else:
            entries.append({"provider": PROVIDER, "custom_handler": _handler})
        litellm.utils.custom_llm_setup()


def install_provider() -> None:
    """Import and configure LiteLLM, and register the ``"audere"`` provider with it.

    :class:`~audere.agent._llm.ModelClient` does this itself; call it before calling
    ``litellm.completion(model="audere/<name>", ...)`` directly.
    """
    from audere.agent._llm import _litellm

    _litellm()
