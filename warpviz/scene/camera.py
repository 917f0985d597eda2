"""The flat-space pinhole camera of a native scene: which straight line each pixel looks along.

The renderer starts a pixel's camera ray from ``camera["position"]`` along

    d = normalize(forward + sx right + sy up),
    sx = (2 (x + u) / W - 1) tan(fov / 2) W / H,    sy = (1 - 2 (y + v) / H) tan(fov / 2),

with (u, v) the sample's jitter in [0, 1)² (``renderer_ext/integrators/camera.h``), pixel (0, 0) the
top-left one, ``forward`` towards ``look_at`` and ``right = forward × up``. In curved space that direction
is measured by the local static observer and the ray then bends; in flat space it is the straight line
drawn here (jitter (1/2, 1/2): the pixel centre), the comparison the teaching view shows beside the bent
ray.

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

__all__ = ["camera_basis", "flat_camera_ray", "pinhole_directions"]


def _vec(camera: Mapping[str, Any], key: str, default=None) -> np.ndarray:
    value = camera.get(key, default)
    if value is None:
        raise ValueError(f"camera: missing key {key!r}")
    vec = np.asarray(value, dtype=np.float64)
    if vec.shape != (3,) or not np.all(np.isfinite(vec)):
        raise ValueError(f"camera: {key} must be 3 finite numbers, got {value!r}")
    return vec


def camera_basis(camera: Mapping[str, Any]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The orthonormal (forward, right, up) vectors of a native scene camera, as the renderer builds them.

    Parameters
    ----------
    camera : dict
        ``position``, ``look_at``, optional ``up`` (default +z), as in ``docs/native-scene.md``.

    Returns
    -------
    forward, right, up : numpy.ndarray
        Each shape (3,) float64; ``right = forward × up_given`` normalised, ``up = right × forward``.

    Raises
    ------
    ValueError
        ``look_at`` equals ``position`` or ``up`` is parallel to the view direction.
    """
    position = _vec(camera, "position")
    forward = _vec(camera, "look_at") - position
    if not np.linalg.norm(forward) > 0.0:
        raise ValueError("camera: look_at must differ from position")
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, _vec(camera, "up", (0.0, 0.0, 1.0)))
    if not np.linalg.norm(right) > 1e-12:
        raise ValueError("camera: up must not be parallel to the view direction")
    right /= np.linalg.norm(right)
    return forward, right, np.cross(right, forward)


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
        Unit vectors in the user frame.
    """
    forward, right, up = camera_basis(camera)
    width, height, fov = int(camera["width"]), int(camera["height"]), float(camera.get("fov", 40.0))
    if width <= 0 or height <= 0:
        raise ValueError(f"camera: width and height must be positive, got {width} x {height}")
    if not 0.0 < fov < 180.0:
        raise ValueError(f"camera: fov must be in (0, 180) degrees, got {fov!r}")
    xy = np.asarray(pixels, dtype=np.float64).reshape(-1, 2)
    tan_half = math.tan(math.radians(fov) / 2.0)
    sx = (2.0 * (xy[:, 0] + jitter[0]) / width - 1.0) * tan_half * width / height
    sy = (1.0 - 2.0 * (xy[:, 1] + jitter[1]) / height) * tan_half
    d = forward[None, :] + sx[:, None] * right[None, :] + sy[:, None] * up[None, :]
    return d / np.linalg.norm(d, axis=1, keepdims=True)


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
    start = _vec(camera, "position")
    return np.stack([start, start + length * pinhole_directions(camera, [x, y])[0]])
