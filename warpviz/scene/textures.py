"""Texture images for scenes: procedural pictures made with numpy, and image files decoded to linear RGB.

Every function returns a float32 array of shape (H, W, 3) in linear RGB, row 0 at the top (texture
coordinate v = 1), which is the ``data`` of an ``{"type": "image"}`` texture in the native scene. Nothing is
downloaded; the procedural pictures depend only on their arguments.

Examples
--------
>>> from warpviz.scene.textures import swatch, earth_like
>>> swatch(cells=(4, 16), cell_px=8).shape
(128, 32, 3)
>>> img = earth_like(width=64, height=32, seed=1)
>>> img.dtype, img.shape, bool(0.0 <= img.min() and img.max() <= 1.0)
(dtype('float32'), (32, 64, 3), True)
"""

from __future__ import annotations

import colorsys
import functools
from pathlib import Path

import numpy as np

IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff", ".exr")


def srgb_to_linear(c: np.ndarray) -> np.ndarray:
    """Decode sRGB-encoded values in [0, 1] to linear RGB (IEC 61966-2-1)."""
    c = np.asarray(c, dtype=np.float64)
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def linear_to_srgb(c: np.ndarray) -> np.ndarray:
    """Encode linear RGB in [0, 1] as sRGB (IEC 61966-2-1)."""
    c = np.clip(np.asarray(c, dtype=np.float64), 0.0, 1.0)
    return np.where(c <= 0.0031308, 12.92 * c, 1.055 * c ** (1.0 / 2.4) - 0.055)


def load_image(path: str | Path, *, srgb: bool | None = None) -> np.ndarray:
    """Read an image file as linear RGB.

    Parameters
    ----------
    path : str or Path
        PNG, JPEG, BMP, TIFF (via Pillow) or OpenEXR file. Alpha is dropped, grey is repeated to RGB.
    srgb : bool, optional, keyword-only
        Whether the stored values are sRGB-encoded. Default: True for 8/16-bit formats, False for EXR.

    Returns
    -------
    numpy.ndarray, shape (H, W, 3), float32
        Linear RGB; row 0 is the top of the picture.

    Raises
    ------
    OSError
        The file is missing or cannot be decoded.
    """
    path = Path(path)
    if path.suffix.lower() == ".exr":
        rgb = _read_exr(path)
        return (srgb_to_linear(rgb) if srgb else rgb).astype(np.float32)
    from PIL import Image

    with Image.open(path) as im:
        im.load()
        if im.mode in ("I;16", "I;16B", "I;16L", "I"):
            grey = np.asarray(im, dtype=np.float64) / 65535.0
            rgb = np.repeat(grey[..., None], 3, axis=2)
        else:
            rgb = np.asarray(im.convert("RGB"), dtype=np.float64) / 255.0
    return (srgb_to_linear(rgb) if srgb in (None, True) else rgb).astype(np.float32)


def _read_exr(path: Path) -> np.ndarray:
    import OpenEXR

    with OpenEXR.File(str(path)) as f:
        channels = f.channels()
        if "RGB" in channels:
            return np.asarray(channels["RGB"].pixels, dtype=np.float64)[..., :3]
        if "RGBA" in channels:
            return np.asarray(channels["RGBA"].pixels, dtype=np.float64)[..., :3]
        if all(c in channels for c in "RGB"):
            return np.stack([np.asarray(channels[c].pixels, dtype=np.float64) for c in "RGB"], axis=-1)
        if "Y" in channels:
            y = np.asarray(channels["Y"].pixels, dtype=np.float64)
            return np.repeat(y[..., None], 3, axis=2)
    raise OSError(f"{path.name}: no R, G, B (or Y) channels")


