"""Gradient-based trajectory optimization with torch: batched random restarts, Adam, exact bounds.

The decision variables are unconstrained ``z`` of shape ``(restarts, horizon, n_u)``. Inputs are
``u = mid + half * tanh(z)`` for components bounded on both sides (``mid``, ``half``: the centre and
half-width of ``[u_min, u_max]``), ``u_min + softplus(z)`` or ``u_max - softplus(z)`` for one-sided
bounds, and ``u = z`` for unbounded ones. Every iterate therefore respects the bounds; the
returned inputs are also clipped to them, so rounding cannot push a value out by an ulp.

All restarts are rolled out at once with :meth:`audere.dynamics.Dynamics.rollout_torch` and
optimized together by one Adam optimizer (their losses are independent, so the gradient of the
sum is each restart's own gradient). The loss adds the terms that are given: goal, reference,
obstacle clearance through a differentiable signed distance (circles and axis-aligned boxes),
input effort, and a smooth STL robustness term (soft minimum and maximum by log-sum-exp with a
``temperature``, which tends to the exact robustness as the temperature goes to 0).
"""

from __future__ import annotations

import math
import time
from collections.abc import Mapping, Sequence
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray
from pydantic import Field

from audere._arrays import FloatArray, as_float_array
from audere._optional import require
from audere.apis import Result
from audere.apis._registry import register_api
from audere.controllers._lqr import _model, input_bounds
from audere.dynamics import Dynamics, IntegrationMethod
from audere.errors import InvalidArgumentError
from audere.stl import (
    Always,
    And,
    Compare,
    Constant,
    Eventually,
    Formula,
    Implies,
    In,
    Not,
    Or,
    RegionShape,
    Until,
    parse,
    robustness,
)
from audere.world import Circle, Obstacle, Rectangle, Square, Workspace, signed_distance

__all__ = ["GradResult", "grad", "smooth_robustness"]

F = NDArray[np.float64]

_BIG = 1e9
"""Stand-in for the infinite robustness of ``true`` / ``false`` (keeps log-sum-exp finite)."""


class GradResult(Result):
    """Result of :func:`audere.planners.grad`: the best restart's inputs, rollout, loss history."""

    loss_history: FloatArray = Field(
        description="Lowest loss over the restarts at each iteration, shape (iterations,)."
    )
    restart_losses: FloatArray = Field(description="Best loss reached by each restart, shape (restarts,).")
    best_restart: int = Field(description="Index of the restart whose inputs are returned.")
    iterations: int = Field(description="Adam iterations run.")
    robustness: float | None = Field(
        None, description="Exact STL robustness of the returned trajectory (when a spec was given)."
    )


# ------------------------------------------------------------------------------ smooth robustness


def _soft_min(torch: Any, values: Any, dim: int, temperature: float) -> Any:
    return -temperature * torch.logsumexp(-values / temperature, dim=dim)


def _soft_max(torch: Any, values: Any, dim: int, temperature: float) -> Any:
    return temperature * torch.logsumexp(values / temperature, dim=dim)


def _box(shape: Square | Rectangle | Workspace) -> tuple[float, float, float, float]:
    if isinstance(shape, Square):
        (cx, cy), h = shape.center, shape.half_side
        return cx - h, cx + h, cy - h, cy + h
    return shape.xmin, shape.xmax, shape.ymin, shape.ymax


