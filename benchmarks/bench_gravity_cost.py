"""Gravity's cost per camera sample: the shipped lit rooms timed flat, with integrated segments and with
closed-form segments, alternately (A, B, C, A, B, C, ...) on one thread, so that the machine's drift falls
on every variant alike.

For each room (fig07: Schwarzschild, fig10d: Kerr a = 0.9, which has no closed form and integrates in
both curved variants) it reports the CPU microseconds per sample (min and median over the repetitions),
the curved/flat ratio of each, the integrator's steps per sample, and how far the closed-form image is from
the integrated one at the same seed and spp (the same paths: their difference is the integrator's error,
not noise; the mean and the median pixel). The rooms' caustics by photons are left out
(``photons_per_pixel=0``): this is the camera paths' cost.

With ``--efficiency`` it measures instead gravity's cost in efficiency (issue 37's second target): each room
rendered flat and curved with its defaults (photons included) at 48 x 36, 16 spp, one thread, over ``--seeds``
seeds (the two variants alternating), each against its reference (``--ref-spp`` samples in two halves whose
noise is subtracted, as the light-connection benchmark does); efficiency = 1 / (relative MSE x CPU seconds), and
the cost is the flat room's efficiency over the curved one's. The references are unbiased by default: path traced
without photons (``--reference unbiased``), so a photon map's blur counts as error, as it does in the picture;
``--reference own`` renders them with the rooms' defaults, photons included, which hides that bias in both (and
made the aim's sharper caustics look like gravity's cost falling). Writes ``gravity_efficiency.csv``.

Usage: ``python benchmarks/bench_gravity_cost.py [--quick] [--rooms fig07,fig10d] [--reps 3] [--out DIR]``
(``--efficiency [--seeds 8] [--ref-spp 1024] [--reference unbiased|own]``); writes ``gravity_cost.csv`` into ``--out`` (default
``benchmarks/results``) and prints the table.
"""

from __future__ import annotations

import argparse
import statistics
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

import warpviz as wv  # noqa: E402
from _common import RESULTS, UNBIASED, Reference, machine_line, timed, write_csv  # noqa: E402

ROOMS = {"fig07": "fig07_schwarzschild_cornell", "fig10d": "fig10d_kerr_cornell_a09"}
VARIANTS = ("flat", "integrate", "closed_form")


def run(room: str, *, size: tuple[int, int], spp: int, reps: int) -> list[dict]:
    """Time the variants of one room alternately; one row per variant."""
    scene = wv.load_scene(Path(__file__).resolve().parents[1] / "scenes" / f"{ROOMS[room]}.toml")
    samples = size[0] * size[1] * spp
    times = {v: [] for v in VARIANTS}
    images, steps = {}, {}
    for _ in range(reps):
        for v in VARIANTS:
            img = wv.render(scene, width=size[0], height=size[1], spp=spp, threads=1, edge_samples=1, progress=None,
                            flat=v == "flat", segment_method="closed_form" if v == "flat" else v,
                            photons_per_pixel=0.0)  # fmt: skip
            times[v].append(img.stats["seconds"] / samples * 1e6)
            images[v] = img.rgb.astype(np.float64)
            steps[v] = img.stats["steps"] / samples
    a, b = images["integrate"], images["closed_form"]
    rel = np.abs(a - b).sum(-1) / (np.abs(a).sum(-1) + 1e-12)
    flat_min, flat_med = min(times["flat"]), statistics.median(times["flat"])
    rows = []
    for v in VARIANTS:
        t_min, t_med = min(times[v]), statistics.median(times[v])
        rows.append({
            "room": room, "variant": v, "width": size[0], "height": size[1], "spp": spp, "reps": reps,
            "us_per_sample_min": t_min, "us_per_sample_median": t_med,
            "over_flat_min": t_min / flat_min, "over_flat_median": t_med / flat_med,
            "steps_per_sample": steps[v],
            "mean_rel_diff_vs_integrate":
                float(abs(images[v].mean() - a.mean()) / a.mean()) if v != "flat" else float("nan"),
            "median_pixel_rel_diff_vs_integrate": float(np.median(rel)) if v == "closed_form" else float("nan"),
        })  # fmt: skip
    return rows


REFERENCES = {"unbiased": UNBIASED, "own": {}}


