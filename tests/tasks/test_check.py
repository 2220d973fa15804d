"""The checker against hand-computed answers: geometry, rollouts, bounds, tracking, goals, STL, bad input."""

from __future__ import annotations

import math
import re
import time
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest
from hypothesis import assume, given
from hypothesis import strategies as st

from audere.errors import InvalidArgumentError
from audere.tasks import CheckReport, MazeTask, Solution
from audere.tasks._check import check

from .factories import KEY_DOOR, MAZE, RA_PATH, RA_UNICYCLE, STL_SI, TRACK_SI, task

# ----------------------------------------------------------------------------------------- geometry


def test_straight_path_through_a_circle_collides_although_both_waypoints_are_outside() -> None:
    t = task(RA_PATH)  # circle centred at (5, 5), radius 1
    report = t.check(np.array([[1.0, 1.0], [9.0, 9.0]]))
    assert not report.success
    assert report.n_violations == 1
    v = report.violations[0]
    assert (v.kind, v.step, v.obstacle) == ("collision", 0, 0)
    entry = 5 - 1 / math.sqrt(2)  # where the diagonal enters the circle
    assert v.point == pytest.approx((entry, entry), abs=1e-12)
    assert "segment 0 from waypoint 0 (1.000, 1.000) to waypoint 1 (9.000, 9.000)" in v.message
    assert "circle centred at (5.00, 5.00), radius 1.00" in v.message
    assert report.metrics["goal_distance"] == 0.0
    assert report.metrics["min_clearance"] == pytest.approx(-1.0)  # the diagonal passes the centre
    assert report.metrics["path_length"] == pytest.approx(8 * math.sqrt(2))


def test_path_grazing_a_circle_tangentially_does_not_collide() -> None:
    t = task(RA_PATH)
    path = np.array([[1.0, 1.0], [1.0, 6.0], [9.0, 6.0], [9.0, 9.0]])  # y = 6 touches the circle at (5, 6)
    report = t.check(path)
    assert report.success, report.feedback()
    assert report.violations == ()
    assert report.metrics["min_clearance"] == pytest.approx(0.0, abs=1e-12)
    assert report.metrics["path_length"] == pytest.approx(5 + 8 + 3)


def test_a_shallow_chord_is_found_exactly_where_sampling_would_miss_it() -> None:
    t = task(RA_PATH)
    y = 5.99  # the segment cuts a chord of length 2*sqrt(1 - 0.99^2) = 0.28 out of the circle
    report = t.check(np.array([[1.0, 1.0], [1.0, y], [9.0, y], [9.0, 9.0]]))
    [v] = report.violations
    assert (v.kind, v.step, v.obstacle) == ("collision", 1, 0)
    assert v.point == pytest.approx((5 - math.sqrt(1 - 0.99**2), y))
    # the authors' checker sampled 20 points per segment: none of them is inside
    samples = np.linspace([1.0, y], [9.0, y], 20)
    assert np.all(np.hypot(samples[:, 0] - 5, samples[:, 1] - 5) >= 1)


def test_waypoint_inside_an_inflated_obstacle_is_a_point_collision() -> None:
    t = task(RA_PATH, margin=0.2)
    path = np.array([[1.0, 1.0], [1.0, 6.1], [9.0, 6.1], [9.0, 9.0]])  # y = 6.1 is inside radius 1.2
    report = t.check(path)
    kinds = [(v.kind, v.step) for v in report.violations]
    assert kinds == [("collision", 1)]  # the segment from the point inside is not reported again
    assert "inflated by the margin 0.200" in report.violations[0].message
    assert task(RA_PATH).check(path).success  # without the margin it is clear


