"""Spacetimes from their line element: a whitelist grammar (:mod:`.grammar`), the metric tensor in the
renderer's Cartesian chart with its derivatives (:mod:`.tensor`) and the C++ of the metric contract
(:mod:`.codegen`), from the text a teacher writes:

    -(1 - 2*M/r)*dt**2 + dr**2/(1 - 2*M/r) + r**2*dOmega**2

Parsing never runs Python's ``eval``; the algebra is sympy's. Not yet wired into scenes or the renderer:
the generated C++ is checked by compiling it (``tests/test_line_element.py``), and a plugin loader is next.
"""

from warpviz.spacetime.line_element.codegen import metric_source
from warpviz.spacetime.line_element.grammar import ExpressionError, parse_expression
from warpviz.spacetime.line_element.tensor import LineElement, LineElementError

__all__ = ["ExpressionError", "LineElement", "LineElementError", "metric_source", "parse_expression"]
