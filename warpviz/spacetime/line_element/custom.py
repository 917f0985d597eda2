"""A metric from its line element as a registered metric: its definition checked, parsed, generated,
compiled and loaded into the core's registry (:func:`load_definition`); ``wv.Metric.from_line_element``
(``spacetime/metrics.py``) gives it a Python class like every built-in metric's.

The registry name is the given name and a hash of the definition (``"custom_3f9a0c12"``), so two different
line elements never share a name and the same one always gets the same name, plugin and class.

Examples
--------
>>> import warpviz as wv
>>> m = wv.Metric.from_line_element(
...     "-dt**2 + dx**2 + dy**2 + dz**2 + 2*M/r*(dt + (x*dx + y*dy + z*dz)/r)**2",
...     parameters={"M": 1.0}, horizon_radius="2*M", photon_sphere_radius="3*M", mass="M", name="ks_schwarzschild")
>>> m.name.startswith("ks_schwarzschild_"), m.landmarks["capture"]
(True, 2.5)
"""

from __future__ import annotations

import functools
import hashlib
import json
import os
import threading
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import numpy as np
import sympy

from warpviz.spacetime.line_element import plugin
from warpviz.spacetime.line_element.codegen import LANDMARKS, metric_source
from warpviz.spacetime.line_element.grammar import ExpressionError, parse_expression
from warpviz.spacetime.line_element.tensor import LineElement, LineElementError

__all__ = ["LineElementDefinition", "ensure_renderer", "line_element_definition", "load_definition"]

_LOCK = threading.Lock()


class LineElementDefinition(dict):
    """What defines a metric from its line element, as plain data (it travels to Dask workers and into
    scene files): ``line_element``, ``coordinates``, ``parameters`` (name → default value), ``definitions``
    (name → expression), ``landmarks`` (name → expression of the parameters) and ``name``."""

    @property
    def digest(self) -> str:
        text = json.dumps({k: self[k] for k in sorted(self) if k != "name"}, sort_keys=True)
        return hashlib.sha256(text.encode()).hexdigest()[:10]

    @property
    def registry_name(self) -> str:
        return f"{self['name']}_{self.digest}"


def _definition(line_element: str, coordinates: str, parameters: Mapping[str, float],
                definitions: Mapping[str, str] | None, landmarks: Mapping[str, str], name: str) -> LineElementDefinition:  # fmt: skip
    if not isinstance(line_element, str):
        raise LineElementError("line_element", f"must be a string, got {type(line_element).__name__}")
    if not isinstance(parameters, Mapping):
        raise LineElementError("parameters", "must map each parameter name to its value, e.g. {'M': 1.0}")
    values = {}
    for k, v in parameters.items():
        if isinstance(v, bool) or not isinstance(v, (int, float)) or v != v or v in (float("inf"), float("-inf")):
            raise LineElementError(f"parameters.{k}", f"must be a finite number, got {v!r}")
        values[str(k)] = float(v)
    for k, v in landmarks.items():
        if k not in LANDMARKS:
            raise LineElementError(k, f"is not a landmark; landmarks are {', '.join(LANDMARKS)}")
        if not isinstance(v, str):
            raise LineElementError(k, f"must be an expression of the parameters (a string), got {v!r}")
    if not isinstance(name, str) or not name.replace("_", "").isalnum() or not name[:1].isalpha() or len(name) > 40:
        raise LineElementError("name", f"must be letters, digits and _, starting with a letter, got {name!r}")
    return LineElementDefinition(line_element=line_element, coordinates=coordinates, parameters=values,
                                 definitions=dict(definitions or {}), landmarks=dict(landmarks), name=name)  # fmt: skip


def _landmark_exprs(le: LineElement, landmarks: Mapping[str, str], values: Mapping[str, float]) -> dict:
    """Each landmark parsed over the parameters only, and checked to be a real radius >= 0 at ``values``."""
    names = {p.name: p for p in le.params}
    out = {}
    for key, text in landmarks.items():
        try:
            expr = parse_expression(text, names)
        except ExpressionError as exc:
            raise LineElementError(key, exc.reason + " (a landmark is an expression of the parameters only)",
                                   exc.column) from None  # fmt: skip
        value = complex(expr.subs({names[k]: v for k, v in values.items() if k in names}).evalf())
        if abs(value.imag) > 0 or not value.real >= 0:
            raise LineElementError(key, f"is {value.real if not value.imag else value} at the parameters' values; "
                                   "a landmark radius is a real number >= 0")  # fmt: skip
        out[key] = expr
    return out