def _soft_trace(torch: Any, node: Formula, p: Any, regions: Mapping[str, RegionShape], tau: float) -> Any:
    """Smooth robustness trace of ``node`` on positions ``p`` (B, n, 2): shape (B, n - horizon)."""
    x, y = p[..., 0], p[..., 1]
    if isinstance(node, Constant):
        return torch.full_like(x, _BIG if node.value else -_BIG)
    if isinstance(node, In):
        shape = regions[node.name]
        if isinstance(shape, Circle):
            cx, cy = shape.center
            return shape.radius - torch.sqrt((x - cx) ** 2 + (y - cy) ** 2 + 1e-12)
        xmin, xmax, ymin, ymax = _box(shape)  # type: ignore[arg-type]
        margins = torch.stack([x - xmin, xmax - x, y - ymin, ymax - y], dim=-1)
        return _soft_min(torch, margins, -1, tau)
    if isinstance(node, Compare):
        s = node.a * x + node.b * y
        return s - node.rhs if node.op == ">=" else node.rhs - s
    if isinstance(node, Not):
        return -_soft_trace(torch, node.child, p, regions, tau)
    if isinstance(node, And | Or | Implies):
        if isinstance(node, Implies):
            parts = [
                -_soft_trace(torch, node.left, p, regions, tau),
                _soft_trace(torch, node.right, p, regions, tau),
            ]
        else:
            parts = [_soft_trace(torch, child, p, regions, tau) for child in node.operands]
        length = min(part.shape[-1] for part in parts)
        stacked = torch.stack([part[..., :length] for part in parts], dim=-1)
        reduce = _soft_min if isinstance(node, And) else _soft_max
        return reduce(torch, stacked, -1, tau)
    if isinstance(node, Always | Eventually):
        child = _soft_trace(torch, node.child, p, regions, tau)
        length = child.shape[-1] - node.hi
        width = node.hi - node.lo + 1
        windows = child[..., node.lo : length + node.hi].unfold(-1, width, 1)  # (B, length, width)
        reduce = _soft_min if isinstance(node, Always) else _soft_max
        return reduce(torch, windows, -1, tau)
    if isinstance(node, Until):
        left = _soft_trace(torch, node.left, p, regions, tau)
        right = _soft_trace(torch, node.right, p, regions, tau)
        length = min(left.shape[-1], right.shape[-1]) - node.hi
        terms = []
        for k in range(node.lo, node.hi + 1):
            parts = [right[..., k : k + length]] + [left[..., j : j + length] for j in range(k)]
            terms.append(
                _soft_min(torch, torch.stack(parts, dim=-1), -1, tau) if len(parts) > 1 else parts[0]
            )
        return _soft_max(torch, torch.stack(terms, dim=-1), -1, tau)
    raise TypeError(f"not an STL formula node: {type(node).__name__}")  # pragma: no cover


def _check_spec(
    spec: Formula | str, regions: Mapping[str, RegionShape] | None, horizon: int | None
) -> tuple[Formula, Mapping[str, RegionShape]]:
    formula = parse(spec) if isinstance(spec, str) else spec
    if not isinstance(formula, Formula):
        raise InvalidArgumentError(f"spec must be an STL Formula or its text, got {type(spec).__name__}")
    regs: Mapping[str, RegionShape] = {} if regions is None else regions
    if not isinstance(regs, Mapping):
        raise InvalidArgumentError(
            f"regions must be a mapping from region name to shape, got {type(regs).__name__}"
        )
    missing = sorted(formula.regions() - set(regs))
    if missing:
        raise InvalidArgumentError(
            f"regions is missing {', '.join(map(repr, missing))}, used by the spec "
            f"(given: {', '.join(sorted(regs)) or 'none'})"
        )
    for name in sorted(formula.regions()):
        if not isinstance(regs[name], Circle | Square | Rectangle | Workspace):
            raise InvalidArgumentError(
                f"regions[{name!r}] must be a Circle, Square, Rectangle or Workspace for smooth robustness, "
                f"got {type(regs[name]).__name__}"
            )
    if horizon is not None and formula.horizon() > horizon:
        raise InvalidArgumentError(
            f"spec needs {formula.horizon()} steps after t = 0 but the horizon is {horizon} steps"
        )
    return formula, regs


def _check_temperature(temperature: float) -> float:
    ok = isinstance(temperature, int | float) and not isinstance(temperature, bool)
    if not (ok and math.isfinite(temperature) and temperature > 0):
        raise InvalidArgumentError(f"temperature must be a finite number > 0 (metres), got {temperature!r}")
    return float(temperature)


