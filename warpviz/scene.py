"""Scene files: load a TOML scene, validate it with precise messages, and build the native scene dict.

The format is described in ``docs/scene-format.md``; the dictionary handed to the renderer in
``docs/native-scene.md``. Every problem raises :class:`SceneError` whose message starts with
``file:line:column:`` (the line and column of the offending key or value) and names the key path.

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

from __future__ import annotations

import copy
import difflib
import math
import numbers
import re
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from warpviz import primitives, textures
from warpviz._native import core, registered_metrics
from warpviz._toml_positions import TomlPositions
from warpviz.catalog import resolve_scene
from warpviz.metrics import Metric, metric_from_dict
from warpviz.trace import STEPPERS

FORMAT_VERSION = 1

AOV_NAMES = ("redshift", "n_steps", "max_drift", "status", "depth", "normal", "errors", "samples")

#: [render] keys that are renderer options (docs/native-scene.md), with width/height the image size.
RENDER_OPTION_KEYS = (
    "spp", "seed", "max_depth", "rr_depth", "light_sampling", "stepper", "tol", "max_steps",
    "escape_radius", "max_drift", "chord_tolerance",
)  # fmt: skip

DEFAULT_SIZE = (96, 72)

# allowed range of each metric parameter: (low, high), both exclusive

_REQUIRED = object()


class SceneError(ValueError):
    """A scene file or scene dict that cannot be used, with where and why.

    Attributes
    ----------
    reason : str
        The message without the location.
    path : str or None
        The scene file.
    line, column : int or None
        1-based position of the offending key or value in the file.
    key : str or None
        Key path such as ``"metric.spin"`` or ``"objects[2].radius"``.
    """

    def __init__(self, reason: str, *, path: str | None = None, line: int | None = None,
                 column: int | None = None, key: str | None = None):  # fmt: skip
        self.reason, self.path, self.line, self.column, self.key = reason, path, line, column, key
        where = ""
        if path is not None:
            where = f"{path}:{line}:{column}: " if line is not None else f"{path}: "
        super().__init__(where + reason)


def key_name(path: tuple) -> str:
    """Dotted display form of a key path: ``("objects", 2, "radius")`` -> ``"objects[2].radius"``."""
    out = ""
    for part in path:
        if isinstance(part, int):
            out += f"[{part}]"
        else:
            text = part if re.fullmatch(r"[A-Za-z0-9_-]+", part) else f'"{part}"'
            out += f".{text}" if out else text
    return out


# ---------------------------------------------------------------------------------------------- reader
class _Reader:
    """Validation helpers that turn problems into SceneErrors at the right file position."""

    def __init__(self, *, label: str | None, positions: TomlPositions | None, base_dir: Path):
        self.label, self.positions, self.base_dir = label, positions, base_dir

    def error(self, path: tuple, reason: str, *, at_value: bool = True) -> SceneError:
        line = column = None
        if self.positions is not None:
            line, column = self.positions.locate(path, prefer_value=at_value)
        return SceneError(reason, path=self.label, line=line, column=column, key=key_name(path) or None)

    def table(self, path: tuple, value: Any, allowed, *, required=(), what: str | None = None) -> dict:
        """Check ``value`` is a table with only ``allowed`` keys and every ``required`` one."""
        where = what or (f"[{key_name(path)}]" if path else "the top level")
        if not isinstance(value, dict):
            raise self.error(path, f"{key_name(path) or 'the scene'} must be a table, got {_describe(value)}")
        for k in value:
            if k not in allowed:
                close = difflib.get_close_matches(k, list(allowed), n=1, cutoff=0.6)
                hint = f"; did you mean {close[0]!r}?" if close else ""
                known = ", ".join(sorted(allowed))
                raise self.error(path + (k,), f"unknown key {k!r} in {where}{hint} (allowed: {known})", at_value=False)
        for k in required:
            if k not in value:
                raise self.error(path, f"{where} is missing the required key {k!r}", at_value=False)
        return value

    def get(self, tbl: dict, path: tuple, name: str, default: Any = _REQUIRED) -> Any:
        if name in tbl:
            return tbl[name]
        if default is _REQUIRED:
            where = key_name(path) or "the scene"
            raise self.error(path, f"{where} is missing the required key {name!r}", at_value=False)
        return default

    def real(self, tbl, path, name, default=_REQUIRED, *, lo=None, hi=None, lo_open=True, hi_open=True) -> float:
        value = self.get(tbl, path, name, default)
        kp = path + (name,)
        if isinstance(value, bool) or not isinstance(value, numbers.Real):
            raise self.error(kp, f"{key_name(kp)} must be a number, got {_describe(value)}")
        value = float(value)
        if not math.isfinite(value):
            raise self.error(kp, f"{key_name(kp)} must be finite, got {value}")
        _check_range(self, kp, value, lo, hi, lo_open, hi_open)
        return value

    def integer(self, tbl, path, name, default=_REQUIRED, *, lo=None, hi=None) -> int:
        value = self.get(tbl, path, name, default)
        kp = path + (name,)
        if isinstance(value, bool) or not isinstance(value, numbers.Integral):
            raise self.error(kp, f"{key_name(kp)} must be an integer, got {_describe(value)}")
        _check_range(self, kp, int(value), lo, hi, False, False)
        return int(value)

    def boolean(self, tbl, path, name, default=_REQUIRED) -> bool:
        value = self.get(tbl, path, name, default)
        if not isinstance(value, bool):
            kp = path + (name,)
            raise self.error(kp, f"{key_name(kp)} must be true or false, got {_describe(value)}")
        return value

    def string(self, tbl, path, name, default=_REQUIRED) -> str:
        value = self.get(tbl, path, name, default)
        if not isinstance(value, str):
            raise self.error(path + (name,), f"{key_name(path + (name,))} must be a string, got {_describe(value)}")
        return value

    def choice(self, tbl, path, name, options, default=_REQUIRED) -> str:
        value = self.string(tbl, path, name, default)
        if value not in options:
            close = difflib.get_close_matches(value, list(options), n=1, cutoff=0.6)
            hint = f"; did you mean {close[0]!r}?" if close else ""
            raise self.error(
                path + (name,), f"{key_name(path + (name,))} = {value!r} is not one of {', '.join(options)}{hint}"
            )
        return value

    def numbers(self, tbl, path, name, n, default=_REQUIRED, *, integer=False, lo=None, hi=None, lo_open=False) -> list:
        value = self.get(tbl, path, name, default)
        kp = path + (name,)
        kind = "integers" if integer else "numbers"
        kind_type = numbers.Integral if integer else numbers.Real
        ok = isinstance(value, (list, tuple)) and len(value) == n
        ok = ok and all(not isinstance(x, bool) and isinstance(x, kind_type) for x in value)
        if not ok:
            raise self.error(kp, f"{key_name(kp)} must be a list of {n} {kind}, got {_describe(value)}")
        out = [int(x) if integer else float(x) for x in value]
        for i, x in enumerate(out):
            if not math.isfinite(x):
                raise self.error(kp + (i,), f"{key_name(kp)}[{i}] must be finite, got {x}")
            _check_range(self, kp + (i,), x, lo, hi, lo_open, False, label=f"{key_name(kp)}[{i}]")
        return out

    def vec3(self, tbl, path, name, default=_REQUIRED, *, nonzero=False) -> list[float]:
        v = self.numbers(tbl, path, name, 3, default)
        if nonzero and not any(v):
            raise self.error(path + (name,), f"{key_name(path + (name,))} must not be the zero vector")
        return v

    def color(self, tbl, path, name, default=_REQUIRED, *, albedo=False) -> list[float]:
        """Linear RGB: three numbers >= 0, and <= 1 for reflectances (``albedo``)."""
        return self.numbers(tbl, path, name, 3, default, lo=0.0, hi=1.0 if albedo else None)

    def file(self, tbl, path, name, *, kind: str, suffixes=None) -> Path:
        rel = self.string(tbl, path, name)
        kp = path + (name,)
        p = Path(rel)
        full = p if p.is_absolute() else self.base_dir / p
        if suffixes is not None and p.suffix.lower() not in suffixes:
            raise self.error(kp, f"{key_name(kp)} = {rel!r}: unsupported {kind} format (use {', '.join(suffixes)})")
        if not full.is_file():
            raise self.error(
                kp, f"{key_name(kp)}: {kind} file {rel!r} not found (paths are relative to the scene file's folder)"
            )
        return full


def _check_range(r: _Reader, kp, value, lo, hi, lo_open, hi_open, *, label=None) -> None:
    label = label or key_name(kp)
    bad_lo = lo is not None and (value <= lo if lo_open else value < lo)
    bad_hi = hi is not None and (value >= hi if hi_open else value > hi)
    if not (bad_lo or bad_hi):
        return
    if lo is not None and hi is not None and math.isfinite(hi):
        left, right = ("(" if lo_open else "["), (")" if hi_open else "]")
        raise r.error(kp, f"{label} must be in {left}{_num(lo)}, {_num(hi)}{right}, got {_num(value)}")
    if bad_lo:
        raise r.error(kp, f"{label} must be {'>' if lo_open else '>='} {_num(lo)}, got {_num(value)}")
    raise r.error(kp, f"{label} must be {'<' if hi_open else '<='} {_num(hi)}, got {_num(value)}")


def _num(x) -> str:
    return f"{x:g}" if isinstance(x, float) else str(x)


def _describe(value: Any) -> str:
    if isinstance(value, dict):
        return "a table"
    if isinstance(value, list):
        return f"a list of {len(value)}" if len(value) != 1 else "a list of 1"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return f"the string {value!r}"
    return repr(value)


# ---------------------------------------------------------------------------------------------- scene
@dataclass(frozen=True, eq=False)
class Scene:
    """A validated scene, ready to render.

    Build one with :func:`load_scene` (a TOML file) or :meth:`Scene.from_dict`. All images and meshes
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
        ``aovs`` (list of AOV names, or None for all) and ``file`` (default output file, or None).
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
    _environment: dict = field(repr=False)
    _environment_other: dict | None = field(repr=False)

    # ------------------------------------------------------------------ construction
    @classmethod
    def from_dict(cls, data: dict, *, base_dir: str | Path) -> Scene:
        """Validate a parsed scene (the structure of a scene file) and load what it refers to.

        Parameters
        ----------
        data : dict
            As :func:`tomllib.loads` returns for a scene file (tuples may stand for lists).
        base_dir : str or Path, keyword-only
            Folder that relative mesh and image paths start from.

        Returns
        -------
        Scene

        Raises
        ------
        SceneError
            The first problem found; the message names the key path (there are no line numbers).
        """
        return _build(_Reader(label=None, positions=None, base_dir=Path(base_dir)), data, path=None)

    # ------------------------------------------------------------------ queries
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
            ``metric``, ``camera``, ``textures``, ``materials``, ``shapes``, ``environment`` and, for a
            wormhole with a sky of its own on the other side, ``environment_other``.
        """
        w, h = self.size(paper=paper)
        for name, value in (("width", width), ("height", height)):
            if value is not None and (isinstance(value, bool) or not isinstance(value, numbers.Integral) or value < 1):
                raise ValueError(f"{name} must be a positive integer, got {value!r}")
        w, h = int(width or w), int(height or h)
        camera = dict(copy.deepcopy(self.camera), width=w, height=h)
        shapes = copy.deepcopy(self._shapes)
        environment = copy.deepcopy(self._environment)
        other = copy.deepcopy(self._environment_other)
        if flat:
            metric = {"name": "minkowski", "params": []}
            sheet = camera["sheet"]
            shapes = [dict(s, sheet=1) for s in shapes if s["sheet"] == sheet]
            if sheet == -1 and other is not None:
                environment = other
            other = None
            camera["sheet"] = 1
        else:
            metric = {"name": self.metric.name, "params": list(self.metric.param_values)}
        out = {
            "metric": metric,
            "camera": camera,
            "textures": copy.deepcopy(self._textures),
            "materials": copy.deepcopy(self._materials),
            "shapes": shapes,
            "environment": environment,
        }
        if other is not None:
            out["environment_other"] = other
        return out

    def summary(self) -> str:
        """One line: metric, image size, shapes and lights."""
        w, h = self.size()
        emissive = {i for i, m in enumerate(self._materials) if m["type"] == "emissive"}
        lights = sum(1 for s in self._shapes if s["material"] in emissive)
        return f"{self.metric!r}, {w}x{h}, {len(self._shapes)} shapes ({lights} emissive)"

    def __repr__(self) -> str:
        where = self.path.name if self.path is not None else "<dict>"
        return f"Scene({where!r}, {self.metric!r})"


def load_scene(path: str | Path) -> Scene:
    """Read, validate and load a scene file.

    Parameters
    ----------
    path : str or Path
        A TOML scene file, or the name of a shipped scene (``"fig07"``; see :mod:`warpviz.catalog`).

    Returns
    -------
    Scene

    Raises
    ------
    SceneError
        Unreadable file, TOML syntax error, or invalid content; the message starts with
        ``file:line:column:``.
    """
    try:
        file = resolve_scene(path)
    except (FileNotFoundError, LookupError) as exc:
        raise SceneError(str(exc.args[0] if exc.args else exc)) from None
    label = str(path) if Path(path).is_file() else str(file)
    try:
        text = file.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise SceneError(f"cannot read the scene file: {exc}", path=label) from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        line, column, reason = _toml_error_position(str(exc), text)
        raise SceneError(f"TOML syntax error: {reason}", path=label, line=line, column=column) from None
    reader = _Reader(label=label, positions=TomlPositions(text), base_dir=file.parent)
    return _build(reader, data, path=file)


def _toml_error_position(message: str, text: str) -> tuple[int, int, str]:
    m = re.search(r"\s*\(at line (\d+), column (\d+)\)\s*$", message)
    if m:
        return int(m.group(1)), int(m.group(2)), message[: m.start()]
    m = re.search(r"\s*\(at end of document\)\s*$", message)
    if m:
        lines = text.split("\n")
        return len(lines), len(lines[-1]) + 1, message[: m.start()] + " (at end of file)"
    return 1, 1, message


# ---------------------------------------------------------------------------------------------- building
_TOP_KEYS = ("version", "description", "metric", "camera", "render", "environment", "environment_other",
             "textures", "materials", "objects", "outputs")  # fmt: skip


def _build(r: _Reader, data: dict, *, path: Path | None) -> Scene:
    r.table((), data, _TOP_KEYS, what="the scene file")
    version = r.get(data, (), "version")
    if isinstance(version, bool) or not isinstance(version, int) or version != FORMAT_VERSION:
        why = f"version must be {FORMAT_VERSION} (the scene format this warpviz reads), got {_describe(version)}"
        raise r.error(("version",), why)
    description = r.string(data, (), "description", "")
    metric = _metric(r, r.get(data, (), "metric"))
    ellis = metric.sheets == 2  # a wormhole: objects, camera and sky may be on its other sheet
    camera = _camera(r, r.get(data, (), "camera"), metric)
    render, paper = _render(r, data.get("render", {}))
    environment = _environment(r, ("environment",), data.get("environment", {}))
    environment_other = None
    if "environment_other" in data:
        if not ellis:
            raise r.error(("environment_other",), "[environment_other] is the sky of a wormhole's other sheet; "
                          f"it needs metric.name = 'ellis', not {metric.name!r}", at_value=False)  # fmt: skip
        environment_other = _environment(r, ("environment_other",), data["environment_other"])
    tex_list, tex_index = _textures(r, data.get("textures", {}))
    mat_list, mat_index = _materials(r, data.get("materials", {}), tex_list, tex_index)
    shapes = _objects(r, data.get("objects", []), mat_index, ellis=ellis)
    outputs = _outputs(r, data.get("outputs", {}))
    return Scene(
        path=path, description=description.strip(), metric=metric, camera=camera, outputs=outputs,
        _render=render, _paper=paper, _textures=tex_list, _materials=mat_list, _shapes=shapes,
        _environment=environment, _environment_other=environment_other,
    )  # fmt: skip


def _metric(r: _Reader, tbl: Any) -> Metric:
    path = ("metric",)
    registry = {m["name"]: m for m in registered_metrics()}
    r.table(path, tbl, [*tbl], required=("name",))  # a table with a name; its keys are checked below
    name = r.choice(tbl, path, "name", list(registry))
    specs = {s["name"]: s for s in registry[name]["param_specs"]}
    r.table(path, tbl, ["name", *specs], what=f"[metric] ({name})")
    params = {}
    for key in tbl:
        if key == "name":
            continue
        s = specs[key]  # ranges from the core's registry
        lo = None if math.isinf(s["lo"]) else s["lo"]
        hi = None if math.isinf(s["hi"]) else s["hi"]
        params[key] = r.real(tbl, path, key, lo=lo, hi=hi, lo_open=s["lo_open"], hi_open=s["hi_open"])
    try:
        return metric_from_dict({"name": name, **params})
    except (TypeError, ValueError) as exc:  # a relation between parameters (|Q| < M), checked by the core
        raise r.error(path, f"metric: {str(exc).split(': ', 1)[-1]}", at_value=False) from None


def _camera(r: _Reader, tbl: Any, metric: Metric) -> dict:
    path = ("camera",)
    r.table(path, tbl, ("position", "look_at", "up", "fov", "sheet"), required=("position",))
    cam = {
        "position": r.vec3(tbl, path, "position"),
        "look_at": r.vec3(tbl, path, "look_at", [0.0, 0.0, 0.0]),
        "up": r.vec3(tbl, path, "up", [0.0, 0.0, 1.0], nonzero=True),
        "fov": r.real(tbl, path, "fov", 40.0, lo=0.0, hi=180.0),
        "sheet": _sheet(r, tbl, path, ellis=metric.sheets == 2),
    }
    forward = np.subtract(cam["look_at"], cam["position"])
    if not np.linalg.norm(forward) > 0:
        raise r.error(path + ("look_at",), "camera.look_at must differ from camera.position")
    up = np.asarray(cam["up"]) / np.linalg.norm(cam["up"])
    if np.linalg.norm(np.cross(forward / np.linalg.norm(forward), up)) < 1e-6:
        raise r.error(path + ("up",), "camera.up must not be parallel to the viewing direction (look_at - position)")
    problem = core.origin_problems(metric.name, metric.param_values, np.array([cam["position"]], dtype=np.float64),
                                   np.array([cam["sheet"]], dtype=np.int32))  # fmt: skip
    if problem is not None:
        raise r.error(path + ("position",), f"camera.position {cam['position']} {problem[1]}")
    return cam


def _sheet(r: _Reader, tbl: dict, path: tuple, *, ellis: bool) -> int:
    sheet = r.integer(tbl, path, "sheet", 1)
    if sheet not in (1, -1):
        raise r.error(path + ("sheet",), f"{key_name(path + ('sheet',))} must be 1 or -1, got {sheet}")
    if sheet == -1 and not ellis:
        kp = path + ("sheet",)
        why = "needs a wormhole (metric.name = 'ellis'); other spacetimes have one sheet"
        raise r.error(kp, f"{key_name(kp)} = -1 {why}")
    return sheet


_RENDER_CHECKS = {
    "width": ("integer", 1, 16384), "height": ("integer", 1, 16384), "spp": ("integer", 1, None),
    "seed": ("integer", 0, 2**63 - 1), "max_depth": ("integer", 1, 10000), "rr_depth": ("integer", 0, None),
    "light_sampling": ("boolean",), "stepper": ("choice", STEPPERS), "tol": ("real", 0.0, 1.0),
    "max_steps": ("integer", 1, None), "escape_radius": ("real", 0.0, None), "max_drift": ("real", 0.0, None),
    "chord_tolerance": ("real", 0.0, None),
}  # fmt: skip


def _render_table(r: _Reader, path: tuple, tbl: Any, *, allow_paper: bool) -> dict:
    allowed = list(_RENDER_CHECKS) + (["paper"] if allow_paper else [])
    r.table(path, tbl, allowed)
    out = {}
    for key in tbl:
        if key == "paper":
            continue
        kind, *args = _RENDER_CHECKS[key]
        if kind == "integer":
            out[key] = r.integer(tbl, path, key, lo=args[0], hi=args[1])
        elif kind == "real":
            out[key] = r.real(tbl, path, key, lo=args[0], hi=args[1])
        elif kind == "boolean":
            out[key] = r.boolean(tbl, path, key)
        else:
            out[key] = r.choice(tbl, path, key, args[0])
    return out


def _render(r: _Reader, tbl: Any) -> tuple[dict, dict]:
    render = _render_table(r, ("render",), tbl, allow_paper=True)
    paper = _render_table(r, ("render", "paper"), tbl.get("paper", {}), allow_paper=False)
    return render, paper


def _environment(r: _Reader, path: tuple, tbl: Any) -> dict:
    r.table(path, tbl, ("color", "image", "stars", "spots"))
    env = {"color": r.color(tbl, path, "color", [0.0, 0.0, 0.0]), "image": None, "stars": None, "spots": []}
    if "image" in tbl:
        file = r.file(tbl, path, "image", kind="image", suffixes=textures.IMAGE_SUFFIXES)
        env["image"] = _load_image(r, path + ("image",), file)
    if "stars" in tbl:
        sp = path + ("stars",)
        stars = tbl["stars"]
        r.table(sp, stars, ("density", "brightness", "size", "seed"))
        env["stars"] = {
            "density": r.real(stars, sp, "density", 2000.0, lo=0.0),
            "brightness": r.real(stars, sp, "brightness", 20.0, lo=0.0, lo_open=False),
            "size": r.real(stars, sp, "size", 0.002, lo=0.0, hi=0.1),
            "seed": r.integer(stars, sp, "seed", 7, lo=0),
        }
    spots = tbl.get("spots", [])
    if not isinstance(spots, list):
        kp = path + ("spots",)
        raise r.error(kp, f"{key_name(kp)} must be an array of tables, got {_describe(spots)}")
    for i, spot in enumerate(spots):
        sp = path + ("spots", i)
        r.table(sp, spot, ("direction", "radius", "color"), required=("direction",), what=key_name(sp))
        d = np.asarray(r.vec3(spot, sp, "direction", nonzero=True))
        env["spots"].append({
            "direction": (d / np.linalg.norm(d)).tolist(),
            "radius": r.real(spot, sp, "radius", 0.01, lo=0.0, hi=math.pi),
            "color": r.color(spot, sp, "color", [1.0, 1.0, 1.0]),
        })  # fmt: skip
    return env


def _load_image(r: _Reader, kp: tuple, file: Path, *, srgb: bool | None = None) -> np.ndarray:
    try:
        return textures.load_image(file, srgb=srgb)
    except Exception as exc:  # noqa: BLE001 - any decoder failure is the file's fault
        raise r.error(kp, f"{key_name(kp)}: cannot read image {file.name!r}: {exc}") from None


_TEXTURE_KEYS = {
    "constant": ("color",),
    "checker": ("color_a", "color_b", "scale"),
    "grid": ("base", "line_u", "line_v", "cells", "width"),
    "image": ("file", "repeat", "srgb"),
    "swatch": ("cells", "cell_px", "border", "seed", "repeat"),
    "earth-like": ("resolution", "seed", "ocean", "repeat"),
}


def _textures(r: _Reader, tbl: Any) -> tuple[list, dict]:
    path = ("textures",)
    if not isinstance(tbl, dict):
        raise r.error(path, f"textures must be a table of [textures.NAME] tables, got {_describe(tbl)}")
    out, index = [], {}
    for name, t in tbl.items():
        tp = path + (name,)
        if not isinstance(t, dict):
            raise r.error(tp, f"{key_name(tp)} must be a table, got {_describe(t)}")
        kind = r.choice(t, tp, "type", list(_TEXTURE_KEYS))
        r.table(tp, t, ("type", *_TEXTURE_KEYS[kind]))
        index[name] = len(out)
        out.append(_texture(r, tp, kind, t))
    return out, index


def _texture(r: _Reader, tp: tuple, kind: str, t: dict) -> dict:
    if kind == "constant":
        return {"type": "constant", "color": r.color(t, tp, "color")}
    if kind == "checker":
        return {
            "type": "checker", "color_a": r.color(t, tp, "color_a", [0.8, 0.8, 0.8]),
            "color_b": r.color(t, tp, "color_b", [0.2, 0.2, 0.2]),
            "scale": r.numbers(t, tp, "scale", 2, [8.0, 8.0], lo=0.0, lo_open=True),
        }  # fmt: skip
    if kind == "grid":
        return {
            "type": "grid", "base": r.color(t, tp, "base", [1.0, 1.0, 1.0]),
            "line_u": r.color(t, tp, "line_u", [0.0, 0.0, 0.0]), "line_v": r.color(t, tp, "line_v", [0.0, 0.0, 0.0]),
            "cells": r.numbers(t, tp, "cells", 2, [10, 10], integer=True, lo=1),
            "width": r.real(t, tp, "width", 0.05, lo=0.0, hi=1.0),
        }  # fmt: skip
    repeat = r.numbers(t, tp, "repeat", 2, [1.0, 1.0], lo=0.0, lo_open=True)
    if kind == "image":
        file = r.file(t, tp, "file", kind="image", suffixes=textures.IMAGE_SUFFIXES)
        srgb = r.boolean(t, tp, "srgb", None) if "srgb" in t else None
        data = _load_image(r, tp + ("file",), file, srgb=srgb)
    elif kind == "swatch":
        data = textures.swatch(
            cells=tuple(r.numbers(t, tp, "cells", 2, [4, 16], integer=True, lo=1, hi=256)),
            cell_px=r.integer(t, tp, "cell_px", 16, lo=2, hi=256),
            border=r.real(t, tp, "border", 0.08, lo=0.0, hi=0.5, lo_open=False),
            seed=r.integer(t, tp, "seed", 0, lo=0),
        )  # fmt: skip
    else:  # earth-like
        w, h = r.numbers(t, tp, "resolution", 2, [256, 128], integer=True, lo=4, hi=8192)
        data = textures.earth_like(width=w, height=h, seed=r.integer(t, tp, "seed", 0, lo=0),
                                   ocean=r.real(t, tp, "ocean", 0.6, lo=0.0, hi=1.0))  # fmt: skip
    return {"type": "image", "data": np.ascontiguousarray(data, dtype=np.float32), "repeat": repeat}


_MATERIAL_KEYS = {
    "diffuse": ("color", "texture"),
    "mirror": ("reflectance",),
    "glass": ("ior", "tint"),
    "emissive": ("strength", "color", "texture", "two_sided", "keplerian", "beaming", "colour_shift"),
}


def _materials(r: _Reader, tbl: Any, tex_list: list, tex_index: dict) -> tuple[list, dict]:
    path = ("materials",)
    if not isinstance(tbl, dict):
        raise r.error(path, f"materials must be a table of [materials.NAME] tables, got {_describe(tbl)}")
    out, index = [], {}

    def texture_ref(m: dict, mp: tuple, *, albedo: bool, default_color: list) -> int:
        if "texture" in m and "color" in m:
            raise r.error(mp + ("texture",), f"{key_name(mp)}: give either color or texture, not both", at_value=False)
        if "texture" in m:
            name = r.string(m, mp, "texture")
            if name not in tex_index:
                close = difflib.get_close_matches(name, list(tex_index), n=1, cutoff=0.6)
                hint = f"; did you mean {close[0]!r}?" if close else ""
                defined = ", ".join(tex_index) or "none"
                kp = mp + ("texture",)
                raise r.error(kp, f"{key_name(kp)}: unknown texture {name!r}{hint} (defined: {defined})")
            return tex_index[name]
        tex_list.append({"type": "constant", "color": r.color(m, mp, "color", default_color, albedo=albedo)})
        return len(tex_list) - 1

    for name, m in tbl.items():
        mp = path + (name,)
        if not isinstance(m, dict):
            raise r.error(mp, f"{key_name(mp)} must be a table, got {_describe(m)}")
        kind = r.choice(m, mp, "type", list(_MATERIAL_KEYS))
        r.table(mp, m, ("type", *_MATERIAL_KEYS[kind]))
        if kind == "diffuse":
            mat = {"type": "diffuse", "texture": texture_ref(m, mp, albedo=True, default_color=[0.8, 0.8, 0.8])}
        elif kind == "mirror":
            mat = {"type": "mirror", "reflectance": r.color(m, mp, "reflectance", [1.0, 1.0, 1.0], albedo=True)}
        elif kind == "glass":
            mat = {"type": "glass", "ior": r.real(m, mp, "ior", 1.5, lo=1.0, hi=4.0, lo_open=False),
                   "tint": r.color(m, mp, "tint", [1.0, 1.0, 1.0], albedo=True)}  # fmt: skip
        else:
            mat = {
                "type": "emissive", "texture": texture_ref(m, mp, albedo=False, default_color=[1.0, 1.0, 1.0]),
                "strength": r.real(m, mp, "strength", 1.0, lo=0.0, lo_open=False),
                "two_sided": r.boolean(m, mp, "two_sided", False),
                "keplerian": r.boolean(m, mp, "keplerian", False),
                "beaming": r.boolean(m, mp, "beaming", False),
                "colour_shift": r.boolean(m, mp, "colour_shift", False),
            }  # fmt: skip
        index[name] = len(out)
        out.append(mat)
    return out, index


_SHAPE_KEYS = {
    "sphere": ("center", "radius", "pole", "meridian"),
    "quad": ("corner", "edge_u", "edge_v"),
    "box": ("center", "size", "rotate"),
    "disk": ("center", "normal", "inner_radius", "outer_radius", "meridian"),
    "mesh": ("file", "translate", "rotate", "scale"),
    "cylinder": ("center", "axis", "radius", "height", "segments", "caps"),
}
_COMMON_OBJECT_KEYS = ("shape", "material", "sheet", "name")
MESH_SUFFIXES = (".obj", ".ply", ".stl", ".glb", ".gltf", ".off")


def _objects(r: _Reader, objs: Any, mat_index: dict, *, ellis: bool) -> list[dict]:
    if not isinstance(objs, list):
        raise r.error(("objects",), f"objects must be an array of [[objects]] tables, got {_describe(objs)}")
    shapes = []
    for i, o in enumerate(objs):
        op = ("objects", i)
        if not isinstance(o, dict):
            raise r.error(op, f"{key_name(op)} must be a table, got {_describe(o)}")
        kind = r.choice(o, op, "shape", list(_SHAPE_KEYS))
        allowed = (*_COMMON_OBJECT_KEYS, *_SHAPE_KEYS[kind])
        r.table(op, o, allowed, required=("material",), what=f"{key_name(op)} ({kind})")
        mat_name = r.string(o, op, "material")
        if mat_name not in mat_index:
            close = difflib.get_close_matches(mat_name, list(mat_index), n=1, cutoff=0.6)
            hint = f"; did you mean {close[0]!r}?" if close else ""
            defined = ", ".join(mat_index) or "none"
            kp = op + ("material",)
            raise r.error(kp, f"{key_name(kp)}: unknown material {mat_name!r}{hint} (defined: {defined})")
        if "name" in o:
            r.string(o, op, "name")
        common = {"material": mat_index[mat_name], "sheet": _sheet(r, o, op, ellis=ellis)}
        for shape in _shape(r, op, kind, o):
            shapes.append({**shape, **common})
    return shapes


def _not_parallel(r: _Reader, kp: tuple, a, b, what: str) -> None:
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    if np.linalg.norm(np.cross(a / np.linalg.norm(a), b / np.linalg.norm(b))) < 1e-9:
        raise r.error(kp, f"{key_name(kp)} must not be parallel to {what}")


def _shape(r: _Reader, op: tuple, kind: str, o: dict) -> list[dict]:
    if kind == "sphere":
        pole = r.vec3(o, op, "pole", [0.0, 0.0, 1.0], nonzero=True)
        meridian = r.vec3(o, op, "meridian", [1.0, 0.0, 0.0], nonzero=True)
        _not_parallel(r, op + ("meridian",), meridian, pole, "the pole")
        return [{"type": "sphere", "center": r.vec3(o, op, "center"), "radius": r.real(o, op, "radius", lo=0.0),
                 "pole": pole, "meridian": meridian}]  # fmt: skip
    if kind == "quad":
        eu, ev = r.vec3(o, op, "edge_u", nonzero=True), r.vec3(o, op, "edge_v", nonzero=True)
        _not_parallel(r, op + ("edge_v",), ev, eu, "edge_u")
        return [{"type": "quad", "corner": r.vec3(o, op, "corner"), "edge_u": eu, "edge_v": ev}]
    if kind == "box":
        size = r.numbers(o, op, "size", 3, lo=0.0, lo_open=True)
        rotate = r.vec3(o, op, "rotate", [0.0, 0.0, 0.0])
        quads = primitives.box_quads(center=r.vec3(o, op, "center"), size=size, rotate=rotate)
        return [{"type": "quad", **q} for q in quads]
    if kind == "disk":
        normal = r.vec3(o, op, "normal", [0.0, 0.0, 1.0], nonzero=True)
        meridian = r.vec3(o, op, "meridian", [1.0, 0.0, 0.0], nonzero=True)
        _not_parallel(r, op + ("meridian",), meridian, normal, "the normal")
        inner = r.real(o, op, "inner_radius", 0.0, lo=0.0, lo_open=False)
        outer = r.real(o, op, "outer_radius", lo=inner)
        return [{"type": "disk", "center": r.vec3(o, op, "center"), "normal": normal, "inner_radius": inner,
                 "outer_radius": outer, "meridian": meridian}]  # fmt: skip
    if kind == "cylinder":
        v, f, uv = primitives.cylinder_mesh(
            center=r.vec3(o, op, "center"), axis=r.vec3(o, op, "axis", [0.0, 0.0, 1.0], nonzero=True),
            radius=r.real(o, op, "radius", lo=0.0), height=r.real(o, op, "height", lo=0.0),
            segments=r.integer(o, op, "segments", 48, lo=3, hi=4096), caps=r.boolean(o, op, "caps", True),
        )  # fmt: skip
        return [{"type": "mesh", "vertices": v, "faces": f, "uvs": uv}]
    # mesh
    file = r.file(o, op, "file", kind="mesh", suffixes=MESH_SUFFIXES)
    scale = o.get("scale", 1.0)
    if isinstance(scale, (list, tuple)):  # one factor per axis (all > 0, so faces keep their orientation)
        scale = r.numbers(o, op, "scale", 3, lo=0.0, lo_open=True)
    else:
        scale = r.real(o, op, "scale", 1.0, lo=0.0)
    vertices, faces, uvs = _read_mesh(r, op + ("file",), file)
    translate, rotate = r.vec3(o, op, "translate", [0.0, 0.0, 0.0]), r.vec3(o, op, "rotate", [0.0, 0.0, 0.0])
    vertices = primitives.transform_points(vertices, translate=translate, rotate=rotate, scale=scale)
    return [{"type": "mesh", "vertices": np.ascontiguousarray(vertices), "faces": faces, "uvs": uvs}]


def _read_mesh(r: _Reader, kp: tuple, file: Path):
    import trimesh

    try:
        mesh = trimesh.load(str(file), force="mesh", process=False)
    except Exception as exc:  # noqa: BLE001 - any loader failure is the file's fault
        raise r.error(kp, f"{key_name(kp)}: cannot read mesh {file.name!r}: {exc}") from None
    vertices = np.asarray(getattr(mesh, "vertices", np.empty((0, 3))), dtype=np.float64)
    faces = np.asarray(getattr(mesh, "faces", np.empty((0, 3))), dtype=np.int32)
    if vertices.ndim != 2 or len(vertices) == 0 or faces.ndim != 2 or len(faces) == 0:
        raise r.error(kp, f"{key_name(kp)}: mesh {file.name!r} has no triangles")
    uv = getattr(getattr(mesh, "visual", None), "uv", None)
    uvs = None
    if uv is not None and np.shape(uv) == (len(vertices), 2):
        uvs = np.ascontiguousarray(uv, dtype=np.float64)
    return np.ascontiguousarray(vertices), np.ascontiguousarray(faces), uvs


def _outputs(r: _Reader, tbl: Any) -> dict:
    path = ("outputs",)
    r.table(path, tbl, ("aovs", "file"))
    aovs = None
    if "aovs" in tbl:
        aovs = tbl["aovs"]
        if not isinstance(aovs, list) or not all(isinstance(a, str) for a in aovs):
            raise r.error(path + ("aovs",), f"outputs.aovs must be a list of names, got {_describe(aovs)}")
        for i, a in enumerate(aovs):
            if a not in AOV_NAMES:
                close = difflib.get_close_matches(a, AOV_NAMES, n=1, cutoff=0.6)
                hint = f"; did you mean {close[0]!r}?" if close else ""
                known = ", ".join(AOV_NAMES)
                raise r.error(path + ("aovs", i), f"outputs.aovs[{i}]: unknown AOV {a!r}{hint} (known: {known})")
    file = None
    if "file" in tbl:
        file = r.string(tbl, path, "file")
        if Path(file).suffix.lower() not in (".png", ".exr"):
            raise r.error(path + ("file",), f"outputs.file must end in .png or .exr, got {file!r}")
    return {"aovs": aovs, "file": file}
