"""The robust predicates give the exact signs (checked with rationals), on near-degenerate input too."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest

from audere.world._predicates import orient, point_circle_sign, segment_circle_sign

from .reference import exact_circle_segment_sign


def _exact_orient(a, b, c) -> int:
    ax, ay, bx, by, cx, cy = (Fraction(float(v)) for v in (*a, *b, *c))
    det = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)
    return (det > 0) - (det < 0)


def _triples(kind: str, n: int = 3000) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(["random", "near-line", "grid", "scaled"].index(kind))
    a = rng.uniform(-10, 10, (n, 2))
    b = rng.uniform(-10, 10, (n, 2))
    if kind == "random":
        c = rng.uniform(-10, 10, (n, 2))
    elif kind == "near-line":  # on the line through a and b, up to rounding: the hard cases
        c = a + rng.uniform(-2, 3, (n, 1)) * (b - a)
    elif kind == "grid":  # exact arithmetic, many exact zeros
        a, b = np.round(a * 2) / 2, np.round(b * 2) / 2
        c = a + rng.integers(-4, 5, (n, 1)) / 2 * (b - a)
    else:  # near-line, far from the origin
        a, b = a + 1e4, b + 1e4
        c = a + rng.uniform(-2, 3, (n, 1)) * (b - a)
    return a, b, c


@pytest.mark.parametrize("kind", ["random", "near-line", "grid", "scaled"])
def test_orient_is_exact(kind: str) -> None:
    a, b, c = _triples(kind)
    got = orient(a[:, 0], a[:, 1], b[:, 0], b[:, 1], c[:, 0], c[:, 1])
    expected = np.array([_exact_orient(*t) for t in zip(a, b, c, strict=True)])
    np.testing.assert_array_equal(got, expected)
    if kind == "grid":
        assert (expected == 0).mean() > 0.5  # the exact-zero cases are really there


def test_orient_broadcasts() -> None:
    a = np.array([[0.0, 0.0]])
    b = np.array([[1.0, 1.0]])
    c = np.array([[0.5, 0.5], [0.1 * 3, 0.3], [0.0, 1.0], [1.0, 0.0]])
    got = orient(a[:, 0, None], a[:, 1, None], b[:, 0, None], b[:, 1, None], c[:, 0], c[:, 1])
    assert got.shape == (1, 4)
    np.testing.assert_array_equal(got[0], [_exact_orient(a[0], b[0], x) for x in c])


def test_circle_signs_are_exact() -> None:
    from audere.world import Circle

    rng = np.random.default_rng(7)
    for _ in range(20):
        cx, cy = rng.uniform(-5, 5, 2)
        r = float(rng.uniform(0.5, 3))
        circle = Circle(center=(cx, cy), radius=r)
        angles = rng.uniform(0, 2 * np.pi, 200)
        # points on the circle up to rounding, and tangent segments through them
        x = cx + r * np.cos(angles)
        y = cy + r * np.sin(angles)
        tx, ty = -np.sin(angles), np.cos(angles)
        pts = np.c_[x, y]
        approx = np.hypot(x - cx, y - cy) - r
        got = point_circle_sign(x, y, np.float64(cx), np.float64(cy), np.float64(r), approx)
        np.testing.assert_array_equal(got, exact_circle_segment_sign(pts, pts, circle))
        p = pts - np.c_[tx, ty]
        q = pts + np.c_[tx, ty]
        e = q - p
        d = np.abs(e[:, 0] * (cy - p[:, 1]) - e[:, 1] * (cx - p[:, 0])) / np.hypot(e[:, 0], e[:, 1])
        got = segment_circle_sign(
            p[:, 0], p[:, 1], q[:, 0], q[:, 1], np.float64(cx), np.float64(cy), np.float64(r), d - r
        )
        np.testing.assert_array_equal(got, exact_circle_segment_sign(p, q, circle))
