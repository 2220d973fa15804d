"""RRT, RRT* and friends through OMPL, with exact collision checking against an audere World."""

from __future__ import annotations

import itertools
import math
import operator
import time
from typing import Annotated, Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray
from pydantic import Field, PlainSerializer, PlainValidator, WithJsonSchema

from audere._arrays import FloatArray, as_float_array
from audere.apis._registry import register_api
from audere.apis._result import Result, Status
from audere.errors import InvalidArgumentError
from audere.world import World

__all__ = ["RRTResult", "rrt"]

Algorithm = Literal["rrt", "rrt_connect", "rrt_star", "informed_rrt_star", "bit_star"]
_ALGORITHMS: tuple[str, ...] = ("rrt", "rrt_connect", "rrt_star", "informed_rrt_star", "bit_star")
_WITH_RANGE = ("rrt", "rrt_connect", "rrt_star", "informed_rrt_star")


def _int_pairs(value: Any) -> NDArray[np.int64]:
    arr = np.asarray(value, dtype=np.int64).reshape(-1, 2)
    arr.setflags(write=False)
    return arr


IndexPairs = Annotated[
    NDArray[np.int64],
    PlainValidator(_int_pairs),
    PlainSerializer(lambda a: np.asarray(a).tolist(), return_type=list),
    WithJsonSchema({"type": "array", "items": {}, "description": "integer pairs (nested lists)"}),
]


class RRTResult(Result):
    """What :func:`rrt` returns: the path, its length, the planner's graph and run statistics.

    ``waypoints`` (k, 2) is the returned path in metres (simplified and interpolated as asked), from
    the start to within ``goal_tolerance`` of the goal; ``cost`` is its length in metres;
    ``to_solution()`` gives what ``Task.check`` accepts for a path task.
    """

    algorithm: str = Field(description="The OMPL planner used (our name, e.g. 'rrt_star').")
    first_solution_time: float | None = Field(
        None, description="Seconds from the start of planning to the first solution; None without one."
    )
    iterations: int | None = Field(
        None, description="Planner iterations (RRT* family and BIT*); None for planners that do not count."
    )
    tree_vertices: FloatArray = Field(
        description="Vertices of the planner's tree or roadmap, (n, 2), metres."
    )
    tree_edges: IndexPairs = Field(
        description="Edges of the tree or roadmap as (parent, child) index pairs, (m, 2)."
    )
    raw_waypoints: FloatArray | None = Field(
        None, description="The planner's path before simplification and interpolation, (k, 2), metres."
    )
    raw_cost: float | None = Field(None, description="Length of raw_waypoints, metres.")
    approximate: bool = Field(
        False, description="True when the planner only got close to the goal (status is then 'time_limit')."
    )
    goal_distance: float | None = Field(
        None, description="Distance from the path's last waypoint to the goal, metres."
    )
    collision_checks: int = Field(0, ge=0, description="State and motion validity checks the planner made.")


def _positive(value: Any, name: str, *, allow_zero: bool = False) -> float:
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise InvalidArgumentError(
            f"{name} must be a number, got {type(value).__name__}: {value!r}"
        ) from None
    if isinstance(value, bool) or not math.isfinite(number) or number < 0 or (number == 0 and not allow_zero):
        expect = ">= 0" if allow_zero else "> 0"
        raise InvalidArgumentError(f"{name} must be a finite number {expect}, got {value!r}")
    return number


def _integer(value: Any, name: str, *, low: int, high: int | None = None) -> int:
    try:
        if isinstance(value, bool):
            raise TypeError
        number = operator.index(value)
    except TypeError:
        raise InvalidArgumentError(
            f"{name} must be an integer, got {type(value).__name__}: {value!r}"
        ) from None
    if number < low or (high is not None and number > high):
        bound = f">= {low}" if high is None else f"in [{low}, {high}]"
        raise InvalidArgumentError(f"{name} must be an integer {bound}, got {number}")
    return number


def _length(path: NDArray[np.float64]) -> float:
    return float(np.hypot(*np.diff(path, axis=0).T).sum()) if len(path) > 1 else 0.0


