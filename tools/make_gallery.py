"""Render every shipped scene into a gallery folder and rewrite the gallery table in README.md (between the
``<!-- gallery -->`` markers).

Usage: ``python tools/make_gallery.py [--quality ci|classroom|quick] [--only fig07 ...] [--spp N]
[--seconds S] [--room-seconds S] [--denoise/--no-denoise] [--out DIR] [--work DIR] [--readme FILE]``.

Qualities (:data:`QUALITIES`):

* ``classroom`` (default): 640x480 pictures a class can read on a projector, each with a time budget on
  the machine that makes it (the rooms, scenes with diffuse surfaces lit by emitters whose indirect light
  is the noisy part, 4 minutes and denoised: the lamps and stars seen directly, the ``emission`` AOV,
  are kept out of the denoiser, so they stay sharp; every other scene 1 minute), into
  ``docs/gallery/classroom``.
  About 50 minutes on 2 cores for the whole gallery.
* ``ci``: each scene at its own default size and samples (96x72, a few seconds each), into
  ``docs/gallery``: what CI renders.
* ``quick``: 32x24 with budgets of a second, into a folder of your choice: the smoke test of this tool.

Resumable, picture by picture: each picture's render is kept as an EXR in ``--work`` (default
``build/gallery-QUALITY``, not committed) with the seconds it has had. A run that is stopped (Ctrl-C,
SIGTERM, the end of a session) keeps the finished passes; the next run continues every picture from its
EXR with what is left of its budget, and skips the pictures that are done (a picture whose scene file has
changed since is rendered again). Each PNG, and the README table,
is written as soon as its picture is done, so a gallery can be built and committed picture by picture.
The table takes each picture's size, samples per pixel, noise and render time from the PNG's own metadata
and names the machine; a scene not yet rendered at the quality keeps its ``ci`` picture, marked as such.

Each picture is what the command in its row makes (the command line's defaults and the scene's
``[outputs]`` tonemap and exposure): the gallery is exactly what a user gets. Figures 5, 6 and 8 are shown
with the companion the paper gives them (:mod:`gallery_companions`: the undistorted star field with the
images marked, the undistorted swatch, the enlarged glass ball), the plain picture linked.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import re
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(Path(__file__).resolve().parent))
from gallery_companions import companion_path, make_companion  # noqa: E402

GALLERY = ROOT / "docs" / "gallery"
START, END = "<!-- gallery -->", "<!-- /gallery -->"

#: Render settings per quality: image size (None: the scene's), samples per pixel (None: the scene's, or
#: as many as the time budget allows), seconds per picture for the rooms and for the other scenes (None:
#: no budget), whether the rooms and the other scenes are denoised, and the folder the PNGs go to (None:
#: given with --out).
QUALITIES = {
    "ci": {"size": None, "spp": None, "seconds": None, "room_seconds": None, "denoise": False,
           "room_denoise": False, "out": GALLERY},
    "classroom": {"size": (640, 480), "spp": None, "seconds": 60.0, "room_seconds": 240.0, "denoise": False,
                  "room_denoise": True, "out": GALLERY / "classroom"},
    "quick": {"size": (32, 24), "spp": None, "seconds": 0.5, "room_seconds": 1.0, "denoise": False,
              "room_denoise": True, "out": None},
}  # fmt: skip

#: The rooms of the paper's figures 3, 7 and 10, shown as one row (same room, same framing: flat space,
#: then the black hole growing in spin), before the table.
ROOM_ROW = ("fig03", "fig07", "fig10a", "fig10b", "fig10c", "fig10d", "fig10e")


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


def short_name(path: Path) -> str:
    """A scene's picture name: its figure (``fig07``) or first word (``mitsuba``), or the whole stem for the
    line-element library (``line_element_kerr_newman``) and the caustic scenes (``caustics_glass_ball``), whose
    scenes share their first words."""
    return path.stem if path.stem.startswith(("line_element_", "caustics_")) else path.stem.split("_")[0]


def settings(scene, quality: str, *, spp: int | None = None, denoise: bool | None = None,
             seconds: float | None = None, room_seconds: float | None = None) -> dict:
    """The render's ``size``, ``spp``, ``seconds`` (time budget) and ``denoise`` for ``scene`` at
    ``quality``; the keyword arguments override the quality's (``spp`` replaces the time budget)."""
    q = QUALITIES[quality]
    room = is_room(scene)
    budget = (room_seconds if room_seconds is not None else q["room_seconds"]) if room else (
        seconds if seconds is not None else q["seconds"])  # fmt: skip
    chosen_spp = spp if spp is not None else q["spp"]
    if chosen_spp is not None:
        budget = None
    denoised = q["room_denoise"] if room else q["denoise"]
    return {"size": q["size"], "spp": chosen_spp, "seconds": budget,
            "denoise": bool(denoised if denoise is None else denoise)}  # fmt: skip


