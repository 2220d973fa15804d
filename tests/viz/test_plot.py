"""Plots of every task kind: what is drawn is what the task, solution and report say.

Assertions look the artists up by their ``gid`` and compare their data with values computed here
independently (hand-written Euler rollouts, the link geometry written out, the task's own fields).
"""

from __future__ import annotations

import importlib.util
import json
import os
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from audere.errors import InvalidArgumentError
from audere.tasks import (
    CheckReport,
    Door,
    MazeTask,
    ReachAvoidTask,
    Solution,
    STLTask,
    TrackingTask,
    Violation,
)
from audere.viz import plot
from audere.world import Circle, Polygon, Rectangle, Square

# ------------------------------------------------------------------------------------- helpers


def _ax(fig: Figure) -> Axes:
    return fig.axes[0]


def _patches(fig: Figure, gid: str) -> list[Patch]:
    return [p for p in _ax(fig).patches if p.get_gid() == gid]


def _lines(fig: Figure, gid: str) -> list[Line2D]:
    return [ln for ln in _ax(fig).lines if ln.get_gid() == gid]


def _texts(fig: Figure, gid: str) -> list[str]:
    return [t.get_text() for t in _ax(fig).texts if t.get_gid() == gid]


def _xy(line: Line2D) -> np.ndarray:
    return np.column_stack([np.asarray(line.get_xdata(), float), np.asarray(line.get_ydata(), float)])


def _save(fig: Figure, path: Path) -> None:
    fig.savefig(path, dpi=60)
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    assert len(data) > 5_000  # an empty 60-dpi canvas of this size compresses to far less


def _legend_outside_map(fig: Figure) -> None:
    fig.draw_without_rendering()  # lays the figure out (constrained layout) without an image
    ax = _ax(fig)
    legend = ax.get_legend()
    assert legend is not None
    box, frame = legend.get_window_extent(), ax.get_window_extent()
    assert box.x0 >= frame.x1, "the legend overlaps the map"


def _violation(kind: str = "collision", **fields: Any) -> CheckReport:
    violation = Violation(kind=kind, message=f"a {kind} happened here, exactly", **fields)  # type: ignore[arg-type]
    return CheckReport(success=False, violations=(violation,), n_violations=3)


# ---------------------------------------------------------------------------------------- tasks


def _reach_avoid(margin: float = 0.2) -> ReachAvoidTask:
    return ReachAvoidTask(
        name="hand/reach-avoid",
        x0=(1.0, 1.0),
        goal=(9.0, 9.0),
        goal_tolerance=0.3,
        margin=margin,
        obstacles=(
            Circle(center=(3.0, 3.0), radius=1.0),
            Square(center=(7.0, 3.0), half_side=0.8),
            Rectangle(xmin=4.0, xmax=6.0, ymin=6.0, ymax=7.0),
            Polygon(vertices=((6.0, 8.0), (8.0, 7.5), (7.0, 9.5))),
        ),
    )


def _tracking() -> TrackingTask:
    t = np.linspace(0.0, 1.0, 21)
    reference = np.column_stack([1 + 8 * t, 1 + 3 * np.sin(3 * t)])
    return TrackingTask(
        name="hand/track-car",
        dynamics="unicycle",
        x0=(1.0, 1.0, 0.0, 0.0),
        reference=reference,
        tolerance=2.0,
        horizon=20,
        u_min=(-0.3, -0.5),
        u_max=(0.3, 0.5),
    )


def _maze() -> MazeTask:
    doors = (
        Door(cells=((0, 0), (0, 1)), offset=0.5, width=0.8),
        Door(cells=((0, 1), (1, 1)), offset=0.3, width=0.8),
        Door(cells=((1, 0), (1, 1)), offset=0.6, width=0.8),
    )
    return MazeTask(
        name="hand/maze",
        x0=(1.0, 1.0),
        goal=(8.0, 8.0),
        rows=2,
        cols=2,
        doors=doors,
        margin=0.15,
        obstacles=(Circle(center=(2.5, 3.0), radius=0.3), Square(center=(7.0, 2.0), half_side=0.3)),
    )


