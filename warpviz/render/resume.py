"""Resuming a render from its EXR: what must match, and the film its channels give back.

An EXR written by a warpviz render holds, beside the radiance and its AOVs, the ``variance`` of every
pixel mean and ``samples`` per pixel, and in its ``warpviz`` header the samples per pixel reached
(``spp``), the settings that decide what a sample adds (:data:`RESUME_SETTINGS`, with the image size
and the metric) and a digest of the whole native scene (:func:`scene_sha256`). ``render(resume=)`` (and
``warpviz render --resume``) checks all of them against the render asked for before any work
(:func:`resume_problem`: a mismatch names the setting and both values), rebuilds the film's sums from
the channels (:func:`film_from_image`) and adds samples ``[spp, ...)``: the result equals one render of
the total to float32 rounding (the resumed radiance was stored as float32 means).

Examples
--------
>>> a = scene_sha256({"metric": {"name": "minkowski", "params": []}, "camera": {"fov": 40.0}})
>>> b = scene_sha256({"camera": {"fov": 40.0}, "metric": {"params": [], "name": "minkowski"}})
>>> a == b, len(a)   # key order does not matter
(True, 64)
>>> a == scene_sha256({"metric": {"name": "minkowski", "params": []}, "camera": {"fov": 41.0}})
False
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import numpy as np

from warpviz._native import core
from warpviz.render.image import read_exr  # here too: resuming starts from one

__all__ = ["RESUME_SETTINGS", "IMPLIED_SETTINGS", "PHOTON_SETTINGS", "FIXES", "scene_sha256", "resume_settings", "read_exr",
           "saved_resume", "resume_problem", "film_from_image", "sample_multiples"]

#: The render options that decide what each sample adds (so a resumed image must have been rendered with
#: the same); spp, threads, batch (bit-identical either way), progress and the limits do not.
RESUME_SETTINGS = ("seed", "max_depth", "rr_depth", "light_sampling", "stepper", "tol", "max_steps",
                   "escape_radius", "max_drift", "chord_tolerance", "segment_method", "light_connection", "lens_images",
                   "lens_focus", "camera_light_samples", "light_roulette",
                   "pixel_sampler", "stratified_paths", "edge_samples", "detail_samples", "filter", "filter_radius",
                   "aim_lights", "light_margin", "pilot_tol", "guide_training", "photons", "photons_per_pixel",
                   "photon_radius", "retro_photons", "photon_aim", "crop")  # fmt: skip

#: What an image written before a setting existed was rendered with (``detail_samples``: none had more;
#: ``guide_training``: none was guided; ``photons``: none traced photons, so their radius never mattered;
#: ``camera_light_samples``: the camera drew none; ``light_roulette``: every light sample was traced;
#: ``lens_focus``: every light point was drawn by area; ``stratified_paths``: only the camera points were
#: stratified; ``retro_photons``: the path tracer kept the light a hole turns back; ``photon_aim``: photons
#: were sent by the cosine alone).
IMPLIED_SETTINGS = {"detail_samples": 1, "guide_training": 0, "photons": 0, "photons_per_pixel": 0.0,
                    "photon_radius": 2.0, "camera_light_samples": False, "light_roulette": 0.0, "lens_focus": False,
                    "stratified_paths": False, "retro_photons": False,
                    "photon_aim": False}

#: The settings that change a render only where it traces photons (``photons`` or ``photons_per_pixel`` above 0):
#: compared only where the image or the render does, so that an image rendered without photons before one of
#: them existed can still be continued with today's defaults.
PHOTON_SETTINGS = ("photon_radius", "retro_photons", "photon_aim")


#: Renderer fixes that change what some samples add without a setting to name them: (tag, which renders they
#: change, what was fixed). A render records the tags it has (``settings["fixes"]``); an image written before a
#: fix that changes its render cannot be continued, since its samples and the new ones would disagree.
FIXES = (("camera_light_hit_aim",
          lambda s: bool(s.get("camera_light_samples") and s.get("sphere_lamps")) and s.get("metric") != "minkowski",
          "the camera's own light samples of a sphere lamp were fixed (0b55c8c, 2026-12-07: a shot that reached the "
          "lamp anywhere counted, so a sphere lamp seen round a hole came out up to 10 % too bright)"),
         ("lens_focus_bins",
          lambda s: bool(s.get("lens_focus")) and s.get("light_connection") != "aimed"
          and s.get("metric") not in ("minkowski", "ellis"),
          "the lens focus drew its angle by what the lens magnifies and nine in ten of the light points (732f3bc, "
          "2026-12-07: the same mean, another estimator)"),
         ("lens_order_extrapolated",
          lambda s: s.get("light_connection") != "aimed" and int(s.get("lens_images") or 0) >= 3
          and s.get("metric") not in ("minkowski", "ellis", "reissner_nordstrom"),
          "the lens connection estimated the first winding's weight without evaluating the lens map (2026-12-07: the "
          "same mean, another draw among the images)"),)


def _sphere_lamps(native: dict) -> bool:
    """Whether the native scene has an emissive sphere."""
    materials = native.get("materials", [])
    return any(shape.get("type") == "sphere" and 0 <= int(shape.get("material", -1)) < len(materials)
               and materials[int(shape["material"])].get("type") == "emissive"
               for shape in native.get("shapes", []))  # fmt: skip


def _digest(node, h) -> None:
    if isinstance(node, dict):
        h.update(b"{")
        for key in sorted(node, key=str):
            h.update(json.dumps(str(key)).encode())
            _digest(node[key], h)
        h.update(b"}")
    elif isinstance(node, (list, tuple)):
        h.update(b"[")
        for item in node:
            _digest(item, h)
        h.update(b"]")
    elif isinstance(node, np.ndarray):
        arr = np.ascontiguousarray(node)
        h.update(f"array:{arr.dtype.str}:{arr.shape}:".encode())
        h.update(arr.tobytes())
    elif isinstance(node, (np.generic,)):
        _digest(node.item(), h)
    else:
        h.update(json.dumps(node).encode())


def scene_sha256(native: dict) -> str:
    """SHA-256 (hex) of a native scene dict: its keys in sorted order, values, and arrays' dtypes,
    shapes and bytes (textures, meshes)."""
    h = hashlib.sha256()
    _digest(native, h)
    return h.hexdigest()


def resume_settings(options: dict, native: dict) -> dict:
    """The settings a resumed render must share with its image: :data:`RESUME_SETTINGS`, the image size
    and the metric with its parameters (JSON types)."""
    out = {key: options[key] for key in RESUME_SETTINGS}
    out["crop"] = list(out["crop"]) if out["crop"] is not None else None
    out["size"] = [int(native["camera"]["width"]), int(native["camera"]["height"])]
    out["metric"] = native["metric"]["name"]
    out["metric_params"] = [float(p) for p in native["metric"].get("params", [])]
    out["sphere_lamps"] = _sphere_lamps(native)
    out["fixes"] = [tag for tag, _, _ in FIXES]
    return json.loads(json.dumps(out))


def saved_resume(meta: dict) -> dict:
    """The resume record of an image's ``warpviz`` metadata (``settings``, ``scene_sha256``, ``passes``, ...),
    or {} where the image has none (not written by a resumable render)."""
    saved = meta.get("resume")
    return saved if isinstance(saved, dict) else {}


def resume_problem(img, *, settings: dict, sha256: str, aovs: list[str] | None, name: str,
                   scene: str | None = None) -> str | None:
    """Why the render asked for cannot continue image ``img``, or None.

    Parameters
    ----------
    img : warpviz.render.image.Image
        The image to continue (:func:`read_exr`).
    settings : dict
        The render's :func:`resume_settings`.
    sha256 : str
        The render's :func:`scene_sha256`.
    aovs : list of str or None
        The optional AOVs the render asks for, None: whatever the image has.
    name : str
        How to name the image in a message (its file).
    scene : str, optional
        The render's scene file (None: a scene not from a file).

    Returns
    -------
    str or None
        A sentence naming what differs (with both values), or None when it can be continued.
    """
    meta = img.metadata
    if "resume" not in meta or "variance" not in img.aovs or "samples" not in img.aovs:
        return (f"{name} cannot be resumed: it was written by a warpviz render that does not record its samples' "
                "variance and settings (render it again)")  # fmt: skip
    saved = saved_resume(meta)
    if not saved.get("resumable", False):
        return (f"{name} cannot be resumed: it holds only part of its first pass (the render was stopped before "
                "any pass finished); render it again")  # fmt: skip
    old = saved.get("settings", {})
    if scene is not None and meta.get("scene") is not None and Path(meta["scene"]).name != Path(scene).name:
        return f"{name} was rendered from another scene ({Path(meta['scene']).name}; this render is of {Path(scene).name})"
    def traces_photons(s: dict) -> bool:
        return float(s.get("photons") or 0) > 0 or float(s.get("photons_per_pixel") or 0) > 0

    photons = traces_photons(settings) or traces_photons({**IMPLIED_SETTINGS, **old})
    for key in ("size", "metric", "metric_params", *RESUME_SETTINGS):
        was = old.get(key, IMPLIED_SETTINGS.get(key))
        if was != settings.get(key) and (photons or key not in PHOTON_SETTINGS):
            return f"{name} was rendered with {key} = {_show(was)}; this render has {key} = {_show(settings.get(key))}"
    if saved.get("scene_sha256") != sha256:
        where = f" ({Path(meta['scene']).name})" if meta.get("scene") else ""
        return (f"{name} was rendered from another scene{where}, or the scene has changed since: its objects, "
                "camera or lights differ from this render's")  # fmt: skip
    fixed = old.get("fixes", [])
    for tag, changes, what in FIXES:
        if tag not in fixed and changes(settings):
            return f"{name} was rendered before {what}; its samples and new ones would disagree (render it again)"
    if aovs is not None:
        have = sorted(k for k in img.aovs if k not in ("errors", "samples", "variance"))
        if sorted(aovs) != have:
            return (f"{name} keeps the AOVs {have or 'none'}; this render asks for {sorted(aovs) or 'none'} (a resumed "
                    "render keeps the image's)")  # fmt: skip
    spp = meta.get("spp")
    counts = np.asarray(img.aovs["samples"])
    multiples = sample_multiples(int(old.get("edge_samples", 1)), int(old.get("detail_samples", 1)))
    if not isinstance(spp, int) or spp < 1 or not np.isin(counts, [spp * k for k in multiples]).all():
        return f"{name}'s samples per pixel do not match its header's spp = {spp!r}: it was not written whole"
    return None


def sample_multiples(edge_samples: int, detail_samples: int) -> tuple[int, int, int, int]:
    """The multiples of spp that a render's pixels get: a plain pixel, an edge pixel (the larger of the two
    options), a detail pixel, and a bright light's edge pixel (``kBrightEdgeFactor`` x an edge pixel's, where
    ``edge_samples`` is on); the last is the largest. The renderer's own rule
    (``renderer_ext/integrators/render_types.h``: ``sample_multiples``), through the binding."""
    return tuple(int(k) for k in core.sample_multiples(int(edge_samples), int(detail_samples)))


def _show(value) -> str:
    return "none" if value is None else json.dumps(value)


def film_from_image(img, aovs: list[str]) -> dict:
    """The core film (sums and counts) whose resolution is ``img``: means times samples, squares from the
    variance of the mean (``variance n (n - 1) + n mean**2``), error counts from the error fractions.

    Parameters
    ----------
    img : warpviz.render.image.Image
        A resumable image (:func:`resume_problem` found nothing).
    aovs : list of str
        The optional AOVs of the film (the image's).

    Returns
    -------
    dict
        The film dict ``_core.render`` continues (``options["film"]``).
    """
    n = np.asarray(img.aovs["samples"], dtype=np.float64)
    n3 = n[..., None]
    mean = np.asarray(img.rgb, dtype=np.float64)
    var = np.nan_to_num(np.asarray(img.aovs["variance"], dtype=np.float64), nan=0.0)
    crop = img.metadata.get("crop") or [0, 0]

    def per_pixel(name, scale=None):
        if name not in aovs:
            return None
        arr = np.asarray(img.aovs[name], dtype=np.float64 if scale is not None else np.float32)
        if scale is not None:
            arr = arr * (scale if arr.ndim == 2 else scale[..., None])
        return np.ascontiguousarray(arr)

    return {
        "x0": int(crop[0]),
        "y0": int(crop[1]),
        "rgb_sum": np.ascontiguousarray(mean * n3),
        "rgb_sq_sum": np.ascontiguousarray(var * n3 * np.maximum(n3 - 1, 0) + n3 * mean * mean),
        "samples": np.ascontiguousarray(n.astype(np.int32)),
        "errors": np.ascontiguousarray(np.rint(np.asarray(img.aovs["errors"], np.float64) * n).astype(np.int32)),
        "steps_sum": per_pixel("n_steps", n),
        "max_drift": per_pixel("max_drift"),
        "redshift": per_pixel("redshift"),
        "status": per_pixel("status"),
        "depth": per_pixel("depth"),
        "normal": per_pixel("normal"),
        "albedo_sum": per_pixel("albedo", n),
        "albedo_normal_sum": per_pixel("albedo_normal", n),
        "emission_sum": per_pixel("emission", n),
    }
