"""planners.milp: exact robustness (oracle against audere.stl), optimality against analytic answers and
brute force, statuses (infeasible, time limit), obstacles, both dynamics, bad inputs."""

from __future__ import annotations

import itertools
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from tests.doc_examples import expected_output, python_blocks

from audere import scenarios
from audere.apis._registry import _REGISTRY
from audere.errors import InvalidArgumentError
from audere.planners import MILPResult, milp
from audere.planners._milp import MIP_SOLVERS, installed_mip_solvers
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
    parse,
    robustness,
    satisfied,
)
from audere.world import Circle, Polygon, Rectangle, Square, Workspace, segments_intersect

WS = Workspace(xmin=0, xmax=10, ymin=0, ymax=10)
TOL = 1e-5  # encoded vs checked robustness: solver feasibility tolerance times the big-Ms

# --- random small formulas over box regions --------------------------------------------------------

REGIONS = {
    "A": Rectangle(xmin=1, xmax=3, ymin=6, ymax=9),
    "B": Rectangle(xmin=4, xmax=6, ymin=2, ymax=7),
    "C": Square(center=(8, 2), half_side=1.0),
    "W": Workspace(xmin=0.5, xmax=9.5, ymin=0.5, ymax=9.5),
}


def _formulas() -> st.SearchStrategy[Formula]:
    leaves = st.one_of(
        st.sampled_from([In("A"), In("B"), In("C"), In("W"), TRUE, FALSE]),
        st.builds(
            Compare,
            st.sampled_from([1.0, -1.0, 0.5, 0.0]),
            st.sampled_from([1.0, 2.0, -1.0]),
            st.sampled_from(["<=", ">="]),
            st.sampled_from([3.0, 7.5, 10.0]),
        ),
    )
    bounds = st.tuples(st.integers(0, 2), st.integers(0, 2)).map(lambda b: (b[0], b[0] + b[1]))

    def extend(children: st.SearchStrategy[Formula]) -> st.SearchStrategy[Formula]:
        pairs = st.lists(children, min_size=2, max_size=3).map(tuple)
        return st.one_of(
            children.map(Not),
            pairs.map(And),
            pairs.map(Or),
            st.builds(Implies, children, children),
            st.builds(lambda b, c: Always(b[0], b[1], c), bounds, children),
            st.builds(lambda b, c: Eventually(b[0], b[1], c), bounds, children),
            st.builds(lambda b, left, right: Until(b[0], b[1], left, right), bounds, children, children),
        )

    return st.recursive(leaves, extend, max_leaves=5)


def _finite(value: float | None) -> float:
    assert value is not None
    return value


@settings(max_examples=50)
@given(
    spec=_formulas(),
    start=st.tuples(st.floats(0.5, 9.5), st.floats(0.5, 9.5)),
    objective=st.sampled_from(["max_robustness", "min_effort"]),
    u=st.sampled_from([1.0, 2.5]),
    double=st.booleans(),
)
def test_encoded_robustness_equals_checker(
    spec: Formula, start: tuple[float, float], objective: str, u: float, double: bool
) -> None:
    horizon = spec.horizon() + 1
    x0 = (*start, 0.5, -0.5) if double else start
    # margin -100: every trajectory is allowed, so min_effort returns arbitrary (non-optimized) robustness
    result = milp(
        spec,
        REGIONS,
        x0,
        horizon=horizon,
        u_max=u,
        workspace=WS,
        objective=objective,  # type: ignore[arg-type]
        margin=-100.0,
        dynamics="double_integrator" if double else "single_integrator",
    )
    if not math.isfinite(robustness(spec, np.tile(start, (horizon + 1, 1)), REGIONS)):
        return  # constant formulas (true/false): nothing to encode
    if double and result.status == "infeasible":
        # braking at once (|a| = 0.5 <= u) stops at step 1, after drifting by (0.5, -0.5): only a start
        # within 1e-6 m (the program's clearance) of the boundary makes that step leave the workspace
        p1 = np.array(start) + np.array([0.5, -0.5])
        assert (p1 < 1e-6).any() or (p1 > 10 - 1e-6).any()
        return
    assert result.status == "solved", result.message
    states = _states(result)
    assert result.inputs is not None
    assert result.checked_robustness == pytest.approx(robustness(spec, states[:, :2], REGIONS), abs=1e-12)
    assert _finite(result.robustness) == pytest.approx(_finite(result.checked_robustness), abs=TOL)


