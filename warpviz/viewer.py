"""The teaching view: a rendered image beside the 3-D paths of its light rays, linked by clicks.

:func:`view` opens a PyVista window with two panels. On the left is the rendered image (tonemapped
with :meth:`warpviz.Image.to_uint8`) with the pixels whose paths were recorded outlined; on the right
the 3-D scene: the recorded rays as polylines coloured by their ``log10_error`` (log10 of the largest
relative error of a conserved quantity), the scene's shapes, the spacetime's landmarks (horizon,
ergosphere, photon sphere or Kerr photon region, Ellis throat) drawn translucent and the camera frustum.
An Ellis wormhole is drawn as its embedding diagram with the rays on it, both sheets visible.

* Click a pixel in the image (a left click without dragging, or a right click): its recorded paths
  light up in 3-D.
* Click a ray in 3-D: its pixel is outlined in the image and its paths light up.
* Press ``f`` (or tick the box in the 3-D panel): the straight flat-space camera ray of each selected
  pixel is drawn beside the bent one.

The logic behind the clicks lives in :mod:`warpviz.picking` and :mod:`warpviz.pinhole` (pure
functions); :class:`TeachingView` holds the state of one window and can be driven from code, which is
how the view is tested off-screen.

Examples
--------
Whether a new window would be off-screen depends only on the environment:

>>> from warpviz.viewer import default_off_screen
>>> default_off_screen({"PYVISTA_OFF_SCREEN": "true", "DISPLAY": ":0"}, jupyter=False)
True
>>> default_off_screen({"DISPLAY": ":0"}, jupyter=False)
False
"""

from __future__ import annotations

import math
import os
import sys
import weakref
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from warpviz.geometry import camera_frustum, ellis_embedding, ellis_embedding_points, metric_features, scene_surfaces
from warpviz.image import tonemap
from warpviz.picking import (
    image_cell_to_pixel,
    pixel_for_ray,
    rays_for_pixel,
    recorded_pixels,
)
from warpviz.pinhole import camera_basis, flat_camera_ray
from warpviz.rays import RayStatus
from warpviz.view_content import ViewContent, view_content

if TYPE_CHECKING:  # pragma: no cover
    import pyvista as pv

__all__ = ["SCALAR_TITLES", "TeachingView", "default_off_screen", "view"]

#: Scalar-bar titles of the point arrays rays can be coloured by.
SCALAR_TITLES = {
    "log10_error": "log10 conserved-quantity error",
    "hamiltonian_err": "relative |H| (null condition)",
    "r": "radius r (M)",
    "affine_param": "affine parameter",
    "coord_time": "coordinate time t (M)",
    "step_size": "step size",
    "sheet": "sheet (+1 ours, -1 other)",
}

#: log10 of double precision: smaller errors (exactly conserved, e.g. flat space) are shown as this.
_LOG10_FLOOR = -16.0

#: Colours and opacities of the landmarks.
_FEATURE_STYLE = {
    "horizon": ("black", 0.55),
    "ergosphere": ("orange", 0.15),
    "photon_sphere": ("deepskyblue", 0.15),
    "throat": ("mediumpurple", 0.3),
}
_SELECTED_COLOR = "magenta"
_PICKED_COLOR = "yellow"
_FLAT_COLOR = "lime"
_FRUSTUM_COLOR = "darkorange"
_MATERIAL_TYPE_COLOR = {"diffuse": (0.75, 0.75, 0.75), "mirror": (0.7, 0.75, 0.85), "glass": (0.6, 0.85, 0.95),
                        "emissive": (1.0, 0.9, 0.4)}  # fmt: skip
_THEMES = {"document": "DocumentTheme", "dark": "DarkTheme", "paraview": "ParaViewTheme",
           "document_pro": "DocumentProTheme"}  # fmt: skip


# --------------------------------------------------------------------------------------------------
# environment


def _in_jupyter() -> bool:
    """True inside a Jupyter kernel (an IPython ZMQ shell)."""
    ipython = sys.modules.get("IPython")
    if ipython is None:
        return False
    try:
        shell = ipython.get_ipython()
    except AttributeError:  # pragma: no cover - very old IPython
        return False
    return shell is not None and type(shell).__name__ == "ZMQInteractiveShell"


