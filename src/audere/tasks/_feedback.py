"""Bounded text about a :class:`~audere.tasks.CheckReport`, meant to go back to a language model.

Two renderings:

- :func:`summary`: one line, the verdict and the key metrics;
- :func:`feedback`: a few lines under a hard character cap: the verdict with violation counts by
  kind, the metrics, the first violations (one line each), per-clause robustness for STL tasks and
  a downsampled preview of the positions with two decimals. The full trajectory is never included.

When the cap is tight, lines are kept in order of usefulness (verdict, metrics, first violation,
STL clauses, preview, further violations) and the text says how many violations were left out.
"""

from __future__ import annotations

import math

import numpy as np

from audere.errors import InvalidArgumentError
from audere.tasks._report import CheckReport

__all__ = ["feedback", "format_value", "preview_steps", "summary"]

_MAX_LINE = 400  # one line of feedback is cut with "..." past this many characters
_MIN_CHARS = 20


def format_value(value: float) -> str:
    """Format a metric for a model: three decimals, scientific notation for very large or small values.

    Parameters
    ----------
    value
        The number.

    Returns
    -------
    str
        E.g. ``"0.031"``, ``"-1.250"``, ``"1.234e+05"``, ``"inf"``.
    """
    if not math.isfinite(value):
        return "nan" if math.isnan(value) else ("inf" if value > 0 else "-inf")
    magnitude = abs(value)
    if magnitude >= 1e5 or 0 < magnitude < 1e-3:
        return f"{value:.3e}"
    text = f"{value:.3f}"
    return "0.000" if text == "-0.000" else text


def preview_steps(n: int, *, max_points: int = 11) -> np.ndarray:
    """Indices of an even downsampling of ``n`` samples, first and last always included.

    Parameters
    ----------
    n
        Number of samples (e.g. ``horizon + 1`` positions).
    max_points
        Largest number of indices returned.

    Returns
    -------
    numpy.ndarray
        Sorted, distinct integer indices into ``range(n)``; ``min(n, max_points)`` of them.
    """
    if n <= 0:
        return np.zeros(0, dtype=int)
    if n <= max_points:
        return np.arange(n)
    # With n > max_points the rounded, evenly spaced indices are at least one apart: distinct.
    return np.round(np.linspace(0, n - 1, max_points)).astype(int)


def _verdict(report: CheckReport) -> str:
    if report.success:
        return "success"
    counts = report.violation_counts
    if "malformed" in counts:
        return "failure: malformed solution"
    n = report.n_violations
    word = "violation" if n == 1 else "violations"
    by_kind = ", ".join(f"{count} {kind}" for kind, count in counts.items())
    return f"failure: {n} {word}" + (f" ({by_kind})" if by_kind else "")


def _metrics(report: CheckReport) -> str:
    return ", ".join(f"{name}={format_value(value)}" for name, value in report.metrics.items())


def summary(report: CheckReport) -> str:
    """One line: the verdict, the violation counts by kind and the key metrics.

    Parameters
    ----------
    report
        The checker's report.

    Returns
    -------
    str
        E.g. ``"success; goal_distance=0.031, min_clearance=0.412, path_length=12.804"`` or
        ``"failure: 3 violations (2 collision, 1 goal); goal_distance=0.532, ..."``.
    """
    if not isinstance(report, CheckReport):
        raise InvalidArgumentError(f"report must be a CheckReport, got {type(report).__name__}")
    metrics = _metrics(report)
    return _verdict(report) + (f"; {metrics}" if metrics else "")


def _clip(line: str, limit: int = _MAX_LINE) -> str:
    return line if len(line) <= limit else line[: limit - 3] + "..."


def _coordinate(value: float) -> str:
    text = f"{value:.3e}" if abs(value) >= 1e5 else f"{value:.2f}"
    return "0.00" if text == "-0.00" else text