def test_workspace_start_and_goal_violations_are_located() -> None:
    t = task(RA_PATH)
    report = t.check(np.array([[1.1, 1.0], [1.0, 11.0], [9.0, 8.5]]))
    got = [(v.kind, v.step) for v in report.violations]
    assert got == [("start", 0), ("workspace", 1), ("goal", 2)]
    start, ws, goal = report.violations
    assert "0.100 from the start (1.000, 1.000)" in start.message
    assert ws.point == (1.0, 11.0)
    assert (
        "ends at (9.000, 8.500), 0.500 from the goal (9.000, 9.000); it must end within 0.100" in goal.message
    )
    assert report.violation_counts == {"start": 1, "workspace": 1, "goal": 1}


def test_maze_walls_block_and_doors_let_through() -> None:
    t = task(MAZE)  # 2 x 2 cells of 5 m, doors at (5, 2.5) and (7.5, 5), walls 0.2 thick, margin 0.1
    through_doors = np.array([[1.0, 1.0], [1.0, 2.5], [7.5, 2.5], [7.5, 9.0], [9.0, 9.0]])
    report = t.check(through_doors)
    assert report.success, report.feedback()
    assert report.metrics["cells_visited"] == 3.0  # (0, 0), (0, 1), (1, 1)
    # door 0 spans y in [2, 3]: the wall ends inflated by 0.1 leave y in [2.1, 2.9], 0.4 from y = 2.5; the
    # circle at (2, 2), radius 0.3 + 0.1, is 0.5 - 0.4 = 0.1 from the segment at y = 2.5
    assert report.metrics["min_clearance"] == pytest.approx(0.1)
    blocked = t.check(np.array([[1.0, 1.0], [9.0, 1.0], [9.0, 9.0]]))
    first = blocked.violations[0]
    assert (first.kind, first.step) == ("collision", 0)
    assert first.obstacle is not None
    assert first.obstacle >= len(t.obstacles)
    assert "wall piece" in first.message
    assert first.point == pytest.approx((5.0 - 0.1 - 0.1, 1.0))  # half thickness + margin before x = 5


def test_path_tasks_take_a_single_waypoint() -> None:
    t = task(RA_PATH, goal=[1.0, 1.05])
    report = t.check([[1.0, 1.0]])
    assert report.success
    assert report.metrics["path_length"] == 0.0


# ----------------------------------------------------------------------------------------- dynamics


def test_unicycle_rollout_matches_a_hand_computation() -> None:
    t = task(RA_UNICYCLE, obstacles=[])
    inputs = np.zeros((10, 2))
    inputs[:2, 1] = 0.5  # accelerate for two steps, then coast at 1 m/s
    report = t.check(inputs)
    x = [1, 1, 1.5, 2.5, 3.5, 4.5, 5.5, 6.5, 7.5, 8.5, 9.5]
    assert report.positions is not None
    np.testing.assert_allclose(report.positions, np.column_stack([x, np.ones(11)]), atol=1e-12)
    assert report.metrics["goal_distance"] == pytest.approx(4.5)
    [goal] = report.violations
    assert (goal.kind, goal.step) == ("goal", 10)
    assert "the trajectory ends at (9.500, 1.000), 4.500 from the goal (5.000, 1.000)" in goal.message


def test_input_bound_violations_are_located() -> None:
    t = task(RA_UNICYCLE, obstacles=[])
    inputs = np.zeros((10, 2))
    inputs[3, 0] = 0.5
    inputs[5, 1] = -0.7
    inputs[7, 0] = 0.3 + 5e-7  # within the tolerance of 1e-6
    report = t.check({"inputs": inputs})
    bounds = [v for v in report.violations if v.kind == "input_bounds"]
    assert [v.step for v in bounds] == [3, 5]
    assert bounds[0].message == "step 3: input omega = 0.500 exceeds its upper bound u_max[0] = 0.300"
    assert bounds[1].message == "step 5: input a = -0.700 is below its lower bound u_min[1] = -0.500"
    assert report.violation_counts["input_bounds"] == 2


