"""The checker: judge a candidate solution against a task, exactly, with bounded diagnostics.

What is checked (in this order of steps; every violation is located):

1. the solution's form: the arrays the task takes, with the right shapes, finite (otherwise one
   ``malformed`` violation saying what was expected and what was received);
2. the trajectory: inputs are rolled out from ``x0`` with the task's integrator (``input_bounds``,
   ``dynamics``); states alone (single integrator) give their inputs back as differences / dt;
   timed waypoints (STL tasks, single integrator) are resampled at ``t = k * dt``; a path's first
   waypoint must be at the start (``start``);
3. geometry, exactly: every position in the workspace (``workspace``), and every position and every
   straight segment between consecutive positions outside every (inflated) obstacle
   (``collision``);
4. the task's own criterion: mean tracking error (``tracking``), distance to the goal at the end
   (``goal``), STL robustness per clause (``stl``).

A solution succeeds when nothing is violated. Violations are ordered by step; the report keeps the
first :attr:`CheckReport.MAX_VIOLATIONS` and counts all of them.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from audere.errors import InvalidArgumentError
from audere.tasks._describe import names_tuple as _names
from audere.tasks._feedback import format_value as _num
from audere.tasks._feedback import preview_steps
from audere.tasks._models import MazeTask, ReachAvoidTask, STLTask, TrackingTask
from audere.tasks._report import CheckReport, ClauseResult, Violation
from audere.tasks._solution import Solution

if TYPE_CHECKING:
    from audere.dynamics import Dynamics
    from audere.world import World

__all__ = ["check"]

AnyTask = TrackingTask | ReachAvoidTask | MazeTask | STLTask
F = NDArray[np.float64]

INPUT_TOLERANCE = 1e-6
"""Inputs may exceed their bounds by this much (absolute) without a violation."""

DYNAMICS_TOLERANCE = 1e-6
"""Given states match the rollout when ``|states - rollout| <= 1e-6 * max(1, |rollout|)``."""

TIME_TOLERANCE = 1e-6
"""Slack on the first and last time of a timed path, relative to ``max(1, horizon * dt)``."""

_FIELDS = ("inputs", "states", "waypoints", "times")

# Ties at the same step are ordered by kind, earliest cause first.
_KIND_ORDER = {
    "malformed": 0,
    "start": 1,
    "dynamics": 2,
    "input_bounds": 3,
    "workspace": 4,
    "collision": 5,
    "tracking": 6,
    "goal": 7,
    "stl": 8,
}


class _Malformed(Exception):
    """The solution does not have the form the task takes (internal; becomes a report)."""


@dataclass
class _Found:
    """Violations of one kind: all counted, the first few (in order of steps) spelled out."""

    count: int = 0
    first: list[Violation] = field(default_factory=list)


@dataclass
class _Trajectory:
    """What the checker evaluates: the planar positions, and states/inputs when there is dynamics."""

    positions: F
    states: F | None
    inputs: F | None
    complete: bool  # False when a rollout diverged and positions is only its finite prefix
    unit: str  # "step" (time steps) or "waypoint" (path tasks)
    found: list[_Found]


# --------------------------------------------------------------------------------------- helpers


def _pt(p: NDArray[Any] | tuple[float, float]) -> str:
    return f"({_num(float(p[0]))}, {_num(float(p[1]))})"


def _vec(v: NDArray[Any]) -> str:
    return "(" + ", ".join(_num(float(a)) for a in v) + ")"


def _found(steps: NDArray[np.intp], build: Callable[[int], Violation]) -> _Found:
    """All violations at the sorted ``steps``; only the first MAX_VIOLATIONS are built."""
    keep = [int(s) for s in steps[: CheckReport.MAX_VIOLATIONS]]
    return _Found(count=len(steps), first=[build(s) for s in keep])


def _one(violation: Violation) -> _Found:
    return _Found(count=1, first=[violation])


def _expected(task: AnyTask) -> str:
    """What the task takes, in words, for malformed-solution messages."""
    model = task.model
    if model is None:
        return "waypoints: an array of shape (k, 2), one row (x, y) per waypoint, k >= 1"
    h = task.horizon
    parts = [f"inputs: an array of shape ({h}, {model.n_u}) {_names(model.input_names)}, one row per step"]
    if "states" in task.solution_kinds:
        parts.append(f"states: an array of shape ({h + 1}, {model.n_x}) {_names(model.state_names)}")
    if "timed_waypoints" in task.solution_kinds:
        parts.append(
            "timed waypoints: an array of shape (k, 3) with rows (x, y, t), or waypoints (k, 2) with times "
            f"(k,), starting at t = 0 and reaching t = {_num(h * task.dt)}"
        )
    return "; or ".join(parts)


def _describe_array(arr: NDArray[Any]) -> str:
    if arr.size == 0:
        return f"an empty array of shape {tuple(arr.shape)}"
    return f"an array of shape {tuple(arr.shape)}"


def _as_array(value: object, name: str) -> F:
    """A float array from anything array-like, or _Malformed naming what was received."""
    if isinstance(value, str | bytes):
        raise _Malformed(f"{name} must be an array of numbers, got a {type(value).__name__}: {value[:40]!r}")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            arr = np.array(value, dtype=np.float64)
    except Exception as exc:
        text = repr(value)
        text = text if len(text) <= 60 else text[:57] + "..."
        reason = "ragged rows" if "inhomogeneous" in str(exc) else f"{type(exc).__name__}"
        raise _Malformed(
            f"{name} must be an array of numbers, got {type(value).__name__} {text} ({reason})"
        ) from None
    return arr


def _require_finite(arr: F, name: str, columns: tuple[str, ...] | None = None) -> None:
    bad = ~np.isfinite(arr)
    if bad.any():
        idx = tuple(int(i) for i in np.argwhere(bad)[0])
        where = f"row {idx[0]}" if arr.ndim >= 1 else "the value"
        if arr.ndim == 2:
            col = f" ({columns[idx[1]]})" if columns is not None and idx[1] < len(columns) else ""
            where += f", column {idx[1]}{col}"
        raise _Malformed(
            f"{name} must be finite, got {arr[idx]} at {where} ({int(bad.sum())} non-finite entries)"
        )


# --------------------------------------------------------------------------------------- form


def _fields(task: AnyTask, solution: object) -> dict[str, F]:
    """The solution's arrays by field name, with shapes checked against the task."""
    if isinstance(solution, Solution):
        raw: dict[str, object] = dict(solution.arrays())
    elif isinstance(solution, Mapping):
        unknown = sorted(str(k) for k in solution if k not in _FIELDS)
        if unknown:
            raise _Malformed(
                f"unknown solution field(s) {', '.join(repr(k) for k in unknown)}; a solution has the fields "
                f"{', '.join(_FIELDS)}. Expected {_expected(task)}"
            )
        raw = {str(k): v for k, v in solution.items() if v is not None}
        if not raw:
            raise _Malformed(f"the solution mapping holds no array. Expected {_expected(task)}")
    elif isinstance(solution, np.ndarray | list | tuple):
        return _bare(task, _as_array(solution, "the solution"))
    else:
        raise _Malformed(
            "a solution must be a Solution, a mapping of its fields (inputs, states, waypoints, times) or "
            f"an array, got {type(solution).__name__}. Expected {_expected(task)}"
        )
    arrays = {name: _as_array(value, name) for name, value in raw.items()}
    return _shaped(task, arrays)


