"""``warpviz scenes``: the shipped scenes.
"""

from __future__ import annotations

import typer
from rich.table import Table

from warpviz.cli.app import app
from warpviz.cli.common import _fail, _guard, out
from warpviz.scene.catalog import scene_description, scene_dirs, shipped_scenes


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
