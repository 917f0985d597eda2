"""The ``warpviz`` command line: render, trace, view and check scenes.

Commands: ``render``, ``trace``, ``view``, ``serve``, ``validate``, ``scenes``, ``bench``, ``doctor``; ``warpviz COMMAND
--help`` describes each. A scene is given as a path to a TOML file or as the name of a shipped scene
(``fig07``; see :mod:`warpviz.scene.catalog`).

Exit codes: 0 success; 1 runtime error; 2 bad input (invalid scene file, bad option, an image too large
for the machine's memory, an output that may not be written; the message goes to stderr without a
traceback, and nothing is written); 3 the render finished but more of its samples failed than
``--max-error-fraction`` allows (the image is written, so it can be inspected); 130 interrupted by Ctrl-C
and 143 stopped by SIGTERM (``render`` and ``trace`` first save the partial image). Set
``WARPVIZ_DEBUG=1`` to see tracebacks of runtime errors.
"""

from __future__ import annotations

import contextlib
import errno
import importlib
import importlib.metadata
import importlib.util
import os
import platform
import re
import signal
import subprocess
import warnings
import sys
import time
from pathlib import Path
from typing import Any, Optional

import numpy as np
import typer
from rich.console import Console
from rich.progress import (
    BarColumn,
    MofNCompleteColumn,
    Progress,
    TaskProgressColumn,
    TextColumn,
    TimeElapsedColumn,
    TimeRemainingColumn,
)
from rich.table import Table
from rich.text import Text

import warpviz
from warpviz.io import check_writable, written_by_warpviz
from warpviz.options import option_help
from warpviz.limits import (EXPOSURE_RANGE, MAX_EDGE_SAMPLES, MAX_IMAGE_SIDE, MAX_SEED, MAX_SPP, TONEMAP_NAMES,
                            duration_seconds, exposure_stops, noise_level)
from warpviz.render.denoise import DenoiserMissing
from warpviz.render.false_colour import FALSE_COLOUR_STYLES
from warpviz.render.render import OPTIONAL_AOVS
from warpviz.scene import Scene, SceneError, load_scene
from warpviz.scene.catalog import looks_like_path, scene_description, scene_dirs, shipped_scenes

EXIT_OK = 0
EXIT_ERROR = 1
EXIT_BAD_INPUT = 2
EXIT_RENDER_FAILED = 3
EXIT_INTERRUPTED = 130
EXIT_TERMINATED = 143

IMAGE_SUFFIXES = (".png", ".exr")

#: ``--max-error-fraction``'s default: a render in which more than 1 % of the samples failed (each one
#: darkens its pixel) exits with code 3. Every shipped scene renders with none.
MAX_ERROR_FRACTION = 0.01

app = typer.Typer(
    name="warpviz",
    help="Render and explain light in curved spacetime (black holes and wormholes).",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,  # help texts are plain: "[outputs] file" must not be read as markup
)

out = Console(highlight=False)
err = Console(stderr=True, highlight=False)


class _Failure(Exception):
    """A problem already explained to the user: print ``message`` and exit with ``code``."""

    def __init__(self, message: str, code: int):
        super().__init__(message)
        self.code = code


def _fail(message: str, code: int = EXIT_ERROR):
    raise _Failure(message, code)


@contextlib.contextmanager
def _guard():
    """Turn exceptions into messages and exit codes (0/1/2/130); no tracebacks unless WARPVIZ_DEBUG=1.
    Warnings are printed as one ``warning:`` line each."""
    try:
        with warnings.catch_warnings():
            warnings.showwarning = _show_warning
            yield
    except (typer.Exit, typer.Abort, typer.BadParameter):
        raise
    except _Failure as exc:
        err.print(Text("error: ", style="bold red") + Text(str(exc)), soft_wrap=True)
        raise typer.Exit(exc.code) from None
    except SceneError as exc:
        err.print(Text("error: ", style="bold red") + Text(str(exc)), soft_wrap=True)
        raise typer.Exit(EXIT_BAD_INPUT) from None
    except KeyboardInterrupt:
        err.print(Text(_stop_word(), style="bold yellow"))
        raise typer.Exit(_stop_code()) from None
    except Exception as exc:  # noqa: BLE001 - the top of the command line
        if os.environ.get("WARPVIZ_DEBUG"):
            raise
        err.print(Text("error: ", style="bold red") + Text(f"{type(exc).__name__}: {exc}"), soft_wrap=True)
        raise typer.Exit(EXIT_ERROR) from None


# ------------------------------------------------------------------------------------------- helpers
def _show_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """A warning as one line on stderr, without the source line Python would print."""
    err.print(Text("warning: ", style="bold yellow") + Text(str(message)), soft_wrap=True)


_terminated = False  # SIGTERM arrived (it stops a render like Ctrl-C; the exit code says which it was)


