"""The :class:`Dynamics` base class: one model definition, three backends, linearization.

A model subclasses :class:`Dynamics`, declares its names, units and parameters, and writes its
continuous-time vector field once in ``_f(x, u, ops)`` against :class:`~audere.dynamics.BackendOps`.
Everything else (numpy batched evaluation, Euler and RK4 steps, rollouts, the torch and CasADi
variants, complex-step linearization, input validation) is derived here from that one definition.
"""

from __future__ import annotations

import dataclasses
import math
import re
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any, ClassVar, Literal, cast, get_args

import numpy as np
from numpy.typing import ArrayLike, NDArray

from audere._arrays import as_float_array
from audere._optional import require
from audere.dynamics._ops import NUMPY_OPS, BackendOps, casadi_ops, torch_ops
from audere.errors import InvalidArgumentError

if TYPE_CHECKING:
    import torch

__all__ = ["Dynamics", "IntegrationMethod"]

IntegrationMethod = Literal["euler", "rk4"]
"""Discretization of ``xdot = f(x, u)`` over one step of length ``dt`` with ``u`` held constant.

``"euler"``: ``x[k+1] = x[k] + dt * f(x[k], u[k])`` (the scheme of the benchmark scenarios).
``"rk4"``: the classical fourth-order Runge-Kutta step.
"""

_METHODS: tuple[str, ...] = get_args(IntegrationMethod)

# The names casadi.Function accepts.
_CASADI_NAME = re.compile(r"[A-Za-z](?:_?[A-Za-z0-9])*")

# Complex-step size: derivatives come out as Im(g(z + i h e_j)) / h with no subtractive
# cancellation, so h can be tiny and the result is exact to machine precision.
_COMPLEX_STEP = 1e-20


# A simulation that diverges returns inf/nan entries (visible in the result) instead of emitting
# floating-point RuntimeWarnings: sampling planners routinely roll out diverging input sequences.
def _quiet() -> np.errstate:
    return np.errstate(over="ignore", invalid="ignore", divide="ignore")


_METHOD_TEXT = {
    "euler": "explicit Euler: x[k+1] = x[k] + dt * f(x[k], u[k])",
    "rk4": (
        "classical 4th-order Runge-Kutta with u[k] held constant over the step: "
        "k1 = f(x[k], u[k]), k2 = f(x[k] + dt/2*k1, u[k]), k3 = f(x[k] + dt/2*k2, u[k]), "
        "k4 = f(x[k] + dt*k3, u[k]), x[k+1] = x[k] + dt/6*(k1 + 2*k2 + 2*k3 + k4)"
    ),
}


def _check_dt(dt: float) -> float:
    if isinstance(dt, (bool, str, bytes)):
        raise InvalidArgumentError(f"dt must be a positive finite number (seconds), got {dt!r}")
    try:
        value = float(dt)
    except (TypeError, ValueError):
        raise InvalidArgumentError(
            f"dt must be a positive finite number (seconds), got {type(dt).__name__}: {dt!r}"
        ) from None
    if not (math.isfinite(value) and value > 0.0):
        raise InvalidArgumentError(f"dt must be a positive finite number (seconds), got {value}")
    return value


def _check_method(method: str) -> str:
    if method not in _METHODS:
        raise InvalidArgumentError(
            f"method must be one of {', '.join(repr(m) for m in _METHODS)}, got {method!r}"
        )
    return method


def _broadcast(shapes: Sequence[tuple[str, tuple[int, ...]]]) -> tuple[int, ...]:
    try:
        return tuple(np.broadcast_shapes(*(s for _, s in shapes)))
    except ValueError:
        described = " and ".join(f"{name} with batch shape {shape}" for name, shape in shapes)
        raise InvalidArgumentError(f"{described} do not broadcast against each other") from None


