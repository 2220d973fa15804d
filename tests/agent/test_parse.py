"""Reading model replies: code blocks, answer lines, JSON, tool arguments, the entry point, predictions."""

from __future__ import annotations

import numpy as np
import pytest

from audere.agent._parse import (
    ReplyError,
    check_entry_point,
    extract_apis,
    extract_code,
    extract_json,
    extract_missing,
    parse_arguments,
    parse_prediction,
)


@pytest.mark.parametrize(
    ("reply", "code"),
    [
        ("```python\ndef solve(task):\n    return 1\n```", "def solve(task):\n    return 1\n"),
        ("plan\n```py\nx = 1\n```\nthen\n```python\ny = 2\n```", "y = 2\n"),  # the last python block
        ("```\ndef solve(task):\n    pass\n```", "def solve(task):\n    pass\n"),  # bare, with solve
        ("```\nx = 1\n```", None),  # bare, without solve
        ("```json\n{}\n```", None),
        ("no code at all", None),
        ("", None),
    ],
)
def test_extract_code(reply: str, code: str | None) -> None:
    assert extract_code(reply) == code


@pytest.mark.parametrize(
    ("reply", "apis"),
    [
        ("APIs: rrt", ["rrt"]),
        ("**APIs:** `astar`, `rrt`\nbecause", ["astar", "rrt"]),
        ("apis: MPC and LQR", ["mpc", "lqr"]),
        ("API: milp.", ["milp"]),
        ("first APIs: pid\nthen\nAPIs: lqr", ["lqr"]),
        ("I would use rrt", None),
    ],
)
def test_extract_apis(reply: str, apis: list[str] | None) -> None:
    assert extract_apis(reply) == apis


def test_extract_missing() -> None:
    assert extract_missing("MISSING: goal: no goal is given") == "goal: no goal is given"
    assert extract_missing("all good") is None


def test_extract_json() -> None:
    assert extract_json('```json\n{"a": [1, 2]}\n```') == {"a": [1, 2]}
    assert extract_json('The answer is {"a": 1} as said.') == {"a": 1}
    with pytest.raises(ReplyError, match="does not parse"):
        extract_json("```json\n{'a': 1}\n```")
    with pytest.raises(ReplyError, match="no JSON object"):
        extract_json("nothing here")


def test_parse_arguments() -> None:
    assert parse_arguments("t", '{"code": "x"}') == {"code": "x"}
    with pytest.raises(ReplyError, match="not valid JSON"):
        parse_arguments("t", '{"code": ')
    with pytest.raises(ReplyError, match="must be a JSON object, got list"):
        parse_arguments("t", "[1]")


@pytest.mark.parametrize(
    ("code", "problem"),
    [
        ("def solve(task):\n    return 1\n", None),
        ("solve = lambda task: 1\n", None),
        ("def solve(task)\n    return 1\n", "SyntaxError at line 1"),
        ("x = (\n", "SyntaxError at line 1"),
        ("def helper(task):\n    return 1\n", "does not define the entry point"),
        ("def main():\n    def solve(task):\n        return 1\n", "does not define the entry point"),
        ("async def solve(task):\n    return 1\n", "plain function"),
        ("def solve():\n    return 1\n", "must take the task"),
        ("x = 1\x00\n", "SyntaxError"),
    ],
)
def test_check_entry_point(code: str, problem: str | None) -> None:
    found = check_entry_point(code)
    if problem is None:
        assert found is None
    else:
        assert found is not None
        assert problem in found


def test_parse_prediction() -> None:
    arrays = parse_prediction({"waypoints": [[0, 0], [1, 1]]}, accepted=["waypoints"])
    np.testing.assert_array_equal(arrays["waypoints"], [[0.0, 0.0], [1.0, 1.0]])
    cases = [
        ([1, 2], "must be a JSON object"),
        ({"path": [[0, 0]]}, "unknown field"),
        ({}, "holds none of the fields"),
        ({"inputs": [[0, 0]]}, "does not accept ['inputs']"),
        ({"waypoints": [[0, "a"]]}, "array of numbers"),
        ({"waypoints": []}, "is empty"),
        ({"waypoints": [[0, float("nan")]]}, "not finite"),
    ]
    for value, message in cases:
        with pytest.raises(ReplyError, match=message.replace("[", r"\[").replace("]", r"\]")):
            parse_prediction(value, accepted=["waypoints"])
