"""A* on grids and graphs: oracles (scipy's Dijkstra, hand examples, shapely), bad inputs, limits."""

from __future__ import annotations

import doctest
import math
import time
from pathlib import Path

import numpy as np
import pytest
import shapely
from hypothesis import given
from hypothesis import strategies as st
from pydantic import ValidationError
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra
from tests.doc_examples import expected_output, python_blocks

from audere import scenarios
from audere.errors import InvalidArgumentError
from audere.planners import (
    AStarResult,
    OccupancyGrid,
    astar,
    astar_graph,
    cell_graph,
    occupancy_grid,
    shortcut,
)
from audere.planners._astar import _grid_heuristic
from audere.tasks import Solution
from audere.world import Circle, Rectangle, Square, Workspace, World

# ---------------------------------------------------------------------------------------- references


def reference_graph(blocked: np.ndarray, connectivity: int, h: float) -> coo_matrix:
    """The grid graph written out edge by edge (no corner cutting), independently of the planner."""
    rows, cols = blocked.shape
    src, dst, w = [], [], []
    moves = [(0, 1), (1, 0), (0, -1), (-1, 0)]
    if connectivity == 8:
        moves += [(1, 1), (1, -1), (-1, 1), (-1, -1)]

    def free(r: int, c: int) -> bool:
        return 0 <= r < rows and 0 <= c < cols and not blocked[r, c]

    for r in range(rows):
        for c in range(cols):
            if not free(r, c):
                continue
            for dr, dc in moves:
                if not free(r + dr, c + dc):
                    continue
                if dr and dc and not (free(r + dr, c) and free(r, c + dc)):
                    continue
                src.append(r * cols + c)
                dst.append((r + dr) * cols + c + dc)
                w.append(h * math.hypot(dr, dc))
    n = rows * cols
    return coo_matrix((w, (src, dst)), shape=(n, n)).tocsr()


def grid_of(blocked: np.ndarray, h: float = 1.0) -> OccupancyGrid:
    return OccupancyGrid(origin=(0.0, 0.0), resolution=h, blocked=blocked)


def random_blocked(rng: np.random.Generator, rows: int, cols: int, density: float) -> np.ndarray:
    return rng.random((rows, cols)) < density


# ------------------------------------------------------------------------------------------- oracles


@pytest.mark.parametrize(
    ("connectivity", "heuristic"),
    [(8, "octile"), (8, "euclidean"), (8, "zero"), (4, "manhattan"), (4, "octile"), (4, "euclidean")],
)
def test_cost_equals_dijkstra_on_random_grids(connectivity: int, heuristic: str) -> None:
    rng = np.random.default_rng(connectivity)
    solved = infeasible = 0
    for _ in range(40):
        rows, cols = rng.integers(2, 25, size=2)
        blocked = random_blocked(rng, rows, cols, rng.uniform(0.0, 0.45))
        h = float(rng.choice([0.1, 0.5, 1.0]))
        grid = grid_of(blocked, h)
        free = np.argwhere(~blocked)
        if len(free) < 2:
            continue
        a, b = free[rng.choice(len(free), size=2, replace=False)]
        dist = dijkstra(reference_graph(blocked, connectivity, h), indices=a[0] * cols + a[1])
        expected = dist[b[0] * cols + b[1]]
        result = astar(
            grid, grid.to_world(a), grid.to_world(b), connectivity=connectivity, heuristic=heuristic
        )
        if np.isinf(expected):
            assert result.status == "infeasible"
            assert result.cells is None
            assert result.waypoints is None
            infeasible += 1
            continue
        solved += 1
        assert result.status == "solved"
        assert result.cost == pytest.approx(expected, rel=1e-9, abs=1e-12)
        cells = np.array(result.cells)
        assert tuple(cells[0]) == tuple(a)
        assert tuple(cells[-1]) == tuple(b)
        assert not blocked[cells[:, 0], cells[:, 1]].any()
        steps = np.abs(np.diff(cells, axis=0))
        assert steps.max() <= 1
        assert (steps.sum(axis=1) >= 1).all()
        if connectivity == 4:
            assert (steps.sum(axis=1) == 1).all()
        # waypoints are the cell centres; their length is the cost
        np.testing.assert_allclose(result.waypoints, grid.to_world(cells))
    assert solved >= 10
    assert infeasible >= 1


