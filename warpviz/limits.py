"""The limits of what warpviz accepts, in one place: image size, samples, seeds, tolerances.

Scene files (:mod:`warpviz.scene.settings`), native scene dicts (:mod:`warpviz.scene.native`), the
renderer's options (:mod:`warpviz.render.render`), :func:`warpviz.trace` and the command line all check
against these numbers, so a value refused by one is refused by all, with the same range in the message.
Memory is checked separately, against the machine, before a render allocates anything
(:mod:`warpviz.render.memory`).

Examples
--------
>>> from warpviz.limits import MAX_IMAGE_SIDE, tolerance_range
>>> MAX_IMAGE_SIDE
65536
>>> tolerance_range("dopri5")
(1e-15, 0.1)
"""

from __future__ import annotations

import math
import numbers
import re

__all__ = ["EXPOSURE_RANGE", "TONEMAP_NAMES", "MAX_EDGE_SAMPLES", "MAX_IMAGE_SIDE", "MAX_SPP", "MAX_SEED", "MAX_STRENGTH", "MAX_MESH_MB", "MESH_LIMIT_VARIABLE", "mesh_limit_bytes", "TOLERANCE_RANGES", "exposure_stops", "image_side",
           "tolerance_problem", "tolerance_range", "MAX_TIME_LIMIT", "NOISE_RANGE", "duration_seconds", "noise_level"]

#: Largest image width or height in pixels. Whether an image of a given size fits in memory is checked
#: against the machine before rendering; this only bounds the pixel coordinates the core indexes with.
MAX_IMAGE_SIDE = 65536

#: Largest number of samples per pixel (the film counts a pixel's samples in 32 bits).
MAX_SPP = 2**31 - 1

#: Largest multiple of spp that the pixels on a light's edge or holding detail get (``render(edge_samples=)``,
#: ``render(detail_samples=)``).
MAX_EDGE_SAMPLES = 64

#: Largest strength of an emitter (the factor on its colour): a sun seen from a lamp-lit room is about 1e5
#: times the lamp; beyond 1e12 a scene is a typo (``1e308`` once gave infinite pixels). The core also counts
#: any sample whose radiance passes 1e30 as failed, whatever made it so.
MAX_STRENGTH = 1e12

#: Largest mesh file read by default, in MB (2**20 bytes); the environment variable named by
#: :data:`MESH_LIMIT_VARIABLE` raises it. The file's size is checked before it is read: a 512 MB sparse
#: file once took 6 s and 1.1 GB of memory before it was found to hold no triangles.
MAX_MESH_MB = 256

#: The environment variable that overrides :data:`MAX_MESH_MB` (a number of MB).
MESH_LIMIT_VARIABLE = "WARPVIZ_MAX_MESH_MB"

#: Largest random seed of a render (the core reads it as a signed 64-bit integer).
MAX_SEED = 2**63 - 1

#: The exposure of a tonemapped picture, in stops (the radiance times 2 ** exposure), as [lowest, highest]:
#: 2**20 is a millionfold either way, far beyond any scene's range, and keeps the scaled radiance finite.
EXPOSURE_RANGE = (-20.0, 20.0)

#: Longest time budget of one render, in seconds (30 days): longer work is a series of resumed renders.
MAX_TIME_LIMIT = 30 * 86400.0

#: A render's noise target (its relative noise estimate, :func:`warpviz.render.passes.noise_estimate`) lies
#: in this open interval: 1 is noise as large as the image, and a target at 0 is never reached.
NOISE_RANGE = (0.0, 1.0)

#: The tonemap curves a PNG may be written with (:mod:`warpviz.render.tonemap` defines them; named here so
#: scene files, which sit below the renderer, check the same names).
TONEMAP_NAMES = ("filmic", "clip", "reinhard")

#: The local error tolerances each stepper can meet in double precision, as [lowest, highest]. Below the
#: lowest, the step-size control asks for errors below the rounding error of the state: the drift of the
#: conserved quantities stops falling at ~5e-15 (dopri5, dop853), a render at ``tol = 1e-30`` ends every ray
#: as ``nan``, and rk4's tolerance-limited step needs more than the renderer's 20000 steps per geodesic
#: below about 1e-12 (every sample of fig04 fails at 1e-14). Above the highest, no result is a geodesic
#: worth the name.
TOLERANCE_RANGES = {"rk4": (1e-12, 0.1), "dopri5": (1e-15, 0.1), "dop853": (1e-15, 0.1)}


def tolerance_range(stepper: str) -> tuple[float, float]:
    """The usable (lowest, highest) local error tolerance of ``stepper``.

    Parameters
    ----------
    stepper : {"rk4", "dopri5", "dop853"}
        The integrator.

    Returns
    -------
    tuple of float
        Inclusive bounds.
    """
    return TOLERANCE_RANGES[stepper]


