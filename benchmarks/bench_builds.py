"""Two builds of the compiled core against each other: CPU time of the same renders, alternating.

A change to the C++ core is measured by timing the build before it (A) and after it (B) on the same
renders in one run, A, B, A, B, ... (a shared machine's load then falls on both alike), one render per
process with that build's ``_core`` loaded in place of the installed one. Reports the min and median CPU
seconds of each and the ratio A / B (above 1: B is faster), and whether the two builds' images are
bit-identical (a change that should not move a pixel is checked by the same run).

    cp build/*/_core*.so /tmp/core_before.so        # before the change
    pip install --no-build-isolation -e .           # build the change
    python benchmarks/bench_builds.py /tmp/core_before.so build/*/_core*.so
    python benchmarks/bench_builds.py A.so B.so --renders mitsuba:128x128:64,fig03:160x120:32 --repeat 5
    python benchmarks/bench_builds.py --quick       # the installed build against itself (seconds)
    python benchmarks/bench_builds.py A.so B.so --renders far-kerr:128x128:1 --repeat 5   # geodesics/s
    python benchmarks/bench_builds.py OLD/_core.so B.so --package-a OLD ...   # an old core with its own Python

A render named ``far-kerr`` or ``far-schwarzschild`` is not a scene but the far observer's image plane of
``bench_geodesics.py`` (r = 1000 M, inclination 60 deg, +-15 M; Kerr a = 0.9 or Schwarzschild), WIDTH x
WIDTH rays traced to escape or capture with dopri5 at tol 1e-8 in SIMD batches on one thread (its SPP is
ignored): the geodesic throughput of each build, printed as rays per CPU second.

With ``--error`` the comparison is at equal error: each timing renders ``--seeds`` seeds (seed 1, 2, ...), every
render's relative MSE is taken against a converged reference rendered by the installed build (two halves of
``--ref-spp`` samples without photons, _common.Reference, noise subtracted), and the row gives each build's mean
relative MSE and the efficiency ratio B / A = (MSE x time of A) / (MSE x time of B): how much less time B needs
for the same error. A build older than a scene file's keys renders its own version of the scene (``--scene-a``,
e.g. ``git show OLD:scenes/fig10d_kerr_cornell_a09.toml > /tmp/old.toml``), so each build runs the room with the
defaults of its day:

    python benchmarks/bench_builds.py OLD/warpviz/_core*.so build/*/_core*.so --package-a OLD \
        --renders fig10d:48x36:16 --repeat 4 --seeds 4 --error --scene-a /tmp/old.toml

An option's own gain is the same core run as both builds, one with the option off (``--options-a``, JSON):

    python benchmarks/bench_builds.py --renders fig07:48x36:16 --repeat 5 --seeds 8 --error --ref-spp 1024 \
        --options-a '{"photon_aim": false}'

Writes ``builds.csv`` (one row per render) to ``--out`` (default benchmarks/results) and prints a table.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

# (_common imports warpviz, so only the parent process imports it: a child must load its build first)
RESULTS = Path(__file__).resolve().parent / "results"

#: scene:WIDTHxHEIGHT:SPP of the default renders: Mitsuba's box and the flat room (the flat path), fig07
#: (Schwarzschild, closed-form segments) and fig10d (Kerr, integrated).
DEFAULT_RENDERS = "mitsuba:128x128:64,fig03:160x120:32,fig07:96x72:16,fig10d:96x72:16"

#: The far observers' image planes (bench_geodesics.py) a render may name instead of a scene: their metrics.
FAR_OBSERVERS = {"far-kerr": ("Kerr", {"mass": 1.0, "spin": 0.9}),
                 "far-schwarzschild": ("Schwarzschild", {"mass": 1.0})}


def _child(core: str, scene: str, size: str, spp: int, image: str, package: str = "", seeds: int = 0,
           options: str = "{}") -> None:
    """In a fresh process: load ``core`` as warpviz._core (and the warpviz package from the source tree
    ``package`` where given, instead of the installed one), render on one thread with the render ``options``
    (JSON), print the CPU seconds (``seeds`` > 0: that many renders, seeds 1, 2, ..., their images stacked)."""
    import importlib.util
    import time

    if package:  # the tree's package, not the installed one (an editable install's finder would win)
        sys.meta_path[:] = [f for f in sys.meta_path if "editable" not in type(f).__module__]
        sys.path.insert(0, package)

    spec = importlib.util.spec_from_file_location("warpviz._core", core)
    module = importlib.util.module_from_spec(spec)
    sys.modules["warpviz._core"] = module
    spec.loader.exec_module(module)
    import warpviz as wv

    if Path(wv._native.core.__file__).resolve() != Path(core).resolve():
        raise SystemExit(f"warpviz loaded {wv._native.core.__file__}, not {core}")
    if package and Path(wv.__file__).resolve().parents[1] != Path(package).resolve():
        raise SystemExit(f"warpviz came from {wv.__file__}, not {package}")
    w, h = (int(v) for v in size.split("x"))
    if scene in FAR_OBSERVERS:
        name, params = FAR_OBSERVERS[scene]
        plane = np.load(_plane_file(Path(image).parent, scene, size))  # (the parent's: the same rays for each build)
        origin, dirs = plane[0], plane[1:]
        t0 = time.process_time()
        rays = wv.trace(getattr(wv, name)(**params), origin, dirs, stepper="dopri5", tol=1e-8, threads=1,
                        max_steps=10_000_000)  # fmt: skip
        seconds = time.process_time() - t0
        np.save(image, np.concatenate([rays.final_directions.ravel(), rays.status.astype(float).ravel()]))
        print(json.dumps({"cpu_s": seconds, "rays": int(len(dirs))}))
        return
    kw = json.loads(options)
    if seeds > 0:
        wv.render(scene, width=8, height=6, spp=1, seed=0, progress=None, threads=1)  # (a line element compiles)
    t0 = time.process_time()
    imgs = [wv.render(scene, width=w, height=h, spp=spp, seed=s, progress=None, threads=1, **kw).rgb
            for s in range(1, max(seeds, 1) + 1)]  # fmt: skip
    seconds = (time.process_time() - t0) / len(imgs)
    np.save(image, np.stack(imgs) if seeds > 0 else imgs[0])
    print(json.dumps({"cpu_s": seconds}))


def _plane_file(folder: Path, scene: str, size: str) -> Path:
    """Where the parent keeps a far observer's rays (origin, then the directions), in the children's folder."""
    return Path(folder) / f"{scene}-{size}-rays.npy"


def installed_core() -> Path:
    """The installed build's compiled core."""
    from warpviz import _native

    return Path(_native.core.__file__)


