"""Export: a whole scene as one VTK multiblock (rays, scene surfaces, landmarks, camera) and its ``.vtm`` file.

The file formats themselves (atomic writes, ``.vtp``, ``.vtm``, reading rays back) are in
:mod:`warpviz.io`, below every layer, since rays and images save themselves through it too. PyVista is
imported when a multiblock is built, not with this package.
"""

from warpviz.export.export import BLOCK_NAMES, save_scene_vtm, scene_multiblock

__all__ = ["BLOCK_NAMES", "save_scene_vtm", "scene_multiblock"]
