"""Caustics by photons (``photons``) against the path tracer alone: error at equal samples and efficiency.

Each caustic room renders at a thumbnail's size with ``spp`` samples, every core, for several seeds, with the
path tracer alone (``photons = 0``) and with each photon count. Reported: the mean relative MSE over the
seeds against the path tracer's converged image (its own noise subtracted, ``_common.Reference``), the mean
wall time and efficiency = 1 / (relative MSE x time), over the path tracer's; over every pixel and over those
whose camera rays do not see a light directly (the lamp's edge in its pixel is noise neither method touches,
and at a thumbnail's size it is most of the photons' error: those pixels are the ones whose samples' light
seen before the first diffuse surface, the ``emission`` AOV of a 256-sample render, is not zero, so the lamp
seen through the glass ball is one). Photon mapping is biased (a
caustic is blurred by the gather radius, which shrinks pass by pass): its error here is measured against the
same unbiased reference, so the bias is in it.

The reference (two halves of ``--ref-spp`` / 2 path-traced samples, independent seeds) is built in pieces of
``--ref-chunk`` samples, each written to ``--cache`` as an EXR and resumed from there, so an interrupted
build goes on where it stopped (``--ref-only`` builds it and stops).

    python benchmarks/bench_caustics.py                          # glass ball, flat and with the hole (64 x 48)
    python benchmarks/bench_caustics.py --rooms glass_ball --photons 0,5000,20000 --seeds 6
    python benchmarks/bench_caustics.py --ref-only --rooms glass_ball_hole   # the reference only (resumable)
    python benchmarks/bench_caustics.py --quick                  # seconds (tests)

Writes ``caustics.csv`` to ``--out`` (default benchmarks/results).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

import warpviz as wv

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import RESULTS, Reference, machine_line, over_baseline, seeded_errors, write_csv  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SCENES = {"glass_ball": ROOT / "scenes" / "caustics_glass_ball.toml",
          "glass_ball_hole": ROOT / "scenes" / "caustics_glass_ball_hole.toml"}  # fmt: skip


def reference_half(room: str, w: int, h: int, spp: int, seed: int, cache: Path, chunk: int) -> np.ndarray:
    """One half of the room's path-traced reference: rendered (or resumed from the cache) up to spp samples in
    pieces of ``chunk``, each piece written to the cache before the next."""
    cache.mkdir(parents=True, exist_ok=True)
    path = cache / f"caustics-{room}-{w}x{h}-pt-seed{seed}.exr"
    img = wv.Image.open(path) if path.is_file() else None
    done = int(img.metadata["spp"]) if img is not None else 0
    while done < spp:
        step = min(spp, done + chunk)
        t0 = time.perf_counter()
        img = wv.render(str(SCENES[room]), width=w, height=h, spp=step, seed=seed, photons=0,
                        photons_per_pixel=0.0, edge_samples=1,
                        detail_samples=1, progress=None, **({"resume": img} if img is not None else {}))  # fmt: skip
        img.save(path)
        done = step
        print(f"  reference {room} seed {seed}: {done}/{spp} spp ({time.perf_counter() - t0:.0f} s)", flush=True)
    if done > spp:
        print(f"  reference {room} seed {seed}: the cache holds {done} spp (more than {spp}): used as it is")
    return img.rgb


def seen_lights(room: str, w: int, h: int, spp: int) -> np.ndarray:
    """(H, W) bool: the pixels whose camera rays reach a light before any diffuse surface (directly or through
    mirrors and glass), by the emission AOV of a path-traced render."""
    img = wv.render(str(SCENES[room]), width=w, height=h, spp=spp, seed=7, photons=0, photons_per_pixel=0.0,
                    aovs=["emission"], progress=None)  # fmt: skip
    return img.aovs["emission"].max(axis=2) > 0.0


def main(argv=None) -> list[dict]:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--rooms", default="glass_ball,glass_ball_hole", help="comma-separated subset of " + ", ".join(SCENES))
    p.add_argument("--photons", default="0,5000,20000",
                   help="photon counts per pass, each in place of the scene's own (0: the path tracer, the baseline)")
    p.add_argument("--seeds", type=int, default=4)
    p.add_argument("--spp", type=int, default=16)
    p.add_argument("--size", default="64x48")
    p.add_argument("--cache", type=Path, default=ROOT / "build" / "bench-references")
    p.add_argument("--ref-spp", type=int, default=8192, help="path-traced samples per pixel of the reference")
    p.add_argument("--ref-chunk", type=int, default=512, help="samples per resumable piece of the reference")
    p.add_argument("--ref-only", action="store_true", help="build (or finish) the references and stop")
    p.add_argument("--quick", action="store_true", help="tiny frames, tiny references (seconds)")
    p.add_argument("--out", type=Path, default=RESULTS)
    args = p.parse_args(argv)
    w, h = (int(v) for v in args.size.split("x"))
    counts = [int(s) for s in args.photons.split(",")]
    seeds, spp, ref_spp, cache = args.seeds, args.spp, args.ref_spp, args.cache
    if args.quick:
        w, h, seeds, spp, counts, ref_spp = 16, 12, 2, 4, [0, 2000], 64
        cache = args.out / "caustics-quick-references"
    print(machine_line(threads=0))
    rows = []
    for room in args.rooms.split(","):
        halves = [reference_half(room, w, h, ref_spp // 2, 1000 + k, cache, args.ref_chunk) for k in (0, 1)]
        if args.ref_only:
            continue
        ref = Reference(halves[0], halves[1], ref_spp // 2)
        off = ~seen_lights(room, w, h, 16 if args.quick else 256)
        for n in counts:
            def render(seed, n=n):
                return wv.render(str(SCENES[room]), width=w, height=h, spp=spp, seed=seed, photons=n,
                                 photons_per_pixel=0.0, aovs=[], progress=None)  # fmt: skip

            rows.append({"room": room, "size": f"{w}x{h}", "spp": spp, "photons": n, "seeds": seeds,
                         "reference_noise": ref.noise, **seeded_errors(render, ref, off, seeds)})  # fmt: skip
        mine = [r for r in rows if r["room"] == room]
        over_baseline(mine, next(r for r in mine if r["photons"] == counts[0]), "base")
    for r in rows:
        print(f"{r['room']:16s} photons {r['photons']:>7d}: rel MSE {r['rel_mse_mean']:.3e} "
              f"({r['mse_over_base']:.3f}x), {r['seconds_mean']:.2f} s, efficiency {r['efficiency_over_base']:.2f}x; "
              f"off the lights {r['rel_mse_off_lights']:.3e} ({r['off_lights_mse_over_base']:.3f}x), efficiency "
              f"{r['off_lights_efficiency_over_base']:.2f}x")
    if rows:
        write_csv(args.out / "caustics.csv", rows)
    return rows


if __name__ == "__main__":
    main()
