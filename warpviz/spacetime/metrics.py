"""Spacetimes: validated metric parameters with their closed-form landmarks.

Each class mirrors one C++ metric file in ``renderer_ext/metrics/`` and only carries parameters;
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

import copy
import inspect
import math
import numbers
import threading
import warnings
from typing import Any, ClassVar

from warpviz._native import core, registered_metrics


def _real(cls: str, key: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"{cls}: {key} must be a real number, got {type(value).__name__} {value!r}")
    value = float(value)
    if not math.isfinite(value):
        raise ValueError(f"{cls}: {key} must be finite, got {value}")
    return value


def _range_text(spec: dict) -> str:
    """The allowed range of a parameter spec in words: ``> 0``, ``|spin| < 1``, ``in [0, 2)``."""
    lo, hi = spec["lo"], spec["hi"]
    lo_op, hi_op = (">" if spec["lo_open"] else ">="), ("<" if spec["hi_open"] else "<=")
    if math.isinf(hi):
        return f"{lo_op} {lo:g}"
    if math.isinf(lo):
        return f"{hi_op} {hi:g}"
    if lo == -hi and spec["lo_open"] == spec["hi_open"]:
        return f"|{spec['name']}| {hi_op} {hi:g}"
    return f"in {'(' if spec['lo_open'] else '['}{lo:g}, {hi:g}{')' if spec['hi_open'] else ']'}"


def _in_range(spec: dict, value: float) -> bool:
    above = value > spec["lo"] if spec["lo_open"] else value >= spec["lo"]
    below = value < spec["hi"] if spec["hi_open"] else value <= spec["hi"]
    return above and below


def _check_param(cls: str, spec: dict, value: Any) -> float:
    """``value`` as a float if it is allowed for ``spec`` (a registry parameter spec), else a clear error."""
    value = _real(cls, spec["name"], value)
    if not _in_range(spec, value):
        rule = _range_text(spec)
        if rule.startswith("|"):
            raise ValueError(f"{cls}: {spec['name']} must satisfy {rule}, got {value} ({spec['doc']})")
        raise ValueError(f"{cls}: {spec['name']} must be {rule}, got {value} ({spec['doc']})")
    return value


#: The core's registry, read once, and extended when a metric from its line element is loaded.
_REGISTRY: dict[str, dict] = {e["name"]: e for e in registered_metrics()}


def _entry(name: str) -> dict:
    if name not in _REGISTRY:
        raise RuntimeError(f"metric {name!r} is not compiled into the core")  # pragma: no cover
    return _REGISTRY[name]


class PerformanceWarning(UserWarning):
    """A metric that runs much slower than it could (no hand-written right-hand side)."""


_WARNED_SLOW: set[str] = set()


class Metric:
    """Base class of the spacetimes, built from the core's registry. Instances are immutable values.

    Every metric compiled into the core (``renderer_ext/metrics/``) has a class: a hand-written subclass
    where it adds closed-form helpers (:class:`Schwarzschild`, :class:`Kerr`, ...), otherwise one made
    from the registry entry (``wv.ReissnerNordstrom``). Parameters are keyword-only; their names, ranges
    and defaults are the registry's (``registered_metrics()[i]["param_specs"]``), and a relation between
    them (such as ``|Q| < M``) is checked by the core.

    Attributes
    ----------
    name : str
        Registry name of the C++ metric (``"kerr"``, ...).
    params : dict[str, float]
        Parameters in the order the C++ constructor takes them.
    """

    name: ClassVar[str] = ""
    _param_names: ClassVar[tuple[str, ...]] = ()
    _specs: ClassVar[tuple[dict, ...]] = ()

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        if cls.name:
            entry = _entry(cls.name)
            cls._specs = tuple(dict(s) for s in entry["param_specs"])
            cls._param_names = tuple(s["name"] for s in cls._specs)
            if "__init__" not in cls.__dict__:  # a signature that names the registry's parameters

                def __init__(self, **params: float) -> None:
                    Metric.__init__(self, **params)

                kw = [inspect.Parameter(s["name"], inspect.Parameter.KEYWORD_ONLY, default=s["default"], annotation=float)
                      for s in cls._specs]  # fmt: skip
                __init__.__signature__ = inspect.Signature(
                    [inspect.Parameter("self", inspect.Parameter.POSITIONAL_ONLY), *kw])
                __init__.__doc__ = f"{cls.__name__}: {entry['summary']}."
                cls.__init__ = __init__

    def __init__(self, **params: float):
        cls = type(self).__name__
        unknown = set(params) - set(self._param_names)
        if unknown:
            raise TypeError(f"{cls}: unknown parameter(s) {sorted(unknown)}; parameters are {list(self._param_names)}")
        values = {s["name"]: _check_param(cls, s, params.get(s["name"], s["default"])) for s in self._specs}
        problem = core.params_problem(self.name, list(values.values()))
        if problem:
            raise ValueError(f"{cls}: {problem.split(': ', 1)[-1]}")
        for k, v in values.items():
            object.__setattr__(self, k, v)
        entry = _entry(self.name)
        if not entry["lane_rhs"] and not entry["flat"] and self.name not in _WARNED_SLOW:
            _WARNED_SLOW.add(self.name)
            warnings.warn(f"metric {self.name!r} has no hand-written right-hand side: its geodesics are "
                          "differentiated automatically and cannot step in SIMD lanes (~6x slower); "
                          "see docs/adding-a-metric.md", PerformanceWarning, stacklevel=2)  # fmt: skip

    @classmethod
    def example(cls) -> "Metric":
        """An instance with the registry's example parameters: a strong-field case (Kerr spin 0.9, ...)
        that the contract tests and the docs use."""
        return cls(**{s["name"]: s["example"] for s in cls._specs})

    def __setattr__(self, key, value):
        raise AttributeError(f"{type(self).__name__} is immutable")

    @property
    def params(self) -> dict[str, float]:
        return {k: getattr(self, k) for k in self._param_names}

    @property
    def param_values(self) -> list[float]:
        return [getattr(self, k) for k in self._param_names]

    @property
    def registry_entry(self) -> dict:
        """The core's facts about this metric (name, class name, summary, parameter specs, invariants,
        sheets, flatness, whether a hand-written right-hand side runs in SIMD lanes); a copy."""
        return copy.deepcopy(_entry(self.name))

    @property
    def invariant_names(self) -> list[str]:
        """Conserved quantities monitored along rays; the first is always ``"H"``."""
        return list(_entry(self.name)["invariants"])

    @property
    def landmarks(self) -> dict[str, float]:
        """Landmark radii from the core, only those the spacetime has (``renderer_ext/spacetime/landmarks.h``).

        Keys among ``horizon``, ``inner_horizon``, ``capture`` (where backward camera rays are captured),
        ``photon_sphere``, ``photon_prograde`` / ``photon_retrograde`` / ``photon_polar`` (a rotating
        hole's photon region), ``ergosphere`` (its equatorial radius), ``throat``, ``mass`` (length scale)
        and ``spin`` (a, a length). Radii are the metric's radial coordinate (areal, or Boyer–Lindquist).
        """
        cached = self.__dict__.get("_landmarks")
        if cached is None:
            raw = core.landmarks(self.name, self.param_values)
            cached = {k: float(v) for k, v in dict(raw).items() if v != 0.0}
            object.__setattr__(self, "_landmarks", cached)
        return dict(cached)

    @property
    def spherical_lens(self) -> dict[str, Any] | None:
        """A static spherical metric's lens functions from the core (``renderer_ext/spacetime/lens_map.h``),
        ``None`` for the others.

        ds² = −A dt² + dR² / (A h) + R² dΩ² in the areal radius R, with ``a`` and ``h`` the coefficients of
        A(u) and h(u) in u = 1 / R (constant first), ``u_inner`` 1 / R of the innermost sphere rays
        approach (photon sphere or throat) and ``throat`` whether that is a wormhole's throat. They draw a
        wormhole's embedding diagram (:func:`warpviz.wormhole_embedding`); a copy.
        """
        if "_lens" not in self.__dict__:
            object.__setattr__(self, "_lens", core.spherical_lens(self.name, self.param_values))
        return copy.deepcopy(self.__dict__["_lens"])

    @property
    def horizon_radius(self) -> float:
        """Radius of the outer event horizon (0 if there is none)."""
        return self.landmarks.get("horizon", 0.0)

    @property
    def is_flat(self) -> bool:
        return bool(_entry(self.name)["flat"])

    @property
    def is_static(self) -> bool:
        """Flat, or static and spherically symmetric: light's spatial path is the same traced forward or
        backward in time, and the exact lens map reaches a point (what point and spot lights need)."""
        entry = _entry(self.name)
        return bool(entry["flat"] or entry["static_spherical"])

    @property
    def sheets(self) -> int:
        """Sheets the user sees as separate Cartesian frames (2 for a wormhole)."""
        return int(_entry(self.name)["sheets"])

    def to_dict(self) -> dict[str, Any]:
        """``{"name": ..., **params}``, the form scene files and VTK field data use."""
        return {"name": self.name, **self.params}

    def prepare(self, *, stepper: str) -> None:
        """Makes sure the core can render this metric with ``stepper`` (a built-in metric always can; a
        metric from its line element compiles that renderer on first use)."""

    @classmethod
    def from_line_element(cls, line_element: str, *, coordinates: str = "cartesian",
                          parameters: dict[str, float] | None = None, definitions: dict[str, str] | None = None,
                          name: str = "custom", progress=None, **landmarks: str) -> "Metric":  # fmt: skip
        """A metric from its line element, compiled into the core on first use (cached afterwards).

        Parameters
        ----------
        line_element : str
            ds², e.g. ``"-(1 - 2*M/r)*dt**2 + dr**2/(1 - 2*M/r) + r**2*dOmega**2"``: numbers, the coordinates
            and parameters, ``+ - * / **``, ``sqrt exp log sin cos tan sinh cosh tanh asin acos atan atan2
            abs``. Never evaluated as Python.
        coordinates : {"cartesian", "spherical"}, keyword-only
            ``t x y z`` (with the helper ``r``) or ``t r theta phi`` (with ``dOmega``), transformed to
            Cartesian coordinates so that the poles are regular.
        parameters : dict of str to float, optional, keyword-only
            Each parameter's name and value (the class's defaults).
        definitions : dict of str to str, optional, keyword-only
            Named helper expressions, in order (``{"f": "1 - 2*M/r"}``).
        name : str, keyword-only
            The metric's name; its registry name adds a hash of the definition.
        progress : callable, optional, keyword-only
            Told, one line at a time, when the metric is compiled.
        **landmarks : str
            ``horizon_radius``, ``inner_horizon_radius``, ``capture_radius``, ``photon_sphere_radius``,
            ``throat_radius``, ``mass`` (the length scale): expressions of the parameters. A black hole needs
            ``horizon_radius``; rays that fall in are captured at ``capture_radius``, by default halfway from
            the horizon to the photon sphere, or 1.1 × the horizon without one.

        Returns
        -------
        Metric

        Examples
        --------
        >>> import warpviz as wv
        >>> rn = wv.Metric.from_line_element(
        ...     "-f*dt**2 + dr**2/f + r**2*dOmega**2", coordinates="spherical",
        ...     definitions={"f": "1 - 2*M/r + Q**2/r**2"}, parameters={"M": 1.0, "Q": 0.8},
        ...     horizon_radius="M + sqrt(M**2 - Q**2)", inner_horizon_radius="M - sqrt(M**2 - Q**2)",
        ...     photon_sphere_radius="(3*M + sqrt(9*M**2 - 8*Q**2))/2", mass="M", name="static_charged")
        >>> rn, round(rn.horizon_radius, 12), rn.invariant_names
        (StaticCharged(M=1.0, Q=0.8), 1.6, ['H', 'E', 'Lz'])
        """
        from warpviz.spacetime.line_element.custom import line_element_definition

        definition = line_element_definition(line_element, coordinates=coordinates, parameters=parameters,
                                             definitions=definitions, name=name, **landmarks)  # fmt: skip
        return line_element_class(definition, progress=progress)(**definition["parameters"])

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


class Schwarzschild(Metric):
    """Non-rotating black hole of mass ``mass`` (Cartesian Kerr–Schild coordinates).

    Parameters
    ----------
    mass : float
        M > 0. Horizon at r = 2M, photon sphere at r = 3M.
    """

    name = "schwarzschild"

    @property
    def photon_sphere_radius(self) -> float:
        return self.landmarks["photon_sphere"]

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

    @property
    def a(self) -> float:
        """Spin parameter a = spin · M (a length)."""
        return self.spin * self.mass

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


def _generated_class(entry: dict) -> type[Metric]:
    """A Metric class for a registry entry that has no hand-written one (a new metric file needs no Python)."""
    specs = "\n".join(f"    {s['name']} : float, default {s['default']:g}\n        {s['doc']}." for s in entry["param_specs"])
    relation = f"\n\n    The parameters must satisfy {entry['param_relation']}." if entry["param_relation"] else ""
    doc = f"{entry['summary']}.{relation}\n\n    Parameters\n    ----------\n{specs}\n" if specs else f"{entry['summary']}."
    return type(entry["class_name"], (Metric,), {"name": entry["name"], "__doc__": doc, "__module__": __name__})


class LineElementMetric(Metric):
    """Base of the classes of metrics given by their line element (:meth:`Metric.from_line_element`).

    Attributes
    ----------
    definition : dict
        What defines the metric (``line_element``, ``coordinates``, ``parameters``, ``definitions``,
        ``landmarks``, ``name``): plain data, from which any process rebuilds the class.
    """

    definition: ClassVar[dict] = {}
    _source: ClassVar[str] = ""

    def prepare(self, *, stepper: str) -> None:
        if not core.has_stepper(self.name, stepper, True):
            from warpviz.spacetime.line_element.custom import ensure_renderer

            ensure_renderer(self._source, stepper)

    def to_dict(self) -> dict[str, Any]:
        """The form of a scene file's ``[metric]`` table, with this instance's parameter values:
        ``{"name": "custom", "label": ..., "line_element": ..., "coordinates": ..., "parameters": {...},
        "definitions": {...}, <landmark>: ...}`` (:func:`metric_from_dict` reads it back)."""
        d = copy.deepcopy(dict(self.definition))
        return {"name": "custom", "label": d["name"], "line_element": d["line_element"],
                "coordinates": d["coordinates"], "parameters": self.params, "definitions": d["definitions"],
                **d["landmarks"]}  # fmt: skip

    def __reduce__(self):  # another process (a Dask worker) rebuilds the class from the definition
        return (_line_element_metric, (dict(self.definition), self.params))


def _line_element_metric(definition: dict, params: dict) -> Metric:
    return line_element_class(definition)(**params)


_LINE_ELEMENT_LOCK = threading.Lock()


def line_element_class(definition: dict, *, progress=None) -> type[LineElementMetric]:
    """The class of the metric a line-element definition describes (``line_element/custom.py``), its plugin
    compiled (first use) and loaded into the core, made from its registry entry as for a metric file without
    a class of its own. The same definition always gives the same class."""
    from warpviz.spacetime.line_element.custom import LineElementDefinition, load_definition

    definition = LineElementDefinition(definition)
    name = definition.registry_name
    with _LINE_ELEMENT_LOCK:
        if name in _CLASSES:
            return _CLASSES[name]
        source = load_definition(definition, progress=progress)
        entry = next(e for e in registered_metrics() if e["name"] == name)
        _REGISTRY[name] = entry
        doc = f"{entry['summary']}.\n\n    A metric from its line element (:meth:`Metric.from_line_element`)."
        cls_name = "".join(part[:1].upper() + part[1:] for part in definition["name"].split("_"))
        cls = type(cls_name, (LineElementMetric,), {"name": name, "__doc__": doc, "__module__": __name__,
                                                    "definition": dict(definition), "_source": source})  # fmt: skip
        _CLASSES[name] = cls
        return cls


_HAND_WRITTEN = (Minkowski, Schwarzschild, Kerr, EllisWormhole)

#: Every metric compiled into the core, by registry name, in registration order.
_CLASSES: dict[str, type[Metric]] = {}
for _e in _REGISTRY.values():
    _CLASSES[_e["name"]] = next((c for c in _HAND_WRITTEN if c.name == _e["name"]), None) or _generated_class(_e)
del _e

#: The same classes by Python class name (``"Kerr"``, ``"ReissnerNordstrom"``), exported by ``warpviz``.
METRIC_CLASSES: dict[str, type[Metric]] = {c.__name__: c for c in _CLASSES.values()}


def metric_names(*, sheets: int | None = None) -> list[str]:
    """Registry names of every metric compiled into the core, in registration order; with ``sheets``, only
    those whose spacetime has that many sheets (2: the wormholes)."""
    return [n for n in _CLASSES if sheets is None or _REGISTRY[n]["sheets"] == sheets]


def metric_class(name: str) -> type[Metric]:
    """The Metric class of registry name ``name``.

    Raises
    ------
    ValueError
        Unknown name, naming the known ones.
    """
    if name not in _CLASSES:
        raise ValueError(f"unknown metric {name!r}; known metrics: {', '.join(sorted(_CLASSES))}")
    return _CLASSES[name]


def metric_from_params(name: str, values) -> Metric:
    """Build a metric from its registry name and parameter values in registry order (the native form
    ``{"name", "params": [...]}`` of scenes and VTK field data).

    Raises
    ------
    ValueError
        Unknown name, a wrong number of values, or invalid values.
    """
    cls = metric_class(name)
    values = list(values)
    if len(values) != len(cls._param_names):
        raise ValueError(f"{cls.__name__} takes {len(cls._param_names)} parameter(s) {list(cls._param_names)}, "
                         f"got {len(values)}")  # fmt: skip
    return cls(**dict(zip(cls._param_names, values)))


def metric_from_dict(spec: dict[str, Any]) -> Metric:
    """Build a metric from ``{"name": ..., **params}`` (the inverse of :meth:`Metric.to_dict`).

    Raises
    ------
    ValueError
        Unknown name or parameter, naming the known ones.
    """
    spec = dict(spec)
    if spec.get("name") == "custom":  # a metric from its line element (LineElementMetric.to_dict)
        spec.pop("name")
        return Metric.from_line_element(spec.pop("line_element", None), name=spec.pop("label", "custom"), **spec)
    cls = metric_class(spec.pop("name", None))
    unknown = set(spec) - set(cls._param_names)
    if unknown:
        raise ValueError(
            f"{cls.__name__}: unknown parameter(s) {sorted(unknown)}; parameters are {list(cls._param_names)}"
        )
    return cls(**spec)
