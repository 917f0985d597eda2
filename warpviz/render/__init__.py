"""Rendering: :func:`render` path-traces a scene whose light rays are null geodesics and returns an
:class:`Image`.

:mod:`~warpviz.render.render` resolves the options (:data:`DEFAULT_OPTIONS`) and calls the core;
:mod:`~warpviz.render.image` holds :class:`Image` (linear RGB, AOVs, recorded rays; saved as EXR or
PNG) and :func:`tonemap`.
"""

from warpviz.render.image import AOV_DESCRIPTIONS, Image, tonemap
from warpviz.render.render import DEFAULT_OPTIONS, render

__all__ = ["AOV_DESCRIPTIONS", "DEFAULT_OPTIONS", "Image", "render", "tonemap"]