def _bare(task: AnyTask, arr: F) -> dict[str, F]:
    """Interpret a bare array by its shape, as the task's solution kinds allow."""
    model = task.model
    h = task.horizon
    kinds = task.solution_kinds
    candidates: list[str] = []
    if model is None:
        if arr.ndim == 2 and arr.shape[1] == 2 and arr.shape[0] >= 1:
            candidates.append("waypoints")
    else:
        if arr.shape == (h, model.n_u) or (model.n_u == 1 and arr.shape == (h,)):
            candidates.append("inputs")
        if "states" in kinds and arr.shape == (h + 1, model.n_x):
            candidates.append("states")
        if "timed_waypoints" in kinds and arr.ndim == 2 and arr.shape[1] == 3 and arr.shape[0] >= 2:
            candidates.append("timed waypoints")
    if not candidates:
        raise _Malformed(f"expected {_expected(task)}; got {_describe_array(arr)}")
    if len(candidates) > 1:
        raise _Malformed(
            f"an array of shape {tuple(arr.shape)} is ambiguous for this task: it could be "
            f"{' or '.join(candidates)}; pass a mapping that names the field, e.g. {{'{candidates[0]}': ...}}"
        )
    kind = candidates[0]
    if kind == "timed waypoints":
        return _shaped(task, {"waypoints": arr})
    return _shaped(task, {kind: arr})


