"""Geodesic throughput and work-precision of the steppers for a far observer's image plane.

For Schwarzschild and Kerr (a = 0.9), a pinhole camera at r = 1000 M (inclination 60 deg) looks at the
hole with a field of view spanning +-15 M; every pixel's ray is traced to escape or capture. The error of
a run is the largest angle between its asymptotic directions and a dop853 tol = 1e-13 reference (escaped
rays), plus the number of pixels whose escaped/captured classification differs. The seed RK4 method is
then run at the cheapest tolerance whose error is no worse than dopri5's, for an equal-error comparison.
Every stepper traces in SIMD batches (the default); dopri5 at tol 1e-8 also one ray at a time.

Run from the repository root (results go to benchmarks/results/geodesics.csv, or ``--out DIR``):

    python benchmarks/bench_geodesics.py            # 128 x 128 image plane, ~1 minute
    python benchmarks/bench_geodesics.py --size 32  # quick look
"""

from __future__ import annotations

import argparse
import csv
import math
import platform
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

import warpviz as wv  # noqa: E402
from _common import pinhole_grid  # noqa: E402


def image_plane(size: int, *, distance: float = 1000.0, inclination_deg: float = 60.0, half_width: float = 15.0):
    """Origin (3,) and unit directions (size*size, 3) of a pinhole camera looking at the origin, its grid of
    rays evenly spaced in angle (:func:`_common.pinhole_grid`)."""
    inc = math.radians(inclination_deg)
    origin = distance * np.array([math.sin(inc), 0.0, math.cos(inc)])
    return origin, pinhole_grid(origin, size=size, half_width=half_width, equal_angles=True)


def angular_error(a: wv.RayBundle, ref: wv.RayBundle) -> tuple[float, int]:
    both = (a.status == wv.RayStatus.ESCAPED) & (ref.status == wv.RayStatus.ESCAPED)
    u, v = a.final_directions[both], ref.final_directions[both]
    angle = np.arctan2(np.linalg.norm(np.cross(u, v), axis=1), np.einsum("ij,ij->i", u, v))  # no arccos floor
    err = float(np.max(angle)) if both.any() else 0.0
    return err, int(np.count_nonzero(a.status != ref.status))


def run(metric, origin, dirs, *, repeat=1, **kw):
    """Rays and the best wall time of ``repeat`` runs on one thread (the others share the machine)."""
    best = math.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        rays = wv.trace(metric, origin, dirs, threads=1, max_steps=10_000_000, **kw)
        best = min(best, time.perf_counter() - t0)
    return rays, best


def main(argv=None) -> list[dict]:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", type=int, default=128, help="image plane is size x size rays")
    ap.add_argument("--rk4-subset", type=int, default=16, help="trace every Nth ray with rk4 (it is slow)")
    ap.add_argument("--repeat", type=int, default=3, help="best of this many timings per dopri5/dop853 run")
    ap.add_argument("--out", type=Path, default=Path(__file__).parent / "results",
                    help="output folder for geodesics.csv (default benchmarks/results)")  # fmt: skip
    args = ap.parse_args(argv)

    origin, dirs = image_plane(args.size)
    rows = []
    print(f"{platform.processor() or platform.machine()}, 1 thread, {len(dirs)} rays per run\n")
    print(
        f"{'metric':<14} {'stepper':<7} {'tol':>7} {'batch':>5} {'geod/s/core':>12} {'steps/ray':>9} "
        f"{'max ang err':>11} {'mismatch':>8}"
    )
    for metric in (wv.Schwarzschild(mass=1.0), wv.Kerr(mass=1.0, spin=0.9)):
        ref, _ = run(metric, origin, dirs, stepper="dop853", tol=1e-13)
        results = {}
        runs = [("dopri5", 1e-8, True), ("dopri5", 1e-8, False), ("dopri5", 1e-10, True), ("dop853", 1e-8, True),
                ("dop853", 1e-10, True)]  # fmt: skip
        for stepper, tol, batch in runs:
            rays, dt = run(metric, origin, dirs, stepper=stepper, tol=tol, batch=batch, repeat=args.repeat)
            results[(stepper, tol, batch)] = (rays, dt, len(dirs))
        # seed RK4 on a subset, at the cheapest tolerance reaching dopri5 tol=1e-8's error
        sub = slice(None, None, args.rk4_subset)
        target, _ = angular_error(results[("dopri5", 1e-8, True)][0], ref)
        ref_sub = wv.trace(metric, origin, dirs[sub], stepper="dop853", tol=1e-13, threads=1)
        for tol in (1e-6, 1e-8, 1e-10, 1e-12, 1e-14, 1e-16):
            rays, dt = run(metric, origin, dirs[sub], stepper="rk4", tol=tol)
            err, _ = angular_error(rays, ref_sub)
            results[("rk4", tol, True)] = (rays, dt, len(dirs[sub]))
            if err <= target:
                break
        for (stepper, tol, batch), (rays, dt, n) in results.items():
            r = ref if n == len(dirs) else ref_sub
            err, mismatch = angular_error(rays, r)
            row = {
                "metric": repr(metric), "stepper": stepper, "tol": tol, "batch": batch, "rays": n, "seconds": dt,
                "geodesics_per_s_per_core": n / dt, "mean_steps": float(rays.n_steps.mean()),
                "max_angular_error": err, "status_mismatch": mismatch,
            }  # fmt: skip
            rows.append(row)
            print(
                f"{metric.name:<14} {stepper:<7} {tol:>7.0e} {'yes' if batch else 'no':>5} "
                f"{row['geodesics_per_s_per_core']:>12.0f} "
                f"{row['mean_steps']:>9.0f} {err:>11.2e} {mismatch:>8d}"
            )
        d5, d5_single = results[("dopri5", 1e-8, True)], results[("dopri5", 1e-8, False)]
        rk = [v for k, v in results.items() if k[0] == "rk4"][-1]
        speedup = (d5[2] / d5[1]) / (rk[2] / rk[1])
        print(f"  dopri5 (tol 1e-8) vs seed rk4 at equal or better error: {speedup:.1f}x faster")
        print(f"  SIMD batches vs one ray at a time (identical results): {d5_single[1] / d5[1]:.1f}x faster\n")
    args.out.mkdir(parents=True, exist_ok=True)
    path = args.out / "geodesics.csv"
    with path.open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    print(f"wrote {path}")
    return rows


if __name__ == "__main__":
    main()