def test_states_given_with_inputs_must_match_the_rollout() -> None:
    t = task(TRACK_SI)
    inputs = np.full((4, 2), [0.5, 0.0])
    states = np.array([[1.0, 1.0], [1.5, 1.0], [2.0, 1.0], [2.5, 1.0], [3.0, 1.0]])
    assert t.check({"inputs": inputs, "states": states + 1e-9}).success
    bad = states.copy()
    bad[2, 0] += 0.01
    report = t.check(Solution(inputs=inputs, states=bad))
    [v] = report.violations
    assert (v.kind, v.step) == ("dynamics", 2)
    assert "the given state x = 2.010 does not match the rollout of the inputs, 2.000" in v.message


def test_states_alone_for_the_single_integrator_recover_the_inputs() -> None:
    t = task(TRACK_SI)
    states = np.array([[1.0, 1.0], [1.5, 1.0], [2.1, 1.0], [2.5, 1.0], [3.0, 1.0]])
    report = t.check(states)  # bare array of shape (horizon + 1, 2): states
    [v] = report.violations
    assert (v.kind, v.step) == ("input_bounds", 1)
    assert "input vx = 0.600 (recovered from the states as (x[k+1] - x[k]) / dt) exceeds" in v.message
    off = np.array([[1.1, 1.0], [1.5, 1.0], [2.0, 1.0], [2.5, 1.0], [3.0, 1.0]])  # starts 0.1 from x0
    start = t.check(off).violations[0]
    assert (start.kind, start.step) == ("start", 0)


def test_tracking_error_exactly() -> None:
    ref = [[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]]
    base: dict[str, Any] = {
        "x0": [0.0, 0.0],
        "horizon": 2,
        "u_min": [-1.0, -1.0],
        "u_max": [1.0, 1.0],
        "reference": ref,
    }
    inputs = np.array([[1.0, 0.0], [1.0, 0.0]])  # positions (0, 0), (1, 0), (2, 0): errors 0, 1, 2
    report = task(TRACK_SI, tolerance=1.0, **base).check(inputs)
    assert report.metrics == {
        "mean_tracking_error": 1.0,
        "max_tracking_error": 2.0,
        "final_tracking_error": 2.0,
    }
    [v] = report.violations
    assert (v.kind, v.step) == ("tracking", 2)
    assert v.message == (
        "the mean position error over the 3 steps is 1.000, not below the tolerance 1.000; the largest error "
        "is 2.000 at step 2 (position (2.000, 0.000), reference (2.000, 2.000))"
    )
    assert task(TRACK_SI, tolerance=1.01, **base).check(inputs).success


def test_tracking_a_reference_of_full_states_compares_positions() -> None:
    ref = np.zeros((11, 4))
    ref[:, 0] = 1.0 + np.arange(11) * 0.1
    ref[:, 1] = 1.0
    ref[:, 2] = 3.0  # headings are not compared, only positions
    t = task(
        RA_UNICYCLE,
        kind="tracking",
        goal=None,
        goal_tolerance=None,
        obstacles=[],
        reference=ref,
        tolerance=0.5,
    )
    report = t.check(np.zeros((10, 2)))  # the robot stays at (1, 1): errors 0.1 k
    assert report.metrics["mean_tracking_error"] == pytest.approx(0.5)
    assert report.metrics["final_tracking_error"] == pytest.approx(1.0)
    assert not report.success


def test_goal_on_the_state_wraps_angles() -> None:
    pend: dict[str, Any] = {
        "kind": "reach_avoid",
        "dynamics": "pendulum",
        "workspace": {"xmin": -2.0, "xmax": 2.0, "ymin": -2.0, "ymax": 2.0},
        "x0": [2 * math.pi, 0.0],  # hanging straight down, one full turn counted
        "horizon": 5,
        "dt": 0.1,
        "goal": [0.0, 0.0],
        "goal_on": "state",
        "goal_tolerance": 0.1,
    }
    wrapped = task(pend, angle_indices=[0]).check(np.zeros((5, 1)))  # (horizon,) inputs also accepted
    assert wrapped.success, wrapped.feedback()
    assert wrapped.metrics["goal_distance"] == pytest.approx(0.0, abs=1e-9)
    plain = task(pend).check(np.zeros(5))
    assert plain.metrics["goal_distance"] == pytest.approx(2 * math.pi)
    assert "is 6.283 from the goal state (0.000, 0.000)" in plain.violations[0].message


