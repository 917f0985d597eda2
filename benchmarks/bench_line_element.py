"""How fast a metric generated from its line element runs, against the built-in one.

Two measurements per metric (Schwarzschild and Kerr a = 0.9, both in Kerr-Schild form):

- **end to end** (the issue's target): the expression is compiled into a plugin with an empty cache (the
  first-use compile time, wall clock, on every core), loaded again from the cache, and a fan of 2000 rays
  is traced on one thread through it and through the built-in metric, alternating (A, B, A, B, A, B): the
  geodesics per second per core of each and their time ratio, min and median;
- **right-hand side**: the generated struct and the hand-written file compiled into one small program with
  the core's flags for the plugin's instruction set; the right-hand side timed one ray at a time (double)
  and eight at a time (SIMD lanes). The generated one is a call (not inlined: codegen.py says why), the
  hand-written one is inlined into the timing loop, which flatters it here more than in a stepper.

    python benchmarks/bench_line_element.py            # ~3 minutes on 2 cores
    warpviz bench line-element

Writes ``line_element.csv`` and ``line_element_trace.csv`` to ``--out`` (default benchmarks/results) and
prints tables. Needs a C++ compiler (``c++`` or ``g++``).
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import RESULTS, machine_line, write_csv  # noqa: E402

import numpy as np  # noqa: E402

import warpviz as wv  # noqa: E402
from warpviz.spacetime.line_element.codegen import metric_source  # noqa: E402
from warpviz.spacetime.line_element.plugin import _isa_flags  # noqa: E402
from warpviz.spacetime.line_element.tensor import LineElement  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]

CASES = {
    "schwarzschild": ("Schwarzschild", "-dt**2 + dx**2 + dy**2 + dz**2 + 2*M/r*(dt + (x*dx + y*dy + z*dz)/r)**2",
                      {"M": 1.0}, None, [1.0]),
    "kerr": ("Kerr", "-dt**2 + dx**2 + dy**2 + dz**2 + f*l**2", {"M": 1.0, "spin": 0.9},
             {"a": "spin*M", "w": "x**2 + y**2 + z**2 - a**2", "rk": "sqrt((w + sqrt(w**2 + 4*a**2*z**2))/2)",
              "f": "2*M*rk**3/(rk**4 + a**2*z**2)",
              "l": "dt + ((rk*x + a*y)*dx + (rk*y - a*x)*dy)/(rk**2 + a**2) + z*dz/rk"}, [1.0, 0.9]),
}  # fmt: skip

#: The landmarks of each, so that rays falling in end where the built-in metric's do (Kerr's horizon is
#: the Cartesian |x| = r+ here, a little inside the built-in's Boyer-Lindquist r = r+: a few more steps).
LANDMARKS = {"schwarzschild": {"horizon_radius": "2*M", "photon_sphere_radius": "3*M", "mass": "M"},
             "kerr": {"horizon_radius": "M + sqrt(M**2 - (spin*M)**2)", "mass": "M"}}  # fmt: skip

HARNESS = """
#include <chrono>
#include <cstdio>
#include "gen.h"
#include "metrics/{file}.cpp"

template <class M, class T>
double seconds(const M& m, const T* ys, int n, int reps) {{
  double best = 1e300, sink = 0.0;
  for (int k = 0; k < 5; ++k) {{
    const auto t0 = std::chrono::steady_clock::now();
    for (int r = 0; r < reps; ++r)
      for (int i = 0; i < n; ++i) {{
        T dy[8];
        m.rhs(ys + 8 * i, dy);
        sink += wv::value_of(dy[5]);
      }}
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    best = s < best ? s : best;
  }}
  std::fprintf(stderr, "%g\\n", sink);
  return best;
}}

