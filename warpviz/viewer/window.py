"""The teaching window: :class:`TeachingView`, the state of one window and the drawing and clicks linking its
image panel to its 3-D panel (see :func:`warpviz.view`, which builds it).
"""

from __future__ import annotations

import math
import weakref
from typing import Any

import numpy as np

from warpviz.scene import camera_basis, camera_frustum, flat_camera_ray, scene_surfaces
from warpviz.spacetime import ellis_embedding, ellis_embedding_points, metric_features
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
    length_unit,
    next_coloring,
    view_title,
    visible_ray_ids,
)
from warpviz.viewer.decorations import bar_range, draw_legend, legend_rows, round_axes
from warpviz.viewer.image_marks import angle_ticks, edge_circle
from warpviz.viewer.layout import BAR_BOX, add_text, font_px, line_px, place_beside, text_box, text_scale, wrap
from warpviz.viewer.meshes import _around, _cut_lines_at, _first_points, _focus_bounds, _image_grid, _pixel_outlines, _surface_rgb
from warpviz.viewer.picking import image_cell_to_pixel, pixel_for_ray, rays_for_pixel, recorded_pixels
from warpviz.viewer.progressive import DEFAULT_MAX_SPP, DEFAULT_REFRESH_MS, BackgroundRefiner, ProgressivePreview
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

#: The help line under the status line.
_KEYS_HELP = "click a ray or a pixel    f: flat-space ray    c: colouring    n: more bounces"

#: The image panel's title.
IMAGE_TITLE = "What the camera sees"


def _weak(method, *, takes_args: bool = True):
    """A callable forwarding to a bound method without keeping its object alive (VTK observers hold
    their callbacks from C++, out of reach of Python's garbage collector). ``takes_args=False`` makes
    a callable of no arguments, as PyVista's key events want."""
    ref = weakref.WeakMethod(method)

    def call(*args):
        bound = ref()
        return None if bound is None else bound(*args)

    def call_without_args():
        bound = ref()
        return None if bound is None else bound()

    return call if takes_args else call_without_args


# --------------------------------------------------------------------------------------------------
# the window


