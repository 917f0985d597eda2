"""Rendering benchmarks: samples/s/core in flat and curved rooms, light connection against brute force,
image-level work-precision of the steppers, a fig07 frame-time extrapolation, and (optional) Mitsuba 3.

All scenes are the fig07-style Cornell room of ``_scenes.py`` (100 M on a side, camera at 45 M from the
centre, max depth 6), empty (flat), or with a Schwarzschild hole (M = 2.5, horizon radius 5), a Kerr
hole (M = 2.5, a = 0.9) or an Ellis throat (b0 = 5) in the middle. Sections:

1. **throughput** — camera samples per CPU-second (per core) with and without the light connection;
   the curved/flat ratio.
2. **light connection vs brute force** — relative RMSE against a high-spp reference (light connection,
   other seeds, its own noise estimated from two halves and subtracted) at several spp; since
   RMSE^2 * time is constant for a Monte Carlo estimator, ``time_ratio`` = (MSE * t)_brute /
   (MSE * t)_light is how much longer brute force takes for the same error, and its square root the
   RMSE ratio at equal time; in curved rooms also the light connection without its light margin
   (``light_margin=False``).
3. **image work-precision** — per-pixel error of a frame against a dop853 tol 1e-12 frame with the
   same seed and spp (the Monte Carlo noise cancels, what is left is the geodesics' error) against CPU
   time, per stepper and tol 1e-4 ... 1e-10 (``rk4`` uses the renderer's base step 1 M with halving):
   relative RMSE, mean absolute error and 99th percentile (which leaves out the rare paths that take
   another branch at an edge and change a pixel by a whole light sample), the fraction of pixels off
   by more than 1e-3, and the adaptive steppers' speed-up over rk4 at equal 99th-percentile error.
4. **fig07 extrapolation** — time of a 1024 x 768, 1000 spp frame of the fig07 room on this machine's
   cores, from a smaller frame rendered on all of them.
5. **Mitsuba 3** (if ``import mitsuba`` works; ``pip install mitsuba``) — the flat room with two
   diffuse spheres at the same resolution, spp and depth, ``scalar_rgb`` variant, against warpviz.

CSV files ``render_*.csv`` and plots ``render_*.png`` go to ``--out`` (default benchmarks/results).

    python benchmarks/bench_render.py            # several minutes
    python benchmarks/bench_render.py --quick    # seconds
"""

from __future__ import annotations

import argparse
import math
import os
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

import warpviz as wv  # noqa: E402
from _common import (RESULTS, add_cluster_options, cluster_render_options, machine_line, pyplot,  # noqa: E402
                     time_at_error, timed, write_csv)
from _scenes import METRICS, cornell_room, mitsuba_transforms, to_mitsuba  # noqa: E402

MAX_DEPTH = 6
RR_DEPTH = 3
FIG07_FRAME = (1024, 768, 1000)  # width, height, spp of the extrapolated frame

FULL = {
    "throughput": {"size": (64, 48), "spp": 8, "min_cpu": 1.0},
    "light": {"size": (32, 24), "ref_spp": {"flat": 2048, "schwarzschild": 512}, "spps": (4, 16, 64)},
    "precision": {"scenes": ("schwarzschild", "kerr_a0.9"), "size": (48, 36), "spp": 4,
                  "tols": [10.0**-k for k in range(4, 11)], "rk4_tols": [10.0**-k for k in range(4, 11)]},
    "fig07": {"size": (128, 96), "spp": 4},
    "mitsuba": {"size": (64, 48), "spp": 64, "min_cpu": 1.0},
}  # fmt: skip
QUICK = {
    "throughput": {"size": (16, 12), "spp": 2, "min_cpu": 0.02},
    "light": {"size": (12, 9), "ref_spp": {"flat": 64, "schwarzschild": 32}, "spps": (2, 8)},
    "precision": {"scenes": ("schwarzschild",), "size": (12, 9), "spp": 1, "tols": [1e-4, 1e-6, 1e-8],
                  "rk4_tols": [1e-4, 1e-6]},
    "fig07": {"size": (32, 24), "spp": 1},
    "mitsuba": {"size": (16, 12), "spp": 4, "min_cpu": 0.02},
}  # fmt: skip