def _shaped(task: AnyTask, arrays: dict[str, F]) -> dict[str, F]:
    """Check which fields are given and their shapes; return them with inputs as (horizon, n_u)."""
    model = task.model
    given = sorted(arrays)
    if model is None:
        extra = [k for k in given if k != "waypoints"]
        if extra or "waypoints" not in arrays:
            got = f"got {', '.join(given)}" if given else "got nothing"
            raise _Malformed(f"this path task takes only waypoints; expected {_expected(task)}; {got}")
        wp = arrays["waypoints"]
        if wp.ndim != 2 or wp.shape[1] != 2 or wp.shape[0] < 1:
            raise _Malformed(f"expected {_expected(task)}; got waypoints as {_describe_array(wp)}")
        _require_finite(wp, "waypoints", ("x", "y"))
        return {"waypoints": wp}

    h = task.horizon
    if "waypoints" in arrays:
        if "timed_waypoints" not in task.solution_kinds:
            raise _Malformed(
                f"this task with dynamics {task.dynamics!r} does not take waypoints; expected "
                f"{_expected(task)}"
            )
        others = [k for k in given if k not in ("waypoints", "times")]
        if others:
            raise _Malformed(
                f"give either timed waypoints or {' and '.join(others)}, not both; expected {_expected(task)}"
            )
        wp = arrays["waypoints"]
        if wp.ndim == 2 and wp.shape[1] == 3 and "times" not in arrays:
            xy, t = wp[:, :2], wp[:, 2]
        elif wp.ndim == 2 and wp.shape[1] == 2 and "times" in arrays:
            xy, t = wp, arrays["times"]
            if t.shape != (wp.shape[0],):
                raise _Malformed(
                    f"times must have shape ({wp.shape[0]},), one time per waypoint; got {_describe_array(t)}"
                )
        elif wp.ndim == 2 and wp.shape[1] == 3:
            raise _Malformed("give the times either as the third column of waypoints or as times, not both")
        elif wp.ndim == 2 and wp.shape[1] == 2:
            raise _Malformed(
                "waypoints without times cannot be checked against an STL task; give times (k,) in seconds "
                f"or waypoints (k, 3) with rows (x, y, t); expected {_expected(task)}"
            )
        else:
            raise _Malformed(f"expected {_expected(task)}; got waypoints as {_describe_array(wp)}")
        if xy.shape[0] < 2:
            raise _Malformed(f"a timed path needs at least 2 waypoints; got {xy.shape[0]}")
        _require_finite(wp, "waypoints", ("x", "y", "t") if wp.shape[1] == 3 else ("x", "y"))
        _require_finite(t, "times")
        return {"waypoints": np.asarray(xy), "times": np.asarray(t)}

    if "times" in arrays:
        raise _Malformed("times belong to waypoints; this solution has times but no waypoints")
    out: dict[str, F] = {}
    if "inputs" in arrays:
        u = arrays["inputs"]
        if model.n_u == 1 and u.shape == (h,):
            u = u.reshape(h, 1)
        if u.shape != (h, model.n_u):
            raise _Malformed(
                f"inputs must have shape ({h}, {model.n_u}) {_names(model.input_names)} (horizon {h} rows); "
                f"got {_describe_array(u)}"
            )
        _require_finite(u, "inputs", tuple(model.input_names))
        out["inputs"] = u
    if "states" in arrays:
        x = arrays["states"]
        if x.shape != (h + 1, model.n_x):
            raise _Malformed(
                f"states must have shape ({h + 1}, {model.n_x}) {_names(model.state_names)} (horizon + 1 = "
                f"{h + 1} rows); got {_describe_array(x)}"
            )
        _require_finite(x, "states", tuple(model.state_names))
        if "inputs" not in out and "states" not in task.solution_kinds:
            raise _Malformed(
                f"states alone cannot be checked for dynamics {task.dynamics!r} (its inputs cannot be "
                f"recovered from them); give inputs. Expected {_expected(task)}"
            )
        out["states"] = x
    return out


