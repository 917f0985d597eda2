"""Scenes: load a TOML scene, validate it with precise messages, and build the native scene dict.

The format is described in ``docs/scene-format.md``; the dictionary handed to the renderer in
``docs/native-scene.md``. Every problem raises :class:`SceneError` whose message starts with
``file:line:column:`` (the line and column of the offending key or value) and names the key path.

Modules, by concern:

* :mod:`~warpviz.scene.loader` -- :func:`load_scene`: reads the file and builds the Scene (:func:`scene_from_dict`: the same from a dict);
* :mod:`~warpviz.scene.reader` -- :class:`SceneError` and the checks behind every message, with
  :mod:`~warpviz.scene._toml_positions` finding the line and column of a key;
* :mod:`~warpviz.scene.model` -- :class:`Scene` and its native scene dict;
* :mod:`~warpviz.scene.native` -- :func:`native_scene`: the one validator of a native scene dict, by
  hand or from a file, which writes every key (its ``SCHEMA`` holds the only defaults);
* :mod:`~warpviz.scene.settings`, :mod:`~warpviz.scene.appearance`, :mod:`~warpviz.scene.objects` --
  the compilers of the scene tables to native scene entries;
* :mod:`~warpviz.scene.catalog` (the shipped scenes), :mod:`~warpviz.scene.textures` (texture images),
  :mod:`~warpviz.scene.primitives` (boxes, cylinders, transforms), :mod:`~warpviz.scene.camera` (the
  pinhole camera: the renderer's, from the core) and :mod:`~warpviz.scene.surfaces` (display meshes of the shapes
  and the camera).

Examples
--------
>>> from warpviz.scene import load_scene
>>> scene = load_scene("fig07")                         # a shipped scene, by name
>>> scene.metric
Schwarzschild(mass=2.5)
>>> native = scene.native(width=32, height=24)
>>> native["camera"]["width"], native["metric"]
(32, {'name': 'schwarzschild', 'params': [2.5]})
>>> scene.native(flat=True)["metric"]
{'name': 'minkowski', 'params': []}
"""

from warpviz.scene import primitives, textures
from warpviz.scene.camera import camera_basis, flat_camera_ray, pinhole_directions
from warpviz.scene.catalog import looks_like_path, resolve_scene, scene_description, scene_dirs, shipped_scenes
from warpviz.scene.loader import FORMAT_VERSION, load_scene, scene_from_dict
from warpviz.scene.model import DEFAULT_SIZE, RENDER_OPTION_KEYS, Scene
from warpviz.scene.native import native_scene
from warpviz.scene.objects import MESH_SUFFIXES
from warpviz.scene.reader import SceneError, key_name
from warpviz.scene.settings import AOV_NAMES
from warpviz.scene.surfaces import camera_frustum, scene_lights, scene_surfaces

__all__ = [
    "AOV_NAMES",
    "DEFAULT_SIZE",
    "FORMAT_VERSION",
    "MESH_SUFFIXES",
    "RENDER_OPTION_KEYS",
    "Scene",
    "SceneError",
    "key_name",
    "load_scene",
    "scene_from_dict",
    "native_scene",
    "looks_like_path",
    "resolve_scene",
    "scene_description",
    "scene_dirs",
    "shipped_scenes",
    "camera_basis",
    "flat_camera_ray",
    "pinhole_directions",
    "camera_frustum",
    "scene_lights",
    "scene_surfaces",
    "primitives",
    "textures",
]
