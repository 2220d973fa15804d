"""The one place that speaks OMPL: exact collision checking against a World, and a planning run.

Everything written in OMPL's camelCase stays in this module; :mod:`audere.planners._rrt` sees plain
Python and numpy data only. OMPL (the ``ompl`` package, 2.x nanobind bindings) is imported inside
:func:`run_planner`, never at module import.

Binding facts this module relies on (ompl 2.0.1):

- states are made with ``SpaceInformation.allocState()`` and read as ``state[0], state[1]``; their
  coordinates are copied out at once and no ``State`` object is kept after the run;
- a validity checker is a plain callable that must return a real Python ``bool``;
- a ``MotionValidator`` subclass replaces OMPL's sampled edge checks by our exact test;
- ``util.RNG.setSeed(s)`` reseeds the generator that seeds every later OMPL random generator
  (``s`` must be positive; OMPL logs an error when generators already exist, which we silence);
- the RRT* family stops at its first solution when the objective's cost threshold is infinite, and
  its best cost can be polled from a termination condition (the intermediate-solution callback is
  not usable from Python).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from audere._optional import require
from audere.world import Circle, Polygon, Rectangle, Square, World

__all__ = ["ALGORITHMS", "ExactChecker", "PlannerRun", "run_planner"]

# algorithm name -> (OMPL geometric planner class name, accepts a range, reports best cost & iterations)
ALGORITHMS: dict[str, tuple[str, bool, bool]] = {
    "bit_star": ("BITstar", False, True),
    "informed_rrt_star": ("InformedRRTstar", True, True),
    "rrt": ("RRT", True, False),
    "rrt_connect": ("RRTConnect", True, False),
    "rrt_star": ("RRTstar", True, True),
}
"""The OMPL planners offered, by our name."""

_FREE, _HIT, _UNSURE = 0, 1, 2


class ExactChecker:
    """Exact point and segment collision tests against a world, fast for one query at a time.

    OMPL asks about one state or one motion per call, where :meth:`World.points_in_collision` and
    :meth:`World.segments_in_collision` (vectorized, with exact predicates) cost a few hundred
    microseconds. This checker first classifies the query in plain floating point with a safety
    band ``tol`` around every obstacle boundary, far wider than the rounding error of the float
    computation: a query clearly outside every band is free, one clearly inside some obstacle
    collides, and only a query that comes within ``tol`` of a boundary (or meets a polygon's bounding
    box) is passed to the World's exact predicates. The answers are therefore exactly the World's.

    Parameters
    ----------
    world
        The world to check against (already inflated by any clearance margin).
    """

    def __init__(self, world: World) -> None:
        self.world = world
        ws = world.workspace
        scale = max(abs(ws.xmin), abs(ws.xmax), abs(ws.ymin), abs(ws.ymax), 1.0)
        self.tol = 1e-9 * scale
        self._bounds = (ws.xmin, ws.xmax, ws.ymin, ws.ymax)
        tol = self.tol
        # Per obstacle: (kind, xmin - tol, xmax + tol, ymin - tol, ymax + tol, data)
        shapes: list[tuple[int, float, float, float, float, tuple[float, ...]]] = []
        for obstacle in world.obstacles:
            if isinstance(obstacle, Circle):
                cx, cy = obstacle.center
                r = obstacle.radius
                data: tuple[float, ...] = (cx, cy, (r + tol) ** 2, max(r - tol, 0.0) ** 2)
                shapes.append((0, cx - r - tol, cx + r + tol, cy - r - tol, cy + r + tol, data))
            elif isinstance(obstacle, Square | Rectangle):
                if isinstance(obstacle, Square):
                    cx, cy = obstacle.center
                    h = obstacle.half_side
                    x0, x1, y0, y1 = cx - h, cx + h, cy - h, cy + h
                else:
                    x0, x1, y0, y1 = obstacle.xmin, obstacle.xmax, obstacle.ymin, obstacle.ymax
                shapes.append(
                    (1, x0 - tol, x1 + tol, y0 - tol, y1 + tol, (x0 + tol, x1 - tol, y0 + tol, y1 - tol))
                )
            elif isinstance(obstacle, Polygon):
                xs = [v[0] for v in obstacle.vertices]
                ys = [v[1] for v in obstacle.vertices]
                shapes.append((2, min(xs) - tol, max(xs) + tol, min(ys) - tol, max(ys) + tol, ()))
        self._shapes = tuple(shapes)
        self.exact_point_calls = 0
        self.exact_segment_calls = 0

    def in_workspace(self, x: float, y: float) -> bool:
        """Whether ``(x, y)`` lies in the workspace, boundary included."""
        x0, x1, y0, y1 = self._bounds
        return x0 <= x <= x1 and y0 <= y <= y1

    def point_free(self, x: float, y: float) -> bool:
        """Whether the point ``(x, y)`` (metres) lies outside every obstacle's interior (exact)."""
        unsure = False
        for kind, bx0, bx1, by0, by1, data in self._shapes:
            if x < bx0 or x > bx1 or y < by0 or y > by1:
                continue
            if kind == 0:
                cx, cy, r_out2, r_in2 = data
                d2 = (x - cx) ** 2 + (y - cy) ** 2
                if d2 < r_in2:
                    return False
                if d2 <= r_out2:
                    unsure = True
            elif kind == 1:
                ix0, ix1, iy0, iy1 = data
                if ix0 < x < ix1 and iy0 < y < iy1:
                    return False
                unsure = True
            else:
                unsure = True
        if not unsure:
            return True
        self.exact_point_calls += 1
        return not bool(self.world.points_in_collision((x, y)))

    def segment_free(self, ax: float, ay: float, bx: float, by: float) -> bool:
        """Whether the closed segment ``(ax, ay)``-``(bx, by)`` stays out of every interior (exact)."""
        lox, hix = (ax, bx) if ax <= bx else (bx, ax)
        loy, hiy = (ay, by) if ay <= by else (by, ay)
        dx, dy = bx - ax, by - ay
        unsure = False
        for kind, bx0, bx1, by0, by1, data in self._shapes:
            if hix < bx0 or lox > bx1 or hiy < by0 or loy > by1:
                continue
            if kind == 0:
                verdict = _circle_segment(ax, ay, dx, dy, data)
            elif kind == 1:
                if not _clip(ax, ay, dx, dy, bx0, bx1, by0, by1):
                    continue
                ix0, ix1, iy0, iy1 = data
                if ix0 < ix1 and iy0 < iy1 and _clip(ax, ay, dx, dy, ix0, ix1, iy0, iy1):
                    return False
                verdict = _UNSURE
            else:
                verdict = _UNSURE if _clip(ax, ay, dx, dy, bx0, bx1, by0, by1) else _FREE
            if verdict == _HIT:
                return False
            if verdict == _UNSURE:
                unsure = True
        if not unsure:
            return True
        self.exact_segment_calls += 1
        return not bool(self.world.segments_in_collision((ax, ay), (bx, by)))