def test_a_diverging_rollout_is_a_violation_not_an_error() -> None:
    t = task(RA_PATH, dynamics="double_integrator", x0=[1.0, 1.0, 0.0, 0.0], horizon=5)
    report = t.check(np.full((5, 2), [1e308, 0.0]))
    assert not report.success
    assert report.violations[0].kind == "dynamics"
    assert "not finite from this step on" in report.violations[0].message
    assert report.metrics == {}


@pytest.mark.parametrize("magnitude", [1e150, 1e300])
def test_absurd_coordinates_fail_quietly(magnitude: float) -> None:
    obstacles = [
        {"kind": "square", "center": [5.0, 5.0], "half_side": 1.0},
        {"kind": "polygon", "vertices": [[1.0, 5.0], [2.0, 5.0], [1.5, 6.0]]},
    ]
    t = task(RA_PATH, obstacles=obstacles)
    report = t.check(np.array([[1.0, 1.0], [magnitude, magnitude]]))  # no warning escapes (-W error)
    assert not report.success
    assert report.violation_counts["workspace"] == 1
    exponent = int(math.log10(magnitude))
    collision, outside = report.violations[:2]
    assert (collision.kind, outside.kind) == ("collision", "workspace")
    assert collision.point == pytest.approx((4.0, 4.0))  # the diagonal still enters the square at its corner
    assert (
        f"waypoint 1: position (1.000e+{exponent}, 1.000e+{exponent}) is outside the workspace"
        in outside.message
    )


# ----------------------------------------------------------------------------------------- STL

# A trajectory for KEY_DOOR that picks up the key A at step 3, passes the door D at step 5 and is in the
# goal E from step 6 on, keeping 2 m from the wall B.
KEY_DOOR_OK = np.array(
    [[1, 1], [1, 4], [1, 7], [1, 9], [4, 9], [7, 9], [9, 9], [9, 9], [9, 9], [9, 9], [9, 9]], dtype=float
)


def test_key_door_trajectory_satisfies_the_spec_with_hand_computed_robustness() -> None:
    t = task(KEY_DOOR)
    report = t.check(KEY_DOOR_OK)
    assert report.success, report.feedback()
    # until: in(A) at step 3 by 0.5 (half the key's side), D far before; G: 2 m from B; F: 0.5 inside E
    assert [c.robustness for c in report.clauses] == pytest.approx([0.5, 2.0, 0.5])
    assert report.metrics["robustness"] == pytest.approx(0.5)
    assert [c.satisfied for c in report.clauses] == [True, True, True]
    assert report.clauses[0].text == "!in(D) U[0,10] in(A)"


def test_skipping_the_key_violates_only_the_until_clause() -> None:
    t = task(KEY_DOOR)
    no_key = np.array(
        [[1, 1], [1, 4], [2, 7], [4.5, 8], [7, 9], [9, 9], [9, 9], [9, 9], [9, 9], [9, 9], [9, 9]],
        dtype=float,
    )
    report = t.check(no_key)
    [v] = report.violations
    assert (v.kind, v.clause) == ("stl", "!in(D) U[0,10] in(A)")
    # the closest approach to A is (2, 7): 0.5 right of it and 1.5 below it; the robustness of in(box) is
    # the least of the four margins x - xmin, xmax - x, y - ymin, ymax - y
    assert v.step == 2
    assert report.clauses[0].robustness == pytest.approx(-1.5)
    assert report.clauses[0].critical_predicate == "in(A)"
    assert "decided by in(A) at step 2" in v.message


