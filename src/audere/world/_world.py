"""A world: the workspace and its obstacles, with vectorized collision and distance queries."""

from __future__ import annotations

from functools import cached_property
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray
from pydantic import BaseModel, ConfigDict

from audere._arrays import as_float_array
from audere.world._geometry import (
    Group,
    as_decimals,
    as_margin,
    as_points,
    as_segments,
    describe_shape,
    finish,
    format_point,
    inflate,
    pack,
    xy,
)
from audere.world._shapes import Obstacle, Workspace

__all__ = ["Collision", "World"]


class Collision(BaseModel):
    """The first place where a path enters an obstacle, as found by :meth:`World.first_collision`.

    Attributes
    ----------
    index
        For ``kind == "point"`` the waypoint's index; for ``kind == "segment"`` the segment's index
        ``i``, the segment running from waypoint ``i`` to waypoint ``i + 1``.
    point
        ``(x, y)`` in metres: the waypoint itself, or the exact point where the segment enters the
        obstacle's interior (on the obstacle's boundary, or the segment's start if it starts on it).
    obstacle_index
        Position of the obstacle in ``World.obstacles``.
    obstacle
        The obstacle itself.
    kind
        ``"point"`` when a waypoint lies inside an obstacle, ``"segment"`` when the segment from a
        collision-free waypoint enters one.
    """

    model_config = ConfigDict(frozen=True, extra="forbid")

    index: int
    point: tuple[float, float]
    obstacle_index: int
    obstacle: Obstacle
    kind: Literal["point", "segment"]

    def describe(self, *, decimals: int = 2) -> str:
        """One line of text saying where the path collides.

        Parameters
        ----------
        decimals
            Decimals of every number, 0 to 12.

        Returns
        -------
        str
            E.g. ``"segment 3 (waypoint 3 to waypoint 4) enters obstacle 1 (circle centred at (5.00, 5.00),
            radius 1.00) at (4.00, 5.00)"``.
        """
        n = as_decimals(decimals)
        where = format_point(self.point, n)
        shape = describe_shape(self.obstacle, decimals=n)
        if self.kind == "point":
            return f"waypoint {self.index} at {where} is inside obstacle {self.obstacle_index} ({shape})"
        return (
            f"segment {self.index} (waypoint {self.index} to waypoint {self.index + 1}) enters obstacle "
            f"{self.obstacle_index} ({shape}) at {where}"
        )