def _brute_force(spec: Formula, start: tuple[float, float], u: float, steps: int, n: int) -> float:
    """Best robustness over trajectories whose inputs lie on an n x n grid of [-u, u]^2 (a lower bound
    of the true maximum, which the MILP must reach)."""
    grid = [np.array(v) for v in itertools.product(np.linspace(-u, u, n), repeat=2)]
    best = -math.inf
    for inputs in itertools.product(grid, repeat=steps):
        states = np.vstack([start, start + np.cumsum(inputs, axis=0)])
        if (states < 0).any() or (states > 10).any():
            continue
        best = max(best, robustness(spec, states, REGIONS))
    return best


@pytest.mark.parametrize(
    "text",
    [
        "F[1,2] in(A)",
        "G[0,2] !in(B) & F[2,2] (x >= 7 | in(C))",
        "(!in(B) U[0,2] in(A)) | F[0,2] y <= 3",
    ],
)
def test_max_robustness_reaches_brute_force(text: str) -> None:
    spec, start, u = parse(text), (3.5, 4.5), 2.5
    result = milp(spec, REGIONS, start, horizon=2, u_max=u, workspace=WS, margin=-100.0)  # type: ignore[arg-type]
    assert result.status == "solved"
    best_grid = _brute_force(spec, start, u, steps=2, n=7)
    assert _finite(result.robustness) >= best_grid - 1e-6
    assert _finite(result.robustness) == pytest.approx(_finite(result.checked_robustness), abs=TOL)


def test_max_robustness_analytic() -> None:
    # the most robust point of a 2 x 4 box is its centre line, robustness 1 (half the short side)
    goal = Rectangle(xmin=4, xmax=6, ymin=4, ymax=8)
    result = milp("F[3,3] in(G)", {"G": goal}, (0, 0), horizon=3, u_max=3, workspace=WS)
    assert result.status == "solved"
    assert _finite(result.robustness) == pytest.approx(1.0, abs=1e-6)
    assert _finite(result.checked_robustness) == pytest.approx(1.0, abs=1e-6)
    assert result.cost == pytest.approx(-1.0, abs=1e-6)


def test_min_effort_analytic() -> None:
    # the cheapest way into [5, 6] x [2, 3] by step 3 (L1 effort) ends at its corner, margin inside
    goal = Rectangle(xmin=5, xmax=6, ymin=2, ymax=3)
    margin = 0.01
    result = milp(
        "F[3,3] in(G)",
        {"G": goal},
        (0, 0),
        horizon=3,
        u_max=3,
        workspace=WS,
        objective="min_effort",
        margin=margin,
    )
    assert result.status == "solved"
    assert result.cost == pytest.approx((5 + margin) + (2 + margin), abs=1e-5)
    assert result.effort == pytest.approx(result.cost)
    assert _finite(result.robustness) == pytest.approx(margin, abs=1e-6)
    assert satisfied(parse("F[3,3] in(G)"), _states(result), {"G": goal})


def _states(result: MILPResult) -> np.ndarray:
    assert result.states is not None
    return np.asarray(result.states)


def test_robustness_cap_stops_early_and_stays_exact() -> None:
    goal = Rectangle(xmin=4, xmax=6, ymin=4, ymax=8)
    result = milp("F[3,3] in(G)", {"G": goal}, (0, 0), horizon=3, u_max=3, workspace=WS, robustness_cap=0.2)
    assert result.status == "solved"
    assert _finite(result.robustness) >= 0.2 - 1e-6
    assert result.cost == pytest.approx(-0.2, abs=1e-6)
    assert _finite(result.robustness) == pytest.approx(_finite(result.checked_robustness), abs=TOL)


def test_result_fields_and_rollout() -> None:
    task = scenarios.make("plan-stl", seed=3)
    result = milp(
        task.formula,
        task.regions,
        task.x0,
        horizon=task.horizon,
        u_max=task.u_max,  # type: ignore[arg-type]
        workspace=task.workspace,
        robustness_cap=0.1,
    )
    assert isinstance(result, MILPResult)
    assert result.status == "solved"
    assert result.solver == "HIGHS"
    assert "kOptimal" in result.solver_status
    states, inputs = _states(result), np.asarray(result.inputs)
    assert states.shape == (21, 2)
    assert inputs.shape == (20, 2)
    np.testing.assert_allclose(np.asarray(result.times), np.arange(21.0))
    np.testing.assert_array_equal(states[0], task.x0)
    np.testing.assert_allclose(np.diff(states, axis=0), inputs, atol=1e-12)
    assert np.abs(inputs).max() <= 4.0
    assert result.n_binaries > 100
    assert result.n_constraints > result.n_binaries
    assert result.n_variables > 0
    assert result.solve_time > 0
    assert _finite(result.checked_robustness) > 0
    assert task.check(result.to_solution()).success


