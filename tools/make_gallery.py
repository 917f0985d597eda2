"""Render every shipped scene into docs/gallery/ and rewrite the gallery table in README.md (between the
``<!-- gallery -->`` markers).

Usage: ``python tools/make_gallery.py [--quality ci|classroom] [--spp N] [--denoise] [--only fig07 ...]``.

Qualities (:data:`QUALITIES`):

* ``ci`` (default): each scene at its own default size and samples (96x72, a few seconds each): what CI
  renders and the README shows today.
* ``classroom``: 640x480, 64 samples per pixel, and the rooms (scenes with diffuse surfaces lit by
  emitters, whose indirect light is the noisy part) at 1024, so a class can read them on a projector.
  Hours on a laptop; not for CI. ``--denoise`` adds Intel Open Image Denoise (``warpviz[denoise]``).

Each picture is rendered with the same command the README shows for it (the command line's defaults and
the scene's ``[outputs]`` tonemap and exposure), so the gallery is exactly what a user gets; at classroom
quality the table also gives each picture's render time on the machine that made it.
"""

from __future__ import annotations

import argparse
import os
import platform
import re
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
GALLERY = ROOT / "docs" / "gallery"
START, END = "<!-- gallery -->", "<!-- /gallery -->"

#: Render settings per quality: image size (None: the scene's), samples per pixel of the scenes and of the
#: rooms (None: the scene's), and whether the rooms are denoised unless ``--denoise`` says so.
QUALITIES = {
    "ci": {"size": None, "spp": None, "room_spp": None, "denoise": False},
    "classroom": {"size": (640, 480), "spp": 64, "room_spp": 1024, "denoise": False},
}


def _machine() -> str:
    """The CPU model and core count, e.g. ``"AMD EPYC 7B13 (2 cores)"``."""
    model = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return f"{model} ({os.cpu_count()} cores)"


def is_room(scene) -> bool:
    """A scene whose diffuse surfaces are lit by emitters: its indirect light needs many samples."""
    materials = scene.native()["materials"]
    diffuse = any(m["type"] == "diffuse" for m in materials)
    lit = any(m["type"] == "emissive" or any(m.get("emission", (0, 0, 0))) for m in materials)
    return diffuse and lit


def settings(scene, quality: str, *, spp: int | None, denoise: bool | None) -> dict:
    """The render's size, spp and denoise for ``scene`` at ``quality`` (``spp``, ``denoise``: overrides)."""
    q = QUALITIES[quality]
    room = is_room(scene)
    chosen = spp if spp is not None else (q["room_spp"] if room else q["spp"])
    return {"size": q["size"], "spp": chosen, "denoise": bool(q["denoise"] if denoise is None else denoise)}


def command(rel: str, short: str, s: dict) -> str:
    """The ``warpviz render`` command that makes the picture with settings ``s``."""
    parts = [f"warpviz render {rel}"]
    if s["size"] is not None:
        parts.append(f"--size {s['size'][0]}x{s['size'][1]}")
    if s["spp"] is not None:
        parts.append(f"--spp {s['spp']}")
    if s["denoise"]:
        parts.append("--denoise")
    parts.append(f"-o {short}.png")
    return " ".join(parts)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quality", choices=list(QUALITIES), default="ci",
                        help="ci: each scene's own size and samples (default); classroom: 640x480, rooms at 1024 spp")
    parser.add_argument("--spp", type=int, default=None, help="samples per pixel of every scene (overrides the quality's)")
    parser.add_argument("--denoise", action=argparse.BooleanOptionalAction, default=None,
                        help="denoise with Intel Open Image Denoise (needs warpviz[denoise]; default: the quality's)")
    parser.add_argument("--only", nargs="*", default=None, help="scene names to render (default: all)")
    args = parser.parse_args(argv)
    if args.spp is not None and args.spp < 1:
        parser.error(f"--spp must be a positive integer, got {args.spp}")

    import warpviz as wv
    from warpviz.scene import load_scene
    from warpviz.scene.catalog import scene_description, shipped_scenes

    if args.denoise:
        from warpviz.render.denoise import require_denoiser

        require_denoiser()  # before hours of rendering
    GALLERY.mkdir(parents=True, exist_ok=True)
    timing = args.quality != "ci"
    rows = []
    for path in shipped_scenes():
        name = path.stem
        short = name.split("_")[0]
        rel = path.relative_to(ROOT).as_posix()
        scene = load_scene(path)
        s = settings(scene, args.quality, spp=args.spp, denoise=args.denoise)
        seconds = None
        if args.only is None or short in args.only or name in args.only:
            width, height = s["size"] if s["size"] is not None else (None, None)
            t0 = time.perf_counter()
            img = wv.render(scene, spp=s["spp"], width=width, height=height, aovs=[], denoise=s["denoise"])
            seconds = time.perf_counter() - t0
            img.save(GALLERY / f"{short}.png", tonemap=scene.outputs.get("tonemap"),
                     exposure=scene.outputs.get("exposure"))  # fmt: skip
            print(f"{short}: {img.shape[1]}x{img.shape[0]}, {img.metadata['spp']} spp, {seconds:.1f} s",
                  file=sys.stderr)
        row = f"| ![{short}](docs/gallery/{short}.png) | `{command(rel, short, s)}` | {scene_description(path)} |"
        if timing:
            row += f" {seconds:.0f} s |" if seconds is not None else " – |"
        rows.append(row)
    header = ["| picture | command | what it shows |", "|---|---|---|"]
    if timing:
        header = ["| picture | command | what it shows | render time |", "|---|---|---|---|"]
    table = "\n".join([*header, *rows])
    if timing:
        table += f"\n\nRender times on {_machine()}, every core."
    readme = ROOT / "README.md"
    text = readme.read_text()
    block = f"{START}\n{table}\n{END}"
    if START in text and END in text:
        text = re.sub(re.escape(START) + r".*?" + re.escape(END), lambda _: block, text, flags=re.S)
    else:
        text += "\n## Gallery\n\nEvery figure of the paper as a shipped scene, rendered at its default size "
        text += "(regenerate with `python tools/make_gallery.py`; add `--paper` to a command for paper size).\n\n"
        text += block + "\n"
    readme.write_text(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