def _on_sigterm(signum, frame):
    global _terminated
    _terminated = True
    raise KeyboardInterrupt


@contextlib.contextmanager
def _stoppable():
    """SIGTERM (what ``timeout``, ``kill`` and batch schedulers send) handled like Ctrl-C while inside."""
    global _terminated
    _terminated = False
    try:
        previous = signal.signal(signal.SIGTERM, _on_sigterm)
    except ValueError:  # not the main thread (e.g. a test runner's worker): nothing to install
        yield
        return
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


def _stop_code() -> int:
    return EXIT_TERMINATED if _terminated else EXIT_INTERRUPTED


def _stop_word() -> str:
    return "terminated" if _terminated else "interrupted"


def _viewer():
    """:func:`warpviz.view` (PyVista and VTK are imported when it is first used)."""
    from warpviz.viewer import view

    return view


def _renderer():
    """:func:`warpviz.render`, called where a command's work starts (after every check of its input)."""
    from warpviz.render.render import render

    return render


def _parse_size(value: Optional[str]) -> Optional[tuple[int, int]]:
    if value is None:
        return None
    m = re.fullmatch(r"\s*(\d+)\s*[xX*]\s*(\d+)\s*", value)
    if not m or not all(1 <= int(g) <= MAX_IMAGE_SIDE for g in m.groups()):
        raise typer.BadParameter(f"expected WIDTHxHEIGHT, each in [1, {MAX_IMAGE_SIDE}], e.g. 320x240; got {value!r}")
    return int(m.group(1)), int(m.group(2))


def _parse_crop(value: Optional[str]) -> Optional[tuple[int, int, int, int]]:
    if value is None:
        return None
    m = re.fullmatch(r"\s*(\d+)\s*,\s*(\d+)\s*,\s*(\d+)\s*[xX,]\s*(\d+)\s*", value)
    if not m:
        raise typer.BadParameter(f"expected X,Y,WIDTHxHEIGHT (the window's top-left pixel and size), e.g. 0,0,640x480; "
                                 f"got {value!r}")  # fmt: skip
    return tuple(int(g) for g in m.groups())


def _parse_pixels(values: list[str]) -> np.ndarray:
    pixels = []
    for value in values:
        for item in re.split(r"[\s;]+", value.strip()):
            if not item:
                continue
            m = re.fullmatch(r"(\d+),(\d+)", item)
            if not m:
                _fail(f"--pixels: expected X,Y pixel coordinates such as 40,30; got {item!r}", EXIT_BAD_INPUT)
            pixels.append((int(m.group(1)), int(m.group(2))))
    if not pixels:
        _fail("--pixels: give at least one pixel as X,Y", EXIT_BAD_INPUT)
    return np.asarray(pixels, dtype=np.int32)


def _output_path(path: Path, suffixes: tuple[str, ...], *, force: bool = False, scene: Optional[Scene] = None) -> Path:
    """Check, before any work, that ``path`` may be written: its suffix, its folder, not a folder itself,
    not a file warpviz did not write (unless ``force``), and, for a file the scene chose (``scene`` given),
    inside the scene's folder or the working directory."""
    what = "the scene's [outputs] file" if scene is not None else "output"
    if path.suffix.lower() not in suffixes:
        _fail(f"{what} {str(path)!r} must end in {' or '.join(suffixes)}", EXIT_BAD_INPUT)
    if len(os.fsencode(path.name)) > 255:  # before any look at the file system, which would fail on it
        _fail(f"cannot write {what} {str(path)!r}: file name too long ({len(os.fsencode(path.name))} bytes; "
              "255 bytes is the most file systems allow)", EXIT_BAD_INPUT)  # fmt: skip
    if scene is not None:
        where = [Path.cwd().resolve()] + ([scene.path.parent.resolve()] if scene.path is not None else [])
        full = (Path.cwd() / path).resolve()
        if not any(full.is_relative_to(folder) for folder in where):
            _fail(f"{what} {str(path)!r} lies outside the scene's folder and the working directory; a scene "
                  "file may not choose where else to write (give -o to write there)", EXIT_BAD_INPUT)  # fmt: skip
    if not path.parent.is_dir():
        _fail(f"output folder {str(path.parent)!r} does not exist", EXIT_BAD_INPUT)
    if path.is_dir():
        _fail(f"output {str(path)!r} is a folder; give a file name (e.g. {str(path / ('image' + suffixes[0]))!r})",
              EXIT_BAD_INPUT)  # fmt: skip
    if path.exists() and not force and not written_by_warpviz(path):
        _fail(f"{str(path)!r} exists and was not written by warpviz; pass --force to replace it", EXIT_BAD_INPUT)
    try:  # the temporary file the writer will use, created and removed now: not after an hour of rendering
        check_writable(path)
    except OSError as exc:
        _fail(f"cannot write {what} {str(path)!r}: {exc.strerror or exc}", EXIT_BAD_INPUT)
    return path


