"""One picture of a task, and optionally of a solution and its check report.

Drawn with matplotlib's object API (a :class:`matplotlib.figure.Figure` and its canvas, no pyplot
state), so it is safe in tests, scripts and notebooks. matplotlib is imported inside :func:`plot`.

Every artist carries a ``gid`` naming what it shows (listed in the notes of :func:`plot`), so that
callers can find and restyle them and tests can count them.
"""

from __future__ import annotations

import dataclasses
import textwrap
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray
from pydantic import ValidationError

from audere._arrays import as_float_array
from audere.errors import InvalidArgumentError
from audere.tasks._models import MazeTask, ReachAvoidTask, STLTask, TrackingTask
from audere.tasks._report import CheckReport, Violation
from audere.tasks._solution import Solution, SolutionLike
from audere.world._shapes import Circle, Obstacle, Rectangle, Square, Workspace

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure
    from matplotlib.patches import Patch

__all__ = ["plot"]

AnyTask = TrackingTask | ReachAvoidTask | MazeTask | STLTask
F64 = NDArray[np.float64]

# Colours: muted map, saturated robot, red only for what went wrong.
_OBSTACLE_FACE = "#9aa3ab"
_OBSTACLE_EDGE = "#4a535b"
_INFLATED_EDGE = "#4a535b"
_WALL = "#1f2933"
_DOOR = "#3fa34d"
_START = "#2e7d32"
_GOAL = "#f2b705"
_GOAL_EDGE = "#8a6500"
_REFERENCE = "#7b3fa0"
_TRAJECTORY = "#1565c0"
_PREVIEW = "#ef6c00"
_ROBOT = "#37474f"
_VIOLATION = "#d50000"
_REGION_COLOURS = ("#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf", "#bcbd22", "#1f77b4")

# Legend entries by gid, most important first (the order of drawing is bottom to top instead).
_LEGEND_ORDER = {
    gid: i
    for i, gid in enumerate(
        (
            "start",
            "goal",
            "goal-tolerance",
            "reference",
            "trajectory",
            "preview",
            "violation",
            "obstacle",
            "obstacle-inflated",
            "wall",
            "wall-inflated",
            "door",
            "base",
            "reach",
            "robot-start",
            "robot-goal",
            "robot-final",
        )
    )
}

# How far outside the workspace a trajectory may pull the view, as a fraction of the workspace span.
_MAX_OVERSHOOT = 0.5


