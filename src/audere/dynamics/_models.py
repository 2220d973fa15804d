"""The built-in models. Each writes its vector field once, in ``_f``, against :class:`BackendOps`."""

from __future__ import annotations

import dataclasses
from typing import Any, ClassVar

from audere.dynamics._base import Dynamics
from audere.dynamics._ops import BackendOps

__all__ = ["DoubleIntegrator", "Pendulum", "SingleIntegrator", "TwoLinkArm", "Unicycle"]


@dataclasses.dataclass(frozen=True)
class SingleIntegrator(Dynamics):
    """Planar single integrator: the input is the velocity.

    State ``(x, y)`` [m], input ``(vx, vy)`` [m/s]; ``xdot = vx``, ``ydot = vy``. No parameters.
    """

    name: ClassVar[str] = "single_integrator"
    title: ClassVar[str] = "planar single integrator (the input is the velocity)"
    state_names: ClassVar[tuple[str, ...]] = ("x", "y")
    input_names: ClassVar[tuple[str, ...]] = ("vx", "vy")
    state_units: ClassVar[tuple[str, ...]] = ("m", "m")
    input_units: ClassVar[tuple[str, ...]] = ("m/s", "m/s")
    state_meanings: ClassVar[tuple[str, ...]] = ("position along x", "position along y")
    input_meanings: ClassVar[tuple[str, ...]] = ("velocity along x", "velocity along y")

    def _f(self, x: Any, u: Any, ops: BackendOps) -> Any:
        return ops.stack([ops.get(u, 0), ops.get(u, 1)])

    def _equations(self) -> list[str]:
        return ["dx/dt = vx", "dy/dt = vy"]


@dataclasses.dataclass(frozen=True)
class DoubleIntegrator(Dynamics):
    """Planar double integrator: the input is the acceleration.

    State ``(x, y, vx, vy)`` [m, m, m/s, m/s], input ``(ax, ay)`` [m/s²]. No parameters.
    """

    name: ClassVar[str] = "double_integrator"
    title: ClassVar[str] = "planar double integrator (the input is the acceleration)"
    state_names: ClassVar[tuple[str, ...]] = ("x", "y", "vx", "vy")
    input_names: ClassVar[tuple[str, ...]] = ("ax", "ay")
    state_units: ClassVar[tuple[str, ...]] = ("m", "m", "m/s", "m/s")
    input_units: ClassVar[tuple[str, ...]] = ("m/s^2", "m/s^2")
    state_meanings: ClassVar[tuple[str, ...]] = (
        "position along x",
        "position along y",
        "velocity along x",
        "velocity along y",
    )
    input_meanings: ClassVar[tuple[str, ...]] = ("acceleration along x", "acceleration along y")

    def _f(self, x: Any, u: Any, ops: BackendOps) -> Any:
        return ops.stack([ops.get(x, 2), ops.get(x, 3), ops.get(u, 0), ops.get(u, 1)])

    def _equations(self) -> list[str]:
        return ["dx/dt = vx", "dy/dt = vy", "dvx/dt = ax", "dvy/dt = ay"]


@dataclasses.dataclass(frozen=True)
class Unicycle(Dynamics):
    """Unicycle with speed as a state (the paper's Track-car, a Dubins car with acceleration).

    State ``(x, y, theta, v)`` [m, m, rad, m/s], input ``(omega, a)`` [rad/s, m/s²]::

        xdot = v cos(theta),  ydot = v sin(theta),  thetadot = omega,  vdot = a

    ``theta`` is the heading, counter-clockwise from the +x axis. No parameters.
    """

    name: ClassVar[str] = "unicycle"
    title: ClassVar[str] = (
        "unicycle / Dubins car with speed as a state (heading rate and acceleration inputs)"
    )
    state_names: ClassVar[tuple[str, ...]] = ("x", "y", "theta", "v")
    input_names: ClassVar[tuple[str, ...]] = ("omega", "a")
    state_units: ClassVar[tuple[str, ...]] = ("m", "m", "rad", "m/s")
    input_units: ClassVar[tuple[str, ...]] = ("rad/s", "m/s^2")
    state_meanings: ClassVar[tuple[str, ...]] = (
        "position along x",
        "position along y",
        "heading, counter-clockwise from the +x axis",
        "forward speed (may be negative: reversing)",
    )
    input_meanings: ClassVar[tuple[str, ...]] = ("turn rate (heading rate)", "forward acceleration")

    def _f(self, x: Any, u: Any, ops: BackendOps) -> Any:
        theta = ops.get(x, 2)
        v = ops.get(x, 3)
        return ops.stack([v * ops.cos(theta), v * ops.sin(theta), ops.get(u, 0), ops.get(u, 1)])

    def _equations(self) -> list[str]:
        return ["dx/dt = v*cos(theta)", "dy/dt = v*sin(theta)", "dtheta/dt = omega", "dv/dt = a"]


