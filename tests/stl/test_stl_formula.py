"""Formula nodes: validation, structural equality, regions/horizon/clauses, operators, printing."""

from __future__ import annotations

import pytest

import audere.stl as stl
from audere.errors import InvalidArgumentError
from audere.stl import (
    FALSE,
    TRUE,
    Always,
    And,
    Compare,
    Constant,
    Eventually,
    Implies,
    In,
    Not,
    Or,
    Until,
    conjunction,
    disjunction,
    parse,
)

A, B, C = In("A"), In("B"), In("C")


def test_public_surface() -> None:
    assert stl.__all__ == sorted(stl.__all__)
    assert set(stl.__all__) == {
        "FALSE", "TRUE", "Always", "And", "ClauseReport", "Compare", "Constant", "Eventually",
        "Formula", "Implies", "In", "Not", "Or", "RegionShape", "STLSyntaxError", "Until",
        "conjunction", "disjunction", "explain", "parse", "robustness", "robustness_trace",
        "satisfied", "to_nnf",
    }  # fmt: skip
    assert issubclass(stl.STLSyntaxError, InvalidArgumentError)


def test_structural_equality_and_hashing() -> None:
    f1 = And((Always(0, 5, Not(A)), Eventually(2, 3, B)))
    f2 = And([Always(0, 5, Not(In("A"))), Eventually(2, 3, In("B"))])
    assert f1 == f2
    assert hash(f1) == hash(f2)
    assert len({f1, f2, Or((A, B))}) == 2
    assert Always(0, 5, A) != Eventually(0, 5, A)
    assert Always(0, 5, A) != Always(0, 6, A)
    assert Compare(1, 0, ">=", 3) == Compare(1.0, 0.0, ">=", 3.0)
    assert isinstance(Compare(1, 0, ">=", 3).a, float)


def test_nodes_are_frozen() -> None:
    f = Always(0, 5, A)
    with pytest.raises(AttributeError):
        f.hi = 7  # type: ignore[misc]


@pytest.mark.parametrize(
    ("build", "message"),
    [
        (lambda: Always(3, 2, A), r"Always: time bounds must satisfy 0 <= lo <= hi, got lo=3, hi=2"),
        (lambda: Eventually(-1, 2, A), r"Eventually: time bounds must satisfy 0 <= lo <= hi, got lo=-1"),
        (lambda: Until(0, 1.5, A, B), r"Until: hi must be an integer number of steps, got float 1.5"),
        (lambda: Always(True, 2, A), r"Always: lo must be an integer number of steps, got bool"),
        (lambda: And(()), r"And: operands must hold at least two formulas, got 0; use conjunction\(\)"),
        (lambda: Or((A,)), r"Or: operands must hold at least two formulas, got 1; use disjunction\(\)"),
        (lambda: And(A), r"And: operands must be a sequence of at least two formulas, got In"),
        (lambda: And((A, "in(B)")), r"And: operands\[1\] must be a Formula, got str 'in\(B\)' \(parse text"),
        (lambda: Not("A"), r"Not: child must be a Formula, got str"),
        (lambda: Implies(A, None), r"Implies: right must be a Formula, got NoneType"),
        (lambda: In("1A"), r"In: name must be an identifier .* got '1A'"),
        (lambda: In("a-b"), r"In: name must be an identifier"),
        (lambda: In(""), r"In: name must be an identifier"),
        (lambda: Compare(0, 0, ">=", 1), r"Compare: a and b .* must not both be zero"),
        (lambda: Compare(1, 0, ">", 1), r"Compare: op must be '<=' or '>=', got '>'"),
        (lambda: Compare(float("nan"), 0, ">=", 1), r"Compare: a must be finite, got nan"),
        (lambda: Compare(1, 0, ">=", float("inf")), r"Compare: rhs must be finite, got inf"),
        (lambda: Compare(1, "2", ">=", 1), r"Compare: b must be a real number, got str"),
        (lambda: Constant(1), r"Constant: value must be a bool, got int"),
    ],
)
def test_constructors_validate(build: object, message: str) -> None:
    with pytest.raises(InvalidArgumentError, match=message):
        build()  # type: ignore[operator]


