"""The teaching view's furniture, apart from what it explains: the legend, round axis ticks and a colour
bar whose ticks are round numbers.

Pure functions (:func:`round_axes`, :func:`bar_range`) decide the numbers; :func:`draw_legend`
puts the legend into a renderer with :mod:`warpviz.viewer.layout`'s text, so its boxes can be checked.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from warpviz.viewer.layout import add_text, font_px, text_box

__all__ = ["bar_range", "decimals", "draw_legend", "legend_rows", "round_axes"]

#: The swatch drawn before each legend label (VTK's font has no box glyph; a bold dash line shows a colour).
SWATCH = "\u2014\u2014"


def _steps(span: float) -> list[float]:
    """Round steps (1, 2 or 5 × 10^k) from about span/20 to span."""
    if not (math.isfinite(span) and span > 0.0):
        return [1.0]
    k = math.floor(math.log10(span))
    return [m * 10.0**e for e in range(k - 2, k + 1) for m in (1.0, 2.0, 5.0) if m * 10.0**e <= span]


def round_axes(bounds: Sequence[float], most: int = 5) -> tuple[list[float], list[int]]:
    """Axis bounds whose evenly spaced labels are round numbers: each axis shrunk to the multiples of a
    round step inside it (so the axes box stays inside the framed scene), keeping as much of the axis as
    3 to ``most`` labels allow.

    Parameters
    ----------
    bounds : sequence of 6 float
        (xmin, xmax, ymin, ymax, zmin, zmax).
    most : int
        At most this many labels per axis.

    Returns
    -------
    bounds : list of 6 float
        The rounded bounds; an axis too short for round values keeps its own.
    labels : list of 3 int
        The number of labels per axis (one per step end), for ``show_bounds(n_xlabels=...)``.

    Examples
    --------
    >>> round_axes([-40.3, 43.1, -19.0, 3.0, 0.0, 1.0])
    ([-40.0, 40.0, -15.0, 0.0, 0.0, 1.0], [5, 4, 3])
    """
    out, labels = [], []
    for lo, hi in zip(bounds[0::2], bounds[1::2]):
        lo, hi = float(lo), float(hi)
        best = None
        for step in _steps(hi - lo):
            a, b = math.ceil(lo / step - 1e-9) * step, math.floor(hi / step + 1e-9) * step
            n = int(round((b - a) / step)) + 1
            if 3 <= n <= most and (best is None or b - a > best[1] - best[0] + 1e-12):
                best = (a, b, n)
        if best is None:
            out += [lo, hi]
            labels.append(2)
        else:
            out += [best[0] + 0.0, best[1] + 0.0]
            labels.append(best[2])
    return out, labels


def bar_range(lo: float, hi: float, *, include: Sequence[float] = (), most: int = 7) -> tuple[float, float, int]:
    """A colour bar's range widened to round ends, with the number of labels that puts one on every step:
    the narrowest such range with 3 to ``most`` labels.

    Parameters
    ----------
    lo, hi : float
        The values drawn.
    include : sequence of float
        Values the bar must show (the good drift's line).
    most : int
        At most this many labels.

    Returns
    -------
    lo, hi : float
    n_labels : int

    Examples
    --------
    >>> bar_range(-15.2, -6.7, include=[-5.0])
    (-16.0, -4.0, 7)
    """
    lo, hi = min([float(lo), *map(float, include)]), max([float(hi), *map(float, include)])
    if not (hi > lo):
        lo, hi = lo - 0.5, lo + 0.5
    best = None
    for step in _steps(2.0 * (hi - lo)):
        a, b = math.floor(lo / step + 1e-9) * step, math.ceil(hi / step - 1e-9) * step
        n = int(round((b - a) / step)) + 1
        if 3 <= n <= most and (best is None or b - a < best[1] - best[0] - 1e-12):
            best = (a, b, n)
    if best is None:
        return lo, hi, 2
    return best[0] + 0.0, best[1] + 0.0, best[2]


def decimals(step: float) -> int:
    """Digits after the point shown on labels ``step`` apart: those of the step's leading digit (0 for 5 or
    20, 1 for 0.5 or 0.2, 2 for 0.05), as the axes and the colour bar print them.

    Examples
    --------
    >>> decimals(20.0), decimals(0.5), decimals(0.05)
    (0, 1, 2)
    """
    return max(0, -math.floor(math.log10(step) + 1e-9)) if step > 0 else 0


def legend_rows(entries: Sequence[tuple[str, str]], scale: float, width_px: float) -> list[list[int]]:
    """The legend's entries flowed into rows no wider than ``width_px`` (indices into ``entries``), as
    :func:`draw_legend` lays them out."""
    size = font_px("legend", scale)
    rows: list[list[int]] = []
    used = width_px
    for i, (label, _) in enumerate(entries):
        w = _entry_width(label, size)
        if rows and used + w <= width_px:
            rows[-1].append(i)
            used += w
        else:
            rows.append([i])
            used = w
    return rows


def _entry_width(label: str, size: int) -> float:
    """Estimated width in pixels of one legend entry (swatch, label, gap) at font height ``size``."""
    return (len(SWATCH) + 0.6 + len(label) + 2.5) * 0.55 * size


def draw_legend(renderer, entries: Sequence[tuple[str, str]], *, scale: float, panel_px: tuple[int, int],
                top: float) -> list:  # fmt: skip
    """Draw the legend under the panel's title: per entry a coloured swatch and its label, flowed into rows
    (:func:`legend_rows`).

    Parameters
    ----------
    renderer : pyvista.Renderer
    entries : sequence of (str, str)
        (label, colour) per entry, in reading order.
    scale : float
        :func:`~warpviz.viewer.layout.text_scale` of the window.
    panel_px : (int, int)
        The renderer's size in pixels.
    top : float
        Normalised height of the legend's top edge.

    Returns
    -------
    list of vtkTextActor
        Swatches and labels, in pairs.
    """
    size = font_px("legend", scale)
    width, height = panel_px
    margin, gap = 8.0, 1.2 * size
    actors = []
    x, row = margin, 0
    for label, color in entries:
        swatch = add_text(renderer, SWATCH, x=0.0, y=0.0, size=size, color=color, bold=True)
        text = add_text(renderer, label, x=0.0, y=0.0, size=size, color="#202020", background="white")
        w_swatch = text_box(swatch, renderer)[1] - text_box(swatch, renderer)[0]
        w_label = text_box(text, renderer)[1] - text_box(text, renderer)[0]
        if x > margin and x + w_swatch + 0.3 * size + w_label > width - margin:  # the next row
            x, row = margin, row + 1
        y = top - row * 1.3 * size / height
        swatch.GetPositionCoordinate().SetValue(x / width, y)
        text.GetPositionCoordinate().SetValue((x + w_swatch + 0.3 * size) / width, y)
        actors += [swatch, text]
        x += w_swatch + 0.3 * size + w_label + gap
    return actors
