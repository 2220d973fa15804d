"""Tool schemas built from an API's signature and numpydoc docstring, and validation of model calls.

The arguments model is made with pydantic's ``create_model`` from the resolved annotations (arrays
become nested number lists, a dynamics model its name) and the docstring's parameter descriptions;
the same model validates the JSON arguments a language model sends. Nothing is written by hand.
"""

from __future__ import annotations

import collections.abc
import functools
import inspect
import types
import typing
from typing import Annotated, Any, Literal, Union

import numpy as np
import numpy.typing as npt
from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    PlainSerializer,
    PlainValidator,
    TypeAdapter,
    ValidationError,
    WithJsonSchema,
    create_model,
)
from pydantic.errors import PydanticUserError
from pydantic.json_schema import GenerateJsonSchema, JsonSchemaValue
from pydantic_core import PydanticSerializationError, core_schema

from audere._arrays import as_float_array
from audere.apis._docstring import parse_docstring
from audere.apis._registry import ApiInfo, get_api
from audere.errors import InvalidArgumentError

__all__ = ["tool_schema", "validate_call"]

_NESTED_NUMBERS: dict[str, Any] = {
    "type": "array",
    "items": {
        "anyOf": [
            {"type": "number"},
            {
                "type": "array",
                "items": {"anyOf": [{"type": "number"}, {"type": "array", "items": {"type": "number"}}]},
            },
        ]
    },
    "description": "numeric array as nested lists of numbers, e.g. [x, y] or [[x0, y0], [x1, y1]]",
}


def _to_array(value: Any) -> npt.NDArray[np.float64]:
    if isinstance(value, (str, bytes, dict, bool)):
        raise ValueError(f"expected a number or nested lists of numbers, got {type(value).__name__}")
    arr = as_float_array(value, name="array")
    arr.setflags(write=False)
    return arr


NumberArray = Annotated[
    Any,
    PlainValidator(_to_array),
    PlainSerializer(lambda a: np.asarray(a).tolist(), return_type=list),
    WithJsonSchema(_NESTED_NUMBERS),
]
"""What an array parameter becomes in a tool schema: nested number lists, validated to float64."""


def _dynamics_names() -> list[str]:
    from audere.dynamics import list_dynamics

    return list_dynamics()


def _to_dynamics(value: Any) -> Any:
    from audere.dynamics import Dynamics, get_dynamics

    if isinstance(value, Dynamics):
        return value
    if isinstance(value, str):
        return get_dynamics(value)
    if isinstance(value, dict) and set(value) <= {"name", "params"} and "name" in value:
        return get_dynamics(value["name"], value.get("params"))
    raise ValueError(f"expected a dynamics model name or {{'name': ..., 'params': {{...}}}}, got {value!r}")


def _dump_dynamics(value: Any) -> Any:
    params = dict(value.params)
    return {"name": value.name, "params": params} if params else value.name


def _dynamics_schema() -> dict[str, Any]:
    names = _dynamics_names()
    return {
        "anyOf": [
            {"type": "string", "enum": names},
            {
                "type": "object",
                "properties": {
                    "name": {"type": "string", "enum": names},
                    "params": {"type": "object", "additionalProperties": {"type": "number"}},
                },
                "required": ["name"],
                "additionalProperties": False,
            },
        ],
        "description": "a dynamics model: its name, or its name and parameters overriding the defaults",
    }


class _Unrepresentable(Exception):
    """An annotation that has no JSON form (a callable, an arbitrary object)."""


@functools.cache
def _arraylike_members() -> frozenset[Any]:
    return frozenset(typing.get_args(npt.ArrayLike))


