"""Scenarios beyond the paper, one per remaining dynamics model.

- ``pendulum-swingup``: the torque bound is well below ``m g l``, so the pendulum must be pumped up;
  solvability is shown by an energy-pumping controller in the tests (not part of the library);
- ``arm-reach``: the end effector of a two-link arm reaches a point while avoiding circles; the
  witness is a smooth joint-space motion whose torques come from exact (Euler) inverse dynamics;
- ``reach-unicycle``: a unicycle reaches a point among circles placed across the straight line;
  the witness is the admissible input sequence whose rollout defines the goal.
"""

from __future__ import annotations

import math
from typing import ClassVar

import numpy as np

from audere.dynamics import Dynamics, get_dynamics
from audere.scenarios._base import F, Generated, fixed, retry, rounded
from audere.tasks import ReachAvoidTask, Solution
from audere.world import Circle, Workspace, segment_distance

__all__ = ["ARM", "PENDULUM", "UNICYCLE", "arm_reach", "pendulum_swingup", "reach_unicycle"]


class PENDULUM:
    """Parameters of pendulum-swingup."""

    params: ClassVar[dict[str, float]] = {"length": 1.0, "mass": 1.0, "gravity": 9.81, "damping": 0.0}
    dt = 0.05
    horizon = 100
    torque_max = 3.5
    """About 0.36 m g l: the pendulum cannot be lifted directly and must be pumped."""
    start = 0.3
    """theta0 and omega0 are uniform in [-0.3, 0.3] (rad, rad/s)."""
    goal_tolerance = 0.2
    workspace = 2.0
    """The workspace is [-2, 2]^2 around the pivot."""


class ARM:
    """Parameters of arm-reach."""

    params: ClassVar[dict[str, float]] = {
        "l1": 1.0,
        "l2": 1.0,
        "m1": 1.0,
        "m2": 1.0,
        "gravity": 0.0,
        "damping": 0.0,
    }
    dt = 0.05
    horizon = 60
    torque_max = 10.0
    witness_torque = 0.9 * torque_max
    """The witness uses at most 90 % of the torque bound."""
    elbow = (0.3, 2.6)
    """|q2| (rad) of the start and the target: away from the stretched and the folded arm."""
    shoulder_move = 2.5
    """The target's q1 is within this of the start's (rad)."""
    min_reach = 1.0
    """The goal is at least this far from the end effector's start, metres."""
    n_obstacles = 2
    radius = (0.15, 0.3)
    margin = 0.05
    clearance = 0.05
    """The witness path keeps this far from every inflated obstacle, metres."""
    goal_tolerance = 0.1
    workspace = 2.5


class UNICYCLE:
    """Parameters of reach-unicycle."""

    dt = 0.5
    horizon = 40
    omega_max = 0.8
    a_max = 0.5
    start_box = (0.5, 2.0)
    keep_in = (0.5, 9.5)
    min_distance = 5.0
    n_obstacles = 4
    n_blocking = 2
    """Obstacles drawn across the straight line from the start to the goal (first choice)."""
    radius = (0.3, 0.7)
    margin = 0.1
    clearance = 0.1
    """The witness path keeps this far from every inflated obstacle, metres."""
    obstacle_gap = 0.2
    goal_tolerance = 0.3


_BATCH = 16


# ------------------------------------------------------------------------------------ pendulum-swingup


def pendulum_swingup(rng: np.random.Generator, name: str) -> Generated:
    """pendulum-swingup: from near hanging to upright and still, with a weak motor.

    Parameters
    ----------
    rng
        The scenario's random stream.
    name
        The task's name.

    Returns
    -------
    Generated
        The task, without a witness (the tests swing it up with an energy-pumping controller).
    """
    x0 = rounded(rng.uniform(-PENDULUM.start, PENDULUM.start, size=2))
    w = PENDULUM.workspace
    task = ReachAvoidTask(
        name=name,
        dynamics="pendulum",
        dynamics_params=dict(PENDULUM.params),
        x0=(float(x0[0]), float(x0[1])),
        dt=PENDULUM.dt,
        horizon=PENDULUM.horizon,
        u_min=(-PENDULUM.torque_max,),
        u_max=(PENDULUM.torque_max,),
        workspace=Workspace(xmin=-w, xmax=w, ymin=-w, ymax=w),
        goal=(math.pi, 0.0),
        goal_on="state",
        angle_indices=(0,),
        goal_tolerance=PENDULUM.goal_tolerance,
    )
    return Generated(task, None)


# ------------------------------------------------------------------------------------------ arm-reach


def _affine_inputs(model: Dynamics, states: F, dt: float) -> F:
    """Inputs that make the Euler rollout follow ``states`` exactly, for models affine in ``u``
    whose last ``n_u`` state rates are actuated (``f(x, u) = f(x, 0) + B(x) u``)."""
    x = states[:-1]
    n = len(x)
    rate = (states[1:] - x) / dt
    f0 = model.f(x, np.zeros((n, model.n_u)))
    columns = [model.f(x, np.tile(e, (n, 1))) - f0 for e in np.eye(model.n_u)]
    b = np.stack(columns, axis=-1)[:, -model.n_u :, :]  # (n, n_u, n_u)
    return np.asarray(np.linalg.solve(b, (rate - f0)[:, -model.n_u :, None])[..., 0], dtype=np.float64)


