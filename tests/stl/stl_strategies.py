"""Hypothesis strategies for STL formulas, signals and regions (shared by the tests/stl files)."""

from __future__ import annotations

import numpy as np
from hypothesis import strategies as st

from audere.stl import (
    FALSE,
    TRUE,
    Always,
    And,
    Compare,
    Eventually,
    Formula,
    Implies,
    In,
    Not,
    Or,
    Until,
)
from audere.world._shapes import Circle, Polygon, Rectangle, Square, Workspace

# --- formulas for the text round trip: any names, any finite numbers, any bounds -------------------

names = st.one_of(
    st.from_regex(r"[A-Za-z_][A-Za-z0-9_]{0,8}", fullmatch=True),
    st.sampled_from(["in", "x", "y", "G", "F", "U", "true", "false", "région", "Ωmega_2"]),
)
any_float = st.floats(allow_nan=False, allow_infinity=False)


@st.composite
def any_compare(draw: st.DrawFn) -> Compare:
    a, b = draw(any_float), draw(any_float)
    if a == 0 and b == 0:
        a = draw(st.sampled_from([1.0, -1.0, 0.5, 1e-300]))
    return Compare(a, b, draw(st.sampled_from(["<=", ">="])), draw(any_float))


@st.composite
def _bounds(draw: st.DrawFn, *, max_lo: int, max_width: int) -> tuple[int, int]:
    lo = draw(st.integers(0, max_lo))
    return lo, lo + draw(st.integers(0, max_width))


def _extend(
    children: st.SearchStrategy[Formula], *, max_lo: int, max_width: int
) -> st.SearchStrategy[Formula]:
    bounds = _bounds(max_lo=max_lo, max_width=max_width)
    operands = st.lists(children, min_size=2, max_size=3).map(tuple)
    return st.one_of(
        children.map(Not),
        operands.map(And),
        operands.map(Or),
        st.builds(Implies, children, children),
        st.builds(lambda b, c: Always(b[0], b[1], c), bounds, children),
        st.builds(lambda b, c: Eventually(b[0], b[1], c), bounds, children),
        st.builds(lambda b, left, right: Until(b[0], b[1], left, right), bounds, children, children),
    )


any_formulas: st.SearchStrategy[Formula] = st.recursive(
    st.one_of(names.map(In), any_compare(), st.sampled_from([TRUE, FALSE])),
    lambda children: _extend(children, max_lo=10**6, max_width=10**6),
    max_leaves=10,
)

# --- small formulas and signals for the semantics: short windows, a few regions ---------------------

REGION_NAMES = ("A", "B", "C", "D", "P")

# Boundaries on the 0.5 grid, so that signals drawn on that grid often touch them (robustness 0).
REGIONS = {
    "A": Rectangle(xmin=0.5, xmax=2.5, ymin=0.5, ymax=2.0),
    "B": Square(center=(3.0, 3.0), half_side=1.0),
    "C": Circle(center=(2.0, 3.0), radius=1.5),
    "D": Workspace(xmin=1.0, xmax=5.0, ymin=0.0, ymax=2.5),
    "P": Polygon(vertices=((0.0, 0.0), (4.0, 0.0), (4.0, 4.0), (2.0, 1.5), (0.0, 4.0))),
}


@st.composite
def _small_compare(draw: st.DrawFn) -> Compare:
    a = draw(st.sampled_from([1.0, -1.0, 0.5, 2.0, 0.0]))
    b = draw(st.sampled_from([1.0, -1.0, -0.5] if a == 0 else [1.0, -1.0, -0.5, 0.0]))
    op = draw(st.sampled_from(["<=", ">="]))
    return Compare(a, b, op, draw(st.sampled_from([0.0, 1.0, 2.5, -1.0, 3.25])))


small_formulas: st.SearchStrategy[Formula] = st.recursive(
    st.one_of(
        st.sampled_from(REGION_NAMES).map(In),
        _small_compare(),
        st.sampled_from([TRUE, FALSE]),
    ),
    lambda children: _extend(children, max_lo=2, max_width=3),
    max_leaves=6,
)


@st.composite
def signals(draw: st.DrawFn, *, rows: int, grid: bool) -> np.ndarray:
    """Positions (rows, 2) in [-0.5, 5.5]^2, on the 0.5 grid or anywhere."""
    if grid:
        values = st.integers(-1, 11).map(lambda k: k * 0.5)
    else:
        values = st.floats(-0.5, 5.5, allow_nan=False, allow_infinity=False)
    flat = draw(st.lists(values, min_size=2 * rows, max_size=2 * rows))
    return np.array(flat, dtype=np.float64).reshape(rows, 2)
