"""The native scene dict (``docs/native-scene.md``): its one validator, and the one place where its
optional keys get their defaults.

The core turns the native scene dict into its own scene (``renderer_ext/bindings/scene_dict.cpp``) and
checks nothing a user could get wrong: it requires every key it reads, of its type, and has no defaults.
:func:`native_scene` stands in front of it. It takes a native scene dict, built by
:meth:`warpviz.scene.Scene.native` from a scene file or by hand in a script, checks every value with a
message that names its key (``shapes[2].radius must be > 0``), and returns a fresh dict that holds every
key the core reads: optional keys with their defaults (:data:`SCHEMA`), numbers as ``float`` or ``int``,
flags as ``bool``, vectors as lists of floats, arrays C-contiguous in the core's dtypes (shared with the
input when they already are), and ``environment_other`` (the sky of a wormhole's other sheet) the same
dict as ``environment`` unless one is given. Keys the core does not read are left out.

The scene-file reader (:mod:`~warpviz.scene.settings`, :mod:`~warpviz.scene.appearance`,
:mod:`~warpviz.scene.objects`) takes its defaults for the keys that map one to one onto native keys from
:data:`SCHEMA` too; its own defaults are only those of keys the native dict does not have (a camera's
``look_at``, a checker's colours, a star field's parameters, ...).

Examples
--------
>>> from warpviz.scene.native import native_scene
>>> full = native_scene({"metric": {"name": "minkowski"},
...                      "camera": {"position": [0, -5, 0], "look_at": [0, 0, 0], "width": 8, "height": 6},
...                      "materials": [{"type": "glass"}], "shapes": []})
>>> full["camera"]["fov"], full["camera"]["up"], full["metric"]
(40.0, [0.0, 0.0, 1.0], {'name': 'minkowski', 'params': []})
>>> full["materials"][0]
{'type': 'glass', 'ior': 1.5, 'tint': [1.0, 1.0, 1.0], 'emission': [0.0, 0.0, 0.0]}
>>> full["environment_other"] is full["environment"]
True
>>> native_scene({**full, "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": -1, "material": 0}]})
Traceback (most recent call last):
...
warpviz.scene.reader.SceneError: shapes[0].radius must be > 0
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Mapping
from typing import Any

import numpy as np

from warpviz.limits import MAX_IMAGE_SIDE, MAX_STRENGTH
from warpviz._native import core
from warpviz.scene.reader import SceneError
from warpviz.spacetime import metric_from_params

__all__ = ["REQUIRED", "SCHEMA", "native_camera", "native_material", "native_scene", "scene_emits", "schema_keys"]


class _Required:
    def __repr__(self) -> str:
        return "REQUIRED"


#: Marks a key without a default in :data:`SCHEMA`.
REQUIRED = _Required()

#: Every key of the native scene dict that the core reads, by table (and, for textures, materials and
#: shapes, by ``type``), with its default or :data:`REQUIRED`. The only defaults of the native scene.
#: ``environment_other``'s default ``None`` means "the same sky as ``environment``"; ``image``, ``stars``
#: and ``uvs`` may be ``None`` (none).
SCHEMA: dict[str, Any] = {
    "scene": {"metric": REQUIRED, "camera": REQUIRED, "textures": (), "materials": REQUIRED, "shapes": REQUIRED,
              "lights": (), "environment": None, "environment_other": None},
    "metric": {"name": REQUIRED, "params": ()},
    "camera": {"position": REQUIRED, "look_at": REQUIRED, "up": (0.0, 0.0, 1.0), "fov": 40.0, "width": REQUIRED,
               "height": REQUIRED, "sheet": 1, "observer": None, "shift": "none"},
    # who holds the camera (docs/observers.md); None: the local static observer (the ZAMO in an ergoregion)
    "observer": {"kind": "local", "velocity": (0.0, 0.0, 0.0), "axis": (0.0, 0.0, 1.0), "fall_from": 0.0,
                 "u": (0.0, 0.0, 0.0, 0.0)},
    "textures": {
        "constant": {"color": REQUIRED},
        "checker": {"color_a": REQUIRED, "color_b": REQUIRED, "scale": (8.0, 8.0)},
        "grid": {"base": REQUIRED, "line_u": REQUIRED, "line_v": REQUIRED, "cells": (10, 10), "width": 0.05,
                 # one line of constant u (v), number 0 .. cells, in a colour of its own; -1: none
                 "mark_u": -1, "mark_v": -1, "mark_u_color": (0.0, 0.0, 0.0), "mark_v_color": (0.0, 0.0, 0.0)},
        "image": {"data": REQUIRED, "repeat": (1.0, 1.0)},
    },
    "materials": {
        # emission: radiance a reflecting material also emits (one-sided, along the shape normal)
        "diffuse": {"texture": REQUIRED, "emission": (0.0, 0.0, 0.0)},
        "mirror": {"reflectance": (1.0, 1.0, 1.0), "emission": (0.0, 0.0, 0.0)},
        "glass": {"ior": 1.5, "tint": (1.0, 1.0, 1.0), "emission": (0.0, 0.0, 0.0)},
        "emissive": {"texture": -1, "strength": 1.0, "two_sided": False, "keplerian": False, "beaming": False,
                     "colour_shift": False},
    },
    "shapes": {
        "sphere": {"material": REQUIRED, "sheet": 1, "center": REQUIRED, "radius": REQUIRED, "pole": (0.0, 0.0, 1.0),
                   "meridian": (1.0, 0.0, 0.0)},
        "quad": {"material": REQUIRED, "sheet": 1, "corner": REQUIRED, "edge_u": REQUIRED, "edge_v": REQUIRED},
        "disk": {"material": REQUIRED, "sheet": 1, "center": REQUIRED, "normal": (0.0, 0.0, 1.0), "inner_radius": 0.0,
                 "outer_radius": REQUIRED, "meridian": (1.0, 0.0, 0.0)},
        "mesh": {"material": REQUIRED, "sheet": 1, "vertices": REQUIRED, "faces": REQUIRED, "uvs": None},
    },
    # point and spot lights (no shape: rays never hit them): radiant intensity color x intensity per steradian
    # of the local sky at position; a spot's cone of half-angle `angle` degrees about `direction`, its edge
    # softened over the last `falloff` degrees
    "lights": {
        "point": {"position": REQUIRED, "sheet": 1, "color": (1.0, 1.0, 1.0), "intensity": REQUIRED},
        "spot": {"position": REQUIRED, "sheet": 1, "color": (1.0, 1.0, 1.0), "intensity": REQUIRED,
                 "direction": REQUIRED, "angle": 30.0, "falloff": 5.0},
    },
    "environment": {"color": (0.0, 0.0, 0.0), "image": None, "stars": None, "spots": ()},
    "stars": {"density": REQUIRED, "brightness": REQUIRED, "size": REQUIRED, "seed": REQUIRED},
    "spots": {"direction": REQUIRED, "radius": 0.01, "color": (1.0, 1.0, 1.0)},
}  # fmt: skip

_TYPED = ("textures", "materials", "shapes", "lights")
_MAX_SEED = 2**53  # the core once read seeds through a double: up to here, the star field is the same


def schema_keys() -> set[str]:
    """Every key name of :data:`SCHEMA` (with ``type``, the key that picks a texture, material or shape)."""
    keys = {"type"}
    for table, entries in SCHEMA.items():
        for value in entries.values() if table in _TYPED else [entries]:
            keys.update(value)
    return keys


def _default(table: str, key: str, kind: str | None = None):
    entries = SCHEMA[table][kind] if kind is not None else SCHEMA[table]
    return entries[key]


# ---------------------------------------------------------------------------------------------- checks
def _fail(where: str, what: str):
    raise SceneError(f"{where} {what}", key=where)


def _get(d: Mapping, key: str, where: str, default):
    """d[key], or the default; a missing required key fails naming it."""
    if key in d:
        return d[key]
    if default is REQUIRED:
        _fail(f"{where}.{key}", "is missing")
    return default


def _is_real(x) -> bool:
    if isinstance(x, np.ndarray) and x.ndim == 0:
        x = x[()]
    return isinstance(x, numbers.Real) and not isinstance(x, (bool, np.bool_))


def _number(d: Mapping, key: str, where: str, kind: str | None = None, *, table: str) -> float:
    w = f"{where}.{key}"
    value = _get(d, key, where, _default(table, key, kind))
    if not _is_real(value):
        _fail(w, "must be a number")
    value = float(value)
    if not math.isfinite(value):
        _fail(w, "must be finite")
    return value


def _integral(d: Mapping, key: str, where: str, kind: str | None = None, *, table: str) -> int:
    """A whole number (an int, or a float with no fraction), as an int."""
    value = _get(d, key, where, _default(table, key, kind))
    if not _is_real(value) or not math.isfinite(float(value)) or float(value) != math.floor(float(value)):
        _fail(f"{where}.{key}", "must be an integer")
    return int(value)


def _vec3(d: Mapping, key: str, where: str, kind: str | None = None, *, table: str) -> list[float]:
    w = f"{where}.{key}"
    value = _get(d, key, where, _default(table, key, kind))
    if isinstance(value, np.ndarray):
        value = value.tolist() if value.ndim == 1 else None
    if not isinstance(value, (list, tuple)) or len(value) != 3:
        _fail(w, "must be a list of 3 numbers")
    if not all(_is_real(x) and math.isfinite(float(x)) for x in value):
        _fail(w, "must be a list of 3 finite numbers")
    return [float(x) for x in value]


def _pair(d: Mapping, key: str, where: str, kind: str, *, table: str) -> list[float]:
    value = _get(d, key, where, _default(table, key, kind))
    if isinstance(value, np.ndarray):
        value = value.tolist() if value.ndim == 1 else None
    ok = isinstance(value, (list, tuple)) and len(value) == 2 and all(_is_real(x) for x in value)
    if not ok or not all(float(x) > 0 and math.isfinite(float(x)) for x in value):
        _fail(f"{where}.{key}", "must be a list of 2 positive numbers")
    return [float(x) for x in value]


def _flag(d: Mapping, key: str, where: str, kind: str, *, table: str) -> bool:
    value = _get(d, key, where, _default(table, key, kind))
    if not isinstance(value, (bool, np.bool_)):
        _fail(f"{where}.{key}", "must be True or False")
    return bool(value)


def _string(d: Mapping, key: str, where: str) -> str:
    value = _get(d, key, where, REQUIRED)
    if not isinstance(value, str):
        _fail(f"{where}.{key}", "must be a string")
    return value


def _table(value, where: str) -> Mapping:
    if not isinstance(value, Mapping):
        _fail(where, "must be a table (dict)")
    return value


def _list(value, where: str) -> list:
    if not isinstance(value, (list, tuple)):
        _fail(where, "must be a list")
    return list(value)


def _index(d: Mapping, key: str, where: str, size: int, kind: str, *, table: str) -> int:
    w = f"{where}.{key}"
    value = _get(d, key, where, _default(table, key, kind))
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Integral):
        _fail(w, "must be an integer")
    value = int(value)
    if value < -1 or value >= size:
        _fail(w, f"index {value} out of range ({size} defined)")
    return value


def _sheet(d: Mapping, where: str, kind: str | None = None, *, table: str) -> int:
    value = _get(d, "sheet", where, _default(table, "sheet", kind))
    if not _is_real(value) or float(value) not in (1.0, -1.0):
        _fail(f"{where}.sheet", "must be +1 or -1")
    return int(value)


def _array(value, where: str, dtype, shape: str, *, columns: int, depth: int = 2, check=None) -> np.ndarray:
    """value as a C-contiguous array of dtype with `depth` dimensions, the last `columns` wide; `check`
    (if given) is called with the array as given, before the conversion."""
    name = np.dtype(dtype).name
    what = f"must be {'an' if name[0] in 'aeiou' else 'a'} {name} array of shape {shape}"
    try:
        a = np.asarray(value)
    except (TypeError, ValueError):
        _fail(where, what)
    if a.dtype.kind not in ("iu" if np.dtype(dtype).kind in "iu" else "iuf") or a.ndim != depth or a.shape[-1] != columns:
        _fail(where, what)
    if a.dtype.kind == "f" and not np.all(np.isfinite(a)):
        _fail(where, "must hold finite numbers")
    if check is not None:
        check(a)
    return np.ascontiguousarray(a, dtype=dtype)


def _image(value, where: str) -> np.ndarray:
    a = _array(value, where, np.float32, "(H, W, 3)", columns=3, depth=3)
    if a.shape[0] < 1 or a.shape[1] < 1:
        _fail(where, "must be a float32 array of shape (H, W, 3)")
    return a


def _length(v) -> float:
    return math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])


def _cross(a, b) -> list[float]:
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


# ---------------------------------------------------------------------------------------------- tables
def native_camera(camera: Mapping[str, Any], where: str = "camera") -> dict:
    """A native scene camera, checked, with every key: ``position``, ``look_at``, ``up``, ``fov``
    (vertical, degrees), ``width``, ``height`` (pixels) and ``sheet``.

    Raises
    ------
    SceneError
        A missing or invalid key, named (``camera.fov must be in (0, 180) degrees``).
    """
    c = _table(camera, where)
    t = "camera"
    out = {"position": _vec3(c, "position", where, table=t), "look_at": _vec3(c, "look_at", where, table=t),
           "up": _vec3(c, "up", where, table=t), "fov": _number(c, "fov", where, table=t)}  # fmt: skip
    if not 0.0 < out["fov"] < 180.0:
        _fail(f"{where}.fov", "must be in (0, 180) degrees")
    size = []
    for key in ("width", "height"):
        value = _get(c, key, where, REQUIRED)
        ok = _is_real(value) and math.isfinite(float(value)) and float(value) == math.floor(float(value))
        if not (ok and 1 <= float(value) <= MAX_IMAGE_SIDE):
            _fail(f"{where}.{key}", f"must be an integer in [1, {MAX_IMAGE_SIDE}], got {value!r}")
        size.append(int(value))
    out["width"], out["height"] = size
    out["sheet"] = _sheet(c, where, table=t)
    if not _length(np.subtract(out["look_at"], out["position"]).tolist()) > 0:
        _fail(f"{where}.look_at", f"must differ from {where}.position")
    out["observer"] = native_observer(_get(c, "observer", where, None), f"{where}.observer")
    shift = _get(c, "shift", where, _default(t, "shift"))
    if shift not in CAMERA_SHIFTS:
        _fail(f"{where}.shift", f"must be one of {', '.join(map(repr, CAMERA_SHIFTS))}, got {shift!r}")
    out["shift"] = shift
    return out


#: The observers a camera may be held by (spacetime/observers.h; docs/observers.md).
OBSERVER_KINDS = ("local", "static", "zamo", "orbit", "free_fall", "moving", "given")
#: What a moving camera does with the Doppler and gravitational shift of what it sees.
CAMERA_SHIFTS = ("none", "beaming", "colour")


def native_observer(observer: Mapping[str, Any] | None, where: str = "camera.observer") -> dict:
    """A native camera observer, checked, with every key: ``kind`` (:data:`OBSERVER_KINDS`), ``velocity``
    (relative to the local observer, units of c), ``axis`` (of an orbit), ``fall_from`` (radius of rest of a
    free fall, 0: infinity) and ``u`` (a chart 4-velocity, ``kind = "given"``). ``None``: the local observer.
    Whether such an observer can be at the camera is the core's to say (``core.observer``)."""
    t = "observer"
    o = _table({} if observer is None else observer, where)
    for key in o:
        if key not in SCHEMA[t]:
            _fail(f"{where}.{key}", f"is not a key of an observer (keys: {', '.join(SCHEMA[t])})")
    kind = _get(o, "kind", where, _default(t, "kind"))
    if kind not in OBSERVER_KINDS:
        _fail(f"{where}.kind", f"must be one of {', '.join(map(repr, OBSERVER_KINDS))}, got {kind!r}")
    out = {"kind": kind, "velocity": _vec3(o, "velocity", where, table=t), "axis": _vec3(o, "axis", where, table=t),
           "fall_from": _number(o, "fall_from", where, table=t)}  # fmt: skip
    if out["fall_from"] < 0:
        _fail(f"{where}.fall_from", "must be >= 0 (0: from rest at infinity)")
    u = _get(o, "u", where, _default(t, "u"))
    if isinstance(u, np.ndarray):
        u = u.tolist()
    if not isinstance(u, (list, tuple)) or len(u) != 4 or not all(_is_real(x) and math.isfinite(float(x)) for x in u):
        _fail(f"{where}.u", "must be a list of 4 finite numbers")
    out["u"] = [float(x) for x in u]
    return out


