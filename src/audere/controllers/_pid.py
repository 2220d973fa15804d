"""PID reference following, simulated in closed loop through a dynamics model.

One PID loop per input channel, discrete time (one control update per step ``dt``):

- single integrator (inputs ``vx, vy``): per-axis PID on the position error, plus the reference
  velocity as feed-forward;
- double integrator (inputs ``ax, ay``): per-axis PID on the position error whose derivative term
  is the velocity error (reference velocity from the reference states, or finite differences of
  the reference positions), plus the reference acceleration as feed-forward;
- unicycle (inputs ``omega, a``): a heading loop steering toward a lookahead point on the
  reference and a speed loop driving the speed to the one that reaches it in ``lookahead`` steps.

Anti-windup: ``"clamping"`` (conditional integration: the integrator stops while the output is
saturated and the error pushes further into saturation), ``"back_calculation"`` (the integrator
is corrected by the saturation excess, with a tracking time constant of one step) or ``"none"``;
``integrator_limit`` additionally bounds each integrator state.
"""

from __future__ import annotations

import math
import time
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray
from pydantic import Field

from audere._arrays import FloatArray, as_float_array
from audere.apis import Result, register_api
from audere.dynamics import Dynamics, IntegrationMethod, get_dynamics
from audere.errors import InvalidArgumentError

__all__ = ["PIDResult", "pid"]

F = NDArray[np.float64]

_SUPPORTED = ("single_integrator", "double_integrator", "unicycle")

AntiWindup = Literal["clamping", "back_calculation", "none"]


class PIDResult(Result):
    """Result of :func:`pid`: the closed-loop trajectory and how well it followed the reference."""

    errors: FloatArray | None = Field(
        None, description="Planar position error to the reference at every step, metres, (horizon+1,)."
    )
    mean_error: float | None = Field(
        None, description="Mean of errors, metres (the tracking tasks' measure)."
    )
    max_error: float | None = Field(None, description="Largest of errors, metres.")
    final_error: float | None = Field(None, description="Last entry of errors, metres.")
    saturated_steps: int = Field(0, ge=0, description="Steps at which at least one input was clipped.")
    integral: FloatArray | None = Field(
        None, description="Final integrator state per input channel (error integrated over time)."
    )


def _default_gains(model: str, dt: float) -> tuple[F, F, F]:
    if model == "single_integrator":
        return np.full(2, 0.8 / dt), np.zeros(2), np.zeros(2)
    if model == "double_integrator":
        wn, zeta = 0.5 / dt, 0.9
        return np.full(2, wn * wn), np.zeros(2), np.full(2, 2.0 * zeta * wn)
    return np.array([0.8 / dt, 0.8 / dt]), np.zeros(2), np.zeros(2)


def _gain(value: ArrayLike | None, default: F, *, name: str, n_u: int) -> F:
    if value is None:
        return default
    arr = as_float_array(value, name=name)
    if arr.ndim == 0 or arr.shape == (1,):
        arr = np.full(n_u, float(arr.reshape(-1)[0]))
    if arr.shape != (n_u,):
        raise InvalidArgumentError(
            f"{name} must be a number or an array of shape ({n_u},) (one gain per input), "
            f"got shape {tuple(arr.shape)}"
        )
    if np.any(arr < 0):
        raise InvalidArgumentError(f"{name} must be >= 0, got {arr.tolist()}")
    return arr


def _bound(value: ArrayLike | None, *, name: str, n_u: int, fill: float) -> F:
    if value is None:
        return np.full(n_u, fill)
    arr = as_float_array(value, name=name, finite=False)
    if arr.ndim == 0 or arr.shape == (1,):
        arr = np.full(n_u, float(arr.reshape(-1)[0]))
    if arr.shape != (n_u,):
        raise InvalidArgumentError(
            f"{name} must be a number or an array of shape ({n_u},), got shape {tuple(arr.shape)}"
        )
    if np.any(np.isnan(arr)):
        raise InvalidArgumentError(f"{name} must not contain NaN, got {arr.tolist()}")
    return arr


