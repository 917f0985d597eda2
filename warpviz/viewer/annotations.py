"""What the teaching view writes beside what it draws: colourings and their colour-bar titles, which
recorded segments are shown, the title, the landmark labels and the legend.

Pure functions of a metric and of names, so the words of the view are tested without rendering. The
window (:mod:`~warpviz.viewer.window`) draws; this module says what it is called and in which colour.

Examples
--------
>>> import warpviz as wv
>>> from warpviz.viewer.annotations import landmark_labels, legend_entries, view_title
>>> view_title("fig10d", wv.Kerr(mass=1.0, spin=0.9))
'fig10d: Kerr black hole, mass M = 1, spin a/M = 0.9'
>>> landmark_labels(wv.Schwarzschild(mass=1.0))
{'horizon': 'horizon r = 2 M', 'photon_sphere': 'photon sphere r = 3 M'}
>>> landmark_labels(wv.Schwarzschild(mass=2.5))["horizon"]  # scene lengths are not in M unless M = 1
'horizon r = 2 M (5 units)'
>>> length_text(15.13, wv.EllisWormhole(throat=8.0))
'1.891 b0 (15.13 units)'
>>> [label for label, _ in legend_entries(["horizon", "camera", "rays"], wv.Schwarzschild(mass=1.0))]
['horizon', 'camera', 'light paths (colour: see the bar)']
"""

from __future__ import annotations

import math
import re
from collections.abc import Sequence

import numpy as np

from warpviz.spacetime import Metric

__all__ = [
    "COLORINGS",
    "DEFAULT_COLORING",
    "GOOD_DRIFT",
    "LEGEND_STYLE",
    "coloring_array",
    "coloring_title",
    "default_bounces",
    "landmark_labels",
    "legend_entries",
    "length_scale",
    "length_text",
    "length_unit",
    "next_coloring",
    "view_title",
    "visible_ray_ids",
]

#: The colourings one key (``c``) cycles through: name -> point array of the recorded rays.
#: ``drift`` shows the term-scaled drift (the digits each conserved quantity kept): the relative drift
#: |X - X0| / |X0| of a quantity that is small against its own terms (Lz or Q of a ray near the axis or
#: the equator) is the same rounding divided by a small number, and read 2e-5 in fig10d where every
#: quantity kept 6.4 digits.
COLORINGS = {"drift": "log10_error_scaled", "r": "r", "redshift": "redshift", "affine": "affine_param"}

#: The colouring a view starts with.
DEFAULT_COLORING = "drift"

#: A ray whose largest term-scaled drift of a conserved quantity stays below this is trustworthy. At the
#: renderer's default tolerance (1e-7 per step) the median camera ray of fig04, fig07, fig10d and fig13
#: drifts by 1e-7 to 3e-7 (measured over 192 pixels each); a ray is marked ``invariant_violation`` when
#: its term-scaled drift passes :func:`warpviz.default_max_drift` (1e-4 there).
GOOD_DRIFT = 1e-5

#: Display name and colour of every item the 3-D panel may draw, by key (the legend lists the drawn
#: ones, in drawing order). Landmarks take their label from :func:`landmark_labels`.
LEGEND_STYLE = {
    "horizon": ("horizon", "black"),
    "ergosphere": ("ergosphere", "orange"),
    "photon_sphere": ("photon sphere", "deepskyblue"),
    "throat": ("throat", "mediumpurple"),
    "our_sheet": ("our sheet", "lightsteelblue"),
    "other_sheet": ("other sheet", "lightsalmon"),
    "surfaces": ("scene objects", "tan"),
    "other_surfaces": ("objects on the other side", "sandybrown"),
    "lights": ("point and spot lights (arrow: a spot's axis)", "gold"),
    "camera": ("camera", "darkorange"),
    "rays": ("light paths (colour: see the bar)", "purple"),  # the window gives the drawn colour
    "highlight": ("selected pixel's paths", "magenta"),
    "picked": ("clicked ray", "yellow"),
    "flat_rays": ("flat-space ray (no gravity)", "lime"),
}

#: Each conserved quantity in words, for the drift colouring's title.
INVARIANT_WORDS = {"H": "the null condition", "E": "energy", "Lz": "angular momentum", "L2": "angular momentum",
                   "Q": "Carter's constant"}  # fmt: skip

_FEATURE_NAMES = {"horizon": "horizon", "ergosphere": "ergosphere", "photon_sphere": "photon sphere",
                  "throat": "throat"}  # fmt: skip


def _num(value: float) -> str:
    """A length or parameter for a label: 4 significant digits, no trailing zeros."""
    return f"{value:.4g}"


def length_scale(metric: Metric | None) -> tuple[str, float]:
    """The natural unit of a spacetime's lengths and its size in scene units: ``("M", M)`` for a
    spacetime with a mass, ``("b0", b0)`` for a wormhole (its throat radius), ``("", 1)`` for flat space.

    Scene lengths (positions, radii) are in the scene's own units; they are lengths in M only where M = 1.
    """
    if metric is None:
        return "", 1.0
    marks = metric.landmarks
    if "throat" in marks:
        return "b0", float(marks["throat"])
    if "mass" in marks and marks["mass"] > 0:
        return "M", float(marks["mass"])
    return "", 1.0