def room(name: str, size, **kw) -> dict:
    """The benchmark room around metric ``name`` (a key of ``_scenes.METRICS``)."""
    return cornell_room(METRICS[name], size=size, **kw)


def render_timed(scene: dict, *, threads: int, **options):
    """Render once; returns (Image, CPU seconds, wall seconds)."""
    return timed(lambda: wv.render(scene, threads=threads, max_depth=MAX_DEPTH, **options))


def samples(scene: dict, spp: int) -> int:
    """Camera samples of a frame: width * height * spp."""
    return scene["camera"]["width"] * scene["camera"]["height"] * spp


def throughput(cfg: dict, *, threads: int) -> list[dict]:
    """Samples per CPU-second of each room, with and without the light connection. spp is raised until
    a run takes ``min_cpu`` CPU seconds."""
    rows = []
    for name in METRICS:
        for light_sampling in (True, False):
            scene = room(name, cfg["size"])
            spp = cfg["spp"]
            while True:
                img, cpu, wall = render_timed(scene, threads=threads, spp=spp, seed=1, light_sampling=light_sampling)
                if cpu >= cfg["min_cpu"] or spp >= 4096:
                    break
                spp = int(min(4096, spp * max(2, math.ceil(1.2 * cfg["min_cpu"] / max(cpu, 1e-3)))))
            n = samples(scene, spp)
            rows.append({
                "scene": name, "light_sampling": light_sampling, "width": cfg["size"][0], "height": cfg["size"][1],
                "spp": spp, "threads": threads, "cpu_s": cpu, "wall_s": wall, "samples_per_s_per_core": n / cpu,
                "steps_per_sample": img.stats["steps"] / n, "segments_per_sample": img.stats["segments"] / n,
                "mean_radiance": float(img.rgb.mean()),
            })  # fmt: skip
    for r in rows:
        flat = next(f for f in rows if f["scene"] == "flat" and f["light_sampling"] == r["light_sampling"])
        r["curved_over_flat"] = r["samples_per_s_per_core"] / flat["samples_per_s_per_core"]
    return rows


