"""Invalid task inputs: each is rejected with a message naming the field, the expectation and the value."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import pytest
from pydantic import ValidationError

from audere.errors import InvalidArgumentError
from audere.tasks import load_task, parse_task

from .factories import MAZE, RA_PATH, RA_UNICYCLE, STL_SI, TRACK_SI, data, task

CIRCLE = {"kind": "circle", "center": [5.0, 5.0], "radius": 1.0}
DOOR_01 = {"cells": [[0, 0], [0, 1]], "offset": 0.5, "width": 1.0}

# (id, task data, regular expression the error message must match)
INVALID: list[tuple[str, dict[str, Any], str]] = [
    # -- where things are
    (
        "x0 outside workspace",
        data(RA_PATH, x0=[11.0, 1.0]),
        r"x0 \(start\) \(11\.000, 1\.000\) lies outside the workspace \[0\.0, 10\.0\] x \[0\.0, 10\.0\]",
    ),
    (
        "x0 inside obstacle",
        data(RA_PATH, x0=[5.0, 5.2]),
        r"x0 \(start\) \(5\.000, 5\.200\) lies inside obstacle 0 \(circle centred at \(5\.00, 5\.00\), "
        r"radius 1\.00\)",
    ),
    (
        "x0 inside inflated obstacle",
        data(RA_PATH, x0=[6.05, 5.0], margin=0.1),
        r"x0 \(start\) \(6\.050, 5\.000\) lies inside obstacle 0 \(circle .*radius 1\.00 inflated by the "
        r"margin 0\.1\)",
    ),
    (
        "x0 of a dynamics task inside obstacle",
        data(RA_UNICYCLE, x0=[5.0, 6.2, 0.0, 0.0]),
        r"x0 \(start\) \(5\.000, 6\.200\) lies inside obstacle 0 \(square centred at \(5\.00, 6\.00\), half "
        r"side 0\.50",
    ),
    (
        "goal inside obstacle",
        data(RA_PATH, goal=[5.5, 5.0]),
        r"goal \(5\.500, 5\.000\) lies inside obstacle 0",
    ),
    (
        "goal inside inflated obstacle",
        data(RA_PATH, goal=[6.1, 5.0], margin=0.2),
        r"goal \(6\.100, 5\.000\) lies inside obstacle 0 .*inflated by the margin 0\.2",
    ),
    (
        "goal outside workspace",
        data(RA_PATH, goal=[9.0, -1.0]),
        r"goal \(9\.000, -1\.000\) lies outside the workspace",
    ),
    (
        "maze goal outside workspace",
        data(MAZE, goal=[10.5, 9.0]),
        r"goal \(10\.500, 9\.000\) lies outside the workspace",
    ),
    (
        "x0 inside a maze wall",
        data(MAZE, x0=[5.0, 1.0]),
        r"x0 \(start\) \(5\.000, 1\.000\) lies inside obstacle 1 \(rectangle",
    ),
    # -- mazes
    (
        "unreachable maze goal",
        data(MAZE, doors=[DOOR_01]),
        r"goal is unreachable by construction: no sequence of doors connects the start cell \(0, 0\) to the "
        r"goal cell \(1, 1\)",
    ),
    (
        "door between non-neighbours",
        data(MAZE, doors=[{"cells": [[0, 0], [1, 1]], "offset": 0.5, "width": 1.0}]),
        r"doors\[0\]\.cells must be neighbouring cells, got \(\(0, 0\), \(1, 1\)\)",
    ),
    (
        "door outside grid",
        data(MAZE, doors=[{"cells": [[0, 1], [0, 2]], "offset": 0.5, "width": 1.0}]),
        r"doors\[0\]\.cells: cell \(0, 2\) is outside the 2x2 grid",
    ),
    (
        "door as wide as the edge",
        data(MAZE, doors=[{"cells": [[0, 0], [0, 1]], "offset": 0.5, "width": 5.0}]),
        r"doors\[0\]\.width must be smaller than the cell edge 5\.000, got 5\.0",
    ),
    (
        "door past the end of its edge",
        data(MAZE, doors=[{"cells": [[0, 0], [0, 1]], "offset": 0.05, "width": 1.0}]),
        r"doors\[0\]\.offset 0\.05 puts the 1\.0 m opening past the end of the edge",
    ),
    (
        "duplicate door",
        data(MAZE, doors=[DOOR_01, {"cells": [[0, 1], [0, 0]], "offset": 0.2, "width": 0.5}]),
        r"doors\[1\]: a second door between cells \(0, 0\) and \(0, 1\)",
    ),
    (
        "door offset above 1",
        data(MAZE, doors=[{"cells": [[0, 0], [0, 1]], "offset": 1.5, "width": 1.0}]),
        r"doors\.0\.offset\n  Input should be less than or equal to 1",
    ),
    (
        "maze with dynamics",
        data(MAZE, dynamics="single_integrator"),
        r"a maze task is a path task and needs dynamics=null, got 'single_integrator'",
    ),
    # -- dimensions
    (
        "x0 with 3 values for the single integrator",
        data(TRACK_SI, x0=[1.0, 1.0, 0.0]),
        r"x0 must have 2 values \('x', 'y'\), got 3 values \(1\.0, 1\.0, 0\.0\)",
    ),
    (
        "x0 with 2 values for the unicycle",
        data(RA_UNICYCLE, x0=[1.0, 1.0]),
        r"x0 must have 4 values \('x', 'y', 'theta', 'v'\), got 2 values",
    ),
    (
        "path x0 with 3 values",
        data(RA_PATH, x0=[1.0, 1.0, 1.0]),
        r"x0 must have a start position \(x, y\), got 3 values",
    ),
    (
        "u_min dimension",
        data(TRACK_SI, u_min=[-0.5]),
        r"u_min must have 2 values \('vx', 'vy'\), got 1 values \(-0\.5,\)",
    ),
    (
        "u_max dimension",
        data(TRACK_SI, u_max=[0.5, 0.5, 0.5]),
        r"u_max must have 2 values \('vx', 'vy'\), got 3 values",
    ),
    (
        "u_min above u_max",
        data(TRACK_SI, u_min=[-0.5, 1.0]),
        r"u_min must not exceed u_max, got u_min\[1\]=1\.0 > u_max\[1\]=0\.5 \(vy\)",
    ),
    ("input bounds on a path task", data(RA_PATH, u_min=[-1.0, -1.0]), r"u_min/u_max need a dynamics model"),
    (
        "reference rows",
        data(TRACK_SI, reference=[[1.0, 1.0]] * 4),
        r"reference must have shape \(5, 2\) \(horizon \+ 1 rows\), got shape \(4, 2\)",
    ),
    (
        "reference columns",
        data(TRACK_SI, reference=[[1.0, 1.0, 0.0]] * 5),
        r"reference must have shape \(5, 2\) .*got shape \(5, 3\)",
    ),
    (
        "reference with NaN",
        data(TRACK_SI, reference=[[1.0, 1.0], [math.nan, 1.0], [2.0, 1.0], [2.5, 1.0], [3.0, 1.0]]),
        r"reference\n.*must be finite, got nan at index \[1, 0\]",
    ),
    (
        "goal dimension",
        data(RA_PATH, goal=[9.0, 9.0, 0.0]),
        r"goal must be a position \(x, y\), got 3 values",
    ),
    (
        "goal state dimension",
        data(RA_UNICYCLE, goal_on="state"),
        r"goal must have 4 values \('x', 'y', 'theta', 'v'\) when goal_on='state', got 2 values",
    ),
    (
        "goal on state without dynamics",
        data(RA_PATH, goal_on="state"),
        r"goal_on='state' needs a dynamics model",
    ),
    (
        "angle index out of range",
        data(RA_UNICYCLE, goal_on="state", goal=[5.0, 1.0, 0.0, 0.0], angle_indices=[4]),
        r"angle_indices must be state indices in \[0, 4\), got \[4\]",
    ),
    (
        "angle indices without a goal state",
        data(RA_UNICYCLE, angle_indices=[2]),
        r"angle_indices only apply when goal_on='state'",
    ),
    # -- numbers
    ("dt zero", data(TRACK_SI, dt=0.0), r"dt\n  Input should be greater than 0"),
    ("dt negative", data(RA_UNICYCLE, dt=-0.1), r"dt\n  Input should be greater than 0"),
    ("horizon zero", data(RA_PATH, horizon=0), r"horizon\n  Input should be greater than 0"),
    ("tolerance zero", data(TRACK_SI, tolerance=0.0), r"tolerance\n  Input should be greater than 0"),
    (
        "goal tolerance negative",
        data(RA_PATH, goal_tolerance=-0.1),
        r"goal_tolerance\n  Input should be greater than 0",
    ),
    (
        "start tolerance zero",
        data(RA_PATH, start_tolerance=0.0),
        r"start_tolerance\n  Input should be greater than 0",
    ),
    ("negative margin", data(RA_PATH, margin=-0.1), r"margin\n  Input should be greater than or equal to 0"),
    ("x0 NaN", data(RA_PATH, x0=[math.nan, 1.0]), r"x0\.0\n  Input should be a finite number"),
    (
        "wall thickness zero",
        data(MAZE, wall_thickness=0.0),
        r"wall_thickness\n  Input should be greater than 0",
    ),
    # -- names and kinds
    (
        "unknown dynamics",
        data(RA_PATH, dynamics="rocket"),
        r"unknown dynamics 'rocket'; expected one of single_integrator, double_integrator, unicycle, "
        r"pendulum, two_link_arm or null",
    ),
    (
        "unknown dynamics parameter",
        data(TRACK_SI, dynamics_params={"mass": 2.0}),
        r"dynamics_params: params for 'single_integrator' accept no parameters, got unknown 'mass'",
    ),
    (
        "unknown kind",
        data(RA_PATH, kind="race"),
        r"Input tag 'race' found using 'kind' does not match any of the expected tags",
    ),
    ("missing kind", data(RA_PATH, kind=None), r"Unable to extract tag using discriminator 'kind'"),
    ("extra field", data(RA_PATH, speed=3.0), r"speed\n  Extra inputs are not permitted"),
    (
        "unknown integrator",
        data(TRACK_SI, integrator="midpoint"),
        r"integrator\n  Input should be 'euler' or 'rk4'",
    ),
    (
        "tracking without dynamics",
        data(TRACK_SI, dynamics=None, u_min=None, u_max=None),
        r"dynamics: a tracking task needs a dynamics model, got null",
    ),
    ("missing reference", data(TRACK_SI, reference=None), r"reference\n  Field required"),
    # -- STL
    (
        "STL without dynamics",
        data(STL_SI, dynamics=None, u_min=None, u_max=None),
        r"dynamics: an STL task needs a dynamics model \(e\.g\. 'single_integrator'\), got null",
    ),
    ("malformed STL text", data(STL_SI, spec="F[0,10 in(A)"), r"spec is not valid STL: .*"),
    (
        "STL region undefined",
        data(STL_SI, spec="F[0,10] in(A) & G[0,10] !in(B)"),
        r"spec uses region\(s\) B not defined in regions \(defined: A\)",
    ),
    (
        "STL horizon too long",
        data(STL_SI, spec="F[0,20] in(A)"),
        r"spec needs 20 steps but the task horizon is 10; shorten the time bounds or raise the horizon",
    ),
    (
        "bad region name",
        data(STL_SI, regions={"1A": {"kind": "circle", "center": [5.0, 5.0], "radius": 1.0}}),
        r"region names must be identifiers, got '1A'",
    ),
    # -- shapes
    (
        "rectangle xmin >= xmax",
        data(RA_PATH, obstacles=[{"kind": "rectangle", "xmin": 3.0, "xmax": 3.0, "ymin": 0.0, "ymax": 1.0}]),
        r"rectangle needs xmin < xmax, got xmin=3\.0, xmax=3\.0",
    ),
    (
        "rectangle ymin >= ymax",
        data(RA_PATH, obstacles=[{"kind": "rectangle", "xmin": 3.0, "xmax": 4.0, "ymin": 2.0, "ymax": 1.0}]),
        r"rectangle needs ymin < ymax, got ymin=2\.0, ymax=1\.0",
    ),
    (
        "circle radius zero",
        data(RA_PATH, obstacles=[{"kind": "circle", "center": [5.0, 5.0], "radius": 0.0}]),
        r"obstacles\.0\.circle\.radius\n  Input should be greater than 0",
    ),
    (
        "square half side negative",
        data(RA_PATH, obstacles=[{"kind": "square", "center": [5.0, 5.0], "half_side": -1.0}]),
        r"obstacles\.0\.square\.half_side\n  Input should be greater than 0",
    ),
    (
        "polygon with 2 vertices",
        data(RA_PATH, obstacles=[{"kind": "polygon", "vertices": [[0.0, 0.0], [1.0, 1.0]]}]),
        r"obstacles\.0\.polygon\.vertices\n  Tuple should have at least 3 items after validation, not 2",
    ),
    (
        "unknown obstacle kind",
        data(RA_PATH, obstacles=[{"kind": "ellipse", "center": [5.0, 5.0]}]),
        r"Input tag 'ellipse' found using 'kind' does not match any of the expected tags",
    ),
    (
        "workspace xmin >= xmax",
        data(RA_PATH, workspace={"xmin": 10.0, "xmax": 0.0}),
        r"workspace needs xmin < xmax, got xmin=10\.0, xmax=0\.0",
    ),
]


def test_the_table_is_large_enough() -> None:
    assert len(INVALID) >= 30
    assert len({name for name, _, _ in INVALID}) == len(INVALID)


@pytest.mark.parametrize(
    ("data_", "pattern"), [(d, p) for _, d, p in INVALID], ids=[n for n, _, _ in INVALID]
)
def test_invalid_task_is_rejected_with_message(data_: dict[str, Any], pattern: str) -> None:
    with pytest.raises(ValidationError, match=pattern) as info:
        task(data_)
    assert isinstance(info.value, ValueError)  # `except ValueError` keeps working


@pytest.mark.parametrize(
    ("text", "fmt", "pattern"),
    [
        ("- 1\n- 2\n", "yaml", r"a task must be a mapping of fields, got list"),
        ("kind: [unclosed\n", "yaml", r"task text is not valid YAML"),
        ('{"kind": "maze",', "json", r"task text is not valid JSON"),
        ("{}", "toml", r"format must be 'json' or 'yaml', got 'toml'"),
    ],
)
def test_unreadable_task_text(text: str, fmt: Any, pattern: str) -> None:
    with pytest.raises(InvalidArgumentError, match=pattern):
        parse_task(text, format=fmt)


def test_task_files_with_bad_names_or_missing(tmp_path: Path) -> None:
    with pytest.raises(
        InvalidArgumentError, match=r"path must end in \.json, \.yaml or \.yml, got '.*task\.txt'"
    ):
        load_task(tmp_path / "task.txt")
    with pytest.raises(InvalidArgumentError, match=r"cannot read task file '.*missing\.yaml'"):
        load_task(tmp_path / "missing.yaml")
