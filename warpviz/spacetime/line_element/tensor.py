"""The metric tensor of a line element, in the renderer's Cartesian chart (t, x, y, z), with its derivatives.

A line element is a sum of terms, each a coefficient times two differentials. Written in Cartesian
coordinates (``coordinates="cartesian"``) it may use ``t x y z``, their differentials ``dt dx dy dz``
and the helper ``r`` = √(x² + y² + z²). Written in spherical coordinates (``"spherical"``) it uses
``t r theta phi``, ``dt dr dtheta dphi`` and ``dOmega`` (only as ``dOmega**2`` = dθ² + sin²θ dφ²); it is
transformed to Cartesian coordinates, as the built-in metrics are, so that the poles are regular:

- r = √(x² + y² + z²), dr = (x dx + y dy + z dz) / r and r² dΩ² = dx² + dy² + dz² − dr²;
- θ and φ may appear only inside ``sin`` and ``cos`` (sin θ = ρ / r, cos θ = z / r, sin φ = y / ρ,
  cos φ = x / ρ with ρ = √(x² + y²)), and dθ, dφ by the chain rule;

``definitions`` are named helper expressions (``{"f": "1 - 2*M/r"}``), each may use the ones before it.
The parameters are symbols; their values are given when the metric is evaluated or compiled.

Examples
--------
>>> le = LineElement("-(1 - 2*M/r)*dt**2 + dr**2/(1 - 2*M/r) + r**2*dOmega**2", coordinates="spherical",
...                  parameters=["M"])
>>> le.g[0, 0]
(2*M - sqrt(x**2 + y**2 + z**2))/sqrt(x**2 + y**2 + z**2)
>>> import numpy as np
>>> g = le.metric_at([0.0, 3.0, 0.0, 4.0], {"M": 1.0})     # at r = 5: g_tt = -(1 - 2/5)
>>> round(float(g[0, 0]), 12), round(float(g[3, 3]), 12)   # g_zz = 1 + (1/f - 1) z²/r² = 1 + (2/3)(16/25)
(-0.6, 1.426666666667)
"""

from __future__ import annotations

import keyword
import re
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import sympy

from warpviz.spacetime.line_element.grammar import FUNCTIONS, ExpressionError, parse_expression

_FUNC_NAMES = set(FUNCTIONS)

__all__ = ["COORDINATES", "LineElement", "LineElementError"]

#: The coordinate systems a line element may be written in, and their coordinate names. ``wormhole``: a
#: static spherical wormhole in its proper radial distance l (−∞ < l < ∞, the two sheets at l > 0 and l < 0).
COORDINATES = {"cartesian": ("t", "x", "y", "z"), "spherical": ("t", "r", "theta", "phi"),
               "wormhole": ("t", "l", "theta", "phi")}  # fmt: skip

_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]{0,31}$")


def _shallow_expand(expr: sympy.Basic) -> sympy.Basic:
    """Products and integer powers multiplied out at the top level only (the differentials' polynomial),
    leaving what is inside functions and denominators alone."""
    return sympy.expand(expr, deep=False, mul=True, multinomial=True, power_exp=False, power_base=False, log=False)


class LineElementError(ValueError):
    """A line element, parameter or definition that cannot be used; ``where`` names which text
    (``"line_element"``, ``"definitions.f"``, ``"parameters"``) and ``column`` (1-based, or None) where in it."""

    def __init__(self, where: str, reason: str, column: int | None = None):
        at = f" (column {column})" if column is not None else ""
        super().__init__(f"{where}{at}: {reason}")
        self.where, self.reason, self.column = where, reason, column


