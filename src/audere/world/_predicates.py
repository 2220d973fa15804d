"""Robust geometric predicates: exact signs on floating-point input (private).

Each predicate first evaluates its expression in floating point together with an error bound; the
few entries whose sign the bound cannot certify are recomputed exactly with rational arithmetic
(:class:`fractions.Fraction` represents every float exactly). The signs are therefore those of the
exact expressions on the given coordinates, as in the robust predicates of shapely/GEOS, while
the common case stays vectorized.
"""

from __future__ import annotations

from collections.abc import Callable
from fractions import Fraction

import numpy as np
from numpy.typing import NDArray

F = NDArray[np.float64]
S = NDArray[np.int8]

_EPS = 2.0**-53
_ORIENT_BOUND = (3.0 + 16.0 * _EPS) * _EPS * 4.0
"""Shewchuk's first orient2d error bound, with a safety factor of 4."""

_RELATIVE_BOUND = 1e-12
"""Relative error bound used by the circle predicates (their float error is a few ulps)."""


def _refine(sign: S, ambiguous: NDArray[np.bool_], args: tuple[F, ...], exact: Callable[..., int]) -> S:
    """Replace ``sign`` where ``ambiguous`` by ``exact(*floats)`` evaluated on the broadcast inputs."""
    if not ambiguous.any():
        return sign
    full = np.broadcast_arrays(*args)
    sign = np.array(np.broadcast_to(sign, ambiguous.shape))
    for idx in zip(*np.nonzero(ambiguous), strict=True):
        sign[idx] = exact(*(float(a[idx]) for a in full))
    return sign


def _sgn(value: Fraction) -> int:
    return (value > 0) - (value < 0)


def _orient_exact(ax: float, ay: float, bx: float, by: float, cx: float, cy: float) -> int:
    a_x, a_y = Fraction(ax), Fraction(ay)
    return _sgn((Fraction(bx) - a_x) * (Fraction(cy) - a_y) - (Fraction(by) - a_y) * (Fraction(cx) - a_x))


def _diff_is_exact(a: F, b: F) -> NDArray[np.bool_]:
    """Is ``a - b`` computed without rounding (Knuth's two-difference error term is zero)."""
    x = a - b
    bv = a - x
    av = x + bv
    return np.asarray(((a - av) + (bv - b)) == 0)


_SPLITTER = 134217729.0  # 2**27 + 1


def _product_is_exact(a: F, b: F) -> NDArray[np.bool_]:
    """Is ``a * b`` computed without rounding (Dekker's two-product error term is zero)."""
    x = a * b
    ca = _SPLITTER * a
    a_hi = ca - (ca - a)
    a_lo = a - a_hi
    cb = _SPLITTER * b
    b_hi = cb - (cb - b)
    b_lo = b - b_hi
    err = a_lo * b_lo - (((x - a_hi * b_hi) - a_lo * b_hi) - a_hi * b_lo)
    return np.asarray(err == 0)


def orient(ax: F, ay: F, bx: F, by: F, cx: F, cy: F) -> S:
    """Exact sign of ``(b - a) x (c - a)``: +1 when ``c`` is left of the line ``a -> b``, 0 on it.

    Three stages: the float sign when Shewchuk's error bound certifies it; else the float sign when
    every difference and product was computed without rounding (common for coordinates on a coarse
    grid, where only the final subtraction rounds and rounding keeps signs); else exact rationals.
    """
    left = (bx - ax) * (cy - ay)
    right = (by - ay) * (cx - ax)
    det = left - right
    sign = np.sign(det).astype(np.int8)
    ambiguous = np.abs(det) <= _ORIENT_BOUND * (np.abs(left) + np.abs(right))
    # An exact zero with both products zero is certain (e.g. axis-aligned data): skip it.
    ambiguous &= (left != 0) | (right != 0)
    if not ambiguous.any():
        return sign
    args = np.broadcast_arrays(ax, ay, bx, by, cx, cy)
    idx = np.nonzero(ambiguous)
    a_x, a_y, b_x, b_y, c_x, c_y = (a[idx] for a in args)
    u1, v1, u2, v2 = b_x - a_x, c_y - a_y, b_y - a_y, c_x - a_x
    exact = (
        _diff_is_exact(b_x, a_x)
        & _diff_is_exact(c_y, a_y)
        & _diff_is_exact(b_y, a_y)
        & _diff_is_exact(c_x, a_x)
        & _product_is_exact(u1, v1)
        & _product_is_exact(u2, v2)
    )
    still = np.zeros(ambiguous.shape, dtype=bool)
    still[tuple(i[~exact] for i in idx)] = True
    return _refine(sign, still, (ax, ay, bx, by, cx, cy), _orient_exact)


def _point_circle_exact(x: float, y: float, cx: float, cy: float, r: float) -> int:
    dx, dy = Fraction(x) - Fraction(cx), Fraction(y) - Fraction(cy)
    return _sgn(dx * dx + dy * dy - Fraction(r) ** 2)


def point_circle_sign(x: F, y: F, cx: F, cy: F, r: F, approx: F) -> S:
    """Exact sign of ``|x - c| - r`` given its float value ``approx``."""
    sign = np.sign(approx).astype(np.int8)
    scale = np.abs(x - cx) + np.abs(y - cy) + r
    ambiguous = np.abs(approx) <= _RELATIVE_BOUND * scale
    return _refine(sign, np.asarray(ambiguous), (x, y, cx, cy, r), _point_circle_exact)


def _segment_circle_exact(px: float, py: float, qx: float, qy: float, cx: float, cy: float, r: float) -> int:
    p_x, p_y, q_x, q_y = Fraction(px), Fraction(py), Fraction(qx), Fraction(qy)
    c_x, c_y, rr = Fraction(cx), Fraction(cy), Fraction(r) ** 2
    dx, dy = q_x - p_x, q_y - p_y
    wx, wy = c_x - p_x, c_y - p_y
    dd = dx * dx + dy * dy
    t = wx * dx + wy * dy
    if dd == 0 or t <= 0:
        return _sgn(wx * wx + wy * wy - rr)
    if t >= dd:
        return _sgn((c_x - q_x) ** 2 + (c_y - q_y) ** 2 - rr)
    cross = dx * wy - dy * wx
    return _sgn(cross * cross - rr * dd)


def segment_circle_sign(px: F, py: F, qx: F, qy: F, cx: F, cy: F, r: F, approx: F) -> S:
    """Exact sign of ``dist(c, [p, q]) - r`` given its float value ``approx``."""
    sign = np.sign(approx).astype(np.int8)
    scale = np.abs(px - cx) + np.abs(py - cy) + np.abs(qx - cx) + np.abs(qy - cy) + r
    ambiguous = np.abs(approx) <= _RELATIVE_BOUND * scale
    return _refine(sign, np.asarray(ambiguous), (px, py, qx, qy, cx, cy, r), _segment_circle_exact)


def with_sign(value: F, sign: S) -> F:
    """``value`` with its sign forced to ``sign`` (0 where ``sign == 0``; the smallest normal number
    where rounding made the magnitude vanish)."""
    tiny = np.finfo(np.float64).tiny
    magnitude = np.maximum(np.abs(value), tiny)
    return np.asarray(np.where(sign == 0, 0.0, sign * magnitude))
