"""Save, or compare against, bit-exact outputs of the renderer and the tracer.

A restructure of the core must not change a single bit of any image or trace. This tool renders every
shipped scene small (curved and ``--flat``, with recorded paths) and traces a fan of rays through every
registered metric with every stepper (recorded, batched and lone), and either saves all arrays to one
``.npz`` file or compares a fresh run with a saved one, array by array, bit for bit.

Usage (from the repository root)::

    python tools/snapshot_outputs.py save before.npz     # on the commit before the change
    python tools/snapshot_outputs.py compare before.npz  # after it: exits 1 on any differing bit

Metrics registered after the snapshot was taken are reported as new, not as differences.
"""

from __future__ import annotations

import argparse
import pathlib
import sys

import numpy as np

import warpviz as wv

ROOT = pathlib.Path(__file__).resolve().parents[1]

# A point and two directions per metric family, outside every horizon and throat.
_ORIGINS = np.array([[0.0, -30.0, 0.5], [3.0, -25.0, 2.0], [-1.0, -40.0, -3.0], [0.2, 12.0, 0.1]])


def _directions(n: int) -> np.ndarray:
    rng = np.random.default_rng(7)
    d = np.tile([0.0, 1.0, 0.0], (n, 1)) + 0.25 * rng.standard_normal((n, 3))
    return d / np.linalg.norm(d, axis=1, keepdims=True)


def _metric_instances():
    for entry in wv.registered_metrics():
        yield entry["name"], wv.metric_from_dict({"name": entry["name"]})
        if entry["name"] == "kerr":
            yield "kerr_a09", wv.metric_from_dict({"name": "kerr", "spin": 0.9})


def collect(options: dict | None = None) -> dict[str, np.ndarray]:
    """Every output array, keyed by a name that says where it came from; `options` go to every render."""
    out: dict[str, np.ndarray] = {}
    for path in sorted((ROOT / "scenes").glob("*.toml")):
        for flat in (False, True):
            key = f"render/{path.stem}/{'flat' if flat else 'curved'}"
            img = wv.render(str(path), width=12, height=9, spp=2, flat=flat, threads=2, progress=None,
                            record_pixels=[[6, 4]], **(options or {}))
            out[key + "/rgb"] = img.rgb
            for name, a in img.aovs.items():
                out[f"{key}/aov/{name}"] = np.asarray(a)
            if img.rays is not None:
                out[key + "/rays/points"] = img.rays.points
    n = 24
    origins = np.repeat(_ORIGINS, n // len(_ORIGINS), axis=0)
    dirs = _directions(n)
    for name, metric in _metric_instances():
        for stepper in wv.STEPPERS:
            for batch in (True, False):
                key = f"trace/{name}/{stepper}/{'batch' if batch else 'lone'}"
                b = wv.trace(metric, origins, dirs, stepper=stepper, record=True, batch=batch, threads=2)
                out[key + "/status"] = np.asarray(b.status)
                out[key + "/final_positions"] = b.final_positions
                out[key + "/points"] = b.points
                out[key + "/point_data"] = np.array([b.point_data[c] for c in sorted(b.point_data)])
                for k, v in b.invariant_drift.items():
                    out[f"{key}/drift/{k}"] = np.asarray(v)
    return out


def _option_value(text: str):
    """A --render-option value: true/false, an integer, a real, else the string itself."""
    if text.lower() in ("true", "false"):
        return text.lower() == "true"
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            pass
    return text


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("mode", choices=["save", "compare"])
    p.add_argument("file")
    p.add_argument("--render-option", action="append", default=[], metavar="KEY=VALUE",
                   help="a render option for every render, e.g. pixel_sampler=independent or edge_samples=1 (repeatable)")
    a = p.parse_args(argv)
    options = {}
    for item in a.render_option:
        key, _, value = item.partition("=")
        options[key] = _option_value(value)
    now = collect(options)
    if a.mode == "save":
        np.savez_compressed(a.file, **now)
        print(f"saved {len(now)} arrays to {a.file}")
        return 0
    before = dict(np.load(a.file))
    bad = []
    for key, old in before.items():
        if key not in now:
            bad.append(f"{key}: missing now")
        elif old.shape != now[key].shape or old.dtype != now[key].dtype:
            bad.append(f"{key}: shape/dtype {old.shape}/{old.dtype} -> {now[key].shape}/{now[key].dtype}")
        elif old.tobytes() != np.ascontiguousarray(now[key]).tobytes():
            bad.append(f"{key}: values differ")
    new = sorted(k for k in now if k not in before)
    for line in bad:
        print("DIFF", line)
    if new:
        print(f"{len(new)} new arrays (metrics or outputs added since the snapshot), e.g. {new[0]}")
    print(f"{len(before) - len(bad)} of {len(before)} arrays bit-identical")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