@contextlib.contextmanager
def _progress_bar(label: str, *, enabled: bool, seconds: Optional[float] = None):
    """A rich progress bar on stderr; yields the ``progress(done, total)`` callback for the renderer, whose
    ``on_pass`` attribute takes the renderer's pass reports (samples per pixel reached, noise).

    With a time budget of ``seconds`` the bar is the time: how much of it is spent and how much is left;
    without one, the samples done of those asked for."""
    info = TextColumn("{task.fields[info]}")
    if seconds is None:
        columns = (TextColumn("{task.description}"), BarColumn(), TaskProgressColumn(), MofNCompleteColumn(), info,
                   TimeElapsedColumn(), TimeRemainingColumn())  # fmt: skip
    else:
        columns = (TextColumn("{task.description}"), BarColumn(), TextColumn("{task.fields[left]}"), info,
                   TimeElapsedColumn())  # fmt: skip
    start = time.perf_counter()
    with Progress(*columns, console=err, disable=not enabled, transient=False) as progress:
        task = progress.add_task(label, total=None if seconds is None else seconds, info="", left="")

        def update(done: int, total: int) -> None:
            if seconds is None:
                progress.update(task, completed=int(done), total=int(total))
            else:
                spent = min(seconds, time.perf_counter() - start)
                progress.update(task, completed=spent, left=f"{_duration(seconds - spent)} left")

        def on_pass(report) -> None:
            noise = "" if report.noise != report.noise else f", noise {100 * report.noise:.2g} %"
            progress.update(task, info=f"{report.spp} spp{noise}")

        update.on_pass = on_pass
        yield update


def _duration(seconds: float) -> str:
    """``'42 s'``, ``'3 min 20 s'``, ``'1 h 05 min'``."""
    seconds = max(0, int(round(seconds)))
    if seconds < 60:
        return f"{seconds} s"
    if seconds < 3600:
        return f"{seconds // 60} min {seconds % 60:02d} s"
    return f"{seconds // 3600} h {seconds % 3600 // 60:02d} min"


def _render_scene(scene: Scene, *, spp, size, seed, threads, flat, paper, light_sampling, progress, record_pixels=None,
                  light_connection=None, crop=None, aovs=None, denoise=False, edge_samples=None, time_limit=None,
                  noise_target=None, resume=None):
    """Call warpviz.render with the command line's options; bad options (and images too large for the
    memory, and an image to resume that does not match) become exit code 2, a denoiser that is not
    installed exit code 1 with the extra to install."""
    render = _renderer()
    width, height = size if size is not None else (None, None)
    extra = {"denoise": True} if denoise else {}  # only when asked: a stand-in renderer need not know them
    for key, value in (("edge_samples", edge_samples), ("time_limit", time_limit), ("noise_target", noise_target),
                       ("resume", resume), ("on_pass", getattr(progress, "on_pass", None))):  # fmt: skip
        if value is not None:
            extra[key] = value
    try:
        return render(scene, spp=spp, width=width, height=height, seed=seed, threads=threads, flat=flat,
                      light_sampling=light_sampling, paper=paper, progress=progress,
                      record_pixels=record_pixels, light_connection=light_connection, crop=crop,
                      aovs=aovs, **extra)  # fmt: skip
    except DenoiserMissing as exc:
        _fail(f"--denoise: {exc}", EXIT_ERROR)
    except (ValueError, TypeError) as exc:
        if isinstance(exc, SceneError):
            raise
        _fail(str(exc), EXIT_BAD_INPUT)


def _look(scene: Scene, *, exposure: Optional[float], tonemap: Optional[str]) -> dict:
    """The PNG's ``exposure`` and ``tonemap`` for ``Image.save``: the flags, else the scene's ``[outputs]``,
    else None (the defaults of :mod:`warpviz.render.tonemap`); a bad flag is exit code 2."""
    exposure = exposure if exposure is not None else scene.outputs.get("exposure")
    tonemap = tonemap if tonemap is not None else scene.outputs.get("tonemap")
    if exposure is not None:
        try:
            exposure = exposure_stops("--exposure", exposure)
        except ValueError as exc:
            _fail(str(exc), EXIT_BAD_INPUT)
    if tonemap is not None and tonemap not in TONEMAP_NAMES:
        _fail(f"--tonemap must be one of {', '.join(TONEMAP_NAMES)}, got {tonemap!r}", EXIT_BAD_INPUT)
    return {"exposure": exposure, "tonemap": tonemap}


