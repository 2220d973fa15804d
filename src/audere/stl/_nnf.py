"""Negation normal form: push negations down to the predicates, keeping robustness exact."""

from __future__ import annotations

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
    conjunction,
    disjunction,
)

__all__ = ["to_nnf"]


def to_nnf(formula: Formula) -> Formula:
    """Rewrite ``formula`` so that negation applies only to predicates.

    The result uses only predicates (``in(R)``, comparisons), negated predicates, ``true``,
    ``false``, ``&``, ``|``, ``G``, ``F`` and ``U`` (no ``->``). Every rewrite is an identity of
    the min/max robustness semantics, so the result has exactly the same robustness (and truth)
    at every step where the original is defined:

    - ``!!a = a``; ``!(a & b) = !a | !b``; ``!(a | b) = !a & !b``; ``a -> b = !a | b``;
    - ``!G[a,b] p = F[a,b] !p``; ``!F[a,b] p = G[a,b] !p``;
    - ``!(l U[a,b] r)`` is the conjunction over ``k = a .. b`` of
      ``G[k,k] !r | F[0,k-1] !l`` (the ``F`` part absent for ``k = 0``), since
      ``-max_k min(r(t+k), min_{j<k} l(t+j)) = min_k max(-r(t+k), max_{j<k} -l(t+j))``.
      This grows linearly with ``b - a``.

    Parameters
    ----------
    formula
        The formula to rewrite.

    Returns
    -------
    Formula
        An equivalent formula in negation normal form; its horizon is at most the original's.
    """
    if not isinstance(formula, Formula):
        raise InvalidArgumentError(
            f"formula must be an STL Formula, got {type(formula).__name__} {formula!r}"
        )
    return _nnf(formula, negate=False)


def _nnf(node: Formula, *, negate: bool) -> Formula:
    if isinstance(node, Constant):
        return Constant(node.value != negate)
    if isinstance(node, In | Compare):
        return Not(node) if negate else node
    if isinstance(node, Not):
        return _nnf(node.child, negate=not negate)
    if isinstance(node, And | Or):
        parts = tuple(_nnf(child, negate=negate) for child in node.operands)
        return Or(parts) if isinstance(node, And) == negate else And(parts)
    if isinstance(node, Implies):
        if negate:  # !(l -> r) = l & !r
            return And((_nnf(node.left, negate=False), _nnf(node.right, negate=True)))
        return Or((_nnf(node.left, negate=True), _nnf(node.right, negate=False)))
    if isinstance(node, Always | Eventually):
        child = _nnf(node.child, negate=negate)
        if isinstance(node, Always) != negate:
            return Always(node.lo, node.hi, child)
        return Eventually(node.lo, node.hi, child)
    if isinstance(node, Until):
        if not negate:
            return Until(node.lo, node.hi, _nnf(node.left, negate=False), _nnf(node.right, negate=False))
        not_left = _nnf(node.left, negate=True)
        not_right = _nnf(node.right, negate=True)
        terms: list[Formula] = []
        for k in range(node.lo, node.hi + 1):
            right_k = not_right if k == 0 else Always(k, k, not_right)
            terms.append(right_k if k == 0 else disjunction([right_k, Eventually(0, k - 1, not_left)]))
        return conjunction(terms)
    raise TypeError(f"not an STL formula node: {type(node).__name__}")  # pragma: no cover
