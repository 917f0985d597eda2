"""The scene model: :class:`Scene`, a validated scene ready to render, and its native scene dict.

A Scene holds what a scene file describes with every name resolved and every image and mesh loaded;
:meth:`Scene.native` hands the renderer the plain dictionary of ``docs/native-scene.md`` (a fresh copy
each call, optionally in flat space or at another size), completed by :mod:`warpviz.scene.native`. Scenes are built by
:func:`~warpviz.scene.loader.load_scene` (a TOML file) or :func:`~warpviz.scene.loader.scene_from_dict` (the
same structure as a dict); this module does not import the loader (the loader imports it).

Examples
--------
>>> from warpviz.scene import scene_from_dict
>>> scene = scene_from_dict({"version": 1, "metric": {"name": "schwarzschild", "mass": 1.0},
...                          "camera": {"position": [0, -20.0, 0]}}, base_dir=".")
>>> scene.summary()
'Schwarzschild(mass=1.0), 96x72, 0 shapes (0 emissive)'
>>> scene.native(width=8, height=6)["camera"]["fov"]
40.0
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, field
from pathlib import Path

from warpviz.limits import image_side
from warpviz.options import SCENE_OPTIONS
from warpviz.scene.native import native_scene
from warpviz.spacetime import Metric

__all__ = ["DEFAULT_SIZE", "RENDER_OPTION_KEYS", "Scene"]

#: [render] keys that are renderer options (warpviz/options.py), besides width/height, the image size.
RENDER_OPTION_KEYS = SCENE_OPTIONS

DEFAULT_SIZE = (96, 72)


@dataclass(frozen=True, eq=False)
class Scene:
    """A validated scene, ready to render.

    Build one with :func:`load_scene` (a TOML file) or :func:`~warpviz.scene.loader.scene_from_dict` (a dict). All images and meshes
    are loaded and all names resolved when it is built, so a Scene that exists renders.

    Attributes
    ----------
    path : Path or None
        The scene file (None for a scene built from a dict).
    description : str
        What the scene shows.
    metric : Metric
        The spacetime.
    camera : dict
        ``position``, ``look_at``, ``up``, ``fov``, ``sheet``.
    outputs : dict
        ``aovs`` (list of AOV names, or None for all), ``file`` (default output file, or None),
        ``tonemap`` and ``exposure`` (how a PNG is tonemapped, or None for the defaults of
        :mod:`warpviz.render.tonemap`).
    """

    path: Path | None
    description: str
    metric: Metric
    camera: dict
    outputs: dict
    _render: dict = field(repr=False)
    _paper: dict = field(repr=False)
    _textures: list = field(repr=False)
    _materials: list = field(repr=False)
    _shapes: list = field(repr=False)
    _lights: list = field(repr=False)
    _environment: dict = field(repr=False)
    _environment_other: dict | None = field(repr=False)

    # ------------------------------------------------------------------ queries
    @property
    def has_paper(self) -> bool:
        """Whether the scene has a ``[render.paper]`` table (the size and samples of its paper figure)."""
        return bool(self._paper)

    def size(self, *, paper: bool = False) -> tuple[int, int]:
        """Image (width, height) in pixels, from [render] or, with ``paper``, [render.paper]."""
        w, h = self._render.get("width", DEFAULT_SIZE[0]), self._render.get("height", DEFAULT_SIZE[1])
        if paper:
            w, h = self._paper.get("width", w), self._paper.get("height", h)
        return w, h

    def render_settings(self, *, paper: bool = False) -> dict:
        """The renderer options (keys of docs/native-scene.md's ``options``) that the scene sets.

        Parameters
        ----------
        paper : bool, keyword-only
            Apply the ``[render.paper]`` overrides.
        """
        settings = {k: v for k, v in self._render.items() if k in RENDER_OPTION_KEYS}
        if paper:
            settings.update({k: v for k, v in self._paper.items() if k in RENDER_OPTION_KEYS})
        return settings

    def native(self, *, flat: bool = False, width: int | None = None, height: int | None = None,
               paper: bool = False) -> dict:  # fmt: skip
        """The native scene dict of docs/native-scene.md (a fresh copy each call).

        Parameters
        ----------
        flat : bool, keyword-only
            Replace the metric by flat space (``{"name": "minkowski", "params": []}``) to compare with
            the curved picture. For a wormhole only the camera's own sheet is kept (as flat space),
            with that sheet's sky.
        width, height : int, optional, keyword-only
            Image size, overriding the scene's.
        paper : bool, keyword-only
            Use the ``[render.paper]`` image size.

        Returns
        -------
        dict
            ``metric``, ``camera``, ``textures``, ``materials``, ``shapes``, ``lights``, ``environment`` and
            ``environment_other`` (a wormhole's other sky; otherwise the same dict as ``environment``),
            every key written (:func:`warpviz.scene.native.native_scene`).
        """
        w, h = self.size(paper=paper)
        w = w if width is None else image_side("width", width)
        h = h if height is None else image_side("height", height)
        camera = dict(copy.deepcopy(self.camera), width=w, height=h)
        shapes = copy.deepcopy(self._shapes)
        lights = copy.deepcopy(self._lights)
        environment = copy.deepcopy(self._environment)
        other = copy.deepcopy(self._environment_other)
        if flat:
            metric = {"name": "minkowski", "params": []}
            sheet = camera["sheet"]
            shapes = [dict(s, sheet=1) for s in shapes if s["sheet"] == sheet]
            lights = [dict(s, sheet=1) for s in lights if s["sheet"] == sheet]
            if sheet == -1 and other is not None:
                environment = other
            other = None
            camera["sheet"] = 1
            # flat space keeps a camera's velocity; the observers that gravity defines are at rest there
            if (camera.get("observer") or {}).get("kind") not in (None, "moving"):
                camera["observer"] = None
        else:
            metric = {"name": self.metric.name, "params": list(self.metric.param_values)}
        return native_scene({
            "metric": metric,
            "camera": camera,
            "textures": copy.deepcopy(self._textures),
            "materials": copy.deepcopy(self._materials),
            "shapes": shapes,
            "lights": lights,
            "environment": environment,
            "environment_other": other,
        })  # fmt: skip

    def summary(self) -> str:
        """One line: metric, image size, shapes and lights."""
        w, h = self.size()
        emissive = {i for i, m in enumerate(self._materials) if m["type"] == "emissive"}
        lights = sum(1 for s in self._shapes if s["material"] in emissive)
        points = f", {len(self._lights)} point or spot lights" if self._lights else ""
        return f"{self.metric!r}, {w}x{h}, {len(self._shapes)} shapes ({lights} emissive){points}"

    def __repr__(self) -> str:
        where = self.path.name if self.path is not None else "<dict>"
        return f"Scene({where!r}, {self.metric!r})"
