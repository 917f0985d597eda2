"""What every command shares: exit codes, the consoles, errors as messages (``_guard``), signals, the
checks of outputs, the progress bar and the render call (``_renderer``, ``_viewer`` and ``_progress_bar``
are looked up here at call time, so a test can replace them).
"""

from __future__ import annotations

import contextlib
import os
import re
import signal
import time
import warnings
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
from rich.text import Text

from warpviz.io import check_writable, name_length_problem, written_by_warpviz
from warpviz.limits import MAX_IMAGE_SIDE, TONEMAP_NAMES, exposure_stops
from warpviz.render.denoise import DenoiserMissing
from warpviz.render.render import OPTIONAL_AOVS
from warpviz.scene import Scene, SceneError

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


@contextlib.contextmanager
def _cluster(workers: Optional[int], address: Optional[str], tile: Optional[int]):
    """The Dask client of ``--workers N`` (a local cluster) or ``--cluster ADDRESS``, its dashboard printed;
    None without either. Both at once, or ``--tile`` without one, is exit code 2; dask.distributed not
    installed exit code 1 with the extra to install."""
    if workers is not None and address is not None:
        _fail("give --workers (a local Dask cluster) or --cluster (a running scheduler), not both", EXIT_BAD_INPUT)
    if workers is None and address is None:
        if tile is not None:
            _fail("--tile is the tile size of a render on a Dask cluster: it needs --workers or --cluster",
                  EXIT_BAD_INPUT)  # fmt: skip
        yield None
        return
    from warpviz.render.distributed import cluster_client

    try:
        manager = cluster_client(workers=workers, address=address)
        client = manager.__enter__()
    except ImportError as exc:
        _fail(str(exc), EXIT_ERROR)
    except ValueError as exc:
        _fail(f"--cluster: {exc}", EXIT_BAD_INPUT)
    try:
        where = f"{workers} local workers" if workers is not None else f"the scheduler at {address}"
        err.print(f"Dask: {where}, dashboard {client.dashboard_link}", soft_wrap=True)
        yield client
    finally:
        manager.__exit__(None, None, None)


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
    too_long = name_length_problem(path)  # before any other look at the file system, which would fail on it
    if too_long:
        _fail(f"cannot write {what} {str(path)!r}: {too_long}", EXIT_BAD_INPUT)
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
                  light_connection=None, crop=None, aovs=None, denoise=False, edge_samples=None, detail_samples=None,
                  guide_training=None, photons=None, photons_per_pixel=None, time_limit=None, noise_target=None,
                  resume=None, client=None, tile=None):
    """Call warpviz.render with the command line's options; bad options (and images too large for the
    memory, and an image to resume that does not match) become exit code 2, a denoiser that is not
    installed exit code 1 with the extra to install."""
    render = _renderer()
    width, height = size if size is not None else (None, None)
    extra = {"denoise": True} if denoise else {}  # only when asked: a stand-in renderer need not know them
    for key, value in (("edge_samples", edge_samples), ("detail_samples", detail_samples),
                       ("guide_training", guide_training), ("photons", photons),
                       ("photons_per_pixel", photons_per_pixel), ("time_limit", time_limit),
                       ("noise_target", noise_target),
                       ("resume", resume), ("on_pass", getattr(progress, "on_pass", None)), ("client", client),
                       ("tile", tile)):  # fmt: skip
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


def _check_paper(sc: Scene, paper: bool) -> None:
    """Exit 2 when --paper asks for the paper settings of a scene that has none."""
    if paper and not sc.has_paper:
        name = sc.path.name if sc.path is not None else "the scene"
        _fail(f"--paper: {name} has no [render.paper] table (the size and samples of its paper figure); give "
              "--size and --spp instead", EXIT_BAD_INPUT)  # fmt: skip


_OFFSCREEN_PROBE = """
import pyvista as pv
pl = pv.Plotter(off_screen=True, window_size=(32, 32))
pl.add_mesh(pv.Sphere())
img = pl.screenshot(return_img=True)
print(pl.render_window.GetClassName(), img.shape[0], img.shape[1])
pl.close()
"""