def _texture(t: Mapping, w: str) -> dict:
    kind = _string(t, "type", w)
    if kind not in SCHEMA["textures"]:
        _fail(f"{w}.type", f"unknown texture type {kind!r} (known: {', '.join(SCHEMA['textures'])})")
    tb = "textures"
    if kind == "constant":
        return {"type": kind, "color": _vec3(t, "color", w, kind, table=tb)}
    if kind == "checker":
        return {"type": kind, "color_a": _vec3(t, "color_a", w, kind, table=tb),
                "color_b": _vec3(t, "color_b", w, kind, table=tb), "scale": _pair(t, "scale", w, kind, table=tb)}
    if kind == "grid":
        return {"type": kind, "base": _vec3(t, "base", w, kind, table=tb), "line_u": _vec3(t, "line_u", w, kind, table=tb),
                "line_v": _vec3(t, "line_v", w, kind, table=tb), "cells": _pair(t, "cells", w, kind, table=tb),
                "width": _number(t, "width", w, kind, table=tb), "mark_u": _integral(t, "mark_u", w, kind, table=tb),
                "mark_v": _integral(t, "mark_v", w, kind, table=tb),
                "mark_u_color": _vec3(t, "mark_u_color", w, kind, table=tb),
                "mark_v_color": _vec3(t, "mark_v_color", w, kind, table=tb)}  # fmt: skip
    return {"type": kind, "data": _image(_get(t, "data", w, REQUIRED), f"{w}.data"),
            "repeat": _pair(t, "repeat", w, kind, table=tb)}