@dataclasses.dataclass(frozen=True)
class Pendulum(Dynamics):
    """Damped, torque-driven pendulum; ``theta = 0`` hangs straight down.

    State ``(theta, omega)`` [rad, rad/s], input ``(torque,)`` [N m]::

        m l² thetaddot = torque - m g l sin(theta) - damping * omega

    :meth:`position` is the bob ``(l sin(theta), -l cos(theta))`` relative to the pivot at the origin.

    Parameters
    ----------
    length
        Rod length ``l`` in metres (massless rod, point mass at its end), ``> 0``.
    mass
        Bob mass ``m`` in kilograms, ``> 0``.
    gravity
        Gravitational acceleration ``g`` in m/s², ``>= 0``.
    damping
        Viscous damping coefficient in N m s/rad, ``>= 0``.
    """

    length: float = 1.0
    mass: float = 1.0
    gravity: float = 9.81
    damping: float = 0.0

    name: ClassVar[str] = "pendulum"
    title: ClassVar[str] = "torque-driven pendulum (point mass on a massless rod)"
    state_names: ClassVar[tuple[str, ...]] = ("theta", "omega")
    input_names: ClassVar[tuple[str, ...]] = ("torque",)
    state_units: ClassVar[tuple[str, ...]] = ("rad", "rad/s")
    input_units: ClassVar[tuple[str, ...]] = ("N m",)
    state_meanings: ClassVar[tuple[str, ...]] = (
        "angle from straight down, counter-clockwise positive (theta = pi is upright)",
        "angular velocity dtheta/dt",
    )
    input_meanings: ClassVar[tuple[str, ...]] = ("torque applied at the pivot, counter-clockwise positive",)
    param_units: ClassVar[dict[str, str]] = {
        "length": "m",
        "mass": "kg",
        "gravity": "m/s^2",
        "damping": "N m s/rad",
    }
    param_rules: ClassVar[dict[str, Any]] = {
        "length": "positive",
        "mass": "positive",
        "gravity": "nonnegative",
        "damping": "nonnegative",
    }

    def _f(self, x: Any, u: Any, ops: BackendOps) -> Any:
        theta = ops.get(x, 0)
        omega = ops.get(x, 1)
        mass, length = self.mass, self.length
        torque = ops.get(u, 0)
        alpha = (torque - mass * self.gravity * length * ops.sin(theta) - self.damping * omega) / (
            mass * length * length
        )
        return ops.stack([omega, alpha])

    def _position(self, x: Any, ops: BackendOps) -> Any:
        theta = ops.get(x, 0)
        return ops.stack([self.length * ops.sin(theta), -self.length * ops.cos(theta)])

    def _equations(self) -> list[str]:
        return [
            "dtheta/dt = omega",
            "domega/dt = (torque - mass*gravity*length*sin(theta) - damping*omega) / (mass*length^2)",
        ]

    def _notes(self) -> list[str]:
        return [
            "position() is the bob at (length*sin(theta), -length*cos(theta)) "
            "relative to the pivot at (0, 0).",
        ]


