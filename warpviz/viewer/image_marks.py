"""What the image panel marks on the rendered image: an angle scale in degrees and, where the physics
gives it exactly, the edge of the shadow (or of a wormhole's window) as the camera sees it.

The camera is the renderer's (:func:`warpviz.scene.camera.pinhole_directions` and the core's
``camera_rays``): a pixel at continuous coordinates (x, y), y down from the top row, looks along

    d = normalize(forward + sx right + sy up),  sx = (2 x / W - 1) t W / H,  sy = (1 - 2 y / H) t,

with t = tan(fov / 2), in the local frame of the static observer at the camera. The angle scale
labels the horizontal and vertical angles atan(sx), atan(sy) from the view's centre.

The shadow of a Schwarzschild hole seen by a static observer at areal radius r is a circle of angular
radius α around the direction of the centre, sin α = 3√3 M √(1 − 2M/r) / r
(:meth:`warpviz.Schwarzschild.shadow_angle`); the window through an Ellis wormhole's throat, seen from
areal radius r on either sheet, is the circle sin α = b0 / r (light with impact parameter below the throat
radius b0 passes through). By spherical symmetry the direction of the centre in the observer's frame is
the image of the coordinate direction towards it, which the core's camera frame gives
(a camera looking at the centre has it as its forward vector).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

__all__ = ["angle_ticks", "edge_circle"]


def _tan_half(camera: Mapping[str, Any]) -> float:
    return math.tan(0.5 * math.radians(float(camera["fov"])))


def angle_ticks(camera: Mapping[str, Any], width: int, height: int) -> dict[str, list[tuple[float, str]]]:
    """Round angles along the image's edges.

    Parameters
    ----------
    camera : dict
        A native scene camera (``fov``: vertical field of view in degrees).
    width, height : int
        The image's size in pixels.

    Returns
    -------
    dict
        ``{"x": [(x, "-20°"), ...], "y": [(y, "10°"), ...]}``: continuous pixel coordinates (x to the
        right, y down from the top) of each tick and its label; angles are measured from the centre of
        the view, positive to the right and up.

    Examples
    --------
    >>> cam = {"fov": 90.0}
    >>> [label for _, label in angle_ticks(cam, 200, 100)["y"]]
    ['-45°', '-30°', '-15°', '0°', '15°', '30°', '45°']
    """
    t = _tan_half(camera)
    aspect = width / height
    half = {"x": math.degrees(math.atan(t * aspect)), "y": math.degrees(math.atan(t))}
    out: dict[str, list[tuple[float, str]]] = {}
    for axis, extent in half.items():
        step = next((s for s in (1, 2, 5, 10, 15, 20, 30, 45) if extent / s <= 3.0), 60)
        ticks = []
        for k in range(-int(extent // step), int(extent // step) + 1):
            angle = k * step
            s = math.tan(math.radians(angle))
            if axis == "x":
                ticks.append(((s / (t * aspect) + 1.0) * width / 2.0, f"{angle}°"))
            else:
                ticks.append(((1.0 - s / t) * height / 2.0, f"{angle}°"))
        out[axis] = ticks
    return out


def _edge_angle(metric, camera: Mapping[str, Any]) -> tuple[float, str] | None:
    """The exact angular radius (rad) of the shadow or window seen from the camera and its name."""
    from warpviz.spacetime.metrics import EllisWormhole, Schwarzschild

    r = float(np.linalg.norm(np.asarray(camera["position"], dtype=np.float64)))
    if isinstance(metric, Schwarzschild) and r > metric.photon_sphere_radius:
        return metric.shadow_angle(r), "shadow radius"
    if isinstance(metric, EllisWormhole) and r > metric.throat:
        return math.asin(metric.throat / r), "window radius"
    return None


def edge_circle(metric, camera: Mapping[str, Any], width: int, height: int,
                n: int = 240) -> tuple[np.ndarray, str] | None:  # fmt: skip
    """Where the exact edge of the shadow (Schwarzschild) or of the window (Ellis wormhole) falls on the
    image, for a camera outside the photon sphere (throat).

    Parameters
    ----------
    metric : Metric or None
    camera : dict
        A native scene camera.
    width, height : int
        The image's size in pixels.
    n : int
        Points around the circle.

    Returns
    -------
    (points, label) or None
        ``points``: shape (K, 2) float64, the continuous pixel coordinates (x right, y down) of the part
        of the circle in front of the camera, in order (K ≤ n; empty where it is all behind);
        ``label``: e.g. ``"shadow radius 13.6° (exact)"``. None where no exact edge is known
        (Kerr, Reissner–Nordström, flat space) or the camera is inside the photon sphere.
    """
    from warpviz._native import core
    from warpviz.scene.native import native_camera, native_observer

    if metric is None:
        return None
    edge = _edge_angle(metric, camera)
    if edge is None:
        return None
    alpha, name = edge
    cam = dict(native_camera(camera), width=int(width), height=int(height))
    pixels = np.zeros((0, 2))
    frame, _ = core.camera_rays(metric.name, metric.param_values, cam, pixels)
    static = dict(cam, observer=native_observer(None))  # the circle is exact in the static observer's sky
    towards = dict(static, look_at=[0.0, 0.0, 0.0])
    for up in (cam["up"], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]):
        try:
            centre = core.camera_rays(metric.name, metric.param_values, dict(towards, up=up), pixels)[0][0]
            break
        except ValueError:
            continue
    forward, right, up = frame
    e1 = np.cross(centre, forward if abs(float(centre @ forward)) < 0.99 else right)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(centre, e1)
    phi = np.linspace(0.0, 2.0 * math.pi, n + 1)
    d = (math.cos(alpha) * centre[None, :]
         + math.sin(alpha) * (np.cos(phi)[:, None] * e1[None, :] + np.sin(phi)[:, None] * e2[None, :]))  # fmt: skip
    moving = cam["observer"]["kind"] != "local"
    if moving:  # the camera's observer sees the circle aberrated (still a circle: the map is conformal)
        d = _aberrated(metric, static, cam, d)
        alpha = 0.5 * float(np.max(np.arccos(np.clip(d @ d.T, -1.0, 1.0))))
    depth = d @ forward
    front = depth > 1e-6
    t = _tan_half(cam)
    aspect = width / height
    sx = (d @ right)[front] / depth[front]
    sy = (d @ up)[front] / depth[front]
    points = np.column_stack([(sx / (t * aspect) + 1.0) * width / 2.0, (1.0 - sy / t) * height / 2.0])
    return points, f"{name} {math.degrees(alpha):.3g}° (exact{', aberrated' if moving else ''})"


def _aberrated(metric, static: dict, cam: dict, dirs: np.ndarray) -> np.ndarray:
    """Look directions ``dirs`` (K, 3) of the static observer at the camera as the camera's own observer
    sees them: the light arriving along -n has 4-momentum u_s - n^j e_j, seen along minus its direction in
    the moving frame."""
    from warpviz._native import core

    _, us, es, g = core.observer(metric.name, metric.param_values, static)
    _, um, em, _ = core.observer(metric.name, metric.param_values, cam)
    p = us[None, :] - dirs @ es  # (K, 4) contravariant, unit energy for the static observer
    pl = p @ g  # lowered
    energy = -(pl @ um)
    k = (pl @ em.T) / energy[:, None]  # propagation direction in the moving frame
    return -k / np.linalg.norm(k, axis=1)[:, None]
