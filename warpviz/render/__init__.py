"""Rendering: :func:`render` path-traces a scene whose light rays are null geodesics and returns an
:class:`Image`.

:mod:`~warpviz.render.render` resolves the options (:data:`DEFAULT_OPTIONS`) and calls the core;
:mod:`~warpviz.render.image` holds :class:`Image` (linear RGB, AOVs, recorded rays; saved as EXR or
PNG); :mod:`~warpviz.render.tonemap` the PNG curves (:func:`tonemap`, exposure in stops).
"""

from warpviz.render.image import AOV_DESCRIPTIONS, Image
from warpviz.render.render import DEFAULT_OPTIONS, render
from warpviz.render.tonemap import DEFAULT_EXPOSURE, DEFAULT_TONEMAP, TONEMAPS, tonemap

__all__ = ["AOV_DESCRIPTIONS", "DEFAULT_EXPOSURE", "DEFAULT_OPTIONS", "DEFAULT_TONEMAP", "Image", "TONEMAPS", "render",
           "tonemap"]
