"""``warpviz animate``: a film along a camera path (orbit, fall, dolly or keyframes), resumable.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Optional

import typer
from rich.text import Text

from warpviz.cli import common, flags
from warpviz.cli.app import app
from warpviz.cli.common import EXIT_BAD_INPUT, _checked, _fail, _guard, _look, _stop_code, _stop_word, _stoppable, err
from warpviz.limits import MAX_SPP, duration_seconds
from warpviz.scene import load_scene


@app.command()
def animate(
    scene: str = typer.Argument(..., help="Scene file (.toml) or shipped scene name, e.g. fig07."),
    path: str = typer.Option(
        "orbit", "--path",
        help="Camera path: orbit (a circular geodesic orbit through the camera, one revolution), fall (the "
        "camera's worldline from rest or as its observer moves; through a horizon), dolly (a straight line "
        "towards --to), or a keyframes .toml (docs/films.md).",
    ),  # fmt: skip
    frames: int = typer.Option(48, "--frames", min=1, max=100_000, help="Number of frames."),
    fps: float = typer.Option(24.0, "--fps", min=0.1, max=240.0, help="Frames per second of the video or GIF."),
    output: Path = typer.Option(
        ..., "--output", "-o",
        help="film.mp4 (pip install 'warpviz[film]'), film.gif, or a folder (no suffix) of frame_NNNNN.png/.exr. "
        "A video's frames are kept in NAME_frames/ beside it: run again to continue an interrupted film.",
    ),  # fmt: skip
    spp: Optional[int] = typer.Option(None, "--spp", min=1, max=MAX_SPP, help="Samples per pixel of each frame."),
    time_budget: Optional[str] = typer.Option(
        None, "--time", help="Time budget of each frame (90s, 2m); with --spp whichever comes first."
    ),
    duration: Optional[float] = typer.Option(
        None, "--duration", min=0.0, help="fall: proper time the film covers (units of M); default: to half the "
        "horizon radius, or through a wormhole to the same radius on the other side."
    ),
    look: str = typer.Option("target", "--look", help="target (the scene's look_at) or ahead (along the motion)."),
    to: Optional[str] = typer.Option(None, "--to", help="dolly: the end point X,Y,Z (default half-way to look_at)."),
    speed: Optional[float] = typer.Option(
        None, "--speed", min=0.0, max=0.999999, help="fall: launch the camera towards look_at at this speed (units of "
        "c): a flight, e.g. through a wormhole."
    ),
    position: Optional[str] = typer.Option(
        None, "--position", help="Start the path at X,Y,Z instead of the scene camera's position (e.g. an orbit's radius)."
    ),
    size: Optional[str] = flags.SIZE,
    threads: int = flags.THREADS,
    seed: Optional[int] = flags.SEED,
    exposure: Optional[float] = flags.EXPOSURE,
    tonemap: Optional[str] = flags.TONEMAP,
    denoise: bool = typer.Option(False, "--denoise", help="Denoise each frame (pip install 'warpviz[denoise]')."),
    workers: Optional[int] = flags.WORKERS,
    cluster: Optional[str] = flags.CLUSTER,
    tile: Optional[int] = flags.TILE,
    force: bool = flags.FORCE,
    quiet: bool = flags.QUIET,
) -> None:
    """Render a film of a scene along a camera path.

    Each frame is a render of its own (seed from the scene's and the frame's number), so a film is the same
    whatever is interrupted and continued: frames already in the frames folder are not rendered again.
    Ctrl-C (exit 130) or SIGTERM (exit 143) keeps every finished frame.
    """
    from warpviz.animate import FILM_SUFFIXES, FilmMismatch, camera_path, frames_folder, render_film

    with _guard(), _stoppable():
        seconds = _checked("--time", duration_seconds, time_budget)
        end, start = _point("--to", to), _point("--position", position)
        if output.suffix and output.suffix.lower() not in FILM_SUFFIXES:
            _fail(f"-o {str(output)!r}: a film is {', '.join(FILM_SUFFIXES)} or a folder (no suffix)", EXIT_BAD_INPUT)
        if output.suffix and output.exists() and not (frames_folder(output) / "film.json").exists() and not force:
            _fail(f"-o {str(output)!r} exists and is not a film warpviz animate wrote (no {frames_folder(output).name}/"
                  "film.json beside it); --force replaces it", EXIT_BAD_INPUT)  # fmt: skip
        sc = load_scene(scene)
        look_png = _look(sc, exposure=exposure, tonemap=tonemap)
        try:
            cameras = camera_path(sc, path, frames, duration=duration, look=look, to=end, position=start,
                                  speed=speed)
        except ValueError as exc:
            _fail(f"--path {path}: {exc}", EXIT_BAD_INPUT)
        width, height = size if size is not None else (None, None)
        t0 = time.perf_counter()
        from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn, TimeRemainingColumn

        columns = (TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TextColumn("frames"),
                   TimeElapsedColumn(), TimeRemainingColumn())  # fmt: skip
        done = {"rendered": 0, "kept": 0}
        with common._cluster(workers, cluster, tile) as client, \
                Progress(*columns, console=err, disable=quiet, transient=False) as bar:
            task = bar.add_task(output.name, total=len(cameras))

            def on_frame(k: int, n: int, rendered: bool) -> None:
                done["rendered" if rendered else "kept"] += 1
                bar.update(task, completed=k)

            try:
                render_film(sc, cameras, output, fps=fps, spp=spp, time_limit=seconds, width=width, height=height,
                            seed=seed, denoise=denoise, threads=threads, on_frame=on_frame, client=client, tile=tile,
                            **look_png)  # fmt: skip
            except FilmMismatch as exc:
                _fail(str(exc), EXIT_BAD_INPUT)
            except KeyboardInterrupt:
                err.print(Text(f"{_stop_word()}: kept {done['rendered'] + done['kept']} finished frames in "
                               f"{frames_folder(output)}; run the same command again to continue", style="yellow"))
                raise typer.Exit(_stop_code())
            except ValueError as exc:
                _fail(str(exc), EXIT_BAD_INPUT)
        kept = f", {done['kept']} already on disk" if done["kept"] else ""
        err.print(f"wrote {output} ({len(cameras)} frames, {done['rendered']} rendered{kept}, "
                  f"{time.perf_counter() - t0:.1f} s)")  # fmt: skip


def _point(flag: str, text: Optional[str]) -> Optional[list[float]]:
    """X,Y,Z as three finite numbers, or None; anything else is exit 2."""
    if text is None:
        return None
    try:
        point = [float(v) for v in text.split(",")]
    except ValueError:
        point = []
    if len(point) != 3 or not all(abs(v) < float("inf") for v in point):
        _fail(f"{flag} must be three numbers X,Y,Z, got {text!r}", EXIT_BAD_INPUT)
    return point
