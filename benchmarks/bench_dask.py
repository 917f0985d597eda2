"""Rendering on a Dask cluster against the local threaded render: wall time, identical image, per-task cost.

A fig07 frame (``--size``, ``--spp``) is rendered locally with every core as threads (A) and on a local
Dask cluster of one single-threaded worker process per core (B), alternating A, B, A, B, ... (``--repeats``
each; the cluster is started once, before the first B, and its start is timed apart). Every B image must
equal A bit for bit. The ratio is B / A of the median wall times (min times too).

The same frame on the cluster with several tile sizes (``--tiles``) shows what the tile size does to a
real render. The fixed cost of one task (sending it, the core's set-up of the scene for a call, the
summary back) is measured apart, where it is not lost in the render's noise: a 96x72 frame of the same
scene at 2 spp, cut into 8-pixel tiles (216 tasks) and into one tile (2 tasks), best of three each; the
difference in wall time times the workers over the difference in tasks is the cost of one task in
worker time. A user chooses a tile size from it. The room's caustics by photons are left out
(``photons_per_pixel=0``): every tile traces the whole image's photon pass, which would hide the tiles'
own cost (a render with photons and no tile size gets a tile per task slot instead: docs/cluster.md).

    python benchmarks/bench_dask.py                 # 320x240, 16 spp: ~3 minutes on 2 cores
    python benchmarks/bench_dask.py --quick         # seconds
    warpviz bench dask --size 640x480

Writes ``dask.csv`` (one row per run) to ``--out`` (default benchmarks/results) and prints a summary.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

import warpviz as wv
from warpviz.render.distributed import tile_windows

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import RESULTS, machine_line, write_csv  # noqa: E402


def _size(text: str) -> tuple[int, int]:
    w, h = text.lower().split("x")
    return int(w), int(h)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scene", default="fig07")
    ap.add_argument("--size", type=_size, default=(320, 240))
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--workers", type=int, default=os.cpu_count() or 2)
    ap.add_argument("--tile", type=int, default=128, help="tile side of the A/B comparison")
    ap.add_argument("--tiles", type=int, nargs="+", default=[16, 32, 64, 128], help="tile sides of the overhead fit")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--quick", action="store_true", help="a 64x48 frame at 4 spp, two repeats")
    ap.add_argument("--out", type=Path, default=RESULTS)
    args = ap.parse_args(argv)
    if args.quick:
        args.size, args.spp, args.repeats, args.tiles = (64, 48), 4, 2, [16, 64]
    from distributed import Client, LocalCluster

    w, h = args.size
    kw = {"width": w, "height": h, "spp": args.spp, "progress": None, "aovs": [], "photons_per_pixel": 0.0}
    print(machine_line(threads=0))
    rows = []
    t0 = time.perf_counter()
    cluster = LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True, dashboard_address=":0")
    client = Client(cluster)
    startup = time.perf_counter() - t0
    try:
        wv.render(args.scene, **kw, client=client, tile=args.tile)  # warm the workers (imports, scene)
        times = {"local": [], "dask": []}
        ref = None
        for _ in range(args.repeats):
            t = time.perf_counter()
            a = wv.render(args.scene, **kw, threads=0)
            times["local"].append(time.perf_counter() - t)
            t = time.perf_counter()
            b = wv.render(args.scene, **kw, client=client, tile=args.tile)
            times["dask"].append(time.perf_counter() - t)
            ref = a.rgb if ref is None else ref
            if not (np.array_equal(a.rgb, b.rgb) and np.array_equal(ref, a.rgb)):
                raise SystemExit("the cluster's image differs from the local one")
        passes = a.metadata["passes"]
        for kind, ts in times.items():
            for t in ts:
                rows.append({"run": kind, "scene": args.scene, "width": w, "height": h, "spp": args.spp,
                             "workers": args.workers, "tile": args.tile if kind == "dask" else "",
                             "tasks": passes * len(tile_windows((0, 0, w, h), args.tile)) if kind == "dask" else "",
                             "wall_s": t})  # fmt: skip
        fit = []
        for tile in args.tiles:
            tasks = passes * len(tile_windows((0, 0, w, h), tile))
            best = min(_wall(lambda: wv.render(args.scene, **kw, client=client, tile=tile)) for _ in range(2))
            fit.append((tasks, best))
            rows.append({"run": "dask-tiles", "scene": args.scene, "width": w, "height": h, "spp": args.spp,
                         "workers": args.workers, "tile": tile, "tasks": tasks, "wall_s": best})  # fmt: skip
        cost = {}
        small = {"width": 96, "height": 72, "spp": 2, "progress": None, "aovs": []}
        for tile in (8, 96):
            tasks = 2 * len(tile_windows((0, 0, 96, 72), tile))
            cost[tasks] = min(_wall(lambda: wv.render(args.scene, **small, client=client, tile=tile)) for _ in range(3))
            rows.append({"run": "task-cost", "scene": args.scene, "width": 96, "height": 72, "spp": 2,
                         "workers": args.workers, "tile": tile, "tasks": tasks, "wall_s": cost[tasks]})  # fmt: skip
    finally:
        client.close()
        cluster.close()
    write_csv(args.out / "dask.csv", rows)
    med = {k: float(np.median(v)) for k, v in times.items()}
    low = {k: float(np.min(v)) for k, v in times.items()}
    (many, t_many), (few, t_few) = sorted(cost.items(), reverse=True)
    per_task = (t_many - t_few) * args.workers / (many - few)
    print(f"{args.scene} {w}x{h}, {args.spp} spp, {passes} passes; cluster start {startup:.1f} s (not counted)")
    print(f"local threads: median {med['local']:.2f} s (min {low['local']:.2f}); {args.workers} workers x 1 thread, "
          f"tile {args.tile}: median {med['dask']:.2f} s (min {low['dask']:.2f})")  # fmt: skip
    print(f"ratio dask / local: median {med['dask'] / med['local']:.3f}, min {low['dask'] / low['local']:.3f}; "
          "images identical")
    print("tiles: " + ", ".join(f"{t} px: {n} tasks {s:.2f} s" for t, (n, s) in zip(args.tiles, fit)))
    print(f"cost of one task: {1e3 * per_task:.1f} ms of a worker ({many} tasks {t_many:.2f} s, {few} tasks "
          f"{t_few:.2f} s, 96x72 at 2 spp)")  # fmt: skip
    return 0


def _wall(fn) -> float:
    t = time.perf_counter()
    fn()
    return time.perf_counter() - t


if __name__ == "__main__":
    raise SystemExit(main())
