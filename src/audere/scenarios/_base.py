"""What every generator shares: the result type, the seeded retry loop, small geometric helpers."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TypeVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from audere.tasks import MazeTask, ReachAvoidTask, Solution, STLTask, TrackingTask

__all__ = ["AnyTask", "F", "Generated", "GenerationError", "Generator", "fixed", "retry", "rounded"]

AnyTask = TrackingTask | ReachAvoidTask | MazeTask | STLTask
F = NDArray[np.float64]

T = TypeVar("T")

MAX_ATTEMPTS = 200
"""Resampling budget of one generator; reaching it is a bug (every scenario succeeds in a few)."""


class GenerationError(RuntimeError):
    """A generator ran out of attempts (a bug in the generator, never a user error)."""


@dataclass(frozen=True)
class Generated:
    """A generated task and, when the generator can build one, a way to build a solution for it.

    Parameters
    ----------
    task
        The task.
    witness
        Builds a solution that the task's checker accepts (computed on demand: :func:`make` does
        not need it), or ``None`` when solvability is shown otherwise (the pendulum swing-up, whose
        witness controller lives in the tests).
    """

    task: AnyTask
    witness: Callable[[], Solution] | None


def fixed(solution: Solution) -> Callable[[], Solution]:
    """A witness builder returning ``solution``.

    Parameters
    ----------
    solution
        A solution already built by the generator.

    Returns
    -------
    callable
        A zero-argument function returning ``solution``.
    """
    return lambda: solution


Generator = Callable[[np.random.Generator, str], Generated]
"""A scenario generator: ``(rng, task_name) -> Generated``."""


def retry(attempt: Callable[[], T | None], *, what: str) -> T:
    """Call ``attempt`` until it returns something other than ``None``.

    Parameters
    ----------
    attempt
        Draws one candidate from the generator's random stream; ``None`` rejects it.
    what
        What is being drawn, for the error message.

    Returns
    -------
    T
        The first accepted candidate.

    Raises
    ------
    GenerationError
        After :data:`MAX_ATTEMPTS` rejections.
    """
    for _ in range(MAX_ATTEMPTS):
        out = attempt()
        if out is not None:
            return out
    raise GenerationError(f"could not draw {what} in {MAX_ATTEMPTS} attempts (a bug in audere.scenarios)")


DECIMALS = 3
"""Generated numbers are rounded to millimetres (and milliradians): readable task files and
descriptions. Every guarantee (clearances, bounds, witnesses) is checked after rounding."""


def rounded(values: ArrayLike) -> F:
    """``values`` rounded to :data:`DECIMALS` decimals, as a new float array.

    Parameters
    ----------
    values
        Any array of numbers.

    Returns
    -------
    numpy.ndarray
        The rounded copy, float64, same shape; ``-0.0`` normalized to ``0.0``.
    """
    return np.asarray(np.round(np.asarray(values, dtype=np.float64), DECIMALS) + 0.0, dtype=np.float64)
