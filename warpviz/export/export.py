"""A whole scene as one VTK multiblock: rays, scene surfaces, the metric's landmarks and the camera.

Examples
--------
>>> import warpviz as wv
>>> rays = wv.trace(wv.Kerr(mass=1.0, spin=0.9), [-30.0, 0, 0], [[1, 0, 0], [1, 0.3, 0]], record=True)
>>> wv.scene_multiblock(rays=rays).keys()
['rays', 'horizon', 'ergosphere', 'photon_sphere']
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from warpviz.scene import camera_frustum, scene_lights, scene_surfaces
from warpviz.spacetime import (
    Metric,
    metric_features,
    metric_from_dict,
    metric_from_params,
    metric_names,
    wormhole_embedding_points,
)
from warpviz.tracing import RayBundle

if TYPE_CHECKING:  # pragma: no cover
    import pyvista as pv

__all__ = ["BLOCK_NAMES", "save_scene_vtm", "scene_multiblock"]

#: Names of the blocks :func:`scene_multiblock` can hold, in the order they appear.
BLOCK_NAMES = (
    "rays", "surfaces", "lights", "horizon", "ergosphere", "photon_sphere", "throat", "embedding", "embedding_rays",
    "camera",
)  # fmt: skip


def _as_metric(spec: Metric | Mapping[str, Any]) -> Metric:
    """A Metric from a Metric, ``{"name", **params}`` or the native ``{"name", "params": [...]}``."""
    if isinstance(spec, Metric):
        return spec
    spec = dict(spec)
    if isinstance(spec.get("params"), (list, tuple, np.ndarray)) and spec.get("name") in metric_names():
        return metric_from_params(spec["name"], [float(v) for v in spec["params"]])
    return metric_from_dict(spec)


def scene_multiblock(
    *,
    rays: RayBundle | pv.PolyData | None = None,
    native_scene: Mapping[str, Any] | None = None,
    metric: Metric | Mapping[str, Any] | None = None,
    resolution: int = 64,
) -> pv.MultiBlock:
    """Collect everything worth looking at into one named multiblock.

    Parameters
    ----------
    rays : RayBundle or pyvista.PolyData, optional, keyword-only
        Recorded rays (a bundle traced with ``record=True``, or its :meth:`RayBundle.to_pyvista`).
    native_scene : dict, optional, keyword-only
        A native scene (``docs/native-scene.md``): its shapes become ``surfaces``, its camera
        ``camera``, and its ``metric`` is used when ``metric`` is not given.
    metric : Metric or dict, optional, keyword-only
        The spacetime; default the metric of ``rays`` or of ``native_scene``. A Metric,
        ``{"name": ..., **params}``, or the native ``{"name": ..., "params": [...]}``.
    resolution : int, keyword-only
        Points around the equator of each landmark surface.

    Returns
    -------
    pyvista.MultiBlock
        Blocks in the order of :data:`BLOCK_NAMES`, only those that apply: ``rays`` (polylines),
        ``surfaces`` (scene shapes with a ``material`` cell array), ``lights`` (the point and spot lights, never
        hit: :func:`warpviz.scene.scene_lights`), the landmarks of
        :func:`warpviz.metric_features` (``horizon``, ``ergosphere``, ``photon_sphere``;
        ``throat``, ``embedding``), ``embedding_rays`` (a static spherical wormhole only: the rays mapped onto the
        embedding diagram with :func:`warpviz.wormhole_embedding_points`) and ``camera`` (the frustum
        of :func:`warpviz.camera_frustum`).

    Raises
    ------
    ValueError
        Rays without recorded paths, or two different metrics among the arguments.
    """
    import pyvista as pv

    metrics = []
    if metric is not None:
        metrics.append(_as_metric(metric))
    if isinstance(rays, RayBundle):
        metrics.append(rays.metric)
    if native_scene is not None and native_scene.get("metric") is not None:
        metrics.append(_as_metric(native_scene["metric"]))
    if any(m != metrics[0] for m in metrics[1:]):
        raise ValueError(f"conflicting metrics: {', '.join(sorted(set(map(repr, metrics))))}")
    the_metric = metrics[0] if metrics else None

    blocks: dict[str, pv.DataSet] = {}
    if rays is not None:
        blocks["rays"] = rays.to_pyvista() if isinstance(rays, RayBundle) else rays
    if native_scene is not None and native_scene.get("shapes"):
        blocks["surfaces"] = scene_surfaces(native_scene)
    if native_scene is not None and native_scene.get("lights"):
        blocks["lights"] = scene_lights(native_scene)
    if the_metric is not None:
        blocks.update(metric_features(the_metric, resolution=resolution))
    if the_metric is not None and "embedding" in blocks and "rays" in blocks and "sheet" in blocks["rays"].point_data:
        embedded = blocks["rays"].copy()
        embedded.points = wormhole_embedding_points(the_metric, embedded.points, embedded.point_data["sheet"])
        blocks["embedding_rays"] = embedded
    if native_scene is not None and native_scene.get("camera") is not None:
        blocks["camera"] = camera_frustum(native_scene["camera"])
    return pv.MultiBlock({name: blocks[name] for name in BLOCK_NAMES if name in blocks})


def save_scene_vtm(
    path: str | os.PathLike,
    *,
    rays: RayBundle | pv.PolyData | None = None,
    native_scene: Mapping[str, Any] | None = None,
    metric: Metric | Mapping[str, Any] | None = None,
    resolution: int = 64,
) -> Path:
    """Write :func:`scene_multiblock` to ``path`` (``.vtm`` plus its folder of pieces, atomically).

    Parameters
    ----------
    path : str or os.PathLike
        Destination ending in ``.vtm``; the pieces go to the folder of the same name without suffix.
    rays, native_scene, metric, resolution
        As for :func:`scene_multiblock`.

    Returns
    -------
    pathlib.Path
        ``path``.

    Examples
    --------
    >>> import pathlib, tempfile, pyvista as pv, warpviz as wv
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     out = wv.save_scene_vtm(pathlib.Path(folder) / "wormhole.vtm", metric=wv.EllisWormhole(throat=1.0))
    ...     print(pv.read(out).keys())
    ['throat', 'embedding']
    """
    from warpviz.io import write_vtm

    block = scene_multiblock(rays=rays, native_scene=native_scene, metric=metric, resolution=resolution)
    return write_vtm(block, path)
