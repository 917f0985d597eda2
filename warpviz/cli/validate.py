"""``warpviz validate``: check scene files without rendering.
"""

from __future__ import annotations

from pathlib import Path

import typer
from rich.text import Text

from warpviz.cli.app import app
from warpviz.cli.common import EXIT_BAD_INPUT, _guard, err, out
from warpviz.scene import SceneError, load_scene


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
