"""The typer application every command registers with, and its ``--version``.
"""

from __future__ import annotations

import typer

import warpviz
from warpviz.cli.common import EXIT_OK, out

app = typer.Typer(
    name="warpviz",
    help="Render and explain light in curved spacetime (black holes and wormholes).",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,  # help texts are plain: "[outputs] file" must not be read as markup
)


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