def _interpolate(path: NDArray[np.float64], count: int) -> NDArray[np.float64]:
    """Insert points along the segments so that the path has ``count`` waypoints (OMPL's rule).

    Each segment gets a share of the new points proportional to its length; the path's vertices
    are kept. Nothing changes when ``count`` is not larger than the number of vertices.
    """
    k = len(path)
    if count <= k or k < 2:
        return path
    lengths = np.hypot(*np.diff(path, axis=0).T)
    total = float(lengths.sum())
    extra = count - k
    if total == 0.0:
        share = np.zeros(k - 1, dtype=np.int64)
        share[0] = extra
    else:
        exact = extra * lengths / total
        share = np.floor(exact).astype(np.int64)
        rest = extra - int(share.sum())
        share[np.argsort(-(exact - share), kind="stable")[:rest]] += 1
    pieces = []
    for i in range(k - 1):
        t = np.arange(share[i] + 1) / (share[i] + 1)
        pieces.append(path[i] + t[:, None] * (path[i + 1] - path[i]))
    pieces.append(path[-1:])
    return np.concatenate(pieces)


@register_api(
    "rrt",
    description="Sampling-based 2-D path planning (RRT, RRT*, informed RRT*, RRT-Connect, BIT*) "
    "through OMPL with exact collision checks; use for point paths among obstacles.",
    tags=("planning", "sampling", "path", "ompl"),
)
def rrt(
    world: World,
    start: ArrayLike,
    goal: ArrayLike,
    *,
    algorithm: Algorithm = "rrt_star",
    time_limit: float = 1.0,
    goal_tolerance: float = 1e-3,
    margin: float = 0.0,
    simplify: bool = True,
    interpolate: int | None = None,
    stop_at_first: bool = False,
    seed: int | None = 0,
    range: float | None = None,
    max_iterations: int | None = None,
) -> RRTResult:
    """Plan a collision-free path for a point robot with an OMPL sampling-based planner.

    The path is a polyline from ``start`` to within ``goal_tolerance`` of ``goal`` inside
    ``world.workspace``. Every state and every straight motion the planner considers is checked
    exactly against ``world.inflate(margin)`` (no sampled edge checks), so the returned path passes
    ``Task.check``. ``rrt`` and ``rrt_connect`` stop at their first solution; the optimizing
    planners (``rrt_star``, ``informed_rrt_star``, ``bit_star``) shorten the path
    until ``time_limit`` unless ``stop_at_first``.

    Parameters
    ----------
    world
        The workspace and obstacles (an :class:`audere.world.World`, e.g. ``task.world(inflated=False)``).
    start
        Start position ``(x, y)``, shape (2,), metres.
    goal
        Goal position ``(x, y)``, shape (2,), metres.
    algorithm
        The OMPL planner: ``"rrt"`` (fast, first solution only), ``"rrt_connect"`` (bidirectional,
        usually fastest to a first solution), ``"rrt_star"`` (asymptotically optimal),
        ``"informed_rrt_star"`` (RRT* that samples only where a shorter path can be, after the first
        solution), ``"bit_star"`` (batch informed trees). OMPL's PRM* is not offered: its
        roadmap grows in a second thread, which can deadlock with Python collision callbacks.
    time_limit
        Planning budget in seconds, > 0. Simplification may take up to as long again.
    goal_tolerance
        The path must end within this distance of ``goal``, metres, > 0. When its last point is not
        the goal itself and the straight segment to the goal is free, the goal is appended.
    margin
        Clearance in metres, >= 0: the path is planned in ``world.inflate(margin)``, so a disc robot
        of this radius stays clear of the real obstacles.
    simplify
        Shorten and smooth the solution with OMPL's path simplifier (shortcuts, vertex reduction).
    interpolate
        If given, insert points along the segments so that the path has this many waypoints
        (>= 2; segments get points in proportion to their length; never fewer than the path's vertices).
    stop_at_first
        Make the optimizing planners stop at their first solution (no effect on ``rrt``, ``rrt_connect``).
    seed
        Seed of OMPL's random number generators, integer in [0, 2**32 - 2], or ``None`` to continue
        OMPL's own sequence. With a seed, a run that stops at its first solution (``rrt``,
        ``rrt_connect``, ``stop_at_first``) or at ``max_iterations`` is bit-reproducible; a run cut by
        ``time_limit`` depends on how many iterations fit in the budget.
    range
        Longest step by which a tree grows towards a sample, metres, > 0; ``None`` for OMPL's default
        (a fifth of the workspace diagonal). Only for the RRT planners.
    max_iterations
        Stop after this many iterations, >= 1 (RRT* family and BIT*, which count them); ``None`` for no limit.

    Returns
    -------
    RRTResult
        ``status``: ``"solved"`` (a path reaches the goal), ``"infeasible"`` (the start or goal is outside
        the workspace or inside an inflated obstacle), ``"time_limit"`` (no path in the budget; an
        approximate path may be given with ``approximate=True``) or ``"failed"``. ``waypoints`` (k, 2) and
        ``cost`` (its length, metres) when solved; the planner's tree in ``tree_vertices`` (n, 2) and
        ``tree_edges`` (m, 2); ``first_solution_time`` and ``solve_time`` in seconds.

    Raises
    ------
    InvalidArgumentError
        For a malformed argument (shape, NaN, unknown algorithm, non-positive budget, ...).
    MissingDependencyError
        When OMPL is not installed (``pip install 'audere[ompl]'``).

    Examples
    --------
    >>> from audere.planners import rrt
    >>> from audere.world import Circle, World, Workspace
    >>> world = World(workspace=Workspace(), obstacles=[Circle(center=(5.0, 5.0), radius=2.0)])
    >>> result = rrt(world, (1.0, 1.0), (9.0, 9.0), time_limit=0.2)
    >>> result.status, result.waypoints[0].tolist(), result.waypoints[-1].tolist()
    ('solved', [1.0, 1.0], [9.0, 9.0])
    >>> bool(world.segments_in_collision(result.waypoints[:-1], result.waypoints[1:]).any())
    False
    """
    started = time.perf_counter()
    if not isinstance(world, World):
        raise InvalidArgumentError(f"world must be an audere.world.World, got {type(world).__name__}")
    p_start = as_float_array(start, name="start", shape=(2,))
    p_goal = as_float_array(goal, name="goal", shape=(2,))
    if algorithm not in _ALGORITHMS:
        raise InvalidArgumentError(f"algorithm must be one of {', '.join(_ALGORITHMS)}, got {algorithm!r}")
    budget = _positive(time_limit, "time_limit")
    tolerance = _positive(goal_tolerance, "goal_tolerance")
    clearance = _positive(margin, "margin", allow_zero=True)
    if interpolate is not None:
        interpolate = _integer(interpolate, "interpolate", low=2)
    if seed is not None:
        seed = _integer(seed, "seed", low=0, high=2**32 - 2)
    if max_iterations is not None:
        max_iterations = _integer(max_iterations, "max_iterations", low=1)
    step: float | None = None
    if range is not None:
        if algorithm not in _WITH_RANGE:
            raise InvalidArgumentError(
                f"range applies to {', '.join(_WITH_RANGE)} only, "
                f"got range={range!r} with algorithm={algorithm!r}"
            )
        step = _positive(range, "range")
    for flag, value in (("simplify", simplify), ("stop_at_first", stop_at_first)):
        if not isinstance(value, bool):
            raise InvalidArgumentError(f"{flag} must be True or False, got {value!r}")

    from audere.planners._ompl_adapter import ExactChecker, run_planner

    planning_world = world.inflate(clearance) if clearance > 0 else world
    checker = ExactChecker(planning_world)
    empty_tree: dict[str, Any] = {
        "tree_vertices": np.zeros((0, 2)),
        "tree_edges": np.zeros((0, 2), dtype=np.int64),
    }
    for name, point in (("start", p_start), ("goal", p_goal)):
        x, y = float(point[0]), float(point[1])
        reason = None
        if not checker.in_workspace(x, y):
            ws = world.workspace
            reason = f"lies outside the workspace [{ws.xmin}, {ws.xmax}] x [{ws.ymin}, {ws.ymax}]"
        elif not checker.point_free(x, y):
            hit = planning_world.first_collision(point[None, :])
            where = f"obstacle {hit.obstacle_index}" if hit is not None else "an obstacle"
            reason = f"lies inside {where}" + (
                f" inflated by the margin {clearance}" if clearance > 0 else ""
            )
        if reason is not None:
            return RRTResult(
                status="infeasible",
                message=f"{name} ({x:.6g}, {y:.6g}) {reason}",
                solve_time=time.perf_counter() - started,
                algorithm=algorithm,
                **empty_tree,
            )

    if float(np.hypot(*(p_goal - p_start))) <= tolerance:
        # Already there (OMPL's informed samplers fail on a zero start-goal distance): no search.
        sx, sy, gx, gy = (float(v) for v in (*p_start, *p_goal))
        path = np.array([p_start, p_goal]) if checker.segment_free(sx, sy, gx, gy) else p_start[None, :]
        return RRTResult(
            status="solved",
            message="the start lies within goal_tolerance of the goal",
            cost=_length(path),
            solve_time=time.perf_counter() - started,
            waypoints=path,
            algorithm=algorithm,
            first_solution_time=0.0,
            tree_vertices=p_start[None, :],
            tree_edges=np.zeros((0, 2), dtype=np.int64),
            raw_waypoints=path,
            raw_cost=_length(path),
            goal_distance=float(np.hypot(*(path[-1] - p_goal))),
        )

    run = run_planner(
        checker,
        (float(p_start[0]), float(p_start[1])),
        (float(p_goal[0]), float(p_goal[1])),
        algorithm=algorithm,
        time_limit=budget,
        goal_tolerance=tolerance,
        simplify=simplify,
        stop_at_first=stop_at_first,
        seed=seed,
        range_=step,
        max_iterations=max_iterations,
    )
    status: Status
    if run.status == "exact":
        status = "solved"
    elif run.status in ("approximate", "timeout"):
        status = "time_limit"
    elif run.status in ("invalid_start", "invalid_goal"):
        status = "infeasible"
    else:
        status = "failed"
    message = run.message

    waypoints = run.simplified if run.simplified is not None else run.path
    if waypoints is not None and status == "solved":
        end = waypoints[-1]
        if (end != p_goal).any() and checker.segment_free(float(end[0]), float(end[1]), *map(float, p_goal)):
            waypoints = np.vstack([waypoints, p_goal])
        if interpolate is not None:
            waypoints = _safe_interpolate(planning_world, waypoints, interpolate)
        # A last exact check of the returned path (the checker answers exactly as the World does).
        # It cannot fail for the planner's own motions; it guards the goal and interpolation steps.
        clear = all(checker.point_free(float(x), float(y)) for x, y in waypoints) and all(
            checker.segment_free(float(a[0]), float(a[1]), float(b[0]), float(b[1]))
            for a, b in itertools.pairwise(waypoints)
        )
        if not clear or float(np.hypot(*(waypoints[-1] - p_goal))) > tolerance:
            bad = planning_world.first_collision(waypoints)
            status, message = "failed", f"the planner's path does not pass the exact check: {bad}"
    goal_distance = float(np.hypot(*(waypoints[-1] - p_goal))) if waypoints is not None else None
    return RRTResult(
        status=status,
        message=message,
        cost=_length(waypoints) if waypoints is not None else None,
        solve_time=time.perf_counter() - started,
        waypoints=waypoints,
        algorithm=algorithm,
        first_solution_time=run.first_solution_time,
        iterations=run.iterations,
        tree_vertices=run.vertices,
        tree_edges=run.edges,
        raw_waypoints=run.path,
        raw_cost=_length(run.path) if run.path is not None else None,
        approximate=run.status == "approximate",
        goal_distance=goal_distance,
        collision_checks=run.state_checks + run.motion_checks,
    )


def _safe_interpolate(world: World, path: NDArray[np.float64], count: int) -> NDArray[np.float64]:
    """Interpolate, keeping a segment as it was if rounding put an inserted point into an obstacle."""
    dense = _interpolate(path, count)
    if len(dense) == len(path) or not world.obstacles:
        return dense
    if world.first_collision(dense) is None:
        return dense
    # Rare: a segment grazing an obstacle; rebuild segment by segment.
    pieces = [path[:1]]
    for i in np.arange(len(path) - 1):
        segment = path[i : i + 2]
        share = max(
            2, round(count * float(np.hypot(*(segment[1] - segment[0]))) / max(_length(path), 1e-300))
        )
        piece = _interpolate(segment, share)
        pieces.append((piece if world.first_collision(piece) is None else segment)[1:])
    return np.concatenate(pieces)
