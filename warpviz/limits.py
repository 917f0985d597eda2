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

import numbers

__all__ = ["EXPOSURE_RANGE", "TONEMAP_NAMES", "MAX_EDGE_SAMPLES", "MAX_IMAGE_SIDE", "MAX_SPP", "MAX_SEED", "TOLERANCE_RANGES", "exposure_stops", "image_side",
           "tolerance_problem", "tolerance_range"]

#: Largest image width or height in pixels. Whether an image of a given size fits in memory is checked
#: against the machine before rendering; this only bounds the pixel coordinates the core indexes with.
MAX_IMAGE_SIDE = 65536

#: Largest number of samples per pixel (the film counts a pixel's samples in 32 bits).
MAX_SPP = 2**31 - 1

#: Largest multiple of spp that the pixels on a directly seen light's edge get (``render(edge_samples=)``).
MAX_EDGE_SAMPLES = 64

#: Largest random seed of a render (the core reads it as a signed 64-bit integer).
MAX_SEED = 2**63 - 1

#: The exposure of a tonemapped picture, in stops (the radiance times 2 ** exposure), as [lowest, highest]:
#: 2**20 is a millionfold either way, far beyond any scene's range, and keeps the scaled radiance finite.
EXPOSURE_RANGE = (-20.0, 20.0)

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
