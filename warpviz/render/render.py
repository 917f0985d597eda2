"""Rendering: path-trace a scene whose light rays are null geodesics.

:func:`render` takes a scene file, a :class:`warpviz.scene.Scene` or a native scene dict
(``docs/native-scene.md``) and returns an :class:`warpviz.render.image.Image`.

Examples
--------
A diffuse white sphere under a uniform white sky, in flat space, reflects exactly the sky's radiance
(the "white furnace"):

>>> import numpy as np, warpviz as wv
>>> scene = {
...     "metric": {"name": "minkowski", "params": []},
...     "camera": {"position": [0, -5, 0], "look_at": [0, 0, 0], "fov": 30, "width": 8, "height": 6},
...     "textures": [{"type": "constant", "color": [1, 1, 1]}],
...     "materials": [{"type": "diffuse", "texture": 0}],
...     "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": 0}],
...     "environment": {"color": [0.5, 0.5, 0.5]},
... }
>>> img = wv.render(scene, spp=4, max_depth=64)
>>> img.shape, bool(np.allclose(img.rgb, 0.5))
((6, 8), True)
"""

from __future__ import annotations

import math
import os
import time
import warnings
from collections.abc import Callable

import numpy as np

from warpviz._native import core
from warpviz.limits import MAX_SPP, duration_seconds, image_side, noise_level, tolerance_problem
from warpviz.options import DEFAULT_OPTIONS as OPTION_DEFAULTS
from warpviz.options import FILTER_RADII, check_option, default_detail_samples, default_edge_samples
from warpviz.render.denoise import DENOISE_AOVS, require_denoiser
from warpviz.render.image import Image
from warpviz.render.memory import check_render_memory
from warpviz.render.passes import PASS_SAMPLES, PassesDone, PassReport, concat_rays, pass_plan, run_passes
from warpviz.render.resume import (IMPLIED_SETTINGS, film_from_image, read_exr, resume_problem, resume_settings,
                                   sample_multiples, saved_resume, scene_sha256)
from warpviz.scene.native import native_scene, scene_emits
from warpviz.spacetime import metric_from_params
from warpviz.tracing import RayBundle, default_max_drift, recorded_point_data

__all__ = ["render", "DarkSceneWarning", "DEFAULT_OPTIONS", "FILTER_RADII", "OPTIONAL_AOVS"]

#: The AOVs a render computes only when asked (``aovs=``); ``errors`` and ``samples`` it always keeps.
OPTIONAL_AOVS = ("redshift", "n_steps", "max_drift", "status", "depth", "normal", "albedo", "albedo_normal",
                 "emission")

#: Renderer options and their defaults (see docs/native-scene.md).
#: What a render starts from: every option of the table's defaults (warpviz/options.py), the optional AOVs
#: computed (radiance, errors and samples always are) and no crop window ((x0, y0, width, height) renders only
#: that window of the image).
DEFAULT_OPTIONS = {**OPTION_DEFAULTS, "aovs": OPTIONAL_AOVS, "crop": None}


def _positive_int(name: str, value, *, allow_zero: bool = False) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < (0 if allow_zero else 1):
        raise ValueError(f"{name} must be a {'non-negative' if allow_zero else 'positive'} integer, got {value!r}")
    return int(value)