class LineElement:
    """A spacetime from its line element: g_{μν} in Cartesian (t, x, y, z), symbolic, and its derivatives.

    Parameters
    ----------
    line_element : str
        The line element, e.g. ``"-(1 - 2*M/r)*dt**2 + dr**2/(1 - 2*M/r) + r**2*dOmega**2"``.
    coordinates : {"cartesian", "spherical"}, keyword-only
        What it is written in (module docstring).
    parameters : sequence of str, keyword-only
        The parameter names it uses (letters, digits, underscores; not a coordinate or function name).
    definitions : mapping of str to str, optional, keyword-only
        Named helper expressions, in order.

    Attributes
    ----------
    g : sympy.Matrix
        (4, 4) covariant metric in (t, x, y, z), symmetric, over the coordinate and parameter symbols.
    dg : list of sympy.Matrix
        ∂g/∂x^μ for μ = t, x, y, z.
    coords : tuple of sympy.Symbol
        t, x, y, z.
    params : tuple of sympy.Symbol
        The parameters, in the order given.

    Raises
    ------
    LineElementError
        A bad name, an expression the grammar refuses (with its column), a term that is not a coefficient
        times two differentials, θ or φ outside sin/cos, or a metric that is not Lorentzian somewhere
        obvious (it has no dt² or no spatial part).
    """

    def __init__(self, line_element: str, *, coordinates: str = "cartesian", parameters: Sequence[str] = (),
                 definitions: Mapping[str, str] | None = None, throat: str | None = None):  # fmt: skip
        if coordinates not in COORDINATES:
            raise LineElementError("coordinates", f"must be one of {', '.join(COORDINATES)}, got {coordinates!r}")
        self.coordinates = coordinates
        t, x, y, z = self.coords = sympy.symbols("t x y z", real=True)
        rho = sympy.sqrt(x**2 + y**2)
        r = sympy.sqrt(x**2 + y**2 + z**2)
        every = {*COORDINATES["cartesian"], *COORDINATES["spherical"], *COORDINATES[coordinates]}
        reserved = {"pi", "dOmega", *every} | {"d" + c for c in every}
        names: dict[str, Any] = {}
        for p in parameters:
            if not isinstance(p, str) or not _NAME.match(p) or keyword.iskeyword(p) or p in reserved or p in _FUNC_NAMES:
                raise LineElementError("parameters", f"{p!r} is not a usable parameter name (letters, digits and _, "
                                       "starting with a letter; not a coordinate, differential or function name)")
            if p in names:
                raise LineElementError("parameters", f"{p!r} is given twice")
            names[p] = sympy.Symbol(p, real=True)
        self.params = tuple(names.values())
        #: Scalar definitions in order: (symbol, expression, gradient symbols, gradient expressions).
        self.definitions: list[tuple] = []
        # the chart's symbols for the names an expression may use
        self._theta_phi = None
        #: ``wormhole`` coordinates: the chart's scale c (the throat's areal radius), as an expression of the
        #: parameters; None otherwise.
        self.chart_scale = None
        if coordinates == "cartesian":
            names.update({"t": t, "x": x, "y": y, "z": z, "r": self._define("r", r)})
            diffs = sympy.symbols("dt dx dy dz")
            names.update(dict(zip(("dt", "dx", "dy", "dz"), diffs)))
            to_cartesian = dict(zip(diffs, diffs))
            written_diffs = set(diffs)  # the differentials the text may use
        else:
            th, ph = sympy.symbols("theta phi", real=True)
            self._theta_phi = (th, ph)
            radial = "r" if coordinates == "spherical" else "l"
            d = sympy.symbols(f"dt d{radial} dtheta dphi dOmega")
            names.update(dict(zip(("dt", f"d{radial}", "dtheta", "dphi", "dOmega"), d)))
            written_diffs = set(d)
            dX = sympy.symbols("dx dy dz")
            diffs = (d[0], *dX)
            dr = (x * dX[0] + y * dX[1] + z * dX[2]) / r
            if coordinates == "spherical":
                names.update({"t": t, "r": r, "theta": th, "phi": ph})
                d_radial = dr
            else:  # l = (rho - c^2 / rho) / 2 in the chart radius rho = |x|: both sheets, regular at the throat
                if throat is None:
                    raise LineElementError("throat_radius", "coordinates = 'wormhole' needs throat_radius, the areal "
                                           "radius at l = 0 (it sets the chart: l = (rho - b^2/rho)/2)")  # fmt: skip
                c = self._parse(throat, names, "throat_radius")
                self.chart_scale = c
                names.update({"t": t, "l": (r - c**2 / r) / 2, "theta": th, "phi": ph})
                d_radial = (1 + c**2 / r**2) / 2 * dr
            to_cartesian = {d[0]: d[0], d[1]: d_radial,
                            d[2]: (z * (x * dX[0] + y * dX[1]) / rho - rho * dX[2]) / r**2,
                            d[3]: (x * dX[1] - y * dX[0]) / rho**2}  # fmt: skip
            self._domega2 = (dX[0] ** 2 + dX[1] ** 2 + dX[2] ** 2 - dr**2) / r**2
            self._omega = d[4]
        for name, text in (definitions or {}).items():
            where = f"definitions.{name}"
            if not isinstance(name, str) or not _NAME.match(name) or keyword.iskeyword(name) or name in names \
                    or name in reserved or name in _FUNC_NAMES:  # fmt: skip
                raise LineElementError("definitions", f"{name!r} is not a usable name for a definition (letters, "
                                       "digits and _; not a parameter, coordinate, differential or function name)")
            value = self._parse(text, names, where)  # (a one-form such as l = dt + x*dx/r is inlined)
            # a scalar is a symbol of its own with chain-rule gradients; a one-form, or a spherical definition
            # with theta or phi (converted with the line element's coefficients), is inlined
            angular = self._theta_phi is not None and (value.has(self._theta_phi[0]) or value.has(self._theta_phi[1]))
            if not value.free_symbols & written_diffs and not angular:
                names[name] = self._define(name, value)
            else:
                names[name] = value
        expr = self._parse(line_element, names, "line_element")
        #: The coefficient of dOmega**2 (the areal radius squared) in Cartesian symbols; 0 when not written so.
        self.areal_radius2 = sympy.Integer(0)
        self.g = self._components(expr, names, diffs, to_cartesian)
        self.dg = [self._d(self.g, mu) for mu in range(4)]

    def _define(self, name: str, value: sympy.Basic) -> sympy.Symbol:
        """A scalar definition as a symbol of its own, with symbols for its gradient (the chain rule keeps the
        derivatives as small as the definitions: Kerr's r(x, y, z) is not expanded into every component)."""
        sym = sympy.Symbol(name, real=True)
        grads = tuple(sympy.Symbol(f"d{name}_d{c}", real=True) for c in "txyz")
        self.definitions.append((sym, value, grads, tuple(self._d(value, mu) for mu in range(4))))
        return sym

    def _d(self, expr, mu: int):
        """∂expr/∂x^μ through the definitions (each definition's derivative is its gradient symbol)."""
        out = expr.diff(self.coords[mu])
        for sym, _, grads, grad_values in self.definitions:
            if expr.has(sym) and grad_values[mu] != 0:  # (∂_t r = 0: no term, so ∂_t g is exactly 0)
                out += expr.diff(sym) * grads[mu]
        return out

    @staticmethod
    def _parse(text: str, names: Mapping[str, Any], where: str) -> sympy.Basic:
        try:
            return parse_expression(text, names)
        except ExpressionError as exc:
            raise LineElementError(where, exc.reason, exc.column) from None

    def _spherical_to_cartesian(self, coeff: sympy.Basic, where: str) -> sympy.Basic:
        th, ph = self._theta_phi
        x, y, z = self.coords[1:]
        rho, r = sympy.sqrt(x**2 + y**2), sympy.sqrt(x**2 + y**2 + z**2)
        coeff = coeff.subs({sympy.sin(th): rho / r, sympy.cos(th): z / r, sympy.sin(ph): y / rho,
                            sympy.cos(ph): x / rho, sympy.tan(th): rho / z, sympy.tan(ph): y / x})  # fmt: skip
        if coeff.has(th) or coeff.has(ph):
            raise LineElementError(where, "theta and phi may appear only inside sin(...) and cos(...) (so that the "
                                   "metric is regular on the poles in Cartesian coordinates)")  # fmt: skip
        return coeff

    def _components(self, expr, names, diffs, to_cartesian) -> sympy.Matrix:
        gens = [s for s in (*diffs, *to_cartesian) if isinstance(s, sympy.Symbol)]
        gens = list(dict.fromkeys(gens + ([self._omega] if self._theta_phi is not None else [])))
        try:
            poly = sympy.Poly(_shallow_expand(expr), *gens)
        except sympy.PolynomialError:
            raise LineElementError("line_element", "every term must be a coefficient times two differentials "
                                   "(dt, dx, ...); a differential appears inside a function or a denominator") from None
        total = sympy.Integer(0)
        for monomial, coeff in poly.terms():
            degree = sum(monomial)
            if degree != 2:
                term = sympy.Mul(*(g**k for g, k in zip(gens, monomial)))
                raise LineElementError("line_element", f"every term must be a coefficient times two differentials; "
                                       f"one has {term} ({degree} differential{'s' if degree != 1 else ''})")
            term = sympy.Mul(*(g**k for g, k in zip(gens, monomial)))
            if self._theta_phi is not None:
                coeff = self._spherical_to_cartesian(coeff, "line_element")
                if self._omega in term.free_symbols:
                    if term != self._omega**2:
                        raise LineElementError("line_element", "dOmega may appear only as dOmega**2 (the unit "
                                               "sphere's dtheta**2 + sin(theta)**2*dphi**2)")  # fmt: skip
                    term = self._domega2
                    self.areal_radius2 = self.areal_radius2 + coeff
                else:
                    term = term.subs(to_cartesian)
            total += coeff * term
        cart = sympy.Poly(_shallow_expand(total), *diffs)
        g = sympy.zeros(4, 4)
        for monomial, coeff in cart.terms():
            idx = [i for i, k in enumerate(monomial) for _ in range(k)]
            a, b = idx
            if a == b:
                g[a, a] += coeff
            else:
                g[a, b] += coeff / 2
                g[b, a] += coeff / 2
        if self._theta_phi is not None:  # dtheta, dphi brought 1/(x^2 + y^2): cancel it where it cancels
            g = g.applyfunc(lambda c: sympy.factor_terms(sympy.cancel(c)) if c != 0 else c)
        if g[0, 0] == 0 and all(g[0, i] == 0 for i in range(1, 4)):
            raise LineElementError("line_element", "it has no dt term: a spacetime needs a time direction")
        if all(g[i, j] == 0 for i in range(1, 4) for j in range(1, 4)):
            raise LineElementError("line_element", "it has no spatial part (dx, dy, dz or dr, dOmega terms)")
        return g

    # -- numbers ------------------------------------------------------------------------------------

    def _functions(self):
        if not hasattr(self, "_lambdas"):
            # our own symbols only (coordinates, checked parameter and definition names), printed by sympy:
            # safe to compile
            inputs = [*self.coords, *self.params]
            steps = []
            for sym, value, grads, grad_values in self.definitions:
                steps.append(self._lambdify(inputs, [value, *grad_values]))
                inputs += [sym, *grads]
            self._lambdas = (steps, self._lambdify(inputs, self.g.tolist()),
                             [self._lambdify(inputs, d.tolist()) for d in self.dg])  # fmt: skip
        return self._lambdas

    @staticmethod
    def _lambdify(inputs: list, exprs: list):
        """A Python function of ``inputs`` returning ``exprs`` (a list, or a list of rows), with every symbol
        renamed a0, a1, ... first."""
        rename = dict(zip(inputs, sympy.symbols(f"a0:{len(inputs)}", real=True)))
        sub = [[c.subs(rename) for c in row] if isinstance(row, list) else row.subs(rename) for row in exprs]
        return sympy.lambdify(list(rename.values()), sub, "math")

    def _args(self, x: Sequence[float], params: Mapping[str, float]) -> list[float]:
        names = [p.name for p in self.params]
        missing = [n for n in names if n not in params]
        if missing:
            raise LineElementError("parameters", f"no value for {', '.join(missing)}")
        args = [float(v) for v in x] + [float(params[n]) for n in names]
        for step in self._functions()[0]:
            args += [float(v) for v in step(*args)]
        return args

    def metric_at(self, x: Sequence[float], params: Mapping[str, float]) -> np.ndarray:
        """g_{μν} at chart point ``x`` = (t, x, y, z), shape (4, 4) float64."""
        return np.array(self._functions()[1](*self._args(x, params)), dtype=np.float64)

    def rhs_at(self, y: Sequence[float], params: Mapping[str, float]) -> np.ndarray:
        """Hamilton's equations at state ``y`` = (x^μ, p_μ), shape (8,): dx^μ/dλ = g^{μν} p_ν and
        dp_μ/dλ = ½ u^α u^β ∂_μ g_{αβ} with u = g⁻¹ p (the form the generated code uses: the inverse is
        numeric, only g and ∂g are symbolic)."""
        args = self._args(y[:4], params)
        _, g_fn, dg_fn = self._functions()
        g = np.array(g_fn(*args), dtype=np.float64)
        u = np.linalg.solve(g, np.asarray(y[4:], dtype=np.float64))
        dp = [0.5 * u @ np.array(d(*args), dtype=np.float64) @ u for d in dg_fn]
        return np.concatenate([u, dp])

    def symmetries(self, params: Mapping[str, float], *, points: int = 8, seed: int = 1) -> dict[str, bool]:
        """Which symmetries the metric has for these parameter values, from its components at ``points``
        random chart points (|x| between 2 and 20; a symmetry holds to 1e-10 of the metric's size at every
        one): ``"stationary"`` (∂_t g = 0, so E = −p_t is conserved) and ``"axisymmetric"`` (the Lie
        derivative along x ∂_y − y ∂_x vanishes, so L_z = x p_y − y p_x is conserved).

        Returns
        -------
        dict of str to bool
        """
        rng = np.random.default_rng(seed)
        stationary = axisymmetric = True
        for _ in range(points):
            direction = rng.normal(size=3)
            x = [float(rng.uniform(-5, 5)), *(direction / np.linalg.norm(direction) * rng.uniform(2.0, 20.0))]
            args = self._args(x, params)
            g = np.array(self._functions()[1](*args), dtype=np.float64)
            dg = [np.array(d(*args), dtype=np.float64) for d in self._functions()[2]]
            scale = np.abs(g).max()
            if not np.all(np.isfinite(g)):
                continue
            stationary &= bool(np.abs(dg[0]).max() <= 1e-10 * scale)
            xi = np.array([0.0, -x[2], x[1], 0.0])
            dxi = np.zeros((4, 4))  # dxi[m, n] = d_n xi^m
            dxi[1, 2], dxi[2, 1] = -1.0, 1.0
            lie = sum(xi[m] * dg[m] for m in range(4)) + dxi.T @ g + g @ dxi
            axisymmetric &= bool(np.abs(lie).max() <= 1e-10 * scale * max(1.0, float(np.linalg.norm(x[1:]))))
        return {"stationary": stationary, "axisymmetric": axisymmetric}

    def wormhole_problem(self, params: Mapping[str, float], *, points: int = 6, seed: int = 2) -> str:
        """``wormhole`` coordinates: "" if the metric is the same on both sheets (even in l, as the chart's
        inversion x -> c² x / |x|² that moves a ray between them requires) and has its throat at l = 0
        (areal radius c there, larger on both sides), else why not."""
        names = [p.name for p in self.params]
        c = float(self.chart_scale.subs({p: params[n] for p, n in zip(self.params, names)}))
        if not (c > 0 and np.isfinite(c)):
            return f"throat_radius must be a radius > 0, got {c:g}"
        rng = np.random.default_rng(seed)
        r2 = self._lambdify([*self.coords, *self.params], [self.areal_radius2.subs(
            {sym: value for sym, value, _, _ in reversed(self.definitions)})])  # fmt: skip
        if self.areal_radius2 == 0:
            return "a wormhole's line element needs its areal radius as the coefficient of dOmega**2"
        values = [float(params[n]) for n in names]
        throat = float(r2(0.0, c, 0.0, 0.0, *values)[0])
        if not abs(throat - c * c) <= 1e-9 * c * c:
            return f"the areal radius at l = 0 is {np.sqrt(max(throat, 0.0)):.6g}, not throat_radius = {c:.6g}"
        for _ in range(points):
            n = rng.normal(size=3)
            n /= np.linalg.norm(n)
            rho = c * float(rng.uniform(1.05, 6.0))
            inner = c * c / rho
            a, b = [0.0, *(n * rho)], [0.0, *(n * inner)]
            ga, gb = self.metric_at(a, params), self.metric_at(b, params)
            om_a, om_b = 0.5 * (1 + c * c / rho**2), 0.5 * (1 + c * c / inner**2)
            # g_tt, g_ll and the areal radius must agree at l and -l
            pairs = [(ga[0, 0], gb[0, 0]), (n @ ga[1:, 1:] @ n / om_a**2, n @ gb[1:, 1:] @ n / om_b**2),
                     (float(r2(*a, *values)[0]), float(r2(*b, *values)[0]))]  # fmt: skip
            for (u, v), what in zip(pairs, ("g_tt", "g_ll", "the areal radius")):
                if not abs(u - v) <= 1e-9 * max(abs(u), abs(v), 1e-300):
                    return (f"{what} differs between l and -l ({u:.6g} against {v:.6g}): warpviz's wormholes are "
                            "the same on both sheets (write the line element even in l)")  # fmt: skip
            if not float(r2(*a, *values)[0]) > throat:
                return "the areal radius must grow away from the throat at l = 0"
        return ""