def native_material(material: Mapping[str, Any], *, textures: int = 0, where: str = "material") -> dict:
    """One native material, checked, with every key of its type.

    Parameters
    ----------
    material : dict
        ``{"type": "diffuse" | "mirror" | "glass" | "emissive", ...}`` (``docs/native-scene.md``).
    textures : int, keyword-only
        How many textures its ``texture`` index may refer to (-1: none).
    where : str, keyword-only
        Its key path in messages.
    """
    m, w, tb = _table(material, where), where, "materials"
    kind = _string(m, "type", w)
    if kind not in SCHEMA["materials"]:
        _fail(f"{w}.type", f"unknown material type {kind!r} (known: {', '.join(SCHEMA['materials'])})")
    if kind in ("diffuse", "mirror", "glass"):
        emission = _vec3(m, "emission", w, kind, table=tb)
        if not min(emission) >= 0.0:
            _fail(f"{w}.emission", "must be >= 0 in every channel")
    if kind == "diffuse":
        return {"type": kind, "texture": _index(m, "texture", w, textures, kind, table=tb), "emission": emission}
    if kind == "mirror":
        return {"type": kind, "reflectance": _vec3(m, "reflectance", w, kind, table=tb), "emission": emission}
    if kind == "glass":
        ior = _number(m, "ior", w, kind, table=tb)
        if not ior >= 1.0:
            _fail(f"{w}.ior", "must be >= 1")
        return {"type": kind, "ior": ior, "tint": _vec3(m, "tint", w, kind, table=tb), "emission": emission}
    out = {"type": kind, "texture": _index(m, "texture", w, textures, kind, table=tb),
           "strength": _number(m, "strength", w, kind, table=tb)}  # fmt: skip
    if not 0 <= out["strength"] <= MAX_STRENGTH:
        _fail(f"{w}.strength", f"must be in [0, {MAX_STRENGTH:g}]")
    for key in ("two_sided", "keplerian", "beaming", "colour_shift"):
        out[key] = _flag(m, key, w, kind, table=tb)
    return out


