"""The ``warpviz`` command line: render, trace, view and check scenes.

Commands: ``render``, ``animate``, ``trace``, ``view``, ``serve``, ``validate``, ``scenes``, ``bench``, ``doctor``; ``warpviz COMMAND
--help`` describes each. A scene is given as a path to a TOML file or as the name of a shipped scene
(``fig07``; see :mod:`warpviz.scene.catalog`).

Exit codes: 0 success; 1 runtime error; 2 bad input (invalid scene file, bad option, an image too large
for the machine's memory, an output that may not be written; the message goes to stderr without a
traceback, and nothing is written); 3 the render finished but more of its samples failed than
``--max-error-fraction`` allows (the image is written, so it can be inspected); 130 interrupted by Ctrl-C
and 143 stopped by SIGTERM (``render`` and ``trace`` first save the partial image). Set
``WARPVIZ_DEBUG=1`` to see tracebacks of runtime errors.

One module per command (``render``, ``trace``, ...); :mod:`~warpviz.cli.common` holds what they share,
:mod:`~warpviz.cli.flags` the flags several commands take (each defined once) and :mod:`~warpviz.cli.app`
the typer application they register with.
"""

from __future__ import annotations

# each command module registers its command with the app when imported
from warpviz.cli import animate, bench, common, doctor, render, scenes, serve, trace, validate, view  # noqa: F401
from warpviz.cli.app import app
from warpviz.cli.common import (
    EXIT_BAD_INPUT,
    EXIT_ERROR,
    EXIT_INTERRUPTED,
    EXIT_OK,
    EXIT_RENDER_FAILED,
    EXIT_TERMINATED,
)

__all__ = ["EXIT_BAD_INPUT", "EXIT_ERROR", "EXIT_INTERRUPTED", "EXIT_OK", "EXIT_RENDER_FAILED", "EXIT_TERMINATED",
           "app", "common", "main"]


def main() -> None:
    """Entry point of the ``warpviz`` console script."""
    app(prog_name="warpviz")


if __name__ == "__main__":  # pragma: no cover
    main()
