"""Rendering in passes: a sample budget, a time budget and a noise target, each checked between passes.

A pass renders samples ``[N, N + n)`` of every pixel (``[k N, k (N + n))`` of a pixel on a directly seen
light's edge, ``k = edge_samples`` (8 times that on the edge of a light far brighter than the faintest), or
holding detail, ``k = detail_samples``) into the film of the passes
before it (``renderer_ext``: ``render_loop.h``), whose sums the core continues in sample order. Any
split of ``[0, N)`` into passes therefore gives the image of one render of ``N`` samples per pixel, bit
for bit; a render can stop after any pass (time budget, noise target, Ctrl-C) and be resumed later from
its EXR (:mod:`warpviz.render.resume`, to float32 rounding). Which passes run depends on timing only through
*how many* samples are reached, never through what they add.

Pass sizes (:func:`standard_pass`): 1, 1, 2, 4, ... samples per pixel (doubling the samples so far, so
the first image comes at once and an interrupted render loses at most half its samples), each pass at
most :data:`PASS_SAMPLES` samples over the image. With a time budget the first pass is one sample per
pixel (to measure the speed), the pass that would not fit is shrunk to what the measured speed says
fits, and the render stops when not one more sample per pixel would (:func:`next_pass`).

Examples
--------
>>> [standard_pass(done, npix=100) for done in (0, 1, 2, 4, 8)]
[1, 1, 2, 4, 8]
>>> standard_pass(64, npix=640 * 480)  # at most PASS_SAMPLES (2**21) samples over the image
6
>>> next_pass(done=8, npix=100, spp=None, seconds_left=3.0, seconds_per_spp=1.0)  # 8 would not fit, 3 do
3
>>> next_pass(done=8, npix=100, spp=None, seconds_left=0.5, seconds_per_spp=1.0) is None  # not one sample
True
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

__all__ = ["PASS_SAMPLES", "PassReport", "standard_pass", "next_pass", "noise_estimate", "run_passes", "PassesDone",
           "add_stats", "SAMPLE_COUNTS", "concat_rays", "film_samples", "pass_plan"]  # fmt: skip

#: At most this many samples over the image in one pass (~30 s of the fig07 room at 640x480 on 2 cores):
#: Ctrl-C loses at most one pass, and a time budget is kept to within one.
PASS_SAMPLES = 1 << 21


def standard_pass(done: int, *, npix: int, pass_samples: int = PASS_SAMPLES) -> int:
    """Samples per pixel of the pass after ``done``: ``done`` (doubling the total; 1 first), at most
    ``pass_samples`` (:data:`PASS_SAMPLES`) / ``npix`` and at least 1."""
    cap = max(1, int(pass_samples) // max(1, int(npix)))
    return max(1, min(int(done), cap))


def next_pass(*, done: int, npix: int, spp: int | None, seconds_left: float | None,
              seconds_per_spp: float | None, pass_samples: int = PASS_SAMPLES) -> int | None:
    """Samples per pixel of the next pass, or None when the render is done.

    Parameters
    ----------
    done : int, keyword-only
        Samples per pixel so far.
    npix : int, keyword-only
        Pixels rendered.
    spp : int or None, keyword-only
        The samples per pixel to reach (None: no limit).
    seconds_left : float or None, keyword-only
        What is left of a time budget (None: none).
    seconds_per_spp : float or None, keyword-only
        Measured seconds per sample per pixel (None before the first pass, which always runs: with a time
        budget it is then one sample per pixel, to measure the speed).
    pass_samples : int, keyword-only
        At most this many samples over the image in one pass (a cluster's passes are larger).

    Returns
    -------
    int or None
        The standard pass, cut to reach ``spp`` exactly and shrunk to what fits in ``seconds_left``;
        None when ``spp`` is reached or not one more sample per pixel fits.
    """
    n = standard_pass(done, npix=npix, pass_samples=pass_samples)
    if spp is not None:
        if done >= spp:
            return None
        n = min(n, spp - done)
    if seconds_left is not None and seconds_per_spp is None:
        return 1  # the speed is not known yet (a resumed image's first pass here)
    if seconds_left is not None:
        fits = math.floor(seconds_left / seconds_per_spp) if seconds_per_spp > 0 else n
        if fits < 1:
            return None
        n = min(n, fits)
    return n


def noise_estimate(mean: np.ndarray, variance: np.ndarray) -> float:
    """Relative noise of an image: the root mean variance of its pixel means over the mean radiance, both
    over the lit pixels (any channel above 0) and channels.

    With the renderer's ``variance`` AOV (each pixel's sample variance over its sample count) its square
    estimates the relative MSE against the converged image over those pixels (the benchmarks' measure,
    restricted to lit pixels) for independent samples, and bounds it from above for the default stratified
    pixel positions (``pixel_sampler="sobol"``), which average a sharp edge inside a pixel faster than
    independent samples would: measured at 32 spp, the true MSE is 0.9x the estimate with independent
    samples, 0.1x in the flat room with its lamp in view (fig03) and 0.26x in fig07. A firefly that no
    sample has found yet is in neither.

    Parameters
    ----------
    mean : numpy.ndarray
        (H, W, 3) pixel means.
    variance : numpy.ndarray
        (H, W, 3) variance of each pixel mean (NaN where a pixel has fewer than two samples).

    Returns
    -------
    float
        The estimate (0 for an image with no lit pixel, NaN while a lit pixel has fewer than two samples).

    Examples
    --------
    >>> import numpy as np
    >>> m = np.zeros((1, 2, 3)); m[0, 0] = 2.0
    >>> v = np.zeros((1, 2, 3)); v[0, 0] = 0.01   # the unlit pixel's variance does not count
    >>> round(noise_estimate(m, v), 6)
    0.05
    """
    mean = np.asarray(mean, dtype=np.float64)
    lit = (mean > 0).any(axis=-1)
    if not lit.any():
        return 0.0
    var = np.asarray(variance, dtype=np.float64)[lit]
    if np.isnan(var).any():
        return math.nan
    level = float(mean[lit].mean())
    return math.sqrt(float(var.mean())) / level if level > 0 else math.inf


@dataclass(frozen=True)
class PassReport:
    """Where a render in passes stands after a pass (``render(on_pass=)``).

    Attributes
    ----------
    spp : int
        Samples per pixel reached (edge and detail pixels: ``edge_samples`` or ``detail_samples`` times as many,
        a bright light's edge pixels 8 x ``edge_samples`` times).
    passes : int
        Passes done (with those of a resumed image).
    seconds : float
        Seconds since the render started (this call).
    seconds_left : float or None
        What is left of the time budget (None: no budget).
    noise : float
        :func:`noise_estimate` (NaN before every lit pixel has two samples).
    """

    spp: int
    passes: int
    seconds: float
    seconds_left: float | None
    noise: float


@dataclass(frozen=True)
class PassesDone:
    """The state after the last finished pass: replaced whole after each pass, so an interruption sees
    either the state before a pass or after it, never half of one.

    Attributes
    ----------
    film : dict or None
        The core's film (sums and counts, numpy arrays), None before any pass.
    spp : int
        Samples per pixel in it.
    passes : int
        Passes in it.
    classes : numpy.ndarray or None
        (K,) int64: the window's pixels that get more samples (a detail, edge or bright edge pixel),
        ``4 x index + class`` (1, 2, 3; ``renderer_ext``: ``render_loop.h``, ``pixel_classes``), once a pass has
        found them.
    stats : dict
        Segment counts, steps and seconds summed over this call's passes.
    rays : list of dict
        Each pass's recorded segments (the core's raw arrays).
    noise : float
        The film's :func:`noise_estimate` (the core computes it from the sums, ``film.h: noise``).
    """

    film: dict | None
    spp: int
    passes: int
    classes: np.ndarray | None = None
    stats: dict = field(default_factory=dict)
    rays: tuple = ()
    noise: float = math.nan


#: The core's counts of what its samples did (``stats``): they add up over passes and over tiles alike.
SAMPLE_COUNTS = ("segments", "steps", "photon_segments", "light_hits", "unsampled_light_hits")


def add_stats(total: dict, add: dict, *,
              summed: tuple[str, ...] = ("seconds", *SAMPLE_COUNTS, "photon_passes", "photons_stored")) -> dict:
    """The core's statistics of two ranges (two passes, or two tiles of one pass) as one: the ``summed`` keys
    and nested counts added, the others (threads, edge and detail pixels of the same window) taken from ``add``."""
    out = dict(total)
    for key, value in add.items():
        if isinstance(value, dict):  # counts by name (segments by status): every one added
            out[key] = add_stats(total.get(key, {}), value, summed=tuple(value))
        elif key in summed:
            out[key] = total.get(key, 0) + value
        else:
            out[key] = value  # threads, (bright_)edge_pixels, detail_pixels: the same each pass
    return out


def run_passes(render_range: Callable[[dict], dict], start: PassesDone, *, npix: int, spp: int | None,
               seconds: float | None, noise: float | None, clock: Callable[[], float],
               progress: Callable[[int, int], object] | None = None,
               on_pass: Callable[[PassReport], object] | None = None,
               pass_samples: int = PASS_SAMPLES) -> tuple[PassesDone, bool, str]:
    """Render passes until a limit is reached or the render is interrupted.

    Parameters
    ----------
    render_range : callable
        ``render_range(options)`` runs the core on one range; ``options`` holds ``spp``,
        ``sample_begin``, ``film``, ``pixel_classes`` and ``progress``; it returns the core's dict
        (``film``, ``noise``, ``pixel_classes``, ``completed``, ``stats``, ``rays``).
    start : PassesDone
        The passes already done (a resumed image's, or none).
    npix : int, keyword-only
        Pixels rendered (for the pass sizes and the progress total).
    spp, seconds, noise : keyword-only
        The limits: samples per pixel to reach, seconds for this call, a :func:`noise_estimate` to
        reach; None where there is none (at least one must be given).
    clock : callable, keyword-only
        Seconds, monotonic (``time.perf_counter``); started before the call.
    progress : callable, optional, keyword-only
        ``progress(done, total)``: samples done in this call and the total expected (with a time budget,
        projected from the speed so far).
    on_pass : callable, optional, keyword-only
        Called with a :class:`PassReport` after every pass.
    pass_samples : int, keyword-only
        The largest pass in samples over the image (:func:`standard_pass`).

    Returns
    -------
    tuple
        ``(done, completed, stopped_by)``: the state after the last finished pass; False if interrupted
        (Ctrl-C, SIGTERM, ``KeyboardInterrupt`` from ``progress``); what ended it: ``"spp"``, ``"time"``,
        ``"noise"`` or ``"interrupted"``. A pass interrupted before any pass finished (in this call or
        in a resumed image) is kept: its film has a partial pass (``done.spp`` is then 0).
    """
    t0 = clock()
    state = start
    rate = None  # seconds per sample per pixel, from the last pass
    done_before = 0  # samples done in this call's finished passes
    try:
        while True:
            if noise is not None and state.noise <= noise:
                return state, True, "noise"
            left = None if seconds is None else seconds - (clock() - t0)
            n = next_pass(done=state.spp, npix=npix, spp=spp, seconds_left=left, seconds_per_spp=rate,
                          pass_samples=pass_samples)  # fmt: skip
            if n is None:
                return state, True, "spp" if spp is not None and state.spp >= spp else "time"
            t_pass = clock()

            def poll(done: int, total: int, _base=done_before, _n=n) -> object:
                if progress is None:
                    return None
                if seconds is not None and rate is not None:
                    remaining = max(0.0, seconds - (clock() - t0))
                    expected = _base + total + int(remaining / rate * npix) if rate > 0 else _base + total
                elif spp is not None:
                    expected = _base + int(total * max(1, spp - state.spp) / _n)
                else:
                    expected = _base + 2 * total
                return progress(_base + done, max(expected, _base + done))

            raw = render_range({"spp": n, "sample_begin": state.spp, "film": state.film,
                                "pixel_classes": state.classes, "progress": poll})  # fmt: skip
            if not raw["completed"]:
                if state.film is None:  # nothing finished yet: the partial pass is all there is
                    state = PassesDone(raw["film"], 0, 0, None, add_stats(state.stats, raw["stats"]),
                                       state.rays + ((raw["rays"],) if "rays" in raw else ()))  # fmt: skip
                return state, False, "interrupted"
            added = film_samples(raw["film"]) - (film_samples(state.film) if state.film is not None else 0)
            state = PassesDone(
                film=raw["film"], spp=state.spp + n, passes=state.passes + 1, classes=raw["pixel_classes"],
                stats=add_stats(state.stats, raw["stats"]),
                rays=state.rays + ((raw["rays"],) if "rays" in raw else ()),
                noise=float(raw["noise"]),
            )  # fmt: skip
            done_before += added
            rate = (clock() - t_pass) / n
            if on_pass is not None:
                elapsed = clock() - t0
                on_pass(PassReport(spp=state.spp, passes=state.passes, seconds=elapsed,
                                   seconds_left=None if seconds is None else max(0.0, seconds - elapsed),
                                   noise=state.noise))  # fmt: skip
    except KeyboardInterrupt:
        return state, False, "interrupted"


def pass_plan(done: int, *, npix: int, spp: int, pass_samples: int = PASS_SAMPLES) -> list[int]:
    """The pass sizes a render without a time budget or noise target runs from ``done`` to ``spp``.

    Examples
    --------
    >>> pass_plan(0, npix=100, spp=20)
    [1, 1, 2, 4, 8, 4]
    """
    plan = []
    while (n := next_pass(done=done, npix=npix, spp=spp, seconds_left=None, seconds_per_spp=None,
                          pass_samples=pass_samples)) is not None:  # fmt: skip
        plan.append(n)
        done += n
    return plan


def film_samples(film) -> int:
    """Samples in a film: the core's dict, or tiles kept on a cluster (:class:`warpviz.render.distributed.TileFilms`)."""
    total = getattr(film, "samples_total", None)
    return int(film["samples"].sum()) if total is None else int(total)


def concat_rays(parts) -> dict:
    """The recorded segments of several passes or tiles (the core's raw dicts) as one, in the given order."""
    parts = list(parts)
    if len(parts) == 1:
        return parts[0]
    out = {"column_names": parts[0]["column_names"]}
    offsets, base = [np.zeros(1, dtype=np.asarray(parts[0]["offsets"]).dtype)], 0
    for p in parts:
        off = np.asarray(p["offsets"])
        offsets.append(off[1:] + base)
        base += int(off[-1])
    out["offsets"] = np.concatenate(offsets)
    out["points"] = np.concatenate([np.asarray(p["points"]).reshape(-1, 3) for p in parts])
    out["columns"] = np.concatenate([np.asarray(p["columns"]) for p in parts], axis=1)
    for key in ("pixel_x", "pixel_y", "sample", "bounce", "kind", "status", "sheet"):
        out[key] = np.concatenate([np.asarray(p[key]) for p in parts])
    return out
