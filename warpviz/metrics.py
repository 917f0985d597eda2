"""Spacetimes: validated metric parameters with their closed-form landmarks.

Each class mirrors one C++ metric file in ``renderer_ext/spacetime/`` and only carries parameters;
the geometry lives in C++. Units are geometric (G = c = 1), lengths in units of the mass M.

Examples
--------
>>> import warpviz as wv
>>> round(wv.Kerr(mass=1.0, spin=0.9).horizon_radius, 12)
1.435889894354
>>> wv.Schwarzschild(mass=2.0).photon_sphere_radius
6.0
"""

from __future__ import annotations

import math
import numbers
from typing import Any, ClassVar

from warpviz._native import registered_metrics


def _real(cls: str, key: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"{cls}: {key} must be a real number, got {type(value).__name__} {value!r}")
    value = float(value)
    if not math.isfinite(value):
        raise ValueError(f"{cls}: {key} must be finite, got {value}")
    return value


def _positive(cls: str, key: str, value: Any) -> float:
    value = _real(cls, key, value)
    if value <= 0.0:
        raise ValueError(f"{cls}: {key} must be > 0, got {value}")
    return value


class Metric:
    """Base class of the spacetimes. Instances are immutable and compare by value.

    Attributes
    ----------
    name : str
        Registry name of the C++ metric (``"kerr"``, ...).
    params : dict[str, float]
        Parameters in the order the C++ constructor takes them.
    """

    name: ClassVar[str] = ""
    _param_names: ClassVar[tuple[str, ...]] = ()

    def __setattr__(self, key, value):
        raise AttributeError(f"{type(self).__name__} is immutable")

    def _set(self, **values: float) -> None:
        for k, v in values.items():
            object.__setattr__(self, k, v)

    @property
    def params(self) -> dict[str, float]:
        return {k: getattr(self, k) for k in self._param_names}

    @property
    def param_values(self) -> list[float]:
        return [getattr(self, k) for k in self._param_names]

    @property
    def invariant_names(self) -> list[str]:
        """Conserved quantities monitored along rays; the first is always ``"H"``."""
        for entry in registered_metrics():
            if entry["name"] == self.name:
                return list(entry["invariants"])
        raise RuntimeError(f"metric {self.name!r} is not compiled into the core")  # pragma: no cover

    @property
    def horizon_radius(self) -> float:
        """Radius of the outer event horizon (0 if there is none)."""
        return 0.0

    @property
    def is_flat(self) -> bool:
        return False

    def to_dict(self) -> dict[str, Any]:
        """``{"name": ..., **params}``, the form scene files and VTK field data use."""
        return {"name": self.name, **self.params}

    def __eq__(self, other: object) -> bool:
        return type(other) is type(self) and other.params == self.params

    def __hash__(self) -> int:
        return hash((self.name, tuple(self.param_values)))

    def __repr__(self) -> str:
        args = ", ".join(f"{k}={v!r}" for k, v in self.params.items())
        return f"{type(self).__name__}({args})"


class Minkowski(Metric):
    """Flat spacetime. Rays are straight lines, traced analytically with zero integration steps."""

    name = "minkowski"

    @property
    def is_flat(self) -> bool:
        return True


class Schwarzschild(Metric):
    """Non-rotating black hole of mass ``mass`` (Cartesian Kerr–Schild coordinates).

    Parameters
    ----------
    mass : float
        M > 0. Horizon at r = 2M, photon sphere at r = 3M.
    """

    name = "schwarzschild"
    _param_names = ("mass",)

    def __init__(self, *, mass: float = 1.0):
        self._set(mass=_positive("Schwarzschild", "mass", mass))

    @property
    def horizon_radius(self) -> float:
        return 2.0 * self.mass

    @property
    def photon_sphere_radius(self) -> float:
        return 3.0 * self.mass

    @property
    def critical_impact_parameter(self) -> float:
        """b_c = 3√3 M: rays with smaller impact parameter fall in."""
        return 3.0 * math.sqrt(3.0) * self.mass

    def shadow_angle(self, r: float) -> float:
        """Angular radius (rad) of the shadow seen by a static observer at areal radius ``r`` > 2M."""
        r = _real("Schwarzschild.shadow_angle", "r", r)
        if r <= self.horizon_radius:
            raise ValueError(f"Schwarzschild.shadow_angle: r must exceed the horizon 2M = {self.horizon_radius}")
        s = self.critical_impact_parameter / r * math.sqrt(1.0 - 2.0 * self.mass / r)
        theta = math.asin(min(1.0, s))
        return theta if r >= self.photon_sphere_radius else math.pi - theta