def render(
    scene,
    *,
    spp: int | None = None,
    width: int | None = None,
    height: int | None = None,
    seed: int | None = None,
    threads: int = 0,
    flat: bool = False,
    paper: bool = False,
    light_sampling: bool | None = None,
    max_depth: int | None = None,
    stepper: str | None = None,
    tol: float | None = None,
    light_connection: str | None = None,
    lens_images: int | None = None,
    lens_focus: bool | None = None,
    camera_light_samples: bool | None = None,
    light_roulette: float | None = None,
    pixel_sampler: str | None = None,
    stratified_paths: bool | None = None,
    edge_samples: int | None = None,
    detail_samples: int | None = None,
    filter: str | None = None,
    filter_radius: float | None = None,
    aim_lights: bool | None = None,
    light_margin: bool | None = None,
    pilot_tol: float | None = None,
    batch: bool | None = None,
    rr_depth: int | None = None,
    max_steps: int | None = None,
    escape_radius: float | None = None,
    max_drift: float | None = None,
    chord_tolerance: float | None = None,
    segment_method: str | None = None,
    guide_training: int | None = None,
    photons: int | None = None,
    photons_per_pixel: float | None = None,
    photon_radius: float | None = None,
    retro_photons: bool | None = None,
    photon_aim: bool | None = None,
    aovs=None,
    crop=None,
    progress: Callable[[int, int], object] | None = None,
    record_pixels=None,
    denoise: bool = False,
    time_limit: float | str | None = None,
    noise_target: float | None = None,
    resume=None,
    on_pass: Callable[[PassReport], object] | None = None,
    client=None,
    tile: int | None = None,
) -> Image:
    """Path-trace a scene.

    Parameters
    ----------
    scene : str, os.PathLike, warpviz.scene.Scene or dict
        A TOML scene file (or the bare name of a shipped scene, e.g. ``"fig07"``), a loaded scene, or a
        native scene dict.
    spp : int, optional, keyword-only
        Samples per pixel to reach (default: the scene's, else 16; with ``time_limit`` or
        ``noise_target`` and no ``spp``: no limit). With ``resume``, the total, the resumed ones counted.
    width, height : int, optional, keyword-only
        Image size in pixels (default: the scene's).
    seed : int, optional, keyword-only
        Random seed; a pixel's samples depend only on (seed, pixel, sample), so the image is the same
        for any thread count.
    threads : int, keyword-only
        Worker threads; 0 uses every core.
    flat : bool, keyword-only
        Render the same scene in flat space (Minkowski) for comparison.
    paper : bool, keyword-only
        Use the scene's paper-size settings (``[render.paper]``).
    light_sampling : bool, optional, keyword-only
        False renders by brute force (no light connection), for comparison.
    max_depth : int, optional, keyword-only
        Geodesic segments per path.
    stepper : {"rk4", "dopri5", "dop853"}, optional, keyword-only
        Integrator for curved rays.
    tol : float, optional, keyword-only
        Integration tolerance.
    light_connection : {"lens", "images", "aimed"}, optional, keyword-only
        How the light strategy finds the lights in curved space. ``"lens"`` (default): where the metric
        is static and spherically symmetric (Schwarzschild, Reissner-Nordstrom, Ellis), a point is drawn
        on a light by area and one of its lensed images is chosen by its exact lens map, with the exact
        pdf; in Kerr, where every light is a quad or a disk, the Schwarzschild lens connection of the same
        mass as a proposal (exact at a = 0), its pdf evaluated where each direction's Schwarzschild orbit
        first crosses the light; elsewhere (lights of other shapes, points within 5 % of the photon sphere
        or throat, within 1.3 Schwarzschild photon-sphere radii in Kerr) Kerr's image proxies or the aimed
        proxies. ``"images"``: in Kerr, the image proxies (the Schwarzschild images of each light's centre
        refined by a pilot geodesic, the light around each mapped by the proxy map's Jacobian) everywhere
        they apply; otherwise as ``"lens"``. ``"aimed"``: the flat-space proxies aimed by pilot geodesics
        everywhere. Flat space is the same either way; every choice is unbiased.
    lens_images : int, optional, keyword-only
        Image orders the lens connection samples, 1-4 (default 3: the direct image, the one round the far
        side of the hole and the first winding; each further order is ~e^(-2 pi) dimmer, but the first
        winding lights a surface the lamp turns its back on, a ceiling above it, as much as the far side's
        image). Higher orders are found by BSDF sampling alone.
    lens_focus : bool, optional, keyword-only
        In curved space, with the lens connection: draw nine in ten of the points on a quad or disk light
        about the point of its plane straight behind the hole as seen from the vertex, where the lens
        magnifies the light without bound (an Einstein ring), as densely as a point lens magnifies them, and
        the rest uniformly by area (default True; unbiased either way). The floor under a hole with a lamp above it,
        lit by the lamp's magnified ring, is then several times less noisy (fig07's direct light: 0.6x the
        error).
    camera_light_samples : bool, optional, keyword-only
        In a static spherical metric seen by a static camera, with the lens connection and the box filter:
        in the pixels where a light's lensed image is small (a sun far away, a lamp's thin arc round a hole
        or a throat's rim), each camera sample also draws a point on a light, maps it through the exact lens
        map into the image and, where it lands in the pixel, traces that ray; weighted against the camera
        rays by the balance heuristic (default True; unbiased either way). A sub-pixel sun's pixel is then
        several times less noisy. The bright stars of a star field whose images are smaller than their
        pixel are drawn the same way. Which pixels, and which lights and stars there, follow from the scene
        alone.
    light_roulette : float, optional, keyword-only
        Curved space, with the lens connection: Russian roulette on the light samples of a path's dim
        vertices (default 0.3; 0 traces every light sample). Before its ray is traced, a light sample's
        contribution is known but for its redshift and whether it is blocked; one below ``light_roulette``
        times the largest so far on its path is traced with probability contribution / threshold and weighted
        by the inverse, so the image stays unbiased and the light samples of deep bounces and grazing light
        mostly cost no geodesic (0.3: 1.02-1.07x the efficiency of 1 in fig07 and fig10d, 8 % less error for
        2-6 % more time; benchmarks/README.md, "Light connection").
    pixel_sampler : {"sobol", "independent"}, optional, keyword-only
        Where a camera sample falls in its pixel. ``"sobol"`` (default): the pixel's Owen-scrambled Sobol
        sequence, stratified for every sample count, so edges inside a pixel (a lensed lamp, the shadow's
        rim) average out faster (fig07 room: 3.9x lower MSE at 16 spp). ``"independent"``: uniform jitter
        from the sample's random numbers (the images of warpviz before the lens connection, bit for bit
        in flat space).
    stratified_paths : bool, optional, keyword-only
        With the ``"sobol"`` pixel sampler: each bounce's light point and BSDF direction are stratified over
        the pixel's samples as its camera points are (default True): each is a pair of Owen-scrambled Sobol
        dimensions, its sample index shuffled by a nested scramble of its own so that the pairs stay
        independent of one another (padding, as Cycles and pbrt's padded sampler do). Soft shadows, a lamp's
        light over a floor and the first bounce's indirect light average out faster (48 x 36 x 16 spp: fig07's
        relative MSE 0.80x, fig10d's 0.89x, at the same speed: benchmarks/README.md). False: they are drawn
        from the sample's random numbers (the images before it, bit for bit). Unbiased either way.
    edge_samples : int, optional, keyword-only
        Pixels on the edge of a light, seen directly or in mirrors and glass, get ``edge_samples`` x
        ``spp`` samples (default 8, and 32 with ``denoise=True``: the denoiser cleans everything but the
        lights seen directly, so their edges carry most of what is left; resuming an image: its value;
        1 turns it off; at most :data:`warpviz.limits.MAX_EDGE_SAMPLES`). Where the camera sees a lamp,
        the lamp's edge inside a pixel (and a lensed lamp's thin arcs) is by far the largest noise of a
        lit room, and no light connection touches it (fig07 room: half the MSE at 16 spp in 12 of 1728
        pixels). The edge pixels are found before any sample, by camera rays through the corners, edge
        midpoints and centres of the pixels, followed through mirrors and glass (glass splits a ray into
        its reflected and refracted branch): a pixel whose nine disagree on which branches end on an
        emitter is an edge pixel, and so is one where some of a ray's branches end on one and others do
        not (a lamp reflected in a glass ball, seen by the samples that the Fresnel choice reflects; fig07
        at 640x480: half the denoised MSE), so a pixel's sample count does not depend on what its samples
        find and every pixel's mean stays unbiased. ``aovs["samples"]`` says how many each pixel got and ``stats["edge_pixels"]`` how
        many pixels got more. The edge of an emitter 64 or more times as bright as the scene's faintest one
        (a sun seen from a room its lamp lights) gets 8 times that (``stats["bright_edge_pixels"]``): its noise
        per sample grows with its radiance. Emitters narrower than half a pixel can slip between the probes;
        they are then sampled like any pixel.
    detail_samples : int, optional, keyword-only
        Pixels that hold more than one surface, seen directly or in mirrors and glass, get
        ``detail_samples`` x ``spp`` samples (default 1, and 8 with ``denoise=True``; resuming an image: its
        value; a pixel on a light's edge gets the larger of the two multiples). The denoiser rebuilds a
        surface from its albedo and normal where a pixel sees one; where it sees several (an object's
        outline, the room squeezed into thin rings round a hole's shadow, the room seen in a glass ball) it
        can only blur what the samples found, and there most of a denoised image's error is (fig10d at
        640x480 and 16 spp, 3.5 % of the pixels: x6 gives 35 % less denoised error for 14 % more time).
        Found by the same probe rays as the edge pixels (a pixel whose nine disagree on which object, or
        the sky or the hole, each of their branches ends on), so the image stays unbiased;
        ``stats["detail_pixels"]`` says how many.
    filter : {"box", "gaussian", "mitchell"}, optional, keyword-only
        Pixel reconstruction filter (default ``"box"``: each pixel averages its own square). Each camera
        sample's offset from its pixel's centre is drawn from the filter and its radiance weighted by
        filter / density (1 for box and gaussian, ±const-ish for Mitchell's negative lobes), so a pixel
        is the filter-weighted image and still depends only on its own samples (bit-identical for any
        thread count or tile). ``"gaussian"``: σ = radius / 3, truncated at the radius; ``"mitchell"``:
        Mitchell–Netravali, B = C = 1/3.
    filter_radius : float, optional, keyword-only
        Half-width of the filter's support in pixels (default :data:`FILTER_RADII`: box 0.5, gaussian
        1.5, i.e. σ = 0.5 px, mitchell 2.0).
    aim_lights : bool, optional, keyword-only
        In curved space, aim the light connection with two pilot geodesics per light and vertex so the
        sampled directions land on the lights despite bending (default True). Unbiased either way.
    light_margin : bool, optional, keyword-only
        With ``aim_lights``, enlarge the proxy each quad or disk light is sampled from by the pilots' aim
        correction relative to the light's size, at most 1.5x (default True): a lensed image is larger
        than the light, and the part of it outside the proxy is found by BSDF sampling alone, as
        fireflies. Fewer light samples reach the light, but the noise is lower. In Kerr and in a metric
        from its line element, it also grows each light the lens connection's proposal draws from by the
        metric's margin (Kerr: twice its spin length a; a line element: a twentieth of the light's size), for
        the same reason: the true images lie near the Schwarzschild ones, not on them. Unbiased either way.
    pilot_tol : float, optional, keyword-only
        Integration tolerance of those pilot geodesics (default 1e-4; never tighter than ``tol`` is
        needed). They only decide where light samples are aimed, so their accuracy changes the noise,
        never the expected image.
    rr_depth, max_steps, escape_radius, max_drift, chord_tolerance : optional, keyword-only
        Russian roulette's first segment, steps per segment, the escape radius, the largest drift of a
        conserved quantity and the chord tolerance (docs/render-options.md lists every option, its range
        and default: warpviz/options.py's table).
    segment_method : {'closed_form', 'integrate'}, optional, keyword-only
        How curved segments are traced (default ``'closed_form'``): the ray's exact orbit where the
        metric has one in closed form (Schwarzschild), else the integrator; ``'integrate'`` always steps
        the integrator, the reference the closed form is tested against (docs/architecture.md).
    guide_training : int, optional, keyword-only
        Path guiding (default 0, or the scene's: off). Before the first sample, training iterations of 1,
        2, 4, ... up to ``guide_training`` samples per point of a grid of at most 64 columns (and half the
        image's width) over the image learn, over the local observer's sky, from which directions light
        arrives indirectly at each part of the scene (off lit walls, through mirrors and glass, along every
        lensed path), and which lights reach it; half of each diffuse bounce's directions and its choice of
        light are then drawn from what they learnt, combined with BSDF sampling and the light connection
        by multiple importance sampling, so the image stays unbiased. The same tree for every pass, tile
        and resumed range (its own random numbers, from ``seed``). Where it helps and where not yet:
        benchmarks/README.md, "Path guiding" (fig12's scene turns it on).
    photons : int, optional, keyword-only
        Caustics by photons (default 0, or the scene's: off): for every sample index a photon pass of this
        many photons leaves the lights (by power, by area, cosine-weighted) as null geodesics, through
        mirrors and glass, and is stored where it first reaches a diffuse surface; each camera path gathers
        the pass of its sample at its first diffuse vertex, and the path tracer leaves those paths (a light
        reached from there through mirrors and glass only) to the photons. The gather radius shrinks pass by
        pass (probabilistic progressive photon mapping), so the image converges to the path tracer's as the
        samples grow (biased at any finite count: a caustic is slightly blurred). In flat space and static
        spherical metrics a photon is traced as the camera's backward segments are (the same spatial path);
        in Kerr and metrics from a line element it is integrated forward in time (frame dragging turns it
        the other way). A pass depends only on (seed, sample index): the same image on any threads, tiles
        and ranges.
    photons_per_pixel : float, optional, keyword-only
        More photons per pass, this many per pixel of the whole image (default 0, or the scene's), added to
        ``photons``: a photon pass's noise in a pixel falls with the photons per pixel, so a density keeps a
        scene's caustics alike at every size (the shipped lit rooms ask for 0.3: 518 photons at 48 x 36,
        92,160 at 640 x 480). A crop or a tile traces the whole image's count.
    photon_radius : float, optional, keyword-only
        The first photon pass's smallest gather radius in pixels' footprints at the gather point (default
        2.0); where photons are sparse the gather reaches to the 16th nearest one.
    retro_photons : bool, optional, keyword-only
        With photons: the passes also carry the light a hole turns back onto diffuse surfaces (a lamp's light
        that turned by more than 120 degrees on its way, round the photon orbits), and the path tracer leaves
        that light to them (default True). Round Kerr and metrics from a line element the light connection
        cannot draw it, and BSDF samples that find it speckle the ceiling above a lamp; photons bring it
        smoothly (slightly blurred, as every photon gather). Where the light connection is the exact lens
        map (static spherical metrics) it draws that light itself, and keeps it. Flat space has no such light.
    photon_aim : bool, optional, keyword-only
        With photons: each photon light's projection map, learnt before the first pass from rays along its
        emission directions, sends four in five photons where they can be stored (towards mirrors and glass,
        and with ``retro_photons`` round the hole), their flux divided by the density ratio (default True).
        In fig07 97 % of the photons were otherwise lost on the walls and in the hole, and the glass ball's
        caustic, bent round the hole onto the floor in front of it, held a third of the image's error at
        16 spp. Unbiased either way.
    batch : bool, optional, keyword-only
        In curved space, step the geodesics of many samples together in SIMD lanes (default True,
        1.5-1.9x faster). The image is bit-identical either way.
    aovs : sequence of str, optional, keyword-only
        The optional AOVs to compute, of :data:`OPTIONAL_AOVS` (default: all of them). One not asked for
        costs neither memory nor time; ``errors`` and ``samples`` are always computed.
    crop : tuple of int, optional, keyword-only
        ``(x0, y0, width, height)``: render only this window of the image (pixel ``(x0, y0)`` is its top
        left). A pixel's samples do not depend on the window, so windows that tile the image give exactly
        the pixels of the whole render: a way to render an image larger than memory in parts.
    progress : callable, optional, keyword-only
        Called about every 20 ms as ``progress(samples_done, samples_total)`` from the calling thread
        (samples of this call; with a time budget the total is projected from the speed so far).
        Raising ``KeyboardInterrupt`` in it stops the render like Ctrl-C.
    record_pixels : array_like of int, optional, keyword-only
        (K, 2) pixel coordinates (x, y) whose sampled paths are recorded into ``Image.rays``.
    denoise : bool, keyword-only
        Denoise the radiance with Intel Open Image Denoise (the optional dependency ``pyoidn``:
        ``pip install 'warpviz[denoise]'``), fed with the ``albedo`` and ``albedo_normal`` AOVs, which are
        then computed whatever ``aovs`` says (default False). ``Image.rgb`` stays the unbiased radiance;
        the denoised one is ``Image.denoised`` (:meth:`Image.denoise`).
    time_limit : float or str, optional, keyword-only
        A time budget for this call: seconds, or ``"2m"``, ``"1h30m"``. The render works in passes
        (:mod:`warpviz.render.passes`: 1, 1, 2, 4, ... samples per pixel, at most ~2 million samples a
        pass) and stops when the next pass would not fit (the last one is shrunk to fit; the first always
        runs). The image depends only on the samples per pixel reached (``metadata["spp"]``), never on
        threads or timing: a render that reached N equals ``render(spp=N)`` bit for bit.
    noise_target : float, optional, keyword-only
        Stop once the relative noise estimate (``metadata["noise"]``,
        :func:`warpviz.render.passes.noise_estimate`: the root mean variance of the pixel means over the
        mean radiance, over the lit pixels) is at most this (e.g. 0.02), checked after each pass.
    resume : str, os.PathLike or Image, optional, keyword-only
        An EXR (or its :class:`Image`) that a warpviz render wrote for the same scene and settings: its
        samples are kept and passes added from where it stopped. Checked before any work; a mismatch
        (another scene, size, seed, tolerance, ...) is a ValueError naming what differs. The result
        equals one render of the total samples to float32 rounding. The AOVs are the image's.
    on_pass : callable, optional, keyword-only
        Called after every pass with a :class:`warpviz.render.passes.PassReport` (samples per pixel
        reached, passes, seconds, time left, noise estimate).
    client : distributed.Client, optional, keyword-only
        Render on this Dask cluster (``pip install "warpviz[dask]"``; :mod:`warpviz.render.distributed`):
        each pass's tiles are tasks, and the image is bit-identical to the local render of the same samples
        per pixel, for any number of workers and any tile size. ``threads`` is then the threads of each
        task (default 1: run one single-threaded worker per core). Every worker must run this warpviz
        build (checked first, a ValueError naming the worker).
    tile : int, optional, keyword-only
        With ``client``: the tiles' side in pixels (default :data:`warpviz.render.distributed.DEFAULT_TILE`, 128;
        with photons, a tile per task slot: :func:`warpviz.render.distributed.default_tile`).

    Returns
    -------
    Image
        ``rgb`` (H, W, 3) float32 linear radiance (H, W: the crop window's size, if one is given),
        ``aovs`` (with ``variance``: (H, W, 3) the variance of each pixel mean, from its samples),
        ``stats``, ``rays``, ``error_fraction`` (the fraction of samples whose path had a geodesic that
        failed) and ``metadata`` (with ``spp`` reached, ``passes``, ``seconds``, ``noise`` and what
        stopped the render, ``stopped_by``). After Ctrl-C or SIGTERM the finished passes are returned
        with ``completed=False`` (the first pass's partial samples if none had finished).

    Raises
    ------
    ValueError
        Invalid scene or option (the message names the key).
    warpviz.render.memory.RenderTooLarge
        The render would need more memory than the machine has free (a ValueError; the message gives
        the estimate and what to do).
    warpviz.render.denoise.DenoiserMissing
        ``denoise=True`` without ``pyoidn`` installed (an ImportError naming the extra), before rendering.
    """
    native, options, source = _resolve(scene, flat=flat, width=width, height=height, paper=paper)
    if not scene_emits(native) and record_pixels is None:  # (recorded paths are worth having in the dark)
        warnings.warn(DarkSceneWarning(f"nothing in {_scene_words(source)} gives off light (no emitting object, a "
                                       "black sky): the image will be black; add a lamp (an emissive material) or "
                                       "a sky colour"), stacklevel=2)  # fmt: skip
    overrides = {"spp": spp, "seed": seed, "light_sampling": light_sampling, "max_depth": max_depth,
                 "stepper": stepper, "tol": tol, "aim_lights": aim_lights,
                 "light_connection": light_connection, "lens_images": lens_images,
                 "lens_focus": lens_focus, "camera_light_samples": camera_light_samples,
                 "light_roulette": light_roulette,
                 "pixel_sampler": pixel_sampler, "stratified_paths": stratified_paths, "edge_samples": edge_samples,
                 "detail_samples": detail_samples,
                 "filter": filter,
                 "filter_radius": filter_radius, "light_margin": light_margin, "pilot_tol": pilot_tol,
                 "batch": batch, "rr_depth": rr_depth, "max_steps": max_steps, "escape_radius": escape_radius,
                 "max_drift": max_drift, "chord_tolerance": chord_tolerance,
                 "segment_method": segment_method, "guide_training": guide_training, "photons": photons,
                 "photons_per_pixel": photons_per_pixel, "photon_radius": photon_radius,
                 "retro_photons": retro_photons, "photon_aim": photon_aim}  # fmt: skip
    for key, value in overrides.items():
        if value is not None:
            options[key] = value
    for name in OPTION_DEFAULTS:  # the one check of every option (warpviz/options.py)
        options[name] = check_option(name, options[name])
    if options["filter_radius"] is None:
        options["filter_radius"] = FILTER_RADII[options["filter"]]
    if not isinstance(denoise, (bool, np.bool_)):
        raise ValueError(f"denoise must be True or False, got {denoise!r}")
    prior = None  # the image to continue: read once, before any work
    if resume is not None:
        prior, prior_name = (resume, "the image") if isinstance(resume, Image) else (read_exr(resume), repr(str(resume)))
    for key, default in (("edge_samples", default_edge_samples), ("detail_samples", default_detail_samples)):
        if options[key] is None:  # derived: a resumed image's, else by whether the render is denoised
            saved = saved_resume(prior.metadata).get("settings") if prior is not None else None
            k = saved.get(key, IMPLIED_SETTINGS.get(key)) if isinstance(saved, dict) else None
            options[key] = k if isinstance(k, int) and not isinstance(k, bool) and k >= 1 else default(bool(denoise))
    problem = tolerance_problem(options["stepper"], options["tol"])
    if problem:
        raise ValueError(problem)
    if options["max_drift"] is None:
        options["max_drift"] = default_max_drift(options["tol"])
    options["threads"] = _positive_int("threads", threads, allow_zero=True)
    if progress is not None and not callable(progress):
        raise ValueError("progress must be a callable(done, total)")
    options["progress"] = progress
    for key, value in (("aovs", aovs), ("crop", crop)):
        if value is not None:
            options[key] = value
    options["aovs"] = _aov_names(options["aovs"])
    limited = time_limit is not None or noise_target is not None
    time_limit = None if time_limit is None else duration_seconds("time_limit", time_limit)
    noise_target = None if noise_target is None else noise_level("noise_target", noise_target)
    if on_pass is not None and not callable(on_pass):
        raise ValueError("on_pass must be a callable(PassReport)")
    if tile is not None and client is None:
        raise ValueError("tile is the tile size of a render on a Dask cluster: it needs client=")
    if client is not None:
        from warpviz.render.distributed import tile_windows

        if tile is not None:
            tile_windows((0, 0, 1, 1), tile)  # checks it
        if not hasattr(client, "submit") or not hasattr(client, "nthreads"):
            raise ValueError(f"client must be a dask.distributed.Client, got {type(client).__name__}")
    # The samples per pixel to reach: spp, or with a time budget or noise target and no spp, as many as
    # fit in the film's 32-bit counts.
    # The largest multiple of spp a pixel gets: a bright light's edge pixel's.
    _, edge, _, most = sample_multiples(options["edge_samples"], options["detail_samples"])
    bright = most // edge
    target = options["spp"] if spp is not None or not limited else MAX_SPP // most
    if target * most > MAX_SPP:
        which = "edge_samples" if options["edge_samples"] >= options["detail_samples"] else "detail_samples"
        which += f" x {bright} (a bright light's edge)" if bright > 1 else ""
        raise ValueError(f"spp x {which} must be at most {MAX_SPP} (2**31 - 1), got "
                         f"{target} x {most}; lower one of them")
    w, h = native["camera"]["width"], native["camera"]["height"]
    x0, y0, cw, ch = options["crop"] = _crop(options["crop"], w, h)
    options["record_pixels"] = _record_pixels(record_pixels, (x0, y0, cw, ch), (w, h))
    metric = _metric(native["metric"])  # validates the parameters with the metric's own messages
    metric.prepare(stepper=options["stepper"])  # a metric from its line element: its renderer, compiled once
    if native.get("lights") and not metric.is_static:
        raise ValueError(f"lights: point and spot lights need a static spacetime (flat, Schwarzschild, "
                         f"Reissner-Nordstrom, Ellis), where the lens map reaches them exactly; {metric.name} is not "
                         f"(use a small emissive sphere or disk instead)")
    settings = resume_settings(options, native)
    digest = scene_sha256(native)
    start = PassesDone(film=None, spp=0, passes=0)
    seconds_before = 0.0  # a resumed image's render time
    if prior is not None:  # checked before any work: a mismatch names what differs
        problem = resume_problem(prior, settings=settings, sha256=digest, aovs=options["aovs"] if aovs is not None else None,
                                 name=prior_name, scene=source)  # fmt: skip
        if problem:
            raise ValueError(f"resume: {problem}")
        options["aovs"] = [a for a in OPTIONAL_AOVS if a in prior.aovs]
        film = film_from_image(prior, options["aovs"])
        start = PassesDone(film=film, spp=int(prior.metadata["spp"]), passes=int(prior.metadata["resume"]["passes"]),
                           noise=float(core.film_noise(film)))  # fmt: skip
        seconds_before = float(prior.metadata.get("seconds") or 0.0)
    elif denoise:
        options["aovs"] += [a for a in DENOISE_AOVS if a not in options["aovs"]]
    if denoise:
        require_denoiser()  # before any work: a missing optional dependency is named at once
    photon_pass = core.photon_pass_bytes(options["photons"], options["photons_per_pixel"], w, h)
    check_render_memory(cw, ch, aovs=options["aovs"], image=None if (cw, ch) == (w, h) else (w, h), photons=photon_pass)

    core_options = {key: value for key, value in options.items() if key != "progress"}
    core_options["record_samples"] = options["spp"]  # a recorded pixel's paths: its first spp samples

    t0 = time.perf_counter()
    guide_segments = 0  # the segments path guiding's training traced
    passes_left = limited or start.spp < target  # (a resume to the image's own samples runs none)
    if options["guide_training"] > 0 and passes_left:  # path guiding: trained once (a one-pixel range trains the
        # whole image's tree, guide_training.h), then handed to every range, tile and pass (no photon pass for its
        # one pixel)
        trained = core.render(native, {**core_options, "spp": 1, "sample_begin": 0, "crop": [0, 0, 1, 1], "aovs": [],
                                       "edge_samples": 1, "detail_samples": 1, "record_pixels": None,
                                       "photons": 0, "photons_per_pixel": 0.0})  # fmt: skip
        if not trained["completed"]:
            raise KeyboardInterrupt
        core_options["guide"] = trained.get("guide")  # (None: nothing emits, nothing to learn)
        guide_segments = int(trained["stats"]["guide_segments"])
    trained_s = time.perf_counter() - t0

    def render_range(extra: dict) -> dict:
        raw = core.render(native, {**core_options, **extra})
        if raw.get("photon_aim") is not None:  # the photons' marks, learnt by the first range: handed to the others
            core_options["photon_aim_marks"] = raw["photon_aim"]
        return raw

    pass_samples = PASS_SAMPLES

    if client is not None:  # the same passes, each one's tiles as tasks on the cluster
        from warpviz.render.distributed import TiledPasses, check_workers, default_tile

        check_workers(client)
        core_options["threads"] = options["threads"] or 1
        if tile is None:  # (with photons: a tile per task slot, each tracing the whole image's photon passes)
            photons = options["photons"] > 0 or options["photons_per_pixel"] > 0
            tile = default_tile((cw, ch), slots=sum(client.nthreads().values()), photons=photons)
        render_range = TiledPasses(client, native, core_options, tile=tile, metric=metric)
        pass_samples = render_range.pass_samples
        if not limited:  # the passes are known: each one's successors queue behind it
            render_range.expect(start.spp, pass_plan(start.spp, npix=cw * ch, spp=target, pass_samples=pass_samples))

    done, completed, stopped_by = run_passes(
        render_range, start, npix=cw * ch, spp=target,
        seconds=None if time_limit is None else max(0.0, time_limit - trained_s), noise=noise_target,
        clock=time.perf_counter, progress=progress, on_pass=on_pass, pass_samples=pass_samples)  # fmt: skip
    film = done.film.gather(client) if hasattr(done.film, "gather") else done.film  # tiles on a cluster, gathered
    if film is None:  # stopped before the first pass had rendered anything: nothing to return
        raise KeyboardInterrupt
    resolved = core.resolve_film(film)
    if completed and progress is not None:
        total = int(resolved["samples_total"]) - (int(start.film["samples"].sum()) if start.film else 0)
        progress(total, total)
    stats = {"segments_by_status": {}, "segments": 0, "steps": 0, "seconds": 0.0, "edge_pixels": 0,
             "bright_edge_pixels": 0, "detail_pixels": 0, "threads": 0, **_plain(done.stats)}  # fmt: skip
    stats["guide_segments"] = guide_segments  # (path guiding's training, counted in "segments" too)
    stats["segments"] += guide_segments
    stats["samples"] = int(resolved["samples_total"])
    stats["samples_with_errors"] = int(resolved["errors_total"])
    error_fraction = stats["samples_with_errors"] / stats["samples"] if stats["samples"] else 0.0
    stats["error_fraction"] = error_fraction
    metadata = {
        "metric": native["metric"]["name"],
        "metric_params": list(native["metric"].get("params", [])),
        "width": native["camera"]["width"],
        "height": native["camera"]["height"],
        "spp": done.spp,
        "seed": options["seed"],
        "stepper": options["stepper"],
        "tol": options["tol"],
        "max_depth": options["max_depth"],
        "light_sampling": bool(options["light_sampling"]),
        "edge_samples": options["edge_samples"],
        "detail_samples": options["detail_samples"],
        "filter": options["filter"],
        "filter_radius": options["filter_radius"],
        "scene": source,
        "completed": bool(completed),
        "error_fraction": error_fraction,
        "passes": done.passes,
        "seconds": seconds_before + (time.perf_counter() - t0),
        "noise": None if math.isnan(done.noise) else done.noise,
        "stopped_by": stopped_by,
        "time_limit": time_limit,
        "noise_target": noise_target,
        # whole passes only: an interrupted first pass (spp 0) has pixels of different sample counts
        "resume": {"resumable": done.spp > 0, "passes": done.passes, "settings": settings, "scene_sha256": digest},
    }
    if (cw, ch) != (w, h):
        metadata["crop"] = [x0, y0, cw, ch]
    rays = _bundle(concat_rays(done.rays), metric, options) if done.rays else None
    # The AOVs in the core's order; the first-hit ones and max_drift are the film's own arrays.
    aovs_out = {}
    for name in OPTIONAL_AOVS:
        value = resolved[name] if name in resolved else film[name]
        if value is not None:
            aovs_out[name] = value
    aovs_out.update(errors=resolved["errors"], samples=resolved["samples"], variance=resolved["variance"])
    img = Image(
        rgb=resolved["rgb"],
        aovs=aovs_out,
        completed=bool(completed),
        stats=stats,
        metadata=metadata,
        rays=rays,
        native_scene=native,
    )
    return img.denoise() if denoise else img


