"""Task models: what a problem *is*, as frozen, validated data.

Four kinds share one discriminated union, :data:`Task`, keyed by ``kind``:

- :class:`TrackingTask` (``"tracking"``): follow a reference with a dynamics model;
- :class:`ReachAvoidTask` (``"reach_avoid"``): reach a goal while avoiding obstacles, with a
  dynamics model or as a geometric path (``dynamics=None``);
- :class:`MazeTask` (``"maze"``): a grid of cells separated by walls with doors, obstacles in the
  cells, reach the goal cell's goal point;
- :class:`STLTask` (``"stl"``): satisfy a signal temporal logic formula over named regions.

Every task is validated when it is built: a message names the field, what was expected and what
was received.
"""

from __future__ import annotations

from collections.abc import Mapping
from functools import cached_property
from typing import TYPE_CHECKING, Annotated, Any, Literal, Self

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, TypeAdapter, field_validator, model_validator

from audere._arrays import FloatArray
from audere.world._shapes import Circle, Obstacle, Polygon, Rectangle, Square, Workspace

if TYPE_CHECKING:
    from audere.dynamics import Dynamics
    from audere.stl import Formula
    from audere.tasks._report import CheckReport
    from audere.tasks._solution import SolutionLike
    from audere.world import World

__all__ = [
    "Door",
    "MazeTask",
    "ReachAvoidTask",
    "Region",
    "STLTask",
    "Task",
    "TaskAdapter",
    "TrackingTask",
]

Region = Annotated[Circle | Square | Rectangle | Polygon, Field(discriminator="kind")]
"""A named region of an STL task: any world shape."""

Cell = tuple[int, int]
"""A maze cell as ``(row, col)``; row 0 is the bottom row (smallest y), col 0 the leftmost."""