def test_infeasible_spec() -> None:
    far = {"G": Rectangle(xmin=9, xmax=9.5, ymin=9, ymax=9.5)}
    result = milp("F[0,3] in(G)", far, (0, 0), horizon=3, u_max=1.0, workspace=WS)
    assert result.status == "infeasible"
    assert result.states is None
    assert result.robustness is None
    # a contradiction, whatever the speed
    result = milp("F[0,2] in(A) & G[0,2] !in(A)", REGIONS, (2, 7), horizon=2, u_max=3.0, workspace=WS)  # type: ignore[arg-type]
    assert result.status == "infeasible"
    # the margin asked for is more than the regions allow (the box is 2 m wide)
    result = milp("F[2,2] in(A)", REGIONS, (2, 7), horizon=2, u_max=3.0, workspace=WS, margin=1.5)  # type: ignore[arg-type]
    assert result.status == "infeasible"


def test_constant_specs() -> None:
    assert milp("false", {}, (1, 1), horizon=2, u_max=1, workspace=WS).status == "infeasible"
    result = milp("true | in(A)", REGIONS, (1, 1), horizon=2, u_max=1, workspace=WS)  # type: ignore[arg-type]
    assert result.status == "solved"
    assert result.robustness == math.inf


def _hard_problem(time_limit: float, solver: str | None = None) -> MILPResult:
    # many region visits in a long horizon: far from solved in a few milliseconds
    regions = {
        f"R{i}": Rectangle(xmin=i, xmax=i + 0.6, ymin=(3 * i) % 9, ymax=(3 * i) % 9 + 0.6) for i in range(9)
    }
    clauses = [f"F[0,40] in(R{i})" for i in range(9)] + [
        f"G[0,40] !in(R{i}) | F[0,40] in(R{(i + 1) % 9})" for i in range(9)
    ]
    return milp(
        " & ".join(clauses),
        regions,
        (0.2, 0.2),
        horizon=40,
        u_max=0.9,
        workspace=WS,  # type: ignore[arg-type]
        objective="min_effort",
        time_limit=time_limit,
        solver=solver,
    )


def test_time_limit() -> None:
    result = _hard_problem(0.05)
    assert result.status == "time_limit"
    assert "time limit" in result.message
    assert ("with an incumbent" in result.message) == (result.states is not None)
    assert result.solve_time < 30


def test_obstacles_are_avoided_segment_by_segment() -> None:
    wall = Rectangle(xmin=4, xmax=5, ymin=0, ymax=8)
    tri = Polygon(vertices=((6, 8.5), (8, 8.5), (7, 10)))
    disc = Circle(center=(7.5, 5), radius=1.0)
    goal = {"G": Rectangle(xmin=8, xmax=9.5, ymin=1, ymax=2)}
    result = milp(
        "F[6,8] in(G)",
        goal,
        (1, 1),
        horizon=8,
        u_max=3,
        workspace=WS,
        obstacles=[wall, tri, disc],
        objective="min_effort",
    )
    assert result.status == "solved", result.message
    states = _states(result)
    for shape in (wall, tri, disc):
        assert not segments_intersect(shape, states[:-1], states[1:]).any()
    assert _finite(result.checked_robustness) > 0
    # without the wall the straight route is cheaper
    free = milp("F[6,8] in(G)", goal, (1, 1), horizon=8, u_max=3, workspace=WS, objective="min_effort")
    assert _finite(free.cost) < _finite(result.cost) - 1


def test_double_integrator() -> None:
    goal = {"G": Rectangle(xmin=6, xmax=7, ymin=6, ymax=7)}
    result = milp(
        "F[6,8] in(G) & G[0,8] x >= 0.5",
        goal,
        (1, 1, 0, 0),
        horizon=8,
        dt=0.5,
        u_max=8.0,
        workspace=WS,
        dynamics="double_integrator",
    )
    assert result.status == "solved", result.message
    states, inputs = _states(result), np.asarray(result.inputs)
    assert states.shape == (9, 4)
    np.testing.assert_allclose(states[1:, :2], states[:-1, :2] + 0.5 * states[:-1, 2:], atol=1e-12)
    np.testing.assert_allclose(states[1:, 2:], states[:-1, 2:] + 0.5 * inputs, atol=1e-12)
    assert _finite(result.robustness) == pytest.approx(_finite(result.checked_robustness), abs=TOL)
    assert _finite(result.checked_robustness) > 0


