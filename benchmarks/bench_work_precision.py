"""Work-precision of the geodesic steppers: run time per geodesic against error from exact references.

For each spacetime (Schwarzschild; Kerr a = 0.5, 0.9, 0.998; Ellis throat 1) and stepper (``dopri5``,
``dop853``, and the seed paper's ``rk4``: fixed step with halving) a sweep of tolerances is timed on one
thread and its error measured:

* **Schwarzschild, Ellis** — relative error of the total deflection angle against the exact values in
  ``tests/data/exact_values.json`` (copied below): each case's ray starts at r = 1000 (M, or throat
  radii) with the exact impact parameter and is traced forwards and backwards; the angle between the
  two asymptotic directions is the deflection. The error is the largest over the cases.
* **Kerr** — a pinhole camera at r = 1000 M, inclination 60 deg, looks at the hole with an image plane
  of +-15 M; the error is the largest angle between a run's asymptotic directions and a dop853
  tol = 1e-13 reference (rays escaped in both), and the largest relative drift of the conserved E, Lz
  and Carter's Q along any ray (``RayBundle.invariant_drift``).

For every metric the CSV also has ``drift_conserved``, the largest relative drift of any monitored
conserved quantity but H along any ray (Kerr: E, Lz, Q; Schwarzschild: E, Lz, L^2; Ellis: E, L^2), and
``drift_H`` (the null condition).

``rk4`` is run twice per tolerance: with the seed's base step ``rk4_step`` = 1 M, and with a matching
sweep ``rk4_step = tol**0.25 * 1000`` (the halving rule's own limit at the start radius, so the step is
kappa * r everywhere, kappa = tol**0.25). The speed-up of dopri5 over rk4 at equal error interpolates
rk4's time (log-log on the Pareto front of all its runs) at each dopri5 run's error.

Time is CPU time per geodesic on one core; the rays of a run are repeated until a measurement takes at
least ``--min-cpu`` seconds. Results: ``work_precision.csv`` and ``work_precision*.png`` in ``--out``.

    python benchmarks/bench_work_precision.py            # a few minutes
    python benchmarks/bench_work_precision.py --quick    # seconds
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

import warpviz as wv  # noqa: E402
from _common import RESULTS, machine_line, pinhole_grid, pyplot, time_at_error, timed, write_csv  # noqa: E402

#: Exact deflection angles (copy of tests/data/exact_values.json): impact parameter b and angle alpha.
SCHWARZSCHILD_DEFLECTION = [  # M = 1
    (5.3463383107818133, 3.2061227419797587),  # closest approach r0 = 3.5
    (5.6568542494923802, 2.1841001877275592),  # r0 = 4
    (7.3484692283495343, 1.014875432217572),  # r0 = 6
    (11.180339887498948, 0.5002356566077917),  # r0 = 10
]
ELLIS_DEFLECTION = [  # throat b0 = 1: alpha = 2 K(1/b) - pi
    (1.5, 0.47774233738338375),
    (2.0, 0.22990805603539885),
    (5.0, 0.032143041318539236),
]

START_RADIUS = 1000.0
FULL_TOLS = [10.0**-k for k in range(4, 13)]
QUICK_TOLS = [1e-4, 1e-6, 1e-8, 1e-10]
QUICK_RK4_TOLS = [1e-4, 1e-6, 1e-8]
REPORT_TOLS = (1e-6, 1e-8, 1e-10)  # dopri5 tolerances of the summary's speed-up columns

COLUMNS = [
    "metric", "stepper", "variant", "tol", "rk4_step", "rays", "geodesics_per_s_per_core", "us_per_geodesic",
    "mean_steps", "error_kind", "error", "median_error", "status_mismatch", "drift_E", "drift_Lz", "drift_Q",
    "drift_conserved", "drift_H", "speedup_vs_rk4", "speedup_vs_rk4_seed_step",
]  # fmt: skip


def launch_direction(b: float, *, mass: float, r0: float = START_RADIUS) -> np.ndarray:
    """Static-frame direction at (-r0, 0, 0) of a ray with impact parameter ``b`` heading for +x in
    the x-y plane: sin(angle from radial) = b sqrt(1 - 2 M / r0) / r0 (mass 0 for Ellis)."""
    s = b * math.sqrt(1.0 - 2.0 * mass / r0) / r0
    return np.array([math.sqrt(1.0 - s * s), s, 0.0])


def deflection_problem(cases, *, mass: float):
    """Rays (forward and backward per case) and an error function: the largest relative error of the
    deflection angle, from the two asymptotic directions of each case."""
    dirs = []
    for b, _ in cases:
        d = launch_direction(b, mass=mass)
        dirs += [d, -d]
    dirs = np.array(dirs)
    origin = np.array([-START_RADIUS, 0.0, 0.0])
    exact = np.array([alpha for _, alpha in cases])

    def errors(rays: wv.RayBundle, _ref) -> dict:
        out_dir, in_dir = rays.final_directions[0::2], -rays.final_directions[1::2]
        ok = (rays.status[0::2] == wv.RayStatus.ESCAPED) & (rays.status[1::2] == wv.RayStatus.ESCAPED)
        turn = np.arctan2(np.cross(in_dir, out_dir)[:, 2], np.einsum("ij,ij->i", in_dir, out_dir))
        alpha = np.mod(-turn, 2 * math.pi)
        rel = np.where(ok, np.abs(alpha - exact) / exact, np.inf)
        return {"error_kind": "max_rel_deflection_error", "error": float(rel.max()),
                "median_error": float(np.median(rel)), "status_mismatch": int(np.count_nonzero(~ok))}  # fmt: skip

    return origin, dirs, errors


def image_plane(size: int, *, distance: float = START_RADIUS, inclination_deg: float = 60.0, half_width: float = 15.0):
    """Origin (3,) and unit directions (size * size, 3) of a pinhole camera at ``distance`` looking at the
    origin from ``inclination_deg`` off the +z axis, its field spanning +-``half_width`` at the centre
    (:func:`_common.pinhole_grid`)."""
    inc = math.radians(inclination_deg)
    origin = distance * np.array([math.sin(inc), 0.0, math.cos(inc)])
    return origin, pinhole_grid(origin, size=size, half_width=half_width)


def direction_errors(rays: wv.RayBundle, ref: wv.RayBundle) -> dict:
    """Angles between asymptotic directions of rays escaped in both bundles, and status mismatches."""
    both = (rays.status == wv.RayStatus.ESCAPED) & (ref.status == wv.RayStatus.ESCAPED)
    u, v = rays.final_directions[both], ref.final_directions[both]
    angle = np.arctan2(np.linalg.norm(np.cross(u, v), axis=1), np.einsum("ij,ij->i", u, v))
    return {"error_kind": "max_direction_error_rad", "error": float(angle.max()) if angle.size else 0.0,
            "median_error": float(np.median(angle)) if angle.size else 0.0,
            "status_mismatch": int(np.count_nonzero(rays.status != ref.status))}  # fmt: skip


def measure(metric, origin, dirs, *, min_cpu: float, threads: int, **options) -> tuple[wv.RayBundle, float]:
    """Trace the rays and the CPU seconds per ray; the rays are repeated (identical copies) until one
    timed call takes at least ``min_cpu`` CPU seconds."""
    kw = dict(options, threads=threads, max_steps=10_000_000)
    rays, cpu, _ = timed(lambda: wv.trace(metric, origin, dirs, **kw))
    if cpu >= min_cpu:
        return rays, cpu / len(dirs)
    reps = int(min(math.ceil(min_cpu / max(cpu, 1e-4)), max(1, 200_000 // len(dirs))))
    tiled = np.tile(dirs, (reps, 1))
    _, cpu, _ = timed(lambda: wv.trace(metric, origin, tiled, **kw))
    return rays, cpu / len(tiled)


def problems(*, size: int):
    """(label, metric, origin, directions, error function, needs a reference) of every spacetime."""
    schwarzschild = deflection_problem(SCHWARZSCHILD_DEFLECTION, mass=1.0)
    out = [("schwarzschild", wv.Schwarzschild(mass=1.0), *schwarzschild, False)]
    origin, dirs = image_plane(size)
    for spin in (0.5, 0.9, 0.998):
        out.append((f"kerr_a{spin:g}", wv.Kerr(mass=1.0, spin=spin), origin, dirs, direction_errors, True))
    out.append(("ellis", wv.EllisWormhole(throat=1.0), *deflection_problem(ELLIS_DEFLECTION, mass=0.0), False))
    return out


def runs(*, quick: bool):
    """(stepper, variant, tol, rk4_step) of every run, in order."""
    tols = QUICK_TOLS if quick else FULL_TOLS
    rk4_tols = QUICK_RK4_TOLS if quick else FULL_TOLS
    out = [(s, "adaptive", t, None) for s in ("dopri5", "dop853") for t in tols]
    for t in rk4_tols:
        out.append(("rk4", "seed step 1 M", t, 1.0))
        out.append(("rk4", "matched step", t, t**0.25 * START_RADIUS))
    return out


def add_speedups(rows: list[dict]) -> None:
    """Fill speedup_vs_rk4 (all rk4 runs) and speedup_vs_rk4_seed_step for the adaptive rows."""
    for metric in {r["metric"] for r in rows}:
        mine = [r for r in rows if r["metric"] == metric]
        rk4 = [r for r in mine if r["stepper"] == "rk4" and r["status_mismatch"] == 0]
        seed = [r for r in rk4 if r["variant"] == "seed step 1 M"]
        for r in mine:
            if r["stepper"] == "rk4":
                continue
            for key, pool in (("speedup_vs_rk4", rk4), ("speedup_vs_rk4_seed_step", seed)):
                t = time_at_error([p["us_per_geodesic"] for p in pool], [p["error"] for p in pool], r["error"])
                r[key] = t / r["us_per_geodesic"] if math.isfinite(t) else math.nan


def summary(rows: list[dict]) -> list[dict]:
    """Per metric: dopri5's speed-up over rk4 (all rk4 runs) at equal error, at the report tolerances."""
    out = []
    for metric in dict.fromkeys(r["metric"] for r in rows):
        entry = {"metric": metric}
        for tol in REPORT_TOLS:
            hit = [r for r in rows if r["metric"] == metric and r["stepper"] == "dopri5" and r["tol"] == tol]
            entry[f"tol {tol:.0e}"] = hit[0]["speedup_vs_rk4"] if hit else math.nan
            entry[f"seed tol {tol:.0e}"] = hit[0]["speedup_vs_rk4_seed_step"] if hit else math.nan
        out.append(entry)
    return out