def _stl() -> STLTask:
    regions = {
        "A": Rectangle.from_center(1.0, 9.0, 1.0, 1.0),
        "B": Rectangle.from_center(2.0, 4.5, 4.0, 6.0),
        "C": Rectangle.from_center(7.5, 6.0, 1.0, 8.0),
        "D": Rectangle.from_center(9.0, 5.5, 2.0, 0.5),
        "E": Circle(center=(9.0, 8.2), radius=0.4),
    }
    return STLTask(
        name="hand/stl",
        dynamics="single_integrator",
        x0=(1.0, 1.0),
        regions=regions,
        horizon=20,
        spec="F[10,17] in(E) & G[0,20] (!in(B) & !in(C)) & (!in(D) U[0,20] in(A))",
        u_min=(-4.0, -4.0),
        u_max=(4.0, 4.0),
    )


def _pendulum() -> ReachAvoidTask:
    return ReachAvoidTask(
        name="hand/pendulum",
        dynamics="pendulum",
        x0=(0.0, 0.0),
        goal=(np.pi, 0.0),
        goal_on="state",
        goal_tolerance=0.1,
        workspace={"xmin": -1.5, "xmax": 1.5, "ymin": -1.5, "ymax": 1.5},
        horizon=30,
        dt=0.05,
    )


def _arm() -> ReachAvoidTask:
    return ReachAvoidTask(
        name="hand/arm",
        dynamics="two_link_arm",
        dynamics_params={"l1": 1.2, "l2": 0.8},
        x0=(0.3, 0.5, 0.0, 0.0),
        goal=(-1.0, 1.2),
        goal_tolerance=0.1,
        workspace={"xmin": -2.2, "xmax": 2.2, "ymin": -2.2, "ymax": 2.2},
        horizon=30,
        dt=0.05,
        obstacles=(Circle(center=(0.5, 1.7), radius=0.2),),
    )


# ---------------------------------------------------------------------------------------- the map


@pytest.mark.parametrize("margin", [0.0, 0.2])
def test_obstacles_of_every_shape_and_their_inflated_outline(margin: float, tmp_path: Path) -> None:
    task = _reach_avoid(margin)
    fig = plot(task)
    assert isinstance(fig, Figure)
    obstacles = _patches(fig, "obstacle")
    assert len(obstacles) == len(task.obstacles) == 4
    # Each patch covers its shape: the centre of every obstacle lies inside its patch.
    centres = [(3.0, 3.0), (7.0, 3.0), (5.0, 6.5), (7.0, 8.3)]
    for patch, centre in zip(obstacles, centres, strict=True):
        assert patch.contains_point(_ax(fig).transData.transform(centre))
    inflated = _patches(fig, "obstacle-inflated")
    assert len(inflated) == (4 if margin > 0 else 0)
    for patch in inflated:
        assert patch.get_linestyle() not in ("-", "solid")
        assert not patch.get_fill()
    if margin > 0:  # the inflated circle is the circle grown by the margin
        radius = inflated[0].get_radius()  # type: ignore[attr-defined]
        assert radius == pytest.approx(1.0 + margin)
    _save(fig, tmp_path / f"reach_avoid_{margin}.png")


def test_start_goal_tolerance_labels_and_aspect(tmp_path: Path) -> None:
    task = _reach_avoid()
    fig = plot(task)
    ax = _ax(fig)
    (start,) = _lines(fig, "start")
    (goal,) = _lines(fig, "goal")
    np.testing.assert_allclose(_xy(start), [[1.0, 1.0]])
    np.testing.assert_allclose(_xy(goal), [[9.0, 9.0]])
    (tolerance,) = _patches(fig, "goal-tolerance")
    assert tolerance.get_radius() == pytest.approx(0.3)  # type: ignore[attr-defined]
    assert ax.get_aspect() == 1.0
    assert "[m]" in ax.get_xlabel()
    assert "[m]" in ax.get_ylabel()
    assert ax.get_title(loc="left") == "hand/reach-avoid"
    x0, x1 = ax.get_xlim()
    y0, y1 = ax.get_ylim()
    assert x0 < 0 < 10 < x1
    assert y0 < 0 < 10 < y1
    legend = ax.get_legend()
    assert legend is not None
    names = [t.get_text() for t in legend.get_texts()]
    assert names[:2] == ["start", "goal"]
    assert names.count("obstacle") == 1  # one entry for all obstacles
    _legend_outside_map(fig)
    _save(fig, tmp_path / "start_goal.png")