def test_heuristics_are_admissible_and_consistent() -> None:
    rng = np.random.default_rng(3)
    for connectivity, names in (
        (8, ("octile", "euclidean", "zero")),
        (4, ("manhattan", "octile", "euclidean")),
    ):
        blocked = random_blocked(rng, 15, 17, 0.25)
        goal = tuple(int(v) for v in np.argwhere(~blocked)[0])
        graph = reference_graph(blocked, connectivity, 1.0)
        true = dijkstra(graph.T, indices=goal[0] * 17 + goal[1])  # distance *to* the goal
        coo = graph.tocoo()
        for name in names:
            h = _grid_heuristic(name, 15, 17, goal)
            reachable = np.isfinite(true)
            assert (h[reachable] <= true[reachable] + 1e-12).all(), name
            assert (h[coo.row] <= coo.data + h[coo.col] + 1e-12).all(), name  # consistency
            assert h[goal[0] * 17 + goal[1]] == 0


def test_hand_examples() -> None:
    empty = grid_of(np.zeros((3, 3), dtype=bool), 0.5)
    diag = astar(empty, (0.25, 0.25), (1.25, 1.25))
    assert diag.cells == ((0, 0), (1, 1), (2, 2))
    assert diag.cost == pytest.approx(2 * 0.5 * math.sqrt(2))
    four = astar(empty, (0.25, 0.25), (1.25, 1.25), connectivity=4, heuristic="manhattan")
    assert four.cost == pytest.approx(2.0)
    assert len(four.cells or ()) == 5
    # no corner cutting: (0,1) blocked forbids the diagonal (0,0) -> (1,1)
    blocked = np.zeros((2, 2), dtype=bool)
    blocked[0, 1] = True
    corner = astar(grid_of(blocked), (0.5, 0.5), (1.5, 1.5))
    assert corner.cells == ((0, 0), (1, 0), (1, 1))
    assert corner.cost == pytest.approx(2.0)
    # a wall with one gap at the top: the path detours through it
    wall = np.zeros((5, 5), dtype=bool)
    wall[:4, 2] = True
    detour = astar(grid_of(wall), (0.5, 0.5), (4.5, 0.5))
    assert (4, 2) in (detour.cells or ())
    oracle = dijkstra(reference_graph(wall, 8, 1.0), indices=0)[4]
    assert detour.cost == pytest.approx(oracle)
    # start and goal off the cell centres: the waypoints begin and end exactly there
    off = astar(empty, (0.1, 0.2), (1.4, 1.3))
    np.testing.assert_allclose(off.waypoints[[0, -1]], [[0.1, 0.2], [1.4, 1.3]])
    assert off.cost == pytest.approx(float(np.linalg.norm(np.diff(off.waypoints, axis=0), axis=1).sum()))
    same = astar(empty, (0.1, 0.1), (0.2, 0.2))
    assert same.solved
    assert same.cells == ((0, 0),)
    assert same.waypoints.shape == (3, 2)


def test_to_solution_passes_a_path_task() -> None:
    task = scenarios.make("plan-hard", seed=1)
    grid = occupancy_grid(task.world(inflated=False), resolution=0.05, margin=task.margin)
    result = astar(grid, task.start, task.goal)
    assert isinstance(result, AStarResult)
    assert result.solved
    assert task.check(result.to_solution()).success


# --------------------------------------------------------------------------------- occupancy grids

