"""Array validation and the shared pydantic-compatible ndarray type.

``FloatArray`` is the one annotated ndarray type used in every JSON-facing model: it accepts
nested lists or arrays, stores a read-only ``float64`` ``numpy.ndarray``, rejects NaN and inf,
and serializes to nested lists.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Annotated, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from pydantic import PlainSerializer, PlainValidator, WithJsonSchema

from audere.errors import InvalidArgumentError

__all__ = ["FloatArray", "as_float_array", "describe_shape"]


def describe_shape(shape: Sequence[int | None]) -> str:
    """Render an expected shape such as ``(None, 2)`` as ``(k, 2)``."""
    names = iter("kmnpqr")
    parts = [str(d) if d is not None else next(names) for d in shape]
    return "(" + ", ".join(parts) + ("," if len(parts) == 1 else "") + ")"


def as_float_array(
    value: ArrayLike,
    *,
    name: str,
    shape: Sequence[int | None] | None = None,
    ndim: int | None = None,
    finite: bool = True,
    min_len: int = 0,
) -> NDArray[np.float64]:
    """Convert ``value`` to a float64 array, checking shape and finiteness.

    Parameters
    ----------
    value
        Anything ``numpy.asarray`` accepts.
    name
        The argument's name, used in error messages.
    shape
        Expected shape; ``None`` entries match any length.
    ndim
        Expected number of dimensions (when ``shape`` is not given).
    finite
        Reject NaN and infinite entries.
    min_len
        Minimum length of the first axis.

    Returns
    -------
    numpy.ndarray
        A new float64 array.

    Raises
    ------
    InvalidArgumentError
        Naming ``name``, the expectation and what was received.
    """
    try:
        arr = np.array(value, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InvalidArgumentError(
            f"{name} must be an array of numbers, got {type(value).__name__}: {_short(value)} ({exc})"
        ) from None
    if shape is not None:
        ok = arr.ndim == len(shape) and all(
            e is None or e == d for e, d in zip(shape, arr.shape, strict=False)
        )
        if not ok:
            raise InvalidArgumentError(
                f"{name} must have shape {describe_shape(shape)}, got shape {tuple(arr.shape)}"
            )
    elif ndim is not None and arr.ndim != ndim:
        raise InvalidArgumentError(
            f"{name} must be a {ndim}-D array, got a {arr.ndim}-D array of shape {arr.shape}"
        )
    if arr.ndim >= 1 and arr.shape[0] < min_len:
        raise InvalidArgumentError(f"{name} must have at least {min_len} rows, got {arr.shape[0]}")
    if finite and not np.all(np.isfinite(arr)):
        bad = np.argwhere(~np.isfinite(arr))[0]
        where = ", ".join(str(int(i)) for i in bad)
        raise InvalidArgumentError(f"{name} must be finite, got {arr[tuple(bad)]} at index [{where}]")
    return arr


def _short(value: Any, limit: int = 80) -> str:
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _validate(value: Any) -> NDArray[np.float64]:
    if isinstance(value, np.ndarray) and value.dtype == np.float64 and not value.flags.writeable:
        arr = value
    else:
        arr = as_float_array(value, name="array")
        arr.setflags(write=False)
    if not np.all(np.isfinite(arr)):
        raise ValueError("array must be finite (no NaN or inf)")
    return arr


FloatArray = Annotated[
    NDArray[np.float64],
    PlainValidator(_validate),
    PlainSerializer(lambda a: np.asarray(a).tolist(), return_type=list),
    WithJsonSchema({"type": "array", "items": {}, "description": "numeric array (nested lists)"}),
]
"""A read-only float64 ndarray field: validated from nested lists, dumped as nested lists."""
