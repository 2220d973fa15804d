"""The text syntax: a table of good inputs and their trees, bad inputs and their messages, and the
printer/parser round trip."""

from __future__ import annotations

import re

import pytest
from hypothesis import given
from hypothesis import strategies as st

from audere.errors import InvalidArgumentError
from audere.stl import (
    FALSE,
    TRUE,
    Always,
    And,
    Compare,
    Eventually,
    Formula,
    Implies,
    In,
    Not,
    Or,
    STLSyntaxError,
    Until,
    parse,
)

from .stl_strategies import any_formulas

A, B, C, D, E = (In(n) for n in "ABCDE")

GOOD = [
    (
        "F[10,17] in(E) & G[0,20] (!in(B) & !in(C)) & (!in(D) U[0,20] in(A))",
        And((Eventually(10, 17, E), Always(0, 20, And((Not(B), Not(C)))), Until(0, 20, Not(D), A))),
    ),
    ("in(A)", A),
    ("  in ( A ) ", A),
    ("in(key_2)", In("key_2")),
    ("in(région)", In("région")),
    ("in(G)", In("G")),
    ("true", TRUE),
    ("false", FALSE),
    ("!in(A)", Not(A)),
    ("!!in(A)", Not(Not(A))),
    ("G[0,5] in(A)", Always(0, 5, A)),
    ("G [ 0 , 5 ]\n\tin(A)", Always(0, 5, A)),
    ("F[3,3]in(A)", Eventually(3, 3, A)),
    ("G[0,5] F[1,2] !in(A)", Always(0, 5, Eventually(1, 2, Not(A)))),
    # precedence: | < & < U < prefix operators
    ("in(A) | in(B) & in(C)", Or((A, And((B, C))))),
    ("in(A) & in(B) | in(C)", Or((And((A, B)), C))),
    ("in(A) & in(B) U[0,3] in(C)", And((A, Until(0, 3, B, C)))),
    ("!in(A) U[0,3] in(B)", Until(0, 3, Not(A), B)),
    ("G[0,5] in(A) U[0,3] in(B)", Until(0, 3, Always(0, 5, A), B)),
    ("in(A) U[0,3] G[0,5] in(B)", Until(0, 3, A, Always(0, 5, B))),
    ("G[0,5] (in(A) U[0,3] in(B))", Always(0, 5, Until(0, 3, A, B))),
    ("(in(A) U[1,2] in(B)) U[0,3] in(C)", Until(0, 3, Until(1, 2, A, B), C)),
    ("in(A) | in(B) | in(C)", Or((A, B, C))),
    ("(in(A) | in(B)) | in(C)", Or((Or((A, B)), C))),
    ("((in(A)))", A),
    # implication: loosest, right-associative
    ("in(A) -> in(B) -> in(C)", Implies(A, Implies(B, C))),
    ("in(A) & in(B) -> in(C) | in(D)", Implies(And((A, B)), Or((C, D)))),
    ("(in(A) -> in(B)) -> in(C)", Implies(Implies(A, B), C)),
    # comparisons: linear in x and y, normalized to a*x + b*y op rhs
    ("x >= 3", Compare(1, 0, ">=", 3)),
    ("2*x - y <= 1", Compare(2, -1, "<=", 1)),
    ("-x+0.5*y>=-2.25", Compare(-1, 0.5, ">=", -2.25)),
    ("3 <= x", Compare(-1, 0, "<=", -3)),
    ("x + 1 <= y", Compare(1, -1, "<=", -1)),
    ("x*2 + x >= 1.5e1", Compare(3, 0, ">=", 15)),
    ("2*3*y <= .5", Compare(0, 6, "<=", 0.5)),
    ("+y >= 1e-3", Compare(0, 1, ">=", 0.001)),
    ("x >= 1 & y <= 2", And((Compare(1, 0, ">=", 1), Compare(0, 1, "<=", 2)))),
    ("!x >= 1", Not(Compare(1, 0, ">=", 1))),
    ("G[0,2] (x >= 1)", Always(0, 2, Compare(1, 0, ">=", 1))),
    ("x >= 1 -> in(A)", Implies(Compare(1, 0, ">=", 1), A)),
]


@pytest.mark.parametrize(("text", "tree"), GOOD)
def test_good_inputs(text: str, tree: Formula) -> None:
    assert parse(text) == tree
    assert parse(str(tree)) == tree


def test_the_example_prints_back_as_written() -> None:
    text = "F[10,17] in(E) & G[0,20] (!in(B) & !in(C)) & (!in(D) U[0,20] in(A))"
    assert str(parse(text)) == text