def _circle_segment(ax: float, ay: float, dx: float, dy: float, data: tuple[float, ...]) -> int:
    cx, cy, r_out2, r_in2 = data
    length2 = dx * dx + dy * dy
    t = 0.0 if length2 == 0.0 else ((cx - ax) * dx + (cy - ay) * dy) / length2
    t = 0.0 if t < 0.0 else (1.0 if t > 1.0 else t)
    ex, ey = ax + t * dx - cx, ay + t * dy - cy
    d2 = ex * ex + ey * ey
    if d2 > r_out2:
        return _FREE
    return _HIT if d2 < r_in2 else _UNSURE


def _clip(ax: float, ay: float, dx: float, dy: float, x0: float, x1: float, y0: float, y1: float) -> bool:
    """Whether the segment ``a + t d``, ``t`` in [0, 1], meets the closed box (Liang-Barsky)."""
    t0, t1 = 0.0, 1.0
    for p, q in ((-dx, ax - x0), (dx, x1 - ax), (-dy, ay - y0), (dy, y1 - ay)):
        if p == 0.0:
            if q < 0.0:
                return False
            continue
        r = q / p
        if p < 0.0:
            if r > t1:
                return False
            t0 = max(t0, r)
        else:
            if r < t0:
                return False
            t1 = min(t1, r)
    return t0 <= t1


@dataclass(frozen=True)
class PlannerRun:
    """What one OMPL run produced, as plain data (no OMPL object survives the run).

    Attributes
    ----------
    status
        ``"exact"``, ``"approximate"``, ``"timeout"``, ``"invalid_start"``, ``"invalid_goal"`` or
        ``"other"``.
    message
        OMPL's status string.
    path
        The raw solution path, (k, 2), or ``None``.
    simplified
        The path after OMPL's simplifier, (k, 2), or ``None`` when not simplified.
    first_solution_time
        Seconds from the start of ``solve`` to the first solution, ``None`` when none was found.
    iterations
        The planner's iteration count where it reports one (RRT* family, BIT*), else ``None``.
    vertices
        Planner graph vertices, (n, 2).
    edges
        Planner graph edges as vertex index pairs, (m, 2) integers.
    solve_time
        Seconds spent in ``solve``.
    simplify_time
        Seconds spent simplifying.
    goal_distance
        OMPL's distance from the path's end to the goal region (0 for an exact solution).
    state_checks
        Validity checks OMPL asked for.
    motion_checks
        Motion checks OMPL asked for.
    exact_calls
        Of those, how many went to the World's exact predicates (the rest were settled in floats).
    """

    status: str
    message: str
    path: NDArray[np.float64] | None
    simplified: NDArray[np.float64] | None
    first_solution_time: float | None
    iterations: int | None
    vertices: NDArray[np.float64]
    edges: NDArray[np.int64]
    solve_time: float
    simplify_time: float
    goal_distance: float
    state_checks: int
    motion_checks: int
    exact_calls: int