class Kerr(Metric):
    """Rotating black hole (Cartesian Kerr–Schild coordinates, spin along +z).

    Parameters
    ----------
    mass : float
        M > 0.
    spin : float
        Dimensionless spin a/M with \\|spin\\| < 1; negative spins rotate about -z.
    """

    name = "kerr"
    _param_names = ("mass", "spin")

    def __init__(self, *, mass: float = 1.0, spin: float = 0.0):
        mass = _positive("Kerr", "mass", mass)
        spin = _real("Kerr", "spin", spin)
        if not abs(spin) < 1.0:
            raise ValueError(
                f"Kerr: spin must satisfy |spin| < 1, got {spin} (|a/M| >= 1 has no horizon: a naked singularity)"
            )
        self._set(mass=mass, spin=spin)

    @property
    def a(self) -> float:
        """Spin parameter a = spin · M (a length)."""
        return self.spin * self.mass

    @property
    def horizon_radius(self) -> float:
        """Outer horizon r+ = M + √(M² − a²) (Boyer–Lindquist r)."""
        return self.mass + math.sqrt((self.mass - self.a) * (self.mass + self.a))

    def ergosphere_radius(self, theta: float) -> float:
        """Outer ergosurface r = M + √(M² − a² cos²θ) at polar angle ``theta``."""
        return self.mass + math.sqrt(self.mass**2 - (self.a * math.cos(theta)) ** 2)

    @property
    def photon_orbit_radii(self) -> tuple[float, float]:
        """Equatorial circular photon orbits (prograde, retrograde), Boyer–Lindquist r."""
        m, chi = self.mass, abs(self.spin)
        pro = 2 * m * (1 + math.cos(2.0 / 3.0 * math.acos(-chi)))
        retro = 2 * m * (1 + math.cos(2.0 / 3.0 * math.acos(chi)))
        return pro, retro


class EllisWormhole(Metric):
    """Ellis wormhole ds² = −dt² + dl² + (b₀² + l²) dΩ² joining two asymptotically flat sheets.

    Positions are given per sheet (``sheet`` +1 ours, −1 the other) as Cartesian vectors whose length
    is the areal radius √(b₀² + l²) ≥ b₀.

    Parameters
    ----------
    throat : float
        Throat radius b₀ > 0.
    """

    name = "ellis"
    _param_names = ("throat",)

    def __init__(self, *, throat: float = 1.0):
        self._set(throat=_positive("EllisWormhole", "throat", throat))


_CLASSES: dict[str, type[Metric]] = {c.name: c for c in (Minkowski, Schwarzschild, Kerr, EllisWormhole)}


def metric_from_dict(spec: dict[str, Any]) -> Metric:
    """Build a metric from ``{"name": ..., **params}`` (the inverse of :meth:`Metric.to_dict`).

    Raises
    ------
    ValueError
        Unknown name or parameter, naming the known ones.
    """
    spec = dict(spec)
    name = spec.pop("name", None)
    if name not in _CLASSES:
        raise ValueError(f"unknown metric {name!r}; known metrics: {', '.join(sorted(_CLASSES))}")
    cls = _CLASSES[name]
    unknown = set(spec) - set(cls._param_names)
    if unknown:
        raise ValueError(
            f"{cls.__name__}: unknown parameter(s) {sorted(unknown)}; parameters are {list(cls._param_names)}"
        )
    return cls(**spec)
