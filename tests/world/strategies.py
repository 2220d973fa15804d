"""Hypothesis strategies for the world tests: shapes (free or on a 0.5 grid), points, segments, margins."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from audere.world import Circle, Obstacle, Polygon, Rectangle, Square

coords = st.floats(-5, 5, allow_nan=False, allow_infinity=False)
"""Free coordinates."""

grid = st.integers(-10, 10).map(lambda i: i / 2)
"""Coordinates on a 0.5 grid: exact arithmetic, so boundary contact happens often and is decided exactly."""

sizes = st.floats(0.25, 3, allow_nan=False)
grid_sizes = st.integers(1, 6).map(lambda i: i / 2)
margins = st.floats(0, 2, allow_nan=False)


def circles(
    c: st.SearchStrategy[float] = coords, r: st.SearchStrategy[float] = sizes
) -> st.SearchStrategy[Circle]:
    return st.builds(Circle, center=st.tuples(c, c), radius=r)


def squares(
    c: st.SearchStrategy[float] = coords, r: st.SearchStrategy[float] = sizes
) -> st.SearchStrategy[Square]:
    return st.builds(Square, center=st.tuples(c, c), half_side=r)


@st.composite
def rectangles(
    draw: st.DrawFn, c: st.SearchStrategy[float] = coords, r: st.SearchStrategy[float] = sizes
) -> Rectangle:
    x0, y0 = draw(c), draw(c)
    return Rectangle(xmin=x0, xmax=x0 + 2 * draw(r), ymin=y0, ymax=y0 + 2 * draw(r))


@st.composite
def polygons(draw: st.DrawFn, on_grid: bool = False) -> Polygon:
    """Star-shaped polygons (simple by construction), often non-convex."""
    n = draw(st.integers(3, 8))
    gaps = np.array(draw(st.lists(st.floats(0.3, 1.0), min_size=n, max_size=n)))
    angles = draw(st.floats(0, 2 * math.pi)) + np.cumsum(gaps / gaps.sum() * 2 * math.pi)
    radii = np.array(draw(st.lists(st.floats(0.5, 3.0), min_size=n, max_size=n)))
    center = np.array([draw(grid if on_grid else coords), draw(grid if on_grid else coords)])
    verts = center + radii[:, None] * np.c_[np.cos(angles), np.sin(angles)]
    if on_grid:
        verts = np.round(verts * 2) / 2
    try:
        return Polygon(vertices=tuple((float(x), float(y)) for x, y in verts))
    except ValueError:  # rounding to the grid made it degenerate
        return Polygon(vertices=((0.0, 0.0), (2.0, 0.0), (1.0, 1.5)))


def shapes(on_grid: bool = False) -> st.SearchStrategy[Obstacle]:
    c = grid if on_grid else coords
    r = grid_sizes if on_grid else sizes
    return st.one_of(circles(c, r), squares(c, r), rectangles(c, r), polygons(on_grid))


def points(on_grid: bool = False, max_n: int = 30) -> st.SearchStrategy[np.ndarray]:
    elements = grid if on_grid else st.floats(-8, 8, allow_nan=False, allow_infinity=False)
    return hnp.arrays(np.float64, st.tuples(st.integers(1, max_n), st.just(2)), elements=elements)


@st.composite
def segments(draw: st.DrawFn, on_grid: bool = False, max_n: int = 20) -> tuple[np.ndarray, np.ndarray]:
    n = draw(st.integers(1, max_n))
    elements = grid if on_grid else st.floats(-8, 8, allow_nan=False, allow_infinity=False)
    p = draw(hnp.arrays(np.float64, (n, 2), elements=elements))
    q = draw(hnp.arrays(np.float64, (n, 2), elements=elements))
    return p, q
