"""A whitelist grammar for the expressions of a line element: parsed into sympy, never evaluated as Python.

A scene file is data that may come from anyone, so its expressions are read by this small parser, not
by ``eval`` or ``sympy.sympify`` (which use Python's ``eval``). What it accepts:

- numbers: ``2``, ``0.5``, ``1e-3`` (kept exact, as rationals);
- names given by the caller (coordinates, differentials, parameters, definitions) and ``pi``;
- ``+ - * /``, powers ``**`` or ``^`` (right-associative; a numeric exponent at most
  :data:`MAX_EXPONENT` in size), parentheses;
- the functions of :data:`FUNCTIONS`: ``sqrt exp log sin cos tan sinh cosh tanh asin acos atan abs``
  and ``atan2(y, x)``.

Anything else (an attribute, a string, an unknown name or function, ``__import__``, a missing operator
between two factors) is an :class:`ExpressionError` that says what was expected at which column.
Expressions longer than :data:`MAX_LENGTH` characters or nested deeper than :data:`MAX_DEPTH` are refused.

Examples
--------
>>> import sympy
>>> r, M = sympy.symbols("r M", positive=True)
>>> parse_expression("1 - 2*M/r", {"r": r, "M": M})
-2*M/r + 1
>>> parse_expression("M r", {"r": r, "M": M})
Traceback (most recent call last):
...
warpviz.spacetime.line_element.grammar.ExpressionError: column 3: expected an operator (+ - * / **) or the end, got 'r'
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass

import sympy

__all__ = ["FUNCTIONS", "MAX_DEPTH", "MAX_EXPONENT", "MAX_LENGTH", "ExpressionError", "parse_expression"]

#: The functions an expression may call, and their sympy counterparts (one argument unless listed in _ARITY).
FUNCTIONS = {
    "sqrt": sympy.sqrt, "exp": sympy.exp, "log": sympy.log, "sin": sympy.sin, "cos": sympy.cos, "tan": sympy.tan,
    "sinh": sympy.sinh, "cosh": sympy.cosh, "tanh": sympy.tanh, "asin": sympy.asin, "acos": sympy.acos,
    "atan": sympy.atan, "abs": sympy.Abs, "atan2": sympy.atan2,
}  # fmt: skip
_ARITY = {"atan2": 2}

#: Longest expression accepted, in characters.
MAX_LENGTH = 4000
#: Deepest nesting of parentheses, function calls and unary signs.
MAX_DEPTH = 64
#: Largest numeric exponent (a power like x**1000000 would make the algebra explode).
MAX_EXPONENT = 64

_TOKEN = re.compile(r"\s*(?:(?P<number>(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)|(?P<name>[A-Za-z_][A-Za-z0-9_]*)"
                    r"|(?P<op>\*\*|[-+*/^(),]))")  # fmt: skip


class ExpressionError(ValueError):
    """A problem in an expression, at ``column`` (1-based) of its text.

    Attributes
    ----------
    column : int
        Where in the expression the problem is (1 = its first character).
    reason : str
        What is wrong, without the column.
    """

    def __init__(self, column: int, reason: str):
        super().__init__(f"column {column}: {reason}")
        self.column = column
        self.reason = reason


@dataclass(frozen=True)
class _Token:
    kind: str  # "number", "name", "op" or "end"
    text: str
    column: int  # 1-based


def _tokens(text: str) -> list[_Token]:
    out, pos = [], 0
    while pos < len(text):
        m = _TOKEN.match(text, pos)
        if m is None or m.end() == pos:
            rest = text[pos:].lstrip()
            if not rest:
                break
            col = len(text) - len(rest) + 1
            raise ExpressionError(col, f"unexpected character {rest[0]!r} (allowed: numbers, names, + - * / ** ^ ( ) ,)")
        kind = m.lastgroup
        out.append(_Token(kind, m.group(kind), m.start(kind) + 1))
        pos = m.end()
    out.append(_Token("end", "", len(text) + 1))
    return out


class _Parser:
    def __init__(self, text: str, names: Mapping[str, sympy.Basic]):
        self.tokens = _tokens(text)
        self.i = 0
        self.names = names
        self.depth = 0

    @property
    def tok(self) -> _Token:
        return self.tokens[self.i]

    def take(self) -> _Token:
        tok = self.tokens[self.i]
        self.i += 1
        return tok

    def expect(self, text: str, what: str) -> _Token:
        if self.tok.text != text or self.tok.kind != "op":
            got = "the end" if self.tok.kind == "end" else repr(self.tok.text)
            raise ExpressionError(self.tok.column, f"expected {what}, got {got}")
        return self.take()

    def nest(self, column: int) -> None:
        self.depth += 1
        if self.depth > MAX_DEPTH:
            raise ExpressionError(column, f"nested deeper than {MAX_DEPTH} levels")

    def expression(self) -> sympy.Basic:
        value = self.term()
        while self.tok.kind == "op" and self.tok.text in "+-":
            op = self.take().text
            right = self.term()
            value = value + right if op == "+" else value - right
        return value

    def term(self) -> sympy.Basic:
        value = self.unary()
        while self.tok.kind == "op" and self.tok.text in ("*", "/"):
            op = self.take()
            right = self.unary()
            if op.text == "/":
                if right == 0:
                    raise ExpressionError(op.column, "division by zero")
                value = value / right
            else:
                value = value * right
        return value

    def unary(self) -> sympy.Basic:
        if self.tok.kind == "op" and self.tok.text in "+-":
            op = self.take()
            self.nest(op.column)
            value = self.unary()
            self.depth -= 1
            return -value if op.text == "-" else value
        return self.power()

    def power(self) -> sympy.Basic:
        base = self.atom()
        if self.tok.kind == "op" and self.tok.text in ("**", "^"):
            op = self.take()
            self.nest(op.column)
            exponent = self.unary()  # right-associative: a**b**c = a**(b**c); a**-2 allowed
            self.depth -= 1
            if exponent.is_number and (not exponent.is_finite or abs(exponent) > MAX_EXPONENT):
                raise ExpressionError(op.column, f"exponent {exponent} is larger than {MAX_EXPONENT} in size")
            if base == 0 and exponent.is_number and exponent.is_negative:
                raise ExpressionError(op.column, "division by zero (0 to a negative power)")
            return base**exponent
        return base

    def atom(self) -> sympy.Basic:
        tok = self.take()
        if tok.kind == "number":
            value = sympy.Rational(tok.text)
            if abs(value) > sympy.Rational(10) ** 300:
                raise ExpressionError(tok.column, f"number {tok.text} is too large")
            return value
        if tok.kind == "name":
            if self.tok.kind == "op" and self.tok.text == "(":
                return self.call(tok)
            if tok.text == "pi":
                return sympy.pi
            if tok.text in self.names:
                return self.names[tok.text]
            if tok.text in FUNCTIONS:
                raise ExpressionError(tok.column, f"{tok.text} is a function: write {tok.text}(...)")
            known = ", ".join(sorted(self.names)) or "none"
            raise ExpressionError(tok.column, f"unknown name {tok.text!r} (names here: {known}, pi)")
        if tok.kind == "op" and tok.text == "(":
            self.nest(tok.column)
            value = self.expression()
            self.expect(")", "')'")
            self.depth -= 1
            return value
        got = "the end" if tok.kind == "end" else repr(tok.text)
        raise ExpressionError(tok.column, f"expected a number, a name or '(', got {got}")

    def call(self, name: _Token) -> sympy.Basic:
        if name.text not in FUNCTIONS:
            raise ExpressionError(name.column, f"unknown function {name.text!r} (functions: {', '.join(FUNCTIONS)})")
        self.take()  # "("
        self.nest(name.column)
        args = [self.expression()]
        while self.tok.kind == "op" and self.tok.text == ",":
            self.take()
            args.append(self.expression())
        self.expect(")", "',' or ')'")
        self.depth -= 1
        arity = _ARITY.get(name.text, 1)
        if len(args) != arity:
            raise ExpressionError(name.column, f"{name.text} takes {arity} argument{'s' if arity > 1 else ''}, "
                                               f"got {len(args)}")  # fmt: skip
        return FUNCTIONS[name.text](*args)


def parse_expression(text: str, names: Mapping[str, sympy.Basic]) -> sympy.Basic:
    """Parse ``text`` into a sympy expression over ``names``, by the whitelist grammar of this module.

    Parameters
    ----------
    text : str
        The expression, e.g. ``"-(1 - 2*M/r)*dt**2 + dr**2/(1 - 2*M/r) + r**2*dOmega**2"``.
    names : mapping of str to sympy.Basic
        The names it may use and what they stand for (symbols or expressions).

    Returns
    -------
    sympy.Basic

    Raises
    ------
    ExpressionError
        The text does not follow the grammar, uses an unknown name or function, is too long or too deep,
        divides by zero or has a huge exponent; the message names the column.
    """
    if not isinstance(text, str):
        raise ExpressionError(1, f"an expression must be a string, got {type(text).__name__}")
    if len(text) > MAX_LENGTH:
        raise ExpressionError(MAX_LENGTH + 1, f"longer than {MAX_LENGTH} characters")
    if not text.strip():
        raise ExpressionError(1, "the expression is empty")
    parser = _Parser(text, names)
    value = parser.expression()
    if parser.tok.kind != "end":
        raise ExpressionError(parser.tok.column, f"expected an operator (+ - * / **) or the end, got {parser.tok.text!r}")
    if value.has(sympy.zoo, sympy.nan) or value in (sympy.oo, -sympy.oo):
        raise ExpressionError(1, "the expression is infinite or undefined (a division by zero)")
    return value