class _TaskBase(BaseModel):
    """Fields and behaviour common to every task kind."""

    model_config = ConfigDict(
        frozen=True, extra="forbid", allow_inf_nan=False, ignored_types=(cached_property,)
    )

    name: str = Field("", description="Provenance label, e.g. 'plan-easy/seed=3'; free text.")
    dynamics: str | None = Field(
        None,
        description="Dynamics model name (see audere.dynamics.list_dynamics()), "
        "or null for a geometric path task.",
    )
    dynamics_params: dict[str, float] = Field(
        default_factory=dict, description="Parameters of the dynamics model (defaults when omitted)."
    )
    integrator: Literal["euler", "rk4"] = Field(
        "euler", description="Discretisation of the dynamics: x[k+1] = x[k] + dt * f(x[k], u[k]) for euler."
    )
    x0: tuple[float, ...] = Field(
        description="Initial state (n_x,), or the start position (x, y) for path tasks."
    )
    dt: float = Field(1.0, gt=0, description="Time step in seconds.")
    horizon: int = Field(20, gt=0, le=100_000, description="Number of time steps.")
    u_min: tuple[float, ...] | None = Field(None, description="Lower input bounds (n_u,), or null for none.")
    u_max: tuple[float, ...] | None = Field(None, description="Upper input bounds (n_u,), or null for none.")
    workspace: Workspace = Field(default_factory=Workspace, description="The box the robot must stay in.")
    obstacles: tuple[Obstacle, ...] = Field((), description="Shapes the robot must not enter.")
    margin: float = Field(
        0.0, ge=0, description="Clearance: obstacles are inflated by this much when checking."
    )
    start_tolerance: float = Field(
        0.05, gt=0, description="A path's first waypoint must lie within this distance of the start."
    )

    # -- derived ------------------------------------------------------------------------------

    def __eq__(self, other: object) -> bool:
        # The generated equality compares ndarray fields with ``==``, which is ambiguous: compare the
        # serialized fields instead (cached properties such as ``model`` are left out).
        if type(other) is not type(self):
            return NotImplemented
        return self.model_dump(mode="json") == other.model_dump(mode="json")

    def __hash__(self) -> int:
        return hash(self.model_dump_json())

    @cached_property
    def model(self) -> Dynamics | None:
        """The dynamics model named by ``dynamics`` (``None`` for a geometric path task)."""
        if self.dynamics is None:
            return None
        from audere.dynamics import get_dynamics

        return get_dynamics(self.dynamics, self.dynamics_params)

    @property
    def start(self) -> tuple[float, float]:
        """The planar start position: ``x0`` itself for path tasks, the model's position otherwise."""
        if self.model is None:
            return (self.x0[0], self.x0[1])
        p = self.model.position(np.asarray(self.x0, dtype=float))
        return (float(p[0]), float(p[1]))

    @property
    def times(self) -> np.ndarray:
        """Time stamps of the states, ``dt * arange(horizon + 1)``, in seconds."""
        return self.dt * np.arange(self.horizon + 1)

    def all_obstacles(self) -> tuple[Obstacle, ...]:
        """Every shape to avoid, before inflation (mazes add their walls)."""
        return self.obstacles

    def world(self, *, inflated: bool = True) -> World:
        """The workspace and obstacles as an :class:`audere.world.World`.

        Parameters
        ----------
        inflated
            Inflate obstacles by ``margin`` (what the checker uses).

        Returns
        -------
        audere.world.World
            The world the solution is checked against.
        """
        return self._worlds[1 if inflated else 0]

    @cached_property
    def _worlds(self) -> tuple[World, World]:
        """The world as given and inflated by the margin, built once (the task is immutable)."""
        from audere.world import World

        world = World(workspace=self.workspace, obstacles=self.all_obstacles())
        return world, (world.inflate(self.margin) if self.margin > 0 else world)

    @property
    def solution_kinds(self) -> tuple[str, ...]:
        """What :meth:`check` accepts: ``"waypoints"`` for path tasks; ``"inputs"`` (and ``"states"``
        for the single integrator, whose inputs are recovered exactly) for tasks with dynamics."""
        if self.model is None:
            return ("waypoints",)
        if self.dynamics == "single_integrator":
            return ("inputs", "states")
        return ("inputs",)

    # -- behaviour (implemented in sibling modules) --------------------------------------------

    def describe(self) -> str:
        """The natural-language description a language model sees: exact numbers, conventions.

        Returns
        -------
        str
            A self-contained description of the task.
        """
        from audere.tasks._describe import describe

        return describe(self)  # type: ignore[arg-type]

    def check(self, solution: SolutionLike) -> CheckReport:
        """Judge a solution.

        Parameters
        ----------
        solution
            A :class:`audere.tasks.Solution`, a mapping with its fields, or a bare array interpreted
            by shape (see :attr:`solution_kinds`).

        Returns
        -------
        CheckReport
            Success, metrics and bounded diagnostics. A malformed solution is reported, not raised.
        """
        from audere.tasks._check import check

        return check(self, solution)  # type: ignore[arg-type]

    def model_copy(self, *, update: Mapping[str, Any] | None = None, deep: bool = False) -> Self:
        """A copy with some fields replaced, validated again.

        Unlike pydantic's default, the copy is validated and its derived values (``model``, the
        worlds, a maze's walls) are rebuilt instead of copied from the original.

        Parameters
        ----------
        update
            Field values to replace, by field name.
        deep
            Ignored: a task is immutable, so a shallow and a deep copy are the same.

        Returns
        -------
        Task
            A new, validated task of the same kind.
        """
        data = self.model_dump()
        data.update(update or {})
        return self.model_validate(data)

    def to_json(self, *, indent: int | None = 2) -> str:
        """Serialize to JSON (round-trips through :func:`audere.tasks.load_task`).

        Parameters
        ----------
        indent
            Indentation of the JSON text, or ``None`` for one line.

        Returns
        -------
        str
            The JSON text.
        """
        return self.model_dump_json(indent=indent)

    def to_yaml(self) -> str:
        """Serialize to YAML (round-trips through :func:`audere.tasks.load_task`).

        Returns
        -------
        str
            The YAML text.
        """
        import yaml

        return yaml.safe_dump(self.model_dump(mode="json"), sort_keys=False)

    # -- validation ----------------------------------------------------------------------------

    @field_validator("dynamics")
    @classmethod
    def _known_dynamics(cls, value: str | None) -> str | None:
        if value is None:
            return value
        from audere.dynamics import list_dynamics

        known = list_dynamics()
        if value not in known:
            raise ValueError(f"unknown dynamics {value!r}; expected one of {', '.join(known)} or null")
        return value

    @model_validator(mode="after")
    def _consistent(self) -> _TaskBase:
        model = self._build_model()
        n_x = 2 if model is None else model.n_x
        if len(self.x0) != n_x:
            what = "a start position (x, y)" if model is None else f"{n_x} values {tuple(model.state_names)}"
            raise ValueError(f"x0 must have {what}, got {len(self.x0)} values {self.x0}")
        if model is None and (self.u_min is not None or self.u_max is not None):
            raise ValueError("u_min/u_max need a dynamics model; this path task has dynamics=null")
        if model is not None:
            for field in ("u_min", "u_max"):
                bound = getattr(self, field)
                if bound is not None and len(bound) != model.n_u:
                    raise ValueError(
                        f"{field} must have {model.n_u} values {tuple(model.input_names)}, "
                        f"got {len(bound)} values {bound}"
                    )
            if self.u_min is not None and self.u_max is not None:
                for i, (lo, hi) in enumerate(zip(self.u_min, self.u_max, strict=True)):
                    if lo > hi:
                        raise ValueError(
                            f"u_min must not exceed u_max, got u_min[{i}]={lo} > u_max[{i}]={hi} "
                            f"({model.input_names[i]})"
                        )
        sx, sy = self._start_of(model)
        _require_in_workspace(self.workspace, (sx, sy), "x0 (start)")
        self._require_free((sx, sy), "x0 (start)")
        return self

    def _build_model(self) -> Dynamics | None:
        if self.dynamics is None:
            return None
        from audere.dynamics import get_dynamics

        try:
            return get_dynamics(self.dynamics, self.dynamics_params)
        except ValueError as exc:
            raise ValueError(f"dynamics_params: {exc}") from None

    def _start_of(self, model: Dynamics | None) -> tuple[float, float]:
        if model is None:
            return (self.x0[0], self.x0[1])
        p = model.position(np.asarray(self.x0, dtype=float))
        return (float(p[0]), float(p[1]))

    def _require_free(self, point: tuple[float, float], what: str) -> None:
        """Raise if ``point`` lies inside an (inflated) obstacle."""
        world = self.world(inflated=True)
        depth = float(world.signed_distance(np.asarray([point], dtype=float))[0])
        if depth < 0:
            from audere.world import describe_shape

            idx = int(np.argmin([_sd(o, point) for o in world.obstacles]))
            margin_note = f" inflated by the margin {self.margin}" if self.margin > 0 else ""
            raise ValueError(
                f"{what} ({point[0]:.3f}, {point[1]:.3f}) lies inside obstacle {idx} "
                f"({describe_shape(self.all_obstacles()[idx])}{margin_note})"
            )


