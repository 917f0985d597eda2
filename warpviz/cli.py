"""The ``warpviz`` command line: render, trace, view and check scenes.

Commands: ``render``, ``trace``, ``view``, ``validate``, ``scenes``, ``bench``, ``doctor``; ``warpviz COMMAND
--help`` describes each. A scene is given as a path to a TOML file or as the name of a shipped scene
(``fig07``; see :mod:`warpviz.scene.catalog`).

Exit codes: 0 success; 1 runtime error; 2 bad input (invalid scene file, bad option; the message goes to
stderr without a traceback); 130 interrupted by Ctrl-C (``render`` first saves the partial image). Set
``WARPVIZ_DEBUG=1`` to see tracebacks of runtime errors.
"""

from __future__ import annotations

import contextlib
import importlib
import importlib.metadata
import importlib.util
import os
import platform
import re
import subprocess
import sys
import time
import types
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
from warpviz.scene import Scene, SceneError, load_scene
from warpviz.scene.catalog import looks_like_path, scene_description, scene_dirs, shipped_scenes

EXIT_OK = 0
EXIT_ERROR = 1
EXIT_BAD_INPUT = 2
EXIT_INTERRUPTED = 130

IMAGE_SUFFIXES = (".png", ".exr")

app = typer.Typer(
    name="warpviz",
    help="Render and explain light in curved spacetime (black holes and wormholes).",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
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
    """Turn exceptions into messages and exit codes (0/1/2/130); no tracebacks unless WARPVIZ_DEBUG=1."""
    try:
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
        err.print(Text("interrupted", style="bold yellow"))
        raise typer.Exit(EXIT_INTERRUPTED) from None
    except Exception as exc:  # noqa: BLE001 - the top of the command line
        if os.environ.get("WARPVIZ_DEBUG"):
            raise
        err.print(Text("error: ", style="bold red") + Text(f"{type(exc).__name__}: {exc}"), soft_wrap=True)
        raise typer.Exit(EXIT_ERROR) from None


# ------------------------------------------------------------------------------------------- helpers
def _api(name: str, module: str) -> Any:
    """A public function of warpviz that may not exist yet (``render``, ``view``), or None."""
    obj = getattr(warpviz, name, None)
    if isinstance(obj, types.ModuleType):
        obj = getattr(obj, name, None)
    if obj is None:
        try:
            obj = getattr(importlib.import_module(f"warpviz.{module}"), name, None)
        except ImportError:
            obj = None
    return obj if callable(obj) else None


def _renderer():
    fn = _api("render", "render")
    if fn is None:
        _fail("the renderer (warpviz.render) is not available in this build of warpviz")
    return fn


def _parse_size(value: Optional[str]) -> Optional[tuple[int, int]]:
    if value is None:
        return None
    m = re.fullmatch(r"\s*(\d+)\s*[xX*]\s*(\d+)\s*", value)
    if not m or int(m.group(1)) < 1 or int(m.group(2)) < 1:
        raise typer.BadParameter(f"expected WIDTHxHEIGHT with positive integers, e.g. 320x240; got {value!r}")
    return int(m.group(1)), int(m.group(2))


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


def _output_path(path: Path, suffixes: tuple[str, ...]) -> Path:
    if path.suffix.lower() not in suffixes:
        _fail(f"output {str(path)!r} must end in {' or '.join(suffixes)}", EXIT_BAD_INPUT)
    if not path.parent.is_dir():
        _fail(f"output folder {str(path.parent)!r} does not exist", EXIT_BAD_INPUT)
    return path


@contextlib.contextmanager
def _progress_bar(label: str, *, enabled: bool):
    """A rich progress bar on stderr; yields the ``progress(done, total)`` callback for the renderer."""
    columns = (TextColumn("{task.description}"), BarColumn(), TaskProgressColumn(), MofNCompleteColumn(),
               TimeElapsedColumn(), TimeRemainingColumn())  # fmt: skip
    with Progress(*columns, console=err, disable=not enabled, transient=False) as progress:
        task = progress.add_task(label, total=None)

        def update(done: int, total: int) -> None:
            progress.update(task, completed=int(done), total=int(total))

        yield update


def _render_scene(scene: Scene, *, spp, size, seed, threads, flat, paper, light_sampling, progress, record_pixels=None,
                  light_connection=None):
    """Call warpviz.render with the command line's options; bad options become exit code 2."""
    render = _renderer()
    width, height = size if size is not None else (None, None)
    try:
        return render(scene, spp=spp, width=width, height=height, seed=seed, threads=threads, flat=flat,
                      light_sampling=light_sampling, paper=paper, progress=progress,
                      record_pixels=record_pixels, light_connection=light_connection)  # fmt: skip
    except (ValueError, TypeError) as exc:
        if isinstance(exc, SceneError):
            raise
        _fail(str(exc), EXIT_BAD_INPUT)


def _keep_aovs(img: Any, names: Optional[list[str]]) -> None:
    """Drop the AOVs a scene's ``[outputs] aovs`` does not list (only before writing an EXR)."""
    aovs = getattr(img, "aovs", None)
    if names is None or not isinstance(aovs, dict):
        return
    for key in [k for k in aovs if k not in names]:
        del aovs[key]


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
        "Default: the scene's [outputs] file, else SCENE_NAME.png.",
    ),  # fmt: skip
    spp: Optional[int] = typer.Option(None, "--spp", min=1, help="Samples per pixel (default: the scene's)."),
    size: Optional[str] = typer.Option(
        None, "--size", callback=_parse_size, help="Image size WIDTHxHEIGHT, e.g. 320x240."
    ),
    threads: int = typer.Option(0, "--threads", min=0, help="Worker threads; 0 uses every core."),
    seed: Optional[int] = typer.Option(None, "--seed", min=0, help="Random seed (default: the scene's)."),
    flat: bool = typer.Option(False, "--flat", help="Render the same scene in flat space, for comparison."),
    paper: bool = typer.Option(False, "--paper", help="Use the scene's [render.paper] size and sample count."),
    no_light_sampling: bool = typer.Option(
        False, "--no-light-sampling", help="Brute-force path tracing, without light connection."
    ),
    light_connection: Optional[str] = typer.Option(
        None, "--light-connection",
        help="How light samples find the lights in curved space: 'lens' (default: every lensed image, exact "
        "in Schwarzschild, Reissner-Nordstrom and Ellis, Newton-refined proxies in Kerr) or 'aimed' (the "
        "older flat-space proxies aimed by pilot geodesics, for comparison).",
    ),  # fmt: skip
    quiet: bool = typer.Option(False, "--quiet", "-q", help="No progress bar."),
) -> None:
    """Render a scene to a PNG or EXR image. Ctrl-C stops early and saves the partial image (exit 130)."""
    with _guard():
        sc = load_scene(scene)
        target = output or Path(sc.outputs.get("file") or f"{sc.path.stem if sc.path else 'scene'}.png")
        target = _output_path(target, IMAGE_SUFFIXES)
        _renderer()
        t0 = time.perf_counter()
        with _progress_bar(sc.path.stem if sc.path else "scene", enabled=not quiet) as progress:
            img = _render_scene(sc, spp=spp, size=size, seed=seed, threads=threads, flat=flat, paper=paper,
                                light_sampling=False if no_light_sampling else None, progress=progress,
                                light_connection=light_connection)  # fmt: skip
        if target.suffix.lower() == ".exr":
            _keep_aovs(img, sc.outputs.get("aovs"))
        img.save(target)
        seconds = time.perf_counter() - t0
        h, w = np.shape(img.rgb)[:2]
        if not getattr(img, "completed", True):
            err.print(Text(f"interrupted: saved the partial image ({w}x{h}) to {target}", style="yellow"))
            raise typer.Exit(EXIT_INTERRUPTED)
        err.print(f"wrote {target} ({w}x{h}, {seconds:.1f} s)")


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
    spp: Optional[int] = typer.Option(None, "--spp", min=1, help="Samples per pixel (default: the scene's)."),
    size: Optional[str] = typer.Option(None, "--size", callback=_parse_size, help="Image size WIDTHxHEIGHT."),
    threads: int = typer.Option(0, "--threads", min=0, help="Worker threads; 0 uses every core."),
    seed: Optional[int] = typer.Option(None, "--seed", min=0, help="Random seed (default: the scene's)."),
    flat: bool = typer.Option(False, "--flat", help="Flat space instead of the scene's metric."),
    paper: bool = typer.Option(False, "--paper", help="Use the scene's [render.paper] settings."),
    quiet: bool = typer.Option(False, "--quiet", "-q", help="No progress bar."),
) -> None:
    """Render a scene and save the sampled light paths of chosen pixels as a .vtp file."""
    with _guard():
        sc = load_scene(scene)
        record = _parse_pixels(pixels)
        width, height = size if size is not None else sc.size(paper=paper)
        outside = [(int(x), int(y)) for x, y in record if not (x < width and y < height)]
        if outside:
            _fail(f"pixel {outside[0][0]},{outside[0][1]} is outside the {width}x{height} image", EXIT_BAD_INPUT)
        target = _output_path(output, (".vtp",))
        picture = _output_path(image, IMAGE_SUFFIXES) if image is not None else None
        _renderer()
        with _progress_bar("tracing", enabled=not quiet) as progress:
            img = _render_scene(sc, spp=spp, size=size, seed=seed, threads=threads, flat=flat, paper=paper,
                                light_sampling=None, progress=progress, record_pixels=record)  # fmt: skip
        rays = getattr(img, "rays", None)
        if rays is None:
            _fail("the renderer returned no recorded rays")
        save = getattr(rays, "save", None)
        if not callable(save):
            _fail("saving rays needs RayBundle.save, which this build of warpviz does not have yet")
        save(target)
        if picture is not None:
            if picture.suffix.lower() == ".exr":
                _keep_aovs(img, sc.outputs.get("aovs"))
            img.save(picture)
        err.print(f"wrote {target} ({len(record)} pixels)" + (f" and {picture}" if picture else ""))
        if not getattr(img, "completed", True):
            raise typer.Exit(EXIT_INTERRUPTED)