def _shape(s: Mapping, w: str, materials: int) -> dict:
    kind = _string(s, "type", w)
    tb = "shapes"
    if kind not in SCHEMA["shapes"]:
        _fail(f"{w}.type", f"unknown shape type {kind!r} (known: {', '.join(SCHEMA['shapes'])})")
    material = _index(s, "material", w, materials, kind, table=tb)
    if material < 0:
        _fail(f"{w}.material", "is required")
    out: dict[str, Any] = {"type": kind, "material": material, "sheet": _sheet(s, w, kind, table=tb)}
    if kind == "sphere":
        out.update(center=_vec3(s, "center", w, kind, table=tb), radius=_number(s, "radius", w, kind, table=tb),
                   pole=_vec3(s, "pole", w, kind, table=tb), meridian=_vec3(s, "meridian", w, kind, table=tb))
        if not out["radius"] > 0:
            _fail(f"{w}.radius", "must be > 0")
        if not _length(out["pole"]) > 0:
            _fail(f"{w}.pole", "must be non-zero")
    elif kind == "quad":
        out.update(corner=_vec3(s, "corner", w, kind, table=tb), edge_u=_vec3(s, "edge_u", w, kind, table=tb),
                   edge_v=_vec3(s, "edge_v", w, kind, table=tb))
        if not _length(_cross(out["edge_u"], out["edge_v"])) > 0:
            _fail(w, "edge_u and edge_v must span a parallelogram (non-zero, not parallel)")
    elif kind == "disk":
        out.update(center=_vec3(s, "center", w, kind, table=tb), normal=_vec3(s, "normal", w, kind, table=tb),
                   inner_radius=_number(s, "inner_radius", w, kind, table=tb),
                   outer_radius=_number(s, "outer_radius", w, kind, table=tb),
                   meridian=_vec3(s, "meridian", w, kind, table=tb))  # fmt: skip
        if not _length(out["normal"]) > 0:
            _fail(f"{w}.normal", "must be non-zero")
        if not 0 <= out["inner_radius"] < out["outer_radius"]:
            _fail(w, "needs 0 <= inner_radius < outer_radius")
    else:
        vertices = _array(_get(s, "vertices", w, REQUIRED), f"{w}.vertices", np.float64, "(V, 3)", columns=3)

        def in_range(faces):
            if faces.size and (faces.min() < 0 or faces.max() >= vertices.shape[0]):
                _fail(f"{w}.faces", "refers to a vertex out of range")

        faces = _array(_get(s, "faces", w, REQUIRED), f"{w}.faces", np.int32, "(F, 3)", columns=3, check=in_range)
        uvs = _get(s, "uvs", w, _default(tb, "uvs", kind))
        if uvs is not None:
            uvs = _array(uvs, f"{w}.uvs", np.float64, "(V, 2)", columns=2)
            if uvs.shape[0] != vertices.shape[0]:
                _fail(f"{w}.uvs", "must be a float64 array of shape (V, 2)")
        out.update(vertices=vertices, faces=faces, uvs=uvs)
    return out


