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
from warpviz.image import Image
from warpviz.render import render
from warpviz.io import atomic_write, read_rays, write_vtm, write_vtp
from warpviz.geometry import (
    camera_frustum,
    ellis_embedding,
    ellis_embedding_points,
    ergosphere_surface,
    horizon_surface,
    metric_features,
    photon_sphere,
    scene_surfaces,
    throat_surface,
)
from warpviz.export import save_scene_vtm, scene_multiblock

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
    "Image",
    "render",
    "atomic_write",
    "read_rays",
    "write_vtm",
    "write_vtp",
    "camera_frustum",
    "ellis_embedding",
    "ellis_embedding_points",
    "ergosphere_surface",
    "horizon_surface",
    "metric_features",
    "photon_sphere",
    "scene_surfaces",
    "throat_surface",
    "save_scene_vtm",
    "scene_multiblock",
]

from warpviz.viewer import view

__all__ += ["view"]

from warpviz.scene import Scene, SceneError, load_scene

__all__ += ["Scene", "SceneError", "load_scene"]
