"""The teaching view as a local web app (``warpviz serve SCENE``), built on trame.

The page holds the rendered preview (a click on a pixel selects that pixel's light paths), the 3-D
panel of the teaching view (:class:`warpviz.viewer.window.TeachingView`, rendered on the server by VTK
and streamed to the page: dragging rotates it, a click on a ray selects it), a status line, and sliders
for the metric's parameters and the camera distance (:mod:`warpviz.web.controls`) that re-render the
preview in the background. Everything runs on this machine; nothing is downloaded.

Needs the optional dependencies of ``pip install "warpviz[web]"`` (trame, trame-vuetify, trame-vtk).

In Jupyter the same page shows in the notebook::

    from warpviz.web import TeachingApp
    app = TeachingApp("fig09")
    await app.ready   # starts the server inside the kernel
    app               # the page, in an iframe
"""

from __future__ import annotations

import asyncio
import base64
import io
from collections.abc import Mapping
from dataclasses import replace

import numpy as np

from warpviz.web.controls import apply_controls, image_click_to_pixel, slider_specs

__all__ = ["MISSING_WEB", "TeachingApp", "require_web", "serve"]

#: What to install when trame is missing.
MISSING_WEB = 'the web app needs trame: pip install "warpviz[web]" (trame, trame-vuetify, trame-vtk)'

#: Width in screen pixels of the picture on the page, and the 3-D panel's size.
IMAGE_WIDTH = 480
PANEL_SIZE = (640, 480)

#: Colours of the outlines of a selected pixel and of pixels with recorded paths (as in the window).
_SELECTED_RGB = (255, 0, 255)
_RECORDED_RGB = (160, 160, 160)


def require_web() -> None:
    """Raise ImportError with :data:`MISSING_WEB` unless trame and its widgets can be imported."""
    try:
        import trame  # noqa: F401
        import trame_vtk  # noqa: F401
        import trame_vuetify  # noqa: F401
    except ImportError as exc:
        raise ImportError(MISSING_WEB) from exc


def _native_of(scene) -> dict:
    """The native scene dict of a scene file name, path, Scene or native dict."""
    if isinstance(scene, Mapping):
        return dict(scene)
    from warpviz.scene import load_scene

    if not hasattr(scene, "native"):
        scene = load_scene(scene)  # a path or a shipped scene's name
    return scene.native(flat=False, width=None, height=None, paper=False)