BAD = [
    ("", r"expected a formula .* found end of input at column 1"),
    ("   ", r"expected a formula .* found end of input at column 4"),
    ("G[0,20 in(A)", r"expected '\]' after time bound, found 'in' at column 8"),
    ("G[5,2] in(A)", r"time bounds must satisfy lo <= hi, got \[5,2\] at column 3"),
    ("G[0,2.5] in(A)", r"expected a non-negative integer time bound after ',', found '2.5' at column 5"),
    ("F[-1,2] in(A)", r"expected a non-negative integer time bound after 'F\[', found '-' at column 3"),
    ("G[0 2] in(A)", r"expected ',' between the time bounds, found '2' at column 5"),
    ("F in(A)", r"expected '\[' after 'F' \(time bounds are required, e\.g\. F\[0,10\]\), found 'in' at col"),
    ("in(A) U in(B)", r"expected '\[' after 'U' .* found 'in' at column 9"),
    ("in(A", r"expected '\)' after region name, found end of input at column 5"),
    ("in()", r"expected a region name \(an identifier\) after 'in\(', found '\)' at column 4"),
    ("in(1A)", r"expected a region name .* found '1' at column 4"),
    ("in A", r"expected '\(' after 'in', found 'A' .* at column 4"),
    ("A & in(B)", r"expected a formula .* found 'A' \(regions are written in\(A\); .*\) at column 1"),
    ("in(A) in(B)", r"expected an operator .* or the end of the formula, found 'in' at column 7"),
    ("in(A) &", r"expected a formula after '&', found end of input at column 8"),
    ("in(A) | | in(B)", r"expected a formula after '\|', found '\|' at column 9"),
    ("in(A) -> ", r"expected a formula after '->', found end of input at column 10"),
    ("!", r"expected a formula after '!', found end of input at column 2"),
    ("G[0,1]", r"expected a formula after 'G', found end of input at column 7"),
    ("(in(A)", r"expected '\)' to close the '\(' opened at column 1, found end of input at column 7"),
    ("()", r"expected a formula after '\(', found '\)' at column 2"),
    ("in(A))", r"expected an operator .* found '\)' at column 6"),
    ("in(A) U[0,1] in(B) U[0,2] in(C)", r"ambiguous chain .* U is not associative.* at column 20"),
    ("in(A) && in(B)", r"found '&&' \(write a single '&' for conjunction\) at column 7"),
    ("in(A) || in(B)", r"found '\|\|' \(write a single '\|' for disjunction\) at column 7"),
    ("not in(A)", r"found 'not' \(write '!' for negation\) at column 1"),
    ("in(A) and in(B)", r"found 'and' \(write '&' for conjunction\) at column 7"),
    ("~in(A)", r"found '~' \(write '!' for negation\) at column 1"),
    ("True", r"found 'True' \(write 'true' \(lower case\)\) at column 1"),
    ("g[0,1] in(A)", r"found 'g' \(write G\[a,b\] \(upper case\) for 'always'\) at column 1"),
    ("x > 3", r"expected '<=' or '>=' .* found '>' \(strict comparisons are not supported, write '>='\) at"),
    ("x == 3", r"found '==' \(equality is not supported, write '<=' and/or '>='\) at column 3"),
    ("x + 1", r"expected '<=' or '>=' after the linear expression, found end of input at column 6"),
    ("2x >= 1", r"expected '\*' between '2' and 'x', found 'x' at column 2"),
    ("x*y >= 1", r"nonlinear term: only linear comparisons in x and y are allowed at column 2"),
    ("3 >= 1", r"a comparison must involve x or y .* at column 1"),
    ("x - x >= 1", r"a comparison must involve x or y .* at column 1"),
    ("x >= ", r"expected a number, x or y, found end of input at column 6"),
    ("z >= 1", r"expected a formula .* found 'z' .* at column 1"),
    ("x >= 1e999", r"number 1e999 is too large at column 6"),
    ("in(A) @ in(B)", r"unexpected character '@' at column 7"),
    ("in(A) &\n  @", r"unexpected character '@' at line 2, column 3"),
    ("(" * 60 + "in(A)" + ")" * 60, r"nested too deeply \(more than 50 parentheses and prefix operators\)"),
    ("!" * 60 + "in(A)", r"formula nested too deeply"),
]


@pytest.mark.parametrize(("text", "message"), BAD)
def test_bad_inputs(text: str, message: str) -> None:
    with pytest.raises(STLSyntaxError, match=message) as info:
        parse(text)
    error = info.value
    assert isinstance(error, InvalidArgumentError)
    # the message ends with the offending line and a caret under the reported column
    *_, source, caret = str(error).split("\n")
    assert caret.index("^") - 2 == error.column - 1
    assert source[2:] == text.split("\n")[error.line - 1]


def test_error_attributes() -> None:
    with pytest.raises(STLSyntaxError) as info:
        parse("G[0,20 in(A)")
    assert (info.value.line, info.value.column, info.value.offset) == (1, 8, 7)
    assert info.value.reason == "expected ']' after time bound, found 'in'"
    lines = ["expected ']' after time bound, found 'in' at column 8", "  G[0,20 in(A)", "         ^"]
    assert str(info.value) == "\n".join(lines)


def test_parse_rejects_non_text() -> None:
    with pytest.raises(InvalidArgumentError, match=r"text must be a str, got bytes"):
        parse(b"in(A)")  # type: ignore[arg-type]


def test_nesting_limit_is_not_hit_by_reasonable_formulas() -> None:
    text = "(" * 25 + "G[0,1] " * 20 + "in(A)" + ")" * 25
    assert parse(text).horizon() == 20


@given(any_formulas)
def test_round_trip(formula: Formula) -> None:
    text = str(formula)
    assert parse(text) == formula
    assert str(parse(text)) == text


@given(any_formulas, st.sampled_from(["  ", "\n", "\t \n "]))
def test_round_trip_is_whitespace_insensitive(formula: Formula, space: str) -> None:
    text = re.sub(r" +", space, str(formula))
    assert parse(text) == formula