def _aovs_for(target: Optional[Path], scene: Scene) -> list[str]:
    """The optional AOVs worth computing for an image written to ``target``: none for a PNG (it holds
    radiance only), the scene's ``[outputs] aovs`` (default: all) for an EXR."""
    if target is None or target.suffix.lower() != ".exr":
        return []
    names = scene.outputs.get("aovs")
    return list(names) if names is not None else list(OPTIONAL_AOVS)


def _keep_aovs(img: Any, names: Optional[list[str]]) -> None:
    """Drop the AOVs a scene's ``[outputs] aovs`` does not list (only before writing an EXR); ``errors``,
    ``samples`` and ``variance`` always stay, so an EXR says which pixels lost samples, how many each has
    and how noisy each is (and can be resumed)."""
    aovs = getattr(img, "aovs", None)
    if names is None or not isinstance(aovs, dict):
        return
    for key in [k for k in aovs if k not in names and k not in ("errors", "samples", "variance")]:
        del aovs[key]


def _checked(flag: str, check, value):
    """``check(flag, value)`` (a limits checker), a ValueError becoming exit code 2; None stays None."""
    if value is None:
        return None
    try:
        return check(flag, value)
    except ValueError as exc:
        _fail(str(exc), EXIT_BAD_INPUT)


def _samples_summary(img: Any) -> str:
    """``', 48 spp in 9 passes, noise 2.1 %'``: what a render in passes reached ('' for a stand-in image)."""
    meta = getattr(img, "metadata", None) or {}
    if "passes" not in meta:
        return ""
    text = f", {meta['spp']} spp in {meta['passes']} pass{'' if meta['passes'] == 1 else 'es'}"
    if meta.get("noise") is not None:
        text += f", noise {100 * meta['noise']:.2g} %"
    return text


def _error_summary(img: Any) -> str:
    """``'0 of 12,288 samples failed'``-style summary of a render's failed samples."""
    stats = getattr(img, "stats", {}) or {}
    total, bad = int(stats.get("samples", 0)), int(stats.get("samples_with_errors", 0))
    if not bad:
        return f"no failed samples of {total:,}"
    return f"{bad:,} of {total:,} samples failed ({100.0 * bad / max(1, total):.3g} %)"


def _check_errors(img: Any, limit: float, target: Path) -> None:
    """Exit 3 when more of the render's samples failed than ``limit`` allows (the image is written)."""
    fraction = float(getattr(img, "error_fraction", 0.0))
    if fraction > limit:
        _fail(f"{_error_summary(img)}, more than --max-error-fraction {limit:g} allows: the image {target} is "
              "darker where they failed (its EXR 'errors' channel shows where). Loosen tol, raise max_steps, "
              "or move the camera and objects away from the horizon.", EXIT_RENDER_FAILED)  # fmt: skip


# ------------------------------------------------------------------------------------------- commands
def _version(value: bool) -> None:
    if value:
        out.print(f"warpviz {warpviz.__version__}")
        raise typer.Exit(EXIT_OK)


