"""Bent rays around a black hole: what a camera sees of a lit grid behind a Schwarzschild black hole.

The camera looks at a black hole of mass M = 1 in front of a glowing grid and a star field. Light from
the grid bends around the hole, so the grid appears pulled around a black disc (the shadow, 2.6 times
wider than the horizon) and a thin ring of light from behind it (the Einstein ring). The paths of one
row of pixels are recorded: the script prints how far each camera ray turned and saves the paths and
a teaching-view screenshot, with the pixel closest to the shadow's edge selected and its straight
flat-space ray drawn beside the bent one.

Writes into ``examples/output/`` (or ``--out``):

* ``black_hole_image.png``: the rendered image;
* ``black_hole_rays.vtp``: the recorded paths (ParaView, or ``warpviz.view("black_hole_rays.vtp")``);
* ``black_hole_view.png``: the teaching view.

    python examples/bent_rays_black_hole.py --size 160x80 --spp 4
"""

from __future__ import annotations


import numpy as np

import warpviz as wv
from _args import example_parser


def black_hole_scene(width: int, height: int) -> dict:
    """Camera 25 M from a Schwarzschild hole; an emissive grid 15 M behind it; stars all around."""
    return {
        "metric": {"name": "schwarzschild", "params": [1.0]},
        "camera": {"position": [0.0, -25.0, 0.0], "look_at": [0.0, 0.0, 0.0], "up": [0, 0, 1], "fov": 50.0,
                   "width": width, "height": height},
        "textures": [{"type": "grid", "base": [0.02, 0.03, 0.08], "line_u": [1.0, 0.75, 0.3],
                      "line_v": [0.35, 0.7, 1.0], "cells": [16, 8], "width": 0.08}],
        "materials": [{"type": "emissive", "texture": 0, "strength": 1.0, "two_sided": True}],
        "shapes": [{"type": "quad", "corner": [-40.0, 15.0, -20.0], "edge_u": [80.0, 0.0, 0.0],
                    "edge_v": [0.0, 0.0, 40.0], "material": 0}],
        "environment": {"color": [0.0, 0.0, 0.0],
                        "stars": {"density": 3000.0, "brightness": 30.0, "size": 0.003, "seed": 7}},
    }


def turning_angle(path: np.ndarray) -> float:
    """Angle in degrees between the first and last chord of a recorded path (P, 3)."""
    if len(path) < 3:
        return 0.0
    a, b = path[1] - path[0], path[-1] - path[-2]
    cos = float(a @ b) / (np.linalg.norm(a) * np.linalg.norm(b))
    return float(np.degrees(np.arccos(np.clip(cos, -1.0, 1.0))))


def main(argv=None) -> None:
    parser = example_parser(__doc__, size=(160, 80))
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)

    width, height = args.size
    row = height // 2
    columns = np.arange(0, width, max(1, width // 16))
    pixels = np.column_stack([columns, np.full_like(columns, row)])
    img = wv.render(black_hole_scene(width, height), spp=args.spp, record_pixels=pixels)
    img.save(args.out / "black_hole_image.png")
    rays = img.rays
    rays.save(args.out / "black_hole_rays.vtp")

    print(f"rendered {width}x{height} at {args.spp} spp: {len(rays)} geodesic segments recorded "
          f"for {len(pixels)} pixels of row {row}")
    print(f"{'pixel x':>7}  {'camera ray':<10} {'turned (deg)':>12}")
    camera_rays = np.flatnonzero((rays.ray_data["sample"] == 0) & (rays.ray_data["bounce"] == 0))
    for i in camera_rays:
        print(f"{rays.ray_data['pixel_x'][i]:7d}  {rays.status_names[i]:<10} {turning_angle(rays.ray_points(i)):12.2f}")

    # the recorded pixel nearest the centre whose camera ray got past the hole: the most bent one
    status = img.aovs["status"][row, columns]
    outside = columns[status != int(wv.RayStatus.HORIZON)]
    chosen = outside[np.argmin(np.abs(outside + 0.5 - width / 2))] if outside.size else columns[0]
    wv.view(img, off_screen=True, screenshot=args.out / "black_hole_view.png", pixels=[[chosen, row]], show_flat=True)
    print(f"selected pixel ({chosen}, {row}); wrote black_hole_image.png, black_hole_rays.vtp, black_hole_view.png "
          f"to {args.out}")


if __name__ == "__main__":
    main()