def test_each_violated_clause_is_reported_in_order_of_steps() -> None:
    t = task(KEY_DOOR)
    bad = KEY_DOOR_OK.copy()
    bad[1] = [3.5, 4.0]  # 0.5 deep inside the wall B at step 1
    bad[6:9] = [7.5, 9.0]  # waits outside E (1 m short) until step 8
    report = t.check(bad)
    assert [(v.kind, v.step, v.clause) for v in report.violations] == [
        ("stl", 1, "G[0,10] !in(B)"),
        ("stl", 6, "F[6,8] in(E)"),
    ]
    assert [c.robustness for c in report.clauses] == pytest.approx([0.5, -0.5, -1.0])
    assert report.metrics["robustness"] == pytest.approx(-1.0)
    assert report.violation_counts == {"stl": 2}


def test_timed_waypoints_are_resampled_at_the_steps() -> None:
    region = {"A": {"kind": "circle", "center": [1.25, 2.5], "radius": 0.5}}
    t = task(STL_SI, horizon=4, u_min=[-1.0, -1.0], u_max=[1.0, 1.0], spec="F[0,4] in(A)", regions=region)
    timed = np.array([[1.0, 1.0, 0.0], [2.0, 1.0, 0.5], [1.0, 3.0, 2.5], [1.0, 3.0, 4.0]])
    report = t.check(timed)
    assert report.positions is not None
    # t = 1 is a quarter of the way from (2, 1) at 0.5 to (1, 3) at 2.5, t = 2 three quarters
    expected = [[1.0, 1.0], [1.75, 1.5], [1.25, 2.5], [1.0, 3.0], [1.0, 3.0]]
    np.testing.assert_allclose(report.positions, expected, atol=1e-12)
    # per-step speeds of the resampled positions: (0.75, 0.5), (-0.5, 1.0), (-0.25, 0.5), (0, 0)
    assert report.success, report.feedback()
    assert report.metrics["robustness"] == pytest.approx(0.5)  # at step 2, the centre of A
    same = t.check({"waypoints": timed[:, :2], "times": timed[:, 2]})
    assert same == report
    slow = task(STL_SI, horizon=4, u_min=[-0.9, -0.9], u_max=[0.9, 0.9], spec="F[0,4] in(A)", regions=region)
    [v] = slow.check(timed).violations
    assert (v.kind, v.step) == ("input_bounds", 1)
    assert "input vy = 1.000 (recovered from the states" in v.message


def test_inputs_states_and_timed_waypoints_of_the_same_motion_agree() -> None:
    t = task(KEY_DOOR)
    by_states = t.check({"states": KEY_DOOR_OK})
    by_inputs = t.check(np.diff(KEY_DOOR_OK, axis=0) / t.dt)
    by_time = t.check(np.column_stack([KEY_DOOR_OK, np.arange(11.0)]))
    assert (by_states.success, by_inputs.success, by_time.success) == (True, True, True)
    assert by_states == by_time
    assert by_inputs.metrics == pytest.approx(by_states.metrics)


# ----------------------------------------------------------------------------------------- malformed