def test_regions_horizon_clauses() -> None:
    f = parse("F[10,17] in(E) & G[0,20] (!in(B) & !in(C)) & (!in(D) U[0,20] in(A))")
    assert f.regions() == frozenset("ABCDE")
    assert f.horizon() == 20
    assert [str(c) for c in f.clauses()] == [
        "F[10,17] in(E)",
        "G[0,20] (!in(B) & !in(C))",
        "!in(D) U[0,20] in(A)",
    ]
    # horizons add up along nesting, take the max across operands
    assert parse("G[2,5] F[0,3] in(A)").horizon() == 8
    assert parse("(G[0,4] in(A)) U[1,2] F[0,7] in(B)").horizon() == 9
    assert parse("in(A) | F[3,3] x >= 1").horizon() == 3
    assert parse("true").horizon() == 0
    assert parse("true").regions() == frozenset()
    # nested conjunctions are flattened into clauses, in order; anything else is one clause
    assert And((And((A, B)), C)).clauses() == (A, B, C)
    assert Or((A, B)).clauses() == (Or((A, B)),)


def test_operators_build_flat_trees_like_the_parser() -> None:
    assert parse("in(A) & in(B) & in(C)") == A & B & C
    assert parse("in(A) | in(B) | in(C)") == A | B | C
    assert Not(A) == ~A
    assert parse("(in(A) & in(B)) | !in(C)") == (A & B) | ~C
    # explicitly nested trees are kept as built, and print with parentheses
    nested = And((And((A, B)), C))
    assert str(nested) == "(in(A) & in(B)) & in(C)"
    assert parse(str(nested)) == nested


def test_conjunction_and_disjunction_helpers() -> None:
    assert conjunction([]) == TRUE
    assert disjunction([]) == FALSE
    assert conjunction([A]) == A
    assert disjunction(iter([A, B])) == Or((A, B))
    assert conjunction((A, B, C)) == And((A, B, C))


@pytest.mark.parametrize(
    ("formula", "text"),
    [
        (Compare(2, -1, "<=", 1), "2*x - y <= 1"),
        (Compare(1, 0, ">=", 3), "x >= 3"),
        (Compare(0, -1, ">=", -2.5), "-y >= -2.5"),
        (Compare(-0.5, 1e-7, "<=", 1e20), "-0.5*x + 1e-07*y <= 1e+20"),
        (Compare(1.5e300, 1, "<=", 0), "1.5e+300*x + y <= 0"),
        (Not(Compare(1, 0, ">=", 3)), "!(x >= 3)"),
        (Always(0, 4, Compare(0, 1, "<=", 2)), "G[0,4] (y <= 2)"),
        (Not(Not(A)), "!!in(A)"),
        (Not(Always(0, 3, Eventually(1, 2, A))), "!G[0,3] F[1,2] in(A)"),
        (Always(0, 3, And((A, B))), "G[0,3] (in(A) & in(B))"),
        (Until(0, 5, Not(A), B), "!in(A) U[0,5] in(B)"),
        (Until(0, 5, Until(1, 2, A, B), C), "(in(A) U[1,2] in(B)) U[0,5] in(C)"),
        (Until(0, 5, A, Or((B, C))), "in(A) U[0,5] (in(B) | in(C))"),
        (Or((And((A, B)), C)), "(in(A) & in(B)) | in(C)"),
        (And((Or((A, B)), C)), "(in(A) | in(B)) & in(C)"),
        (Implies(A, Implies(B, C)), "in(A) -> in(B) -> in(C)"),
        (Implies(Implies(A, B), C), "(in(A) -> in(B)) -> in(C)"),
        (Or((Implies(A, B), C)), "(in(A) -> in(B)) | in(C)"),
        (And((TRUE, Not(FALSE))), "true & !false"),
    ],
)
def test_printer(formula: stl.Formula, text: str) -> None:
    assert str(formula) == text
    assert parse(text) == formula
