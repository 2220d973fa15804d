"""The API registry: register-time checks, lookups, cards, sources, tool schemas and validation."""

from __future__ import annotations

import ast
import inspect
import subprocess
import sys
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any, Literal

import jsonschema
import numpy as np
import pytest
from numpy.typing import ArrayLike, NDArray

from audere.apis import (
    Result,
    _registry,
    api_card,
    api_source,
    catalog,
    get_api,
    list_apis,
    register_api,
    tool_schema,
    validate_call,
)
from audere.apis._docstring import parse_docstring
from audere.apis._registry import _problems
from audere.apis._schema import _dump_arguments
from audere.dynamics import Dynamics
from audere.errors import InvalidArgumentError
from audere.world import World

ROOT = Path(__file__).resolve().parents[2]


class ScaleResult(Result):
    """Result of the test API ``scale``."""

    factor: float = 1.0
    """The factor applied."""


def scale(
    points: ArrayLike,
    dynamics: Dynamics,
    *,
    factor: float = 2.0,
    mode: Literal["fast", "exact"] = "exact",
    offsets: NDArray[np.float64] | None = None,
    world: World | None = None,
    cost: Callable[[float], float] | None = None,
) -> ScaleResult:
    """Scale points (a tiny API for the registry tests).

    Parameters
    ----------
    points
        Points, shape (k, 2), metres.
    dynamics
        A dynamics model (name in JSON).
    factor
        Scale factor, dimensionless.
    mode
        How to scale.
    offsets
        Optional offsets, shape (k, 2), metres.
    world
        Optional world, unused.
    cost
        A Python-only callable option.

    Returns
    -------
    ScaleResult
        ``waypoints`` = ``factor * points (+ offsets)``.
    """
    p = np.asarray(points, dtype=float) * factor
    if offsets is not None:
        p = p + offsets
    return ScaleResult(status="solved", waypoints=p, factor=factor, message=dynamics.name)


def ping(*, times: int = 1) -> Result:
    """Do nothing, ``times`` times.

    Parameters
    ----------
    times
        How often.

    Returns
    -------
    Result
        Always solved.
    """
    return Result(status="solved", message="pong" * times)


@pytest.fixture
def registry() -> Iterator[None]:
    """The two tiny test APIs registered for one test, the registry restored afterwards."""
    _registry.list_apis()  # built-ins loaded first, so restoring keeps them
    saved = dict(_registry._REGISTRY)
    register_api("scale_test", description="Scale points; a test API.", tags=("test",))(scale)
    register_api("ping_test", description="Reply pong; a test API.")(ping)
    try:
        yield
    finally:
        _registry._REGISTRY.clear()
        _registry._REGISTRY.update(saved)


# ----------------------------------------------------------------------------- register-time checks


def test_register_collects_every_problem() -> None:
    def bad(a, b: int = 1, *args: int, c, **kwargs: int):  # type: ignore[no-untyped-def]
        """Bad.

        Parameters
        ----------
        a
            A.
        ghost
            Not a parameter.
        """

    with pytest.raises(InvalidArgumentError) as info:
        register_api("bad_test", description="Bad.")(bad)
    text = str(info.value)
    for expected in [
        "a: missing type annotation",
        "b: an option with a default must be keyword-only",
        "*args: variadic positional",
        "**kwargs: variadic keyword",
        "c: missing type annotation",
        "b: not documented",
        "c: not documented",
        "ghost: documented in Parameters but not a parameter",
        "missing return annotation",
        "missing Returns section",
    ]:
        assert expected in text
    assert "bad_test" not in {i.name for i in list_apis()}


def test_register_rejects_bad_name_description_and_duplicates(registry: None) -> None:
    with pytest.raises(InvalidArgumentError, match="name must be a lower-case identifier"):
        register_api("Bad-Name", description="x")
    with pytest.raises(InvalidArgumentError, match="description must be one non-empty line"):
        register_api("ok", description="two\nlines")
    with pytest.raises(InvalidArgumentError, match="tags must be a sequence of non-empty strings"):
        register_api("ok", description="x", tags="planning")
    with pytest.raises(InvalidArgumentError, match="'scale_test' is already registered"):
        register_api("scale_test", description="x")(ping)


def test_register_returns_the_function_unchanged(registry: None) -> None:
    assert register_api("ping_test", description="Reply pong; a test API.")(ping) is ping
    assert get_api("ping_test").function is ping


def test_positional_required_data_is_allowed() -> None:
    assert _problems(scale) == []


def test_get_api_unknown_lists_names(registry: None) -> None:
    with pytest.raises(InvalidArgumentError, match=r"registered API \(.*'ping_test'.*\), got 'nope'"):
        get_api("nope")


def test_builtin_modules_are_the_eight() -> None:
    short = sorted(m.rsplit("._", 1)[1] for m in _registry._BUILTIN_MODULES)
    assert short == ["astar", "cem", "grad", "lqr", "milp", "mpc", "pid", "rrt"]