int main() {{
  const wv::{gen} gen(std::vector<double>{{{params}}});
  const wv::{built} built(std::vector<double>{{{params}}});
  const int n = 1024, reps = 200;
  static double ys[8 * n];
  static wv::Lanes yl[8 * n / 8];
  for (int i = 0; i < n; ++i) {{
    const double r = 4.0 + 0.05 * i, c = std::cos(0.37 * i), s = std::sin(0.37 * i);
    const double y[8] = {{0.0, r * c * 0.8, r * s * 0.8, r * 0.6, -1.0, 0.3 * s, -0.2 * c, 0.9}};
    for (int k = 0; k < 8; ++k) {{
      ys[8 * i + k] = y[k];
      yl[8 * (i / 8) + k][i % 8] = y[k];
    }}
  }}
  std::printf("%.6e %.6e %.6e %.6e\\n", seconds(gen, ys, n, reps), seconds(built, ys, n, reps),
              seconds(gen, yl, n / 8, reps), seconds(built, yl, n / 8, reps));
}}
"""

VALUE_OF = """
namespace wv {
inline double value_of(double v) { return v; }
inline double value_of(Lanes v) { return v[0]; }
}
"""


def measure(name: str, compiler: str, work: Path) -> dict:
    built_cls, text, values, definitions, params = CASES[name]
    t0 = time.perf_counter()
    le = LineElement(text, parameters=list(values), definitions=definitions)
    source = metric_source(le, name=f"expr_{name}", values=values, register=False)
    generate_s = time.perf_counter() - t0
    (work / "gen.h").write_text(source + VALUE_OF)
    stub = work / "stub" / "engine"
    stub.mkdir(parents=True, exist_ok=True)
    (stub / "register.h").write_text("#pragma once\n#define WARPVIZ_REGISTER_METRIC(M)\n")
    gen_cls = "".join(p[:1].upper() + p[1:] for p in f"expr_{name}".split("_"))
    (work / "main.cpp").write_text(HARNESS.format(file=name, gen=gen_cls, built=built_cls,
                                                  params=", ".join(repr(p) for p in params)))  # fmt: skip
    exe = work / f"bench_{name}"
    t0 = time.perf_counter()
    subprocess.run([compiler, "-std=c++20", "-O3", "-fno-math-errno", "-fno-trapping-math", "-ffp-contract=off",
                    *_isa_flags(),  # the plugin's instruction set (line_element/plugin.py)
                    f"-I{work / 'stub'}", f"-I{work}", f"-I{ROOT / 'renderer_ext'}", str(work / "main.cpp"), "-o",
                    str(exe)], check=True, capture_output=True, timeout=600)  # fmt: skip
    compile_s = time.perf_counter() - t0
    out = subprocess.run([str(exe)], check=True, capture_output=True, text=True, timeout=600).stdout.split()
    gen_d, built_d, gen_l, built_l = (float(v) for v in out)
    evals = 1024 * 200
    return {"metric": name, "generate_s": generate_s, "compile_s": compile_s,
            "generated_ns_per_rhs": 1e9 * gen_d / evals, "built_in_ns_per_rhs": 1e9 * built_d / evals,
            "ratio_double": gen_d / built_d, "generated_ns_per_rhs_lanes": 1e9 * gen_l / evals,
            "built_in_ns_per_rhs_lanes": 1e9 * built_l / evals, "ratio_lanes": gen_l / built_l}  # fmt: skip


BUILT_IN = {"schwarzschild": lambda: wv.Schwarzschild(mass=1.0), "kerr": lambda: wv.Kerr(mass=1.0, spin=0.9)}


def measure_trace(name: str, cache: Path, rays: int = 2000, reps: int = 3) -> dict:
    """First-use compile time, cached load time and traced geodesics per second per core (module docstring)."""
    _, text, values, definitions, _ = CASES[name]
    os.environ["WARPVIZ_CACHE_DIR"] = str(cache)
    t0 = time.perf_counter()
    marks = LANDMARKS[name]
    expr = wv.Metric.from_line_element(text, parameters=values, definitions=definitions, name=f"bench_{name}",
                                       **marks)  # fmt: skip
    compile_s = time.perf_counter() - t0
    # a second process finds the libraries in the cache: the cost of a cached first use
    code = ("import time, warpviz as wv; t = time.perf_counter(); "
            f"wv.Metric.from_line_element({text!r}, parameters={values!r}, definitions={definitions!r}, "
            f"name='bench_{name}', **{marks!r}); print(time.perf_counter() - t)")  # fmt: skip
    cached_s = float(subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                                    env={**os.environ}, timeout=600).stdout.split()[-1])  # fmt: skip
    built = BUILT_IN[name]()
    rng = np.random.default_rng(1)
    d = rng.normal(size=(rays, 3))
    d[:, 1] = 3.0 * np.abs(d[:, 1])
    d /= np.linalg.norm(d, axis=1)[:, None]
    o = np.array([0.0, -20.0, 1.0])
    times = {"expr": [], "built": []}
    for _ in range(reps):  # alternating, so a busy moment of the machine hits both
        for key, metric in (("expr", expr), ("built", built)):
            t0 = time.perf_counter()
            wv.trace(metric, o, d, tol=1e-9, threads=1)
            times[key].append(time.perf_counter() - t0)
    ratios = [a / b for a, b in zip(times["expr"], times["built"])]
    return {"metric": name, "compile_s": compile_s, "cached_load_s": cached_s,
            "expr_geodesics_per_s": rays / min(times["expr"]), "built_in_geodesics_per_s": rays / min(times["built"]),
            "ratio_min": min(ratios), "ratio_median": float(np.median(ratios))}  # fmt: skip


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--metrics", nargs="+", default=list(CASES), choices=list(CASES))
    ap.add_argument("--out", type=Path, default=RESULTS)
    args = ap.parse_args(argv)
    compiler = shutil.which("c++") or shutil.which("g++")
    if compiler is None:
        print("no C++ compiler (c++ or g++) on this machine: nothing to measure")
        return 1
    print(machine_line(threads=1))
    rows, traced = [], []
    with tempfile.TemporaryDirectory() as tmp:
        for name in args.metrics:
            traced.append(measure_trace(name, Path(tmp) / "cache"))
        for name in args.metrics:
            rows.append(measure(name, compiler, Path(tmp)))
    write_csv(args.out / "line_element_trace.csv", traced)
    write_csv(args.out / "line_element.csv", rows)
    print(f"{'metric':<14} {'compile s':>9} {'cached s':>8} {'geodesics/s gen':>15} {'built-in':>9} {'ratio min':>9} "
          f"{'median':>6}")  # fmt: skip
    for r in traced:
        print(f"{r['metric']:<14} {r['compile_s']:>9.1f} {r['cached_load_s']:>8.2f} {r['expr_geodesics_per_s']:>15.0f} "
              f"{r['built_in_geodesics_per_s']:>9.0f} {r['ratio_min']:>9.2f} {r['ratio_median']:>6.2f}")  # fmt: skip
    print(f"{'metric':<14} {'generate s':>10} {'compile s':>9} {'ns/rhs gen':>10} {'built-in':>9} {'ratio':>6} "
          f"{'ns/rhs lanes gen':>16} {'built-in':>9} {'ratio':>6}")  # fmt: skip
    for r in rows:
        print(f"{r['metric']:<14} {r['generate_s']:>10.2f} {r['compile_s']:>9.1f} {r['generated_ns_per_rhs']:>10.1f} "
              f"{r['built_in_ns_per_rhs']:>9.1f} {r['ratio_double']:>6.2f} {r['generated_ns_per_rhs_lanes']:>16.1f} "
              f"{r['built_in_ns_per_rhs_lanes']:>9.1f} {r['ratio_lanes']:>6.2f}")  # fmt: skip
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
