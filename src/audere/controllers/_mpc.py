"""Model predictive control with CasADi: one compiled problem, solved once (open loop) or at every step.

The optimal-control problem over ``horizon`` steps is written once with CasADi ``SX`` symbols
(multiple shooting: the predicted states are decision variables tied by the discrete dynamics) and
compiled once into an ``nlpsol`` (IPOPT, any model) or a ``qpsol`` (OSQP or qrqp, linear models
without obstacles) whose *parameters* are the current state and the reference window. The
closed-loop simulation then only changes parameter values and the initial guess (the previous plan,
shifted by one step) between solves.
"""

from __future__ import annotations

import itertools
import logging
import math
import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Literal, get_args

import numpy as np
from numpy.typing import ArrayLike, NDArray
from pydantic import Field

from audere._arrays import FloatArray, as_float_array
from audere._optional import require
from audere.apis._registry import register_api
from audere.apis._result import Result, Status
from audere.controllers._common import square_weight
from audere.dynamics import Dynamics, IntegrationMethod, get_dynamics
from audere.errors import InvalidArgumentError
from audere.world import Circle, Obstacle, Polygon, Rectangle, Square, describe_shape, signed_distance

__all__ = ["MPCMode", "MPCResult", "MPCSolver", "mpc"]

_LOG = logging.getLogger(__name__)

F = NDArray[np.float64]

MPCMode = Literal["closed_loop", "open_loop"]
"""``"closed_loop"``: receding horizon, one solve per simulated step; ``"open_loop"``: one solve."""

MPCSolver = Literal["auto", "ipopt", "osqp", "qrqp"]
"""``"auto"`` picks OSQP for linear models without obstacles and IPOPT otherwise."""

_SUPERELLIPSE_EXPONENT = 8
"""Boxes are avoided through ``(dx / A)^8 + (dy / B)^8 >= 1`` (see :func:`mpc`)."""

_OSQP_ITERATIONS_PER_ITER = 50
"""OSQP's ADMM iterations are cheap: it may take this many per unit of ``max_iter``."""

_QP_SOLVERS = ("osqp", "qrqp")


class MPCResult(Result):
    """What :func:`mpc` returns: the simulated trajectory, its cost and per-solve solver statistics.

    ``states`` ``(steps + 1, n_x)`` are the rollout of ``inputs`` ``(steps, n_u)`` from ``x0`` with the
    same discrete model the solver predicts with, ``times`` ``(steps + 1,)`` in seconds. ``cost`` is
    the quadratic cost of that trajectory (see :func:`mpc`).
    """

    solver: str = Field(description="The solver used: 'ipopt', 'osqp' or 'qrqp'.")
    mode: str = Field(description="'closed_loop' or 'open_loop'.")
    horizon: int = Field(description="Prediction horizon N (steps) of every solve.")
    step_status: tuple[str, ...] = Field(description="The solver's own return status of each solve.")
    iterations: tuple[int, ...] = Field(
        description="Iterations of each solve (-1 where the solver does not report them)."
    )
    solve_times: tuple[float, ...] = Field(description="Wall-clock time of each solve, seconds.")
    build_time: float = Field(ge=0, description="Time spent building and compiling the problem, seconds.")
    failed_step: int | None = Field(
        None, description="The first closed-loop step (or 0 in open loop) whose solve failed, if any."
    )
    predicted_states: FloatArray | None = Field(
        None, description="The last solve's predicted states, shape (horizon + 1, n_x)."
    )
    predicted_inputs: FloatArray | None = Field(
        None, description="The last solve's planned inputs, shape (horizon, n_u)."
    )


# ------------------------------------------------------------------------------------------ validation


def _positive_int(value: object, name: str) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or int(value) < 1:
        raise InvalidArgumentError(f"{name} must be a positive integer, got {value!r}")
    return int(value)


def _positive_float(value: object, name: str, unit: str) -> float:
    if isinstance(value, (bool, str, bytes)):
        raise InvalidArgumentError(f"{name} must be a positive finite number ({unit}), got {value!r}")
    try:
        number = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise InvalidArgumentError(
            f"{name} must be a positive finite number ({unit}), got {type(value).__name__}: {value!r}"
        ) from None
    if not (math.isfinite(number) and number > 0.0):
        raise InvalidArgumentError(f"{name} must be a positive finite number ({unit}), got {number}")
    return number


def _choice(value: object, name: str, options: tuple[str, ...]) -> str:
    if not isinstance(value, str) or value not in options:
        raise InvalidArgumentError(f"{name} must be one of {', '.join(map(repr, options))}, got {value!r}")
    return value


