"""Path guiding (``guide_training``) against the same render without it: error at equal samples and efficiency.

Each room renders at a quarter of the references' size (160 x 120 from 640 x 480: a pixel is exactly a 4 x 4
block of the reference's, so the box-filtered reference averaged over blocks is the small image's expected
value) with ``spp`` samples, every core, for several seeds (the relative MSE of one seed swings by ~10 %:
half of it sits in the 1 % of pixels that caught a caustic), with guiding off and at each training setting.
Reported: mean relative MSE over the seeds (the reference's own noise subtracted), over every pixel and over
those whose camera rays do not see a light directly (a lamp or sun seen directly is noise of where in the
pixel a sample looks, which guiding does not touch), mean wall time (training included) and efficiency =
1 / (relative MSE x time), over guiding off.

References: the time-to-clean ones (``build/bench-references``, built by ``bench_time_to_clean.py --ref-time``)
for fig07 and fig10d; the others (Mitsuba's box, the wormhole rooms fig12 and fig13) get two halves of
``--ref-spp`` / 2 samples rendered here.

    python benchmarks/bench_path_guiding.py                      # ~4 minutes on 2 cores
    python benchmarks/bench_path_guiding.py --rooms mitsuba --seeds 6 --settings 0,8,32
    python benchmarks/bench_path_guiding.py --quick              # seconds (tests)

Writes ``path_guiding.csv`` to ``--out`` (default benchmarks/results).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

import warpviz as wv

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import RESULTS, Reference, machine_line, over_baseline, seeded_errors, write_csv  # noqa: E402
from bench_time_to_clean import light_pixels  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SCENES = {"fig10d": "fig10d", "fig07": "fig07", "fig12": "fig12", "fig13": "fig13",
          "mitsuba": str(ROOT / "scenes" / "mitsuba_cornell.toml")}
CACHED = ("fig07", "fig10d")  # rooms whose time-to-clean references are read from the cache


def reference(room: str, w: int, h: int, cache: Path, quick: bool, ref_spp: int) -> Reference | None:
    """The room's reference at w x h: the cached 4w x 4h halves averaged over 4 x 4 blocks (fig07, fig10d), or
    two halves of ref_spp / 2 rendered here (the others, and every room with --quick)."""
    if room in CACHED and not quick:
        paths = [cache / f"{room}-{4 * w}x{4 * h}-seed{1000 + k}.exr" for k in (0, 1)]
        if not all(p.is_file() for p in paths):
            print(f"skipped {room}: no reference {paths[0]} (bench_time_to_clean.py --ref-time S builds it)")
            return None
        halves = [wv.Image.open(p) for p in paths]
        down = [x.rgb.astype(np.float64).reshape(h, 4, w, 4, 3).mean(axis=(1, 3)) for x in halves]
        return Reference(down[0], down[1], 16 * min(int(x.metadata["spp"]) for x in halves))
    spp = 16 if quick else ref_spp // 2
    halves = [wv.render(SCENES[room], width=w, height=h, spp=spp, seed=1000 + k, aovs=[], progress=None).rgb
              for k in (0, 1)]  # fmt: skip
    return Reference(halves[0], halves[1], spp)


def main(argv=None) -> list[dict]:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--rooms", default="mitsuba,fig10d", help="comma-separated subset of " + ", ".join(SCENES))
    p.add_argument("--settings", default="0,8", help="guide_training values (0: off, the baseline)")
    p.add_argument("--seeds", type=int, default=4)
    p.add_argument("--spp", type=int, default=16)
    p.add_argument("--size", default="160x120", help="a quarter of the references' size")
    p.add_argument("--cache", type=Path, default=ROOT / "build" / "bench-references")
    p.add_argument("--ref-spp", type=int, default=1024, help="samples per pixel of a reference rendered here")
    p.add_argument("--quick", action="store_true", help="tiny frames, references rendered here (seconds)")
    p.add_argument("--out", type=Path, default=RESULTS)
    args = p.parse_args(argv)
    w, h = (int(v) for v in args.size.split("x"))
    settings = [int(s) for s in args.settings.split(",")]
    seeds, spp = args.seeds, args.spp
    if args.quick:
        w, h, seeds, spp, settings = 16, 12, 2, 4, [0, 2]
    print(machine_line(threads=0))
    rows = []
    for room in args.rooms.split(","):
        ref = reference(room, w, h, args.cache, args.quick, args.ref_spp)
        if ref is None:
            continue
        off = ~light_pixels(SCENES[room], w, h)  # the pixels whose camera rays do not see a light directly
        for g in settings:
            def render(seed, g=g):
                return wv.render(SCENES[room], width=w, height=h, spp=spp, seed=seed, guide_training=g, aovs=[],
                                 progress=None)  # fmt: skip

            rows.append({"room": room, "size": f"{w}x{h}", "spp": spp, "guide_training": g, "seeds": seeds,
                         **seeded_errors(render, ref, off, seeds)})  # fmt: skip
        mine = [r for r in rows if r["room"] == room]
        over_baseline(mine, next(r for r in mine if r["guide_training"] == settings[0]), "off")
    print(f"{'room':8} {'training':>8} {'rel MSE mean (min-max)':>30} {'s':>6} {'MSE/off':>8} {'eff/off':>8}"
          f" | off the lights: {'rel MSE':>10} {'MSE/off':>8} {'eff/off':>8}")  # fmt: skip
    for r in rows:
        print(f"{r['room']:8} {r['guide_training']:8d} {r['rel_mse_mean']:12.4e} ({r['rel_mse_min']:.3e}-"
              f"{r['rel_mse_max']:.3e}) {r['seconds_mean']:6.2f} {r['mse_over_off']:8.3f} "
              f"{r['efficiency_over_off']:8.3f} | {'':16}{r['rel_mse_off_lights']:10.4e} "
              f"{r['off_lights_mse_over_off']:8.3f} {r['off_lights_efficiency_over_off']:8.3f}")  # fmt: skip
    args.out.mkdir(parents=True, exist_ok=True)
    write_csv(args.out / "path_guiding.csv", rows)
    return rows


if __name__ == "__main__":
    main()