def efficiency(room: str, *, size: tuple[int, int], spp: int, seeds: int, ref_spp: int,
               reference: str = "unbiased") -> list[dict]:
    """Gravity's cost in efficiency: the room flat and curved (its defaults), each against its reference (of
    :data:`REFERENCES`: path traced without photons, or with the room's defaults)."""
    scene = wv.load_scene(Path(__file__).resolve().parents[1] / "scenes" / f"{ROOMS[room]}.toml")
    kw = {"width": size[0], "height": size[1]}
    refs = {}
    for flat in (True, False):
        half = [wv.render(scene, spp=ref_spp // 2, seed=10_000 + k, flat=flat, progress=None, **kw,
                          **REFERENCES[reference]).rgb
                for k in range(2)]  # (every core: only the test renders are timed)
        refs[flat] = Reference(half[0], half[1], ref_spp // 2)
    err = {True: [], False: []}
    cpu = {True: [], False: []}
    for seed in range(seeds):
        for flat in ((True, False) if seed % 2 == 0 else (False, True)):
            img, t, _ = timed(lambda: wv.render(scene, spp=spp, seed=seed, flat=flat, threads=1, progress=None, **kw))
            err[flat].append(refs[flat].rel_mse(img.rgb)[0])
            cpu[flat].append(t)
    rows = []
    for flat in (True, False):
        rel, t = float(np.mean(err[flat])), float(np.mean(cpu[flat]))
        rows.append({"room": room, "variant": "flat" if flat else "curved", "width": size[0], "height": size[1],
                     "spp": spp, "seeds": seeds, "reference": reference, "reference_spp": ref_spp, "rel_mse": rel, "cpu_s": t,
                     "efficiency": 1.0 / (rel * t)})
    for r in rows:
        r["flat_over_this"] = rows[0]["efficiency"] / r["efficiency"]
    return rows


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="tiny frames for a smoke test (seconds)")
    parser.add_argument("--rooms", default="fig07,fig10d", help=f"comma-separated, of {', '.join(ROOMS)}")
    parser.add_argument("--reps", type=int, default=None, help="alternating repetitions (default 3; quick 1)")
    parser.add_argument("--out", type=Path, default=RESULTS, help="output folder (default benchmarks/results)")
    parser.add_argument("--efficiency", action="store_true",
                        help="gravity's cost in efficiency (error x time) instead of time per sample")
    parser.add_argument("--seeds", type=int, default=None, help="--efficiency: seeds per variant (default 8; quick 2)")
    parser.add_argument("--ref-spp", type=int, default=None,
                        help="--efficiency: the references' samples per pixel (default 1024; quick 32)")
    parser.add_argument("--reference", choices=sorted(REFERENCES), default="unbiased",
                        help="--efficiency: references path traced without photons (default) or the rooms' own")
    args = parser.parse_args(argv)
    rooms = [r.strip() for r in args.rooms.split(",") if r.strip()]
    unknown = [r for r in rooms if r not in ROOMS]
    if unknown:
        parser.error(f"unknown room(s) {', '.join(unknown)}; choose from {', '.join(ROOMS)}")
    if args.efficiency:
        size, spp = ((12, 9), 4) if args.quick else ((48, 36), 16)
        seeds = args.seeds or (2 if args.quick else 8)
        ref_spp = args.ref_spp or (32 if args.quick else 1024)
        rows = [row for room in rooms for row in efficiency(room, size=size, spp=spp, seeds=seeds, ref_spp=ref_spp,
                                                        reference=args.reference)]
        header = f"{'room':8} {'variant':8} {'rel MSE':>9} {'cpu s':>7} {'efficiency':>11} {'flat / this':>12}"
        line = "{room:8} {variant:8} {rel_mse:9.4f} {cpu_s:7.3f} {efficiency:11.1f} {flat_over_this:12.2f}"
        return _report(rows, args.out / "gravity_efficiency.csv", header, line)
    size, spp = ((12, 9), 2) if args.quick else ((96, 72), 16)
    reps = args.reps or (1 if args.quick else 3)
    rows = [row for room in rooms for row in run(room, size=size, spp=spp, reps=reps)]
    header = f"{'room':8} {'variant':12} {'us/sample min':>14} {'median':>8} {'/flat min':>10} {'median':>8} {'steps':>7}"
    line = ("{room:8} {variant:12} {us_per_sample_min:14.2f} {us_per_sample_median:8.2f} {over_flat_min:10.2f} "
            "{over_flat_median:8.2f} {steps_per_sample:7.1f}")
    return _report(rows, args.out / "gravity_cost.csv", header, line)


def _report(rows: list[dict], path: Path, header: str, line: str) -> int:
    """Write the rows to ``path`` (CSV) and print them under the machine's line, one ``line.format(**row)`` each."""
    path = write_csv(path, rows)
    print(machine_line(threads=1))
    print(header)
    for r in rows:
        print(line.format(**r))
    print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
