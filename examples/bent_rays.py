"""Bent light around a black hole: a fan of parallel rays passing a Schwarzschild mass.

Prints, for each impact parameter b, what happened to the ray and its deflection angle beside the
weak-field estimate 4M/b, and saves the recorded paths to ``examples/output/bent_rays.npz`` (or the
folder of ``--out``): points (P, 3), offsets (N + 1,), impact parameters (N,), for plotting or the VTK
export.

    python examples/bent_rays.py [--out FOLDER]
"""

import argparse
from pathlib import Path

import numpy as np

import warpviz as wv

parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
parser.add_argument("--out", type=Path, default=Path(__file__).resolve().parent / "output",
                    help="output folder (default examples/output)")  # fmt: skip
args = parser.parse_args()

bh = wv.Schwarzschild(mass=1.0)
b = np.array([3.0, 5.0, 5.2, 5.5, 6.0, 8.0, 12.0, 20.0, 40.0])
# parallel rays from the far left; at r = 1000 M the impact parameter is b to 0.1 %
origins = np.column_stack([np.full_like(b, -1000.0), b, np.zeros_like(b)])
rays = wv.trace(bh, origins, [1.0, 0.0, 0.0], tol=1e-10, record=True)

print(rays)
print(f"{'b / M':>6}  {'fate':<9} {'deflection (deg)':>16} {'4M/b (deg)':>11}  {'steps':>5}")
for bi, fate, d, n in zip(b, rays.status_names, rays.final_directions, rays.n_steps):
    bend = np.degrees(np.arctan2(-d[1], d[0]) % (2 * np.pi)) if fate == "escaped" else float("nan")
    print(f"{bi:6.1f}  {fate:<9} {bend:16.4f} {np.degrees(4 / bi):11.4f}  {n:5d}")
print(f"critical impact parameter 3*sqrt(3) M = {bh.critical_impact_parameter:.4f}: rays inside it fall in")

out = args.out
if out.exists() and not out.is_dir():
    parser.error(f"--out {str(out)!r} is a file; give a folder to write bent_rays.npz into")
out.mkdir(parents=True, exist_ok=True)
np.savez(out / "bent_rays.npz", points=rays.points, offsets=rays.offsets, impact_parameter=b)
print(f"paths saved to {out / 'bent_rays.npz'}")