def _wrap(angle: float) -> float:
    return (angle + math.pi) % (2.0 * math.pi) - math.pi


@register_api(
    "pid",
    description=(
        "PID reference/waypoint following with input saturation and anti-windup, simulated in closed "
        "loop (single/double integrator, unicycle); use for simple tracking without a model-based design."
    ),
    tags=("control", "tracking", "feedback", "closed_loop"),
)
def pid(
    dynamics: Dynamics | str,
    x0: ArrayLike,
    reference: ArrayLike,
    dt: float,
    *,
    kp: ArrayLike | None = None,
    ki: ArrayLike | None = None,
    kd: ArrayLike | None = None,
    u_min: ArrayLike | None = None,
    u_max: ArrayLike | None = None,
    anti_windup: AntiWindup = "clamping",
    integrator_limit: float | None = None,
    feedforward: bool = True,
    lookahead: int = 2,
    method: IntegrationMethod = "euler",
    time_limit: float = 10.0,
) -> PIDResult:
    """Follow a reference with discrete-time PID loops, simulated in closed loop.

    Every step ``k`` the controller measures the state, computes one input per channel from the
    error to the reference, clips it to ``[u_min, u_max]`` and advances the model by ``dt``. The
    loops: single integrator, per-axis PID on the position error ``r[k] - p[k]`` plus the reference
    velocity ``(r[k+1] - r[k]) / dt`` as feed-forward (P only: the error shrinks by the factor
    ``1 - kp*dt`` per step); double integrator, per-axis PD(+I) on position with the velocity error
    as the derivative, plus the reference acceleration as feed-forward; unicycle, a heading loop
    (``omega``) toward the reference point ``lookahead`` steps ahead and a speed loop (``a``) toward
    the speed that reaches it in ``lookahead`` steps.

    Parameters
    ----------
    dynamics
        ``"single_integrator"``, ``"double_integrator"`` or ``"unicycle"`` (or that model).
    x0
        Initial state, shape (n_x,), SI units (metres, radians, m/s).
    reference
        Reference, shape (horizon+1, 2) planar positions in metres, or (horizon+1, n_x) states
        (the double integrator then uses the reference velocities); row ``k`` is the target at time
        ``k*dt``. The simulation runs ``horizon`` steps.
    dt
        Control period and simulation step, seconds, > 0.
    kp
        Proportional gains, one per input channel (a number applies to all); ``None`` picks the
        model's default (single: ``0.8/dt``; double: ``(0.5/dt)**2``; unicycle: ``0.8/dt`` for the
        heading and the speed loop). Units: input unit per error unit.
    ki
        Integral gains per channel (error integrated over seconds); ``None`` means 0.
    kd
        Derivative gains per channel (error rate in units per second); ``None`` means 0 except for
        the double integrator (``2*0.9*0.5/dt``, acting on the velocity error).
    u_min
        Lower input bounds, shape (n_u,) or a number; ``None`` means unbounded.
    u_max
        Upper input bounds, shape (n_u,) or a number; ``None`` means unbounded.
    anti_windup
        ``"clamping"`` (conditional integration), ``"back_calculation"`` (the integrator is
        corrected by the clipped excess, tracking time constant one step) or ``"none"``.
    integrator_limit
        Bound on the absolute value of each integrator state (error times seconds), ``> 0``;
        ``None`` means no bound.
    feedforward
        Add the reference velocity (single integrator) or acceleration (double integrator) to the
        PID output. Ignored for the unicycle.
    lookahead
        Unicycle only: how many steps ahead the steering target lies on the reference, ``>= 1``.
    method
        Integration scheme of the simulation, ``"euler"`` (as the benchmark tasks) or ``"rk4"``.
    time_limit
        Wall-clock budget in seconds, ``> 0``; past it the simulation stops with status
        ``"time_limit"`` and the steps done so far.

    Returns
    -------
    PIDResult
        ``states`` (horizon+1, n_x), ``inputs`` (horizon, n_u) (clipped, as applied), ``times``
        (horizon+1,) seconds, the position ``errors`` per step with their mean (also the ``cost``),
        max and final value, the number of saturated steps and the final integrator state. Status
        ``"solved"`` when the simulation completed with finite states, ``"failed"`` when it
        diverged, ``"time_limit"`` when the budget ran out.

    Raises
    ------
    InvalidArgumentError
        For an unsupported model, shapes that do not match the model, NaN or inf in the data,
        negative gains, ``u_min > u_max``, a non-positive ``dt``, ``integrator_limit`` or
        ``time_limit``, or ``lookahead < 1``.

    Examples
    --------
    >>> import numpy as np
    >>> reference = np.linspace([0.0, 0.0], [5.0, 2.0], 11)
    >>> result = pid("single_integrator", [0.5, 0.0], reference, 1.0, u_max=0.8, u_min=-0.8)
    >>> result.status, round(result.final_error, 3)
    ('solved', 0.0)
    """
    t0 = time.perf_counter()
    model = get_dynamics(dynamics) if isinstance(dynamics, str) else dynamics
    if not isinstance(model, Dynamics) or model.name not in _SUPPORTED:
        got = getattr(model, "name", None) or repr(dynamics)
        raise InvalidArgumentError(f"dynamics must be one of {', '.join(map(repr, _SUPPORTED))}, got {got!r}")
    n_x, n_u = model.n_x, model.n_u
    x = as_float_array(x0, name="x0", shape=(n_x,))
    ref = as_float_array(reference, name="reference", ndim=2, min_len=2)
    if ref.shape[1] not in (2, n_x):
        raise InvalidArgumentError(
            f"reference must have shape (horizon+1, 2) or (horizon+1, {n_x}), got shape {tuple(ref.shape)}"
        )
    if isinstance(dt, bool) or not isinstance(dt, (int, float)) or not (math.isfinite(dt) and dt > 0):
        raise InvalidArgumentError(f"dt must be a positive finite number (seconds), got {dt!r}")
    dt = float(dt)
    kp0, ki0, kd0 = _default_gains(model.name, dt)
    gp = _gain(kp, kp0, name="kp", n_u=n_u)
    gi = _gain(ki, ki0, name="ki", n_u=n_u)
    gd = _gain(kd, kd0, name="kd", n_u=n_u)
    lo = _bound(u_min, name="u_min", n_u=n_u, fill=-math.inf)
    hi = _bound(u_max, name="u_max", n_u=n_u, fill=math.inf)
    if np.any(lo > hi):
        raise InvalidArgumentError(
            f"u_min must be <= u_max elementwise, got u_min={lo.tolist()}, u_max={hi.tolist()}"
        )
    if anti_windup not in ("clamping", "back_calculation", "none"):
        raise InvalidArgumentError(
            f"anti_windup must be 'clamping', 'back_calculation' or 'none', got {anti_windup!r}"
        )
    if integrator_limit is not None and not (
        isinstance(integrator_limit, (int, float))
        and math.isfinite(integrator_limit)
        and integrator_limit > 0
    ):
        raise InvalidArgumentError(
            f"integrator_limit must be a positive number or None, got {integrator_limit!r}"
        )
    if isinstance(lookahead, bool) or not isinstance(lookahead, int) or lookahead < 1:
        raise InvalidArgumentError(f"lookahead must be an integer >= 1, got {lookahead!r}")
    if not (isinstance(time_limit, (int, float)) and time_limit > 0):
        raise InvalidArgumentError(f"time_limit must be a positive number of seconds, got {time_limit!r}")
    if method not in ("euler", "rk4"):
        raise InvalidArgumentError(f"method must be 'euler' or 'rk4', got {method!r}")

    horizon = ref.shape[0] - 1
    positions = ref[:, :2]
    if model.name == "double_integrator":
        if ref.shape[1] == n_x:
            ref_vel = ref[:, 2:4]
        else:
            ref_vel = np.vstack([np.diff(positions, axis=0) / dt, np.zeros((1, 2))])
    else:
        ref_vel = np.zeros((horizon + 1, 2))

    states = np.empty((horizon + 1, n_x))
    inputs = np.empty((horizon, n_u))
    states[0] = x
    integral = np.zeros(n_u)
    previous: F | None = None
    saturated = 0
    status = "solved"
    message = f"closed-loop PID simulation over {horizon} steps"
    done = horizon
    # a diverging loop is reported through the status, not floating-point warnings
    with np.errstate(over="ignore", invalid="ignore"):
        for k in range(horizon):
            if time.perf_counter() - t0 > time_limit:
                status, done = "time_limit", k
                message = f"time limit of {time_limit} s reached after {k} of {horizon} steps"
                break
            pos = x[:2]
            if model.name == "unicycle":
                target = positions[min(k + lookahead, horizon)]
                delta = target - pos
                distance = float(np.hypot(delta[0], delta[1]))
                heading = math.atan2(delta[1], delta[0]) if distance > 1e-9 else float(x[2])
                heading_error = _wrap(heading - float(x[2]))
                steps = min(lookahead, horizon - k)
                speed_wanted = math.cos(heading_error) * distance / (steps * dt)
                error = np.array([heading_error, speed_wanted - float(x[3])])
                rate = np.zeros(2) if previous is None else (error - previous) / dt
                rate[0] = _wrap(float(error[0] - previous[0])) / dt if previous is not None else 0.0
                ff = np.zeros(2)
            elif model.name == "double_integrator":
                error = positions[k] - pos
                rate = ref_vel[k] - x[2:4]
                ff = (ref_vel[min(k + 1, horizon)] - ref_vel[k]) / dt if feedforward else np.zeros(2)
            else:
                error = positions[k] - pos
                rate = np.zeros(2) if previous is None else (error - previous) / dt
                ff = (positions[k + 1] - positions[k]) / dt if feedforward else np.zeros(2)
            previous = error
            candidate = integral + error * dt
            if integrator_limit is not None:
                candidate = np.clip(candidate, -integrator_limit, integrator_limit)
            raw = ff + gp * error + gi * candidate + gd * rate
            u = np.clip(raw, lo, hi)
            clipped = u != raw
            if np.any(clipped):
                saturated += 1
            if anti_windup == "clamping":
                # integrate only the channels that are not pushed further into saturation
                pushing = clipped & (np.sign(error) == np.sign(raw - u))
                integral = np.where(pushing, integral, candidate)
            elif anti_windup == "back_calculation":
                excess = np.divide(u - raw, gi, out=np.zeros(n_u), where=gi > 0)
                integral = candidate + excess
            else:
                integral = candidate
            if integrator_limit is not None:
                integral = np.clip(integral, -integrator_limit, integrator_limit)
            if not np.all(np.isfinite(u)):
                status, done = "failed", k
                message = f"the closed loop diverged at step {k} (non-finite input); lower the gains"
                break
            inputs[k] = u
            x = model.step(x, u, dt, method=method)
            states[k + 1] = x
            if not np.all(np.isfinite(x)):
                status, done = "failed", k + 1
                message = f"the closed loop diverged at step {k + 1} (non-finite state); lower the gains"
                break
    states = states[: done + 1]
    inputs = inputs[:done]
    times = dt * np.arange(done + 1)
    errors = (
        np.linalg.norm(model.position(states) - positions[: done + 1], axis=-1)
        if status != "failed"
        else None
    )
    finite = errors is not None and bool(np.all(np.isfinite(errors)))
    return PIDResult(
        status=status,
        message=message,
        cost=float(np.mean(errors)) if finite and errors is not None else None,
        solve_time=time.perf_counter() - t0,
        states=states if status != "failed" else None,
        inputs=inputs if status != "failed" else None,
        times=times if status != "failed" else None,
        errors=errors if finite else None,
        mean_error=float(np.mean(errors)) if finite and errors is not None else None,
        max_error=float(np.max(errors)) if finite and errors is not None else None,
        final_error=float(errors[-1]) if finite and errors is not None else None,
        saturated_steps=saturated,
        integral=integral if np.all(np.isfinite(integral)) else None,
    )
