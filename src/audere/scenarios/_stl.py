"""The STL scenario ``plan-stl`` (the paper's): pick up the key, pass the door, reach the goal in time.

Five rectangles on the [0, 10]^2 map (before the random left-right mirror): the key A in the top
left, the wall B in the left half, the wall C that closes a room in the right strip, the door D (a
band across that room) and the goal E inside the room above the door. The specification::

    F[t_start,17] in(E) & G[0,20] (!in(B) & !in(C)) & (!in(D) U[0,20] in(A))

Solvability is shown by construction: a witness visits A, comes back, passes under C, goes up
through D into E and waits there, at most 3.5 m per axis per step (the bound is 4).
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from audere.scenarios._base import F, Generated, GenerationError, fixed, retry, rounded
from audere.tasks import Solution, STLTask
from audere.world import Rectangle, Workspace, signed_distance

__all__ = ["STL", "plan_stl"]


class STL:
    """Parameters of plan-stl."""

    horizon = 20
    dt = 1.0
    u_max = 4.0
    start_box = (0.5, 1.5)
    start_clearance = 0.1
    """The start keeps at least this far from every region (it is inside none)."""
    key_scale = (0.9, 1.1)
    goal_scale = (0.9, 1.1)
    wall_height_scale = (0.8, 1.0)
    shift = (-0.2, 0.8)
    """D and E move down by this much (one shared offset)."""
    t_start = (horizon // 2, horizon - 4)
    """``t_start`` is a whole step in [t_start[0], t_start[1])."""
    t_end = horizon - 3
    witness_speed = 3.5
    """Largest per-axis displacement of the witness in one step, metres."""
    corridor_x = 5.5
    """The witness's vertical corridor, between B (x <= 4) and C (x >= 7)."""
    low_y = 1.0
    """The witness's way under C (whose bottom is at y = 2)."""
    high_y = 9.0
    """The witness's way over B (whose top is at most 7.5) to the key."""


SPEC = "F[{t_start},{t_end}] in(E) & G[0,{horizon}] (!in(B) & !in(C)) & (!in(D) U[0,{horizon}] in(A))"
"""The specification, with the time window filled in."""


def _rect(cx: float, cy: float, width: float, height: float, mirror: bool) -> Rectangle:
    """A rectangle from centre and size, mirrored about x = 5 when ``mirror``, bounds rounded."""
    if mirror:
        cx = 10.0 - cx
    lo = rounded(np.array([cx - width / 2, cy - height / 2]))
    hi = rounded(np.array([cx + width / 2, cy + height / 2]))
    return Rectangle(xmin=float(lo[0]), xmax=float(hi[0]), ymin=float(lo[1]), ymax=float(hi[1]))


def _center(r: Rectangle) -> tuple[float, float]:
    return ((r.xmin + r.xmax) / 2, (r.ymin + r.ymax) / 2)


def _witness(start: F, regions: dict[str, Rectangle], mirror: bool) -> F:
    """Positions (horizon + 1, 2) at the steps: via points joined at constant speed, then a wait in E."""
    key, goal = _center(regions["A"]), _center(regions["E"])
    x = STL.corridor_x if not mirror else 10.0 - STL.corridor_x
    room_x = goal[0]
    via = np.array(
        [
            start,
            (x, STL.low_y),
            (x, STL.high_y),
            key,
            (x, STL.high_y),
            (x, STL.low_y),
            (room_x, STL.low_y),
            goal,
        ]
    )
    points = [via[0]]
    for p, q in itertools.pairwise(via):
        n = max(1, math.ceil(float(np.abs(q - p).max()) / STL.witness_speed - 1e-12))
        points += [p + (q - p) * j / n for j in range(1, n + 1)]
    if len(points) - 1 > STL.t_end:  # pragma: no cover - at most 16 steps for every draw
        raise GenerationError(f"plan-stl witness needs {len(points) - 1} steps, more than t_end={STL.t_end}")
    points += [via[-1]] * (STL.horizon + 1 - len(points))
    return np.asarray(points, dtype=np.float64)


def plan_stl(rng: np.random.Generator, name: str) -> Generated:
    """plan-stl: key A before door D, avoid walls B and C, reach goal E in a random time window.

    Parameters
    ----------
    rng
        The scenario's random stream.
    name
        The task's name.

    Returns
    -------
    Generated
        The task and a witness trajectory (states of the single integrator).
    """
    key = rng.uniform(*STL.key_scale)
    goal = rng.uniform(*STL.goal_scale)
    wall = rng.uniform(*STL.wall_height_scale)
    shift = rng.uniform(*STL.shift)
    mirror = bool(rng.random() < 0.5)
    t_start = int(rng.integers(*STL.t_start))
    regions = {
        "A": _rect(1.0, 9.0, key, key, mirror),
        "B": _rect(2.0, 4.5, 4.0, 6.0 * wall, mirror),
        "C": _rect(7.5, 6.0, 1.0, 8.0, mirror),
        "D": _rect(9.0, 5.5 - shift, 2.0, 0.5, mirror),
        "E": _rect(9.0, 8.2 - shift, 0.8 * goal, 0.8 * goal, mirror),
    }

    def draw_start() -> F | None:
        p = rounded(rng.uniform(*STL.start_box, size=2))
        if mirror:
            p[0] = 10.0 - p[0]
        clear = min(float(signed_distance(r, p[None, :])[0]) for r in regions.values())
        return p if clear >= STL.start_clearance else None

    start = retry(draw_start, what="a plan-stl start outside every region")
    task = STLTask(
        name=name,
        dynamics="single_integrator",
        x0=(float(start[0]), float(start[1])),
        dt=STL.dt,
        horizon=STL.horizon,
        u_min=(-STL.u_max, -STL.u_max),
        u_max=(STL.u_max, STL.u_max),
        workspace=Workspace(xmin=0.0, xmax=10.0, ymin=0.0, ymax=10.0),
        regions=regions,
        spec=SPEC.format(t_start=t_start, t_end=STL.t_end, horizon=STL.horizon),
    )
    return Generated(task, fixed(Solution(states=_witness(start, regions, mirror))))