shapes = st.one_of(
    st.builds(
        lambda x, y, r: Circle(center=(x, y), radius=r),
        st.floats(0, 4),
        st.floats(0, 3),
        st.floats(0.05, 0.8),
    ),
    st.builds(
        lambda x, y, s: Square(center=(x, y), half_side=s),
        st.floats(0, 4),
        st.floats(0, 3),
        st.floats(0.05, 0.6),
    ),
    st.builds(
        lambda x, y, w, h: Rectangle(xmin=x, xmax=x + w, ymin=y, ymax=y + h),
        st.floats(-0.5, 4),
        st.floats(-0.5, 3),
        st.floats(0.05, 1.5),
        st.floats(0.05, 1.5),
    ),
)


def shapely_of(shape: Circle | Square | Rectangle) -> shapely.Geometry:
    if isinstance(shape, Circle):
        return shapely.Point(shape.center)  # distance minus the radius below
    if isinstance(shape, Square):
        (x, y), s = shape.center, shape.half_side
        return shapely.box(x - s, y - s, x + s, y + s)
    return shapely.box(shape.xmin, shape.ymin, shape.xmax, shape.ymax)


@given(
    obstacles=st.lists(shapes, min_size=1, max_size=5),
    resolution=st.sampled_from([0.1, 0.17, 0.25]),
    margin=st.sampled_from([0.0, 0.05, 0.2]),
)
def test_free_cells_keep_the_margin_shapely(
    obstacles: list[Circle | Square | Rectangle], resolution: float, margin: float
) -> None:
    world = World(workspace=Workspace(xmin=0, xmax=4, ymin=0, ymax=3), obstacles=tuple(obstacles))
    grid = occupancy_grid(world, resolution=resolution, margin=margin)
    rows, cols = grid.shape
    assert rows == math.ceil(3 / resolution - 1e-9)
    assert cols == math.ceil(4 / resolution - 1e-9)
    free = np.argwhere(~grid.blocked)
    x0 = free[:, 1] * resolution
    y0 = free[:, 0] * resolution
    boxes = shapely.box(x0, y0, x0 + resolution, y0 + resolution)
    for shape in obstacles:
        d = shapely.distance(boxes, shapely_of(shape))
        if isinstance(shape, Circle):
            d = d - shape.radius
        assert (d >= margin - 1e-9).all()
    # and the centres of free cells lie in the workspace
    assert world.in_workspace(grid.to_world(free)).all()


@given(
    obstacles=st.lists(shapes, min_size=1, max_size=6),
    margin=st.sampled_from([0.0, 0.1, 0.2]),
    ends=st.lists(st.tuples(st.floats(0, 4), st.floats(0, 3)), min_size=2, max_size=2),
)
def test_waypoints_are_collision_free_in_the_inflated_world(
    obstacles: list[Circle | Square | Rectangle], margin: float, ends: list[tuple[float, float]]
) -> None:
    world = World(workspace=Workspace(xmin=0, xmax=4, ymin=0, ymax=3), obstacles=tuple(obstacles))
    grid = occupancy_grid(world, resolution=0.1, margin=margin)
    result = astar(grid, ends[0], ends[1])
    start_cell, goal_cell = (tuple(c) for c in grid.to_cell(np.array(ends)))
    if grid.blocked[start_cell] or grid.blocked[goal_cell]:
        assert result.status == "infeasible"
        assert "blocked" in result.message
        return
    if result.solved:
        assert result.waypoints is not None
        grown = world.inflate(margin) if margin else world
        assert grown.first_collision(result.waypoints) is None
        assert world.in_workspace(result.waypoints).all()
        smooth = shortcut(result.waypoints, grown)
        assert grown.first_collision(smooth) is None
    else:
        assert result.status == "infeasible"