def _smoothstep(s: F) -> F:
    """The quintic ``10 s^3 - 15 s^4 + 6 s^5``: 0 to 1 with zero speed and acceleration at both ends."""
    return np.asarray(s**3 * (10.0 - 15.0 * s + 6.0 * s * s), dtype=np.float64)


def _clear_of(path: F, circle: Circle, distance: float) -> bool:
    """Whether the polyline ``path`` stays at least ``distance`` from ``circle`` (exact)."""
    return bool(segment_distance(circle, path[:-1], path[1:]).min() >= distance)


def _circles(
    rng: np.random.Generator,
    *,
    count: int,
    n_blocking: int,
    radius: tuple[float, float],
    path: F,
    clearance: float,
    gap: float,
    near: tuple[F, F],
    anywhere: tuple[F, F],
    tries: int = 32,
) -> list[Circle] | None:
    """Circles clear of ``path`` by ``clearance`` and of each other by ``gap``.

    The first ``n_blocking`` are drawn across the segment ``near`` (centre at 30-70 % of the way,
    up to 0.3 m to the side), falling back to ``anywhere`` (a box) when none of ``tries`` fits.
    """
    a, b = near
    axis = b - a
    normal = np.array([-axis[1], axis[0]]) / max(float(np.linalg.norm(axis)), 1e-12)
    out: list[Circle] = []
    for k in range(count):
        pool = []
        if k < n_blocking:
            t = rng.uniform(0.3, 0.7, size=tries)
            side = rng.uniform(-0.3, 0.3, size=tries)
            pool.append(a + t[:, None] * axis + side[:, None] * normal)
        lo, hi = anywhere
        pool.append(lo + rng.random((tries, 2)) * (hi - lo))
        r = rounded(rng.uniform(*radius, size=tries))
        placed = None
        for centers in pool:
            c = rounded(centers)
            # Cheap necessary conditions first (vectorized); the exact segment test decides.
            gaps = (c[:, None, 0] - path[None, :, 0]) ** 2 + (c[:, None, 1] - path[None, :, 1]) ** 2
            ok = gaps.min(axis=1) >= (r + clearance) ** 2
            for o in out:
                ok &= (c[:, 0] - o.center[0]) ** 2 + (c[:, 1] - o.center[1]) ** 2 >= (r + o.radius + gap) ** 2
            for j in np.flatnonzero(ok):
                circle = Circle(center=(float(c[j, 0]), float(c[j, 1])), radius=float(r[j]))
                if _clear_of(path, circle, clearance):
                    placed = circle
                    break
            if placed is not None:
                break
        if placed is None:
            return None
        out.append(placed)
    return out


def arm_reach(rng: np.random.Generator, name: str) -> Generated:
    """arm-reach: move the end effector of a two-link arm to a reachable point, around two circles.

    Parameters
    ----------
    rng
        The scenario's random stream.
    name
        The task's name.

    Returns
    -------
    Generated
        The task and the inverse-dynamics torques of a smooth joint-space motion.
    """
    model = get_dynamics("two_link_arm", ARM.params)
    n = ARM.horizon
    k = np.arange(n + 1)
    # Rest at steps 0-1 and n-1..n: the Euler rollout starts and ends at zero joint speed.
    profile = _smoothstep(np.clip((k - 1) / (n - 2), 0.0, 1.0))

    def attempt() -> tuple[F, F, F, F] | None:
        side = rng.choice([-1.0, 1.0])
        q0 = rounded([rng.uniform(-math.pi, math.pi), side * rng.uniform(*ARM.elbow)])
        q_goal = np.array(
            [q0[0] + rng.uniform(-ARM.shoulder_move, ARM.shoulder_move), side * rng.uniform(*ARM.elbow)]
        )
        goal = rounded(model.position(np.concatenate([q_goal, [0.0, 0.0]])))
        start_ee = model.position(np.concatenate([q0, [0.0, 0.0]]))
        if np.linalg.norm(goal - start_ee) < ARM.min_reach:
            return None
        q = q0 + np.outer(profile, q_goal - q0)
        dq = np.zeros_like(q)
        dq[:-1] = np.diff(q, axis=0) / ARM.dt
        states = np.hstack([q, dq])
        inputs = _affine_inputs(model, states, ARM.dt)
        if np.abs(inputs).max() > ARM.witness_torque:
            return None
        # The rollout of these inputs is ``states`` up to rounding (the tests check it through
        # Task.check); the obstacle clearance below leaves far more room than that.
        return states[0], inputs, goal, model.position(states)

    def attempt_with_obstacles() -> tuple[F, F, F, list[Circle]] | None:
        drawn = attempt()
        if drawn is None:
            return None
        x0, inputs, goal, path = drawn
        reach = 1.9
        circles = _circles(
            rng,
            count=ARM.n_obstacles,
            n_blocking=ARM.n_obstacles,
            radius=ARM.radius,
            path=path,
            clearance=ARM.margin + ARM.clearance,
            gap=0.1,
            near=(path[0], path[-1]),
            anywhere=(np.full(2, -reach), np.full(2, reach)),
        )
        return None if circles is None else (x0, inputs, goal, circles)

    x0, inputs, goal, circles = retry(attempt_with_obstacles, what="an arm-reach motion and obstacles")
    w = ARM.workspace
    task = ReachAvoidTask(
        name=name,
        dynamics="two_link_arm",
        dynamics_params=dict(ARM.params),
        x0=tuple(float(v) for v in x0),
        dt=ARM.dt,
        horizon=ARM.horizon,
        u_min=(-ARM.torque_max, -ARM.torque_max),
        u_max=(ARM.torque_max, ARM.torque_max),
        workspace=Workspace(xmin=-w, xmax=w, ymin=-w, ymax=w),
        obstacles=tuple(circles),
        margin=ARM.margin,
        goal=(float(goal[0]), float(goal[1])),
        goal_tolerance=ARM.goal_tolerance,
    )
    return Generated(task, fixed(Solution(inputs=inputs)))