def swatch(*, cells: tuple[int, int] = (4, 16), cell_px: int = 16, border: float = 0.08, seed: int = 0) -> np.ndarray:
    """A paint-swatch chart: ``nu`` x ``nv`` cells of clearly different colours with dark seams.

    Neighbouring cells differ in hue by the golden angle and alternate in saturation and value, so any
    patch of the chart can be told apart from any other: the point of the picture is to show where each
    part of a lensed image comes from.

    Parameters
    ----------
    cells : (int, int), keyword-only
        Number of cells along u (columns) and v (rows).
    cell_px : int, keyword-only
        Pixels per cell side.
    border : float, keyword-only
        Width of the dark seam, as a fraction of a cell (0 for none).
    seed : int, keyword-only
        Rotates the colour sequence.

    Returns
    -------
    numpy.ndarray, shape (nv * cell_px, nu * cell_px, 3), float32
        Linear RGB in [0, 1].
    """
    nu, nv = int(cells[0]), int(cells[1])
    if nu < 1 or nv < 1 or cell_px < 2:
        raise ValueError(f"swatch: cells must be >= 1 and cell_px >= 2, got cells={cells}, cell_px={cell_px}")
    colours = np.empty((nv, nu, 3))
    golden = 0.6180339887498949
    for row in range(nv):
        for col in range(nu):
            k = row * nu + col
            hue = (0.13 * seed + k * golden) % 1.0
            sat = (0.85, 0.55, 0.95)[(row + col) % 3]
            val = (0.95, 0.7)[(row // 1 + col // 2) % 2]
            colours[row, col] = colorsys.hsv_to_rgb(hue, sat, val)
    img = np.repeat(np.repeat(colours, cell_px, axis=0), cell_px, axis=1)
    if border > 0:
        edge = max(1, int(round(border * cell_px / 2)))
        t = np.arange(cell_px)
        seam = (t < edge) | (t >= cell_px - edge)
        rows = np.tile(seam, nv)
        cols = np.tile(seam, nu)
        img[rows, :, :] = 0.08
        img[:, cols, :] = 0.08
    img = img[::-1]  # row 0 is v = 1: cell row 0 at the bottom
    return srgb_to_linear(img).astype(np.float32)


def _hash01(ix: np.ndarray, iy: np.ndarray, iz: np.ndarray, seed: int) -> np.ndarray:
    """Deterministic pseudo-random values in [0, 1) at integer lattice points (a 64-bit integer mix)."""
    with np.errstate(over="ignore"):
        h = ix.astype(np.uint64) * np.uint64(0x9E3779B97F4A7C15)
        h ^= iy.astype(np.uint64) * np.uint64(0xC2B2AE3D27D4EB4F)
        h ^= iz.astype(np.uint64) * np.uint64(0x165667B19E3779F9)
        h ^= np.uint64(seed & 0xFFFFFFFF) * np.uint64(0x27D4EB2F165667C5)
        h ^= h >> np.uint64(31)
        h *= np.uint64(0xBF58476D1CE4E5B9)
        h ^= h >> np.uint64(29)
        h *= np.uint64(0x94D049BB133111EB)
        h ^= h >> np.uint64(32)
    return (h >> np.uint64(11)).astype(np.float64) / float(1 << 53)


def value_noise(p: np.ndarray, *, seed: int = 0) -> np.ndarray:
    """Smooth 3-D value noise in [0, 1] at points ``p`` of shape (..., 3)."""
    p = np.asarray(p, dtype=np.float64)
    base = np.floor(p)
    f = p - base
    w = f * f * (3.0 - 2.0 * f)  # smoothstep weights
    i = base.astype(np.int64)
    out = np.zeros(p.shape[:-1])
    for dx in (0, 1):
        wx = w[..., 0] if dx else 1.0 - w[..., 0]
        for dy in (0, 1):
            wy = w[..., 1] if dy else 1.0 - w[..., 1]
            for dz in (0, 1):
                wz = w[..., 2] if dz else 1.0 - w[..., 2]
                out += wx * wy * wz * _hash01(i[..., 0] + dx, i[..., 1] + dy, i[..., 2] + dz, seed)
    return out


def fbm(p: np.ndarray, *, octaves: int = 6, seed: int = 0) -> np.ndarray:
    """Fractal sum of :func:`value_noise` octaves (each twice the frequency, half the amplitude), in [0, 1]."""
    total = np.zeros(np.shape(p)[:-1])
    amp, norm = 1.0, 0.0
    for k in range(octaves):
        total += amp * value_noise(np.asarray(p) * (2.0**k), seed=seed + 101 * k)
        norm += amp
        amp *= 0.5
    return total / norm


def _sphere_points(width: int, height: int) -> tuple[np.ndarray, np.ndarray]:
    """Unit vectors at the pixel centres of an equirectangular image (row 0 = north pole), and latitudes."""
    theta = np.pi * (np.arange(height) + 0.5) / height
    phi = 2.0 * np.pi * (np.arange(width) + 0.5) / width
    th, ph = np.meshgrid(theta, phi, indexing="ij")
    pts = np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)], axis=-1)
    return pts, 0.5 * np.pi - th


def earth_like(*, width: int = 256, height: int = 128, seed: int = 0, ocean: float = 0.6) -> np.ndarray:
    """A procedural Earth-like planet map (equirectangular, seamless): oceans, continents, ice caps, clouds.

    Parameters
    ----------
    width, height : int, keyword-only
        Image size; longitude spans the width, the north pole is row 0.
    seed : int, keyword-only
        Selects the planet.
    ocean : float, keyword-only
        Fraction of the surface covered by water, in (0, 1).

    Returns
    -------
    numpy.ndarray, shape (height, width, 3), float32
        Linear RGB albedo in [0, 1].
    """
    if width < 4 or height < 2:
        raise ValueError(f"earth_like: image must be at least 4 x 2, got {width} x {height}")
    if not 0.0 < ocean < 1.0:
        raise ValueError(f"earth_like: ocean must be in (0, 1), got {ocean}")
    return _earth_like(int(width), int(height), int(seed), float(ocean)).copy()


