"""What Intel Open Image Denoise is worth in the fig07 room: relative MSE against a converged reference,
noisy against denoised, at a few sample counts and at equal CPU time.

The room (fig07: a Schwarzschild black hole in the Cornell room) is rendered at ``--size`` with each of
``--spp`` samples per pixel, with the denoiser's features (``albedo``, ``albedo_normal``), and denoised
(``Image.denoise``, OIDN's ``RT`` filter, HDR, quality ``high``). The reference is the same room at
``--ref-spp`` in two independent halves (seeds); their difference estimates the reference's own noise,
which is subtracted from every MSE. The relative MSE is the mean squared error over pixels and channels
divided by the squared mean of the reference.

Equal time: the noisy estimate is unbiased, so its MSE falls as 1 / time; the noisy image that costs as
much CPU time as rendering *and* denoising at ``spp`` has MSE ``noisy * t_render / (t_render +
t_denoise)``, the column ``noisy_rel_mse_equal_time``; ``gain_equal_time`` is that over the denoised MSE.

    python benchmarks/bench_denoise.py            # 96x72, references at 1024 spp: ~10 minutes on one core
    python benchmarks/bench_denoise.py --quick    # seconds
    warpviz bench denoise --quick

Needs ``pyoidn`` (``pip install 'warpviz[denoise]'``). Writes ``denoise.csv`` (one row per spp) to
``--out`` (default benchmarks/results) and prints a table.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

import warpviz as wv

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import (RESULTS, UNBIASED, add_cluster_options, cluster_render_options, machine_line, timed,  # noqa: E402
                     write_csv)

SCENE = "fig07"


def rel_mse(image: np.ndarray, ref: np.ndarray, ref_noise: float) -> float:
    """Mean squared error over pixels and channels over the squared mean of ``ref``, less the reference's
    own (relative) noise, never below 0."""
    mse = float(np.mean((np.asarray(image, np.float64) - ref) ** 2)) / float(np.mean(ref)) ** 2
    return max(mse - ref_noise, 0.0)


def main(argv: list[str] | None = None) -> list[dict]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="tiny problems for a smoke test (seconds)")
    parser.add_argument("--size", default=None, help="WIDTHxHEIGHT (default 96x72; --quick 24x18)")
    parser.add_argument("--spp", default=None, help="comma-separated samples per pixel (default 4,16,64; --quick 1,16)")
    parser.add_argument("--ref-spp", type=int, default=None, help="reference samples, two halves (default 1024; --quick 32)")
    parser.add_argument("--threads", type=int, default=1, help="render threads (default 1: CPU time is per core)")
    parser.add_argument("--out", type=Path, default=RESULTS, help="output folder (default benchmarks/results)")
    add_cluster_options(parser)
    args = parser.parse_args(argv)
    from warpviz.render.denoise import require_denoiser

    require_denoiser()
    w, h = (int(v) for v in (args.size or ("24x18" if args.quick else "96x72")).lower().split("x"))
    # (quick: 1 and 16 spp, far enough apart that more samples always show less noise against a 32-spp reference;
    # 1 and 4 spp tie where one of them holds a firefly)
    spps = [int(s) for s in (args.spp or ("1,16" if args.quick else "4,16,64")).split(",")]
    ref_spp = args.ref_spp or (32 if args.quick else 1024)
    kw = {"width": w, "height": h, "threads": args.threads, "progress": None}

    with cluster_render_options(args) as via:
        halves = [wv.render(SCENE, spp=ref_spp // 2, seed=1000 + k, aovs=[], **{**kw, **via, **UNBIASED}).rgb.astype(np.float64)
                  for k in (0, 1)]  # fmt: skip
    ref = 0.5 * (halves[0] + halves[1])
    ref_noise = float(np.mean((halves[0] - halves[1]) ** 2)) / 4.0 / float(np.mean(ref)) ** 2

    rows = []
    for spp in spps:
        img, t_render, _ = timed(lambda: wv.render(SCENE, spp=spp, seed=1, aovs=["albedo", "albedo_normal"], **kw))
        den, t_denoise, _ = timed(img.denoise)
        noisy, denoised = rel_mse(img.rgb, ref, ref_noise), rel_mse(den.denoised, ref, ref_noise)
        equal = noisy * t_render / (t_render + t_denoise)
        rows.append({"scene": SCENE, "width": w, "height": h, "spp": spp, "ref_spp": ref_spp,
                     "cpu_s_render": t_render, "cpu_s_denoise": t_denoise,
                     "noisy_rel_mse": noisy, "denoised_rel_mse": denoised,
                     "noisy_rel_mse_equal_time": equal,
                     "gain_equal_time": equal / denoised if denoised > 0 else float("inf"),
                     "ref_rel_noise": ref_noise})  # fmt: skip

    print(machine_line(threads=args.threads))
    print(f"{SCENE} {w}x{h}, reference {ref_spp} spp (relative noise {ref_noise:.2e})")
    print(f"{'spp':>5s} {'render s':>9s} {'denoise s':>9s} {'noisy':>10s} {'denoised':>10s} {'noisy@=t':>10s} {'gain':>6s}")
    for r in rows:
        print(f"{r['spp']:5d} {r['cpu_s_render']:9.2f} {r['cpu_s_denoise']:9.2f} {r['noisy_rel_mse']:10.3e} "
              f"{r['denoised_rel_mse']:10.3e} {r['noisy_rel_mse_equal_time']:10.3e} {r['gain_equal_time']:6.1f}")
    args.out.mkdir(parents=True, exist_ok=True)
    write_csv(args.out / "denoise.csv", rows)
    return rows


if __name__ == "__main__":
    main()
    raise SystemExit(0)
