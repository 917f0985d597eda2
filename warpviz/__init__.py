"""warpviz: render and explain light in curved spacetime.

The spacetime core traces null geodesics of Minkowski, Schwarzschild, Kerr and Ellis-wormhole
spacetimes in C++ and returns them as :class:`RayBundle` objects.

>>> import warpviz as wv
>>> rays = wv.trace(wv.Kerr(mass=1.0, spin=0.9), [0, -50.0, 0], [0, 1.0, 0])
>>> rays.status_names.tolist()
['horizon']
"""

from warpviz._native import build_info, registered_metrics
from warpviz.metrics import EllisWormhole, Kerr, Metric, Minkowski, Schwarzschild, metric_from_dict
from warpviz.rays import RayBundle, RayStatus
from warpviz.trace import STEPPERS, trace

__version__ = "0.1.0"

__all__ = [
    "EllisWormhole",
    "Kerr",
    "Metric",
    "Minkowski",
    "RayBundle",
    "RayStatus",
    "STEPPERS",
    "Schwarzschild",
    "build_info",
    "metric_from_dict",
    "registered_metrics",
    "trace",
    "__version__",
]