def test_grid_conversions() -> None:
    grid = OccupancyGrid(origin=(1.0, -2.0), resolution=0.5, blocked=np.zeros((4, 6), dtype=bool))
    cells = np.array([[0, 0], [3, 5], [2, 1]])
    np.testing.assert_array_equal(grid.to_cell(grid.to_world(cells)), cells)
    np.testing.assert_allclose(grid.to_world((0, 0)), [1.25, -1.75])
    np.testing.assert_array_equal(grid.to_cell((4.0, 0.0)), [3, 5])  # upper-right corner: last cell
    assert grid.contains([[1.0, -2.0], [4.0, 0.0]]).all()
    assert not grid.contains((0.9, 0.0))
    assert not grid.blocked.flags.writeable
    assert grid.shape == (4, 6)
    round_trip = OccupancyGrid.model_validate_json(grid.model_dump_json())
    np.testing.assert_array_equal(round_trip.blocked, grid.blocked)


# ------------------------------------------------------------------------------------ graph search


def test_graph_cost_equals_dijkstra() -> None:
    rng = np.random.default_rng(7)
    for _ in range(20):
        n = int(rng.integers(2, 30))
        xy = rng.uniform(0, 10, size=(n, 2))
        edges = []
        for _ in range(int(rng.integers(1, 3 * n))):
            u, v = (int(i) for i in rng.integers(0, n, size=2))
            w = float(np.linalg.norm(xy[u] - xy[v]) * rng.uniform(1.0, 2.0))
            edges.append((u, v, w))
        coords = {i: xy[i] for i in range(n)}
        nodes = sorted({u for e in edges for u in e[:2]})
        s, g = nodes[0], nodes[-1]
        m = coo_matrix(([e[2] for e in edges], ([e[0] for e in edges], [e[1] for e in edges])), shape=(n, n))
        # scipy keeps the smallest of duplicate edges only with a dense min; build it explicitly
        dense = np.full((n, n), np.inf)
        for u, v, w in edges:
            dense[u, v] = dense[v, u] = min(dense[u, v], w)
        dense[np.isinf(dense)] = 0
        expected = dijkstra(dense, directed=False, indices=s)[g]
        assert m.shape == (n, n)
        result = astar_graph(edges, s, g, coordinates=coords)
        plain = astar_graph(edges, s, g, heuristic="zero")
        if np.isinf(expected):
            assert result.status == plain.status == "infeasible"
            continue
        assert result.cost == pytest.approx(expected)
        assert plain.cost == pytest.approx(expected)
        assert result.nodes[0] == s
        assert result.nodes[-1] == g
        np.testing.assert_allclose(result.waypoints, xy[list(result.nodes)])
        assert plain.waypoints is None
        assert result.expanded <= plain.expanded


def test_graph_forms() -> None:
    coords = {"a": (0, 0), "b": (1, 0), "c": (1, 1)}
    unweighted = astar_graph([("a", "b"), ("b", "c")], "a", "c", coordinates=coords)
    assert unweighted.cost == pytest.approx(2.0)
    assert unweighted.nodes == ("a", "b", "c")
    directed = {"a": {"b": 1.0}, "b": {"c": 1.0}}
    assert astar_graph(directed, "a", "c").solved
    assert astar_graph(directed, "c", "a").status == "infeasible"
    assert astar_graph(directed, "a", "a").cost == 0.0


def test_cell_graph_matches_the_maze() -> None:
    task = scenarios.make("plan-hard", seed=4)
    graph = cell_graph(task)
    doors = task.door_graph()
    assert {c: tuple(sorted(n)) for c, n in graph.adjacency.items()} == doors
    for door, centre in zip(task.doors, task.door_centers(), strict=True):
        a, b = door.cells
        assert graph.doors[(a, b)] == graph.doors[(b, a)] == centre
        assert graph.adjacency[a][b] >= math.dist(graph.coordinates[a], graph.coordinates[b])
    a, b = task.cell_of(task.start), task.cell_of(task.goal)
    route = astar_graph(graph.adjacency, a, b, coordinates=graph.coordinates)
    assert route.solved
    assert route.nodes is not None
    assert len(route.nodes) >= len(task.door_path(a, b) or ())  # BFS is fewest doors, A* shortest
    for u, v in zip(route.nodes, route.nodes[1:], strict=False):
        assert v in doors[u]


# ------------------------------------------------------------------------------------------ shortcut


