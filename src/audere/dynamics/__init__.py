"""Robot dynamics models, each defined once and evaluated on numpy, torch or CasADi.

Every model is a frozen :class:`Dynamics` dataclass whose vector field ``xdot = f(x, u)`` is
written once against a small operations shim (:class:`BackendOps`). From that single definition
come batched numpy evaluation (:meth:`Dynamics.f`, :meth:`Dynamics.step`, :meth:`Dynamics.rollout`),
differentiable torch evaluation (``*_torch``), CasADi expressions and functions (``*_casadi``,
:meth:`Dynamics.casadi_function`) and exact linearizations (:meth:`Dynamics.linearize`, by complex
step on the numpy definition). torch and CasADi are imported only when their methods are called.

>>> from audere.dynamics import get_dynamics
>>> car = get_dynamics("unicycle")
>>> car.step([0.0, 0.0, 0.0, 1.0], [0.1, 0.0], 1.0).tolist()
[1.0, 0.0, 0.1, 1.0]
"""

from __future__ import annotations

from audere.dynamics._base import Dynamics, IntegrationMethod
from audere.dynamics._models import DoubleIntegrator, Pendulum, SingleIntegrator, TwoLinkArm, Unicycle
from audere.dynamics._ops import BackendOps
from audere.dynamics._registry import get_dynamics, list_dynamics

__all__ = [
    "BackendOps",
    "DoubleIntegrator",
    "Dynamics",
    "IntegrationMethod",
    "Pendulum",
    "SingleIntegrator",
    "TwoLinkArm",
    "Unicycle",
    "get_dynamics",
    "list_dynamics",
]
