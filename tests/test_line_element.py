"""Spacetimes from their line element (warpviz/spacetime/line_element/): the whitelist grammar refuses
hostile text with its column and never runs it; line elements give the built-in metrics' g^{μν} and
Hamilton equations to rounding; spherical input equals Cartesian input."""

import numpy as np
import pytest
import sympy

from warpviz._native import testing
from warpviz.spacetime.line_element import ExpressionError, parse_expression
from warpviz.spacetime.line_element.tensor import LineElement, LineElementError

POINTS = ([0.0, 3.0, 1.0, 4.0], [0.0, -7.0, 2.0, 0.5], [0.0, 0.0, 0.0, 9.0], [2.0, 5.0, -3.0, 0.0])
MOMENTUM = [-1.0, 0.3, -0.2, 0.9]

SCHWARZSCHILD_KS = "-dt**2 + dx**2 + dy**2 + dz**2 + 2*M/r*(dt + (x*dx + y*dy + z*dz)/r)**2"
RN_SPHERICAL = "-(1 - 2*M/r + Q**2/r**2)*dt**2 + dr**2/(1 - 2*M/r + Q**2/r**2) + r**2*dOmega**2"


@pytest.mark.parametrize("text, column, says", [
    ('__import__("os").system("x")', 12, "unexpected character '\"'"),
    ("M.__class__", 2, "unexpected character '.'"),
    ("M r", 3, "expected an operator"),
    ("r**100000", 2, "exponent 100000 is larger than 64"),
    ("eval(r)", 1, "unknown function 'eval'"),
    ("lambda_(r)", 1, "unknown function 'lambda_'"),
    ("1/(M - M)", 2, "division by zero"),
    ("sqrt(r", 7, "expected ',' or ')'"),
    ("sin r", 1, "sin is a function"),
    ("atan2(r)", 1, "atan2 takes 2 arguments"),
    ("r; M", 2, "unexpected character ';'"),
    ("q", 1, "unknown name 'q'"),
    ("(" * 70 + "r" + ")" * 70, 65, "nested deeper than 64"),
    ("", 1, "empty"),
])  # fmt: skip
def test_the_grammar_refuses_hostile_and_broken_text_naming_the_column(text, column, says):
    r, M = sympy.symbols("r M", positive=True)
    with pytest.raises(ExpressionError) as err:
        parse_expression(text, {"r": r, "M": M})
    assert err.value.column == column and says in str(err.value)


def test_the_grammar_reads_numbers_exactly_and_powers_right_to_left():
    x = sympy.Symbol("x")
    assert parse_expression("0.1 + 1e-3", {}) == sympy.Rational(101, 1000)
    assert parse_expression("2^3^2", {}) == 512 and parse_expression("-x**-2", {"x": x}) == -(x**-2)
    assert parse_expression("atan2(x, 1) + pi", {"x": x}) == sympy.atan2(x, 1) + sympy.pi
    with pytest.raises(ExpressionError, match="longer than 4000"):
        parse_expression("x+" * 2001 + "x", {"x": x})


def test_no_python_is_ever_run(monkeypatch):
    """The parser never reaches eval, exec or sympy's string parser, whatever the text."""
    import builtins

    import sympy.parsing.sympy_parser as sympy_parser

    def refuse(*args, **kwargs):
        raise AssertionError("eval, exec or parse_expr was called")

    parse_expression("r**2 + sin(r)", {"r": sympy.Symbol("r")})  # sympy's lazy imports (which exec) done first

    monkeypatch.setattr(builtins, "eval", refuse)
    monkeypatch.setattr(builtins, "exec", refuse)
    monkeypatch.setattr(sympy_parser, "parse_expr", refuse)
    for text in ('__import__("os")', "().__class__", "open('x')", "r**2 + sin(r)"):
        try:
            parse_expression(text, {"r": sympy.Symbol("r")})
        except ExpressionError:
            pass


def test_kerr_schild_schwarzschild_equals_the_built_in_metric():
    le = LineElement(SCHWARZSCHILD_KS, parameters=["M"])
    for x in POINTS:
        gi = np.linalg.inv(le.metric_at(x, {"M": 1.3}))
        np.testing.assert_allclose(gi, testing.inverse_metric("schwarzschild", [1.3], np.array(x)), rtol=0, atol=1e-15)
        y = np.array(x + MOMENTUM)
        built_in = testing.rhs("schwarzschild", [1.3], y)
        np.testing.assert_allclose(le.rhs_at(y, {"M": 1.3}), built_in, rtol=0, atol=1e-15 * np.abs(built_in).max())
    assert le.symmetries({"M": 1.3}) == {"stationary": True, "axisymmetric": True}