def _duration(seconds: float) -> str:
    """A budget as the command line takes it: ``'4m'``, ``'90'``, ``'0.5'``."""
    if seconds >= 60 and seconds % 60 == 0:
        return f"{int(seconds // 60)}m"
    return f"{seconds:g}"


def command(rel: str, short: str, s: dict) -> str:
    """The ``warpviz render`` command that makes the picture with settings ``s``."""
    parts = [f"warpviz render {rel}"]
    if s["size"] is not None:
        parts.append(f"--size {s['size'][0]}x{s['size'][1]}")
    if s["spp"] is not None:
        parts.append(f"--spp {s['spp']}")
    if s.get("seconds") is not None:
        parts.append(f"--time {_duration(s['seconds'])}")
    if s["denoise"]:
        parts.append("--denoise")
    parts.append(f"-o {short}.png")
    return " ".join(parts)


def png_metadata(path: Path) -> dict | None:
    """The ``warpviz`` metadata of a PNG the renderer wrote, or None."""
    if not path.is_file():
        return None
    from PIL import Image

    with Image.open(path) as im:
        text = im.info.get("warpviz")
    try:
        return json.loads(text) if text else None
    except json.JSONDecodeError:
        return None


def _done(meta: dict | None, s: dict) -> bool:
    """Whether a kept render (its metadata) has had all it is asked for: its samples, or its budget."""
    if meta is None or not meta.get("completed", False):
        return False
    if s["spp"] is not None:
        return meta.get("spp") == s["spp"]
    return meta.get("stopped_by") in ("time", "noise") and meta.get("time_limit") is not None


def _kept_problem(scene, prior, *, width, height, aovs: list[str]) -> str | None:
    """Why a kept render that has had its samples or budget is not what rendering ``scene`` today gives, or None.

    The renderer itself is asked (a resume to the image's own samples: no pass runs), so every setting and
    default it compares is compared here too: a default changed since the picture was rendered (say
    ``photon_aim``) makes it render again rather than keep a picture of the old settings.
    """
    import warpviz as wv

    try:
        wv.render(scene, resume=prior, spp=int(prior.metadata["spp"]), width=width, height=height, aovs=aovs)
    except ValueError as exc:
        if not str(exc).startswith("resume:"):
            raise
        return str(exc).removeprefix("resume:").strip()
    return None


def render_picture(scene, short: str, s: dict, *, out: Path, work: Path, log=print) -> dict:
    """Render (or continue, or reuse) one picture; write its EXR into ``work`` and its PNG into ``out``.

    A kept EXR is continued (or reused, when it has had its samples or budget) only while the scene is the
    one it was rendered from (the digest in its header) and today's settings would continue it (a default
    changed since: :func:`_kept_problem`); otherwise it is rendered again. Returns
    the PNG's metadata. An interruption keeps the finished passes in the EXR and propagates.
    """
    import warpviz as wv
    from warpviz.render.image import Image
    from warpviz.render.resume import saved_resume, scene_sha256

    width, height = s["size"] if s["size"] is not None else (None, None)
    aovs = ["albedo", "albedo_normal"] if s["denoise"] else []
    exr = work / f"{short}.exr"
    png = out / f"{short}.png"
    prior = None
    if exr.is_file():
        try:
            prior = Image.open(exr)
        except ValueError:
            prior = None
    if prior is not None and (saved_resume(prior.metadata).get("scene_sha256")
                              != scene_sha256(scene.native(width=width, height=height))):
        log(f"{short}: the scene has changed since {exr.name} was rendered; starting again")
        prior = None
    if prior is not None and _done(prior.metadata, s):
        problem = _kept_problem(scene, prior, width=width, height=height, aovs=aovs)
        if problem is not None:  # (a default changed since: the picture would not be today's render)
            log(f"{short}: the kept {exr.name} is not what today's settings render ({problem}); starting again")
            prior = None
    spent = float(prior.metadata.get("seconds") or 0.0) if prior is not None else 0.0
    if prior is not None and _done(prior.metadata, s) and png_metadata(png) is not None:
        log(f"{short}: done ({prior.metadata['spp']} spp, {spent:.0f} s), kept")
        companion = companion_path(out, short)
        if companion is not None and not companion.is_file():
            make_companion(short, scene, png, exr)
        return png_metadata(png)
    left = None if s["seconds"] is None else max(1e-3, s["seconds"] - spent)  # the first pass always runs
    kwargs = {"spp": s["spp"], "width": width, "height": height, "aovs": aovs, "denoise": s["denoise"]}
    if left is not None:
        kwargs["time_limit"] = left
    t0 = time.perf_counter()
    try:
        img = wv.render(scene, resume=exr if prior is not None else None, **kwargs)
    except ValueError as exc:
        if prior is None or not str(exc).startswith("resume:"):
            raise
        log(f"{short}: the kept {exr.name} does not fit these settings ({exc}); starting again")
        spent = 0.0
        if left is not None:
            kwargs["time_limit"] = s["seconds"]
        img = wv.render(scene, **kwargs)
    img.metadata["machine"] = _machine()  # (the table's render times name it: machines_line)
    img.save(exr)
    if not img.completed:
        raise KeyboardInterrupt
    img.save(png, tonemap=scene.outputs.get("tonemap"), exposure=scene.outputs.get("exposure"))
    make_companion(short, scene, png, exr)  # the paper's inset or side-by-side, where it has one
    meta = png_metadata(png)
    log(f"{short}: {img.shape[1]}x{img.shape[0]}, {img.metadata['spp']} spp, {img.metadata['seconds']:.0f} s "
        f"(this run {time.perf_counter() - t0:.0f} s)" + (", denoised" if img.denoised is not None else ""))
    return meta


