"""Descriptions: every number the checker uses, the conventions, deterministic and tidy text."""

from __future__ import annotations

import pytest

from audere.errors import InvalidArgumentError
from audere.stl import parse
from audere.tasks._describe import describe, describe_formula, fmt

from .factories import KEY_DOOR, MAZE, RA_PATH, RA_UNICYCLE, STL_SI, TRACK_SI, task

MIXED_OBSTACLES = [
    {"kind": "circle", "center": [5.0, 5.0], "radius": 1.0},
    {"kind": "square", "center": [2.0, 7.25], "half_side": 0.5},
    {"kind": "rectangle", "xmin": 6.5, "xmax": 8.0, "ymin": 1.0, "ymax": 2.75},
    {"kind": "polygon", "vertices": [[1.5, 3.0], [3.0, 3.0], [2.25, 4.5]]},
]


def _tidy(text: str) -> None:
    assert all(line == line.rstrip() for line in text.splitlines()), "trailing spaces"
    assert "\t" not in text
    assert not text.endswith("\n")
    assert "{" not in text.replace("{'", "")  # no unformatted placeholders


@pytest.mark.parametrize("base", [RA_PATH, RA_UNICYCLE, TRACK_SI, MAZE, STL_SI, KEY_DOOR])
def test_descriptions_are_deterministic_and_tidy(base: dict[str, object]) -> None:
    t = task(base)
    text = t.describe()
    assert text == describe(task(base))
    _tidy(text)
    assert "Success when all of these hold:" in text


def test_every_obstacle_is_stated_with_its_numbers_and_the_square_convention() -> None:
    t = task(RA_PATH, obstacles=MIXED_OBSTACLES, margin=0.15)
    text = t.describe()
    assert "- 0: circle centred at (5.00, 5.00), radius 1.00" in text
    assert (
        "- 1: square centred at (2.00, 7.25), half side 0.50 (side length 1.00; covers x in [1.50, 2.50], "
        "y in [6.75, 7.75])"
    ) in text
    assert "- 2: rectangle x in [6.50, 8.00], y in [1.00, 2.75]" in text
    assert "- 3: polygon with vertices (1.50, 3.00), (3.00, 3.00), (2.25, 4.50)" in text
    assert "its HALF side h (the distance from the centre to each edge)" in text
    assert "so its side length is 2 h" in text
    assert "touching the boundary is allowed" in text
    assert "every obstacle is inflated by the margin 0.15" in text
    assert "a square's half side grows by 0.15" in text
    assert "Start: (1.00, 1.00)." in text
    assert "Goal: the position (9.00, 9.00), with tolerance 0.10." in text
    assert "the first waypoint is within 0.05 of the start" in text
    assert "Solution: waypoints, an array of shape (k, 2)" in text


def test_numbers_that_need_more_than_two_decimals_keep_them() -> None:
    t = task(RA_PATH, obstacles=[{"kind": "circle", "center": [5.125, 5.0], "radius": 1.0 / 3.0}])
    assert "circle centred at (5.125, 5.00), radius 0.3333" in t.describe()
    assert [fmt(v) for v in (1.5, 0.125, 10 / 3, -0.0, -1e-12, 2.0)] == [
        "1.50",
        "0.125",
        "3.3333",
        "0.00",
        "0.00",
        "2.00",
    ]


def test_dynamics_task_states_model_time_and_bounds() -> None:
    text = task(RA_UNICYCLE).describe()
    assert "Dynamics 'unicycle'" in text
    assert "dx/dt = v*cos(theta)" in text
    assert "Discrete time with step dt = 1 s: explicit Euler" in text
    assert "Initial state x0: (x, y, theta, v) = (1.00, 1.00, 0.00, 0.00)" in text
    assert "horizon 10 steps" in text
    assert "-0.30 <= omega <= 0.30, -0.50 <= a <= 0.50" in text
    assert "Solution: inputs, an array of shape (10, 2), row k = (omega, a)" in text
    assert "the position at step 10 is within 0.50 of the goal" in text
    assert "states, an array" not in text  # the unicycle's inputs cannot be recovered from states


