"""``warpviz bench``: run one of the benchmark suites of ``benchmarks/``.
"""

from __future__ import annotations

import importlib
import importlib.metadata
import importlib.util
import sys
from pathlib import Path

import typer

from warpviz.cli.app import app
from warpviz.cli.common import EXIT_BAD_INPUT, _fail, _guard

#: ``warpviz bench SUITE``: the benchmark scripts of the repository's benchmarks/ folder.
BENCH_SUITES = {
    "geodesics": "bench_geodesics.py",
    "work-precision": "bench_work_precision.py",
    "render": "bench_render.py",
    "skips": "bench_skips.py",
    "light-connection": "bench_light_connection.py",
    "mitsuba-cornell": "bench_mitsuba_cornell.py",
    "denoise": "bench_denoise.py",
    "edge-samples": "bench_edge_samples.py",
    "time-to-clean": "bench_time_to_clean.py",
    "dask": "bench_dask.py",
    "line-element": "bench_line_element.py",
    "gravity-cost": "bench_gravity_cost.py",
    "builds": "bench_builds.py",
    "caustics": "bench_caustics.py",
}


@app.command(context_settings={"allow_extra_args": True, "ignore_unknown_options": True})
def bench(ctx: typer.Context) -> None:
    """Run a benchmark: `warpviz bench SUITE OPTIONS`, SUITE one of geodesics, work-precision, render, skips,
    light-connection, mitsuba-cornell, denoise, edge-samples, time-to-clean, dask, line-element, gravity-cost,
    builds, caustics.

    Without a SUITE it runs the far-observer geodesic benchmark (benchmarks/bench_geodesics.py); every
    suite takes its own options after the name, e.g. `warpviz bench --size 32` or
    `warpviz bench render --quick`. Results (CSV, plots) go to --out DIR, by default the working
    directory; the repository's committed results are refreshed only by running a script directly.
    """
    with _guard():
        args = list(ctx.args)
        if args and not args[0].startswith("-") and args[0] not in BENCH_SUITES:
            _fail(f"no benchmark suite {args[0]!r}; the suites are: {', '.join(BENCH_SUITES)}", EXIT_BAD_INPUT)
        suite = args.pop(0) if args and args[0] in BENCH_SUITES else "geodesics"
        if not any(a == "--out" or a.startswith("--out=") for a in args) and not {"-h", "--help"} & set(args):
            args += ["--out", str(Path.cwd())]
        folder = Path(__file__).resolve().parents[2] / "benchmarks"  # the repository beside the package
        script = folder / BENCH_SUITES[suite]
        if not script.is_file():
            _fail(f"benchmark script not found: {script} (it ships with the repository, not the package)")
        sys.path.insert(0, str(folder))  # the scripts share benchmarks/_common.py and _scenes.py
        spec = importlib.util.spec_from_file_location(f"warpviz_bench_{suite.replace('-', '_')}", script)
        module = importlib.util.module_from_spec(spec)
        saved_prog, sys.argv[0] = sys.argv[0], f"warpviz bench {suite}"  # argparse names the program after argv[0]
        try:
            spec.loader.exec_module(module)
            module.main(args)
        except SystemExit as exc:  # argparse: --help (0) or bad options (2)
            code = exc.code if isinstance(exc.code, int) else EXIT_BAD_INPUT
            raise typer.Exit(code) from None
        finally:
            sys.argv[0] = saved_prog
            sys.path.remove(str(folder))