@app.callback()
def _main(
    version: bool = typer.Option(
        False, "--version", callback=_version, is_eager=True, help="Print the version and exit."
    ),
) -> None:
    """Render and explain light in curved spacetime (black holes and wormholes).

    Exit codes: 0 ok, 1 runtime error, 2 bad input, 130 interrupted.
    """


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
    size: Optional[str] = typer.Option(
        None, "--size", callback=_parse_size, help=f"Image size WIDTHxHEIGHT, e.g. 320x240 (each at most {MAX_IMAGE_SIDE})."
    ),
    crop: Optional[str] = typer.Option(
        None, "--crop", callback=_parse_crop,
        help="Render only the window X,Y,WIDTHxHEIGHT of the image (top-left pixel and size), e.g. "
        "0,0,640x480. Windows that tile the image hold exactly its pixels: a way to render an image "
        "larger than memory in parts.",
    ),  # fmt: skip
    threads: int = typer.Option(0, "--threads", min=0, help="Worker threads; 0 uses every core."),
    seed: Optional[int] = typer.Option(None, "--seed", min=0, max=MAX_SEED, help=option_help("seed")),
    flat: bool = typer.Option(False, "--flat", help="Render the same scene in flat space, for comparison."),
    paper: bool = typer.Option(False, "--paper", help="Use the scene's [render.paper] size and sample count."),
    no_light_sampling: bool = typer.Option(
        False, "--no-light-sampling", help="Brute-force path tracing: light_sampling off. " + option_help("light_sampling")
    ),
    light_connection: Optional[str] = typer.Option(None, "--light-connection", help=option_help("light_connection")),
    edge_samples: Optional[int] = typer.Option(
        None, "--edge-samples", min=1, max=MAX_EDGE_SAMPLES, help=option_help("edge_samples")
    ),
    max_error_fraction: float = typer.Option(
        MAX_ERROR_FRACTION, "--max-error-fraction", min=0.0, max=1.0,
        help="Exit with code 3 when more than this fraction of the samples failed (a geodesic ran out of "
        "steps, broke a conservation law or became nan); the image is still written.",
    ),  # fmt: skip
    exposure: Optional[float] = typer.Option(
        None, "--exposure",
        help=f"PNG only: exposure in stops, the radiance times 2**S before tonemapping, in "
        f"[{EXPOSURE_RANGE[0]:g}, {EXPOSURE_RANGE[1]:g}] (default: the scene's [outputs] exposure, else 0).",
    ),  # fmt: skip
    tonemap: Optional[str] = typer.Option(
        None, "--tonemap",
        help="PNG only: 'filmic' (default: hue-preserving shoulder, saturated lights keep their colour), 'clip' "
        "(each channel clamped to 1) or 'reinhard' (x / (1 + x) per channel). Default: the scene's [outputs] "
        "tonemap, else filmic.",
    ),  # fmt: skip
    denoise: bool = typer.Option(
        False, "--denoise",
        help="Denoise with Intel Open Image Denoise (pip install 'warpviz[denoise]'), fed with the albedo and "
        "normal at each path's first non-specular hit. A PNG shows the denoised image; an EXR keeps the "
        "unbiased radiance as R, G, B and adds the denoised one as the layer denoised.R/G/B.",
    ),  # fmt: skip
    false_colour: Optional[str] = typer.Option(
        None, "--false-colour",
        help=f"Write a false-colour PNG of this AOV ({', '.join(FALSE_COLOUR_STYLES)}) with a colour bar "
        "naming the quantity and its range, instead of the tonemapped picture.",
    ),  # fmt: skip
    force: bool = typer.Option(False, "--force", help="Replace an existing output file that warpviz did not write."),
    quiet: bool = typer.Option(False, "--quiet", "-q", help="No progress bar."),
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
        _renderer()
        t0 = time.perf_counter()
        bar = {"seconds": seconds_budget} if seconds_budget is not None else {}  # a stand-in bar need not know it
        with _progress_bar(sc.path.stem if sc.path else "scene", enabled=not quiet, **bar) as progress:
            img = _render_scene(sc, spp=spp, size=size, seed=seed, threads=threads, flat=flat, paper=paper,
                                light_sampling=False if no_light_sampling else None, progress=progress,
                                light_connection=light_connection, crop=crop, aovs=aovs,
                                denoise=denoise, edge_samples=edge_samples, time_limit=seconds_budget,
                                noise_target=noise_target, resume=resume)  # fmt: skip
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
    size: Optional[str] = typer.Option(None, "--size", callback=_parse_size, help="Image size WIDTHxHEIGHT."),
    threads: int = typer.Option(0, "--threads", min=0, help="Worker threads; 0 uses every core."),
    seed: Optional[int] = typer.Option(None, "--seed", min=0, max=MAX_SEED, help=option_help("seed")),
    flat: bool = typer.Option(False, "--flat", help="Flat space instead of the scene's metric."),
    paper: bool = typer.Option(False, "--paper", help="Use the scene's [render.paper] settings."),
    exposure: Optional[float] = typer.Option(None, "--exposure", help="PNG --image only: exposure in stops (see render)."),
    tonemap: Optional[str] = typer.Option(None, "--tonemap", help="PNG --image only: filmic, clip or reinhard (see render)."),
    force: bool = typer.Option(False, "--force", help="Replace existing output files that warpviz did not write."),
    quiet: bool = typer.Option(False, "--quiet", "-q", help="No progress bar."),
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
        _renderer()
        with _progress_bar("tracing", enabled=not quiet) as progress:
            img = _render_scene(sc, spp=spp, size=size, seed=seed, threads=threads, flat=flat, paper=paper,
                                light_sampling=None, progress=progress, record_pixels=record,
                                aovs=_aovs_for(picture, sc))  # fmt: skip
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


