"""Spacetimes from their line element: a whitelist grammar (:mod:`.grammar`), the metric tensor in the
renderer's Cartesian chart with its derivatives (:mod:`.tensor`), the C++ of the metric contract
(:mod:`.codegen`), compiled into a plugin of the core on first use (:mod:`.plugin`) and registered with a
Python class like a built-in metric (:mod:`.custom`, ``wv.Metric.from_line_element``), from the text a
teacher writes:

    -(1 - 2*M/r)*dt**2 + dr**2/(1 - 2*M/r) + r**2*dOmega**2

Parsing never runs Python's ``eval``; the algebra is sympy's. The guide is ``docs/line-element.md``.
"""

from warpviz.spacetime.line_element.codegen import metric_source
from warpviz.spacetime.line_element.grammar import ExpressionError, parse_expression
from warpviz.spacetime.line_element.tensor import LineElement, LineElementError

__all__ = ["ExpressionError", "LineElement", "LineElementError", "metric_source", "parse_expression"]
