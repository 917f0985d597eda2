"""Through the wormhole: light rays that pass the throat of an Ellis wormhole come out in another universe.

A fan of parallel light rays in the equatorial plane approaches an Ellis wormhole of throat radius
b0 = 1. A ray's impact parameter b is its angular momentum, and the throat is the narrowest circle
(areal radius b0) light can pass through: rays with b < b0 cross to the other sheet, rays with b > b0
are deflected and stay on ours. The script prints the fate of each ray, renders what a camera near
the throat sees (the other universe's sky inside the throat, ours around it) with the paths of one
row of pixels recorded, and draws the rays on the wormhole's embedding diagram, our sheet above, the
other below.

Writes into ``examples/output/`` (or ``--out``):

* ``wormhole_fan.vtp``: the fan's paths (open in ParaView, or ``warpviz.view("wormhole_fan.vtp")``);
* ``wormhole_fan.png``: the fan on the embedding diagram;
* ``wormhole_image.png``: the rendered image;
* ``wormhole_view.png``: the teaching view of the render (image beside the recorded paths).

    python examples/through_the_wormhole.py --size 128x64 --spp 4
"""

from __future__ import annotations


import numpy as np

import warpviz as wv
from _args import example_parser

THROAT = 1.0


def wormhole_scene(width: int, height: int) -> dict:
    """A camera on our sheet looking at the throat; a starry blue sky here, a warm one on the other side."""
    return {
        "metric": {"name": "ellis", "params": [THROAT]},
        "camera": {"position": [0.0, -6.0, 0.0], "look_at": [0.0, 0.0, 0.0], "up": [0, 0, 1], "fov": 60.0,
                   "width": width, "height": height, "sheet": 1},
        "materials": [],
        "shapes": [],
        "environment": {"color": [0.05, 0.08, 0.2],
                        "stars": {"density": 3000.0, "brightness": 30.0, "size": 0.004, "seed": 1}},
        "environment_other": {"color": [0.6, 0.3, 0.08],
                              "stars": {"density": 3000.0, "brightness": 30.0, "size": 0.004, "seed": 2}},
    }


def main(argv=None) -> None:
    parser = example_parser(__doc__, size=(128, 64))
    parser.add_argument("--rays", type=int, default=13, help="rays in the fan (default 13)")
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)

    metric = wv.EllisWormhole(throat=THROAT)
    b = (np.arange(args.rays) + 0.5) * 2.5 / args.rays  # never b = b0 exactly, which would orbit the throat
    start = 30.0
    origins = np.column_stack([np.full_like(b, -start), b, np.zeros_like(b)])
    fan = wv.trace(metric, origins, [1.0, 0.0, 0.0], record=True, escape_radius=60.0)
    print(f"Ellis wormhole, throat b0 = {THROAT}: parallel rays with impact parameter b")
    print(f"{'b':>6}  {'ends on':<12}")
    for bi, sheet in zip(b, fan.final_sheets):
        print(f"{bi:6.2f}  {'other sheet' if sheet < 0 else 'our sheet':<12}")
    crossed = b[fan.final_sheets < 0]
    print(f"{crossed.size} rays crossed, the largest b among them {crossed.max() if crossed.size else 0:.2f}: "
          f"the throat lets through b < b0 = {THROAT}")
    fan.save(args.out / "wormhole_fan.vtp")
    wv.view(fan, off_screen=True, screenshot=args.out / "wormhole_fan.png", window_size=(900, 700))

    width, height = args.size
    columns = np.arange(0, width, max(1, width // 12))
    pixels = np.column_stack([columns, np.full_like(columns, height // 2)])  # a row through the throat
    img = wv.render(wormhole_scene(width, height), spp=args.spp, record_pixels=pixels)
    img.save(args.out / "wormhole_image.png")
    through = int(np.sum(img.rays.final_sheets < 0))
    print(f"rendered {width}x{height} at {args.spp} spp; {through} of the {len(img.rays)} recorded paths "
          "end on the other sheet")
    wv.view(img, off_screen=True, screenshot=args.out / "wormhole_view.png", pixels=[pixels[len(pixels) // 2]],
            show_flat=True)
    print(f"wrote {', '.join(sorted(p.name for p in args.out.glob('wormhole_*')))} to {args.out}")


if __name__ == "__main__":
    main()
