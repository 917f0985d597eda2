"""The trace-only example runs and reports far rays' deflection as the weak-field series says."""

import re
import subprocess
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def test_bent_rays_example_prints_deflections_and_saves_paths(tmp_path):
    out = subprocess.run([sys.executable, str(ROOT / "examples" / "bent_rays.py"), "--out", str(tmp_path)],
                         capture_output=True, text=True, check=True).stdout  # fmt: skip
    rows = {float(m[0]): (m[1], float(m[2]), float(m[3])) for m in
            re.findall(r"^\s*([\d.]+)\s+(\w+)\s+([\d.na]+)\s+([\d.]+)", out, flags=re.M)}
    assert rows[3.0][0] == "horizon" and rows[40.0][0] == "escaped"
    bend = np.radians(rows[40.0][1])
    b = 40.0
    # weak-field series of the Schwarzschild deflection: 4/b + 15 pi / (4 b^2) + 128 / (3 b^3)
    assert abs(bend - (4 / b + 15 * np.pi / (4 * b**2) + 128 / (3 * b**3))) < 5e-3 * bend
    data = np.load(tmp_path / "bent_rays.npz")  # tests write only into temporary folders
    assert data["offsets"][-1] == len(data["points"])
