"""Feedback for a model: exact format on hand-made reports, a hard length bound, counts kept when cut."""

from __future__ import annotations

import re

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from audere.errors import InvalidArgumentError
from audere.tasks import CheckReport, ClauseResult, Violation
from audere.tasks._feedback import feedback, format_value, preview_steps, summary

from .factories import RA_PATH, task


def _zigzag_report(n_segments: int) -> CheckReport:
    """A path whose every segment crosses the circle at (5, 5), radius 1, with both ends outside it."""
    t = task(RA_PATH, x0=[5.0, 3.0], goal=[5.0, 3.0] if n_segments % 2 == 0 else [5.0, 7.0])
    path = np.tile([[5.0, 3.0], [5.0, 7.0]], (n_segments // 2 + 1, 1))[: n_segments + 1]
    return t.check(path)


def test_feedback_of_a_thousand_violations_is_bounded_and_counts_them_all() -> None:
    report = _zigzag_report(1000)
    assert report.n_violations == 1000
    assert report.violation_counts == {"collision": 1000}
    text = report.feedback(max_chars=800)
    assert len(text) <= 800
    assert text.startswith("Verdict: failure: 1000 violations (1000 collision).")
    shown = re.findall(r"^- collision: segment (\d+) ", text, flags=re.MULTILINE)
    assert shown  # at least the first violation
    assert [int(s) for s in shown] == list(range(len(shown)))  # the first ones, none skipped
    assert f"... ({1000 - len(shown)} more violations)" in text
    assert text.count("(5.00, 3.00)") + text.count("(5.00, 7.00)") <= 11  # the preview, not the trajectory


@given(max_chars=st.integers(20, 4000))
def test_feedback_never_exceeds_max_chars(max_chars: int) -> None:
    text = feedback(_REPORT_1000, max_chars=max_chars)
    assert len(text) <= max_chars
    assert text.startswith("Verdict: failure:"[: max_chars - 3])


_REPORT_1000 = _zigzag_report(1000)


def test_feedback_of_a_success_lists_metrics_and_preview() -> None:
    t = task(RA_PATH)
    report = t.check(np.array([[1.0, 1.0], [1.0, 6.0], [9.0, 6.0], [9.0, 9.0]]))
    assert report.feedback() == (
        "Verdict: success.\n"
        "Metrics: goal_distance=0.000, min_clearance=0.000, path_length=16.000\n"
        "Positions (4 of 4, at steps 0, 1, 2, 3): (1.00, 1.00), (1.00, 6.00), (9.00, 6.00), (9.00, 9.00)"
    )
    assert report.summary() == "success; goal_distance=0.000, min_clearance=0.000, path_length=16.000"


def test_feedback_format_with_violations_and_clauses() -> None:
    report = CheckReport(
        success=False,
        metrics={"robustness": -0.25},
        violations=(
            Violation(
                kind="input_bounds", step=2, message="step 2: input vx = 5.000 exceeds its upper bound"
            ),
            Violation(
                kind="stl", step=7, clause="G[0,10] !in(B)", message="the clause G[0,10] !in(B) is violated"
            ),
        ),
        n_violations=3,
        violation_counts={"input_bounds": 2, "stl": 1},
        clauses=(
            ClauseResult(text="F[0,10] in(A)", robustness=0.5, satisfied=True, critical_step=3),
            ClauseResult(text="G[0,10] !in(B)", robustness=-0.25, satisfied=False, critical_step=7),
        ),
        preview=np.array([[0.0, 0.0], [1.234, -0.001]]),
        positions=np.array([[0.0, 0.0], [1.234, -0.001]]),
    )
    assert report.feedback() == (
        "Verdict: failure: 3 violations (2 input_bounds, 1 stl).\n"
        "Metrics: robustness=-0.250\n"
        "Violations (3 in all, in order of steps):\n"
        "- input_bounds: step 2: input vx = 5.000 exceeds its upper bound\n"
        "- stl: the clause G[0,10] !in(B) is violated\n"
        "... (1 more violation)\n"
        "STL clauses (robustness > 0 means satisfied):\n"
        "- F[0,10] in(A): robustness 0.500 (satisfied, critical step 3)\n"
        "- G[0,10] !in(B): robustness -0.250 (VIOLATED, critical step 7)\n"
        "Positions (2 of 2, at steps 0, 1): (0.00, 0.00), (1.23, 0.00)"
    )
    assert summary(report) == "failure: 3 violations (2 input_bounds, 1 stl); robustness=-0.250"


def test_tight_budget_keeps_verdict_metrics_and_first_violation_first() -> None:
    report = _REPORT_1000
    full = report.feedback(max_chars=100_000)
    lines = full.splitlines()
    budget = len("\n".join(lines[:4])) + len("\n... (999 more violations)")  # verdict, metrics, header, first
    text = report.feedback(max_chars=budget)
    assert text.splitlines()[:4] == lines[:4]
    assert "... (999 more violations)" in text
    assert "Positions" not in text  # the preview goes before further violations, but not before the first


def test_malformed_verdict() -> None:
    report = task(RA_PATH).check("a path please")
    text = report.feedback()
    assert text.splitlines()[0] == "Verdict: failure: malformed solution."
    assert text.splitlines()[2].startswith("- malformed: a solution must be a Solution")


def test_max_chars_must_be_reasonable() -> None:
    with pytest.raises(InvalidArgumentError, match=r"max_chars must be an integer >= 20, got 5"):
        _REPORT_1000.feedback(max_chars=5)
    with pytest.raises(InvalidArgumentError, match=r"report must be a CheckReport, got str"):
        feedback("report")  # type: ignore[arg-type]


def test_preview_steps_and_value_format() -> None:
    assert preview_steps(0).tolist() == []
    assert preview_steps(3).tolist() == [0, 1, 2]
    assert preview_steps(21).tolist() == [0, 2, 4, 6, 8, 10, 12, 14, 16, 18, 20]
    steps = preview_steps(200)
    assert (steps[0], steps[-1], len(set(steps.tolist()))) == (0, 199, 11)
    assert [format_value(v) for v in (0.0312, -1.25, 123456.0, 2e-5, float("inf"))] == [
        "0.031",
        "-1.250",
        "1.235e+05",
        "2.000e-05",
        "inf",
    ]