def _sd(shape: Obstacle, point: tuple[float, float]) -> float:
    from audere.world import signed_distance

    return float(signed_distance(shape, np.asarray([point], dtype=float))[0])


def _require_in_workspace(ws: Workspace, point: tuple[float, float], what: str) -> None:
    x, y = point
    if not (ws.xmin <= x <= ws.xmax and ws.ymin <= y <= ws.ymax):
        raise ValueError(
            f"{what} ({x:.3f}, {y:.3f}) lies outside the workspace "
            f"[{ws.xmin}, {ws.xmax}] x [{ws.ymin}, {ws.ymax}]"
        )


class TrackingTask(_TaskBase):
    """Follow a reference trajectory with a dynamics model.

    Success: the mean Euclidean distance between the planar positions of the rolled-out states and
    of the reference, over all ``horizon + 1`` steps, is below ``tolerance`` (and, if given, no
    obstacle is entered and the inputs respect their bounds).
    """

    kind: Literal["tracking"] = "tracking"
    reference: FloatArray = Field(
        description="Reference, (horizon+1, 2) positions or (horizon+1, n_x) states, one row per step."
    )
    tolerance: float = Field(gt=0, description="Bound on the mean position error, in metres.")

    @model_validator(mode="after")
    def _reference_shape(self) -> TrackingTask:
        if self.dynamics is None:
            raise ValueError("dynamics: a tracking task needs a dynamics model, got null")
        model = self.model
        if model is None:  # pragma: no cover - guarded above
            raise ValueError("dynamics: a tracking task needs a dynamics model")
        ref = self.reference
        widths = sorted({2, model.n_x})
        if ref.ndim != 2 or ref.shape[0] != self.horizon + 1 or ref.shape[1] not in widths:
            expected = " or ".join(f"({self.horizon + 1}, {w})" for w in widths)
            raise ValueError(
                f"reference must have shape {expected} (horizon + 1 rows), got shape {tuple(ref.shape)}"
            )
        return self

    @property
    def reference_positions(self) -> np.ndarray:
        """The reference as planar positions, shape (horizon+1, 2)."""
        ref = self.reference
        model = self.model
        if ref.shape[1] == 2 and (model is None or model.n_x != 2 or self.dynamics == "single_integrator"):
            return np.asarray(ref)
        if model is None:  # pragma: no cover
            return np.asarray(ref[:, :2])
        return np.asarray(model.position(ref))


