"""Controllers: PID, LQR (python-control), MPC (CasADi).

Each controller is a plain function returning a typed :class:`audere.apis.Result` subclass. Names
load lazily, so ``import audere.controllers`` imports no heavy backend.
"""

from __future__ import annotations

import importlib
from typing import Any

# public name -> private module that defines it (one line per name; keep sorted by name)
_EXPORTS: dict[str, str] = {
    "LQRResult": "_lqr",
    "MPCResult": "_mpc",
    "PIDResult": "_pid",
    "lqr": "_lqr",
    "mpc": "_mpc",
    "pid": "_pid",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name: str) -> Any:
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'audere.controllers' has no attribute {name!r}")
    value = getattr(importlib.import_module(f"audere.controllers.{module}"), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_EXPORTS))
