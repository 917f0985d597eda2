"""Observers who hold a camera: their 4-velocity and frame at a point (:func:`observer`).

The core computes them (``renderer_ext/spacetime/observers.h``); a render's camera uses the same code
through its scene's ``[camera] observer``. See docs/observers.md.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from warpviz._native import core

__all__ = ["ObserverFrame", "observer"]

#: The observers, by name: the local static observer (the ZAMO inside an ergoregion; every camera before
#: moving observers), strictly static, the zero-angular-momentum observer, a circular geodesic orbit, radial
#: free fall, a velocity relative to the local observer, and a chart 4-velocity given outright.
KINDS = ("local", "static", "zamo", "orbit", "free_fall", "moving", "given")


@dataclass(frozen=True)
class ObserverFrame:
    """An observer at a point: where, how it moves and its axes.

    Attributes
    ----------
    x : numpy.ndarray, shape (4,)
        The point in the metric's chart (t, x, y, z).
    u : numpy.ndarray, shape (4,)
        The 4-velocity u^μ (chart components), g(u, u) = -1.
    e : numpy.ndarray, shape (3, 4)
        The spatial axes e_j^μ (rows: the frame's x, y, z): orthonormal and orthogonal to ``u``.
    g : numpy.ndarray, shape (4, 4)
        The covariant metric g_μν at ``x``.
    """

    x: np.ndarray
    u: np.ndarray
    e: np.ndarray
    g: np.ndarray

    def speed_relative_to(self, other: "ObserverFrame") -> float:
        """Speed (units of c) of this observer as the other, at the same point, measures it:
        sqrt(1 - 1/γ²) with γ = -g(u, u_other)."""
        gamma = -float(self.u @ self.g @ other.u)
        return float(np.sqrt(max(0.0, 1.0 - 1.0 / (gamma * gamma))))


def observer(metric, position, kind: str = "local", *, velocity=(0.0, 0.0, 0.0), axis=(0.0, 0.0, 1.0),
             fall_from: float = 0.0, u=(0.0, 0.0, 0.0, 0.0), sheet: int = 1) -> ObserverFrame:  # fmt: skip
    """The observer ``kind`` at ``position``: its chart point, 4-velocity and frame.

    Parameters
    ----------
    metric : Metric
        The spacetime, e.g. ``Schwarzschild(mass=1)``.
    position : array_like, shape (3,)
        The point (Cartesian, units of M).
    kind : {"local", "static", "zamo", "orbit", "free_fall", "moving", "given"}
        ``local``: the static observer, the ZAMO inside an ergoregion; ``static``: at rest (only where
        g_tt < 0); ``zamo``: zero angular momentum about z; ``orbit``: a circular geodesic orbit about
        ``axis`` (prograde about it; in the plane through the centre perpendicular to it); ``free_fall``:
        radial free fall from rest at ``fall_from`` (0: infinity); ``moving``: ``velocity`` relative to the
        local observer; ``given``: the chart 4-velocity ``u``.
    velocity : array_like, shape (3,)
        ``moving``: velocity in units of c, in the local observer's axes (closest to x, y, z); |v| < 1.
    axis : array_like, shape (3,)
        ``orbit``: the axis the orbit turns about (right-handed).
    fall_from : float
        ``free_fall``: the radius the fall starts from at rest; 0 (default) from infinity.
    u : array_like, shape (4,)
        ``given``: u^μ in the metric's chart, g(u, u) = -1 to 1e-6.
    sheet : {1, -1}
        A wormhole's sheet.

    Returns
    -------
    ObserverFrame

    Raises
    ------
    ValueError
        An unknown kind, or no such observer at the point (the reason: faster than light, inside the
        ergoregion for ``static``, out of an orbit's plane, ...).

    Examples
    --------
    >>> import warpviz as wv
    >>> from warpviz.spacetime.observers import observer
    >>> o = observer(wv.Schwarzschild(mass=1.0), [8.0, 0, 0], "free_fall")
    >>> round(o.speed_relative_to(observer(wv.Schwarzschild(mass=1.0), [8.0, 0, 0])), 12)  # sqrt(2M/r)
    0.5
    """
    if kind not in KINDS:
        raise ValueError(f"observer kind must be one of {', '.join(map(repr, KINDS))}, got {kind!r}")
    pos = [float(c) for c in np.asarray(position, dtype=np.float64).reshape(3)]
    camera: dict[str, Any] = {
        "position": pos, "look_at": [pos[0] + 1.0, pos[1], pos[2]], "up": [0.0, 0.0, 1.0], "fov": 40.0,
        "width": 1, "height": 1, "sheet": int(sheet), "shift": "none",
        "observer": {"kind": kind, "velocity": [float(v) for v in velocity], "axis": [float(a) for a in axis],
                     "fall_from": float(fall_from), "u": [float(c) for c in u]},
    }  # fmt: skip
    x, uu, e, g = core.observer(metric.name, list(metric.param_values), camera)
    return ObserverFrame(x=x, u=uu, e=e, g=g)
