"""Display meshes of the landmarks of each spacetime (horizon, ergosphere, photon sphere or region, throat,
embedding diagram), as PyVista polydata.

Positions are in the frame rays are reported in (see the README): Cartesian Kerr–Schild x, y, z for
Schwarzschild and Kerr (spin along +z), the per-sheet areal-radius frame for a wormhole.
A Boyer–Lindquist sphere r = const is an oblate spheroid in Kerr–Schild coordinates,

    x² + y² = (r² + a²) sin²θ,    z = r cos θ,

so the Kerr horizon, ergosurface and photon region below are surfaces of revolution about z built
from their Boyer–Lindquist r(θ). All meshes are surfaces of quads and triangles for display (no texture
coordinates); closed ones have their normals pointing out of the volume they enclose.

Examples
--------
>>> import warpviz as wv
>>> sorted(wv.metric_features(wv.Kerr(mass=1.0, spin=0.9)))
['ergosphere', 'horizon', 'photon_sphere']
>>> wv.metric_features(wv.Minkowski())
{}
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from warpviz.spacetime._meshes import _check_resolution, _per_point, _revolve, _theta
from warpviz.spacetime.embedding import has_embedding, wormhole_embedding
from warpviz.spacetime.metrics import Metric

if TYPE_CHECKING:  # pragma: no cover
    import pyvista as pv

__all__ = [
    "ergosphere_surface",
    "horizon_surface",
    "metric_features",
    "photon_sphere",
    "throat_surface",
]


def _kerr_schild_surface(r: np.ndarray, theta: np.ndarray, a: float, resolution: int) -> pv.PolyData:
    """The surface of revolution of the Boyer–Lindquist curve r(θ), θ from 0 to π, in Kerr–Schild
    Cartesian coordinates; point data ``r``."""
    rho = np.sqrt(r * r + a * a) * np.sin(theta)
    rho[[0, -1]] = 0.0  # exactly on the axis at the poles
    z = r * np.cos(theta)
    return _revolve(rho, z, n_phi=resolution).polydata(r=_per_point(r, rho, resolution))


# --------------------------------------------------------------------------------------------------
# spacetime landmarks


def horizon_surface(metric: Metric, *, resolution: int = 64) -> pv.PolyData:
    """The outer event horizon.

    Schwarzschild: the sphere r = 2M. Kerr: r = r₊ = M + √(M² − a²), which in Kerr–Schild Cartesian
    coordinates is the oblate spheroid with semi-axes √(r₊² + a²) (x, y) and r₊ (z).

    Parameters
    ----------
    metric : Schwarzschild or Kerr
    resolution : int, keyword-only
        Points around the equator; the meridian has ``resolution // 2 + 1`` points.

    Returns
    -------
    pyvista.PolyData
        Closed surface, outward normals; point data ``r`` float64 (Boyer–Lindquist radius, = r₊).

    Raises
    ------
    ValueError
        The metric has no horizon.

    Examples
    --------
    >>> import warpviz as wv
    >>> h = horizon_surface(wv.Kerr(mass=1.0, spin=0.6))
    >>> [round(float(v), 12) for v in h.bounds[1::2]]   # x, y semi-axes sqrt(r+^2 + a^2) = sqrt(3.6); z: r+ = 1.8
    [1.897366596101, 1.897366596101, 1.8]
    """
    resolution = _check_resolution(resolution)
    marks = metric.landmarks
    if "horizon" not in marks:
        raise ValueError(f"{metric!r} has no horizon")
    theta = _theta(resolution)
    return _kerr_schild_surface(np.full_like(theta, marks["horizon"]), theta, marks.get("spin", 0.0), resolution)


def ergosphere_surface(metric: Metric, *, resolution: int = 64) -> pv.PolyData:
    """The outer boundary of Kerr's ergoregion (the static limit).

    Boyer–Lindquist r_E(θ) = M + √(M² − a² cos²θ), mapped to Kerr–Schild Cartesian coordinates:
    it touches the horizon at the poles (r_E = r₊) and reaches r_E = 2M on the equator, a
    cylindrical radius of √(4M² + a²).

    Parameters
    ----------
    metric : Kerr
    resolution : int, keyword-only
        Points around the equator; the meridian has ``resolution // 2 + 1`` points.

    Returns
    -------
    pyvista.PolyData
        Closed surface, outward normals; point data ``r`` float64 (Boyer–Lindquist r_E(θ)).

    Raises
    ------
    ValueError
        Not a Kerr metric (a non-rotating hole has no ergoregion: its static limit is the horizon).

    Examples
    --------
    >>> import warpviz as wv
    >>> e = ergosphere_surface(wv.Kerr(mass=1.0, spin=0.6))
    >>> round(float(e.points[:, 2].max()), 12), round(float(e.point_data["r"].max()), 12)
    (1.8, 2.0)
    """
    resolution = _check_resolution(resolution)
    marks = metric.landmarks
    if "ergosphere" not in marks:
        raise ValueError(f"{metric!r} has no ergosphere (only a rotating black hole does)")
    theta = _theta(resolution)
    m, a = marks["mass"], marks["spin"]
    r = m + np.sqrt(np.maximum(m * m - (a * np.cos(theta)) ** 2, 0.0))
    return _kerr_schild_surface(r, theta, a, resolution)


def _kerr_photon_region_cos2(m: float, a: float, r: np.ndarray) -> np.ndarray:
    """cos²θ of the turning points of the spherical photon orbit at Boyer–Lindquist radius r.

    The photon region is (2rΔ − (r − M)Σ)² ≤ 4a²r²Δ sin²θ, with Δ = r² − 2Mr + a² and
    Σ = r² + a²cos²θ. As a quadratic in w = cos²θ, divided by a², it reads αw² + βw + γ ≤ 0, and w
    runs up to its larger root, computed in the cancellation-free form −2γ / (β + √(β² − 4αγ)).
    """
    delta = r * r - 2.0 * m * r + a * a
    a_over = (r * r * (r - 3.0 * m) + 2.0 * a * a * r) / a  # (2rΔ − (r − M) r²) / a
    alpha = ((r - m) * a) ** 2
    beta = 4.0 * r * r * delta - 2.0 * a * a_over * (r - m)
    gamma = a_over**2 - 4.0 * r * r * delta
    w = -2.0 * gamma / (beta + np.sqrt(np.maximum(beta * beta - 4.0 * alpha * gamma, 0.0)))
    return np.clip(w, 0.0, 1.0)


def photon_sphere(metric: Metric, *, resolution: int = 64) -> pv.PolyData:
    """Where light can orbit: the photon sphere, or Kerr's photon region.

    Schwarzschild: the sphere r = 3M. Kerr: the boundary of the *photon region*, the set of
    Boyer–Lindquist (r, θ) through which spherical photon orbits pass. It is a shell between the
    prograde and retrograde equatorial circular orbits (``Kerr.photon_orbit_radii``) on the
    equator that narrows towards the axis, where its inner and outer walls meet at the radius of
    the polar orbit. The wall at Boyer–Lindquist r reaches up to the turning latitude of the
    spherical orbit of that radius. Drawn translucent, the shell shows why the shadow of a spinning
    hole is flattened on one side. For |a| ≤ 1e-12 M the sphere r = 3M is returned.

    Parameters
    ----------
    metric : Schwarzschild or Kerr
    resolution : int, keyword-only
        Points around the equator; each wall's meridian has about ``resolution // 2`` points.

    Returns
    -------
    pyvista.PolyData
        Closed surface (for Kerr, a closed shell of two walls touching on the axis) with normals
        pointing out of the region; point data ``r`` float64 (Boyer–Lindquist radius).

    Raises
    ------
    ValueError
        The metric has no photon orbits.

    Examples
    --------
    >>> import warpviz as wv
    >>> kerr = wv.Kerr(mass=1.0, spin=0.9)
    >>> shell = photon_sphere(kerr)
    >>> r = shell.point_data["r"]
    >>> bool(abs(r.min() - kerr.photon_orbit_radii[0]) < 1e-12), bool(abs(r.max() - kerr.photon_orbit_radii[1]) < 1e-12)
    (True, True)
    """
    resolution = _check_resolution(resolution)
    marks = metric.landmarks
    if "photon_sphere" in marks:
        theta = _theta(resolution)
        return _kerr_schild_surface(np.full_like(theta, marks["photon_sphere"]), theta, marks.get("spin", 0.0),
                                    resolution)  # fmt: skip
    if "photon_prograde" not in marks:
        raise ValueError(f"{metric!r} has no photon sphere")
    m, a = marks["mass"], marks["spin"]
    pro, retro, polar = marks["photon_prograde"], marks["photon_retrograde"], marks["photon_polar"]
    # sin² spacing: the wall leaves the equator like sqrt(r - r_orbit), so this samples it evenly
    t = np.sin(np.linspace(0.0, 0.5 * math.pi, max(resolution // 4, 2) + 1)) ** 2
    r_up = np.concatenate([pro + (polar - pro) * t, polar + (retro - polar) * t[1:]])
    cos2 = _kerr_photon_region_cos2(m, a, r_up)
    cos2[0] = cos2[-1] = 0.0
    cos2[t.shape[0] - 1] = 1.0  # the polar orbit reaches the axis
    # meridian loop: inner wall up from the equator to the north pole, outer wall down to the
    # equator, on to the south pole and back up the inner wall
    r_loop = np.concatenate([r_up, r_up[-2:0:-1]])
    cos_loop = np.concatenate([np.sqrt(cos2), -np.sqrt(cos2[-2:0:-1])])
    rho = np.sqrt((r_loop**2 + a * a) * (1.0 - cos_loop**2))
    rho[np.abs(cos_loop) == 1.0] = 0.0
    z = r_loop * cos_loop
    return _revolve(rho, z, n_phi=resolution, closed=True).polydata(r=_per_point(r_loop, rho, resolution))


def throat_surface(metric: Metric, *, resolution: int = 64) -> pv.PolyData:
    """The throat of a wormhole: the sphere of areal radius b₀ where the two sheets meet.

    Parameters
    ----------
    metric : Metric
        A wormhole (its landmarks have a ``throat``).
    resolution : int, keyword-only
        Points around the equator; the meridian has ``resolution // 2 + 1`` points.

    Returns
    -------
    pyvista.PolyData
        Closed sphere of radius b₀, outward normals; point data ``r`` float64 (= b₀).

    Examples
    --------
    >>> import warpviz as wv
    >>> throat_surface(wv.EllisWormhole(throat=2.0)).bounds[1]
    2.0
    """
    resolution = _check_resolution(resolution)
    if "throat" not in metric.landmarks:
        raise ValueError(f"{metric!r} has no throat (only a wormhole does)")
    theta = _theta(resolution)
    return _kerr_schild_surface(np.full_like(theta, metric.landmarks["throat"]), theta, 0.0, resolution)


def metric_features(metric: Metric, *, resolution: int = 64) -> dict[str, pv.PolyData]:
    """Every landmark surface the metric has, by block name.

    Schwarzschild: ``horizon``, ``photon_sphere``. Kerr: ``horizon``, ``ergosphere`` (when spinning),
    ``photon_sphere`` (the photon region). A wormhole: ``throat`` and, when static and spherical (Ellis), ``embedding``. Minkowski: none.

    Parameters
    ----------
    metric : Metric
    resolution : int, keyword-only
        Passed to each surface.

    Returns
    -------
    dict[str, pyvista.PolyData]

    Examples
    --------
    >>> import warpviz as wv
    >>> list(metric_features(wv.Schwarzschild(mass=1.0)))
    ['horizon', 'photon_sphere']
    """
    marks = metric.landmarks  # from the core's registry: what this spacetime has
    features = {}
    if "horizon" in marks:
        features["horizon"] = horizon_surface(metric, resolution=resolution)
    if "ergosphere" in marks:
        features["ergosphere"] = ergosphere_surface(metric, resolution=resolution)
    if "photon_sphere" in marks or "photon_prograde" in marks:
        features["photon_sphere"] = photon_sphere(metric, resolution=resolution)
    if "throat" in marks:
        features["throat"] = throat_surface(metric, resolution=resolution)
    if has_embedding(metric):  # a static spherical wormhole (its lens functions give the diagram)
        features["embedding"] = wormhole_embedding(metric, resolution=resolution)
    return features
