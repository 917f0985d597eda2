"""How fast a metric generated from its line element evaluates Hamilton's equations, against the built-in one.

The generated struct (``warpviz/spacetime/line_element/codegen.py``) and the hand-written metric file are
compiled into one small program with the core's flags (-O3, no FMA contraction); it times the right-hand
side on a fixed set of states, one ray at a time (double) and eight at a time (SIMD lanes, the renderer's
batches), best of five. The right-hand side is most of a geodesic step's cost, so the ratio bounds what
an expression metric will cost in the renderer until it is compiled into a plugin and traced end to end.

    python benchmarks/bench_line_element.py            # Schwarzschild and Kerr in Kerr-Schild form; ~2 minutes
    warpviz bench line-element

Writes ``line_element.csv`` to ``--out`` (default benchmarks/results) and prints a table. Needs a C++
compiler (``c++`` or ``g++``).
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import RESULTS, machine_line, write_csv  # noqa: E402

from warpviz.spacetime.line_element.codegen import metric_source  # noqa: E402
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
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for name in args.metrics:
            rows.append(measure(name, compiler, Path(tmp)))
    write_csv(args.out / "line_element.csv", rows)
    print(f"{'metric':<14} {'generate s':>10} {'compile s':>9} {'ns/rhs gen':>10} {'built-in':>9} {'ratio':>6} "
          f"{'ns/rhs lanes gen':>16} {'built-in':>9} {'ratio':>6}")  # fmt: skip
    for r in rows:
        print(f"{r['metric']:<14} {r['generate_s']:>10.2f} {r['compile_s']:>9.1f} {r['generated_ns_per_rhs']:>10.1f} "
              f"{r['built_in_ns_per_rhs']:>9.1f} {r['ratio_double']:>6.2f} {r['generated_ns_per_rhs_lanes']:>16.1f} "
              f"{r['built_in_ns_per_rhs_lanes']:>9.1f} {r['ratio_lanes']:>6.2f}")  # fmt: skip
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
