"""C++ for a metric given by its line element: a struct that satisfies the metric contract of
``renderer_ext/spacetime/metric.h`` like the hand-written files, templated over the value type (double,
``Dual<N>`` for the contract's automatic derivatives, ``Lanes`` for the SIMD batches).

What is generated from a :class:`~warpviz.spacetime.line_element.tensor.LineElement`:

- ``metric(x, g)``: g_{μν} as straight-line code, each scalar definition computed once, sympy's common
  subexpressions eliminated;
- for a line element of Kerr–Schild form, g = η + f k⊗k (:func:`kerr_schild_form`), ``rhs`` = the gradient
  of H = ½ η p p − ½ f (k̂·p)² / (1 + f k̂·k) from the closed-form inverse, differentiated symbolically
  with CSE (what the hand-written files do; as fast as they are, benchmarks/README.md); otherwise:
- ``inverse_metric`` = the numeric inverse of g (``cofactor_inverse4`` in ``core/linalg.h``), and ``rhs`` = Hamilton's
  equations in the form dx^μ/dλ = u^μ = g^{μν} p_ν, dp_λ/dλ = ½ u^μ u^ν ∂_λ g_{μν} (no symbolic inverse:
  it would be large, and its derivative larger), u solved by the 3+1 split (``split_solve4``) wherever the
  spatial block and the lapse allow (:func:`split_solve_applies`), else from the cofactor inverse. Its body
  computes g and the ∂_λ g_{μν} that are not identically zero as local values, each definition once with
  its gradient (the chain rule of the tensor module), after CSE;
- the conserved quantities it has (E where g does not depend on t, L_z where it is axisymmetric, H always);
- the landmarks given as expressions of the parameters (horizon, capture radius, photon sphere, ...).

``rhs`` is not force-inlined as the hand-written files' is: the steppers call it at every stage, and
inlining a generated body there doubles a plugin's compile time (measured: 36 s → 18 s per part) for no
speed a ray can measure; a plugin is compiled for the machine's own instruction set (``plugin.py``), so the
call keeps the batch kernel's vector width.

Only names the generator makes appear in the code (``x[i]``, ``p_[i]``, ``d_<definition>``, ``c<k>``);
a parameter or definition name is never pasted into C++ except inside a comment, after the grammar has
limited it to letters, digits and underscores.

Examples
--------
>>> from warpviz.spacetime.line_element.tensor import LineElement
>>> le = LineElement("-(1 - 2*M/r)*dt**2 + dx**2 + dy**2 + dz**2", parameters=["M"])
>>> src = metric_source(le, name="weak_field", values={"M": 1.0})
>>> "struct WeakField" in src and "cofactor_inverse4(g, gi);" in src
True
"""

from __future__ import annotations

import hashlib
import itertools
from collections.abc import Mapping

import numpy as np
import sympy
from sympy.printing.c import C99CodePrinter

from warpviz.spacetime.line_element.tensor import LineElement

__all__ = ["kerr_schild_form", "metric_source", "source_hash", "split_solve_applies"]

_FUNCTIONS = {"exp": "exp_of", "log": "log_of", "sin": "sin_of", "cos": "cos_of", "tan": "tan_of",
              "sinh": "sinh_of", "cosh": "cosh_of", "tanh": "tanh_of", "asin": "asin_of", "acos": "acos_of",
              "atan": "atan_of"}  # fmt: skip


