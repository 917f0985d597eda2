"""What the teaching view shows, gathered from whatever it was given.

:func:`warpviz.view` accepts a render (:class:`~warpviz.Image`), a recorded
:class:`~warpviz.RayBundle`, a ``.vtp`` ray file, a scene ``.vtm`` or a scene to render first;
:func:`view_content` turns each into one :class:`ViewContent`: the picture (if any), the rays as
polydata (cell ``i`` = ray ``i``), the metric, the scene's camera and shapes and the metric's landmarks.

Examples
--------
>>> import warpviz as wv
>>> from warpviz.viewer.view_content import view_content
>>> rays = wv.trace(wv.Kerr(mass=1.0, spin=0.9), [-30.0, 0, 0], [[1, 0.1, 0]], record=True)
>>> content = view_content(rays)
>>> content.image is None, content.rays.n_cells, content.metric
(True, 1, Kerr(mass=1.0, spin=0.9))
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from warpviz.render import Image
from warpviz.scene.native import SCHEMA
from warpviz.spacetime import Metric
from warpviz.tracing import RayBundle
from warpviz.scene.camera import pinhole_directions
from warpviz.viewer.picking import teaching_pixels

__all__ = ["ViewContent", "camera_from_frustum", "flat_impact_parameters", "view_content"]

@dataclass
class ViewContent:
    """Everything one teaching view shows.

    Attributes
    ----------
    title : str
        A short name (the scene file's stem, the file's stem or the metric's name).
    image : numpy.ndarray or None
        (H, W, 3) uint8 tonemapped picture, or None (rays without a render).
    rays : pyvista.PolyData or None
        The recorded rays, one polyline cell per ray (cell ``i`` = ray ``i``) with the data of
        :meth:`warpviz.RayBundle.to_pyvista`.
    metric : Metric or None
        The spacetime.
    native_scene : dict or None
        The rendered native scene (for the shapes' colours).
    camera : dict or None
        The native scene camera.
    surfaces : pyvista.PolyData or None
        Scene shapes read from a ``.vtm`` (otherwise built from ``native_scene`` when drawn).
    lights : pyvista.PolyData or None
        Point and spot lights read from a ``.vtm`` (otherwise built from ``native_scene`` when drawn:
        :func:`warpviz.scene.scene_lights`).
    features : dict[str, pyvista.PolyData]
        Landmarks read from a ``.vtm`` (otherwise built from ``metric`` when drawn).
    pixel_labels : dict[tuple[int, int], str]
        What the pixels chosen by :func:`~warpviz.viewer.picking.teaching_pixels` show ("edge of the
        shadow", "light bent round the hole", "light that hardly bends"), for the labels in the view.
    source : scene or None
        The scene the image was rendered from (a Scene or native dict), so the view can refine it.
    preview : dict or None
        ``width``, ``height``, ``spp`` and ``seed`` of that render, and ``rgb``: its (height, width, 3)
        float32 linear radiance (the first pass of :class:`~warpviz.viewer.progressive.ProgressivePreview`).
    """

    title: str
    image: np.ndarray | None = None
    rays: Any = None
    metric: Metric | None = None
    native_scene: Mapping[str, Any] | None = None
    camera: Mapping[str, Any] | None = None
    surfaces: Any = None
    lights: Any = None
    features: dict = field(default_factory=dict)
    pixel_labels: dict = field(default_factory=dict)
    source: Any = None
    preview: dict | None = None


def _metric_of_polydata(poly) -> Metric | None:
    """The metric named in the field data of a ray file, or None."""
    from warpviz.export.export import _as_metric

    fields = poly.field_data
    if "metric" not in fields:
        return None
    params = np.asarray(fields["metric_params"]).tolist() if "metric_params" in fields else []
    return _as_metric({"name": str(np.asarray(fields["metric"])[0]), "params": params})


def camera_from_frustum(frustum) -> dict:
    """The native camera dict drawn by :func:`warpviz.camera_frustum` (its default length), read back.

    Parameters
    ----------
    frustum : pyvista.PolyData
        A frustum as written into a scene ``.vtm`` (points: apex, four base corners, up-marker tip;
        field data ``fov``, ``width``, ``height``, ``sheet``).

    Returns
    -------
    dict
        ``position``, ``look_at`` (the base centre), ``up``, ``fov``, ``width``, ``height``, ``sheet``.
    """
    pts = np.asarray(frustum.points, dtype=np.float64)
    centre = pts[1:5].mean(axis=0)
    fields = frustum.field_data
    return {
        "position": pts[0].tolist(),
        "look_at": centre.tolist(),
        "up": (pts[5] - centre).tolist(),
        "fov": float(np.asarray(fields["fov"])[0]),
        "width": int(np.asarray(fields["width"])[0]),
        "height": int(np.asarray(fields["height"])[0]),
        "sheet": int(np.asarray(fields["sheet"])[0]) if "sheet" in fields else SCHEMA["camera"]["sheet"],
    }


def _content_from_image(img: Image) -> ViewContent:
    native = img.native_scene
    metric = img.rays.metric if img.rays is not None else None
    if metric is None:
        metric = _metric_of_native(native)
    scene = img.metadata.get("scene") if img.metadata else None
    title = Path(scene).stem if scene else (metric.name if metric else "render")
    return ViewContent(
        title=title,
        image=img.to_uint8(),
        rays=img.rays.to_pyvista() if img.rays is not None and len(img.rays) else None,
        metric=metric,
        native_scene=native,
        camera=native.get("camera") if native else None,
    )


def _content_from_file(path: Path) -> ViewContent:
    import pyvista as pv

    from warpviz.io import read_rays

    suffix = path.suffix.lower()
    if suffix == ".vtp":
        rays = read_rays(path)
        return ViewContent(title=path.stem, rays=rays, metric=_metric_of_polydata(rays))
    if not path.is_file():
        raise FileNotFoundError(f"no such file: {str(path)!r}")
    blocks = pv.read(path)
    names = list(blocks.keys())
    content = ViewContent(title=path.stem)
    if "rays" in names:
        content.rays = blocks["rays"]
        content.metric = _metric_of_polydata(content.rays)
    if "surfaces" in names:
        content.surfaces = blocks["surfaces"]
    if "lights" in names:
        content.lights = blocks["lights"]
    if "camera" in names:
        content.camera = camera_from_frustum(blocks["camera"])
    content.features = {n: blocks[n] for n in ("horizon", "ergosphere", "photon_sphere", "throat", "embedding")
                        if n in names}  # fmt: skip
    if not content.features and content.rays is None and content.surfaces is None:
        raise ValueError(f"{str(path)!r} holds none of the blocks of a warpviz scene (found: {names})")
    return content


def _preview_size(camera: Mapping[str, Any], width: int) -> tuple[int, int]:
    """The camera's image size shrunk to at most ``width`` pixels across, aspect kept."""
    w, h = int(camera["width"]), int(camera["height"])
    if w <= width:
        return w, h
    return width, max(1, round(h * width / w))


def flat_impact_parameters(camera: Mapping[str, Any], width: int, height: int) -> np.ndarray:
    """The impact parameter about the origin (where every metric has its centre) of each pixel's
    straight camera ray.

    Parameters
    ----------
    camera : dict
        A native scene camera.
    width, height : int
        The image size the pixels belong to.

    Returns
    -------
    numpy.ndarray
        (height, width) float64 distances of closest approach ``|position x direction|`` (scene units); ``inf``
        for rays that point away from the centre.
    """
    yy, xx = np.mgrid[0:height, 0:width]
    cam = dict(camera, width=width, height=height)
    d = pinhole_directions(cam, np.column_stack([xx.ravel(), yy.ravel()]))
    p = np.asarray(cam["position"], dtype=np.float64)
    b = np.linalg.norm(np.cross(p, d), axis=1)
    return np.where(d @ p < 0.0, b, np.inf).reshape(height, width)


def _content_from_scene(scene, *, pixels, preview_width: int, spp: int | None, time_limit=None) -> ViewContent:
    """Render a scene small, recording the paths of ``pixels`` (given at the preview size) or of the few
    pixels :func:`~warpviz.viewer.picking.teaching_pixels` chooses from a first render."""
    from warpviz.render import render

    if isinstance(scene, Mapping):
        camera = scene["camera"]
    else:
        from warpviz.scene import load_scene

        if isinstance(scene, (str, os.PathLike)):
            scene = load_scene(scene)
        camera = scene.native(flat=False, width=None, height=None, paper=False)["camera"]
    width, height = _preview_size(camera, preview_width)
    labels: dict = {}
    if pixels is None:
        first = render(scene, width=width, height=height, spp=min(spp or 4, 4), aovs=["status"])
        metric = _metric_of_native(first.native_scene)
        throat = metric.landmarks.get("throat") if metric is not None else None
        chosen = teaching_pixels(first.aovs["status"], first.rgb, flat_impact_parameters(camera, width, height),
                                 edge_impact=throat)  # fmt: skip
        labels = {xy: label for label, xy in chosen}
        record = np.array(list(labels) or [(width // 2, height // 2)], dtype=np.int64)
    else:
        record = np.asarray(pixels, dtype=np.int64).reshape(-1, 2)
    img = render(scene, width=width, height=height, spp=spp, time_limit=time_limit, record_pixels=record)
    content = _content_from_image(img)
    content.pixel_labels = labels
    content.source = scene
    content.preview = {"width": width, "height": height, "spp": img.metadata["spp"], "seed": img.metadata.get("seed"),
                       "rgb": np.asarray(img.rgb)}
    return content


def _metric_of_native(native: Mapping[str, Any] | None) -> Metric | None:
    if native is None:
        return None
    from warpviz.export.export import _as_metric

    return _as_metric(native["metric"])


def view_content(obj, *, pixels=None, preview_width: int = 96, spp: int | None = 4, time_limit=None) -> ViewContent:
    """Gather what :func:`warpviz.view` shows of ``obj``.

    Parameters
    ----------
    obj : Image, RayBundle, str, os.PathLike, warpviz.scene.Scene or dict
        A render, a recorded bundle, a ``.vtp``/``.vtm`` file, or a scene (file, Scene or native dict),
        which is rendered at ``preview_width`` pixels across, recording the paths of ``pixels`` or of
        the few pixels :func:`warpviz.viewer.picking.teaching_pixels` chooses (the shadow's or throat's
        edge, the lensed light, a plain one).
    pixels : array_like of int, optional, keyword-only
        (K, 2) pixels to record when ``obj`` is a scene (ignored otherwise).
    preview_width, spp : int, keyword-only
        Size and samples per pixel of a scene's preview render (``spp`` None with a ``time_limit``: as many
        as fit).
    time_limit : float or str, optional, keyword-only
        A time budget for the preview render (``render(time_limit=)``; with ``spp``, whichever comes first).

    Returns
    -------
    ViewContent

    Raises
    ------
    TypeError
        ``obj`` is none of the accepted kinds.
    ValueError
        A bundle without recorded paths, or a ``.vtm`` with nothing warpviz wrote in it.
    FileNotFoundError
        A file that does not exist.
    """
    if isinstance(obj, Image):
        return _content_from_image(obj)
    if isinstance(obj, RayBundle):
        if not obj.recorded:
            raise ValueError("this RayBundle has no recorded paths: trace with record=True to view them")
        return ViewContent(title=obj.metric.name, rays=obj.to_pyvista(), metric=obj.metric)
    if isinstance(obj, (str, os.PathLike)) and Path(obj).suffix.lower() in (".vtp", ".vtm"):
        return _content_from_file(Path(obj))
    if isinstance(obj, (str, os.PathLike, Mapping)) or type(obj).__name__ == "Scene":
        return _content_from_scene(obj, pixels=pixels, preview_width=preview_width, spp=spp, time_limit=time_limit)
    raise TypeError(
        f"cannot view a {type(obj).__name__}: pass an Image from warpviz.render, a RayBundle, a .vtp/.vtm "
        "file, a scene file, a warpviz.scene.Scene or a native scene dict"
    )