def test_maze_walls_doors_and_inflated_walls(tmp_path: Path) -> None:
    task = _maze()
    fig = plot(task)
    walls = _patches(fig, "wall")
    assert len(walls) == len(task.walls) > 0
    assert len(_patches(fig, "obstacle")) == len(task.obstacles) == 2
    assert _patches(fig, "wall-inflated")
    doors = _lines(fig, "door")
    assert len(doors) == len(task.doors)
    for line, door, (cx, cy) in zip(doors, task.doors, task.door_centers(), strict=True):
        xy = _xy(line)
        np.testing.assert_allclose(xy.mean(axis=0), [cx, cy])
        assert np.linalg.norm(xy[1] - xy[0]) == pytest.approx(door.width)
        # A door is a gap: its centre lies in no wall piece.
        for wall in task.walls:
            assert not (wall.xmin < cx < wall.xmax and wall.ymin < cy < wall.ymax)
    _legend_outside_map(fig)
    _save(fig, tmp_path / "maze.png")


def test_stl_regions_filled_and_labelled(tmp_path: Path) -> None:
    task = _stl()
    fig = plot(task)
    regions = _patches(fig, "region")
    assert len(regions) == len(task.regions)
    assert all(0 < p.get_alpha() < 1 for p in regions)  # type: ignore[operator]
    assert len({p.get_facecolor()[:3] for p in regions}) == len(regions)  # one colour each
    assert sorted(_texts(fig, "region-label")) == sorted(task.regions)
    ax = _ax(fig)
    for text in ax.texts:
        if text.get_gid() == "region-label":
            shape = task.regions[text.get_text()]
            x, y = text.get_position()
            if isinstance(shape, Rectangle):
                assert shape.xmin < x < shape.xmax
                assert shape.ymin < y < shape.ymax
    (spec,) = _texts(fig, "spec")
    assert " ".join(spec.split()).replace("spec: ", "") == task.spec
    _save(fig, tmp_path / "stl.png")


def test_tracking_reference_dashed_with_points() -> None:
    task = _tracking()
    fig = plot(task)
    (ref,) = _lines(fig, "reference")
    np.testing.assert_allclose(_xy(ref), task.reference_positions)
    assert ref.get_linestyle() == "--"
    assert ref.get_marker() not in (None, "None", "")


# ---------------------------------------------------------------------------------------- trajectories


def _unicycle_euler(x0: tuple[float, ...], inputs: np.ndarray, dt: float) -> np.ndarray:
    x, y, th, v = x0
    out = [(x, y)]
    for omega, a in inputs:
        x, y, th, v = x + dt * v * np.cos(th), y + dt * v * np.sin(th), th + dt * omega, v + dt * a
        out.append((x, y))
    return np.array(out)


def test_inputs_are_rolled_out_through_the_model(tmp_path: Path) -> None:
    task = _tracking()
    inputs = np.tile([0.05, 0.2], (20, 1))
    inputs[8:] = [-0.1, -0.1]
    fig = plot(task, Solution(inputs=inputs))
    (line,) = _lines(fig, "trajectory")
    np.testing.assert_allclose(_xy(line), _unicycle_euler(task.x0, inputs, task.dt), atol=1e-12)
    _save(fig, tmp_path / "tracking.png")


def test_states_and_mappings_are_accepted() -> None:
    task = _stl()
    states = np.column_stack([np.linspace(1, 9, 21), np.linspace(1, 2, 21)])
    for solution in (Solution(states=states), {"states": states.tolist()}):
        (line,) = _lines(plot(task, solution), "trajectory")
        np.testing.assert_allclose(_xy(line), states)


