"""Time-varying LQR tracking around a reference, on the model's discrete linearization.

The controller applies ``u[k] = sat(u_ref[k] - K[k] (x[k] - x_ref[k]))``: a feed-forward input
from the reference plus linear feedback on the tracking error, clipped to the input bounds. The
gains come from the linearization ``A[k], B[k]`` of the discrete step at each reference point
(:meth:`audere.dynamics.Dynamics.linearize`): ``"stationary"`` gains solve the discrete algebraic
Riccati equation with python-control's ``dlqr`` (one solve for a linear model), ``"time_varying"``
gains come from the finite-horizon backward Riccati recursion, which reduces to ``dlqr``'s gain
when the model is linear and the terminal weight is the stationary solution.
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray
from pydantic import Field

from audere._arrays import FloatArray, as_float_array
from audere._optional import require
from audere.apis import Result
from audere.apis._registry import register_api
from audere.controllers._common import square_weight
from audere.dynamics import Dynamics, IntegrationMethod, get_dynamics
from audere.errors import InvalidArgumentError

__all__ = ["LQRResult", "lqr"]

F = NDArray[np.float64]


class LQRResult(Result):
    """Result of :func:`audere.controllers.lqr`: the closed-loop trajectory, the gains, tracking errors.

    ``states`` (horizon+1, n_x), ``inputs`` (horizon, n_u) and ``times`` (horizon+1,) are the
    simulated closed loop; ``cost`` is the quadratic cost of the deviations from the reference
    (see :func:`~audere.controllers.lqr`).
    """

    gains: FloatArray = Field(description="Feedback gains K[k], shape (horizon, n_u, n_x).")
    feedforward: FloatArray = Field(description="Feed-forward inputs u_ref[k], shape (horizon, n_u).")
    riccati: FloatArray = Field(
        description="Cost-to-go matrix P[0] of the first step, shape (n_x, n_x): cost = e0' P e0 for "
        "a linear model without saturation."
    )
    tracking_error: FloatArray = Field(
        description="Euclidean norm of the (angle-wrapped) state error at every step, shape (horizon+1,)."
    )
    mean_tracking_error: float = Field(description="Mean of tracking_error.")
    max_tracking_error: float = Field(description="Largest entry of tracking_error.")
    saturated_steps: int = Field(description="Steps at which an input was clipped to its bounds.")
    mode: Literal["stationary", "time_varying"] = Field(description="How the gains were computed.")


def _wrap(values: F, indices: Sequence[int]) -> F:
    out = np.array(values, dtype=np.float64)
    if len(indices):
        idx = list(indices)
        out[..., idx] = (out[..., idx] + math.pi) % (2.0 * math.pi) - math.pi
    return out


def _weight(value: ArrayLike | None, n: int, *, name: str, default: float, positive: bool) -> F:
    """A weight matrix (n, n) from ``None``, a scalar, a diagonal (n,) or a full matrix (n, n)."""
    mat = square_weight(value, n, name=name, default=default)
    if not np.allclose(mat, mat.T, rtol=1e-10, atol=1e-12):
        raise InvalidArgumentError(f"{name} must be symmetric, got {mat.tolist()}")
    eig = np.linalg.eigvalsh(0.5 * (mat + mat.T))
    if positive and not eig.min() > 0.0:
        raise InvalidArgumentError(
            f"{name} must be positive definite, got smallest eigenvalue {eig.min():.3g}"
        )
    if not positive and not eig.min() >= -1e-12:
        raise InvalidArgumentError(
            f"{name} must be positive semidefinite, got smallest eigenvalue {eig.min():.3g}"
        )
    return np.asarray(mat, dtype=np.float64)


def _model(dynamics: Dynamics | str) -> Dynamics:
    if isinstance(dynamics, Dynamics):
        return dynamics
    if isinstance(dynamics, str):
        return get_dynamics(dynamics)
    raise InvalidArgumentError(
        f"dynamics must be a Dynamics model or a model name such as 'double_integrator', "
        f"got {type(dynamics).__name__}: {dynamics!r}"
    )


def input_bounds(model: Dynamics, u_min: ArrayLike | None, u_max: ArrayLike | None) -> tuple[F, F]:
    """Validated input bounds (n_u,) each, defaulting to the model's (``+-inf`` where unbounded)."""
    n_u = model.n_u
    lo = model.input_lower.copy() if u_min is None else _bound(u_min, n_u, "u_min", model)
    hi = model.input_upper.copy() if u_max is None else _bound(u_max, n_u, "u_max", model)
    if np.any(np.isnan(lo)) or np.any(np.isnan(hi)):
        raise InvalidArgumentError(f"u_min and u_max must not be NaN, got {lo.tolist()} and {hi.tolist()}")
    if np.any(lo > hi):
        raise InvalidArgumentError(
            f"u_min must be <= u_max in every component, got u_min={lo.tolist()} and u_max={hi.tolist()}"
        )
    return lo, hi