def plot(
    task: AnyTask,
    solution: SolutionLike | None = None,
    report: CheckReport | None = None,
    *,
    ax: Axes | None = None,
    title: str | None = None,
    show_preview: bool = False,
) -> Figure:
    """Draw a task, and optionally a solution and the checker's report on it.

    The map shows the workspace box, the obstacles (with their outline inflated by ``task.margin``
    dashed when the margin is positive), maze walls (solid, dark) with their doors marked, STL
    regions (translucent, labelled with their names), the start, the goal with its tolerance
    circle (a goal *state* has no circle: its tolerance is not in metres), and a tracking task's
    reference (dashed, one dot per step). The trajectory comes from ``solution`` (inputs rolled out
    through the task's model, states, or waypoints), or from ``report.positions`` when only a
    report is given. For the pendulum and the arm the planar position is the bob or the end
    effector; the rod or links are drawn at the start, at a goal state and at the final state,
    with the circle the robot can reach.
    The first violation of the report is marked with a red cross and its kind and step.

    Parameters
    ----------
    task
        Any task (tracking, reach-avoid, maze or STL).
    solution
        A :class:`audere.tasks.Solution`, a mapping of its fields, or a bare array (interpreted by
        the task's checker, as :meth:`Task.check` does), or ``None`` to draw the task alone.
    report
        The result of ``task.check(solution)``: its first violation is marked and its verdict goes
        into the title. Its ``positions`` are drawn when ``solution`` is ``None``.
    ax
        Axes to draw into (their figure is returned); ``None`` makes a new figure.
    title
        First title line; ``None`` uses ``task.name`` (or the task kind). A second line gives the
        report's verdict when a report is given.
    show_preview
        Also mark ``report.preview``, the downsampled positions a model is shown in feedback.

    Returns
    -------
    matplotlib.figure.Figure
        The figure drawn into (save it with ``fig.savefig(path)``). Coordinates are in metres.

    Raises
    ------
    InvalidArgumentError
        When ``solution`` cannot be turned into positions (wrong field shapes, or a field the task
        has no use for).

    Notes
    -----
    Every artist carries a ``gid`` naming what it shows: ``workspace``; ``obstacle``,
    ``obstacle-inflated``, ``obstacle-hit``; ``wall``, ``wall-inflated``, ``door``; ``region``,
    ``region-edge``, ``region-label``, ``spec``; ``start``, ``goal``, ``goal-tolerance``;
    ``reference``, ``trajectory``, ``preview``; ``base``, ``reach``, ``robot-start``,
    ``robot-goal``, ``robot-final``; ``violation``, ``violation-label``, ``violation-note``.
    """
    if not isinstance(task, TrackingTask | ReachAvoidTask | MazeTask | STLTask):
        raise InvalidArgumentError(
            f"task must be a TrackingTask, ReachAvoidTask, MazeTask or STLTask, got {type(task).__name__}"
        )
    if report is not None and not isinstance(report, CheckReport):
        raise InvalidArgumentError(f"report must be a CheckReport or None, got {type(report).__name__}")
    track = _trajectory(task, solution, report)
    states = track.states if track is not None else None

    from matplotlib.figure import Figure

    if ax is None:
        fig = Figure(figsize=(9.0, 6.4), layout="constrained")
        ax = fig.add_subplot()
    else:
        root = ax.get_figure(root=True)
        if not isinstance(root, Figure):  # pragma: no cover - axes always belong to a figure
            raise InvalidArgumentError("ax must belong to a matplotlib Figure")
        fig = root

    labels = _Labels()
    first = report.first_violation if report is not None else None
    _draw_workspace(ax, task.workspace)
    if isinstance(task, STLTask):
        _draw_regions(ax, task)
    _draw_obstacles(ax, task, labels)
    if isinstance(task, MazeTask):
        _draw_maze(ax, task, labels)
    if first is not None:
        _draw_hit(ax, task, first)
    if isinstance(task, TrackingTask):
        ref = task.reference_positions
        ax.plot(
            ref[:, 0],
            ref[:, 1],
            ls="--",
            lw=1.4,
            marker=".",
            ms=6,
            color=_REFERENCE,
            zorder=4,
            label="reference",
            gid="reference",
        )
    _draw_robot(ax, task, states, labels)
    if track is not None:
        positions = track.positions
        what = f"path ({positions.shape[0]} waypoints)" if track.is_path else "trajectory"
        ax.plot(
            positions[:, 0],
            positions[:, 1],
            "-o",
            lw=1.8,
            ms=3.0,
            color=_TRAJECTORY,
            zorder=6,
            label=what,
            gid="trajectory",
        )
    _draw_start_goal(ax, task)
    if show_preview and report is not None and report.preview is not None and len(report.preview):
        preview = np.asarray(report.preview)
        ax.plot(
            preview[:, 0],
            preview[:, 1],
            ls="none",
            marker="s",
            ms=8,
            mfc="none",
            mec=_PREVIEW,
            mew=1.6,
            zorder=7,
            label="preview (shown to the model)",
            gid="preview",
        )
    if first is not None:
        _draw_violation(ax, first, track, task.dt)
    _draw_notes(ax, task, report)

    ax.set_aspect("equal", adjustable="box")
    _set_limits(ax, task, track)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.grid(True, color="#e3e6e8", lw=0.6, zorder=0)
    ax.set_axisbelow(True)
    ax.set_title(_title(task, report, title), fontsize=11, loc="left")
    handles, names = ax.get_legend_handles_labels()
    order = sorted(range(len(handles)), key=lambda i: _LEGEND_ORDER.get(str(handles[i].get_gid()), 99))
    handles, names = [handles[i] for i in order], [names[i] for i in order]
    if handles:
        ax.legend(
            handles,
            names,
            loc="upper left",
            bbox_to_anchor=(1.02, 1.0),
            borderaxespad=0.0,
            fontsize=9,
            frameon=False,
            handlelength=2.2,
        )
    return fig


# ---------------------------------------------------------------------------------------- data