@app.command()
def view(
    target: str = typer.Argument(..., help="Scene (.toml or shipped name), or recorded rays (.vtp) or a scene .vtm."),
    pixels: Optional[list[str]] = typer.Option(
        None, "--pixels", "-p", help="Pixels X,Y (at the preview size) whose paths are shown; repeatable."
    ),
    screenshot: Optional[Path] = typer.Option(
        None, "--screenshot", help="Write a PNG of the view; without a display the view is only written."
    ),
    force: bool = typer.Option(False, "--force", help="Replace an existing screenshot that warpviz did not write."),
    bounces: Optional[int] = typer.Option(
        None, "--bounces", help="Draw each recorded path up to this bounce (0: camera segments only). Default: "
        "camera segments for the pixels the view chooses, every bounce for --pixels; key n shows one more."),
    flat_ray: bool = typer.Option(
        False, "--flat-ray", help="Draw the straight flat-space ray (no gravity) beside each shown pixel's bent one."),
    color_by: Optional[str] = typer.Option(
        None, "--color-by", help="Colour the paths by drift (largest drift of the conserved quantities against their terms, "
        "the default), r, redshift or affine (the affine parameter); key c cycles them."),
    spp: Optional[int] = typer.Option(
        None, "--spp", min=1, max=MAX_SPP, help="Samples per pixel of a scene's image panel (default 4; with --time "
        "alone: as many as fit)."),
    time_budget: Optional[str] = typer.Option(
        None, "--time", help="Time budget of a scene's image panel: seconds, or 30s, 2m (with --spp: whichever "
        "comes first). A window then refines it further while it is open."),
    preview_width: Optional[int] = typer.Option(
        None, "--width", min=8, max=4096, help="Width in pixels of a scene's image panel (default 96)."),
) -> None:
    """Open the PyVista teaching view: the image beside the 3-D paths of its light rays."""
    with _guard():
        viewer = _viewer()
        path = Path(target)
        if path.is_file() and path.suffix.lower() in (".vtp", ".vtm"):
            obj: Any = _ray_file(path)
        elif path.is_file() and path.suffix.lower() != ".toml":
            _fail(f"{target}: can view a scene (.toml or a shipped name), a .vtp or a .vtm file", EXIT_BAD_INPUT)
        elif path.is_file() or not looks_like_path(target):
            obj = load_scene(target)
        else:
            _fail(f"{target}: no such file", EXIT_BAD_INPUT)
        options: dict[str, Any] = {}
        seconds_budget = _checked("--time", duration_seconds, time_budget)
        if seconds_budget is not None:
            options["time_limit"] = seconds_budget
            options["spp"] = spp  # None: as many as the budget allows
        elif spp is not None:
            options["spp"] = spp
        if preview_width is not None:
            options["preview_width"] = preview_width
        if pixels:
            options["pixels"] = _parse_pixels(pixels)
        if bounces is not None:
            if bounces < 0:
                _fail(f"--bounces must be 0 (camera segments only) or more, got {bounces}", EXIT_BAD_INPUT)
            options["bounces"] = bounces
        if flat_ray:
            options["show_flat"] = True
        if color_by is not None:
            from warpviz.viewer.annotations import COLORINGS

            if color_by not in COLORINGS:
                _fail(f"--color-by must be one of {', '.join(COLORINGS)}, got {color_by!r}", EXIT_BAD_INPUT)
            options["color_by"] = color_by
        if screenshot is not None:
            options["screenshot"] = _output_path(screenshot, (".png",), force=force)
        else:
            from warpviz.viewer.offscreen import default_off_screen

            if default_off_screen():
                _fail("no display to open the view on (DISPLAY is not set, or PYVISTA_OFF_SCREEN is on): write "
                      f"the view to a file with --screenshot view.png, e.g. warpviz view {target} --screenshot "
                      "view.png", EXIT_BAD_INPUT)  # fmt: skip
        try:
            viewer(obj, **options)
        except ValueError as exc:  # e.g. a pixel outside the preview image
            _fail(str(exc), EXIT_BAD_INPUT)
        if screenshot is not None:
            err.print(f"wrote {screenshot}")


def _ray_file(path: Path) -> Path:
    """``path`` checked to be a ray file warpviz wrote (read quietly: VTK's own complaints about a file
    that is not VTK are replaced by one message)."""
    from warpviz.io import read_rays

    try:
        with _quiet_vtk():
            read_rays(path)
    except (ValueError, OSError) as exc:
        _fail(f"{path}: {exc}", EXIT_BAD_INPUT)
    except Exception:  # noqa: BLE001 - VTK raises what it likes on garbage
        _fail(f"{path}: not a VTK file warpviz can read", EXIT_BAD_INPUT)
    return path


@contextlib.contextmanager
def _quiet_vtk():
    """VTK's error output and PyVista's reader warnings silenced for the block."""
    import warnings

    from vtkmodules.vtkCommonCore import vtkObject

    previous = vtkObject.GetGlobalWarningDisplay()
    vtkObject.GlobalWarningDisplayOff()
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            yield
    finally:
        vtkObject.SetGlobalWarningDisplay(previous)


def _check_paper(sc: Scene, paper: bool) -> None:
    """Exit 2 when --paper asks for the paper settings of a scene that has none."""
    if paper and not sc.has_paper:
        name = sc.path.name if sc.path is not None else "the scene"
        _fail(f"--paper: {name} has no [render.paper] table (the size and samples of its paper figure); give "
              "--size and --spp instead", EXIT_BAD_INPUT)  # fmt: skip