def test_waypoints_drawn_as_a_path() -> None:
    task = _reach_avoid()
    path = np.array([[1.0, 1.0], [1.0, 9.0], [9.0, 9.0]])
    fig = plot(task, Solution(waypoints=path))
    (line,) = _lines(fig, "trajectory")
    np.testing.assert_allclose(_xy(line), path)
    assert line.get_label() == "path (3 waypoints)"


def test_report_positions_drawn_when_only_a_report_is_given() -> None:
    task = _reach_avoid()
    positions = np.array([[1.0, 1.0], [5.0, 5.0], [9.0, 9.0]])
    report = CheckReport(success=True, positions=positions)
    fig = plot(task, report=report)
    (line,) = _lines(fig, "trajectory")
    np.testing.assert_allclose(_xy(line), positions)
    assert _ax(fig).get_title(loc="left").endswith("\nsuccess")
    assert not _lines(fig, "violation")


@pytest.mark.skipif(
    importlib.util.find_spec("audere.tasks._check") is None, reason="the checker is not written yet"
)
def test_bare_array_is_interpreted_by_the_checker() -> None:
    task = _reach_avoid()
    path = np.array([[1.0, 1.0], [1.0, 9.0], [9.0, 9.0]])
    (line,) = _lines(plot(task, path), "trajectory")
    np.testing.assert_allclose(_xy(line), path)


def test_pendulum_bob_and_rod(tmp_path: Path) -> None:
    task = _pendulum()
    inputs = np.full((30, 1), 2.5)
    fig = plot(task, Solution(inputs=inputs))
    # Independent Euler rollout of theta'' = torque / (m l^2) - g / l sin(theta) with m = l = 1.
    theta, omega, bobs = 0.0, 0.0, [(0.0, -1.0)]
    for (tau,) in inputs:
        theta, omega = theta + task.dt * omega, omega + task.dt * (tau - 9.81 * np.sin(theta))
        bobs.append((np.sin(theta), -np.cos(theta)))
    (line,) = _lines(fig, "trajectory")
    np.testing.assert_allclose(_xy(line), bobs, atol=1e-12)
    (final,) = _lines(fig, "robot-final")
    np.testing.assert_allclose(_xy(final), [[0.0, 0.0], bobs[-1]], atol=1e-12)
    (first,) = _lines(fig, "robot-start")
    np.testing.assert_allclose(_xy(first), [[0.0, 0.0], [0.0, -1.0]], atol=1e-12)
    np.testing.assert_allclose(_xy(_lines(fig, "goal")[0]), [[0.0, 1.0]], atol=1e-12)  # upright
    (goal,) = _lines(fig, "robot-goal")
    np.testing.assert_allclose(_xy(goal), [[0.0, 0.0], [0.0, 1.0]], atol=1e-12)
    assert not _patches(fig, "goal-tolerance")  # a state tolerance is not a circle in metres
    (reach,) = _patches(fig, "reach")
    assert reach.get_radius() == pytest.approx(1.0)  # type: ignore[attr-defined]
    _save(fig, tmp_path / "pendulum.png")


def test_arm_end_effector_and_links_at_the_final_state(tmp_path: Path) -> None:
    task = _arm()
    inputs = np.tile([1.5, 0.5], (30, 1))
    fig = plot(task, Solution(inputs=inputs))
    (line,) = _lines(fig, "trajectory")
    model = task.model
    assert model is not None
    states = model.rollout(task.x0, inputs, task.dt)
    q1, q2 = states[-1, :2]
    elbow = (1.2 * np.cos(q1), 1.2 * np.sin(q1))
    hand = (elbow[0] + 0.8 * np.cos(q1 + q2), elbow[1] + 0.8 * np.sin(q1 + q2))
    (final,) = _lines(fig, "robot-final")
    np.testing.assert_allclose(_xy(final), [(0.0, 0.0), elbow, hand], atol=1e-12)
    np.testing.assert_allclose(_xy(line)[-1], hand, atol=1e-12)
    assert len(_patches(fig, "obstacle")) == 1
    assert not _lines(fig, "robot-goal")  # the goal is a position here
    (reach,) = _patches(fig, "reach")
    assert reach.get_radius() == pytest.approx(2.0)  # type: ignore[attr-defined]
    _save(fig, tmp_path / "arm.png")


