"""``warpviz trace``: render a scene and save the sampled light paths of chosen pixels as ``.vtp``.
"""

from __future__ import annotations

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
    _aovs_for,
    _check_paper,
    _error_summary,
    _fail,
    _guard,
    _keep_aovs,
    _look,
    _output_path,
    _parse_pixels,
    _render_scene,
    _samples_summary,
    _stop_code,
    _stop_word,
    _stoppable,
    err,
)
from warpviz.limits import MAX_SPP
from warpviz.scene import load_scene


@app.command()
def trace(
    scene: str = typer.Argument(..., help="Scene file (.toml) or shipped scene name."),
    pixels: list[str] = typer.Option(
        ..., "--pixels", "-p",
        help="Pixel X,Y whose light paths are recorded; repeat the option or give several separated by spaces.",
    ),  # fmt: skip
    output: Path = typer.Option(
        Path("rays.vtp"), "--output", "-o", help="VTK PolyData file (.vtp) for the recorded paths."
    ),
    image: Optional[Path] = typer.Option(None, "--image", help="Also save the rendered image (.png or .exr)."),
    spp: Optional[int] = typer.Option(None, "--spp", min=1, max=MAX_SPP, help="Samples per pixel (default: the scene's)."),
    size: Optional[str] = flags.SIZE,
    threads: int = flags.THREADS,
    seed: Optional[int] = flags.SEED,
    flat: bool = flags.FLAT,
    paper: bool = flags.PAPER,
    exposure: Optional[float] = flags.EXPOSURE,
    tonemap: Optional[str] = flags.TONEMAP,
    workers: Optional[int] = flags.WORKERS,
    cluster: Optional[str] = flags.CLUSTER,
    tile: Optional[int] = flags.TILE,
    force: bool = flags.FORCE,
    quiet: bool = flags.QUIET,
) -> None:
    """Render a scene and save the sampled light paths of chosen pixels as a .vtp file."""
    with _guard(), _stoppable():
        sc = load_scene(scene)
        _check_paper(sc, paper)
        look = _look(sc, exposure=exposure, tonemap=tonemap)
        record = _parse_pixels(pixels)
        width, height = size if size is not None else sc.size(paper=paper)
        outside = [(int(x), int(y)) for x, y in record if not (x < width and y < height)]
        if outside:
            _fail(f"pixel {outside[0][0]},{outside[0][1]} is outside the {width}x{height} image", EXIT_BAD_INPUT)
        target = _output_path(output, (".vtp",), force=force)
        picture = _output_path(image, IMAGE_SUFFIXES, force=force) if image is not None else None
        common._renderer()
        with common._cluster(workers, cluster, tile) as client, \
                common._progress_bar("tracing", enabled=not quiet) as progress:
            img = _render_scene(sc, spp=spp, size=size, seed=seed, threads=threads, flat=flat, paper=paper,
                                light_sampling=None, progress=progress, record_pixels=record,
                                aovs=_aovs_for(picture, sc), client=client, tile=tile)  # fmt: skip
        rays = getattr(img, "rays", None)
        if rays is None:
            _fail("the renderer returned no recorded rays")
        rays.save(target)
        if picture is not None:
            if picture.suffix.lower() == ".exr":
                _keep_aovs(img, sc.outputs.get("aovs"))
            img.save(picture, **look)
        written = f"{target} ({len(record)} pixels)" + (f" and {picture}" if picture else "")
        if not getattr(img, "completed", True):
            h, w = np.shape(img.rgb)[:2]
            err.print(Text(f"{_stop_word()}: saved the partial paths and image ({w}x{h}{_samples_summary(img)}, "
                           f"{_error_summary(img)}) to {written}", style="yellow"))  # fmt: skip
            raise typer.Exit(_stop_code())
        err.print(f"wrote {written}")