def _json_type(tp: Any) -> Any:
    """``tp`` with arrays and dynamics models replaced by their JSON-facing types."""
    from audere.dynamics import Dynamics

    if tp is Any or tp is inspect.Parameter.empty:
        raise _Unrepresentable("no usable annotation")
    origin = typing.get_origin(tp)
    if tp is np.ndarray or origin is np.ndarray:
        return NumberArray
    if isinstance(tp, type) and issubclass(tp, Dynamics):
        return Annotated[
            Any,
            PlainValidator(_to_dynamics),
            PlainSerializer(_dump_dynamics),
            WithJsonSchema(_dynamics_schema()),
        ]
    if origin is Annotated:
        inner = typing.get_args(tp)[0]
        if inner is np.ndarray or typing.get_origin(inner) is np.ndarray:  # FloatArray and friends
            return NumberArray
        return tp
    if origin is Union or isinstance(tp, types.UnionType):
        members = list(typing.get_args(tp))
        out: list[Any] = []
        arraylike = _arraylike_members()
        if arraylike <= set(members):
            members = [m for m in members if m not in arraylike]
            out.append(NumberArray)
        dropped = []
        for member in members:
            if member is type(None):
                out.append(member)
                continue
            try:  # a member with no JSON form (a formula tree next to its string) is left out
                mapped = _json_type(member)
            except _Unrepresentable:
                dropped.append(member)
                continue
            if _representable(mapped):
                out.append(mapped)
            else:
                dropped.append(member)
        if not [m for m in out if m is not type(None)]:
            raise _Unrepresentable("no member of the union has a JSON form")
        return functools.reduce(lambda a, b: Union[a, b], out)  # noqa: UP007 - built at runtime
    if origin is Literal:
        return tp
    if origin in (list, tuple, set, frozenset, dict, collections.abc.Sequence, collections.abc.Mapping):
        args = tuple(a if a is Ellipsis else _json_type(a) for a in typing.get_args(tp))
        return origin[args] if args else origin
    if origin is collections.abc.Callable or tp is collections.abc.Callable or _callable_type(tp):
        raise _Unrepresentable("a callable has no JSON form")
    return tp


def _callable_type(tp: Any) -> bool:
    """Whether ``tp`` is a callable type (``typing.Callable``, ``collections.abc.Callable``)."""
    return (
        tp in (typing.Callable, collections.abc.Callable) or typing.get_origin(tp) is collections.abc.Callable
    )


def _resolve(function: Any, annotation: Any) -> Any:
    if not isinstance(annotation, str):
        return annotation
    namespace = dict(getattr(function, "__globals__", {}))
    try:
        return eval(annotation, namespace)  # an annotation from the API's own module
    except Exception as exc:  # an annotation naming something the module does not define at runtime
        raise _Unrepresentable(f"annotation {annotation!r} cannot be resolved ({exc})") from None


class _QuietSchema(GenerateJsonSchema):
    """Leaves defaults that have no JSON form out of the schema without a warning."""

    def emit_warning(self, kind: Any, detail: str) -> None:
        if kind != "non-serializable-default":
            super().emit_warning(kind, detail)

    def default_schema(self, schema: core_schema.WithDefaultSchema) -> JsonSchemaValue:
        try:
            return super().default_schema(schema)
        except PydanticSerializationError:  # pragma: no cover - pydantic usually warns instead
            return self.generate_inner(schema["schema"])


def _representable(tp: Any) -> bool:
    try:
        TypeAdapter(tp).json_schema(schema_generator=_QuietSchema)
    except (PydanticUserError, TypeError, ValueError, NameError):
        return False
    return True


@functools.cache
def _build(info: ApiInfo) -> tuple[type[BaseModel], tuple[str, ...], str]:
    """The arguments model, the Python-only options left out of it, and the tool description."""
    function = info.function
    signature = inspect.signature(function)
    doc = parse_docstring(inspect.getdoc(function))
    fields: dict[str, Any] = {}
    omitted: list[str] = []
    problems: list[str] = []
    for p in signature.parameters.values():
        entry = doc.params.get(p.name)
        description = entry.description if entry is not None else ""
        try:
            tp = _json_type(_resolve(function, p.annotation))
            if not _representable(tp):
                raise _Unrepresentable(f"{p.annotation!r} has no JSON schema")
        except _Unrepresentable as exc:
            if p.default is p.empty:
                written = p.annotation if isinstance(p.annotation, str) else repr(p.annotation)
                problems.append(f"{p.name} (annotated {written}): {exc}")
            else:
                omitted.append(p.name)
            continue
        default = ... if p.default is p.empty else p.default
        fields["f_" + p.name] = (tp, Field(default, alias=p.name, description=description or None))
    if problems:
        raise InvalidArgumentError(
            f"API {info.name!r} has required parameters with no JSON form: {'; '.join(problems)}"
        )
    model = create_model(
        f"{info.name}_arguments",
        __config__=ConfigDict(extra="forbid", arbitrary_types_allowed=True, populate_by_name=False),
        **fields,
    )
    text = info.description
    if doc.summary:
        text += "\n\n" + "\n\n".join(" ".join(p.split()) for p in doc.summary.split("\n\n"))
    if omitted:
        text += "\n\nPython-only options (not settable here): " + ", ".join(omitted) + "."
    return model, tuple(omitted), text


