"""False-colour pictures of a render's physics AOVs, with a labelled colour bar.

A scalar AOV (the redshift g, integration steps, the largest drift of a conserved quantity, ...) is mapped
through a matplotlib colormap to an 8-bit picture; beside it a colour bar names the quantity, its units and
the range shown. Each AOV's colormap, scale and label live in :data:`FALSE_COLOUR_STYLES`:

* ``redshift``: diverging ``RdBu`` centred on g = 1 (red: light arrives redshifted, g < 1; blue:
  blueshifted, g > 1), the range symmetric about 1; g = 0 (the horizon) has no colour of its own and is
  drawn black.
* ``n_steps``: ``viridis``, linear; ``max_drift``: ``magma`` of log10 of the drift (0 drawn black);
  ``depth``: ``viridis``; ``errors``: ``inferno``; ``samples``: ``viridis``; ``status``: ``tab10`` codes.

Pixels without a value (NaN, infinite, or the masked ones above) are drawn black. A small image is
enlarged by an integer factor (nearest neighbour) so that the bar's labels are readable.

Examples
--------
>>> import numpy as np
>>> from warpviz.render.false_colour import false_colour
>>> fc = false_colour(np.array([[0.5, 1.0, 1.5]], dtype=np.float32), quantity="redshift")
>>> fc.vmin, fc.vmax, fc.pixels.dtype
(0.5, 1.5, dtype('uint8'))
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from warpviz.io import write_png

__all__ = ["FALSE_COLOUR_STYLES", "FalseColour", "false_colour", "false_colour_style"]

#: How each AOV is shown: colormap, scale (``"linear"``, ``"log10"`` or ``"diverging"`` about ``centre``),
#: which values mean "no value" (``mask``), and the bar's label.
FALSE_COLOUR_STYLES = {
    "redshift": {"cmap": "RdBu", "scale": "diverging", "centre": 1.0, "mask": "zero",
                 "label": "redshift g = nu_camera / nu_source"},
    "n_steps": {"cmap": "viridis", "scale": "linear", "mask": None, "label": "integration steps per sample"},
    "max_drift": {"cmap": "magma", "scale": "log10", "mask": "zero",
                  "label": "log10 largest drift of a conserved quantity"},
    "depth": {"cmap": "viridis", "scale": "linear", "mask": None, "label": "distance to the first hit"},
    "errors": {"cmap": "inferno", "scale": "linear", "mask": None, "label": "fraction of failed samples"},
    "samples": {"cmap": "viridis", "scale": "linear", "mask": None, "label": "samples per pixel"},
    "status": {"cmap": "tab10", "scale": "linear", "mask": None, "label": "status of the camera ray (code)"},
}  # fmt: skip

#: Height in pixels the picture is enlarged to at least (an integer factor), so the bar's text is readable.
MIN_HEIGHT = 240
#: Width of the colour bar and of the label column beside it, in pixels.
_BAR_WIDTH, _LABEL_WIDTH = 18, 78
#: Rows of label text above the picture.
_TITLE_HEIGHT = 30
#: Colour of pixels without a value.
_NO_VALUE = (0, 0, 0)


def false_colour_style(quantity: str) -> dict:
    """The style of ``quantity`` (a copy of its :data:`FALSE_COLOUR_STYLES` entry).

    Raises
    ------
    ValueError
        Not a scalar AOV that has a style; the message lists those that have one.
    """
    if quantity not in FALSE_COLOUR_STYLES:
        raise ValueError(f"no false colour for {quantity!r}: use one of {', '.join(FALSE_COLOUR_STYLES)}")
    return dict(FALSE_COLOUR_STYLES[quantity])


@dataclass(frozen=True)
class FalseColour:
    """A false-colour picture with its colour bar.

    Attributes
    ----------
    pixels : numpy.ndarray
        (H', W', 3) uint8 sRGB: the (enlarged) picture with the colour bar and labels at its right.
    quantity : str
        The AOV shown.
    vmin, vmax : float
        The range the colormap spans, in the AOV's own units (for ``log10`` styles, the drift itself).
    cmap : str
        The matplotlib colormap.
    scale : str
        ``"linear"``, ``"log10"`` or ``"diverging"``.
    zoom : int
        The factor the AOV's pixels were enlarged by: AOV pixel (x, y) covers ``pixels[top + zoom * y :
        top + zoom * (y + 1), zoom * x : zoom * (x + 1)]``.
    top : int
        Rows of label text above the picture.
    """

    pixels: np.ndarray
    quantity: str
    vmin: float
    vmax: float
    cmap: str
    scale: str
    zoom: int = 1
    top: int = 0

    def save(self, path: str | os.PathLike, *, metadata: dict | None = None) -> Path:
        """Write the picture as a PNG (atomically), the quantity, range and colormap in its ``warpviz`` text.

        Parameters
        ----------
        path : str or os.PathLike
            A ``.png`` file.
        metadata : dict, optional, keyword-only
            The render's metadata, stored beside the false-colour keys.
        """
        meta = {**(metadata or {}), "false_colour": {"quantity": self.quantity, "vmin": self.vmin,
                                                      "vmax": self.vmax, "cmap": self.cmap, "scale": self.scale}}
        return write_png(path, self.pixels, text={"warpviz": json.dumps(meta, sort_keys=True, default=str)})


def _finite_range(v: np.ndarray) -> tuple[float, float]:
    return (float(v.min()), float(v.max())) if v.size else (0.0, 1.0)


def false_colour(values, *, quantity: str, vmin: float | None = None, vmax: float | None = None,
                 cmap: str | None = None) -> FalseColour:
    """Map a scalar AOV to colours and draw its labelled colour bar.

    Parameters
    ----------
    values : array_like
        (H, W) float values of the AOV.
    quantity : str, keyword-only
        Which AOV they are (a key of :data:`FALSE_COLOUR_STYLES`): chooses colormap, scale and label.
    vmin, vmax : float, optional, keyword-only
        The range shown (values outside are drawn at its ends). Default: the range of the values that have
        one; for ``redshift`` symmetric about g = 1; for ``max_drift`` the drift's own values (positive).
    cmap : str, optional, keyword-only
        A matplotlib colormap name instead of the style's.

    Returns
    -------
    FalseColour

    Raises
    ------
    ValueError
        Not an (H, W) array, an unknown quantity or colormap, or an empty or reversed range.
    """
    import matplotlib

    style = false_colour_style(quantity)
    v = np.asarray(values, dtype=np.float64)
    if v.ndim != 2 or v.size == 0:
        raise ValueError(f"false colour of {quantity!r} needs an (H, W) array of values, got shape {v.shape}")
    name = cmap if cmap is not None else style["cmap"]
    try:
        colormap = matplotlib.colormaps[name]
    except KeyError:
        raise ValueError(f"unknown colormap {name!r} (any of matplotlib.colormaps, e.g. viridis, magma)") from None
    valid = np.isfinite(v)
    if style["mask"] == "zero":
        valid &= v > 0.0 if style["scale"] == "log10" else v != 0.0
    shown = v[valid]
    lo, hi = _finite_range(shown)
    if style["scale"] == "diverging":
        c = style["centre"]
        half = max(abs(lo - c), abs(hi - c)) or 1e-3
        lo, hi = c - half, c + half
    lo = float(vmin) if vmin is not None else lo
    hi = float(vmax) if vmax is not None else hi
    if style["scale"] == "log10" and not lo > 0.0:
        raise ValueError(f"false colour of {quantity!r} is logarithmic: vmin must be > 0, got {lo!r}")
    if not (np.isfinite(lo) and np.isfinite(hi) and lo <= hi):
        raise ValueError(f"false colour of {quantity!r}: the range [{lo!r}, {hi!r}] must be finite with vmin <= vmax")
    if style["scale"] == "log10":
        t = (np.log10(np.where(valid, v, lo)) - np.log10(lo)) / (np.log10(hi) - np.log10(lo) or 1.0)
    else:
        t = (np.where(valid, v, lo) - lo) / ((hi - lo) or 1.0)
    rgba = colormap(np.clip(t, 0.0, 1.0))
    picture = np.round(rgba[..., :3] * 255.0).astype(np.uint8)
    picture[~valid] = _NO_VALUE
    pixels, zoom = _with_bar(picture, colormap, lo, hi, style["scale"], style["label"])
    return FalseColour(pixels=pixels, quantity=quantity, vmin=lo, vmax=hi, cmap=name, scale=style["scale"],
                       zoom=zoom, top=_TITLE_HEIGHT)


def _tick(value: float) -> str:
    return f"{value:.3g}"


def _font(size: int):
    from PIL import ImageFont

    try:
        return ImageFont.load_default(size=size)
    except TypeError:  # Pillow < 10.1: the fixed bitmap font
        return ImageFont.load_default()


def _with_bar(picture: np.ndarray, colormap, lo: float, hi: float, scale: str, label: str) -> tuple[np.ndarray, int]:
    """The picture enlarged to at least :data:`MIN_HEIGHT` rows, a vertical colour bar at its right (high
    values at the top) with ticks at both ends and the middle, and the label above; and the zoom factor."""
    from PIL import Image as PILImage
    from PIL import ImageDraw

    h, w = picture.shape[:2]
    k = max(1, -(-MIN_HEIGHT // h))
    big = np.repeat(np.repeat(picture, k, axis=0), k, axis=1)
    H, W = big.shape[:2]
    title_h = _TITLE_HEIGHT
    canvas = PILImage.new("RGB", (W + 8 + _BAR_WIDTH + _LABEL_WIDTH, H + title_h), (255, 255, 255))
    canvas.paste(PILImage.fromarray(big), (0, title_h))
    ramp = np.linspace(1.0, 0.0, H)[:, None].repeat(_BAR_WIDTH, axis=1)
    bar = np.round(colormap(ramp)[..., :3] * 255.0).astype(np.uint8)
    x_bar = W + 8
    canvas.paste(PILImage.fromarray(bar), (x_bar, title_h))
    draw = ImageDraw.Draw(canvas)
    draw.rectangle([x_bar - 1, title_h - 1, x_bar + _BAR_WIDTH, title_h + H], outline=(0, 0, 0))
    font = _font(11)
    if scale == "log10":
        ticks = [(0.0, lo), (0.5, 10 ** (0.5 * (np.log10(lo) + np.log10(hi)))), (1.0, hi)]
    else:
        ticks = [(0.0, lo), (0.5, 0.5 * (lo + hi)), (1.0, hi)]
    for frac, value in ticks:
        y = title_h + int(round((1.0 - frac) * (H - 1)))
        draw.line([x_bar + _BAR_WIDTH, y, x_bar + _BAR_WIDTH + 4, y], fill=(0, 0, 0))
        text_y = min(max(y - 6, title_h), title_h + H - 12)
        draw.text((x_bar + _BAR_WIDTH + 6, text_y), _tick(value), fill=(0, 0, 0), font=font)
    draw.text((4, 2), label, fill=(0, 0, 0), font=font)
    draw.text((4, 15), f"range {_tick(lo)} .. {_tick(hi)}" + (" (log scale)" if scale == "log10" else ""),
              fill=(0, 0, 0), font=font)
    return np.asarray(canvas, dtype=np.uint8), k
