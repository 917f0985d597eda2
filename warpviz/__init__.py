"""warpviz: render and explain light in curved spacetime.

The C++ core traces null geodesics of every spacetime in its registry (:func:`registered_metrics`: black
holes, a wormhole, flat space; each a class here) with :func:`trace`, returning :class:`RayBundle`
objects, and path-traces scenes whose light rays are those geodesics with :func:`render`, returning an
:class:`Image`. Scenes come from TOML files (:func:`load_scene`); rays and scenes export to VTK files and
show in a PyVista teaching view (:func:`view`).

The package is layered by concern, each subpackage importing only those below it:
:mod:`warpviz.spacetime` (metrics and their landmarks) < :mod:`warpviz.tracing` (:func:`trace`,
:class:`RayBundle`) < :mod:`warpviz.scene` (scene files, the camera) < :mod:`warpviz.render`
(:func:`render`, :class:`Image`) < :mod:`warpviz.export` (VTK multiblocks) < :mod:`warpviz.viewer`
(the teaching view) < :mod:`warpviz.cli`. :mod:`warpviz._native` (the only importer of the compiled
core) and :mod:`warpviz.io` (atomic file writes, VTK files) lie below them all.

>>> import warpviz as wv
>>> rays = wv.trace(wv.Kerr(mass=1.0, spin=0.9), [0, -50.0, 0], [0, 1.0, 0])
>>> rays.status_names.tolist()
['horizon']
"""

from warpviz._native import build_info, registered_metrics
from warpviz.export import save_scene_vtm, scene_multiblock
from warpviz.io import atomic_write, read_rays, write_vtm, write_vtp
from warpviz.render import Image, render
from warpviz.scene import Scene, SceneError, camera_frustum, load_scene, scene_surfaces
from warpviz.spacetime import (
    METRIC_CLASSES,
    EllisWormhole,
    Kerr,
    Metric,
    Minkowski,
    Schwarzschild,
    ergosphere_surface,
    horizon_surface,
    metric_class,
    metric_features,
    metric_from_dict,
    metric_from_params,
    photon_sphere,
    throat_surface,
    wormhole_embedding,
    wormhole_embedding_points,
)
from warpviz.tracing import STEPPERS, RayBundle, RayStatus, trace
from warpviz.viewer import view

__version__ = "0.1.0"

# Every metric compiled into the core is a public class, also those without a hand-written Python class
# (a new metric file in renderer_ext/metrics/ is wv.<its kClassName> with no Python edit).
globals().update(METRIC_CLASSES)

__all__ = [
    # spacetimes and geodesics
    "EllisWormhole",
    "Kerr",
    "Metric",
    "Minkowski",
    "Schwarzschild",
    "metric_class",
    "metric_from_dict",
    "metric_from_params",
    *METRIC_CLASSES,
    "STEPPERS",
    "RayBundle",
    "RayStatus",
    "trace",
    # scenes and rendering
    "Image",
    "Scene",
    "SceneError",
    "load_scene",
    "render",
    # files, geometry and the teaching view
    "atomic_write",
    "read_rays",
    "write_vtm",
    "write_vtp",
    "camera_frustum",
    "wormhole_embedding",
    "wormhole_embedding_points",
    "ergosphere_surface",
    "horizon_surface",
    "metric_features",
    "photon_sphere",
    "scene_surfaces",
    "throat_surface",
    "save_scene_vtm",
    "scene_multiblock",
    "view",
    # build
    "build_info",
    "registered_metrics",
    "__version__",
]
