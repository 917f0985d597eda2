"""Time to a clean picture: how long a room takes, on every core, until its relative MSE against a
converged reference is at most ``--target`` (default 1e-3), denoised and not.

For each scene (default fig07 and fig10d) at ``--size`` (default 640x480):

1. **The reference** is two renders of independent seeds, each kept as an EXR in ``--cache`` (default
   ``build/bench-references``) and continued with ``render(resume=)`` by up to ``--ref-time`` seconds per
   run, towards ``--ref-spp`` samples per pixel: a reference of hours is built over several runs. Their
   mean is the reference; their difference gives its own noise, which is subtracted from every MSE
   (pixel by pixel: the measurement is unbiased however noisy the reference; each MSE is printed with its
   standard error, which says whether the reference is good enough yet). ``--reference-only`` only
   continues the references, for a background job; ``--workers N`` or ``--cluster ADDRESS`` renders
   them (and the timed renders) on a Dask cluster, the same images bit for bit.
2. **The renders**: two renders per entry of ``--spp`` (fresh, every core, seed 1), timed (wall clock):
   one as rendered, one with ``denoise=True`` (Intel Open Image Denoise, its time included; a denoised
   render's own defaults: ``edge_samples`` 32 instead of 8, ``detail_samples`` 8 instead of 1); each error
   over every pixel and over the pixels that do not see a light directly (``light_pixels``: the lamp's
   radiance dominates an MSE over all of them, and the denoiser's error is mostly there). The relative MSE is the mean squared error
   over pixels and channels divided by the squared mean of the reference, less the reference's noise.
3. **Time to the target**: interpolated log-log on each method's runs (``time_at_error``); where the
   largest run is still above the target the time is extrapolated with MSE proportional to 1 / time (the
   unbiased estimate's rate; marked ``extrapolated``). A denoised image's error stops falling at its bias,
   so it is never extrapolated.

    python benchmarks/bench_time_to_clean.py --ref-time 600        # add 10 minutes to each reference, measure
    python benchmarks/bench_time_to_clean.py --size 160x120        # the whole thing in ~15 minutes on 2 cores
    python benchmarks/bench_time_to_clean.py --quick               # seconds
    warpviz bench time-to-clean --quick

Writes ``time_to_clean.csv`` (one row per scene, method and spp) and ``time_to_clean_summary.csv`` (one
row per scene and method) to ``--out`` (default benchmarks/results) and prints a table. Needs ``pyoidn``
(``pip install 'warpviz[denoise]'``).
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np

import warpviz as wv

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import (RESULTS, UNBIASED, Reference, add_cluster_options, cluster_render_options,  # noqa: E402
                     machine_line, time_at_error, write_csv)

ROOT = Path(__file__).resolve().parents[1]


def light_pixels(scene: str, w: int, h: int) -> np.ndarray:
    """(H, W) bool: the pixels whose camera rays reach a light directly (the lamp, its lensed images, a sky),
    from a render of the camera segment alone. Their radiance is 10-100x the room's, so they weigh most in
    an MSE over all pixels; the room a viewer looks at is the rest."""
    img = wv.render(scene, width=w, height=h, spp=4, seed=7, max_depth=1, edge_samples=1, aovs=[], progress=None)
    return img.rgb.max(axis=2) > 0.0


def reference(scene: str, w: int, h: int, *, cache: Path, seconds: float, spp: int, via: dict | None = None) -> Reference:
    """The reference of ``scene`` at w x h: its two halves continued by up to ``seconds`` each towards
    ``spp`` samples per pixel (each run is a resumed render, so a reference of hours is built in pieces);
    ``via``: :func:`warpviz.render` keywords that send it to a Dask cluster (``_common.cluster_render_options``)."""
    cache.mkdir(parents=True, exist_ok=True)
    halves = []
    for k in (0, 1):
        path = cache / f"{scene}-{w}x{h}-seed{1000 + k}.exr"
        kw = {"width": w, "height": h, "seed": 1000 + k, "aovs": [], "progress": None, **UNBIASED}
        prior = path if path.is_file() else None
        if seconds > 0:
            img = wv.render(scene, spp=spp, time_limit=seconds, resume=prior, **kw, **(via or {}))
            img.save(path)
        elif prior is None:
            raise SystemExit(f"no reference {path} yet: run with --ref-time S to build it")
        halves.append(wv.Image.open(path))
    return Reference(halves[0].rgb, halves[1].rgb, min(int(x.metadata["spp"]) for x in halves))


def extrapolated_time(times: list[float], errors: list[float], target: float) -> float:
    """The time at which an unbiased estimate (MSE proportional to 1 / time) reaches ``target``, from its
    longest run."""
    i = int(np.argmax(times))
    return times[i] * errors[i] / target if errors[i] > 0 else math.nan


def measure(scene: str, w: int, h: int, spps: list[int], ref: Reference, threads: int, via: dict | None = None,
            edge_samples: int | None = None) -> list[dict]:
    rows = []
    off = ~light_pixels(scene, w, h)
    workers = len(via["client"].nthreads()) if via else 0
    for spp in spps:
        for method in ("noisy", "denoised"):  # each as a user renders it (a denoised render's own defaults)
            t0 = time.perf_counter()
            img = wv.render(scene, width=w, height=h, spp=spp, seed=1, progress=None, denoise=method == "denoised",
                            edge_samples=edge_samples, **{"threads": threads, **(via or {})})  # fmt: skip
            seconds = time.perf_counter() - t0
            image = img.denoised if method == "denoised" else img.rgb
            err, se = ref.rel_mse(image)
            err_off, se_off = ref.rel_mse(image, off)
            rows.append({"scene": scene, "width": w, "height": h, "method": method, "spp": spp,
                         "wall_s": seconds, "dask_workers": workers, "rel_mse": err, "rel_mse_se": se,
                         "rel_mse_off_lights": err_off, "rel_mse_off_lights_se": se_off,
                         "light_pixels": int((~off).sum()), "edge_samples": int(img.metadata["edge_samples"]),
                         "noise_estimate": img.metadata["noise"], "ref_rel_noise": ref.noise})  # fmt: skip
    return rows


def summarise(rows: list[dict], target: float, ref_spp: int) -> list[dict]:
    """Time to ``target`` per scene, method and pixels (all, or off the lights seen directly)."""
    out = []
    for scene in dict.fromkeys(r["scene"] for r in rows):
        for pixels, key in (("all", "rel_mse"), ("off lights", "rel_mse_off_lights")):
            for method in ("noisy", "denoised"):
                runs = [r for r in rows if r["scene"] == scene and r["method"] == method]
                times, errors = [r["wall_s"] for r in runs], [r[key] for r in runs]
                t = time_at_error(times, [max(e, 1e-300) for e in errors], target)
                how = "interpolated"
                if math.isnan(t) and method == "noisy" and min(errors) > target:
                    t, how = extrapolated_time(times, errors, target), "extrapolated"
                elif math.isnan(t):
                    how = "reached by the first run" if max(errors) <= target else "not reached"
                    t = min(times) if max(errors) <= target else math.nan
                out.append({"scene": scene, "width": runs[0]["width"], "height": runs[0]["height"],
                            "method": method, "pixels": pixels, "target_rel_mse": target, "seconds_to_target": t,
                            "how": how, "ref_spp": ref_spp, "ref_rel_noise": runs[0]["ref_rel_noise"]})  # fmt: skip
    return out


def main(argv: list[str] | None = None) -> list[dict]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="tiny problems for a smoke test (seconds)")
    parser.add_argument("--scenes", default="fig07,fig10d", help="comma-separated shipped rooms")
    parser.add_argument("--size", default=None, help="WIDTHxHEIGHT (default 640x480; --quick 24x18)")
    parser.add_argument("--spp", default=None, help="comma-separated samples per pixel of the timed renders "
                        "(default 1,2,4,8,16,32; --quick 1,16)")  # fmt: skip
    parser.add_argument("--target", type=float, default=1e-3, help="relative MSE to reach (default 1e-3)")
    parser.add_argument("--ref-time", type=float, default=None,
                        help="seconds added to each reference half this run (default 0: use what is cached; --quick 1)")
    parser.add_argument("--ref-spp", type=int, default=None, help="samples per pixel each reference half aims at "
                        "(default 4096; --quick 64)")  # fmt: skip
    parser.add_argument("--cache", type=Path, default=ROOT / "build" / "bench-references",
                        help="folder of the reference EXRs (kept between runs)")
    parser.add_argument("--reference-only", action="store_true",
                        help="only continue the references by --ref-time (no timed renders): run it in the background")
    parser.add_argument("--edge-samples", type=int, default=None,
                        help="edge_samples of every timed render (default: the render's own, 8, or 32 denoised)")
    parser.add_argument("--threads", type=int, default=0, help="render threads (default 0: every core, as a user renders)")
    parser.add_argument("--out", type=Path, default=RESULTS, help="output folder (default benchmarks/results)")
    add_cluster_options(parser, what="the references and the timed renders (the time a user of that cluster waits)")
    args = parser.parse_args(argv)
    from warpviz.render.denoise import require_denoiser

    require_denoiser()
    w, h = (int(v) for v in (args.size or ("24x18" if args.quick else "640x480")).lower().split("x"))
    spps = [int(s) for s in (args.spp or ("1,16" if args.quick else "1,2,4,8,16,32")).split(",")]
    ref_time = args.ref_time if args.ref_time is not None else (1.0 if args.quick else 0.0)
    ref_spp = args.ref_spp or (64 if args.quick else 4096)
    rows, refs = [], {}
    with cluster_render_options(args) as via:
        for scene in args.scenes.split(","):
            refs[scene] = ref = reference(scene, w, h, cache=args.cache, seconds=ref_time, spp=ref_spp, via=via)
            print(f"{scene} {w}x{h}: reference 2 x {ref.spp} spp, its relative noise {ref.noise:.2e} "
                  f"({ref.noise / args.target:.2g} of the target)", flush=True)  # fmt: skip
            if not args.reference_only:
                rows += measure(scene, w, h, spps, ref, args.threads, via, edge_samples=args.edge_samples)
    if args.reference_only:
        return []
    summary = []
    for scene, ref in refs.items():
        summary += summarise([r for r in rows if r["scene"] == scene], args.target, ref.spp)

    print(machine_line(threads=args.threads))
    print(f"{'scene':8s} {'method':9s} {'spp':>5s} {'wall s':>8s} {'rel MSE':>10s} {'± (1 s.e.)':>10s} "
          f"{'off lights':>10s} {'± (1 s.e.)':>10s}")  # fmt: skip
    for r in rows:
        print(f"{r['scene']:8s} {r['method']:9s} {r['spp']:5d} {r['wall_s']:8.2f} {r['rel_mse']:10.3e} "
              f"{r['rel_mse_se']:10.1e} {r['rel_mse_off_lights']:10.3e} {r['rel_mse_off_lights_se']:10.1e}")  # fmt: skip
    print(f"time to relative MSE {args.target:g}:")
    for s in summary:
        print(f"  {s['scene']:8s} {s['method']:9s} {s['pixels']:10s} {s['seconds_to_target']:8.1f} s ({s['how']})")
    args.out.mkdir(parents=True, exist_ok=True)
    write_csv(args.out / "time_to_clean.csv", rows)
    write_csv(args.out / "time_to_clean_summary.csv", summary)
    return summary


if __name__ == "__main__":
    main()
    raise SystemExit(0)