# ---------------------------------------------------------------------------------------- violations


def test_first_violation_marked_at_its_point_with_kind_and_step(tmp_path: Path) -> None:
    task = _reach_avoid()
    path = np.array([[1.0, 1.0], [4.0, 4.0], [9.0, 9.0]])
    report = _violation("collision", step=0, point=(2.3, 2.3), obstacle=0)
    fig = plot(task, Solution(waypoints=path), report)
    (marker,) = _lines(fig, "violation")
    np.testing.assert_allclose(_xy(marker), [[2.3, 2.3]])
    assert marker.get_color() in ("#d50000", (0.8352941176470589, 0.0, 0.0, 1.0))
    assert marker.get_marker() == "x"
    (label,) = _texts(fig, "violation-label")
    assert "collision" in label
    assert "step 0" in label
    (hit,) = _patches(fig, "obstacle-hit")
    assert hit.get_radius() == pytest.approx(1.0)  # type: ignore[attr-defined]  # the circle, not inflated
    (note,) = _texts(fig, "violation-note")
    assert "a collision happened here" in " ".join(note.split())
    assert "3 in all" in note
    title = _ax(fig).get_title(loc="left")
    assert "failure: 3 violations" in title
    assert "collision at step 0" in title
    _legend_outside_map(fig)
    _save(fig, tmp_path / "violation.png")


def test_violation_without_point_is_located_by_its_step() -> None:
    task = _tracking()
    inputs = np.zeros((20, 2))
    inputs[:, 1] = 0.3
    fig = plot(task, Solution(inputs=inputs), _violation("workspace", step=12))
    (marker,) = _lines(fig, "violation")
    np.testing.assert_allclose(_xy(marker)[0], _unicycle_euler(task.x0, inputs, 1.0)[12], atol=1e-12)


def test_violation_on_timed_waypoints_is_located_at_its_time() -> None:
    task = _stl()
    waypoints = np.array([[1.0, 1.0], [0.5, 9.0], [5.0, 9.5], [9.0, 0.5]])
    times = np.array([0.0, 4.0, 8.0, 14.0])
    fig = plot(task, Solution(waypoints=waypoints, times=times), _violation("stl", step=11))
    (marker,) = _lines(fig, "violation")
    np.testing.assert_allclose(_xy(marker), [[7.0, 5.0]])  # halfway from t=8 to t=14


def test_violation_without_location_is_only_described() -> None:
    task = _tracking()
    fig = plot(task, Solution(inputs=np.zeros((20, 2))), _violation("tracking"))
    assert not _lines(fig, "violation")
    (note,) = _texts(fig, "violation-note")
    assert " ".join(note.split()).startswith("first violation: tracking (3 in all) a tracking happened")


def test_preview_points_on_request() -> None:
    task = _reach_avoid()
    preview = np.array([[1.0, 1.0], [5.0, 5.0]])
    report = CheckReport(success=True, preview=preview, positions=preview)
    assert not _lines(plot(task, report=report), "preview")
    (line,) = _lines(plot(task, report=report, show_preview=True), "preview")
    np.testing.assert_allclose(_xy(line), preview)


# ---------------------------------------------------------------------------------------- options and errors


def test_draws_into_given_axes_with_a_title() -> None:
    fig = Figure()
    left, right = fig.subplots(1, 2)
    out = plot(_maze(), ax=right, title="my maze")
    assert out is fig
    assert right.get_title(loc="left") == "my maze"
    assert not left.patches
    assert any(p.get_gid() == "wall" for p in right.patches)


@pytest.mark.parametrize(
    ("solution", "match"),
    [
        (Solution(inputs=np.zeros((20, 3))), r"inputs must have shape \(horizon, 2\)"),
        (
            Solution(waypoints=np.zeros((4, 3))),
            r"solution.waypoints must have shape \(k, 2\), got shape \(4, 3\)",
        ),
        ({"inputs": "abc"}, r"solution is not a valid Solution: inputs"),
    ],
)
def test_bad_solution_named_in_the_error(solution: Any, match: str) -> None:
    with pytest.raises(InvalidArgumentError, match=match):
        plot(_tracking(), solution)