@dataclasses.dataclass(frozen=True)
class TwoLinkArm(Dynamics):
    """Planar two-link arm with point masses at the link ends, rotating about a base at the origin.

    State ``(q1, q2, dq1, dq2)`` [rad, rad, rad/s, rad/s], input ``(tau1, tau2)`` [N m]. ``q1`` is
    the angle of link 1 counter-clockwise from the +x axis, ``q2`` the angle of link 2 relative
    to link 1. Manipulator equations ``M(q) qdd + C(q, qd) qd + G(q) = tau - damping * qd`` with::

        M11 = (m1 + m2) l1² + m2 l2² + 2 m2 l1 l2 cos q2
        M12 = M21 = m2 l2² + m2 l1 l2 cos q2,   M22 = m2 l2²
        C qd = (-h (2 dq1 dq2 + dq2²), h dq1²),  h = m2 l1 l2 sin q2
        G = ((m1 + m2) g l1 cos q1 + m2 g l2 cos(q1 + q2),  m2 g l2 cos(q1 + q2))

    solved with the closed-form 2x2 inverse (``det M = m2 l1² l2² (m1 + m2 sin² q2) > 0``).
    Gravity acts along -y. :meth:`position` is the end effector
    ``(l1 cos q1 + l2 cos(q1 + q2), l1 sin q1 + l2 sin(q1 + q2))``.

    Parameters
    ----------
    l1
        Length of link 1 in metres, ``> 0``.
    l2
        Length of link 2 in metres, ``> 0``.
    m1
        Point mass at the end of link 1 (the elbow) in kilograms, ``> 0``.
    m2
        Point mass at the end of link 2 (the end effector) in kilograms, ``> 0``.
    gravity
        Gravitational acceleration along -y in m/s², ``>= 0`` (0: the arm moves in a horizontal plane).
    damping
        Viscous joint damping in N m s/rad, ``>= 0``.
    """

    l1: float = 1.0
    l2: float = 1.0
    m1: float = 1.0
    m2: float = 1.0
    gravity: float = 0.0
    damping: float = 0.0

    name: ClassVar[str] = "two_link_arm"
    title: ClassVar[str] = "planar two-link arm with point masses at the link ends"
    state_names: ClassVar[tuple[str, ...]] = ("q1", "q2", "dq1", "dq2")
    input_names: ClassVar[tuple[str, ...]] = ("tau1", "tau2")
    state_units: ClassVar[tuple[str, ...]] = ("rad", "rad", "rad/s", "rad/s")
    input_units: ClassVar[tuple[str, ...]] = ("N m", "N m")
    state_meanings: ClassVar[tuple[str, ...]] = (
        "shoulder angle of link 1, counter-clockwise from the +x axis",
        "elbow angle of link 2 relative to link 1",
        "shoulder angular velocity",
        "elbow angular velocity",
    )
    input_meanings: ClassVar[tuple[str, ...]] = ("shoulder torque", "elbow torque")
    param_units: ClassVar[dict[str, str]] = {
        "l1": "m",
        "l2": "m",
        "m1": "kg",
        "m2": "kg",
        "gravity": "m/s^2",
        "damping": "N m s/rad",
    }
    param_rules: ClassVar[dict[str, Any]] = {
        "l1": "positive",
        "l2": "positive",
        "m1": "positive",
        "m2": "positive",
        "gravity": "nonnegative",
        "damping": "nonnegative",
    }

    def _f(self, x: Any, u: Any, ops: BackendOps) -> Any:
        q1, q2, dq1, dq2 = (ops.get(x, i) for i in range(4))
        l1, l2, m1, m2, g = self.l1, self.l2, self.m1, self.m2, self.gravity
        c2, s2 = ops.cos(q2), ops.sin(q2)
        m11 = (m1 + m2) * l1 * l1 + m2 * l2 * l2 + 2.0 * m2 * l1 * l2 * c2
        m12 = m2 * l2 * l2 + m2 * l1 * l2 * c2
        m22 = m2 * l2 * l2
        h = m2 * l1 * l2 * s2
        c12 = ops.cos(q1 + q2)
        g1 = (m1 + m2) * g * l1 * ops.cos(q1) + m2 * g * l2 * c12
        g2 = m2 * g * l2 * c12
        r1 = ops.get(u, 0) - self.damping * dq1 + h * (2.0 * dq1 * dq2 + dq2 * dq2) - g1
        r2 = ops.get(u, 1) - self.damping * dq2 - h * dq1 * dq1 - g2
        det = m11 * m22 - m12 * m12
        ddq1 = (m22 * r1 - m12 * r2) / det
        ddq2 = (m11 * r2 - m12 * r1) / det
        return ops.stack([dq1, dq2, ddq1, ddq2])

    def _position(self, x: Any, ops: BackendOps) -> Any:
        q1, q2 = ops.get(x, 0), ops.get(x, 1)
        return ops.stack(
            [
                self.l1 * ops.cos(q1) + self.l2 * ops.cos(q1 + q2),
                self.l1 * ops.sin(q1) + self.l2 * ops.sin(q1 + q2),
            ]
        )

    def _equations(self) -> list[str]:
        return [
            "d(q1)/dt = dq1",
            "d(q2)/dt = dq2",
            "[d(dq1)/dt, d(dq2)/dt] = inverse(M) * ([tau1, tau2] - damping*[dq1, dq2] - C - G) with "
            "M11 = (m1 + m2)*l1^2 + m2*l2^2 + 2*m2*l1*l2*cos(q2), M12 = M21 = m2*l2^2 + m2*l1*l2*cos(q2), "
            "M22 = m2*l2^2, C = [-h*(2*dq1*dq2 + dq2^2), h*dq1^2] with h = m2*l1*l2*sin(q2), "
            "G = [(m1 + m2)*gravity*l1*cos(q1) + m2*gravity*l2*cos(q1 + q2), m2*gravity*l2*cos(q1 + q2)]",
        ]

    def _notes(self) -> list[str]:
        return [
            "The base joint is at (0, 0); gravity acts along -y. position() is the end effector at "
            "(l1*cos(q1) + l2*cos(q1 + q2), l1*sin(q1) + l2*sin(q1 + q2)); the elbow is at "
            "(l1*cos(q1), l1*sin(q1)).",
        ]
