"""Where the teaching view's text goes and how big it is: one place for every font size and band.

The text is sized from the window, so a view projected in a classroom is read from the back row: at the
reference window of 1400×700 pixels (two 700×700 panels) the title is 20 px high and the labels 22 px,
twice what they were, and they grow and shrink with the panel (:func:`text_scale`). Every flat text is
a ``vtkTextActor`` placed by this module, so :func:`text_box` can say where it landed on screen and the
tests can check that no two overlap.

Each panel keeps three horizontal bands: the title at the top, the content (the image, or the 3-D scene)
in the middle, and the colour bar (:data:`BAR_BOX`) or the status lines at the bottom. The 3-D camera and
the image's zoom frame the content inside the middle band.
"""

from __future__ import annotations

import textwrap
from collections.abc import Iterable, Sequence

__all__ = [
    "BAR_BOX",
    "FONT_PX",
    "REFERENCE_PANEL",
    "add_text",
    "font_px",
    "line_px",
    "overlapping",
    "place_beside",
    "text_box",
    "text_scale",
    "wrap",
]

#: Width and height (pixels) of the panel the sizes of :data:`FONT_PX` are for: half of a 1400×700 window.
REFERENCE_PANEL = (700, 700)

#: Text heights in pixels on a :data:`REFERENCE_PANEL` panel, by role.
FONT_PX = {
    "title": 20,  # the panel titles
    "help": 16,  # the keys line
    "status": 18,  # what is selected
    "label": 22,  # labels at the chosen pixels and the shadow's edge
    "label3d": 22,  # labels at points in 3-D: the landmarks, the camera
    "legend": 18,  # the 3-D panel's legend
    "axes": 16,  # the 3-D axes' tick labels and titles
    "caption": 20,  # the colour bar's words (VTK drew them at about 10 px in the colour bar's own title)
    "bar": 20,  # the colour bar's tick values
    "ticks": 16,  # the image's angle scale
}

#: The colour bar's box in the 3-D panel's normalised coordinates: (x, y, width, height); the caption
#: sits above it.
BAR_BOX = (0.12, 0.025, 0.76, 0.085)

#: Average glyph width as a fraction of the font height (the sans-serif font VTK draws in), for wrapping.
_GLYPH_WIDTH = 0.55


def text_scale(window_size: Sequence[int], panels: int = 2) -> float:
    """How much larger than on the reference panel text is drawn in a window.

    Parameters
    ----------
    window_size : (int, int)
        Window width and height in pixels.
    panels : int
        Panels side by side (2: image and 3-D, 1: 3-D only).

    Returns
    -------
    float
        The smaller of the panel's width and height ratios to :data:`REFERENCE_PANEL`, at least 0.5
        (a thumbnail window keeps readable text).
    """
    width, height = (int(v) for v in window_size)
    panel_width = width / max(1, int(panels))
    return max(0.5, min(panel_width / REFERENCE_PANEL[0], height / REFERENCE_PANEL[1]))


def font_px(role: str, scale: float) -> int:
    """The text height (pixels) of ``role`` (a key of :data:`FONT_PX`) at ``scale``."""
    return max(8, round(FONT_PX[role] * scale))