@dataclasses.dataclass(frozen=True)
class _Track:
    """What to draw of a solution: planar positions (k, 2), and what is known behind them."""

    positions: F64
    states: F64 | None = None  # (k, n_x) when the positions come from states
    times: F64 | None = None  # (k,) seconds, for timed waypoints
    is_path: bool = False  # waypoints rather than one position per time step

    def at_step(self, step: int, dt: float) -> tuple[float, float] | None:
        """The position at time step ``step`` (waypoint ``step`` for an untimed path)."""
        if self.times is not None:
            t = step * dt
            if not self.times[0] <= t <= self.times[-1]:
                return None
            xy = (
                np.interp(t, self.times, self.positions[:, 0]),
                np.interp(t, self.times, self.positions[:, 1]),
            )
        elif 0 <= step < self.positions.shape[0]:
            xy = (self.positions[step, 0], self.positions[step, 1])
        else:
            return None
        return (float(xy[0]), float(xy[1])) if np.all(np.isfinite(xy)) else None


def _trajectory(task: AnyTask, solution: SolutionLike | None, report: CheckReport | None) -> _Track | None:
    """The track to draw: from the solution, else from the report, else nothing."""
    if solution is None:
        if report is not None and report.positions is not None:
            return _Track(_positions(report.positions, name="report.positions"), is_path=task.model is None)
        return None
    if isinstance(solution, Mapping):
        try:
            solution = Solution.model_validate(dict(solution))
        except ValidationError as exc:
            raise InvalidArgumentError(f"solution is not a valid Solution: {_one_line(exc)}") from None
    if isinstance(solution, Solution):
        return _from_solution(task, solution)
    # A bare array means inputs, states or waypoints depending on its shape: the checker decides.
    checked = report if report is not None and report.positions is not None else task.check(solution)
    if checked.positions is None:
        why = checked.first_violation.message if checked.first_violation is not None else "no positions"
        raise InvalidArgumentError(f"solution cannot be drawn: {why}")
    return _Track(_positions(checked.positions, name="solution"), is_path=task.model is None)


def _from_solution(task: AnyTask, solution: Solution) -> _Track:
    model = task.model
    if model is not None and solution.inputs is not None:
        states = model.rollout(
            np.asarray(task.x0, dtype=float), solution.inputs, task.dt, method=task.integrator
        )
        return _Track(_positions(model.position(states), name="solution.inputs (rolled out)"), states)
    if model is not None and solution.states is not None:
        states = as_float_array(solution.states, name="solution.states", shape=(None, model.n_x), min_len=1)
        return _Track(_positions(model.position(states), name="solution.states"), states)
    if solution.waypoints is not None:
        waypoints = _positions(solution.waypoints, name="solution.waypoints")
        times = None
        if solution.times is not None:
            times = as_float_array(solution.times, name="solution.times", shape=(waypoints.shape[0],))
            if np.any(np.diff(times) < 0):
                raise InvalidArgumentError(
                    "solution.times must be non-decreasing, got " + str(times.tolist())
                )
        return _Track(waypoints, times=times, is_path=True)
    given = ", ".join(solution.arrays()) or "none"
    raise InvalidArgumentError(
        f"solution must give {' or '.join(task.solution_kinds)} for this task, got fields: {given}"
    )


def _positions(value: Any, *, name: str) -> F64:
    return as_float_array(value, name=name, shape=(None, 2), min_len=1, finite=False)


def _one_line(exc: ValidationError) -> str:
    return "; ".join(f"{'.'.join(str(p) for p in e['loc']) or 'value'}: {e['msg']}" for e in exc.errors())


# ---------------------------------------------------------------------------------------- drawing


class _Labels:
    """Hands out a legend label the first time a kind of artist is drawn, then hides repeats."""

    def __init__(self) -> None:
        self._seen: set[str] = set()

    def __call__(self, text: str) -> str:
        if text in self._seen:
            return "_nolegend_"
        self._seen.add(text)
        return text


def _patch(shape: Obstacle | Workspace, **style: Any) -> Patch:
    from matplotlib import patches

    if isinstance(shape, Circle):
        return patches.Circle(shape.center, shape.radius, **style)
    if isinstance(shape, Square):
        (cx, cy), h = shape.center, shape.half_side
        return patches.Rectangle((cx - h, cy - h), 2 * h, 2 * h, **style)
    if isinstance(shape, Rectangle | Workspace):
        return patches.Rectangle(
            (shape.xmin, shape.ymin), shape.xmax - shape.xmin, shape.ymax - shape.ymin, **style
        )
    return patches.Polygon(np.asarray(shape.vertices, dtype=float), closed=True, **style)