@dataclasses.dataclass(frozen=True)
class Dynamics:
    """A continuous-time model ``xdot = f(x, u)`` with numpy, torch and CasADi evaluation.

    Subclasses are frozen dataclasses whose fields are the model's (float) parameters; they set
    the class variables below and implement :meth:`_f` once. Instances are immutable and
    hashable; build them with :func:`audere.dynamics.get_dynamics` or their class.

    Shapes: numpy and torch functions take states ``x`` of shape ``(..., n_x)`` and inputs ``u`` of
    shape ``(..., n_u)``; the leading (batch) dimensions broadcast against each other. CasADi
    functions take column vectors ``(n_x, 1)`` and ``(n_u, 1)``.
    """

    name: ClassVar[str] = ""
    """Registry name, e.g. ``"unicycle"``."""
    title: ClassVar[str] = ""
    """Human-readable name used in :meth:`describe`."""
    state_names: ClassVar[tuple[str, ...]] = ()
    """Names of the state components, in order."""
    input_names: ClassVar[tuple[str, ...]] = ()
    """Names of the input components, in order."""
    state_units: ClassVar[tuple[str, ...]] = ()
    """Units of the state components, in order."""
    input_units: ClassVar[tuple[str, ...]] = ()
    """Units of the input components, in order."""
    state_meanings: ClassVar[tuple[str, ...]] = ()
    """One short phrase per state component, for :meth:`describe`."""
    input_meanings: ClassVar[tuple[str, ...]] = ()
    """One short phrase per input component, for :meth:`describe`."""
    param_units: ClassVar[Mapping[str, str]] = {}
    """Unit of each parameter field."""
    param_rules: ClassVar[Mapping[str, Literal["positive", "nonnegative"]]] = {}
    """Sign constraint of each parameter field (parameters not listed only need to be finite)."""
    default_state_bounds: ClassVar[tuple[tuple[float, float], ...] | None] = None
    """Per-component ``(lower, upper)`` state bounds; ``None`` means unbounded."""
    default_input_bounds: ClassVar[tuple[tuple[float, float], ...] | None] = None
    """Per-component ``(lower, upper)`` input bounds; ``None`` means unbounded."""

    def __post_init__(self) -> None:
        for field in dataclasses.fields(self):
            value = getattr(self, field.name)
            if isinstance(value, (bool, str, bytes)) or not isinstance(value, (int, float, np.number)):
                raise InvalidArgumentError(
                    f"{self.name} parameter {field.name!r} must be a real number, "
                    f"got {type(value).__name__}: {value!r}"
                )
            number = float(value)
            if not math.isfinite(number):
                raise InvalidArgumentError(
                    f"{self.name} parameter {field.name!r} must be finite, got {number}"
                )
            rule = self.param_rules.get(field.name)
            if rule == "positive" and not number > 0.0:
                raise InvalidArgumentError(f"{self.name} parameter {field.name!r} must be > 0, got {number}")
            if rule == "nonnegative" and not number >= 0.0:
                raise InvalidArgumentError(f"{self.name} parameter {field.name!r} must be >= 0, got {number}")
            object.__setattr__(self, field.name, number)

    def _repr_pretty_(self, printer: Any, cycle: bool) -> None:
        """Pretty-print as the dataclass repr (parameters only) in IPython and Hypothesis reports."""
        printer.text(repr(self))

    # ------------------------------------------------------------------ the one definition

    def _f(self, x: Any, u: Any, ops: BackendOps) -> Any:
        """Continuous-time vector field, written once for every backend.

        Parameters
        ----------
        x
            State: array/tensor ``(..., n_x)`` or CasADi column ``(n_x, 1)``; read components with
            ``ops.get(x, i)``.
        u
            Input, same convention with ``n_u`` components.
        ops
            The backend operations; use only arithmetic and ``ops`` (keep it analytic: no ``abs``,
            ``max`` or branches on values).

        Returns
        -------
        Any
            ``xdot`` built with ``ops.stack([...])``, one entry per state component.
        """
        raise NotImplementedError(f"{type(self).__name__} must implement _f(self, x, u, ops)")

    def _position(self, x: Any, ops: BackendOps) -> Any:
        """Planar position of the robot; the default is the first two state components."""
        return ops.stack([ops.get(x, 0), ops.get(x, 1)])

    def _advance(self, x: Any, u: Any, dt: float, method: str, ops: BackendOps) -> Any:
        """One discrete step, generic over the backend (only arithmetic and ``_f``)."""
        if method == "euler":
            return x + dt * self._f(x, u, ops)
        k1 = self._f(x, u, ops)
        k2 = self._f(x + (0.5 * dt) * k1, u, ops)
        k3 = self._f(x + (0.5 * dt) * k2, u, ops)
        k4 = self._f(x + dt * k3, u, ops)
        return x + (dt / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4)

    # ------------------------------------------------------------------ sizes and bounds

    @property
    def n_x(self) -> int:
        """Number of state components."""
        return len(self.state_names)

    @property
    def n_u(self) -> int:
        """Number of input components."""
        return len(self.input_names)

    @property
    def params(self) -> dict[str, float]:
        """The model parameters as a plain dict (the keys :func:`get_dynamics` accepts)."""
        return {field.name: float(getattr(self, field.name)) for field in dataclasses.fields(self)}

    def _bounds(
        self, bounds: tuple[tuple[float, float], ...] | None, n: int, side: int
    ) -> NDArray[np.float64]:
        if bounds is None:
            values = np.full(n, -np.inf if side == 0 else np.inf)
        else:
            values = np.array([b[side] for b in bounds], dtype=np.float64)
        values.setflags(write=False)
        return values

    @property
    def state_lower(self) -> NDArray[np.float64]:
        """Default lower state bounds ``(n_x,)`` (``-inf`` where unbounded)."""
        return self._bounds(self.default_state_bounds, self.n_x, 0)

    @property
    def state_upper(self) -> NDArray[np.float64]:
        """Default upper state bounds ``(n_x,)`` (``+inf`` where unbounded)."""
        return self._bounds(self.default_state_bounds, self.n_x, 1)

    @property
    def input_lower(self) -> NDArray[np.float64]:
        """Default lower input bounds ``(n_u,)`` (``-inf`` where unbounded; tasks set their own)."""
        return self._bounds(self.default_input_bounds, self.n_u, 0)

    @property
    def input_upper(self) -> NDArray[np.float64]:
        """Default upper input bounds ``(n_u,)`` (``+inf`` where unbounded; tasks set their own)."""
        return self._bounds(self.default_input_bounds, self.n_u, 1)

    # ------------------------------------------------------------------ numpy validation

    def _labels(self, names: tuple[str, ...]) -> str:
        return "(" + ", ".join(names) + ")"

    def _np_vector(
        self, value: ArrayLike, *, name: str, n: int, names: tuple[str, ...]
    ) -> NDArray[np.float64]:
        arr = as_float_array(value, name=name, finite=False)
        if arr.ndim == 0 or arr.shape[-1] != n:
            raise InvalidArgumentError(
                f"{name} must have last dimension {n} {self._labels(names)}, got shape {tuple(arr.shape)}"
            )
        return as_float_array(arr, name=name)

    def _np_pair(self, x: ArrayLike, u: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        xa = self._np_vector(x, name="x", n=self.n_x, names=self.state_names)
        ua = self._np_vector(u, name="u", n=self.n_u, names=self.input_names)
        batch = _broadcast([("x", xa.shape[:-1]), ("u", ua.shape[:-1])])
        return np.broadcast_to(xa, (*batch, self.n_x)), np.broadcast_to(ua, (*batch, self.n_u))

    # ------------------------------------------------------------------ numpy backend

    def f(self, x: ArrayLike, u: ArrayLike) -> NDArray[np.float64]:
        """Continuous-time vector field ``xdot = f(x, u)`` (numpy, batched).

        Parameters
        ----------
        x
            State, shape ``(..., n_x)``.
        u
            Input, shape ``(..., n_u)``; its leading dimensions broadcast against those of ``x``.

        Returns
        -------
        numpy.ndarray
            Time derivative of the state, shape ``(..., n_x)`` (state units per second).
        """
        xa, ua = self._np_pair(x, u)
        with _quiet():
            return np.asarray(self._f(xa, ua, NUMPY_OPS), dtype=np.float64)

    def step(
        self, x: ArrayLike, u: ArrayLike, dt: float, *, method: IntegrationMethod = "euler"
    ) -> NDArray[np.float64]:
        """One discrete-time step from ``x`` with ``u`` held constant for ``dt`` (numpy, batched).

        Parameters
        ----------
        x
            State, shape ``(..., n_x)``.
        u
            Input, shape ``(..., n_u)``; its leading dimensions broadcast against those of ``x``.
        dt
            Step length in seconds, ``> 0``.
        method
            ``"euler"`` (``x + dt * f(x, u)``, the benchmark's scheme) or ``"rk4"``.

        Returns
        -------
        numpy.ndarray
            Next state, shape ``(..., n_x)``.
        """
        step_dt = _check_dt(dt)
        meth = _check_method(method)
        xa, ua = self._np_pair(x, u)
        with _quiet():
            return np.asarray(self._advance(xa, ua, step_dt, meth, NUMPY_OPS), dtype=np.float64)

    def rollout(
        self, x0: ArrayLike, inputs: ArrayLike, dt: float, *, method: IntegrationMethod = "euler"
    ) -> NDArray[np.float64]:
        """Simulate ``horizon`` steps from ``x0`` under ``inputs`` (numpy, batched over leading dims).

        Parameters
        ----------
        x0
            Initial state, shape ``(n_x,)`` or batched ``(..., n_x)``.
        inputs
            Input sequence, shape ``(horizon, n_u)`` or batched ``(..., horizon, n_u)``; its batch
            dimensions broadcast against those of ``x0`` (e.g. one ``x0`` and ``(B, horizon, n_u)``).
        dt
            Step length in seconds, ``> 0``.
        method
            ``"euler"`` or ``"rk4"`` (see :meth:`step`).

        Returns
        -------
        numpy.ndarray
            ``states`` of shape ``(..., horizon + 1, n_x)``; ``states[..., 0, :]`` is ``x0`` and
            ``states[..., k + 1, :] = step(states[..., k, :], inputs[..., k, :], dt)``.
        """
        step_dt = _check_dt(dt)
        meth = _check_method(method)
        x0a = self._np_vector(x0, name="x0", n=self.n_x, names=self.state_names)
        ua = self._np_inputs(inputs)
        batch = _broadcast([("x0", x0a.shape[:-1]), ("inputs", ua.shape[:-2])])
        horizon = ua.shape[-2]
        ua = np.broadcast_to(ua, (*batch, horizon, self.n_u))
        states = np.empty((*batch, horizon + 1, self.n_x), dtype=np.float64)
        x = np.broadcast_to(x0a, (*batch, self.n_x))
        states[..., 0, :] = x
        with _quiet():
            for k in range(horizon):
                x = self._advance(x, ua[..., k, :], step_dt, meth, NUMPY_OPS)
                states[..., k + 1, :] = x
        return states

    def _np_inputs(self, inputs: ArrayLike) -> NDArray[np.float64]:
        arr = as_float_array(inputs, name="inputs", finite=False)
        if arr.ndim < 2 or arr.shape[-1] != self.n_u:
            raise InvalidArgumentError(
                f"inputs must have shape (horizon, {self.n_u}) or (..., horizon, {self.n_u}) "
                f"{self._labels(self.input_names)}, got shape {tuple(arr.shape)}"
            )
        return as_float_array(arr, name="inputs")

    def position(self, states: ArrayLike) -> NDArray[np.float64]:
        """Planar position of the robot for each state (numpy, batched).

        Parameters
        ----------
        states
            States, shape ``(..., n_x)``.

        Returns
        -------
        numpy.ndarray
            Positions ``(..., 2)`` in metres: ``(x, y)`` for mobile robots, the bob for the
            pendulum, the end effector for the arm (see :meth:`describe`).
        """
        xa = self._np_vector(states, name="states", n=self.n_x, names=self.state_names)
        with _quiet():
            return np.asarray(self._position(xa, NUMPY_OPS), dtype=np.float64)

    # ------------------------------------------------------------------ linearization

    def _complex_jacobian(
        self, x: ArrayLike, u: ArrayLike, fun: Any
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        xa, ua = self._np_pair(x, u)
        n = self.n_x + self.n_u
        z = np.concatenate([xa, ua], axis=-1)
        # Row j of the perturbation block moves component j along the imaginary axis.
        zc = z[..., None, :] + (1j * _COMPLEX_STEP) * np.eye(n)
        with _quiet():
            out = fun(zc[..., : self.n_x], zc[..., self.n_x :])
        jac = np.swapaxes(np.asarray(out).imag / _COMPLEX_STEP, -1, -2)
        a = np.ascontiguousarray(jac[..., : self.n_x], dtype=np.float64)
        b = np.ascontiguousarray(jac[..., self.n_x :], dtype=np.float64)
        return a, b

    def linearize(
        self, x: ArrayLike, u: ArrayLike, dt: float, *, method: IntegrationMethod = "euler"
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Jacobians of the discrete step at ``(x, u)``: ``step(x + dx, u + du) ≈ step(x, u) + A dx + B du``.

        Computed by complex-step differentiation of the numpy definition (exact to machine
        precision; needs neither torch nor CasADi).

        Parameters
        ----------
        x
            Linearization state, shape ``(n_x,)`` or batched ``(..., n_x)``.
        u
            Linearization input, shape ``(n_u,)`` or batched ``(..., n_u)``.
        dt
            Step length in seconds, ``> 0``.
        method
            ``"euler"`` or ``"rk4"`` (see :meth:`step`).

        Returns
        -------
        tuple of numpy.ndarray
            ``A`` of shape ``(..., n_x, n_x)`` and ``B`` of shape ``(..., n_x, n_u)``.
        """
        step_dt = _check_dt(dt)
        meth = _check_method(method)
        return self._complex_jacobian(x, u, lambda xc, uc: self._advance(xc, uc, step_dt, meth, NUMPY_OPS))

    def linearize_continuous(
        self, x: ArrayLike, u: ArrayLike
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Jacobians of the vector field at ``(x, u)``: ``A = df/dx``, ``B = df/du``.

        Computed by complex-step differentiation of the numpy definition (exact to machine
        precision).

        Parameters
        ----------
        x
            Linearization state, shape ``(n_x,)`` or batched ``(..., n_x)``.
        u
            Linearization input, shape ``(n_u,)`` or batched ``(..., n_u)``.

        Returns
        -------
        tuple of numpy.ndarray
            ``A`` of shape ``(..., n_x, n_x)`` (1/s) and ``B`` of shape ``(..., n_x, n_u)``.
        """
        return self._complex_jacobian(x, u, lambda xc, uc: self._f(xc, uc, NUMPY_OPS))

    # ------------------------------------------------------------------ torch backend

    def _torch_tensor(self, torch: Any, value: Any, ref: Any, *, name: str) -> Any:
        if isinstance(value, torch.Tensor):
            return value
        arr = as_float_array(value, name=name, finite=False)
        if ref is None:
            return torch.as_tensor(arr)
        return torch.as_tensor(arr, dtype=ref.dtype, device=ref.device)

    def _torch_check(self, t: Any, *, name: str, n: int, names: tuple[str, ...], min_ndim: int = 1) -> None:
        if not t.is_floating_point():
            raise InvalidArgumentError(f"{name} must be a floating-point tensor, got dtype {t.dtype}")
        if t.ndim < min_ndim or t.shape[-1] != n:
            if min_ndim == 1:
                expected = f"last dimension {n} {self._labels(names)}"
            else:
                expected = f"shape (horizon, {n}) or (..., horizon, {n}) {self._labels(names)}"
            raise InvalidArgumentError(f"{name} must have {expected}, got shape {tuple(t.shape)}")
        torch = _torch_module()
        if not bool(torch.isfinite(t.detach()).all()):
            raise InvalidArgumentError(f"{name} must be finite, got a tensor with NaN or inf entries")

    def _torch_pair(
        self, a: Any, b: Any, *, names: tuple[str, str], min_ndims: tuple[int, int] = (1, 1)
    ) -> tuple[Any, Any]:
        torch = _torch_module()
        ref = a if isinstance(a, torch.Tensor) else b if isinstance(b, torch.Tensor) else None
        ta = self._torch_tensor(torch, a, ref, name=names[0])
        tb = self._torch_tensor(torch, b, ref if ref is not None else ta, name=names[1])
        self._torch_check(ta, name=names[0], n=self.n_x, names=self.state_names)
        self._torch_check(tb, name=names[1], n=self.n_u, names=self.input_names, min_ndim=min_ndims[1])
        if ta.dtype != tb.dtype:
            raise InvalidArgumentError(
                f"{names[0]} and {names[1]} must have the same dtype, got {ta.dtype} and {tb.dtype}"
            )
        if ta.device != tb.device:
            raise InvalidArgumentError(
                f"{names[0]} and {names[1]} must be on the same device, got {ta.device} and {tb.device}"
            )
        return ta, tb

    def f_torch(self, x: torch.Tensor, u: torch.Tensor) -> torch.Tensor:
        """Continuous-time vector field on torch tensors (batched, differentiable).

        Parameters
        ----------
        x
            State tensor ``(..., n_x)``; a non-tensor is converted to the other argument's dtype and device.
        u
            Input tensor ``(..., n_u)``; leading dimensions broadcast against those of ``x``.

        Returns
        -------
        torch.Tensor
            ``xdot`` of shape ``(..., n_x)``, with the dtype and device of the inputs.
        """
        tx, tu = self._torch_pair(x, u, names=("x", "u"))
        tx, tu = self._torch_expand(tx, tu, ("x", "u"))
        return cast("torch.Tensor", self._f(tx, tu, torch_ops()))

    def _torch_expand(self, tx: Any, tu: Any, names: tuple[str, str]) -> tuple[Any, Any]:
        batch = _broadcast([(names[0], tuple(tx.shape[:-1])), (names[1], tuple(tu.shape[:-1]))])
        return tx.expand(*batch, self.n_x), tu.expand(*batch, self.n_u)

    def step_torch(
        self, x: torch.Tensor, u: torch.Tensor, dt: float, *, method: IntegrationMethod = "euler"
    ) -> torch.Tensor:
        """One discrete-time step on torch tensors (batched, differentiable).

        Parameters
        ----------
        x
            State tensor ``(..., n_x)``; a non-tensor is converted to the other argument's dtype and device.
        u
            Input tensor ``(..., n_u)``; leading dimensions broadcast against those of ``x``.
        dt
            Step length in seconds, ``> 0``.
        method
            ``"euler"`` or ``"rk4"`` (see :meth:`step`).

        Returns
        -------
        torch.Tensor
            Next state ``(..., n_x)``, with the dtype and device of the inputs.
        """
        step_dt = _check_dt(dt)
        meth = _check_method(method)
        tx, tu = self._torch_pair(x, u, names=("x", "u"))
        tx, tu = self._torch_expand(tx, tu, ("x", "u"))
        return cast("torch.Tensor", self._advance(tx, tu, step_dt, meth, torch_ops()))

    def rollout_torch(
        self, x0: torch.Tensor, inputs: torch.Tensor, dt: float, *, method: IntegrationMethod = "euler"
    ) -> torch.Tensor:
        """Simulate ``horizon`` steps on torch tensors; gradients flow to ``x0`` and ``inputs``.

        Parameters
        ----------
        x0
            Initial state ``(n_x,)`` or batched ``(..., n_x)``; a non-tensor is converted to the
            dtype and device of ``inputs``.
        inputs
            Input sequence ``(horizon, n_u)`` or batched ``(..., horizon, n_u)``; batch dimensions
            broadcast against those of ``x0``.
        dt
            Step length in seconds, ``> 0``.
        method
            ``"euler"`` or ``"rk4"`` (see :meth:`step`).

        Returns
        -------
        torch.Tensor
            ``states`` of shape ``(..., horizon + 1, n_x)`` with the dtype and device of the inputs.
        """
        step_dt = _check_dt(dt)
        meth = _check_method(method)
        tmod = _torch_module()
        tx, tu = self._torch_pair(x0, inputs, names=("x0", "inputs"), min_ndims=(1, 2))
        batch = _broadcast([("x0", tuple(tx.shape[:-1])), ("inputs", tuple(tu.shape[:-2]))])
        horizon = tu.shape[-2]
        tu = tu.expand(*batch, horizon, self.n_u)
        x = tx.expand(*batch, self.n_x)
        ops = torch_ops()
        states = [x]
        for k in range(horizon):
            x = self._advance(x, tu[..., k, :], step_dt, meth, ops)
            states.append(x)
        return cast("torch.Tensor", tmod.stack(states, dim=-2))

    def position_torch(self, states: torch.Tensor) -> torch.Tensor:
        """Planar position for each state, on torch tensors (batched, differentiable).

        Parameters
        ----------
        states
            State tensor ``(..., n_x)``.

        Returns
        -------
        torch.Tensor
            Positions ``(..., 2)`` in metres (see :meth:`position`).
        """
        tmod = _torch_module()
        t = self._torch_tensor(tmod, states, None, name="states")
        self._torch_check(t, name="states", n=self.n_x, names=self.state_names)
        return cast("torch.Tensor", self._position(t, torch_ops()))

    # ------------------------------------------------------------------ CasADi backend

    def _casadi_column(self, value: Any, *, name: str, n: int, names: tuple[str, ...]) -> Any:
        ca = require("casadi", extra="casadi", purpose="the CasADi dynamics backend")
        if isinstance(value, (ca.SX, ca.MX, ca.DM)):
            col = value
        else:
            arr = as_float_array(value, name=name, finite=False)
            if arr.ndim == 1:
                arr = arr[:, None]
            col = ca.DM(arr) if arr.ndim == 2 else None
            if col is None:
                raise InvalidArgumentError(
                    f"{name} must be a column vector of shape ({n}, 1) {self._labels(names)}, "
                    f"got shape {tuple(arr.shape)}"
                )
        if tuple(col.shape) != (n, 1):
            raise InvalidArgumentError(
                f"{name} must be a column vector of shape ({n}, 1) {self._labels(names)}, "
                f"got shape {tuple(col.shape)}"
            )
        if isinstance(col, ca.DM) and not np.all(np.isfinite(col.full())):
            raise InvalidArgumentError(f"{name} must be finite, got {col.full().ravel().tolist()}")
        return col

    def f_casadi(self, x: Any, u: Any) -> Any:
        """Continuous-time vector field as a CasADi expression.

        Parameters
        ----------
        x
            State column ``(n_x, 1)``: ``casadi.SX``, ``casadi.MX`` or ``casadi.DM`` (a numpy vector
            is converted to ``DM``).
        u
            Input column ``(n_u, 1)``, same types.

        Returns
        -------
        casadi.SX or casadi.MX or casadi.DM
            ``xdot`` as a column ``(n_x, 1)``.
        """
        cx = self._casadi_column(x, name="x", n=self.n_x, names=self.state_names)
        cu = self._casadi_column(u, name="u", n=self.n_u, names=self.input_names)
        return self._f(cx, cu, casadi_ops())

    def step_casadi(self, x: Any, u: Any, dt: float, *, method: IntegrationMethod = "euler") -> Any:
        """One discrete-time step as a CasADi expression.

        Parameters
        ----------
        x
            State column ``(n_x, 1)``: ``casadi.SX``, ``casadi.MX`` or ``casadi.DM``.
        u
            Input column ``(n_u, 1)``, same types.
        dt
            Step length in seconds, ``> 0``.
        method
            ``"euler"`` or ``"rk4"`` (see :meth:`step`).

        Returns
        -------
        casadi.SX or casadi.MX or casadi.DM
            Next state as a column ``(n_x, 1)``.
        """
        step_dt = _check_dt(dt)
        meth = _check_method(method)
        cx = self._casadi_column(x, name="x", n=self.n_x, names=self.state_names)
        cu = self._casadi_column(u, name="u", n=self.n_u, names=self.input_names)
        return self._advance(cx, cu, step_dt, meth, casadi_ops())

    def casadi_function(self, dt: float, *, method: IntegrationMethod = "euler", name: str = "F") -> Any:
        """The discrete step as a ``casadi.Function`` ``(x, u) -> x_next`` built on ``SX`` symbols.

        Parameters
        ----------
        dt
            Step length in seconds, ``> 0``.
        method
            ``"euler"`` or ``"rk4"`` (see :meth:`step`).
        name
            Name of the CasADi function.

        Returns
        -------
        casadi.Function
            Inputs ``x`` ``(n_x, 1)`` and ``u`` ``(n_u, 1)``, output ``x_next`` ``(n_x, 1)``;
            use ``.map(N)`` to evaluate many columns at once.
        """
        step_dt = _check_dt(dt)
        meth = _check_method(method)
        if not isinstance(name, str) or not _CASADI_NAME.fullmatch(name) or name in ("null", "jac", "hess"):
            raise InvalidArgumentError(
                "name must start with a letter and contain only letters, digits and single underscores "
                f"(and not be 'null', 'jac' or 'hess'), got {name!r}"
            )
        ca = require("casadi", extra="casadi", purpose="the CasADi dynamics backend")
        x = ca.SX.sym("x", self.n_x)
        u = ca.SX.sym("u", self.n_u)
        x_next = self._advance(x, u, step_dt, meth, casadi_ops())
        return ca.Function(name, [x, u], [x_next], ["x", "u"], ["x_next"])

    def position_casadi(self, x: Any) -> Any:
        """Planar position as a CasADi expression.

        Parameters
        ----------
        x
            State column ``(n_x, 1)``: ``casadi.SX``, ``casadi.MX`` or ``casadi.DM``.

        Returns
        -------
        casadi.SX or casadi.MX or casadi.DM
            Position column ``(2, 1)`` in metres (see :meth:`position`).
        """
        cx = self._casadi_column(x, name="x", n=self.n_x, names=self.state_names)
        return self._position(cx, casadi_ops())

    # ------------------------------------------------------------------ description

    def _equations(self) -> list[str]:
        """The vector field in ASCII math, one line per state component."""
        raise NotImplementedError

    def _notes(self) -> list[str]:
        """Conventions worth stating (angles, what :meth:`position` returns)."""
        return ["position() (the planar point task checkers use) is (x, y)."]

    def describe(self, *, dt: float | None = None, method: IntegrationMethod = "euler") -> str:
        """A precise plain-text description of the model, for people and language models.

        Parameters
        ----------
        dt
            Step length in seconds to state in the discretization line; ``None`` leaves it symbolic.
        method
            The discretization to describe: ``"euler"`` or ``"rk4"``.

        Returns
        -------
        str
            Several lines: state and input with units, parameters, equations, bounds and the
            discrete-time update.
        """
        meth = _check_method(method)
        step_text = "dt" if dt is None else f"dt = {_check_dt(dt):g} s"
        states = "; ".join(
            f"{n} [{unit}] = {meaning}"
            for n, unit, meaning in zip(self.state_names, self.state_units, self.state_meanings, strict=True)
        )
        inputs = "; ".join(
            f"{n} [{unit}] = {meaning}"
            for n, unit, meaning in zip(self.input_names, self.input_units, self.input_meanings, strict=True)
        )
        lines = [
            f"Dynamics '{self.name}': {self.title}, continuous time xdot = f(x, u).",
            f"State x = {self._labels(self.state_names)}: {states}.",
            f"Input u = {self._labels(self.input_names)}: {inputs}.",
        ]
        if self.params:
            lines.append(
                "Parameters: "
                + ", ".join(
                    f"{k} = {v:g} {self.param_units.get(k, '')}".rstrip() for k, v in self.params.items()
                )
                + "."
            )
        lines.append("Equations: " + "; ".join(self._equations()) + ".")
        lines.extend(self._notes())
        state_bounds = self._describe_bounds(self.state_names, self.state_lower, self.state_upper)
        input_bounds = self._describe_bounds(self.input_names, self.input_lower, self.input_upper)
        lines.append(f"Default state bounds: {state_bounds}.")
        lines.append(f"Default input bounds: {input_bounds}.")
        lines.append(f"Discrete time with step {step_text}: {_METHOD_TEXT[meth]}.")
        return "\n".join(lines)

    def _describe_bounds(
        self, names: tuple[str, ...], lower: NDArray[np.float64], upper: NDArray[np.float64]
    ) -> str:
        parts = [
            f"{lo:g} <= {n} <= {hi:g}"
            for n, lo, hi in zip(names, lower, upper, strict=True)
            if np.isfinite(lo) or np.isfinite(hi)
        ]
        return ", ".join(parts) if parts else "none (unbounded; tasks may set their own)"


def _torch_module() -> Any:
    """The torch module, imported on first use (raises MissingDependencyError when absent)."""
    return require("torch", extra="torch", purpose="the torch dynamics backend")