def _aov_names(value) -> list[str]:
    """The optional AOVs asked for, checked against :data:`OPTIONAL_AOVS`."""
    if isinstance(value, str) or not all(isinstance(a, str) for a in _iterable("aovs", value)):
        raise ValueError(f"aovs must be a list of AOV names (of {', '.join(OPTIONAL_AOVS)}), got {value!r}")
    names = []
    for a in value:
        if a in ("errors", "samples", "variance"):
            continue  # always computed
        if a not in OPTIONAL_AOVS:
            raise ValueError(f"aovs: unknown AOV {a!r} (known: {', '.join(OPTIONAL_AOVS)}, errors, samples)")
        names.append(a)
    return names


def _iterable(name: str, value):
    try:
        return list(value)
    except TypeError:
        raise ValueError(f"{name} must be a list, got {value!r}") from None


def _crop(value, width: int, height: int) -> list[int]:
    """The crop window (x0, y0, w, h), checked to lie in the width x height image; None: the whole image."""
    if value is None:
        return [0, 0, width, height]
    items = _iterable("crop", value)
    if len(items) != 4 or not all(isinstance(v, (int, np.integer)) and not isinstance(v, bool) for v in items):
        raise ValueError(f"crop must be four integers (x0, y0, width, height), got {value!r}")
    x0, y0, w, h = (int(v) for v in items)
    if x0 < 0 or y0 < 0 or w < 1 or h < 1 or x0 + w > width or y0 + h > height:
        raise ValueError(f"crop {(x0, y0, w, h)} must be a window of at least one pixel inside the "
                         f"{width}x{height} image (0 <= x0, x0 + width <= {width}, 0 <= y0, y0 + height <= {height})")
    return [x0, y0, w, h]