def _model(dynamics: Dynamics | str) -> Dynamics:
    if isinstance(dynamics, Dynamics):
        return dynamics
    if isinstance(dynamics, str):
        return get_dynamics(dynamics)
    raise InvalidArgumentError(
        "dynamics must be a Dynamics model or a model name such as 'unicycle', "
        f"got {type(dynamics).__name__}: {dynamics!r}"
    )


def _weight(value: ArrayLike | None, name: str, n: int, default: float, labels: tuple[str, ...]) -> F:
    """A symmetric PSD ``(n, n)`` weight from a scalar, a diagonal ``(n,)`` or a matrix ``(n, n)``."""
    w = square_weight(value, n, name=name, default=default, over=f" over {_labels(labels)}")
    if not np.allclose(w, w.T, rtol=1e-9, atol=1e-12):
        raise InvalidArgumentError(f"{name} must be symmetric, got {w.tolist()}")
    w = 0.5 * (w + w.T)
    smallest = float(np.linalg.eigvalsh(w).min())
    if smallest < -1e-10 * max(1.0, float(np.abs(w).max())):
        raise InvalidArgumentError(
            f"{name} must be positive semidefinite, got a matrix with eigenvalue {smallest:.3g}"
        )
    return np.asarray(w, dtype=np.float64)


def _labels(names: tuple[str, ...]) -> str:
    return "(" + ", ".join(names) + ")"


def _bounds(
    lower: ArrayLike | None, upper: ArrayLike | None, names: tuple[str, str], n: int, labels: tuple[str, ...]
) -> tuple[F, F]:
    out = []
    for value, name, fill in ((lower, names[0], -np.inf), (upper, names[1], np.inf)):
        if value is None:
            out.append(np.full(n, fill))
            continue
        arr = as_float_array(value, name=name, finite=False)
        if arr.ndim == 0:
            arr = np.full(n, float(arr))
        if arr.shape != (n,):
            raise InvalidArgumentError(
                f"{name} must be a scalar or have shape ({n},) {_labels(labels)}, "
                f"got shape {tuple(arr.shape)}"
            )
        if np.isnan(arr).any():
            raise InvalidArgumentError(
                f"{name} must not contain NaN (use +-inf for no bound), got {arr.tolist()}"
            )
        out.append(arr)
    lo, hi = out
    bad = np.flatnonzero(lo > hi)
    if bad.size:
        i = int(bad[0])
        raise InvalidArgumentError(
            f"{names[0]} must not exceed {names[1]}, got {names[0]}[{i}] = {lo[i]} > "
            f"{names[1]}[{i}] = {hi[i]} ({labels[i]})"
        )
    return lo, hi


def _obstacles(obstacles: object) -> tuple[Obstacle, ...]:
    if isinstance(obstacles, (str, bytes)) or not isinstance(obstacles, Sequence):
        raise InvalidArgumentError(
            "obstacles must be a sequence of Circle, Square, Rectangle or Polygon shapes, "
            f"got {type(obstacles).__name__}: {obstacles!r}"
        )
    for i, shape in enumerate(obstacles):
        if not isinstance(shape, (Circle, Square, Rectangle, Polygon)):
            raise InvalidArgumentError(
                f"obstacles[{i}] must be a Circle, Square, Rectangle or Polygon, "
                f"got {type(shape).__name__}: {shape!r}"
            )
    return tuple(obstacles)


# ------------------------------------------------------------------------------------------ the problem


@dataclass(frozen=True)
class _Spec:
    """Validated problem data: everything the compiled problem depends on."""

    model: Dynamics
    dt: float
    method: IntegrationMethod
    horizon: int
    on_position: bool  # the reference / goal is a planar position (else a full state)
    q: F
    r: F
    qf: F
    u_lo: F
    u_hi: F
    x_lo: F
    x_hi: F
    obstacles: tuple[Obstacle, ...]
    margin: float
    solver: str
    max_iter: int
    time_limit: float

    @property
    def n_z(self) -> int:
        return 2 if self.on_position else self.model.n_x


@dataclass(frozen=True)
class _Solve:
    """One solve: the plan, the solver's verdict and statistics."""

    states: F  # (N + 1, n_x), row 0 is the current state
    inputs: F  # (N, n_u)
    success: bool
    status: str
    iterations: int
    seconds: float
    w: F  # raw primal solution, for warm starts
    lam_w: F
    lam_g: F


