"""``warpviz render``: render a scene to PNG or EXR, with a time budget, a noise target or a resume.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Optional

import numpy as np
import typer
from rich.text import Text

from warpviz.cli import common, flags
from warpviz.cli.app import app
from warpviz.cli.common import (
    EXIT_BAD_INPUT,
    IMAGE_SUFFIXES,
    MAX_ERROR_FRACTION,
    _aovs_for,
    _check_errors,
    _check_paper,
    _checked,
    _error_summary,
    _fail,
    _guard,
    _keep_aovs,
    _look,
    _output_path,
    _parse_crop,
    _render_scene,
    _samples_summary,
    _stop_code,
    _stop_word,
    _stoppable,
    err,
)
from warpviz.limits import (
    MAX_EDGE_SAMPLES,
    MAX_SPP,
    duration_seconds,
    noise_level,
)
from warpviz.options import option_help
from warpviz.render.false_colour import FALSE_COLOUR_STYLES
from warpviz.render.render import OPTIONAL_AOVS
from warpviz.scene import load_scene


@app.command()
def render(
    scene: str = typer.Argument(..., help="Scene file (.toml) or shipped scene name, e.g. fig07."),
    output: Optional[Path] = typer.Option(
        None, "--output", "-o",
        help="Image to write: .png (tonemapped) or .exr (linear, with AOVs). "
        "Default: the scene's [outputs] file (inside the scene's folder or the working directory), "
        "else SCENE_NAME.png.",
    ),  # fmt: skip
    spp: Optional[int] = typer.Option(
        None, "--spp", min=1, max=MAX_SPP,
        help="Samples per pixel (default: the scene's; with --time or --noise alone: no limit). With --resume, the "
        "total, the image's own counted.",
    ),  # fmt: skip
    time_budget: Optional[str] = typer.Option(
        None, "--time",
        help="Time budget: seconds, or 90s, 2m, 1h30m. The render works in passes and stops when the next would "
        "not fit; the samples per pixel reached are printed and stored (the image equals a --spp render of "
        "them). With --spp or --noise: whichever comes first.",
    ),  # fmt: skip
    noise: Optional[float] = typer.Option(
        None, "--noise",
        help="Stop once the estimated relative noise (root mean variance of the pixel means over the mean radiance, "
        "lit pixels) is at most this, e.g. 0.02 for 2 %; checked after each pass.",
    ),  # fmt: skip
    resume: Optional[Path] = typer.Option(
        None, "--resume",
        help="Add passes to this EXR, which warpviz wrote for the same scene and settings (anything else is refused, "
        "naming what differs). Without -o the EXR itself is updated. The result equals one render of the total "
        "samples to float32 rounding.",
    ),  # fmt: skip
    size: Optional[str] = flags.SIZE,
    crop: Optional[str] = typer.Option(
        None, "--crop", callback=_parse_crop,
        help="Render only the window X,Y,WIDTHxHEIGHT of the image (top-left pixel and size), e.g. "
        "0,0,640x480. Windows that tile the image hold exactly its pixels: a way to render an image "
        "larger than memory in parts.",
    ),  # fmt: skip
    threads: int = flags.THREADS,
    seed: Optional[int] = flags.SEED,
    flat: bool = flags.FLAT,
    paper: bool = flags.PAPER,
    no_light_sampling: bool = typer.Option(
        False, "--no-light-sampling", help="Brute-force path tracing: light_sampling off. " + option_help("light_sampling")
    ),
    light_connection: Optional[str] = typer.Option(None, "--light-connection", help=option_help("light_connection")),
    edge_samples: Optional[int] = typer.Option(
        None, "--edge-samples", min=1, max=MAX_EDGE_SAMPLES, help=option_help("edge_samples")
    ),
    detail_samples: Optional[int] = typer.Option(
        None, "--detail-samples", min=1, max=MAX_EDGE_SAMPLES, help=option_help("detail_samples")
    ),
    guide_training: Optional[int] = typer.Option(
        None, "--guide-training", min=0, max=256, help=option_help("guide_training")
    ),
    photons: Optional[int] = typer.Option(None, "--photons", min=0, max=10**8, help=option_help("photons")),
    photons_per_pixel: Optional[float] = typer.Option(
        None, "--photons-per-pixel", min=0.0, max=1e3, help=option_help("photons_per_pixel")
    ),
    max_error_fraction: float = typer.Option(
        MAX_ERROR_FRACTION, "--max-error-fraction", min=0.0, max=1.0,
        help="Exit with code 3 when more than this fraction of the samples failed (a geodesic ran out of "
        "steps, broke a conservation law or became nan); the image is still written.",
    ),  # fmt: skip
    exposure: Optional[float] = flags.EXPOSURE,
    tonemap: Optional[str] = flags.TONEMAP,
    denoise: bool = typer.Option(
        False, "--denoise",
        help="Denoise with Intel Open Image Denoise (pip install 'warpviz[denoise]'), fed with the albedo and "
        "normal at each path's first non-specular hit; the light a path met before that hit (lamps, stars) is "
        "kept out of the denoiser and added back. A PNG shows the denoised image; an EXR keeps the "
        "unbiased radiance as R, G, B and adds the denoised one as the layer denoised.R/G/B.",
    ),  # fmt: skip
    false_colour: Optional[str] = typer.Option(
        None, "--false-colour",
        help=f"Write a false-colour PNG of this AOV ({', '.join(FALSE_COLOUR_STYLES)}) with a colour bar "
        "naming the quantity and its range, instead of the tonemapped picture.",
    ),  # fmt: skip
    workers: Optional[int] = flags.WORKERS,
    cluster: Optional[str] = flags.CLUSTER,
    tile: Optional[int] = flags.TILE,
    force: bool = flags.FORCE,
    quiet: bool = flags.QUIET,
) -> None:
    """Render a scene to a PNG or EXR image.

    Ctrl-C (exit 130) or SIGTERM (exit 143) stops early and saves the finished passes (an EXR of them can be
    resumed with --resume); exit 3 means too many samples failed (see --max-error-fraction).
    """
    with _guard(), _stoppable():
        seconds_budget = _checked("--time", duration_seconds, time_budget)
        noise_target = _checked("--noise", noise_level, noise)
        if resume is not None:
            if resume.suffix.lower() != ".exr" or not resume.is_file():
                _fail(f"--resume {str(resume)!r} must be an existing .exr file that warpviz wrote", EXIT_BAD_INPUT)
            if output is None:
                output = resume  # the image is continued in place
        sc = load_scene(scene)
        _check_paper(sc, paper)
        look = _look(sc, exposure=exposure, tonemap=tonemap)
        chosen = output is None and sc.outputs.get("file") is not None
        target = output or Path(sc.outputs.get("file") or f"{sc.path.stem if sc.path else 'scene'}.png")
        target = _output_path(target, IMAGE_SUFFIXES, force=force, scene=sc if chosen else None)
        aovs = None if resume is not None else _aovs_for(target, sc)  # a resumed image keeps its own
        if false_colour is not None:
            if false_colour not in FALSE_COLOUR_STYLES:
                _fail(f"--false-colour must be one of {', '.join(FALSE_COLOUR_STYLES)}, got {false_colour!r}",
                      EXIT_BAD_INPUT)  # fmt: skip
            if target.suffix.lower() != ".png":
                _fail(f"--false-colour writes a PNG picture: give -o NAME.png, not {str(target)!r}", EXIT_BAD_INPUT)
            aovs = [false_colour] if false_colour in OPTIONAL_AOVS else []
        common._renderer()
        t0 = time.perf_counter()
        bar = {"seconds": seconds_budget} if seconds_budget is not None else {}  # a stand-in bar need not know it
        with common._cluster(workers, cluster, tile) as client, \
                common._progress_bar(sc.path.stem if sc.path else "scene", enabled=not quiet, **bar) as progress:
            img = _render_scene(sc, spp=spp, size=size, seed=seed, threads=threads, flat=flat, paper=paper,
                                light_sampling=False if no_light_sampling else None, progress=progress,
                                light_connection=light_connection, crop=crop, aovs=aovs,
                                denoise=denoise, edge_samples=edge_samples, detail_samples=detail_samples,
                                guide_training=guide_training, photons=photons, photons_per_pixel=photons_per_pixel,
                                time_limit=seconds_budget,
                                noise_target=noise_target, resume=resume, client=client, tile=tile)  # fmt: skip
        if target.suffix.lower() == ".exr":
            _keep_aovs(img, sc.outputs.get("aovs"))
        if false_colour is not None:
            img.false_colour(false_colour).save(target, metadata=img.metadata)
        else:
            img.save(target, **look)
        seconds = time.perf_counter() - t0
        h, w = np.shape(img.rgb)[:2]
        if not getattr(img, "completed", True):
            err.print(Text(f"{_stop_word()}: saved the partial image ({w}x{h}{_samples_summary(img)}, "
                           f"{_error_summary(img)}) to {target}", style="yellow"))  # fmt: skip
            raise typer.Exit(_stop_code())
        err.print(f"wrote {target} ({w}x{h}{_samples_summary(img)}, {seconds:.1f} s, {_error_summary(img)})")
        _check_errors(img, max_error_fraction, target)
