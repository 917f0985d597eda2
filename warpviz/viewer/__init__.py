"""The teaching view: a rendered image beside the 3-D paths of its light rays, linked by clicks.

:func:`view` (:mod:`~warpviz.viewer.viewer`) opens the window; :mod:`~warpviz.viewer.window` holds its
state (:class:`TeachingView`), :mod:`~warpviz.viewer.view_content` gathers what is shown from a render,
rays, a file or a scene, :mod:`~warpviz.viewer.picking` maps pixels to recorded rays and back,
:mod:`~warpviz.viewer.annotations` names what is drawn (colour bars,
labels, title, legend), :mod:`~warpviz.viewer.meshes` builds the display meshes and :mod:`~warpviz.viewer.offscreen` decides
whether a window opens. PyVista and VTK are imported when a view is made, not with this package.
"""

from warpviz.viewer.offscreen import default_off_screen
from warpviz.viewer.picking import (
    image_cell_to_pixel,
    pixel_for_ray,
    pixel_to_image_cell,
    ray_pixels,
    rays_for_pixel,
    recorded_pixels,
    sparse_pixel_grid,
)
from warpviz.viewer.view_content import ViewContent, camera_from_frustum, view_content
from warpviz.viewer.viewer import view
from warpviz.viewer.window import SCALAR_TITLES, TeachingView

__all__ = [
    "SCALAR_TITLES",
    "TeachingView",
    "ViewContent",
    "camera_from_frustum",
    "default_off_screen",
    "image_cell_to_pixel",
    "pixel_for_ray",
    "pixel_to_image_cell",
    "ray_pixels",
    "rays_for_pixel",
    "recorded_pixels",
    "sparse_pixel_grid",
    "view",
    "view_content",
]