def _obstacle_constraints(ca: Any, p: Any, shape: Obstacle, margin: float) -> Any:
    """A smooth expression ``>= 0`` outside the (inflated) shape (conservative, see :func:`mpc`)."""
    if isinstance(shape, Circle):
        cx, cy = shape.center
        rr = shape.radius + margin
        return (p[0] - cx) ** 2 + (p[1] - cy) ** 2 - rr * rr
    if isinstance(shape, (Square, Rectangle)):
        if isinstance(shape, Square):
            (cx, cy), a, b = shape.center, shape.half_side, shape.half_side
        else:
            cx, cy = 0.5 * (shape.xmin + shape.xmax), 0.5 * (shape.ymin + shape.ymax)
            a, b = 0.5 * (shape.xmax - shape.xmin), 0.5 * (shape.ymax - shape.ymin)
        e = _SUPERELLIPSE_EXPONENT
        scale = 2.0 ** (1.0 / e)  # the superellipse passes through the corners of the inflated box
        big_a, big_b = scale * (a + margin), scale * (b + margin)
        return ((p[0] - cx) / big_a) ** e + ((p[1] - cy) / big_b) ** e - 1.0
    vertices = np.asarray(shape.vertices, dtype=np.float64)
    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    center = 0.5 * (lo + hi)
    rr = float(np.linalg.norm(vertices - center, axis=1).max()) + margin
    return (p[0] - center[0]) ** 2 + (p[1] - center[1]) ** 2 - rr * rr


class _Problem:
    """The optimal-control problem over the horizon, compiled once and solved many times.

    Decision variables ``w = [x_1 .. x_N, u_0 .. u_{N-1}]`` (the current state ``x_0`` is a
    parameter), parameters ``[x_0, r_0 .. r_N]``; constraints: the dynamics (equalities) and the
    obstacles at every predicted position and at the midpoint of every predicted segment.
    """

    def __init__(self, spec: _Spec) -> None:
        ca = require("casadi", extra="casadi", purpose="controllers.mpc")
        self.spec = spec
        model, n = spec.model, spec.horizon
        n_x, n_u, n_z = model.n_x, model.n_u, spec.n_z
        step = model.casadi_function(spec.dt, method=spec.method)
        xs = ca.SX.sym("X", n_x, n)
        us = ca.SX.sym("U", n_u, n)
        x0 = ca.SX.sym("x0", n_x)
        ref = ca.SX.sym("ref", n_z, n + 1)
        q, r, qf = (ca.DM(m) for m in (spec.q, spec.r, spec.qf))

        def z(x: Any) -> Any:
            return model.position_casadi(x) if spec.on_position else x

        cost = 0
        dyn = []
        prev = x0
        positions = [model.position_casadi(x0)]
        for k in range(n):
            e = z(prev) - ref[:, k]
            cost += ca.bilin(q, e, e) + ca.bilin(r, us[:, k], us[:, k])
            dyn.append(xs[:, k] - step(prev, us[:, k]))
            prev = xs[:, k]
            positions.append(model.position_casadi(prev))
        e = z(prev) - ref[:, n]
        cost += ca.bilin(qf, e, e)
        obs: list[Any] = []
        if spec.obstacles:
            points = positions[1:] + [0.5 * (a + b) for a, b in itertools.pairwise(positions)]
            for shape in spec.obstacles:
                obs.extend(_obstacle_constraints(ca, p, shape, spec.margin) for p in points)
        self.n_dyn = n * n_x
        self.n_obs = len(obs)
        w = ca.vertcat(ca.vec(xs), ca.vec(us))
        g = ca.vertcat(*dyn, *obs)
        params = ca.vertcat(x0, ca.vec(ref))
        problem = {"x": w, "p": params, "f": cost, "g": g}
        if spec.solver == "ipopt":
            options = {
                "print_time": False,
                "error_on_fail": False,
                "ipopt.print_level": 0,
                "ipopt.sb": "yes",
                "ipopt.max_iter": spec.max_iter,
                "ipopt.max_wall_time": spec.time_limit,
            }
            self.function = ca.nlpsol("mpc", "ipopt", problem, options)
        elif spec.solver == "osqp":
            options = {
                "print_time": False,
                "error_on_fail": False,
                "osqp": {
                    "verbose": False,
                    "eps_abs": 1e-8,
                    "eps_rel": 1e-8,
                    "max_iter": spec.max_iter * _OSQP_ITERATIONS_PER_ITER,
                },
            }
            self.function = ca.qpsol("mpc", "osqp", problem, options)
        else:
            options = {
                "print_time": False,
                "error_on_fail": False,
                "print_iter": False,
                "print_header": False,
                "print_info": False,
                "max_iter": spec.max_iter,
            }
            self.function = ca.qpsol("mpc", "qrqp", problem, options)
        x_lo = np.tile(spec.x_lo, n)
        x_hi = np.tile(spec.x_hi, n)
        self.lbw = np.concatenate([x_lo, np.tile(spec.u_lo, n)])
        self.ubw = np.concatenate([x_hi, np.tile(spec.u_hi, n)])
        self.lbg = np.zeros(self.n_dyn + self.n_obs)
        self.ubg = np.concatenate([np.zeros(self.n_dyn), np.full(self.n_obs, np.inf)])

    def cold_guess(self, x0: F) -> F:
        """The initial guess without a previous plan: stay at ``x0`` with inputs at (clipped) zero."""
        spec, n = self.spec, self.spec.horizon
        u = np.clip(np.zeros(spec.model.n_u), spec.u_lo, spec.u_hi)
        x = np.clip(x0, spec.x_lo, spec.x_hi)
        return np.concatenate([np.tile(x, n), np.tile(u, n)])

    def guess_from(self, x0: F, inputs: F) -> F:
        """The initial guess from an input sequence: the clipped inputs and their clipped rollout."""
        spec = self.spec
        u = np.clip(inputs, spec.u_lo, spec.u_hi)
        x = spec.model.rollout(x0, u, spec.dt, method=spec.method)[1:]
        x = np.clip(np.nan_to_num(x, nan=0.0, posinf=0.0, neginf=0.0), spec.x_lo, spec.x_hi)
        return np.concatenate([x.ravel(), u.ravel()])

    def shifted(self, solve: _Solve) -> F:
        """The previous plan shifted by one step (its last state and input repeated)."""
        x = np.vstack([solve.states[2:], solve.states[-1:]])
        u = np.vstack([solve.inputs[1:], solve.inputs[-1:]])
        return np.concatenate([x.ravel(), u.ravel()])

    def solve(self, x0: F, ref: F, guess: F, previous: _Solve | None = None) -> _Solve:
        """Solve for the current state ``x0`` and the reference window ``ref`` ``(N + 1, n_z)``."""
        spec, n = self.spec, self.spec.horizon
        n_x, n_u = spec.model.n_x, spec.model.n_u
        args: dict[str, Any] = {
            "x0": guess,
            "p": np.concatenate([x0, ref.ravel()]),
            "lbx": self.lbw,
            "ubx": self.ubw,
            "lbg": self.lbg,
            "ubg": self.ubg,
        }
        if previous is not None and spec.solver == "osqp":
            args["lam_x0"] = previous.lam_w
            args["lam_g0"] = previous.lam_g
        start = time.perf_counter()
        out = self.function(**args)
        seconds = time.perf_counter() - start
        stats = self.function.stats()
        w = np.asarray(out["x"], dtype=np.float64).ravel()
        states = np.vstack([x0, w[: n * n_x].reshape(n, n_x)])
        inputs = w[n * n_x :].reshape(n, n_u)
        status = str(stats.get("return_status", "unknown"))
        success = bool(stats.get("success", False)) and bool(np.all(np.isfinite(w)))
        if success and spec.solver != "ipopt" and seconds > spec.time_limit:
            success, status = False, f"{status} (but took {seconds:.3g} s > time_limit {spec.time_limit:g} s)"
        return _Solve(
            states=states,
            inputs=inputs,
            success=success,
            status=status,
            iterations=int(stats.get("iter_count", -1)),
            seconds=seconds,
            w=w,
            lam_w=np.asarray(out["lam_x"], dtype=np.float64).ravel(),
            lam_g=np.asarray(out["lam_g"], dtype=np.float64).ravel(),
        )


