"""Quantitative (robustness) and boolean semantics of STL, vectorized over time.

Both semantics are computed bottom-up as *traces*: for a node needing ``h`` steps (its horizon) on
a signal of ``n`` rows, the trace holds its value at every step ``t = 0 .. n - 1 - h``. Robustness
uses exact sliding-window minima and maxima (van Herk / Gil-Werman, O(n) per window); the boolean
semantics is implemented separately with window counts (cumulative sums), so the two can be tested
against each other.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from audere._arrays import as_float_array
from audere.errors import InvalidArgumentError
from audere.stl._formula import (
    Always,
    And,
    Compare,
    Constant,
    Eventually,
    Formula,
    Implies,
    In,
    Not,
    Or,
    Until,
)
from audere.stl._parser import parse
from audere.stl._regions import REGION_TYPES, RegionShape, region_robustness, region_truth

__all__ = ["Evaluation", "prepare", "robustness", "robustness_trace", "satisfied"]

FloatTrace = NDArray[np.float64]
BoolTrace = NDArray[np.bool_]


# --- validation ------------------------------------------------------------------------------------


@dataclass
class Evaluation:
    """A validated formula, signal and region mapping, with per-evaluation caches."""

    formula: Formula
    positions: NDArray[np.float64]
    regions: Mapping[str, RegionShape]
    robustness_cache: dict[str, FloatTrace] = field(default_factory=dict)
    truth_cache: dict[str, BoolTrace] = field(default_factory=dict)
    traces: dict[int, FloatTrace] | None = None


def prepare(
    formula: Formula | str,
    positions: ArrayLike,
    regions: Mapping[str, RegionShape],
    *,
    t: int,
) -> Evaluation:
    """Validate the arguments of the public evaluation functions.

    Parameters
    ----------
    formula
        A formula, or its text.
    positions
        Array (T+1, 2) of planar positions.
    regions
        Region name to shape; must define every name the formula uses.
    t
        Step at which the formula is evaluated (>= 0).

    Returns
    -------
    Evaluation
        The parsed formula, positions as a float64 array, and the regions.
    """
    if isinstance(formula, str):
        formula = parse(formula)
    elif not isinstance(formula, Formula):
        raise InvalidArgumentError(
            f"formula must be an STL Formula or its text, got {type(formula).__name__} {formula!r}"
        )
    array = as_float_array(positions, name="positions", shape=(None, 2))
    if len(array) == 0:
        raise InvalidArgumentError("positions must have at least one row (step 0), got shape (0, 2)")
    if not isinstance(regions, Mapping):
        raise InvalidArgumentError(
            f"regions must be a mapping from region name to shape, got {type(regions).__name__}"
        )
    used = formula.regions()
    missing = sorted(used - set(regions))
    if missing:
        given = ", ".join(sorted(map(str, regions))) or "none"
        raise InvalidArgumentError(
            f"regions is missing {', '.join(map(repr, missing))}, used by the formula (given: {given})"
        )
    for name in sorted(used):
        if not isinstance(regions[name], REGION_TYPES):
            raise InvalidArgumentError(
                f"regions[{name!r}] must be a Circle, Square, Rectangle, Polygon or Workspace, "
                f"got {type(regions[name]).__name__}"
            )
    if isinstance(t, bool) or not isinstance(t, int | np.integer):
        raise InvalidArgumentError(f"t must be an integer step, got {type(t).__name__} {t!r}")
    t = int(t)
    if t < 0:
        raise InvalidArgumentError(f"t must be >= 0, got {t}")
    horizon = formula.horizon()
    if len(array) < t + horizon + 1:
        raise InvalidArgumentError(
            f"positions is too short for the formula at t={t}: it needs {horizon} steps after t, that is "
            f"{t + horizon + 1} rows (steps 0..{t + horizon}), "
            f"got {len(array)} rows (steps 0..{len(array) - 1})"
        )
    return Evaluation(formula, array, regions)


# --- windows -----------------------------------------------------------------------------------------


def sliding_min(values: FloatTrace, width: int) -> FloatTrace:
    """Minimum over every window of ``width`` consecutive entries (exact, O(n)).

    Parameters
    ----------
    values
        Array (n,), n >= width.
    width
        Window length (>= 1).

    Returns
    -------
    numpy.ndarray
        Array (n - width + 1,): entry ``i`` is ``min(values[i : i + width])``.
    """
    if width == 1:
        return values.copy()
    n = len(values)
    n_blocks = -(-n // width)
    padded = np.full(n_blocks * width, np.inf)
    padded[:n] = values
    blocks = padded.reshape(n_blocks, width)
    prefix = np.minimum.accumulate(blocks, axis=1).ravel()
    suffix = np.minimum.accumulate(blocks[:, ::-1], axis=1)[:, ::-1].ravel()
    m = n - width + 1
    return np.minimum(suffix[:m], prefix[width - 1 : width - 1 + m])


def _sliding_max(values: FloatTrace, width: int) -> FloatTrace:
    return -sliding_min(-values, width)


def _window_counts(flags: BoolTrace, lo: int, hi: int, length: int) -> NDArray[np.int64]:
    """For t = 0 .. length-1, how many of ``flags[t+lo .. t+hi]`` are true."""
    cumulative = np.concatenate(([0], np.cumsum(flags, dtype=np.int64)))
    starts = np.arange(length) + lo
    return np.asarray(cumulative[starts + (hi - lo) + 1] - cumulative[starts], dtype=np.int64)


# --- robustness --------------------------------------------------------------------------------------


def rho(node: Formula, ev: Evaluation) -> FloatTrace:
    """Robustness trace of ``node``: its value at steps ``0 .. n - 1 - node.horizon()``."""
    out = _rho(node, ev)
    if ev.traces is not None:
        ev.traces[id(node)] = out
    return out


def _rho(node: Formula, ev: Evaluation) -> FloatTrace:
    n = len(ev.positions)
    if isinstance(node, Constant):
        return np.full(n, np.inf if node.value else -np.inf)
    if isinstance(node, In):
        cached = ev.robustness_cache.get(node.name)
        if cached is None:
            cached = region_robustness(ev.regions[node.name], ev.positions)
            ev.robustness_cache[node.name] = cached
        return cached
    if isinstance(node, Compare):
        s = node.a * ev.positions[:, 0] + node.b * ev.positions[:, 1]
        return np.asarray(s - node.rhs if node.op == ">=" else node.rhs - s, dtype=np.float64)
    if isinstance(node, Not):
        return -rho(node.child, ev)
    if isinstance(node, And | Or):
        traces = [rho(child, ev) for child in node.operands]
        length = min(len(trace) for trace in traces)
        reduce = np.minimum if isinstance(node, And) else np.maximum
        return np.asarray(reduce.reduce([trace[:length] for trace in traces], axis=0), dtype=np.float64)
    if isinstance(node, Implies):
        left, right = rho(node.left, ev), rho(node.right, ev)
        length = min(len(left), len(right))
        return np.maximum(-left[:length], right[:length])
    if isinstance(node, Always | Eventually):
        child = rho(node.child, ev)
        length = len(child) - node.hi
        window = child[node.lo : length + node.hi]
        width = node.hi - node.lo + 1
        return sliding_min(window, width) if isinstance(node, Always) else _sliding_max(window, width)
    if isinstance(node, Until):
        left, right = rho(node.left, ev), rho(node.right, ev)
        length = min(len(left), len(right)) - node.hi
        best = np.full(length, -np.inf)
        left_min = np.full(length, np.inf)  # min of left over [t, t+k)
        for k in range(node.hi + 1):
            if k >= node.lo:
                best = np.maximum(best, np.minimum(right[k : k + length], left_min))
            if k < node.hi:
                left_min = np.minimum(left_min, left[k : k + length])
        return best
    raise TypeError(f"not an STL formula node: {type(node).__name__}")  # pragma: no cover


# --- boolean semantics ------------------------------------------------------------------------------


def truth(node: Formula, ev: Evaluation) -> BoolTrace:
    """Boolean trace of ``node``: whether it holds at steps ``0 .. n - 1 - node.horizon()``."""
    n = len(ev.positions)
    if isinstance(node, Constant):
        return np.full(n, node.value)
    if isinstance(node, In):
        cached = ev.truth_cache.get(node.name)
        if cached is None:
            cached = region_truth(ev.regions[node.name], ev.positions)
            ev.truth_cache[node.name] = cached
        return cached
    if isinstance(node, Compare):
        s = node.a * ev.positions[:, 0] + node.b * ev.positions[:, 1]
        return np.asarray(s >= node.rhs if node.op == ">=" else s <= node.rhs)
    if isinstance(node, Not):
        return ~truth(node.child, ev)
    if isinstance(node, And | Or):
        traces = [truth(child, ev) for child in node.operands]
        length = min(len(trace) for trace in traces)
        stacked = np.stack([trace[:length] for trace in traces])
        return np.asarray(stacked.all(axis=0) if isinstance(node, And) else stacked.any(axis=0))
    if isinstance(node, Implies):
        left, right = truth(node.left, ev), truth(node.right, ev)
        length = min(len(left), len(right))
        return np.asarray(~left[:length] | right[:length], dtype=np.bool_)
    if isinstance(node, Always):
        child = truth(node.child, ev)
        return np.asarray(_window_counts(~child, node.lo, node.hi, len(child) - node.hi) == 0)
    if isinstance(node, Eventually):
        child = truth(node.child, ev)
        return np.asarray(_window_counts(child, node.lo, node.hi, len(child) - node.hi) > 0)
    if isinstance(node, Until):
        left, right = truth(node.left, ev), truth(node.right, ev)
        length = min(len(left), len(right)) - node.hi
        # first_false[t]: the first step >= t where left fails (len(left) if none): right must be met
        # at some t' in [t+lo, t+hi] with t' <= first_false[t].
        steps = np.arange(len(left))
        first_false = np.minimum.accumulate(np.where(left, len(left), steps)[::-1])[::-1]
        t = np.arange(length)
        start = t + node.lo
        end = np.minimum(t + node.hi, first_false[:length])
        cumulative = np.concatenate(([0], np.cumsum(right, dtype=np.int64)))
        safe_end = np.maximum(end, start - 1)
        return np.asarray((end >= start) & (cumulative[safe_end + 1] - cumulative[start] > 0))
    raise TypeError(f"not an STL formula node: {type(node).__name__}")  # pragma: no cover


# --- public functions -------------------------------------------------------------------------------


def _window(ev: Evaluation, t: int) -> Evaluation:
    """The evaluation restricted to the rows the formula needs at ``t`` (STL is shift-invariant)."""
    stop = t + ev.formula.horizon() + 1
    return Evaluation(ev.formula, ev.positions[t:stop], ev.regions)


def robustness(
    formula: Formula | str,
    positions: ArrayLike,
    regions: Mapping[str, RegionShape],
    *,
    t: int = 0,
) -> float:
    """Robustness of ``formula`` on the signal ``positions`` at step ``t``.

    Positive means satisfied with that margin, negative violated by that much (for region
    predicates the unit is metres). Exact discrete-time semantics: ``!`` negates, ``&`` is the
    minimum, ``|`` the maximum, ``G[a,b]`` the minimum over steps ``t+a .. t+b``, ``F[a,b]`` the
    maximum, ``l U[a,b] r`` the maximum over ``t' in t+a .. t+b`` of
    ``min(r(t'), min of l over t .. t'-1)``; see ``docs/stl.md``.

    Parameters
    ----------
    formula
        The specification, as a formula or its text.
    positions
        Array (T+1, 2): row ``k`` is the position ``(x, y)`` at step ``k``, in metres. Must have at
        least ``t + formula.horizon() + 1`` rows.
    regions
        Region name to shape (:class:`~audere.world.Circle`, :class:`~audere.world.Square`,
        :class:`~audere.world.Rectangle`, :class:`~audere.world.Polygon` or
        :class:`~audere.world.Workspace`); must define every name the formula uses.
    t
        Step at which to evaluate (>= 0).

    Returns
    -------
    float
        The robustness; ``inf`` or ``-inf`` only for formulas decided by ``true`` or ``false``.

    Raises
    ------
    InvalidArgumentError
        For a bad shape or non-finite positions, missing regions, a negative ``t``, or a signal
        too short for the formula's horizon at ``t``.
    """
    ev = _window(prepare(formula, positions, regions, t=t), t)
    return float(rho(ev.formula, ev)[0])


def robustness_trace(
    formula: Formula | str,
    positions: ArrayLike,
    regions: Mapping[str, RegionShape],
) -> NDArray[np.float64]:
    """Robustness of ``formula`` at every step where the signal is long enough to decide it.

    Parameters
    ----------
    formula
        The specification, as a formula or its text.
    positions
        Array (T+1, 2) of positions ``(x, y)`` in metres, at least ``formula.horizon() + 1`` rows.
    regions
        Region name to shape; must define every name the formula uses.

    Returns
    -------
    numpy.ndarray
        Array (T + 1 - formula.horizon(),): entry ``t`` equals
        ``robustness(formula, positions, regions, t=t)``.

    Raises
    ------
    InvalidArgumentError
        For bad positions, missing regions, or a signal shorter than the formula's horizon.
    """
    ev = prepare(formula, positions, regions, t=0)
    return rho(ev.formula, ev).copy()


def satisfied(
    formula: Formula | str,
    positions: ArrayLike,
    regions: Mapping[str, RegionShape],
    *,
    t: int = 0,
) -> bool:
    """Whether the signal ``positions`` satisfies ``formula`` at step ``t`` (boolean semantics).

    Computed independently of :func:`robustness`; the two agree wherever the robustness is not
    zero (positive robustness implies satisfied, negative implies violated). ``in(R)`` holds when
    the position is strictly inside ``R``; a comparison holds when it holds as written.

    Parameters
    ----------
    formula
        The specification, as a formula or its text.
    positions
        Array (T+1, 2) of positions ``(x, y)`` in metres, at least ``t + formula.horizon() + 1`` rows.
    regions
        Region name to shape; must define every name the formula uses.
    t
        Step at which to evaluate (>= 0).

    Returns
    -------
    bool
        True when the formula holds at ``t``.

    Raises
    ------
    InvalidArgumentError
        For bad positions, missing regions, a negative ``t``, or a signal too short at ``t``.
    """
    ev = _window(prepare(formula, positions, regions, t=t), t)
    return bool(truth(ev.formula, ev)[0])
