"""``planners.milp``: plan a trajectory that satisfies an STL specification with a mixed-integer program.

The robustness of the specification is encoded exactly with big-M constraints
(:mod:`audere.planners._stl_milp`), the dynamics (single or double integrator, Euler steps) and the
bounds are linear, obstacles are avoided segment by segment with binaries, and the program is
solved through cvxpy (HiGHS by default).
"""

from __future__ import annotations

import logging
import math
import time
import warnings
from collections.abc import Mapping, Sequence
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray
from pydantic import Field

from audere._arrays import FloatArray, as_float_array
from audere._optional import require
from audere.apis import Result, Status, register_api
from audere.errors import InvalidArgumentError
from audere.planners._stl_milp import Affine, LinearModel, StlEncoder, box_of
from audere.stl import Formula, parse, robustness
from audere.world import Circle, Polygon, Rectangle, Square, Workspace, contains

__all__ = ["MILPResult", "milp"]

logger = logging.getLogger(__name__)

MIP_SOLVERS = ("HIGHS", "SCIPY", "GUROBI", "SCIP", "CBC", "CPLEX", "MOSEK", "COPT")
"""cvxpy solvers that handle mixed-integer linear programs and whose time limit we know how to set."""

FEASIBILITY_TOLERANCE = 1e-6
"""Positions keep this far inside the workspace and outside obstacles (metres), and a returned point
may violate the program by this much; solvers are only accurate to about 1e-7."""

CIRCLE_SIDES = 8
"""A circular obstacle is replaced by the regular polygon with this many sides drawn around it."""


class MILPResult(Result):
    """Result of :func:`milp`.

    ``states`` (horizon+1, n_x) and ``inputs`` (horizon, 2) are ``None`` unless a feasible point was
    found. ``states`` are the exact Euler rollout of the returned ``inputs`` from ``x0``.
    """

    robustness: float | None = Field(
        None, description="Robustness of the spec as encoded in the program (value of its variable)."
    )
    checked_robustness: float | None = Field(
        None, description="Robustness recomputed with audere.stl.robustness on the returned positions."
    )
    solver: str = Field("", description="The solver used (cvxpy name, e.g. HIGHS).")
    solver_status: str = Field("", description="The solver's own status, as reported through cvxpy.")
    n_binaries: int = Field(0, ge=0, description="Number of binary variables of the program.")
    n_constraints: int = Field(0, ge=0, description="Number of linear constraints (rows) of the program.")
    n_variables: int = Field(0, ge=0, description="Number of variables of the program.")
    objective: str = Field("", description="max_robustness or min_effort.")
    effort: float | None = Field(None, description="dt * sum(|inputs|) of the returned inputs.")


def _validate_spec(spec: Formula | str) -> Formula:
    if isinstance(spec, str):
        return parse(spec)
    if not isinstance(spec, Formula):
        raise InvalidArgumentError(
            f"spec must be an STL Formula or its text, got {type(spec).__name__} {spec!r}"
        )
    return spec


def _validate_regions(spec: Formula, regions: Mapping[str, object]) -> dict[str, object]:
    if not isinstance(regions, Mapping):
        raise InvalidArgumentError(
            f"regions must be a mapping from region name to shape, got {type(regions).__name__}"
        )
    used = spec.regions()
    missing = sorted(used - set(regions))
    if missing:
        given = ", ".join(sorted(map(str, regions))) or "none"
        raise InvalidArgumentError(
            f"regions is missing {', '.join(map(repr, missing))}, used by the spec (given: {given})"
        )
    for name in sorted(used):
        shape = regions[name]
        if box_of(shape) is None:
            kind = type(shape).__name__
            why = (
                "its robustness (radius - distance) is not linear"
                if isinstance(shape, Circle)
                else "its robustness (a Euclidean signed distance) is not linear outside it"
                if isinstance(shape, Polygon)
                else "it is not a world shape"
            )
            raise InvalidArgumentError(
                f"regions[{name!r}] must be an axis-aligned box (Rectangle, Square or Workspace) for the "
                f"MILP, got a {kind}: {why}; replace it by a box (e.g. an inscribed Rectangle)"
            )
    return {name: regions[name] for name in used}