def default_off_screen(environ: Mapping[str, str] | None = None, *, jupyter: bool | None = None) -> bool:
    """Whether :func:`view` renders off-screen when not told.

    Off-screen when ``PYVISTA_OFF_SCREEN`` is true, or on Linux-like systems when ``DISPLAY`` is unset
    outside Jupyter (no X server to open a window on); on-screen otherwise.

    Parameters
    ----------
    environ : mapping, optional
        Environment variables (default :data:`os.environ`).
    jupyter : bool, optional, keyword-only
        Whether we run in a Jupyter kernel (default: detected).

    Returns
    -------
    bool
    """
    env = os.environ if environ is None else environ
    if str(env.get("PYVISTA_OFF_SCREEN", "")).strip().lower() in ("1", "true", "yes", "on"):
        return True
    if _in_jupyter() if jupyter is None else jupyter:
        return False
    return sys.platform not in ("win32", "darwin") and not env.get("DISPLAY")


# --------------------------------------------------------------------------------------------------
# display meshes


def _image_grid(image: np.ndarray):
    """The picture as a W x H grid of unit cells in z = 0 with uint8 cell data ``rgb`` (pixel (x, y) is
    cell ``x + W (H - 1 - y)``, see :mod:`warpviz.picking`)."""
    import pyvista as pv

    height, width = image.shape[:2]
    grid = pv.ImageData(dimensions=(width + 1, height + 1, 1))
    grid.cell_data["rgb"] = np.ascontiguousarray(image[::-1].reshape(-1, 3))
    return grid


def _pixel_outlines(pixels: np.ndarray, height: int, *, pad: float, z: float):
    """Closed squares around pixels (x, y) of the image grid, as polylines."""
    import pyvista as pv

    pixels = np.asarray(pixels, dtype=np.float64).reshape(-1, 2)
    if not len(pixels):
        return pv.PolyData()
    x0 = pixels[:, 0] - pad
    y0 = height - 1 - pixels[:, 1] - pad
    x1, y1 = x0 + 1 + 2 * pad, y0 + 1 + 2 * pad
    corners = np.stack([np.column_stack([x0, y0]), np.column_stack([x1, y0]), np.column_stack([x1, y1]),
                        np.column_stack([x0, y1])], axis=1)  # fmt: skip
    points = np.concatenate([corners.reshape(-1, 2), np.full((corners.shape[0] * 4, 1), z)], axis=1)
    base = 4 * np.arange(len(pixels))[:, None]
    lines = np.column_stack([np.full(len(pixels), 5), base + np.array([0, 1, 2, 3, 0])[None, :]])
    return pv.PolyData(points, lines=lines.ravel())


def _texture_color(texture: Mapping[str, Any] | None) -> np.ndarray:
    """(3,) typical linear colour of a native scene texture."""
    if not texture:
        return np.full(3, 0.75)
    kind = texture.get("type")
    if kind == "constant":
        return np.asarray(texture["color"], dtype=np.float64)
    if kind == "checker":
        return 0.5 * np.add(np.asarray(texture["color_a"], dtype=np.float64), texture["color_b"])
    if kind == "grid":
        return np.asarray(texture["base"], dtype=np.float64)
    if kind == "image":
        return np.asarray(texture["data"], dtype=np.float64).reshape(-1, 3).mean(axis=0)
    return np.full(3, 0.75)


def _material_colors(native_scene: Mapping[str, Any] | None, material_types) -> np.ndarray:
    """(M, 3) float display colours (linear, about [0, 1]) of a scene's materials."""
    if native_scene is not None:
        materials, textures = native_scene.get("materials") or [], native_scene.get("textures") or []
        out = []
        for m in materials:
            kind = m.get("type")
            tex = textures[m["texture"]] if "texture" in m and 0 <= m["texture"] < len(textures) else None
            if kind == "diffuse":
                out.append(_texture_color(tex))
            elif kind == "emissive":
                c = _texture_color(tex) * float(m.get("strength", 1.0))
                out.append(c / max(float(c.max()), 1e-12))
            elif kind == "mirror":
                out.append(0.5 + 0.4 * np.asarray(m.get("reflectance", [1, 1, 1]), dtype=np.float64))
            elif kind == "glass":
                out.append(0.3 * np.asarray(m.get("tint", [1, 1, 1]), dtype=np.float64) + np.array([0.4, 0.6, 0.7]))
            else:
                out.append(np.full(3, 0.75))
        return np.array(out, dtype=np.float64).reshape(-1, 3)
    return np.array([_MATERIAL_TYPE_COLOR.get(str(t), (0.75, 0.75, 0.75)) for t in material_types]).reshape(-1, 3)


