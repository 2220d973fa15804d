"""Import optional heavy backends where they are used, with an actionable error when missing."""

from __future__ import annotations

import importlib
from types import ModuleType

from audere.errors import MissingDependencyError

__all__ = ["require"]


def require(module: str, *, extra: str, purpose: str) -> ModuleType:
    """Import ``module`` or raise :class:`MissingDependencyError` naming the install command.

    Parameters
    ----------
    module
        Dotted module name, e.g. ``"casadi"``.
    extra
        The audere extra that installs it, e.g. ``"casadi"``.
    purpose
        What needs it, for the message, e.g. ``"the CasADi dynamics backend"``.
    """
    try:
        return importlib.import_module(module)
    except ImportError as exc:
        raise MissingDependencyError(
            f"{purpose} needs the optional package {module!r}, which is not installed; "
            f"install it with: pip install 'audere[{extra}]'"
        ) from exc
