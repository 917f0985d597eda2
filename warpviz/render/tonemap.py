"""Tonemapping: linear radiance to 8-bit sRGB, with an exposure in stops.

Three curves map exposed linear radiance to display values in [0, 1] before the sRGB encoding:

* ``"clip"`` clamps each channel to [0, 1] (warpviz's PNGs before tonemapping had a choice, bit for bit).
  A saturated source brighter than 1 loses its hue: orange (4, 1.6, 0.4) becomes (1, 1, 0.4), yellow-white.
* ``"filmic"`` (the default) is hue-preserving: it compresses the largest channel m of a pixel with a smooth
  shoulder and scales all three channels by the same factor, so the ratios of the channels, hence hue and
  saturation in linear light, stay exactly those of the source. Below the knee (m <= :data:`FILMIC_KNEE`)
  the curve is the identity, so dim and mid-tone pixels are bit-identical to ``"clip"``; above it
  ``m -> k + (1 - k) t / (1 + t)``, ``t = (m - k) / (1 - k)``, which has slope 1 at the knee (no visible
  seam), rises monotonically and reaches 1 only at infinity: m = 1 shows as 0.75, m = 10 as 0.97, so a
  source ten times brighter than the clip level is still brighter than one twice as bright. Over-bright
  areas do not bleach to white; lower the exposure to see more of their range.
* ``"reinhard"`` maps each channel to x / (1 + x) (per channel: hue shifts towards white).

Exposure is in stops: the linear radiance is multiplied by ``2 ** exposure`` before the curve, within
:data:`warpviz.limits.EXPOSURE_RANGE`.

Examples
--------
>>> import numpy as np
>>> from warpviz.render.tonemap import tonemap
>>> tonemap(np.array([[[0.0, 0.5, 2.0]]], dtype=np.float32), method="clip").tolist()
[[[0, 188, 255]]]
>>> tonemap(np.array([[[4.0, 1.6, 0.4]]], dtype=np.float32), method="filmic").tolist()  # stays orange
[[[248, 165, 86]]]
>>> tonemap(np.array([[[0.25, 0.25, 0.25]]]), exposure=1.0, method="clip").tolist()  # one stop up: 0.5
[[[188, 188, 188]]]
"""

from __future__ import annotations

import numpy as np

from warpviz.limits import TONEMAP_NAMES, exposure_stops

__all__ = ["DEFAULT_EXPOSURE", "DEFAULT_TONEMAP", "FILMIC_KNEE", "TONEMAPS", "clip", "encode_srgb", "exposed",
           "filmic", "reinhard", "tonemap", "tonemap_name"]

#: Exposure in stops applied when none is given (0: the radiance as rendered).
DEFAULT_EXPOSURE = 0.0

#: Where ``filmic``'s shoulder starts, as a linear display value: below it the curve is the identity.
FILMIC_KNEE = 0.5


def exposed(rgb, exposure: float = DEFAULT_EXPOSURE) -> np.ndarray:
    """Linear radiance scaled by ``2 ** exposure``, NaN as 0, +inf as 1, negatives as 0.

    Parameters
    ----------
    rgb : array_like
        (..., 3) float linear radiance.
    exposure : float
        Stops (checked against :data:`warpviz.limits.EXPOSURE_RANGE`).

    Returns
    -------
    numpy.ndarray
        (..., 3) float64, non-negative and finite.
    """
    scale = 2.0 ** exposure_stops("exposure", exposure)
    x = np.asarray(rgb, dtype=np.float64) * scale
    x = np.nan_to_num(x, nan=0.0, posinf=1.0, neginf=0.0)
    return np.maximum(x, 0.0)


def clip(x: np.ndarray) -> np.ndarray:
    """Each channel clamped to [0, 1].

    Parameters
    ----------
    x : numpy.ndarray
        (..., 3) float64 non-negative exposed radiance (:func:`exposed`).

    Returns
    -------
    numpy.ndarray
        (..., 3) float64 display values in [0, 1].
    """
    return np.minimum(x, 1.0)