def plot(rows: list[dict], out: Path, *, per_metric: bool = True) -> list[Path]:
    """An overview PNG of all metrics and (``per_metric``) one PNG per metric, Kerr's with a second panel
    for the conserved-quantity drift."""
    plt = pyplot()
    if plt is None:
        return []
    styles = {("dopri5", "adaptive"): ("C0", "o", "dopri5"), ("dop853", "adaptive"): ("C1", "s", "dop853"),
              ("rk4", "seed step 1 M"): ("C3", "v", "rk4 (seed, step 1 M)"),
              ("rk4", "matched step"): ("C2", "^", "rk4 (step tol^1/4 r0)")}  # fmt: skip
    metrics = list(dict.fromkeys(r["metric"] for r in rows))

    def panel(ax, metric, key, ylabel):
        for (stepper, variant), (color, marker, label) in styles.items():
            pts = sorted(((r["us_per_geodesic"], r[key], r["tol"]) for r in rows
                          if r["metric"] == metric and r["stepper"] == stepper and r["variant"] == variant
                          and r[key] > 0 and math.isfinite(r[key])), key=lambda p: -p[2])  # loose to tight tol
            if pts:
                ax.loglog([p[0] for p in pts], [p[1] for p in pts], marker=marker, color=color, label=label, ms=4)
            if stepper == "dopri5":
                for t, e, tol in pts:
                    ax.annotate(f"{tol:.0e}", (t, e), fontsize=6, xytext=(3, 3), textcoords="offset points")
        ax.set_xlabel("CPU time per geodesic (us, 1 core)")
        ax.set_ylabel(ylabel)
        ax.set_title(metric)
        ax.grid(True, which="major", alpha=0.3)

    labels = {"max_rel_deflection_error": "max rel. deflection error",
              "max_direction_error_rad": "max direction error (rad)"}
    paths = []
    for metric in metrics if per_metric else []:
        kind = next(r["error_kind"] for r in rows if r["metric"] == metric)
        kerr = kind == "max_direction_error_rad"
        fig, axes = plt.subplots(1, 2 if kerr else 1, figsize=(11 if kerr else 5.8, 4.3), squeeze=False)
        panel(axes[0, 0], metric, "error", labels[kind])
        if kerr:
            panel(axes[0, 1], metric, "drift_conserved", "max rel. drift of E, Lz, Q")
            axes[0, 1].set_title(f"{metric}: conserved quantities")
        axes[0, 0].legend(fontsize=7)
        fig.tight_layout()
        paths.append(out / f"work_precision_{metric}.png")
        fig.savefig(paths[-1], dpi=110)
        plt.close(fig)
    cols = 3
    nrows = math.ceil(len(metrics) / cols)
    fig, axes = plt.subplots(nrows, cols, figsize=(5 * cols, 4 * nrows), squeeze=False)
    for ax, metric in zip(axes.flat, metrics):
        kind = next(r["error_kind"] for r in rows if r["metric"] == metric)
        panel(ax, metric, "error", labels[kind])
    for ax in list(axes.flat)[len(metrics):]:
        ax.axis("off")
    axes[0, 0].legend(fontsize=7)
    fig.suptitle("Work-precision of the geodesic steppers (1 core)")
    fig.tight_layout()
    paths.append(out / "work_precision.png")
    fig.savefig(paths[-1], dpi=110)
    plt.close(fig)
    return paths


