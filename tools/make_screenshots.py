"""Write the teaching view's screenshots for the docs into docs/images/ (off-screen, no display needed).

Usage: ``python tools/make_screenshots.py [--only fig04 ...] [--out FOLDER] [--size WxH] [--spp N]``. Each shot is
the view of ``warpviz view SCENE`` with the flags in :data:`SHOTS` (its command is printed), with the
preview rendered at :data:`SPP` samples per pixel instead of the window's first 4, so a still picture
looks like the refined image a window shows after a few seconds.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
IMAGES = ROOT / "docs" / "images"

#: Samples per pixel of each screenshot's preview render.
SPP = 32

#: Window size (width, height) of the screenshots.
WINDOW = (1400, 700)

#: Shot name -> (scene, keyword options of warpviz.view, the same as ``warpviz view`` flags).
SHOTS = {
    "fig04": ("fig04", {"pixels": [[20, 36]], "show_flat": True}, "--pixels 20,36 --flat-ray"),
    "fig07": ("fig07", {"show_flat": True}, "--flat-ray"),
    "fig10d": ("fig10d", {}, ""),
    "wormhole": ("fig13", {"show_flat": True}, "--flat-ray"),
}


def _size(text: str) -> tuple[int, int]:
    try:
        width, height = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected WIDTHxHEIGHT, e.g. 1400x700, got {text!r}") from None
    if width < 100 or height < 100:
        raise argparse.ArgumentTypeError(f"the window must be at least 100x100, got {text!r}")
    return width, height


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", nargs="*", default=None, choices=list(SHOTS), help="shots to make (default: all)")
    parser.add_argument("--out", type=Path, default=IMAGES, help="folder to write into (default: docs/images)")
    parser.add_argument("--size", type=_size, default=WINDOW, help="window size WxH (default: 1400x700)")
    parser.add_argument("--spp", type=int, default=SPP, help=f"samples per pixel of the previews (default: {SPP})")
    args = parser.parse_args(argv)
    if args.spp < 1:
        parser.error(f"--spp must be at least 1, got {args.spp}")

    import warpviz as wv

    args.out.mkdir(parents=True, exist_ok=True)
    for name, (scene, options, flags) in SHOTS.items():
        if args.only is not None and name not in args.only:
            continue
        t0 = time.perf_counter()
        path = args.out / f"view_{name}.png"
        wv.view(scene, off_screen=True, screenshot=path, window_size=args.size, spp=args.spp, **options)
        command = f"warpviz view {scene} {flags}".strip()
        print(f"{path.name}: {command} ({time.perf_counter() - t0:.1f} s)", file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
