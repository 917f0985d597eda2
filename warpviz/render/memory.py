"""How much memory a render needs, and whether the machine has it, before anything is allocated.

A render's memory grows with its pixel count: the core's film (double sums of radiance and of its
squares, sample and error counts, and the AOVs asked for), twice while a pass continues the finished
passes' film, then the float32 image and AOVs resolved from it, and the copies made while saving. :func:`render_bytes` adds these up from the film's layout (``renderer_ext/film/film.h``);
a render with caustics by photons also holds a photon pass (at most ``core.photon_pass_bytes``: every photon
stored, ``renderer_ext/integrators/render_types.h``);
:func:`check_render_memory` compares the estimate with the memory the machine has free (the smaller of
``MemAvailable`` and the process's cgroup limit, or ``WARPVIZ_MEMORY_LIMIT`` where set) and refuses, with a
:class:`RenderTooLarge` error naming the size, the estimate and what to do, a render that would not fit.

Examples
--------
>>> from warpviz.render.memory import render_bytes
>>> render_bytes(1000, 1000, aovs=())  # radiance, its variance, samples and errors: 112 bytes per pixel
112000000
>>> render_bytes(1000, 1000, aovs=("depth", "normal")) > render_bytes(1000, 1000, aovs=())
True
"""

from __future__ import annotations

import os
import re
from collections.abc import Iterable
from pathlib import Path

__all__ = ["RenderTooLarge", "render_bytes", "available_memory", "check_render_memory", "format_bytes"]

# Bytes per pixel, from renderer_ext/film/film.h and bindings/module.cpp.
#: The core's film: double sums of radiance and of its squares (24 + 24), sample and error counts (4 + 4).
_FILM = 56
#: What resolving it makes: float32 radiance and the variance of its mean (12 + 12), errors and samples
#: (4 + 4).
_IMAGE = 32
#: Each optional AOV: bytes in the film, and those its resolution adds (the first-hit AOVs and max_drift are
#: per pixel already: the image keeps the film's own arrays; the sums resolve to float32 means).
AOV_BYTES = {
    "n_steps": (8, 4),
    "max_drift": (4, 0),
    "redshift": (4, 0),
    "status": (4, 0),
    "depth": (4, 0),
    "normal": (12, 0),
    "albedo": (24, 12),
    "albedo_normal": (24, 12),
    "emission": (24, 12),
}
#: Kept free beside the estimate: the interpreter, the extension, the scene and the samples in flight.
_HEADROOM = 256 * 2**20
#: A render may use at most this fraction of the memory that is free.
_FRACTION = 0.8


class RenderTooLarge(ValueError):
    """A render would need more memory than the machine has free (bad input: exit code 2 on the CLI)."""


def render_bytes(width: int, height: int, *, aovs: Iterable[str]) -> int:
    """Peak memory, in bytes, that rendering and saving an image needs.

    Parameters
    ----------
    width, height : int
        Pixels rendered (the crop window's size, if one is given).
    aovs : iterable of str, keyword-only
        The optional AOVs computed (``n_steps``, ``max_drift``, ``redshift``, ``status``, ``depth``,
        ``normal``, ``albedo``, ``albedo_normal``, ``emission``); radiance, ``errors`` and ``samples`` are
        always kept.

    Returns
    -------
    int
        The estimate, without the fixed cost of the process (:data:`_HEADROOM` covers that).
    """
    extra = set(aovs) & set(AOV_BYTES)
    film = _FILM + sum(AOV_BYTES[a][0] for a in extra)
    image = _IMAGE + sum(AOV_BYTES[a][1] for a in extra)
    # A render in passes holds two films while a pass runs (the finished passes', kept in case it is
    # interrupted, and the one the core continues), then the film and the image resolved from it; saving
    # copies less than the film that is then freed.
    return int(width) * int(height) * max(2 * film, film + image)


def _parse_bytes(text: str) -> int:
    m = re.fullmatch(r"\s*(\d+(?:\.\d*)?)\s*([kKmMgGtT]?)i?[bB]?\s*", text)
    if not m:
        raise ValueError(f"WARPVIZ_MEMORY_LIMIT must be a size such as 4G or 512M, got {text!r}")
    scale = {"": 1, "k": 2**10, "m": 2**20, "g": 2**30, "t": 2**40}[m.group(2).lower()]
    return int(float(m.group(1)) * scale)


def _cgroup_free() -> int | None:
    """Bytes this process's cgroup still allows (v2 or v1), or None where there is no limit."""
    for limit, usage in (("memory.max", "memory.current"), ("memory/memory.limit_in_bytes", "memory/memory.usage_in_bytes")):
        try:
            cap = Path("/sys/fs/cgroup", limit).read_text().strip()
            used = Path("/sys/fs/cgroup", usage).read_text().strip()
        except OSError:
            continue
        if cap.isdigit() and used.isdigit() and int(cap) < 2**60:
            return max(0, int(cap) - int(used))
    return None