def _light(s: Mapping, w: str) -> dict:
    kind = _string(s, "type", w)
    tb = "lights"
    if kind not in SCHEMA["lights"]:
        _fail(f"{w}.type", f"unknown light type {kind!r} (known: {', '.join(SCHEMA['lights'])})")
    out: dict[str, Any] = {"type": kind, "position": _vec3(s, "position", w, kind, table=tb),
                           "sheet": _sheet(s, w, kind, table=tb), "color": _vec3(s, "color", w, kind, table=tb),
                           "intensity": _number(s, "intensity", w, kind, table=tb)}  # fmt: skip
    if min(out["color"]) < 0:
        _fail(f"{w}.color", "must be >= 0 in every channel")
    if not 0 <= out["intensity"] <= MAX_STRENGTH:
        _fail(f"{w}.intensity", f"must be in [0, {MAX_STRENGTH:g}]")
    if kind == "spot":
        out.update(direction=_vec3(s, "direction", w, kind, table=tb), angle=_number(s, "angle", w, kind, table=tb),
                   falloff=_number(s, "falloff", w, kind, table=tb))  # fmt: skip
        if not _length(out["direction"]) > 0:
            _fail(f"{w}.direction", "must be non-zero")
        if not 0 < out["angle"] <= 180:
            _fail(f"{w}.angle", "must be in (0, 180] degrees")
        if not 0 <= out["falloff"] <= out["angle"]:
            _fail(f"{w}.falloff", "must be in [0, angle] degrees")
    return out


