"""Robustness and boolean semantics against a direct, recursive reference implementation; the sign
property linking them; negation normal form; region predicates; argument validation."""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from functools import cache

import numpy as np
import pytest
import shapely
from hypothesis import given
from hypothesis import strategies as st

from audere.errors import InvalidArgumentError
from audere.stl import (
    FALSE,
    TRUE,
    Always,
    And,
    Compare,
    Constant,
    Eventually,
    Formula,
    Implies,
    In,
    Not,
    Or,
    Until,
    parse,
    robustness,
    robustness_trace,
    satisfied,
    to_nnf,
)
from audere.world import Circle, Polygon, Rectangle, Square, Workspace

from .stl_strategies import REGIONS, signals, small_formulas

# --- the reference: the textbook definitions, one step at a time, in plain Python ----------------


def _region_value(shape: object, x: float, y: float) -> float:
    if isinstance(shape, Circle):
        return shape.radius - math.dist((x, y), shape.center)
    if isinstance(shape, Polygon):
        polygon, point = shapely.Polygon(shape.vertices), shapely.Point(x, y)
        distance = polygon.exterior.distance(point)
        return distance if polygon.contains(point) else -distance
    if isinstance(shape, Square):
        (cx, cy), h = shape.center, shape.half_side
        xmin, xmax, ymin, ymax = cx - h, cx + h, cy - h, cy + h
    else:
        assert isinstance(shape, Rectangle | Workspace)
        xmin, xmax, ymin, ymax = shape.xmin, shape.xmax, shape.ymin, shape.ymax
    return min(x - xmin, xmax - x, y - ymin, ymax - y)


def _region_inside(shape: object, x: float, y: float) -> bool:
    if isinstance(shape, Circle):
        return math.dist((x, y), shape.center) < shape.radius
    if isinstance(shape, Polygon):
        return bool(shapely.Polygon(shape.vertices).contains(shapely.Point(x, y)))
    if isinstance(shape, Square):
        (cx, cy), h = shape.center, shape.half_side
        return cx - h < x < cx + h and cy - h < y < cy + h
    assert isinstance(shape, Rectangle | Workspace)
    return shape.xmin < x < shape.xmax and shape.ymin < y < shape.ymax


def reference_robustness(
    positions: np.ndarray, regions: Mapping[str, object]
) -> Callable[[Formula, int], float]:
    @cache
    def rho(f: Formula, t: int) -> float:
        x, y = float(positions[t, 0]), float(positions[t, 1])
        if isinstance(f, Constant):
            return math.inf if f.value else -math.inf
        if isinstance(f, In):
            return _region_value(regions[f.name], x, y)
        if isinstance(f, Compare):
            s = f.a * x + f.b * y
            return s - f.rhs if f.op == ">=" else f.rhs - s
        if isinstance(f, Not):
            return -rho(f.child, t)
        if isinstance(f, And):
            return min(rho(c, t) for c in f.operands)
        if isinstance(f, Or):
            return max(rho(c, t) for c in f.operands)
        if isinstance(f, Implies):
            return max(-rho(f.left, t), rho(f.right, t))
        if isinstance(f, Always):
            return min(rho(f.child, s) for s in range(t + f.lo, t + f.hi + 1))
        if isinstance(f, Eventually):
            return max(rho(f.child, s) for s in range(t + f.lo, t + f.hi + 1))
        assert isinstance(f, Until)
        return max(
            min(rho(f.right, s), min((rho(f.left, r) for r in range(t, s)), default=math.inf))
            for s in range(t + f.lo, t + f.hi + 1)
        )

    return rho


def reference_truth(positions: np.ndarray, regions: Mapping[str, object]) -> Callable[[Formula, int], bool]:
    @cache
    def holds(f: Formula, t: int) -> bool:
        x, y = float(positions[t, 0]), float(positions[t, 1])
        if isinstance(f, Constant):
            return f.value
        if isinstance(f, In):
            return _region_inside(regions[f.name], x, y)
        if isinstance(f, Compare):
            s = f.a * x + f.b * y
            return s >= f.rhs if f.op == ">=" else s <= f.rhs
        if isinstance(f, Not):
            return not holds(f.child, t)
        if isinstance(f, And):
            return all(holds(c, t) for c in f.operands)
        if isinstance(f, Or):
            return any(holds(c, t) for c in f.operands)
        if isinstance(f, Implies):
            return not holds(f.left, t) or holds(f.right, t)
        if isinstance(f, Always):
            return all(holds(f.child, s) for s in range(t + f.lo, t + f.hi + 1))
        if isinstance(f, Eventually):
            return any(holds(f.child, s) for s in range(t + f.lo, t + f.hi + 1))
        assert isinstance(f, Until)
        return any(
            holds(f.right, s) and all(holds(f.left, r) for r in range(t, s))
            for s in range(t + f.lo, t + f.hi + 1)
        )

    return holds