def test_tracking_lists_every_reference_row() -> None:
    ref = [[1.0, 1.0], [1.5, 1.0], [2.0, 1.125], [2.5, 1.0], [3.0, 1.0]]
    text = task(TRACK_SI, reference=ref).describe()
    assert "Reference: 5 positions (x, y), one per step 0..4:" in text
    assert "[(1.00, 1.00), (1.50, 1.00), (2.00, 1.125), (2.50, 1.00), (3.00, 1.00)]" in text
    assert "is below 0.50" in text
    assert "Or: states, an array of shape (5, 2)" in text


def test_maze_describes_cells_walls_and_doors_not_wall_pieces() -> None:
    t = task(MAZE)
    text = t.describe()
    assert "2 rows x 2 columns of cells, each 5.00 wide (x) and 5.00 high (y)" in text
    assert "row 0 has the smallest y" in text
    assert "a wall of thickness 0.20, centred on the border line" in text
    assert (
        "- door 0 connects cells (0, 0) and (0, 1): an opening of width 1.00 in the wall on x = 5.00, "
        "from y = " in text
    )
    assert "from y = 2.00 to y = 3.00" in text
    assert (
        "- door 1 connects cells (0, 1) and (1, 1): an opening of width 1.00 in the wall on y = 5.00, "
        in text
    )
    assert "a door of width W leaves a passage of width W - 0.20" in text
    assert "The start is in cell (0, 0), the goal in cell (1, 1)." in text
    assert "- 0: circle centred at (2.00, 2.00), radius 0.30" in text
    assert "rectangle x in" not in text  # wall pieces are not listed one by one
    assert len(t.walls) > 0


def test_stl_states_spec_regions_and_a_reading_of_each_clause() -> None:
    text = task(KEY_DOOR).describe()
    assert "  (!in(D)) U[0,10] in(A) & G[0,10] !in(B) & F[6,8] in(E)" in text
    assert "- A: rectangle x in [0.50, 1.50], y in [8.50, 9.50]" in text
    assert "- E: square centred at (9.00, 9.00), half side 0.50" in text
    assert (
        "1. !in(D) U[0,10] in(A): at some step k from 0 to 10, the position is inside A, and at every step j "
        "from 0 to k-1 before it, the position is not inside D."
    ) in text
    assert "2. G[0,10] !in(B): at every step k from 0 to 10, the position is not inside B." in text
    assert "3. F[6,8] in(E): at some step k from 6 to 8, the position is inside E." in text
    assert "in(R) holds only when the position is strictly inside region R" in text
    assert "Or: timed waypoints, an array of shape (k, 3) with rows (x, y, t)" in text
    assert "the robustness of the specification at step 0 is > 0" in text


@pytest.mark.parametrize(
    ("spec", "reading"),
    [
        ("in(A)", "1. in(A): at step 0, the position is inside A."),
        (
            "G[0,5] F[1,3] in(A)",
            "1. G[0,5] F[1,3] in(A): at every step k from 0 to 5, at some step j from k+1 to k+3, "
            "the position is inside A.",
        ),
        (
            "x + 2*y <= 3 -> G[2,4] !in(A)",
            "1. x + 2*y <= 3 -> G[2,4] !in(A): at step 0, if the position satisfies "
            "x + 2.00*y <= 3.00, then at every step k from 2 to 4, the position is not inside A.",
        ),
        (
            "F[0,3] (in(A) | in(B)) & !(in(A) & in(B))",
            "2. !(in(A) & in(B)): at step 0, it is not the case that "
            "(the position is inside A and the position is inside B).",
        ),
    ],
)
def test_plain_english_reading(spec: str, reading: str) -> None:
    assert reading in describe_formula(parse(spec))


def test_describe_rejects_a_non_task() -> None:
    with pytest.raises(InvalidArgumentError, match=r"task must be a TrackingTask, .* got str"):
        describe("a task")  # type: ignore[arg-type]


def test_models_whose_position_is_derived_say_which_point_is_checked() -> None:
    from audere.scenarios import make

    for name in ("arm-reach", "pendulum-swingup"):
        assert "Checked point: 'position' means" in make(name, 0).describe(), name
    assert "Checked point" not in task(RA_UNICYCLE).describe()