def tolerance_problem(stepper: str, tol: float) -> str:
    """Why ``tol`` is no tolerance for ``stepper``, or ``""`` where it is usable.

    Parameters
    ----------
    stepper : {"rk4", "dopri5", "dop853"}
        The integrator.
    tol : float
        The local error tolerance asked for.

    Returns
    -------
    str
        E.g. ``"tol = 1e-30 is outside what dopri5 can meet in double precision: use [1e-15, 0.1]"``; the
        caller may put a key path in front of ``tol``.
    """
    lo, hi = tolerance_range(stepper)
    if lo <= tol <= hi:
        return ""
    return f"tol = {tol:g} is outside what {stepper} can meet in double precision: use [{lo:g}, {hi:g}]"


def image_side(name: str, value) -> int:
    """``value`` as an image width or height, checked to be an integer in [1, :data:`MAX_IMAGE_SIDE`].

    Parameters
    ----------
    name : str
        What the value is, for the message (``"width"``).
    value : int
        The size in pixels.

    Returns
    -------
    int

    Raises
    ------
    ValueError
        Not an integer, or out of range.
    """
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or not 1 <= value <= MAX_IMAGE_SIDE:
        raise ValueError(f"{name} must be an integer in [1, {MAX_IMAGE_SIDE}], got {value!r}")
    return int(value)


def exposure_stops(name: str, value) -> float:
    """``value`` as an exposure in stops, checked to be a real number in :data:`EXPOSURE_RANGE`.

    Parameters
    ----------
    name : str
        What the value is, for the message (``"exposure"``, ``"outputs.exposure"``).
    value : float
        Stops.

    Returns
    -------
    float

    Raises
    ------
    ValueError
        Not a real number, or out of range.
    """
    lo, hi = EXPOSURE_RANGE
    if isinstance(value, bool) or not isinstance(value, numbers.Real) or not lo <= float(value) <= hi:
        raise ValueError(f"{name} must be a number of stops in [{lo:g}, {hi:g}], got {value!r}")
    return float(value)


_DURATION = re.compile(r"(?:(?P<h>\d+(?:\.\d*)?)h)?(?:(?P<m>\d+(?:\.\d*)?)m)?(?:(?P<s>\d+(?:\.\d*)?)s?)?")


def duration_seconds(name: str, value) -> float:
    """``value`` as a time budget in seconds, in (0, :data:`MAX_TIME_LIMIT`].

    Parameters
    ----------
    name : str
        What the value is, for the message (``"--time"``, ``"time_limit"``).
    value : float or str
        Seconds, or a string of seconds with an optional unit: ``"90"``, ``"90s"``, ``"2m"``, ``"1h30m"``,
        ``"1.5h"``.

    Returns
    -------
    float

    Raises
    ------
    ValueError
        Not a duration, not positive, or above the limit.

    Examples
    --------
    >>> [duration_seconds("--time", v) for v in ("90", "2m", "1h30m", "1.5m", 45)]
    [90.0, 120.0, 5400.0, 90.0, 45.0]
    """
    seconds = None
    if isinstance(value, str):
        text = value.strip().lower().replace(" ", "")
        m = _DURATION.fullmatch(text)
        if text and m and any(m.group(k) for k in "hms"):
            seconds = sum(float(m.group(k) or 0) * f for k, f in (("h", 3600.0), ("m", 60.0), ("s", 1.0)))
    elif isinstance(value, numbers.Real) and not isinstance(value, bool):
        seconds = float(value)
    if seconds is None or not math.isfinite(seconds):
        raise ValueError(f"{name} must be a time such as 90 (seconds), 90s, 2m or 1h30m, got {value!r}")
    if not 0 < seconds <= MAX_TIME_LIMIT:
        raise ValueError(f"{name} must be more than 0 and at most {MAX_TIME_LIMIT:.0f} s (30 days), got {value!r}")
    return seconds


def noise_level(name: str, value) -> float:
    """``value`` as a noise target: a relative error in the open interval :data:`NOISE_RANGE` (0.02: 2 %).

    Raises
    ------
    ValueError
        Not a real number in (0, 1).
    """
    lo, hi = NOISE_RANGE
    if isinstance(value, bool) or not isinstance(value, numbers.Real) or not lo < float(value) < hi:
        raise ValueError(f"{name} must be a relative error in ({lo:g}, {hi:g}), e.g. 0.02 for 2 %, got {value!r}")
    return float(value)


def mesh_limit_bytes() -> int:
    """The largest mesh file that is read, in bytes: :data:`MAX_MESH_MB`, or the environment's
    :data:`MESH_LIMIT_VARIABLE` where it is set to a positive number of MB.

    Raises
    ------
    ValueError
        The variable is set to something that is not a positive number.
    """
    import os

    text = os.environ.get(MESH_LIMIT_VARIABLE)
    if text is None or not text.strip():
        return MAX_MESH_MB * 2**20
    try:
        mb = float(text)
    except ValueError:
        mb = float("nan")
    if not (math.isfinite(mb) and mb > 0):
        raise ValueError(f"{MESH_LIMIT_VARIABLE}={text!r} must be a positive number of MB")
    return int(mb * 2**20)