_STATUS = {
    "EXACT_SOLUTION": "exact",
    "APPROXIMATE_SOLUTION": "approximate",
    "TIMEOUT": "timeout",
    "INVALID_START": "invalid_start",
    "INVALID_GOAL": "invalid_goal",
}


def _path_array(path: Any) -> NDArray[np.float64]:
    return np.array([(float(s[0]), float(s[1])) for s in path.getStates()], dtype=np.float64).reshape(-1, 2)


_MOTION_VALIDATOR: list[type] = []


def _motion_validator_class(ob: Any) -> type:
    """OMPL ``MotionValidator`` subclass calling a Python function (defined once per process)."""
    if not _MOTION_VALIDATOR:

        class ExactMotionValidator(ob.MotionValidator):  # type: ignore[misc]
            def __init__(self, si: Any, check: Callable[[Any, Any], bool]) -> None:
                super().__init__(si)
                self._check = check

            def checkMotion(self, s1: Any, s2: Any) -> bool:
                return self._check(s1, s2)

        _MOTION_VALIDATOR.append(ExactMotionValidator)
    return _MOTION_VALIDATOR[0]


def run_planner(
    checker: ExactChecker,
    start: tuple[float, float],
    goal: tuple[float, float],
    *,
    algorithm: str,
    time_limit: float,
    goal_tolerance: float,
    simplify: bool,
    stop_at_first: bool,
    seed: int | None,
    range_: float | None,
    max_iterations: int | None,
) -> PlannerRun:
    """Plan a 2-D point path with an OMPL geometric planner under exact collision checking.

    Parameters
    ----------
    checker
        Exact checker of the (inflated) world; its workspace bounds the state space.
    start
        ``(x, y)``, metres.
    goal
        ``(x, y)``, metres.
    algorithm
        A key of :data:`ALGORITHMS`.
    time_limit
        Seconds for ``solve`` (> 0); simplification gets at most as long again.
    goal_tolerance
        Radius of the goal region, metres (> 0).
    simplify
        Run OMPL's path simplifier (shortcutting, vertex reduction, better goal).
    stop_at_first
        Stop the asymptotically optimal planners at their first solution.
    seed
        Seed of OMPL's random generators (``seed + 1`` is passed: OMPL rejects 0), or ``None``.
    range_
        Longest extension step of the tree planners, metres, or ``None`` for OMPL's default.
    max_iterations
        Stop after this many iterations (planners that count them), or ``None``.

    Returns
    -------
    PlannerRun
        Plain data; no OMPL object is kept.
    """
    ompl = require("ompl", extra="ompl", purpose="planners.rrt (OMPL's sampling-based planners)")
    ob = require("ompl.base", extra="ompl", purpose="planners.rrt (OMPL's sampling-based planners)")
    og = require("ompl.geometric", extra="ompl", purpose="planners.rrt (OMPL's sampling-based planners)")
    ou = require("ompl.util", extra="ompl", purpose="planners.rrt (OMPL's sampling-based planners)")
    del ompl
    class_name, _, reports_cost = ALGORITHMS[algorithm]

    previous_level = ou.getLogLevel()
    ou.setLogLevel(ou.LOG_ERROR)
    try:
        if seed is not None:
            # OMPL logs an error (and still reseeds) when generators already exist: silence it.
            ou.noOutputHandler()
            try:
                ou.RNG.setSeed(seed + 1)
            finally:
                ou.restorePreviousOutputHandler()
        return _solve(
            ob, og, checker, start, goal, class_name, reports_cost, time_limit=time_limit,
            goal_tolerance=goal_tolerance, simplify=simplify, stop_at_first=stop_at_first,
            range_=range_, max_iterations=max_iterations,
        )  # fmt: skip
    finally:
        ou.setLogLevel(previous_level)