MALFORMED: list[tuple[str, dict[str, Any], Any, str]] = [
    (
        "waypoints with 3 columns",
        RA_PATH,
        np.zeros((3, 3)),
        r"^expected waypoints: an array of shape \(k, 2\), one row \(x, y\) per waypoint, k >= 1; got an "
        r"array of shape \(3, 3\)$",
    ),
    ("empty waypoints", RA_PATH, np.zeros((0, 2)), r"got an empty array of shape \(0, 2\)$"),
    ("empty list", RA_PATH, [], r"got an empty array of shape \(0,\)$"),
    ("a single number", RA_PATH, 3.0, r"a solution must be a Solution, .* got float"),
    (
        "NaN waypoint",
        RA_PATH,
        [[1.0, 1.0], [math.nan, 2.0]],
        r"^waypoints must be finite, got nan at row 1, column 0 \(x\) \(1 non-finite entries\)$",
    ),
    (
        "infinite waypoint",
        RA_PATH,
        [[1.0, 1.0], [2.0, math.inf]],
        r"waypoints must be finite, got inf at row 1, column 1 \(y\)",
    ),
    (
        "ragged rows",
        RA_PATH,
        [[1.0, 1.0], [2.0]],
        r"the solution must be an array of numbers, got list .*\(ragged rows\)",
    ),
    ("text", RA_PATH, "go to the goal", r"a solution must be a Solution, a mapping of its fields .* got str"),
    ("None", RA_PATH, None, r"got NoneType"),
    (
        "inputs for a path task",
        RA_PATH,
        {"inputs": np.zeros((20, 2))},
        r"this path task takes only waypoints; expected waypoints: .*; got inputs",
    ),
    (
        "unknown field",
        RA_PATH,
        {"path": [[1.0, 1.0]]},
        r"unknown solution field\(s\) 'path'; a solution has the fields inputs, states, waypoints, times",
    ),
    ("empty mapping", RA_PATH, {}, r"the solution mapping holds no array"),
    (
        "words in a field",
        RA_PATH,
        {"waypoints": "north"},
        r"waypoints must be an array of numbers, got a str: 'north'",
    ),
    (
        "complex numbers",
        RA_PATH,
        {"waypoints": np.array([[1 + 1j, 1.0]])},
        r"waypoints must be an array of numbers",
    ),
    (
        "wrong bare shape for tracking",
        TRACK_SI,
        np.zeros((4, 3)),
        r"^expected inputs: an array of shape \(4, 2\) \(vx, vy\), one row per step; or states: an array of "
        r"shape \(5, 2\) \(x, y\); got an array of shape \(4, 3\)$",
    ),
    (
        "inputs with one row too many",
        TRACK_SI,
        {"inputs": np.zeros((5, 2))},
        r"^inputs must have shape \(4, 2\) \(vx, vy\) \(horizon 4 rows\); got an array of shape \(5, 2\)$",
    ),
    (
        "states with one row too few",
        TRACK_SI,
        {"states": np.zeros((4, 2))},
        r"states must have shape \(5, 2\) \(x, y\) \(horizon \+ 1 = 5 rows\); got an array of shape \(4, 2\)",
    ),
    (
        "NaN input",
        TRACK_SI,
        {"inputs": [[0.0, 0.0], [0.0, math.nan], [0.0, 0.0], [0.0, 0.0]]},
        r"inputs must be finite, got nan at row 1, column 1 \(vy\)",
    ),
    ("1-D inputs for a 2-input model", TRACK_SI, np.zeros(4), r"got an array of shape \(4,\)"),
    (
        "states alone for the unicycle",
        RA_UNICYCLE,
        {"states": np.zeros((11, 4))},
        r"states alone cannot be checked for dynamics 'unicycle' \(its inputs cannot be recovered from "
        r"them\); give inputs",
    ),
    (
        "waypoints for the unicycle",
        RA_UNICYCLE,
        {"waypoints": np.zeros((3, 2))},
        r"this task with dynamics 'unicycle' does not take waypoints",
    ),
    (
        "waypoints without times",
        STL_SI,
        {"waypoints": np.zeros((3, 2))},
        r"waypoints without times cannot be checked",
    ),
    (
        "times twice",
        STL_SI,
        {"waypoints": np.zeros((3, 3)), "times": [0.0, 1.0, 2.0]},
        r"give the times either as the third column of waypoints or as times, not both",
    ),
    ("times alone", STL_SI, {"times": [0.0, 1.0]}, r"times belong to waypoints"),
    (
        "times and inputs",
        STL_SI,
        {"waypoints": np.zeros((2, 3)), "inputs": np.zeros((10, 2))},
        r"give either timed waypoints or inputs, not both",
    ),
    (
        "one timed waypoint",
        STL_SI,
        {"waypoints": [[1.0, 1.0, 0.0]]},
        r"a timed path needs at least 2 waypoints; got 1",
    ),
    (
        "times of the wrong length",
        STL_SI,
        {"waypoints": np.zeros((3, 2)), "times": [0.0, 10.0]},
        r"times must have shape \(3,\), one time per waypoint; got an array of shape \(2,\)",
    ),
    (
        "times not increasing",
        STL_SI,
        [[1.0, 1.0, 0.0], [2.0, 2.0, 5.0], [3.0, 3.0, 5.0], [3.0, 3.0, 10.0]],
        r"times must be strictly increasing; got t\[2\] = 5\.000 after t\[1\] = 5\.000",
    ),
    (
        "timed path starting late",
        STL_SI,
        [[1.0, 1.0, 1.0], [2.0, 2.0, 10.0]],
        r"the timed path must start at t = 0; got t\[0\] = 1\.000",
    ),
    (
        "timed path ending early",
        STL_SI,
        [[1.0, 1.0, 0.0], [2.0, 2.0, 9.5]],
        r"the timed path must reach t = 10\.000 \(horizon 10 x dt 1\.000\); its last time is 9\.500",
    ),
    (
        "Solution of the wrong shape",
        RA_PATH,
        Solution(waypoints=[[1.0, 1.0, 1.0]]),
        r"got waypoints as an array of shape \(1, 3\)",
    ),
]


