"""How the teaching window's 3-D panel is framed: the axes at round values, the camera fitted between the
title (and legend) and the colour bar, the 3-D labels placed where they fit, a box to look at, a new
title. A part of :class:`~warpviz.viewer.window.TeachingView`.
"""

from __future__ import annotations

import math

import numpy as np

from warpviz.scene import camera_basis
from warpviz.viewer.annotations import legend_entries, length_unit
from warpviz.viewer.decorations import decimals, legend_rows, round_axes
from warpviz.viewer.layout import BAR_BOX, font_px, line_px, place_beside, wrap

__all__ = ["Framing"]


class Framing:
    """The 3-D panel's framing (a mixin of :class:`~warpviz.viewer.window.TeachingView`)."""

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
        digits = decimals(step)
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

    def _wrap_title(self, text: str) -> str:
        """The 3-D panel's title broken into lines that fit the panel."""
        return wrap(text, self._panel_px(self._scene_renderer)[0] - 20, font_px("title", self._scale))

    def set_title(self, text: str) -> None:
        """Replace the 3-D panel's title (wrapped to the panel); the legend and the framing make room."""
        self.title_text = self._wrap_title(str(text))
        renderer, actor = self._text_actors["title"][-1]
        actor.SetInput(self.title_text)
        self.legend = []  # drawn again under the new title
        self._update_legend()
        self._set_3d_camera()
        self.plotter.render()

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