def _record_pixels(value, crop: tuple[int, int, int, int], size: tuple[int, int]) -> np.ndarray | None:
    """record_pixels as a (K, 2) int32 array of image pixels inside the rendered window."""
    if value is None:
        return None
    arr = np.asarray(value)
    if arr.dtype.kind not in "iu" or arr.size == 0 or arr.size % 2 or (arr.ndim == 2 and arr.shape[1] != 2) or arr.ndim > 2:
        raise ValueError(f"record_pixels must be integer (x, y) pixel coordinates of shape (K, 2), got "
                         f"{arr.dtype} of shape {arr.shape}")  # fmt: skip
    pixels = arr.astype(np.int64).reshape(-1, 2)
    x0, y0, w, h = crop
    bad = (pixels[:, 0] < x0) | (pixels[:, 0] >= x0 + w) | (pixels[:, 1] < y0) | (pixels[:, 1] >= y0 + h)
    if bad.any():
        i = int(np.argmax(bad))
        where = f"the {size[0]}x{size[1]} image" if (w, h) == size else f"the crop window {tuple(crop)}"
        raise ValueError(f"record_pixels row {i}: pixel ({pixels[i, 0]}, {pixels[i, 1]}) lies outside {where}")
    return np.ascontiguousarray(pixels, dtype=np.int32)