class ReachAvoidTask(_TaskBase):
    """Reach a goal while avoiding obstacles and staying in the workspace.

    With ``dynamics=None`` the solution is a path of waypoints that starts at ``x0`` and ends within
    ``goal_tolerance`` of ``goal``; no waypoint and no segment between waypoints may enter an
    obstacle (checked exactly on segments). With a dynamics model the solution is an input sequence
    rolled out from ``x0``; the final state must be within ``goal_tolerance`` of the goal.
    """

    kind: Literal["reach_avoid"] = "reach_avoid"
    goal: tuple[float, ...] = Field(
        description="Goal position (x, y), or a full goal state when goal_on='state'."
    )
    goal_tolerance: float = Field(0.1, gt=0, description="Allowed distance to the goal at the end.")
    goal_on: Literal["position", "state"] = Field(
        "position", description="Whether the goal is a planar position or a full state."
    )
    angle_indices: tuple[int, ...] = Field(
        (), description="State indices that are angles: their goal error is wrapped to [-pi, pi)."
    )

    @model_validator(mode="after")
    def _goal_valid(self) -> ReachAvoidTask:
        model = self.model
        if self.goal_on == "state":
            if model is None:
                raise ValueError("goal_on='state' needs a dynamics model; this path task has dynamics=null")
            if len(self.goal) != model.n_x:
                raise ValueError(
                    f"goal must have {model.n_x} values {tuple(model.state_names)} when goal_on='state', "
                    f"got {len(self.goal)} values {self.goal}"
                )
            bad = [i for i in self.angle_indices if not 0 <= i < model.n_x]
            if bad:
                raise ValueError(f"angle_indices must be state indices in [0, {model.n_x}), got {bad}")
            goal_point = model.position(np.asarray(self.goal, dtype=float))
            gp = (float(goal_point[0]), float(goal_point[1]))
        else:
            if len(self.goal) != 2:
                raise ValueError(f"goal must be a position (x, y), got {len(self.goal)} values {self.goal}")
            if self.angle_indices:
                raise ValueError("angle_indices only apply when goal_on='state'")
            gp = (self.goal[0], self.goal[1])
        _require_in_workspace(self.workspace, gp, "goal")
        self._require_free(gp, "goal")
        return self

    @property
    def goal_position(self) -> tuple[float, float]:
        """The planar goal position."""
        if self.goal_on == "state" and self.model is not None:
            p = self.model.position(np.asarray(self.goal, dtype=float))
            return (float(p[0]), float(p[1]))
        return (self.goal[0], self.goal[1])