def length_text(value: float, metric: Metric | None) -> str:
    """How every label shows a length (the one place that decides it).

    Parameters
    ----------
    value : float
        A length in scene units (a radius, a distance).
    metric : Metric or None

    Returns
    -------
    str
        In the spacetime's natural unit (:func:`length_scale`), with the scene value beside it where the
        unit is not 1: ``"2 M"`` (M = 1), ``"2 M (5 units)"`` (M = 2.5), ``"1.891 b0 (15.13 units)"``
        (an Ellis wormhole of throat radius 8), ``"45 units"`` (flat space).
    """
    unit, size = length_scale(metric)
    if not unit:
        return f"{_num(value)} units"
    text = f"{_num(value / size)} {unit}"
    return text if size == 1.0 else f"{text} ({_num(value)} units)"


def length_unit(metric: Metric | None) -> str:
    """The unit of the axes and of a radius colour bar, which show scene coordinates: ``"M"`` where they
    are lengths in M (a mass of 1), else ``"units, M = 2.5"``, ``"units, b0 = 8"`` or ``"units"``."""
    unit, size = length_scale(metric)
    if unit == "M" and size == 1.0:
        return "M"
    return f"units, {unit} = {_num(size)}" if unit else "units"


def view_title(title: str, metric: Metric | None) -> str:
    """The 3-D panel's title: the view's name, the spacetime and its parameters.

    Parameters
    ----------
    title : str
        The view's short name (a scene's stem, a file's stem).
    metric : Metric or None

    Returns
    -------
    str
        e.g. ``"fig07: Schwarzschild black hole, mass M = 1"``.
    """
    if metric is None:
        return title
    marks = metric.landmarks
    name = type(metric).__name__
    if "throat" in marks:  # named after its class (the registry's): EllisWormhole -> "Ellis wormhole"
        words = re.sub(r"(?<=[a-z])(?=[A-Z])", " ", name).split()
        words = [w.lower() if w in ("Wormhole", "Black", "Hole") else w for w in words]
        what = f"{' '.join(words)}, throat radius b0 = {_num(marks['throat'])} units"
    elif metric.is_flat:
        what = f"{name} (flat space)"
    else:
        parts = []
        for key, value in metric.params.items():
            if key == "mass":
                parts.append(f"mass M = {_num(value)}")
            elif key == "spin":
                parts.append(f"spin a/M = {_num(value)}")
            else:
                parts.append(f"{key} = {_num(value)}")
        kind = "black hole" if "horizon" in marks else "spacetime"
        what = f"{name} {kind}" + (", " + ", ".join(parts) if parts else "")
    return f"{title}: {what}" if title and title != metric.name else what


def landmark_labels(metric: Metric | None) -> dict[str, str]:
    """The label of each landmark surface the metric has, by its block name in
    :func:`warpviz.metric_features` (``throat`` for an Ellis wormhole, whose embedding is drawn).

    Parameters
    ----------
    metric : Metric or None

    Returns
    -------
    dict[str, str]
        e.g. ``{"horizon": "horizon r = 2 M", "photon_sphere": "photon sphere r = 3 M"}``; radii are the
        metric's radial coordinate (areal, or Boyer–Lindquist), the ergosphere's on the equator, shown by
        :func:`length_text` (``"horizon r = 2 M (5 units)"`` where M = 2.5).
    """
    if metric is None:
        return {}
    m = metric.landmarks
    out: dict[str, str] = {}
    if "horizon" in m:
        out["horizon"] = f"horizon r = {length_text(m['horizon'], metric)}"
    if "ergosphere" in m:
        out["ergosphere"] = f"ergosphere r = {length_text(m['ergosphere'], metric)} on the equator"
    if "photon_prograde" in m and "photon_retrograde" in m:
        lo, hi = sorted((m["photon_prograde"], m["photon_retrograde"]))
        unit, size = length_scale(metric)
        both = f"{_num(lo / size)}-{_num(hi / size)} {unit}"
        out["photon_sphere"] = f"photon region r = {both}" + ("" if size == 1.0 else f" ({_num(lo)}-{_num(hi)} units)")
    elif "photon_sphere" in m:
        out["photon_sphere"] = f"photon sphere r = {length_text(m['photon_sphere'], metric)}"
    if "throat" in m:
        out["throat"] = f"throat radius b0 = {_num(m['throat'])} units"
    return out


