"""Denoising a render with Intel Open Image Denoise (OIDN), through its Python binding ``pyoidn``.

OIDN's ``RT`` filter takes the noisy HDR radiance and, as features, the albedo and the normal at each
path's first non-specular hit, averaged over the pixel's samples (the ``albedo`` and ``albedo_normal``
AOVs, which :func:`warpviz.render` computes when asked, and always with ``denoise=True``). The features
let it keep edges and textures that the radiance's noise would hide. ``pyoidn`` ships the library in its
wheel; it is the optional extra ``warpviz[denoise]``.

The features are averages over a pixel's samples, so they are noisy too where a pixel's samples reach
different surfaces (through glass by their Fresnel choices, in a lensed or mirrored image of a room
squeezed into a few pixels); as OIDN advises, each is first denoised on its own (OIDN's prefiltering:
the ``RT`` filter with that feature as its only input) and the radiance is then denoised with the
cleaned features (``cleanAux``). At 640 x 480, 16 spp, this lowers the denoised image's relative MSE
13 % in fig07 and fig10d for ~1 s of filtering (benchmarks/README.md, "Denoising").

The denoised radiance is biased (a learned filter); warpviz keeps the unbiased one as the image's ``rgb``
and the EXR's R, G, B, and the denoised one beside it (:attr:`warpviz.Image.denoised`, the EXR's
``denoised.R/G/B`` layer; a PNG shows it).
"""

from __future__ import annotations

import threading

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


def denoise_radiance(rgb, *, albedo=None, normal=None, prefilter: bool = True) -> np.ndarray:
    """OIDN's denoised HDR radiance.

    Parameters
    ----------
    rgb : array_like
        (H, W, 3) float linear radiance (negative or non-finite values are taken as 0).
    albedo : array_like, optional, keyword-only
        (H, W, 3) float albedo in [0, 1] at the first non-specular hit.
    normal : array_like, optional, keyword-only
        (H, W, 3) float normal there (used only with ``albedo``, as OIDN requires).
    prefilter : bool, optional, keyword-only
        Denoise the features on their own first and give them to the radiance's filter as clean (OIDN's
        advice for noisy features; default). False: the features as they are.

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
    if prefilter and a is not None:
        a = np.clip(_prefiltered(pyoidn, a, pyoidn.OIDN_IMAGE_ALBEDO), 0.0, 1.0)
        if n is not None:
            n = np.clip(_prefiltered(pyoidn, n, pyoidn.OIDN_IMAGE_NORMAL), -1.0, 1.0)
    out = pyoidn.denoise(color, a, n, hdr=True, clean_aux=prefilter and a is not None, quality=QUALITY)
    return np.maximum(np.asarray(out, dtype=np.float32), 0.0)


#: OIDN's quality setting for prefiltering the features (``"balanced"``: the same gain as ``"high"`` in
#: fig07 and fig10d at 640 x 480, in 0.9 s instead of 2 s for the two features).
PREFILTER_QUALITY = "balanced"

_DEVICE = None  # the CPU device of the prefilters, made on first use
_DEVICE_LOCK = threading.Lock()


def _prefiltered(pyoidn, feature: np.ndarray, slot: str) -> np.ndarray:
    """(H, W, 3) float32: one feature image denoised on its own (OIDN's prefiltering of an auxiliary
    image: the ``RT`` filter with only that image, in its ``slot``, as input)."""
    global _DEVICE
    feature = np.ascontiguousarray(feature, dtype=np.float32)
    out = np.zeros_like(feature)
    quality = {"high": pyoidn.OIDN_QUALITY_HIGH, "balanced": pyoidn.OIDN_QUALITY_BALANCED}[PREFILTER_QUALITY]
    with _DEVICE_LOCK:
        if _DEVICE is None:
            _DEVICE = pyoidn.Device(pyoidn.OIDN_DEVICE_TYPE_CPU)
            _DEVICE.commit()
        filt = pyoidn.Filter(_DEVICE, "RT")
        try:
            filt.set_image(slot, feature, pyoidn.OIDN_FORMAT_FLOAT3)
            filt.set_image(pyoidn.OIDN_IMAGE_OUTPUT, out, pyoidn.OIDN_FORMAT_FLOAT3)
            filt.set_quality(quality)
            filt.commit()
            filt.execute()
        finally:
            filt.release()
    return out
