"""warpviz against Mitsuba 3 on Mitsuba's own Cornell box (``scenes/mitsuba_cornell.toml``).

The scene is built from ``mitsuba.cornell_box()``'s numbers (18 quads; the light a white diffuse quad
that also emits). Both renderers run it as Mitsuba's comparison does: 128 x 128, max depth 8, Russian
roulette from depth 5, one thread, box pixel filter (Mitsuba ``scalar_rgb``, ``path`` integrator,
``independent`` sampler; warpviz's defaults otherwise: stratified pixel samples, next-event estimation
with MIS). Two measurements:

* **speed**: samples per CPU second, alternating the renderers (warpviz, Mitsuba, warpviz, ...) so a
  noisy machine loads both alike; the min and median of each are reported, and their ratio;
* **radiance**: the mean over the image of each renderer's converged frame (``--ref-spp``, all
  threads), and every 4 x 4 pixel block's mean, compared relative to Mitsuba's (goal: mean within 0.3 %,
  every block within 1.5 %). Each block's own noise (from two independent halves) is reported beside it.

    python benchmarks/bench_mitsuba_cornell.py            # ~3 minutes on 2 cores
    python benchmarks/bench_mitsuba_cornell.py --quick    # seconds

Needs ``pip install mitsuba`` (skipped with a message otherwise). Writes ``mitsuba_cornell.csv`` to
``--out`` (default benchmarks/results) and prints a table.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

import warpviz as wv

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import RESULTS, machine_line, timed, write_csv  # noqa: E402

SCENE = Path(__file__).resolve().parents[1] / "scenes" / "mitsuba_cornell.toml"
MAX_DEPTH, RR_DEPTH, SIZE = 8, 5, 128
#: Goals of issue 19: mean radiance within 0.3 % of Mitsuba's, every 4 x 4 block within 1.5 %.
MEAN_GOAL, BLOCK_GOAL, BLOCK = 0.003, 0.015, 4


def mitsuba_scene(mi, *, size: int, spp: int):
    """Mitsuba's own Cornell box at ``size`` x ``size`` with a box filter and the comparison's depths."""
    d = mi.cornell_box()
    film = d["sensor"]["film"]
    film["width"] = film["height"] = int(size)
    film["rfilter"] = {"type": "box"}
    d["sensor"]["sampler"] = {"type": "independent", "sample_count": int(spp)}
    d["integrator"] = {"type": "path", "max_depth": MAX_DEPTH, "rr_depth": RR_DEPTH}
    return mi.load_dict(d)


def render_warpviz(*, size: int, spp: int, seed: int, threads: int) -> np.ndarray:
    # max depth 8 and Russian roulette from depth 5 are the scene file's
    img = wv.render(SCENE, width=size, height=size, spp=spp, seed=seed, threads=threads, max_depth=MAX_DEPTH,
                    filter="box", progress=None)  # fmt: skip
    return img.rgb.astype(np.float64)


def speed(cfg: dict, mi, dr) -> list[dict]:
    """Samples per CPU second of each renderer, alternated ``cfg['rounds']`` times on one thread."""
    dr.set_thread_count(1)
    size, spp = cfg["size"], cfg["spp"]
    scene = mitsuba_scene(mi, size=size, spp=spp)
    mi.render(scene, spp=1)  # lazy initialisation
    render_warpviz(size=size, spp=1, seed=0, threads=1)
    times: dict[str, list[float]] = {"warpviz": [], "mitsuba": []}
    for _ in range(cfg["rounds"]):
        times["warpviz"].append(timed(lambda: render_warpviz(size=size, spp=spp, seed=1, threads=1))[1])
        times["mitsuba"].append(timed(lambda: np.array(mi.render(scene, spp=spp, seed=1)))[1])
    n = size * size * spp
    rows = []
    for name, ts in times.items():
        rows.append({"measure": "speed", "renderer": name,
                     "variant": f"mitsuba {mi.__version__} scalar_rgb" if name == "mitsuba" else f"warpviz {wv.__version__}",
                     "size": size, "spp": spp, "threads": 1, "cpu_s_min": min(ts), "cpu_s_median": float(np.median(ts)),
                     "samples_per_s_max": n / min(ts), "samples_per_s_median": n / float(np.median(ts))})  # fmt: skip
    rows[0]["warpviz_over_mitsuba_min"] = min(times["mitsuba"]) / min(times["warpviz"])
    rows[0]["warpviz_over_mitsuba_median"] = float(np.median(times["mitsuba"]) / np.median(times["warpviz"]))
    return rows


def _blocks(img: np.ndarray) -> np.ndarray:
    h, w = img.shape[0] // BLOCK, img.shape[1] // BLOCK
    return img[: h * BLOCK, : w * BLOCK].mean(axis=2).reshape(h, BLOCK, w, BLOCK).mean(axis=(1, 3))


def radiance(cfg: dict, mi, dr) -> list[dict]:
    """Converged frames of both renderers (two halves each), their mean and 4 x 4 block ratios."""
    dr.set_thread_count(0)
    size, half = cfg["size"], cfg["ref_spp"] // 2
    scene = mitsuba_scene(mi, size=size, spp=half)
    m = [np.array(mi.render(scene, spp=half, seed=s), dtype=np.float64)[..., :3] for s in (11, 23)]
    w = [render_warpviz(size=size, spp=half, seed=s, threads=0) for s in (11, 23)]
    mref, wref = 0.5 * (m[0] + m[1]), 0.5 * (w[0] + w[1])
    bm, bw = _blocks(mref), _blocks(wref)
    lit = bm > 1e-3 * bm.max()  # blocks that see the room (all do in this box)
    ratio = bw[lit] / bm[lit] - 1.0
    # each block's noise: half the difference of the halves, both renderers, relative
    noise = np.sqrt((0.5 * (_blocks(m[0]) - _blocks(m[1]))) ** 2 + (0.5 * (_blocks(w[0]) - _blocks(w[1]))) ** 2)
    rel_noise = noise[lit] / bm[lit]
    mean_ratio = float(wref.mean() / mref.mean() - 1.0)
    return [{"measure": "radiance", "renderer": "warpviz / mitsuba", "size": size, "spp": cfg["ref_spp"],
             "mean_warpviz": float(wref.mean()), "mean_mitsuba": float(mref.mean()),
             "mean_rel_diff": mean_ratio, "mean_goal_met": abs(mean_ratio) <= MEAN_GOAL,
             "block_rel_diff_max": float(np.abs(ratio).max()), "block_rel_diff_p99": float(np.quantile(np.abs(ratio), 0.99)),
             "block_rel_noise_median": float(np.median(rel_noise)),
             "blocks_over_goal": int((np.abs(ratio) > BLOCK_GOAL).sum()),
             "blocks_over_goal_beyond_noise": int((np.abs(ratio) > BLOCK_GOAL + 3 * rel_noise).sum()),
             "blocks": int(lit.sum())}]  # fmt: skip


def main(argv=None) -> list[dict]:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--quick", action="store_true", help="tiny frames (seconds; for tests)")
    p.add_argument("--out", type=Path, default=RESULTS)
    p.add_argument("--ref-spp", type=int, default=None, help="samples per pixel of the converged frames")
    p.add_argument("--rounds", type=int, default=None, help="alternating timings of each renderer (default 3)")
    args = p.parse_args(argv)
    try:
        import drjit as dr
        import mitsuba as mi
    except ImportError as exc:
        print(f"skipped: mitsuba is not importable ({exc}); pip install mitsuba")
        return []
    mi.set_variant("scalar_rgb")
    cfg = ({"size": 16, "spp": 4, "rounds": 1, "ref_spp": 16} if args.quick else
           {"size": SIZE, "spp": 32, "rounds": 3, "ref_spp": 1024})  # fmt: skip
    if args.ref_spp:
        cfg["ref_spp"] = args.ref_spp
    if args.rounds:
        cfg["rounds"] = args.rounds
    print(machine_line(threads=1))
    rows = speed(cfg, mi, dr) + radiance(cfg, mi, dr)
    s = rows[0]
    print(f"speed: warpviz / mitsuba samples per CPU second = {s['warpviz_over_mitsuba_min']:.3f} (min), "
          f"{s['warpviz_over_mitsuba_median']:.3f} (median); warpviz {s['samples_per_s_max']:.3g} samples/s, "
          f"mitsuba {rows[1]['samples_per_s_max']:.3g}")  # fmt: skip
    r = rows[-1]
    print(f"radiance at {r['spp']} spp: mean warpviz/mitsuba - 1 = {r['mean_rel_diff']:+.4%} (goal {MEAN_GOAL:.1%}); "
          f"4x4 blocks: max |diff| {r['block_rel_diff_max']:.3%}, {r['blocks_over_goal']} of {r['blocks']} over "
          f"{BLOCK_GOAL:.1%} ({r['blocks_over_goal_beyond_noise']} beyond 3x their noise, median noise "
          f"{r['block_rel_noise_median']:.3%})")  # fmt: skip
    args.out.mkdir(parents=True, exist_ok=True)
    write_csv(args.out / "mitsuba_cornell.csv", rows)
    return rows


if __name__ == "__main__":
    main()
