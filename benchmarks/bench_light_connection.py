"""Efficiency of the light connections in the lit rooms around black holes and wormholes.

Efficiency = 1 / (relative MSE x CPU time) against a converged reference, for the shipped rooms fig07
(Schwarzschild), fig10d (Kerr a = 0.9), fig12 and fig13 (Ellis, the space side and the room side) and
line_element_kerr_newman (Kerr-Newman from its line element), each rendered with

* ``lens``          the defaults: the lens-aware connection (the exact lens map where the metric is static
                    and spherical, in Kerr and a line element with a mass the Schwarzschild map of the same
                    mass as a proposal),
                    Russian roulette on the light samples of a path's dim vertices (``light_roulette``),
                    stratified pixel samples, and 8x the samples in the pixels on a directly seen lamp's
                    edge (``edge_samples``); the rooms with a mirror and a glass ball trace caustics by photons
                    (their scenes' ``photons_per_pixel = 0.3``),
* ``lens, unguided`` (fig12 only, whose scene turns path guiding on) the same without path guiding,
* ``lens, guided``  (the other curved rooms) the same with path guiding (``guide_training=8``),
* ``images``        (Kerr rooms only) the same with Kerr's Newton-refined image proxies instead of the
                    proposal (``light_connection="images"``: the default before it),
* ``lens, no photons`` (the rooms with a mirror and a glass ball) the same without their caustics by photons
                    (``photons_per_pixel=0``; the scenes ask for 0.3 per pixel),
* ``lens, no retro`` (the same rooms) the photons for caustics only: the light the hole turns back by more
                    than 120 degrees stays the path tracer's (``retro_photons=False``),
* ``lens, no camera lights`` (the static spherical rooms) the same without the camera's own light samples
                    in the pixels where a light's image is small (``camera_light_samples=False``),
* ``lens, no focus`` (the rooms round a mass) the same with every light point drawn by area (``lens_focus=False``;
                    the default draws half of them about where the hole focuses the light onto the vertex),
* ``lens, unstratified`` (fig07, fig10d) the same with each bounce's light point and BSDF direction drawn
                    independently (``stratified_paths=False``; the default stratifies them over a pixel's samples),
* ``lens, no roulette`` the same with every light sample traced (``light_roulette=0``; the default plays
                    Russian roulette with the light samples of a path's dim vertices),
* ``lens, no edge`` the same with ``edge_samples=1`` (every pixel gets spp samples),
* ``lens, jitter``  the same with uniform jitter in the pixel (``pixel_sampler="independent"``),
* ``aimed, jitter`` the renderer before this work: flat-space proxies aimed by pilot geodesics, jitter,
                    spp samples in every pixel,
* ``brute``         no light connection (BSDF sampling only, unguided), stratified pixels and edge samples,
* ``brute, jitter`` the same with jitter,
* ``seed``          the seed paper's method: brute force with its fixed-step RK4, jitter, spp everywhere,

and the same room in flat space (``--flat``, the default connection, which is exact there). The machine's
speed drifts between the estimators' runs, so the lens connection's efficiency over brute force is also
measured with their times taken alternately (five rounds of lens, brute; ``over_brute_interleaved_min``
and ``_median``, from the rounds' largest and median time ratio).

The reference of each room is the default estimator without photons at ``--ref-spp`` samples in two
independent halves; their difference estimates the reference's own noise, which is subtracted from every
MSE. The relative MSE is the mean squared error over pixels and channels divided by the squared mean of
the reference. It is reported twice: over every pixel, and over the pixels that do not see an emitter
directly (found by a camera-segment-only render): those few pixels, where the camera sees a lensed image of
the lamp, carry the noise of the camera rays' pixel footprint (the lamp's edge inside a pixel), which no
light connection touches; ``edge_samples`` gives the ones its probes find more samples. Direct light alone
(max depth 2) gives the relative RMSE at 16 spp the issue compares with the flat room's.

    python benchmarks/bench_light_connection.py            # ~10 minutes on one core
    python benchmarks/bench_light_connection.py --quick    # seconds
    git show a377547:scenes/fig07_schwarzschild_cornell.toml > /tmp/old_fig07.toml
    python benchmarks/bench_light_connection.py --rooms fig07 --scene fig07=/tmp/old_fig07.toml  # an older room

``--scene ROOM=FILE`` renders a room (and its flat companion) from that scene file: a room as it was at an older
commit, so that today's estimators are compared on the scene an older measurement used (the reference, too, is
rendered from it).

Writes ``light_connection.csv`` (one row per room and estimator) to ``--out`` (default
benchmarks/results) and prints a table.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

import warpviz as wv

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import (RESULTS, UNBIASED, Reference, add_cluster_options, cluster_render_options,  # noqa: E402
                     machine_line, timed, write_csv)

#: Estimators: name -> render options.
ESTIMATORS = {
    "lens": {},  # the scene's defaults (fig12: path guiding, from its [render])
    "lens, unguided": {"guide_training": 0},
    "lens, guided": {"guide_training": 8},
    "images": {"light_connection": "images"},
    "lens, no edge": {"edge_samples": 1},
    "lens, jitter": {"pixel_sampler": "independent"},
    "aimed, jitter": {"light_connection": "aimed", "pixel_sampler": "independent", "edge_samples": 1,
                      "guide_training": 0, "photons_per_pixel": 0.0},
    "lens, no photons": {"photons_per_pixel": 0.0},  # the rooms' caustics by photons (0.3 per pixel) off
    "lens, no retro": {"retro_photons": False},  # the photons for caustics only, not for the light turned back
    "lens, no camera lights": {"camera_light_samples": False},  # the camera's own light samples off
    "lens, no focus": {"lens_focus": False},  # every light point drawn by area
    "lens, unstratified": {"stratified_paths": False},  # light points and directions drawn independently
    "lens, no roulette": {"light_roulette": 0.0},  # every light sample traced
    "brute": {"light_sampling": False, "guide_training": 0, "photons_per_pixel": 0.0},
    "brute, jitter": {"light_sampling": False, "pixel_sampler": "independent", "guide_training": 0,
                      "photons_per_pixel": 0.0},
    "seed": {"light_sampling": False, "stepper": "rk4", "pixel_sampler": "independent", "edge_samples": 1,
             "guide_training": 0, "photons_per_pixel": 0.0},
}

#: Rooms: name -> (scene, flat companion).
ROOMS = {"fig07": False, "fig10d": False, "fig12": False, "fig13": False, "line_element_kerr_newman": False,
         "fig07 flat": True}

#: Estimators measured in some rooms only: name -> those rooms (elsewhere they equal another).
ONLY_IN = {"images": {"fig10d", "line_element_kerr_newman"}, "lens, unguided": {"fig12"},
           "lens, guided": {"fig07", "fig10d", "fig13"},
           "lens, no photons": {"fig07", "fig10d", "line_element_kerr_newman"},
           "lens, no retro": {"fig07", "fig10d", "line_element_kerr_newman"},
           "lens, no focus": {"fig07", "fig10d", "line_element_kerr_newman"},  # (Ellis: no mass, no focus)
           "lens, unstratified": {"fig07", "fig10d"},
           "lens, no camera lights": {"fig07", "fig12", "fig13"}}  # (static spherical rooms: elsewhere the same)


def _scene(room: str, cfg: dict) -> str:
    """The scene a room renders: its shipped one, or the file --scene named for it (cfg['scenes'])."""
    name = room.split()[0]
    return cfg.get("scenes", {}).get(name, name)


def _render(room: str, cfg: dict, *, spp: int, seed: int, max_depth: int | None = None, via: dict | None = None,
            **options):
    kw = {"width": cfg["size"][0], "height": cfg["size"][1], "threads": 1, "flat": ROOMS[room], **(via or {})}
    if max_depth is not None:
        kw["max_depth"] = max_depth
    img, cpu, _ = timed(lambda: wv.render(_scene(room, cfg), spp=spp, seed=seed, **kw, **options))
    return img.rgb.astype(np.float64), cpu, img.stats


def reference(room: str, cfg: dict, *, max_depth: int | None = None, via: dict | None = None):
    """The reference frame from two halves, the MSE its own noise adds, and the mask of pixels that see
    no emitter directly (``via``: render keywords that send the halves to a Dask cluster). The halves are the
    path tracer's, without the scene's photons: unbiased (a photon render's bias is part of its error)."""
    half = {"spp": cfg["ref_spp"] // 2, "max_depth": max_depth, "via": via, **UNBIASED}
    a, _, _ = _render(room, cfg, seed=100_001, **half)
    b, _, _ = _render(room, cfg, seed=200_003, **half)
    direct, _, _ = _render(room, cfg, spp=64, seed=7, max_depth=1, edge_samples=1)  # the camera segment alone
    ref = Reference(a, b, cfg["ref_spp"] // 2)
    return ref.image, ref.noise_map, direct.max(axis=2) <= 0.0


def measure(room: str, cfg: dict, estimator: str, ref, noise, mask, *, max_depth: int | None = None) -> dict:
    """Relative MSE (all pixels and emitter-free ones) and CPU time of one estimator, over cfg['seeds'], and the
    BSDF samples that reached a light by a direction the light strategy cannot draw (the render's
    ``unsampled_light_hits`` of its ``light_hits``, summed over the seeds)."""
    scale_all, scale_masked = float(ref.mean()) ** 2, float(ref[mask].mean()) ** 2
    mse_all, mse_masked, cpu = [], [], []
    hits = unsampled = 0
    for seed in range(cfg["seeds"]):
        img, t, stats = _render(room, cfg, spp=cfg["spp"], seed=seed, max_depth=max_depth, **ESTIMATORS[estimator])
        hits += stats["light_hits"]
        unsampled += stats["unsampled_light_hits"]
        err = (img - ref) ** 2 - noise
        mse_all.append(max(float(err.mean()), 1e-30) / scale_all)
        mse_masked.append(max(float(err[mask].mean()), 1e-30) / scale_masked)
        cpu.append(t)
    t = float(np.mean(cpu))
    rel_all, rel_masked = float(np.mean(mse_all)), float(np.mean(mse_masked))
    return {"room": room, "scene": Path(_scene(room, cfg)).name, "estimator": estimator,
            "max_depth": max_depth or "scene", "spp": cfg["spp"], "width": cfg["size"][0], "height": cfg["size"][1],
            "reference_spp": cfg["ref_spp"],
            "cpu_s": t, "rel_mse": rel_all, "efficiency": 1.0 / (rel_all * t),
            "rel_mse_no_emitter_pixels": rel_masked, "efficiency_no_emitter_pixels": 1.0 / (rel_masked * t),
            "rel_rmse": math.sqrt(rel_all), "rel_rmse_no_emitter_pixels": math.sqrt(rel_masked),
            "emitter_pixels": int((~mask).sum()), "light_hits": hits, "unsampled_light_hits": unsampled}  # fmt: skip


def interleaved_time_ratio(room: str, cfg: dict, a: str, b: str, *, rounds: int) -> list[float]:
    """CPU time of estimator a over that of b, measured as A, B, A, B, ... (``rounds`` pairs, each over
    cfg['seeds'] renders), so that a machine whose speed drifts affects both alike: one ratio per round."""
    ratios = []
    for _ in range(rounds):
        t = {}
        for est in (a, b):
            t[est] = sum(_render(room, cfg, spp=cfg["spp"], seed=seed, **ESTIMATORS[est])[1]
                         for seed in range(cfg["seeds"]))  # fmt: skip
        ratios.append(t[a] / t[b])
    return ratios


def main(argv=None) -> list[dict]:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--quick", action="store_true", help="tiny frames and references (seconds; for tests)")
    p.add_argument("--out", type=Path, default=RESULTS)
    p.add_argument("--rooms", default=",".join(ROOMS), help="comma-separated subset of " + ", ".join(ROOMS))
    p.add_argument("--scene", action="append", default=[], metavar="ROOM=FILE",
                   help="render ROOM (and its flat companion) from this scene file (e.g. the room at an older "
                        "commit); repeatable")  # fmt: skip
    add_cluster_options(p)
    args = p.parse_args(argv)
    scenes = {}
    for item in args.scene:
        name, sep, file = item.partition("=")
        if not sep or name not in ROOMS or not Path(file).is_file():
            raise SystemExit(f"--scene {item!r}: expected ROOM=FILE with ROOM one of {', '.join(ROOMS)} and "
                             "FILE an existing scene file")  # fmt: skip
        scenes[name] = file
    cfg = ({"size": (12, 9), "spp": 4, "ref_spp": 32, "seeds": 1, "rounds": 2} if args.quick else
           {"size": (48, 36), "spp": 16, "ref_spp": 1024, "seeds": 3, "rounds": 5})  # fmt: skip
    cfg["scenes"] = scenes
    print(machine_line(threads=1))
    rows = []
    rooms = [r.strip() for r in args.rooms.split(",") if r.strip()]
    unknown = [room for room in rooms if room not in ROOMS]
    if unknown:
        raise SystemExit(f"unknown room {unknown[0]!r} (known: {', '.join(ROOMS)})")
    with cluster_render_options(args) as via:  # the references (their halves) on a cluster where asked
        refs = {room: (reference(room, cfg, via=via), reference(room, cfg, max_depth=2, via=via)) for room in rooms}
    for room in rooms:
        (ref, noise, mask), direct_ref = refs[room]
        estimators = ["lens"] if ROOMS[room] else [e for e in ESTIMATORS if room in ONLY_IN.get(e, {room})]
        for est in estimators:
            rows.append(measure(room, cfg, est, ref, noise, mask))
        if not ROOMS[room]:
            # The lens connection against brute force with their times taken alternately (A, B, A, B):
            # efficiency ratio = MSE ratio / time ratio, at the rounds' min, median and max time ratio.
            ratios = np.array(interleaved_time_ratio(room, cfg, "lens", "brute", rounds=cfg["rounds"]))
            lens, brute = rows[-len(estimators)], rows[-len(estimators) + estimators.index("brute")]
            for which, mse in (("", "rel_mse"), ("_no_emitter_pixels", "rel_mse_no_emitter_pixels")):
                gain = brute[mse] / lens[mse]
                lens[f"over_brute{which}_interleaved_min"] = gain / float(ratios.max())
                lens[f"over_brute{which}_interleaved_median"] = gain / float(np.median(ratios))
        # direct light alone
        dref, dnoise, dmask = direct_ref
        direct = ["lens", "images", "lens, no edge", "lens, jitter", "aimed, jitter", "brute"]
        for est in ["lens"] if ROOMS[room] else [e for e in direct if room in ONLY_IN.get(e, {room})]:
            rows.append(measure(room, cfg, est, dref, dnoise, dmask, max_depth=2))
    for r in rows:
        same = [q for q in rows if q["room"] == r["room"] and q["max_depth"] == r["max_depth"]]
        base = {q["estimator"]: q for q in same}
        flat = next((q for q in rows if q["room"] == "fig07 flat" and q["max_depth"] == r["max_depth"]), None)
        for label, other in (("brute", "brute"), ("brute_jitter", "brute, jitter"), ("seed", "seed"),
                             ("before", "aimed, jitter")):  # fmt: skip
            if other in base:
                r[f"over_{label}"] = r["efficiency"] / base[other]["efficiency"]
                r[f"over_{label}_no_emitter_pixels"] = (r["efficiency_no_emitter_pixels"]
                                                        / base[other]["efficiency_no_emitter_pixels"])  # fmt: skip
        if flat is not None and r["room"].startswith("fig07"):
            r["flat_over_this"] = flat["efficiency"] / r["efficiency"]
            r["flat_over_this_no_emitter_pixels"] = (flat["efficiency_no_emitter_pixels"]
                                                     / r["efficiency_no_emitter_pixels"])  # fmt: skip
    path = write_csv(args.out / "light_connection.csv", rows)
    print(f"{'room':12s} {'depth':6s} {'estimator':14s} {'cpu s':>7s} {'rel MSE':>9s} {'eff':>9s} "
          f"{'rel MSE*':>9s} {'eff*':>9s}   (* pixels that see no emitter directly)")  # fmt: skip
    for r in rows:
        print(f"{r['room']:12s} {str(r['max_depth']):6s} {r['estimator']:14s} {r['cpu_s']:7.2f} {r['rel_mse']:9.4f} "
              f"{r['efficiency']:9.2f} {r['rel_mse_no_emitter_pixels']:9.5f} {r['efficiency_no_emitter_pixels']:9.2f}")
    print(f"wrote {path}")
    return rows


if __name__ == "__main__":
    main()