@functools.lru_cache(maxsize=8)
def _earth_like(width: int, height: int, seed: int, ocean: float) -> np.ndarray:
    """Cached body of :func:`earth_like` (callers get a copy)."""
    pts, lat = _sphere_points(width, height)
    elevation = fbm(pts * 1.8 + 10.0, octaves=6, seed=seed)
    moisture = fbm(pts * 2.5 - 7.0, octaves=4, seed=seed + 17)
    clouds = fbm(pts * 3.0 + 3.0, octaves=5, seed=seed + 29)
    sea = np.quantile(elevation, ocean)
    top = max(float(elevation.max()), sea + 1e-6)

    # colours in sRGB, mixed per pixel, decoded to linear at the end
    deep, shallow = np.array([0.02, 0.08, 0.28]), np.array([0.08, 0.32, 0.55])
    green, dry, rock = np.array([0.16, 0.38, 0.12]), np.array([0.66, 0.58, 0.36]), np.array([0.45, 0.40, 0.36])
    depth = np.clip((sea - elevation) / max(sea - float(elevation.min()), 1e-6), 0.0, 1.0)[..., None]
    height_frac = np.clip((elevation - sea) / (top - sea), 0.0, 1.0)[..., None]
    water = shallow + (deep - shallow) * np.sqrt(depth)
    wet = np.clip((moisture[..., None] - 0.35) * 4.0, 0.0, 1.0)
    land = dry + (green - dry) * wet
    land = land + (rock - land) * np.clip((height_frac - 0.45) * 2.5, 0.0, 1.0)
    img = np.where((elevation < sea)[..., None], water, land)

    ice_edge = np.radians(68.0) + np.radians(8.0) * (fbm(pts * 4.0, octaves=3, seed=seed + 5) - 0.5)
    ice = (np.abs(lat) > ice_edge)[..., None]
    img = np.where(ice, np.array([0.92, 0.94, 0.97]), img)
    cover = np.clip((clouds - 0.55) * 3.0, 0.0, 0.85)[..., None]
    img = img + (np.array([0.97, 0.97, 0.97]) - img) * cover
    return srgb_to_linear(img).astype(np.float32)


def accretion_disk(
    *, width: int = 256, height: int = 64, seed: int = 0, inner: float = 6.0, outer: float = 20.0
) -> np.ndarray:
    """Emission map of a thin accretion disk for a native ``disk`` shape: u = radius, v = azimuth.

    Brightness follows the thin-disk temperature profile T ~ r^(-3/4) (1 - sqrt(r_in / r))^(1/4) (hot white-yellow
    inside, dull red outside), broken into sheared spiral streaks so the rotation of the lensed image is
    visible.

    Parameters
    ----------
    width : int, keyword-only
        Samples along the radius (u from ``inner`` to ``outer``).
    height : int, keyword-only
        Samples around the disk (v = azimuth / 2 pi; row 0 is v = 1).
    seed : int, keyword-only
        Selects the streak pattern.
    inner, outer : float, keyword-only
        Radii the texture spans (only their ratio matters for the colours).

    Returns
    -------
    numpy.ndarray, shape (height, width, 3), float32
        Linear RGB in [0, 1], brightest at the inner edge.
    """
    if not 0.0 < inner < outer:
        raise ValueError(f"accretion_disk: need 0 < inner < outer, got {inner}, {outer}")
    u = (np.arange(width) + 0.5) / width
    v = 1.0 - (np.arange(height) + 0.5) / height
    r = inner + (outer - inner) * u
    flux = r**-0.75 * np.clip(1.0 - np.sqrt(inner / r), 0.0, None) ** 0.25
    flux = flux / flux.max()
    vv, rr = np.meshgrid(v, r, indexing="ij")
    phase = 2.0 * np.pi * vv + 2.2 * np.log(rr / inner)  # logarithmic spiral shear
    ring = np.stack([np.cos(phase), np.sin(phase), 1.5 * rr], axis=-1)  # slow around, fast across radius
    streaks = 0.5 + 1.6 * (fbm(ring * np.array([1.2, 1.2, 1.0]), octaves=4, seed=seed) - 0.5)
    intensity = np.clip(flux[None, :] * streaks, 0.0, 1.0)
    # colour from hot (inner) to cool (outer): white -> yellow -> orange -> deep red
    stops = np.array([[1.0, 0.97, 0.9], [1.0, 0.82, 0.42], [0.95, 0.45, 0.12], [0.45, 0.08, 0.03]])
    x = np.clip(u, 0.0, 1.0) * (len(stops) - 1)
    k = np.minimum(x.astype(int), len(stops) - 2)
    t = (x - k)[:, None]
    colour = stops[k] * (1.0 - t) + stops[k + 1] * t  # (width, 3)
    return np.clip(intensity[..., None] * colour[None, :, :], 0.0, 1.0).astype(np.float32)