def _crosses_horizon(le: LineElement, horizon: sympy.Basic | None, values: Mapping[str, float]) -> bool:
    """Whether the chart is regular at the horizon: g stays finite and of the size it has at 1.5 × the
    horizon radius, 1e-6 of the radius on either side of it, in six directions (a Kerr–Schild chart is;
    a static one, with g_rr = 1/f, grows a millionfold)."""
    if horizon is None:
        return True
    r_h = float(horizon.subs({p: values[p.name] for p in le.params}))
    if not r_h > 0:
        return True
    for n in ((1, 0, 0), (0, 1, 0), (0, 0, 1), (-1, 0, 0), (0.6, 0, -0.8), (0, -0.8, 0.6)):
        n = np.asarray(n, dtype=float)
        with np.errstate(all="ignore"):
            try:
                far = np.abs(le.metric_at([0.0, *(1.5 * r_h * n)], values)).max()
                near = max(np.abs(le.metric_at([0.0, *(f * r_h * n)], values)).max() for f in (1 - 1e-6, 1 + 1e-6))
            except (ZeroDivisionError, ValueError, OverflowError):
                return False
        if not np.isfinite(near) or near > 1e3 * far:
            return False
    return True


def line_element_definition(line_element: str, *, coordinates: str = "cartesian",
                            parameters: Mapping[str, float] | None = None,
                            definitions: Mapping[str, str] | None = None, name: str = "custom",
                            **landmarks: str) -> LineElementDefinition:  # fmt: skip
    """The checked definition of a metric from its line element (what ``wv.Metric.from_line_element`` takes).

    Raises
    ------
    LineElementError
        A bad parameter value, landmark key or name (the expressions are checked by :func:`load_definition`).
    """
    return _definition(line_element, coordinates, parameters or {}, definitions, landmarks, name)


def load_definition(definition: Mapping[str, Any], *, progress: Callable[[str], None] | None = None) -> str:
    """Parses, generates, compiles (first use) and loads the plugin of ``definition``; returns the C++ source.
    The metric is then registered under ``definition.registry_name``.

    Raises
    ------
    LineElementError
        A bad line element, definition or landmark, naming which and the column, before any compilation.
    warpviz.spacetime.line_element.plugin.CompilerNotFoundError
        No C++ compiler, saying what to install.
    """
    definition = LineElementDefinition(definition)
    key = definition.registry_name
    cached = plugin.cache_dir() / "sources" / f"{key}-{_generator_digest()}.cpp"
    if cached.is_file():  # generated before by this warpviz: the algebra (seconds for Kerr) is skipped
        source = cached.read_text()
    else:
        values = definition["parameters"]
        wormhole = definition["coordinates"] == "wormhole"
        le = LineElement(definition["line_element"], coordinates=definition["coordinates"],
                         parameters=list(values), definitions=definition["definitions"],
                         throat=definition["landmarks"].get("throat_radius") if wormhole else None)  # fmt: skip
        exprs = _landmark_exprs(le, definition["landmarks"], values)
        if wormhole and (why := le.wormhole_problem(values)):
            raise LineElementError("line_element", why)
        source = metric_source(le, name=key, values=values, landmarks=exprs,
                               crosses_horizon=_crosses_horizon(le, exprs.get("horizon_radius"), values),
                               summary=f"{definition['name']}: {' '.join(definition['line_element'].split())}"[:200])  # fmt: skip
    with _LOCK:
        plugin.load_parts(source, ["facts", "dopri5"], progress=progress)
    if not cached.is_file():  # kept once it compiled, written whole (safe to share)
        cached.parent.mkdir(parents=True, exist_ok=True)
        tmp = cached.with_suffix(f".{os.getpid()}.tmp")
        tmp.write_text(source)
        os.replace(tmp, cached)
    return source


@functools.lru_cache(maxsize=1)
def _generator_digest() -> str:
    """What decides a definition's generated source besides the definition: this package's generator
    modules and sympy's version."""
    h = hashlib.sha256(sympy.__version__.encode())
    for module in ("grammar.py", "tensor.py", "codegen.py", "custom.py"):
        h.update((Path(__file__).parent / module).read_bytes())
    return h.hexdigest()[:12]


def ensure_renderer(source: str, stepper: str, progress: Callable[[str], None] | None = None) -> None:
    """Compiles and loads the renderer part of a plugin for ``stepper`` if the registry lacks it."""
    with _LOCK:
        plugin.load_parts(source, [stepper], progress=progress)