def test_all_eight_are_registered_from_their_modules() -> None:
    builtin = {i.name: i for i in list_apis() if i.module in _registry._BUILTIN_MODULES}
    assert sorted(builtin) == ["astar", "cem", "grad", "lqr", "milp", "mpc", "pid", "rrt"]
    for name, info in builtin.items():
        assert info.module.rsplit("._", 1)[1] == name


def test_missing_builtin_module_is_an_error(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(_registry, "_loaded", False)
    monkeypatch.setattr(_registry, "_BUILTIN_MODULES", ("audere.planners._no_such_api",))
    with pytest.raises(ImportError, match=r"built-in API module 'audere\.planners\._no_such_api' is missing"):
        list_apis()


# ----------------------------------------------------------------------------- docstring parser


def test_parse_docstring_sections_and_parameters() -> None:
    doc = parse_docstring(scale.__doc__)
    assert doc.short_summary == "Scale points (a tiny API for the registry tests)."
    assert list(doc.params) == ["points", "dynamics", "factor", "mode", "offsets", "world", "cost"]
    assert doc.params["points"].description == "Points, shape (k, 2), metres."
    assert "ScaleResult" in doc.sections["Returns"]
    typed = parse_docstring("S.\n\nParameters\n----------\na, b : int\n    Two.\n\n    More.\n")
    assert typed.params["b"].type == "int"
    assert typed.params["a"].description == "Two.\n\nMore."


# ----------------------------------------------------------------------------- catalog, card, source


def test_catalog_has_one_line_per_api(registry: None) -> None:
    lines = catalog().splitlines()
    assert len(lines) == len(list_apis())
    assert "scale_test: Scale points; a test API. [test]" in lines
    assert "ping_test: Reply pong; a test API." in lines


def test_card_is_a_python_stub_with_the_result_fields(registry: None) -> None:
    card = api_card("scale_test")
    tree = ast.parse(card)
    functions = [n for n in tree.body if isinstance(n, ast.FunctionDef)]
    assert [f.name for f in functions] == ["scale_test"]
    args = functions[0].args
    assert [a.arg for a in args.args] == ["points", "dynamics"]
    assert [a.arg for a in args.kwonlyargs][:2] == ["factor", "mode"]
    assert ast.get_docstring(functions[0]) == inspect.getdoc(scale)
    classes = {n.name for n in tree.body if isinstance(n, ast.ClassDef)}
    assert classes == {"Result", "ScaleResult"}
    assert "factor: float = 1.0" in card
    assert '"""The factor applied."""' in card
    assert "def to_solution(self)" in card


def test_source_is_the_module(registry: None) -> None:
    source = api_source("scale_test")
    assert "def scale(" in source
    assert "class ScaleResult(Result)" in source
    assert source.endswith(inspect.getsource(sys.modules[__name__]))


# ----------------------------------------------------------------------------- schema and validation


def test_tool_schema_shape(registry: None) -> None:
    schema = tool_schema("scale_test")
    assert schema["type"] == "function"
    function = schema["function"]
    assert function["name"] == "scale_test"
    assert function["description"].startswith("Scale points; a test API.\n\nScale points (a tiny API")
    assert "Python-only options (not settable here): cost." in function["description"]
    parameters = function["parameters"]
    jsonschema.Draft202012Validator.check_schema(parameters)
    props = parameters["properties"]
    assert list(props) == ["points", "dynamics", "factor", "mode", "offsets", "world"]
    assert parameters["required"] == ["points", "dynamics"]
    assert props["points"]["type"] == "array"
    assert props["points"]["description"] == "Points, shape (k, 2), metres."
    assert props["factor"] == {
        "default": 2.0,
        "description": "Scale factor, dimensionless.",
        "type": "number",
    }
    assert props["mode"]["enum"] == ["fast", "exact"]
    assert "unicycle" in props["dynamics"]["anyOf"][0]["enum"]
    assert parameters["additionalProperties"] is False


def test_validate_call_converts_and_calls(registry: None) -> None:
    kwargs = validate_call("scale_test", {"points": [[1, 2], [3, 4]], "dynamics": "unicycle", "factor": 3})
    assert set(kwargs) == {"points", "dynamics", "factor"}
    assert isinstance(kwargs["points"], np.ndarray)
    assert kwargs["points"].dtype == np.float64
    assert kwargs["dynamics"].name == "unicycle"
    result = get_api("scale_test").function(**kwargs)
    np.testing.assert_array_equal(result.waypoints, [[3, 6], [9, 12]])
    params = {"name": "pendulum", "params": {"length": 0.5}}
    assert validate_call("scale_test", {"points": [0], "dynamics": params})["dynamics"].length == 0.5


@pytest.mark.parametrize(
    ("arguments", "match"),
    [
        ({"dynamics": "unicycle"}, r"points: Field required"),
        ({"points": [[1, "a"]], "dynamics": "unicycle"}, r"points: .*array of numbers"),
        ({"points": [[1, float("nan")]], "dynamics": "unicycle"}, r"points: .*must be finite"),
        ({"points": [1], "dynamics": "boat"}, r"dynamics: .*name must be one of"),
        ({"points": [1], "dynamics": "unicycle", "mode": "slow"}, r"mode: Input should be 'fast' or 'exact'"),
        ({"points": [1], "dynamics": "unicycle", "speed": 1}, r"speed: Extra inputs are not permitted"),
        ({"points": [1], "dynamics": "unicycle", "cost": "x"}, r"cost: a Python-only option"),
    ],
)
def test_validate_call_bad_arguments(registry: None, arguments: dict[str, Any], match: str) -> None:
    with pytest.raises(InvalidArgumentError, match=match):
        validate_call("scale_test", arguments)


def test_validate_call_needs_a_dict(registry: None) -> None:
    with pytest.raises(InvalidArgumentError, match="arguments must be a dict"):
        validate_call("ping_test", [1])  # type: ignore[arg-type]


def test_required_callable_cannot_make_a_schema(registry: None) -> None:
    def apply(function: Callable[[float], float]) -> Result:
        """Apply.

        Parameters
        ----------
        function
            A callable.

        Returns
        -------
        Result
            Solved.
        """
        return Result(status="solved")

    register_api("apply_test", description="Apply a callable.")(apply)
    with pytest.raises(InvalidArgumentError, match="required parameters with no JSON form: function"):
        tool_schema("apply_test")


# ----------------------------------------------------------------------------- every registered API


def _example(schema: dict[str, Any], defs: dict[str, Any]) -> Any:
    """A JSON value satisfying ``schema`` (defaults first, else a small valid value)."""
    if "default" in schema:
        return schema["default"]
    if "$ref" in schema:
        return _example(defs[schema["$ref"].rsplit("/", 1)[1]], defs)
    if "const" in schema:
        return schema["const"]
    if "enum" in schema:
        return schema["enum"][0]
    for key in ("anyOf", "oneOf"):
        if key in schema:
            options = [s for s in schema[key] if s.get("type") != "null"] or schema[key]
            return _example(options[0], defs)
    kind = schema.get("type")
    if kind == "object":
        props = schema.get("properties", {})
        return {k: _example(props[k], defs) for k in schema.get("required", [])}
    if kind == "array":
        if "prefixItems" in schema:
            return [_example(s, defs) for s in schema["prefixItems"]]
        item = schema.get("items", {})
        return [_example(item, defs) for _ in range(max(1, schema.get("minItems", 1)))]
    if kind == "number":
        low = schema.get("minimum", schema.get("exclusiveMinimum", 0.5))
        return float(low) + 0.5
    if kind == "integer":
        return int(schema.get("minimum", schema.get("exclusiveMinimum", 0))) + 1
    if kind == "boolean":
        return False
    if kind == "string":
        return "x"
    return None


# Built-in APIs whose required problem data includes a Python callable: callable from code (card,
# source, validation of the other rules), but with no JSON tool schema. Each entry says why.
CODE_ONLY: dict[str, str] = {}


def _names() -> list[str]:
    return sorted({i.name for i in list_apis()} | {"scale_test", "ping_test"})


@pytest.mark.parametrize("name", _names())
def test_every_api_follows_the_rules(registry: None, name: str) -> None:
    info = get_api(name)
    assert _problems(info.function) == []
    signature = inspect.signature(info.function)
    assert all(p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY) for p in signature.parameters.values())
    documented = parse_docstring(inspect.getdoc(info.function)).params
    assert set(documented) == set(signature.parameters)

    card = api_card(name)
    ast.parse(card)
    assert f"def {name}(" in card
    assert "\n    ...\n" in card
    assert f"def {info.function.__name__}(" in api_source(name)

    if name in CODE_ONLY:
        with pytest.raises(InvalidArgumentError, match="required parameters with no JSON form"):
            tool_schema(name)
        return
    schema = tool_schema(name)
    parameters = schema["function"]["parameters"]
    jsonschema.Draft202012Validator.check_schema(parameters)
    assert set(parameters["properties"]) <= set(signature.parameters)
    for prop, body in parameters["properties"].items():
        assert body.get("description"), f"{name}.{prop} has no description in the schema"

    example = _example(parameters, parameters.get("$defs", {}))
    jsonschema.validate(example, parameters)
    kwargs = validate_call(name, example)
    assert set(kwargs) == set(example)
    dumped = _dump_arguments(name, kwargs)
    jsonschema.validate(dumped, parameters)
    assert _dump_arguments(name, validate_call(name, dumped)) == dumped


def test_test_apis_run_from_an_example_call(registry: None) -> None:
    kwargs = validate_call("ping_test", {"times": 2})
    assert get_api("ping_test").function(**kwargs).message == "pongpong"


# ----------------------------------------------------------------------------- the user example


def test_register_example_runs() -> None:
    done = subprocess.run(
        [sys.executable, "-W", "error", str(ROOT / "examples" / "register_api.py")],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    assert "straight_line: Straight segment from start to goal" in done.stdout
    assert "def straight_line(" in done.stdout
    assert done.stdout.strip().endswith("solved 8.0\ninfeasible")