def filmic(x: np.ndarray, *, knee: float = FILMIC_KNEE) -> np.ndarray:
    """Hue-preserving shoulder on each pixel's largest channel (see the module's description).

    Parameters
    ----------
    x : numpy.ndarray
        (..., 3) float64 non-negative exposed radiance (:func:`exposed`).
    knee : float, keyword-only
        Display value in (0, 1) where the shoulder starts; below it the curve is the identity.

    Returns
    -------
    numpy.ndarray
        (..., 3) float64 display values in [0, 1), each pixel ``x * f(m) / m`` with m its largest channel.
    """
    if not 0.0 < knee < 1.0:
        raise ValueError(f"filmic knee must be in (0, 1), got {knee!r}")
    m = np.max(x, axis=-1, keepdims=True)
    t = np.maximum(m - knee, 0.0) / (1.0 - knee)
    shoulder = knee + (1.0 - knee) * t / (1.0 + t)
    scale = np.where(m > knee, shoulder / np.where(m > knee, m, 1.0), 1.0)
    return np.minimum(x * scale, 1.0)


def reinhard(x: np.ndarray) -> np.ndarray:
    """Each channel mapped to x / (1 + x) (highlights kept, hue shifted towards white).

    Parameters
    ----------
    x : numpy.ndarray
        (..., 3) float64 non-negative exposed radiance (:func:`exposed`).

    Returns
    -------
    numpy.ndarray
        (..., 3) float64 display values in [0, 1).
    """
    return np.minimum(x / (1.0 + x), 1.0)


#: The tonemap curves by name: exposed linear radiance -> display values in [0, 1].
TONEMAPS = {"filmic": filmic, "clip": clip, "reinhard": reinhard}
assert tuple(TONEMAPS) == TONEMAP_NAMES, "warpviz.limits.TONEMAP_NAMES names the curves defined here"

#: The curve used when none is given. ``filmic``: every pixel whose channels all lie below its knee is
#: bit-identical to ``clip``, and brighter ones keep their hue (``docs/tonemapping.md`` has the measurement
#: over the shipped scenes).
DEFAULT_TONEMAP = "filmic"


def tonemap_name(method) -> str:
    """``method`` checked to be one of :data:`TONEMAPS`.

    Raises
    ------
    ValueError
        Not a known tonemap; the message lists the known ones.
    """
    if not isinstance(method, str) or method not in TONEMAPS:
        raise ValueError(f"unknown tonemap {method!r} (known: {', '.join(TONEMAPS)})")
    return method


def encode_srgb(display: np.ndarray) -> np.ndarray:
    """Display values in [0, 1] to 8-bit sRGB.

    Parameters
    ----------
    display : numpy.ndarray
        (..., 3) float64 in [0, 1].

    Returns
    -------
    numpy.ndarray
        (..., 3) uint8.
    """
    srgb = np.where(display <= 0.0031308, 12.92 * display, 1.055 * np.power(display, 1.0 / 2.4) - 0.055)
    return np.round(srgb * 255.0).astype(np.uint8)


def tonemap(rgb, *, exposure: float = DEFAULT_EXPOSURE, method: str = DEFAULT_TONEMAP) -> np.ndarray:
    """Linear RGB to 8-bit sRGB.

    Parameters
    ----------
    rgb : array_like
        (H, W, 3) (or any (..., 3)) float linear radiance.
    exposure : float, keyword-only
        Stops: the radiance is multiplied by ``2 ** exposure`` first.
    method : {"filmic", "clip", "reinhard"}, keyword-only
        The curve (:data:`TONEMAPS`).

    Returns
    -------
    numpy.ndarray
        (..., 3) uint8, sRGB-encoded.

    Raises
    ------
    ValueError
        Unknown method, or an exposure that is not a number in :data:`warpviz.limits.EXPOSURE_RANGE`.
    """
    curve = TONEMAPS[tonemap_name(method)]
    return encode_srgb(curve(exposed(rgb, exposure)))