class _Printer(C99CodePrinter):
    """Expressions as C++ over the value type T: integer powers multiplied out, half powers through sqrt,
    every function one that core/elementary.h defines for double, Dual and Lanes."""

    def __init__(self, names: Mapping[sympy.Symbol, str]):
        super().__init__({"strict": False})
        self._names = dict(names)

    def _print_Symbol(self, expr):
        if expr in self._names:
            return self._names[expr]
        raise ValueError(f"codegen: no C++ name for symbol {expr}")  # pragma: no cover - a generator bug

    _print_Dummy = _print_Symbol

    def _print_Integer(self, expr):
        return f"{int(expr)}.0"

    def _print_Rational(self, expr):
        return f"({int(expr.p)}.0 / {int(expr.q)}.0)"

    def _print_Float(self, expr):
        return repr(float(expr))

    def _print_Pi(self, expr):
        return repr(float(sympy.pi))

    def _print_Pow(self, expr):
        base, e = expr.base, expr.exp
        b = self.parenthesize(base, 100)
        if e.is_Integer:
            n = int(e)
            if n == 0:
                return "1.0"
            prod = "*".join([b] * abs(n))
            return f"({prod})" if n > 0 else f"(1.0 / ({prod}))"
        if e.is_Rational and e.q == 2:
            n = int(e.p)
            root = f"sqrt({self._print(base)})"
            rest = "*".join([b] * (abs(n) // 2))
            value = f"({root}*{rest})" if rest else root
            return value if n > 0 else f"(1.0 / {value})"
        return f"exp_of(({self._print(e)})*log_of({self._print(base)}))"

    def _print_Function(self, expr):
        name = type(expr).__name__
        if name in _FUNCTIONS:
            return f"{_FUNCTIONS[name]}({self._print(expr.args[0])})"
        raise ValueError(f"codegen: function {name} has no C++ form")  # pragma: no cover

    # sympy's C printers have methods of their own for some functions (tanh, ...), found before
    # _print_Function: every function of the grammar is routed here by name (set below the class).

    def _print_Abs(self, expr):
        return f"fabs_of({self._print(expr.args[0])})"

    def _print_sign(self, expr):  # the derivative of |x|
        return f"sign_of({self._print(expr.args[0])})"

    def _print_atan2(self, expr):
        return f"atan2_of({self._print(expr.args[0])}, {self._print(expr.args[1])})"


for _name in _FUNCTIONS:
    setattr(_Printer, f"_print_{_name}", _Printer._print_Function)
del _name


def source_hash(le: LineElement) -> str:
    """A short hash of what decides the generated code (the metric's symbolic components and definitions)."""
    text = repr((le.coordinates, [p.name for p in le.params], [(d[0].name, str(d[1])) for d in le.definitions],
                 str(le.g)))  # fmt: skip
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def _straight_line(exprs: list, names: dict, tvals: set, counter: list) -> tuple[list, list, list]:
    """Common subexpressions of ``exprs`` as C++ lines. A value that depends on a T-valued symbol (a
    coordinate, or something made from one) is a T, the others doubles (a SIMD vector cannot be initialised
    from a double). Returns (lines, printed expressions, whether each is T-valued)."""
    fresh = (sympy.Dummy(f"cse{i}") for i in itertools.count())  # never the same symbol in two calls
    replacements, reduced = sympy.cse(exprs, symbols=fresh, order="none")
    lines = []
    for sym, value in replacements:
        cname = f"c{counter[0]}"
        counter[0] += 1
        is_t = bool(value.free_symbols & tvals)
        lines.append(f"    const {'T' if is_t else 'double'} {cname} = {_Printer(names).doprint(value)};")
        names[sym] = cname
        if is_t:
            tvals.add(sym)
    return lines, [_Printer(names).doprint(e) for e in reduced], [bool(e.free_symbols & tvals) for e in reduced]


def _as_t(text: str, is_t: bool) -> str:
    """``text`` as a T: a double-valued expression is lifted (``T{} + v``: exact, and a vector broadcast)."""
    return text if is_t else f"T{{}} + ({text})"


def _scope(le: LineElement, state: str) -> tuple[dict, set, list]:
    """The C++ names of the coordinates (``state[i]``) and parameters (``p_[i]``), the T-valued symbols and
    the counter of common subexpressions, where a generated method's body starts."""
    names: dict[sympy.Symbol, str] = {c: f"{state}[{i}]" for i, c in enumerate(le.coords)}
    names.update({p: f"p_[{i}]" for i, p in enumerate(le.params)})
    return names, set(le.coords), [0]


def _body(le: LineElement) -> list[str]:
    """The body of ``metric``: g_{μν}(x) as straight-line code after CSE."""
    names, tvals, counter = _scope(le, "x")
    lines = _definition_lines(le, names, tvals, counter, gradients=False)
    pairs = [(a, b) for a in range(4) for b in range(a, 4)]
    pre, printed, is_t = _straight_line([le.g[a, b] for a, b in pairs], names, tvals, counter)
    lines += pre
    for (a, b), text, t in zip(pairs, printed, is_t):
        lines.append(f"    g[{a}][{b}] = {_as_t(text, t)};" + (f"\n    g[{b}][{a}] = g[{a}][{b}];" if a != b else ""))
    return lines


def kerr_schild_form(le: LineElement) -> tuple[sympy.Basic, list] | None:
    """``(f, k)`` if g = η + f k⊗k with k_t = 1 (Kerr–Schild form: Schwarzschild, Reissner–Nordström, Kerr,
    Kerr–Newman written so), else None. Found from g − η: f = (g − η)_tt, k_i = (g − η)_ti / f, and every
    component must equal f k_a k_b identically (rational identities in the coordinates and definitions)."""
    eta = sympy.diag(-1, 1, 1, 1)
    F = le.g - eta
    f = F[0, 0]
    if f == 0:
        return None
    for a in range(4):
        for b in range(a, 4):
            if sympy.cancel(F[a, b] * f - F[0, a] * F[0, b]) != 0:
                return None
    return f, [sympy.Integer(1)] + [sympy.cancel(F[0, i] / f) for i in range(1, 4)]


def _definition_lines(le: LineElement, names: dict, tvals: set, counter: list, *, gradients: bool = True) -> list[str]:
    """Each definition once, with its gradient (the chain rule of the tensor module) if ``gradients``, as locals."""
    lines = []
    for k, (sym, value, grads, grad_values) in enumerate(le.definitions):
        grad_values = grad_values if gradients else ()
        pre, printed, is_t = _straight_line([value, *grad_values], names, tvals, counter)
        lines += pre
        lines.append(f"    const {'T' if is_t[0] else 'double'} d{k} = {printed[0]};  // {sym.name}")
        names[sym] = f"d{k}"
        if is_t[0]:
            tvals.add(sym)
        for mu, g in enumerate(grads[:len(grad_values)]):
            if grad_values[mu] == 0:  # never referenced (tensor.LineElement._d leaves zero gradients out)
                continue
            lines.append(f"    const {'T' if is_t[1 + mu] else 'double'} d{k}_{mu} = {printed[1 + mu]};")
            names[g] = f"d{k}_{mu}"
            if is_t[1 + mu]:
                tvals.add(g)
    return lines


def _kerr_schild_rhs_lines(le: LineElement, f: sympy.Basic, k: list) -> list[str]:
    """Hamilton's equations of g = η + f k⊗k from its closed-form inverse (Sherman–Morrison):
    g^{μν} = η^{μν} − f k̂^μ k̂^ν / (1 + f k̂·k), k̂ = η k, so H = ½ η p p − ½ f (k̂·p)² / (1 + f k̂·k)
    (the denominator is 1 for a null k, as in the hand-written files), differentiated symbolically."""
    P = sympy.symbols("P0:4", real=True)
    eta = (-1, 1, 1, 1)
    khat_p = sum(eta[a] * k[a] * P[a] for a in range(4))
    kk = sum(eta[a] * k[a] * k[a] for a in range(4))
    H = sympy.Rational(1, 2) * sum(eta[a] * P[a] ** 2 for a in range(4)) - f * khat_p**2 / (2 * (1 + f * kk))
    names, tvals, counter = _scope(le, "y")
    names.update({P[a]: f"y[{4 + a}]" for a in range(4)})
    tvals |= set(P)
    lines = _definition_lines(le, names, tvals, counter)
    exprs = [H.diff(P[a]) for a in range(4)] + [-le._d(H, m) for m in range(4)]
    pre, printed, is_t = _straight_line(exprs, names, tvals, counter)
    lines += pre
    for i, (text, t, e) in enumerate(zip(printed, is_t, exprs)):
        lines.append(f"    dy[{i}] = {'T{}' if e == 0 else _as_t(text, t)};")
    return lines


def _kerr_schild_frame_lines(le: LineElement, f: sympy.Basic, k: list) -> list[str]:
    """The static observer's frame in closed form for g = η + f k⊗k (``closed_frame``, as the hand-written Kerr
    file has it: spacetime/frame.h, ``kerr_schild_static_frame``): f and k at x after CSE, the closed form where k
    is null (|k| = 1, checked at x) and f < 1, the generic construction elsewhere (an ergoregion). Frames are built
    at every path vertex; the generic one solves for the observer and orthonormalises (5 % of a Kerr–Newman
    room's time)."""
    names, tvals, counter = _scope(le, "x")
    lines = ["  // Kerr-Schild form g = eta + f k (x) k: f and k's spatial part at x.",
             "  template <class T>", "  void kerr_schild_parts(const T* x, T& f, T k[3]) const {"]  # fmt: skip
    lines += _definition_lines(le, names, tvals, counter, gradients=False)
    pre, printed, is_t = _straight_line([f, *k[1:]], names, tvals, counter)
    lines += pre
    lines.append(f"    f = {_as_t(printed[0], is_t[0])};")
    lines += [f"    k[{i}] = {_as_t(text, t)};" for i, (text, t) in enumerate(zip(printed[1:], is_t[1:]))]
    lines += ["  }", "",
              "  // The static observer's frame in closed form where k is null and f < 1, else the generic one.",
              "  bool closed_frame(const double* x, ObserverFrame& fr) const {",
              "    double f, k[3];",
              "    kerr_schild_parts(x, f, k);",
              "    const double kk = k[0] * k[0] + k[1] * k[1] + k[2] * k[2];",
              "    const bool null_k = std::fabs(kk - 1.0) <= 1e-12;",
              "    if (std::isfinite(f) && null_k && kerr_schild_static_frame(f, k, fr)) return true;",
              "    return observer_frame_generic(*this, x, fr);",
              "  }"]  # fmt: skip
    return lines


def _rhs_lines(le: LineElement, split: bool) -> list[str]:
    """The body of ``rhs``: the definitions, g and every ∂g component that is not identically zero as local
    values after CSE (never stored in arrays: in SIMD lanes the arrays' loads and stores cost more than
    their arithmetic, measured 2.6x), u = g⁻¹p, then dp_l = ½ u^a u^b ∂_l g_ab over those components (each
    pair a < b once, doubled): a stationary metric skips ∂_t g, a sparse one most of the rest."""
    names, tvals, counter = _scope(le, "y")
    lines = _definition_lines(le, names, tvals, counter)
    pairs = [(a, b) for a in range(4) for b in range(a, 4)]
    forces = [(m, a, b) for m in range(4) for a, b in pairs if le.dg[m][a, b] != 0]
    exprs = [le.g[a, b] for a, b in pairs] + [le.dg[m][a, b] for m, a, b in forces]
    pre, printed, is_t = _straight_line(exprs, names, tvals, counter)
    lines += pre
    lines.append("    T g[4][4];")
    for (a, b), text, t in zip(pairs, printed, is_t):
        lines.append(f"    g[{a}][{b}] = {_as_t(text, t)};" + (f"\n    g[{b}][{a}] = g[{a}][{b}];" if a != b else ""))
    for (m, a, b), text, t in zip(forces, printed[len(pairs):], is_t[len(pairs):]):
        lines.append(f"    const T dg{m}_{a}{b} = {_as_t(text, t)};")
    if split:
        lines += ["    T u[4];", "    split_solve4(g, y + 4, u);"]
    else:
        lines += ["    T gi[4][4], u[4];", "    cofactor_inverse4(g, gi);",
                  "    for (int a = 0; a < 4; ++a) u[a] = gi[a][0] * y[4] + gi[a][1] * y[5] + gi[a][2] * y[6] + gi[a][3] * y[7];"]  # fmt: skip
    lines.append("    for (int a = 0; a < 4; ++a) dy[a] = u[a];")
    for m in range(4):
        terms = [f"u[{a}] * u[{a}] * dg{m}_{a}{b}" if a == b else f"2.0 * (u[{a}] * u[{b}] * dg{m}_{a}{b})"
                 for mm, a, b in forces if mm == m]  # fmt: skip
        lines.append(f"    dy[{4 + m}] = " + (f"0.5 * ({' + '.join(terms)});" if terms else "T{};"))
    return lines


def split_solve_applies(le: LineElement, values: Mapping[str, float], *, points: int = 16, seed: int = 5) -> bool:
    """Whether u = g⁻¹p may be solved by the 3+1 split (``split_solve4`` in core/linalg.h): the spatial block
    of g invertible and g^{tt} ≠ 0 at ``points`` random chart points (|x| from 2 to 20), each to 1e-9 of the
    metric's size. Not so in null coordinates (ingoing Eddington–Finkelstein: g_rr = 0), which keep the
    cofactor inverse."""
    rng = np.random.default_rng(seed)
    for _ in range(points):
        n = rng.normal(size=3)
        x = [float(rng.uniform(-5.0, 5.0)), *(n / np.linalg.norm(n) * rng.uniform(2.0, 20.0))]
        with np.errstate(all="ignore"):
            try:
                g = le.metric_at(x, values)
            except (ZeroDivisionError, ValueError, OverflowError):
                continue
            if not np.all(np.isfinite(g)):
                continue
            scale = np.abs(g).max()
            det3 = np.linalg.det(g[1:, 1:])
            if not abs(det3) > 1e-9 * scale**3:
                return False
            shift = np.linalg.solve(g[1:, 1:], g[0, 1:])
            alpha2 = shift @ g[0, 1:] - g[0, 0]
        if not (np.isfinite(alpha2) and abs(alpha2) > 1e-9 * scale):
            return False
    return True


def _rhs_body(le: LineElement, values: Mapping[str, float], split: bool | None, ks: tuple | None) -> list[str]:
    """The body of ``rhs``: from the Kerr–Schild form ``ks`` (:func:`kerr_schild_form`) where there is one, else
    the general path."""
    if ks is not None:
        return _kerr_schild_rhs_lines(le, *ks)
    return _rhs_lines(le, split_solve_applies(le, values) if split is None else split)


def _class_name(name: str) -> str:
    return "".join(part[:1].upper() + part[1:] for part in name.split("_") if part) or "Custom"


#: Landmarks a line element may give (expressions of its parameters) and the Landmarks field each sets
#: (renderer_ext/spacetime/landmarks.h).
LANDMARKS = {"horizon_radius": "horizon", "inner_horizon_radius": "inner_horizon", "capture_radius": "capture",
             "photon_sphere_radius": "photon_sphere", "throat_radius": "throat", "mass": "mass",
             "escape_radius": "escape"}  # fmt: skip


def _landmark_lines(le: LineElement, landmarks: Mapping[str, sympy.Basic]) -> list[str]:
    """The landmark methods: an expression of the parameters each (doubles). A horizon without a capture
    radius captures at 1.1 × the horizon, or halfway to the photon sphere where one is given (no inward
    light ray turns back out inside the photon sphere)."""
    unknown = set(landmarks) - set(LANDMARKS)
    if unknown:
        raise ValueError(f"unknown landmark(s) {sorted(unknown)}; landmarks are {list(LANDMARKS)}")
    names = {p: f"p_[{i}]" for i, p in enumerate(le.params)}
    text = {LANDMARKS[k]: _Printer(names).doprint(sympy.sympify(v)) for k, v in landmarks.items()}
    if "horizon" in text and "capture" not in text:
        text["capture"] = (f"0.5 * (({text['horizon']}) + ({text['photon_sphere']}))" if "photon_sphere" in text
                           else f"1.1 * ({text['horizon']})")  # fmt: skip
    lines = []
    if "horizon" in text:
        lines.append(f"  double horizon_radius() const {{ return {text['horizon']}; }}")
    if "capture" in text:
        lines.append(f"  double capture_radius() const {{ return {text['capture']}; }}")
    if "mass" in text:
        lines.append(f"  double length_scale() const {{ return {text['mass']}; }}")
    if "escape" in text:  # not asymptotically flat: rays escape here (spacetime/metric.h, escape_limit)
        lines.append(f"  double escape_limit() const {{ return {text['escape']}; }}")
    if "mass" in text and not ({"escape", "throat"} & set(text)) and le.coordinates != "wormhole":
        # An asymptotically flat spacetime with a mass and no throat is Schwarzschild far out: its lens map of
        # that mass is the light connection's proposal, as Kerr's (integrators/lens_proposal.h; any metric
        # keeps the mean, one near Schwarzschild's lowers the noise).
        lines += ["  static constexpr bool kLensProxy = true;",
                  "  SphericalLens lens_proxy() const {  // (no mass: no proxy, the proposal stays off)",
                  f"    const double m = {text['mass']};",
                  "    return m > 0.0 ? SphericalLens::schwarzschild(m) : SphericalLens{};",
                  "  }"]  # fmt: skip
    extra = [f"    l.{k} = {text[k]};" for k in ("inner_horizon", "photon_sphere", "throat", "mass") if k in text]
    if extra:
        lines += ["  Landmarks landmarks() const {", "    Landmarks l = MetricBase::landmarks();", *extra,
                  "    return l;", "  }"]  # fmt: skip
    return lines


def _wormhole_lines(le: LineElement) -> list[str]:
    """A wormhole in its chart (``wormhole`` coordinates, as the Ellis file): rho = |x| > c is our sheet, rho < c
    the other, l = (rho - c²/rho)/2; the inversion x -> c² x / rho² exchanges them (an isometry: the metric is
    even in l, checked by LineElement.wormhole_problem), and the user sees each sheet with |x| the areal
    radius. The areal radius (the square root of the dOmega**2 coefficient) is the metric's radius."""
    names = {c: f"x[{i}]" for i, c in enumerate(le.coords)}
    names.update({p: f"p_[{i}]" for i, p in enumerate(le.params)})
    r2 = le.areal_radius2
    for sym, value, _, _ in reversed(le.definitions):
        r2 = r2.subs(sym, value)
    area = _Printer(names).doprint(r2)
    c = _Printer({p: f"p_[{i}]" for i, p in enumerate(le.params)}).doprint(le.chart_scale)
    return [
        f"  double chart_scale() const {{ return {c}; }}",
        f"  double radius(const double* x) const {{ return std::sqrt({area}); }}",
        "  bool normalize_chart(double* y, int& sheet) const {",
        "    return invert_through_throat(y, chart_scale() * chart_scale(), sheet);",
        "  }",
        "  int chart_to_user(const double* x, int sheet, double pos[3]) const {",
        "    const double rho2 = x[1] * x[1] + x[2] * x[2] + x[3] * x[3], s = radius(x) / std::sqrt(rho2);",
        "    for (int i = 0; i < 3; ++i) pos[i] = x[1 + i] * s;",
        "    return rho2 >= chart_scale() * chart_scale() ? sheet : -sheet;",
        "  }",
        "  // rho >= c with radius = |pos|, by bisection (the areal radius grows away from the throat)",
        "  bool user_to_chart(const double pos[3], int /*sheet*/, double x[4]) const {",
        "    const double R = std::sqrt(pos[0] * pos[0] + pos[1] * pos[1] + pos[2] * pos[2]), c = chart_scale();",
        "    double at[4] = {0.0, c, 0.0, 0.0};",
        "    if (!(R >= radius(at) * (1.0 - 1e-12))) return false;",
        "    double lo = c, hi = 2.0 * c;",
        "    for (int i = 0; i < 200; ++i) {",
        "      at[1] = hi;",
        "      if (radius(at) >= R) break;",
        "      lo = hi;",
        "      hi *= 2.0;",
        "    }",
        "    for (int i = 0; i < 200 && hi - lo > 1e-15 * hi; ++i) {",
        "      at[1] = 0.5 * (lo + hi);",
        "      (radius(at) < R ? lo : hi) = at[1];",
        "    }",
        "    const double rho = 0.5 * (lo + hi);",
        "    x[0] = 0.0;",
        "    for (int i = 0; i < 3; ++i) x[1 + i] = R > 0.0 ? pos[i] * rho / R : 0.0;",
        "    return true;",
        "  }",
        "  std::string outside_chart_message(const double* pos) const {",
        "    return \"lies inside the wormhole throat (|x| = \" +",
        "           std::to_string(std::sqrt(pos[0] * pos[0] + pos[1] * pos[1] + pos[2] * pos[2])) +",
        "           \" < throat = \" + std::to_string(chart_scale()) + \"; positions are areal radii)\";",
        "  }",
    ]


def _relation_lines(le: LineElement, landmarks: Mapping[str, sympy.Basic]) -> list[str]:
    """The parameters' relation: every landmark a real radius >= 0 (sqrt(M**2 - Q**2) needs |Q| <= M), so
    the core refuses other values by name, as it refuses |Q| > M for the built-in metric."""
    if not landmarks:
        return []
    names = {p: f"p[{i}]" for i, p in enumerate(le.params)}
    keys = sorted(landmarks)
    lines = [f'  static constexpr const char* kParamRelation = "every landmark ({", ".join(keys)}) is a real radius >= 0";',
             "  static std::string param_relation_problem(const double* p) {",
             "    (void)p;"]  # fmt: skip
    for key in keys:
        text = str(landmarks[key]).replace('"', "").replace("\\", "")
        lines += [f"    if (const double v = {_Printer(names).doprint(sympy.sympify(landmarks[key]))}; !(v >= 0.0))",
                  f'      return "{key} = {text} is " + std::to_string(v) + ", not a real radius >= 0";']  # fmt: skip
    return [*lines, "    return {};", "  }"]


def metric_source(le: LineElement, *, name: str, values: Mapping[str, float], summary: str = "",
                  landmarks: Mapping[str, sympy.Basic] | None = None, crosses_horizon: bool = True,
                  split: bool | None = None, structure: str = "auto", register: bool = True) -> str:  # fmt: skip
    """The C++ of a metric struct for ``le`` (module docstring).

    Parameters
    ----------
    le : LineElement
    name : str, keyword-only
        Registry name (letters, digits, underscores); the struct is its CamelCase form.
    values : mapping of str to float, keyword-only
        Default value of each parameter (the registry's default and example).
    summary : str, keyword-only
        One line for the registry (default: the line element's kind).
    landmarks : mapping of str to sympy expression, optional, keyword-only
        Landmark radii (:data:`LANDMARKS`) as expressions of the parameters.
    structure : {"auto", "general"}, keyword-only
        ``"auto"``: a line element of Kerr–Schild form (:func:`kerr_schild_form`) gets Hamilton's equations
        from its closed-form inverse, differentiated symbolically, as the hand-written files have them;
        ``"general"``: always g, ∂g and the numeric solve.
    split : bool or None, keyword-only
        Solve u = g⁻¹p by the 3+1 split (True), by the cofactor inverse (False), or as
        :func:`split_solve_applies` finds (None, the default).
    crosses_horizon : bool, keyword-only
        Whether the chart is regular through the horizon (``kChartCrossesHorizon``; False: every ray is
        absorbed at the capture radius, as for a line element in Schwarzschild coordinates).
    register : bool, keyword-only
        End with ``WARPVIZ_REGISTER_METRIC`` (a plugin); False for a test harness that includes the struct.

    Returns
    -------
    str
        A complete C++ file.
    """
    if not name.replace("_", "").isalnum() or not name[:1].isalpha():
        raise ValueError(f"a metric name is letters, digits and _, starting with a letter, got {name!r}")
    cls = _class_name(name)
    if structure not in ("auto", "general"):
        raise ValueError(f"structure must be 'auto' or 'general', got {structure!r}")
    ks = kerr_schild_form(le) if structure == "auto" else None  # g = eta + f k k: closed-form H and frame
    wormhole = le.coordinates == "wormhole"
    if wormhole:  # the throat sets the length scale unless a mass is given
        landmarks = {"mass": le.chart_scale, **(landmarks or {})}
    sym = le.symmetries(values)
    invariants = ["H"] + (["E"] if sym["stationary"] else []) + (["Lz"] if sym["axisymmetric"] else [])
    specs = ",\n      ".join(
        f'{{"{p.name}", -kUnbounded, true, kUnbounded, true, {float(values[p.name])!r}, {float(values[p.name])!r}, '
        f'"parameter {p.name} of the line element"}}' for p in le.params)  # fmt: skip
    param_block = (f"  static constexpr ParamSpec kParams[] = {{\n      {specs}}};\n"
                   f"  static constexpr int kNumParams = {len(le.params)};\n") if le.params else ""  # fmt: skip
    conserved, scales = [], []
    for k, inv in enumerate(invariants[1:], start=1):
        if inv == "E":
            conserved.append(f"    out[{k}] = -y[4];\n    if (mag) mag[{k}] = std::fabs(y[4]);")
            scales.append(f"    scale[{k}] = energy_scale(y, inv[{k}]);")
        else:
            conserved.append(f"    out[{k}] = y[1] * y[6] - y[2] * y[5];\n"
                             f"    if (mag) mag[{k}] = std::fabs(y[1] * y[6]) + std::fabs(y[2] * y[5]);")  # fmt: skip
            scales.append(f"    scale[{k}] = std::max(std::fabs(inv[{k}]), radius(y) * energy_scale(y, -y[4]));")
    names = ", ".join(f'"{n}"' for n in invariants)
    lines = [
        f"// Generated by warpviz from a line element ({le.coordinates} coordinates; hash {source_hash(le)}).",
        "// Do not edit: warpviz/spacetime/line_element/codegen.py writes it.",
        "#include <algorithm>",
        "#include <cmath>",
        "#include <string>",
        "#include <vector>",
        "",
        '#include "core/elementary.h"',
        '#include "core/linalg.h"',
        '#include "core/simd.h"',
        '#include "spacetime/frame.h"',
        '#include "spacetime/metric.h"',
        *(['#include "spacetime/throat_chart.h"'] if wormhole else []),
        *(['#include "engine/register.h"'] if register else []),
        "",
        "namespace wv {",
        "",
        f"struct {cls} : MetricBase<{cls}> {{",
        f'  static constexpr const char* kName = "{name}";',
        f'  static constexpr const char* kClassName = "{cls}";',
        f'  static constexpr const char* kSummary = "{(summary or "Spacetime from its line element").replace(chr(34), "")}";',
        param_block.rstrip("\n"),
        *_relation_lines(le, landmarks or {}),
        *([] if crosses_horizon else ["  static constexpr bool kChartCrossesHorizon = false;"]),
        *(["  static constexpr int kSheets = 2;", "  static constexpr bool kUserIsChart = false;"] if wormhole else []),
        f"  static constexpr int kNumInvariants = {len(invariants)};",
        f"  static constexpr const char* kInvariantNames[kNumInvariants] = {{{names}}};",
        f"  double p_[{max(1, len(le.params))}] = {{}};",
        "",
        f"  explicit {cls}(const std::vector<double>& p) {{",
        f"    for (size_t i = 0; i < p.size() && i < {len(le.params)}; ++i) p_[i] = p[i];",
        "  }",
        "",
        "  // g_{mu nu}(x)",
        "  template <class T>",
        "  WV_INLINE void metric(const T* x, T g[4][4]) const {",
        *_body(le),
        "  }",
        "",
        "  template <class T>",
        "  void inverse_metric(const T* x, T gi[4][4]) const {",
        "    T g[4][4];",
        "    metric(x, g);",
        "    cofactor_inverse4(g, gi);",
        "  }",
        "",
        "  // dx^mu = u^mu = g^{mu nu} p_nu, dp_l = (1/2) u^mu u^nu d_l g_{mu nu} (not inlined: codegen.py)",
        "  template <class T>",
        "  __attribute__((noinline)) void rhs(const T y[8], T dy[8]) const {",
        *_rhs_body(le, values, split, ks),
        "  }",
        "",
        *(_kerr_schild_frame_lines(le, *ks) + [""] if ks is not None else []),
        *(_wormhole_lines(le) if wormhole else
          ["  double radius(const double* x) const { return std::sqrt(x[1] * x[1] + x[2] * x[2] + x[3] * x[3]); }"]),
        *_landmark_lines(le, landmarks or {}),
        "",
        "  void conserved(const double y[8], const HamiltonianParts& /*hp*/, double out[], double mag[]) const {",
        *(conserved or ["    (void)y; (void)out; (void)mag;"]),
        "  }",
        "  void invariant_scales(const double y[8], const double inv[], double scale[]) const {",
        "    (void)y; (void)inv;",
        "    scale[0] = 1.0;",
        *scales,
        "  }",
        "};",
        "",
        *([f"WARPVIZ_REGISTER_METRIC({cls});", ""] if register else []),
        "}  // namespace wv",
        "",
    ]
    return "\n".join(line for line in lines if line is not None)