# --------------------------------------------------------------------------------------- trajectory


def _input_bounds(task: AnyTask, model: Dynamics) -> tuple[F, F]:
    lo = np.asarray(task.u_min if task.u_min is not None else model.input_lower, dtype=np.float64)
    hi = np.asarray(task.u_max if task.u_max is not None else model.input_upper, dtype=np.float64)
    return lo, hi


def _check_inputs(task: AnyTask, model: Dynamics, inputs: F, *, recovered: bool) -> _Found:
    lo, hi = _input_bounds(task, model)
    with np.errstate(invalid="ignore"):
        excess = np.maximum(inputs - hi, lo - inputs)  # > 0 where out of bounds
    bad_steps = np.flatnonzero((excess > INPUT_TOLERANCE).any(axis=1))
    names = model.input_names
    note = " (recovered from the states as (x[k+1] - x[k]) / dt)" if recovered else ""

    def build(k: int) -> Violation:
        j = int(np.argmax(excess[k]))
        value = float(inputs[k, j])
        if value > hi[j]:
            rel = f"exceeds its upper bound u_max[{j}] = {_num(float(hi[j]))}"
        else:
            rel = f"is below its lower bound u_min[{j}] = {_num(float(lo[j]))}"
        n_bad = int((excess[k] > INPUT_TOLERANCE).sum())
        more = f" ({n_bad} inputs out of bounds at this step)" if n_bad > 1 else ""
        return Violation(
            kind="input_bounds",
            step=k,
            message=f"step {k}: input {names[j]} = {_num(value)}{note} {rel}{more}",
        )

    return _found(bad_steps, build)


