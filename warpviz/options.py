"""The render options, one row each: name, kind, default, range, whether a scene's ``[render]`` may set it,
its command-line flag and what it does. Everything else is made from this table:

* :data:`DEFAULT_OPTIONS` (:func:`warpviz.render` starts from it),
* :func:`check_option`, the one check of a value (``render()``, scene files and the command line give the
  same message with the same range),
* :data:`SCENE_OPTIONS`, the ``[render]`` keys a scene file may set (:mod:`warpviz.scene.settings` reads
  them with file:line:col errors),
* :func:`option_help`, the help text of a command-line flag (its range and default appended),
* :func:`options_markdown`, the options table of ``docs/render-options.md`` (a test keeps it current).

The core (``renderer_ext/bindings/module.cpp``) reads every row's key and has no default of its own: a
missing key is an error naming it (``tests/test_render_options.py`` removes each in turn). Adding an option
is one row here, one field of ``RenderOptions`` in ``integrators/render_types.h`` and its use.

Examples
--------
>>> from warpviz.options import DEFAULT_OPTIONS, check_option, default_edge_samples
>>> DEFAULT_OPTIONS["lens_images"]
3
>>> DEFAULT_OPTIONS["edge_samples"] is None, default_edge_samples(denoise=False), default_edge_samples(denoise=True)
(True, 8, 32)
>>> check_option("lens_images", 2)
2
>>> check_option("filter", "lanczos")
Traceback (most recent call last):
...
ValueError: filter must be one of 'box', 'gaussian', 'mitchell', got 'lanczos'
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass
from typing import Any

from warpviz.limits import MAX_EDGE_SAMPLES, MAX_SEED, MAX_SPP

__all__ = ["DEFAULT_OPTIONS", "DETAIL_SAMPLES", "DETAIL_SAMPLES_DENOISED", "EDGE_SAMPLES", "EDGE_SAMPLES_DENOISED",
           "FILTER_RADII", "RENDER_OPTIONS", "SCENE_OPTIONS", "RenderOption", "check_option", "default_detail_samples",
           "default_edge_samples", "option_help", "options_markdown"]  # fmt: skip

#: The steppers (integrators/stepper.h); warpviz.tracing.STEPPERS is this tuple.
STEPPER_NAMES = ("rk4", "dopri5", "dop853")

#: Each pixel filter's default radius (pixels): the box of the pixel itself, a gaussian of sigma 0.5 px
#: (Mitsuba's and pbrt's default) truncated at 3 sigma, and Mitchell-Netravali's usual support of 2 px.
FILTER_RADII = {"box": 0.5, "gaussian": 1.5, "mitchell": 2.0}


@dataclass(frozen=True)
class RenderOption:
    """One render option.

    Attributes
    ----------
    name : str
        Its key in ``render()``, a scene's ``[render]`` and the core's options.
    kind : {"int", "real", "bool", "choice"}
    default : Any
        None where it is derived from others (``derived`` says how).
    help : str
        What it does, in a sentence or two.
    lo, hi : float or None
        The range of an int (inclusive) or a real (``lo_open``/``hi_open``: exclusive ends).
    choices : tuple of str
        The values of a choice.
    scene : bool
        Whether a scene's ``[render]`` may set it.
    flag : str or None
        Its command-line flag, where it has one.
    derived : str
        How a default of None is made.
    """

    name: str
    kind: str
    default: Any
    help: str
    lo: float | None = None
    hi: float | None = None
    lo_open: bool = False
    hi_open: bool = False
    choices: tuple = ()
    scene: bool = True
    flag: str | None = None
    derived: str = ""

    def range_text(self) -> str:
        """The allowed values in words: ``[1, 64]``, ``(0, 1)``, ``'lens' or 'aimed'``, ``true or false``."""
        if self.kind == "bool":
            return "true or false"
        if self.kind == "choice":
            return ", ".join(repr(c) for c in self.choices)
        left, right = ("(" if self.lo_open else "["), (")" if self.hi_open else "]")
        if self.kind == "int":
            return f"[{int(self.lo)}, {int(self.hi)}]"
        hi = "inf" if self.hi is None or math.isinf(self.hi) else f"{self.hi:g}"
        return f"{left}{self.lo:g}, {hi}{right}"


RENDER_OPTIONS: tuple[RenderOption, ...] = (
    RenderOption("spp", "int", 16, "Samples per pixel.", lo=1, hi=MAX_SPP),
    RenderOption("seed", "int", 0, "Random seed: the same seed gives the same image, bit for bit, on any "
                 "number of threads.", lo=0, hi=MAX_SEED),  # fmt: skip
    RenderOption("max_depth", "int", 8, "Geodesic segments per path (bounces + 1).", lo=1, hi=10000),
    RenderOption("rr_depth", "int", 3, "Russian roulette ends paths from this segment on.", lo=1, hi=10000),
    RenderOption("light_sampling", "bool", True, "Connect each diffuse hit to the lights (false: brute-force "
                 "path tracing).", flag="--no-light-sampling"),  # fmt: skip
    RenderOption("stepper", "choice", "dopri5", "The geodesic integrator.", choices=STEPPER_NAMES),
    RenderOption("tol", "real", 1e-7, "Local error tolerance of each step (looser than trace()'s 1e-9: a pixel "
                 "averages many paths, and at 1e-7 the image error is far below the noise of any spp a frame "
                 "uses; benchmarks/README.md).", lo=0.0, hi=1.0, lo_open=True, hi_open=True),  # fmt: skip
    RenderOption("max_steps", "int", 20000, "Steps per geodesic segment before it counts as failed.", lo=1,
                 hi=10**9),  # fmt: skip
    RenderOption("escape_radius", "real", 1e3, "A ray this far from the centre has escaped to the sky.", lo=0.0,
                 hi=math.inf, lo_open=True, hi_open=True),  # fmt: skip
    RenderOption("max_drift", "real", None, "Largest term-scaled drift of a conserved quantity before a ray "
                 "counts as failed.", lo=0.0, hi=math.inf, lo_open=True, hi_open=True,
                 derived="warpviz.default_max_drift(tol)"),  # fmt: skip
    RenderOption("chord_tolerance", "real", 1e-3, "Largest distance between a step's chord and the curved ray "
                 "when the chord is tested against the scene.", lo=0.0, hi=math.inf, lo_open=True,
                 hi_open=True),  # fmt: skip
    RenderOption("segment_method", "choice", "closed_form", "How curved segments are traced: 'closed_form' "
                 "evaluates the ray's exact orbit where the metric has one (Schwarzschild: an elliptic function "
                 "of the azimuth; other metrics integrate), 'integrate' always steps the integrator (the "
                 "reference).", choices=("closed_form", "integrate")),  # fmt: skip
    RenderOption("light_connection", "choice", "lens", "How light samples find the lights in curved space: "
                 "'lens' samples every lensed image of a light (exact in Schwarzschild, Reissner-Nordstrom and "
                 "Ellis; in Kerr and in a metric from its line element that gives a mass, the Schwarzschild "
                 "connection of that mass as a proposal); 'images' uses Newton-refined image proxies instead, and "
                 "'aimed' flat-space proxies aimed by pilot geodesics, for comparison.",
                 choices=("lens", "images", "aimed"), flag="--light-connection"),  # fmt: skip
    RenderOption("lens_images", "int", 3, "Image orders the lens connection samples (1: the direct image, 2: "
                 "also round the far side, 3: also the first winding, which lights a ceiling above a lamp as much as "
                 "the far side's image; ...).", lo=1, hi=4),  # fmt: skip
    RenderOption("lens_focus", "bool", True, "Curved space, with the lens connection: draw nine in ten of a "
                 "light's points about where the hole focuses it onto the vertex (behind the centre, as densely as the "
                 "lens magnifies them; the floor under a hole with a lamp above it is lit by the lamp's magnified ring) "
                 "and the rest by area (still unbiased)."),  # fmt: skip
    RenderOption("camera_light_samples", "bool", True, "Static spherical metrics, with the lens connection: in the "
                 "pixels where a light's or a star's lensed image is small (a far sun, a thin arc round a hole, "
                 "stars) the camera draws light samples of its own through the exact lens map."),  # fmt: skip
    RenderOption("light_roulette", "real", 0.3, "Curved space, with the lens connection: Russian roulette on the "
                 "light samples of a path's dim vertices. A light sample whose contribution, as far as it is known "
                 "before its ray is traced, is below this times the largest on its path so far is traced with "
                 "probability contribution / threshold and weighted by the inverse (still unbiased); 0 traces "
                 "every one.", lo=0.0, hi=1e3),  # fmt: skip
    RenderOption("pixel_sampler", "choice", "sobol", "Where a camera sample falls in its pixel: 'sobol' "
                 "(stratified, Owen-scrambled Sobol; with stratified_paths its light points and directions too) or "
                 "'independent' (uniform jitter, and every random number independent).",
                 choices=("sobol", "independent")),  # fmt: skip
    RenderOption("stratified_paths", "bool", True, "With the 'sobol' pixel sampler: each bounce's light point and "
                 "BSDF direction are stratified over the pixel's samples too, as its camera points are (a pair of "
                 "Owen-scrambled Sobol dimensions each, shuffled apart); false: drawn independently. Unbiased "
                 "either way."),  # fmt: skip
    RenderOption("edge_samples", "int", None, "Samples per pixel, as a multiple of spp, in the pixels a light's "
                 "edge crosses, seen directly or in mirrors and glass, and those that see a light in glass by "
                 "some samples' Fresnel choice only (found by probe rays before rendering, so the image stays "
                 "unbiased); the edge of an emitter 64 or more times as bright as the scene's faintest gets 8 "
                 "times this; 1 turns it off.", lo=1, hi=MAX_EDGE_SAMPLES, flag="--edge-samples",
                 derived="8, or 32 in a denoised render (a resumed render: its image's)"),  # fmt: skip
    RenderOption("detail_samples", "int", None, "Samples per pixel, as a multiple of spp, in the pixels that "
                 "hold more than one surface, seen directly or in mirrors and glass (an outline, the squeezed "
                 "images round a hole's shadow, the room in a glass ball: detail the denoiser cannot rebuild "
                 "from its features; found by the same probe rays as the edges, so the image stays unbiased); "
                 "1 turns it off.", lo=1, hi=MAX_EDGE_SAMPLES, flag="--detail-samples",
                 derived="1, or 8 in a denoised render (a resumed render: its image's)"),  # fmt: skip
    RenderOption("guide_training", "int", 0, "Path guiding: before the first sample, training iterations of 1, "
                 "2, 4, ... up to this many samples per point of a grid over the image learn from which directions "
                 "of the local sky light arrives indirectly (off other surfaces, through mirrors and glass) at each "
                 "part of the scene, and which lights reach it, and half of every diffuse bounce's directions "
                 "and its choice of light are then drawn from what the last iteration learnt (still unbiased); "
                 "0 turns it off.", lo=0, hi=256,
                 flag="--guide-training"),  # fmt: skip
    RenderOption("photons", "int", 0, "Caustics by photons: photons traced from the lights through mirrors and "
                 "glass for every sample index (a photon pass), gathered where a camera path first meets a diffuse "
                 "surface (progressive photon mapping: the gather radius shrinks pass by pass, so the image "
                 "converges); the path tracer leaves those paths to them. Every spacetime (in Kerr and metrics from "
                 "a line element the photons are integrated forward in time); 0 turns it off.", lo=0, hi=10**8,
                 flag="--photons"),  # fmt: skip
    RenderOption("photons_per_pixel", "real", 0.0, "Caustics by photons: more photons per pass, this many per "
                 "pixel of the whole image (added to `photons`): the gather's noise follows the pixels' number, so "
                 "a scene that names a density keeps its caustics' quality at every size (the lit rooms: 0.3).",
                 lo=0.0, hi=1e3, flag="--photons-per-pixel"),  # fmt: skip
    RenderOption("photon_radius", "real", 2.0, "Caustics by photons: the first photon pass's smallest gather "
                 "radius, in pixels' footprints at the gather point (the camera path's length there times a "
                 "pixel's angle); where photons are sparse it reaches to the 16th nearest; later passes shrink "
                 "it.", lo=0.0, hi=1e4, lo_open=True),  # fmt: skip
    RenderOption("retro_photons", "bool", True, "Caustics by photons, round a hole: the photon passes also carry "
                 "the light the hole turns back onto diffuse surfaces (from a lamp, round the photon orbits, turned "
                 "by more than 120 degrees), which the path tracer then leaves to them. Round Kerr and metrics from "
                 "a line element the light connection cannot draw that light and it speckles the ceiling above a "
                 "lamp (fig10d's error -24 % at 16 spp); where the connection is the exact lens map (Schwarzschild, "
                 "Reissner-Nordstrom, Ellis) it draws that light itself and keeps it. Only with photons; flat space "
                 "has none."),  # fmt: skip
    RenderOption("photon_aim", "bool", True, "Caustics by photons: each photon light's projection map, learnt "
                 "before the first pass from rays along its emission directions, sends four in five photons where "
                 "they can be stored (towards mirrors and glass, and with retro photons round the hole), their "
                 "flux divided by the density ratio, so the caustics converge with fewer photons (fig07: 97 % of "
                 "the photons left unstored before); false sends them by the cosine alone. Unbiased either way."),  # fmt: skip
    RenderOption("filter", "choice", "box", "Pixel reconstruction filter, by importance sampling of each "
                 "camera sample's offset.", choices=tuple(FILTER_RADII)),  # fmt: skip
    RenderOption("filter_radius", "real", None, "Half-width of the filter's support in pixels.", lo=0.0,
                 hi=64.0, lo_open=True, hi_open=True, derived="0.5 (box), 1.5 (gaussian), 2 (mitchell)"),  # fmt: skip
    RenderOption("aim_lights", "bool", True, "Curved space: aim light samples with pilot geodesics."),
    RenderOption("light_margin", "bool", True, "Curved space: enlarge quad and disk light proxies by the aim's "
                 "correction (lensed images are larger); in Kerr and line elements grow the lights the lens "
                 "connection's proposal sees by the metric's margin (true images lie near the proxy's)."),  # fmt: skip
    RenderOption("pilot_tol", "real", 1e-4, "Tolerance of the pilot geodesics (at least tol; they only aim, so "
                 "they cannot bias the image).", lo=0.0, hi=1.0, lo_open=True, hi_open=True),  # fmt: skip
    RenderOption("batch", "bool", True, "Curved space: many samples' geodesics step together in SIMD lanes "
                 "(the same image either way)."),  # fmt: skip
)

_BY_NAME = {o.name: o for o in RENDER_OPTIONS}

#: ``edge_samples`` of a render that is not denoised, and of one that is. The denoiser takes the noise out of
#: everything but the lights seen directly (the ``emission`` AOV, kept out of it), so in a denoised render
#: the lights' edges carry most of the error left and are worth more samples: fig07 at 640x480, 16 spp,
#: denoised relative MSE 1.18e-3 at x8, 0.96e-3 at x32 for 4 % more time; fig10d at 8 spp 3.37e-3 -> 2.68e-3
#: at equal time. Not denoised the noise of the rest dominates and x32 loses (48x36 thumbnails: fig04 2x
#: less efficient than at x8; 640x480 fig07: equal error, 4 % more time): benchmarks/README.md, "Edge samples".
EDGE_SAMPLES = 8
EDGE_SAMPLES_DENOISED = 32


def default_edge_samples(denoise: bool) -> int:
    """``edge_samples`` where neither the call nor the scene sets it: :data:`EDGE_SAMPLES_DENOISED` for a
    render that will be denoised, else :data:`EDGE_SAMPLES`."""
    return EDGE_SAMPLES_DENOISED if denoise else EDGE_SAMPLES


#: ``detail_samples`` of a render that is not denoised, and of one that is. A denoiser rebuilds a surface
#: from its features where the pixel holds one; where it holds several (the room squeezed into the rings
#: round fig10d's shadow, the room seen in a glass ball) it can only blur what the samples found, so those
#: pixels carry most of a denoised image's error: benchmarks/README.md, "Detail samples".
DETAIL_SAMPLES = 1
DETAIL_SAMPLES_DENOISED = 8


def default_detail_samples(denoise: bool) -> int:
    """``detail_samples`` where neither the call nor the scene sets it: :data:`DETAIL_SAMPLES_DENOISED` for a
    render that will be denoised, else :data:`DETAIL_SAMPLES`."""
    return DETAIL_SAMPLES_DENOISED if denoise else DETAIL_SAMPLES


#: Every option's default (None: derived from others, see :attr:`RenderOption.derived`).
DEFAULT_OPTIONS: dict[str, Any] = {o.name: o.default for o in RENDER_OPTIONS}

#: The options a scene's ``[render]`` (and ``[render.paper]``) may set.
SCENE_OPTIONS: tuple[str, ...] = tuple(o.name for o in RENDER_OPTIONS if o.scene)


def check_option(name: str, value: Any) -> Any:
    """``value`` checked against option ``name``'s row and converted (an int, a float, a bool, a string);
    None for an option whose default is derived.

    Raises
    ------
    KeyError
        ``name`` is not an option.
    ValueError
        The value is outside the option's range, named: ``edge_samples must be an integer in [1, 64], got 0``.
    """
    o = _BY_NAME[name]
    if value is None and o.default is None:
        return None
    if o.kind == "bool":
        if type(value).__name__ not in ("bool", "bool_"):
            raise ValueError(f"{name} must be True or False, got {value!r}")
        return bool(value)
    if o.kind == "choice":
        if value not in o.choices:
            raise ValueError(f"{name} must be one of {o.range_text()}, got {value!r}")
        return str(value)
    if o.kind == "int":
        if isinstance(value, bool) or not isinstance(value, numbers.Integral) or not (o.lo <= value <= o.hi):
            raise ValueError(f"{name} must be an integer in {o.range_text()}, got {value!r}")
        return int(value)
    if isinstance(value, bool) or not isinstance(value, numbers.Real) or not math.isfinite(float(value)):
        raise ValueError(f"{name} must be a finite number in {o.range_text()}, got {value!r}")
    value = float(value)
    low = value <= o.lo if o.lo_open else value < o.lo
    high = o.hi is not None and (value >= o.hi if o.hi_open else value > o.hi)
    if low or high:
        raise ValueError(f"{name} must be in {o.range_text()}, got {value!r}")
    return value


def option_help(name: str) -> str:
    """A command-line flag's help: the option's text, its range and its default."""
    o = _BY_NAME[name]
    default = o.derived or ("on" if o.default is True else "off" if o.default is False else repr(o.default))
    allowed = "" if o.kind == "bool" else f" One of {o.range_text()}." if o.kind == "choice" else \
        f" In {o.range_text()}."  # fmt: skip
    return f"{o.help}{allowed} Default: {default} (or the scene's [render] {name})."


def options_markdown() -> str:
    """The table of docs/render-options.md: one line per option."""
    lines = ["| option | values | default | scene `[render]` | flag | what it does |", "|---|---|---|---|---|---|"]
    for o in RENDER_OPTIONS:
        default = o.derived or (str(o.default).lower() if isinstance(o.default, bool) else repr(o.default))
        lines.append(f"| `{o.name}` | {o.range_text()} | {default} | {'yes' if o.scene else 'no'} | "
                     f"{f'`{o.flag}`' if o.flag else ''} | {o.help} |")  # fmt: skip
    return "\n".join(lines) + "\n"
