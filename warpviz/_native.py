"""The one place that imports the compiled extension ``warpviz._core``.

Everything else in the package goes through :data:`core`, so a missing or broken build fails here
with one clear message instead of deep inside a call.
"""

from __future__ import annotations

try:
    from warpviz import _core as core
except ImportError as exc:  # pragma: no cover - exercised only on a broken install
    raise ImportError(
        "warpviz's compiled extension (warpviz._core) could not be loaded: "
        f"{exc}. Build it with `pip install -e .` from the repository root "
        "(needs a C++20 compiler and CMake; scikit-build-core fetches nanobind)."
    ) from exc

__all__ = ["core", "testing", "build_info", "registered_metrics"]

#: Test hooks of the core (a metric's geometry at a point, a material's BSDF); not public API.
testing = core._testing


def build_info() -> dict:
    """Compiler, optimisation flags, thread count and SIMD kernel of the compiled core, and the metrics
    whose right-hand side is differentiated automatically instead of hand-written (``slow_metrics``:
    they cannot step in SIMD lanes and run ~6x slower)."""
    info = dict(core.build_info())
    info["slow_metrics"] = [m["name"] for m in registered_metrics() if not m["lane_rhs"] and not m["flat"]]
    return info


def registered_metrics() -> list[dict]:
    """Metrics compiled into the core and their facts, from the core's registry (``engine/registry.h``).

    Returns
    -------
    list of dict
        One per metric, in registration order: ``name`` (str), ``class_name`` (str), ``summary`` (str),
        ``params`` (list of str, constructor order), ``param_specs`` (list of dict with ``name``, ``lo``,
        ``lo_open``, ``hi``, ``hi_open``, ``default``, ``example``, ``doc``), ``param_relation`` (str, a constraint
        between parameters or ""), ``invariants`` (list of str, the first ``"H"``), ``sheets`` (int),
        ``flat`` (bool), ``lane_rhs`` (bool: a hand-written right-hand side that steps in SIMD lanes) and
        ``static_spherical`` (bool: an exact lens map, used by the light connection).
    """
    out = []
    for m in core.metrics():
        entry = dict(m)
        entry["param_specs"] = [dict(s) for s in entry["param_specs"]]
        out.append(entry)
    return out
