"""Embedding diagrams of wormholes, from the functions a static spherical metric declares to the core.

A static, spherically symmetric metric gives the core its lens functions (``renderer_ext/spacetime/lens_map.h``)

    ds² = −A(R) dt² + dR² / (A(R) h(R)) + R² dΩ²,    A, h polynomials in u = 1 / R,

and a wormhole marks its throat, the sphere R₀ = 1 / u_inner where F = A h vanishes and rays pass to the
other sheet. The equatorial slice t = const, θ = π/2 has the spatial metric dR² / F + R² dφ²; drawn as a
surface of revolution ρ = R, z(R) in Euclidean space it is isometric when

    dz/dR = √(1/F − 1),    and the proper distance from the throat is   l(R) = ∫ dR / √F.

Both integrals have an inverse-square-root end at the throat; with R = R₀ + s² they become smooth in s
(F / s² is a polynomial in δ = u_inner − u = s² / (R₀ (R₀ + s²)), shifted so nothing cancels), and are
evaluated by Gauss–Legendre on pieces of s doubling in length: to rounding for any such metric. So a new
wormhole metric file gets its diagram, its rays on the diagram and the teaching view's drawing of them
with no Python: Ellis's catenoid z = b₀ asinh(l / b₀) is one case (tested against it), the Morris–Thorne
wormhole of constant shape function b₀ (z = 2 √(b₀ (R − b₀)), Flamm's paraboloid) another.

Our sheet (+1) is drawn above the throat's waist (z > 0), the other sheet (−1) below it.

Examples
--------
>>> import warpviz as wv
>>> round(float(WormholeProfile.of(wv.EllisWormhole(throat=2.0)).height(2.0 * 2.0 ** 0.5)), 12)  # b0 asinh(l / b0), l = 2
1.762747174039
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.polynomial import polynomial as P

from warpviz.spacetime._meshes import _check_resolution, _per_point, _revolve
from warpviz.spacetime.metrics import Metric

if TYPE_CHECKING:  # pragma: no cover
    import pyvista as pv

__all__ = ["WormholeProfile", "has_embedding", "wormhole_embedding", "wormhole_embedding_points"]

_NODES, _WEIGHTS = np.polynomial.legendre.leggauss(24)
#: Piece ends in s / √R₀: fine ones at the throat, then doubling (an analytic integrand on each piece, whose
#: nearest singularity, R = 0 at s = i √R₀, is at least a piece's length away: 24 nodes reach rounding).
_FIRST = (0.0, 0.125, 0.25, 0.5)


def has_embedding(metric: Metric) -> bool:
    """Whether ``metric`` is a static spherical wormhole, whose embedding diagram can be drawn."""
    lens = metric.spherical_lens
    return lens is not None and bool(lens["throat"])


class WormholeProfile:
    """The meridian of a wormhole's equatorial embedding: height z and proper distance l against areal radius.

    Parameters
    ----------
    lens : dict
        A static spherical wormhole's lens functions as :attr:`warpviz.Metric.spherical_lens` gives them:
        ``a`` and ``h`` (coefficients of A(u) and h(u) in u = 1 / R, constant first), ``u_inner`` (1 / R₀
        at the throat) and ``throat`` (must be true).

    Attributes
    ----------
    throat : float
        Areal radius R₀ of the throat.
    """

    def __init__(self, lens: dict[str, Any]):
        if not lens or not lens.get("throat"):
            raise ValueError("an embedding diagram needs a static spherical wormhole (a lens with a throat)")
        self.u0 = float(lens["u_inner"])
        if not (self.u0 > 0.0 and math.isfinite(self.u0)):
            raise ValueError(f"the throat's u_inner must be positive and finite, got {lens['u_inner']!r}")
        self.throat = 1.0 / self.u0
        self._a = np.trim_zeros(np.asarray(lens["a"], dtype=np.float64), "b")
        h = np.trim_zeros(np.asarray(lens["h"], dtype=np.float64), "b")
        # h(u0 - d) = sum c_k d^k: Taylor shift (c_0 = h(u0) = 0 at a throat, dropped so nothing cancels)
        shifted = _shift(h, self.u0)
        self._h_over_d = shifted[1:] if shifted.size > 1 else np.zeros(1)
        # 1 - A h as a polynomial in u (its constant term is 0 for a spacetime flat far out)
        one_minus_f = -P.polymul(self._a, h)
        one_minus_f[0] += 1.0
        self._one_minus_f = one_minus_f
        self._ends = np.array(_FIRST) * math.sqrt(self.throat)
        self._cum = np.zeros((2, len(_FIRST)))  # (l, z) at each piece end
        self._cum[:, 1:] = np.cumsum([self._piece(a, b) for a, b in zip(self._ends[:-1], self._ends[1:])], axis=0).T

    @classmethod
    def of(cls, metric: Metric) -> "WormholeProfile":
        """The profile of ``metric``; ``ValueError`` for a metric that is not a static spherical wormhole."""
        if not has_embedding(metric):
            raise ValueError(f"{metric!r} is not a static spherical wormhole: it has no embedding diagram")
        return cls(metric.spherical_lens)

    def _rates(self, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """dl/ds and dz/ds at s (R = R₀ + s²), regular at the throat."""
        r = self.throat + s * s
        u = 1.0 / r
        d_over_s2 = 1.0 / (self.throat * r)  # delta / s^2, exact
        f_over_s2 = P.polyval(u, self._a) * P.polyval(d_over_s2 * s * s, self._h_over_d) * d_over_s2
        f_over_s2 = np.maximum(f_over_s2, np.finfo(float).tiny)
        dl = 2.0 / np.sqrt(f_over_s2)
        dz = 2.0 * np.sqrt(np.maximum(P.polyval(u, self._one_minus_f), 0.0) / f_over_s2)
        return dl, dz

    def _piece(self, a: float | np.ndarray, b: float | np.ndarray) -> np.ndarray:
        """(l, z) integrated over s from a to b (arrays of the same shape: one piece each)."""
        a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
        half, mid = 0.5 * (b - a), 0.5 * (b + a)
        s = mid[..., None] + half[..., None] * _NODES
        dl, dz = self._rates(s)
        return np.stack([half * (dl @ _WEIGHTS), half * (dz @ _WEIGHTS)])

    def _extend(self, s_max: float) -> None:
        while self._ends[-1] < s_max:
            a = self._ends[-1]
            self._cum = np.column_stack([self._cum, self._cum[:, -1] + self._piece(a, 2.0 * a)])
            self._ends = np.append(self._ends, 2.0 * a)

    def _integrals(self, s: np.ndarray) -> np.ndarray:
        """(l, z) from the throat to s, shape (2, *s.shape)."""
        s = np.asarray(s, dtype=np.float64)
        if s.size and not np.all(np.isfinite(s)):
            raise ValueError("radii must be finite")
        self._extend(float(np.max(s, initial=0.0)))
        k = np.clip(np.searchsorted(self._ends, s, side="right") - 1, 0, self._ends.size - 1)
        return self._cum[:, k] + self._piece(self._ends[k], s)

    def _s(self, radius: Any) -> np.ndarray:
        r = np.asarray(radius, dtype=np.float64)
        return np.sqrt(np.maximum(r - self.throat, 0.0))

    def height(self, radius: Any) -> np.ndarray:
        """Height z ≥ 0 of the diagram above the waist at areal radius ``radius`` (clamped to the throat).

        Parameters
        ----------
        radius : array_like, float

        Returns
        -------
        numpy.ndarray, float64, the shape of ``radius``
        """
        return self._integrals(self._s(radius))[1]

    def distance(self, radius: Any) -> np.ndarray:
        """Proper radial distance l ≥ 0 from the throat to areal radius ``radius`` (clamped to the throat).

        Parameters
        ----------
        radius : array_like, float

        Returns
        -------
        numpy.ndarray, float64, the shape of ``radius``
        """
        return self._integrals(self._s(radius))[0]

    def radius_at(self, distance: Any) -> np.ndarray:
        """Areal radius R at proper distance ``distance`` ≥ 0 from the throat (Newton on l(R); the inverse
        of :meth:`distance` to rounding).

        Parameters
        ----------
        distance : array_like, float

        Returns
        -------
        numpy.ndarray, float64, the shape of ``distance``
        """
        target = np.asarray(distance, dtype=np.float64)
        if np.any(target < 0.0) or not np.all(np.isfinite(target)):
            raise ValueError("distances from the throat must be finite and >= 0")
        s = np.sqrt(target)  # far out l ~ R ~ s^2; near the throat l ~ 2 s / sqrt(F')
        close = False
        for _ in range(60):  # l(s) is increasing: Newton converges, then one more step reaches rounding
            step = (self._integrals(s)[0] - target) / self._rates(s)[0]
            s = np.maximum(s - step, 0.5 * s)
            if close:
                break
            close = bool(np.all(np.abs(step) <= 1e-9 * s))
        return self.throat + s * s


def _shift(coef: np.ndarray, u0: float) -> np.ndarray:
    """Coefficients of p(u0 - d) in d, for p with coefficients ``coef`` in u."""
    out = np.zeros(1)
    for c in coef[::-1]:  # Horner in the polynomial (u0 - d)
        out = P.polyadd(P.polymul(out, [u0, -1.0]), [c])
    return out


def wormhole_embedding(metric: Metric, *, l_max: float | None = None, resolution: int = 64) -> pv.PolyData:
    """Embedding diagram of a static spherical wormhole's equatorial plane, both sheets.

    The slice t = const, θ = π/2 drawn as the surface of revolution ρ = R, z = ±z(R) (module docstring):
    our sheet (l > 0) is the upper half, the other sheet (l < 0) the lower one, the throat the waist at
    z = 0. Lengths along the meridians are true proper distances l. For the Ellis wormhole it is the
    catenoid ρ = b₀ cosh(z / b₀).

    Parameters
    ----------
    metric : Metric
        A wormhole whose metric file declares its lens functions (``kStaticSpherical``), such as
        :class:`warpviz.EllisWormhole`.
    l_max : float, optional, keyword-only
        Proper radial distance from the throat drawn on each sheet (default 10 throat radii).
    resolution : int, keyword-only
        Points around the circles; ``resolution + 1`` meridian points (evenly spaced in l).

    Returns
    -------
    pyvista.PolyData
        Open surface with point data ``l`` float64 (signed proper distance), ``r`` float64 (areal
        radius ρ) and ``sheet`` int8 (+1 for l ≥ 0, −1 for l < 0).

    Raises
    ------
    ValueError
        Not a static spherical wormhole, or a bad ``l_max`` or ``resolution``.

    Examples
    --------
    >>> import numpy as np, warpviz as wv
    >>> emb = wormhole_embedding(wv.EllisWormhole(throat=1.0), l_max=5.0)
    >>> sorted(set(emb.point_data["sheet"].tolist())), bool(np.isclose(emb.bounds[5], np.arcsinh(5.0), rtol=1e-13))
    ([-1, 1], True)
    """
    resolution = _check_resolution(resolution)
    profile = WormholeProfile.of(metric)
    l_max = 10.0 * profile.throat if l_max is None else l_max
    if isinstance(l_max, bool) or not isinstance(l_max, (int, float, np.floating, np.integer)):
        raise ValueError(f"l_max must be a positive finite length, got {l_max!r}")
    l_max = float(l_max)
    if not (l_max > 0.0 and math.isfinite(l_max)):
        raise ValueError(f"l_max must be a positive finite length, got {l_max!r}")
    ell = np.linspace(l_max, -l_max, 2 * (resolution // 2) + 1)  # north (our sheet) to south
    rho = profile.radius_at(np.abs(ell))
    rho[ell == 0.0] = profile.throat
    z = np.sign(ell) * profile.height(rho)
    sheet = np.where(ell >= 0.0, 1, -1).astype(np.int8)
    return _revolve(rho, z, n_phi=resolution).polydata(
        l=_per_point(ell, rho, resolution), r=_per_point(rho, rho, resolution), sheet=np.repeat(sheet, resolution)
    )


def wormhole_embedding_points(metric: Metric, points: Any, sheet: Any) -> np.ndarray:
    """Map positions on a static spherical wormhole onto its embedding diagram (:func:`wormhole_embedding`).

    A point at areal radius R = |x| on sheet s goes to the point of the diagram at that radius on that
    sheet, at its azimuth φ = atan2(y, x); it lies exactly on the surface. Rays in the plane z = 0 are
    drawn faithfully; other rays are projected along their latitude (their distance from the throat and
    azimuth are kept). A ray through the throat crosses the waist from one sheet to the other.

    Parameters
    ----------
    metric : Metric
        A static spherical wormhole (:func:`has_embedding`).
    points : array_like, shape (P, 3), float
        Positions in each point's sheet frame (as in ``RayBundle.points``).
    sheet : array_like, shape (P,), {+1, -1}
        Sheet of each point (``RayBundle.point_data["sheet"]``).

    Returns
    -------
    numpy.ndarray, shape (P, 3), float64
        Positions on the embedding surface.

    Examples
    --------
    >>> import warpviz as wv
    >>> wormhole_embedding_points(wv.EllisWormhole(throat=1.0), [[0, 5.0, 0], [5.0, 0, 0]], [1, -1]).round(6).tolist()
    [[0.0, 5.0, 2.292432], [5.0, 0.0, -2.292432]]
    """
    profile = WormholeProfile.of(metric)
    points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    sheet = np.asarray(sheet).reshape(-1)
    if sheet.shape[0] != points.shape[0]:
        raise ValueError(f"sheet must have one entry per point ({points.shape[0]}), got {sheet.shape[0]}")
    if not np.all((sheet == 1) | (sheet == -1)):
        raise ValueError("sheet entries must be +1 or -1")
    radius = np.maximum(np.linalg.norm(points, axis=1), profile.throat)
    phi = np.arctan2(points[:, 1], points[:, 0])
    z = np.where(sheet > 0, 1.0, -1.0) * profile.height(radius)
    return np.column_stack([radius * np.cos(phi), radius * np.sin(phi), z])
