"""What a language model reads about the APIs: the catalog, a Python stub per API, the source."""

from __future__ import annotations

import inspect
import re
import sys
import types
import typing
from typing import Any

import numpy as np
import numpy.typing as npt
from pydantic import BaseModel

from audere.apis._registry import ApiInfo, get_api, list_apis
from audere.apis._result import Result

__all__ = ["api_card", "api_source", "catalog"]

_WIDTH = 100


def catalog() -> str:
    """One line per registered API: its name, what it does and when to use it, and its tags.

    What a model sees first when choosing an API; :func:`api_card` gives the details of one.

    Returns
    -------
    str
        Lines ``"<name>: <description> [tag, tag]"``, sorted by name.
    """
    lines = []
    for info in list_apis():
        tags = f" [{', '.join(info.tags)}]" if info.tags else ""
        lines.append(f"{info.name}: {info.description}{tags}")
    return "\n".join(lines)


def _format_annotation(annotation: Any) -> str:
    """An annotation as its author would write it (``ArrayLike | None``, ``NDArray[np.float64]``)."""
    if isinstance(annotation, str):
        return annotation
    if annotation is None or annotation is type(None):
        return "None"
    if annotation is Ellipsis:
        return "..."
    origin = typing.get_origin(annotation)
    args = typing.get_args(annotation)
    if origin is typing.Union or isinstance(annotation, types.UnionType):
        members = list(args)
        parts: list[str] = []
        arraylike = set(typing.get_args(npt.ArrayLike))
        if arraylike <= set(members):
            members = [m for m in members if m not in arraylike]
            parts.append("ArrayLike")
        parts.extend(_format_annotation(m) for m in members)
        return " | ".join(parts)
    if annotation is np.ndarray or origin is np.ndarray:
        dtype = typing.get_args(args[1])[0] if len(args) == 2 and typing.get_args(args[1]) else None
        return f"NDArray[np.{dtype.__name__}]" if isinstance(dtype, type) else "NDArray"
    if origin is typing.Annotated:
        return _format_annotation(args[0])
    if origin is typing.Literal:
        return f"Literal[{', '.join(repr(a) for a in args)}]"
    if origin is not None:
        name = getattr(origin, "__qualname__", None) or repr(origin)
        inner = ", ".join(
            "[" + ", ".join(_format_annotation(x) for x in a) + "]"
            if isinstance(a, list)
            else _format_annotation(a)
            for a in args
        )
        return f"{name}[{inner}]" if args else name
    if isinstance(annotation, type):
        return annotation.__qualname__
    return re.sub(r"\b(?:typing|collections\.abc|numpy\.typing|types)\.", "", repr(annotation))


