"""The image panel of the teaching window: the rendered picture framed between its title and the status
lines, its angle scale, the exact edge of the shadow (or window), the chosen pixels' labels, and the
picture refined in the background while the window is open. A part of :class:`~warpviz.viewer.window.TeachingView`.
"""

from __future__ import annotations

import numpy as np

from warpviz.viewer.callbacks import IMAGE_TITLE, KEYS_HELP, weak_callback
from warpviz.viewer.image_marks import angle_ticks, edge_circle
from warpviz.viewer.layout import font_px, line_px, place_beside, text_box, wrap
from warpviz.viewer.meshes import _image_grid, _pixel_outlines
from warpviz.viewer.picking import recorded_pixels
from warpviz.viewer.progressive import DEFAULT_MAX_SPP, DEFAULT_REFRESH_MS, BackgroundRefiner, ProgressivePreview

__all__ = ["ImagePanel"]


class ImagePanel:
    """The image panel's drawing and refinement (a mixin of :class:`~warpviz.viewer.window.TeachingView`)."""

    def _status_lines(self, renderer) -> None:
        """The status line and the keys under it, bottom left of ``renderer``."""
        _, height = self._panel_px(renderer)
        gap = 6.0 / height
        self._status_actor = self._text(renderer, "status", "", x=0.012, y=gap + line_px("help", self._scale) / height,
                                        valign="bottom")  # fmt: skip
        self._text(renderer, "help", KEYS_HELP, x=0.012, y=gap, valign="bottom", color="#404040")

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
            iren.add_observer("TimerEvent", weak_callback(self._on_timer))
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