def _environment(value, w: str) -> dict:
    e = _table({} if value is None else value, w)
    tb = "environment"
    out = {"color": _vec3(e, "color", w, table=tb), "image": None, "stars": None, "spots": []}
    image = _get(e, "image", w, _default(tb, "image"))
    if image is not None:
        out["image"] = _image(image, f"{w}.image")
    stars = _get(e, "stars", w, _default(tb, "stars"))
    if stars is not None:
        ws = f"{w}.stars"
        s = _table(stars, ws)
        out["stars"] = {key: _number(s, key, ws, table="stars") for key in ("density", "brightness", "size")}
        seed = _integral(s, "seed", ws, table="stars")
        if not 0 <= seed <= _MAX_SEED:
            _fail(f"{ws}.seed", f"must be in [0, 2**53], got {seed}")
        out["stars"]["seed"] = seed
        if not (out["stars"]["density"] >= 0 and out["stars"]["size"] > 0):
            _fail(ws, "needs density >= 0 and size > 0")
    for i, spot in enumerate(_list(_get(e, "spots", w, _default(tb, "spots")), f"{w}.spots")):
        wp = f"{w}.spots[{i}]"
        sp = _table(spot, wp)
        d = {"direction": _vec3(sp, "direction", wp, table="spots"), "radius": _number(sp, "radius", wp, table="spots"),
             "color": _vec3(sp, "color", wp, table="spots")}  # fmt: skip
        if not _length(d["direction"]) > 0:
            _fail(f"{wp}.direction", "must be non-zero")
        if not 0 < d["radius"] < math.pi:
            _fail(f"{wp}.radius", "must be in (0, pi)")
        out["spots"].append(d)
    return out


