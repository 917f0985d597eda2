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

__all__ = ["core", "build_info", "registered_metrics"]


def build_info() -> dict:
    """Compiler, optimisation flags and thread count of the compiled core."""
    return dict(core.build_info())


def registered_metrics() -> list[dict]:
    """Metrics compiled into the core: ``[{"name", "params", "invariants"}, ...]``."""
    return [dict(m) for m in core.metrics()]