def legend_entries(drawn: Sequence[str], metric: Metric | None,
                   colors: dict[str, str] | None = None) -> list[tuple[str, str]]:
    """The legend of the 3-D panel: one (label, colour) per drawn item, in drawing order.

    Parameters
    ----------
    drawn : sequence of str
        Keys of :data:`LEGEND_STYLE` of the items drawn now (repeats listed once).
    metric : Metric or None
        Names Kerr's photon orbits a region. The legend says what each colour is; the radii are in the
        labels beside the landmarks (:func:`landmark_labels`), so the legend stays narrow enough for
        text read from the back of a room.
    colors : dict[str, str], optional
        Colours of items drawn in other colours than :data:`LEGEND_STYLE`'s: the recorded paths, drawn
        through a colour map, are shown in the colour of their median value.

    Returns
    -------
    list of (str, str)

    Raises
    ------
    KeyError
        A key that is not in :data:`LEGEND_STYLE`.
    """
    region = metric is not None and "photon_prograde" in metric.landmarks  # Kerr: a region of orbits
    out, seen = [], set()
    for key in drawn:
        if key in seen:
            continue
        if key not in LEGEND_STYLE:
            raise KeyError(f"no legend entry for {key!r}; known: {', '.join(LEGEND_STYLE)}")
        seen.add(key)
        label, color = LEGEND_STYLE[key]
        if key == "photon_sphere" and region:
            label = "photon region"
        out.append((label, (colors or {}).get(key, color)))
    return out


def coloring_array(color_by: str, available=None) -> str:
    """The point array a colouring shows: a name of :data:`COLORINGS` or a point array's own name. Rays
    saved before ``log10_error_scaled`` existed (``available``: their point arrays) show ``log10_error``."""
    array = COLORINGS.get(color_by, color_by)
    if array == "log10_error_scaled" and available is not None and array not in available and "log10_error" in available:
        return "log10_error"
    return array


def coloring_title(color_by: str, metric: Metric | None, *, fallback: dict[str, str] | None = None) -> str:
    """The colour bar's title: the quantity shown and, for the drift, its good range.

    Parameters
    ----------
    color_by : str
        A colouring of :data:`COLORINGS` or a point array's name.
    metric : Metric or None
        Names the conserved quantities (its invariants: H, E, Lz, Q for Kerr).
    fallback : dict[str, str], optional, keyword-only
        Titles of other point arrays (e.g. :data:`warpviz.viewer.window.SCALAR_TITLES`).

    Returns
    -------
    str
    """
    array = coloring_array(color_by)
    if array in ("log10_error_scaled", "log10_error"):
        names = metric.invariant_names if metric is not None else ["H", "E", "Lz", "Q"]
        words = list(dict.fromkeys(INVARIANT_WORDS.get(n, n) for n in names if n != "H")) or ["H"]
        quantities = ", ".join(words[:-1]) + " and " + words[-1] if len(words) > 1 else words[0]
        good = round(math.log10(GOOD_DRIFT))
        which = "error" if array == "log10_error_scaled" else "relative error"  # scaled: against its terms
        return (f"how well each ray keeps {quantities}\n"
                f"log10 of the {which}: -10 is ten correct digits; good below {good}")  # fmt: skip
    if array == "r":
        return f"radius r ({length_unit(metric)})"
    if array == "redshift":
        return "redshift: frequency / frequency at the start (1 = unshifted)"
    if array == "affine_param":
        return "affine parameter along the ray"
    return (fallback or {}).get(array, array)


def next_coloring(color_by: str, available: Sequence[str] | None = None) -> str:
    """The colouring after ``color_by`` in :data:`COLORINGS` (key ``c``), skipping those whose array is
    not in ``available``; a point array outside :data:`COLORINGS` goes to the first."""
    names = [n for n in COLORINGS if available is None or COLORINGS[n] in available] or list(COLORINGS)
    key = next((n for n in COLORINGS if n == color_by or COLORINGS[n] == color_by), None)
    if key not in names:
        return names[0]
    return names[(names.index(key) + 1) % len(names)]


def default_bounces(chosen_pixels: bool) -> int | None:
    """How many bounces of each recorded path the view draws when not told: only the camera segment
    (0) for the pixels the view chose itself, every segment (None) for pixels the user recorded."""
    return 0 if chosen_pixels else None


def visible_ray_ids(bounce: np.ndarray | None, n_rays: int, max_bounce: int | None) -> np.ndarray:
    """The recorded segments drawn: those of bounce at most ``max_bounce``.

    Parameters
    ----------
    bounce : numpy.ndarray or None
        (N,) integer bounce of each segment (0 = the camera segment), or None (traced rays: all shown).
    n_rays : int
        N.
    max_bounce : int or None
        Largest bounce drawn; None draws every segment.

    Returns
    -------
    numpy.ndarray
        (K,) int64 segment indices, increasing.

    Examples
    --------
    >>> visible_ray_ids(np.array([0, 1, 2, 0, 1]), 5, 1).tolist()
    [0, 1, 3, 4]
    """
    if bounce is None or max_bounce is None:
        return np.arange(int(n_rays), dtype=np.int64)
    if int(max_bounce) < 0:
        raise ValueError(f"bounces must be >= 0, got {max_bounce}")
    return np.flatnonzero(np.asarray(bounce) <= int(max_bounce)).astype(np.int64)
