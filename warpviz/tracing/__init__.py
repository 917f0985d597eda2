"""Tracing null geodesics: :func:`trace` and its result, the :class:`RayBundle`.

:mod:`~warpviz.tracing.trace` validates the arguments and calls the core (:data:`STEPPERS`,
:func:`default_max_drift`); :mod:`~warpviz.tracing.rays` holds :class:`RayBundle` (end states, recorded
polylines, conversion to PyVista) and :class:`RayStatus`.

Examples
--------
>>> from warpviz.spacetime import Schwarzschild
>>> from warpviz.tracing import RayStatus, trace
>>> rays = trace(Schwarzschild(mass=1.0), [-50.0, 0, 0], [[1, 0, 0], [1, 0.5, 0]])
>>> [RayStatus(s).name for s in rays.status]
['HORIZON', 'ESCAPED']
"""

from warpviz.tracing.rays import RayBundle, RayStatus, recorded_point_data
from warpviz.tracing.trace import STEPPERS, default_max_drift, trace

__all__ = ["RayBundle", "RayStatus", "STEPPERS", "default_max_drift", "recorded_point_data", "trace"]