def _bounds(
    u_min: ArrayLike | None, u_max: ArrayLike | None
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    def one(value: ArrayLike | None, name: str, default: float) -> NDArray[np.float64]:
        if value is None:
            return np.full(2, default)
        arr = as_float_array(value, name=name, finite=False)
        if arr.ndim == 0:
            arr = np.full(2, float(arr))
        if arr.shape != (2,):
            raise InvalidArgumentError(f"{name} must be a number or have shape (2,), got shape {arr.shape}")
        if np.isnan(arr).any():
            raise InvalidArgumentError(f"{name} must not contain NaN, got {arr.tolist()}")
        return arr

    hi = one(u_max, "u_max", math.inf)
    lo = -hi if u_min is None else one(u_min, "u_min", -math.inf)
    if (lo > hi).any():
        raise InvalidArgumentError(
            f"u_min must be <= u_max on every axis, got u_min={lo.tolist()}, u_max={hi.tolist()}"
        )
    return lo, hi


def _faces(shape: object, index: int) -> list[tuple[NDArray[np.float64], float]]:
    """Outward half-planes ``a . p >= b`` of a convex obstacle (outside of face ``i``)."""
    box = box_of(shape)
    if box is not None and not isinstance(shape, Workspace):
        xmin, xmax, ymin, ymax = box
        return [
            (np.array([-1.0, 0.0]), -xmin),
            (np.array([1.0, 0.0]), xmax),
            (np.array([0.0, -1.0]), -ymin),
            (np.array([0.0, 1.0]), ymax),
        ]
    if isinstance(shape, Circle):
        n = CIRCLE_SIDES
        c = np.asarray(shape.center, dtype=np.float64)
        angles = 2 * np.pi * np.arange(n) / n
        return [
            (
                np.array([math.cos(a), math.sin(a)]),
                float(np.dot([math.cos(a), math.sin(a)], c) + shape.radius),
            )
            for a in angles
        ]
    if isinstance(shape, Polygon):
        v = np.asarray(shape.vertices, dtype=np.float64)
        if len(v) > 3 and np.allclose(v[0], v[-1]):
            v = v[:-1]
        edges = np.roll(v, -1, axis=0) - v
        area2 = float(np.sum(v[:, 0] * np.roll(v[:, 1], -1) - np.roll(v[:, 0], -1) * v[:, 1]))
        turns = edges[:, 0] * np.roll(edges[:, 1], -1) - edges[:, 1] * np.roll(edges[:, 0], -1)
        if (turns * np.sign(area2) < -1e-12).any():
            raise InvalidArgumentError(
                f"obstacles[{index}] must be convex for the MILP (a non-convex Polygon cannot be avoided "
                "with one disjunction); split it into convex polygons"
            )
        faces = []
        for p, e in zip(v, edges, strict=True):
            normal = np.array([e[1], -e[0]]) if area2 > 0 else np.array([-e[1], e[0]])
            length = float(np.hypot(*normal))
            if length == 0:
                continue
            normal /= length
            faces.append((normal, float(np.dot(normal, p))))
        return faces
    raise InvalidArgumentError(
        f"obstacles[{index}] must be a Rectangle, Square, Circle or convex Polygon, "
        f"got {type(shape).__name__}"
    )


def _solver_options(solver: str, time_limit: float) -> dict[str, Any]:
    if solver == "HIGHS":
        # More primal heuristics than HiGHS's default 0.05: a third faster on plan-stl (median).
        return {"time_limit": time_limit, "mip_heuristic_effort": 0.3}
    if solver == "SCIPY":
        return {"scipy_options": {"time_limit": time_limit}}
    if solver in ("GUROBI", "COPT"):
        return {"TimeLimit": time_limit}
    if solver == "SCIP":
        return {"scip_params": {"limits/time": time_limit}}
    if solver == "CBC":
        return {"maximumSeconds": max(1, math.ceil(time_limit))}
    if solver == "CPLEX":
        return {"cplex_params": {"timelimit": time_limit}}
    return {"mosek_params": {"MSK_DPAR_MIO_MAX_TIME": time_limit}}  # MOSEK


def _status_text(problem: Any, solver: str) -> str:
    """The solver's own status, where cvxpy keeps it, else cvxpy's status."""
    status = str(problem.status)
    cache = getattr(problem, "_solver_cache", None)
    if isinstance(cache, dict) and solver in cache:
        entry = cache[solver]
        if isinstance(entry, tuple) and len(entry) == 3 and isinstance(entry[2], dict):
            own = entry[2].get("model_status")
            if own:
                return f"{own} (cvxpy: {status})"
    return status


@register_api(
    "milp",
    description="Plan a trajectory satisfying an STL spec over box regions with a mixed-integer program "
    "(exact big-M robustness; max robustness or min effort); use for temporal-logic tasks.",
    tags=("planning", "stl", "optimization", "milp"),
)
def milp(
    spec: Formula | str,
    regions: Mapping[str, Rectangle | Square | Workspace],
    x0: ArrayLike,
    *,
    horizon: int,
    dt: float = 1.0,
    u_max: ArrayLike | None = None,
    u_min: ArrayLike | None = None,
    dynamics: Literal["single_integrator", "double_integrator"] = "single_integrator",
    workspace: Workspace | None = None,
    obstacles: Sequence[Rectangle | Square | Polygon | Circle] = (),
    objective: Literal["max_robustness", "min_effort"] = "max_robustness",
    margin: float = 1e-3,
    robustness_cap: float | None = None,
    big_m: float | None = None,
    solver: str | None = None,
    time_limit: float = 10.0,
) -> MILPResult:
    """Plan positions that satisfy an STL specification by mixed-integer linear programming.

    The robustness of ``spec`` at step 0 is encoded *exactly* with big-M constraints over its
    negation normal form (stlpy's design: predicates are affine, ``&``/``G``/``in(box)`` are minima
    and ``|``/``F``/``!in(box)``/``U`` maxima, each with binaries), so the returned ``robustness``
    equals ``audere.stl.robustness`` of the returned trajectory up to solver tolerance (about 1e-6).
    The program requires ``robustness >= margin`` and either maximizes the robustness (capped at
    ``robustness_cap``) or minimizes the effort ``dt * sum(|u|)``. A ``solved`` result with
    ``margin > 0`` therefore satisfies the spec under audere's strict checker; the small default
    margin keeps trajectories off region boundaries, where the checker counts robustness 0 as a
    failure.

    Parameters
    ----------
    spec
        The STL specification (a formula or its text), evaluated at step 0 on the positions.
    regions
        Region name to shape for every ``in(NAME)`` the spec uses. Only axis-aligned boxes
        (``Rectangle``, ``Square``, ``Workspace``) can be encoded exactly; circles and polygons are
        rejected.
    x0
        Initial state: ``(x, y)`` in metres for the single integrator, ``(x, y, vx, vy)`` (m, m/s)
        for the double integrator. Must lie in the workspace and outside every obstacle.
    horizon
        Number of steps (>= 1); the plan has ``horizon + 1`` states. Must be at least the spec's
        horizon (``spec.horizon()``).
    dt
        Time step in seconds (> 0). Single integrator: ``x[k+1] = x[k] + dt * u[k]``; double
        integrator: ``p[k+1] = p[k] + dt * v[k]``, ``v[k+1] = v[k] + dt * u[k]``.
    u_max
        Per-axis upper input bounds, shape (2,) or one number for both axes (m/s for the single
        integrator, m/s^2 for the double integrator); ``None`` for none.
    u_min
        Per-axis lower input bounds, shape (2,) or one number; ``None`` means ``-u_max``.
    dynamics
        ``"single_integrator"`` (the input is the velocity) or ``"double_integrator"`` (the input is
        the acceleration).
    workspace
        Box every position must stay in (boundary included), or ``None`` for none. Together with the
        input bounds it bounds the positions, from which every big-M is derived.
    obstacles
        Shapes every position and every segment between consecutive positions must avoid:
        ``Rectangle``, ``Square``, convex ``Polygon``, or ``Circle`` (replaced by the regular octagon
        drawn around it, conservative). A segment is kept out by requiring both its ends outside one
        common face (sufficient, slightly conservative at corners).
    objective
        ``"max_robustness"``: maximize ``min(robustness, robustness_cap)``; ``"min_effort"``:
        minimize ``dt * sum(|u|)``. Both require ``robustness >= margin``.
    margin
        Required robustness (finite; metres for region predicates). Keep it > 0 for a trajectory the
        strict checker accepts; a negative margin with ``max_robustness`` returns the least violating
        trajectory.
    robustness_cap
        With ``max_robustness``, robustness above this value earns nothing, so the solver can stop as
        soon as it reaches it (much faster when any satisfying trajectory will do); ``None``: no cap.
        Must be >= ``margin``.
    big_m
        One big-M constant (> 0) for every disjunction, or ``None`` (recommended) to derive a tight one
        per constraint from the workspace and the positions reachable under the input bounds. A given
        value too small can cut off solutions (never makes a wrong trajectory look right).
    solver
        cvxpy name of the MILP solver: ``None`` for HiGHS (license-free), or ``"SCIPY"``, ``"GUROBI"``,
        ``"SCIP"``, ``"CBC"``, ``"CPLEX"``, ``"MOSEK"``, ``"COPT"`` when installed.
    time_limit
        Solver time budget in seconds (> 0); building the program comes on top (milliseconds).

    Returns
    -------
    MILPResult
        ``status``: ``solved`` (a feasible trajectory; optimal up to the solver's gap), ``infeasible``
        (no trajectory reaches ``robustness >= margin``), ``time_limit`` (the budget ran out; the
        message says whether an incumbent trajectory is returned) or ``failed``. With a trajectory:
        ``states`` (horizon+1, n_x), ``inputs`` (horizon, 2), ``times`` (horizon+1,) in seconds,
        ``robustness`` (encoded), ``checked_robustness`` (recomputed), ``effort``; always ``solver``,
        ``solver_status``, ``solve_time`` (s, building included), ``n_binaries``, ``n_constraints``,
        ``n_variables``. ``cost`` is the minimized objective: the effort, or minus the capped
        robustness.

    Raises
    ------
    InvalidArgumentError
        For bad shapes or values, a region that is not a box, a spec longer than ``horizon``, a start
        outside the workspace or inside an obstacle, an unknown solver or one that is not installed.
    MissingDependencyError
        When cvxpy is not installed (``pip install 'audere[milp]'``).

    Examples
    --------
    >>> from audere.planners import milp
    >>> from audere.world import Rectangle, Workspace
    >>> regions = {
    ...     "goal": Rectangle(xmin=8, xmax=9, ymin=8, ymax=9),
    ...     "wall": Rectangle(xmin=4, xmax=6, ymin=0, ymax=7),
    ... }
    >>> result = milp("F[5,10] in(goal) & G[0,10] !in(wall)", regions, (1, 1), horizon=10, u_max=2,
    ...               workspace=Workspace())  # doctest: +SKIP
    >>> result.status, round(result.robustness, 3) == round(result.checked_robustness, 3)  # doctest: +SKIP
    ('solved', True)
    """
    started = time.perf_counter()
    formula = _validate_spec(spec)
    used_regions = _validate_regions(formula, regions)
    if isinstance(horizon, bool) or not isinstance(horizon, int | np.integer) or horizon < 1:
        raise InvalidArgumentError(f"horizon must be an integer >= 1 (steps), got {horizon!r}")
    horizon = int(horizon)
    if formula.horizon() > horizon:
        raise InvalidArgumentError(
            f"horizon must be at least the spec's horizon {formula.horizon()} (steps), got {horizon}"
        )
    dt = _positive(dt, "dt")
    time_limit = _positive(time_limit, "time_limit")
    if dynamics not in ("single_integrator", "double_integrator"):
        raise InvalidArgumentError(
            f"dynamics must be 'single_integrator' or 'double_integrator', got {dynamics!r}"
        )
    n_x = 2 if dynamics == "single_integrator" else 4
    names = "(x, y)" if n_x == 2 else "(x, y, vx, vy)"
    start = as_float_array(x0, name="x0")
    if start.shape != (n_x,):
        raise InvalidArgumentError(
            f"x0 must have shape ({n_x},) {names} for the {dynamics}, got shape {start.shape}"
        )
    lo_u, hi_u = _bounds(u_min, u_max)
    if workspace is not None and not isinstance(workspace, Workspace):
        raise InvalidArgumentError(f"workspace must be a Workspace or None, got {type(workspace).__name__}")
    if objective not in ("max_robustness", "min_effort"):
        raise InvalidArgumentError(f"objective must be 'max_robustness' or 'min_effort', got {objective!r}")
    margin = _finite(margin, "margin")
    if robustness_cap is not None:
        robustness_cap = _finite(robustness_cap, "robustness_cap")
        if robustness_cap < margin:
            raise InvalidArgumentError(f"robustness_cap must be >= margin ({margin}), got {robustness_cap}")
    if big_m is not None:
        big_m = _positive(big_m, "big_m")
    solver_name = _choose_solver(solver)
    if isinstance(obstacles, Mapping) or not isinstance(obstacles, Sequence):
        raise InvalidArgumentError(f"obstacles must be a sequence of shapes, got {type(obstacles).__name__}")
    faces = [_faces(shape, i) for i, shape in enumerate(obstacles)]
    if workspace is not None:
        inside = workspace.xmin <= start[0] <= workspace.xmax and workspace.ymin <= start[1] <= workspace.ymax
        if not inside:
            raise InvalidArgumentError(
                f"x0 must lie in the workspace [{workspace.xmin}, {workspace.xmax}] x [{workspace.ymin}, "
                f"{workspace.ymax}], got position ({start[0]}, {start[1]})"
            )
    for i, shape in enumerate(obstacles):
        if isinstance(shape, Circle | Square | Rectangle | Polygon) and bool(contains(shape, start[:2])):
            raise InvalidArgumentError(
                f"x0 must lie outside every obstacle, got position ({start[0]}, {start[1]}) inside "
                f"obstacles[{i}]"
            )
    cp = require("cvxpy", extra="milp", purpose="planners.milp")

    # --- the program --------------------------------------------------------------------------------
    model = LinearModel()
    box_lo, box_hi = _reachable(start, lo_u, hi_u, dt, horizon, dynamics)
    if workspace is not None:
        tol = FEASIBILITY_TOLERANCE
        box_lo = np.maximum(box_lo, [workspace.xmin + tol, workspace.ymin + tol])
        box_hi = np.minimum(box_hi, [workspace.xmax - tol, workspace.ymax - tol])
        box_lo[0], box_hi[0] = start[:2], start[:2]
    state = [
        [model.add_var(float(box_lo[k, j]), float(box_hi[k, j])) for j in range(2)]
        for k in range(horizon + 1)
    ]
    if n_x == 4:
        for k in range(horizon + 1):
            state[k] += [model.add_var(), model.add_var()]
        for j in range(2):
            model.lb[state[0][2 + j]] = model.ub[state[0][2 + j]] = float(start[2 + j])
    inputs = [[model.add_var(float(lo_u[j]), float(hi_u[j])) for j in range(2)] for _ in range(horizon)]
    for k in range(horizon):
        for j in range(2):
            rate = inputs[k][j] if n_x == 2 else state[k][2 + j]
            model.add_row({state[k + 1][j]: 1.0, state[k][j]: -1.0, rate: -dt}, lo=0.0, hi=0.0)
            if n_x == 4:
                model.add_row(
                    {state[k + 1][2 + j]: 1.0, state[k][2 + j]: -1.0, inputs[k][j]: -dt}, lo=0.0, hi=0.0
                )
    positions = [(row[0], row[1]) for row in state]
    blocked = _avoid(model, positions, faces, big_m)
    if blocked is not None:
        return _result("infeasible", blocked, solver_name, "not solved", started, model, objective)
    encoder = StlEncoder(model, positions, used_regions, big_m=big_m)
    rho = encoder.encode(formula)
    if isinstance(rho, float):
        if rho < margin:  # the spec is false: no trajectory
            return _result(
                "infeasible",
                "the spec simplifies to false",
                solver_name,
                "not solved",
                started,
                model,
                objective,
                robustness_value=rho,
            )
        rho_expr: Affine | None = None
    else:
        rho_expr = rho
        model.add_le(rho, scale=-1.0, rhs=-margin)  # rho >= margin
    cost: dict[int, float] = {}
    if objective == "min_effort":
        for k in range(horizon):
            for j in range(2):
                s = model.add_var(0.0, max(abs(lo_u[j]), abs(hi_u[j])))
                model.add_row({s: 1.0, inputs[k][j]: -1.0}, lo=0.0)
                model.add_row({s: 1.0, inputs[k][j]: 1.0}, lo=0.0)
                cost[s] = dt
    elif rho_expr is not None:
        z = model.add_var(-math.inf, math.inf if robustness_cap is None else robustness_cap)
        model.add_le(rho_expr, scale=-1.0, extra={z: 1.0})  # z <= rho
        cost[z] = -1.0

    # --- solve ---------------------------------------------------------------------------------------
    problem, xc, xb = _to_cvxpy(cp, model, cost)
    solve_started = time.perf_counter()
    try:
        # cvxpy warns when a solver stops early ("Solution may be inaccurate"): the status and the
        # message of the result say so instead; the warnings go to the log.
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            problem.solve(solver=solver_name, **_solver_options(solver_name, time_limit))
        for warning in caught:
            logger.debug("cvxpy: %s", warning.message)
    except cp.error.SolverError as exc:
        # cvxpy raises when a solver returns no point; at the time limit that is a time limit
        if time.perf_counter() - solve_started >= 0.9 * time_limit:
            message = f"time limit of {time_limit} s reached without a feasible trajectory ({exc})"
            return _result("time_limit", message, solver_name, "solver_error", started, model, objective)
        return _result(
            "failed", f"{solver_name} failed: {exc}", solver_name, "solver_error", started, model, objective
        )
    status = str(problem.status)
    own = _status_text(problem, solver_name)
    solve_wall = time.perf_counter() - solve_started
    # A stop at the time limit: HiGHS and Gurobi say so (user_limit); scipy.optimize.milp reports
    # "optimal_inaccurate" for any limit; others are recognized by the time spent.
    hit_limit = (
        "time" in own.lower()
        or status == cp.USER_LIMIT
        or (solver_name == "SCIPY" and status == cp.OPTIMAL_INACCURATE)
        or (status in (cp.OPTIMAL_INACCURATE, cp.SOLVER_ERROR) and solve_wall >= 0.9 * time_limit)
    )
    point = _values(model, xc, xb)
    feasible = point is not None and model.violation(point) <= 100 * FEASIBILITY_TOLERANCE
    if status in (cp.INFEASIBLE, cp.INFEASIBLE_INACCURATE, "infeasible_or_unbounded") and not hit_limit:
        return _result(
            "infeasible",
            f"no trajectory reaches robustness >= {margin} within the bounds ({own})",
            solver_name,
            own,
            started,
            model,
            objective,
        )
    if hit_limit:
        kind: Status = "time_limit"
        message = (
            f"time limit of {time_limit} s reached with an incumbent (feasible, maybe not optimal) ({own})"
            if feasible
            else f"time limit of {time_limit} s reached without a feasible trajectory ({own})"
        )
    elif status in (cp.OPTIMAL, cp.OPTIMAL_INACCURATE) and feasible:
        kind, message = "solved", f"{solver_name}: {own}"
    elif status == cp.UNBOUNDED:
        kind, message = "failed", f"the program is unbounded; give robustness_cap or bounds ({own})"
    else:
        kind = "failed"
        message = f"{solver_name} returned {own}" + (
            ""
            if point is None or feasible
            else f" with a point violating the program by {model.violation(point):.2g}"
        )
    if not feasible or point is None:
        return _result(kind, message, solver_name, own, started, model, objective)

    u = np.clip(np.array([[point[i] for i in row] for row in inputs]), lo_u, hi_u)
    states = _rollout(start, u, dt, dynamics)
    checked = robustness(formula, states[:, :2], used_regions)  # type: ignore[arg-type]
    encoded = model.value(rho_expr, point) if rho_expr is not None else math.inf
    effort = float(dt * np.abs(u).sum())
    cost_value: float | None = effort
    if objective == "max_robustness":
        capped = -min(encoded, robustness_cap if robustness_cap is not None else math.inf)
        cost_value = capped if math.isfinite(capped) else None  # None: a spec that is always true
    return _result(
        kind,
        message,
        solver_name,
        own,
        started,
        model,
        objective,
        robustness_value=encoded,
        checked=checked,
        states=states,
        inputs=u,
        times=dt * np.arange(horizon + 1, dtype=np.float64),
        effort=effort,
        cost=cost_value,
    )


def _positive(value: object, name: str) -> float:
    out = _finite(value, name)
    if out <= 0:
        raise InvalidArgumentError(f"{name} must be > 0, got {out}")
    return out


def _finite(value: object, name: str) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float | np.integer | np.floating):
        raise InvalidArgumentError(f"{name} must be a number, got {type(value).__name__} {value!r}")
    out = float(value)
    if not math.isfinite(out):
        raise InvalidArgumentError(f"{name} must be finite, got {out}")
    return out


