"""Spacetimes: the metric classes of the core's registry and the display meshes of their landmarks.

:mod:`~warpviz.spacetime.metrics` holds :class:`Metric` and one class per metric compiled into the core
(hand-written for Minkowski, Schwarzschild, Kerr and the Ellis wormhole, generated from the registry for
the others); :mod:`~warpviz.spacetime.landmarks` the horizon, ergosphere, photon sphere or region and throat
as PyVista polydata; :mod:`~warpviz.spacetime.embedding` a static spherical wormhole's embedding diagram,
from the lens functions its metric file declares. This is the bottom layer of the Python package: it imports
nothing of warpviz but :mod:`warpviz._native`.

Examples
--------
>>> from warpviz.spacetime import Kerr, metric_from_dict
>>> metric_from_dict({"name": "kerr", "mass": 1.0, "spin": 0.5}) == Kerr(mass=1.0, spin=0.5)
True
"""

from warpviz.spacetime.embedding import (
    WormholeProfile,
    has_embedding,
    wormhole_embedding,
    wormhole_embedding_points,
)
from warpviz.spacetime.landmarks import (
    ergosphere_surface,
    horizon_surface,
    metric_features,
    photon_sphere,
    throat_surface,
)
from warpviz.spacetime.metrics import (
    METRIC_CLASSES,
    EllisWormhole,
    Kerr,
    Metric,
    Minkowski,
    PerformanceWarning,
    Schwarzschild,
    metric_class,
    metric_from_dict,
    metric_from_params,
    metric_names,
)

# every metric compiled into the core, also those generated from the registry (wv.ReissnerNordstrom)
globals().update(METRIC_CLASSES)

__all__ = [
    "EllisWormhole",
    "Kerr",
    "METRIC_CLASSES",
    "Metric",
    "Minkowski",
    "PerformanceWarning",
    "Schwarzschild",
    *METRIC_CLASSES,
    "metric_class",
    "metric_from_dict",
    "metric_from_params",
    "metric_names",
    "WormholeProfile",
    "has_embedding",
    "wormhole_embedding",
    "wormhole_embedding_points",
    "ergosphere_surface",
    "horizon_surface",
    "metric_features",
    "photon_sphere",
    "throat_surface",
]