@given(
    obstacles=st.lists(shapes, min_size=0, max_size=4),
    points=st.lists(st.tuples(st.floats(0, 4), st.floats(0, 3)), min_size=1, max_size=12),
)
def test_shortcut_is_a_subsequence_without_new_collisions(
    obstacles: list[Circle | Square | Rectangle], points: list[tuple[float, float]]
) -> None:
    world = World(workspace=Workspace(xmin=0, xmax=4, ymin=0, ymax=3), obstacles=tuple(obstacles))
    path = np.array(points)
    out = shortcut(path, world)
    np.testing.assert_array_equal(out[[0, -1]], path[[0, -1]])
    idx = [int(np.flatnonzero((path == row).all(axis=1))[0]) for row in out]
    assert len(out) <= len(path)
    bad_in = world.segments_in_collision(path[:-1], path[1:]) if len(path) > 1 else np.zeros(0, bool)
    if len(out) > 1:
        bad_out = world.segments_in_collision(out[:-1], out[1:])
        if not bad_in.any():
            assert not bad_out.any()
    assert idx == sorted(idx) or len(set(map(tuple, path))) < len(path)


def test_shortcut_straightens_free_space() -> None:
    path = np.array([[0, 0], [1, 1], [2, 0], [3, 1], [4, 0]], dtype=float)
    world = World(workspace=Workspace(xmin=0, xmax=4, ymin=0, ymax=3))
    np.testing.assert_array_equal(shortcut(path, world), [[0, 0], [4, 0]])
    blocker = World(workspace=world.workspace, obstacles=(Circle(center=(2, 0), radius=0.5),))
    out = shortcut(path, blocker)
    assert len(out) > 2
    assert blocker.first_collision(out) is None


# --------------------------------------------------------------------------------- status and limits


def test_infeasible_statuses() -> None:
    blocked = np.zeros((5, 5), dtype=bool)
    blocked[:, 2] = True
    grid = grid_of(blocked)
    cut = astar(grid, (0.5, 0.5), (4.5, 4.5))
    assert cut.status == "infeasible"
    assert "no free path" in cut.message
    assert cut.expanded == 10
    assert cut.cost is None
    assert cut.solve_time >= 0
    start = astar(grid, (2.5, 0.5), (4.5, 4.5))
    assert start.status == "infeasible"
    assert "start cell (0, 2) is blocked" in start.message
    goal = astar(grid, (0.5, 0.5), (2.1, 3.9))
    assert goal.status == "infeasible"
    assert "goal cell (3, 2) is blocked" in goal.message
    # a goal inside an obstacle, through the world helpers
    world = World(
        workspace=Workspace(xmin=0, xmax=2, ymin=0, ymax=2), obstacles=(Circle(center=(1, 1), radius=0.3),)
    )
    inside = astar(occupancy_grid(world, resolution=0.1), (0.1, 0.1), (1.0, 1.0))
    assert inside.status == "infeasible"


def test_time_limit() -> None:
    grid = grid_of(np.zeros((300, 300), dtype=bool), 0.1)
    result = astar(grid, (0.05, 0.05), (29.95, 29.95), heuristic="zero", time_limit=1e-6)
    assert result.status == "time_limit"
    assert "budget" in result.message
    assert result.expanded == 1024
    assert result.waypoints is None


def test_deterministic() -> None:
    rng = np.random.default_rng(11)
    blocked = random_blocked(rng, 40, 40, 0.2)
    blocked[0, 0] = blocked[-1, -1] = False
    grid = grid_of(blocked, 0.25)
    first, second = astar(grid, (0.1, 0.1), (9.9, 9.9)), astar(grid, (0.1, 0.1), (9.9, 9.9))
    assert first.status == second.status
    assert first.cells == second.cells
    assert first.expanded == second.expanded