def _trajectory(task: AnyTask, arrays: dict[str, F]) -> _Trajectory:
    model = task.model
    found: list[_Found] = []
    if model is None:
        wp = arrays["waypoints"]
        start = np.asarray(task.start)
        d = float(np.hypot(*(wp[0] - start)))
        if d > task.start_tolerance:
            found.append(
                _one(
                    Violation(
                        kind="start",
                        step=0,
                        point=(float(wp[0, 0]), float(wp[0, 1])),
                        message=f"waypoint 0 {_pt(wp[0])} is {_num(d)} from the start {_pt(start)}; "
                        f"the path must start within {_num(task.start_tolerance)} of it",
                    )
                )
            )
        return _Trajectory(wp, None, None, True, "waypoint", found)

    x0 = np.asarray(task.x0, dtype=np.float64)
    recovered = False
    states: F | None
    if "waypoints" in arrays:  # timed path, single integrator: resample at t = k * dt
        states = _resample(task, arrays["waypoints"], arrays["times"])
    else:
        states = arrays.get("states")
    if "inputs" in arrays:
        inputs = arrays["inputs"]
        with np.errstate(all="ignore"):
            rollout = model.rollout(x0, inputs, task.dt, method=task.integrator)
        if states is not None:
            found.append(_check_states(model, states, rollout))
        states = rollout
    else:  # states alone: the single integrator, inputs recovered exactly
        if states is None:  # pragma: no cover - _shaped guarantees inputs or states
            raise _Malformed(f"the solution holds neither inputs nor states; expected {_expected(task)}")
        inputs = np.diff(states, axis=0) / task.dt
        recovered = True
        start = model.position(x0)
        p0 = model.position(states[0])
        d = float(np.hypot(*(p0 - start)))
        if d > task.start_tolerance:
            found.append(
                _one(
                    Violation(
                        kind="start",
                        step=0,
                        point=(float(p0[0]), float(p0[1])),
                        message=f"the trajectory starts at {_pt(p0)}, {_num(d)} from x0 {_pt(start)}; "
                        f"it must start within {_num(task.start_tolerance)} of it",
                    )
                )
            )
    found.append(_check_inputs(task, model, inputs, recovered=recovered))

    finite = np.isfinite(states).all(axis=1)
    complete = bool(finite.all())
    if not complete:
        k = int(np.argmin(finite))
        found.append(
            _one(
                Violation(
                    kind="dynamics",
                    step=k,
                    message=f"step {k}: the rollout of the inputs is not finite from this step on "
                    "(the state grows without bound); only the steps before it are checked",
                )
            )
        )
        states = states[:k]
    positions = np.asarray(model.position(states)) if len(states) else np.zeros((0, 2))
    return _Trajectory(positions, states, inputs, complete, "step", found)


def _resample(task: AnyTask, xy: F, t: F) -> F:
    """Positions of a timed path at ``t = k * dt``, ``k = 0..horizon``, by linear interpolation."""
    dt_t = np.diff(t)
    if np.any(dt_t <= 0):
        i = int(np.argmax(dt_t <= 0))
        raise _Malformed(
            f"times must be strictly increasing; got t[{i + 1}] = {_num(float(t[i + 1]))} after t[{i}] = "
            f"{_num(float(t[i]))}"
        )
    end = task.horizon * task.dt
    slack = TIME_TOLERANCE * max(1.0, end)
    if abs(float(t[0])) > slack:
        raise _Malformed(f"the timed path must start at t = 0; got t[0] = {_num(float(t[0]))}")
    if float(t[-1]) < end - slack:
        raise _Malformed(
            f"the timed path must reach t = {_num(end)} (horizon {task.horizon} x dt {_num(task.dt)}); its "
            f"last time is {_num(float(t[-1]))}"
        )
    grid = task.dt * np.arange(task.horizon + 1)
    return np.column_stack([np.interp(grid, t, xy[:, 0]), np.interp(grid, t, xy[:, 1])])


def _check_states(model: Dynamics, states: F, rollout: F) -> _Found:
    with np.errstate(invalid="ignore"):
        diff = np.abs(states - rollout)
        bad = ~(diff <= DYNAMICS_TOLERANCE * np.maximum(1.0, np.abs(rollout)))
    bad_steps = np.flatnonzero(bad.any(axis=1))

    def build(k: int) -> Violation:
        j = int(np.argmax(np.where(bad[k], np.nan_to_num(diff[k], nan=np.inf), -1.0)))
        return Violation(
            kind="dynamics",
            step=k,
            message=f"step {k}: the given state {model.state_names[j]} = {_num(float(states[k, j]))} does "
            f"not match the rollout of the inputs, {_num(float(rollout[k, j]))} (the rollout is what is "
            "checked)",
        )

    return _found(bad_steps, build)


# --------------------------------------------------------------------------------------- geometry


