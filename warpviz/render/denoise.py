"""Denoising a render with Intel Open Image Denoise (OIDN), through its Python binding ``pyoidn``.

OIDN's ``RT`` filter takes the noisy HDR radiance and, as features, the albedo and the normal at each
path's first non-specular hit, averaged over the pixel's samples (the ``albedo`` and ``albedo_normal``
AOVs, which :func:`warpviz.render` computes when asked, and always with ``denoise=True``). The features
let it keep edges and textures that the radiance's noise would hide. ``pyoidn`` ships the library in its
wheel; it is the optional extra ``warpviz[denoise]``.

The denoised radiance is biased (a learned filter); warpviz keeps the unbiased one as the image's ``rgb``
and the EXR's R, G, B, and the denoised one beside it (:attr:`warpviz.Image.denoised`, the EXR's
``denoised.R/G/B`` layer; a PNG shows it).
"""

from __future__ import annotations

import numpy as np

__all__ = ["DENOISE_AOVS", "DENOISE_FEATURES", "DenoiserMissing", "denoise_radiance", "denoiser_version", "require_denoiser"]

#: The AOVs the denoiser is fed with: albedo, then normal (OIDN takes a normal only with an albedo).
DENOISE_FEATURES = ("albedo", "albedo_normal")

#: What ``render(denoise=True)`` keeps for denoising: the features, and the ``emission`` that is left out
#: of the denoised radiance and added back (:meth:`warpviz.Image.denoise`).
DENOISE_AOVS = (*DENOISE_FEATURES, "emission")

#: OIDN's quality setting used (``"high"``: its best, for final frames).
QUALITY = "high"


class DenoiserMissing(ImportError):
    """Denoising was asked for, but the optional dependency ``pyoidn`` is not installed."""


def require_denoiser():
    """The ``pyoidn`` module.

    Raises
    ------
    DenoiserMissing
        ``pyoidn`` cannot be imported; the message names the extra that installs it.
    """
    try:
        import pyoidn
    except ImportError as exc:
        raise DenoiserMissing(
            "denoising needs Intel Open Image Denoise's Python binding 'pyoidn', which is not installed: "
            "pip install 'warpviz[denoise]' (or pip install pyoidn)") from exc  # fmt: skip
    return pyoidn


def denoiser_version() -> str:
    """``"pyoidn X.Y.Z"``, for the metadata of a denoised image."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        return f"pyoidn {version('pyoidn')}"
    except PackageNotFoundError:
        return "pyoidn"


def _rgb_input(name: str, value, shape) -> np.ndarray:
    arr = np.asarray(value, dtype=np.float32)
    if arr.shape != shape:
        raise ValueError(f"denoise: {name} must have the radiance's shape {shape}, got {arr.shape}")
    return np.ascontiguousarray(np.nan_to_num(arr, nan=0.0, posinf=0.0, neginf=0.0))


def denoise_radiance(rgb, *, albedo=None, normal=None) -> np.ndarray:
    """OIDN's denoised HDR radiance.

    Parameters
    ----------
    rgb : array_like
        (H, W, 3) float linear radiance (negative or non-finite values are taken as 0).
    albedo : array_like, optional, keyword-only
        (H, W, 3) float albedo in [0, 1] at the first non-specular hit.
    normal : array_like, optional, keyword-only
        (H, W, 3) float normal there (used only with ``albedo``, as OIDN requires).

    Returns
    -------
    numpy.ndarray
        (H, W, 3) float32, non-negative.

    Raises
    ------
    DenoiserMissing
        ``pyoidn`` is not installed.
    ValueError
        A shape that is not (H, W, 3), or features of another shape.
    """
    pyoidn = require_denoiser()
    color = np.asarray(rgb, dtype=np.float32)
    if color.ndim != 3 or color.shape[2] != 3 or min(color.shape[:2]) == 0:
        raise ValueError(f"denoise: the radiance must be (H, W, 3), got shape {color.shape}")
    color = np.ascontiguousarray(np.maximum(np.nan_to_num(color, nan=0.0, posinf=0.0, neginf=0.0), 0.0))
    a = _rgb_input("albedo", albedo, color.shape) if albedo is not None else None
    n = _rgb_input("normal", normal, color.shape) if normal is not None and a is not None else None
    if a is not None:
        a = np.clip(a, 0.0, 1.0)
    if n is not None:
        n = np.clip(n, -1.0, 1.0)
    out = pyoidn.denoise(color, a, n, hdr=True, quality=QUALITY)
    return np.maximum(np.asarray(out, dtype=np.float32), 0.0)