def wrap(text: str, width_px: float, size_px: int) -> str:
    """Break ``text`` into lines no wider than ``width_px`` at ``size_px`` (existing line breaks kept),
    balanced: as few lines as fit, as even as possible (no word left alone on a last line), never inside
    ``"M = 2.5"``.

    Examples
    --------
    >>> print(wrap("log10 of the error: -10 is ten correct digits; good below -5", 400, 16))
    log10 of the error: -10 is ten
    correct digits; good below -5
    """
    chars = max(12, int(width_px / (_GLYPH_WIDTH * size_px)))
    glue = "\x1f"  # holds "a = b" together; not whitespace to textwrap

    def balanced(line: str) -> list[str]:
        line = line.replace(" = ", f"{glue}={glue}")
        lines = textwrap.wrap(line, chars, break_on_hyphens=False) or [""]
        for width in range(max(1, -(-len(line) // len(lines))), chars):
            even = textwrap.wrap(line, width, break_on_hyphens=False)
            if len(even) <= len(lines):
                lines = even
                break
        return [piece.replace(glue, " ") for piece in lines]

    return "\n".join("\n".join(balanced(line)) for line in text.split("\n"))


def line_px(role: str, scale: float) -> float:
    """Height in pixels of one line of ``role`` text at ``scale`` (the font and its line gap)."""
    return 1.25 * font_px(role, scale)


def add_text(renderer, text: str, *, x: float, y: float, size: int, color="black", halign: str = "left",
             valign: str = "top", bold: bool = False, background: str | None = None, world: bool = False):  # fmt: skip
    """Put a flat text into ``renderer`` and return its ``vtkTextActor``.

    Parameters
    ----------
    renderer : pyvista.Renderer
    text : str
    x, y : float
        The anchor: in the renderer's normalised viewport coordinates (0..1), or in world coordinates
        (z = 0) with ``world=True`` (a label that moves with the picture); with ``world=True``, ``x``
        may be a 3-D point (``y`` None).
    size : int
        Text height in pixels.
    color : color-like
    halign, valign : str
        Which side of the text the anchor is on: ``left``/``centered``/``right``, ``top``/``centered``/
        ``bottom``.
    bold : bool
    background : color-like or None
        A box behind the text (0.7 opaque), for text drawn over a picture.
    world : bool

    Returns
    -------
    vtkTextActor
    """
    import pyvista as pv
    from vtkmodules.vtkRenderingCore import vtkTextActor

    actor = vtkTextActor()
    actor.SetInput(text)
    coord = actor.GetPositionCoordinate()
    if world:  # a pixel offset (0, 0 now: place_beside moves it) from a point of the world
        from vtkmodules.vtkRenderingCore import vtkCoordinate

        anchor = vtkCoordinate()
        anchor.SetCoordinateSystemToWorld()
        anchor.SetValue(*((float(v) for v in x) if y is None else (float(x), float(y), 0.0)))
        coord.SetCoordinateSystemToDisplay()
        coord.SetValue(0.0, 0.0)
        coord.SetReferenceCoordinate(anchor)
        actor._warpviz_anchor = anchor  # keep the reference alive with the actor
    else:
        coord.SetCoordinateSystemToNormalizedViewport()
        coord.SetValue(float(x), float(y))
    prop = actor.GetTextProperty()
    prop.SetFontSize(int(size))
    prop.SetColor(pv.Color(color).float_rgb)
    prop.SetBold(bool(bold))
    prop.SetJustification({"left": 0, "centered": 1, "right": 2}[halign])
    prop.SetVerticalJustification({"bottom": 0, "centered": 1, "top": 2}[valign])
    if background is not None:
        prop.SetBackgroundColor(pv.Color(background).float_rgb)
        prop.SetBackgroundOpacity(0.7)
        prop.SetFrame(False)
    actor.SetPickable(False)
    renderer.AddActor(actor)
    return actor


def place_beside(actor, renderer, taken: list, x_range: tuple[float, float], gap: float = 6.0) -> tuple:
    """Move a world-anchored text (from :func:`add_text` with ``world=True``) beside its point: the first
    of right, left, above, below, the diagonals and two lines up or down where its box stays inside
    ``x_range`` and overlaps none of ``taken`` (or the place with the fewest clashes).

    Parameters
    ----------
    actor : vtkTextActor
    renderer : vtkRenderer
    taken : list of (x0, x1, y0, y1)
        Boxes (window pixels) already placed; the chosen box is appended.
    x_range : (float, float)
        The panel's left and right edges in window pixels.
    gap : float
        Pixels between the point and the text.

    Returns
    -------
    tuple of float
        The chosen box.
    """
    prop = actor.GetTextProperty()
    prop.SetJustification(0)
    prop.SetVerticalJustification(1)
    actor.GetPositionCoordinate().SetValue(0.0, 0.0)
    x0, x1, y0, y1 = text_box(actor, renderer)
    w, h = x1 - x0, y1 - y0
    ax, ay = x0, (y0 + y1) / 2.0  # the point (left edge, middle of the box)
    candidates = [(gap, 0.0, 0), (-gap, 0.0, 2), (0.0, h, 1), (0.0, -h, 1), (gap, h, 0), (-gap, h, 2),
                  (gap, -h, 0), (-gap, -h, 2), (0.0, 2 * h, 1), (0.0, -2 * h, 1)]  # fmt: skip
    best = None
    for dx, dy, halign in candidates:
        left = ax + dx - {0: 0.0, 1: w / 2, 2: w}[halign]
        box = (left, left + w, ay + dy - h / 2, ay + dy + h / 2)
        clash = sum(bool(overlapping([("new", box), ("old", old)])) for old in taken)
        clash += 2 * ((box[0] < x_range[0] + 2) + (box[1] > x_range[1] - 2))
        if best is None or clash < best[0]:
            best = (clash, dx, dy, halign, box)
        if clash == 0:
            break
    _, dx, dy, halign, box = best
    prop.SetJustification(halign)
    actor.GetPositionCoordinate().SetValue(dx, dy)
    taken.append(box)
    return box


def text_box(actor, renderer) -> tuple[float, float, float, float]:
    """Where a text actor is drawn: (x0, x1, y0, y1) in window pixels from the lower-left corner.

    Parameters
    ----------
    actor : vtkTextActor
    renderer : vtkRenderer
        The renderer that draws it (its viewport places the text).
    """
    box = [0.0] * 4
    actor.GetBoundingBox(renderer, box)  # relative to the anchor
    ax, ay = actor.GetPositionCoordinate().GetComputedDisplayValue(renderer)
    return ax + box[0], ax + box[1], ay + box[2], ay + box[3]


def overlapping(boxes: Iterable[tuple[str, tuple[float, float, float, float]]],
                margin: float = 1.0) -> list[tuple[str, str]]:  # fmt: skip
    """Pairs of named boxes (x0, x1, y0, y1) that overlap by more than ``margin`` pixels each way."""
    items = [(name, box) for name, box in boxes if box[1] > box[0] and box[3] > box[2]]
    out = []
    for i, (a, p) in enumerate(items):
        for b, q in items[i + 1 :]:
            if min(p[1], q[1]) - max(p[0], q[0]) > margin and min(p[3], q[3]) - max(p[2], q[2]) > margin:
                out.append((a, b))
    return out