def _bound(value: ArrayLike, n: int, name: str, model: Dynamics) -> F:
    arr = as_float_array(value, name=name, finite=False)
    if arr.ndim == 0:
        arr = np.full(n, float(arr))
    if arr.shape != (n,):
        raise InvalidArgumentError(
            f"{name} must be a scalar or have shape ({n},) {tuple(model.input_names)}, got shape {arr.shape}"
        )
    return arr


def _riccati_step(a: F, b: F, q: F, r: F, p: F) -> tuple[F, F]:
    """One backward step: gain K and cost-to-go P for ``x+ = A x + B u`` and next cost-to-go ``p``."""
    bp = b.T @ p
    k = np.asarray(np.linalg.solve(r + bp @ b, bp @ a), dtype=np.float64)
    p_new = q + a.T @ p @ (a - b @ k)
    return k, np.asarray(0.5 * (p_new + p_new.T), dtype=np.float64)


@register_api(
    "lqr",
    description="LQR tracking of a state reference (linear or linearized model, time-varying gains, "
    "input saturation); use to follow a feasible reference or stabilize around a point.",
    tags=("control", "tracking", "linear", "stabilization"),
)
def lqr(
    dynamics: Dynamics | str,
    x0: ArrayLike,
    reference: ArrayLike,
    *,
    dt: float,
    reference_inputs: ArrayLike | None = None,
    state_weight: ArrayLike | None = None,
    input_weight: ArrayLike | None = None,
    terminal_weight: ArrayLike | None = None,
    u_min: ArrayLike | None = None,
    u_max: ArrayLike | None = None,
    mode: Literal["auto", "stationary", "time_varying"] = "auto",
    angle_indices: Sequence[int] = (),
    method: IntegrationMethod = "euler",
    time_limit: float = 10.0,
) -> LQRResult:
    """Track a state reference with (time-varying) LQR feedback and simulate the closed loop.

    At step ``k`` the controller applies ``u[k] = clip(u_ref[k] - K[k] e[k], u_min, u_max)`` with the
    tracking error ``e[k] = x[k] - x_ref[k]`` (components listed in ``angle_indices`` wrapped to
    ``[-pi, pi)``), and the model advances ``x[k+1] = step(x[k], u[k], dt)``. The gains minimize
    ``sum_k e[k]' Q e[k] + v[k]' R v[k] + e[T]' P_T e[T]`` (``v = u - u_ref``) for the linearization
    ``A[k], B[k]`` of the discrete step at ``(x_ref[k], u_ref[k])``.

    Parameters
    ----------
    dynamics
        The model, or its registry name (e.g. ``"double_integrator"``).
    x0
        Initial state, shape ``(n_x,)``.
    reference
        Reference states, shape ``(horizon+1, n_x)``; row ``k`` is the state wanted at step ``k``.
        A single state ``(n_x,)`` is a set point held for ``horizon`` steps (then ``reference_inputs``
        must be given, to set the horizon).
    dt
        Step length in seconds, ``> 0``.
    reference_inputs
        Feed-forward inputs ``u_ref``, shape ``(horizon, n_u)`` (or ``(n_u,)``, held constant). When
        ``None`` they are inferred from the reference by least squares on the linearized step,
        ``u_ref[k] = argmin_u ||step(x_ref[k], 0) + B[k] u - x_ref[k+1]||`` (exact for models affine
        in ``u`` that can follow the reference, e.g. fully actuated linear models), then clipped to
        the bounds.
    state_weight
        ``Q``: a scalar, a diagonal ``(n_x,)`` or a symmetric positive semidefinite ``(n_x, n_x)``
        matrix; default the identity.
    input_weight
        ``R``: a scalar, a diagonal ``(n_u,)`` or a symmetric positive definite ``(n_u, n_u)`` matrix;
        default ``0.1`` times the identity.
    terminal_weight
        ``P_T`` for the time-varying recursion, same forms as ``state_weight``; default the
        stationary Riccati solution at the last reference point (or ``Q`` when that has none).
    u_min
        Lower input bounds, a scalar or shape ``(n_u,)``; default the model's (``-inf`` if none).
    u_max
        Upper input bounds, a scalar or shape ``(n_u,)``; default the model's (``+inf`` if none).
    mode
        ``"stationary"``: infinite-horizon gain from python-control ``dlqr`` at each reference point
        (computed once when the linearization does not change); ``"time_varying"``: finite-horizon
        backward Riccati recursion over the reference; ``"auto"``: stationary when every
        linearization is the same (a linear model), time-varying otherwise.
    angle_indices
        State indices that are angles, whose error is wrapped to ``[-pi, pi)``.
    method
        Discretization of the model, ``"euler"`` or ``"rk4"`` (use the task's integrator).
    time_limit
        Wall-clock budget in seconds, ``> 0``, counted from the end of python-control's import (a
        one-off 2-4 s in a fresh process, included in ``solve_time``); the simulation stops with
        status ``time_limit`` when it runs out.

    Returns
    -------
    LQRResult
        ``states`` (horizon+1, n_x), ``inputs`` (horizon, n_u), ``times`` (horizon+1,) in seconds,
        ``gains`` (horizon, n_u, n_x), ``feedforward`` (horizon, n_u), ``riccati`` (n_x, n_x),
        ``tracking_error`` (horizon+1,), its mean and maximum, ``saturated_steps``, ``cost`` (the
        quadratic deviation cost above, with ``P_T`` as the terminal weight) and ``status``:
        ``solved``, ``time_limit``, or ``failed`` when the Riccati equation has no stabilizing
        solution or the simulation diverges.

    Raises
    ------
    InvalidArgumentError
        For shapes that do not match the model, NaN or infinite values, weights that are not
        symmetric and (semi)definite, ``u_min > u_max``, a bad ``mode``, ``angle_indices`` or
        ``time_limit``.
    MissingDependencyError
        When python-control is not installed (``pip install 'audere[control]'``).

    Examples
    --------
    >>> import numpy as np
    >>> from audere.controllers import lqr
    >>> ref = np.column_stack([np.linspace(0, 2, 11), np.zeros(11)])  # single integrator, 0.2 m/step
    >>> result = lqr("single_integrator", [0.5, 0.3], ref, dt=1.0, u_min=-0.5, u_max=0.5)
    >>> result.status, round(result.mean_tracking_error, 3)
    ('solved', 0.058)
    """
    started = time.perf_counter()
    model = _model(dynamics)
    n_x, n_u = model.n_x, model.n_u
    x_start = as_float_array(x0, name="x0")
    if x_start.shape != (n_x,):
        raise InvalidArgumentError(
            f"x0 must have shape ({n_x},) {tuple(model.state_names)}, got shape {x_start.shape}"
        )
    ref = as_float_array(reference, name="reference")
    ff_given = None if reference_inputs is None else as_float_array(reference_inputs, name="reference_inputs")
    if ref.ndim == 1:
        if ff_given is None or ff_given.ndim != 2:
            raise InvalidArgumentError(
                "reference is a single state: give reference_inputs of shape (horizon, n_u) to set the "
                f"horizon, got {None if ff_given is None else ff_given.shape}"
            )
        ref = np.tile(ref, (len(ff_given) + 1, 1))
    if ref.ndim != 2 or ref.shape[1] != n_x or len(ref) < 2:
        raise InvalidArgumentError(
            f"reference must have shape (horizon+1, {n_x}) {tuple(model.state_names)} with horizon >= 1, "
            f"got shape {ref.shape}"
        )
    horizon = len(ref) - 1
    if mode not in ("auto", "stationary", "time_varying"):
        raise InvalidArgumentError(f"mode must be 'auto', 'stationary' or 'time_varying', got {mode!r}")
    angles = tuple(angle_indices)
    if any(isinstance(i, bool) or not isinstance(i, int | np.integer) or not 0 <= i < n_x for i in angles):
        raise InvalidArgumentError(f"angle_indices must be state indices in [0, {n_x}), got {angles}")
    if isinstance(time_limit, bool) or not (isinstance(time_limit, int | float) and time_limit > 0):
        raise InvalidArgumentError(f"time_limit must be a positive number of seconds, got {time_limit!r}")
    q = _weight(state_weight, n_x, name="state_weight", default=1.0, positive=False)
    r = _weight(input_weight, n_u, name="input_weight", default=0.1, positive=True)
    lo, hi = input_bounds(model, u_min, u_max)
    model.step(x_start, np.zeros(n_u), dt, method=method)  # validates dt and method

    # Feed-forward inputs and linearizations along the reference.
    if ff_given is not None:
        if ff_given.ndim == 1 and ff_given.shape == (n_u,):
            ff_given = np.tile(ff_given, (horizon, 1))
        if ff_given.shape != (horizon, n_u):
            raise InvalidArgumentError(
                f"reference_inputs must have shape ({horizon}, {n_u}) (horizon, n_u) to match the "
                f"reference, got shape {ff_given.shape}"
            )
        ff = np.clip(ff_given, lo, hi)
        a_k, b_k = model.linearize(ref[:-1], ff, dt, method=method)
    else:
        zero = np.zeros((horizon, n_u))
        _, b_k = model.linearize(ref[:-1], zero, dt, method=method)
        gap = _wrap(ref[1:] - model.step(ref[:-1], zero, dt, method=method), angles)
        ff = np.stack([np.linalg.lstsq(b_k[k], gap[k], rcond=None)[0] for k in range(horizon)])
        ff = np.clip(np.nan_to_num(ff), lo, hi)
        a_k, b_k = model.linearize(ref[:-1], ff, dt, method=method)
    # The terminal point is linearized with the last feed-forward input.
    a_t, b_t = model.linearize(ref[-1], ff[-1], dt, method=method)

    linear = bool(
        np.allclose(a_k, a_k[0], rtol=1e-12, atol=1e-12) and np.allclose(b_k, b_k[0], rtol=1e-12, atol=1e-12)
    )
    used: Literal["stationary", "time_varying"] = (
        ("stationary" if linear else "time_varying") if mode == "auto" else mode
    )
    control = require("control", extra="control", purpose="LQR gains (controllers.lqr)")
    clock = time.perf_counter()  # the budget starts after python-control's one-off import (2-4 s)

    def dare(a: F, b: F) -> tuple[F, F] | None:
        try:
            k, p, _ = control.dlqr(a, b, q, r)
        except Exception:  # python-control raises several types for unsolvable problems
            return None
        return np.asarray(k, dtype=np.float64), np.asarray(p, dtype=np.float64)

    gains = np.zeros((horizon, n_u, n_x))
    message = ""
    if used == "stationary":
        cache: dict[bytes, tuple[F, F] | None] = {}
        p_first: F | None = None
        for k in range(horizon):
            key = a_k[k].tobytes() + b_k[k].tobytes()
            if key not in cache:
                cache[key] = dare(a_k[k], b_k[k])
            solved = cache[key]
            if solved is None:
                return _failed(
                    started,
                    f"no stabilizing solution of the discrete Riccati equation at reference step {k} "
                    "(the linearization is not stabilizable with these weights)",
                    mode=used,
                )
            gains[k] = solved[0]
            if k == 0:
                p_first = solved[1]
        terminal = None
        if terminal_weight is None:
            key = a_t.tobytes() + b_t.tobytes()
            terminal = cache[key] if key in cache else dare(a_t, b_t)
        p_final = (
            _weight(terminal_weight, n_x, name="terminal_weight", default=1.0, positive=False)
            if terminal_weight is not None
            else (terminal[1] if terminal is not None else q)
        )
        riccati = p_first if p_first is not None else p_final
        message = "stationary gains from python-control dlqr"
    else:
        if terminal_weight is not None:
            p = _weight(terminal_weight, n_x, name="terminal_weight", default=1.0, positive=False)
        else:
            terminal = dare(a_t, b_t)
            p = terminal[1] if terminal is not None else q
        p_final = p
        for k in range(horizon - 1, -1, -1):
            gains[k], p = _riccati_step(a_k[k], b_k[k], q, r, p)
            if not np.all(np.isfinite(p)):
                return _failed(started, f"the Riccati recursion diverged at step {k}", mode=used)
        riccati = p
        message = "time-varying gains from the backward Riccati recursion"

    # Closed-loop simulation with saturation.
    states = np.empty((horizon + 1, n_x))
    inputs = np.empty((horizon, n_u))
    states[0] = x_start
    saturated = 0
    cost = 0.0
    status: Literal["solved", "time_limit", "failed"] = "solved"
    for k in range(horizon):
        if time.perf_counter() - clock > time_limit:
            status = "time_limit"
            message = f"time limit of {time_limit:g} s reached at step {k} of {horizon}"
            break
        err = _wrap(states[k] - ref[k], angles)
        raw = ff[k] - gains[k] @ err
        u = np.clip(raw, lo, hi)
        saturated += int(np.any(u != raw))
        inputs[k] = u
        states[k + 1] = model.step(states[k], u, dt, method=method)
        dev = u - ff[k]
        cost += float(err @ q @ err + dev @ r @ dev)
        if not np.all(np.isfinite(states[k + 1])):
            status = "failed"
            message = f"the closed loop diverged at step {k + 1}"
            break
    if status != "solved":
        return _failed(started, message, mode=used, status=status)
    errors = _wrap(states - ref, angles)
    cost += float(errors[-1] @ p_final @ errors[-1])
    norms = np.linalg.norm(errors, axis=1)
    return LQRResult(
        status="solved",
        message=message,
        cost=cost,
        solve_time=time.perf_counter() - started,
        states=states,
        inputs=inputs,
        times=dt * np.arange(horizon + 1),
        gains=gains,
        feedforward=ff,
        riccati=riccati,
        tracking_error=norms,
        mean_tracking_error=float(norms.mean()),
        max_tracking_error=float(norms.max()),
        saturated_steps=saturated,
        mode=used,
    )


def _failed(
    started: float,
    message: str,
    *,
    mode: Literal["stationary", "time_varying"],
    status: Literal["time_limit", "failed"] = "failed",
) -> LQRResult:
    empty = np.zeros((0,))
    return LQRResult(
        status=status,
        message=message,
        solve_time=time.perf_counter() - started,
        gains=np.zeros((0, 0, 0)),
        feedforward=np.zeros((0, 0)),
        riccati=np.zeros((0, 0)),
        tracking_error=empty,
        mean_tracking_error=math.inf,
        max_tracking_error=math.inf,
        saturated_steps=0,
        mode=mode,
    )