KERR_DEFINITIONS = {
    "a": "spin*M", "w": "x**2 + y**2 + z**2 - a**2", "rk": "sqrt((w + sqrt(w**2 + 4*a**2*z**2))/2)",
    "f": "2*M*rk**3/(rk**4 + a**2*z**2)", "l": "dt + ((rk*x + a*y)*dx + (rk*y - a*x)*dy)/(rk**2 + a**2) + z*dz/rk",
}  # fmt: skip


def test_kerr_written_in_kerr_schild_form_equals_the_built_in_metric():
    """Definitions stay symbols with chain-rule gradients, so Kerr's implicit r(x, y, z) is cheap."""
    le = LineElement("-dt**2 + dx**2 + dy**2 + dz**2 + f*l**2", parameters=["M", "spin"], definitions=KERR_DEFINITIONS)
    params = {"M": 1.2, "spin": 0.7}
    for x in (*POINTS, [0.0, 0.01, 0.02, 9.0]):
        gi = np.linalg.inv(le.metric_at(x, params))
        np.testing.assert_allclose(gi, testing.inverse_metric("kerr", [1.2, 0.7], np.array(x)), rtol=0, atol=1e-15)
        y = np.array(x + MOMENTUM)
        built_in = testing.rhs("kerr", [1.2, 0.7], y)
        np.testing.assert_allclose(le.rhs_at(y, params), built_in, rtol=0, atol=1e-15 * np.abs(built_in).max())
    assert le.symmetries(params) == {"stationary": True, "axisymmetric": True}
    assert [d[0].name for d in le.definitions] == ["r", "a", "w", "rk", "f"]  # l, a one-form, is inlined