class TeachingView:
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
        self._embedding = self.metric is not None and "throat" in self.metric.landmarks
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

    def _status_lines(self, renderer) -> None:
        """The status line and the keys under it, bottom left of ``renderer``."""
        _, height = self._panel_px(renderer)
        gap = 6.0 / height
        self._status_actor = self._text(renderer, "status", "", x=0.012, y=gap + line_px("help", self._scale) / height,
                                        valign="bottom")  # fmt: skip
        self._text(renderer, "help", _KEYS_HELP, x=0.012, y=gap, valign="bottom", color="#404040")

    def _draw_image(self) -> None:
        p = self.plotter
        height, width = self.image.shape[:2]
        self._image_actor = p.add_mesh(_image_grid(self.image), scalars="rgb", rgb=True, lighting=False,
                                       show_scalar_bar=False, name="image")  # fmt: skip
        if self.rays is not None:
            marks = recorded_pixels(self.rays)
            if len(marks):
                outlines = _pixel_outlines(marks, height, pad=0.0, z=0.01)
                p.add_mesh(outlines, color="gray", line_width=1, lighting=False, pickable=False, name="recorded")
        renderer = self._image_renderer
        panel_w, panel_h = self._panel_px(renderer)
        s = self._scale
        title = f"{IMAGE_TITLE}: click a pixel to see its light paths"
        self._text(renderer, "title", wrap(title, panel_w - 20, font_px("title", s)), x=0.012, y=0.988)
        self._status_lines(renderer)
        # the image's frame: room for the title above, the angle scale left and below, the status lines
        top = 2.6 * line_px("title", s) + 10
        bottom = line_px("help", s) + 2 * line_px("status", s) + 2.4 * line_px("ticks", s) + 16
        left = 4.0 * font_px("ticks", s) + 12
        right = 0.03 * panel_w
        per_px = max(width / max(1.0, panel_w - left - right), height / max(1.0, panel_h - top - bottom))
        cx = width / 2.0 - ((left + (panel_w - left - right) / 2.0) - panel_w / 2.0) * per_px
        cy = height / 2.0 - ((bottom + (panel_h - top - bottom) / 2.0) - panel_h / 2.0) * per_px
        p.view_xy()
        p.enable_parallel_projection()
        cam = renderer.GetActiveCamera()
        cam.SetFocalPoint(cx, cy, 0.0)
        cam.SetPosition(cx, cy, 10.0 * max(width, height))
        cam.SetViewUp(0.0, 1.0, 0.0)
        cam.SetParallelScale(0.5 * panel_h * per_px)
        renderer.ResetCameraClippingRange()
        self._draw_image_marks(per_px)

    def _draw_image_marks(self, per_px: float) -> None:
        """The angle scale along the image's lower and left edges, the exact edge of the shadow (or the
        window) and the chosen pixels' labels."""
        import pyvista as pv

        renderer = self._image_renderer
        height, width = self.image.shape[:2]
        s = self._scale
        tick = 0.6 * font_px("ticks", s) * per_px  # tick length in image units
        if self.camera is not None:
            ticks = angle_ticks(self.camera, width, height)
            lines = [[(x, 0.0, 0.02), (x, -tick, 0.02)] for x, _ in ticks["x"]]
            lines += [[(0.0, height - y, 0.02), (-tick, height - y, 0.02)] for y, _ in ticks["y"]]
            if lines:
                segments = np.asarray(lines, dtype=np.float64).reshape(-1, 3)
                self._replace(renderer, "angle_ticks", pv.line_segments_from_points(segments), color="#303030",
                              line_width=2)  # fmt: skip
            for x, label in ticks["x"]:
                self._text(renderer, "ticks", label, x=x, y=-1.3 * tick, halign="centered", world=True)
            for y, label in ticks["y"]:
                self._text(renderer, "ticks", label, x=-1.4 * tick, y=height - y, halign="right", valign="centered",
                           world=True)  # fmt: skip
            self._text(renderer, "ticks", "angle from the centre of view", x=width / 2.0,
                       y=-1.3 * tick - 1.25 * font_px("ticks", s) * per_px, halign="centered", world=True,
                       color="#404040")  # fmt: skip
            edge = edge_circle(self.metric, self.camera, width, height)
            if edge is not None and len(edge[0]) > 1:
                points, label = edge
                inside = (points[:, 0] >= 0) & (points[:, 0] <= width) & (points[:, 1] >= 0) & (points[:, 1] <= height)
                if inside.any():
                    xyz = np.column_stack([points[:, 0], height - points[:, 1], np.full(len(points), 0.025)])
                    self._replace(renderer, "edge_circle", pv.lines_from_points(xyz), color="white", line_width=2)
                    top = xyz[inside][np.argmax(xyz[inside, 1])]
                    self.image_edge_label = label
                    self._text(renderer, "label", label, x=top[0], y=top[1] + 0.4 * tick, halign="centered",
                               valign="bottom", world=True, background="white")  # fmt: skip
        self._place_pixel_labels(per_px)

    def _place_pixel_labels(self, per_px: float) -> None:
        """Label the chosen pixels with what they show: each label beside its pixel, on the first side
        (right, left, above, below) where it overlaps no label placed before and stays in the panel."""
        renderer = self._image_renderer
        height, _ = self.image.shape[:2]
        vx0, _, vx1, _ = renderer.GetViewport()
        panel_x = (vx0 * self.plotter.window_size[0], vx1 * self.plotter.window_size[0])
        taken = [text_box(actor, renderer) for role in ("label", "ticks") for _, actor in self._text_actors.get(role, [])]
        for (x, y), text in self.pixel_labels.items():
            actor = self._text(renderer, "label", text, x=x + 0.5, y=height - 1 - y + 0.5, world=True,
                               background="white", valign="centered")  # fmt: skip
            place_beside(actor, renderer, taken, panel_x, gap=0.6 * font_px("label", self._scale))

    def _unrotate_image(self) -> None:
        """Undo any rotation of the image panel's camera (a drag there), keeping its pan and zoom."""
        cam = self._image_renderer.GetActiveCamera()
        fx, fy, _ = cam.GetFocalPoint()
        cam.SetFocalPoint(fx, fy, 0.0)
        cam.SetPosition(fx, fy, cam.GetDistance())
        cam.SetViewUp(0.0, 1.0, 0.0)
        self._image_renderer.ResetCameraClippingRange()

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
                grid = ellis_embedding(self.metric, resolution=24) if self._embedding else mesh
                p.add_mesh(grid, style="wireframe", color="slategray", opacity=0.5, line_width=1, lighting=False,
                           pickable=False, name="embedding_grid")  # fmt: skip
                waist_radius = (self.metric.throat if self._embedding
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
                shown.points = ellis_embedding_points(self.metric, shown.points, shown.point_data["sheet"])
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
        self.title_text = wrap(view_title(self.title, self.metric), panel_w - 20, font_px("title", self._scale))
        self._text(renderer, "title", self.title_text, x=0.012, y=0.988)
        if self._image_renderer is None:  # one panel: the status lines go under the title
            lines = self.title_text.count("\n") + 1
            top = 0.988 - (lines * line_px("title", self._scale) + 4) / panel_h
            self._text(renderer, "help", _KEYS_HELP, x=0.012, y=top, color="#404040")
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

    def _draw_axes(self) -> None:
        """The axes' box at the round values inside the focus box (:func:`round_axes`)."""
        if self._focus is None:
            return
        p = self.plotter
        p.subplot(0, self._scene_col)
        unit = length_unit(self.metric)
        titles = [f"{axis} ({unit})" for axis in "xyz"]
        bounds, counts = round_axes(self._focus)
        spans = [b - a for a, b in zip(bounds[0::2], bounds[1::2])]
        step = min((span / max(1, n - 1) for span, n in zip(spans, counts) if span >= 0.1 * max(spans)),
                   default=1.0)  # a thin axis (a fan in a plane) does not set the digits
        digits = max(0, -math.floor(math.log10(step) + 1e-9)) if step > 0 else 0
        p.show_bounds(bounds=bounds, xtitle=titles[0], ytitle=titles[1], ztitle=titles[2], location="outer",
                      ticks="outside", font_size=font_px("axes", self._scale), fmt=f"%.{digits}f", grid=False,
                      use_3d_text=False, n_xlabels=counts[0], n_ylabels=counts[1], n_zlabels=counts[2])

    def frame(self, bounds) -> None:
        """Look at a box in the 3-D panel: the axes at the round values inside it and the camera fitted
        to it between the title and the colour bar (what is outside is still drawn).

        Parameters
        ----------
        bounds : sequence of 6 float
            (xmin, xmax, ymin, ymax, zmin, zmax) in scene units.
        """
        b = np.asarray(bounds, dtype=np.float64).reshape(6)
        if not (np.isfinite(b).all() and (b[1::2] >= b[0::2]).all()):
            raise ValueError(f"bounds must be finite (xmin, xmax, ymin, ymax, zmin, zmax), got {list(bounds)}")
        self._focus = b
        self._fit_points = np.array([(x, y, z) for x in b[0:2] for y in b[2:4] for z in b[4:6]])
        self._draw_axes()
        self._set_3d_camera()
        self.plotter.render()

    def set_title(self, text: str) -> None:
        """Replace the 3-D panel's title (wrapped to the panel); the legend and the framing make room."""
        panel_w, _ = self._panel_px(self._scene_renderer)
        self.title_text = wrap(str(text), panel_w - 20, font_px("title", self._scale))
        renderer, actor = self._text_actors["title"][-1]
        actor.SetInput(self.title_text)
        self.legend = []  # drawn again under the new title
        self._update_legend()
        self._set_3d_camera()
        self.plotter.render()

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
        digits = max(0, -math.floor(math.log10(step) + 1e-9)) if step > 0 else 0
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

    def _set_3d_camera(self) -> None:
        r = self._scene_renderer
        if self._focus is None:
            r.reset_camera()
            return
        b = self._focus
        centre = np.array([(b[0] + b[1]) / 2, (b[2] + b[3]) / 2, (b[4] + b[5]) / 2])
        radius = 0.5 * float(np.linalg.norm([b[1] - b[0], b[3] - b[2], b[5] - b[4]])) or 1.0
        if self.camera is not None and not self._embedding:  # above and behind the scene camera
            forward, right, up = camera_basis(self.camera)
            offset = 1.0 * up - 0.45 * forward + 0.45 * right
        elif self.camera is not None:  # the embedding diagram from the side, a little above its rim
            forward, right, _ = camera_basis(self.camera)
            offset = 1.0 * right - 0.35 * forward + np.array([0.0, 0.0, 0.4])
        elif self._embedding:
            offset = np.array([0.35, -1.0, 0.4])
        elif self._planar_rays():  # e.g. a fan in the equatorial plane: from above, slightly tilted
            offset = np.array([0.0, -0.3, 1.0])
        else:
            offset = np.array([0.55, -0.75, 0.9])
        offset /= np.linalg.norm(offset)
        view_up = np.array([0.0, 0.0, 1.0]) if abs(offset[2]) < 0.95 else np.array([0.0, 1.0, 0.0])
        angle = math.radians(r.camera.view_angle)
        distance = 1.1 * radius / math.sin(angle / 2.0)
        cam = r.camera
        cam.focal_point = centre.tolist()
        cam.position = (centre + distance * offset).tolist()
        cam.up = view_up.tolist()
        r.ResetCameraClippingRange()
        self._fit_in_band()
        self._justify_labels()

    def _justify_labels(self) -> None:
        """Each 3-D label beside its point where it stays inside the panel and clear of the labels placed
        before it (:func:`~warpviz.viewer.layout.place_beside`)."""
        r = self._scene_renderer
        x0 = r.GetViewport()[0] * self.plotter.window_size[0]
        panel_w, _ = self._panel_px(r)
        taken: list = []
        for _, actor in self._text_actors.get("label3d", []):
            place_beside(actor, r, taken, (x0, x0 + panel_w))

    def fit_points(self) -> np.ndarray:
        """The points the 3-D camera frames, shape (K, 3): the drawn landmarks, objects and camera (a
        subsample) and the corners of the axes' box."""
        axes = self._scene_renderer.cube_axes_actor
        corners = []
        if axes is not None:
            b = axes.GetBounds()
            corners = [(x, y, z) for x in b[0:2] for y in b[2:4] for z in b[4:6]]
        pieces = [np.asarray(corners, dtype=np.float64).reshape(-1, 3)]
        if self._fit_points is not None:
            pieces.append(self._fit_points)
        return np.concatenate(pieces)

    def _fit_in_band(self) -> None:
        """Move the 3-D camera along its view and shift the picture so what :meth:`fit_points` names fills
        the band between the top texts and the colour bar, with room for the axes' labels."""
        r = self._scene_renderer
        cam = r.camera
        panel_w, panel_h = self._panel_px(r)
        top, bottom = self._bands_px()
        pad = 2.5 * line_px("axes", self._scale)  # the axes' labels and titles outside the box
        avail_w, avail_h = max(1.0, panel_w - 2 * pad), max(1.0, panel_h - top - bottom - 2.5 * pad)
        corners = self.fit_points()
        x0, y0 = r.GetViewport()[0] * self.plotter.window_size[0], r.GetViewport()[1] * self.plotter.window_size[1]
        def extent():
            shown = []
            for corner in corners:
                r.SetWorldPoint(*corner, 1.0)
                r.WorldToDisplay()
                dx, dy, _ = r.GetDisplayPoint()
                shown.append((dx - x0, dy - y0))
            shown = np.asarray(shown)
            return shown.min(axis=0), shown.max(axis=0)

        for _ in range(3):
            lo, hi = extent()
            factor = max((hi[0] - lo[0]) / avail_w, (hi[1] - lo[1]) / avail_h, 1e-3)
            focal = np.asarray(cam.focal_point)
            cam.position = (focal + factor * (np.asarray(cam.position) - focal)).tolist()
            lo, hi = extent()  # then the box's centre onto the band's (WindowCenter moves it by -size/2 per unit)
            want = np.array([panel_w / 2.0, bottom + 1.5 * pad + avail_h / 2.0])
            shift = ((lo + hi) / 2.0 - want) / (np.array([panel_w, panel_h]) / 2.0)
            wx, wy = cam.GetWindowCenter()
            cam.SetWindowCenter(wx + shift[0], wy + shift[1])
        r.ResetCameraClippingRange()

    def _top_lines_px(self) -> float:
        """Height (pixels) of the 3-D panel's title, and of the status lines where they sit under it."""
        height = (self.title_text.count("\n") + 1) * line_px("title", self._scale) + 6
        if self._image_renderer is None:
            height += 2 * line_px("status", self._scale) + line_px("help", self._scale)
        return height

    def _bands_px(self) -> tuple[float, float]:
        """Heights (pixels) of the 3-D panel's top band (title, status, legend) and bottom band (the colour
        bar and its caption), which the scene is framed between."""
        renderer = self._scene_renderer
        panel_w, panel_h = self._panel_px(renderer)
        possible = self.drawn_items() + ["highlight", "picked"] + (["flat_rays"] if self.camera is not None else [])
        rows = len(legend_rows(legend_entries(possible, self.metric), self._scale, panel_w - 16))
        top = self._top_lines_px() + rows * 1.3 * font_px("legend", self._scale) + 8
        bottom = 8.0
        if self._rays_actor is not None:
            bottom += (BAR_BOX[1] + BAR_BOX[3]) * panel_h + self._caption_lines * line_px("caption", self._scale)
        return top, bottom

    def _planar_rays(self) -> bool:
        """Whether all rays lie in a plane z = const."""
        if self.rays is None or not self.rays.n_points:
            return False
        b = self.rays.bounds
        return b[5] - b[4] <= 1e-6 * max(b[1] - b[0], b[3] - b[2], 1e-300)

    def _embed(self, points: np.ndarray, sheet) -> np.ndarray:
        sheets = np.broadcast_to(np.asarray(sheet), (points.shape[0],))
        return ellis_embedding_points(self.metric, points, sheets)

    # ---------------------------------------------------------------- progressive image

    def set_image(self, image: np.ndarray, *, samples: int | None = None) -> None:
        """Show a new picture of the same size in the image panel (a refined preview).

        Parameters
        ----------
        image : numpy.ndarray
            (H, W, 3) uint8 sRGB, the size of the current image.
        samples : int, optional, keyword-only
            Its samples per pixel, for the status line.
        """
        image = np.asarray(image)
        if self.image is None or image.shape != self.image.shape or image.dtype != np.uint8:
            want = None if self.image is None else self.image.shape
            raise ValueError(f"set_image needs a {want} uint8 image, got {image.shape} {image.dtype}")
        from vtkmodules.util.numpy_support import vtk_to_numpy

        self.image = image
        colors = self._image_actor.GetMapper().GetInput().GetCellData().GetArray("rgb")
        vtk_to_numpy(colors)[:] = image[::-1].reshape(-1, 3)  # in place: the mapper keeps its array
        colors.Modified()
        if samples is not None:
            self.image_samples = int(samples)
        self.refresh()

    def start_refining(self, *, max_spp: int = DEFAULT_MAX_SPP, refresh_ms: int = DEFAULT_REFRESH_MS,
                       threads: int | None = None) -> BackgroundRefiner | None:  # fmt: skip
        """Refine the image while the window is open: passes of the preview with more samples are
        rendered on a background thread (:class:`~warpviz.viewer.progressive.BackgroundRefiner`) and
        swapped in by a VTK timer every ``refresh_ms``.

        Parameters
        ----------
        max_spp : int, keyword-only
            Samples per pixel at which refining stops.
        refresh_ms : int, keyword-only
            How often the window takes the newest image.
        threads : int, optional, keyword-only
            Render threads (default: the renderer's).

        Returns
        -------
        BackgroundRefiner or None
            The worker, or None when the view has no scene to refine (a render or rays given, not a
            scene) or already refines.
        """
        if self.refiner is not None or self.source is None or self.preview is None or self.image is None:
            return None
        preview = ProgressivePreview(self.source, width=self.preview["width"], height=self.preview["height"],
                                     spp=self.preview["spp"], seed=self.preview.get("seed") or 0,
                                     max_spp=max(int(max_spp), self.preview["spp"]), first=self.preview.get("rgb"),
                                     threads=threads)  # fmt: skip
        self.refiner = BackgroundRefiner(preview).start()
        iren = self.plotter.iren
        if iren is not None:
            iren.add_observer("TimerEvent", _weak(self._on_timer))
            self._timer_id = iren.create_timer(int(refresh_ms), repeating=True)
        return self.refiner

    def _on_timer(self, *_) -> bool:
        """Swap in the refiner's newest image, if there is one; returns whether the image changed."""
        latest = self.refiner.take() if self.refiner is not None else None
        if latest is None:
            return False
        samples, image = latest
        self.set_image(image, samples=samples)
        return True

    def stop_refining(self) -> None:
        """Stop the background passes (the image keeps its last refinement)."""
        if self.refiner is not None:
            self.refiner.stop()
            timer = getattr(self, "_timer_id", None)
            if timer is not None and self.plotter.iren is not None:
                self.plotter.iren.interactor.DestroyTimer(timer)
                self._timer_id = None

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

    def pick(self, x: float, y: float) -> tuple[str, Any] | None:
        """Act on a click at display position (x, y) (pixels from the window's lower-left corner).

        A click on the image selects that pixel; a click on a ray selects the ray.

        Returns
        -------
        tuple or None
            ``("pixel", (px, py))``, ``("ray", i)``, or None when nothing pickable is there.
        """
        from vtkmodules.vtkRenderingCore import vtkCellPicker

        targets = []
        if self._image_renderer is not None:
            targets.append((self._image_renderer, self._image_actor, "pixel"))
        if self._rays_actor is not None:
            targets.append((self._scene_renderer, self._rays_actor, "ray"))
        for renderer, actor, kind in targets:
            if not renderer.IsInViewport(int(x), int(y)):
                continue
            picker = vtkCellPicker()
            picker.SetTolerance(0.004)
            picker.PickFromListOn()
            picker.AddPickList(actor)
            if not picker.Pick(float(x), float(y), 0.0, renderer) or picker.GetCellId() < 0:
                return None
            cell = int(picker.GetCellId())
            if kind == "ray":  # a cell of the drawn segments: back to the ray's index
                cell = int(self._visible[cell])
            if kind == "pixel":
                height, width = self.image.shape[:2]
                pixel = image_cell_to_pixel(cell, width=width, height=height)
                self.select_pixel(*pixel)
                return "pixel", pixel
            self.select_ray(cell)
            return "ray", cell
        return None

    def _install_events(self) -> None:
        iren = self.plotter.iren
        if iren is None:
            return
        iren.add_observer("LeftButtonPressEvent", _weak(self._on_press))
        iren.add_observer("LeftButtonReleaseEvent", _weak(self._on_release))
        iren.add_observer("RightButtonPressEvent", _weak(self._on_right))
        self.plotter.add_key_event("f", _weak(self.toggle_flat, takes_args=False))
        self.plotter.add_key_event("c", _weak(self.cycle_coloring, takes_args=False))
        self.plotter.add_key_event("n", _weak(self.show_bounces, takes_args=False))
        style = iren.style
        if hasattr(style, "add_observer"):  # keep VTK's own "f" (fly to the point under the mouse) out of it
            style.add_observer("CharEvent", _weak(self._on_char))
        if self.camera is not None:  # a tick box for the flat rays, bottom left of the 3-D panel
            self.plotter.subplot(0, self._scene_col)
            x0 = self._scene_renderer.GetViewport()[0] * self.plotter.window_size[0]
            self._flat_box = self.plotter.add_checkbox_button_widget(
                _weak(self.toggle_flat), value=self.flat_visible, size=20, position=(x0 + 8, 8), color_on=_FLAT_COLOR)

    def _event_position(self) -> tuple[int, int]:
        return tuple(self.plotter.iren.get_event_position())

    def _on_press(self, *_) -> None:
        self._press = self._event_position()

    def _on_release(self, *_) -> None:
        if self._press is None:
            return
        (x0, y0), (x1, y1) = self._press, self._event_position()
        self._press = None
        if abs(x1 - x0) <= 3 and abs(y1 - y0) <= 3:  # a click, not a drag
            self.pick(x1, y1)
        elif self._image_renderer is not None and self._image_renderer.IsInViewport(x0, y0):
            self._unrotate_image()
            self.plotter.render()

    def _on_char(self, style, *_) -> None:
        """Replaces the interactor style's key handling (VTK calls an observer of CharEvent instead of
        the style's OnChar): every key but ``f`` goes on to the style."""
        if style.GetInteractor().GetKeySym() not in ("f", "F"):
            style.OnChar()

    def _on_right(self, *_) -> None:
        self.pick(*self._event_position())


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