def main(argv=None) -> list[dict]:
    """Run the work-precision benchmark.

    Parameters
    ----------
    argv : list of str, optional
        Command-line arguments (default: ``sys.argv[1:]``): ``--quick``, ``--out DIR``, ``--threads N``,
        ``--size N`` (Kerr image plane N x N), ``--min-cpu S``, ``--no-plots``. Quick mode writes only
        the overview plot.

    Returns
    -------
    list of dict
        One row per (metric, stepper, variant, tol), the CSV's rows.
    """
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="small sweep for a smoke test (seconds)")
    ap.add_argument("--out", type=Path, default=RESULTS, help="output folder (default benchmarks/results)")
    ap.add_argument("--threads", type=int, default=1, help="trace threads (default 1; rates are per core anyway)")
    ap.add_argument("--size", type=int, default=None, help="Kerr image plane is size x size rays (default 16, quick 4)")
    ap.add_argument("--no-plots", action="store_true", help="write the CSV only")
    ap.add_argument("--no-batch", action="store_true",
                    help="trace dopri5 one ray at a time too (like rk4 and dop853), for a like-for-like comparison")
    ap.add_argument("--min-cpu", type=float, default=None, help="CPU seconds per timing (default 0.3, quick 0.01)")
    args = ap.parse_args(argv)
    size = args.size or (4 if args.quick else 16)
    min_cpu = args.min_cpu if args.min_cpu is not None else (0.01 if args.quick else 0.3)

    print(f"{machine_line(threads=args.threads)}\nrates are geodesics per CPU-second (per core)\n")
    print(f"{'metric':<14} {'stepper':<7} {'variant':<14} {'tol':>7} {'geod/s/core':>11} {'steps':>8} "
          f"{'error':>9} {'drift':>8} {'mism':>4}")  # fmt: skip
    rows = []
    for label, metric, origin, dirs, errors, needs_ref in problems(size=size):
        ref = wv.trace(metric, origin, dirs, stepper="dop853", tol=1e-13, threads=args.threads,
                       max_steps=10_000_000) if needs_ref else None  # fmt: skip
        for stepper, variant, tol, rk4_step in runs(quick=args.quick):
            opts = {"stepper": stepper, "tol": tol, "batch": not args.no_batch} | ({"rk4_step": rk4_step} if rk4_step else {})
            rays, per_ray = measure(metric, origin, dirs, min_cpu=min_cpu, threads=args.threads, **opts)
            drift = rays.invariant_drift
            conserved = [v for k, v in drift.items() if k != "H"]  # E, Lz, Q (Kerr); E, Lz, L2; E, L2 (Ellis)
            row = {
                "metric": label, "stepper": stepper, "variant": variant, "tol": tol,
                "rk4_step": rk4_step if rk4_step else math.nan, "rays": len(dirs),
                "geodesics_per_s_per_core": 1.0 / per_ray, "us_per_geodesic": 1e6 * per_ray,
                "mean_steps": float(rays.n_steps.mean()), **errors(rays, ref),
                **{f"drift_{k}": float(drift[k].max()) if k in drift else math.nan for k in ("E", "Lz", "Q")},
                "drift_conserved": float(np.max(conserved)), "drift_H": float(drift["H"].max()),
            }  # fmt: skip
            rows.append(row)
            print(f"{label:<14} {stepper:<7} {variant:<14} {tol:>7.0e} {row['geodesics_per_s_per_core']:>11.0f} "
                  f"{row['mean_steps']:>8.0f} {row['error']:>9.2e} {row['drift_conserved']:>8.1e} "
                  f"{row['status_mismatch']:>4d}")  # fmt: skip
    add_speedups(rows)
    rows = [{k: r.get(k, math.nan) for k in COLUMNS} for r in rows]
    args.out.mkdir(parents=True, exist_ok=True)
    path = write_csv(args.out / "work_precision.csv", rows)

    print("\ndopri5 vs rk4 speed-up at equal error (rk4's CPU time interpolated at dopri5's error;")
    print("best of both rk4 step sweeps, in brackets against the seed's step 1 M alone; - = outside rk4's range)")
    table = summary(rows)
    print(f"{'metric':<14}" + "".join(f" {'dopri5 tol ' + format(t, '.0e'):>22}" for t in REPORT_TOLS))
    for entry in table:
        cells = []
        for tol in REPORT_TOLS:
            a, b = entry[f"tol {tol:.0e}"], entry[f"seed tol {tol:.0e}"]
            cells.append(f"{_x(a)} ({_x(b)})")
        print(f"{entry['metric']:<14}" + "".join(f" {c:>22}" for c in cells))
    written = [path, *([] if args.no_plots else plot(rows, args.out, per_metric=not args.quick))]
    print("\nwrote " + ", ".join(str(p) for p in written))
    return rows


def _x(v: float) -> str:
    return f"{v:.1f}x" if math.isfinite(v) else "-"


if __name__ == "__main__":
    main()
