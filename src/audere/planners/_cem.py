"""The cross-entropy method over input sequences, with batched numpy rollouts.

CEM keeps a Gaussian over input sequences ``(horizon, n_u)`` (a mean and a per-entry standard
deviation). Each iteration draws ``population`` sequences, clips them to the input bounds, rolls
them all out at once with :meth:`audere.dynamics.Dynamics.rollout`, scores them with the cost, and
refits the Gaussian to the best ``elite_fraction`` of them (blended with the previous fit by
``smoothing``). The best sequence ever seen is returned.

Costs are plain callables ``cost(states, inputs) -> (B,)`` on batches; :func:`goal_cost`,
:func:`tracking_cost`, :func:`obstacle_cost` and :func:`effort_cost` build the usual ones, and a
list of costs is summed.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray
from pydantic import Field

from audere._arrays import FloatArray, as_float_array
from audere.apis import Result
from audere.apis._registry import register_api
from audere.controllers._lqr import _model, input_bounds
from audere.dynamics import Dynamics, IntegrationMethod
from audere.errors import InvalidArgumentError
from audere.world import Circle, Obstacle, Polygon, Rectangle, Square, signed_distance

__all__ = [
    "CEMResult",
    "CostFunction",
    "cem",
    "effort_cost",
    "goal_cost",
    "obstacle_cost",
    "tracking_cost",
]

F = NDArray[np.float64]

CostFunction = Callable[[F, F], F]
"""``cost(states, inputs) -> costs``: ``states`` (B, horizon+1, n_x), ``inputs`` (B, horizon, n_u),
``costs`` (B,); lower is better, ``inf`` or ``nan`` marks a rejected sample."""


def _wrap(values: F, indices: Sequence[int]) -> F:
    out = np.array(values, dtype=np.float64)
    if len(indices):
        idx = list(indices)
        out[..., idx] = (out[..., idx] + math.pi) % (2.0 * math.pi) - math.pi
    return out


def _diag(value: ArrayLike, n: int, *, name: str) -> F:
    arr = as_float_array(value, name=name)
    if arr.ndim == 0:
        arr = np.full(n, float(arr))
    if arr.shape != (n,) or np.any(arr < 0):
        raise InvalidArgumentError(
            f"{name} must be a non-negative scalar or {n} non-negative values, got {arr.tolist()}"
        )
    return arr


def _indices(values: Sequence[int], n: int, *, name: str) -> tuple[int, ...]:
    out = tuple(values)
    if any(isinstance(i, bool) or not isinstance(i, int | np.integer) or not 0 <= i < n for i in out):
        raise InvalidArgumentError(f"{name} must be indices in [0, {n}), got {out}")
    return tuple(int(i) for i in out)


def goal_cost(
    goal: ArrayLike,
    *,
    weight: ArrayLike = 1.0,
    running_weight: float = 0.0,
    angle_indices: Sequence[int] = (),
    position_of: Dynamics | None = None,
) -> CostFunction:
    """A cost on the distance of the states to a goal state: terminal, plus optionally along the way.

    ``cost = sum_i w_i e_i(T)^2 + running_weight * mean_k sum_i w_i e_i(k)^2`` with ``e = x - goal``
    (angle components wrapped to ``[-pi, pi)``).

    Parameters
    ----------
    goal
        Goal state, shape ``(n_x,)`` (or its first ``m`` components, shape ``(m,)``); with
        ``position_of``, a planar position ``(2,)``.
    weight
        Per-component weights ``w``: a scalar or shape like ``goal``, non-negative.
    running_weight
        Weight of the mean error over all steps (``0``: terminal only), ``>= 0``.
    angle_indices
        Indices (into ``goal``) of angle components, whose error is wrapped.
    position_of
        A model whose :meth:`~audere.dynamics.Dynamics.position` maps states to the planar points
        compared with a position ``goal`` (e.g. the pendulum's bob); ``None`` compares states.

    Returns
    -------
    CostFunction
        ``cost(states (B, T+1, n_x), inputs (B, T, n_u)) -> (B,)``.

    Examples
    --------
    >>> import numpy as np
    >>> cost = goal_cost([1.0, 0.0])
    >>> cost(np.zeros((1, 3, 2)), np.zeros((1, 2, 2))).tolist()
    [1.0]
    """
    g = as_float_array(goal, name="goal", ndim=1)
    n = len(g)
    w = _diag(weight, n, name="weight")
    angles = _indices(angle_indices, n, name="angle_indices")
    if not (math.isfinite(running_weight) and running_weight >= 0):
        raise InvalidArgumentError(f"running_weight must be a finite number >= 0, got {running_weight!r}")
    if position_of is not None and n != 2:
        raise InvalidArgumentError(f"goal must be a position (x, y) with position_of, got {n} values")

    def cost(states: F, inputs: F) -> F:
        values = states[..., :n] if position_of is None else position_of.position(states)
        err = _wrap(values - g, angles)
        sq = (w * err * err).sum(axis=-1)  # (B, T+1)
        out = sq[:, -1]
        if running_weight:
            out = out + running_weight * sq.mean(axis=-1)
        return np.asarray(out, dtype=np.float64)

    return cost


def tracking_cost(
    reference: ArrayLike,
    *,
    weight: ArrayLike = 1.0,
    angle_indices: Sequence[int] = (),
) -> CostFunction:
    """A cost on the squared distance to a reference at every step, averaged over the steps.

    Parameters
    ----------
    reference
        Reference, shape ``(horizon+1, m)``: full states (``m = n_x``) or their first ``m``
        components (e.g. positions, ``m = 2``).
    weight
        Per-component weights: a scalar or shape ``(m,)``, non-negative.
    angle_indices
        Indices (into the reference's columns) of angle components, whose error is wrapped.

    Returns
    -------
    CostFunction
        ``cost(states (B, horizon+1, n_x), inputs) -> (B,)``: the mean over steps of the weighted
        squared error.
    """
    ref = as_float_array(reference, name="reference", ndim=2)
    m = ref.shape[1]
    w = _diag(weight, m, name="weight")
    angles = _indices(angle_indices, m, name="angle_indices")

    def cost(states: F, inputs: F) -> F:
        if states.shape[-2] != len(ref):
            raise InvalidArgumentError(
                f"tracking_cost: the reference has {len(ref)} rows but the states have {states.shape[-2]} "
                "(horizon + 1 rows are expected)"
            )
        err = _wrap(states[..., :m] - ref, angles)
        return np.asarray((w * err * err).sum(axis=-1).mean(axis=-1), dtype=np.float64)

    return cost


def effort_cost(*, weight: ArrayLike = 1.0) -> CostFunction:
    """A cost on the input effort: the mean over steps of ``sum_j w_j u_j^2``.

    Parameters
    ----------
    weight
        Per-input weights: a non-negative scalar, or one value per input.

    Returns
    -------
    CostFunction
        ``cost(states, inputs (B, horizon, n_u)) -> (B,)``.
    """
    w = as_float_array(weight, name="weight")
    if w.ndim > 1 or np.any(w < 0):
        raise InvalidArgumentError(f"weight must be a non-negative scalar or vector, got {w.tolist()}")

    def cost(states: F, inputs: F) -> F:
        return np.asarray((w * inputs * inputs).sum(axis=-1).mean(axis=-1), dtype=np.float64)

    return cost


def obstacle_cost(
    obstacles: Sequence[Obstacle],
    *,
    dynamics: Dynamics | None = None,
    margin: float = 0.0,
    weight: float = 100.0,
) -> CostFunction:
    """A penalty on positions closer than ``margin`` to an obstacle (or inside it).

    ``cost = weight * sum_k sum_o max(0, margin - sd_o(p_k))^2`` with ``sd_o`` the exact signed
    distance to obstacle ``o`` (:func:`audere.world.signed_distance`, negative inside) and ``p_k``
    the planar position at step ``k``.

    Parameters
    ----------
    obstacles
        World shapes (circles, squares, rectangles, polygons).
    dynamics
        The model whose :meth:`~audere.dynamics.Dynamics.position` gives the planar position; ``None``
        takes the first two state components.
    margin
        Clearance wanted, metres, ``>= 0``.
    weight
        Penalty weight, ``>= 0``.

    Returns
    -------
    CostFunction
        ``cost(states (B, T+1, n_x), inputs) -> (B,)``.
    """
    shapes = tuple(obstacles)
    for i, shape in enumerate(shapes):
        if not isinstance(shape, Circle | Square | Rectangle | Polygon):
            raise InvalidArgumentError(
                f"obstacles[{i}] must be a Circle, Square, Rectangle or Polygon, got {type(shape).__name__}"
            )
    if not (math.isfinite(margin) and margin >= 0):
        raise InvalidArgumentError(f"margin must be a finite number >= 0 (metres), got {margin!r}")
    if not (math.isfinite(weight) and weight >= 0):
        raise InvalidArgumentError(f"weight must be a finite number >= 0, got {weight!r}")

    def cost(states: F, inputs: F) -> F:
        points = dynamics.position(states) if dynamics is not None else states[..., :2]
        flat = np.nan_to_num(points.reshape(-1, 2), nan=1e9, posinf=1e9, neginf=-1e9)
        total = np.zeros(len(flat))
        for shape in shapes:
            total += np.maximum(0.0, margin - signed_distance(shape, flat)) ** 2
        return np.asarray(weight * total.reshape(points.shape[:-1]).sum(axis=-1), dtype=np.float64)

    return cost


class CEMResult(Result):
    """Result of :func:`audere.planners.cem`: the best input sequence, its rollout and cost history."""

    cost_history: FloatArray = Field(
        description="Best cost found after each iteration, shape (iterations,) (iterations before the first "
        "finite cost are left out)."
    )
    iterations: int = Field(description="Iterations run.")
    samples: int = Field(description="Input sequences rolled out in total.")
    mean: FloatArray = Field(description="Final sampling mean, shape (horizon, n_u).")
    std: FloatArray = Field(description="Final sampling standard deviation, shape (horizon, n_u).")


def _positive_int(value: object, name: str, minimum: int = 1) -> int:
    if isinstance(value, bool) or not isinstance(value, int | np.integer) or value < minimum:
        raise InvalidArgumentError(f"{name} must be an integer >= {minimum}, got {value!r}")
    return int(value)


def _unit_interval(value: object, name: str) -> float:
    """A number in ``(0, 1]``."""
    if isinstance(value, bool) or not isinstance(value, int | float) or not 0 < value <= 1:
        raise InvalidArgumentError(f"{name} must be a number in (0, 1], got {value!r}")
    return float(value)


@register_api(
    "cem",
    description="Cross-entropy method over input sequences with batched rollouts and any cost; use for "
    "nonlinear or non-smooth problems (swing-up, reach with obstacles) without gradients.",
    tags=("planning", "trajectory_optimization", "sampling", "nonlinear"),
)
def cem(
    dynamics: Dynamics | str,
    x0: ArrayLike,
    *,
    horizon: int,
    dt: float,
    cost: CostFunction | Sequence[CostFunction] | None = None,
    goal: ArrayLike | None = None,
    goal_on: Literal["state", "position"] = "state",
    goal_weight: ArrayLike = 1.0,
    angle_indices: Sequence[int] = (),
    reference: ArrayLike | None = None,
    reference_weight: ArrayLike = 1.0,
    obstacles: Sequence[Obstacle] = (),
    margin: float = 0.0,
    obstacle_weight: float = 100.0,
    effort_weight: float = 0.0,
    u_min: ArrayLike | None = None,
    u_max: ArrayLike | None = None,
    method: IntegrationMethod = "euler",
    population: int = 256,
    elite_fraction: float = 0.1,
    iterations: int = 50,
    smoothing: float = 0.2,
    init_mean: ArrayLike | None = None,
    init_std: ArrayLike | None = None,
    min_std: float = 1e-3,
    target_cost: float | None = None,
    seed: int | None = 0,
    time_limit: float = 10.0,
) -> CEMResult:
    """Minimize a trajectory cost over input sequences with the cross-entropy method.

    Each iteration samples ``population`` sequences from ``N(mean, std^2)`` (entry-wise), clips them
    to ``[u_min, u_max]``, rolls them out from ``x0``, and refits ``mean`` and ``std`` to the elite
    samples: ``mean <- smoothing * mean + (1 - smoothing) * mean(elites)`` (the same for ``std``).
    The best sequence found so far is always part of the next population.

    Parameters
    ----------
    dynamics
        The model, or its registry name (e.g. ``"pendulum"``).
    x0
        Initial state, shape ``(n_x,)``.
    horizon
        Number of steps, ``>= 1``.
    dt
        Step length in seconds, ``> 0``.
    cost
        ``cost(states (B, horizon+1, n_x), inputs (B, horizon, n_u)) -> (B,)``, lower is better
        (``inf``/``nan`` reject a sample), or a sequence of such callables that are summed. Build
        them with :func:`goal_cost`, :func:`tracking_cost`, :func:`obstacle_cost`,
        :func:`effort_cost`, or write one. ``None``: only the terms below. At least one term is
        needed.
    goal
        Adds ``goal_cost(goal, weight=goal_weight, angle_indices=angle_indices)`` (terminal squared
        error): a state ``(n_x,)`` when ``goal_on="state"``, a planar position ``(2,)`` (compared with
        the model's position) when ``goal_on="position"``.
    goal_on
        ``"state"`` or ``"position"``: what ``goal`` is.
    goal_weight
        Weight per goal component (scalar or like ``goal``), ``>= 0``.
    angle_indices
        Indices of ``goal`` (and ``reference``) components that are angles, wrapped to ``[-pi, pi)``.
    reference
        Adds ``tracking_cost(reference, weight=reference_weight)``: shape ``(horizon+1, m)``, the
        first ``m`` state components wanted at every step.
    reference_weight
        Weight per reference component, ``>= 0``.
    obstacles
        Adds ``obstacle_cost(obstacles, margin=margin, weight=obstacle_weight)`` on the model's
        planar positions: circles, squares, rectangles or polygons.
    margin
        Clearance wanted from the obstacles, metres, ``>= 0``.
    obstacle_weight
        Weight of the obstacle penalty, ``>= 0``.
    effort_weight
        Adds ``effort_cost(weight=effort_weight)`` when ``> 0``.
    u_min
        Lower input bounds, a scalar or shape ``(n_u,)``; default the model's. Samples are clipped.
    u_max
        Upper input bounds, a scalar or shape ``(n_u,)``; default the model's.
    method
        Discretization, ``"euler"`` or ``"rk4"`` (use the task's integrator).
    population
        Samples per iteration, ``>= 2``.
    elite_fraction
        Fraction of the population refitted to, in ``(0, 1]`` (at least one sample).
    iterations
        Maximum number of iterations, ``>= 1``.
    smoothing
        Weight of the previous mean and standard deviation in the update, in ``[0, 1)``.
    init_mean
        Initial mean ``(horizon, n_u)`` or ``(n_u,)``; default the middle of the bounds (0 where
        unbounded).
    init_std
        Initial standard deviation, same shapes or a scalar, ``> 0``; default half the bound range
        (1 where unbounded).
    min_std
        Floor of the standard deviation, ``>= 0`` (keeps exploring).
    target_cost
        Stop as soon as the best cost is at or below this value; ``None`` runs every iteration.
    seed
        Seed of the random generator (``None``: fresh entropy, not reproducible).
    time_limit
        Wall-clock budget in seconds, ``> 0``.

    Returns
    -------
    CEMResult
        ``inputs`` (horizon, n_u) clipped to the bounds, their rollout ``states`` (horizon+1, n_x),
        ``times`` (horizon+1,), ``cost``, ``cost_history`` (best cost after each iteration),
        ``iterations``, ``samples``, the final ``mean`` and ``std``, and ``status``: ``solved`` (all
        iterations ran or ``target_cost`` was reached), ``time_limit`` (stopped by the budget; the best
        sequence so far is returned), ``infeasible`` (the start is inside one of ``obstacles``) or
        ``failed`` (no sample had a finite cost).

    Raises
    ------
    InvalidArgumentError
        For bad shapes, NaN, ``u_min > u_max``, out-of-range options, or a cost that does not return
        one number per sample.

    Examples
    --------
    >>> from audere.planners import cem
    >>> result = cem("single_integrator", [0.0, 0.0], goal=[1.0, 1.0], horizon=5, dt=1.0,
    ...              u_min=-0.5, u_max=0.5)
    >>> result.status, bool(result.cost < 1e-2)
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
    steps = _positive_int(horizon, "horizon")
    costs: tuple[CostFunction, ...] = ()
    if cost is not None:
        costs = (cost,) if callable(cost) else tuple(cost) if isinstance(cost, Sequence) else ()
        if not costs or not all(callable(c) for c in costs):
            raise InvalidArgumentError(
                "cost must be a callable cost(states, inputs) -> (B,) or a non-empty sequence of them, "
                f"got {cost!r}"
            )
    if goal_on not in ("state", "position"):
        raise InvalidArgumentError(f"goal_on must be 'state' or 'position', got {goal_on!r}")
    if goal is not None:
        g = as_float_array(goal, name="goal", ndim=1)
        expected = n_x if goal_on == "state" else 2
        if g.shape != (expected,):
            raise InvalidArgumentError(
                f"goal must have shape ({expected},) when goal_on={goal_on!r}, got shape {g.shape}"
            )
        position_of = model if goal_on == "position" else None
        costs += (goal_cost(g, weight=goal_weight, angle_indices=angle_indices, position_of=position_of),)
    if reference is not None:
        ref = as_float_array(reference, name="reference", ndim=2)
        if len(ref) != steps + 1 or ref.shape[1] > n_x:
            raise InvalidArgumentError(
                f"reference must have shape ({steps + 1}, m) (horizon + 1 rows, m <= {n_x} state "
                f"components), got shape {ref.shape}"
            )
        ref_angles = tuple(i for i in angle_indices if isinstance(i, int) and i < ref.shape[1])
        costs += (tracking_cost(ref, weight=reference_weight, angle_indices=ref_angles),)
    if len(obstacles):
        costs += (obstacle_cost(obstacles, dynamics=model, margin=margin, weight=obstacle_weight),)
    if not (isinstance(effort_weight, int | float) and math.isfinite(effort_weight) and effort_weight >= 0):
        raise InvalidArgumentError(f"effort_weight must be a finite number >= 0, got {effort_weight!r}")
    if effort_weight > 0:
        costs += (effort_cost(weight=effort_weight),)
    if not costs:
        raise InvalidArgumentError(
            "nothing to minimize: give cost (a callable), or at least one of goal, reference, obstacles "
            "or effort_weight > 0"
        )
    pop = _positive_int(population, "population", 2)
    iters = _positive_int(iterations, "iterations")
    elite = _unit_interval(elite_fraction, "elite_fraction")
    if not (isinstance(smoothing, int | float) and 0 <= smoothing < 1):
        raise InvalidArgumentError(f"smoothing must be a number in [0, 1), got {smoothing!r}")
    if not (isinstance(min_std, int | float) and math.isfinite(min_std) and min_std >= 0):
        raise InvalidArgumentError(f"min_std must be a finite number >= 0, got {min_std!r}")
    if isinstance(time_limit, bool) or not (isinstance(time_limit, int | float) and time_limit > 0):
        raise InvalidArgumentError(f"time_limit must be a positive number of seconds, got {time_limit!r}")
    if target_cost is not None and not (isinstance(target_cost, int | float) and not math.isnan(target_cost)):
        raise InvalidArgumentError(f"target_cost must be a number or None, got {target_cost!r}")
    if seed is not None and (isinstance(seed, bool) or not isinstance(seed, int | np.integer) or seed < 0):
        raise InvalidArgumentError(f"seed must be a non-negative integer or None, got {seed!r}")
    lo, hi = input_bounds(model, u_min, u_max)
    model.step(start, np.zeros(n_u), dt, method=method)  # validates dt and method

    finite_lo, finite_hi = np.isfinite(lo), np.isfinite(hi)
    both = finite_lo & finite_hi
    safe_lo, safe_hi = np.where(finite_lo, lo, 0.0), np.where(finite_hi, hi, 0.0)
    middle = np.where(both, 0.5 * (safe_lo + safe_hi), np.where(finite_lo, safe_lo, safe_hi))
    spread = np.where(both, 0.5 * (safe_hi - safe_lo), 1.0)
    mean = _plan_array(init_mean, steps, n_u, "init_mean", default=middle)
    mean = np.clip(mean, lo, hi)
    std = _plan_array(init_std, steps, n_u, "init_std", default=spread)
    if np.any(std <= 0):
        raise InvalidArgumentError(f"init_std must be > 0, got minimum {float(std.min())}")

    if len(obstacles):
        p0 = model.position(start)
        for i, shape in enumerate(obstacles):
            if float(signed_distance(shape, p0)) < 0:
                return CEMResult(
                    status="infeasible",
                    message=f"the start position ({p0[0]:g}, {p0[1]:g}) is inside obstacles[{i}]",
                    solve_time=time.perf_counter() - started,
                    cost_history=np.zeros(0),
                    iterations=0,
                    samples=0,
                    mean=mean,
                    std=std,
                )
    rng = np.random.default_rng(seed)
    n_elite = max(1, math.ceil(elite * pop))
    best_inputs = mean.copy()
    best_cost = math.inf
    history: list[float] = []
    status: Literal["solved", "time_limit", "failed"] = "solved"
    message = ""
    samples = 0
    for it in range(iters):
        if it > 0 and time.perf_counter() - started > time_limit:
            status = "time_limit"
            message = f"time limit of {time_limit:g} s reached after {it} iterations"
            break
        draws = mean + std * rng.standard_normal((pop, steps, n_u))
        draws[0] = mean
        if math.isfinite(best_cost):
            draws[1] = best_inputs
        draws = np.clip(draws, lo, hi)
        states = model.rollout(start, draws, dt, method=method)
        values = _evaluate(costs, states, draws)
        samples += pop
        values = np.where(np.isfinite(values), values, np.inf)
        order = np.argsort(values, kind="stable")
        if values[order[0]] < best_cost:
            best_cost = float(values[order[0]])
            best_inputs = draws[order[0]].copy()
        if math.isfinite(best_cost):
            history.append(best_cost)
        if target_cost is not None and best_cost <= target_cost:
            message = f"target cost {target_cost:g} reached after {it + 1} iterations"
            break
        elites = draws[order[:n_elite]]
        elites = elites[np.isfinite(values[order[:n_elite]])]
        if len(elites) == 0:
            continue
        mean = smoothing * mean + (1.0 - smoothing) * elites.mean(axis=0)
        std = smoothing * std + (1.0 - smoothing) * elites.std(axis=0)
        std = np.maximum(std, min_std)
    if not math.isfinite(best_cost):
        return CEMResult(
            status="failed",
            message="no sampled input sequence had a finite cost",
            solve_time=time.perf_counter() - started,
            cost_history=np.zeros(0),
            iterations=samples // pop,
            samples=samples,
            mean=mean,
            std=std,
        )
    if status == "solved" and not message:
        message = f"{samples // pop} iterations of {pop} samples"
    best_states = model.rollout(start, best_inputs, dt, method=method)
    return CEMResult(
        status=status,
        message=message,
        cost=best_cost,
        solve_time=time.perf_counter() - started,
        states=best_states,
        inputs=best_inputs,
        times=dt * np.arange(steps + 1),
        cost_history=np.asarray(history),
        iterations=samples // pop,
        samples=samples,
        mean=mean,
        std=std,
    )


def _plan_array(value: ArrayLike | None, steps: int, n_u: int, name: str, *, default: F) -> F:
    if value is None:
        return np.tile(default, (steps, 1)).astype(np.float64)
    arr = as_float_array(value, name=name)
    if arr.ndim == 0:
        return np.full((steps, n_u), float(arr))
    if arr.shape == (n_u,):
        return np.tile(arr, (steps, 1))
    if arr.shape != (steps, n_u):
        raise InvalidArgumentError(
            f"{name} must be a scalar or have shape ({n_u},) or ({steps}, {n_u}) (horizon, n_u), "
            f"got shape {arr.shape}"
        )
    return arr


def _evaluate(costs: tuple[CostFunction, ...], states: F, inputs: F) -> F:
    total = np.zeros(len(states))
    with np.errstate(over="ignore", invalid="ignore"):
        for c in costs:
            value = np.asarray(c(states, inputs), dtype=np.float64)
            if value.shape != (len(states),):
                raise InvalidArgumentError(
                    f"cost must return one number per sample, shape ({len(states)},), got shape {value.shape}"
                )
            total = total + value
    return total