def _surface_rgb(surfaces, native_scene) -> np.ndarray:
    """(F, 3) uint8 sRGB colour per surface cell, from its material."""
    types = np.asarray(surfaces.field_data["material_type"]).tolist() if "material_type" in surfaces.field_data else []
    colors = _material_colors(native_scene, types)
    material = np.asarray(surfaces.cell_data["material"]) if "material" in surfaces.cell_data else None
    linear = np.full((surfaces.n_cells, 3), 0.75)
    if material is not None and len(colors):
        ok = (material >= 0) & (material < len(colors))
        linear[ok] = colors[material[ok]]
    return tonemap(linear[None, :, :])[0]


def _focus_bounds(meshes) -> np.ndarray | None:
    """(6,) union of the bounds of the non-empty meshes."""
    boxes = [np.asarray(m.bounds, dtype=np.float64) for m in meshes if m is not None and m.n_points]
    if not boxes:
        return None
    b = np.stack(boxes)
    return np.array([b[:, 0].min(), b[:, 1].max(), b[:, 2].min(), b[:, 3].max(), b[:, 4].min(), b[:, 5].max()])


def _first_points(poly) -> np.ndarray:
    """(N, 3) first point of each polyline cell of ``poly`` (cells without points skipped)."""
    from vtkmodules.util.numpy_support import vtk_to_numpy

    lines = poly.GetLines()
    offsets = vtk_to_numpy(lines.GetOffsetsArray())
    conn = vtk_to_numpy(lines.GetConnectivityArray())
    starts = offsets[:-1][np.diff(offsets) > 0]
    return np.asarray(poly.points)[conn[starts]] if len(starts) else np.zeros((0, 3))