def measure(a: Path, b: Path, renders: list[tuple[str, str, int]], repeat: int,
            packages: dict[str, str] | None = None, seeds: int = 0, ref_spp: int = 0,
            scenes: dict[str, str] | None = None, options: dict[str, dict] | None = None) -> list[dict]:
    """Times (and with ``ref_spp`` > 0, the errors of) builds a and b on each render, alternating; ``seeds``
    renders per timing, ``scenes`` a build's own scene file in place of the render's, ``options`` a build's
    own render options."""
    rows = []
    packages, scenes, options = packages or {}, scenes or {}, options or {}
    with tempfile.TemporaryDirectory() as tmp:
        for scene, size, spp in renders:
            if scene in FAR_OBSERVERS:
                from bench_geodesics import image_plane

                origin, dirs = image_plane(int(size.split("x")[0]))
                np.save(_plane_file(tmp, scene, size), np.vstack([origin[None, :], dirs]))
            times: dict[str, list[float]] = {"a": [], "b": []}
            mse: dict[str, list[float]] = {"a": [], "b": []}
            ref = _reference(scene, size, ref_spp) if ref_spp > 0 else None
            rays = 0
            for _ in range(repeat):
                for name, core in (("a", a), ("b", b)):
                    out = subprocess.run([sys.executable, __file__, "--child", str(core), scenes.get(name) or scene,
                                          size, str(spp), f"{tmp}/{name}.npy", packages.get(name, ""), str(seeds),
                                          json.dumps(options.get(name, {}))],
                                         capture_output=True, text=True)  # fmt: skip
                    if out.returncode != 0:
                        raise SystemExit(f"the render of {scene} with {core} failed:\n{out.stderr}")
                    result = json.loads(out.stdout.strip().splitlines()[-1])
                    times[name].append(result["cpu_s"])
                    rays = result.get("rays", 0)
                    if ref is not None:
                        mse[name] += [ref.rel_mse(img)[0] for img in np.load(f"{tmp}/{name}.npy")]
            same = bool(np.array_equal(np.load(f"{tmp}/a.npy"), np.load(f"{tmp}/b.npy")))
            errors = {}
            if ref is not None:  # (the renders repeat the same seeds: their error is the same each round)
                ma, mb = float(np.mean(mse["a"])), float(np.mean(mse["b"]))
                errors = {"a_rel_mse": ma, "b_rel_mse": mb,
                          "efficiency_b_over_a_min": ma * min(times["a"]) / (mb * min(times["b"])),
                          "efficiency_b_over_a_median": ma * float(np.median(times["a"])) /
                                                        (mb * float(np.median(times["b"])))}  # fmt: skip
            rows.append({"scene": scene, "size": size, "spp": spp, "repeat": repeat,
                         "a_cpu_s_min": min(times["a"]), "a_cpu_s_median": float(np.median(times["a"])),
                         "b_cpu_s_min": min(times["b"]), "b_cpu_s_median": float(np.median(times["b"])),
                         "a_over_b_min": min(times["a"]) / min(times["b"]),
                         "a_over_b_median": float(np.median(times["a"]) / np.median(times["b"])),
                         "identical": same, "rays": rays,
                         "a_rays_per_s_best": rays / min(times["a"]) if rays else "",
                         "b_rays_per_s_best": rays / min(times["b"]) if rays else "", **errors})  # fmt: skip
    return rows