def _metric(spec: dict):
    """The Metric of a native ``{"name", "params": [...]}`` entry."""
    return metric_from_params(spec["name"], spec.get("params", []))


class DarkSceneWarning(UserWarning):
    """A render of a scene in which nothing gives off light (:func:`warpviz.scene.native.scene_emits`)."""


def _scene_words(source: str | None) -> str:
    return f"the scene {os.path.basename(source)!r}" if source else "the scene"


def _plain(d):
    return {k: _plain(v) if isinstance(v, dict) else v for k, v in dict(d).items()}


def _resolve(scene, *, flat: bool, width, height, paper: bool) -> tuple[dict, dict, str | None]:
    """The native scene dict, the renderer options and a description of where the scene came from."""
    options = dict(DEFAULT_OPTIONS)
    if isinstance(scene, dict):
        native = native_scene(scene)  # checked (a SceneError names a missing or bad key), a new dict
        for key, value in (("width", width), ("height", height)):
            if value is not None:
                native["camera"][key] = image_side(key, value)
        if flat:
            native["metric"] = {"name": "minkowski", "params": []}
        return native, options, None
    from warpviz.scene import Scene, load_scene

    if isinstance(scene, (str, os.PathLike)):
        scene = load_scene(scene)
    if not isinstance(scene, Scene):
        raise TypeError(f"scene must be a path, a warpviz.scene.Scene or a native scene dict, not {type(scene).__name__}")
    native = scene.native(flat=flat, width=width, height=height, paper=paper)
    options.update(scene.render_settings(paper=paper))
    return native, options, str(scene.path) if scene.path is not None else None


