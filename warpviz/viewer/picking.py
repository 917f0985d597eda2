"""Which recorded rays belong to which pixel, and which pixel a cell of the displayed image is.

These are the pure functions behind the clicks of the teaching view (:func:`warpviz.view`). Rays come
either as a :class:`~warpviz.tracing.rays.RayBundle` recorded by :func:`warpviz.render` (per-ray ``pixel_x``,
``pixel_y``, ``sample``, ``bounce`` in ``ray_data``) or as the polydata of
:meth:`~warpviz.tracing.rays.RayBundle.to_pyvista` / :func:`warpviz.read_rays` (the same arrays as cell data,
cell ``i`` = ray ``i``).

The image is displayed as a grid of W x H square cells in the plane z = 0, cell (i, j) covering
[i, i + 1] x [j, j + 1] with j counted up from the bottom, so pixel (x, y) (y down from the top row) is
cell ``x + W (H - 1 - y)``.

Examples
--------
>>> import numpy as np
>>> from warpviz.viewer.picking import image_cell_to_pixel, pixel_to_image_cell, sparse_pixel_grid
>>> pixel_to_image_cell(3, 0, width=8, height=4), image_cell_to_pixel(27, width=8, height=4)
(27, (3, 0))
>>> sparse_pixel_grid(8, 4, nx=4, ny=2).tolist()
[[1, 1], [3, 1], [5, 1], [7, 1], [1, 3], [3, 3], [5, 3], [7, 3]]
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = [
    "PIXEL_WORDS",
    "image_cell_to_pixel",
    "pixel_for_ray",
    "pixel_to_image_cell",
    "ray_pixels",
    "rays_for_pixel",
    "recorded_pixels",
    "sparse_pixel_grid",
    "teaching_pixels",
]

#: RayStatus code of a camera ray that fell into a horizon (the status AOV's value for shadow pixels).
_HORIZON = 2


def _per_ray(rays: Any, name: str) -> np.ndarray | None:
    """The per-ray array ``name`` of a RayBundle (``ray_data``) or ray polydata (cell data), or None."""
    ray_data = getattr(rays, "ray_data", None)
    if isinstance(ray_data, dict):
        values = ray_data.get(name)
    else:
        cell_data = getattr(rays, "cell_data", None)
        if cell_data is None:
            raise TypeError(f"expected a RayBundle or ray polydata, got {type(rays).__name__}")
        values = cell_data[name] if name in cell_data else None
    return None if values is None else np.asarray(values)


def _n_rays(rays: Any) -> int:
    return len(rays) if hasattr(rays, "ray_data") else int(rays.n_cells)


def ray_pixels(rays: Any) -> np.ndarray | None:
    """The pixel each ray was recorded for.

    Parameters
    ----------
    rays : RayBundle or pyvista.PolyData
        Recorded rays (see the module docstring).

    Returns
    -------
    numpy.ndarray or None
        (N, 2) int64 pixel coordinates (x, y) per ray, or None when the rays carry no pixels (e.g.
        rays from :func:`warpviz.trace`).
    """
    px, py = _per_ray(rays, "pixel_x"), _per_ray(rays, "pixel_y")
    if px is None or py is None:
        return None
    return np.column_stack([px, py]).astype(np.int64).reshape(-1, 2)


def rays_for_pixel(rays: Any, x: int, y: int, *, sample: int | None = None) -> np.ndarray:
    """Indices of the recorded rays (geodesic segments) of one pixel.

    Parameters
    ----------
    rays : RayBundle or pyvista.PolyData
        Recorded rays.
    x, y : int
        The pixel (x to the right, y down from the top row).
    sample : int, optional, keyword-only
        Only the segments of this sample's path.

    Returns
    -------
    numpy.ndarray, shape (K,), int64
        Ray indices in increasing order (a path's camera segment first, then its bounces); empty if
        the pixel was not recorded or the rays carry no pixels.

    Examples
    --------
    >>> import numpy as np, warpviz as wv
    >>> from warpviz.viewer.picking import rays_for_pixel
    >>> rays = wv.trace(wv.Minkowski(), [0, 0, 0], [[1, 0, 0], [0, 1, 0], [0, 0, 1]], record=True)
    >>> rays = type(rays)(**{**rays.__dict__, "ray_data": {"pixel_x": np.array([2, 5, 2]),
    ...                                                    "pixel_y": np.array([1, 1, 1])}})
    >>> rays_for_pixel(rays, 2, 1).tolist(), rays_for_pixel(rays, 0, 0).tolist()
    ([0, 2], [])
    """
    pixels = ray_pixels(rays)
    if pixels is None:
        return np.zeros(0, dtype=np.int64)
    keep = (pixels[:, 0] == int(x)) & (pixels[:, 1] == int(y))
    if sample is not None:
        samples = _per_ray(rays, "sample")
        keep &= False if samples is None else samples == int(sample)
    return np.flatnonzero(keep).astype(np.int64)


def pixel_for_ray(rays: Any, i: int) -> tuple[int, int] | None:
    """The pixel ray ``i`` was recorded for.

    Parameters
    ----------
    rays : RayBundle or pyvista.PolyData
        Recorded rays.
    i : int
        Ray index (negative counts from the end).

    Returns
    -------
    tuple of int or None
        (x, y), or None when the rays carry no pixels.

    Raises
    ------
    IndexError
        ``i`` is out of range.
    """
    n = _n_rays(rays)
    if not -n <= int(i) < n:
        raise IndexError(f"ray {i} out of range for {n} rays")
    pixels = ray_pixels(rays)
    if pixels is None:
        return None
    x, y = pixels[int(i)]
    return int(x), int(y)


def recorded_pixels(rays: Any) -> np.ndarray:
    """The distinct pixels that have recorded rays.

    Parameters
    ----------
    rays : RayBundle or pyvista.PolyData

    Returns
    -------
    numpy.ndarray, shape (K, 2), int64
        (x, y) rows sorted by row y, then x; (0, 2) when the rays carry no pixels.
    """
    pixels = ray_pixels(rays)
    if pixels is None or not len(pixels):
        return np.zeros((0, 2), dtype=np.int64)
    unique = np.unique(pixels[:, ::-1], axis=0)[:, ::-1]
    return np.ascontiguousarray(unique)


def sparse_pixel_grid(width: int, height: int, *, nx: int = 8, ny: int = 6) -> np.ndarray:
    """An even grid of at most nx x ny pixels spread over an image, for recording a few paths.

    Parameters
    ----------
    width, height : int
        Image size.
    nx, ny : int, keyword-only
        Pixels across and down (clipped to the image size).

    Returns
    -------
    numpy.ndarray, shape (min(nx, width) * min(ny, height), 2), int64
        (x, y) pixel coordinates, rows top to bottom, each left to right; the centres of an nx x ny
        partition of the image.
    """
    width, height, nx, ny = int(width), int(height), int(nx), int(ny)
    if min(width, height, nx, ny) < 1:
        raise ValueError(f"need a positive image size and grid, got {width}x{height}, {nx}x{ny}")
    nx, ny = min(nx, width), min(ny, height)
    xs = ((np.arange(nx) + 0.5) * width / nx).astype(np.int64)
    ys = ((np.arange(ny) + 0.5) * height / ny).astype(np.int64)
    gx, gy = np.meshgrid(xs, ys)
    return np.column_stack([gx.ravel(), gy.ravel()])


#: What each pixel :func:`teaching_pixels` chooses shows, in words a student reads beside the image.
PIXEL_WORDS = {
    "shadow_edge": "edge of the shadow",
    "throat_edge": "edge of the window",
    "bent": "light bent round the hole",
    "other_side": "light from the other side",
    "plain": "light that hardly bends",
}


def teaching_pixels(status: np.ndarray, rgb: np.ndarray, impact: np.ndarray, *,
                    edge_impact: float | None = None) -> list[tuple[str, tuple[int, int]]]:  # fmt: skip
    """A few pixels whose light paths explain a picture: one at the shadow's (or throat's) edge, one
    through the brightest lensed light, one plain.

    Parameters
    ----------
    status : numpy.ndarray
        (H, W) RayStatus code of each pixel's camera ray (the ``status`` AOV); 2 = fell into a horizon.
    rgb : numpy.ndarray
        (H, W, 3) float linear radiance.
    impact : numpy.ndarray
        (H, W) float impact parameter of each pixel's straight (flat-space) camera ray about the centre
        of the spacetime; ``inf`` for rays pointing away from it.
    edge_impact : float, optional, keyword-only
        Without horizon pixels (a wormhole), the impact parameter of the edge to show (the throat's).

    Returns
    -------
    list of (str, (int, int))
        (label, (x, y)) with the labels of :data:`PIXEL_WORDS`: the shadow's (or the wormhole's window's)
        edge, the brightest light nearest the centre (bent round the hole, or from the other side of
        the wormhole), and light that hardly bends; each where the picture has one, without repeats.

    Examples
    --------
    >>> import numpy as np
    >>> status = np.zeros((5, 7)); status[1:4, 2:5] = 2          # a 3 x 3 shadow in the middle
    >>> rgb = np.full((5, 7, 3), 0.1); rgb[2, 6] = 5.0            # one bright pixel
    >>> yy, xx = np.mgrid[0:5, 0:7]
    >>> impact = np.hypot(xx - 3.0, yy - 2.0)
    >>> [(label, xy) for label, xy in teaching_pixels(status, rgb, impact)]
    [('edge of the shadow', (5, 2)), ('light bent round the hole', (6, 2)), ('light that hardly bends', (1, 2))]
    """
    status = np.asarray(status)
    rgb = np.asarray(rgb, dtype=np.float64)
    impact = np.asarray(impact, dtype=np.float64)
    h, w = status.shape
    shadow = status == _HORIZON
    out: list[tuple[str, tuple[int, int]]] = []
    row = h // 2
    if shadow.any():
        ys, xs = np.nonzero(shadow)
        row = int(round(ys.mean()))
        row = int(ys[np.argmin(np.abs(ys - row))])  # a row through the shadow
        cols = np.flatnonzero(shadow[row])
        edge = int(cols.max()) + 1
        if edge < w:
            out.append((PIXEL_WORDS["shadow_edge"], (edge, row)))
    elif edge_impact is not None:
        finite = np.isfinite(impact[row])
        if finite.any():
            x = int(np.argmin(np.where(finite, np.abs(impact[row] - edge_impact), np.inf)))
            out.append((PIXEL_WORDS["throat_edge"], (x, row)))
    luminance = rgb @ np.array([0.2126, 0.7152, 0.0722])
    luminance = np.where(shadow | ~np.isfinite(luminance), 0.0, luminance)
    if luminance.max() > 0:
        bright = luminance >= 0.5 * luminance.max()
        y, x = np.unravel_index(np.argmin(np.where(bright, impact, np.inf)), (h, w))
        out.append((PIXEL_WORDS["bent" if edge_impact is None else "other_side"], (int(x), int(y))))
    plain = (int(0.15 * w), row)
    if not shadow[plain[1], plain[0]]:
        out.append((PIXEL_WORDS["plain"], plain))
    seen, unique = set(), []
    for label, xy in out:
        if xy not in seen:
            seen.add(xy)
            unique.append((label, xy))
    return unique


def pixel_to_image_cell(x: int, y: int, *, width: int, height: int) -> int:
    """The cell of the displayed image grid that shows pixel (x, y) (see the module docstring)."""
    if not (0 <= x < width and 0 <= y < height):
        raise IndexError(f"pixel ({x}, {y}) lies outside the {width}x{height} image")
    return int(x) + int(width) * (int(height) - 1 - int(y))


def image_cell_to_pixel(cell: int, *, width: int, height: int) -> tuple[int, int]:
    """The pixel (x, y) shown by cell ``cell`` of the displayed image grid (inverse of
    :func:`pixel_to_image_cell`)."""
    if not 0 <= cell < width * height:
        raise IndexError(f"cell {cell} out of range for a {width}x{height} image")
    j, x = divmod(int(cell), int(width))
    return x, int(height) - 1 - j