def _point(p: np.ndarray) -> str:
    return f"({_coordinate(float(p[0]))}, {_coordinate(float(p[1]))})"


def feedback(report: CheckReport, *, max_chars: int = 2000) -> str:
    """Bounded feedback for a language model about one checked solution.

    Parameters
    ----------
    report
        The checker's report.
    max_chars
        Hard cap on the length of the returned text, in characters (at least 20).

    Returns
    -------
    str
        Lines: ``Verdict: ...``, ``Metrics: ...``, ``Violations (first k of n):`` with one line per
        violation and ``... (m more violations)`` when some are left out, ``STL clauses:`` with the
        robustness of each clause, and ``Positions (...)``: at most 11 positions with 2 decimals,
        first and last included. Never longer than ``max_chars``.

    Raises
    ------
    InvalidArgumentError
        If ``report`` is not a CheckReport or ``max_chars`` is below 20.
    """
    if not isinstance(report, CheckReport):
        raise InvalidArgumentError(f"report must be a CheckReport, got {type(report).__name__}")
    if isinstance(max_chars, bool) or not isinstance(max_chars, int) or max_chars < _MIN_CHARS:
        raise InvalidArgumentError(f"max_chars must be an integer >= {_MIN_CHARS}, got {max_chars!r}")

    # Each line: (priority, position in the text, group, text). Lines are kept greedily by priority
    # while the text fits; once a line of a group does not fit, the later lines of that group are
    # dropped too (so the violations shown are always the first ones).
    items: list[tuple[int, int, str, str]] = []

    def add(priority: int, group: str, line: str) -> None:
        items.append((priority, len(items), group, _clip(line)))

    add(0, "verdict", f"Verdict: {_verdict(report)}.")
    if report.metrics:
        add(1, "metrics", f"Metrics: {_metrics(report)}")
    if report.violations:
        add(2, "violations", f"Violations ({report.n_violations} in all, in order of steps):")
        for i, v in enumerate(report.violations):
            add(2 if i == 0 else 6, "violations", f"- {v.kind}: {v.message}")
    note_at = len(items)  # the "... (N more violations)" note goes right after the violations
    if report.clauses:
        add(3, "clauses", "STL clauses (robustness > 0 means satisfied):")
        for c in report.clauses:
            state = "satisfied" if c.satisfied else "VIOLATED"
            where = f", critical step {c.critical_step}" if c.critical_step is not None else ""
            add(4, "clauses", f"- {c.text}: robustness {format_value(c.robustness)} ({state}{where})")
    if report.preview is not None and len(report.preview):
        preview = np.asarray(report.preview)
        total = len(report.positions) if report.positions is not None else None
        if total is not None and len(preview_steps(total)) == len(preview):
            steps = ", ".join(str(int(s)) for s in preview_steps(total))
            head = f"Positions ({len(preview)} of {total}, at steps {steps}): "
        else:
            head = f"Positions ({len(preview)} samples): "
        add(5, "preview", head + ", ".join(_point(p) for p in preview))

    def render(chosen: list[tuple[int, int, str, str]]) -> str:
        lines = sorted(chosen, key=lambda item: item[1])
        n_shown = sum(1 for _, o, g, t in lines if g == "violations" and t.startswith("- "))
        missing = report.n_violations - n_shown
        out = [t for _, o, _, t in lines if o < note_at]
        if report.violations and missing > 0:
            out.append(f"... ({missing} more violation{'s' if missing != 1 else ''})")
        out += [t for _, o, _, t in lines if o >= note_at]
        return "\n".join(out)

    chosen = [items[0]]
    closed: set[str] = set()
    for item in sorted(items[1:]):
        if item[2] in closed:
            continue
        if len(render([*chosen, item])) <= max_chars:
            chosen.append(item)
        else:
            closed.add(item[2])
    text = render(chosen)
    if len(text) > max_chars:  # only when even the verdict does not fit
        text = text[: max_chars - 3].rstrip() + "..."
    return text