def _reference(scene: str, size: str, spp: int):
    """The converged reference of a render: the installed build's unbiased estimator (no photons) in two
    halves of spp samples, both cores."""
    import warpviz as wv
    from _common import UNBIASED, Reference

    w, h = (int(v) for v in size.split("x"))
    halves = [wv.render(scene, width=w, height=h, spp=spp, seed=seed, progress=None, **UNBIASED).rgb
              for seed in (10_001, 10_002)]  # fmt: skip
    return Reference(halves[0], halves[1], spp)


def main(argv: list[str] | None = None) -> list[dict]:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("a", nargs="?", type=Path, help="the core before (a _core*.so); default: the installed one")
    p.add_argument("b", nargs="?", type=Path, help="the core after; default: the installed one")
    p.add_argument("--renders", default=None, help=f"comma-separated scene:WIDTHxHEIGHT:SPP (default {DEFAULT_RENDERS})")
    p.add_argument("--repeat", type=int, default=None, help="timings of each build per render (default 3)")
    p.add_argument("--package-a", default="", help="the source tree whose warpviz package runs with core A, where "
                   "its Python layer differs from the installed one (e.g. `git archive OLD | tar -x -C DIR`)")
    p.add_argument("--package-b", default="", help="the same for core B")
    p.add_argument("--error", action="store_true", help="compare at equal error: each build's relative MSE "
                   "against a converged reference, and the efficiency ratio")
    p.add_argument("--seeds", type=int, default=None, help="renders (seeds 1, 2, ...) per timing (default 1; "
                   "with --error 4)")
    p.add_argument("--ref-spp", type=int, default=512, help="samples of each half of the reference (--error)")
    p.add_argument("--scene-a", default="", help="build A's own scene file in place of the render's scene")
    p.add_argument("--scene-b", default="", help="the same for build B")
    p.add_argument("--options-a", default="{}", help="build A's own render options, as JSON (e.g. one build with "
                   "an option off: the same core as both builds)")
    p.add_argument("--options-b", default="{}", help="the same for build B")
    p.add_argument("--quick", action="store_true", help="one tiny render of each (seconds; for tests)")
    p.add_argument("--out", type=Path, default=RESULTS)
    args = p.parse_args(argv)
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from _common import machine_line, write_csv

    a = args.a or installed_core()
    b = args.b or installed_core()
    for core in (a, b):
        if not Path(core).is_file():
            raise SystemExit(f"no compiled core at {core}")
    spec = args.renders or ("fig03:16x12:2,fig07:8x6:1,far-kerr:8x8:1" if args.quick else DEFAULT_RENDERS)
    renders = []
    for item in spec.split(","):
        scene, size, spp = item.split(":")
        renders.append((scene, size, int(spp)))
    repeat = args.repeat or (1 if args.quick else 3)
    print(machine_line(threads=1))
    seeds = args.seeds if args.seeds is not None else (4 if args.error else 0)
    if args.error:
        seeds = max(seeds, 1)  # (the error needs the stacked images of at least one seed)
    rows = measure(Path(a), Path(b), renders, repeat, {"a": args.package_a, "b": args.package_b}, seeds=seeds,
                   ref_spp=args.ref_spp if args.error else 0, scenes={"a": args.scene_a, "b": args.scene_b},
                   options={"a": json.loads(args.options_a), "b": json.loads(args.options_b)})  # fmt: skip
    print(f"A = {a}\nB = {b}")
    print(f"{'scene':8s} {'size':>9s} {'spp':>4s} {'A min/med s':>13s} {'B min/med s':>13s} {'A/B min':>8s} "
          f"{'A/B med':>8s}  identical")  # fmt: skip
    for r in rows:
        print(f"{r['scene']:8s} {r['size']:>9s} {r['spp']:4d} {r['a_cpu_s_min']:6.2f}/{r['a_cpu_s_median']:<6.2f} "
              f"{r['b_cpu_s_min']:6.2f}/{r['b_cpu_s_median']:<6.2f} {r['a_over_b_min']:8.3f} {r['a_over_b_median']:8.3f}"
              f"  {r['identical']}")  # fmt: skip
        if "a_rel_mse" in r:
            print(f"{'':8s} rel. MSE A {r['a_rel_mse']:.4g}, B {r['b_rel_mse']:.4g}; efficiency B / A "
                  f"{r['efficiency_b_over_a_min']:.3f} (min times), {r['efficiency_b_over_a_median']:.3f} (median)")
        if r["rays"]:
            print(f"{'':8s} {r['rays']} rays: A {r['a_rays_per_s_best']:.4g}, B {r['b_rays_per_s_best']:.4g} per CPU s "
                  "(best)")  # fmt: skip
    args.out.mkdir(parents=True, exist_ok=True)
    write_csv(args.out / "builds.csv", rows)
    return rows


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == "--child":
        _child(sys.argv[2], sys.argv[3], sys.argv[4], int(sys.argv[5]), sys.argv[6], sys.argv[7],
               int(sys.argv[8]) if len(sys.argv) > 8 else 0, sys.argv[9] if len(sys.argv) > 9 else "{}")
    else:
        main()
    raise SystemExit(0)