def smooth_robustness(
    spec: Formula | str,
    positions: ArrayLike,
    regions: Mapping[str, RegionShape],
    *,
    temperature: float = 0.05,
) -> F:
    """Smooth STL robustness at step 0: minima and maxima replaced by log-sum-exp.

    ``softmin(a) = -temperature * log(sum(exp(-a / temperature)))`` and ``softmax`` likewise, applied
    over the formula tree (``&``, ``G``: soft minimum; ``|``, ``F``: soft maximum; ``U``: both; box
    regions use the soft minimum of their four margins). Each soft operator is within
    ``temperature * log(n)`` of the exact one over ``n`` values, so the result tends to
    :func:`audere.stl.robustness` as ``temperature -> 0``. This is the differentiable term
    :func:`grad` maximizes (computed there on torch tensors).

    Parameters
    ----------
    spec
        The STL formula, or its text.
    positions
        Planar positions, shape ``(T+1, 2)`` or batched ``(B, T+1, 2)``, metres.
    regions
        Region name to shape (circles and axis-aligned boxes: Circle, Square, Rectangle, Workspace).
    temperature
        Smoothing length in metres, ``> 0``.

    Returns
    -------
    numpy.ndarray
        Smooth robustness, shape ``()`` for one signal or ``(B,)`` for a batch.

    Raises
    ------
    InvalidArgumentError
        For a bad spec, missing or unsupported regions, a short signal or a bad temperature.
    MissingDependencyError
        When torch is not installed (``pip install 'audere[torch]'``).
    """
    tau = _check_temperature(temperature)
    arr = as_float_array(positions, name="positions")
    if arr.ndim not in (2, 3) or arr.shape[-1] != 2:
        raise InvalidArgumentError(
            f"positions must have shape (T+1, 2) or (B, T+1, 2), got shape {arr.shape}"
        )
    formula, regs = _check_spec(spec, regions, arr.shape[-2] - 1)
    torch = require("torch", extra="torch", purpose="smooth STL robustness")
    batch = torch.as_tensor(arr.reshape(-1, *arr.shape[-2:]), dtype=torch.float64)
    with torch.no_grad():
        value = _soft_trace(torch, formula, batch, regs, tau)[..., 0]
    out = np.asarray(value.numpy(), dtype=np.float64)
    return out.reshape(arr.shape[:-2])


# ------------------------------------------------------------------------------ obstacles


def _torch_signed_distance(torch: Any, shape: Obstacle, p: Any) -> Any:
    """Differentiable signed distance (negative inside) to a circle or an axis-aligned box."""
    if isinstance(shape, Circle):
        cx, cy = shape.center
        return torch.sqrt((p[..., 0] - cx) ** 2 + (p[..., 1] - cy) ** 2 + 1e-12) - shape.radius
    xmin, xmax, ymin, ymax = _box(shape)  # type: ignore[arg-type]
    qx = torch.abs(p[..., 0] - 0.5 * (xmin + xmax)) - 0.5 * (xmax - xmin)
    qy = torch.abs(p[..., 1] - 0.5 * (ymin + ymax)) - 0.5 * (ymax - ymin)
    outside = torch.sqrt(torch.clamp(qx, min=0.0) ** 2 + torch.clamp(qy, min=0.0) ** 2 + 1e-12)
    inside = torch.clamp(torch.maximum(qx, qy), max=0.0)
    return outside + inside


# ------------------------------------------------------------------------------ the API


def _vector(value: ArrayLike, n: int, name: str) -> F:
    arr = as_float_array(value, name=name)
    if arr.ndim == 0:
        arr = np.full(n, float(arr))
    if arr.shape != (n,) or np.any(arr < 0):
        raise InvalidArgumentError(
            f"{name} must be a non-negative scalar or {n} non-negative values, got {arr.tolist()}"
        )
    return arr


def _number(value: object, name: str, *, positive: bool = False) -> float:
    ok = isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)
    if not ok or (value <= 0 if positive else value < 0):  # type: ignore[operator]
        raise InvalidArgumentError(
            f"{name} must be a finite number {'> 0' if positive else '>= 0'}, got {value!r}"
        )
    return float(value)  # type: ignore[arg-type]


def _count(value: object, name: str) -> int:
    if isinstance(value, bool) or not isinstance(value, int | np.integer) or value < 1:
        raise InvalidArgumentError(f"{name} must be an integer >= 1, got {value!r}")
    return int(value)