def native_scene(scene: Mapping[str, Any]) -> dict:
    """The complete, checked native scene dict that the core's ``render`` converts.

    Parameters
    ----------
    scene : dict
        A native scene dict (``docs/native-scene.md``); optional keys may be left out.

    Returns
    -------
    dict
        A fresh dict with every key of :data:`SCHEMA` for each table, in the types the core reads
        (arrays are shared with ``scene`` where they already have the core's dtype and layout).

    Raises
    ------
    SceneError
        The first missing or invalid key, named; the metric's own message for invalid parameters; the
        camera's position where no ray can start (inside a horizon, outside the chart).
    """
    d = _table(scene, "the native scene")
    md = _table(_get(d, "metric", "scene", REQUIRED), "metric")
    name = _string(md, "name", "metric")
    params = _list(_get(md, "params", "metric", _default("metric", "params")), "metric.params")
    if not all(_is_real(p) for p in params):
        _fail("metric.params", "must be a list of numbers")
    params = [float(p) for p in params]
    try:
        metric_from_params(name, params)  # the metric's own messages (ranges, relations between parameters)
    except (TypeError, ValueError) as exc:
        raise SceneError(str(exc), key="metric") from None
    out: dict[str, Any] = {"metric": {"name": name, "params": params},
                           "camera": native_camera(_get(d, "camera", "scene", REQUIRED))}  # fmt: skip
    textures = _list(_get(d, "textures", "scene", _default("scene", "textures")), "textures")
    out["textures"] = [_texture(_table(t, f"textures[{i}]"), f"textures[{i}]") for i, t in enumerate(textures)]
    materials = _list(_get(d, "materials", "scene", REQUIRED), "materials")
    out["materials"] = [native_material(m, textures=len(textures), where=f"materials[{i}]")
                        for i, m in enumerate(materials)]  # fmt: skip
    shapes = _list(_get(d, "shapes", "scene", REQUIRED), "shapes")
    out["shapes"] = [_shape(_table(s, f"shapes[{i}]"), f"shapes[{i}]", len(materials)) for i, s in enumerate(shapes)]
    lights = _list(_get(d, "lights", "scene", _default("scene", "lights")), "lights")
    out["lights"] = [_light(_table(s, f"lights[{i}]"), f"lights[{i}]") for i, s in enumerate(lights)]
    out["environment"] = _environment(_get(d, "environment", "scene", _default("scene", "environment")), "environment")
    other = _get(d, "environment_other", "scene", _default("scene", "environment_other"))
    out["environment_other"] = out["environment"] if other is None else _environment(other, "environment_other")
    cam = out["camera"]
    problem = core.origin_problems(name, params, np.array([cam["position"]], dtype=np.float64),
                                   np.array([cam["sheet"]], dtype=np.int32),
                                   cam["observer"]["kind"] != "local")  # a moving camera may be inside a horizon
    if problem is not None:
        _fail("camera.position", problem[1])
    return out