def _close(a: float, b: float) -> bool:
    return a == b or math.isclose(a, b, rel_tol=1e-12, abs_tol=1e-12)


# --- properties -------------------------------------------------------------------------------------


@st.composite
def cases(draw: st.DrawFn, *, grid: bool) -> tuple[Formula, np.ndarray]:
    formula = draw(small_formulas)
    extra = draw(st.integers(0, 4))
    return formula, draw(signals(rows=formula.horizon() + 1 + extra, grid=grid))


@given(cases(grid=False))
def test_robustness_trace_matches_the_reference(case: tuple[Formula, np.ndarray]) -> None:
    formula, positions = case
    trace = robustness_trace(formula, positions, REGIONS)
    assert trace.shape == (len(positions) - formula.horizon(),)
    rho = reference_robustness(positions, REGIONS)
    for t, value in enumerate(trace):
        assert _close(value, rho(formula, t)), (t, value, rho(formula, t))
        assert robustness(formula, positions, REGIONS, t=t) == value


@given(cases(grid=True))
def test_satisfied_matches_the_reference(case: tuple[Formula, np.ndarray]) -> None:
    # On the 0.5 grid, signals often sit exactly on region boundaries and comparison lines.
    formula, positions = case
    holds = reference_truth(positions, REGIONS)
    for t in range(len(positions) - formula.horizon()):
        assert satisfied(formula, positions, REGIONS, t=t) == holds(formula, t)


@pytest.mark.parametrize(
    "atom",
    [
        *(In(name) for name in REGIONS),
        Compare(1, 0, ">=", 1),
        Compare(0.5, -1, "<=", -1),
        Compare(-1, 2, ">=", 2.5),
    ],
    ids=str,
)
def test_predicates_on_a_grid_through_their_boundaries(atom: Formula) -> None:
    """Every point of the 0.5 grid, many of them on a region boundary or comparison line."""
    grid = np.array([(i * 0.5, j * 0.5) for i in range(-1, 12) for j in range(-1, 12)])
    rho, holds = reference_robustness(grid, REGIONS), reference_truth(grid, REGIONS)
    trace = robustness_trace(atom, grid, REGIONS)
    on_boundary = 0
    for t in range(len(grid)):
        assert _close(trace[t], rho(atom, t))
        assert satisfied(atom, grid, REGIONS, t=t) == holds(atom, t)
        assert satisfied(Not(atom), grid, REGIONS, t=t) == (not holds(atom, t))
        on_boundary += trace[t] == 0
    assert on_boundary >= 3  # the grid really goes through the boundary


@given(cases(grid=True) | cases(grid=False))
def test_robustness_sign_agrees_with_satisfaction(case: tuple[Formula, np.ndarray]) -> None:
    formula, positions = case
    for t, value in enumerate(robustness_trace(formula, positions, REGIONS)):
        if value > 0:
            assert satisfied(formula, positions, REGIONS, t=t)
        elif value < 0:
            assert not satisfied(formula, positions, REGIONS, t=t)


def _is_nnf(f: Formula) -> bool:
    if isinstance(f, Not):
        return isinstance(f.child, In | Compare)
    if isinstance(f, Implies):
        return False
    return all(_is_nnf(c) for c in f.children())


@given(cases(grid=True) | cases(grid=False))
def test_to_nnf_preserves_robustness_and_truth(case: tuple[Formula, np.ndarray]) -> None:
    formula, positions = case
    for f in (formula, Not(formula)):
        nnf = to_nnf(f)
        assert _is_nnf(nnf)
        assert nnf.horizon() <= f.horizon()
        assert nnf.regions() <= f.regions()
        expected = robustness_trace(f, positions, REGIONS)
        assert np.array_equal(robustness_trace(nnf, positions, REGIONS)[: len(expected)], expected)
        for t in range(len(expected)):
            assert satisfied(nnf, positions, REGIONS, t=t) == satisfied(f, positions, REGIONS, t=t)


def test_to_nnf_rewrites() -> None:
    A, B = In("A"), In("B")
    assert to_nnf(parse("!!in(A)")) == A
    assert to_nnf(parse("!(in(A) & !in(B))")) == Or((Not(A), B))
    assert to_nnf(parse("!G[1,4] (in(A) | in(B))")) == Eventually(1, 4, And((Not(A), Not(B))))
    assert to_nnf(parse("!F[0,2] !true")) == Always(0, 2, TRUE)
    assert to_nnf(parse("in(A) -> in(B)")) == Or((Not(A), B))
    assert to_nnf(parse("!(in(A) -> in(B))")) == And((A, Not(B)))
    assert to_nnf(parse("!(in(A) U[0,2] in(B))")) == parse(
        "!in(B) & (G[1,1] !in(B) | F[0,0] !in(A)) & (G[2,2] !in(B) | F[0,1] !in(A))"
    )
    assert to_nnf(parse("!(in(A) U[3,3] in(B))")) == parse("G[3,3] !in(B) | F[0,2] !in(A)")
    assert to_nnf(parse("!x >= 1")) == parse("!x >= 1")  # negated predicates stay
    assert to_nnf(FALSE) == FALSE
    with pytest.raises(InvalidArgumentError, match="formula must be an STL Formula, got str"):
        to_nnf("in(A)")  # type: ignore[arg-type]


