"""Private helpers shared by the controllers (weight matrices)."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from audere._arrays import as_float_array
from audere.errors import InvalidArgumentError

F = NDArray[np.float64]


def square_weight(value: ArrayLike | None, n: int, *, name: str, default: float, over: str = "") -> F:
    """An ``(n, n)`` weight from ``None`` (``default`` times identity), a scalar, a diagonal or a matrix.

    Parameters
    ----------
    value
        The weight as given by the caller, or ``None``.
    n
        Size of the square matrix.
    name
        Argument name used in error messages.
    default
        Scale of the identity returned for ``None``.
    over
        Text inserted after the expected shapes in the error message (e.g. ``" over (x, y)"``).

    Returns
    -------
    numpy.ndarray
        The ``(n, n)`` matrix (not yet checked for symmetry or definiteness).
    """
    if value is None:
        return default * np.eye(n)
    arr = as_float_array(value, name=name)
    if arr.ndim == 0:
        return float(arr) * np.eye(n)
    if arr.shape == (n,):
        return np.diag(arr)
    if arr.shape == (n, n):
        return arr
    raise InvalidArgumentError(
        f"{name} must be a scalar, a diagonal of shape ({n},) or a matrix of shape ({n}, {n}){over}, "
        f"got shape {tuple(arr.shape)}"
    )