def picture_png(image: np.ndarray, selected=(), *, scale: int = 1, recorded=()) -> bytes:
    """The preview as PNG bytes, each pixel ``scale`` screen pixels wide, pixels with recorded paths
    outlined grey and selected ones magenta.

    Parameters
    ----------
    image : numpy.ndarray
        (H, W, 3) uint8 picture.
    selected : iterable of tuple of int
        (x, y) pixels to outline (y from the top row).
    scale : int, keyword-only
        Nearest-neighbour magnification (>= 1).
    recorded : iterable of tuple of int, keyword-only
        (x, y) pixels whose paths were recorded.

    Returns
    -------
    bytes
        A PNG file.
    """
    from PIL import Image as PILImage

    s = max(int(scale), 1)
    big = np.repeat(np.repeat(np.asarray(image, dtype=np.uint8), s, axis=0), s, axis=1).copy()
    h, w = image.shape[:2]
    t = max(1, s // 4)
    for pixels, rgb in ((recorded, _RECORDED_RGB), (selected, _SELECTED_RGB)):
        for x, y in pixels:
            if 0 <= x < w and 0 <= y < h:
                y0, y1, x0, x1 = y * s, (y + 1) * s, x * s, (x + 1) * s
                for sl in ((slice(y0, y0 + t), slice(x0, x1)), (slice(y1 - t, y1), slice(x0, x1)),
                           (slice(y0, y1), slice(x0, x0 + t)), (slice(y0, y1), slice(x1 - t, x1))):  # fmt: skip
                    big[sl] = rgb
    buf = io.BytesIO()
    PILImage.fromarray(big).save(buf, format="PNG")
    return buf.getvalue()


class TeachingApp:
    """One web teaching view: the scene, its preview, the 3-D panel and the trame server that shows them.

    Parameters
    ----------
    scene : str, os.PathLike, warpviz.scene.Scene or dict
        A shipped scene name, a scene file, a Scene or a native scene dict.
    preview_width : int, keyword-only
        Width in pixels of the preview render.
    spp : int, keyword-only
        Samples per pixel of the preview render.
    server : trame server or str, optional, keyword-only
        The trame server (or its name) to build on; default a new one.

    Attributes
    ----------
    native : dict
        The native scene as the sliders last set it.
    content : warpviz.viewer.view_content.ViewContent
        What is shown now.
    teaching : warpviz.viewer.window.TeachingView
        The 3-D panel's state (selection, status).
    renders : int
        Preview renders done so far (1 after start-up).
    """

    _count = 0

    def __init__(self, scene, *, preview_width: int = 96, spp: int = 4, server=None):
        require_web()
        import pyvista as pv
        from trame.app import get_server

        self.base = _native_of(scene)
        self.preview_width = int(preview_width)
        self.spp = int(spp)
        self._generation = 0
        self.native, self.content = self._preview({})
        self.renders = 1
        self.plotter = pv.Plotter(off_screen=True, window_size=list(PANEL_SIZE), border=False)
        self.teaching = self._build_panel()
        TeachingApp._count += 1  # one trame server per app: two apps in one Jupyter kernel stay apart
        self.server = server if server is not None and not isinstance(server, str) else get_server(
            server or f"warpviz-{TeachingApp._count}", client_type="vue3")
        self.sliders = slider_specs(self.base)
        self._init_state()
        self._build_ui()

    # ------------------------------------------------------------------ state

    def _build_panel(self):
        from warpviz.viewer.window import TeachingView

        self.plotter.clear()
        self.plotter.clear_button_widgets()
        return TeachingView(replace(self.content, image=None), self.plotter)

    def _picture_src(self) -> str:
        img = self.content.image
        scale = max(1, IMAGE_WIDTH // img.shape[1])
        png = picture_png(img, self.teaching.selected, scale=scale, recorded=[tuple(p) for p in self._recorded()])
        return "data:image/png;base64," + base64.b64encode(png).decode("ascii")

    def _init_state(self) -> None:
        state = self.server.state
        state.image_src = self._picture_src()
        state.status = self._status()
        state.hint = self._hint()
        state.busy = False
        state.problem = ""
        for s in self.sliders:
            state[f"slider_{s['name']}"] = s["value"]
        state.change(*[f"slider_{s['name']}" for s in self.sliders])(self._on_slider)

    def _hint(self) -> str:
        """Which pixels have recorded paths (outlined grey in the picture), with what they show."""
        labels = self.content.pixel_labels
        marks = self._recorded()
        if not len(marks):
            return "no recorded paths"
        named = [f"{labels[(int(x), int(y))]} ({x}, {y})" if (int(x), int(y)) in labels else f"({x}, {y})"
                 for x, y in marks[:6]]  # fmt: skip
        more = f" and {len(marks) - 6} more" if len(marks) > 6 else ""
        return "click a pixel outlined in grey: " + ", ".join(named) + more

    def _recorded(self) -> np.ndarray:
        from warpviz.viewer.picking import recorded_pixels

        rays = self.content.rays
        return recorded_pixels(rays) if rays is not None else np.zeros((0, 2), dtype=np.int64)

    def _status(self) -> str:
        h, w = self.content.image.shape[:2]
        return f"{self.content.title} ({w}x{h}, {self.content.preview['spp']} spp): {self.teaching.status()}"

    def _push(self) -> None:
        """Send the picture, the status and the 3-D panel to the page."""
        state = self.server.state
        state.image_src = self._picture_src()
        state.status = self._status()
        state.hint = self._hint()
        self.server.controller.view_update()

    # ------------------------------------------------------------------ events

    def click_image(self, x: float, y: float, shown_w: float, shown_h: float) -> tuple[int, int]:
        """Select the pixel under a click at (x, y) on the picture shown ``shown_w`` x ``shown_h``."""
        h, w = self.content.image.shape[:2]
        pixel = image_click_to_pixel(x, y, shown=(shown_w, shown_h), size=(w, h))
        self.teaching.select_pixel(*pixel)
        self._push()
        return pixel

    def slider_values(self) -> dict[str, float]:
        """The sliders' current values, by name."""
        return {s["name"]: float(self.server.state[f"slider_{s['name']}"]) for s in self.sliders}

    def _preview(self, values: Mapping[str, float]):
        """The native scene the slider ``values`` describe and its rendered view content (blocking)."""
        from warpviz.viewer.view_content import view_content

        native = apply_controls(self.base, values)
        return native, view_content(native, preview_width=self.preview_width, spp=self.spp)

    def rerender(self, values: Mapping[str, float]) -> None:
        """Render the preview of the scene the slider ``values`` describe and show it (blocking)."""
        self._show(*self._preview(values))

    def _show(self, native: dict, content) -> None:
        self.native, self.content = native, content
        self.renders += 1
        self.teaching = self._build_panel()  # frames the 3-D panel as the window does
        self._push()

    def _on_slider(self, **_) -> None:
        from trame.app import asynchronous

        self._generation += 1
        asynchronous.create_task(self._rerender_later(self._generation, self.slider_values()))

    async def _rerender_later(self, generation: int, values: dict[str, float]) -> None:
        """Re-render in a worker thread after the slider has rested a moment; a newer move wins."""
        await asyncio.sleep(0.15)
        if generation != self._generation:
            return
        state = self.server.state
        with state:
            state.busy, state.problem = True, ""
        try:
            native, content = await asyncio.to_thread(self._preview, values)
        except ValueError as exc:  # parameters the metric refuses: say so, keep the last picture
            with state:
                state.busy, state.problem = False, str(exc)
            return
        if generation != self._generation:
            return
        with state:
            self._show(native, content)
            state.busy = False

    # ------------------------------------------------------------------ page

    def _build_ui(self) -> None:
        from trame.ui.vuetify3 import SinglePageLayout
        from trame.widgets import html, vuetify3
        from trame.widgets import vtk as vtk_widgets

        server, ctrl = self.server, self.server.controller
        ctrl.click_image = self.click_image
        ctrl.on_server_bind.add(_answer_session_probe)
        server.state.trame__title = f"warpviz: {self.content.title}"  # the browser tab's title
        with SinglePageLayout(server, full_height=True) as layout:
            layout.title.set_text(f"warpviz: {self.content.title}")
            with layout.toolbar:
                vuetify3.VSpacer()
                vuetify3.VProgressCircular(v_show=("busy",), indeterminate=True, size=24, classes="mr-4")
            with layout.content:
                with vuetify3.VContainer(fluid=True, classes="pa-2"):
                    with vuetify3.VRow(dense=True):
                        with vuetify3.VCol(cols="auto"):
                            html.Img(
                                id="warpviz-image", src=("image_src",), width=IMAGE_WIDTH,
                                style="image-rendering: pixelated; cursor: crosshair; display: block;",
                                click=(ctrl.click_image, "[$event.offsetX, $event.offsetY, "
                                       "$event.target.clientWidth, $event.target.clientHeight]"),
                            )  # fmt: skip
                            html.Div("{{ status }}", id="warpviz-status", classes="text-body-2 mt-2",
                                     style=f"max-width: {IMAGE_WIDTH}px")  # fmt: skip
                            html.Div("{{ problem }}", id="warpviz-problem", classes="text-error text-body-2")
                            html.Div("{{ hint }}", id="warpviz-hint", classes="text-caption",
                                     style=f"max-width: {IMAGE_WIDTH}px")  # fmt: skip
                            for s in self.sliders:
                                # room above each slider for its value, which floats above the thumb
                                with html.Div(id=f"warpviz-slider-{s['name']}", classes="warpviz-slider",
                                              style=f"max-width: {IMAGE_WIDTH}px; padding-top: 30px"):  # fmt: skip
                                    vuetify3.VSlider(
                                        v_model=(f"slider_{s['name']}",), label=s["label"], min=s["min"],
                                        max=s["max"], step=s["step"], thumb_label="always", hide_details=True,
                                    )  # fmt: skip
                        with vuetify3.VCol():
                            with html.Div(id="warpviz-3d",
                                          style=f"width: {PANEL_SIZE[0]}px; height: {PANEL_SIZE[1]}px;"):  # fmt: skip
                                view = vtk_widgets.VtkRemoteView(self.plotter.ren_win, interactive_ratio=1)
                                ctrl.view_update = view.update
        self.layout = layout

    @property
    def ready(self):
        """In Jupyter: ``await app.ready`` starts the server as a task of the kernel's event loop; then
        displaying ``app`` (the last expression of a cell) shows the page in the notebook."""
        return self.layout.ready

    @property
    def url(self) -> str:
        """The page's address once the server runs."""
        return self.layout.url

    def _ipython_display_(self):
        self.layout._ipython_display_()

    def start(self, *, port: int = 0, host: str = "127.0.0.1", open_browser: bool = False, ready=None) -> None:
        """Serve the page until interrupted (blocking).

        Parameters
        ----------
        port : int, keyword-only
            TCP port; 0 picks a free one.
        host : str, keyword-only
            Interface to listen on (default: this machine only).
        open_browser : bool, keyword-only
            Open the page in the default browser.
        ready : callable, optional, keyword-only
            Called with the page's URL once the server listens.
        """
        import sys

        if ready is not None:
            self.server.controller.on_server_ready.add(lambda **_: ready(f"http://{host}:{self.server.port}/"))
        argv, sys.argv = sys.argv, sys.argv[:1]  # trame reads its own options from sys.argv: give it none
        try:
            self.server.start(port=port, host=host, open_browser=open_browser, show_connection_info=False,
                              disable_logging=True, timeout=0)  # fmt: skip
        finally:
            sys.argv = argv


def _answer_session_probe(wslink_server) -> None:
    """Answer the trame page's session-manager probe (``POST /paraview/``) with this server's own
    WebSocket, so the page connects at once instead of logging a 405 error in the browser console and
    falling back to the same address."""
    from aiohttp import web

    async def session(request):
        scheme = "wss" if request.secure else "ws"
        return web.json_response({"sessionURL": f"{scheme}://{request.host}/ws"})

    wslink_server.app.router.add_post("/paraview/", session)


def serve(scene, *, port: int = 0, host: str = "127.0.0.1", open_browser: bool = False, preview_width: int = 96,
          spp: int = 4, ready=None) -> None:
    """Serve the teaching view of ``scene`` as a local web page (blocking; see :class:`TeachingApp`).

    Raises
    ------
    ImportError
        trame is not installed (the message says what to install).
    """
    TeachingApp(scene, preview_width=preview_width, spp=spp).start(port=port, host=host, open_browser=open_browser,
                                                                   ready=ready)  # fmt: skip