def _classify(status: str) -> Status:
    """Map a solver's failure status to ``infeasible``, ``time_limit`` or ``failed``."""
    text = status.lower()
    if "infeasib" in text:
        return "infeasible"
    if "time" in text:
        return "time_limit"
    return "failed"


def _window(reference: F, k: int, n: int) -> F:
    """Rows ``k .. k + n`` of ``reference``, the last row repeated past its end."""
    idx = np.minimum(np.arange(k, k + n + 1), len(reference) - 1)
    return np.asarray(reference[idx], dtype=np.float64)


def _is_linear(model: Dynamics, dt: float, method: IntegrationMethod, on_position: bool) -> bool:
    ca = require("casadi", extra="casadi", purpose="controllers.mpc")
    x = ca.SX.sym("x", model.n_x)
    u = ca.SX.sym("u", model.n_u)
    step = model.step_casadi(x, u, dt, method=method)
    linear = bool(ca.is_linear(step, ca.vertcat(x, u)))
    if on_position:
        linear = linear and bool(ca.is_linear(model.position_casadi(x), x))
    return linear


# ------------------------------------------------------------------------------------------ the API


@register_api(
    "mpc",
    description="Model predictive control (CasADi: IPOPT, or OSQP/qrqp for linear models): track a "
    "reference or reach a goal under input/state bounds and obstacle constraints, open or closed loop.",
    tags=("control", "tracking", "optimization", "nonlinear", "constraints", "obstacles"),
)
def mpc(
    dynamics: Dynamics | str,
    x0: ArrayLike,
    *,
    reference: ArrayLike | None = None,
    goal: ArrayLike | None = None,
    steps: int = 20,
    horizon: int = 10,
    dt: float = 0.1,
    Q: ArrayLike | None = None,
    R: ArrayLike | None = None,
    Qf: ArrayLike | None = None,
    u_min: ArrayLike | None = None,
    u_max: ArrayLike | None = None,
    x_min: ArrayLike | None = None,
    x_max: ArrayLike | None = None,
    obstacles: Sequence[Obstacle] = (),
    margin: float = 0.0,
    mode: MPCMode = "closed_loop",
    solver: MPCSolver = "auto",
    method: IntegrationMethod = "euler",
    max_iter: int = 200,
    time_limit: float = 2.0,
    warm_start: bool = True,
    initial_inputs: ArrayLike | None = None,
) -> MPCResult:
    """Model predictive control with CasADi: track a reference or reach a goal, with constraints.

    At every solve, the inputs ``u_0 .. u_{N-1}`` over the prediction horizon ``N`` minimise::

        sum_{k<N} (z_k - r_k)' Q (z_k - r_k) + u_k' R u_k  +  (z_N - r_N)' Qf (z_N - r_N)

    subject to the discrete dynamics ``x_{k+1} = step(x_k, u_k, dt)`` (``method``), the input and
    state bounds, and the obstacles. ``z`` is the planar position (:meth:`Dynamics.position`: the
    end effector of the arm, the bob of the pendulum) when the reference or goal gives positions,
    and the full state otherwise; ``r`` is the reference window or the goal. The problem is built
    and compiled once per call and re-solved with new parameter values (the current state and the
    reference window) at every closed-loop step, warm-started from the previous plan shifted by
    one step.

    Obstacles are smooth constraints imposed at every predicted position and at the midpoint of
    every predicted segment (positions between steps are not otherwise constrained: add
    ``margin`` when segments must stay clear): a circle ``|p - c|^2 >= (radius + margin)^2``; a
    square or rectangle of half sides ``a, b`` inflated by ``margin`` through the superellipse
    ``(dx / A)^8 + (dy / B)^8 >= 1`` with ``A = 2^(1/8) (a + margin)``, ``B = 2^(1/8) (b + margin)``,
    which passes through the corners of the inflated box and so contains it (conservative by at
    most 9 % along the axes); a polygon by its circumscribed circle around its bounding-box centre.

    Parameters
    ----------
    dynamics
        The model, a :class:`audere.dynamics.Dynamics` or a model name such as ``"unicycle"``.
    x0
        Initial state, shape ``(n_x,)`` in the model's units.
    reference
        Reference to track, one row per step from step 0: states ``(T + 1, n_x)`` or planar
        positions ``(T + 1, 2)`` (a 2-column reference is read as states when ``n_x == 2``). Rows
        past its end repeat the last row (so a short reference, or a single row, is held).
        Give at most one of ``reference`` and ``goal``; with neither the target is the zero state.
    goal
        A constant target: a state ``(n_x,)`` or a planar position ``(2,)`` (read as a state when
        ``n_x == 2``).
    steps
        Closed-loop steps to simulate (the length of the returned ``inputs``), ``>= 1``. In open
        loop, the first ``steps`` inputs of the single plan are returned (``steps <= horizon``).
    horizon
        Prediction horizon ``N`` of each solve, in steps, ``>= 1``.
    dt
        Step length in seconds, ``> 0`` (of the prediction model and of the simulation).
    Q
        Weight of the tracking error ``z - r``: a scalar, a diagonal ``(n_z,)`` or a symmetric
        positive semidefinite matrix ``(n_z, n_z)`` (``n_z = 2`` for positions, ``n_x`` for states).
        Default: identity.
    R
        Input weight: a scalar, ``(n_u,)`` or ``(n_u, n_u)``, symmetric positive semidefinite.
        Default: ``0.1`` times the identity.
    Qf
        Terminal weight, shaped like ``Q``. Default: ``10 Q``.
    u_min
        Lower input bounds ``(n_u,)`` or a scalar for all; ``None`` (or ``-inf`` entries): unbounded.
    u_max
        Upper input bounds ``(n_u,)`` or a scalar; ``None`` (or ``inf`` entries): unbounded.
    x_min
        Lower state bounds ``(n_x,)`` or a scalar, imposed on the predicted states ``x_1 .. x_N``.
    x_max
        Upper state bounds ``(n_x,)`` or a scalar, imposed on the predicted states ``x_1 .. x_N``.
    obstacles
        Shapes (:class:`audere.world.Circle`, ``Square``, ``Rectangle``, ``Polygon``) the planar
        position must stay out of (for a :class:`audere.world.World`, pass ``world.obstacles``).
    margin
        Clearance added around every obstacle, metres, ``>= 0``.
    mode
        ``"closed_loop"``: receding horizon, one solve per step, the first input applied;
        ``"open_loop"``: one solve from ``x0``, its inputs applied in turn.
    solver
        ``"auto"``: OSQP when the discrete dynamics (and the tracked position) are linear in the
        state and input (detected symbolically; the single and double integrators) and there are no
        obstacles, IPOPT otherwise. ``"osqp"`` or ``"qrqp"`` (QP solvers; linear models without
        obstacles only) or ``"ipopt"`` (any model).
    method
        Discretisation ``"euler"`` or ``"rk4"`` (see :meth:`audere.dynamics.Dynamics.step`); use
        the task's integrator so that the returned states match a checker's rollout.
    max_iter
        Iteration limit per solve, ``>= 1`` (IPOPT and qrqp iterations; OSQP may take 50 times as
        many of its cheap ADMM iterations).
    time_limit
        Wall-clock limit per solve in seconds, ``> 0`` (IPOPT stops at it; for the QP solvers, a
        solve that took longer is reported as failed).
    warm_start
        Start each closed-loop solve from the previous plan shifted by one step (otherwise from
        ``x0`` held with zero inputs).
    initial_inputs
        Initial guess for the first solve's inputs, shape ``(horizon, n_u)`` (clipped to the
        bounds; the predicted states start as their rollout from ``x0``), e.g. a plan from another
        planner or a manoeuvre that goes around an obstacle on a chosen side. ``None``: zero inputs.
        Nonlinear problems (obstacles above all) have local optima; different guesses find
        different ones.

    Returns
    -------
    MPCResult
        ``states`` ``(steps + 1, n_x)`` (the rollout of ``inputs`` from ``x0`` with ``method``),
        ``inputs`` ``(steps, n_u)`` (within the bounds), ``times`` ``(steps + 1,)`` seconds;
        ``cost`` the objective above summed over the simulated steps (stage costs at steps
        ``0 .. steps - 1`` and ``Qf`` at step ``steps``, reference padded); per-solve
        ``step_status``, ``iterations``, ``solve_times``; ``status`` ``"solved"`` when every solve
        succeeded, else the first failure's class (``infeasible``, ``time_limit``, ``failed``) with
        its step in ``failed_step`` and the solver's status in ``message``. After an infeasible
        solve the simulation stops there (the arrays are shorter); after another failure it goes on
        with the previous plan's next input (or the clipped unfinished iterate).

    Raises
    ------
    InvalidArgumentError
        For malformed arguments (shapes, NaN, ``u_min > u_max``, a weight that is not positive
        semidefinite, a QP solver with a nonlinear model or with obstacles).
    MissingDependencyError
        When CasADi is not installed (``pip install 'audere[casadi]'``).

    Examples
    --------
    >>> import numpy as np
    >>> from audere.controllers import mpc
    >>> t = np.arange(31) * 0.5
    >>> circle = np.column_stack([3 * np.cos(0.1 * t), 3 * np.sin(0.1 * t)])
    >>> result = mpc("unicycle", [3.0, 0.0, np.pi / 2, 0.0], reference=circle, steps=30, horizon=10,
    ...              dt=0.5, u_min=[-1, -1], u_max=[1, 1])
    >>> result.status, result.inputs.shape
    ('solved', (30, 2))
    """
    t_start = time.perf_counter()
    model = _model(dynamics)
    n_x, n_u = model.n_x, model.n_u
    x_init = as_float_array(x0, name="x0")
    if x_init.shape != (n_x,):
        raise InvalidArgumentError(
            f"x0 must have shape ({n_x},) {_labels(model.state_names)}, got shape {tuple(x_init.shape)}"
        )
    n_steps = _positive_int(steps, "steps")
    n_horizon = _positive_int(horizon, "horizon")
    step_dt = _positive_float(dt, "dt", "seconds")
    run_mode = _choice(mode, "mode", get_args(MPCMode))
    chosen = _choice(solver, "solver", get_args(MPCSolver))
    meth = _choice(method, "method", get_args(IntegrationMethod))
    iterations = _positive_int(max_iter, "max_iter")
    limit = _positive_float(time_limit, "time_limit", "seconds")
    if not isinstance(warm_start, (bool, np.bool_)):
        raise InvalidArgumentError(f"warm_start must be True or False, got {warm_start!r}")
    if run_mode == "open_loop" and n_steps > n_horizon:
        raise InvalidArgumentError(
            f"steps must not exceed horizon in open loop (one plan of horizon steps), got steps = "
            f"{n_steps} > horizon = {n_horizon}"
        )

    # The target: a reference (T + 1 rows), a goal (held), or the zero state.
    if reference is not None and goal is not None:
        raise InvalidArgumentError("give at most one of reference and goal, got both")
    if reference is not None:
        ref = as_float_array(reference, name="reference", ndim=2, min_len=1)
        widths = sorted({2, n_x})
        if ref.shape[1] not in widths:
            expected = " or ".join(f"(T + 1, {w})" for w in widths)
            raise InvalidArgumentError(
                f"reference must have shape {expected} (states {_labels(model.state_names)} or positions "
                f"(x, y)), got shape {tuple(ref.shape)}"
            )
        target = ref
    elif goal is not None:
        g = as_float_array(goal, name="goal")
        if g.ndim != 1 or g.shape[0] not in (2, n_x):
            raise InvalidArgumentError(
                f"goal must be a state ({n_x},) {_labels(model.state_names)} or a position (2,) (x, y), "
                f"got shape {tuple(g.shape)}"
            )
        target = g[None, :]
    else:
        target = np.zeros((1, n_x))
    on_position = target.shape[1] != n_x
    n_z = target.shape[1]
    z_labels = ("x", "y") if on_position else model.state_names

    q = _weight(Q, "Q", n_z, 1.0, z_labels)
    r = _weight(R, "R", n_u, 0.1, model.input_names)
    qf = _weight(Qf, "Qf", n_z, 0.0, z_labels) if Qf is not None else 10.0 * q
    u_lo, u_hi = _bounds(u_min, u_max, ("u_min", "u_max"), n_u, model.input_names)
    x_lo, x_hi = _bounds(x_min, x_max, ("x_min", "x_max"), n_x, model.state_names)
    shapes = _obstacles(obstacles)
    clearance = as_float_array(margin, name="margin")
    if clearance.ndim != 0 or not clearance >= 0:
        raise InvalidArgumentError(f"margin must be a finite number >= 0 (metres), got {margin!r}")

    linear = _is_linear(model, step_dt, meth, on_position)  # type: ignore[arg-type]
    if chosen == "auto":
        chosen = "osqp" if linear and not shapes else "ipopt"
    elif chosen in _QP_SOLVERS and not linear:
        raise InvalidArgumentError(
            f"solver {chosen!r} solves quadratic programs and needs dynamics linear in (x, u) (and a linear "
            f"tracked position); {model.name!r} is not: use solver='ipopt' or 'auto'"
        )
    elif chosen in _QP_SOLVERS and shapes:
        raise InvalidArgumentError(
            f"solver {chosen!r} solves convex quadratic programs; obstacle constraints are nonconvex "
            f"({len(shapes)} obstacles given): use solver='ipopt' or 'auto'"
        )

    times = step_dt * np.arange(n_steps + 1)
    base = {"solver": chosen, "mode": run_mode, "horizon": n_horizon}

    def early(status: Status, message: str) -> MPCResult:
        return MPCResult(
            status=status,
            message=message,
            solve_time=time.perf_counter() - t_start,
            states=x_init[None, :],
            inputs=np.zeros((0, n_u)),
            times=times[:1],
            step_status=(),
            iterations=(),
            solve_times=(),
            build_time=0.0,
            failed_step=0,
            **base,
        )

    # Infeasible by construction: the start violates a state bound or lies inside an obstacle.
    outside = np.flatnonzero((x_init < x_lo) | (x_init > x_hi))
    if outside.size:
        i = int(outside[0])
        return early(
            "infeasible",
            f"x0[{i}] ({model.state_names[i]}) = {x_init[i]:g} violates its bounds "
            f"[{x_lo[i]:g}, {x_hi[i]:g}]",
        )
    if shapes:
        start = model.position(x_init)
        for i, shape in enumerate(shapes):
            if float(signed_distance(shape, start)) < 0.0:
                return early(
                    "infeasible",
                    f"the start position ({start[0]:.3f}, {start[1]:.3f}) lies inside obstacle {i} "
                    f"({describe_shape(shape)})",
                )

    guess_inputs: F | None = None
    if initial_inputs is not None:
        guess_inputs = as_float_array(initial_inputs, name="initial_inputs")
        if guess_inputs.shape != (n_horizon, n_u):
            raise InvalidArgumentError(
                f"initial_inputs must have shape (horizon, n_u) = ({n_horizon}, {n_u}) "
                f"{_labels(model.input_names)}, got shape {tuple(guess_inputs.shape)}"
            )

    spec = _Spec(
        model=model,
        dt=step_dt,
        method=meth,  # type: ignore[arg-type]
        horizon=n_horizon,
        on_position=on_position,
        q=q,
        r=r,
        qf=qf,
        u_lo=u_lo,
        u_hi=u_hi,
        x_lo=x_lo,
        x_hi=x_hi,
        obstacles=shapes,
        margin=float(clearance),
        solver=chosen,
        max_iter=iterations,
        time_limit=limit,
    )
    t_build = time.perf_counter()
    problem = _Problem(spec)
    build_time = time.perf_counter() - t_build

    solves: list[_Solve] = []
    applied: list[F] = []
    state = x_init
    failed_step: int | None = None
    failure: tuple[Status, str] | None = None
    previous: _Solve | None = None
    plan: _Solve | None = None  # the last successful plan (the fallback after a failed solve)
    plan_age = 0
    rounds = 1 if run_mode == "open_loop" else n_steps
    for k in range(rounds):
        if warm_start and previous is not None:
            guess = problem.shifted(previous)
        elif k == 0 and guess_inputs is not None:
            guess = problem.guess_from(state, guess_inputs)
        else:
            guess = problem.cold_guess(state)
        result = problem.solve(state, _window(target, k, n_horizon), guess, previous if warm_start else None)
        solves.append(result)
        if result.success:
            plan, plan_age = result, 0
        else:
            kind = _classify(result.status)
            if failure is None:
                failed_step, failure = k, (kind, f"step {k}: {chosen} returned {result.status!r}")
            _LOG.debug("mpc step %d: %s returned %s", k, chosen, result.status)
            if kind == "infeasible":
                break
        if run_mode == "open_loop":
            finite = np.nan_to_num(result.inputs[:n_steps], nan=0.0, posinf=0.0, neginf=0.0)
            applied = [np.clip(u, u_lo, u_hi) for u in finite]
            break
        if result.success:
            u = result.inputs[0]
        elif plan is not None and plan_age + 1 < n_horizon:
            plan_age += 1
            u = plan.inputs[plan_age]
        else:
            u = np.nan_to_num(result.inputs[0], nan=0.0, posinf=0.0, neginf=0.0)
        u = np.clip(u, u_lo, u_hi)
        applied.append(u)
        state = model.step(state, u, step_dt, method=meth)  # type: ignore[arg-type]
        if not np.all(np.isfinite(state)):
            if failure is None:
                failed_step, failure = k, ("failed", f"step {k}: the simulated state is not finite")
            break
        # A failed solve's iterate still seeds the next one, unless it is not finite.
        previous = result if np.all(np.isfinite(result.w)) else None

    inputs = np.asarray(applied, dtype=np.float64).reshape(-1, n_u)
    states = model.rollout(x_init, inputs, step_dt, method=meth)  # type: ignore[arg-type]
    finite_rows = np.isfinite(states).all(axis=1)
    if not finite_rows.all():  # the model diverged under the applied inputs: keep the finite prefix
        k = int(np.argmin(finite_rows))
        states, inputs = states[:k], inputs[: k - 1]
        if failure is None:
            failed_step, failure = k - 1, ("failed", f"step {k - 1}: the simulated state is not finite")
    cost = _trajectory_cost(model, states, inputs, target, on_position, q, r, qf)
    last = solves[-1]
    if failure is None:
        status: Status = "solved"
        message = f"{chosen}: {len(solves)} solve(s) succeeded ({last.status})"
    else:
        status, message = failure
    return MPCResult(
        status=status,
        message=message,
        cost=cost if math.isfinite(cost) else None,
        solve_time=time.perf_counter() - t_start,
        states=states,
        inputs=inputs,
        times=times[: len(states)],
        step_status=tuple(s.status for s in solves),
        iterations=tuple(s.iterations for s in solves),
        solve_times=tuple(s.seconds for s in solves),
        build_time=build_time,
        failed_step=failed_step,
        predicted_states=last.states if np.all(np.isfinite(last.states)) else None,
        predicted_inputs=last.inputs if np.all(np.isfinite(last.inputs)) else None,
        **base,
    )


def _trajectory_cost(
    model: Dynamics, states: F, inputs: F, target: F, on_position: bool, q: F, r: F, qf: F
) -> float:
    """The MPC objective evaluated on the simulated trajectory (the reference padded past its end)."""
    z = model.position(states) if on_position else states
    ref = _window(target, 0, len(states) - 1)
    e = z - ref
    stage = np.einsum("ki,ij,kj->", e[:-1], q, e[:-1]) + np.einsum("ki,ij,kj->", inputs, r, inputs)
    return float(stage + e[-1] @ qf @ e[-1])
