"""Clicks and keys of the teaching window: a click picks a pixel or a ray, ``f`` ``c`` ``n`` toggle the
flat ray, the colouring and the bounces, a drag in the image panel pans without turning it. A part of
:class:`~warpviz.viewer.window.TeachingView`.
"""

from __future__ import annotations

from typing import Any

from warpviz.viewer.annotations import LEGEND_STYLE
from warpviz.viewer.callbacks import weak_callback
from warpviz.viewer.picking import image_cell_to_pixel

__all__ = ["Events"]

_FLAT_COLOR = LEGEND_STYLE["flat_rays"][1]


class Events:
    """Picking and key handling (a mixin of :class:`~warpviz.viewer.window.TeachingView`)."""

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
        iren.add_observer("LeftButtonPressEvent", weak_callback(self._on_press))
        iren.add_observer("LeftButtonReleaseEvent", weak_callback(self._on_release))
        iren.add_observer("RightButtonPressEvent", weak_callback(self._on_right))
        self.plotter.add_key_event("f", weak_callback(self.toggle_flat, takes_args=False))
        self.plotter.add_key_event("c", weak_callback(self.cycle_coloring, takes_args=False))
        self.plotter.add_key_event("n", weak_callback(self.show_bounces, takes_args=False))
        style = iren.style
        if hasattr(style, "add_observer"):  # keep VTK's own "f" (fly to the point under the mouse) out of it
            style.add_observer("CharEvent", weak_callback(self._on_char))
        if self.camera is not None:  # a tick box for the flat rays, bottom left of the 3-D panel
            self.plotter.subplot(0, self._scene_col)
            x0 = self._scene_renderer.GetViewport()[0] * self.plotter.window_size[0]
            self._flat_box = self.plotter.add_checkbox_button_widget(
                weak_callback(self.toggle_flat), value=self.flat_visible, size=20, position=(x0 + 8, 8), color_on=_FLAT_COLOR)

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
        elif self._scene_renderer.IsInViewport(x0, y0):  # the scene turned: its labels find their places again
            self._justify_labels()
            self.plotter.render()

    def _on_char(self, style, *_) -> None:
        """Replaces the interactor style's key handling (VTK calls an observer of CharEvent instead of
        the style's OnChar): every key but ``f`` goes on to the style."""
        if style.GetInteractor().GetKeySym() not in ("f", "F"):
            style.OnChar()

    def _on_right(self, *_) -> None:
        self.pick(*self._event_position())
