"""The teaching view: a rendered image beside the 3-D paths of its light rays, linked by clicks.

:func:`view` opens a PyVista window with two panels. On the left is the rendered image (tonemapped
with :meth:`warpviz.Image.to_uint8`) with the pixels whose paths were recorded outlined and the pixels the
view chose labelled in words (edge of the shadow, light bent round the hole, light that hardly bends); on the right the 3-D scene: the recorded rays as
polylines coloured by the largest drift of their conserved quantities against the size of their terms
(``log10_error_scaled``: the digits each kept; the relative drift |X − X₀| / |X₀| is ``log10_error``, see
:class:`warpviz.RayBundle`), or by ``r``, redshift or affine parameter, with a colour bar naming the
quantity; the scene's shapes; the spacetime's landmarks (horizon, ergosphere, photon sphere or Kerr photon
region, Ellis throat) drawn translucent and labelled with their radii (in M, or throat radii, with the
scene value beside them: :func:`~warpviz.viewer.annotations.length_text`); the camera; axes in scene
units (in M where M = 1); a title with the metric and its parameters and a legend of what is drawn. An Ellis wormhole is drawn as its
embedding diagram with the rays and the objects of both sheets on it. By default only the camera
segment of each chosen pixel's paths is drawn; bounces come on demand.

* Click a pixel in the image (a left click without dragging, or a right click): its recorded paths
  light up in 3-D.
* Click a ray in 3-D: its pixel is outlined in the image and its paths light up.
* Press ``f`` (or tick the box in the 3-D panel): the straight flat-space camera ray of each selected
  pixel (without a selection: of each chosen pixel) is drawn beside the bent one.
* Press ``c``: the next colouring (drift, r, redshift, affine parameter).
* Press ``n``: one bounce more of each path (after the last: all of them; then back to the camera
  segments).

The words of the view (colour-bar titles, labels, title, legend) come from
:mod:`~warpviz.viewer.annotations` (pure functions). The logic behind the clicks lives in :mod:`warpviz.viewer.picking` and :mod:`warpviz.scene.camera` (pure
functions); :class:`~warpviz.viewer.window.TeachingView` holds the state of one window and can be driven
from code, which is how the view is tested off-screen. This module holds the entry point :func:`view`;
:mod:`~warpviz.viewer.view_content` gathers what is shown, :mod:`~warpviz.viewer.meshes` builds the
display meshes and :mod:`~warpviz.viewer.offscreen` decides whether a window opens.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from warpviz.viewer.annotations import DEFAULT_COLORING, default_bounces
from warpviz.viewer.offscreen import default_off_screen
from warpviz.viewer.view_content import view_content
from warpviz.viewer.window import TeachingView

__all__ = ["view"]

_THEMES = {"document": "DocumentTheme", "dark": "DarkTheme", "paraview": "ParaViewTheme",
           "document_pro": "DocumentProTheme"}  # fmt: skip


def _theme(theme):
    if theme is None or not isinstance(theme, str):
        return theme
    from pyvista.plotting import themes

    if theme not in _THEMES:
        raise ValueError(f"unknown theme {theme!r}; known: {', '.join(_THEMES)} (or a pyvista Theme)")
    return getattr(themes, _THEMES[theme])()


# --------------------------------------------------------------------------------------------------
# entry point


def view(
    obj,
    *,
    off_screen: bool | None = None,
    screenshot: str | os.PathLike | None = None,
    window_size: tuple[int, int] = (1400, 700),
    pixels=None,
    show_flat: bool = False,
    color_by: str = DEFAULT_COLORING,
    bounces: int | None | str = "auto",
    theme=None,
    return_plotter: bool = False,
    preview_width: int = 96,
    spp: int | None = 4,
    time_limit: float | str | None = None,
    jupyter_backend: str | None = None,
    refine: bool = True,
):
    """Show a render beside the 3-D paths of its light rays.

    Parameters
    ----------
    obj : Image, RayBundle, str, os.PathLike, warpviz.scene.Scene or dict
        An :class:`~warpviz.Image` from :func:`warpviz.render` (rendered with ``record_pixels`` to have
        paths to show), a recorded :class:`~warpviz.RayBundle`, a ``.vtp`` ray file or scene ``.vtm``,
        or a scene (file, Scene or native dict), which is first rendered at ``preview_width`` pixels
        across, recording the paths of ``pixels`` or of a few chosen pixels (the shadow's or throat's
        edge, the lensed light, a plain one: :func:`warpviz.viewer.picking.teaching_pixels`).
    off_screen : bool, optional, keyword-only
        Render without a window; default :func:`default_off_screen` (off-screen without a display or
        with ``PYVISTA_OFF_SCREEN=true``).
    screenshot : str or os.PathLike, optional, keyword-only
        Write a PNG of the window (atomically). Off-screen it is written at once and the window closed;
        on-screen when the window is closed.
    window_size : tuple of int, keyword-only
        (width, height) of the window in screen pixels.
    pixels : array_like of int, optional, keyword-only
        (K, 2) pixels (x, y) selected at the start: outlined in the image, their paths highlighted (and
        their flat-space rays drawn with ``show_flat``). For a scene, the pixels whose paths are
        recorded (at the preview size).
    show_flat : bool, keyword-only
        Start with the straight flat-space camera rays shown (key ``f``): of the selected pixels, or
        without a selection of the pixels the view chose.
    color_by : str, keyword-only
        What the rays are coloured by: a colouring of
        :data:`~warpviz.viewer.annotations.COLORINGS` (``"drift"``: log10 of the largest term-scaled
        drift of the conserved quantities, ``"r"``, ``"redshift"``, ``"affine"``; key ``c`` cycles them) or any
        point array of the rays (``"log10_error"``, ``"step_size"``, ...).
    bounces : int or None or "auto", keyword-only
        Largest bounce of each recorded path drawn (0: the camera segments only; None: every segment;
        key ``n`` shows one more). ``"auto"``: :func:`~warpviz.viewer.annotations.default_bounces`
        (camera segments for the pixels the view chose, everything for pixels given).
    theme : str or pyvista.plotting.themes.Theme, optional, keyword-only
        ``"document"``, ``"dark"``, ``"paraview"``, ``"document_pro"`` or a Theme; default PyVista's.
    return_plotter : bool, keyword-only
        Return the (not yet shown) plotter instead of showing it; its ``teaching_view`` attribute is
        the :class:`TeachingView`. Close it with ``plotter.close()``.
    preview_width : int, keyword-only
        Width in pixels of the preview render of a scene.
    spp : int or None, keyword-only
        Samples per pixel of the preview render (None with ``time_limit``: as many as fit).
    time_limit : float or str, optional, keyword-only
        A time budget for the preview render: seconds or ``"30s"``, ``"2m"`` (with ``spp``, whichever
        comes first), for a clean image panel at once.
    refine : bool, keyword-only
        In a window, refine a scene's preview while the window is open: passes with more samples render
        on a background thread and replace the image (:meth:`TeachingView.start_refining`, up to
        :data:`~warpviz.viewer.progressive.DEFAULT_MAX_SPP` samples per pixel). Off-screen and with
        ``return_plotter`` the image stays the preview (call ``start_refining`` yourself).
    jupyter_backend : str, optional, keyword-only
        Passed to :meth:`pyvista.Plotter.show` in Jupyter: ``"trame"`` (server-side rendering: clicks
        and keys work), ``"client"`` (browser-side, no picking) or ``"static"`` (a picture).

    Returns
    -------
    pyvista.Plotter or pathlib.Path or None
        The plotter with ``return_plotter``; else the screenshot path, or None.

    Raises
    ------
    TypeError
        ``obj`` is none of the accepted kinds.
    ValueError
        A bundle without recorded paths, ``color_by`` neither a colouring nor a point array of the rays,
        or ``bounces`` negative.

    Examples
    --------
    >>> import warpviz as wv
    >>> rays = wv.trace(wv.Schwarzschild(mass=1.0), [-30.0, 0, 0], [[1, 0.1, 0], [1, 0.2, 0]], record=True)
    >>> plotter = wv.view(rays, off_screen=True, return_plotter=True, window_size=(300, 200))
    >>> plotter.teaching_view.select_ray(1) is None   # traced rays have no pixels
    True
    >>> plotter.teaching_view.selected_rays().tolist()
    [1]
    >>> plotter.close()
    """
    import pyvista as pv

    if screenshot is not None and Path(screenshot).suffix.lower() != ".png":
        raise ValueError(f"screenshot must be a .png file, got {str(screenshot)!r}")
    theme = _theme(theme)
    if pixels is not None:
        pixels = np.asarray(pixels, dtype=np.int64).reshape(-1, 2)
    if isinstance(bounces, str) and bounces != "auto":
        raise ValueError(f"bounces must be an integer >= 0, None or 'auto', got {bounces!r}")
    if bounces is not None and not isinstance(bounces, str) and int(bounces) < 0:
        raise ValueError(f"bounces must be >= 0 (0: camera segments only), got {bounces}")
    content = view_content(obj, pixels=pixels, preview_width=preview_width, spp=spp, time_limit=time_limit)
    if bounces == "auto":
        bounces = default_bounces(bool(content.pixel_labels))
    if off_screen is None:
        off_screen = default_off_screen()
    shape = (1, 2) if content.image is not None else (1, 1)
    plotter = pv.Plotter(shape=shape, off_screen=bool(off_screen), window_size=list(window_size),
                         theme=theme, border=False)  # fmt: skip
    try:
        teaching = TeachingView(content, plotter, color_by=color_by, show_flat=show_flat, bounces=bounces)
        if pixels is not None:
            teaching.select_pixels(pixels)
        getattr(pv, "set_new_attribute", setattr)(plotter, "teaching_view", teaching)
    except BaseException:
        plotter.close()
        raise

    if return_plotter:
        if screenshot is not None:
            _save_screenshot(plotter, screenshot)
        return plotter
    if off_screen:
        try:
            return _save_screenshot(plotter, screenshot) if screenshot is not None else None
        finally:
            plotter.close()
    shot = Path(screenshot) if screenshot is not None else None
    if refine:
        teaching.start_refining()
    try:
        plotter.show(title=f"warpviz: {content.title}", screenshot=str(shot) if shot else None,
                     jupyter_backend=jupyter_backend)  # fmt: skip
    finally:
        teaching.stop_refining()
    return shot


def _save_screenshot(plotter, path: str | os.PathLike) -> Path:
    """Render and write a PNG of the window, atomically."""
    from warpviz.io import write_png

    return write_png(path, plotter.screenshot(return_img=True))
