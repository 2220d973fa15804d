"""Register your own API: a straight-line planner that checks its segment against the world.

Run it with ``python examples/register_api.py``. Registration checks the function against the
API rules (annotations, keyword-only options, a numpydoc entry for every parameter, a Returns
section) and, once registered, the planner appears in ``list_apis()``, ``catalog()``,
``api_card()`` and ``tool_schema()`` next to the built-in ones, and a model's JSON call is
validated with ``validate_call``.
"""

from __future__ import annotations

import time

import numpy as np
from numpy.typing import ArrayLike

from audere.apis import Result, api_card, catalog, get_api, register_api, tool_schema, validate_call
from audere.errors import InvalidArgumentError
from audere.world import World


def _point(value: ArrayLike, *, name: str) -> np.ndarray:
    """``value`` as a finite (2,) float array, or an error naming the argument."""
    point = np.asarray(value, dtype=np.float64)
    if point.shape != (2,) or not np.all(np.isfinite(point)):
        raise InvalidArgumentError(f"{name} must be a finite (x, y) position of shape (2,), got {value!r}")
    return point


class StraightLineResult(Result):
    """Result of :func:`straight_line`: the waypoints of the segment, or why it is blocked."""

    length: float | None = None
    """Length of the path in metres (``None`` when blocked)."""


@register_api(
    "straight_line",
    description="Straight segment from start to goal if it is collision-free; try it before a planner.",
    tags=("planning", "path"),
)
def straight_line(
    start: ArrayLike, goal: ArrayLike, world: World, *, n_points: int = 11
) -> StraightLineResult:
    """Connect ``start`` to ``goal`` with a straight segment, if the world allows it.

    Parameters
    ----------
    start
        Start position ``(x, y)``, metres, shape (2,).
    goal
        Goal position ``(x, y)``, metres, shape (2,).
    world
        Workspace and obstacles; the segment must stay in the workspace and out of every obstacle.
    n_points
        Number of evenly spaced waypoints, ``>= 2``, including both ends.

    Returns
    -------
    StraightLineResult
        ``status="solved"`` with ``waypoints`` of shape (n_points, 2) when the segment is free,
        ``status="infeasible"`` with the first obstacle hit in ``message`` otherwise.

    Raises
    ------
    InvalidArgumentError
        For a start or goal that is not a finite (2,) array, or ``n_points < 2``.

    Examples
    --------
    >>> from audere.world import Circle, Workspace, World
    >>> world = World(workspace=Workspace(), obstacles=(Circle(center=(5, 5), radius=1),))
    >>> straight_line([1, 1], [9, 1], world).status
    'solved'
    """
    t0 = time.perf_counter()
    p = _point(start, name="start")
    q = _point(goal, name="goal")
    if isinstance(n_points, bool) or not isinstance(n_points, int) or n_points < 2:
        raise InvalidArgumentError(f"n_points must be an integer >= 2, got {n_points!r}")
    waypoints = np.linspace(p, q, n_points)
    if not bool(np.all(world.in_workspace(waypoints))):
        return StraightLineResult(
            status="infeasible",
            message="the segment leaves the workspace",
            solve_time=time.perf_counter() - t0,
        )
    hit = world.first_collision(waypoints)
    if hit is not None:
        return StraightLineResult(
            status="infeasible", message=f"the segment is blocked: {hit}", solve_time=time.perf_counter() - t0
        )
    length = float(np.linalg.norm(q - p))
    return StraightLineResult(
        status="solved",
        message="straight segment is collision-free",
        cost=length,
        length=length,
        waypoints=waypoints,
        solve_time=time.perf_counter() - t0,
    )


def main() -> None:
    """Show the registered planner the way a model sees it, then call it the way a model would."""
    assert get_api("straight_line").function is straight_line
    print(catalog())
    print()
    print(api_card("straight_line"))
    schema = tool_schema("straight_line")
    print(sorted(schema["function"]["parameters"]["properties"]))
    call = {
        "start": [1, 1],
        "goal": [9, 1],
        "world": {"workspace": {}, "obstacles": [{"kind": "circle", "center": [5, 5], "radius": 1}]},
    }
    result = straight_line(**validate_call("straight_line", call))
    print(result.status, result.length)
    blocked = straight_line(**validate_call("straight_line", {**call, "goal": [9, 9]}))
    print(blocked.status)


if __name__ == "__main__":
    main()
