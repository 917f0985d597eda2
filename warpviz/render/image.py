"""The result of a render: linear RGB, arbitrary output variables (AOVs) and the recorded rays.

An :class:`Image` is what :func:`warpviz.render` returns. It saves itself as OpenEXR (float32 RGB plus
every AOV as extra channels, render settings in the header) or as a tonemapped 8-bit PNG.

Examples
--------
>>> import numpy as np
>>> from warpviz.render.image import Image, tonemap
>>> img = Image(rgb=np.full((2, 3, 3), 0.5, dtype=np.float32), aovs={}, completed=True, stats={},
...             metadata={"metric": "minkowski"})
>>> img.shape
(2, 3)
>>> tonemap(np.array([[[0.0, 0.5, 2.0]]], dtype=np.float32)).tolist()
[[[0, 188, 255]]]
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from warpviz.io import SOFTWARE_KEY, atomic_write, software, write_png
from warpviz.tracing import RayBundle

__all__ = ["Image", "tonemap", "AOV_DESCRIPTIONS"]

#: What each AOV of a render holds (all float32, (H, W) unless noted).
AOV_DESCRIPTIONS = {
    "redshift": "g = nu_camera / nu_source of the camera ray's first hit or of the sky (0: horizon), sample 0",
    "n_steps": "mean number of integration steps per sample (all geodesics of the path)",
    "max_drift": "largest reported drift (relative |X - X0| / |X0|, term-scaled where X0 ~ 0 and for H) of any conserved quantity on any geodesic of the pixel",
    "status": "RayStatus code of the camera geodesic of sample 0 (0 escaped, 1 hit, 2 horizon, ...)",
    "depth": "user-frame distance from the camera to the first hit (inf: none), sample 0",
    "normal": "(H, W, 3) user-frame geometric normal at the first hit, sample 0",
    "errors": "fraction of samples whose path had a geodesic ending in max_steps/invariant_violation/nan",
    "samples": "number of samples accumulated (less than spp after an interruption)",
}


_TONEMAP_PIXELS = 1 << 16  # pixels tonemapped at a time (~6 MB of float64 temporaries)


def tonemap(rgb: np.ndarray, *, exposure: float = 1.0, method: str = "clip") -> np.ndarray:
    """Linear RGB to 8-bit sRGB.

    Parameters
    ----------
    rgb : numpy.ndarray
        (H, W, 3) float linear radiance.
    exposure : float, keyword-only
        Scale applied before tonemapping.
    method : {"clip", "reinhard"}, keyword-only
        ``"clip"`` clamps to [0, 1]; ``"reinhard"`` maps x to x / (1 + x), keeping highlights.

    Returns
    -------
    numpy.ndarray
        (H, W, 3) uint8, sRGB-encoded.
    """
    x = np.nan_to_num(np.asarray(rgb, dtype=np.float64) * exposure, nan=0.0, posinf=1.0, neginf=0.0)
    x = np.maximum(x, 0.0)
    if method == "reinhard":
        x = x / (1.0 + x)
    elif method != "clip":
        raise ValueError(f"unknown tonemap method {method!r} (known: clip, reinhard)")
    x = np.minimum(x, 1.0)
    srgb = np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1.0 / 2.4) - 0.055)
    return np.round(srgb * 255.0).astype(np.uint8)


@dataclass(frozen=True, eq=False)
class Image:
    """A rendered frame.

    Attributes
    ----------
    rgb : numpy.ndarray
        (H, W, 3) float32 linear radiance (the mean of each pixel's samples).
    aovs : dict[str, numpy.ndarray]
        Arbitrary output variables, float32 (H, W) or (H, W, 3); see :data:`AOV_DESCRIPTIONS`.
    completed : bool
        False if the render was interrupted (Ctrl-C): the image holds the samples finished so far and
        ``aovs["samples"]`` says how many per pixel.
    stats : dict
        Geodesic segments by status, integration steps, seconds, threads.
    metadata : dict
        Metric, render settings and scene file, written into EXR headers.
    rays : RayBundle or None
        Recorded geodesic segments of the pixels asked for with ``record_pixels``; per-segment arrays
        ``pixel_x``, ``pixel_y``, ``sample``, ``bounce``, ``kind`` (0 camera, 1 bounce, 2 light) in
        ``rays.ray_data``.
    native_scene : dict or None
        The native scene dictionary that was rendered (for the 3-D view).
    """

    rgb: np.ndarray
    aovs: dict
    completed: bool
    stats: dict
    metadata: dict = field(default_factory=dict)
    rays: RayBundle | None = None
    native_scene: dict | None = None

    @property
    def shape(self) -> tuple[int, int]:
        """(height, width) in pixels."""
        return tuple(self.rgb.shape[:2])

    @property
    def error_fraction(self) -> float:
        """Fraction of all samples whose path had a geodesic that failed (``max_steps``,
        ``invariant_violation`` or ``nan``); such a sample adds nothing to its pixel, so the image is
        darker there by this fraction on average. Per pixel: ``aovs["errors"]``."""
        return float(self.stats.get("error_fraction", 0.0))

    def to_uint8(self, *, exposure: float = 1.0, method: str = "clip") -> np.ndarray:
        """The tonemapped (H, W, 3) uint8 sRGB picture (see :func:`tonemap`), made in bands of rows so a
        large image needs no float64 copy of itself."""
        rgb = np.asarray(self.rgb)
        out = np.empty(rgb.shape[:2] + (3,), dtype=np.uint8)
        rows = max(1, _TONEMAP_PIXELS // max(1, rgb.shape[1]))
        for y in range(0, rgb.shape[0], rows):
            out[y : y + rows] = tonemap(rgb[y : y + rows], exposure=exposure, method=method)
        return out

    def save(self, path: str | os.PathLike, *, exposure: float = 1.0, tonemap_method: str = "clip") -> Path:
        """Write the image, atomically.

        Parameters
        ----------
        path : str or os.PathLike
            ``.exr``: float32 channels R, G, B plus every AOV (``normal`` as ``normal.X/Y/Z``), the
            metadata as the ``warpviz`` header string and ``errorFraction`` as a float attribute.
            ``.png``: tonemapped 8-bit sRGB, the metadata as a ``warpviz`` text chunk.
        exposure, tonemap_method : keyword-only
            PNG only; see :func:`tonemap`.

        Returns
        -------
        pathlib.Path
            The written file.
        """
        path = Path(path)
        suffix = path.suffix.lower()
        if suffix == ".exr":
            return atomic_write(path, self._write_exr)
        if suffix == ".png":
            pixels = self.to_uint8(exposure=exposure, method=tonemap_method)
            return write_png(path, pixels, text={"warpviz": json.dumps(self.metadata, sort_keys=True, default=str)})
        raise ValueError(f"cannot save {str(path)!r}: use a .exr or .png file name")

    def _write_exr(self, tmp: Path) -> None:
        import OpenEXR

        channels = {
            "R": np.ascontiguousarray(self.rgb[..., 0], dtype=np.float32),
            "G": np.ascontiguousarray(self.rgb[..., 1], dtype=np.float32),
            "B": np.ascontiguousarray(self.rgb[..., 2], dtype=np.float32),
        }
        for name, arr in self.aovs.items():
            arr = np.asarray(arr, dtype=np.float32)
            if arr.ndim == 3:
                for k, axis in enumerate("XYZ"):
                    channels[f"{name}.{axis}"] = np.ascontiguousarray(arr[..., k])
            else:
                channels[name] = np.ascontiguousarray(arr)
        header = {
            "compression": OpenEXR.ZIP_COMPRESSION,
            "type": OpenEXR.scanlineimage,
            "warpviz": json.dumps(self.metadata, sort_keys=True, default=str),
            SOFTWARE_KEY: software(),
            "errorFraction": float(self.error_fraction),
        }
        with OpenEXR.File(header, channels) as f:
            f.write(str(tmp))
