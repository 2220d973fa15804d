"""The agent: a language model chooses among audere's APIs, writes the glue code, and repairs it.

This package is imported lazily: ``import audere`` does not load it, and its submodules load
their heavy dependencies (litellm) only when used.

- :mod:`audere.agent.sandbox`: isolated execution of model-written code.
"""

from __future__ import annotations

import importlib
from types import ModuleType
from typing import TYPE_CHECKING

__all__ = ["sandbox"]

if TYPE_CHECKING:  # pragma: no cover
    from audere.agent import sandbox


def __getattr__(name: str) -> ModuleType:
    if name in __all__:
        module = importlib.import_module(f"audere.agent.{name}")
        globals()[name] = module
        return module
    raise AttributeError(f"module 'audere.agent' has no attribute {name!r}")
