"""Bad inputs raise InvalidArgumentError naming the argument, the expectation and what was received."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import casadi as ca
import numpy as np
import pytest
import torch

from audere.dynamics import Pendulum, get_dynamics
from audere.errors import InvalidArgumentError

CAR = get_dynamics("unicycle")
X = np.zeros(4)
U = np.zeros(2)

BAD_CALLS: list[tuple[str, Callable[[], Any], str]] = [
    (
        "x-short",
        lambda: CAR.f(np.zeros(3), U),
        r"x must have last dimension 4 \(x, y, theta, v\), got shape \(3,\)",
    ),
    ("x-scalar", lambda: CAR.f(1.0, U), r"x must have last dimension 4 \(x, y, theta, v\), got shape \(\)"),
    (
        "u-long",
        lambda: CAR.step(X, np.zeros(3), 0.1),
        r"u must have last dimension 2 \(omega, a\), got shape \(3,\)",
    ),
    ("x-nan", lambda: CAR.f([0.0, np.nan, 0.0, 0.0], U), r"x must be finite, got nan at index \[1\]"),
    ("u-inf", lambda: CAR.step(X, [np.inf, 0.0], 0.1), r"u must be finite, got inf at index \[0\]"),
    ("x-text", lambda: CAR.f("abcd", U), r"x must be an array of numbers"),
    (
        "batch",
        lambda: CAR.f(np.zeros((3, 4)), np.zeros((5, 2))),
        r"x with batch shape \(3,\) and u with batch",
    ),
    ("dt-zero", lambda: CAR.step(X, U, 0.0), r"dt must be a positive finite number \(seconds\), got 0.0"),
    ("dt-negative", lambda: CAR.rollout(X, np.zeros((3, 2)), -1.0), r"dt must be a positive .*, got -1.0"),
    ("dt-nan", lambda: CAR.linearize(X, U, float("nan")), r"dt must be a positive .*, got nan"),
    ("dt-inf", lambda: CAR.step(X, U, float("inf")), r"dt must be a positive .*, got inf"),
    ("dt-text", lambda: CAR.step(X, U, "0.1"), r"dt must be a positive .*, got '0.1'"),  # type: ignore[arg-type]
    ("dt-bool", lambda: CAR.step(X, U, True), r"dt must be a positive .*, got True"),
    ("dt-none", lambda: CAR.step(X, U, None), r"dt must be a positive .*, got NoneType: None"),  # type: ignore[arg-type]
    (
        "method",
        lambda: CAR.step(X, U, 0.1, method="rk45"),  # type: ignore[arg-type]
        r"method must be one of 'euler', 'rk4', got 'rk45'",
    ),
    (
        "inputs-1d",
        lambda: CAR.rollout(X, np.zeros(2), 0.1),
        r"inputs must have shape \(horizon, 2\) or \(\.\.\., horizon, 2\) \(omega, a\), got shape \(2,\)",
    ),
    ("inputs-width", lambda: CAR.rollout(X, np.zeros((5, 3)), 0.1), r"inputs must have shape \(horizon, 2\)"),
    ("inputs-nan", lambda: CAR.rollout(X, [[0.0, np.nan]], 0.1), r"inputs must be finite"),
    ("x0-short", lambda: CAR.rollout(np.zeros(2), np.zeros((5, 2)), 0.1), r"x0 must have last dimension 4"),
    (
        "rollout-batch",
        lambda: CAR.rollout(np.zeros((3, 4)), np.zeros((2, 5, 2)), 0.1),
        r"x0 with batch shape \(3,\) and inputs with batch shape \(2,\) do not broadcast",
    ),
    ("states", lambda: CAR.position(np.zeros((5, 2))), r"states must have last dimension 4"),
    ("linearize-x", lambda: CAR.linearize_continuous(np.zeros(5), U), r"x must have last dimension 4"),
    (
        "name",
        lambda: get_dynamics("car"),
        r"name must be one of 'single_integrator', 'double_integrator', 'unicycle', 'pendulum', "
        r"'two_link_arm', got 'car'",
    ),
    (
        "param-unknown",
        lambda: get_dynamics("pendulum", {"len": 1.0}),
        r"params for 'pendulum' accept 'length', 'mass', 'gravity', 'damping', got unknown 'len'",
    ),
    (
        "param-none-accepted",
        lambda: get_dynamics("unicycle", {"mass": 1.0}),
        r"params for 'unicycle' accept no parameters, got unknown 'mass'",
    ),
    (
        "params-not-mapping",
        lambda: get_dynamics("pendulum", [("length", 1.0)]),  # type: ignore[arg-type]
        r"params must be a mapping from parameter name to value or None, got list",
    ),
    ("param-negative", lambda: get_dynamics("pendulum", {"length": -1.0}), r"'length' must be > 0, got -1.0"),
    ("param-zero-mass", lambda: Pendulum(mass=0.0), r"pendulum parameter 'mass' must be > 0, got 0.0"),
    (
        "param-damping",
        lambda: get_dynamics("two_link_arm", {"damping": -0.1}),
        r"'damping' must be >= 0, got -0.1",
    ),
    (
        "param-nan",
        lambda: get_dynamics("two_link_arm", {"l1": float("nan")}),
        r"'l1' must be finite, got nan",
    ),
    ("param-text", lambda: Pendulum(length="1"), r"'length' must be a real number, got str: '1'"),  # type: ignore[arg-type]
    ("param-bool", lambda: Pendulum(length=True), r"'length' must be a real number, got bool"),
    ("describe-method", lambda: CAR.describe(method="midpoint"), r"method must be one of"),  # type: ignore[arg-type]
    ("describe-dt", lambda: CAR.describe(dt=-1.0), r"dt must be a positive"),
]


@pytest.mark.parametrize(("call", "message"), [c[1:] for c in BAD_CALLS], ids=[c[0] for c in BAD_CALLS])
def test_bad_numpy_arguments(call: Callable[[], Any], message: str) -> None:
    with pytest.raises(InvalidArgumentError, match=message):
        call()


T4 = torch.zeros(4, dtype=torch.float64)
T2 = torch.zeros(2, dtype=torch.float64)

BAD_TORCH: list[tuple[str, Callable[[], Any], str]] = [
    (
        "x-short",
        lambda: CAR.f_torch(torch.zeros(3, dtype=torch.float64), T2),
        r"x must have last dimension 4",
    ),
    (
        "u-int",
        lambda: CAR.f_torch(T4, torch.zeros(2, dtype=torch.int64)),
        r"u must be a floating-point tensor",
    ),
    (
        "dtype-mix",
        lambda: CAR.step_torch(T4, torch.zeros(2, dtype=torch.float32), 0.1),
        r"x and u must have the same dtype, got torch.float64 and torch.float32",
    ),
    ("x-nan", lambda: CAR.f_torch(torch.full((4,), float("nan")), torch.zeros(2)), r"x must be finite"),
    ("dt", lambda: CAR.step_torch(T4, T2, 0.0), r"dt must be a positive"),
    ("method", lambda: CAR.rollout_torch(T4, torch.zeros(3, 2), 0.1, method="rk2"), r"method must be one of"),  # type: ignore[arg-type]
    (
        "inputs-1d",
        lambda: CAR.rollout_torch(T4, T2, 0.1),
        r"inputs must have shape \(horizon, 2\) or \(\.\.\., horizon, 2\)",
    ),
    (
        "batch",
        lambda: CAR.rollout_torch(torch.zeros(3, 4), torch.zeros(2, 5, 2), 0.1),
        r"x0 with batch shape \(3,\) and inputs with batch shape \(2,\) do not broadcast",
    ),
    ("states", lambda: CAR.position_torch(torch.zeros(3)), r"states must have last dimension 4"),
]


@pytest.mark.parametrize(("call", "message"), [c[1:] for c in BAD_TORCH], ids=[c[0] for c in BAD_TORCH])
def test_bad_torch_arguments(call: Callable[[], Any], message: str) -> None:
    with pytest.raises(InvalidArgumentError, match=message):
        call()


BAD_CASADI: list[tuple[str, Callable[[], Any], str]] = [
    (
        "x-row",
        lambda: CAR.f_casadi(ca.SX.sym("x", 1, 4), ca.SX.sym("u", 2)),
        r"x must be a column vector of shape \(4, 1\) \(x, y, theta, v\), got shape \(1, 4\)",
    ),
    (
        "u-short",
        lambda: CAR.step_casadi(ca.MX.sym("x", 4), ca.MX.sym("u", 1), 0.1),
        r"u must be a column vector",
    ),
    ("x-3d", lambda: CAR.f_casadi(np.zeros((4, 1, 1)), U), r"x must be a column vector of shape \(4, 1\)"),
    ("x-nan", lambda: CAR.f_casadi(ca.DM([0, 0, np.nan, 0]), U), r"x must be finite"),
    ("dt", lambda: CAR.casadi_function(-0.1), r"dt must be a positive"),
    ("method", lambda: CAR.casadi_function(0.1, method="RK4"), r"method must be one of"),  # type: ignore[arg-type]
    ("name-reserved", lambda: CAR.casadi_function(0.1, name="jac"), r"name must start with a letter"),
    ("name-spaces", lambda: CAR.casadi_function(0.1, name="my step"), r"got 'my step'"),
    (
        "position",
        lambda: CAR.position_casadi(ca.SX.sym("x", 3)),
        r"x must be a column vector of shape \(4, 1\)",
    ),
]


@pytest.mark.parametrize(("call", "message"), [c[1:] for c in BAD_CASADI], ids=[c[0] for c in BAD_CASADI])
def test_bad_casadi_arguments(call: Callable[[], Any], message: str) -> None:
    with pytest.raises(InvalidArgumentError, match=message):
        call()


def test_invalid_argument_errors_are_value_errors() -> None:
    with pytest.raises(ValueError, match="dt must be"):
        CAR.step(X, U, -1.0)