def _solve(
    ob: Any,
    og: Any,
    checker: ExactChecker,
    start: tuple[float, float],
    goal: tuple[float, float],
    class_name: str,
    reports_cost: bool,
    *,
    time_limit: float,
    goal_tolerance: float,
    simplify: bool,
    stop_at_first: bool,
    range_: float | None,
    max_iterations: int | None,
) -> PlannerRun:
    x0, x1, y0, y1 = checker._bounds
    space = ob.RealVectorStateSpace(2)
    bounds = ob.RealVectorBounds(2)
    bounds.setLow(0, x0)
    bounds.setHigh(0, x1)
    bounds.setLow(1, y0)
    bounds.setHigh(1, y1)
    space.setBounds(bounds)
    si = ob.SpaceInformation(space)

    counts = [0, 0]
    in_workspace, point_free, segment_free = checker.in_workspace, checker.point_free, checker.segment_free

    def is_valid(state: Any) -> bool:
        counts[0] += 1
        x, y = float(state[0]), float(state[1])
        return bool(in_workspace(x, y) and point_free(x, y))

    def check_motion(s1: Any, s2: Any) -> bool:
        counts[1] += 1
        return bool(segment_free(float(s1[0]), float(s1[1]), float(s2[0]), float(s2[1])))

    si.setStateValidityChecker(is_valid)
    motions = _motion_validator_class(ob)(si, check_motion)
    si.setMotionValidator(motions)
    si.setup()

    pdef = ob.ProblemDefinition(si)
    s_state, g_state = si.allocState(), si.allocState()
    s_state[0], s_state[1] = start
    g_state[0], g_state[1] = goal
    pdef.setStartAndGoalStates(s_state, g_state, goal_tolerance)
    objective = ob.PathLengthOptimizationObjective(si)
    if stop_at_first:
        objective.setCostThreshold(ob.Cost(math.inf))
    pdef.setOptimizationObjective(objective)

    planner = getattr(og, class_name)(si)
    if range_ is not None:
        planner.setRange(range_)
    planner.setProblemDefinition(pdef)
    planner.setup()

    first: list[float | None] = [None]
    t_start = time.perf_counter()
    best_cost: Callable[[], Any] | None = planner.bestCost if reports_cost else None
    iterations: Callable[[], int] | None = planner.numIterations if reports_cost else None

    def stop() -> bool:
        now = time.perf_counter() - t_start
        if first[0] is None:
            found = math.isfinite(best_cost().value()) if best_cost is not None else pdef.hasSolution()
            if found:
                first[0] = now
        if max_iterations is not None and iterations is not None and iterations() >= max_iterations:
            return True
        return now >= time_limit

    try:
        status = planner.solve(ob.PlannerTerminationCondition(stop))
    except RuntimeError as exc:  # OMPL's C++ exceptions (a degenerate problem, ...)
        kind, message = "other", f"OMPL raised: {exc}"
    else:
        kind = _STATUS.get(status.getStatus().name, "other")
        message = str(status.asString())
    solve_time = time.perf_counter() - t_start

    path = simplified = None
    simplify_time = 0.0
    goal_distance = math.inf
    if pdef.hasSolution():
        if first[0] is None:
            first[0] = solve_time
        goal_distance = float(pdef.getSolutionDifference()) if pdef.hasApproximateSolution() else 0.0
        solution = pdef.getSolutionPath()
        path = _path_array(solution)
        if simplify and kind == "exact":
            t_simplify = time.perf_counter()
            budget = max(time_limit, 0.05)
            simplifier = og.PathSimplifier(si, pdef.getGoal())
            copy = og.PathGeometric(solution)
            simplifier.simplify(
                copy, ob.PlannerTerminationCondition(lambda: time.perf_counter() - t_simplify > budget)
            )
            simplified = _path_array(copy)
            simplify_time = time.perf_counter() - t_simplify
    else:
        first[0] = None

    data = ob.PlannerData(si)
    planner.getPlannerData(data)
    n = int(data.numVertices())
    vertices = np.empty((n, 2), dtype=np.float64)
    edge_list: list[tuple[int, int]] = []
    for i in range(n):
        state = data.getVertex(i).getState()
        vertices[i] = (float(state[0]), float(state[1]))
        edge_list.extend((i, int(j)) for j in data.getEdges(i))
    edges = np.array(edge_list, dtype=np.int64).reshape(-1, 2)
    n_iterations = int(iterations()) if iterations is not None else None

    return PlannerRun(
        status=kind,
        message=message,
        path=path,
        simplified=simplified,
        first_solution_time=first[0],
        iterations=n_iterations,
        vertices=vertices,
        edges=edges,
        solve_time=solve_time,
        simplify_time=simplify_time,
        goal_distance=goal_distance,
        state_checks=counts[0],
        motion_checks=counts[1],
        exact_calls=checker.exact_point_calls + checker.exact_segment_calls,
    )
