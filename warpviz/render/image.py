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
>>> tonemap(np.array([[[0.0, 0.5, 2.0]]], dtype=np.float32), method="clip").tolist()
[[[0, 188, 255]]]
"""

from __future__ import annotations

import dataclasses
import json
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from warpviz.io import SOFTWARE_KEY, atomic_write, software, write_png
from warpviz.render.tonemap import DEFAULT_EXPOSURE, DEFAULT_TONEMAP, tonemap, tonemap_name
from warpviz.limits import exposure_stops
from warpviz.tracing import RayBundle

__all__ = ["Image", "tonemap", "AOV_DESCRIPTIONS"]

#: What each AOV of a render holds (all float32, (H, W) unless noted).
AOV_DESCRIPTIONS = {
    "redshift": "g = nu_camera / nu_source of the camera ray's first hit or of the sky (0: horizon), sample 0",
    "n_steps": "mean number of integration steps per sample (all geodesics of the path; 0 for flat and closed-form segments)",
    "max_drift": "largest reported drift (relative |X - X0| / |X0|, term-scaled where X0 ~ 0 and for H) of any conserved quantity on any geodesic of the pixel",
    "status": "RayStatus code of the camera geodesic of sample 0 (0 escaped, 1 hit, 2 horizon, ...)",
    "depth": "user-frame distance from the camera to the first hit (inf: none), sample 0",
    "normal": "(H, W, 3) user-frame geometric normal at the first hit, sample 0",
    "albedo": "(H, W, 3) mean over samples of the albedo in [0, 1] at the path's first non-specular hit "
              "(through mirrors and glass; an emitter: its colour; 0 where none): the denoiser's feature",
    "albedo_normal": "(H, W, 3) mean over samples of the user-frame normal at the path's first non-specular hit "
                     "(0 where none): the denoiser's feature",
    "emission": "(H, W, 3) mean over samples of the radiance the path collected up to and at its first non-specular "
                "hit (lights seen directly or through mirrors and glass, the sky and its stars): part of rgb, sharp "
                "and hardly noisy, which the denoiser leaves alone",
    "variance": "(H, W, 3) variance of each pixel mean's R, G, B, estimated from the pixel's samples (sample variance "
                "/ samples; NaN below 2 samples): the noise left, and what a resumed render continues",
    "errors": "fraction of samples whose path had a geodesic ending in max_steps/invariant_violation/nan",
    "samples": "number of samples accumulated (less than spp after an interruption)",
}


#: (H, W, 3) AOVs whose channels are colours (``variance.R/G/B`` in an EXR); the others are vectors (``.X/Y/Z``).
_COLOUR_AOVS = ("variance", "emission")

_TONEMAP_PIXELS = 1 << 16  # pixels tonemapped at a time (~6 MB of float64 temporaries)


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
    denoised : numpy.ndarray or None
        (H, W, 3) float32 radiance denoised by Intel Open Image Denoise (:meth:`denoise`,
        ``render(denoise=True)``), or None. ``rgb`` stays the unbiased estimate; a PNG shows this one,
        an EXR keeps it as the extra layer ``denoised.R/G/B``.
    """

    rgb: np.ndarray
    aovs: dict
    completed: bool
    stats: dict
    metadata: dict = field(default_factory=dict)
    rays: RayBundle | None = None
    native_scene: dict | None = None
    denoised: np.ndarray | None = None

    @classmethod
    def open(cls, path: str | os.PathLike) -> Image:
        """An EXR that a warpviz render wrote (:func:`read_exr`): radiance, AOVs and the header's metadata,
        e.g. to look at, or to continue with ``render(resume=...)``."""
        return read_exr(path)

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

    def denoise(self) -> Image:
        """This image with its radiance denoised by Intel Open Image Denoise (the optional ``pyoidn``).

        The ``albedo`` and ``albedo_normal`` AOVs are the denoiser's features where the image has them
        (``render(denoise=True)`` computes them); without them the radiance alone is denoised. Where the
        image has the ``emission`` AOV, only ``rgb - emission`` is denoised and the emission is added back:
        the lights a camera sees directly (and the stars) stay as sharp as rendered, and their radiance,
        10-100x the room's, no longer bleeds into the room (in fig07 at 640 x 480 the denoised frame's
        relative MSE falls 3.7x at 8 spp and 7x at 32: benchmarks/README.md, "Time to a clean picture").
        The features are denoised on their own first (:func:`warpviz.render.denoise.denoise_radiance`).

        Returns
        -------
        Image
            A copy with :attr:`denoised` set and ``metadata["denoised"]`` naming the denoiser and the
            features it used; ``rgb`` and the AOVs are this image's own (not copied).

        Raises
        ------
        warpviz.render.denoise.DenoiserMissing
            ``pyoidn`` is not installed (``pip install 'warpviz[denoise]'``).
        """
        from warpviz.render.denoise import DENOISE_FEATURES, denoise_radiance, denoiser_version

        albedo, normal = (self.aovs.get(name) for name in DENOISE_FEATURES)
        features = [name for name, a in zip(DENOISE_FEATURES, (albedo, normal)) if a is not None]
        if albedo is None:
            features = []
        sharp = self.aovs.get("emission")
        rgb = self.rgb if sharp is None else np.asarray(self.rgb, np.float32) - np.asarray(sharp, np.float32)
        out = denoise_radiance(rgb, albedo=albedo, normal=normal if albedo is not None else None)
        if sharp is not None:
            out = out + np.maximum(np.asarray(sharp, np.float32), 0.0)
        meta = {**self.metadata, "denoised": {"denoiser": denoiser_version(), "features": features,
                                              "features_prefiltered": bool(features),
                                              "kept_sharp": "emission" if sharp is not None else None}}  # fmt: skip
        return dataclasses.replace(self, denoised=out, metadata=meta)

    def false_colour(self, aov: str, *, vmin: float | None = None, vmax: float | None = None,
                     cmap: str | None = None):
        """A false-colour picture of a scalar AOV with a labelled colour bar.

        Parameters
        ----------
        aov : str
            ``redshift``, ``n_steps``, ``max_drift``, ``depth``, ``errors``, ``samples`` or ``status``
            (:data:`warpviz.render.false_colour.FALSE_COLOUR_STYLES`); the image must have it.
        vmin, vmax : float, optional, keyword-only
            The range shown (default: the values' own; redshift symmetric about g = 1).
        cmap : str, optional, keyword-only
            A matplotlib colormap instead of the AOV's.

        Returns
        -------
        warpviz.render.false_colour.FalseColour
            ``pixels`` (H', W', 3) uint8, ``vmin``, ``vmax``, ``save(path)``.
        """
        from warpviz.render.false_colour import false_colour, false_colour_style

        false_colour_style(aov)  # a known quantity, before asking whether the image has it
        if aov not in self.aovs:
            have = ", ".join(sorted(self.aovs)) or "none"
            raise ValueError(f"this image has no {aov!r} AOV (it has: {have}); render with aovs=[{aov!r}]")
        return false_colour(self.aovs[aov], quantity=aov, vmin=vmin, vmax=vmax, cmap=cmap)

    def to_uint8(self, *, exposure: float = DEFAULT_EXPOSURE, method: str = DEFAULT_TONEMAP) -> np.ndarray:
        """The tonemapped picture, made in bands of rows so a large image needs no float64 copy of itself.

        Parameters
        ----------
        exposure : float, keyword-only
            Stops (radiance times ``2 ** exposure``), in :data:`warpviz.limits.EXPOSURE_RANGE`. The
            radiance is the denoised one where the image has it (:attr:`denoised`).
        method : {"filmic", "clip", "reinhard"}, keyword-only
            The curve (:mod:`warpviz.render.tonemap`).

        Returns
        -------
        numpy.ndarray
            (H, W, 3) uint8 sRGB.
        """
        exposure, method = exposure_stops("exposure", exposure), tonemap_name(method)
        rgb = np.asarray(self.rgb if self.denoised is None else self.denoised)
        out = np.empty(rgb.shape[:2] + (3,), dtype=np.uint8)
        rows = max(1, _TONEMAP_PIXELS // max(1, rgb.shape[1]))
        for y in range(0, rgb.shape[0], rows):
            out[y : y + rows] = tonemap(rgb[y : y + rows], exposure=exposure, method=method)
        return out

    def save(self, path: str | os.PathLike, *, exposure: float | None = None, tonemap: str | None = None) -> Path:
        """Write the image, atomically.

        Parameters
        ----------
        path : str or os.PathLike
            ``.exr``: float32 channels R, G, B (the unbiased radiance) plus every AOV (``normal`` as
            ``normal.X/Y/Z``, ``variance`` as ``variance.R/G/B``) and, for a denoised image, the layer ``denoised.R/G/B``; the metadata as
            the ``warpviz`` header string and ``errorFraction`` as a float attribute.
            ``.png``: tonemapped 8-bit sRGB (of the denoised radiance, where there is one), the metadata
            (with the ``tonemap`` and ``exposure`` used) as a ``warpviz`` text chunk.
        exposure : float, optional, keyword-only
            PNG only: stops (default :data:`warpviz.render.tonemap.DEFAULT_EXPOSURE`, 0).
        tonemap : {"filmic", "clip", "reinhard"}, optional, keyword-only
            PNG only: the curve (default :data:`warpviz.render.tonemap.DEFAULT_TONEMAP`).

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
            exposure = DEFAULT_EXPOSURE if exposure is None else exposure_stops("exposure", exposure)
            method = DEFAULT_TONEMAP if tonemap is None else tonemap_name(tonemap)
            pixels = self.to_uint8(exposure=exposure, method=method)
            meta = {**self.metadata, "tonemap": method, "exposure": exposure}
            return write_png(path, pixels, text={"warpviz": json.dumps(meta, sort_keys=True, default=str)})
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
                for k, axis in enumerate("RGB" if name in _COLOUR_AOVS else "XYZ"):
                    channels[f"{name}.{axis}"] = np.ascontiguousarray(arr[..., k])
            else:
                channels[name] = np.ascontiguousarray(arr)
        if self.denoised is not None:
            for k, c in enumerate("RGB"):
                channels[f"denoised.{c}"] = np.ascontiguousarray(self.denoised[..., k], dtype=np.float32)
        header = {
            "compression": OpenEXR.ZIP_COMPRESSION,
            "type": OpenEXR.scanlineimage,
            "warpviz": json.dumps(self.metadata, sort_keys=True, default=str),
            SOFTWARE_KEY: software(),
            "errorFraction": float(self.error_fraction),
        }
        with OpenEXR.File(header, channels) as f:
            f.write(str(tmp))


def read_exr(path: str | os.PathLike):
    """An EXR that warpviz wrote, as an :class:`Image` (:meth:`Image.open`).

    Parameters
    ----------
    path : str or os.PathLike
        The file.

    Returns
    -------
    warpviz.render.image.Image
        ``rgb``, every AOV channel (``name.X/Y/Z`` and ``variance.R/G/B`` put back together), the
        header's metadata; ``completed`` from it; no ``denoised`` (a resumed render denoises again).

    Raises
    ------
    ValueError
        The file cannot be read as an EXR, or has no warpviz header.
    """
    import OpenEXR

    path = Path(path)
    try:
        with OpenEXR.File(str(path)) as f:
            header = dict(f.header())
            channels = {name: np.asarray(ch.pixels) for name, ch in f.channels().items()}
    except Exception as exc:  # noqa: BLE001 - OpenEXR raises plain exceptions for any unreadable file
        raise ValueError(f"{str(path)!r} cannot be read as an OpenEXR image ({exc})") from None
    text = header.get("warpviz")
    try:
        metadata = json.loads(text) if isinstance(text, (str, bytes)) else None
    except json.JSONDecodeError:
        metadata = None
    if not isinstance(metadata, dict):
        raise ValueError(f"{str(path)!r} has no warpviz header: it was not written by a warpviz render")
    if "RGB" in channels:  # OpenEXR groups R, G, B into one (H, W, 3) channel
        rgb = channels.pop("RGB")
    else:
        try:
            rgb = np.stack([channels.pop(c) for c in "RGB"], axis=-1)
        except KeyError:
            raise ValueError(f"{str(path)!r} has no R, G, B channels") from None
    aovs: dict[str, np.ndarray] = {}
    groups: dict[str, dict[str, np.ndarray]] = {}
    for name, arr in channels.items():
        if "." in name:
            base, part = name.rsplit(".", 1)
            if arr.ndim == 3:  # grouped by OpenEXR: base.XYZ as one (H, W, 3) channel
                groups.setdefault(base, {})["*"] = arr
            else:
                groups.setdefault(base, {})[part] = arr
        else:
            aovs[name] = np.asarray(arr, dtype=np.float32)
    for base, parts in groups.items():
        if base == "denoised":
            continue
        if "*" in parts:
            aovs[base] = np.asarray(parts["*"], dtype=np.float32)
            continue
        order = "RGB" if set(parts) == set("RGB") else "XYZ"
        if set(parts) != set(order):
            continue  # not one of warpviz's (H, W, 3) AOVs
        aovs[base] = np.stack([parts[c] for c in order], axis=-1).astype(np.float32)
    return Image(rgb=np.asarray(rgb, dtype=np.float32), aovs=aovs, completed=bool(metadata.get("completed", True)),
                 stats={}, metadata=metadata)  # fmt: skip
