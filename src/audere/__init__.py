"""audere: robot planning and control driven by language models.

``import audere`` is cheap and silent: subpackages load on first attribute access
(``audere.scenarios.make(...)``), and heavy backends (torch, casadi, ompl, cvxpy, control,
litellm) are imported only by the functions that use them.
"""

from __future__ import annotations

import importlib
from types import ModuleType
from typing import TYPE_CHECKING

__version__ = "0.1.0.dev0"

_SUBPACKAGES = (
    "agent",
    "apis",
    "bench",
    "controllers",
    "dynamics",
    "errors",
    "planners",
    "recipes",
    "scenarios",
    "stl",
    "tasks",
    "viz",
    "world",
)

__all__ = [
    "__version__",
    "agent",
    "apis",
    "bench",
    "controllers",
    "dynamics",
    "errors",
    "planners",
    "recipes",
    "scenarios",
    "stl",
    "tasks",
    "viz",
    "world",
]

if TYPE_CHECKING:  # pragma: no cover
    from audere import (
        agent,
        apis,
        bench,
        controllers,
        dynamics,
        errors,
        planners,
        recipes,
        scenarios,
        stl,
        tasks,
        viz,
        world,
    )


def __getattr__(name: str) -> ModuleType:
    if name in _SUBPACKAGES:
        module = importlib.import_module(f"audere.{name}")
        globals()[name] = module
        return module
    raise AttributeError(f"module 'audere' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_SUBPACKAGES))