def _strip_titles(schema: Any) -> Any:
    if isinstance(schema, dict):
        return {
            k: _strip_titles(v)
            for k, v in schema.items()
            if not (k == "title" and isinstance(v, str))
            or isinstance(schema.get("type"), dict)  # a property literally named "title"
        }
    if isinstance(schema, list):
        return [_strip_titles(v) for v in schema]
    return schema


def tool_schema(name: str) -> dict[str, Any]:
    """The OpenAI-style function tool schema of a registered API.

    Built from the signature (pydantic ``create_model`` over the annotations) and the numpydoc
    parameter descriptions; arrays are nested number lists, a dynamics model is its name (or
    ``{"name", "params"}``), world shapes and worlds use their own pydantic schemas. Options that
    have no JSON form (e.g. a Python callable with a default) are left out and named in the
    description.

    Parameters
    ----------
    name
        A registered API name, e.g. ``"pid"``.

    Returns
    -------
    dict
        ``{"type": "function", "function": {"name", "description", "parameters"}}`` where
        ``parameters`` is a JSON Schema object.

    Raises
    ------
    InvalidArgumentError
        For an unknown name, or an API with a required parameter that has no JSON form.
    """
    info = get_api(name)
    model, _, description = _build(info)
    parameters = model.model_json_schema(by_alias=True, schema_generator=_QuietSchema)
    parameters.pop("title", None)
    properties = parameters.get("properties", {})
    parameters["properties"] = {k: _strip_titles(v) for k, v in properties.items()}
    return {
        "type": "function",
        "function": {"name": info.name, "description": description, "parameters": parameters},
    }


def validate_call(name: str, arguments: dict[str, Any]) -> dict[str, Any]:
    """Validate a model's JSON arguments for an API and convert them to Python values.

    Uses the same pydantic model as :func:`tool_schema`: nested lists become read-only float64
    arrays, a dynamics name becomes the model. Only the arguments given are returned, so the
    function's own defaults apply to the rest: call ``get_api(name).function(**kwargs)``.

    Parameters
    ----------
    name
        A registered API name.
    arguments
        The call's arguments, parameter name -> JSON value.

    Returns
    -------
    dict
        Keyword arguments for the API function.

    Raises
    ------
    InvalidArgumentError
        For an unknown API, or arguments that do not match the schema (the message lists every
        problem with the parameter it concerns).
    """
    info = get_api(name)
    if not isinstance(arguments, dict):
        raise InvalidArgumentError(
            f"arguments must be a dict of parameter name -> value, got {type(arguments).__name__}"
        )
    model, omitted, _ = _build(info)
    try:
        values = model.model_validate(arguments)
    except ValidationError as exc:
        problems = []
        for error in exc.errors(include_url=False):
            where = ".".join(str(part) for part in error["loc"]) or "arguments"
            if error["type"] == "extra_forbidden" and error["loc"] and error["loc"][0] in omitted:
                problems.append(f"{where}: a Python-only option, not settable from a tool call")
            else:
                problems.append(f"{where}: {error['msg']}")
        raise InvalidArgumentError(f"arguments for {name!r} are invalid: " + "; ".join(problems)) from None
    by_alias = {f: info_.alias or f for f, info_ in type(values).model_fields.items()}
    return {by_alias[f]: getattr(values, f) for f in values.model_fields_set}


def _dump_arguments(name: str, kwargs: dict[str, Any]) -> dict[str, Any]:
    """The JSON form of converted keyword arguments (the inverse of :func:`validate_call`)."""
    model, _, _ = _build(get_api(name))
    values = model.model_validate(kwargs)
    return dict(values.model_dump(mode="json", by_alias=True, exclude_unset=True))