def _centre(shape: Obstacle) -> tuple[float, float]:
    if isinstance(shape, Circle | Square):
        return (shape.center[0], shape.center[1])
    if isinstance(shape, Rectangle):
        return ((shape.xmin + shape.xmax) / 2, (shape.ymin + shape.ymax) / 2)
    import shapely

    p = shapely.Polygon(shape.vertices).representative_point()
    return (float(p.x), float(p.y))


def _draw_workspace(ax: Axes, ws: Workspace) -> None:
    ax.add_patch(_patch(ws, fill=False, ec="black", lw=1.6, zorder=8, gid="workspace"))


def _draw_obstacles(ax: Axes, task: AnyTask, labels: _Labels) -> None:
    inflated = task.world(inflated=True).obstacles if task.margin > 0 else ()
    for shape in task.obstacles:
        ax.add_patch(
            _patch(
                shape,
                fc=_OBSTACLE_FACE,
                ec=_OBSTACLE_EDGE,
                lw=1.0,
                zorder=3,
                label=labels("obstacle"),
                gid="obstacle",
            )
        )
    for shape in inflated[: len(task.obstacles)]:
        ax.add_patch(
            _patch(
                shape,
                fill=False,
                ec=_INFLATED_EDGE,
                lw=0.9,
                ls=(0, (4, 3)),
                zorder=3.5,
                label=labels(f"inflated by margin {task.margin:g} m"),
                gid="obstacle-inflated",
            )
        )


def _draw_maze(ax: Axes, task: MazeTask, labels: _Labels) -> None:
    for wall in task.walls:
        ax.add_patch(_patch(wall, fc=_WALL, ec=_WALL, lw=0.5, zorder=3, label=labels("wall"), gid="wall"))
    if task.margin > 0 and task.walls:
        # The inflated walls overlap at the junctions: draw the outline of their union once.
        import shapely
        from matplotlib import patches

        m = task.margin
        union = shapely.union_all(
            [shapely.box(w.xmin - m, w.ymin - m, w.xmax + m, w.ymax + m) for w in task.walls]
        )
        parts = getattr(union, "geoms", [union])
        for part in parts:
            for ring in (part.exterior, *part.interiors):
                ax.add_patch(
                    patches.Polygon(
                        np.asarray(ring.coords),
                        closed=True,
                        fill=False,
                        ec=_WALL,
                        lw=0.7,
                        ls=(0, (3, 2)),
                        zorder=3.5,
                        label=labels(f"inflated by margin {m:g} m"),
                        gid="wall-inflated",
                    )
                )
    for door, (x, y) in zip(task.doors, task.door_centers(), strict=True):
        (r1, _), (r2, _) = door.cells
        half = door.width / 2
        xs, ys = ([x, x], [y - half, y + half]) if r1 == r2 else ([x - half, x + half], [y, y])
        ax.plot(
            xs,
            ys,
            color=_DOOR,
            lw=3.5,
            alpha=0.55,
            solid_capstyle="butt",
            zorder=2.5,
            label=labels("door"),
            gid="door",
        )


def _draw_regions(ax: Axes, task: STLTask) -> None:
    for i, (name, shape) in enumerate(task.regions.items()):
        colour = _REGION_COLOURS[i % len(_REGION_COLOURS)]
        ax.add_patch(_patch(shape, fc=colour, ec=colour, alpha=0.28, lw=1.4, zorder=1.5, gid="region"))
        ax.add_patch(_patch(shape, fill=False, ec=colour, lw=1.4, zorder=1.6, gid="region-edge"))
        cx, cy = _centre(shape)
        ax.text(
            cx,
            cy,
            name,
            ha="center",
            va="center",
            fontsize=12,
            fontweight="bold",
            color="#202020",
            zorder=9,
            gid="region-label",
            bbox={"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none", "alpha": 0.6},
        )


