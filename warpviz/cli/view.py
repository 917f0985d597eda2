"""``warpviz view``: the PyVista teaching view of a scene, a ray file or a scene ``.vtm``.
"""

from __future__ import annotations

import contextlib
from pathlib import Path
from typing import Any, Optional

import typer

from warpviz.cli import common
from warpviz.cli.app import app
from warpviz.cli.common import EXIT_BAD_INPUT, _checked, _fail, _guard, _output_path, _parse_pixels, err
from warpviz.limits import MAX_SPP, duration_seconds
from warpviz.scene import load_scene
from warpviz.scene.catalog import looks_like_path


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
        viewer = common._viewer()
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