def _around(bounds: np.ndarray, points: np.ndarray) -> np.ndarray:
    """(6,) bounds centred on the centre of ``bounds``, grown per axis to hold ``points`` (K, 3)."""
    centre = 0.5 * (bounds[0::2] + bounds[1::2])
    half = 0.5 * (bounds[1::2] - bounds[0::2])
    if len(points):
        half = np.maximum(half, np.abs(points - centre).max(axis=0))
    return np.column_stack([centre - half, centre + half]).ravel()


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
    """

    def __init__(self, content: ViewContent, plotter, *, color_by: str = "log10_error", show_flat: bool = False):
        self.plotter = plotter
        self.title = content.title
        self.image = content.image
        self.rays = content.rays
        self.metric = content.metric
        self.camera = dict(content.camera) if content.camera is not None else None
        self.selected: list[tuple[int, int]] = []
        self.picked_ray: int | None = None
        self.flat_visible = bool(show_flat)
        self._embedding = self.metric is not None and "throat" in self.metric.landmarks
        self._image_renderer = None
        self._image_actor = None
        self._rays_actor = None
        self._press: tuple[int, int] | None = None
        self._named_actors: dict[str, Any] = {}

        has_image = self.image is not None
        scene_col = 1 if has_image else 0
        if has_image:
            plotter.subplot(0, 0)
            self._image_renderer = plotter.renderer
            self._draw_image()
        plotter.subplot(0, scene_col)
        self._scene_renderer = plotter.renderer
        self.shown_rays = self._draw_scene(content, color_by)
        if not has_image:
            self._status_actor = plotter.add_text("", position="lower_left", font_size=9, name="status")
        self._install_events()
        self.refresh()

    # ---------------------------------------------------------------- drawing

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
        p.add_text("rendered image: click a pixel", position="upper_left", font_size=9, name="image_title")
        self._status_actor = p.add_text("", position="lower_left", font_size=9, name="status")
        p.view_xy()
        p.enable_parallel_projection()
        p.reset_camera()
        p.renderer.camera.zoom(1.05)

    def _unrotate_image(self) -> None:
        """Undo any rotation of the image panel's camera (a drag there), keeping its pan and zoom."""
        cam = self._image_renderer.GetActiveCamera()
        fx, fy, _ = cam.GetFocalPoint()
        cam.SetFocalPoint(fx, fy, 0.0)
        cam.SetPosition(fx, fy, cam.GetDistance())
        cam.SetViewUp(0.0, 1.0, 0.0)
        self._image_renderer.ResetCameraClippingRange()

    def _draw_scene(self, content: ViewContent, color_by: str):
        import pyvista as pv

        p = self.plotter
        legend: list[tuple[str, str]] = []
        focus = []
        features = dict(content.features) or (metric_features(self.metric) if self.metric is not None else {})
        for name, mesh in features.items():
            if name == "embedding":
                sheet = np.asarray(mesh.point_data["sheet"]) if "sheet" in mesh.point_data else np.ones(mesh.n_points)
                p.add_mesh(mesh, scalars=np.where(sheet > 0, 0.0, 1.0), cmap=["lightsteelblue", "lightsalmon"],
                           clim=(0, 1), opacity=0.45, smooth_shading=True, specular=0.3, show_scalar_bar=False,
                           pickable=False, name="embedding")  # fmt: skip
                grid = ellis_embedding(self.metric, resolution=24) if self._embedding else mesh
                p.add_mesh(grid, style="wireframe", color="slategray", opacity=0.5, line_width=1, lighting=False,
                           pickable=False, name="embedding_grid")  # fmt: skip
                waist = pv.Polygon(center=(0.0, 0.0, 0.0), radius=self.metric.throat if self._embedding else
                                   float(np.min(np.linalg.norm(mesh.points[:, :2], axis=1))), normal=(0, 0, 1),
                                   n_sides=96, fill=False)  # fmt: skip
                p.add_mesh(waist, color=_FEATURE_STYLE["throat"][0], line_width=3, pickable=False, name="waist")
                legend += [("our sheet", "lightsteelblue"), ("other sheet", "lightsalmon"),
                           ("throat", _FEATURE_STYLE["throat"][0])]  # fmt: skip
                focus.append(mesh)
                continue
            if name == "throat" and "embedding" in features:  # drawn as the waist of the embedding diagram
                continue
            color, opacity = _FEATURE_STYLE.get(name, ("gray", 0.2))
            p.add_mesh(mesh, color=color, opacity=opacity, pickable=False, smooth_shading=True, name=name)
            legend.append((name.replace("_", " ") if not (name == "photon_sphere" and "photon_prograde" in self.metric.landmarks)
                           else "photon region", color))  # fmt: skip
            focus.append(mesh)

        surfaces = content.surfaces
        if surfaces is None and content.native_scene is not None and content.native_scene.get("shapes"):
            surfaces = scene_surfaces(content.native_scene)
        if surfaces is not None and surfaces.n_cells and not self._embedding:
            surfaces.cell_data["display_rgb"] = _surface_rgb(surfaces, content.native_scene)
            p.add_mesh(surfaces, scalars="display_rgb", rgb=True, opacity=0.3, show_scalar_bar=False,
                       pickable=False, name="surfaces")  # fmt: skip
            focus.append(surfaces)

        if self.camera is not None:
            if self._embedding:
                pos = self._embed(np.asarray([self.camera["position"]], dtype=np.float64), self.camera.get("sheet", 1))
                marker = pv.PolyData(pos)
                p.add_mesh(marker, color=_FRUSTUM_COLOR, point_size=12, render_points_as_spheres=True,
                           pickable=False, name="camera")  # fmt: skip
                focus.append(marker)
            else:
                frustum = camera_frustum(self.camera)
                p.add_mesh(frustum, color=_FRUSTUM_COLOR, line_width=2, pickable=False, name="camera")
                focus.append(frustum)
            legend.append(("camera", _FRUSTUM_COLOR))

        shown = None
        if self.rays is not None and self.rays.n_cells:
            shown = self.rays.copy()
            if self._embedding and "sheet" in shown.point_data:
                shown.points = ellis_embedding_points(self.metric, shown.points, shown.point_data["sheet"])
            if color_by not in shown.point_data:
                raise ValueError(f"color_by={color_by!r} is not a point array of the rays; "
                                 f"available: {', '.join(sorted(shown.point_data.keys()))}")  # fmt: skip
            values = np.asarray(shown.point_data[color_by], dtype=np.float64)
            finite = values[np.isfinite(values)]
            lo, hi = (float(finite.min()), float(finite.max())) if finite.size else (0.0, 1.0)
            if color_by == "log10_error":
                lo, hi = max(lo, _LOG10_FLOOR), max(hi, _LOG10_FLOOR)
            if hi <= lo:
                lo, hi = lo - 0.5, lo + 0.5
            self._rays_actor = p.add_mesh(
                shown, scalars=color_by, cmap="plasma", clim=(lo, hi), line_width=2, lighting=False, name="rays",
                scalar_bar_args={"title": SCALAR_TITLES.get(color_by, color_by), "vertical": False,
                                 "position_x": 0.25, "position_y": 0.03, "width": 0.5, "height": 0.06,
                                 "title_font_size": 12, "label_font_size": 10, "n_labels": 4, "fmt": "%.3g"},
            )  # fmt: skip
            starts = None if self.camera is not None else _first_points(shown)
            if "pixel_x" in shown.cell_data:
                legend.append(("selected pixel's rays", _SELECTED_COLOR))
            legend.append(("clicked ray", _PICKED_COLOR))
        if self.camera is not None:
            legend.append(("flat-space ray", _FLAT_COLOR))
        if legend:
            p.add_legend(labels=[list(item) for item in legend], bcolor=None, size=(0.22, 0.04 * len(legend) + 0.02),
                         loc="upper right", face=None, name="legend")  # fmt: skip
        p.add_text(f"{self.title}: click a ray" + ("   f: flat-space ray" if self.camera is not None else ""),
                   position="upper_left", font_size=9, name="scene_title")  # fmt: skip

        self._focus = _focus_bounds(focus)
        if shown is not None and self.camera is None:  # traced rays: the landmarks and where the rays start
            self._focus = _around(self._focus, starts) if self._focus is not None else _focus_bounds([shown])
        self._set_3d_camera()
        return shown

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

    def _planar_rays(self) -> bool:
        """Whether all rays lie in a plane z = const."""
        if self.rays is None or not self.rays.n_points:
            return False
        b = self.rays.bounds
        return b[5] - b[4] <= 1e-6 * max(b[1] - b[0], b[3] - b[2], 1e-300)

    def _embed(self, points: np.ndarray, sheet) -> np.ndarray:
        sheets = np.broadcast_to(np.asarray(sheet), (points.shape[0],))
        return ellis_embedding_points(self.metric, points, sheets)

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
        """Indices of the rays highlighted now, shape (K,) int64 (the selected pixels' rays and the
        picked ray)."""
        if self.rays is None:
            return np.zeros(0, dtype=np.int64)
        ids = [rays_for_pixel(self.rays, x, y) for x, y in self.selected]
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

    def flat_rays(self) -> np.ndarray:
        """The flat-space camera rays of the selected pixels as drawn: (K, 2, 3) float64 segments in the
        user frame (empty without a camera)."""
        if self.camera is None or not self.selected:
            return np.zeros((0, 2, 3))
        length = self._flat_length()
        return np.stack([flat_camera_ray(self.camera, x, y, length=length) for x, y in self.selected])

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
        self._status_actor.SetText(0, self.status())  # corner 0: lower left

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
        box = getattr(self, "_flat_box", None)
        if box is not None and box.GetRepresentation().GetState() != int(self.flat_visible):
            box.GetRepresentation().SetState(int(self.flat_visible))
        p.render()  # a no-op until the window is shown

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
        return "; ".join(parts) if parts else "nothing selected"

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
        style = iren.style
        if hasattr(style, "add_observer"):  # keep VTK's own "f" (fly to the point under the mouse) out of it
            style.add_observer("CharEvent", _weak(self._on_char))
        if self.camera is not None:  # a tick box for the flat rays, bottom left of the 3-D panel
            self.plotter.subplot(0, 1 if self._image_renderer is not None else 0)
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