def _row(short: str, rel: str, description: str, s: dict, meta: dict | None, pictures: Path, fallback: Path,
         readme: Path, timing: bool) -> str:
    """One table row: the picture (linked to the full-size file), its command, what it shows and, at a
    timed quality, size, samples, noise and render time from its metadata."""
    here = readme.parent
    png = pictures / f"{short}.png"
    companion = companion_path(pictures, short)
    if meta is not None:
        link = os.path.relpath(png, here)
        pic = f'<a href="{link}"><img src="{link}" width="320" alt="{short}"></a>' if timing else f"![{short}]({link})"
        if companion is not None and companion.is_file():
            shown = os.path.relpath(companion, here)
            pic = (f'<a href="{shown}"><img src="{shown}" width="320" alt="{short} with the paper\'s companion"></a> '
                   f"([the picture alone]({link}))")
    elif (fallback / f"{short}.png").is_file():
        link = os.path.relpath(fallback / f"{short}.png", here)
        pic = f"![{short}]({link}) (small preview: not rendered at this quality yet)"
    else:
        pic = "–"
    row = f"| {pic} | `{command(rel, short, s)}` | {description} |"
    if timing:
        if meta is None:
            row += " – |"
        else:
            noise = f", noise {100 * meta['noise']:.2g} %" if meta.get("noise") is not None else ""
            den = ", denoised" if meta.get("denoised") else ""
            row += f" {meta['width']}×{meta['height']}, {meta['spp']} spp{noise}{den}, {meta['seconds']:.0f} s |"
    return row


def _room_row(metas: dict, pictures: Path, readme: Path) -> str:
    """The rooms of figures 3, 7 and 10 side by side, where they are rendered."""
    cells = []
    for short in ROOM_ROW:
        if metas.get(short) is None:
            continue
        link = os.path.relpath(pictures / f"{short}.png", readme.parent)
        cells.append((short, f'<a href="{link}"><img src="{link}" width="200" alt="{short}"></a>'))
    if len(cells) < 2:
        return ""
    head = "| " + " | ".join(short for short, _ in cells) + " |"
    rule = "|" + "---|" * len(cells)
    body = "| " + " | ".join(cell for _, cell in cells) + " |"
    return ("The same room, framed alike: flat space (fig03), a Schwarzschild black hole (fig07), and Kerr "
            "black holes of growing spin at a fixed horizon radius (fig10a-e).\n\n" + "\n".join([head, rule, body]))


def machines_line(metas: dict) -> str:
    """The sentence under a timed table naming the machines its render times are from: each picture's own
    (``metadata["machine"]``, which :func:`render_picture` records; a picture from before it names none), the most
    common one first and the others with their pictures, e.g. ``"Render times on A (2 cores), every core (fig07 and
    fig10a on B (2 cores)); ..."``."""
    by: dict[str, list[str]] = {}
    for short, meta in metas.items():
        if meta is not None:
            by.setdefault(meta.get("machine") or "", []).append(short)
    named = sorted((m for m in by if m), key=lambda m: -len(by[m]))
    if not named:
        return "Render times on every core; each picture's full-size file is linked."

    def pictures(shorts: list[str]) -> str:
        return shorts[0] if len(shorts) == 1 else ", ".join(shorts[:-1]) + " and " + shorts[-1]

    others = [f"{pictures(by[m])} on {m}" for m in named[1:]]
    if "" in by:
        others.append(f"{pictures(by[''])}: machine not recorded")
    extra = f" ({'; '.join(others)})" if others else ""
    return f"Render times on {named[0]}, every core{extra}; each picture's full-size file is linked."


