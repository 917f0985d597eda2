"""Spacetimes from their line element: a whitelist grammar (:mod:`.grammar`) and the metric tensor in the
renderer's Cartesian chart with its derivatives (:mod:`.tensor`), from the text a teacher writes:

    -(1 - 2*M/r)*dt**2 + dr**2/(1 - 2*M/r) + r**2*dOmega**2

Parsing never runs Python's ``eval``; the algebra is sympy's.
"""

from warpviz.spacetime.line_element.grammar import ExpressionError, parse_expression

__all__ = ["ExpressionError", "parse_expression"]
