"""Tracking scenarios: ``track-lin``, ``track-car`` (the paper's) and ``track-double`` (ours).

Every reference is *feasible*: it starts at the initial position and is exactly reproduced by some
admissible input sequence (which the generator returns as the witness), so a perfect tracker
exists and the success threshold measures tracking quality, not luck.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from audere.dynamics import get_dynamics
from audere.scenarios._base import F, Generated, fixed, retry, rounded
from audere.tasks import Solution, TrackingTask

__all__ = ["track_car", "track_double", "track_lin"]

HORIZON = 20
"""Steps of every paper scenario (21 states)."""
DT = 1.0
"""Step of every paper scenario, seconds."""
KEEP_IN = (0.3, 9.7)
"""Every reference position keeps at least 0.3 m from the edges of the [0, 10]^2 workspace."""

LIN_U_MAX = 0.5
"""track-lin: per-axis speed bound, m/s."""
LIN_STEP = 0.96 * LIN_U_MAX * DT
"""track-lin: largest per-axis displacement of the reference in one step (a 4 % reserve)."""
LIN_TOLERANCE = 1.0

CAR_OMEGA_MAX = 0.3
CAR_A_MAX = 0.5
CAR_TOLERANCE = 2.0

DOUBLE_A_MAX = 0.25
DOUBLE_TOLERANCE = 0.5

_BATCH = 16
"""Candidate references drawn (and rolled out) at once; the first acceptable one is kept."""


def _start(rng: np.random.Generator) -> F:
    return rounded(rng.uniform(0.5, 1.5, size=2))


def _inside(positions: F) -> NDArray[np.bool_]:
    """Which candidates (leading axis) keep every position within :data:`KEEP_IN`."""
    lo, hi = KEEP_IN
    return np.asarray(np.all((positions >= lo) & (positions <= hi), axis=(-2, -1)), dtype=np.bool_)


def track_lin(rng: np.random.Generator, name: str) -> Generated:
    """track-lin: single integrator, speed bound 0.5 per axis, a flat or curved 21-point reference.

    Parameters
    ----------
    rng
        The scenario's random stream.
    name
        The task's name.

    Returns
    -------
    Generated
        The task and the exact reference-following inputs.
    """
    x0 = _start(rng)
    s = np.linspace(0.0, 1.0, HORIZON + 1)

    def attempt() -> F | None:
        heading = rng.uniform(0.0, math.pi / 2)
        length = rng.uniform(4.0, 8.0)
        curved = bool(rng.random() < 0.5)
        amplitude = rng.uniform(0.5, 1.5) * rng.choice([-1.0, 1.0])
        half_waves = int(rng.integers(1, 3))
        along = np.array([math.cos(heading), math.sin(heading)])
        normal = np.array([-along[1], along[0]])
        lateral = amplitude * np.sin(math.pi * half_waves * s) if curved else np.zeros_like(s)
        offsets = np.outer(length * s, along) + np.outer(lateral, normal)
        peak = float(np.abs(np.diff(offsets, axis=0)).max())
        if peak > LIN_STEP:  # slow the whole shape down until every step is admissible
            offsets *= LIN_STEP / peak
        reference = rounded(x0 + offsets)
        reference[0] = x0
        if np.abs(np.diff(reference, axis=0)).max() > LIN_U_MAX * DT or not _inside(reference):
            return None
        return reference

    reference = retry(attempt, what="a track-lin reference inside the workspace")
    task = TrackingTask(
        name=name,
        dynamics="single_integrator",
        x0=tuple(x0),
        dt=DT,
        horizon=HORIZON,
        u_min=(-LIN_U_MAX, -LIN_U_MAX),
        u_max=(LIN_U_MAX, LIN_U_MAX),
        reference=reference,
        tolerance=LIN_TOLERANCE,
    )
    return Generated(task, fixed(Solution(inputs=np.diff(reference, axis=0) / DT)))


def _smooth_wave(rng: np.random.Generator, n: int, *, bias: tuple[float, float], amplitude: float) -> F:
    """``n`` candidate signals over the horizon: a random bias plus one random slow sine, (n, HORIZON)."""
    k = np.arange(HORIZON)
    b = rng.uniform(*bias, size=(n, 1))
    a = rng.uniform(0.0, amplitude, size=(n, 1))
    cycles = rng.uniform(0.5, 1.5, size=(n, 1))
    phase = rng.uniform(0.0, 2 * math.pi, size=(n, 1))
    return np.asarray(b + a * np.sin(2 * math.pi * cycles * k / HORIZON + phase), dtype=np.float64)


def track_car(rng: np.random.Generator, name: str) -> Generated:
    """track-car: unicycle from rest, |omega| <= 0.3, |a| <= 0.5, a reference of 21 reachable positions.

    Parameters
    ----------
    rng
        The scenario's random stream.
    name
        The task's name.

    Returns
    -------
    Generated
        The task and the admissible input sequence whose rollout is the reference.
    """
    model = get_dynamics("unicycle")
    p0 = _start(rng)
    x0 = np.array([p0[0], p0[1], 0.0, 0.0])

    def attempt() -> tuple[F, F] | None:
        omega = np.clip(_smooth_wave(rng, _BATCH, bias=(-0.05, 0.15), amplitude=0.2), -0.27, 0.27)
        cruise = rng.uniform(0.3, 0.55, size=_BATCH)
        ramp = rng.integers(2, 5, size=_BATCH)
        change_at = rng.integers(8, 15, size=_BATCH)
        change = rng.uniform(-0.2, 0.2, size=_BATCH)
        k = np.arange(HORIZON)
        accel = np.where(k < ramp[:, None], (cruise / ramp)[:, None], 0.0)
        accel = accel + np.where(k == change_at[:, None], change[:, None], 0.0)
        inputs = rounded(np.stack([omega, accel], axis=-1))
        states = model.rollout(x0, inputs, DT)
        positions = states[..., :2]
        length = np.linalg.norm(np.diff(positions, axis=-2), axis=-1).sum(axis=-1)
        ok = np.flatnonzero(_inside(positions) & (length >= 4.0))
        if ok.size == 0:
            return None
        return inputs[ok[0]], positions[ok[0]]

    inputs, positions = retry(attempt, what="a track-car reference inside the workspace")
    task = TrackingTask(
        name=name,
        dynamics="unicycle",
        x0=tuple(x0),
        dt=DT,
        horizon=HORIZON,
        u_min=(-CAR_OMEGA_MAX, -CAR_A_MAX),
        u_max=(CAR_OMEGA_MAX, CAR_A_MAX),
        reference=rounded(positions),
        tolerance=CAR_TOLERANCE,
    )
    return Generated(task, fixed(Solution(inputs=inputs)))


def track_double(rng: np.random.Generator, name: str) -> Generated:
    """track-double: double integrator from rest, |a| <= 0.25 per axis, a reference of 21 reachable states.

    Parameters
    ----------
    rng
        The scenario's random stream.
    name
        The task's name.

    Returns
    -------
    Generated
        The task and the admissible accelerations whose rollout is the reference.
    """
    model = get_dynamics("double_integrator")
    p0 = _start(rng)
    x0 = np.array([p0[0], p0[1], 0.0, 0.0])

    def attempt() -> tuple[F, F] | None:
        # A velocity profile that starts at rest: a ramp to a cruise velocity plus a slow wobble.
        heading = rng.uniform(0.0, math.pi / 2, size=_BATCH)
        speed = rng.uniform(0.25, 0.45, size=_BATCH)
        ramp = rng.integers(3, 7, size=_BATCH)
        wobble = np.stack(
            [_smooth_wave(rng, _BATCH, bias=(0.0, 0.0), amplitude=0.15) for _ in range(2)], axis=-1
        )
        k = np.arange(HORIZON + 1)
        gain = np.minimum(1.0, k / ramp[:, None])[..., None]  # (B, H+1, 1)
        cruise = np.stack([speed * np.cos(heading), speed * np.sin(heading)], axis=-1)[:, None, :]
        wob = np.concatenate([np.zeros((_BATCH, 1, 2)), wobble], axis=1)
        velocity = gain * (cruise + wob)
        inputs = rounded(np.diff(velocity, axis=1) / DT)
        states = model.rollout(x0, inputs, DT)
        ok = np.flatnonzero(
            _inside(states[..., :2]) & (np.abs(inputs).max(axis=(-2, -1)) <= 0.9 * DOUBLE_A_MAX)
        )
        if ok.size == 0:
            return None
        return inputs[ok[0]], states[ok[0]]

    inputs, states = retry(attempt, what="a track-double reference inside the workspace")
    task = TrackingTask(
        name=name,
        dynamics="double_integrator",
        x0=tuple(x0),
        dt=DT,
        horizon=HORIZON,
        u_min=(-DOUBLE_A_MAX, -DOUBLE_A_MAX),
        u_max=(DOUBLE_A_MAX, DOUBLE_A_MAX),
        reference=rounded(states),
        tolerance=DOUBLE_TOLERANCE,
    )
    return Generated(task, fixed(Solution(inputs=inputs)))