def write_table(rows: list[str], *, readme: Path, timing: bool, room_row: str, machines: str = "") -> None:
    """Put the gallery table between the README's markers (appending a Gallery section if it has none);
    ``machines``: the sentence naming where the render times come from (:func:`machines_line`)."""
    header = ["| picture | command | what it shows |", "|---|---|---|"]
    if timing:
        header = ["| picture | command | what it shows | size, samples, render time |", "|---|---|---|---|"]
    table = "\n".join([*header, *rows])
    if timing:
        table += "\n\n" + (machines or f"Render times on {_machine()}, every core; each picture's full-size file is "
                                        "linked.")
        if room_row:
            table = room_row + "\n\n" + table
    text = readme.read_text() if readme.is_file() else ""
    block = f"{START}\n{table}\n{END}"
    if START in text and END in text:
        text = re.sub(re.escape(START) + r".*?" + re.escape(END), lambda _: block, text, flags=re.S)
    else:
        text += "\n## Gallery\n\n" + block + "\n"
    readme.write_text(text)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quality", choices=list(QUALITIES), default="classroom",
                        help="classroom: 640x480, time budgets (default); ci: each scene's own size and samples; "
                        "quick: a smoke test")  # fmt: skip
    parser.add_argument("--spp", type=int, default=None, help="samples per pixel of every scene (instead of budgets)")
    parser.add_argument("--seconds", type=float, default=None, help="time budget of each scene that is not a room")
    parser.add_argument("--room-seconds", type=float, default=None, help="time budget of each room")
    parser.add_argument("--denoise", action=argparse.BooleanOptionalAction, default=None,
                        help="denoise every picture (default: the quality's: the rooms at classroom quality)")
    parser.add_argument("--only", nargs="*", default=None, help="scene names to render (default: all)")
    parser.add_argument("--out", type=Path, default=None, help="folder of the PNGs (default: the quality's)")
    parser.add_argument("--work", type=Path, default=None, help="folder of the EXRs kept to resume (default build/gallery-QUALITY)")
    parser.add_argument("--readme", type=Path, default=ROOT / "README.md", help="the file whose gallery table is rewritten")
    args = parser.parse_args(argv)
    if args.spp is not None and args.spp < 1:
        parser.error(f"--spp must be a positive integer, got {args.spp}")
    for flag, value in (("--seconds", args.seconds), ("--room-seconds", args.room_seconds)):
        if value is not None and not value > 0:
            parser.error(f"{flag} must be a positive number of seconds, got {value}")
    out = args.out or QUALITIES[args.quality]["out"]
    if out is None:
        parser.error(f"--quality {args.quality} needs --out (a folder for its pictures)")
    work = args.work or ROOT / "build" / f"gallery-{args.quality}"

    from warpviz.scene import load_scene
    from warpviz.scene.catalog import scene_description, shipped_scenes

    scenes = []
    for path in shipped_scenes():
        scene = load_scene(path)
        s = settings(scene, args.quality, spp=args.spp, denoise=args.denoise, seconds=args.seconds,
                     room_seconds=args.room_seconds)  # fmt: skip
        scenes.append((path, scene, s))
    if any(s["denoise"] for _, _, s in scenes):
        from warpviz.render.denoise import require_denoiser

        require_denoiser()  # before any rendering
    out.mkdir(parents=True, exist_ok=True)
    work.mkdir(parents=True, exist_ok=True)
    timing = QUALITIES[args.quality]["seconds"] is not None or args.spp is not None and args.quality != "ci"
    metas: dict[str, dict | None] = {}

    def rewrite() -> None:
        rows = []
        for path, _, s in scenes:
            short = short_name(path)
            rows.append(_row(short, path.relative_to(ROOT).as_posix(), scene_description(path), s,
                             metas.get(short), out, GALLERY, args.readme, timing))  # fmt: skip
        write_table(rows, readme=args.readme, timing=timing, room_row=_room_row(metas, out, args.readme),
                    machines=machines_line(metas))

    for path, _, _ in scenes:
        short = short_name(path)
        metas[short] = png_metadata(out / f"{short}.png")
    for path, scene, s in scenes:
        name = path.stem
        short = short_name(path)
        if args.only is not None and short not in args.only and name not in args.only:
            continue
        try:
            metas[short] = render_picture(scene, short, s, out=out, work=work,
                                          log=lambda m: print(m, file=sys.stderr))  # fmt: skip
        except KeyboardInterrupt:
            print(f"{short}: stopped; its finished passes are kept in {work / (short + '.exr')}: run again to "
                  "continue", file=sys.stderr)  # fmt: skip
            rewrite()
            return 130
        rewrite()
    rewrite()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