def reference(scene: dict, spp: int, *, seed: int, via: dict | None = None, **options) -> tuple[np.ndarray, float]:
    """A light-connection reference frame from two independent halves, and the mean squared error its
    own noise adds to a comparison (estimated from the halves' difference: var(mean) = E[(a - b)^2] / 4).
    ``via``: render keywords that send the halves to a Dask cluster (default: every core here)."""
    kw = {"threads": 0, "max_depth": MAX_DEPTH, **options, **(via or {})}
    a = wv.render(scene, spp=spp // 2, seed=seed, **kw).rgb.astype(np.float64)
    b = wv.render(scene, spp=spp // 2, seed=seed + 1, **kw).rgb.astype(np.float64)
    return 0.5 * (a + b), float(np.mean((a - b) ** 2)) / 4.0


def light_reach(scene: dict, *, spp: int, stride: int = 2) -> float:
    """Fraction of light-connection segments (aimed at a light by its flat-space proxy) that end on an
    emissive quad, from the recorded paths of every ``stride``-th pixel in x and y."""
    w, h = scene["camera"]["width"], scene["camera"]["height"]
    pixels = [[x, y] for y in range(0, h, stride) for x in range(0, w, stride)]
    rays = wv.render(scene, spp=spp, seed=5, threads=0, max_depth=MAX_DEPTH, record_pixels=pixels).rays
    ends = rays.final_positions[rays.ray_data["kind"] == 2]  # 2 = light-connection segment
    on = np.zeros(len(ends), dtype=bool)
    for shape in scene["shapes"]:
        if shape["type"] != "quad" or scene["materials"][shape["material"]]["type"] != "emissive":
            continue
        c, u, v = (np.asarray(shape[k], dtype=float) for k in ("corner", "edge_u", "edge_v"))
        n = np.cross(u, v) / np.linalg.norm(np.cross(u, v))
        d = ends - c
        s_, t_ = d @ u / (u @ u), d @ v / (v @ v)
        on |= (np.abs(d @ n) < 1e-6 * np.linalg.norm(u)) & (s_ >= 0) & (s_ <= 1) & (t_ >= 0) & (t_ <= 1)
    return float(on.mean()) if len(ends) else math.nan


#: The estimators compared: name -> render options. "light connection" is the default (lens-aware where
#: the metric allows); "no margin" is the older aimed connection with its proxies at the light's own size
#: (``light_connection="aimed", light_margin=False``; the same as the light connection in flat space).
#: bench_light_connection.py compares the connections in the shipped rooms.
ESTIMATORS = {
    "light connection": {"light_sampling": True},
    "brute force": {"light_sampling": False},
    "no margin": {"light_sampling": True, "light_connection": "aimed", "light_margin": False},
}


def light_connection(cfg: dict, *, threads: int, via: dict | None = None) -> list[dict]:
    """Relative RMSE against a reference at equal spp and its CPU time, for each estimator (``no margin``
    in curved rooms only), flat and curved."""
    rows = []
    for name, ref_spp in cfg["ref_spp"].items():
        scene = room(name, cfg["size"])
        ref, ref_mse = reference(scene, ref_spp, seed=10_001, via=via)
        scale = float(ref.mean())
        for estimator, options in ESTIMATORS.items():
            if estimator == "no margin" and name == "flat":
                continue
            for spp in cfg["spps"]:
                img, cpu, wall = render_timed(scene, threads=threads, spp=spp, seed=1, **options)
                mse = max(float(np.mean((img.rgb.astype(np.float64) - ref) ** 2)) - ref_mse, 1e-30)
                rows.append({
                    "scene": name, "estimator": estimator, "spp": spp,
                    "width": cfg["size"][0], "height": cfg["size"][1], "reference_spp": ref_spp, "cpu_s": cpu,
                    "wall_s": wall, "samples_per_s_per_core": samples(scene, spp) / cpu,
                    "rel_rmse": math.sqrt(mse) / scale, "rel_rmse_reference_noise": math.sqrt(ref_mse) / scale,
                    "mse_times_cpu_s": mse / scale**2 * cpu,
                })  # fmt: skip
    return rows


def light_summary(rows: list[dict], cfg: dict) -> list[dict]:
    """Per scene: brute force's time factor for equal error (geometric mean over spp), RMSE ratio at
    equal time, how many light-connection segments reach the light, and (curved rooms) the time factor
    of the light connection without its light margin."""
    out = []
    for name in dict.fromkeys(r["scene"] for r in rows):
        reach = light_reach(room(name, cfg["size"]), spp=cfg["spps"][0])
        cost = {est: np.exp(np.mean([math.log(r["mse_times_cpu_s"]) for r in rows
                                     if r["scene"] == name and r["estimator"] == est] or [math.nan]))
                for est in ESTIMATORS}  # fmt: skip
        ratio = cost["brute force"] / cost["light connection"]
        out.append({"scene": name, "brute_force_time_for_equal_error": ratio,
                    "rmse_ratio_at_equal_time": math.sqrt(ratio), "light_segments_reaching_light": reach,
                    "no_margin_time_for_equal_error": cost["no margin"] / cost["light connection"]})  # fmt: skip
    return out


def image_precision(cfg: dict, *, threads: int, via: dict | None = None) -> list[dict]:
    """Per-pixel error of frames against a dop853 tol 1e-12 frame (same seed and spp) against CPU time.

    The pilot geodesics that aim light samples are traced at the frame's tolerance here (``pilot_tol``),
    so that the frames converge to the reference sample by sample; by default they run at 1e-4, which
    changes which light samples are drawn (the noise) but not the expected image."""
    rows = []
    for name in cfg["scenes"]:
        scene = room(name, cfg["size"])
        ref = wv.render(scene, spp=cfg["spp"], seed=3, max_depth=MAX_DEPTH, stepper="dop853", tol=1e-12,
                        pilot_tol=1e-12, segment_method="integrate",
                        **{"threads": 0, **(via or {})}).rgb.astype(np.float64)  # fmt: skip
        scale = float(ref.mean())
        # the integrators at each tolerance, then the closed-form segments (where the metric has them; their
        # pilots at 1e-12 so that only the segments differ from the reference)
        runs = [(stepper, tol, "integrate") for stepper in ("dopri5", "dop853", "rk4")
                for tol in (cfg["rk4_tols"] if stepper == "rk4" else cfg["tols"])]  # fmt: skip
        runs.append(("closed_form", 1e-12, "closed_form"))
        for stepper, tol, method in runs:
            img, cpu, wall = render_timed(scene, threads=threads, spp=cfg["spp"], seed=3,
                                          stepper="dop853" if method == "closed_form" else stepper, tol=tol,
                                          pilot_tol=tol, segment_method=method)  # fmt: skip
            diff = np.abs(img.rgb.astype(np.float64) - ref)
            rows.append({
                "scene": name, "stepper": stepper, "tol": tol, "width": cfg["size"][0], "height": cfg["size"][1],
                "spp": cfg["spp"], "cpu_s": cpu, "wall_s": wall,
                "samples_per_s_per_core": samples(scene, cfg["spp"]) / cpu,
                "steps_per_sample": img.stats["steps"] / samples(scene, cfg["spp"]),
                "rel_rmse": float(np.sqrt(np.mean(diff**2))) / scale, "rel_mae": float(diff.mean()) / scale,
                "rel_p99": float(np.percentile(diff.max(axis=-1), 99)) / scale, "max_abs_error": float(diff.max()),
                "frac_pixels_off": float(np.mean(diff.max(axis=-1) > 1e-3 * scale)),
            })  # fmt: skip
    return rows


def add_image_speedups(rows: list[dict]) -> None:
    """``speedup_vs_rk4`` of the adaptive rows: rk4's CPU time interpolated (log-log, Pareto front) at
    the row's 99th-percentile pixel error, over the row's time; NaN outside rk4's error range."""
    for r in rows:
        rk4 = [p for p in rows if p["scene"] == r["scene"] and p["stepper"] == "rk4"]
        t = time_at_error([p["cpu_s"] for p in rk4], [p["rel_p99"] for p in rk4], r["rel_p99"])
        r["speedup_vs_rk4"] = t / r["cpu_s"] if r["stepper"] != "rk4" and math.isfinite(t) else math.nan


def fig07(cfg: dict) -> dict:
    """Render the fig07 room on every core and extrapolate to a 1024 x 768, 1000 spp frame."""
    scene = room("schwarzschild", cfg["size"])
    cores = os.cpu_count() or 1
    img, cpu, wall = render_timed(scene, threads=0, spp=cfg["spp"], seed=1)
    n = samples(scene, cfg["spp"])
    big = FIG07_FRAME[0] * FIG07_FRAME[1] * FIG07_FRAME[2]
    return {
        "scene": "fig07 room (Schwarzschild M = 2.5)", "width": cfg["size"][0], "height": cfg["size"][1],
        "spp": cfg["spp"], "cores": cores, "cpu_s": cpu, "wall_s": wall, "samples_per_s_per_core": n / cpu,
        "samples_per_s_all_cores": n / wall, "parallel_efficiency": cpu / (wall * cores),
        "target": "x".join(map(str, FIG07_FRAME[:2])) + f" {FIG07_FRAME[2]} spp", "target_samples": big,
        "extrapolated_hours_all_cores": big / (n / wall) / 3600.0,
        "extrapolated_hours_ideal_scaling": big / (cores * n / cpu) / 3600.0,
        "extrapolated_core_hours": big / (n / cpu) / 3600.0,
    }  # fmt: skip


def mitsuba_comparison(cfg: dict, *, threads: int) -> list[dict]:
    """warpviz and Mitsuba 3 (scalar_rgb) on the flat room with two diffuse spheres; [] if unavailable."""
    try:
        import drjit as dr
        import mitsuba as mi
    except ImportError as exc:
        print(f"Mitsuba comparison skipped: mitsuba is not importable ({exc}); pip install mitsuba")
        return []
    mi.set_variant("scalar_rgb")
    dr.set_thread_count(threads or os.cpu_count() or 1)
    scene = room("flat", cfg["size"], spheres=True)
    spec = to_mitsuba(scene, max_depth=MAX_DEPTH, rr_depth=RR_DEPTH, spp=cfg["spp"])
    mscene = mi.load_dict(mitsuba_transforms(spec, mi))
    mi.render(mscene, spp=1)  # warm-up (lazy initialisation)
    rows = []
    for renderer in ("warpviz", "mitsuba"):
        spp = cfg["spp"]
        while True:
            if renderer == "warpviz":
                img, cpu, wall = render_timed(scene, threads=threads, spp=spp, seed=1)
                rgb = img.rgb
            else:
                rgb, cpu, wall = timed(lambda: np.array(mi.render(mscene, spp=spp, seed=1)))
            if cpu >= cfg["min_cpu"] or spp >= 8192:
                break
            spp *= max(2, math.ceil(1.2 * cfg["min_cpu"] / max(cpu, 1e-3)))
        n = samples(scene, spp)
        w = rgb.shape[1]
        rows.append({
            "renderer": renderer, "variant": f"mitsuba {mi.__version__} scalar_rgb" if renderer == "mitsuba" else
            f"warpviz {wv.__version__}", "width": cfg["size"][0], "height": cfg["size"][1], "spp": spp,
            "max_depth": MAX_DEPTH, "rr_depth": RR_DEPTH, "threads": threads, "cpu_s": cpu, "wall_s": wall,
            "samples_per_s_per_core": n / cpu, "mean_radiance": float(rgb.mean()),
            "left_third_red_minus_green": float((rgb[:, : w // 3, 0] - rgb[:, : w // 3, 1]).mean()),
            "right_third_green_minus_red": float((rgb[:, -(w // 3):, 1] - rgb[:, -(w // 3):, 0]).mean()),
        })  # fmt: skip
    rows[1]["mitsuba_over_warpviz"] = rows[1]["samples_per_s_per_core"] / rows[0]["samples_per_s_per_core"]
    return rows


def plot(tp: list[dict], lc: list[dict], wp: list[dict], out: Path) -> list[Path]:
    """render_throughput.png, render_light_connection.png, render_work_precision.png."""
    plt = pyplot()
    if plt is None:
        return []
    paths = []
    fig, ax = plt.subplots(figsize=(6.5, 4))
    names = list(dict.fromkeys(r["scene"] for r in tp))
    x = np.arange(len(names))
    for k, (ls, label) in enumerate(((True, "light connection"), (False, "brute force"))):
        vals = [next(r["samples_per_s_per_core"] for r in tp if r["scene"] == n and r["light_sampling"] == ls)
                for n in names]
        ax.bar(x + (k - 0.5) * 0.38, vals, width=0.38, label=label)
    ax.set_xticks(x, names)
    ax.set_yscale("log")
    ax.set_ylabel("camera samples / s / core")
    ax.set_title("Render throughput, fig07 room, max depth 6")
    ax.legend(fontsize=8)
    fig.tight_layout()
    paths.append(out / "render_throughput.png")
    fig.savefig(paths[-1], dpi=110)
    plt.close(fig)

    scenes = list(dict.fromkeys(r["scene"] for r in lc))
    fig, axes = plt.subplots(1, len(scenes), figsize=(5.2 * len(scenes), 4), squeeze=False)
    for ax, name in zip(axes[0], scenes):
        for est, marker in (("light connection", "o"), ("brute force", "s"), ("no margin", "^")):
            pts = sorted((r["cpu_s"], r["rel_rmse"]) for r in lc if r["scene"] == name and r["estimator"] == est)
            if pts:
                ax.loglog(*zip(*pts), marker=marker, label=est)
        ax.set_xlabel("CPU seconds (1 core)")
        ax.set_ylabel("relative RMSE vs reference")
        ax.set_title(f"{name} room")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    paths.append(out / "render_light_connection.png")
    fig.savefig(paths[-1], dpi=110)
    plt.close(fig)

    scenes = list(dict.fromkeys(r["scene"] for r in wp))
    fig, axes = plt.subplots(2, len(scenes), figsize=(5.4 * len(scenes), 8), squeeze=False)
    for row, (key, label) in enumerate((("rel_mae", "relative mean abs. error"),
                                        ("rel_p99", "99th percentile of rel. pixel error"))):
        for ax, name in zip(axes[row], scenes):
            for stepper, marker in (("dopri5", "o"), ("dop853", "s"), ("rk4", "v"), ("closed_form", "*")):
                pts = sorted(((r["cpu_s"], r[key], r["tol"]) for r in wp
                              if r["scene"] == name and r["stepper"] == stepper and r[key] > 0),
                             key=lambda p: -p[2])  # loose to tight tol
                if not pts:
                    continue
                ax.loglog([p[0] for p in pts], [p[1] for p in pts], marker=marker, label=stepper)
                for t, e, tol in pts:
                    ax.annotate(f"{tol:.0e}", (t, e), fontsize=6, xytext=(3, 3), textcoords="offset points")
            ax.set_xlabel("CPU seconds per frame (1 core)")
            ax.set_ylabel(f"{label} vs dop853 tol 1e-12 frame")
            ax.set_title(f"{name} room, same seed and spp")
            ax.grid(True, alpha=0.3)
            ax.legend(fontsize=8)
    fig.tight_layout()
    paths.append(out / "render_work_precision.png")
    fig.savefig(paths[-1], dpi=110)
    plt.close(fig)
    return paths


def main(argv=None) -> dict[str, list[dict]]:
    """Run the render benchmarks.

    Parameters
    ----------
    argv : list of str, optional
        Command-line arguments (default: ``sys.argv[1:]``): ``--quick``, ``--out DIR``, ``--threads N``,
        ``--no-mitsuba``, ``--no-plots``.

    Returns
    -------
    dict
        Rows of each section: ``throughput``, ``light_connection``, ``light_summary``,
        ``work_precision``, ``fig07``, ``mitsuba`` (empty when skipped).
    """
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="tiny frames for a smoke test (seconds)")
    ap.add_argument("--out", type=Path, default=RESULTS, help="output folder (default benchmarks/results)")
    ap.add_argument("--threads", type=int, default=1,
                    help="render threads of the timed runs (default 1; references and fig07 use every core)")
    ap.add_argument("--no-mitsuba", action="store_true", help="skip the Mitsuba 3 comparison")
    ap.add_argument("--no-plots", action="store_true", help="write the CSV files only")
    add_cluster_options(ap)
    args = ap.parse_args(argv)
    cfg = QUICK if args.quick else FULL
    out = args.out
    out.mkdir(parents=True, exist_ok=True)
    print(f"{machine_line(threads=args.threads)}\nrates are camera samples per CPU-second (per core)\n")

    tp = throughput(cfg["throughput"], threads=args.threads)
    print(f"{'scene':<15} {'light conn.':<11} {'samples/s/core':>14} {'steps/sample':>12} {'curved/flat':>11}")
    for r in tp:
        print(f"{r['scene']:<15} {str(r['light_sampling']):<11} {r['samples_per_s_per_core']:>14.0f} "
              f"{r['steps_per_sample']:>12.1f} {r['curved_over_flat']:>11.4f}")  # fmt: skip

    with cluster_render_options(args) as via:  # the references on a Dask cluster where asked; timed runs here
        lc = light_connection(cfg["light"], threads=args.threads, via=via)
        ls = light_summary(lc, cfg["light"])
        print(f"\n{'scene':<15} {'estimator':<17} {'spp':>4} {'cpu s':>7} {'rel RMSE':>9}")
        for r in lc:
            print(f"{r['scene']:<15} {r['estimator']:<17} {r['spp']:>4} {r['cpu_s']:>7.2f} {r['rel_rmse']:>9.4f}")
        for r in ls:
            print(f"{r['scene']}: brute force needs {r['brute_force_time_for_equal_error']:.1f}x the time of the light "
                  f"connection for equal RMSE (RMSE {r['rmse_ratio_at_equal_time']:.2f}x at equal time); "
                  f"{100 * r['light_segments_reaching_light']:.0f}% of light connections reach the light")  # fmt: skip
            if math.isfinite(r["no_margin_time_for_equal_error"]):
                print(f"{r['scene']}: without the light margin the light connection needs "
                      f"{r['no_margin_time_for_equal_error']:.2f}x the time for equal RMSE")

        wp = image_precision(cfg["precision"], threads=args.threads, via=via)
        add_image_speedups(wp)
        print(f"\n{'scene':<15} {'stepper':<7} {'tol':>7} {'cpu s':>7} {'samples/s/core':>14} {'rel RMSE':>9} "
              f"{'rel MAE':>9} {'rel p99':>9} {'px off':>7} {'vs rk4':>7}")  # fmt: skip
        for r in wp:
            speedup = f"{r['speedup_vs_rk4']:.1f}x" if math.isfinite(r["speedup_vs_rk4"]) else "-"
            print(f"{r['scene']:<15} {r['stepper']:<7} {r['tol']:>7.0e} {r['cpu_s']:>7.2f} "
                  f"{r['samples_per_s_per_core']:>14.0f} {r['rel_rmse']:>9.2e} {r['rel_mae']:>9.2e} {r['rel_p99']:>9.2e} "
                  f"{r['frac_pixels_off']:>7.3f} {speedup:>7}")  # fmt: skip

    f7 = fig07(cfg["fig07"])
    print(f"\nfig07 room {f7['width']}x{f7['height']} {f7['spp']} spp on {f7['cores']} cores: "
          f"{f7['samples_per_s_all_cores']:.0f} samples/s ({f7['samples_per_s_per_core']:.0f} per core, parallel "
          f"efficiency {f7['parallel_efficiency']:.2f}) -> {f7['target']}: {f7['extrapolated_hours_all_cores']:.1f} h "
          f"on {f7['cores']} cores ({f7['extrapolated_core_hours']:.1f} core-hours)")  # fmt: skip

    mc = [] if args.no_mitsuba else mitsuba_comparison(cfg["mitsuba"], threads=args.threads)
    for r in mc:
        print(f"{r['variant']:<28} {r['samples_per_s_per_core']:>12.0f} samples/s/core  mean radiance "
              f"{r['mean_radiance']:.4f}")  # fmt: skip
    if mc:
        print(f"Mitsuba / warpviz samples/s/core: {mc[1]['mitsuba_over_warpviz']:.2f}")

    written = [
        write_csv(out / "render_throughput.csv", tp),
        write_csv(out / "render_light_connection.csv", lc),
        write_csv(out / "render_light_connection_summary.csv", ls),
        write_csv(out / "render_work_precision.csv", wp),
        write_csv(out / "render_fig07_extrapolation.csv", [f7]),
    ]
    if mc:
        written.append(write_csv(out / "render_mitsuba.csv", mc))
    if not args.no_plots:
        written += plot(tp, lc, wp, out)
    print("\nwrote " + ", ".join(str(p) for p in written))
    return {"throughput": tp, "light_connection": lc, "light_summary": ls, "work_precision": wp, "fig07": [f7],
            "mitsuba": mc}  # fmt: skip


if __name__ == "__main__":
    main()