@pytest.mark.parametrize(
    ("base", "solution", "pattern"), [m[1:] for m in MALFORMED], ids=[m[0] for m in MALFORMED]
)
def test_malformed_solutions_are_reported_not_raised(
    base: dict[str, Any], solution: Any, pattern: str
) -> None:
    report = task(base).check(solution)
    assert not report.success
    assert report.n_violations == 1
    assert report.violation_counts == {"malformed": 1}
    [v] = report.violations
    assert v.kind == "malformed"
    assert re.search(pattern, v.message), v.message
    assert report.positions is None
    assert report.preview is None


def test_ambiguous_bare_array_is_reported() -> None:
    t = task(STL_SI)
    # No built-in model makes two readings of one shape possible; a model with 3 inputs would: an array
    # (horizon, 3) could be its inputs or timed waypoints.
    fake = SimpleNamespace(n_u=3, n_x=2, input_names=("a", "b", "c"), state_names=("x", "y"))
    t.__dict__["model"] = fake  # the cached dynamics model
    report = t.check(np.zeros((10, 3)))
    [v] = report.violations
    assert v.message == (
        "an array of shape (10, 3) is ambiguous for this task: it could be inputs or timed waypoints; pass a "
        "mapping that names the field, e.g. {'inputs': ...}"
    )


def test_checking_a_non_task_is_a_programming_error() -> None:
    with pytest.raises(InvalidArgumentError, match=r"task must be a TrackingTask, .* got dict"):
        check(RA_PATH, np.zeros((2, 2)))  # type: ignore[arg-type]


# ----------------------------------------------------------------------------------------- report shape


def test_preview_is_downsampled_and_positions_are_kept() -> None:
    t = task(RA_PATH, obstacles=[])
    path = np.column_stack([np.linspace(1, 9, 200), np.linspace(1, 9, 200)])
    report = t.check(path)
    assert report.success
    assert report.preview is not None
    assert report.positions is not None
    assert report.preview.shape == (11, 2)
    np.testing.assert_array_equal(report.preview[0], path[0])
    np.testing.assert_array_equal(report.preview[-1], path[-1])
    np.testing.assert_array_equal(report.positions, path)
    short = t.check(path[::40])
    assert short.preview is not None
    assert short.preview.shape == (5, 2)