def test_spherical_reissner_nordstrom_equals_its_cartesian_form_also_next_to_the_pole():
    sph = LineElement(RN_SPHERICAL, coordinates="spherical", parameters=["M", "Q"])
    spelled = LineElement("-(1 - 2*M/r + Q**2/r**2)*dt**2 + dr**2/(1 - 2*M/r + Q**2/r**2) + "
                          "r**2*(dtheta**2 + sin(theta)**2*dphi**2)", coordinates="spherical", parameters=["M", "Q"])
    cart = LineElement("-f*dt**2 + dx**2 + dy**2 + dz**2 + (1/f - 1)*((x*dx + y*dy + z*dz)/r)**2",
                       parameters=["M", "Q"], definitions={"f": "1 - 2*M/r + Q**2/r**2"})  # fmt: skip
    params = {"M": 1.0, "Q": 0.6}
    for x in (*POINTS, [0.0, 1e-9, -2e-9, 7.0]):  # the last a hair off the z axis
        want = cart.metric_at(x, params)
        np.testing.assert_allclose(sph.metric_at(x, params), want, rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(spelled.metric_at(x, params), want, rtol=1e-12, atol=1e-12)
    assert sph.g[0, 0].free_symbols >= {sph.params[0]}


def test_a_time_dependent_or_twisted_metric_is_told_apart():
    wave = LineElement("-dt**2 + dx**2 + dy**2 + dz**2 + exp(-(x - t)**2)*dx*dt")
    assert wave.symmetries({}) == {"stationary": False, "axisymmetric": False}
    assert sympy.simplify(wave.g[0, 1] - sympy.exp(-(wave.coords[1] - wave.coords[0]) ** 2) / 2) == 0


@pytest.mark.parametrize("kwargs, where, says", [
    ({"line_element": "-dt**2 + dx**2 + dt*dx*dy"}, "line_element", "3 differentials"),
    ({"line_element": "-dt**2 + sin(dx)"}, "line_element", "coefficient times two differentials"),
    ({"line_element": "dx**2 + dy**2 + dz**2"}, "line_element", "no dt term"),
    ({"line_element": "-dt**2 + r**2*dOmega", "coordinates": "spherical"}, "line_element", "one has dOmega"),
    ({"line_element": "-dt**2 + dr*dOmega", "coordinates": "spherical"}, "line_element", "dOmega may appear only"),
    ({"line_element": "-dt**2 + dr**2 + theta*dphi**2", "coordinates": "spherical"}, "line_element",
     "theta and phi may appear only inside sin"),
    ({"line_element": "-dt**2 + dx**2", "parameters": ["x"]}, "parameters", "not a usable parameter name"),
    ({"line_element": "-dt**2 + dx**2", "parameters": ["__class__"]}, "parameters", "not a usable parameter name"),
    ({"line_element": "-dt**2 + dx**2 + M*dy**2", "parameters": ["M", "M"]}, "parameters", "given twice"),
    ({"line_element": "-dt**2 + dx**2 + f*dy**2", "definitions": {"f": "1 + q"}}, "definitions.f", "unknown name 'q'"),
    ({"line_element": "-dt**2 + dx**2 +* dy**2"}, "line_element", "expected a number"),
    ({"line_element": "-dt**2 + dx**2", "coordinates": "polar"}, "coordinates", "must be one of"),
])  # fmt: skip
def test_bad_line_elements_are_named(kwargs, where, says):
    text = kwargs.pop("line_element")
    with pytest.raises(LineElementError) as err:
        LineElement(text, **kwargs)
    assert err.value.where == where and says in str(err.value)


# ------------------------------------------------------------------------------------------ generated C++
ROOT = __import__("pathlib").Path(__file__).resolve().parents[1]


def _compiled_values(le, name, values, states, tmp_path, split=None, structure="auto"):
    """Compile the generated struct into a small program that prints, for each state, g^{mu nu}, rhs, the
    contract's dual-number rhs and rhs in SIMD lanes; returns them as arrays."""
    import shutil
    import subprocess

    from warpviz.spacetime.line_element.codegen import metric_source

    compiler = shutil.which("c++") or shutil.which("g++")
    if compiler is None:
        pytest.skip("no C++ compiler on this machine (the generated code is checked where there is one)")
    (tmp_path / "gen.h").write_text(metric_source(le, name=name, values=values, register=False, split=split,
                                                  structure=structure))
    cls = "".join(p[:1].upper() + p[1:] for p in name.split("_"))
    rows = ",".join("{" + ",".join(repr(float(v)) for v in s) + "}" for s in states)
    params = ",".join(repr(float(values[p.name])) for p in le.params)
    (tmp_path / "main.cpp").write_text(f"""
#include <cstdio>
#include "gen.h"
int main() {{
  const wv::{cls} m(std::vector<double>{{{params}}});
  const double ys[][8] = {{{rows}}};
  for (const auto& y : ys) {{
    double gi[4][4], dy[8], da[8];
    m.inverse_metric(y, gi);
    m.rhs(y, dy);
    wv::rhs_autodiff(m, y, da);
    wv::Lanes yl[8], dl[8];
    for (int i = 0; i < 8; ++i) yl[i] = wv::Lanes{{}} + y[i];
    m.rhs(yl, dl);
    for (int i = 0; i < 16; ++i) std::printf("%.17g ", gi[i / 4][i % 4]);
    for (int i = 0; i < 8; ++i) std::printf("%.17g ", dy[i]);
    for (int i = 0; i < 8; ++i) std::printf("%.17g ", da[i]);
    for (int i = 0; i < 8; ++i) std::printf("%.17g ", dl[i][5]);
    std::printf("\\n");
  }}
}}
""")
    exe = tmp_path / "harness"
    subprocess.run([compiler, "-std=c++20", "-O1", "-ffp-contract=off", f"-I{ROOT / 'renderer_ext'}", f"-I{tmp_path}",
                    str(tmp_path / "main.cpp"), "-o", str(exe)], check=True, capture_output=True, timeout=300)  # fmt: skip
    out = subprocess.run([str(exe)], check=True, capture_output=True, text=True, timeout=60).stdout
    return np.array([[float(v) for v in line.split()] for line in out.strip().splitlines()])


@pytest.mark.parametrize("structure, split", [("auto", None), ("general", True), ("general", False)],
                         ids=["kerr_schild_closed_form", "split_solve", "cofactor_inverse"])
@pytest.mark.parametrize("metric, text, params, definitions", [
    ("schwarzschild", SCHWARZSCHILD_KS, {"M": 1.3}, None),
    ("kerr", "-dt**2 + dx**2 + dy**2 + dz**2 + f*l**2", {"M": 1.2, "spin": 0.7}, KERR_DEFINITIONS),
])  # fmt: skip
def test_the_generated_cpp_equals_the_built_in_metric_for_doubles_duals_and_lanes(tmp_path, metric, text, params,
                                                                                   definitions, structure, split):  # fmt: skip
    """Every form of the generated Hamilton equations gives the built-in rhs: H from the closed-form inverse
    of a Kerr-Schild line element, and g⁻¹p solved by the 3+1 split or the cofactor inverse."""
    le = LineElement(text, parameters=list(params), definitions=definitions)
    states = [x + MOMENTUM for x in POINTS]
    got = _compiled_values(le, f"expr_{metric}", params, states, tmp_path, split=split, structure=structure)
    for y, row in zip(states, got):
        built_gi = testing.inverse_metric(metric, list(params.values()), np.array(y[:4]))
        built = testing.rhs(metric, list(params.values()), np.array(y))
        scale = np.abs(built).max()
        np.testing.assert_allclose(row[:16].reshape(4, 4), built_gi, rtol=0, atol=1e-14)
        np.testing.assert_allclose(row[16:24], built, rtol=0, atol=1e-14 * scale)  # rhs
        np.testing.assert_allclose(row[24:32], built, rtol=0, atol=1e-12 * scale)  # the contract's dual numbers
        np.testing.assert_array_equal(row[32:40], row[16:24])  # a lane gives the double's bits


def test_the_3_plus_1_split_is_used_where_the_slices_are_spacelike_and_not_in_null_coordinates():
    from warpviz.spacetime.line_element.codegen import split_solve_applies

    assert split_solve_applies(LineElement(SCHWARZSCHILD_KS, parameters=["M"]), {"M": 1.0})
    assert split_solve_applies(LineElement(RN_SPHERICAL, coordinates="spherical", parameters=["M", "Q"]),
                               {"M": 1.0, "Q": 0.5})  # fmt: skip
    # ingoing Eddington-Finkelstein: ds^2 = -f dv^2 + 2 dv dr + r^2 dOmega^2 has g_rr = 0
    ef = LineElement("-(1 - 2*M/r)*dt**2 + 2*dt*dr + r**2*dOmega**2", coordinates="spherical", parameters=["M"])
    assert not split_solve_applies(ef, {"M": 1.0})


def test_every_function_of_the_grammar_compiles_for_doubles_duals_and_lanes(tmp_path):
    """Each function the grammar accepts reaches core/elementary.h (sympy's C printer has methods of its own
    for some, such as tanh, that printed the libm name, which does not take a Dual or Lanes): the compiled
    Hamilton equations equal the Python ones of the same line element."""
    text = ("-(1 + (exp(-r) + log(1 + r) + sin(x) + cos(y) + tan(z/50) + sinh(x/20) + cosh(y/20) + tanh(z)"
            " + asin(x/(2*r)) + acos(y/(2*r)) + atan(z) + abs(x) + atan2(y, x))/40)*dt**2"
            " + dx**2 + dy**2 + dz**2")  # fmt: skip
    le = LineElement(text)
    states = [x + MOMENTUM for x in POINTS if x[1] != 0.0]
    got = _compiled_values(le, "every_function", {}, states, tmp_path)
    for y, row in zip(states, got):
        want = le.rhs_at(np.array(y), {})
        scale = np.abs(want).max()
        np.testing.assert_allclose(row[16:24], want, rtol=0, atol=1e-13 * scale)
        np.testing.assert_allclose(row[24:32], want, rtol=0, atol=1e-12 * scale)
        np.testing.assert_array_equal(row[32:40], row[16:24])


def test_kerr_schild_form_is_recognised_and_nothing_else():
    from warpviz.spacetime.line_element.codegen import kerr_schild_form

    f, k = kerr_schild_form(LineElement(SCHWARZSCHILD_KS, parameters=["M"]))
    assert k[0] == 1 and sympy.simplify(f - 2 * sympy.Symbol("M", real=True) / sympy.Symbol("r", real=True)) == 0
    assert kerr_schild_form(LineElement("-dt**2 + dx**2 + dy**2 + dz**2 + f*l**2", parameters=["M", "spin"],
                                        definitions=KERR_DEFINITIONS)) is not None  # fmt: skip
    assert kerr_schild_form(LineElement(RN_SPHERICAL, coordinates="spherical", parameters=["M", "Q"])) is None
