"""Frame dragging: a spinning black hole bends light on its two sides differently.

A fan of parallel light rays crosses the equatorial plane of a Kerr black hole (spin a = 0.9 M about
+z) and, for comparison, of a non-spinning Schwarzschild hole and of one spinning the other way. Rays
moving with the rotation (prograde) can pass closer before they are captured than rays moving against
it (retrograde), so the captured band of impact parameters is lopsided: from about 2.84 M on the
prograde side to 6.83 M on the retrograde side, against 5.20 M on both sides without spin. The
rendered shadow is flattened on the prograde side for the same reason.

Writes into ``examples/output/`` (or ``--out``):

* ``kerr_fan.vtp``: the a = 0.9 fan's paths (ParaView, or ``warpviz.view("kerr_fan.vtp")``);
* ``kerr_fan.png``: the a = 0.9 fan coloured by conserved-quantity error, the Schwarzschild fan in grey;
* ``kerr_image.png``: the rendered shadow of the a = 0.9 hole in front of a grid;
* ``kerr_view.png``: the teaching view of that render.

    python examples/frame_dragging_kerr.py --size 128x64 --spp 4
"""

from __future__ import annotations


import numpy as np

import warpviz as wv
from _args import example_parser

SPIN = 0.9
START = 40.0  # the fan starts at x = -START, far enough for y to be the impact parameter to ~3 %


def equatorial_critical_b(metric) -> tuple[float, float]:
    """Impact parameters (signed y of the fan below) of the prograde and retrograde circular photon orbits.

    The equatorial circular photon orbit at Boyer-Lindquist radius r has L/E = -(r^3 - 3Mr^2 + a^2 r + a^2 M)
    / (a (r - M)); a ray at height y moving along +x has L_z = -y E, hence y = -L/E.
    """
    if not isinstance(metric, wv.Kerr) or metric.a == 0.0:
        b = 3.0 * np.sqrt(3.0) * metric.mass
        return -b, b
    m, a = metric.mass, metric.a
    ys = []
    for r in metric.photon_orbit_radii:
        ys.append((r**3 - 3 * m * r**2 + a * a * r + a * a * m) / (a * (r - m)))
    return min(ys), max(ys)


def fan(metric, ys: np.ndarray):
    """Parallel rays moving along +x in the plane z = 0, at heights y."""
    origins = np.column_stack([np.full_like(ys, -START), ys, np.zeros_like(ys)])
    return wv.trace(metric, origins, [1.0, 0.0, 0.0], record=True, escape_radius=1.5 * START)


def shadow_scene(width: int, height: int) -> dict:
    """The a = 0.9 hole seen from its equatorial plane, in front of a glowing grid."""
    return {
        "metric": {"name": "kerr", "params": [1.0, SPIN]},
        "camera": {"position": [0.0, -25.0, 0.0], "look_at": [0.0, 0.0, 0.0], "up": [0, 0, 1], "fov": 40.0,
                   "width": width, "height": height},
        "textures": [{"type": "grid", "base": [0.02, 0.03, 0.08], "line_u": [1.0, 0.75, 0.3],
                      "line_v": [0.35, 0.7, 1.0], "cells": [16, 8], "width": 0.08}],
        "materials": [{"type": "emissive", "texture": 0, "strength": 1.0, "two_sided": True}],
        "shapes": [{"type": "quad", "corner": [-40.0, 15.0, -20.0], "edge_u": [80.0, 0.0, 0.0],
                    "edge_v": [0.0, 0.0, 40.0], "material": 0}],
        "environment": {"color": [0.0, 0.0, 0.0]},
    }


def main(argv=None) -> None:
    parser = example_parser(__doc__, size=(128, 64))
    parser.add_argument("--rays", type=int, default=41, help="rays in each fan (default 41)")
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)

    ys = np.linspace(-10.0, 10.0, args.rays)
    step = ys[1] - ys[0] if len(ys) > 1 else 0.0
    print(f"fans of {len(ys)} parallel rays from x = -{START:g} M along +x at heights y = -10 ... 10 M "
          f"(spacing {step:.2f} M);")
    print("y < 0 passes the hole moving with a positive spin (prograde)")
    print(f"{'hole':<22} {'captured y (measured)':>22} {'prediction':>18}")
    fans = {}
    holes = [(f"Kerr a = +{SPIN}", wv.Kerr(mass=1.0, spin=SPIN)), ("Schwarzschild", wv.Schwarzschild(mass=1.0)),
             (f"Kerr a = -{SPIN}", wv.Kerr(mass=1.0, spin=-SPIN))]  # fmt: skip
    for name, metric in holes:
        rays = fan(metric, ys)
        fans[name] = rays
        captured = ys[rays.status == int(wv.RayStatus.HORIZON)]
        lo, hi = equatorial_critical_b(metric)
        measured = f"{captured.min():+.2f} ... {captured.max():+.2f}" if captured.size else "none"
        print(f"{name:<22} {measured:>22} {lo:+8.2f} ... {hi:+.2f}")

    kerr_fan = fans[f"Kerr a = +{SPIN}"]
    kerr_fan.save(args.out / "kerr_fan.vtp")
    plotter = wv.view(kerr_fan, off_screen=True, return_plotter=True, window_size=(900, 700))
    try:
        plotter.add_mesh(fans["Schwarzschild"].to_pyvista(), color="gray", opacity=0.6, line_width=1,
                         pickable=False, name="schwarzschild_fan")  # fmt: skip
        view = plotter.teaching_view
        view.set_title(f"Kerr a = {SPIN} (coloured, spin +z: counter-clockwise) and Schwarzschild (grey)")
        view.frame([-20.0, 20.0, -20.0, 20.0, -1.0, 1.0])  # the view holds the whole fan; look closer at the hole
        wv.atomic_write(args.out / "kerr_fan.png", lambda tmp: plotter.screenshot(str(tmp)))
    finally:
        plotter.close()

    width, height = args.size
    columns = np.arange(0, width, max(1, width // 16))
    pixels = np.column_stack([columns, np.full_like(columns, height // 2)])  # the equatorial row
    img = wv.render(shadow_scene(width, height), spp=args.spp, record_pixels=pixels)
    img.save(args.out / "kerr_image.png")
    shadow = img.aovs["status"][height // 2] == int(wv.RayStatus.HORIZON)
    if shadow.any():
        left, right = np.flatnonzero(shadow)[[0, -1]]
        print(f"rendered {width}x{height} at {args.spp} spp: the shadow spans pixels {left} to {right} of the "
              f"middle row, centre {0.5 * (left + right + 1):.1f} vs the image centre {width / 2:.1f}")
    wv.view(img, off_screen=True, screenshot=args.out / "kerr_view.png", pixels=[pixels[len(pixels) // 2 - 2]],
            show_flat=True)
    print(f"wrote kerr_fan.vtp, kerr_fan.png, kerr_image.png, kerr_view.png to {args.out}")


if __name__ == "__main__":
    main()
