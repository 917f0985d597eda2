"""Regenerate the small assets the shipped scenes use (nothing is downloaded).

    python tools/make_scene_assets.py

writes

* ``scenes/textures/accretion_disk.png``: 256 x 64 emission map of a thin accretion disk (u = radius from
  the inner to the outer edge, v = azimuth), from :func:`warpviz.scene.textures.accretion_disk`;
* ``scenes/meshes/satellite_panels.obj``: the two solar panels and the strut of the satellite of
  figures 12 and 13 (its body is the scene's green cylinder), as an OBJ with texture coordinates.

The output is deterministic, so re-running it leaves the files unchanged.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
from PIL import Image

from warpviz.scene.primitives import box_quads
from warpviz.scene.textures import accretion_disk, linear_to_srgb

ROOT = Path(__file__).resolve().parents[1]


def write_png(path: Path, linear_rgb: np.ndarray) -> None:
    """Save linear RGB in [0, 1] as an 8-bit sRGB PNG."""
    data = np.round(linear_to_srgb(linear_rgb) * 255.0).astype(np.uint8)
    path.parent.mkdir(parents=True, exist_ok=True)
    Image.fromarray(data).save(path, optimize=True)


def box_obj_lines(quads: list[dict], first_vertex: int) -> tuple[list[str], int]:
    """OBJ ``v``/``vt``/``f`` lines for quads (two counter-clockwise triangles each)."""
    lines = []
    n = first_vertex
    for q in quads:
        c, u, v = (np.asarray(q[k]) for k in ("corner", "edge_u", "edge_v"))
        corners = [c, c + u, c + u + v, c + v]
        for p, (s, t) in zip(corners, [(0, 0), (1, 0), (1, 1), (0, 1)], strict=True):
            lines.append(f"v {p[0]:.6g} {p[1]:.6g} {p[2]:.6g}")
            lines.append(f"vt {s} {t}")
        a, b, cc, d = n, n + 1, n + 2, n + 3
        lines.append(f"f {a}/{a} {b}/{b} {cc}/{cc}")
        lines.append(f"f {a}/{a} {cc}/{cc} {d}/{d}")
        n += 4
    return lines, n


def satellite_panels_obj() -> str:
    """Two 7 x 2.4 panels on either side of a body of radius 1.2 along z (body not included), and a strut."""
    parts = [
        box_quads(center=[0.0, 5.1, 0.0], size=[0.16, 7.0, 2.4]),
        box_quads(center=[0.0, -5.1, 0.0], size=[0.16, 7.0, 2.4]),
        box_quads(center=[0.0, 0.0, 0.0], size=[0.2, 3.2, 0.2]),
    ]
    lines = ["# satellite solar panels and strut (tools/make_scene_assets.py); body axis along z, radius 1.2"]
    n = 1
    for quads in parts:
        body, n = box_obj_lines(quads, n)
        lines += body
    return "\n".join(lines) + "\n"


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=ROOT / "scenes", help="scenes folder (default: the repository's)")
    args = ap.parse_args(argv)
    write_png(args.out / "textures" / "accretion_disk.png", accretion_disk(width=256, height=64, seed=3))
    mesh = args.out / "meshes" / "satellite_panels.obj"
    mesh.parent.mkdir(parents=True, exist_ok=True)
    mesh.write_text(satellite_panels_obj())
    print(f"wrote {args.out / 'textures' / 'accretion_disk.png'} and {mesh}")


if __name__ == "__main__":
    main()