def test_violations_are_capped_and_all_counted() -> None:
    t = task(RA_PATH, x0=[5.0, 3.0], goal=[5.0, 3.0])
    zigzag = np.tile([[5.0, 3.0], [5.0, 7.0]], (300, 1))[:-1]  # 598 segments, each crossing the circle
    report = t.check(zigzag)
    assert report.n_violations == 598
    assert len(report.violations) == CheckReport.MAX_VIOLATIONS
    assert [v.step for v in report.violations] == list(range(10))
    assert report.violation_counts == {"collision": 598}


def test_report_survives_a_json_round_trip() -> None:
    report = task(KEY_DOOR).check(KEY_DOOR_OK)
    assert CheckReport.model_validate_json(report.model_dump_json()) == report


# ----------------------------------------------------------------------------------------- properties


@given(
    p=st.tuples(st.floats(0.0, 10.0), st.floats(0.0, 10.0)),
    q=st.tuples(st.floats(0.0, 10.0), st.floats(0.0, 10.0)),
)
def test_segment_verdict_agrees_with_the_closed_form_distance(
    p: tuple[float, float], q: tuple[float, float]
) -> None:
    """Collision of one segment with the circle at (5, 5), r = 1, against an independent closed form."""
    a, b, c = np.array(p), np.array(q), np.array([5.0, 5.0])
    assume(np.hypot(*(a - c)) > 1 + 1e-6 and np.hypot(*(b - c)) > 1 + 1e-6)  # valid start, no point inside
    d = b - a
    dd = float(np.dot(d, d))  # 0 also when d is so small that its square underflows
    s = 0.0 if dd == 0.0 else float(np.clip(np.dot(c - a, d) / dd, 0.0, 1.0))
    distance = float(np.hypot(*(a + s * d - c)))
    assume(abs(distance - 1.0) > 1e-9)  # not a numerical tangent
    t = task(RA_PATH, x0=list(p), goal=list(q))
    report = t.check(np.array([a, b]))
    assert report.success == (distance > 1.0)
    if distance < 1.0:
        assert (report.violations[0].kind, report.violations[0].step) == ("collision", 0)


def test_checking_a_plan_hard_sized_path_is_fast() -> None:
    """200 waypoints against ~100 obstacles (a 3 x 3 maze with 4 obstacles per cell and its walls)."""
    rng = np.random.default_rng(1)
    obstacles = [  # 10 per cell, in a row across its upper part
        {
            "kind": "circle" if k % 2 else "square",
            "center": [c * 10 / 3 + 0.35 + 0.3 * k, r * 10 / 3 + 2.6],
            "radius" if k % 2 else "half_side": float(rng.uniform(0.2, 0.35)),
        }
        for r in range(3)
        for c in range(3)
        for k in range(10)
    ]
    doors = [
        {"cells": [[r, c], [r, c + 1]], "offset": 0.5, "width": 0.8} for r in range(3) for c in range(2)
    ] + [{"cells": [[r, c], [r + 1, c]], "offset": 0.5, "width": 0.8} for r in range(2) for c in range(3)]
    t = task(
        MAZE,
        rows=3,
        cols=3,
        doors=doors,
        obstacles=obstacles,
        x0=[0.5, 0.5],
        goal=[9.5, 0.5],
        margin=0.15,
        wall_thickness=0.1,
    )
    assert isinstance(t, MazeTask)
    assert len(t.all_obstacles()) >= 100
    y = 1.6667  # through the doors of the bottom row, below the obstacles
    corners = np.array([[0.5, 0.5], [0.5, y], [9.5, y], [9.5, 0.5]])
    path = np.concatenate([np.linspace(corners[i], corners[i + 1], 67, endpoint=False) for i in range(3)])
    path = np.vstack([path[:199], corners[-1]])
    assert path.shape == (200, 2)
    report = t.check(path)
    assert report.success, report.feedback()
    timings = []
    for _ in range(5):
        start = time.perf_counter()
        t.check(path)
        timings.append(time.perf_counter() - start)
    assert min(timings) < 0.05  # typically 2-4 ms; generous for loaded machines
