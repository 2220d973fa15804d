"""Witness solutions built in the tests, independently of the generators' own witnesses."""

from __future__ import annotations

import math

import numpy as np
import scipy.linalg

from audere.tasks import ReachAvoidTask, Solution


def swing_up(task: ReachAvoidTask, *, pump_gain: float, catch_level: float) -> Solution:
    """Energy pumping with saturated torque, then a discrete LQR catch around the upright position.

    The pump drives the energy ``E = m l^2 w^2 / 2 + m g l (1 - cos th)`` towards the upright
    energy ``2 m g l`` with ``u = sat(k (E* - E) w)``; once the LQR cost-to-go ``e' P e`` of the
    Euler-linearized upright model falls below ``catch_level`` the LQR gain takes over.
    """
    model = task.model
    assert model is not None
    assert task.u_max is not None
    p = model.params
    m, ln, g, damping = p["mass"], p["length"], p["gravity"], p["damping"]
    dt, umax = task.dt, task.u_max[0]
    inertia = m * ln * ln
    a = np.array([[1.0, dt], [dt * g / ln, 1.0 - dt * damping / inertia]])
    b = np.array([[0.0], [dt / inertia]])
    q, r = np.diag([10.0, 1.0]), np.array([[0.1]])
    pm = scipy.linalg.solve_discrete_are(a, b, q, r)
    gain = np.linalg.solve(r + b.T @ pm @ b, b.T @ pm @ a)
    x = np.asarray(task.x0, dtype=float)
    inputs = []
    for _ in range(task.horizon):
        th, om = x
        energy = 0.5 * inertia * om**2 + m * g * ln * (1.0 - math.cos(th))
        e = np.array([math.remainder(th - math.pi, 2 * math.pi), om])
        if e @ pm @ e < catch_level:
            u = float(-(gain @ e)[0])
        else:
            u = pump_gain * (2 * m * g * ln - energy) * (om if abs(om) > 1e-3 else 1.0)
        u = min(max(u, -umax), umax)
        inputs.append([u])
        x = model.step(x, [u], dt)
    return Solution(inputs=np.array(inputs))


def swing_up_any(task: ReachAvoidTask) -> tuple[Solution, bool]:
    """The first of a few gain settings whose swing-up the checker accepts (or the last tried)."""
    for pump_gain in (2.0, 5.0, 1.0, 10.0):
        for catch_level in (30.0, 10.0, 100.0):
            solution = swing_up(task, pump_gain=pump_gain, catch_level=catch_level)
            if task.check(solution).success:
                return solution, True
    return solution, False