def _check_workspace(task: AnyTask, world: World, traj: _Trajectory) -> _Found:
    p = traj.positions
    outside = ~np.asarray(world.in_workspace(p), dtype=bool) if len(p) else np.zeros(0, dtype=bool)
    ws = task.workspace
    box = f"x in [{_num(ws.xmin)}, {_num(ws.xmax)}], y in [{_num(ws.ymin)}, {_num(ws.ymax)}]"

    def build(k: int) -> Violation:
        return Violation(
            kind="workspace",
            step=k,
            point=(float(p[k, 0]), float(p[k, 1])),
            message=f"{traj.unit} {k}: position {_pt(p[k])} is outside the workspace {box}",
        )

    return _found(np.flatnonzero(outside), build)


def _obstacle_text(task: AnyTask, index: int) -> str:
    from audere.world import describe_shape

    shapes = task.all_obstacles()
    n_own = len(task.obstacles)
    if index >= n_own and isinstance(task, MazeTask):
        what = f"wall piece {index - n_own} ({describe_shape(shapes[index])})"
    else:
        what = f"obstacle {index} ({describe_shape(shapes[index])})"
    if task.margin > 0:
        what += f" inflated by the margin {_num(task.margin)}"
    return what


def _check_collisions(task: AnyTask, world: World, traj: _Trajectory) -> _Found:
    p = traj.positions
    if not len(world.obstacles) or not len(p):
        return _Found()
    points = np.asarray(world.points_in_collision(p), dtype=bool)
    if len(p) > 1:
        segs = np.asarray(world.segments_in_collision(p[:-1], p[1:]), dtype=bool)
        # A segment with an endpoint inside is already reported through that point.
        segs &= ~points[:-1] & ~points[1:]
    else:
        segs = np.zeros(0, dtype=bool)
    events = sorted(
        [(int(k), 0) for k in np.flatnonzero(points)][: CheckReport.MAX_VIOLATIONS]
        + [(int(k), 1) for k in np.flatnonzero(segs)][: CheckReport.MAX_VIOLATIONS]
    )
    count = int(points.sum() + segs.sum())
    unit = traj.unit
    first: list[Violation] = []
    for k, is_segment in events[: CheckReport.MAX_VIOLATIONS]:
        hit = world.first_collision(p[k : k + 2] if is_segment else p[k : k + 1])
        index = int(hit.obstacle_index) if hit is not None else -1
        point = np.asarray(hit.point if hit is not None else p[k], dtype=np.float64)
        what = _obstacle_text(task, index) if index >= 0 else "an obstacle"
        if is_segment:
            message = (
                f"segment {k} from {unit} {k} {_pt(p[k])} to {unit} {k + 1} {_pt(p[k + 1])} passes through "
                f"{what}, entering at {_pt(point)} (both ends are outside it)"
            )
        else:
            message = f"{unit} {k}: position {_pt(p[k])} is inside {what}"
        first.append(
            Violation(
                kind="collision",
                step=k,
                point=(float(point[0]), float(point[1])),
                obstacle=index if index >= 0 else None,
                message=message,
            )
        )
    return _Found(count=count, first=first)


# --------------------------------------------------------------------------------------- criteria


def _path_length(p: F) -> float:
    return float(np.hypot(*np.diff(p, axis=0).T).sum()) if len(p) > 1 else 0.0


def _tracking(task: TrackingTask, traj: _Trajectory, metrics: dict[str, float]) -> _Found:
    ref = task.reference_positions
    err = np.hypot(*(traj.positions - ref).T)
    mean, k_max = float(err.mean()), int(np.argmax(err))
    metrics["mean_tracking_error"] = mean
    metrics["max_tracking_error"] = float(err[k_max])
    metrics["final_tracking_error"] = float(err[-1])
    if mean < task.tolerance:
        return _Found()
    return _one(
        Violation(
            kind="tracking",
            step=k_max,
            point=(float(traj.positions[k_max, 0]), float(traj.positions[k_max, 1])),
            message=f"the mean position error over the {len(err)} steps is {_num(mean)}, not below the "
            f"tolerance {_num(task.tolerance)}; the largest error is {_num(float(err[k_max]))} at step "
            f"{k_max} (position {_pt(traj.positions[k_max])}, reference {_pt(ref[k_max])})",
        )
    )


