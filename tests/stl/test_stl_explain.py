"""The paper's key/door specification on hand-made trajectories, and per-clause explanations."""

from __future__ import annotations

import numpy as np
import pytest

from audere.errors import InvalidArgumentError
from audere.stl import ClauseReport, explain, parse, robustness, robustness_trace, satisfied
from audere.world import Rectangle

# Plan-STL regions before randomization, as (centre x, centre y, width, height): A key, B and C walls,
# D door, E goal. With nt = 30 steps, t_start = 15 and t_end = nt - 3 = 27.
REGIONS = {
    name: Rectangle.from_center(*box)
    for name, box in {
        "A": (1, 9, 1, 1),  # [0.5, 1.5] x [8.5, 9.5]
        "B": (2, 4.5, 4, 6),  # [0, 4] x [1.5, 7.5]
        "C": (7.5, 6, 1, 8),  # [7, 8] x [2, 10]
        "D": (9, 5.5, 2, 0.5),  # [8, 10] x [5.25, 5.75], across the corridor right of C
        "E": (9, 8.2, 0.8, 0.8),  # [8.6, 9.4] x [7.8, 8.6]
    }.items()
}
SPEC = "F[15,27] in(E) & G[0,30] (!in(B) & !in(C)) & (!in(D) U[0,30] in(A))"
CLAUSES = ["F[15,27] in(E)", "G[0,30] (!in(B) & !in(C))", "!in(D) U[0,30] in(A)"]

START = [(1, 1), (3, 1), (5.5, 1), (5.5, 4), (5.5, 7), (5.5, 8.5), (3, 9)]  # steps 0-6: round B
KEY = [(1, 9)]  # in A
TO_GOAL = [
    (3, 9),
    (5.5, 8.5),
    (5.5, 5),
    (5.5, 1.5),
    (7.5, 1),
    (9, 1),
    (9, 4),
    (9, 5.5),
    (9, 7),
]  # under C, via D
GOAL = (9, 8.2)  # in E


def _path(*parts: list[tuple[float, float]]) -> np.ndarray:
    points = [p for part in parts for p in part]
    points += [GOAL] * (31 - len(points))  # wait in E until step 30
    assert len(points) == 31
    return np.array(points, dtype=float)


# Key at step 7, through the door at step 15, goal from step 17 on: every clause holds.
GOOD = _path(START, KEY, TO_GOAL)
# Straight up through wall B to the key (steps 1-2), then as GOOD.
THROUGH_WALL = _path([(1, 1), (1, 4), (1, 7)], KEY * 5, TO_GOAL)
# Waits at the key until step 18: reaches E at step 28, after the window [15, 27].
LATE = _path(START, KEY * 12, TO_GOAL)
# Never picks up the key: under C and through the door straight to the goal.
NO_KEY = _path([(1, 1), (4.5, 1), (7.5, 1), (9, 1), (9, 4), (9, 5.5), (9, 7)])
# Through the door (step 4) before fetching the key (step 11), then back to the goal.
DOOR_FIRST = _path(
    [(1, 1), (5.5, 1), (9, 1), (9, 4), (9, 5.5), (9, 4), (9, 1), (5.5, 1.5), (5.5, 5), (5.5, 8.5), (3, 9)],
    KEY,
    TO_GOAL,
)


def _summary(positions: np.ndarray) -> list[tuple[str, float, bool, int, str]]:
    return [
        (r.text, round(r.robustness, 9), r.satisfied, r.critical_step, r.critical_predicate)
        for r in explain(SPEC, positions, REGIONS)
    ]


def test_satisfying_trajectory() -> None:
    assert robustness(SPEC, GOOD, REGIONS) == pytest.approx(0.4)
    assert satisfied(SPEC, GOOD, REGIONS)
    assert _summary(GOOD) == [
        (CLAUSES[0], 0.4, True, 17, "in(E)"),  # the first step in E, margin 0.4 on all sides
        (CLAUSES[1], 0.5, True, 0, "!in(B)"),  # the start is 0.5 below B
        (CLAUSES[2], 0.5, True, 7, "in(A)"),  # the key, at A's centre
    ]