class World(BaseModel):
    """The workspace and the obstacles in it; every query is exact and vectorized.

    A point collides when it lies strictly inside an obstacle (touching is allowed). A path is a
    polyline through its waypoints; its segments are closed. Queries are vectorized over points or
    segments and over the obstacles of each kind (circles, boxes, polygons); segment queries first
    discard (segment, obstacle) pairs whose bounding boxes do not overlap.

    Attributes
    ----------
    workspace
        The box the robot must stay in (boundary included). Collision queries concern obstacles only;
        use :meth:`in_workspace` for the bounds (a polyline stays in the box iff its waypoints do).
    obstacles
        The obstacles, any mix of :class:`Circle`, :class:`Square`, :class:`Rectangle`, :class:`Polygon`.
    """

    model_config = ConfigDict(frozen=True, extra="forbid")

    workspace: Workspace
    obstacles: tuple[Obstacle, ...] = ()

    @cached_property
    def _groups(self) -> tuple[Group, ...]:
        return pack(self.obstacles)

    def signed_distance(self, points: ArrayLike) -> NDArray[np.float64]:
        """Signed distance from points to the nearest obstacle (negative strictly inside one).

        Parameters
        ----------
        points
            Points, array of shape ``(N, 2)`` in metres, or one point of shape ``(2,)``.

        Returns
        -------
        numpy.ndarray
            Shape ``(N,)`` (``()`` for one point), metres: the least signed distance over the
            obstacles, ``+inf`` when there are none.
        """
        x, single = as_points(points, name="points")
        px, py = xy(x)
        out = np.full(x.shape[0], np.inf)
        for group in self._groups:
            out = np.minimum(out, group.point_sd_min(px, py))
        return np.asarray(finish(out, single), dtype=np.float64)

    def points_in_collision(self, points: ArrayLike) -> NDArray[np.bool_]:
        """Which points lie strictly inside some obstacle.

        Parameters
        ----------
        points
            Points, array of shape ``(N, 2)`` in metres, or one point of shape ``(2,)``.

        Returns
        -------
        numpy.ndarray
            Booleans of shape ``(N,)`` (``()`` for one point).
        """
        x, single = as_points(points, name="points")
        px, py = xy(x)
        out = np.zeros(x.shape[0], dtype=bool)
        for group in self._groups:
            i, _ = group.inside_pairs(px, py)
            out[i] = True
        return np.asarray(finish(out, single), dtype=np.bool_)

    def segments_in_collision(self, p: ArrayLike, q: ArrayLike) -> NDArray[np.bool_]:
        """Which closed segments ``[p, q]`` reach the interior of some obstacle (exact test).

        Parameters
        ----------
        p
            Segment starts, array of shape ``(N, 2)`` in metres, or one point of shape ``(2,)``.
        q
            Segment ends, the same shape as ``p``.

        Returns
        -------
        numpy.ndarray
            Booleans of shape ``(N,)`` (``()`` for one segment).
        """
        p_arr, q_arr, single = as_segments(p, q)
        seg = (*xy(p_arr), *xy(q_arr))
        out = np.zeros(p_arr.shape[0], dtype=bool)
        for group in self._groups:
            i, _ = group.intersecting_pairs(*seg)
            out[i] = True
        return np.asarray(finish(out, single), dtype=np.bool_)

    def in_workspace(self, points: ArrayLike) -> NDArray[np.bool_]:
        """Which points lie in the workspace (its boundary included).

        Parameters
        ----------
        points
            Points, array of shape ``(N, 2)`` in metres, or one point of shape ``(2,)``.

        Returns
        -------
        numpy.ndarray
            Booleans of shape ``(N,)`` (``()`` for one point).
        """
        x, single = as_points(points, name="points")
        ws = self.workspace
        ok = (x[:, 0] >= ws.xmin) & (x[:, 0] <= ws.xmax) & (x[:, 1] >= ws.ymin) & (x[:, 1] <= ws.ymax)
        return np.asarray(finish(ok, single), dtype=np.bool_)

    def first_collision(self, path: ArrayLike) -> Collision | None:
        """The earliest collision along a path, or ``None`` when the path is collision-free.

        The path is walked in order: waypoint 0, segment 0 (waypoint 0 to 1), waypoint 1, segment 1,
        and so on. A segment that collides is reported with its exact entry point, so a waypoint is
        reported as a ``"point"`` collision only when it is the path's first waypoint or when the path
        has a single waypoint. Among several obstacles, the one entered first wins (ties: the lowest
        obstacle index).

        Parameters
        ----------
        path
            Waypoints, array of shape ``(k, 2)`` in metres, ``k >= 1``.

        Returns
        -------
        Collision | None
            Where and how the path first enters an obstacle.
        """
        waypoints = as_float_array(path, name="path", shape=(None, 2), min_len=1)
        n = waypoints.shape[0]
        # Waypoints: (index, obstacle) of the first waypoint strictly inside an obstacle.
        best_point: tuple[int, int] | None = None
        wx, wy = xy(waypoints)
        for group in self._groups:
            i, k = group.inside_pairs(wx, wy)
            if i.size:
                first = int(i.min())
                cand = (first, int(group.index[k[i == first]].min()))
                best_point = cand if best_point is None or cand < best_point else best_point
        # Segments: (index, entry parameter, obstacle) of the earliest entry.
        best_seg: tuple[int, float, int] | None = None
        if n >= 2:
            px, py, qx, qy = wx[:-1], wy[:-1], wx[1:], wy[1:]
            for group in self._groups:
                i, k = group.intersecting_pairs(px, py, qx, qy)
                if i.size == 0:
                    continue
                t = group.entry(px[i], py[i], qx[i], qy[i], k)
                order = np.lexsort((group.index[k], t, i))[0]
                cand_seg = (int(i[order]), float(t[order]), int(group.index[k[order]]))
                best_seg = cand_seg if best_seg is None or cand_seg < best_seg else best_seg
        if best_point is not None and (best_seg is None or best_point[0] <= best_seg[0]):
            i_pt, obstacle = best_point
            x, y = waypoints[i_pt]
            return Collision(
                index=i_pt,
                point=(float(x), float(y)),
                obstacle_index=obstacle,
                obstacle=self.obstacles[obstacle],
                kind="point",
            )
        if best_seg is not None:
            i_seg, t_seg, obstacle = best_seg
            x, y = waypoints[i_seg] + t_seg * (waypoints[i_seg + 1] - waypoints[i_seg])
            return Collision(
                index=i_seg,
                point=(float(x), float(y)),
                obstacle_index=obstacle,
                obstacle=self.obstacles[obstacle],
                kind="segment",
            )
        return None

    def clearance(self, path: ArrayLike) -> float:
        """Least distance from a path (polyline) to the obstacles; negative when it penetrates one.

        Where the path stays outside every obstacle's interior this is the exact distance from the
        closed polyline to the nearest obstacle (0 when it touches one). Where it enters an obstacle
        the result is minus the deepest penetration: the most negative signed distance reached along
        the path, exact for circles, squares and rectangles; for polygons it is evaluated at 65 evenly
        spaced points per segment (plus the middle of every piece inside), so it may fall short of the
        exact depth by at most ``segment_length / 128``, and it is negative whenever the path enters.

        Parameters
        ----------
        path
            Waypoints, array of shape ``(k, 2)`` in metres, ``k >= 1`` (one waypoint: its signed distance).

        Returns
        -------
        float
            Metres; ``+inf`` when there are no obstacles.
        """
        waypoints = as_float_array(path, name="path", shape=(None, 2), min_len=1)
        wx, wy = xy(waypoints)
        if waypoints.shape[0] == 1:
            px, py, qx, qy = wx, wy, wx, wy
        else:
            px, py, qx, qy = wx[:-1], wy[:-1], wx[1:], wy[1:]
        depth = np.inf
        for group in self._groups:
            i, k = group.intersecting_pairs(px, py, qx, qy)
            if i.size:
                depth = min(depth, float(group.depth(px[i], py[i], qx[i], qy[i], k).min()))
        if depth < np.inf:
            return depth
        # No penetration: the waypoints' distance bounds the answer; only closer pairs are computed.
        best = float(self.signed_distance(waypoints).min())
        for group in self._groups:
            best = group.segment_distance_below(px, py, qx, qy, best)
        return best

    def inflate(self, margin: float) -> World:
        """The same world with every obstacle grown by ``margin`` (see :func:`audere.world.inflate`).

        Planning a point path in the inflated world keeps a disc robot of radius ``margin`` clear of
        the original obstacles. The workspace is unchanged.

        Parameters
        ----------
        margin
            Distance to grow by, metres, ``>= 0``.

        Returns
        -------
        World
            A new world with the same workspace.
        """
        m = as_margin(margin)
        return World(workspace=self.workspace, obstacles=tuple(inflate(o, m) for o in self.obstacles))

    def describe(self, *, decimals: int = 2) -> str:
        """The workspace and each numbered obstacle, one per line.

        Parameters
        ----------
        decimals
            Decimals of every number, 0 to 12.

        Returns
        -------
        str
            Several lines, the first describing the workspace, then ``"obstacle 0: circle centred at
            ..."`` and so on (or ``"no obstacles"``).
        """
        n = as_decimals(decimals)
        lines = [describe_shape(self.workspace, decimals=n)]
        if not self.obstacles:
            lines.append("no obstacles")
        lines.extend(f"obstacle {i}: {describe_shape(o, decimals=n)}" for i, o in enumerate(self.obstacles))
        return "\n".join(lines)
