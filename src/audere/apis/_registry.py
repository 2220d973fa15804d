"""The registry of planning and control APIs the agent chooses among.

``@register_api`` checks a function against the house rules when it is registered (every problem
collected, one error raised); :func:`list_apis` and :func:`get_api` load the built-in API modules
first, so every built-in API is registered by the time anyone looks.
"""

from __future__ import annotations

import importlib
import inspect
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, TypeVar

from audere.apis._docstring import parse_docstring
from audere.errors import InvalidArgumentError

__all__ = ["ApiInfo", "get_api", "list_apis", "register_api"]

F = TypeVar("F", bound=Callable[..., Any])

# The modules defining the built-in APIs, imported by list_apis()/get_api() (keep sorted).
_BUILTIN_MODULES: tuple[str, ...] = (
    "audere.controllers._lqr",
    "audere.controllers._mpc",
    "audere.controllers._pid",
    "audere.planners._astar",
    "audere.planners._cem",
    "audere.planners._grad",
    "audere.planners._milp",
    "audere.planners._rrt",
)


@dataclass(frozen=True)
class ApiInfo:
    """A registered API: its name, one-line description, tags and the function itself."""

    name: str
    """Unique identifier, e.g. ``"rrt"``."""
    description: str
    """One line: what it does and when to use it."""
    tags: tuple[str, ...]
    """Capabilities, e.g. ``("planning", "sampling")``."""
    function: Callable[..., Any]
    """The function; call it directly."""

    @property
    def module(self) -> str:
        """Dotted name of the module that defines the function."""
        return str(self.function.__module__)


_REGISTRY: dict[str, ApiInfo] = {}
_loaded = False


def _problems(function: Callable[..., Any]) -> list[str]:
    """Every way ``function`` breaks the API rules (empty when it follows them)."""
    problems: list[str] = []
    try:
        signature = inspect.signature(function)
    except (TypeError, ValueError) as exc:
        return [f"its signature cannot be read ({exc})"]
    params = list(signature.parameters.values())
    for p in params:
        if p.kind is p.VAR_POSITIONAL:
            problems.append(f"*{p.name}: variadic positional parameters are not allowed (name each one)")
        elif p.kind is p.VAR_KEYWORD:
            problems.append(f"**{p.name}: variadic keyword parameters are not allowed (name each one)")
        elif p.kind is p.POSITIONAL_ONLY:
            problems.append(f"{p.name}: positional-only parameters are not allowed (callers pass keywords)")
        elif p.kind is p.POSITIONAL_OR_KEYWORD and p.default is not p.empty:
            problems.append(
                f"{p.name}: an option with a default must be keyword-only (put it after '*'); "
                "only the required problem data may be positional"
            )
        if p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD) and p.annotation is p.empty:
            problems.append(f"{p.name}: missing type annotation")
    if signature.return_annotation is signature.empty:
        problems.append("missing return annotation")
    doc = parse_docstring(inspect.getdoc(function))
    if not doc.summary:
        problems.append("missing docstring summary")
    names = [p.name for p in params if p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD)]
    for name in names:
        entry = doc.params.get(name)
        if entry is None:
            problems.append(f"{name}: not documented in the docstring's Parameters section")
        elif not entry.description:
            problems.append(f"{name}: documented without a description")
    for name in doc.params:
        if name not in names:
            problems.append(f"{name}: documented in Parameters but not a parameter of the function")
    if not doc.sections.get("Returns", "").strip():
        problems.append("missing Returns section in the docstring")
    return problems


def register_api(name: str, *, description: str, tags: Sequence[str] = ()) -> Callable[[F], F]:
    """Register a function as an API the agent can choose.

    The function must follow the API rules, all checked here: every parameter and the return
    value annotated; no ``*args``/``**kwargs``; only the required problem data (no defaults) may
    be positional, every option is keyword-only; a numpydoc docstring with a summary, a
    ``Parameters`` entry for every parameter (and none for parameters that do not exist) and a
    ``Returns`` section. Every problem is collected and reported in one error.

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

    Raises
    ------
    InvalidArgumentError
        For a bad name, description or tags, a name already taken by another function, or a
        function that breaks the API rules (the message lists every problem).
    """
    if not isinstance(name, str) or not name.isidentifier() or not name.islower() or name.startswith("_"):
        raise InvalidArgumentError(f"name must be a lower-case identifier such as 'rrt', got {name!r}")
    if not isinstance(description, str) or not description.strip() or "\n" in description.strip():
        raise InvalidArgumentError(f"description must be one non-empty line, got {description!r}")
    if isinstance(tags, str) or not all(isinstance(t, str) and t.strip() for t in tags):
        raise InvalidArgumentError(f"tags must be a sequence of non-empty strings, got {tags!r}")

    def decorator(function: F) -> F:
        if not callable(function):
            raise InvalidArgumentError(
                f"register_api({name!r}) must decorate a function, got {type(function).__name__}"
            )
        where = f"{getattr(function, '__module__', '?')}.{getattr(function, '__qualname__', '?')}"
        problems = _problems(function)
        if problems:
            listed = "\n".join(f"  - {p}" for p in problems)
            raise InvalidArgumentError(
                f"cannot register {where} as API {name!r}: {len(problems)} problem(s):\n{listed}"
            )
        existing = _REGISTRY.get(name)
        if existing is not None and existing.function is not function:
            other = f"{existing.function.__module__}.{existing.function.__qualname__}"
            if other != where:  # re-importing the same module (e.g. a reload) may replace it
                raise InvalidArgumentError(f"an API named {name!r} is already registered ({other})")
        _REGISTRY[name] = ApiInfo(
            name=name, description=description.strip(), tags=tuple(tags), function=function
        )
        return function

    return decorator


def _load() -> None:
    """Import every built-in API module (once); a missing one is an error."""
    global _loaded
    if _loaded:
        return
    for module in _BUILTIN_MODULES:
        try:
            importlib.import_module(module)
        except ModuleNotFoundError as exc:
            if exc.name != module:
                raise
            raise ImportError(
                f"the built-in API module {module!r} is missing from this installation"
            ) from exc
    _loaded = True


def list_apis() -> list[ApiInfo]:
    """All registered APIs (the built-in ones and any a user registered), sorted by name.

    Returns
    -------
    list of ApiInfo
        One entry per API.
    """
    _load()
    return [_REGISTRY[k] for k in sorted(_REGISTRY)]


def get_api(name: str) -> ApiInfo:
    """The registered API called ``name``.

    Parameters
    ----------
    name
        An API name, e.g. ``"rrt"`` (see :func:`list_apis`).

    Returns
    -------
    ApiInfo
        Its name, description, tags and function.

    Raises
    ------
    InvalidArgumentError
        For an unknown name (the message lists the registered ones).
    """
    _load()
    info = _REGISTRY.get(name) if isinstance(name, str) else None
    if info is None:
        known = ", ".join(repr(k) for k in sorted(_REGISTRY)) or "none"
        raise InvalidArgumentError(f"name must be a registered API ({known}), got {name!r}")
    return info
