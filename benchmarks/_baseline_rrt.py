"""A straightforward pure-Python RRT, written the way research scripts write it (benchmark baseline).

Not part of the library: it is what :func:`audere.planners.rrt` is compared against. Nearest
neighbour by a linear scan over the tree, a fixed step towards the sample, goal bias, and edge checks
by testing evenly spaced points along the edge (20 per edge, as the paper's authors did), each point
against every obstacle in a Python loop. Sampled edge checks can miss a corner that an edge clips:
the benchmark counts how often the returned path fails the exact check.
"""

from __future__ import annotations

import math
import random
import time

from audere.world import Circle, Rectangle, Square, World


def _point_free(obstacles: list[tuple[str, tuple[float, ...]]], x: float, y: float) -> bool:
    for kind, d in obstacles:
        if kind == "circle":
            if (x - d[0]) ** 2 + (y - d[1]) ** 2 < d[2] ** 2:
                return False
        elif d[0] < x < d[1] and d[2] < y < d[3]:
            return False
    return True


def _obstacles(world: World) -> list[tuple[str, tuple[float, ...]]]:
    out: list[tuple[str, tuple[float, ...]]] = []
    for o in world.obstacles:
        if isinstance(o, Circle):
            out.append(("circle", (o.center[0], o.center[1], o.radius)))
        elif isinstance(o, Square):
            (cx, cy), h = o.center, o.half_side
            out.append(("box", (cx - h, cx + h, cy - h, cy + h)))
        elif isinstance(o, Rectangle):
            out.append(("box", (o.xmin, o.xmax, o.ymin, o.ymax)))
        else:
            raise TypeError("the baseline handles circles, squares and rectangles")
    return out


def baseline_rrt(
    world: World,
    start: tuple[float, float],
    goal: tuple[float, float],
    *,
    step: float = 0.5,
    goal_bias: float = 0.05,
    goal_tolerance: float = 0.1,
    edge_points: int = 20,
    time_limit: float = 30.0,
    seed: int = 0,
) -> tuple[list[tuple[float, float]] | None, float, int]:
    """Plan with a plain RRT; return ``(path or None, seconds, tree size)``."""
    rng = random.Random(seed)
    obstacles = _obstacles(world)
    ws = world.workspace
    t0 = time.perf_counter()

    def edge_free(a: tuple[float, float], b: tuple[float, float]) -> bool:
        for k in range(edge_points + 1):
            t = k / edge_points
            if not _point_free(obstacles, a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])):
                return False
        return True

    nodes = [start]
    parents = [-1]
    while time.perf_counter() - t0 < time_limit:
        if rng.random() < goal_bias:
            sample = goal
        else:
            sample = (rng.uniform(ws.xmin, ws.xmax), rng.uniform(ws.ymin, ws.ymax))
        nearest = min(range(len(nodes)), key=lambda i: math.dist(nodes[i], sample))
        near = nodes[nearest]
        d = math.dist(near, sample)
        new = (
            sample
            if d <= step
            else (near[0] + step * (sample[0] - near[0]) / d, near[1] + step * (sample[1] - near[1]) / d)
        )
        if not edge_free(near, new):
            continue
        nodes.append(new)
        parents.append(nearest)
        if math.dist(new, goal) <= goal_tolerance or (math.dist(new, goal) <= step and edge_free(new, goal)):
            if new != goal:
                nodes.append(goal)
                parents.append(len(nodes) - 2)
            path, k = [], len(nodes) - 1
            while k != -1:
                path.append(nodes[k])
                k = parents[k]
            return path[::-1], time.perf_counter() - t0, len(nodes)
    return None, time.perf_counter() - t0, len(nodes)