def _check_port(host: str, port: int) -> None:
    """Exit 2 unless a server can listen on (host, port) now (port 0: the system picks a free one)."""
    import socket

    try:
        infos = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM)
    except (OSError, UnicodeError) as exc:
        _fail(f"--host {host!r}: not an address of this machine ({exc})", EXIT_BAD_INPUT)
    family, kind, proto, _, address = infos[0]
    with socket.socket(family, kind, proto) as probe:
        probe.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)  # as the web server does
        try:
            probe.bind(address)
        except OSError as exc:
            why = "is in use" if exc.errno == errno.EADDRINUSE else f"cannot be used ({exc.strerror})"
            _fail(f"port {port} on {host} {why}; choose another with --port, or --port 0 for a free one",
                  EXIT_BAD_INPUT)  # fmt: skip


@app.command()
def serve(
    scene: str = typer.Argument(..., help="Scene (.toml or shipped name)."),
    port: int = typer.Option(8080, "--port", min=0, max=65535, help="TCP port to listen on; 0 picks a free one."),
    host: str = typer.Option("127.0.0.1", "--host", help="Interface to listen on (default: this machine only)."),
    open_browser: bool = typer.Option(True, "--browser/--no-browser", help="Open the page in the default browser."),
    preview_width: int = typer.Option(96, "--preview-width", min=8, max=1024, help="Width of the preview render."),
    spp: int = typer.Option(4, "--spp", min=1, max=1024, help="Samples per pixel of the preview render."),
) -> None:
    """Serve the teaching view as a local web page: the image, the 3-D rays, sliders for the metric and camera.

    Needs pip install "warpviz[web]". Stop it with Ctrl-C.
    """
    with _guard():
        try:
            from warpviz.web.app import require_web, serve as serve_app

            require_web()
        except ImportError as exc:
            _fail(str(exc), EXIT_BAD_INPUT)
        sc = load_scene(scene)  # a missing file or unknown name: a SceneError, exit 2
        _check_port(host, port)  # before the preview is rendered
        err.print(f"rendering the preview of {sc.path.name if sc.path else scene} ...")

        def ready(url: str) -> None:
            out.print(f"serving the teaching view at {url} (Ctrl-C stops)", soft_wrap=True)
            sys.stdout.flush()

        serve_app(sc, port=port, host=host, open_browser=open_browser, preview_width=preview_width, spp=spp,
                  ready=ready)  # fmt: skip


@app.command()
def validate(
    scenes: list[str] = typer.Argument(..., help="Scene files or shipped scene names."),
) -> None:
    """Check scene files: syntax, keys, values, referenced files. Exit 2 if any is invalid."""
    with _guard():
        bad = 0
        for spec in scenes:
            try:
                sc = load_scene(spec)
            except SceneError as exc:
                bad += 1
                err.print(Text("invalid ", style="bold red") + Text(str(exc)), soft_wrap=True)
                continue
            name = str(spec) if Path(spec).is_file() else str(sc.path)
            out.print(Text("ok      ", style="bold green") + Text(f"{name}: {sc.summary()}"), soft_wrap=True)
        if bad:
            err.print(f"{bad} of {len(scenes)} scene(s) invalid")
            raise typer.Exit(EXIT_BAD_INPUT)


@app.command("scenes")
def list_scenes(
    paths: bool = typer.Option(False, "--paths", help="Show the file of each scene."),
) -> None:
    """List the shipped figure scenes with their descriptions."""
    with _guard():
        files = shipped_scenes()
        if not files:
            _fail("no shipped scenes found (looked in $WARPVIZ_SCENES and the repository's scenes/ folder)")
        table = Table(title="Shipped scenes (warpviz render NAME)", show_lines=False)
        table.add_column("name", no_wrap=True, style="bold")
        table.add_column("description")
        if paths:
            table.add_column("file", no_wrap=True)
        for f in files:
            row = [f.stem, scene_description(f)] + ([str(f)] if paths else [])
            table.add_row(*row)
        out.print(table)
        out.print(f"{len(files)} scenes in {', '.join(str(d) for d in scene_dirs())}")


def _package_version(dist: str) -> str:
    try:
        return importlib.metadata.version(dist)
    except importlib.metadata.PackageNotFoundError:
        return "not installed"


_OFFSCREEN_PROBE = """
import pyvista as pv
pl = pv.Plotter(off_screen=True, window_size=(32, 32))
pl.add_mesh(pv.Sphere())
img = pl.screenshot(return_img=True)
print(pl.render_window.GetClassName(), img.shape[0], img.shape[1])
pl.close()
"""