# ------------------------------------------------------------------------------------- reach-unicycle


def reach_unicycle(rng: np.random.Generator, name: str) -> Generated:
    """reach-unicycle: drive a unicycle from rest to a point, around circles across the straight line.

    Parameters
    ----------
    rng
        The scenario's random stream.
    name
        The task's name.

    Returns
    -------
    Generated
        The task and the admissible inputs whose rollout ends at the goal.
    """
    model = get_dynamics("unicycle")
    n = UNICYCLE.horizon
    k = np.arange(n)

    def attempt() -> tuple[F, F, F, F] | None:
        p0 = rounded(rng.uniform(*UNICYCLE.start_box, size=2))
        heading = float(rounded(np.array(rng.uniform(0.0, math.pi / 2))))
        x0 = np.array([p0[0], p0[1], heading, 0.0])
        # Turn rate: a bias and a slow sine; speed: up to cruise, hold, back down to rest.
        bias = rng.uniform(-0.15, 0.15, size=(_BATCH, 1))
        amplitude = rng.uniform(0.1, 0.4, size=(_BATCH, 1))
        cycles = rng.uniform(0.5, 1.5, size=(_BATCH, 1))
        phase = rng.uniform(0.0, 2 * math.pi, size=(_BATCH, 1))
        omega = np.clip(bias + amplitude * np.sin(2 * math.pi * cycles * k / n + phase), -0.7, 0.7)
        cruise = rng.uniform(0.4, 0.6, size=(_BATCH, 1))
        ramp = 4
        accel = np.where(k < ramp, cruise / (ramp * UNICYCLE.dt), 0.0)
        accel = np.where(k >= n - ramp, -cruise / (ramp * UNICYCLE.dt), accel)
        inputs = rounded(np.stack([omega, accel], axis=-1))
        positions = model.position(model.rollout(x0, inputs, UNICYCLE.dt))
        lo, hi = UNICYCLE.keep_in
        inside = np.all((positions >= lo) & (positions <= hi), axis=(-2, -1))
        far = np.linalg.norm(positions[:, -1] - p0, axis=-1) >= UNICYCLE.min_distance
        ok = np.flatnonzero(inside & far)
        if ok.size == 0:
            return None
        i = int(ok[0])
        return x0, inputs[i], rounded(positions[i, -1]), positions[i]

    def attempt_with_obstacles() -> tuple[F, F, F, list[Circle]] | None:
        drawn = attempt()
        if drawn is None:
            return None
        x0, inputs, goal, path = drawn
        circles = _circles(
            rng,
            count=UNICYCLE.n_obstacles,
            n_blocking=UNICYCLE.n_blocking,
            radius=UNICYCLE.radius,
            path=path,
            clearance=UNICYCLE.margin + UNICYCLE.clearance,
            gap=UNICYCLE.obstacle_gap,
            near=(path[0], path[-1]),
            anywhere=(np.full(2, 0.5), np.full(2, 9.5)),
        )
        return None if circles is None else (x0, inputs, goal, circles)

    x0, inputs, goal, circles = retry(attempt_with_obstacles, what="a reach-unicycle motion and obstacles")
    task = ReachAvoidTask(
        name=name,
        dynamics="unicycle",
        x0=tuple(float(v) for v in x0),
        dt=UNICYCLE.dt,
        horizon=UNICYCLE.horizon,
        u_min=(-UNICYCLE.omega_max, -UNICYCLE.a_max),
        u_max=(UNICYCLE.omega_max, UNICYCLE.a_max),
        workspace=Workspace(xmin=0.0, xmax=10.0, ymin=0.0, ymax=10.0),
        obstacles=tuple(circles),
        margin=UNICYCLE.margin,
        goal=(float(goal[0]), float(goal[1])),
        goal_tolerance=UNICYCLE.goal_tolerance,
    )
    return Generated(task, fixed(Solution(inputs=inputs)))