def available_memory() -> int | None:
    """Bytes of memory a render may count on now, or None where the machine does not say.

    ``WARPVIZ_MEMORY_LIMIT`` (e.g. ``4G``), where set, is used instead of what the machine reports.

    Returns
    -------
    int or None
        The smaller of ``MemAvailable`` (``/proc/meminfo``; elsewhere the free physical pages) and the
        cgroup's remaining limit.
    """
    override = os.environ.get("WARPVIZ_MEMORY_LIMIT")
    if override:
        return _parse_bytes(override)
    free = None
    try:
        for line in Path("/proc/meminfo").read_text().splitlines():
            if line.startswith("MemAvailable:"):
                free = int(line.split()[1]) * 1024
                break
    except (OSError, ValueError, IndexError):
        free = None
    if free is None:
        try:
            free = os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
        except (ValueError, OSError, AttributeError):
            free = None
    group = _cgroup_free()
    candidates = [v for v in (free, group) if v is not None]
    return min(candidates) if candidates else None


def format_bytes(n: float) -> str:
    """``n`` bytes for people: ``'1.5 GB'`` (powers of 1024)."""
    for unit in ("B", "KB", "MB", "GB", "TB"):
        if abs(n) < 1024 or unit == "TB":
            return f"{n:.0f} {unit}" if unit == "B" else f"{n:.1f} {unit}"
        n /= 1024
    raise AssertionError("unreachable")


def check_render_memory(width: int, height: int, *, aovs: Iterable[str], image: tuple[int, int] | None = None,
                        photons: tuple[int, int] = (0, 0)) -> int:
    """Refuse a render that would not fit in memory, before it allocates anything.

    Parameters
    ----------
    width, height : int
        Pixels rendered (a crop window's size, if one is given).
    aovs : iterable of str, keyword-only
        The optional AOVs computed.
    image : tuple of int, optional, keyword-only
        (width, height) of the whole image when a window of it is rendered (for the message).
    photons : tuple of int, optional, keyword-only
        A photon pass's photons and the most bytes it holds at once (``core.photon_pass_bytes``: every photon
        stored), held beside the films while a pass runs; (0, 0) without photons.

    Returns
    -------
    int
        The estimate in bytes.

    Raises
    ------
    RenderTooLarge
        The estimate exceeds ``WARPVIZ_MEMORY_LIMIT`` where set, else 80 % of the free memory less a
        fixed headroom (256 MB for the interpreter, the extension and the samples in flight).
    """
    aovs = tuple(aovs)
    n_photons, photon_bytes = (int(v) for v in photons)
    film = render_bytes(width, height, aovs=aovs)
    need = film + photon_bytes
    limited = bool(os.environ.get("WARPVIZ_MEMORY_LIMIT"))
    free = available_memory()
    if free is None:
        return need
    # A limit the user set is what the render may use; what the machine reports free is shared with the
    # process itself and everything else running, so only part of it is counted on.
    budget = free if limited else _FRACTION * max(0, free - _HEADROOM)
    if need <= budget:
        return need
    size = f"{width}x{height}" + (f" window of the {image[0]}x{image[1]} image" if image else "")
    per_pixel = need / max(1, width * height)
    fits = int((budget / per_pixel) ** 0.5)
    hints = [f"a smaller size (about {fits}x{fits} fits)"] if fits >= 1 else []
    if photon_bytes > film / 4:  # (a photon pass is the whole image's, whatever the window)
        hints.insert(0, f"fewer photons a pass (photons / photons_per_pixel: {n_photons} photons a pass may hold "
                        f"{format_bytes(photon_bytes)})")  # fmt: skip
    else:
        hints.append("rendering it in windows (tiles) with crop= / --crop")
    extra = [a for a in aovs if a in AOV_BYTES]
    if extra:
        hints.append(f"fewer AOVs (asked for: {', '.join(extra)}; a PNG needs none)")
    source = "WARPVIZ_MEMORY_LIMIT allows" if limited else "free on this machine allow"
    parts = f"{film / max(1, width * height):.0f} bytes per pixel"
    if photon_bytes:
        parts = (f"{format_bytes(film)} for its {parts} and up to {format_bytes(photon_bytes)} for a photon pass of "
                 f"{n_photons} photons")  # fmt: skip
    raise RenderTooLarge(
        f"a {size} render needs about {format_bytes(need)} ({parts}), more than the {format_bytes(free)} {source}; "
        f"use {', or '.join(hints)}"
    )