# --- hand-computed values ---------------------------------------------------------------------------

LINE = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [3.0, 0.0], [4.0, 0.0], [5.0, 0.0]])


@pytest.mark.parametrize(
    ("text", "trace"),
    [
        ("x >= 2", [-2, -1, 0, 1, 2, 3]),
        ("2*x - y <= 3", [3, 1, -1, -3, -5, -7]),
        ("G[0,2] x >= 2", [-2, -1, 0, 1]),
        ("F[1,3] x <= 1", [0, -1, -2]),
        # l U r at t: max over k of min(r(t+k), l(t), ..., l(t+k-1))
        ("(x <= 3) U[0,5] (x >= 4)", [0]),  # k=4: min(r=0, l=3,2,1,0)
        ("(x <= 3) U[1,3] (x >= 2)", [1, 1, 1]),
        ("(x <= 0.5) U[1,3] (x >= 2)", [-0.5, -0.5, -1.5]),
        ("true U[2,3] x >= 4", [-1, 0, 1]),
        ("!F[0,1] x >= 4", [3, 2, 1, 0, -1]),
        ("x >= 1 -> x >= 4", [1, 0, -1, -1, 0, 1]),
        ("G[0,1] true", [math.inf] * 5),
        ("F[0,1] false", [-math.inf] * 5),
    ],
)
def test_hand_computed_traces(text: str, trace: list[float]) -> None:
    assert robustness_trace(text, LINE, {}).tolist() == trace


@pytest.mark.parametrize(
    ("text", "truth"),
    [
        ("x >= 2", [False, False, True, True, True, True]),  # on the line: a comparison holds
        ("x <= 2", [True, True, True, False, False, False]),
        ("!(x >= 2)", [True, True, False, False, False, False]),
        ("G[0,2] x >= 2", [False, False, True, True]),
        ("F[1,3] x <= 1", [True, False, False]),
        ("(x <= 3) U[0,5] (x >= 4)", [True]),  # robustness 0, and it holds
        ("(x <= 2) U[0,5] (x >= 4)", [False]),
        ("(x <= 3) U[1,3] (x >= 4)", [False, True, True]),  # t=0: x >= 4 first at step 4 > 0+3
        ("x >= 1 -> x >= 4", [True, False, False, False, True, True]),
    ],
)
def test_hand_computed_truth(text: str, truth: list[bool]) -> None:
    assert [satisfied(text, LINE, {}, t=t) for t in range(len(truth))] == truth


def test_region_kinds() -> None:
    points = np.array([[1.0, 1.0], [3.0, 1.0], [2.0, 3.5], [6.0, 6.0], [0.0, 0.0]])
    regions = {
        "R": Rectangle(xmin=0.0, xmax=4.0, ymin=0.0, ymax=2.0),
        "S": Square(center=(1.0, 1.0), half_side=0.5),
        "W": Workspace(xmin=0.0, xmax=10.0, ymin=0.0, ymax=10.0),
        "C": Circle(center=(0.0, 0.0), radius=2.0),
        # a right triangle; inside, the signed distance is the distance to the nearest edge
        "P": Polygon(vertices=((0.0, 0.0), (4.0, 0.0), (0.0, 4.0))),
    }
    expected = {
        "R": [1.0, 1.0, -1.5, -4.0, 0.0],
        "S": [0.5, -1.5, -2.0, -4.5, -0.5],  # box: min of the four margins, not the Euclidean distance
        "W": [1.0, 1.0, 2.0, 4.0, 0.0],
        "C": [2 - math.sqrt(2), 2 - math.sqrt(10), 2 - math.hypot(2, 3.5), 2 - math.hypot(6, 6), 2.0],
        "P": [1.0, 0.0, -1.5 / math.sqrt(2), -8 / math.sqrt(2), 0.0],
    }
    for name, values in expected.items():
        trace = robustness_trace(f"in({name})", points, regions)
        np.testing.assert_allclose(trace, values, rtol=0, atol=1e-12, err_msg=name)
    # truth: strictly inside; the boundary is outside
    assert [satisfied("in(R)", points, regions, t=t) for t in range(5)] == [True, True, False, False, False]
    assert [satisfied("in(P)", points, regions, t=t) for t in range(5)] == [True, False, False, False, False]
    assert [satisfied("!in(C)", points, regions, t=t) for t in range(5)] == [False, True, True, True, False]


