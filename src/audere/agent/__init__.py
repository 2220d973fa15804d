"""The agent: a language model chooses among audere's APIs, writes the glue code, and repairs it.

``Agent(task).solve()`` runs the paper's loop (select APIs, read their source, write the integration
code, run it in the sandbox, check, feed the diagnostics back) with any LiteLLM model, or with the
offline models: ``audere/expert`` (a rule-based strategist, not an LLM, the default) and
``audere/replay`` (recorded transcripts).

This package is imported lazily: ``import audere`` does not load it, and nothing here imports
litellm until a model is called.

- :class:`Agent`, :class:`SolveResult`, :class:`Round`, :class:`ModelCall`, :class:`ErrorCategory`,
  :class:`Event`;
- :class:`ModelClient`, :class:`ModelError`, :class:`Reply` (model access through LiteLLM);
- :func:`register_model`, :class:`ScriptedModel`, :class:`OfflineRequest`, :class:`OfflineReply`,
  :class:`ProviderError` (offline models, for tests and demos);
- :mod:`audere.agent.sandbox`: isolated execution of model-written code.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

__all__ = [
    "DEFAULT_MODEL",
    "Agent",
    "ErrorCategory",
    "Event",
    "ModelCall",
    "ModelClient",
    "ModelError",
    "OfflineReply",
    "OfflineRequest",
    "ProviderError",
    "Reply",
    "Round",
    "ScriptedModel",
    "SolveResult",
    "register_model",
    "sandbox",
]

_WHERE = {
    "DEFAULT_MODEL": "_agent",
    "Agent": "_agent",
    "ErrorCategory": "_categories",
    "Event": "_loop",
    "ModelCall": "_result",
    "ModelClient": "_llm",
    "ModelError": "_llm",
    "OfflineReply": "_offline",
    "OfflineRequest": "_offline",
    "ProviderError": "_offline",
    "Reply": "_llm",
    "Round": "_result",
    "ScriptedModel": "_offline",
    "SolveResult": "_result",
    "register_model": "_offline",
}

if TYPE_CHECKING:  # pragma: no cover
    from audere.agent import sandbox
    from audere.agent._agent import DEFAULT_MODEL, Agent
    from audere.agent._categories import ErrorCategory
    from audere.agent._llm import ModelClient, ModelError, Reply
    from audere.agent._loop import Event
    from audere.agent._offline import (
        OfflineReply,
        OfflineRequest,
        ProviderError,
        ScriptedModel,
        register_model,
    )
    from audere.agent._result import ModelCall, Round, SolveResult


def __getattr__(name: str) -> Any:
    if name == "sandbox":
        module = importlib.import_module("audere.agent.sandbox")
        globals()[name] = module
        return module
    if name in _WHERE:
        value = getattr(importlib.import_module(f"audere.agent.{_WHERE[name]}"), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'audere.agent' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(__all__)
