"""What skipping unneeded work is worth: each shortcut the renderer and the tracer take, timed with and
without it on the same work.

* flat space: the fig07-style room traced as straight lines (Minkowski) against the same room with a
  1e-12 M mass, which integrates every segment (the images agree to noise level, see tests/test_render.py);
* recording: tracing a far-observer image plane with and without ``record=True`` (polylines and per-point
  data are only built when asked);
* the light connection's pilot geodesics (``aim_lights``) in the curved room;
* the far-field tail of escaped rays: the integration stops at R = (10 M^2 b / tol)^(1/3) and the rest of
  the bending comes from a 16-point Born-approximation quadrature, against integrating out to 1e6 M;
* conserved quantities other than H checked every 4th step at tol >= 1e-8 (Kerr plane) against every step;
* pilot geodesics traced at ``pilot_tol`` = 1e-4 against the render tolerance (they only aim light
  samples, so their accuracy cannot bias the image).

Usage: ``python benchmarks/bench_skips.py [--quick] [--out DIR]``; writes ``skips.csv`` into ``--out``
(default ``benchmarks/results``) and prints the table.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import warpviz as wv  # noqa: E402
from _common import RESULTS, machine_line, pinhole_grid, timed, write_csv  # noqa: E402
from _scenes import cornell_room  # noqa: E402


def far_observer_plane(n: int, *, distance: float = 1000.0, half: float = 12.0):
    """Directions of an n x n image plane seen from (-distance, 0, 0) towards the origin: (n*n, 3), spanning
    +-``half`` at the origin (:func:`_common.pinhole_grid`)."""
    return pinhole_grid([-distance, 0.0, 0.0], size=n, half_width=half)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="tiny problems for a smoke test (seconds)")
    parser.add_argument("--out", type=Path, default=RESULTS, help="output folder (default benchmarks/results)")
    args = parser.parse_args(argv)
    size = (16, 12) if args.quick else (48, 36)
    spp = 2 if args.quick else 8
    n = 16 if args.quick else 64
    rows = []

    def add(what, without, with_, unit, seconds_without, seconds_with, note=""):
        rows.append({"shortcut": what, "without": without, "with": with_, "unit": unit,
                     "cpu_s_without": seconds_without, "cpu_s_with": seconds_with,
                     "speedup": seconds_without / seconds_with if seconds_with > 0 else float("nan"),
                     "note": note})

    samples = size[0] * size[1] * spp
    flat = cornell_room({"name": "minkowski", "params": []}, size=size)
    tiny = cornell_room({"name": "schwarzschild", "params": [1e-12]}, size=size)
    a, t_flat, _ = timed(lambda: wv.render(flat, spp=spp, threads=1))
    b, t_tiny, _ = timed(lambda: wv.render(tiny, spp=spp, threads=1))
    add("flat space traced as straight lines", samples / t_tiny, samples / t_flat, "samples/s", t_tiny, t_flat,
        f"mean radiance {a.rgb.mean():.4f} vs {b.rgb.mean():.4f}")

    bh = wv.Schwarzschild(mass=1.0)
    dirs = far_observer_plane(n)
    _, t_rec, _ = timed(lambda: wv.trace(bh, [-1000.0, 0, 0], dirs, tol=1e-8, record=True, threads=1))
    _, t_plain, _ = timed(lambda: wv.trace(bh, [-1000.0, 0, 0], dirs, tol=1e-8, threads=1))
    add("no recording unless asked", len(dirs) / t_rec, len(dirs) / t_plain, "geodesics/s", t_rec, t_plain)

    room = cornell_room({"name": "schwarzschild", "params": [2.5]}, size=size)
    _, t_aim, _ = timed(lambda: wv.render(room, spp=spp, threads=1, aim_lights=True))
    _, t_noaim, _ = timed(lambda: wv.render(room, spp=spp, threads=1, aim_lights=False))
    add("no pilot geodesics (aim_lights=False)", samples / t_aim, samples / t_noaim, "samples/s", t_aim, t_noaim,
        "pilots cost time but lower the error per sample; see README")

    far = wv.trace(bh, [-1000.0, 0, 0], dirs, tol=1e-8, threads=1)
    _, t_tail, _ = timed(lambda: wv.trace(bh, [-1000.0, 0, 0], dirs, tol=1e-8, threads=1))
    _, t_long, _ = timed(lambda: wv.trace(bh, [-1000.0, 0, 0], dirs, tol=1e-8, threads=1, escape_radius=1e6))
    add("far-field Born tail instead of integrating to 1e6 M", len(dirs) / t_long, len(dirs) / t_tail,
        "geodesics/s", t_long, t_tail, f"{int((far.status_names == 'escaped').sum())} escaped rays")

    kerr = wv.Kerr(mass=1.0, spin=0.9)
    _, t_every, _ = timed(lambda: wv.trace(kerr, [-1000.0, 0, 0], dirs, tol=1e-8, threads=1, monitor_every=1))
    _, t_fourth, _ = timed(lambda: wv.trace(kerr, [-1000.0, 0, 0], dirs, tol=1e-8, threads=1))
    add("Kerr: conserved quantities checked every 4th step", len(dirs) / t_every, len(dirs) / t_fourth,
        "geodesics/s", t_every, t_fourth, "H still every step; tol 1e-8")

    render_tol = 1e-7
    _, t_exact_pilots, _ = timed(lambda: wv.render(room, spp=spp, threads=1, pilot_tol=render_tol))
    add("pilots at tol 1e-4 instead of the render's 1e-7", samples / t_exact_pilots, samples / t_aim, "samples/s",
        t_exact_pilots, t_aim, "the share of light samples reaching the lamp is unchanged")

    print(machine_line(threads=1))
    print(f"{'shortcut':52s} {'without':>12s} {'with':>12s} {'unit':>12s} {'speed-up':>9s}")
    for r in rows:
        print(f"{r['shortcut']:52s} {r['without']:12.0f} {r['with']:12.0f} {r['unit']:>12s} {r['speedup']:8.2f}x")
    args.out.mkdir(parents=True, exist_ok=True)
    write_csv(args.out / "skips.csv", rows)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