def _draw_start_goal(ax: Axes, task: AnyTask) -> None:
    from matplotlib import patches

    sx, sy = task.start
    ax.plot(
        [sx],
        [sy],
        ls="none",
        marker="o",
        ms=10,
        mfc=_START,
        mec="white",
        mew=1.5,
        zorder=10,
        label="start",
        gid="start",
    )
    if isinstance(task, ReachAvoidTask | MazeTask):
        gx, gy = task.goal_position if isinstance(task, ReachAvoidTask) else task.goal
        tol = task.goal_tolerance
        if isinstance(task, ReachAvoidTask) and task.goal_on == "state":
            # The tolerance is a distance between states, not metres on the map: no circle.
            _goal_marker(ax, (gx, gy), f"goal state (tolerance {tol:g})")
            return
        ax.add_patch(
            patches.Circle(
                (gx, gy),
                tol,
                fill=False,
                ec=_GOAL_EDGE,
                lw=1.2,
                ls=(0, (3, 2)),
                zorder=9,
                label=f"goal tolerance ({tol:g} m)",
                gid="goal-tolerance",
            )
        )
        _goal_marker(ax, (gx, gy), "goal")


def _goal_marker(ax: Axes, point: tuple[float, float], label: str) -> None:
    ax.plot(
        [point[0]],
        [point[1]],
        ls="none",
        marker="*",
        ms=17,
        mfc=_GOAL,
        mec=_GOAL_EDGE,
        mew=1.0,
        zorder=10,
        label=label,
        gid="goal",
    )


def _draw_robot(ax: Axes, task: AnyTask, states: F64 | None, labels: _Labels) -> None:
    """Pendulum rod or arm links at the start, the final state and a goal state (planar models only)."""
    from matplotlib import patches

    model = task.model
    if model is None or model.name not in ("pendulum", "two_link_arm"):
        return
    params = model.params
    ax.plot([0.0], [0.0], ls="none", marker="s", ms=8, color=_ROBOT, zorder=9, label="base", gid="base")
    reach = params["length"] if model.name == "pendulum" else params["l1"] + params["l2"]
    ax.add_patch(
        patches.Circle(
            (0.0, 0.0), reach, fill=False, ec=_ROBOT, lw=0.8, ls=":", zorder=2, label="reach", gid="reach"
        )
    )
    # (gid, state, style, legend text)
    poses: list[tuple[str, F64, dict[str, Any], str]] = [
        ("robot-start", np.asarray(task.x0, dtype=float), {"color": _ROBOT, "alpha": 0.3}, "at the start")
    ]
    if isinstance(task, ReachAvoidTask) and task.goal_on == "state":
        goal = np.asarray(task.goal, dtype=float)
        poses.append(
            ("robot-goal", goal, {"color": _GOAL_EDGE, "alpha": 0.8, "ls": "--", "lw": 2.0}, "at the goal")
        )
    if states is not None and states.shape[0] > 0 and np.all(np.isfinite(states[-1])):
        poses.append(("robot-final", states[-1], {"color": _ROBOT, "alpha": 0.9}, "at the final state"))
    what = "pendulum" if model.name == "pendulum" else "arm"
    for gid, x, style, when in poses:
        if model.name == "pendulum":
            joints = np.vstack([[0.0, 0.0], model.position(x)])
        else:
            q1 = float(x[0])
            elbow = [params["l1"] * np.cos(q1), params["l1"] * np.sin(q1)]
            joints = np.vstack([[0.0, 0.0], elbow, model.position(x)])
        ax.plot(
            joints[:, 0],
            joints[:, 1],
            **{"marker": "o", "lw": 4.0, "ms": 6, "solid_capstyle": "round", "zorder": 5, **style},
            label=labels(f"{what} {when}"),
            gid=gid,
        )


def _draw_hit(ax: Axes, task: AnyTask, violation: Violation) -> None:
    shapes = task.all_obstacles()
    if (
        violation.kind == "collision"
        and violation.obstacle is not None
        and 0 <= violation.obstacle < len(shapes)
    ):
        shape = shapes[violation.obstacle]
        ax.add_patch(_patch(shape, fill=False, ec=_VIOLATION, lw=2.2, zorder=4, gid="obstacle-hit"))


def _violation_text(violation: Violation) -> str:
    text = violation.kind.replace("_", " ")
    return text if violation.step is None else f"{text} at step {violation.step}"