def _theme(theme):
    if theme is None or not isinstance(theme, str):
        return theme
    from pyvista.plotting import themes

    if theme not in _THEMES:
        raise ValueError(f"unknown theme {theme!r}; known: {', '.join(_THEMES)} (or a pyvista Theme)")
    return getattr(themes, _THEMES[theme])()


# --------------------------------------------------------------------------------------------------
# entry point


def view(
    obj,
    *,
    off_screen: bool | None = None,
    screenshot: str | os.PathLike | None = None,
    window_size: tuple[int, int] = (1400, 700),
    pixels=None,
    show_flat: bool = False,
    color_by: str = "log10_error",
    theme=None,
    return_plotter: bool = False,
    preview_width: int = 96,
    spp: int = 4,
    jupyter_backend: str | None = None,
):
    """Show a render beside the 3-D paths of its light rays.

    Parameters
    ----------
    obj : Image, RayBundle, str, os.PathLike, warpviz.scene.Scene or dict
        An :class:`~warpviz.Image` from :func:`warpviz.render` (rendered with ``record_pixels`` to have
        paths to show), a recorded :class:`~warpviz.RayBundle`, a ``.vtp`` ray file or scene ``.vtm``,
        or a scene (file, Scene or native dict), which is first rendered at ``preview_width`` pixels
        across, recording the paths of ``pixels`` or of an 8 x 6 grid of pixels.
    off_screen : bool, optional, keyword-only
        Render without a window; default :func:`default_off_screen` (off-screen without a display or
        with ``PYVISTA_OFF_SCREEN=true``).
    screenshot : str or os.PathLike, optional, keyword-only
        Write a PNG of the window (atomically). Off-screen it is written at once and the window closed;
        on-screen when the window is closed.
    window_size : tuple of int, keyword-only
        (width, height) of the window in screen pixels.
    pixels : array_like of int, optional, keyword-only
        (K, 2) pixels (x, y) selected at the start: outlined in the image, their paths highlighted (and
        their flat-space rays drawn with ``show_flat``). For a scene, the pixels whose paths are
        recorded (at the preview size).
    show_flat : bool, keyword-only
        Start with the straight flat-space camera rays of the selected pixels shown (key ``f``).
    color_by : str, keyword-only
        Point array the rays are coloured by (``"log10_error"``, ``"r"``, ``"affine_param"``, ...).
    theme : str or pyvista.plotting.themes.Theme, optional, keyword-only
        ``"document"``, ``"dark"``, ``"paraview"``, ``"document_pro"`` or a Theme; default PyVista's.
    return_plotter : bool, keyword-only
        Return the (not yet shown) plotter instead of showing it; its ``teaching_view`` attribute is
        the :class:`TeachingView`. Close it with ``plotter.close()``.
    preview_width : int, keyword-only
        Width in pixels of the preview render of a scene.
    spp : int, keyword-only
        Samples per pixel of the preview render.
    jupyter_backend : str, optional, keyword-only
        Passed to :meth:`pyvista.Plotter.show` in Jupyter: ``"trame"`` (server-side rendering: clicks
        and keys work), ``"client"`` (browser-side, no picking) or ``"static"`` (a picture).

    Returns
    -------
    pyvista.Plotter or pathlib.Path or None
        The plotter with ``return_plotter``; else the screenshot path, or None.

    Raises
    ------
    TypeError
        ``obj`` is none of the accepted kinds.
    ValueError
        A bundle without recorded paths, or ``color_by`` not a point array of the rays.

    Examples
    --------
    >>> import warpviz as wv
    >>> rays = wv.trace(wv.Schwarzschild(mass=1.0), [-30.0, 0, 0], [[1, 0.1, 0], [1, 0.2, 0]], record=True)
    >>> plotter = wv.view(rays, off_screen=True, return_plotter=True, window_size=(300, 200))
    >>> plotter.teaching_view.select_ray(1) is None   # traced rays have no pixels
    True
    >>> plotter.teaching_view.selected_rays().tolist()
    [1]
    >>> plotter.close()
    """
    import pyvista as pv

    if screenshot is not None and Path(screenshot).suffix.lower() != ".png":
        raise ValueError(f"screenshot must be a .png file, got {str(screenshot)!r}")
    theme = _theme(theme)
    if pixels is not None:
        pixels = np.asarray(pixels, dtype=np.int64).reshape(-1, 2)
    content = view_content(obj, pixels=pixels, preview_width=preview_width, spp=spp)
    if off_screen is None:
        off_screen = default_off_screen()
    shape = (1, 2) if content.image is not None else (1, 1)
    plotter = pv.Plotter(shape=shape, off_screen=bool(off_screen), window_size=list(window_size),
                         theme=theme, border=False)  # fmt: skip
    try:
        teaching = TeachingView(content, plotter, color_by=color_by, show_flat=show_flat)
        if pixels is not None:
            teaching.select_pixels(pixels)
        getattr(pv, "set_new_attribute", setattr)(plotter, "teaching_view", teaching)
    except BaseException:
        plotter.close()
        raise

    if return_plotter:
        if screenshot is not None:
            _save_screenshot(plotter, screenshot)
        return plotter
    if off_screen:
        try:
            return _save_screenshot(plotter, screenshot) if screenshot is not None else None
        finally:
            plotter.close()
    shot = Path(screenshot) if screenshot is not None else None
    plotter.show(title=f"warpviz: {content.title}", screenshot=str(shot) if shot else None,
                 jupyter_backend=jupyter_backend)  # fmt: skip
    return shot


def _save_screenshot(plotter, path: str | os.PathLike) -> Path:
    """Render and write a PNG of the window, atomically."""
    from warpviz.io import atomic_write

    return atomic_write(Path(path), lambda tmp: plotter.screenshot(str(tmp)))