def test_speed_200x200() -> None:
    rng = np.random.default_rng(0)
    blocked = random_blocked(rng, 200, 200, 0.2)
    blocked[:3, :3] = blocked[-3:, -3:] = False
    grid = grid_of(blocked, 0.05)
    t0 = time.perf_counter()
    result = astar(grid, (0.01, 0.01), (9.99, 9.99))
    elapsed = time.perf_counter() - t0
    assert result.solved
    assert result.expanded > 5000
    assert elapsed < 1.0, f"200 x 200 A* took {elapsed:.2f} s"
    # Dijkstra over every free cell of an empty 200 x 200 grid (40,000 expansions)
    t0 = time.perf_counter()
    full = astar(
        grid_of(np.zeros((200, 200), dtype=bool), 0.05), (0.01, 0.01), (9.99, 9.99), heuristic="zero"
    )
    elapsed = time.perf_counter() - t0
    assert full.expanded == 40_000
    assert elapsed < 1.5, f"200 x 200 Dijkstra took {elapsed:.2f} s"


BAD_GRID = grid_of(np.zeros((4, 4), dtype=bool))


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"grid": np.zeros((4, 4))}, r"grid must be an OccupancyGrid .* got ndarray"),
        ({"start": (0.5,)}, r"start must have shape \(2,\), got shape \(1,\)"),
        ({"goal": (float("nan"), 1.0)}, r"goal must be finite, got nan"),
        ({"start": "here"}, r"start must be an array of numbers"),
        ({"goal": (5.0, 1.0)}, r"goal must lie on the grid \[0, 4\] x \[0, 4\], got \(5, 1\)"),
        ({"connectivity": 6}, r"connectivity must be 4 or 8, got 6"),
        ({"heuristic": "chebyshev"}, r"heuristic must be one of .* got 'chebyshev'"),
        ({"heuristic": "manhattan"}, r"heuristic 'manhattan' is not admissible with connectivity=8"),
        ({"time_limit": 0}, r"time_limit must be a finite number of seconds > 0, got 0"),
        ({"time_limit": float("inf")}, r"time_limit must be .* got inf"),
    ],
)
def test_astar_bad_inputs(kwargs: dict[str, object], match: str) -> None:
    args: dict[str, object] = {"grid": BAD_GRID, "start": (0.5, 0.5), "goal": (3.5, 3.5), **kwargs}
    with pytest.raises(InvalidArgumentError, match=match):
        astar(**args)  # type: ignore[arg-type]


