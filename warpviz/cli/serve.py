"""``warpviz serve``: the teaching view as a local web page (trame).
"""

from __future__ import annotations

import errno
import sys

import typer

from warpviz.cli.app import app
from warpviz.cli.common import EXIT_BAD_INPUT, _fail, _guard, err, out
from warpviz.scene import load_scene


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
            from warpviz.web.app import require_web
            from warpviz.web.app import serve as serve_app

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