def _wrap(angle: F) -> F:
    return np.asarray((angle + math.pi) % (2 * math.pi) - math.pi)


def _goal(task: ReachAvoidTask | MazeTask, traj: _Trajectory, metrics: dict[str, float]) -> _Found:
    p = traj.positions
    k = len(p) - 1
    if isinstance(task, ReachAvoidTask) and task.goal_on == "state" and traj.states is not None:
        diff = traj.states[-1] - np.asarray(task.goal, dtype=np.float64)
        idx = list(task.angle_indices)
        diff[idx] = _wrap(diff[idx])
        d = float(np.linalg.norm(diff))
        goal_state = _vec(np.asarray(task.goal))
        end = f"the final state {_vec(traj.states[-1])} is {_num(d)} from the goal state {goal_state}"
        if idx:
            end += " (angle differences wrapped to [-pi, pi))"
    else:
        goal = np.asarray(task.goal[:2] if isinstance(task, MazeTask) else task.goal_position)
        d = float(np.hypot(*(p[-1] - goal)))
        what = "path" if traj.unit == "waypoint" else "trajectory"
        end = f"the {what} ends at {_pt(p[-1])}, {_num(d)} from the goal {_pt(goal)}"
    metrics["goal_distance"] = d
    if d <= task.goal_tolerance:
        return _Found()
    return _one(
        Violation(
            kind="goal",
            step=k,
            point=(float(p[-1, 0]), float(p[-1, 1])),
            message=f"{end}; it must end within {_num(task.goal_tolerance)}",
        )
    )


def _stl(task: STLTask, traj: _Trajectory, metrics: dict[str, float]) -> tuple[_Found, list[ClauseResult]]:
    from audere.stl import explain

    formula = task.formula
    reports = explain(formula, traj.positions, dict(task.regions), max_clauses=max(1, len(formula.clauses())))
    # The formula is the conjunction of its clauses: its robustness is their minimum.
    metrics["robustness"] = min(c.robustness for c in reports)
    clauses = [
        ClauseResult(
            text=c.text,
            robustness=c.robustness,
            satisfied=c.satisfied,
            critical_step=c.critical_step,
            critical_predicate=c.critical_predicate,
        )
        for c in reports
    ]
    first = [
        Violation(
            kind="stl",
            step=c.critical_step,
            clause=c.text,
            point=(float(traj.positions[c.critical_step, 0]), float(traj.positions[c.critical_step, 1])),
            message=f"the clause {c.text} is {'violated' if not c.satisfied else 'met only on a boundary'}: "
            f"robustness {_num(c.robustness)} (it must be > 0), decided by {c.critical_predicate} at step "
            f"{c.critical_step}, position {_pt(traj.positions[c.critical_step])}",
        )
        for c in reports
        if c.robustness <= 0 or not c.satisfied
    ]
    first.sort(key=lambda v: v.step or 0)
    return _Found(count=len(first), first=first[: CheckReport.MAX_VIOLATIONS]), clauses


# --------------------------------------------------------------------------------------- entry point


def _malformed(message: str) -> CheckReport:
    return CheckReport(
        success=False,
        violations=(Violation(kind="malformed", message=message),),
        n_violations=1,
        violation_counts={"malformed": 1},
    )