@register_api(
    "grad",
    description="Gradient-based trajectory optimization (torch, Adam, random restarts, exact input bounds) "
    "for goal, reference, obstacle and smooth STL costs; use for smooth problems and local refinement.",
    tags=("planning", "trajectory_optimization", "nonlinear"),
)
def grad(
    dynamics: Dynamics | str,
    x0: ArrayLike,
    *,
    horizon: int,
    dt: float,
    goal: ArrayLike | None = None,
    goal_on: Literal["state", "position"] = "state",
    goal_weight: ArrayLike = 1.0,
    angle_indices: Sequence[int] = (),
    reference: ArrayLike | None = None,
    reference_weight: ArrayLike = 1.0,
    obstacles: Sequence[Obstacle] = (),
    margin: float = 0.0,
    obstacle_weight: float = 100.0,
    effort_weight: float = 1e-3,
    spec: Formula | str | None = None,
    regions: Mapping[str, RegionShape] | None = None,
    stl_weight: float = 10.0,
    stl_margin: float = 0.05,
    temperature: float = 0.05,
    u_min: ArrayLike | None = None,
    u_max: ArrayLike | None = None,
    method: IntegrationMethod = "euler",
    restarts: int = 8,
    iterations: int = 200,
    learning_rate: float = 0.05,
    init_inputs: ArrayLike | None = None,
    init_std: float = 0.5,
    seed: int | None = 0,
    time_limit: float = 10.0,
) -> GradResult:
    """Optimize an input sequence by gradient descent (Adam) through a differentiable rollout.

    The loss of a restart is the sum of the terms that are given (``e`` errors with angle
    components wrapped, ``p_k`` the model's planar position at step ``k``)::

        goal_weight . e(T)^2                                      (goal)
      + mean_k reference_weight . e_k^2                            (reference)
      + obstacle_weight * sum_k sum_o max(0, margin - sd_o(p_k))^2 (obstacles)
      + effort_weight * mean_k |u_k|^2                             (effort)
      + stl_weight * max(0, stl_margin - smooth_robustness)        (spec)

    Inputs are reparametrized so that every iterate respects ``[u_min, u_max]`` exactly (module
    docstring). Restart 0 starts from ``init_inputs`` (default: the middle of the bounds), the
    others from random perturbations of it. The best iterate of every restart is kept and the
    restart with the lowest loss is returned, its states recomputed with the numpy rollout.

    Parameters
    ----------
    dynamics
        The model, or its registry name (e.g. ``"unicycle"``).
    x0
        Initial state, shape ``(n_x,)``.
    horizon
        Number of steps, ``>= 1``.
    dt
        Step length in seconds, ``> 0``.
    goal
        Goal: a state ``(n_x,)`` when ``goal_on="state"``, a planar position ``(2,)`` when
        ``goal_on="position"``; ``None`` for no goal term.
    goal_on
        ``"state"`` or ``"position"``: what ``goal`` is.
    goal_weight
        Weight per goal component (scalar or like ``goal``), ``>= 0``.
    angle_indices
        Indices of goal (and reference) components that are angles, wrapped to ``[-pi, pi)``.
    reference
        Reference ``(horizon+1, m)``: the first ``m`` state components wanted at every step.
    reference_weight
        Weight per reference component, ``>= 0``.
    obstacles
        Circles, squares and rectangles whose clearance is penalized (polygons are not supported).
    margin
        Clearance wanted from the obstacles, metres, ``>= 0``.
    obstacle_weight
        Weight of the clearance penalty, ``>= 0``.
    effort_weight
        Weight of the mean squared input, ``>= 0``.
    spec
        STL formula (or its text) on the planar positions ``p_0 .. p_T``; ``None`` for no STL term.
    regions
        Region name to shape for ``spec`` (Circle, Square, Rectangle or Workspace).
    stl_weight
        Weight of the robustness hinge, ``>= 0``.
    stl_margin
        Robustness wanted, metres: the hinge is zero once the smooth robustness exceeds it.
    temperature
        Smoothing length of the soft minimum and maximum, metres, ``> 0`` (smaller: closer to the
        exact robustness, harder to optimize).
    u_min
        Lower input bounds, a scalar or shape ``(n_u,)``; default the model's.
    u_max
        Upper input bounds, a scalar or shape ``(n_u,)``; default the model's.
    method
        Discretization, ``"euler"`` or ``"rk4"`` (use the task's integrator).
    restarts
        Number of restarts optimized in parallel, ``>= 1``.
    iterations
        Maximum Adam iterations, ``>= 1``.
    learning_rate
        Adam step size (in the reparametrized variables), ``> 0``.
    init_inputs
        Initial inputs ``(horizon, n_u)`` or ``(n_u,)`` for restart 0 (clipped into the bounds).
    init_std
        Standard deviation of the random perturbation of the other restarts (reparametrized
        variables), ``>= 0``.
    seed
        Seed of the random restarts (``None``: fresh entropy).
    time_limit
        Wall-clock budget of the iterations in seconds, ``> 0``. It starts once torch is imported and
        the optimizer is built: in a fresh process these one-off costs take 2-8 s (torch's import
        and the first Adam construction), which ``solve_time`` includes.

    Returns
    -------
    GradResult
        ``inputs`` (horizon, n_u) within the bounds, ``states`` (horizon+1, n_x) from the numpy
        rollout, ``times`` (horizon+1,), ``cost`` (the loss), ``loss_history``, ``restart_losses``,
        ``best_restart``, ``iterations``, ``robustness`` (exact, when ``spec`` is given) and
        ``status``: ``solved`` (all iterations ran), ``time_limit`` (stopped by the budget; the best
        iterate so far is returned), ``infeasible`` (the start is inside an obstacle) or ``failed``
        (the loss was never finite).

    Raises
    ------
    InvalidArgumentError
        For bad shapes, NaN, ``u_min > u_max``, unsupported obstacles or regions, a spec longer than
        the horizon, out-of-range options, or nothing to minimize.
    MissingDependencyError
        When torch is not installed (``pip install 'audere[torch]'``).

    Examples
    --------
    >>> from audere.planners import grad
    >>> result = grad("single_integrator", [0.0, 0.0], goal=[1.0, 1.0], horizon=10, dt=0.5,
    ...               u_min=-0.5, u_max=0.5)
    >>> result.status, bool(result.cost < 0.01)  # doctest: +SKIP
    ('solved', True)
    """
    started = time.perf_counter()
    model = _model(dynamics)
    n_x, n_u = model.n_x, model.n_u
    start = as_float_array(x0, name="x0")
    if start.shape != (n_x,):
        raise InvalidArgumentError(
            f"x0 must have shape ({n_x},) {tuple(model.state_names)}, got shape {start.shape}"
        )
    steps = _count(horizon, "horizon")
    n_restarts = _count(restarts, "restarts")
    n_iters = _count(iterations, "iterations")
    lr = _number(learning_rate, "learning_rate", positive=True)
    std0 = _number(init_std, "init_std")
    tau = _check_temperature(temperature)
    _number(time_limit, "time_limit", positive=True)
    if seed is not None and (isinstance(seed, bool) or not isinstance(seed, int | np.integer) or seed < 0):
        raise InvalidArgumentError(f"seed must be a non-negative integer or None, got {seed!r}")
    if goal_on not in ("state", "position"):
        raise InvalidArgumentError(f"goal_on must be 'state' or 'position', got {goal_on!r}")
    angles = tuple(angle_indices)
    lo, hi = input_bounds(model, u_min, u_max)
    model.step(start, np.zeros(n_u), dt, method=method)  # validates dt and method

    g = w_goal = None
    if goal is not None:
        g = as_float_array(goal, name="goal", ndim=1)
        expected = n_x if goal_on == "state" else 2
        if g.shape != (expected,):
            raise InvalidArgumentError(
                f"goal must have shape ({expected},) when goal_on={goal_on!r}, got shape {g.shape}"
            )
        w_goal = _vector(goal_weight, expected, "goal_weight")
        if any(
            isinstance(i, bool) or not isinstance(i, int | np.integer) or not 0 <= i < expected
            for i in angles
        ):
            raise InvalidArgumentError(f"angle_indices must be indices in [0, {expected}), got {angles}")
    ref = w_ref = None
    if reference is not None:
        ref = as_float_array(reference, name="reference", ndim=2)
        if len(ref) != steps + 1 or ref.shape[1] > n_x:
            raise InvalidArgumentError(
                f"reference must have shape ({steps + 1}, m) (horizon + 1 rows, m <= {n_x} state "
                f"components), got shape {ref.shape}"
            )
        w_ref = _vector(reference_weight, ref.shape[1], "reference_weight")
    shapes = tuple(obstacles)
    for i, shape in enumerate(shapes):
        if not isinstance(shape, Circle | Square | Rectangle):
            raise InvalidArgumentError(
                f"obstacles[{i}] must be a Circle, Square or Rectangle (differentiable signed distance), "
                f"got {type(shape).__name__}"
            )
    clearance = _number(margin, "margin")
    w_obs = _number(obstacle_weight, "obstacle_weight")
    w_effort = _number(effort_weight, "effort_weight")
    formula = regs = None
    if spec is not None:
        formula, regs = _check_spec(spec, regions, steps)
    w_stl = _number(stl_weight, "stl_weight")
    if not (isinstance(stl_margin, int | float) and math.isfinite(stl_margin)):
        raise InvalidArgumentError(f"stl_margin must be a finite number (metres), got {stl_margin!r}")
    if g is None and ref is None and not shapes and formula is None and w_effort == 0:
        raise InvalidArgumentError(
            "nothing to minimize: give at least one of goal, reference, obstacles, spec or effort_weight > 0"
        )
    if shapes:
        p0 = model.position(start)
        for i, shape in enumerate(shapes):
            if float(signed_distance(shape, p0)) < 0:
                return GradResult(
                    status="infeasible",
                    message=f"the start position ({p0[0]:g}, {p0[1]:g}) is inside obstacles[{i}]",
                    solve_time=time.perf_counter() - started,
                    loss_history=np.zeros(0),
                    restart_losses=np.zeros(0),
                    best_restart=0,
                    iterations=0,
                )

    # Reparametrization u = mid + half * tanh(z) (two-sided), lo + softplus(z), hi - softplus(z), z.
    finite_lo, finite_hi = np.isfinite(lo), np.isfinite(hi)
    both = finite_lo & finite_hi
    safe_lo, safe_hi = np.where(finite_lo, lo, 0.0), np.where(finite_hi, hi, 0.0)
    mid = np.where(both, 0.5 * (safe_lo + safe_hi), 0.0)
    half = np.where(both, 0.5 * (safe_hi - safe_lo), 1.0)
    if init_inputs is None:
        u_init = np.tile(
            np.where(both, mid, np.where(finite_lo, safe_lo + 1.0, np.where(finite_hi, safe_hi - 1.0, 0.0))),
            (steps, 1),
        )
    else:
        u_init = as_float_array(init_inputs, name="init_inputs")
        if u_init.shape == (n_u,):
            u_init = np.tile(u_init, (steps, 1))
        if u_init.shape != (steps, n_u):
            raise InvalidArgumentError(
                f"init_inputs must have shape ({steps}, {n_u}) (horizon, n_u) or ({n_u},), "
                f"got shape {u_init.shape}"
            )
        u_init = np.clip(u_init, lo, hi)
    with np.errstate(divide="ignore", invalid="ignore"):
        scaled = np.clip((u_init - mid) / np.where(half > 0, half, 1.0), -0.999999, 0.999999)
        z_two = np.arctanh(scaled)
        z_lo = np.log(np.expm1(np.maximum(u_init - safe_lo, 1e-6)))
        z_hi = np.log(np.expm1(np.maximum(safe_hi - u_init, 1e-6)))
    z_init = np.where(both, z_two, np.where(finite_lo, z_lo, np.where(finite_hi, z_hi, u_init)))
    rng = np.random.default_rng(seed)
    z_start = np.repeat(z_init[None], n_restarts, axis=0)
    z_start[1:] += std0 * rng.standard_normal((n_restarts - 1, steps, n_u))

    torch = require("torch", extra="torch", purpose="gradient-based trajectory optimization (planners.grad)")
    threads = torch.get_num_threads()
    torch.set_num_threads(1)  # small problems: intra-op threading only adds overhead
    try:
        t = {"dtype": torch.float64}
        t_mid, t_half = torch.as_tensor(mid, **t), torch.as_tensor(half, **t)
        t_lo, t_hi = torch.as_tensor(safe_lo, **t), torch.as_tensor(safe_hi, **t)
        m_both, m_lo, m_hi = (
            torch.as_tensor(m) for m in (both, finite_lo & ~finite_hi, finite_hi & ~finite_lo)
        )
        t_x0 = torch.as_tensor(start, **t)

        def inputs_of(z: Any) -> Any:
            two = t_mid + t_half * torch.tanh(z)
            softplus = torch.nn.functional.softplus(z)
            return torch.where(
                m_both, two, torch.where(m_lo, t_lo + softplus, torch.where(m_hi, t_hi - softplus, z))
            )

        def wrap(e: Any, idx: Sequence[int]) -> Any:
            if not idx:
                return e
            cols = list(idx)
            wrapped = torch.atan2(torch.sin(e[..., cols]), torch.cos(e[..., cols]))
            e = e.clone()
            e[..., cols] = wrapped
            return e

        t_goal = None if g is None else torch.as_tensor(g, **t)
        t_wgoal = None if w_goal is None else torch.as_tensor(w_goal, **t)
        t_ref = None if ref is None else torch.as_tensor(ref, **t)
        t_wref = None if w_ref is None else torch.as_tensor(w_ref, **t)
        ref_angles = tuple(i for i in angles if ref is not None and i < ref.shape[1])
        need_positions = bool(shapes) or formula is not None or (g is not None and goal_on == "position")

        def loss_of(u: Any) -> Any:
            states = model.rollout_torch(t_x0, u, dt, method=method)  # (R, T+1, n_x)
            loss = torch.zeros(u.shape[0], **t)
            positions = model.position_torch(states) if need_positions else None
            if t_goal is not None:
                end = states[:, -1, :] if goal_on == "state" else positions[:, -1, :]  # type: ignore[index]
                e = wrap(end - t_goal, angles)
                loss = loss + (t_wgoal * e * e).sum(-1)
            if t_ref is not None:
                e = wrap(states[..., : t_ref.shape[1]] - t_ref, ref_angles)
                loss = loss + (t_wref * e * e).sum(-1).mean(-1)
            if shapes:
                for shape in shapes:
                    sd = _torch_signed_distance(torch, shape, positions)
                    loss = loss + w_obs * (torch.clamp(clearance - sd, min=0.0) ** 2).sum(-1)
            if w_effort:
                loss = loss + w_effort * (u * u).sum(-1).mean(-1)
            if formula is not None and regs is not None:
                rho = _soft_trace(torch, formula, positions, regs, tau)[..., 0]
                loss = loss + w_stl * torch.clamp(stl_margin - rho, min=0.0)
            return loss

        z = torch.tensor(z_start, requires_grad=True, **t)
        optimizer = torch.optim.Adam([z], lr=lr)
        clock = time.perf_counter()  # the budget covers the iterations, not torch's one-off warm-up
        best_loss = np.full(n_restarts, np.inf)
        best_z = z_start.copy()
        history: list[float] = []
        status: Literal["solved", "time_limit", "failed"] = "solved"
        message = f"{n_iters} Adam iterations with {n_restarts} restarts"
        for it in range(n_iters):
            if it > 0 and time.perf_counter() - clock > time_limit:
                status = "time_limit"
                message = f"time limit of {time_limit:g} s reached after {it} iterations"
                break
            optimizer.zero_grad()
            losses = loss_of(inputs_of(z))
            values = losses.detach().numpy().copy()
            finite = np.isfinite(values)
            improved = finite & (values < best_loss)
            if improved.any():
                best_loss[improved] = values[improved]
                best_z[improved] = z.detach().numpy()[improved]
            if finite.any():
                history.append(float(values[finite].min()))
            total = torch.where(torch.isfinite(losses), losses, torch.zeros_like(losses)).sum()
            total.backward()
            with torch.no_grad():
                z.grad = torch.nan_to_num(z.grad, nan=0.0, posinf=0.0, neginf=0.0)
            optimizer.step()
        else:
            it = n_iters
        ran = it if status == "time_limit" else n_iters
        if not np.isfinite(best_loss).any():
            return GradResult(
                status="failed",
                message="the loss was never finite (the rollout diverges for every restart)",
                solve_time=time.perf_counter() - started,
                loss_history=np.asarray(history),
                restart_losses=np.zeros(0),
                best_restart=0,
                iterations=ran,
            )
        winner = int(np.argmin(best_loss))
        with torch.no_grad():
            u_best = inputs_of(torch.as_tensor(best_z[winner], **t)).numpy()
    finally:
        torch.set_num_threads(threads)
    inputs = np.clip(np.asarray(u_best, dtype=np.float64), lo, hi)
    states = model.rollout(start, inputs, dt, method=method)
    rob = None
    if formula is not None and regs is not None:
        rob = float(robustness(formula, model.position(states), regs))
    restart_losses = np.where(np.isfinite(best_loss), best_loss, np.finfo(np.float64).max)
    return GradResult(
        status=status,
        message=message,
        cost=float(best_loss[winner]),
        solve_time=time.perf_counter() - started,
        states=states,
        inputs=inputs,
        times=dt * np.arange(steps + 1),
        loss_history=np.asarray(history),
        restart_losses=restart_losses,
        best_restart=winner,
        iterations=ran,
        robustness=rob,
    )
