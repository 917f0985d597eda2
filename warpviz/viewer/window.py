"""The teaching window: :class:`TeachingView`, the state of one window, the 3-D panel's drawing (landmarks,
objects, rays and their colour bar, legend) and the selection linking it to the image panel (see
:func:`warpviz.view`, which builds it).

The window's other concerns are parts of their own: :mod:`~warpviz.viewer.image_panel` (the picture, its
marks and its refinement), :mod:`~warpviz.viewer.framing` (axes, camera, label placement) and
:mod:`~warpviz.viewer.events` (clicks and keys); where text goes and how big it is,
:mod:`~warpviz.viewer.layout`.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from warpviz.scene import camera_frustum, flat_camera_ray, scene_lights, scene_surfaces
from warpviz.spacetime import has_embedding, metric_features, wormhole_embedding, wormhole_embedding_points
from warpviz.tracing import RayStatus
from warpviz.viewer.annotations import (
    COLORINGS,
    DEFAULT_COLORING,
    GOOD_DRIFT,
    LEGEND_STYLE,
    coloring_array,
    coloring_title,
    landmark_labels,
    legend_entries,
    length_text,
    next_coloring,
    view_title,
    visible_ray_ids,
)
from warpviz.viewer.callbacks import KEYS_HELP
from warpviz.viewer.decorations import bar_range, decimals, draw_legend
from warpviz.viewer.events import Events
from warpviz.viewer.framing import Framing
from warpviz.viewer.image_panel import ImagePanel
from warpviz.viewer.layout import BAR_BOX, add_text, font_px, line_px, text_box, text_scale, wrap
from warpviz.viewer.meshes import _around, _cut_lines_at, _first_points, _focus_bounds, _pixel_outlines, _surface_rgb
from warpviz.viewer.picking import pixel_for_ray, rays_for_pixel
from warpviz.viewer.view_content import ViewContent

__all__ = ["SCALAR_TITLES", "TeachingView"]

#: Scalar-bar titles of the point arrays rays can be coloured by.
SCALAR_TITLES = {
    "log10_error": "log10 drift |X-X0|/|X0| (X0~0: scaled)",
    "log10_error_scaled": "log10 drift / size of the terms (digits kept)",
    "hamiltonian_err": "|2H| / size of its terms (null condition)",
    "r": "radius r (M)",
    "affine_param": "affine parameter",
    "coord_time": "coordinate time t (M)",
    "step_size": "step size",
    "E_drift": "E drift |E-E0|/|E0|",
    "Lz_drift": "Lz drift |Lz-Lz0|/|Lz0| (term-scaled where Lz0~0)",
    "Q_drift": "Q drift |Q-Q0|/|Q0| (term-scaled where Q0~0)",
    "L2_drift": "L2 drift |L2-L2_0|/|L2_0| (term-scaled where L2_0~0)",
    "E_drift_scaled": "E drift / size of its terms",
    "Lz_drift_scaled": "Lz drift / size of its terms",
    "Q_drift_scaled": "Q drift / size of its terms",
    "L2_drift_scaled": "L2 drift / size of its terms",
    "sheet": "sheet (+1 ours, -1 other)",
}

#: log10 of double precision: smaller errors (exactly conserved, e.g. flat space) are shown as this.
_LOG10_FLOOR = -16.0

#: Opacities of the landmarks (their colours are :data:`~warpviz.viewer.annotations.LEGEND_STYLE`'s).
_FEATURE_OPACITY = {"horizon": 0.55, "ergosphere": 0.15, "photon_sphere": 0.15, "throat": 0.3}

#: The landmarks' label sits at the point of their surfaces farthest along this direction (above, a
#: little towards -y).
_LABEL_DIRECTION = (0.0, -0.3, 1.0)

_SELECTED_COLOR = LEGEND_STYLE["highlight"][1]
#: The colour map of the recorded paths (the colour bar shows its values).
_RAYS_CMAP = "plasma"
_PICKED_COLOR = LEGEND_STYLE["picked"][1]
_FLAT_COLOR = LEGEND_STYLE["flat_rays"][1]
_FRUSTUM_COLOR = LEGEND_STYLE["camera"][1]



# --------------------------------------------------------------------------------------------------
# the window


class TeachingView(ImagePanel, Framing, Events):
    """One teaching window: the image panel, the 3-D panel and the selection linking them.

    Build it with :func:`view` (``return_plotter=True`` returns the plotter; this object is its
    ``teaching_view`` attribute).

    Attributes
    ----------
    plotter : pyvista.Plotter
        The window, shape (1, 2) with an image (left, subplot (0, 0)) or (1, 1) without.
    rays : pyvista.PolyData or None
        The recorded rays, one polyline cell per ray (as :meth:`RayBundle.to_pyvista`).
    shown_rays : pyvista.PolyData or None
        The rays as drawn (for an Ellis wormhole: mapped onto the embedding diagram).
    camera : dict or None
        The native scene camera (for the frustum and the flat-space rays).
    selected : list of tuple of int
        Selected pixels (x, y).
    picked_ray : int or None
        The ray last clicked in 3-D.
    flat_visible : bool
        Whether the flat-space camera rays are drawn.
    color_by : str
        The colouring of the rays (:data:`~warpviz.viewer.annotations.COLORINGS` or a point array).
    bounces : int or None
        The largest bounce of each recorded path drawn (None: all).
    pixel_labels : dict[tuple[int, int], str]
        What each pixel the view chose shows (labelled in the image).
    labels_3d : list of (str, numpy.ndarray)
        The labels in the 3-D panel and their (3,) float64 anchor points as drawn: the landmarks with
        their radii (one line each, in one label above the outermost), the camera, the wormhole's throat
        and sheets.
    legend : list of (str, str)
        The legend's (label, colour) entries now: :func:`~warpviz.viewer.annotations.legend_entries` of
        :meth:`drawn_items`.
    """

    def __init__(self, content: ViewContent, plotter, *, color_by: str = DEFAULT_COLORING, show_flat: bool = False,
                 bounces: int | None = None):  # fmt: skip
        self.plotter = plotter
        self.title = content.title
        self.image = content.image
        self.rays = content.rays
        self.metric = content.metric
        self.camera = dict(content.camera) if content.camera is not None else None
        self.pixel_labels = dict(content.pixel_labels)
        self.source = content.source
        self.preview = dict(content.preview) if content.preview is not None else None
        self.image_samples = self.preview["spp"] if self.preview is not None else None
        self.refiner = None
        self.selected: list[tuple[int, int]] = []
        self.picked_ray: int | None = None
        self.flat_visible = bool(show_flat)
        self.color_by = str(color_by)
        self.bounces = None if bounces is None else int(bounces)
        if self.bounces is not None and self.bounces < 0:
            raise ValueError(f"bounces must be >= 0 (0: camera segments only), got {bounces}")
        self._embedding = self.metric is not None and has_embedding(self.metric)  # a static spherical wormhole
        self._image_renderer = None
        self._image_actor = None
        self._rays_actor = None
        self._rays_color = LEGEND_STYLE["rays"][1]
        self._bar_title: str | None = None
        self._caption_lines = 0
        self._good_mark = None  # the colour bar's mark of the good drift
        self._fit_points = None
        self.title_text = ""
        self._press: tuple[int, int] | None = None
        self._named_actors: dict[str, Any] = {}
        self._drawn: list[str] = []  # legend keys of the fixed items, in drawing order
        self.legend: list[tuple[str, str]] = []

        has_image = self.image is not None
        self.image_edge_label: str | None = None  # the exact shadow's (window's) label, where drawn
        self._text_actors: dict[str, list] = {}  # flat texts by role, per panel: for text_boxes()
        self._scale = text_scale(plotter.window_size, panels=2 if has_image else 1)
        scene_col = 1 if has_image else 0
        self._scene_col = scene_col
        if has_image:
            plotter.subplot(0, 0)
            self._image_renderer = plotter.renderer
            self._draw_image()
        plotter.subplot(0, scene_col)
        self._scene_renderer = plotter.renderer
        self.shown_rays = self._draw_scene(content)
        self._install_events()
        self.refresh()

    # ---------------------------------------------------------------- drawing

    def _panel_px(self, renderer) -> tuple[int, int]:
        """A panel's size in pixels."""
        x0, y0, x1, y1 = renderer.GetViewport()
        width, height = self.plotter.window_size
        return max(1, round((x1 - x0) * width)), max(1, round((y1 - y0) * height))

    def _text(self, renderer, role: str, text: str, **place):
        """A flat text of ``role`` (a :data:`~warpviz.viewer.layout.FONT_PX` key) in ``renderer``,
        kept for :meth:`text_boxes`."""
        actor = add_text(renderer, text, size=font_px(role, self._scale), **place)
        self._text_actors.setdefault(role, []).append((renderer, actor))
        return actor

    def text_boxes(self) -> list[tuple[str, tuple[float, float, float, float]]]:
        """Where every flat text is drawn now: (role, (x0, x1, y0, y1)) in window pixels, for checking
        that nothing overlaps (the landmarks' 3-D labels move with the scene and are not among them)."""
        out = []
        for role, items in self._text_actors.items():
            for renderer, actor in items:
                if actor.GetVisibility() and actor.GetInput():
                    out.append((role, text_box(actor, renderer)))
        return out

    def _embed_surfaces(self, surfaces, reach: float):
        """The scene's shapes laid on the embedding diagram (each point on its shape's sheet), without the
        cells that reach farther than ``reach`` from the centre (a distant sun would shrink the diagram to
        a dot)."""
        from vtkmodules.util.numpy_support import vtk_to_numpy

        mesh = surfaces.copy()
        cell_sheet = np.asarray(mesh.cell_data["sheet"], dtype=np.float64)
        point_sheet = np.ones(mesh.n_points)
        polys = mesh.GetPolys()  # the shapes are triangles and quads: each point takes its cell's sheet
        offsets = vtk_to_numpy(polys.GetOffsetsArray())
        point_sheet[vtk_to_numpy(polys.GetConnectivityArray())] = np.repeat(cell_sheet, np.diff(offsets))
        points = np.asarray(mesh.points, dtype=np.float64)
        near = np.linalg.norm(points, axis=1) <= reach
        mesh.points = self._embed(points, np.where(point_sheet < 0, -1, 1))
        if not near.all():
            mesh = mesh.extract_points(near, adjacent_cells=False)
        return mesh

    def _draw_scene(self, content: ViewContent):
        import pyvista as pv

        p = self.plotter
        drawn = self._drawn
        focus = []
        labels = landmark_labels(self.metric)
        label_points, label_texts = [], []
        landmark_lines, landmark_tops = [], []
        features = dict(content.features) or (metric_features(self.metric) if self.metric is not None else {})
        for name, mesh in features.items():
            if name == "embedding":
                sheet = np.asarray(mesh.point_data["sheet"]) if "sheet" in mesh.point_data else np.ones(mesh.n_points)
                p.add_mesh(mesh, scalars=np.where(sheet > 0, 0.0, 1.0),
                           cmap=[LEGEND_STYLE["our_sheet"][1], LEGEND_STYLE["other_sheet"][1]],
                           clim=(0, 1), opacity=0.45, smooth_shading=True, specular=0.3, show_scalar_bar=False,
                           pickable=False, name="embedding")  # fmt: skip
                grid = wormhole_embedding(self.metric, resolution=24) if self._embedding else mesh
                p.add_mesh(grid, style="wireframe", color="slategray", opacity=0.5, line_width=1, lighting=False,
                           pickable=False, name="embedding_grid")  # fmt: skip
                waist_radius = (self.metric.landmarks["throat"] if self._embedding
                                else float(np.min(np.linalg.norm(mesh.points[:, :2], axis=1))))  # fmt: skip
                waist = pv.Polygon(center=(0.0, 0.0, 0.0), radius=waist_radius, normal=(0, 0, 1), n_sides=96,
                                   fill=False)  # fmt: skip
                p.add_mesh(waist, color=LEGEND_STYLE["throat"][1], line_width=3, pickable=False, name="waist")
                drawn += ["our_sheet", "other_sheet", "throat"]
                if "throat" in labels:
                    label_points.append((waist_radius, 0.0, 0.0))
                    label_texts.append(labels["throat"])
                zs = np.asarray(mesh.points)[:, 2]
                rim = float(np.max(np.linalg.norm(np.asarray(mesh.points)[:, :2], axis=1)))
                label_points += [(0.0, -rim, float(zs.max())), (0.0, -rim, float(zs.min()))]
                label_texts += [LEGEND_STYLE["our_sheet"][0], LEGEND_STYLE["other_sheet"][0] + " (through the throat)"]
                focus.append(mesh)
                continue
            if name == "throat" and "embedding" in features:  # drawn as the waist of the embedding diagram
                continue
            color = LEGEND_STYLE.get(name, ("", "gray"))[1]
            p.add_mesh(mesh, color=color, opacity=_FEATURE_OPACITY.get(name, 0.2), pickable=False, smooth_shading=True,
                       name=name)  # fmt: skip
            if name in LEGEND_STYLE:
                drawn.append(name)
            if name in labels and mesh.n_points:
                landmark_lines.append(labels[name])
                landmark_tops.append(np.asarray(mesh.points, dtype=np.float64))
            focus.append(mesh)
        if landmark_lines:  # one box of lines above the outermost landmark: nested surfaces' labels would overlap
            tops = np.concatenate(landmark_tops)
            label_points.append(tops[int(np.argmax(tops @ np.asarray(_LABEL_DIRECTION)))])
            label_texts.append("\n".join(landmark_lines))

        surfaces = content.surfaces
        if surfaces is None and content.native_scene is not None and content.native_scene.get("shapes"):
            surfaces = scene_surfaces(content.native_scene)
        if surfaces is not None and surfaces.n_cells:
            surfaces.cell_data["display_rgb"] = _surface_rgb(surfaces, content.native_scene)
            if self._embedding and "sheet" in surfaces.cell_data:  # both sides of the throat, on the diagram
                rim = max((float(np.max(np.linalg.norm(np.asarray(m.points)[:, :2], axis=1)))
                           for m in focus if m.n_points), default=0.0)  # fmt: skip
                reach = max(rim, 1.25 * float(np.linalg.norm(self.camera["position"])) if self.camera else 0.0)
                shown_surfaces = self._embed_surfaces(surfaces, reach)
                sheets = np.asarray(shown_surfaces.cell_data["sheet"])
                drawn += (["surfaces"] if (sheets > 0).any() else []) + (["other_surfaces"] if (sheets < 0).any() else [])
                if shown_surfaces.n_cells:
                    p.add_mesh(shown_surfaces, scalars="display_rgb", rgb=True, opacity=0.8, show_scalar_bar=False,
                               pickable=False, name="surfaces")  # fmt: skip
                    focus.append(shown_surfaces)
            elif not self._embedding:
                p.add_mesh(surfaces, scalars="display_rgb", rgb=True, opacity=0.3, show_scalar_bar=False,
                           pickable=False, name="surfaces")  # fmt: skip
                drawn.append("surfaces")
                focus.append(surfaces)

        lights = content.lights
        if lights is None and content.native_scene is not None:
            lights = scene_lights(content.native_scene)
        if lights is not None and lights.n_points:
            self._draw_lights(p, lights, focus)
            drawn.append("lights")

        if self.camera is not None:
            position = np.asarray(self.camera["position"], dtype=np.float64)
            if self._embedding:
                pos = self._embed(position[None, :], self.camera.get("sheet", 1))
                marker = pv.PolyData(pos)
                p.add_mesh(marker, color=_FRUSTUM_COLOR, point_size=12, render_points_as_spheres=True,
                           pickable=False, name="camera")  # fmt: skip
                focus.append(marker)
                label_points.append(pos[0])
            else:
                frustum = camera_frustum(self.camera)
                p.add_mesh(frustum, color=_FRUSTUM_COLOR, line_width=2, pickable=False, name="camera")
                focus.append(frustum)
                label_points.append(position)
            distance = float(np.linalg.norm(position))
            label_texts.append(f"camera, {length_text(distance, self.metric)} from the centre")
            drawn.append("camera")

        shown = None
        starts = None
        if self.rays is not None and self.rays.n_cells:
            shown = self.rays.copy()
            if self._embedding and "sheet" in shown.point_data:
                shown.points = wormhole_embedding_points(self.metric, shown.points, shown.point_data["sheet"])
                rims = [float(np.max(np.hypot(*np.asarray(m.points)[:, :2].T))) for m in focus if m.n_points]
                if rims:  # rays leaving for infinity end a little beyond the diagram's rim
                    shown = _cut_lines_at(shown, 1.15 * max(rims))
            array = coloring_array(self.color_by, shown.point_data.keys())
            if array not in shown.point_data:
                raise ValueError(f"color_by={self.color_by!r} is not a colouring ({', '.join(COLORINGS)}) or a point "
                                 f"array of the rays; available: {', '.join(sorted(shown.point_data.keys()))}")  # fmt: skip
            self.shown_rays = shown
            self._draw_rays()
            starts = None if self.camera is not None else _first_points(shown)
            drawn.append("rays")
        self.labels_3d = [(text, np.asarray(point, dtype=np.float64)) for text, point in zip(label_texts, label_points)]
        if label_points:  # a dot at each anchor, the text beside it (on the side with room: _justify_labels)
            p.add_mesh(pv.PolyData(np.asarray(label_points, dtype=np.float64)), color="white", point_size=7,
                       render_points_as_spheres=True, pickable=False, name="landmark_points")  # fmt: skip
            for text, point in self.labels_3d:
                padded = "\n".join(f" {line} " for line in text.split("\n"))  # clear of the dot
                self._text(self._scene_renderer, "label3d", padded, x=point, y=None, world=True, bold=True,
                           background="#c8c8c8", valign="centered")  # fmt: skip
        renderer = self._scene_renderer
        panel_w, panel_h = self._panel_px(renderer)
        self.title_text = self._wrap_title(view_title(self.title, self.metric))
        self._text(renderer, "title", self.title_text, x=0.012, y=0.988)
        if self._image_renderer is None:  # one panel: the status lines go under the title
            lines = self.title_text.count("\n") + 1
            top = 0.988 - (lines * line_px("title", self._scale) + 4) / panel_h
            self._text(renderer, "help", KEYS_HELP, x=0.012, y=top, color="#404040")
            self._status_actor = self._text(renderer, "status", "", x=0.012,
                                            y=top - line_px("help", self._scale) / panel_h)  # fmt: skip

        self._focus = _focus_bounds(focus)
        points = [np.asarray(m.points, dtype=np.float64) for m in focus if m.n_points]
        self._fit_points = np.concatenate(points)[:: max(1, sum(map(len, points)) // 4000)] if points else None
        if shown is not None and self.camera is None:  # traced rays: the landmarks and where the rays start
            self._focus = _around(self._focus, starts) if self._focus is not None else _focus_bounds([shown])
        self._draw_axes()
        self._set_3d_camera()
        return shown

    def _draw_rays(self) -> None:
        """(Re)draw the rays of the shown bounces, coloured by :attr:`color_by`, with their colour bar."""
        p = self.plotter
        shown = self.shown_rays
        array = coloring_array(self.color_by, shown.point_data.keys())
        bounce = np.asarray(shown.cell_data["bounce"]) if "bounce" in shown.cell_data else None
        self._visible = visible_ray_ids(bounce, shown.n_cells, self.bounces)
        mesh = shown.extract_cells(self._visible)
        values = np.asarray(mesh.point_data[array], dtype=np.float64) if mesh.n_points else np.zeros(0)
        finite = values[np.isfinite(values)]
        lo, hi = (float(finite.min()), float(finite.max())) if finite.size else (0.0, 1.0)
        drift = array in ("log10_error", "log10_error_scaled")
        if drift:
            lo, hi = max(lo, _LOG10_FLOOR), max(hi, _LOG10_FLOOR)
        lo, hi, n_labels = bar_range(lo, hi, include=[math.log10(GOOD_DRIFT)] if drift else [])
        shown_as = array if self.color_by in COLORINGS else self.color_by  # old rays: their log10_error
        title = coloring_title(shown_as, self.metric, fallback=SCALAR_TITLES)
        p.subplot(0, self._scene_col)  # the colour bar goes into the 3-D panel
        if self._bar_title is not None and self._bar_title in p.scalar_bars:
            p.remove_scalar_bar(self._bar_title, render=False)
        for renderer, actor in self._text_actors.pop("caption", []):
            renderer.RemoveActor(actor)
        if self._good_mark is not None:
            self._scene_renderer.RemoveActor(self._good_mark)
            self._good_mark = None
        if self._rays_actor is not None:
            self._scene_renderer.remove_actor(self._rays_actor, reset_camera=False, render=False)
            self._rays_actor = None
        if not mesh.n_cells:
            self._bar_title = None
            return
        # the legend's swatch: the colour map at the drawn values' median (they are drawn through it)
        from matplotlib import colormaps
        from matplotlib.colors import to_hex

        middle = float(np.median(finite)) if finite.size else lo
        self._rays_color = to_hex(colormaps[_RAYS_CMAP](min(1.0, max(0.0, (middle - lo) / (hi - lo)))))
        x, y, width, height = BAR_BOX
        step = (hi - lo) / max(1, n_labels - 1)
        digits = decimals(step)
        self._rays_actor = p.add_mesh(
            mesh, scalars=array, cmap=_RAYS_CMAP, clim=(lo, hi), line_width=2, lighting=False, name="rays",
            reset_camera=False,
            scalar_bar_args={"title": title, "vertical": False, "position_x": x, "position_y": y, "width": width,
                             "height": height, "label_font_size": font_px("bar", self._scale), "n_labels": n_labels,
                             "fmt": f"%.{digits}f", "unconstrained_font_size": True},
        )  # fmt: skip
        self._bar_title = title
        bar = p.scalar_bars[title]
        bar.GetTitleTextProperty().SetOpacity(0.0)  # the caption below says it, where its box is known
        bar.SetTextPositionToSucceedScalarBar()  # tick values above the bar, under the caption
        if drift:  # the good line on the bar: a mark at log10(GOOD_DRIFT)
            at = x + width * (math.log10(GOOD_DRIFT) - lo) / (hi - lo)
            self._good_mark = _bar_mark(self._scene_renderer, at, y, y + height)
        panel_w, panel_h = self._panel_px(self._scene_renderer)
        caption = wrap(title, panel_w - 24, font_px("caption", self._scale))
        self._caption_lines = caption.count("\n") + 1
        self._text(self._scene_renderer, "caption", caption, x=0.5, y=y + height + 4.0 / panel_h,
                   halign="centered", valign="bottom", background="white")  # fmt: skip

    def cycle_coloring(self, color_by: str | None = None) -> str:
        """Colour the rays by the next colouring of :data:`~warpviz.viewer.annotations.COLORINGS` (key
        ``c``), or by ``color_by``.

        Returns
        -------
        str
            The colouring now shown.
        """
        if self.shown_rays is None:
            return self.color_by
        available = list(self.shown_rays.point_data.keys())
        target = next_coloring(self.color_by, available) if color_by is None else str(color_by)
        if coloring_array(target, available) not in available:
            raise ValueError(f"color_by={target!r} is not a colouring ({', '.join(COLORINGS)}) or a point array "
                             f"of the rays; available: {', '.join(sorted(available))}")  # fmt: skip
        self.color_by = target
        self._draw_rays()
        self.refresh()
        return self.color_by

    def show_bounces(self, bounces: int | None = -1) -> int | None:
        """Draw the recorded segments up to bounce ``bounces`` (None: all); the default ``-1`` shows one
        bounce more than now, and all of them after the last (key ``n``: bounces on demand).

        Returns
        -------
        int or None
            The largest bounce drawn now (None: all).
        """
        if self.shown_rays is None:
            return self.bounces
        deepest = (int(np.max(self.shown_rays.cell_data["bounce"])) if "bounce" in self.shown_rays.cell_data
                   and self.shown_rays.n_cells else 0)  # fmt: skip
        if bounces == -1:
            if self.bounces is None:
                bounces = 0
            else:
                bounces = self.bounces + 1 if self.bounces < deepest else None
        elif bounces is not None and int(bounces) < 0:
            raise ValueError(f"bounces must be >= 0 or None, got {bounces}")
        self.bounces = None if bounces is None else int(bounces)
        self._draw_rays()
        self.refresh()
        return self.bounces

    def _draw_lights(self, p, lights, focus: list) -> None:
        """Point and spot lights (never hit, so no surface shows them) as gold balls, each spot with an arrow
        along its axis a tenth of the drawn scene's size long; on a wormhole's embedding diagram, the balls."""
        import pyvista as pv

        color = LEGEND_STYLE["lights"][1]
        shown = lights
        if self._embedding:
            sheets = lights.point_data["sheet"] if "sheet" in lights.point_data else 1
            shown = pv.PolyData(self._embed(np.asarray(lights.points, dtype=np.float64), sheets))
        p.add_mesh(shown, color=color, point_size=14, render_points_as_spheres=True, pickable=False, name="lights")
        focus.append(shown)
        spots = np.asarray(lights.point_data["spot"]) == 1 if "spot" in lights.point_data else np.zeros(0, bool)
        if self._embedding or not spots.any():
            return
        sizes = [m.length for m in focus if m.n_points > 1]
        axes = pv.PolyData(np.asarray(lights.points, dtype=np.float64)[spots])
        axes.point_data["direction"] = np.asarray(lights.point_data["direction"])[spots]
        arrows = axes.glyph(orient="direction", scale=False, factor=0.1 * max(sizes, default=1.0), geom=pv.Arrow())
        p.add_mesh(arrows, color=color, pickable=False, name="light_axes")

    def _embed(self, points: np.ndarray, sheet) -> np.ndarray:
        sheets = np.broadcast_to(np.asarray(sheet), (points.shape[0],))
        return wormhole_embedding_points(self.metric, points, sheets)

    # ---------------------------------------------------------------- progressive image

    # ---------------------------------------------------------------- selection

    def select_pixels(self, pixels) -> None:
        """Select pixels and highlight their recorded paths.

        Parameters
        ----------
        pixels : array_like, shape (K, 2)
            (x, y) pixel coordinates; empty clears the selection.
        """
        rows = np.asarray(pixels, dtype=np.int64).reshape(-1, 2)
        self.selected = [(int(x), int(y)) for x, y in rows]
        self.picked_ray = None
        self.refresh()

    def select_pixel(self, x: int, y: int) -> np.ndarray:
        """Select one pixel; returns the indices of its recorded rays, shape (K,) int64."""
        self.select_pixels([[x, y]])
        return self.selected_rays()

    def select_ray(self, i: int) -> tuple[int, int] | None:
        """Select a ray (as if clicked in 3-D): its pixel is outlined and the pixel's paths highlighted.

        Returns
        -------
        tuple of int or None
            The ray's pixel (x, y), or None when the rays carry no pixels.
        """
        if self.rays is None:
            raise ValueError("there are no rays to select")
        pixel = pixel_for_ray(self.rays, i)
        self.selected = [] if pixel is None else [pixel]
        self.picked_ray = int(i) % self.rays.n_cells
        self.refresh()
        return pixel

    def selected_rays(self) -> np.ndarray:
        """Indices of the rays highlighted now, shape (K,) int64 (the selected pixels' drawn segments, see
        :meth:`show_bounces`, and the picked ray)."""
        if self.rays is None:
            return np.zeros(0, dtype=np.int64)
        visible = getattr(self, "_visible", None)
        ids = [rays_for_pixel(self.rays, x, y) for x, y in self.selected]
        if visible is not None:
            ids = [i[np.isin(i, visible)] for i in ids]
        if self.picked_ray is not None:
            ids.append(np.array([self.picked_ray], dtype=np.int64))
        return np.unique(np.concatenate(ids)) if ids else np.zeros(0, dtype=np.int64)

    def toggle_flat(self, state: bool | None = None) -> bool:
        """Show or hide the straight flat-space camera rays of the selected pixels (key ``f``).

        Parameters
        ----------
        state : bool, optional
            The new state; default the opposite of the current one.

        Returns
        -------
        bool
            Whether the flat rays are now shown.
        """
        self.flat_visible = (not self.flat_visible) if state is None else bool(state)
        self.refresh()
        return self.flat_visible

    def flat_pixels(self) -> list[tuple[int, int]]:
        """The pixels whose flat-space rays are drawn: the selected ones, or without a selection the
        pixels the view chose (:attr:`pixel_labels`)."""
        return list(self.selected) if self.selected else list(self.pixel_labels)

    def flat_rays(self) -> np.ndarray:
        """The flat-space camera rays of :meth:`flat_pixels` as drawn: (K, 2, 3) float64 segments in the
        user frame (empty without a camera)."""
        pixels = self.flat_pixels()
        if self.camera is None or not pixels:
            return np.zeros((0, 2, 3))
        length = self._flat_length()
        return np.stack([flat_camera_ray(self.camera, x, y, length=length) for x, y in pixels])

    def _flat_length(self) -> float:
        """Long enough to cross everything in view: the distance from the camera to the far corner of
        the focus box."""
        start = np.asarray(self.camera["position"], dtype=np.float64)
        if self._focus is None:
            return 2.0 * float(np.linalg.norm(np.asarray(self.camera["look_at"], dtype=np.float64) - start))
        b = self._focus
        corners = np.array([[x, y, z] for x in b[0:2] for y in b[2:4] for z in b[4:6]])
        return max(float(np.linalg.norm(corners - start, axis=1).max()), 1e-6)

    def refresh(self) -> None:
        """Redraw the selection marks, highlighted rays, flat rays and the status line."""
        import pyvista as pv

        p = self.plotter
        if self._image_renderer is not None:
            height, width = self.image.shape[:2]
            inside = [(x, y) for x, y in self.selected if 0 <= x < width and 0 <= y < height]
            pad = max(0.5, 0.012 * max(width, height))
            self._replace(self._image_renderer, "selected_pixels",
                          _pixel_outlines(np.array(inside).reshape(-1, 2), height, pad=pad, z=0.02) if inside else None,
                          color=_SELECTED_COLOR, line_width=3, lighting=False, pickable=False)  # fmt: skip
        status_panel = self._image_renderer if self._image_renderer is not None else self._scene_renderer
        width = self._panel_px(status_panel)[0] - 20
        self._status_actor.SetInput("\n".join(wrap(self.status(), width, font_px("status", self._scale)).split("\n")[:2]))

        ids = self.selected_rays()
        pixel_ids = ids if self.picked_ray is None else ids[ids != self.picked_ray]
        shown = self.shown_rays
        self._replace(self._scene_renderer, "highlight",
                      shown.extract_cells(pixel_ids) if shown is not None and len(pixel_ids) else None,
                      color=_SELECTED_COLOR, line_width=5, lighting=False, pickable=False)  # fmt: skip
        picked = shown.extract_cells([self.picked_ray]) if shown is not None and self.picked_ray is not None else None
        self._replace(self._scene_renderer, "picked", picked, color=_PICKED_COLOR, line_width=6, lighting=False,
                      pickable=False)  # fmt: skip

        flat = None
        segments = self.flat_rays() if self.flat_visible else np.zeros((0, 2, 3))
        if len(segments):
            if self._embedding:  # sample the straight line densely, then lay it on the camera's sheet
                t = np.linspace(0.0, 1.0, 400)[None, :, None]
                dense = segments[:, :1] + t * (segments[:, 1:] - segments[:, :1])
                pieces = [self._embed(line, self.camera.get("sheet", 1)) for line in dense]
            else:
                pieces = list(segments)
            flat = pv.PolyData()
            for piece in pieces:
                flat = flat.merge(pv.lines_from_points(piece)) if flat.n_points else pv.lines_from_points(piece)
        self._replace(self._scene_renderer, "flat_rays", flat, color=_FLAT_COLOR, line_width=4, lighting=False,
                      pickable=False)  # fmt: skip
        self._update_legend()
        box = getattr(self, "_flat_box", None)
        if box is not None and box.GetRepresentation().GetState() != int(self.flat_visible):
            box.GetRepresentation().SetState(int(self.flat_visible))
        p.render()  # a no-op until the window is shown

    def drawn_items(self) -> list[str]:
        """Legend keys (:data:`~warpviz.viewer.annotations.LEGEND_STYLE`) of what the 3-D panel draws now,
        in drawing order."""
        items = list(self._drawn)
        if self._rays_actor is None and "rays" in items:
            items.remove("rays")
        return items + [key for key in ("highlight", "picked", "flat_rays") if key in self._named_actors]

    def legend_colors(self) -> dict[str, str]:
        """Colours of the legend's items drawn through a colour map (the recorded paths: their median)."""
        return {"rays": self._rays_color} if self._rays_actor is not None else {}

    def _update_legend(self) -> None:
        entries = legend_entries(self.drawn_items(), self.metric, self.legend_colors())
        if entries == self.legend:
            return
        self.legend = entries
        renderer = self._scene_renderer
        for _, actor in self._text_actors.pop("legend", []):
            renderer.RemoveActor(actor)
        if entries:
            panel_px = self._panel_px(renderer)
            top = 0.988 - self._top_lines_px() / panel_px[1]
            self._text_actors["legend"] = [(renderer, a) for a in draw_legend(renderer, entries, scale=self._scale,
                                                                               panel_px=panel_px, top=top)]

    def _replace(self, renderer, name: str, mesh, **style) -> None:
        """Put ``mesh`` into ``renderer`` under ``name``, replacing what was there (None removes it)."""
        old = self._named_actors.pop(name, None)
        if old is not None:
            renderer.remove_actor(old, reset_camera=False, render=False)
        if mesh is not None and mesh.n_points:
            actor = renderer.add_actor(_line_actor(mesh, **style), reset_camera=False, name=name,
                                       pickable=style.get("pickable", False), render=False)[0]  # fmt: skip
            self._named_actors[name] = actor

    def status(self) -> str:
        """The status line: what is selected and how its rays ended."""
        codes = np.asarray(self.rays.cell_data["status"]) if self.rays is not None else np.zeros(0, dtype=np.int8)
        parts = []
        if self.picked_ray is not None:
            parts.append(f"ray {self.picked_ray}: {RayStatus(int(codes[self.picked_ray])).name.lower()}")
        if self.selected:
            x, y = self.selected[0]
            ids = rays_for_pixel(self.rays, x, y) if self.rays is not None else np.zeros(0, dtype=np.int64)
            if len(ids):
                fates = ", ".join(f"{n} {RayStatus(int(c)).name.lower()}"
                                  for c, n in zip(*np.unique(codes[ids], return_counts=True)))  # fmt: skip
                parts.append(f"pixel ({x}, {y}): {len(ids)} geodesic segments: {fates}")
            else:
                parts.append(f"pixel ({x}, {y}): no recorded paths")
            if len(self.selected) > 1:
                parts.append(f"+{len(self.selected) - 1} more pixels")
        text = "; ".join(parts) if parts else "nothing selected"
        if self.image_samples is not None:
            text += f"; image: {self.image_samples} samples per pixel"
        return text

    # ---------------------------------------------------------------- clicks and keys









def _bar_mark(renderer, x: float, y0: float, y1: float):
    """A black vertical line from (x, y0) to (x, y1) in normalised viewport coordinates, over the colour
    bar (an actor of ``renderer``, returned)."""
    from vtkmodules.vtkCommonCore import vtkPoints
    from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkPolyData
    from vtkmodules.vtkRenderingCore import vtkActor2D, vtkCoordinate, vtkPolyDataMapper2D

    points = vtkPoints()
    points.InsertNextPoint(x, y0, 0.0)
    points.InsertNextPoint(x, y1, 0.0)
    lines = vtkCellArray()
    lines.InsertNextCell(2)
    lines.InsertCellPoint(0)
    lines.InsertCellPoint(1)
    poly = vtkPolyData()
    poly.SetPoints(points)
    poly.SetLines(lines)
    coordinate = vtkCoordinate()
    coordinate.SetCoordinateSystemToNormalizedViewport()
    mapper = vtkPolyDataMapper2D()
    mapper.SetInputData(poly)
    mapper.SetTransformCoordinate(coordinate)
    actor = vtkActor2D()
    actor.SetMapper(mapper)
    actor.GetProperty().SetColor(0.0, 0.0, 0.0)
    actor.GetProperty().SetLineWidth(3.0)
    actor.SetPickable(False)
    renderer.AddActor(actor)
    return actor


def _line_actor(mesh, *, color, line_width: float, lighting: bool = False, pickable: bool = False):
    import pyvista as pv

    mapper = pv.DataSetMapper(mesh)
    mapper.scalar_visibility = False
    actor = pv.Actor(mapper=mapper)
    prop = actor.prop
    prop.color = color
    prop.line_width = line_width
    prop.lighting = lighting
    actor.pickable = pickable
    return actor