WORLD = World(workspace=Workspace(xmin=0, xmax=1, ymin=0, ymax=1))


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: occupancy_grid("world", resolution=0.1), r"world must be an audere.world.World, got str"),  # type: ignore[arg-type]
        (
            lambda: occupancy_grid(WORLD, resolution=0),
            r"resolution must be a finite number of metres > 0, got 0",
        ),
        (lambda: occupancy_grid(WORLD, resolution=float("nan")), r"resolution must be .* got nan"),
        (lambda: occupancy_grid(WORLD, resolution=0.1, margin=-1), r"margin must be .* >= 0, got -1"),
        (lambda: occupancy_grid(WORLD, resolution=1e-4), r"more than 4,000,000"),
        (lambda: BAD_GRID.to_world([1, 2, 3]), r"cells must have shape \(k, 2\) or \(2,\), got shape \(3,\)"),
        (lambda: BAD_GRID.to_cell([[1, 2, 3]]), r"points must have shape"),
        (
            lambda: astar_graph({"a": {"b": -1}}, "a", "b"),
            r"graph\['a'\]\['b'\] must be finite and >= 0, got -1",
        ),
        (lambda: astar_graph({"a": {"b": "x"}}, "a", "b"), r"graph\['a'\]\['b'\] must be a number, got 'x'"),
        (lambda: astar_graph({"a": [1]}, "a", "b"), r"graph\['a'\] must be a mapping"),  # type: ignore[dict-item]
        (lambda: astar_graph([("a",)], "a", "b"), r"graph\[0\] must be an edge \(u, v\) or \(u, v, weight\)"),
        (lambda: astar_graph([("a", "b")], "a", "b"), r"graph\[0\] = \('a', 'b'\) has no weight"),
        (lambda: astar_graph(42, "a", "b"), r"graph must be a mapping .* got int"),  # type: ignore[arg-type]
        (lambda: astar_graph([("a", "b", 1)], "a", "z"), r"goal must be a node of the graph, got 'z'"),
        (
            lambda: astar_graph([("a", "b", 1)], "a", "b", heuristic="octile"),
            r"heuristic must be 'euclidean' or 'zero'",
        ),  # type: ignore[arg-type]
        (
            lambda: astar_graph([("a", "b", 0.5)], "a", "b", coordinates={"a": (0, 0), "b": (1, 0)}),
            r"heuristic 'euclidean' is not admissible: edge \('a', 'b'\) weighs 0.5",
        ),
        (
            lambda: astar_graph([("a", "b", 1)], "a", "b", coordinates={"a": (0, 0)}),
            r"coordinates must give a position for every node, missing 1: \['b'\]",
        ),
        (
            lambda: astar_graph([("a", "b", 1)], "a", "b", coordinates={"a": (0, 0, 1)}),
            r"coordinates\['a'\] must have shape",
        ),
        (lambda: astar_graph([("a", "b", 1)], "a", "b", time_limit=-1), r"time_limit must be .* got -1"),
        (lambda: cell_graph(WORLD), r"task must be a MazeTask, got World"),
        (lambda: shortcut([[0, 0, 0]], WORLD), r"waypoints must have shape \(k, 2\), got shape \(1, 3\)"),
        (lambda: shortcut([], WORLD), r"waypoints must have shape \(k, 2\)"),
        (lambda: shortcut([[0, 0]], None), r"world must be an audere.world.World, got NoneType"),  # type: ignore[arg-type]
    ],
)
def test_helper_bad_inputs(call: object, match: str) -> None:
    with pytest.raises(InvalidArgumentError, match=match):
        call()  # type: ignore[operator]


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: OccupancyGrid(origin=(0, 0), resolution=1, blocked=[1, 0]), r"non-empty 2-D array"),
        (lambda: OccupancyGrid(origin=(0, 0), resolution=1, blocked=[[2]]), r"booleans"),
        (lambda: OccupancyGrid(origin=(0, 0), resolution=-1, blocked=[[0]]), r"greater than 0"),
    ],
)
def test_occupancy_grid_fields_are_validated(call: object, match: str) -> None:
    # OccupancyGrid is a pydantic model: its fields raise pydantic's ValidationError (a ValueError)
    with pytest.raises(ValidationError, match=match):
        call()  # type: ignore[operator]


# ---------------------------------------------------------------------------------------------- docs

DOC = Path(__file__).resolve().parents[2] / "docs" / "apis" / "astar.md"


def test_docs_page_examples_print_what_they_say(capsys: pytest.CaptureFixture[str]) -> None:
    blocks = python_blocks(DOC)
    assert len(blocks) >= 3
    for i, source in enumerate(blocks):
        namespace: dict[str, object] = {"__name__": "docs_astar"}
        exec(compile(source, f"{DOC}#block{i}", "exec", dont_inherit=True), namespace)
        printed = capsys.readouterr().out.splitlines()
        assert printed == expected_output(source), f"block {i}"


def test_docstring_examples() -> None:
    import audere.planners._astar as module

    result = doctest.testmod(module, optionflags=doctest.NORMALIZE_WHITESPACE)
    assert result.attempted >= 8
    assert result.failed == 0


@pytest.mark.parametrize("seed", range(5))
def test_plan_easy_with_astar(seed: int) -> None:
    """The A* alternative for plan-easy shown in the docs (the registered recipe uses rrt)."""
    task = scenarios.make("plan-easy", seed=seed)
    grid = occupancy_grid(task.world(inflated=False), resolution=0.05, margin=task.margin)
    result = astar(grid, task.start, task.goal_position)
    assert result.solved
    path = shortcut(result.waypoints, task.world())
    assert task.check(Solution(waypoints=path)).success