def test_scipy_solver_agrees_with_highs() -> None:
    spec = "G[0,2] !in(B) & F[2,2] (x >= 7 | in(C))"
    # Optimum 0.5: x1 >= 4 + r to reach x >= 7 + r at step 2 puts step 1 beside B, so it passes
    # below B (y1 <= 2 - r) from y0 = 4.5 with |u| <= 3: r <= 0.5. (With u_max = 2.5 it would be 0.)
    kwargs: dict[str, object] = {"horizon": 2, "u_max": 3.0, "workspace": WS, "margin": -100.0}
    a = milp(spec, REGIONS, (2.5, 4.5), **kwargs)  # type: ignore[arg-type]
    b = milp(spec, REGIONS, (2.5, 4.5), solver="scipy", **kwargs)  # type: ignore[arg-type]
    assert a.status == "solved"
    assert _finite(a.robustness) == pytest.approx(0.5, abs=1e-6)
    assert b.solver == "SCIPY"
    assert b.status == "solved"
    assert _finite(a.robustness) == pytest.approx(_finite(b.robustness), abs=1e-6)


def test_deterministic() -> None:
    task = scenarios.make("plan-stl", seed=5)
    kwargs = {
        "horizon": task.horizon,
        "u_max": task.u_max,
        "workspace": task.workspace,
        "robustness_cap": 0.1,
    }
    a = milp(task.formula, task.regions, task.x0, **kwargs)  # type: ignore[arg-type]
    b = milp(task.formula, task.regions, task.x0, **kwargs)  # type: ignore[arg-type]
    np.testing.assert_array_equal(np.asarray(a.states), np.asarray(b.states))


def test_registered() -> None:
    info = _REGISTRY["milp"]
    assert info.function is milp
    assert "stl" in info.tags


# --- bad inputs ----------------------------------------------------------------------------------------

BOX = {"A": Rectangle(xmin=1, xmax=2, ymin=1, ymax=2)}
OK: dict[str, object] = {"horizon": 3, "u_max": 1.0, "workspace": WS}
UNINSTALLED = next((name for name in MIP_SOLVERS if name not in installed_mip_solvers()), None)

BAD = [
    ({"spec": 3}, "spec must be an STL Formula or its text, got int"),
    (
        {"regions": {"A": Circle(center=(1, 1), radius=1)}},
        r"regions\['A'\] must be an axis-aligned box .* Circle",
    ),
    ({"regions": {"A": Polygon(vertices=((0, 0), (1, 0), (0, 1)))}}, r"regions\['A'\] .* Polygon"),
    ({"regions": {}}, "regions is missing 'A'"),
    ({"regions": [1]}, "regions must be a mapping"),
    ({"horizon": 0}, "horizon must be an integer >= 1"),
    ({"horizon": 2.5}, "horizon must be an integer >= 1"),
    ({"spec": "F[0,5] in(A)"}, "horizon must be at least the spec's horizon 5"),
    ({"dt": 0.0}, "dt must be > 0, got 0.0"),
    ({"dt": math.nan}, "dt must be finite"),
    ({"x0": (1, 2, 3)}, r"x0 must have shape \(2,\) \(x, y\)"),
    ({"x0": (math.nan, 1)}, "x0"),
    ({"x0": (11, 1)}, "x0 must lie in the workspace"),
    ({"x0": (1, 1, 0, 0)}, r"x0 must have shape \(2,\)"),
    ({"x0": (1, 1), "dynamics": "double_integrator"}, r"x0 must have shape \(4,\)"),
    ({"dynamics": "unicycle"}, "dynamics must be 'single_integrator' or 'double_integrator'"),
    ({"u_max": (1, 2, 3)}, r"u_max must be a number or have shape \(2,\)"),
    ({"u_max": (1, math.nan)}, "u_max must not contain NaN"),
    ({"u_min": 2.0}, "u_min must be <= u_max on every axis"),
    ({"workspace": (0, 10, 0, 10)}, "workspace must be a Workspace or None"),
    ({"objective": "fastest"}, "objective must be 'max_robustness' or 'min_effort'"),
    ({"margin": math.inf}, "margin must be finite"),
    ({"margin": "big"}, "margin must be a number"),
    ({"robustness_cap": -1.0}, r"robustness_cap must be >= margin"),
    ({"big_m": -5.0}, "big_m must be > 0"),
    ({"time_limit": 0}, "time_limit must be > 0"),
    ({"solver": "NOPE"}, r"solver must be one of the MILP solvers .* \(installed here: HIGHS"),
    ({"solver": "OSQP"}, "solver must be one of the MILP solvers"),
    (
        {"obstacles": [Rectangle(xmin=0.5, xmax=1.5, ymin=0.5, ymax=1.5)]},
        r"x0 must lie outside every obstacle",
    ),
    (
        {"obstacles": [Polygon(vertices=((3, 3), (6, 3), (4, 4), (3, 6)))]},
        r"obstacles\[0\] must be convex",
    ),
    ({"obstacles": [Workspace()]}, r"obstacles\[0\] must be a Rectangle, Square, Circle or convex Polygon"),
    ({"obstacles": Rectangle(xmin=3, xmax=4, ymin=3, ymax=4)}, "obstacles must be a sequence of shapes"),
    ({"workspace": None, "u_max": None}, "big_m cannot be derived"),
]


