"""The flat-space pinhole camera of a native scene: which straight line each pixel looks along.

The camera is the renderer's own (``renderer_ext/integrators/camera.h``), reached through the core's
``camera_rays``: nothing here repeats its arithmetic. A pixel's camera ray starts at
``camera["position"]`` along

    d = normalize(forward + sx right + sy up),
    sx = (2 (x + u) / W - 1) tan(fov / 2) W / H,    sy = (1 - 2 (y + v) / H) tan(fov / 2),

with (u, v) the sample's jitter in [0, 1)², pixel (0, 0) the top-left one, ``forward`` towards
``look_at`` and ``right = forward × up``. In curved space that direction is measured by the local static
observer and the ray then bends; in flat space it is the straight line drawn here (jitter (1/2, 1/2): the
pixel centre), the comparison the teaching view shows beside the bent ray.

Examples
--------
>>> cam = {"position": [0, 0, 0], "look_at": [10, 0, 0], "up": [0, 0, 1], "fov": 90.0, "width": 2, "height": 2}
>>> pinhole_directions(cam, [[0, 0], [1, 1]]).round(6).tolist()   # top-left and bottom-right pixel centres
[[0.816497, 0.408248, 0.408248], [0.816497, -0.408248, -0.408248]]
>>> flat_camera_ray(cam, 0, 0, length=2.0).round(6).tolist()
[[0.0, 0.0, 0.0], [1.632993, 0.816497, 0.816497]]
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from warpviz._native import core
from warpviz.scene.native import native_camera, native_observer

__all__ = ["camera_basis", "flat_camera_ray", "pinhole_directions"]


def _camera_rays(camera: Mapping[str, Any], xy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The core's flat-space camera: frame rows (forward, right, up) and directions through xy (K, 2).
    Flat space has one sheet: a camera on a wormhole's other sheet is drawn in that sheet's own frame."""
    flat = dict(native_camera(camera), sheet=1, observer=native_observer(None))  # the frustum as its observer sees it
    return core.camera_rays("minkowski", [], flat, np.ascontiguousarray(xy, dtype=np.float64))


def camera_basis(camera: Mapping[str, Any]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The orthonormal (forward, right, up) vectors of a native scene camera, as the renderer builds them.

    Parameters
    ----------
    camera : dict
        A native scene camera (``docs/native-scene.md``): ``position``, ``look_at``, ``width``,
        ``height``, optional ``up`` (default +z), ``fov``, ``sheet``.

    Returns
    -------
    forward, right, up : numpy.ndarray
        Each shape (3,) float64; ``right = forward × up_given`` normalised, ``up = right × forward``.

    Raises
    ------
    ValueError
        A missing or invalid key, ``look_at`` equal to ``position``, or ``up`` parallel to the view
        direction.
    """
    frame, _ = _camera_rays(camera, np.zeros((0, 2)))
    return frame[0].copy(), frame[1].copy(), frame[2].copy()


def pinhole_directions(camera: Mapping[str, Any], pixels, *, jitter=(0.5, 0.5)) -> np.ndarray:
    """Unit directions of the flat-space camera rays through pixels.

    Parameters
    ----------
    camera : dict
        A native scene camera: ``position``, ``look_at``, ``up``, ``fov`` (vertical, degrees),
        ``width``, ``height``.
    pixels : array_like, shape (K, 2) or (2,)
        Pixel coordinates (x, y), x to the right, y down from the top row. Need not be integers.
    jitter : tuple of float, keyword-only
        Position inside the pixel, (0, 0) its top-left corner; default the centre.

    Returns
    -------
    numpy.ndarray, shape (K, 3), float64
        Unit vectors in the user frame, bit for bit the renderer's (flat space, the same jitter).
    """
    xy = np.asarray(pixels, dtype=np.float64).reshape(-1, 2) + np.asarray(jitter, dtype=np.float64)
    return _camera_rays(camera, xy)[1]


def flat_camera_ray(camera: Mapping[str, Any], x: float, y: float, *, length: float) -> np.ndarray:
    """The straight flat-space camera ray through the centre of pixel (x, y).

    Parameters
    ----------
    camera : dict
        A native scene camera (see :func:`pinhole_directions`).
    x, y : float
        Pixel coordinates (x to the right, y down).
    length : float, keyword-only
        Length of the segment drawn, > 0.

    Returns
    -------
    numpy.ndarray, shape (2, 3), float64
        Start (the camera position) and end point.
    """
    length = float(length)
    if not (length > 0.0 and math.isfinite(length)):
        raise ValueError(f"length must be a positive finite distance, got {length!r}")
    start = np.asarray(native_camera(camera)["position"], dtype=np.float64)
    return np.stack([start, start + length * pinhole_directions(camera, [x, y])[0]])
