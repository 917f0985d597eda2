"""What the edge samples are worth: efficiency against ``edge_samples`` in scenes where the camera sees
emitters directly.

Each scene is rendered at ``--size`` and ``--spp`` with each ``edge_samples`` of ``--settings`` (default
1 (off), 2, 4, 8, 16 and 32): the pixels whose footprint straddles the edge of a surface that emits (found by probe rays on
the half-pixel lattice before any sample) get that many times spp samples. Efficiency = 1 / (relative MSE
x CPU time) against a reference at ``--ref-spp`` in two independent halves (their difference estimates the
reference's own noise, which is subtracted); relative MSE = mean squared error over pixels and channels
over the squared mean of the reference. ``over_off`` is each row's efficiency over ``edge_samples=1``.

    python benchmarks/bench_edge_samples.py           # fig02, fig04, fig07 at 48x36: ~8 minutes on one core
    python benchmarks/bench_edge_samples.py --size 160x120 --settings 1,8,32   # a larger frame: fewer edge pixels
    python benchmarks/bench_edge_samples.py --quick   # seconds
    warpviz bench edge-samples --scenes fig07

Writes ``edge_samples.csv`` (one row per scene and setting) to ``--out`` (default benchmarks/results) and
prints a table.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

import warpviz as wv

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import (RESULTS, UNBIASED, Reference, add_cluster_options, cluster_render_options,  # noqa: E402
                     machine_line, timed, write_csv)

SETTINGS = (1, 2, 4, 8, 16, 32)


def _render(scene: str, size, *, spp: int, seed: int, edge_samples: int, via: dict | None = None, **options):
    img, cpu, _ = timed(lambda: wv.render(scene, width=size[0], height=size[1], spp=spp, seed=seed,
                                          edge_samples=edge_samples, **{"threads": 1, **(via or {}), **options}))
    return img, cpu


def reference(scene: str, *, size, ref_spp: int, via: dict | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The reference of ``scene`` from two halves and, per pixel, the squared error its own noise adds
    (``via``: render keywords that send the halves to a Dask cluster)."""
    a, _ = _render(scene, size, spp=ref_spp // 2, seed=100_001, edge_samples=8, via=via, **UNBIASED)
    b, _ = _render(scene, size, spp=ref_spp // 2, seed=200_003, edge_samples=8, via=via, **UNBIASED)
    ref = Reference(a.rgb, b.rgb, ref_spp // 2)
    return ref.image, ref.noise_map


def measure(scene: str, *, size, spp: int, ref: np.ndarray, noise: np.ndarray, ref_spp: int, seeds: int,
            settings=SETTINGS) -> list[dict]:
    """One row per setting of ``edge_samples`` in ``settings`` (the first is the baseline of ``over_off``)
    for ``scene``, against its reference."""
    scale = float(ref.mean()) ** 2
    rows = []
    for es in settings:
        mse, cpu = [], []
        for seed in range(seeds):
            img, t = _render(scene, size, spp=spp, seed=seed, edge_samples=es)
            mse.append(max(float(((img.rgb.astype(np.float64) - ref) ** 2 - noise).mean()), 1e-30) / scale)
            cpu.append(t)
        rel, t = float(np.mean(mse)), float(np.mean(cpu))
        rows.append({"scene": scene, "edge_samples": es, "edge_pixels": int(img.stats["edge_pixels"]),
                     "width": size[0], "height": size[1], "spp": spp, "reference_spp": ref_spp, "cpu_s": t,
                     "rel_mse": rel, "efficiency": 1.0 / (rel * t)})  # fmt: skip
    for r in rows:
        r["over_off"] = r["efficiency"] / rows[0]["efficiency"]
    return rows


def main(argv=None) -> list[dict]:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--quick", action="store_true", help="tiny frames and references (seconds; for tests)")
    p.add_argument("--scenes", default="fig02,fig04,fig07", help="comma-separated shipped scenes")
    p.add_argument("--size", default=None, help="WIDTHxHEIGHT (default 48x36; --quick 12x9)")
    p.add_argument("--settings", default=None, help="comma-separated edge_samples values, the first the baseline "
                   "(default 1,2,4,8,16,32; --quick 1,2,4,8)")  # fmt: skip
    p.add_argument("--out", type=Path, default=RESULTS)
    add_cluster_options(p)
    args = p.parse_args(argv)
    cfg = ({"size": (12, 9), "spp": 2, "ref_spp": 16, "seeds": 1} if args.quick else
           {"size": (48, 36), "spp": 16, "ref_spp": 1024, "seeds": 3})  # fmt: skip
    if args.size:
        cfg["size"] = tuple(int(v) for v in args.size.lower().split("x"))
    settings = tuple(int(v) for v in (args.settings or ("1,2,4,8" if args.quick else "1,2,4,8,16,32")).split(","))
    print(machine_line(threads=1))
    scenes = [s.strip() for s in args.scenes.split(",") if s.strip()]
    with cluster_render_options(args) as via:  # the references on a Dask cluster where asked
        refs = {scene: reference(scene, size=cfg["size"], ref_spp=cfg["ref_spp"], via=via) for scene in scenes}
    rows = []
    for scene in scenes:
        rows += measure(scene, **cfg, ref=refs[scene][0], noise=refs[scene][1], settings=settings)
    path = write_csv(args.out / "edge_samples.csv", rows)
    print(f"{'scene':8s} {'edge':>4s} {'pixels':>6s} {'cpu s':>7s} {'rel MSE':>9s} {'eff':>9s} {'over off':>8s}")
    for r in rows:
        print(f"{r['scene']:8s} {r['edge_samples']:4d} {r['edge_pixels']:6d} {r['cpu_s']:7.3f} {r['rel_mse']:9.5f} "
              f"{r['efficiency']:9.1f} {r['over_off']:8.2f}")
    print(f"wrote {path}")
    return rows


if __name__ == "__main__":
    main()
