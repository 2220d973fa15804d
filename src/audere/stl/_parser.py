"""The STL text syntax: a tokenizer and a hand-written recursive-descent parser.

Grammar (loosest first; whitespace is ignored between tokens)::

    formula    := disjunct ( "->" formula )?                 # implication, right-associative
    disjunct   := conjunct ( "|" conjunct )*                 # n-ary Or
    conjunct   := untilexpr ( "&" untilexpr )*               # n-ary And
    untilexpr  := unary ( "U" bounds unary )?                # non-associative: a U b U c is an error
    unary      := ( "!" | "G" bounds | "F" bounds )* atom
    atom       := "true" | "false" | "in" "(" NAME ")" | comparison | "(" formula ")"
    bounds     := "[" INT "," INT "]"
    comparison := linear ( "<=" | ">=" ) linear             # linear in x and y
    linear     := sign? term ( ( "+" | "-" ) term )*
    term       := factor ( "*" factor )*                    # at most one of x, y per term
    factor     := NUMBER | "x" | "y"
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass
from typing import Literal

from audere.errors import InvalidArgumentError
from audere.stl._formula import (
    FALSE,
    IDENTIFIER,
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
    Until,
)

__all__ = ["STLSyntaxError", "parse"]

MAX_NESTING = 50
"""Most parentheses and prefix operators (``!``, ``G``, ``F``) the parser accepts around any point."""


class STLSyntaxError(InvalidArgumentError):
    """The text is not a valid STL formula.

    The message says what was expected, what was found and where (1-based column, and line when
    the text has several), followed by the offending line and a caret under the position.

    Parameters
    ----------
    message
        What was expected and what was found, without the position.
    text
        The whole text being parsed.
    offset
        0-based character offset of the error in ``text``.
    """

    def __init__(self, message: str, text: str, offset: int) -> None:
        self.reason = message
        self.text = text
        self.offset = offset
        lines = text.split("\n")
        line_index = text.count("\n", 0, offset)
        self.line = line_index + 1
        self.column = offset - (text.rfind("\n", 0, offset) + 1) + 1
        where = f"column {self.column}" if len(lines) == 1 else f"line {self.line}, column {self.column}"
        source = lines[line_index] if line_index < len(lines) else ""
        super().__init__(f"{message} at {where}\n  {source}\n  {' ' * (self.column - 1)}^")


TokenKind = Literal["number", "name", "punct", "end"]


@dataclass(frozen=True, slots=True)
class _Token:
    kind: TokenKind
    text: str
    offset: int

    def describe(self) -> str:
        return "end of input" if self.kind == "end" else repr(self.text)


_NUMBER = re.compile(r"(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")
# Longest first, so that "->" is not read as "-" then ">".
_PUNCT: tuple[str, ...] = ("->", "<=", ">=", "==", "!=", "&&", "||")
_PUNCT += ("(", ")", "[", "]", ",", "!", "&", "|", "+", "-", "*", "<", ">", "=", "~")
_SPACE = re.compile(r"\s+")

# Words people reach for that the syntax spells differently, with the fix.
_WORD_HINTS = {
    "not": "write '!' for negation",
    "and": "write '&' for conjunction",
    "or": "write '|' for disjunction",
    "implies": "write '->' for implication",
    "always": "write G[a,b] for 'always'",
    "eventually": "write F[a,b] for 'eventually'",
    "until": "write U[a,b] for 'until'",
    "True": "write 'true' (lower case)",
    "False": "write 'false' (lower case)",
    "g": "write G[a,b] (upper case) for 'always'",
    "f": "write F[a,b] (upper case) for 'eventually'",
}
_PUNCT_HINTS = {
    "&&": "write a single '&' for conjunction",
    "||": "write a single '|' for disjunction",
    "~": "write '!' for negation",
    "<": "strict comparisons are not supported, write '<='",
    ">": "strict comparisons are not supported, write '>='",
    "=": "equality is not supported, write '<=' and/or '>='",
    "==": "equality is not supported, write '<=' and/or '>='",
    "!=": "'!=' is not supported, write '<=' or '>='",
}


def _tokenize(text: str) -> list[_Token]:
    tokens: list[_Token] = []
    pos = 0
    while pos < len(text):
        space = _SPACE.match(text, pos)
        if space:
            pos = space.end()
            continue
        number = _NUMBER.match(text, pos)
        if number:
            tokens.append(_Token("number", number.group(), pos))
            pos = number.end()
            continue
        name = IDENTIFIER.match(text, pos)
        if name:
            tokens.append(_Token("name", name.group(), pos))
            pos = name.end()
            continue
        for punct in _PUNCT:
            if text.startswith(punct, pos):
                tokens.append(_Token("punct", punct, pos))
                pos += len(punct)
                break
        else:
            raise STLSyntaxError(f"unexpected character {text[pos]!r}", text, pos)
    tokens.append(_Token("end", "", len(text)))
    return tokens


class _Parser:
    def __init__(self, text: str) -> None:
        self.text = text
        self.tokens = _tokenize(text)
        self.index = 0
        self.nesting = 0

    # -- helpers ----------------------------------------------------------------------------------

    @property
    def token(self) -> _Token:
        return self.tokens[self.index]

    def advance(self) -> _Token:
        token = self.tokens[self.index]
        if token.kind != "end":
            self.index += 1
        return token

    def at(self, text: str, kind: TokenKind = "punct") -> bool:
        return self.token.kind == kind and self.token.text == text

    def error(self, expected: str, token: _Token | None = None) -> STLSyntaxError:
        token = self.token if token is None else token
        hint = _hint(token)
        return STLSyntaxError(
            f"expected {expected}, found {token.describe()}" + (f" ({hint})" if hint else ""),
            self.text,
            token.offset,
        )

    def enter(self, offset: int) -> None:
        self.nesting += 1
        if self.nesting > MAX_NESTING:
            raise STLSyntaxError(
                f"formula nested too deeply (more than {MAX_NESTING} parentheses and prefix operators)",
                self.text,
                offset,
            )

    def expect(self, text: str, what: str) -> _Token:
        if not self.at(text):
            raise self.error(f"{text!r} {what}")
        return self.advance()

    # -- grammar ----------------------------------------------------------------------------------

    def parse(self) -> Formula:
        formula = self.formula()
        if self.token.kind != "end":
            raise self.error("an operator ('&', '|', '->', 'U[a,b]') or the end of the formula")
        return formula

    def formula(self) -> Formula:
        left = self.disjunct()
        if self.at("->"):
            self.advance()
            return Implies(left, self.operand_of("'->'", self.formula))
        return left

    def disjunct(self) -> Formula:
        items = [self.conjunct()]
        while self.at("|"):
            self.advance()
            items.append(self.operand_of("'|'", self.conjunct))
        return items[0] if len(items) == 1 else Or(tuple(items))

    def conjunct(self) -> Formula:
        items = [self.until()]
        while self.at("&"):
            self.advance()
            items.append(self.operand_of("'&'", self.until))
        return items[0] if len(items) == 1 else And(tuple(items))

    def until(self) -> Formula:
        left = self.unary()
        if not self.at("U", "name"):
            return left
        self.advance()
        lo, hi = self.bounds("U")
        right = self.operand_of("'U[a,b]'", self.unary)
        if self.at("U", "name"):
            raise STLSyntaxError(
                "ambiguous chain 'a U[..] b U[..] c': U is not associative, add parentheses, e.g. "
                "'(a U[0,5] b) U[0,5] c' or 'a U[0,5] (b U[0,5] c)'",
                self.text,
                self.token.offset,
            )
        return Until(lo, hi, left, right)

    def operand_of(self, operator: str, rule: Callable[[], Formula]) -> Formula:
        if self.token.kind == "end" or self.token.text in (")", "]", ",", "&", "|", "->"):
            raise self.error(f"a formula after {operator}")
        return rule()

    def unary(self) -> Formula:
        prefixes: list[tuple[str, int, int]] = []
        while True:
            start = self.token.offset
            if self.at("!"):
                self.advance()
                prefixes.append(("!", 0, 0))
            elif self.token.kind == "name" and self.token.text in ("G", "F"):
                op = self.advance().text
                lo, hi = self.bounds(op)
                prefixes.append((op, lo, hi))
            else:
                break
            self.enter(start)
        if prefixes and (self.token.kind == "end" or self.token.text in (")", "&", "|", "->", "]", ",")):
            raise self.error(f"a formula after {prefixes[-1][0]!r}")
        node = self.atom()
        self.nesting -= len(prefixes)
        for op, lo, hi in reversed(prefixes):
            if op == "!":
                node = Not(node)
            elif op == "G":
                node = Always(lo, hi, node)
            else:
                node = Eventually(lo, hi, node)
        return node

    def bounds(self, op: str) -> tuple[int, int]:
        if not self.at("["):
            raise self.error(f"'[' after {op!r} (time bounds are required, e.g. {op}[0,10])")
        self.advance()
        lo_token = self.token
        lo = self.step(f"a non-negative integer time bound after '{op}['")
        self.expect(",", "between the time bounds")
        hi = self.step("a non-negative integer time bound after ','")
        self.expect("]", "after time bound")
        if lo > hi:
            raise STLSyntaxError(
                f"time bounds must satisfy lo <= hi, got [{lo},{hi}]", self.text, lo_token.offset
            )
        return lo, hi

    def step(self, expected: str) -> int:
        token = self.token
        if token.kind != "number" or not token.text.isdigit():
            raise self.error(expected)
        self.advance()
        return int(token.text)

    def atom(self) -> Formula:
        token = self.token
        if self.at("("):
            self.advance()
            self.enter(token.offset)
            inner = self.operand_of("'('", self.formula)
            if not self.at(")"):
                raise self.error(f"')' to close the '(' opened at column {_column(self.text, token.offset)}")
            self.advance()
            self.nesting -= 1
            return inner
        if token.kind == "name":
            if token.text == "true":
                self.advance()
                return TRUE
            if token.text == "false":
                self.advance()
                return FALSE
            if token.text == "in":
                self.advance()
                self.expect("(", "after 'in'")
                name = self.token
                if name.kind != "name":
                    raise self.error("a region name (an identifier) after 'in('")
                self.advance()
                self.expect(")", "after region name")
                try:
                    return In(name.text)
                except InvalidArgumentError as exc:
                    raise STLSyntaxError(f"invalid region name: {exc}", self.text, name.offset) from None
            if token.text in ("x", "y"):
                return self.comparison()
        if token.kind == "number" or self.at("-") or self.at("+"):
            return self.comparison()
        raise self.error("a formula (in(NAME), a comparison such as x >= 1, true, false, '!', G, F or '(')")

    def comparison(self) -> Formula:
        start = self.token
        left = self.linear()
        op_token = self.token
        if not (self.at("<=") or self.at(">=")):
            raise self.error("'<=' or '>=' after the linear expression")
        self.advance()
        right = self.linear()
        a, b = left[0] - right[0], left[1] - right[1]
        if a == 0 and b == 0:
            raise STLSyntaxError(
                "a comparison must involve x or y (with non-zero total coefficient)", self.text, start.offset
            )
        op: Literal["<=", ">="] = "<=" if op_token.text == "<=" else ">="
        try:
            return Compare(a, b, op, right[2] - left[2])
        except InvalidArgumentError as exc:  # e.g. coefficients overflowing to inf
            raise STLSyntaxError(f"invalid comparison: {exc}", self.text, start.offset) from None

    def linear(self) -> tuple[float, float, float]:
        """Parse a linear expression; return its coefficients of x and y and its constant."""
        coef = [0.0, 0.0, 0.0]
        sign = 1.0
        if self.at("-") or self.at("+"):
            sign = -1.0 if self.advance().text == "-" else 1.0
        while True:
            slot, value = self.term()
            coef[slot] += sign * value
            if self.at("+") or self.at("-"):
                sign = -1.0 if self.advance().text == "-" else 1.0
            else:
                return coef[0], coef[1], coef[2]

    def term(self) -> tuple[int, float]:
        """Parse a product of numbers and at most one variable; return (slot, value), slot 2 = constant."""
        slot, value = self.factor()
        while self.at("*"):
            star = self.advance()
            other_slot, other = self.factor()
            if slot != 2 and other_slot != 2:
                raise STLSyntaxError(
                    "nonlinear term: only linear comparisons in x and y are allowed", self.text, star.offset
                )
            slot = other_slot if slot == 2 else slot
            value *= other
        return slot, value

    def factor(self) -> tuple[int, float]:
        token = self.token
        if token.kind == "number":
            self.advance()
            value = float(token.text)
            if value == float("inf"):
                raise STLSyntaxError(f"number {token.text} is too large", self.text, token.offset)
            if self.token.kind == "name" and self.token.text in ("x", "y"):
                raise self.error(f"'*' between {token.text!r} and {self.token.text!r}")
            return 2, value
        if token.kind == "name" and token.text in ("x", "y"):
            self.advance()
            return (0 if token.text == "x" else 1), 1.0
        raise self.error("a number, x or y")


def _column(text: str, offset: int) -> int:
    return offset - (text.rfind("\n", 0, offset) + 1) + 1


def _hint(token: _Token) -> str:
    if token.kind == "name":
        if token.text in _WORD_HINTS:
            return _WORD_HINTS[token.text]
        if token.text not in ("in", "true", "false", "x", "y", "G", "F", "U"):
            return f"regions are written in({token.text}); comparisons use x and y"
    if token.kind == "punct":
        return _PUNCT_HINTS.get(token.text, "")
    return ""


def parse(text: str) -> Formula:
    """Parse the STL text syntax into a formula tree.

    Example: ``F[10,17] in(E) & G[0,20] (!in(B) & !in(C)) & (!in(D) U[0,20] in(A))``. Precedence,
    loosest first: ``->`` (right-associative), ``|``, ``&``, ``U[a,b]`` (not associative), the
    prefix operators ``!``, ``G[a,b]``, ``F[a,b]``, then atoms ``in(NAME)``, linear comparisons
    such as ``2*x - y <= 1``, ``true``, ``false`` and parenthesized formulas. See ``docs/stl.md``.

    Parameters
    ----------
    text
        The formula text; whitespace (including newlines) between tokens is ignored.

    Returns
    -------
    Formula
        The formula tree; ``parse(str(f)) == f`` for every formula ``f``.

    Raises
    ------
    STLSyntaxError
        When ``text`` is not a formula: the message says what was expected, what was found and at
        which column, with a caret under the position.
    InvalidArgumentError
        When ``text`` is not a string.
    """
    if not isinstance(text, str):
        raise InvalidArgumentError(f"text must be a str, got {type(text).__name__} {text!r}")
    return _Parser(text).parse()