class Door(BaseModel):
    """An opening in the wall between two neighbouring maze cells."""

    model_config = ConfigDict(frozen=True, extra="forbid", allow_inf_nan=False)

    cells: tuple[Cell, Cell] = Field(description="The two neighbouring cells, each (row, col).")
    offset: float = Field(
        ge=0,
        le=1,
        description="Position of the door's centre along the shared edge, 0..1 (from left or bottom).",
    )
    width: float = Field(gt=0, description="Width of the opening in metres.")


class MazeTask(_TaskBase):
    """Plan a path through a grid of cells separated by walls with doors.

    The workspace is split into ``rows x cols`` equal cells. Every border between two neighbouring
    cells is a wall of thickness ``wall_thickness`` except where a :class:`Door` opens it. Walls and
    obstacles are inflated by ``margin`` for checking. The solution is a path of waypoints starting
    within ``start_tolerance`` of ``x0`` and ending within ``goal_tolerance`` of ``goal``.
    """

    kind: Literal["maze"] = "maze"
    rows: int = Field(3, ge=1, le=50, description="Number of cell rows (along y).")
    cols: int = Field(3, ge=1, le=50, description="Number of cell columns (along x).")
    doors: tuple[Door, ...] = Field((), description="Openings between neighbouring cells.")
    wall_thickness: float = Field(0.1, gt=0, description="Thickness of the walls between cells, in metres.")
    goal: tuple[float, float] = Field(description="Goal position (x, y).")
    goal_tolerance: float = Field(
        0.05, gt=0, description="The path must end within this distance of the goal."
    )

    @property
    def cell_size(self) -> tuple[float, float]:
        """Width and height of one cell."""
        ws = self.workspace
        return ((ws.xmax - ws.xmin) / self.cols, (ws.ymax - ws.ymin) / self.rows)

    def cell_of(self, point: tuple[float, float]) -> Cell:
        """The ``(row, col)`` of the cell containing ``point`` (clamped to the grid).

        Parameters
        ----------
        point
            A planar position (x, y).

        Returns
        -------
        tuple of int
            ``(row, col)``.
        """
        ws = self.workspace
        w, h = self.cell_size
        col = min(max(int((point[0] - ws.xmin) // w), 0), self.cols - 1)
        row = min(max(int((point[1] - ws.ymin) // h), 0), self.rows - 1)
        return (row, col)

    def door_graph(self) -> dict[Cell, tuple[Cell, ...]]:
        """Adjacency of cells through doors.

        Returns
        -------
        dict
            Each cell mapped to the cells reachable through one door, sorted.
        """
        adj: dict[Cell, set[Cell]] = {(r, c): set() for r in range(self.rows) for c in range(self.cols)}
        for door in self.doors:
            a, b = door.cells
            adj[a].add(b)
            adj[b].add(a)
        return {cell: tuple(sorted(n)) for cell, n in adj.items()}

    def door_path(self, start: Cell, goal: Cell) -> list[Cell] | None:
        """A shortest sequence of cells from ``start`` to ``goal`` through doors (breadth first).

        Parameters
        ----------
        start, goal
            Cells as ``(row, col)``.

        Returns
        -------
        list of tuple or None
            The cells visited, ends included, or ``None`` when the goal cell cannot be reached.
        """
        graph = self.door_graph()
        prev: dict[Cell, Cell | None] = {start: None}
        frontier = [start]
        while frontier:
            nxt: list[Cell] = []
            for cell in frontier:
                for n in graph[cell]:
                    if n not in prev:
                        prev[n] = cell
                        nxt.append(n)
            frontier = nxt
        if goal not in prev:
            return None
        path = [goal]
        while (p := prev[path[-1]]) is not None:
            path.append(p)
        return path[::-1]

    def door_centers(self) -> tuple[tuple[float, float], ...]:
        """Centre point of each door, in the order of ``doors``."""
        return tuple(self._door_geometry(d)[0] for d in self.doors)

    def _door_geometry(self, door: Door) -> tuple[tuple[float, float], Literal["v", "h"]]:
        (r1, c1), (r2, c2) = door.cells
        ws = self.workspace
        w, h = self.cell_size
        if r1 == r2:  # horizontal neighbours share a vertical edge
            x = ws.xmin + max(c1, c2) * w
            y = ws.ymin + r1 * h + door.offset * h
            return (x, y), "v"
        x = ws.xmin + c1 * w + door.offset * w
        y = ws.ymin + max(r1, r2) * h
        return (x, y), "h"

    @cached_property
    def walls(self) -> tuple[Rectangle, ...]:
        """The wall pieces between cells (doors cut out), as rectangles."""
        ws = self.workspace
        w, h = self.cell_size
        half = self.wall_thickness / 2
        openings: dict[tuple[Cell, Cell], list[Door]] = {}
        for d in self.doors:
            openings.setdefault(tuple(sorted(d.cells)), []).append(d)  # type: ignore[arg-type]
        pieces: list[Rectangle] = []
        for r in range(self.rows):
            for c in range(self.cols):
                for dr, dc in ((0, 1), (1, 0)):
                    r2, c2 = r + dr, c + dc
                    if r2 >= self.rows or c2 >= self.cols:
                        continue
                    if dc:  # vertical edge at x between (r, c) and (r, c+1)
                        x = ws.xmin + c2 * w
                        lo, hi = ws.ymin + r * h, ws.ymin + (r + 1) * h
                    else:  # horizontal edge at y between (r, c) and (r+1, c)
                        y = ws.ymin + r2 * h
                        lo, hi = ws.xmin + c * w, ws.xmin + (c + 1) * w
                    gaps = sorted(
                        (lo + d.offset * (hi - lo) - d.width / 2, lo + d.offset * (hi - lo) + d.width / 2)
                        for d in openings.get(((r, c), (r2, c2)), [])
                    )
                    start = lo
                    spans: list[tuple[float, float]] = []
                    for g0, g1 in gaps:
                        if g0 > start:
                            spans.append((start, g0))
                        start = max(start, g1)
                    if start < hi:
                        spans.append((start, hi))
                    for s0, s1 in spans:
                        if s1 - s0 <= 1e-9:
                            continue
                        if dc:
                            pieces.append(Rectangle(xmin=x - half, xmax=x + half, ymin=s0, ymax=s1))
                        else:
                            pieces.append(Rectangle(xmin=s0, xmax=s1, ymin=y - half, ymax=y + half))
        return tuple(pieces)

    def all_obstacles(self) -> tuple[Obstacle, ...]:
        """The cell obstacles followed by the wall pieces."""
        return (*self.obstacles, *self.walls)

    @model_validator(mode="after")
    def _maze_valid(self) -> MazeTask:
        if self.dynamics is not None:
            raise ValueError(
                f"dynamics: a maze task is a path task and needs dynamics=null, got {self.dynamics!r}"
            )
        seen: set[tuple[Cell, Cell]] = set()
        for i, door in enumerate(self.doors):
            (r1, c1), (r2, c2) = door.cells
            for r, c in door.cells:
                if not (0 <= r < self.rows and 0 <= c < self.cols):
                    raise ValueError(
                        f"doors[{i}].cells: cell ({r}, {c}) is outside the {self.rows}x{self.cols} grid"
                    )
            if abs(r1 - r2) + abs(c1 - c2) != 1:
                raise ValueError(f"doors[{i}].cells must be neighbouring cells, got {door.cells}")
            key: tuple[Cell, Cell] = tuple(sorted(door.cells))  # type: ignore[assignment]
            if key in seen:
                raise ValueError(f"doors[{i}]: a second door between cells {key[0]} and {key[1]}")
            seen.add(key)
            edge = self.cell_size[1] if r1 == r2 else self.cell_size[0]
            if door.width >= edge:
                raise ValueError(
                    f"doors[{i}].width must be smaller than the cell edge {edge:.3f}, got {door.width}"
                )
            lo = door.offset * edge - door.width / 2
            hi = door.offset * edge + door.width / 2
            if lo < 0 or hi > edge:
                raise ValueError(
                    f"doors[{i}].offset {door.offset} puts the {door.width} m opening past the end "
                    "of the edge"
                )
        _require_in_workspace(self.workspace, self.goal, "goal")
        self._require_free(self.goal, "goal")
        start_cell, goal_cell = self.cell_of(self.start), self.cell_of(self.goal)
        if self.door_path(start_cell, goal_cell) is None:
            raise ValueError(
                f"goal is unreachable by construction: no sequence of doors connects the start cell "
                f"{start_cell} to the goal cell {goal_cell}"
            )
        return self


class STLTask(_TaskBase):
    """Satisfy a signal temporal logic specification over named regions.

    The robot's planar position at steps ``0..horizon`` must satisfy ``spec`` (see
    :mod:`audere.stl` for the syntax), stay in the workspace, avoid ``obstacles``, and respect the
    input bounds (for the single integrator these bound the per-axis speed).
    """

    kind: Literal["stl"] = "stl"
    regions: dict[str, Region] = Field(description="Named regions used by the spec's in(NAME) predicates.")
    spec: str = Field(description="The STL formula in audere's text syntax.")

    @field_validator("regions")
    @classmethod
    def _region_names(cls, value: dict[str, Any]) -> dict[str, Any]:
        for key in value:
            if not key.isidentifier():
                raise ValueError(f"region names must be identifiers, got {key!r}")
        return value

    @model_validator(mode="after")
    def _spec_valid(self) -> STLTask:
        if self.dynamics is None:
            raise ValueError(
                "dynamics: an STL task needs a dynamics model (e.g. 'single_integrator'), got null"
            )
        from audere.stl import parse

        try:
            formula = parse(self.spec)
        except ValueError as exc:
            raise ValueError(f"spec is not valid STL: {exc}") from None
        missing = sorted(formula.regions() - set(self.regions))
        if missing:
            raise ValueError(
                f"spec uses region(s) {', '.join(missing)} not defined in regions "
                f"(defined: {', '.join(sorted(self.regions)) or 'none'})"
            )
        if formula.horizon() > self.horizon:
            raise ValueError(
                f"spec needs {formula.horizon()} steps but the task horizon is {self.horizon}; "
                "shorten the time bounds or raise the horizon"
            )
        return self

    @property
    def solution_kinds(self) -> tuple[str, ...]:
        """What :meth:`check` accepts: as for every task with dynamics, plus ``"timed_waypoints"``
        (``(k, 3)`` rows ``(x, y, t)``, resampled at ``t = k * dt``) for the single integrator, whose
        inputs the resampled positions determine exactly."""
        kinds = super().solution_kinds
        return (*kinds, "timed_waypoints") if self.dynamics == "single_integrator" else kinds

    @property
    def formula(self) -> Formula:
        """The parsed specification."""
        from audere.stl import parse

        return parse(self.spec)


Task = Annotated[TrackingTask | ReachAvoidTask | MazeTask | STLTask, Field(discriminator="kind")]
"""Any task; the ``kind`` field says which (``tracking``, ``reach_avoid``, ``maze``, ``stl``)."""

TaskAdapter: TypeAdapter[TrackingTask | ReachAvoidTask | MazeTask | STLTask] = TypeAdapter(Task)
"""Validates and serializes any :data:`Task` (``TaskAdapter.validate_python(data)``)."""
