"""Render every shipped scene at its default size into docs/gallery/ and rewrite the gallery table in
README.md (between the ``<!-- gallery -->`` markers).

Usage: ``python tools/make_gallery.py [--spp N] [--only fig07 ...]``. Each picture is rendered with the
same command the README shows for it, so the gallery is exactly what a user gets.
"""

from __future__ import annotations

import argparse
import re
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
GALLERY = ROOT / "docs" / "gallery"
START, END = "<!-- gallery -->", "<!-- /gallery -->"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--spp", type=int, default=None, help="samples per pixel (default: each scene's)")
    parser.add_argument("--only", nargs="*", default=None, help="scene names to render (default: all)")
    args = parser.parse_args(argv)

    import warpviz as wv
    from warpviz.scene.catalog import scene_description, shipped_scenes

    GALLERY.mkdir(parents=True, exist_ok=True)
    rows = []
    for path in shipped_scenes():
        name = path.stem
        short = name.split("_")[0]
        rel = path.relative_to(ROOT).as_posix()
        if args.only is None or short in args.only or name in args.only:
            t0 = time.perf_counter()
            img = wv.render(path, spp=args.spp)
            img.save(GALLERY / f"{short}.png")
            print(f"{short}: {img.shape[1]}x{img.shape[0]}, {img.metadata['spp']} spp, "
                  f"{time.perf_counter() - t0:.1f} s", file=sys.stderr)
        rows.append(f"| ![{short}](docs/gallery/{short}.png) | `warpviz render {rel} -o {short}.png` | "
                    f"{scene_description(path)} |")
    table = "\n".join(["| picture | command | what it shows |", "|---|---|---|", *rows])
    readme = ROOT / "README.md"
    text = readme.read_text()
    block = f"{START}\n{table}\n{END}"
    if START in text and END in text:
        text = re.sub(re.escape(START) + r".*?" + re.escape(END), lambda _: block, text, flags=re.S)
    else:
        text += f"\n## Gallery\n\nEvery figure of the paper as a shipped scene, rendered at its default size "
        text += f"(regenerate with `python tools/make_gallery.py`; add `--paper` to a command for paper size).\n\n"
        text += block + "\n"
    readme.write_text(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
