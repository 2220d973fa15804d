"""Signal temporal logic over planar position signals.

Formulas are immutable trees (:class:`Formula` and its node classes) with a text syntax read by
:func:`parse` and printed by ``str(formula)``, for example::

    F[10,17] in(E) & G[0,20] (!in(B) & !in(C)) & (!in(D) U[0,20] in(A))

A formula is evaluated on ``positions``, an array (T+1, 2) whose row ``t`` is the position
``(x, y)`` at step ``t``, with ``regions`` mapping each name used in ``in(NAME)`` to a world shape:
:func:`robustness` (quantitative semantics), :func:`robustness_trace` (at every step),
:func:`satisfied` (boolean semantics, implemented separately) and :func:`explain` (per top-level
clause). :func:`to_nnf` pushes negations down to the predicates without changing the robustness.
See ``docs/stl.md`` for the grammar and the definitions.
"""

from __future__ import annotations

from audere.stl._explain import ClauseReport, explain
from audere.stl._formula import (
    FALSE,
    TRUE,
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
from audere.stl._nnf import to_nnf
from audere.stl._parser import STLSyntaxError, parse
from audere.stl._regions import RegionShape
from audere.stl._semantics import robustness, robustness_trace, satisfied

# Plain sorted() order (pinned by tests/test_package.py), not ruff's isort-style order.
__all__ = [  # noqa: RUF022
    "Always",
    "And",
    "ClauseReport",
    "Compare",
    "Constant",
    "Eventually",
    "FALSE",
    "Formula",
    "Implies",
    "In",
    "Not",
    "Or",
    "RegionShape",
    "STLSyntaxError",
    "TRUE",
    "Until",
    "conjunction",
    "disjunction",
    "explain",
    "parse",
    "robustness",
    "robustness_trace",
    "satisfied",
    "to_nnf",
]