def _bundle(raw: dict, metric, options: dict) -> RayBundle:
    """The renderer's recorded geodesic segments as a RayBundle (one 'ray' per segment)."""
    offsets = np.asarray(raw["offsets"])
    points = np.asarray(raw["points"])
    cols = np.asarray(raw["columns"])
    names = list(raw["column_names"])
    point_data = recorded_point_data(cols, names)
    n = len(offsets) - 1
    status = np.asarray(raw["status"]).astype(np.int8)
    last = np.maximum(offsets[1:] - 1, 0)
    final_positions = points[last] if len(points) else np.zeros((n, 3))

    def per_ray_max(values):
        return np.array([values[offsets[i]:offsets[i + 1]].max(initial=0.0) for i in range(n)])

    drift = {"H": per_ray_max(point_data["hamiltonian_err"])}
    drift.update({name[: -len("_drift")]: per_ray_max(point_data[name]) for name in names if name.endswith("_drift")})
    scaled = {"H": drift["H"]}
    scaled.update({name[: -len("_drift_scaled")]: per_ray_max(point_data[name])
                   for name in names if name.endswith("_drift_scaled")})  # fmt: skip
    seg = np.diff(points, axis=0) if len(points) > 1 else np.zeros((0, 3))
    final_dirs = np.zeros((n, 3))
    for i in range(n):
        if offsets[i + 1] - offsets[i] >= 2:
            v = seg[offsets[i + 1] - 2]
            norm = np.linalg.norm(v)
            final_dirs[i] = v / norm if norm > 0 else 0.0
    n_steps = np.maximum(np.diff(offsets) - 1, 0).astype(np.int64)
    return RayBundle(
        metric=metric,
        stepper=options["stepper"],
        tol=float(options["tol"]),
        status=status,
        final_positions=final_positions,
        final_directions=final_dirs,
        final_sheets=point_data["sheet"][last].astype(np.int32) if len(points) else np.ones(n, dtype=np.int32),
        n_steps=n_steps,
        invariant_drift=drift,
        invariant_drift_scaled=scaled,
        points=points,
        offsets=offsets,
        point_data=point_data,
        ray_data={
            "pixel_x": np.asarray(raw["pixel_x"]),
            "pixel_y": np.asarray(raw["pixel_y"]),
            "sample": np.asarray(raw["sample"]),
            "bounce": np.asarray(raw["bounce"]),
            "kind": np.asarray(raw["kind"]),
        },
    )
