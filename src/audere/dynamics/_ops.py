"""The small set of array operations a dynamics definition is written against.

A model's equations are written once, in :meth:`audere.dynamics.Dynamics._f`, using ordinary
arithmetic (``+ - * / **``) and the few operations of :class:`BackendOps`. Three implementations
of that protocol evaluate the same definition on three backends:

- :data:`NUMPY_OPS`: arrays of shape ``(..., n)``, batched over the leading dimensions; works with
  complex dtypes, which :meth:`~audere.dynamics.Dynamics.linearize` relies on (complex-step
  differentiation);
- :func:`torch_ops`: tensors of shape ``(..., n)``, differentiable with autograd;
- :func:`casadi_ops`: CasADi ``SX``/``MX``/``DM`` column vectors of shape ``(n, 1)``.

torch and casadi are imported only when their ops are requested.
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import cache
from typing import Any, Protocol

import numpy as np

from audere._optional import require

__all__ = ["NUMPY_OPS", "BackendOps", "casadi_ops", "torch_ops"]


class BackendOps(Protocol):
    """Operations a model definition may use besides arithmetic.

    Every function must stay analytic (no ``abs``, ``max``, comparisons or branches on values)
    so that complex-step linearization and automatic differentiation stay exact.
    """

    def get(self, x: Any, i: int) -> Any:
        """Component ``i`` of ``x`` (the last axis for arrays, the row for CasADi columns)."""
        ...

    def stack(self, parts: Sequence[Any]) -> Any:
        """Stack components into a vector along the component axis (broadcasting batch shapes)."""
        ...

    def sin(self, a: Any) -> Any:
        """Elementwise sine."""
        ...

    def cos(self, a: Any) -> Any:
        """Elementwise cosine."""
        ...


class _NumpyOps:
    """numpy arrays ``(..., n)``; float or complex dtype."""

    name = "numpy"

    def get(self, x: Any, i: int) -> Any:
        return x[..., i]

    def stack(self, parts: Sequence[Any]) -> Any:
        return np.stack(np.broadcast_arrays(*parts), axis=-1)

    def sin(self, a: Any) -> Any:
        return np.sin(a)

    def cos(self, a: Any) -> Any:
        return np.cos(a)


class _TorchOps:
    """torch tensors ``(..., n)``; keeps dtype, device and the autograd graph."""

    name = "torch"

    def __init__(self, torch: Any) -> None:
        self._torch = torch

    def get(self, x: Any, i: int) -> Any:
        return x[..., i]

    def stack(self, parts: Sequence[Any]) -> Any:
        torch = self._torch
        ref = next(p for p in parts if isinstance(p, torch.Tensor))
        tensors = [
            p if isinstance(p, torch.Tensor) else torch.as_tensor(p, dtype=ref.dtype, device=ref.device)
            for p in parts
        ]
        return torch.stack(torch.broadcast_tensors(*tensors), dim=-1)

    def sin(self, a: Any) -> Any:
        return self._torch.sin(a)

    def cos(self, a: Any) -> Any:
        return self._torch.cos(a)


class _CasadiOps:
    """CasADi column vectors ``(n, 1)`` (``SX``, ``MX`` or ``DM``)."""

    name = "casadi"

    def __init__(self, casadi: Any) -> None:
        self._ca = casadi

    def get(self, x: Any, i: int) -> Any:
        return x[i]

    def stack(self, parts: Sequence[Any]) -> Any:
        return self._ca.vertcat(*parts)

    def sin(self, a: Any) -> Any:
        return self._ca.sin(a)

    def cos(self, a: Any) -> Any:
        return self._ca.cos(a)


NUMPY_OPS: BackendOps = _NumpyOps()
"""The numpy implementation of :class:`BackendOps` (batched, complex-safe)."""


@cache
def torch_ops() -> BackendOps:
    """The torch implementation of :class:`BackendOps` (imports torch on first use).

    Returns
    -------
    BackendOps
        Operations on tensors of shape ``(..., n)``.
    """
    torch = require("torch", extra="torch", purpose="the torch dynamics backend")
    return _TorchOps(torch)


@cache
def casadi_ops() -> BackendOps:
    """The CasADi implementation of :class:`BackendOps` (imports casadi on first use).

    Returns
    -------
    BackendOps
        Operations on CasADi column vectors of shape ``(n, 1)``.
    """
    casadi = require("casadi", extra="casadi", purpose="the CasADi dynamics backend")
    return _CasadiOps(casadi)