def check(task: AnyTask, solution: object) -> CheckReport:
    """Judge a candidate solution against a task.

    Parameters
    ----------
    task
        A :class:`TrackingTask`, :class:`ReachAvoidTask`, :class:`MazeTask` or :class:`STLTask`.
    solution
        A :class:`Solution`, a mapping of its fields (``inputs``, ``states``, ``waypoints``,
        ``times``), or a bare array interpreted by its shape: inputs ``(horizon, n_u)``, states
        ``(horizon + 1, n_x)`` (single integrator), waypoints ``(k, 2)`` (path tasks), timed
        waypoints ``(k, 3)`` with rows ``(x, y, t)`` (STL tasks with the single integrator).

    Returns
    -------
    CheckReport
        ``success`` when nothing is violated; metrics; the first violations in order of steps and
        their total count; per-clause robustness for STL tasks; a preview of at most 11 positions
        and the full positions (for plots). A malformed solution gives a report with one
        ``malformed`` violation saying what was expected and what was received.

    Raises
    ------
    InvalidArgumentError
        If ``task`` is not a task (a programming error; a bad solution is never raised).
    """
    if not isinstance(task, TrackingTask | ReachAvoidTask | MazeTask | STLTask):
        raise InvalidArgumentError(
            f"task must be a TrackingTask, ReachAvoidTask, MazeTask or STLTask, got {type(task).__name__}"
        )
    try:
        traj = _trajectory(task, _fields(task, solution))
    except _Malformed as exc:
        return _malformed(str(exc))

    world = task.world(inflated=True)
    found = list(traj.found)
    metrics: dict[str, float] = {}
    clauses: list[ClauseResult] = []
    p = traj.positions
    # Absurd but finite positions (say 1e200, from a wild rollout) overflow squared distances; they are
    # outside the workspace, so the verdict does not depend on those values: keep numpy quiet.
    with np.errstate(over="ignore", invalid="ignore"):
        found.append(_check_workspace(task, world, traj))
        found.append(_check_collisions(task, world, traj))
        if traj.complete:
            if isinstance(task, TrackingTask):
                found.append(_tracking(task, traj, metrics))
            elif isinstance(task, ReachAvoidTask | MazeTask):
                found.append(_goal(task, traj, metrics))
            else:
                stl_found, clauses = _stl(task, traj, metrics)
                found.append(stl_found)
            if len(world.obstacles):
                try:
                    with np.errstate(over="raise", invalid="raise"):
                        metrics["min_clearance"] = float(world.clearance(p))
                except FloatingPointError:  # absurd coordinates: no meaningful clearance
                    pass
            if isinstance(task, ReachAvoidTask | MazeTask):
                metrics["path_length"] = _path_length(p)
            if isinstance(task, MazeTask):
                metrics["cells_visited"] = float(_cells_visited(task, p))

    counts: dict[str, int] = {}
    everything: list[Violation] = []
    for f in found:
        everything.extend(f.first)
        if f.count:
            kind = f.first[0].kind
            counts[kind] = counts.get(kind, 0) + f.count
    everything.sort(key=lambda v: (v.step if v.step is not None else -1, _KIND_ORDER[v.kind]))
    n = sum(counts.values())
    counts = dict(sorted(counts.items(), key=lambda item: _KIND_ORDER[item[0]]))
    keep = preview_steps(len(p))
    return CheckReport(
        success=n == 0,
        metrics=metrics,
        violations=tuple(everything[: CheckReport.MAX_VIOLATIONS]),
        n_violations=n,
        violation_counts=counts,
        clauses=tuple(clauses),
        preview=p[keep] if len(p) else None,
        positions=p if len(p) else None,
    )


def _cells_visited(task: MazeTask, p: F) -> int:
    ws = task.workspace
    w, h = task.cell_size
    col = np.clip(np.floor((p[:, 0] - ws.xmin) / w), 0, task.cols - 1).astype(int)
    row = np.clip(np.floor((p[:, 1] - ws.ymin) / h), 0, task.rows - 1).astype(int)
    return len(set(zip(row.tolist(), col.tolist(), strict=True)))