# --- validation -------------------------------------------------------------------------------------

REGION_A = {"A": Rectangle(xmin=0.0, xmax=1.0, ymin=0.0, ymax=1.0)}
P3 = np.zeros((3, 2))


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (
            lambda: robustness("in(A)", np.zeros((3, 3)), REGION_A),
            r"positions must have shape \(k, 2\), got shape \(3, 3\)",
        ),
        (
            lambda: robustness("in(A)", np.zeros(2), REGION_A),
            r"positions must have shape \(k, 2\), got shape \(2,\)",
        ),
        (lambda: robustness("in(A)", np.zeros((0, 2)), REGION_A), r"positions must have at least one row"),
        (
            lambda: robustness("in(A)", [[0, np.nan]], REGION_A),
            r"positions must be finite, got nan at index \[0, 1\]",
        ),
        (lambda: robustness("in(A)", "abc", REGION_A), r"positions must be an array of numbers, got str"),
        (
            lambda: robustness("in(A) & in(B) | in(C)", P3, REGION_A),
            r"regions is missing 'B', 'C', used by the formula \(given: A\)",
        ),
        (lambda: satisfied("in(Z)", P3, {}), r"regions is missing 'Z', used by the formula \(given: none\)"),
        (
            lambda: robustness("in(A)", P3, [("A", 1)]),
            r"regions must be a mapping from region name to shape, got list",
        ),
        (
            lambda: robustness("in(A)", P3, {"A": (0, 1, 0, 1)}),
            r"regions\['A'\] must be a Circle, .* got tuple",
        ),
        (lambda: robustness("in(A)", P3, REGION_A, t=-1), r"t must be >= 0, got -1"),
        (lambda: robustness("in(A)", P3, REGION_A, t=1.0), r"t must be an integer step, got float 1.0"),
        (lambda: satisfied("in(A)", P3, REGION_A, t=True), r"t must be an integer step, got bool"),
        (
            lambda: robustness("G[0,5] in(A)", P3, REGION_A),
            r"positions is too short for the formula at t=0: it needs 5 steps after t, that is 6 rows "
            r"\(steps 0..5\), got 3 rows \(steps 0..2\)",
        ),
        (
            lambda: satisfied("F[0,1] in(A)", P3, REGION_A, t=2),
            r"positions is too short for the formula at t=2: it needs 1 steps after t, that is 4 rows",
        ),
        (lambda: robustness_trace("G[3,3] in(A)", P3, REGION_A), r"it needs 3 steps after t, that is 4 rows"),
        (lambda: robustness(42, P3, REGION_A), r"formula must be an STL Formula or its text, got int 42"),
        (lambda: robustness("in(A", P3, REGION_A), r"expected '\)' after region name"),
    ],
)
def test_bad_arguments(call: Callable[[], object], message: str) -> None:
    with pytest.raises(InvalidArgumentError, match=message):
        call()


def test_accepts_lists_numpy_integers_and_extra_regions() -> None:
    regions = {**REGION_A, "unused": Circle(center=(5.0, 5.0), radius=1.0)}
    positions = [[0.5, 0.5], [2, 2], [0.5, 0.25]]
    assert robustness("in(A)", positions, regions, t=np.int64(2)) == 0.25
    assert satisfied(In("A"), positions, regions)
    assert robustness_trace(In("A"), positions, regions).tolist() == [0.5, -1.0, 0.25]


def test_long_signal_and_wide_windows() -> None:
    """Performance sanity (not timed): a long signal with wide windows, spot-checked."""
    rng = np.random.default_rng(7)
    positions = np.cumsum(rng.normal(0.0, 0.1, size=(5001, 2)), axis=0) + 2.5
    formula = parse(
        "G[0,400] (!in(B) | F[0,50] in(A)) & (!in(C) U[10,300] (in(D) & x >= 1)) | F[100,1000] G[0,30] in(P)"
    )
    trace = robustness_trace(formula, positions, REGIONS)
    assert trace.shape == (5001 - formula.horizon(),)
    expected = [robustness(formula, positions, REGIONS, t=t) for t in (0, 17, 2000, len(trace) - 1)]
    assert trace[[0, 17, 2000, len(trace) - 1]].tolist() == expected
    # spot-check one step against the reference on a short window
    short = positions[1000 : 1000 + formula.horizon() + 1]
    assert _close(robustness(formula, short, REGIONS), reference_robustness(short, REGIONS)(formula, 0))
    assert trace[1000] == robustness(formula, short, REGIONS)