def installed_mip_solvers() -> list[str]:
    """The MILP-capable cvxpy solvers installed here (those :func:`milp` accepts).

    Returns
    -------
    list of str
        Subset of :data:`MIP_SOLVERS`, in that order.
    """
    cp = require("cvxpy", extra="milp", purpose="planners.milp")
    installed = set(cp.installed_solvers())
    return [name for name in MIP_SOLVERS if name in installed]


def _choose_solver(solver: str | None) -> str:
    name = "HIGHS" if solver is None else solver
    if not isinstance(name, str):
        raise InvalidArgumentError(
            f"solver must be a solver name or None, got {type(solver).__name__} {solver!r}"
        )
    name = name.upper()
    installed = installed_mip_solvers()
    if name not in MIP_SOLVERS:
        raise InvalidArgumentError(
            f"solver must be one of the MILP solvers {', '.join(MIP_SOLVERS)} (installed here: "
            f"{', '.join(installed) or 'none'}), got {solver!r}"
        )
    if name not in installed:
        raise InvalidArgumentError(
            f"solver {name!r} is not installed; installed MILP solvers: {', '.join(installed) or 'none'}"
        )
    return name


def _reachable(
    start: NDArray[np.float64],
    lo_u: NDArray[np.float64],
    hi_u: NDArray[np.float64],
    dt: float,
    horizon: int,
    dynamics: str,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Per-step bounds (horizon+1, 2) on the positions reachable from ``start`` under the input bounds."""
    k = np.arange(horizon + 1, dtype=np.float64)[:, None]
    with np.errstate(invalid="ignore"):
        if dynamics == "single_integrator":
            lo = start[None, :2] + k * dt * lo_u[None, :]
            hi = start[None, :2] + k * dt * hi_u[None, :]
        else:
            drift = start[None, :2] + k * dt * start[None, 2:]
            scale = dt * dt * k * (k - 1) / 2
            lo = drift + np.where(scale > 0, scale * lo_u[None, :], 0.0)
            hi = drift + np.where(scale > 0, scale * hi_u[None, :], 0.0)
    lo = np.where(np.isnan(lo), -np.inf, lo)
    hi = np.where(np.isnan(hi), np.inf, hi)
    lo[0], hi[0] = start[:2], start[:2]
    return lo, hi


def _avoid(
    model: LinearModel,
    positions: Sequence[tuple[int, int]],
    faces: Sequence[list[tuple[NDArray[np.float64], float]]],
    big_m: float | None,
) -> str | None:
    """Keep every segment (p_k, p_k+1) outside every obstacle: both ends outside one common face.

    Returns why no trajectory can, when the bounds already rule it out, else None."""
    for index, obstacle in enumerate(faces):
        for k in range(len(positions) - 1):
            ends = (positions[k], positions[k + 1])
            options: list[tuple[NDArray[np.float64], float]] = []
            safe = False
            for a, b in obstacle:
                exprs = [model.affine({p[0]: a[0], p[1]: a[1]}) for p in ends]
                needs = [b + (FEASIBILITY_TOLERANCE if j + k > 0 else 0.0) for j in range(2)]
                if all(e.lo >= n for e, n in zip(exprs, needs, strict=True)):
                    safe = True  # both ends are always outside this face
                    break
                if all(e.hi >= n for e, n in zip(exprs, needs, strict=True)):
                    options.append((a, b))
            if safe:
                continue
            if not options:
                return (
                    f"no trajectory keeps the segment of steps {k} and {k + 1} outside obstacles[{index}] "
                    "within the input bounds and the workspace"
                )
            zs = [model.add_binary() for _ in options]
            model.add_row(dict.fromkeys(zs, 1.0), lo=1.0)
            for z, (a, b) in zip(zs, options, strict=True):
                for j, p in enumerate(ends):
                    need = b + (FEASIBILITY_TOLERANCE if j + k > 0 else 0.0)
                    expr = model.affine({p[0]: a[0], p[1]: a[1]})
                    m = need - expr.lo if big_m is None else big_m  # need - a.p <= m (1 - z)
                    if not math.isfinite(m):
                        raise InvalidArgumentError(
                            "big-M for the obstacles cannot be derived because the positions are unbounded: "
                            "give a workspace, input bounds (u_min, u_max) or big_m"
                        )
                    model.add_le(expr, scale=-1.0, extra={z: m}, rhs=m - need)
    return None


def _to_cvxpy(cp: Any, model: LinearModel, cost: Mapping[int, float]) -> tuple[Any, Any, Any]:
    """The program as a cvxpy problem over a continuous vector and a boolean vector (sparse matrices)."""
    import scipy.sparse as sp

    n = model.n_vars
    binary = np.asarray(model.binary, dtype=bool)
    cont_idx, bin_idx = np.flatnonzero(~binary), np.flatnonzero(binary)
    rows: list[int] = []
    cols: list[int] = []
    data: list[float] = []
    for r, (index, coef) in enumerate(zip(model.rows_index, model.rows_coef, strict=True)):
        rows.extend([r] * len(index))
        cols.extend(index)
        data.extend(coef)
    a = sp.csc_matrix((data, (rows, cols)), shape=(model.n_rows, n))
    a_c, a_b = a[:, cont_idx].tocsr(), a[:, bin_idx].tocsr()
    xc = cp.Variable(len(cont_idx))
    xb = cp.Variable(len(bin_idx), boolean=True) if len(bin_idx) else None
    lo, hi = np.asarray(model.rows_lo), np.asarray(model.rows_hi)
    lb, ub = np.asarray(model.lb)[cont_idx], np.asarray(model.ub)[cont_idx]

    def lhs(sel: NDArray[np.intp]) -> Any:
        out = a_c[sel] @ xc
        return out if xb is None else out + a_b[sel] @ xb

    constraints = []
    eq = np.flatnonzero(lo == hi)
    upper = np.flatnonzero(np.isfinite(hi) & (lo != hi))
    lower = np.flatnonzero(np.isfinite(lo) & (lo != hi))
    if len(eq):
        constraints.append(lhs(eq) == lo[eq])
    if len(upper):
        constraints.append(lhs(upper) <= hi[upper])
    if len(lower):
        constraints.append(lhs(lower) >= lo[lower])
    fin_lb, fin_ub = np.flatnonzero(np.isfinite(lb)), np.flatnonzero(np.isfinite(ub))
    if len(fin_lb):
        constraints.append(xc[fin_lb] >= lb[fin_lb])
    if len(fin_ub):
        constraints.append(xc[fin_ub] <= ub[fin_ub])
    c = np.zeros(n)
    for i, w in cost.items():
        c[i] += w
    objective = c[cont_idx] @ xc + (0 if xb is None else c[bin_idx] @ xb)
    return cp.Problem(cp.Minimize(objective), constraints), xc, xb


def _values(model: LinearModel, xc: Any, xb: Any) -> NDArray[np.float64] | None:
    """The solver's point in the model's variable order, or None when it returned none."""
    if xc.value is None or (xb is not None and xb.value is None):
        return None
    binary = np.asarray(model.binary, dtype=bool)
    point = np.empty(model.n_vars)
    point[~binary] = np.asarray(xc.value, dtype=np.float64).ravel()
    if xb is not None:
        point[binary] = np.asarray(xb.value, dtype=np.float64).ravel()
    return point


def _rollout(
    start: NDArray[np.float64], u: NDArray[np.float64], dt: float, dynamics: str
) -> NDArray[np.float64]:
    states = np.empty((len(u) + 1, len(start)))
    states[0] = start
    for k in range(len(u)):
        if dynamics == "single_integrator":
            states[k + 1] = states[k] + dt * u[k]
        else:
            x = states[k]
            states[k + 1] = x + dt * np.concatenate([x[2:], u[k]])
    return states


def _result(
    status: Status,
    message: str,
    solver: str,
    solver_status: str,
    started: float,
    model: LinearModel,
    objective: str,
    *,
    robustness_value: float | None = None,
    checked: float | None = None,
    states: NDArray[np.float64] | None = None,
    inputs: NDArray[np.float64] | None = None,
    times: NDArray[np.float64] | None = None,
    effort: float | None = None,
    cost: float | None = None,
) -> MILPResult:
    return MILPResult(
        status=status,
        message=message,
        cost=cost,
        solve_time=time.perf_counter() - started,
        states=states,
        inputs=inputs,
        times=times,
        robustness=robustness_value,
        checked_robustness=checked,
        solver=solver,
        solver_status=solver_status,
        n_binaries=model.n_binaries,
        n_constraints=model.n_rows,
        n_variables=model.n_vars,
        objective=objective,
        effort=effort,
    )


_ = FloatArray  # re-exported type used by the Result base