def _offscreen_check(timeout: float = 60.0) -> str:
    """Try a tiny off-screen PyVista render in a child process (a crash there cannot hurt us)."""
    try:
        proc = subprocess.run([sys.executable, "-c", _OFFSCREEN_PROBE], capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return f"failed: no answer within {timeout:.0f} s"
    if proc.returncode == 0 and proc.stdout.strip():
        window = proc.stdout.split()[0]
        kinds = {"EGL": "EGL (headless GPU/Mesa)", "OSMesa": "OSMesa (software)"}
        how = next((v for k, v in kinds.items() if k in window), "X/native")
        return f"ok: {window}, {how}"
    last = (proc.stderr.strip().splitlines() or ["no output"])[-1]
    return f"failed (exit {proc.returncode}): {last[:200]}"


@app.command()
def doctor(
    quick: bool = typer.Option(False, "--quick", help="Skip the off-screen rendering test (a few seconds)."),
) -> None:
    """Report the build, threads, packages and whether headless 3-D rendering works."""
    with _guard():
        info = warpviz.build_info()
        table = Table(title="warpviz doctor", show_header=False)
        table.add_column("item", style="bold", no_wrap=True)
        table.add_column("value")
        table.add_row("warpviz", f"{warpviz.__version__} ({Path(warpviz.__file__).parent})")
        table.add_row("python", f"{platform.python_version()} ({sys.executable})")
        table.add_row("platform", platform.platform())
        for key, value in info.items():
            table.add_row(f"core {key}", str(value))
        cpus = os.cpu_count()
        usable = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else cpus
        table.add_row("threads", f"{usable} usable of {cpus} CPUs; threads=0 uses every core")
        table.add_row("metrics", ", ".join(m["name"] for m in warpviz.registered_metrics()))
        folders = ", ".join(str(d) for d in scene_dirs()) or "nowhere"
        table.add_row("scenes", f"{len(shipped_scenes())} shipped in {folders}")
        for dist in ("numpy", "trimesh", "pillow", "OpenEXR", "typer", "rich", "pyvista", "vtk", "matplotlib", "pyoidn"):
            table.add_row(dist, _package_version(dist))
        display = os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")
        table.add_row("display", display or "none (headless)")
        table.add_row("off-screen 3-D", "skipped (--quick)" if quick else _offscreen_check())
        out.print(table)


#: ``warpviz bench SUITE``: the benchmark scripts of the repository's benchmarks/ folder.
BENCH_SUITES = {
    "geodesics": "bench_geodesics.py",
    "work-precision": "bench_work_precision.py",
    "render": "bench_render.py",
    "skips": "bench_skips.py",
    "light-connection": "bench_light_connection.py",
    "mitsuba-cornell": "bench_mitsuba_cornell.py",
    "denoise": "bench_denoise.py",
    "edge-samples": "bench_edge_samples.py",
    "time-to-clean": "bench_time_to_clean.py",
}


@app.command(context_settings={"allow_extra_args": True, "ignore_unknown_options": True})
def bench(ctx: typer.Context) -> None:
    """Run a benchmark: `warpviz bench SUITE OPTIONS`, SUITE one of geodesics, work-precision, render, skips,
    light-connection, mitsuba-cornell, denoise, edge-samples, time-to-clean.

    Without a SUITE it runs the far-observer geodesic benchmark (benchmarks/bench_geodesics.py); every
    suite takes its own options after the name, e.g. `warpviz bench --size 32` or
    `warpviz bench render --quick`. Results (CSV, plots) go to --out DIR, by default the working
    directory; the repository's committed results are refreshed only by running a script directly.
    """
    with _guard():
        args = list(ctx.args)
        if args and not args[0].startswith("-") and args[0] not in BENCH_SUITES:
            _fail(f"no benchmark suite {args[0]!r}; the suites are: {', '.join(BENCH_SUITES)}", EXIT_BAD_INPUT)
        suite = args.pop(0) if args and args[0] in BENCH_SUITES else "geodesics"
        if not any(a == "--out" or a.startswith("--out=") for a in args) and not {"-h", "--help"} & set(args):
            args += ["--out", str(Path.cwd())]
        folder = Path(__file__).resolve().parent.parent / "benchmarks"
        script = folder / BENCH_SUITES[suite]
        if not script.is_file():
            _fail(f"benchmark script not found: {script} (it ships with the repository, not the package)")
        sys.path.insert(0, str(folder))  # the scripts share benchmarks/_common.py and _scenes.py
        spec = importlib.util.spec_from_file_location(f"warpviz_bench_{suite.replace('-', '_')}", script)
        module = importlib.util.module_from_spec(spec)
        saved_prog, sys.argv[0] = sys.argv[0], f"warpviz bench {suite}"  # argparse names the program after argv[0]
        try:
            spec.loader.exec_module(module)
            module.main(args)
        except SystemExit as exc:  # argparse: --help (0) or bad options (2)
            code = exc.code if isinstance(exc.code, int) else EXIT_BAD_INPUT
            raise typer.Exit(code) from None
        finally:
            sys.argv[0] = saved_prog
            sys.path.remove(str(folder))


def main() -> None:
    """Entry point of the ``warpviz`` console script."""
    app(prog_name="warpviz")


if __name__ == "__main__":  # pragma: no cover
    main()
