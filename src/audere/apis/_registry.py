"""The registry of planning and control APIs the agent chooses among."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, TypeVar

from audere.errors import InvalidArgumentError

__all__ = ["ApiInfo", "register_api"]

F = TypeVar("F", bound=Callable[..., Any])


@dataclass(frozen=True)
class ApiInfo:
    """A registered API: its name, one-line description, tags and the function itself."""

    name: str
    description: str
    tags: tuple[str, ...]
    function: Callable[..., Any]


_REGISTRY: dict[str, ApiInfo] = {}


def register_api(name: str, *, description: str, tags: Sequence[str] = ()) -> Callable[[F], F]:
    """Register a function as an API the agent can choose.

    Parameters
    ----------
    name
        Unique, short identifier (``[a-z][a-z0-9_]*``), e.g. ``"rrt"``.
    description
        One line: what it does and when to use it.
    tags
        Capabilities, e.g. ``("planning", "sampling")``.

    Returns
    -------
    callable
        A decorator that registers the function and returns it unchanged.
    """
    if not name.isidentifier() or not name.islower():
        raise InvalidArgumentError(f"name must be a lower-case identifier, got {name!r}")
    if not description.strip() or "\n" in description.strip():
        raise InvalidArgumentError(f"description must be one non-empty line, got {description!r}")

    def decorator(function: F) -> F:
        existing = _REGISTRY.get(name)
        if existing is not None and existing.function is not function:
            where = f"{existing.function.__module__}.{existing.function.__qualname__}"
            raise InvalidArgumentError(f"an API named {name!r} is already registered ({where})")
        _REGISTRY[name] = ApiInfo(
            name=name, description=description.strip(), tags=tuple(tags), function=function
        )
        return function

    return decorator