def _format_default(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 60 else f"{text[:57]}..."


def _stub_signature(info: ApiInfo) -> str:
    signature = inspect.signature(info.function)
    parts: list[str] = []
    star_done = False
    for p in signature.parameters.values():
        if p.kind is p.KEYWORD_ONLY and not star_done:
            parts.append("*")
            star_done = True
        text = p.name
        if p.annotation is not p.empty:
            text += f": {_format_annotation(p.annotation)}"
        if p.default is not p.empty:
            text += f" = {_format_default(p.default)}" if p.annotation is not p.empty else f"={p.default!r}"
        parts.append(text)
    returns = ""
    if signature.return_annotation is not signature.empty:
        returns = f" -> {_format_annotation(signature.return_annotation)}"
    one_line = f"def {info.name}({', '.join(parts)}){returns}:"
    if len(one_line) <= _WIDTH:
        return one_line
    body = "".join(f"    {part},\n" for part in parts)
    return f"def {info.name}(\n{body}){returns}:"


def _docstring_block(doc: str | None, indent: str) -> str:
    text = inspect.cleandoc(doc or "").replace('"""', r"\"\"\"")
    lines = [(indent + line) if line.strip() else "" for line in text.splitlines()]
    if not lines:
        return ""
    lines[0] = f'{indent}"""{lines[0].strip()}'
    if len(lines) == 1:
        return lines[0] + '"""\n'
    return "\n".join(lines) + f'\n{indent}"""\n'


def _result_class(info: ApiInfo) -> type[BaseModel] | None:
    annotation = inspect.signature(info.function).return_annotation
    if isinstance(annotation, str):
        namespace = dict(getattr(info.function, "__globals__", {}))
        try:
            annotation = eval(annotation, namespace)  # the API module's own annotation
        except Exception:  # an annotation only defined for type checkers: no class to show
            return None
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return annotation
    return None


def _class_stub(cls: type[BaseModel]) -> str:
    """The class's own fields (with descriptions) and public methods, as a stub."""
    bases = ", ".join(b.__name__ for b in cls.__bases__)
    out = [f"class {cls.__name__}({bases}):\n", _docstring_block(cls.__doc__, "    "), "\n"]
    own = inspect.get_annotations(cls)
    for field_name, field in cls.model_fields.items():
        if field_name not in own:
            continue
        annotation = _format_annotation(own.get(field_name, field.annotation))
        default = "" if field.is_required() else f" = {_format_default(field.get_default())}"
        out.append(f"    {field_name}: {annotation}{default}\n")
        if field.description:
            out.append(f'    """{field.description}"""\n')
    for attr, value in cls.__dict__.items():
        if attr.startswith("_") or attr in cls.model_fields:
            continue
        summary = (inspect.getdoc(value) or "").split("\n\n")[0].strip()
        doc = f'        """{" ".join(summary.split())}"""\n' if summary else ""
        if isinstance(value, property) and value.fget is not None:
            returns = _format_annotation(inspect.signature(value.fget).return_annotation)
            out.append(f"\n    @property\n    def {attr}(self) -> {returns}:\n{doc}        ...\n")
        elif inspect.isfunction(value):
            sig = inspect.signature(value)
            returns = _format_annotation(sig.return_annotation)
            args = ", ".join(str(p) for p in sig.parameters.values())
            out.append(f"\n    def {attr}({args}) -> {returns}:\n{doc}        ...\n")
    return "".join(out)


_KNOWN = frozenset({"ArrayLike", "NDArray", "Literal", "Any", "None", "np"})


def _aliases(info: ApiInfo) -> str:
    """Definitions of the type aliases the signature uses (``AntiWindup = Literal[...]``)."""
    signature = inspect.signature(info.function)
    written = [p.annotation for p in signature.parameters.values() if isinstance(p.annotation, str)]
    namespace = getattr(info.function, "__globals__", {})
    lines: list[str] = []
    seen: set[str] = set()
    for text in written:
        for word in re.findall(r"\b[A-Za-z_]\w*\b", text):
            if word in seen or word in _KNOWN:
                continue
            seen.add(word)
            value = namespace.get(word)
            if value is None or isinstance(value, (type, types.ModuleType)):
                continue
            if typing.get_origin(value) is not None:
                lines.append(f"{word} = {_format_annotation(value)}\n")
    return "".join(lines)


def api_card(name: str) -> str:
    """A Python stub of an API: its signature, full docstring, and the fields of its result class.

    What a model reads first about an API (the implementation is :func:`api_source`).

    Parameters
    ----------
    name
        A registered API name, e.g. ``"pid"``.

    Returns
    -------
    str
        Python source: ``def name(...) -> ResultType:`` with the docstring and ``...`` as the body,
        followed by a stub of the result class (its fields with their descriptions, its methods).

    Raises
    ------
    InvalidArgumentError
        For an unknown name.
    """
    info = get_api(name)
    parts = [
        f"# {info.name}: {info.description}" + (f" [{', '.join(info.tags)}]" if info.tags else ""),
        "\n",
        _aliases(info),
        _stub_signature(info),
        "\n",
        _docstring_block(info.function.__doc__, "    "),
        "    ...\n",
    ]
    result = _result_class(info)
    if result is not None:
        if issubclass(result, Result):
            parts.append(
                '\n\nStatus = Literal["solved", "infeasible", "time_limit", "failed"]\n'
                "FloatArray = NDArray[np.float64]  # read-only; nested lists in JSON\n"
            )
        chain = [c for c in result.__mro__ if c is not BaseModel and issubclass(c, BaseModel)]
        for klass in reversed(chain):
            parts.append("\n\n" + _class_stub(klass))
    return "".join(parts)


def api_source(name: str) -> str:
    """The implementation of an API: the complete source of the module that defines it.

    For on-demand retrieval when the card is not enough (how a cost is computed, what a status
    means exactly).

    Parameters
    ----------
    name
        A registered API name.

    Returns
    -------
    str
        The module's source, preceded by one comment line naming the module and the function.

    Raises
    ------
    InvalidArgumentError
        For an unknown name.
    """
    info = get_api(name)
    module = sys.modules.get(info.function.__module__)
    try:
        source = inspect.getsource(module) if module is not None else inspect.getsource(info.function)
    except (OSError, TypeError):  # defined interactively: fall back to the function alone
        source = inspect.getsource(info.function)
    header = f"# module {info.function.__module__}, API {info.name!r} is {info.function.__qualname__}\n"
    return header + source