@pytest.mark.parametrize(("change", "message"), BAD, ids=[f"bad{i}" for i in range(len(BAD))])
def test_bad_inputs(change: dict[str, object], message: str) -> None:
    args: dict[str, object] = {"spec": "F[0,3] in(A)", "regions": BOX, "x0": (1, 1), **OK, **change}
    with pytest.raises(InvalidArgumentError, match=message):
        milp(**args)  # type: ignore[arg-type]


@pytest.mark.skipif(UNINSTALLED is None, reason="every MILP solver cvxpy knows is installed")
def test_uninstalled_solver_lists_the_installed_ones() -> None:
    with pytest.raises(
        InvalidArgumentError,
        match=rf"solver '{UNINSTALLED}' is not installed; installed MILP solvers: .*HIGHS",
    ):
        milp("F[0,3] in(A)", BOX, (1, 1), horizon=3, u_max=1.0, workspace=WS, solver=UNINSTALLED)


def test_user_big_m_keeps_the_encoding_exact() -> None:
    result = milp(
        "F[1,3] in(A) | G[0,3] y <= 1.5", BOX, (3, 3), horizon=3, u_max=1.0, workspace=WS, big_m=100.0
    )
    assert result.status == "solved"
    assert _finite(result.robustness) == pytest.approx(_finite(result.checked_robustness), abs=1e-4)


def test_unbounded_positions_with_big_m() -> None:
    # no workspace, no input bounds: the user's big_m makes the encoding possible; the cap keeps it bounded
    result = milp("F[2,2] x >= 3", {}, (0, 0), horizon=2, workspace=None, big_m=1e3, robustness_cap=5.0)
    assert result.status == "solved"
    assert _finite(result.robustness) == pytest.approx(5.0, abs=1e-6)


def test_constant_folding_of_until_and_windows() -> None:
    # robustness of folded formulas still matches the checker
    for text in [
        "true U[1,2] in(A)",
        "in(A) U[1,2] true",
        "false U[0,2] in(A)",
        "G[0,1] true & F[0,2] in(A)",
    ]:
        spec = parse(text)
        result = milp(spec, BOX, (3, 3), horizon=3, u_max=2.0, workspace=WS, margin=-100.0)
        value = robustness(spec, _states(result), BOX)
        assert _finite(result.robustness) == pytest.approx(value, abs=TOL), text
    _ = And, Or, Eventually  # imported for the strategies above


# --- the examples of docs/apis/milp.md ------------------------------------------------------------------

DOC = Path(__file__).resolve().parents[2] / "docs" / "apis" / "milp.md"
DOC_BLOCKS = python_blocks(DOC)


def test_the_page_has_examples() -> None:
    assert len(DOC_BLOCKS) >= 2


@pytest.mark.parametrize("source", DOC_BLOCKS, ids=[f"block{i}" for i in range(len(DOC_BLOCKS))])
def test_doc_example_prints_what_it_says(source: str, capsys: pytest.CaptureFixture[str]) -> None:
    exec(compile(source, str(DOC), "exec", dont_inherit=True), {"__name__": "docs_milp"})
    assert capsys.readouterr().out.splitlines() == expected_output(source)


def test_time_limit_with_scipy() -> None:
    # scipy.optimize.milp reports a stop at its time limit as "optimal_inaccurate": still a time limit
    result = _hard_problem(0.3, solver="SCIPY")
    assert result.status == "time_limit", result.message


def test_obstacle_blocking_every_reachable_position_is_infeasible() -> None:
    # the inputs are pinned to (0, 0.1): step 1 is (1, 1.25), inside the obstacle
    cover = Rectangle(xmin=0.4, xmax=1.6, ymin=1.2, ymax=3.0)
    result = milp(
        "F[0,2] x >= 0",
        {},
        (1, 1.15),
        horizon=2,
        u_min=(0, 0.1),
        u_max=(0, 0.1),
        workspace=WS,
        obstacles=[cover],
    )
    assert result.status == "infeasible"
    assert "outside obstacles[0]" in result.message