def scene_emits(native: Mapping[str, Any]) -> bool:
    """Whether anything in a checked native scene gives off light: a point or spot light, a shape whose
    material emits (an ``emissive`` material of positive strength, or a reflecting one with a positive
    ``emission``), or a
    sky (either sheet's) with a colour, an image, stars or spots. A scene that does not renders black.

    Examples
    --------
    >>> dark = native_scene({"metric": {"name": "minkowski"}, "camera": {"position": [0, -5, 0],
    ...     "look_at": [0, 0, 0], "width": 4, "height": 4}, "textures": [], "materials": [], "shapes": [],
    ...     "environment": {"color": [0, 0, 0]}})
    >>> scene_emits(dark), scene_emits(dict(dark, environment={"color": [0.1, 0, 0]}))
    (False, True)
    """
    if any(float(li.get("intensity", 0.0)) > 0.0 and max(float(v) for v in li.get("color", (1.0,))) > 0.0
           for li in native.get("lights", [])):  # fmt: skip
        return True
    materials = native.get("materials", [])
    used = {int(s["material"]) for s in native.get("shapes", []) if "material" in s}
    for i in used:
        m = materials[i] if 0 <= i < len(materials) else {}
        if m.get("type") == "emissive" and float(m.get("strength", 0.0)) > 0.0:
            return True
        if max((float(v) for v in m.get("emission", (0.0,))), default=0.0) > 0.0:
            return True
    for sky in (native.get("environment"), native.get("environment_other")):
        if not sky:
            continue
        if max(float(v) for v in sky.get("color", (0.0,))) > 0.0 or sky.get("image") or sky.get("stars") \
                or sky.get("spots"):  # fmt: skip
            return True
    return False
