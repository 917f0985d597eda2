"""``warpviz doctor``: what this installation has and can do.
"""

from __future__ import annotations

import importlib
import importlib.metadata
import importlib.util
import os
import platform
import subprocess
import sys
from pathlib import Path

import typer
from rich.table import Table

import warpviz
from warpviz.cli.app import app
from warpviz.cli.common import _OFFSCREEN_PROBE, _guard, out
from warpviz.scene.catalog import scene_dirs, shipped_scenes


def _package_version(dist: str) -> str:
    try:
        return importlib.metadata.version(dist)
    except importlib.metadata.PackageNotFoundError:
        return "not installed"


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