@pytest.mark.parametrize(
    ("positions", "violated", "robustness_", "step", "predicate"),
    [
        (THROUGH_WALL, 1, -1.0, 1, "!in(B)"),  # (1, 4) is 1 m inside B
        (LATE, 0, -0.8, 27, "in(E)"),  # at step 27 the robot is at (9, 7), 0.8 below E
        (NO_KEY, 2, -7.5, 0, "in(A)"),  # A is never approached closer than 7.5 (vertically)
        (DOOR_FIRST, 2, -0.25, 4, "!in(D)"),  # in D at step 4, 0.25 deep, before the key
    ],
    ids=["through-wall", "late", "no-key", "door-first"],
)
def test_violating_trajectories(
    positions: np.ndarray, violated: int, robustness_: float, step: int, predicate: str
) -> None:
    reports = explain(SPEC, positions, REGIONS)
    assert [r.satisfied for r in reports] == [i != violated for i in range(3)]
    bad = reports[violated]
    assert bad.text == CLAUSES[violated]
    assert bad.robustness == pytest.approx(robustness_)
    assert (bad.critical_step, bad.critical_predicate) == (step, predicate)
    assert all(r.robustness > 0 for r in reports if r.index != violated)
    assert not satisfied(SPEC, positions, REGIONS)
    assert robustness(SPEC, positions, REGIONS) == pytest.approx(robustness_)
    # the critical predicate really has that value at that step
    value = robustness(predicate, positions, REGIONS, t=step)
    assert value == pytest.approx(robustness_)


def test_robustness_trace_of_the_spec_is_defined_where_the_signal_is_long_enough() -> None:
    longer = np.vstack([GOOD, [GOAL] * 5])
    trace = robustness_trace(SPEC, longer, REGIONS)
    assert trace.shape == (6,)
    assert trace[0] == robustness(SPEC, GOOD, REGIONS)


def test_report_summary_and_serialization() -> None:
    report = explain(SPEC, THROUGH_WALL, REGIONS)[1]
    assert report.summary() == "G[0,30] (!in(B) & !in(C)): violated, robustness -1.000 (!in(B) at step 1)"
    assert ClauseReport.model_validate_json(report.model_dump_json()) == report
    with pytest.raises(ValueError, match="frozen"):
        report.robustness = 2.0  # type: ignore[misc]


LINE = np.array([[float(x), 0.0] for x in range(8)])


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("G[0,5] x >= 2", [(0, "x >= 2")]),  # the worst step
        ("F[0,5] x <= 2", [(0, "x <= 2")]),  # the best step (first of ties: none here)
        ("F[2,5] x >= 4", [(5, "x >= 4")]),
        ("!G[1,4] x >= 2", [(1, "!(x >= 2)")]),  # the step deciding G, reported negated
        ("(x <= 3) U[0,6] (x >= 5)", [(4, "x >= 5")]),  # k=4: min(r=-1, l>=0); k=5 ties, the first wins
        ("(x <= 1) U[3,6] (x >= 3)", [(2, "x <= 1")]),  # k=3: r=0 but l fails at step 2 (-1)
        ("(x <= 9) U[0,6] (x >= 5)", [(6, "x >= 5")]),  # the best step for the right side
        ("x >= 2 -> x >= 3", [(0, "!(x >= 2)")]),
        ("G[0,2] (x >= 1 | y >= 1) & F[0,1] true", [(0, "x >= 1"), (0, "true")]),
    ],
)
def test_critical_steps(text: str, expected: list[tuple[int, str]]) -> None:
    reports = explain(text, LINE, {})
    assert [(r.critical_step, r.critical_predicate) for r in reports] == expected
    for report in reports:
        if np.isfinite(report.robustness):
            value = robustness(report.critical_predicate, LINE, {}, t=report.critical_step)
            assert value == report.robustness


def test_max_clauses_keeps_the_most_violated_in_order() -> None:
    text = " & ".join(f"F[0,2] x >= {k}" for k in range(6))  # robustness 2 - k
    reports = explain(text, LINE, {}, max_clauses=3)
    assert [r.index for r in reports] == [3, 4, 5]
    assert [r.robustness for r in reports] == [-1.0, -2.0, -3.0]
    assert len(explain(text, LINE, {})) == 6
    assert [r.index for r in explain(parse("in(A)"), [[1, 9]], REGIONS)] == [0]


@pytest.mark.parametrize("bad", [0, -1, 2.5, True])
def test_max_clauses_is_validated(bad: object) -> None:
    with pytest.raises(InvalidArgumentError, match=r"max_clauses must be an integer >= 1, got"):
        explain("x >= 0", LINE, {}, max_clauses=bad)  # type: ignore[arg-type]


def test_explain_validates_like_robustness() -> None:
    with pytest.raises(InvalidArgumentError, match=r"it needs 30 steps after t, that is 31 rows"):
        explain(SPEC, GOOD[:20], REGIONS)
    with pytest.raises(InvalidArgumentError, match=r"regions is missing 'E'"):
        explain(SPEC, GOOD, {k: v for k, v in REGIONS.items() if k != "E"})
