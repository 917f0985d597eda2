"""What the web app's sliders change, and where a click on its image lands: pure functions, no trame.

The web app (:mod:`warpviz.web.app`) offers one slider per parameter of the scene's metric (mass, spin,
charge, throat radius: whatever the registry lists) and one for the camera's distance from the point it
looks at. :func:`slider_specs` chooses their ranges; :func:`apply_controls` makes the native scene the
sliders describe; :func:`image_click_to_pixel` turns a click on the scaled picture into a pixel.

Examples
--------
>>> native = {"metric": {"name": "kerr", "params": [1.0, 0.5]},
...           "camera": {"position": [0.0, -20.0, 0.0], "look_at": [0.0, 0.0, 0.0]}}
>>> [s["name"] for s in slider_specs(native)]
['mass', 'spin', 'distance']
>>> moved = apply_controls(native, {"spin": 0.9, "distance": 40.0})
>>> moved["metric"]["params"], moved["camera"]["position"]
([1.0, 0.9], [0.0, -40.0, 0.0])
>>> image_click_to_pixel(479.0, 0.0, shown=(480, 360), size=(96, 72))
(95, 0)
"""

from __future__ import annotations

import copy
import math
from collections.abc import Mapping
from typing import Any

import numpy as np

__all__ = ["SLIDER_STEPS", "apply_controls", "camera_distance", "image_click_to_pixel", "slider_specs"]

#: Positions along each slider (its step is its span over this).
SLIDER_STEPS = 200

#: A parameter with no upper bound (mass, throat) slides up to the scene's value plus this many times it
#: (5x the value), and down to the scene's value over it where its lower bound is 0.
_UNBOUNDED_SPAN = 4.0


def _registry_entry(name: str) -> dict:
    from warpviz.spacetime.metrics import registered_metrics

    for entry in registered_metrics():
        if entry["name"] == name:
            return entry
    raise ValueError(f"unknown metric {name!r}")


def camera_distance(camera: Mapping[str, Any]) -> float:
    """Distance from the camera to the point it looks at (scene units)."""
    return float(np.linalg.norm(np.subtract(camera["position"], camera["look_at"], dtype=np.float64)))


def _bounded(lo: float, hi: float, lo_open: bool, hi_open: bool) -> tuple[float, float]:
    """Close an open interval by 1 % of its span (a slider cannot reach |spin| = 1)."""
    span = hi - lo
    return (lo + 0.01 * span if lo_open else lo), (hi - 0.01 * span if hi_open else hi)


def _range(spec: Mapping[str, Any], value: float) -> tuple[float, float]:
    lo, hi = float(spec["lo"]), float(spec["hi"])
    size = abs(value) if value != 0.0 else 1.0
    if not math.isfinite(hi):
        hi, hi_open = max(value, 0.0) + _UNBOUNDED_SPAN * size, False
    else:
        hi_open = bool(spec["hi_open"])
    if not math.isfinite(lo):
        lo, lo_open = min(value, 0.0) - _UNBOUNDED_SPAN * size, False
    elif lo == 0.0 and spec["lo_open"] and value > 0.0:
        lo, lo_open = value / _UNBOUNDED_SPAN, False
    else:
        lo_open = bool(spec["lo_open"])
    if math.isfinite(float(spec["hi"])) and math.isfinite(float(spec["lo"])):
        return _bounded(lo, hi, lo_open, hi_open)
    return lo, hi


def slider_specs(native: Mapping[str, Any]) -> list[dict]:
    """The sliders for a native scene: its metric's parameters, then the camera distance.

    Parameters
    ----------
    native : Mapping
        A native scene dict (``metric`` with ``name`` and ``params``, ``camera`` with ``position`` and
        ``look_at``).

    Returns
    -------
    list of dict
        One per slider: ``name``, ``label``, ``value`` (the scene's), ``min``, ``max``, ``step`` (floats).
        The camera distance slides from half to twice the scene's, never inside 1.5 times the metric's
        capture radius (where the camera would fall in).
    """
    metric = native["metric"]
    entry = _registry_entry(metric["name"])
    sliders = []
    for spec, value in zip(entry["param_specs"], metric["params"]):
        lo, hi = _range(spec, float(value))
        sliders.append({"name": spec["name"], "label": spec["name"], "value": float(value), "min": lo, "max": hi,
                        "step": (hi - lo) / SLIDER_STEPS})  # fmt: skip
    d = camera_distance(native["camera"])
    lo = 0.5 * d
    from warpviz.spacetime.metrics import metric_from_params

    capture = metric_from_params(metric["name"], metric["params"]).landmarks.get("capture")
    if capture:
        lo = max(lo, 1.5 * float(capture))
    hi = max(2.0 * d, lo * 1.01)
    sliders.append({"name": "distance", "label": "camera distance (scene units)", "value": d, "min": lo, "max": hi,
                    "step": (hi - lo) / SLIDER_STEPS})  # fmt: skip
    return sliders


def apply_controls(native: Mapping[str, Any], values: Mapping[str, float]) -> dict:
    """A copy of ``native`` with the sliders' values applied.

    Parameters
    ----------
    native : Mapping
        The native scene dict the sliders started from.
    values : Mapping of str to float
        Slider name -> value (names from :func:`slider_specs`; missing ones keep the scene's value).
        ``distance`` moves the camera along its line of sight, keeping what it looks at.

    Returns
    -------
    dict
        The new native scene.

    Raises
    ------
    ValueError
        An unknown slider name, or parameters the metric refuses (e.g. a Reissner–Nordström charge
        above the mass), with the metric's own message.
    """
    from warpviz.spacetime.metrics import metric_from_params

    out = copy.deepcopy(dict(native))
    entry = _registry_entry(out["metric"]["name"])
    names = [s["name"] for s in entry["param_specs"]]
    unknown = sorted(set(values) - set(names) - {"distance"})
    if unknown:
        raise ValueError(f"unknown slider(s) {', '.join(unknown)} (this scene has {', '.join(names + ['distance'])})")
    params = [float(values.get(n, p)) for n, p in zip(names, out["metric"]["params"])]
    metric_from_params(out["metric"]["name"], params)  # the metric's own checks (ranges, relations)
    out["metric"]["params"] = params
    if "distance" in values:
        d = float(values["distance"])
        if not (math.isfinite(d) and d > 0.0):
            raise ValueError(f"camera distance must be a positive number, got {d}")
        cam = out["camera"]
        look = np.asarray(cam["look_at"], dtype=np.float64)
        pos = np.asarray(cam["position"], dtype=np.float64)
        out["camera"]["position"] = (look + (pos - look) * (d / camera_distance(cam))).tolist()
    return out


def image_click_to_pixel(x: float, y: float, *, shown: tuple[float, float], size: tuple[int, int]) -> tuple[int, int]:
    """The image pixel under a click on the picture as the browser shows it.

    Parameters
    ----------
    x, y : float
        Click position in the shown picture, from its top-left corner (the event's ``offsetX/Y``).
    shown : tuple of float, keyword-only
        (width, height) of the picture on the page.
    size : tuple of int, keyword-only
        (width, height) of the image in pixels.

    Returns
    -------
    tuple of int
        (x, y) pixel, clamped into the image; y counts down from the top row, as everywhere in warpviz.
    """
    (sw, sh), (w, h) = shown, size
    px = int(np.clip(math.floor(x * w / max(float(sw), 1.0)), 0, w - 1))
    py = int(np.clip(math.floor(y * h / max(float(sh), 1.0)), 0, h - 1))
    return px, py
