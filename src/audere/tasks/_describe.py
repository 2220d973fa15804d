"""The natural-language description of a task, as a language model sees it.

Every number the checker uses is stated, with its convention: the robot (the dynamics model's own
description, with the task's time step and integrator), the initial state, time step and horizon,
the input bounds, the workspace, every obstacle (squares by their half side), the margin, the goal,
the reference, the maze's cells, walls and doors, the STL specification with its regions and a
plain-English reading, what the solution must be, and the success criterion.

Numbers are printed with two decimals, or with up to four when two would not be exact.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from typing import TYPE_CHECKING

import numpy as np

from audere.errors import InvalidArgumentError
from audere.tasks._models import MazeTask, ReachAvoidTask, STLTask, TrackingTask

if TYPE_CHECKING:
    from audere.dynamics import Dynamics
    from audere.stl import Formula
    from audere.world import Obstacle, Workspace

__all__ = ["describe", "describe_formula", "describe_obstacle", "fmt", "names_tuple"]

AnyTask = TrackingTask | ReachAvoidTask | MazeTask | STLTask


def fmt(value: float, *, decimals: int = 2, max_decimals: int = 4) -> str:
    """Format a number with ``decimals`` decimals, or more (up to ``max_decimals``) when needed to be exact.

    Parameters
    ----------
    value
        The number.
    decimals
        Decimals always shown.
    max_decimals
        Most decimals shown; values that need more are rounded to this many.

    Returns
    -------
    str
        E.g. ``fmt(1.5) == "1.50"``, ``fmt(0.125) == "0.125"``, ``fmt(10 / 3) == "3.3333"``.
    """
    v = float(value)
    if not np.isfinite(v):
        return "inf" if v > 0 else ("-inf" if v < 0 else "nan")
    for d in range(decimals, max_decimals + 1):
        text = f"{v:.{d}f}"
        if abs(float(text) - v) <= 1e-9 * max(1.0, abs(v)):
            break
    if float(text) == 0:
        text = text.lstrip("-")
    return text


def _pt(p: Sequence[float] | np.ndarray, *, decimals: int = 2, max_decimals: int = 4) -> str:
    return "(" + ", ".join(fmt(float(a), decimals=decimals, max_decimals=max_decimals) for a in p) + ")"


def names_tuple(names: Iterable[str]) -> str:
    """Names as a parenthesized list, e.g. ``"(omega, a)"``.

    Parameters
    ----------
    names
        State or input names.

    Returns
    -------
    str
        The names in parentheses, separated by commas.
    """
    return "(" + ", ".join(names) + ")"


_names = names_tuple


# --------------------------------------------------------------------------------------- shapes


def describe_obstacle(shape: Obstacle | Workspace) -> str:
    """Exact one-line text of a shape (squares by centre and half side, with the side length).

    Parameters
    ----------
    shape
        A circle, square, rectangle, polygon or the workspace.

    Returns
    -------
    str
        E.g. ``"circle centred at (3.20, 4.10), radius 1.25"`` or ``"square centred at (5.00, 5.00),
        half side 0.50 (side length 1.00; covers x in [4.50, 5.50], y in [4.50, 5.50])"``.
    """
    from audere.world import Circle, Polygon, Rectangle, Square, Workspace

    if isinstance(shape, Circle):
        return f"circle centred at {_pt(shape.center)}, radius {fmt(shape.radius)}"
    if isinstance(shape, Square):
        (cx, cy), h = shape.center, shape.half_side
        return (
            f"square centred at {_pt(shape.center)}, half side {fmt(h)} (side length {fmt(2 * h)}; covers x "
            f"in [{fmt(cx - h)}, {fmt(cx + h)}], y in [{fmt(cy - h)}, {fmt(cy + h)}])"
        )
    if isinstance(shape, Rectangle | Workspace):
        what = "rectangle" if isinstance(shape, Rectangle) else "workspace"
        return (
            f"{what} x in [{fmt(shape.xmin)}, {fmt(shape.xmax)}], y in [{fmt(shape.ymin)}, {fmt(shape.ymax)}]"
        )
    if isinstance(shape, Polygon):
        return "polygon with vertices " + ", ".join(_pt(v) for v in shape.vertices)
    raise InvalidArgumentError(
        f"shape must be a circle, square, rectangle or polygon, got {type(shape).__name__}"
    )


def _conventions(kinds: Iterable[str], margin: float, *, regions: bool = False) -> list[str]:
    """The shape conventions, for the kinds present, stated explicitly."""
    lines = ["Conventions for shapes (coordinates in metres):"]
    if "circle" in kinds:
        lines.append("- a circle is given by its centre and radius;")
    lines.append(
        "- a square is axis-aligned and given by its centre and its HALF side h (the distance from the "
        "centre to each edge): it covers [cx - h, cx + h] x [cy - h, cy + h], so its side length is 2 h;"
    )
    if "rectangle" in kinds:
        lines.append(
            "- a rectangle is axis-aligned and given by its bounds x in [xmin, xmax], y in [ymin, ymax];"
        )
    if "polygon" in kinds:
        lines.append("- a polygon is given by its vertices in order;")
    if regions:
        lines.append(
            "- in(R) holds only when the position is strictly inside region R: a position on R's boundary is "
            "not inside R."
        )
        return lines
    lines.append(
        "- a position collides with an obstacle only when it is strictly inside it: touching the boundary is "
        "allowed" + (";" if margin > 0 else ".")
    )
    if margin > 0:
        m = fmt(margin)
        grow = {
            "circle": f"a circle's radius grows by {m}",
            "square": f"a square's half side grows by {m} (it stays a square)",
            "rectangle": f"a rectangle's sides move out by {m}",
            "polygon": f"a polygon's edges move out by {m} (mitred corners)",
        }
        parts = ", ".join(text for kind, text in grow.items() if kind in kinds)
        lines.append(
            f"- for checking, every obstacle is inflated by the margin {m}: {parts}. Keep at least {m} away "
            "from the shapes listed."
        )
    return lines


def _obstacle_lines(task: AnyTask) -> list[str]:
    if not task.obstacles:
        return ["Obstacles: none."] if not isinstance(task, MazeTask) else ["Obstacles in the cells: none."]
    head = "Obstacles in the cells" if isinstance(task, MazeTask) else "Obstacles"
    lines = [f"{head} ({len(task.obstacles)}, numbered from 0):"]
    lines += [f"- {i}: {describe_obstacle(o)}" for i, o in enumerate(task.obstacles)]
    return lines


# --------------------------------------------------------------------------------------- STL


_STEP_NAMES = ("k", "j", "i", "m", "n", "p", "q", "r")


def _window(base: int | str, lo: int, hi: int) -> tuple[str, str]:
    if isinstance(base, int):
        return str(base + lo), str(base + hi)
    return (base if lo == 0 else f"{base}+{lo}"), f"{base}+{hi}"


def _compare_text(a: float, b: float, op: str, rhs: float) -> str:
    parts: list[str] = []
    for coef, var in ((a, "x"), (b, "y")):
        if coef == 0:
            continue
        body = var if abs(coef) == 1 else f"{fmt(abs(coef))}*{var}"
        sign = "-" if coef < 0 else "+"
        parts.append((f"-{body}" if coef < 0 else body) if not parts else f" {sign} {body}")
    return f"{''.join(parts)} {op} {fmt(rhs)}"


def _english(node: Formula, base: int | str, depth: int) -> str:
    from audere.stl import Always, And, Compare, Constant, Eventually, Implies, In, Not, Or, Until

    def sub(child: Formula, b: int | str = base, d: int = depth) -> str:
        text = _english(child, b, d)
        return f"({text})" if isinstance(child, And | Or | Implies | Until) else text

    if isinstance(node, Constant):
        return "true" if node.value else "false"
    if isinstance(node, In):
        return f"the position is inside {node.name}"
    if isinstance(node, Compare):
        return f"the position satisfies {_compare_text(node.a, node.b, node.op, node.rhs)}"
    if isinstance(node, Not):
        if isinstance(node.child, In):
            return f"the position is not inside {node.child.name}"
        return f"it is not the case that {sub(node.child)}"
    if isinstance(node, And):
        return " and ".join(sub(c) for c in node.operands)
    if isinstance(node, Or):
        return " or ".join(sub(c) for c in node.operands)
    if isinstance(node, Implies):
        return f"if {sub(node.left)}, then {sub(node.right)}"
    name = _STEP_NAMES[min(depth, len(_STEP_NAMES) - 1)] + ("" if depth < len(_STEP_NAMES) else str(depth))
    if isinstance(node, Always | Eventually):
        lo, hi = _window(base, node.lo, node.hi)
        quant = "every" if isinstance(node, Always) else "some"
        return f"at {quant} step {name} from {lo} to {hi}, {sub(node.child, name, depth + 1)}"
    if isinstance(node, Until):
        lo, hi = _window(base, node.lo, node.hi)
        inner = _STEP_NAMES[min(depth + 1, len(_STEP_NAMES) - 1)]
        return (
            f"at some step {name} from {lo} to {hi}, {sub(node.right, name, depth + 1)}, and at every step "
            f"{inner} from {base} to {name}-1 before it, {sub(node.left, inner, depth + 2)}"
        )
    raise InvalidArgumentError(f"not an STL formula node: {type(node).__name__}")  # pragma: no cover


def describe_formula(formula: Formula) -> list[str]:
    """A plain-English reading of an STL formula, one line per top-level clause.

    Parameters
    ----------
    formula
        The parsed specification.

    Returns
    -------
    list of str
        Lines such as ``"1. F[10,17] in(E): at some step k from 10 to 17, the position is inside E."``.
    """
    clauses = formula.clauses()
    lines = []
    for i, clause in enumerate(clauses, start=1):
        text = _english(clause, 0, 0)
        if not text.startswith("at "):
            text = "at step 0, " + text
        lines.append(f"{i}. {clause}: {text}.")
    return lines


# --------------------------------------------------------------------------------------- sections


def _robot_lines(task: AnyTask, model: Dynamics) -> list[str]:
    lines = ["Robot:"]
    describe_model = getattr(model, "describe", None)
    if callable(describe_model):
        lines.append(str(describe_model(dt=task.dt, method=task.integrator)))
    else:  # pragma: no cover - every built-in model describes itself
        lines.append(
            f"dynamics {model.name!r}, state {_names(model.state_names)}, input {_names(model.input_names)}"
        )
    x0 = " = ".join([_names(model.state_names), _pt(task.x0)])
    lines.append(f"Initial state x0: {x0}; the robot starts at the position {_pt(task.start)}.")
    if tuple(model.state_names[:2]) != ("x", "y"):
        lines.append(
            "Checked point: 'position' means the planar point given by position() above; only that point "
            "(and the straight segments between its positions at consecutive steps) is checked against the "
            "workspace and the obstacles, not the rest of the robot."
        )
    method = "Euler" if task.integrator == "euler" else "classical Runge-Kutta (RK4)"
    lines.append(
        f"Time: dt = {fmt(task.dt)} s, horizon {task.horizon} steps (states at steps 0..{task.horizon}, "
        f"inputs at steps 0..{task.horizon - 1}; {method} step, input u[k] held from step k to k+1)."
    )
    lo = np.asarray(task.u_min if task.u_min is not None else model.input_lower, dtype=float)
    hi = np.asarray(task.u_max if task.u_max is not None else model.input_upper, dtype=float)
    parts = []
    for name, a, b in zip(model.input_names, lo, hi, strict=True):
        if np.isfinite(a) and np.isfinite(b):
            parts.append(f"{fmt(a)} <= {name} <= {fmt(b)}")
        elif np.isfinite(a):
            parts.append(f"{name} >= {fmt(a)}")
        elif np.isfinite(b):
            parts.append(f"{name} <= {fmt(b)}")
    bounds = ", ".join(parts) if parts else "none"
    lines.append(f"Input bounds (at every step, these replace the model's defaults): {bounds}.")
    return lines


def _solution_lines(task: AnyTask) -> list[str]:
    model = task.model
    if model is None:
        return [
            "Solution: waypoints, an array of shape (k, 2) with one row (x, y) per waypoint, in order, k >= "
            "1; the path is the polyline through them (a straight segment between consecutive waypoints)."
        ]
    h = task.horizon
    lines = [
        f"Solution: inputs, an array of shape ({h}, {model.n_u}), row k = {_names(model.input_names)} "
        "applied from step k to k+1; the states are the rollout of the inputs from x0 with the step above"
        + (f" (an array of shape ({h},) is accepted too)." if model.n_u == 1 else ".")
    ]
    kinds = task.solution_kinds
    if "states" in kinds:
        lines.append(
            f"Or: states, an array of shape ({h + 1}, {model.n_x}), row k = {_names(model.state_names)} at "
            "step k; the inputs are then (states[k+1] - states[k]) / dt and must respect the bounds, and "
            f"states[0] must be within {fmt(task.start_tolerance)} of x0."
        )
    if "timed_waypoints" in kinds:
        end = fmt(h * task.dt)
        lines.append(
            "Or: timed waypoints, an array of shape (k, 3) with rows (x, y, t), t in seconds strictly "
            f"increasing from t = 0 to at least t = {end}; the positions at t = 0, {fmt(task.dt)}, ..., "
            f"{end} are obtained by linear interpolation and checked as states (so the velocity between "
            "consecutive resampled positions must respect the input bounds)."
        )
    return lines


def _geometry_criteria(task: AnyTask, where: str) -> list[str]:
    out = [f"{where} lies in the workspace"]
    if task.all_obstacles():
        inflated = " (inflated by the margin)" if task.margin > 0 else ""
        shapes = "obstacle or wall" if isinstance(task, MazeTask) else "obstacle"
        out.append(
            "no position and no straight segment between consecutive positions enters an "
            f"{shapes}{inflated}; segments are checked exactly, not sampled"
        )
    return out


def _criteria(task: AnyTask) -> list[str]:
    model = task.model
    items: list[str] = []
    if model is None:
        items.append(f"the first waypoint is within {fmt(task.start_tolerance)} of the start")
        where = "every waypoint"
    else:
        items.append("every input is within its bounds (tolerance 1e-6)")
        where = f"the position at every step 0..{task.horizon}"
    items += _geometry_criteria(task, where)
    if isinstance(task, TrackingTask):
        items.append(
            f"the mean, over steps 0..{task.horizon}, of the Euclidean distance between the robot's position "
            f"and the reference position is below {fmt(task.tolerance)}"
        )
    elif isinstance(task, ReachAvoidTask):
        if task.goal_on == "state" and model is not None:
            angles = ", ".join(model.state_names[i] for i in task.angle_indices)
            plural = "s" if len(task.angle_indices) > 1 else ""
            wrap = (
                f", with the difference{plural} of the angle{plural} {angles} wrapped to [-pi, pi)"
                if angles
                else ""
            )
            items.append(
                f"the final state is within {fmt(task.goal_tolerance)} of the goal state (Euclidean norm of "
                f"the state difference{wrap})"
            )
        else:
            last = "the last waypoint" if model is None else f"the position at step {task.horizon}"
            items.append(f"{last} is within {fmt(task.goal_tolerance)} of the goal")
    elif isinstance(task, MazeTask):
        items.append(f"the last waypoint is within {fmt(task.goal_tolerance)} of the goal")
    else:
        items.append(
            "the robustness of the specification at step 0 is > 0 (every clause holds with a margin)"
        )
    return ["Success when all of these hold:"] + [f"- {item};" for item in items[:-1]] + [f"- {items[-1]}."]


def _reference_lines(task: TrackingTask) -> list[str]:
    ref = np.asarray(task.reference)
    model = task.model
    as_positions = ref.shape[1] == 2 and np.array_equal(np.asarray(task.reference_positions), ref)
    rows = ", ".join(_pt(r, decimals=2, max_decimals=3) for r in ref)
    if as_positions:
        head = f"Reference: {len(ref)} positions (x, y), one per step 0..{task.horizon}:"
    else:
        names = _names(model.state_names) if model is not None else "states"
        head = (
            f"Reference: {len(ref)} states {names}, one per step 0..{task.horizon}; the robot's position is "
            "compared with the position of each reference state:"
        )
    return [head, f"[{rows}]"]


def _maze_lines(task: MazeTask) -> list[str]:
    ws = task.workspace
    w, h = task.cell_size
    t = fmt(task.wall_thickness)
    lines = [
        f"Maze: the workspace is divided into {task.rows} rows x {task.cols} columns of cells, each {fmt(w)} "
        f"wide (x) and {fmt(h)} high (y). Cell (r, c) has row r counted from the bottom (row 0 has the "
        f"smallest y) and column c from the left: it spans x in [{fmt(ws.xmin)} + c*{fmt(w)}, {fmt(ws.xmin)} "
        f"+ (c+1)*{fmt(w)}], y in [{fmt(ws.ymin)} + r*{fmt(h)}, {fmt(ws.ymin)} + (r+1)*{fmt(h)}].",
        f"Walls: every border between two neighbouring cells is a wall of thickness {t}, centred on the "
        f"border line (a wall on the line x = X covers x in [X - {fmt(task.wall_thickness / 2)}, X + "
        f"{fmt(task.wall_thickness / 2)}]), except where a door opens it. The outer edge of the workspace "
        "has no wall (the workspace bounds apply).",
    ]
    if task.margin > 0:
        lines.append(
            f"Walls are inflated by the margin {fmt(task.margin)} like the obstacles, so a door of width W "
            f"leaves a passage of width W - {fmt(2 * task.margin)}."
        )
    if not task.doors:
        lines.append("Doors: none.")
    else:
        lines.append(f"Doors ({len(task.doors)}):")
        for i, (door, (centre, orient)) in enumerate(
            zip(task.doors, (task._door_geometry(d) for d in task.doors), strict=True)
        ):
            a, b = door.cells
            half = door.width / 2
            if orient == "v":
                where = (
                    f"in the wall on x = {fmt(centre[0])}, from y = {fmt(centre[1] - half)} to y = "
                    f"{fmt(centre[1] + half)}"
                )
            else:
                where = (
                    f"in the wall on y = {fmt(centre[1])}, from x = {fmt(centre[0] - half)} to x = "
                    f"{fmt(centre[0] + half)}"
                )
            lines.append(
                f"- door {i} connects cells {a} and {b}: an opening of width {fmt(door.width)} {where}"
            )
    start_cell, goal_cell = task.cell_of(task.start), task.cell_of(task.goal)
    lines.append(f"The start is in cell {start_cell}, the goal in cell {goal_cell}.")
    return lines


def _stl_lines(task: STLTask) -> list[str]:
    formula = task.formula
    lines = [
        f"Specification (signal temporal logic; time in steps, step k is time k*dt = k*{fmt(task.dt)} s):",
        f"  {task.spec.strip()}",
        "Regions:",
    ]
    lines += [f"- {name}: {describe_obstacle(shape)}" for name, shape in sorted(task.regions.items())]
    lines.append(
        "in(R) holds when the position is strictly inside region R; ! is not, & is and, | is or, -> is "
        "implies; G[a,b] f: f holds at every step a..b from now; F[a,b] f: f holds at some step a..b from "
        "now; f U[a,b] g: g holds at some step a..b from now and f at every step before it."
    )
    lines.append("Reading, clause by clause (all must hold, evaluated at step 0):")
    lines += describe_formula(formula)
    lines.append(
        "Robustness: how well the specification holds, in metres (positive: satisfied with that margin; "
        "negative: violated by that much). For in(R) it is, for a rectangle or square R, the least of the "
        "four margins x - xmin, xmax - x, y - ymin, ymax - y; for a circle, radius minus the distance to the "
        "centre; for a polygon, the distance to its boundary (negative outside). ! negates it, & and G take "
        "the minimum, | and F the maximum."
    )
    return lines


def _header(task: AnyTask) -> str:
    if isinstance(task, TrackingTask):
        what = "Tracking task: steer the robot so that its position follows a reference trajectory."
    elif isinstance(task, MazeTask):
        what = (
            "Maze task: plan a collision-free path from the start to the goal through a grid of walled cells."
        )
    elif isinstance(task, ReachAvoidTask):
        if task.model is None:
            what = "Reach-avoid task: plan a collision-free path of waypoints from the start to the goal."
        else:
            what = "Reach-avoid task: steer the robot from its initial state to the goal, avoiding obstacles."
    else:
        what = (
            "STL task: steer the robot so that its positions satisfy a signal temporal logic specification."
        )
    return what


def describe(task: AnyTask) -> str:
    """The natural-language description of a task that a language model sees.

    Parameters
    ----------
    task
        A :class:`TrackingTask`, :class:`ReachAvoidTask`, :class:`MazeTask` or :class:`STLTask`.

    Returns
    -------
    str
        Sections separated by blank lines: what to do; the robot (dynamics, x0, dt, horizon, input
        bounds) or the start; the workspace; the obstacles with exact numbers and the shape
        conventions (squares by half side, boundary contact allowed, inflation by the margin); the
        goal, reference, maze or specification; the solution's form; the success criterion.
        Deterministic, no trailing spaces.

    Raises
    ------
    InvalidArgumentError
        If ``task`` is not a task.
    """
    if not isinstance(task, TrackingTask | ReachAvoidTask | MazeTask | STLTask):
        raise InvalidArgumentError(
            f"task must be a TrackingTask, ReachAvoidTask, MazeTask or STLTask, got {type(task).__name__}"
        )
    sections: list[list[str]] = [[_header(task)]]
    model = task.model
    if model is None:
        sections.append(
            [
                "Robot: a point that moves along straight segments between consecutive waypoints (no "
                "dynamics, no time).",
                f"Start: {_pt(task.x0)}.",
            ]
        )
    else:
        sections.append(_robot_lines(task, model))
    ws = task.workspace
    sections.append(
        [
            f"Workspace: x in [{fmt(ws.xmin)}, {fmt(ws.xmax)}], y in [{fmt(ws.ymin)}, {fmt(ws.ymax)}] "
            "(metres); every position must stay inside it (the boundary is allowed)."
        ]
    )
    if isinstance(task, MazeTask):
        sections.append(_maze_lines(task))
    obstacles = _obstacle_lines(task)
    kinds: set[str] = {o.kind for o in task.obstacles}
    if isinstance(task, MazeTask):
        kinds.add("rectangle")
    if task.all_obstacles():
        obstacles += _conventions(kinds, task.margin)
    elif task.margin > 0:
        obstacles.append(f"Margin: {fmt(task.margin)} (no obstacle to inflate).")
    sections.append(obstacles)
    if isinstance(task, TrackingTask):
        sections.append(_reference_lines(task))
    elif isinstance(task, ReachAvoidTask):
        if task.goal_on == "state" and model is not None:
            goal = f"Goal: the final state {_names(model.state_names)} = {_pt(task.goal)}"
        else:
            goal = f"Goal: the position {_pt(task.goal)}"
        sections.append([f"{goal}, with tolerance {fmt(task.goal_tolerance)}."])
    elif isinstance(task, MazeTask):
        sections.append([f"Goal: the position {_pt(task.goal)}, with tolerance {fmt(task.goal_tolerance)}."])
    else:
        stl = _stl_lines(task)
        stl += _conventions({r.kind for r in task.regions.values()}, 0.0, regions=True)
        sections.append(stl)
    sections.append(_solution_lines(task))
    sections.append(_criteria(task))
    text = "\n\n".join("\n".join(lines) for lines in sections)
    return "\n".join(line.rstrip() for line in text.splitlines())