def test_path_task_needs_waypoints() -> None:
    with pytest.raises(
        InvalidArgumentError, match=r"solution must give waypoints for this task, got fields: states"
    ):
        plot(_reach_avoid(), Solution(states=np.zeros((3, 2))))


def test_bad_task_and_report_types() -> None:
    with pytest.raises(InvalidArgumentError, match=r"task must be a TrackingTask.*got dict"):
        plot({"kind": "maze"})  # type: ignore[arg-type]
    with pytest.raises(InvalidArgumentError, match=r"report must be a CheckReport or None, got str"):
        plot(_maze(), report="failed")  # type: ignore[arg-type]


def test_no_pyplot_state(tmp_path: Path) -> None:
    code = (
        "import sys, json\n"
        "import audere.viz\n"
        "before = 'matplotlib' in sys.modules\n"
        "from audere.tasks import ReachAvoidTask\n"
        "fig = audere.viz.plot(ReachAvoidTask(x0=(1, 1), goal=(9, 9)))\n"
        f"fig.savefig({str(tmp_path / 'x.png')!r})\n"
        "print(json.dumps([before, 'matplotlib.pyplot' in sys.modules]))\n"
    )
    env = {k: v for k, v in os.environ.items() if k != "MPLBACKEND"}
    done = subprocess.run(
        [sys.executable, "-W", "error", "-c", code],
        capture_output=True,
        text=True,
        env=env,
        timeout=120,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout) == [False, False]
    assert (tmp_path / "x.png").stat().st_size > 0


# ---------------------------------------------------------------------------------------- scenarios


def _scenario_names() -> list[str]:
    if importlib.util.find_spec("audere.scenarios") is None:
        return []
    from audere.scenarios import list_scenarios

    return [info.name for info in list_scenarios()]


def _naive_solution(task: Any) -> Any:
    """A solution that is easy to write down and (almost always) wrong: a straight line or zero inputs."""
    model = task.model
    if model is None:
        return Solution(waypoints=np.array([task.start, task.goal]))
    return Solution(inputs=np.zeros((task.horizon, model.n_u)))


@pytest.mark.skipif(not _scenario_names(), reason="audere.scenarios is not written yet")
@pytest.mark.parametrize("name", _scenario_names() or ["none"])
def test_every_scenario_plots_alone_and_with_a_checked_solution(name: str, tmp_path: Path) -> None:
    from audere.scenarios import make

    task = make(name, seed=1)
    fig = plot(task)
    assert len(_patches(fig, "obstacle")) == len(task.obstacles)
    if isinstance(task, MazeTask):
        assert len(_patches(fig, "wall")) == len(task.walls)
        assert len(_lines(fig, "door")) == len(task.doors)
    if isinstance(task, STLTask):
        assert sorted(_texts(fig, "region-label")) == sorted(task.regions)
    if isinstance(task, TrackingTask):
        assert len(_lines(fig, "reference")) == 1
    (start,) = _lines(fig, "start")
    np.testing.assert_allclose(_xy(start), [task.start])
    assert not _lines(fig, "trajectory")

    solution = _naive_solution(task)
    report = task.check(solution)
    fig = plot(task, solution, report, show_preview=True)
    (line,) = _lines(fig, "trajectory")
    assert report.positions is not None
    np.testing.assert_allclose(_xy(line)[-1], report.positions[-1], atol=1e-9)  # the checker saw the same end
    title = _ax(fig).get_title(loc="left")
    assert title.startswith(task.name)
    if not report.success:
        assert "failure" in title
        first = report.first_violation
        assert first is not None
        located = _lines(fig, "violation")
        if first.point is not None:
            (marker,) = located
            np.testing.assert_allclose(_xy(marker), [first.point])
        assert _texts(fig, "violation-note")
    _legend_outside_map(fig)
    _save(fig, tmp_path / f"{name}-checked.png")
