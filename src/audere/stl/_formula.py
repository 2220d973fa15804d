"""STL formula trees: immutable nodes with structural equality, and the text printer.

Every node is a frozen dataclass, so formulas are hashable and two formulas are equal exactly when
their trees are equal. ``str(formula)`` prints the text syntax that :func:`audere.stl.parse` reads
back: ``parse(str(f)) == f`` for every formula ``f``.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable
from dataclasses import dataclass
from numbers import Integral, Real
from typing import Literal

from audere.errors import InvalidArgumentError

__all__ = [
    "FALSE",
    "TRUE",
    "Always",
    "And",
    "Compare",
    "Constant",
    "Eventually",
    "Formula",
    "Implies",
    "In",
    "Not",
    "Or",
    "Until",
    "conjunction",
    "disjunction",
]

IDENTIFIER = re.compile(r"[^\W\d]\w*")
"""What the tokenizer reads as a name (region names, keywords)."""


class Formula:
    """Base class of every STL formula node.

    A formula is evaluated on a planar position signal ``positions`` (array (T+1, 2)) at a step
    ``t``. Subclasses are frozen dataclasses; build them directly, with :func:`audere.stl.parse`,
    or with the operators ``a & b`` (:class:`And`), ``a | b`` (:class:`Or`) and ``~a``
    (:class:`Not`). The operators flatten: ``a & b & c`` is one three-way :class:`And`, as
    ``parse("a & b & c")`` is.
    """

    __slots__ = ()

    def children(self) -> tuple[Formula, ...]:
        """The direct subformulas, in order.

        Returns
        -------
        tuple of Formula
            Empty for predicates and constants.
        """
        return ()

    def regions(self) -> frozenset[str]:
        """The region names used by ``in(NAME)`` predicates anywhere in the formula.

        Returns
        -------
        frozenset of str
            The names; empty when the formula uses no region.
        """
        names: set[str] = set()
        stack: list[Formula] = [self]
        while stack:
            node = stack.pop()
            if isinstance(node, In):
                names.add(node.name)
            stack.extend(node.children())
        return frozenset(names)

    def horizon(self) -> int:
        """The number of steps after ``t`` the formula needs to be decided at ``t``.

        Predicates need 0 steps; ``G[a,b]``, ``F[a,b]`` and ``U[a,b]`` add ``b`` to what their
        operands need; the boolean connectives take the maximum over their operands. Evaluating at
        step ``t`` needs ``positions`` rows ``0 .. t + horizon``.

        Returns
        -------
        int
            The horizon, in steps (>= 0).
        """
        return max((child.horizon() for child in self.children()), default=0)

    def clauses(self) -> tuple[Formula, ...]:
        """The top-level conjuncts.

        Returns
        -------
        tuple of Formula
            The children of a top-level :class:`And` (nested conjunctions flattened, in order),
            or ``(self,)`` for any other formula.
        """
        return (self,)

    def __str__(self) -> str:
        return _format(self)

    def __and__(self, other: Formula) -> And:
        if not isinstance(other, Formula):
            return NotImplemented
        return And(_flatten(And, (self, other)))

    def __or__(self, other: Formula) -> Or:
        if not isinstance(other, Formula):
            return NotImplemented
        return Or(_flatten(Or, (self, other)))

    def __invert__(self) -> Not:
        return Not(self)


def _flatten(kind: type[And] | type[Or], parts: Iterable[Formula]) -> tuple[Formula, ...]:
    out: list[Formula] = []
    for part in parts:
        if isinstance(part, kind):
            out.extend(part.children())
        else:
            out.append(part)
    return tuple(out)


def _check_formula(value: object, *, owner: str, name: str) -> None:
    if not isinstance(value, Formula):
        hint = " (parse text with audere.stl.parse first)" if isinstance(value, str) else ""
        raise InvalidArgumentError(
            f"{owner}: {name} must be a Formula, got {type(value).__name__} {value!r}{hint}"
        )


def _as_steps(value: object, *, owner: str, name: str) -> int:
    if isinstance(value, bool) or not isinstance(value, Integral):
        raise InvalidArgumentError(
            f"{owner}: {name} must be an integer number of steps, got {type(value).__name__} {value!r}"
        )
    return int(value)


def _check_bounds(lo: object, hi: object, *, owner: str) -> tuple[int, int]:
    lo_i, hi_i = _as_steps(lo, owner=owner, name="lo"), _as_steps(hi, owner=owner, name="hi")
    if not 0 <= lo_i <= hi_i:
        raise InvalidArgumentError(
            f"{owner}: time bounds must satisfy 0 <= lo <= hi, got lo={lo_i}, hi={hi_i}"
        )
    return lo_i, hi_i


def _check_real(value: object, *, owner: str, name: str) -> float:
    if isinstance(value, bool) or not isinstance(value, Real):
        raise InvalidArgumentError(
            f"{owner}: {name} must be a real number, got {type(value).__name__} {value!r}"
        )
    out = float(value)
    if not math.isfinite(out):
        raise InvalidArgumentError(f"{owner}: {name} must be finite, got {out}")
    return out


@dataclass(frozen=True, slots=True)
class Constant(Formula):
    """The constant formula ``true`` or ``false`` (robustness +inf or -inf).

    Parameters
    ----------
    value
        The truth value.
    """

    value: bool

    def __post_init__(self) -> None:
        if not isinstance(self.value, bool):
            raise InvalidArgumentError(
                f"Constant: value must be a bool, got {type(self.value).__name__} {self.value!r}"
            )


TRUE = Constant(True)
"""The formula ``true``."""

FALSE = Constant(False)
"""The formula ``false``."""


@dataclass(frozen=True, slots=True)
class In(Formula):
    """The predicate ``in(NAME)``: the position is inside the named region.

    Parameters
    ----------
    name
        Region name, an identifier (letters, digits and underscores, not starting with a digit),
        looked up in the ``regions`` mapping at evaluation.
    """

    name: str

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not (
            self.name.isidentifier() and IDENTIFIER.fullmatch(self.name)
        ):
            raise InvalidArgumentError(
                "In: name must be an identifier (letters, digits, underscores, not starting with a "
                f"digit), got {self.name!r}"
            )


@dataclass(frozen=True, slots=True)
class Compare(Formula):
    """A linear predicate on the position ``(x, y)``: ``a*x + b*y <= rhs`` or ``a*x + b*y >= rhs``.

    Its robustness is the signed margin ``rhs - (a*x + b*y)`` for ``<=`` and ``(a*x + b*y) - rhs``
    for ``>=`` (in metres times the coefficients); it holds when the relation holds as written
    (a point on the line satisfies both ``<=`` and ``>=``).

    Parameters
    ----------
    a
        Coefficient of ``x`` (finite).
    b
        Coefficient of ``y`` (finite); ``a`` and ``b`` are not both zero.
    op
        The relation, ``"<="`` or ``">="``.
    rhs
        Right-hand side (finite).
    """

    a: float
    b: float
    op: Literal["<=", ">="]
    rhs: float

    def __post_init__(self) -> None:
        for name in ("a", "b", "rhs"):
            object.__setattr__(self, name, _check_real(getattr(self, name), owner="Compare", name=name))
        if self.op not in ("<=", ">="):
            raise InvalidArgumentError(f"Compare: op must be '<=' or '>=', got {self.op!r}")
        if self.a == 0 and self.b == 0:
            raise InvalidArgumentError(
                "Compare: a and b (the coefficients of x and y) must not both be zero; use TRUE or FALSE "
                "for a constant"
            )


@dataclass(frozen=True, slots=True)
class Not(Formula):
    """Negation ``!child`` (robustness negated).

    Parameters
    ----------
    child
        The negated formula.
    """

    child: Formula

    def __post_init__(self) -> None:
        _check_formula(self.child, owner="Not", name="child")

    def children(self) -> tuple[Formula, ...]:
        return (self.child,)


def _check_children(node: And | Or) -> None:
    owner = type(node).__name__
    value: object = node.operands
    if isinstance(value, Formula | str) or not isinstance(value, Iterable):
        raise InvalidArgumentError(
            f"{owner}: operands must be a sequence of at least two formulas, "
            f"got {type(value).__name__} {value!r}"
        )
    items = tuple(value)
    if len(items) < 2:
        raise InvalidArgumentError(
            f"{owner}: operands must hold at least two formulas, got {len(items)}; use "
            f"{'conjunction' if owner == 'And' else 'disjunction'}() to accept any number"
        )
    for i, item in enumerate(items):
        _check_formula(item, owner=owner, name=f"operands[{i}]")
    object.__setattr__(node, "operands", items)


@dataclass(frozen=True, slots=True)
class And(Formula):
    """Conjunction of two or more formulas (robustness: the minimum).

    Parameters
    ----------
    operands
        The conjuncts, at least two, in order (any sequence; stored as a tuple). Nested
        conjunctions are kept as given (``And((And((a, b)), c))`` prints as ``(a & b) & c``).
    """

    operands: tuple[Formula, ...]

    def __post_init__(self) -> None:
        _check_children(self)

    def children(self) -> tuple[Formula, ...]:
        return self.operands

    def clauses(self) -> tuple[Formula, ...]:
        out: list[Formula] = []
        for child in self.operands:
            out.extend(child.clauses())
        return tuple(out)


@dataclass(frozen=True, slots=True)
class Or(Formula):
    """Disjunction of two or more formulas (robustness: the maximum).

    Parameters
    ----------
    operands
        The disjuncts, at least two, in order (any sequence; stored as a tuple).
    """

    operands: tuple[Formula, ...]

    def __post_init__(self) -> None:
        _check_children(self)

    def children(self) -> tuple[Formula, ...]:
        return self.operands


@dataclass(frozen=True, slots=True)
class Implies(Formula):
    """Implication ``left -> right``, the same as ``!left | right``.

    Parameters
    ----------
    left
        The premise.
    right
        The conclusion.
    """

    left: Formula
    right: Formula

    def __post_init__(self) -> None:
        _check_formula(self.left, owner="Implies", name="left")
        _check_formula(self.right, owner="Implies", name="right")

    def children(self) -> tuple[Formula, ...]:
        return (self.left, self.right)


@dataclass(frozen=True, slots=True)
class Always(Formula):
    """``G[lo,hi] child``: ``child`` holds at every step ``t+lo .. t+hi`` (robustness: the minimum).

    Parameters
    ----------
    lo
        First step of the window, relative to ``t`` (integer, >= 0).
    hi
        Last step of the window, relative to ``t`` (integer, >= lo).
    child
        The formula that must hold throughout.
    """

    lo: int
    hi: int
    child: Formula

    def __post_init__(self) -> None:
        lo, hi = _check_bounds(self.lo, self.hi, owner="Always")
        object.__setattr__(self, "lo", lo)
        object.__setattr__(self, "hi", hi)
        _check_formula(self.child, owner="Always", name="child")

    def children(self) -> tuple[Formula, ...]:
        return (self.child,)

    def horizon(self) -> int:
        return self.hi + self.child.horizon()


@dataclass(frozen=True, slots=True)
class Eventually(Formula):
    """``F[lo,hi] child``: ``child`` holds at some step ``t+lo .. t+hi`` (robustness: the maximum).

    Parameters
    ----------
    lo
        First step of the window, relative to ``t`` (integer, >= 0).
    hi
        Last step of the window, relative to ``t`` (integer, >= lo).
    child
        The formula that must hold at least once.
    """

    lo: int
    hi: int
    child: Formula

    def __post_init__(self) -> None:
        lo, hi = _check_bounds(self.lo, self.hi, owner="Eventually")
        object.__setattr__(self, "lo", lo)
        object.__setattr__(self, "hi", hi)
        _check_formula(self.child, owner="Eventually", name="child")

    def children(self) -> tuple[Formula, ...]:
        return (self.child,)

    def horizon(self) -> int:
        return self.hi + self.child.horizon()


@dataclass(frozen=True, slots=True)
class Until(Formula):
    """``left U[lo,hi] right``: ``right`` holds at some step ``t' in t+lo .. t+hi`` and ``left`` at every
    step ``t .. t'-1`` before it.

    Parameters
    ----------
    lo
        First step at which ``right`` may be met, relative to ``t`` (integer, >= 0).
    hi
        Last step at which ``right`` may be met, relative to ``t`` (integer, >= lo).
    left
        The formula that must hold until ``right`` does.
    right
        The formula that must eventually hold.
    """

    lo: int
    hi: int
    left: Formula
    right: Formula

    def __post_init__(self) -> None:
        lo, hi = _check_bounds(self.lo, self.hi, owner="Until")
        object.__setattr__(self, "lo", lo)
        object.__setattr__(self, "hi", hi)
        _check_formula(self.left, owner="Until", name="left")
        _check_formula(self.right, owner="Until", name="right")

    def children(self) -> tuple[Formula, ...]:
        return (self.left, self.right)

    def horizon(self) -> int:
        return self.hi + max(self.left.horizon(), self.right.horizon())


def conjunction(formulas: Iterable[Formula]) -> Formula:
    """The conjunction of any number of formulas.

    Parameters
    ----------
    formulas
        The conjuncts, in order.

    Returns
    -------
    Formula
        ``TRUE`` when there are none, the formula itself when there is one, else an :class:`And`.
    """
    items = tuple(formulas)
    if not items:
        return TRUE
    return items[0] if len(items) == 1 else And(items)


def disjunction(formulas: Iterable[Formula]) -> Formula:
    """The disjunction of any number of formulas.

    Parameters
    ----------
    formulas
        The disjuncts, in order.

    Returns
    -------
    Formula
        ``FALSE`` when there are none, the formula itself when there is one, else an :class:`Or`.
    """
    items = tuple(formulas)
    if not items:
        return FALSE
    return items[0] if len(items) == 1 else Or(items)


# --- printer -------------------------------------------------------------------------------------

# Binding strength, loosest first; a child binding looser than its context gets parentheses.
_IMPLIES, _OR, _AND, _UNTIL, _UNARY, _ATOM = range(6)


def _precedence(node: Formula) -> int:
    if isinstance(node, Implies):
        return _IMPLIES
    if isinstance(node, Or):
        return _OR
    if isinstance(node, And):
        return _AND
    if isinstance(node, Until):
        return _UNTIL
    if isinstance(node, Not | Always | Eventually):
        return _UNARY
    return _ATOM


def _number(value: float) -> str:
    """Shortest text that reads back as exactly ``value`` (integers without a decimal point)."""
    if value.is_integer() and abs(value) < 1e16:
        return str(int(value))
    return repr(value)


def _linear(a: float, b: float) -> str:
    parts: list[str] = []
    for coef, var in ((a, "x"), (b, "y")):
        if coef == 0:
            continue
        body = var if abs(coef) == 1 else f"{_number(abs(coef))}*{var}"
        if not parts:
            parts.append(f"-{body}" if coef < 0 else body)
        else:
            parts.append(f" - {body}" if coef < 0 else f" + {body}")
    return "".join(parts)


def _wrap(node: Formula, loosest: int) -> str:
    """Print ``node``, in parentheses when it binds looser than ``loosest``."""
    text = _format(node)
    return text if _precedence(node) >= loosest else f"({text})"


def _operand(node: Formula) -> str:
    """Print the operand of a prefix operator (comparisons parenthesized, for readability)."""
    if isinstance(node, Compare):
        return f"({_format(node)})"
    return _wrap(node, _UNARY)


def _format(node: Formula) -> str:
    if isinstance(node, Constant):
        return "true" if node.value else "false"
    if isinstance(node, In):
        return f"in({node.name})"
    if isinstance(node, Compare):
        return f"{_linear(node.a, node.b)} {node.op} {_number(node.rhs)}"
    if isinstance(node, Not):
        return f"!{_operand(node.child)}"
    if isinstance(node, Always):
        return f"G[{node.lo},{node.hi}] {_operand(node.child)}"
    if isinstance(node, Eventually):
        return f"F[{node.lo},{node.hi}] {_operand(node.child)}"
    if isinstance(node, Until):
        return f"{_wrap(node.left, _UNARY)} U[{node.lo},{node.hi}] {_wrap(node.right, _UNARY)}"
    if isinstance(node, And):
        # An Until operand is parenthesized too: not needed (U binds tighter), but easier to read.
        return " & ".join(_wrap(child, _UNARY) for child in node.operands)
    if isinstance(node, Or):
        return " | ".join(_wrap(child, _UNARY) for child in node.operands)
    if isinstance(node, Implies):
        return f"{_wrap(node.left, _OR)} -> {_wrap(node.right, _IMPLIES)}"
    raise TypeError(f"not an STL formula node: {type(node).__name__}")  # pragma: no cover