@app.command()
def view(
    target: str = typer.Argument(..., help="Scene (.toml or shipped name), or recorded rays (.vtp) or a scene .vtm."),
    pixels: Optional[list[str]] = typer.Option(
        None, "--pixels", "-p", help="Pixels X,Y (at the preview size) whose paths are shown; repeatable."
    ),
    screenshot: Optional[Path] = typer.Option(
        None, "--screenshot", help="Write a PNG of the view; without a display the view is only written."
    ),
) -> None:
    """Open the PyVista teaching view: the image beside the 3-D paths of its light rays."""
    with _guard():
        viewer = _api("view", "viewer")
        if viewer is None:
            _fail("the PyVista viewer (warpviz.view) is not available in this build of warpviz")
        path = Path(target)
        if path.is_file() and path.suffix.lower() in (".vtp", ".vtm"):
            obj: Any = path
        elif path.is_file() and path.suffix.lower() != ".toml":
            _fail(f"{target}: can view a scene (.toml or a shipped name), a .vtp or a .vtm file", EXIT_BAD_INPUT)
        elif path.is_file() or not looks_like_path(target):
            obj = load_scene(target)
        else:
            _fail(f"{target}: no such file", EXIT_BAD_INPUT)
        options: dict[str, Any] = {}
        if pixels:
            options["pixels"] = _parse_pixels(pixels)
        if screenshot is not None:
            options["screenshot"] = _output_path(screenshot, (".png",))
        viewer(obj, **options)
        if screenshot is not None:
            err.print(f"wrote {screenshot}")


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
        table.add_row("renderer", "available" if _api("render", "render") else "not in this build")
        table.add_row("viewer", "available" if _api("view", "viewer") else "not in this build")
        folders = ", ".join(str(d) for d in scene_dirs()) or "nowhere"
        table.add_row("scenes", f"{len(shipped_scenes())} shipped in {folders}")
        for dist in ("numpy", "trimesh", "pillow", "OpenEXR", "typer", "rich", "pyvista", "vtk"):
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
}


@app.command(context_settings={"allow_extra_args": True, "ignore_unknown_options": True})
def bench(ctx: typer.Context) -> None:
    """Run a benchmark: `warpviz bench SUITE OPTIONS`, SUITE one of geodesics, work-precision, render, skips,
    light-connection.

    Without a SUITE it runs the far-observer geodesic benchmark (benchmarks/bench_geodesics.py); every
    suite takes its own options after the name, e.g. `warpviz bench --size 32` or
    `warpviz bench render --quick`.
    """
    with _guard():
        args = list(ctx.args)
        suite = args.pop(0) if args and args[0] in BENCH_SUITES else "geodesics"
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