def _draw_violation(ax: Axes, violation: Violation, track: _Track | None, dt: float) -> None:
    """A red cross where the first violation happens, labelled with its kind and step."""
    point = violation.point
    if point is None and track is not None and violation.step is not None:
        point = track.at_step(violation.step, dt)
    if point is None:
        return  # no location: the note beside the map says what went wrong
    ax.plot(
        [point[0]],
        [point[1]],
        ls="none",
        marker="x",
        ms=13,
        mew=3.0,
        color=_VIOLATION,
        zorder=9.5,  # under the start and goal markers, which stay visible in its middle
        label="first violation",
        gid="violation",
    )
    ax.annotate(
        _violation_text(violation),
        xy=point,
        xytext=(9, 9),
        textcoords="offset points",
        fontsize=9,
        color=_VIOLATION,
        zorder=12,
        bbox={"boxstyle": "round,pad=0.25", "fc": "white", "ec": _VIOLATION, "lw": 0.8, "alpha": 0.9},
        gid="violation-label",
    )


def _draw_notes(ax: Axes, task: AnyTask, report: CheckReport | None) -> None:
    """Text beside the map (never over it): the STL spec and the first violation's message."""
    notes: list[tuple[str, str, str]] = []
    if isinstance(task, STLTask):
        notes.append(("spec", "spec:\n" + _wrap(task.spec, lines=8), "#202020"))
    first = report.first_violation if report is not None else None
    if first is not None:
        more = "" if report is None or report.n_violations <= 1 else f" ({report.n_violations} in all)"
        head = _wrap(f"first violation: {_violation_text(first)}{more}", lines=2)
        notes.append(("violation-note", head + "\n" + _wrap(first.message, lines=6), _VIOLATION))
    y = 0.0  # stacked upwards from the lower right corner of the axes, in points
    for gid, text, colour in reversed(notes):
        ax.annotate(
            text,
            xy=(1.0, 0.0),
            xycoords="axes fraction",
            xytext=(10.0, y),
            textcoords="offset points",
            ha="left",
            va="bottom",
            fontsize=8.5,
            color=colour,
            gid=gid,
            annotation_clip=False,
        )
        y += (text.count("\n") + 1) * 8.5 * 1.25 + 8


def _wrap(text: str, *, lines: int, width: int = 34) -> str:
    wrapped = textwrap.wrap(" ".join(text.split()), width=width, break_long_words=True)
    if len(wrapped) > lines:
        wrapped = [*wrapped[: lines - 1], wrapped[lines - 1][: width - 3] + "..."]
    return "\n".join(wrapped)


def _set_limits(ax: Axes, task: AnyTask, track: _Track | None) -> None:
    """Show the workspace, plus whatever is drawn outside it (up to half a span more per side)."""
    ws = task.workspace
    lo = np.array([ws.xmin, ws.ymin])
    hi = np.array([ws.xmax, ws.ymax])
    span = hi - lo
    extra: list[F64] = []
    if track is not None:
        extra.append(track.positions)
    if isinstance(task, TrackingTask):
        extra.append(task.reference_positions)
    model = task.model
    if model is not None and model.name in ("pendulum", "two_link_arm"):
        extra.append(np.zeros((1, 2)))
    pts = np.vstack(extra) if extra else np.empty((0, 2))
    pts = pts[np.all(np.isfinite(pts), axis=1)]
    if len(pts):
        lo = np.maximum(np.minimum(lo, pts.min(axis=0)), lo - _MAX_OVERSHOOT * span)
        hi = np.minimum(np.maximum(hi, pts.max(axis=0)), hi + _MAX_OVERSHOOT * span)
    pad = 0.03 * (hi - lo)
    ax.set_xlim(float(lo[0] - pad[0]), float(hi[0] + pad[0]))
    ax.set_ylim(float(lo[1] - pad[1]), float(hi[1] + pad[1]))


def _title(task: AnyTask, report: CheckReport | None, title: str | None) -> str:
    head = title if title is not None else (task.name or f"{task.kind.replace('_', '-')} task")
    if report is None:
        return head
    if report.success:
        return f"{head}\nsuccess"
    n = report.n_violations
    first = report.first_violation
    verdict = f"failure: {n} violation{'s' if n != 1 else ''}"
    if first is not None:
        verdict += f", first: {_violation_text(first)}"
    return f"{head}\n{verdict}"
