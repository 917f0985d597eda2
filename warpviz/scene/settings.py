"""Compiling the settings tables of a scene: ``[metric]``, ``[camera]``, ``[render]`` and ``[outputs]``.

Each function validates one table with a :class:`~warpviz.scene.reader._Reader` and returns its native
form: the :class:`~warpviz.Metric` (parameters in the ranges of the core's registry), the native camera
dict (checked to start outside every horizon), the renderer options of ``[render]`` and
``[render.paper]``, and the outputs (AOV names, default file).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from warpviz.limits import EXPOSURE_RANGE, MAX_IMAGE_SIDE, TONEMAP_NAMES, tolerance_problem
from warpviz.options import DEFAULT_OPTIONS, RENDER_OPTIONS
from warpviz._native import core, registered_metrics
from warpviz.scene.native import CAMERA_SHIFTS, OBSERVER_KINDS, SCHEMA, native_camera
from warpviz.scene.reader import _describe, _Reader, did_you_mean, key_name
from warpviz.spacetime import Metric, metric_from_dict, metric_names


__all__ = ["AOV_NAMES"]

#: The AOV names a scene's ``[outputs] aovs`` may list: :data:`warpviz.render.render.OPTIONAL_AOVS` (the
#: renderer sits above scenes, so they are named here too; tests/test_scene.py checks they agree) and the
#: two a render always keeps.
AOV_NAMES = ("redshift", "n_steps", "max_drift", "status", "depth", "normal", "albedo", "albedo_normal", "emission",
             "errors", "samples")


#: The keys of a ``[metric]`` table with ``name = "custom"``, besides the landmarks (docs/line-element.md).
CUSTOM_METRIC_KEYS = ("name", "line_element", "coordinates", "parameters", "definitions", "label")


def _custom_metric(r: _Reader, tbl: dict) -> Metric:
    """``[metric] name = "custom"``: a metric from its line element, checked (expressions with the column in
    the file where they go wrong) before it is compiled on first use."""
    from warpviz.spacetime.line_element import LineElementError
    from warpviz.spacetime.line_element.codegen import LANDMARKS
    from warpviz.spacetime.line_element.tensor import COORDINATES

    path = ("metric",)
    r.table(path, tbl, [*CUSTOM_METRIC_KEYS, *LANDMARKS], required=("line_element",), what="[metric] (custom)")
    text = r.string(tbl, path, "line_element")
    coordinates = r.choice(tbl, path, "coordinates", list(COORDINATES), "cartesian")
    label = r.string(tbl, path, "label", "custom")
    params = r.get(tbl, path, "parameters", {})
    r.table(path + ("parameters",), params, [*params])
    values = {k: r.real(params, path + ("parameters",), k) for k in params}
    defs = r.get(tbl, path, "definitions", {})
    r.table(path + ("definitions",), defs, [*defs])
    definitions = {k: r.string(defs, path + ("definitions",), k) for k in defs}
    landmarks = {k: r.string(tbl, path, k) for k in LANDMARKS if k in tbl}
    try:
        return Metric.from_line_element(text, coordinates=coordinates, parameters=values, definitions=definitions,
                                        name=label, **landmarks)  # fmt: skip
    except LineElementError as exc:
        where = exc.where.split(".")
        key = path + (("label",) if where == ["name"] else tuple(where))
        raise r.error(key, f"metric.{exc.where}: {exc.reason}", inside=exc.column) from None
    except RuntimeError as exc:  # no compiler (says what to install), or a plugin the core refused
        raise r.error(path, f"metric: {exc}", at_value=False) from None


def _metric(r: _Reader, tbl: Any) -> Metric:
    path = ("metric",)
    registry = {m["name"]: m for m in registered_metrics()}
    r.table(path, tbl, [*tbl], required=("name",))  # a table with a name; its keys are checked below
    if tbl.get("name") == "custom":
        return _custom_metric(r, tbl)
    name = r.choice(tbl, path, "name", [*registry, "custom"])
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
    r.table(path, tbl, ("position", "look_at", "up", "fov", "sheet", *CAMERA_OBSERVER_KEYS), required=("position",))
    native = SCHEMA["camera"]  # the defaults of keys the native camera has; look_at is the file's own
    cam = {
        "position": r.vec3(tbl, path, "position"),
        "look_at": r.vec3(tbl, path, "look_at", [0.0, 0.0, 0.0]),
        "up": r.vec3(tbl, path, "up", native["up"], nonzero=True),
        "fov": r.real(tbl, path, "fov", native["fov"], lo=0.0, hi=180.0),
        "sheet": _sheet(r, tbl, path, two_sheets=metric.sheets == 2),
    }
    forward = np.subtract(cam["look_at"], cam["position"])
    if not np.linalg.norm(forward) > 0:
        raise r.error(path + ("look_at",), "camera.look_at must differ from camera.position")
    up = np.asarray(cam["up"]) / np.linalg.norm(cam["up"])
    if np.linalg.norm(np.cross(forward / np.linalg.norm(forward), up)) < 1e-6:
        raise r.error(path + ("up",), "camera.up must not be parallel to the viewing direction (look_at - position)")
    observer = _observer(r, tbl, path)
    problem = core.origin_problems(metric.name, metric.param_values, np.array([cam["position"]], dtype=np.float64),
                                   np.array([cam["sheet"]], dtype=np.int32), observer is not None)  # fmt: skip
    if problem is not None:
        raise r.error(path + ("position",), f"camera.position {cam['position']} {problem[1]}")
    if observer is not None:
        cam["observer"] = observer
        check = native_camera(dict(cam, width=1, height=1))
        try:
            core.observer(metric.name, metric.param_values, check)
        except ValueError as exc:
            raise r.error(path + ("observer",) if "observer" in tbl else path + ("velocity",),
                          f"camera.observer = {observer['kind']!r} at {cam['position']}: {exc}") from None
    shift = r.choice(tbl, path, "shift", list(CAMERA_SHIFTS), SCHEMA["camera"]["shift"])
    if shift != SCHEMA["camera"]["shift"]:
        cam["shift"] = shift
    return cam


#: The ``[camera]`` keys that say who holds the camera and what it does with the shift of the light it sees
#: (docs/observers.md).
CAMERA_OBSERVER_KEYS = ("observer", "velocity", "axis", "fall_from", "shift")
#: The observers a scene file may name (the native ``given``, a 4-velocity in chart components, is for
#: camera paths computed in Python).
SCENE_OBSERVERS = tuple(k for k in OBSERVER_KINDS if k != "given")


def _observer(r: _Reader, tbl: dict, path: tuple) -> dict | None:
    """The native observer of a ``[camera]`` table, or None for the local static observer. ``velocity``
    alone means ``observer = "moving"``; ``axis`` belongs to an orbit and ``fall_from`` to a free fall."""
    default = "moving" if "velocity" in tbl else "local"
    kind = r.choice(tbl, path, "observer", list(SCENE_OBSERVERS), default)
    needs = {"velocity": "moving", "axis": "orbit", "fall_from": "free_fall"}
    for key, owner in needs.items():
        if key in tbl and kind != owner:
            raise r.error(path + (key,), f"camera.{key} belongs to observer = {owner!r}, not {kind!r}")
    if kind == "local":
        return None
    out = dict(SCHEMA["observer"], kind=kind)
    if kind == "moving":
        out["velocity"] = r.vec3(tbl, path, "velocity")
        speed = math.sqrt(sum(v * v for v in out["velocity"]))
        if not speed < 1.0:
            raise r.error(path + ("velocity",), f"camera.velocity has speed {speed:g} c: a camera moves slower than "
                          "light (|velocity| < 1, in units of c)")  # fmt: skip
    if kind == "orbit":
        out["axis"] = r.vec3(tbl, path, "axis", list(SCHEMA["observer"]["axis"]), nonzero=True)
    if kind == "free_fall":
        value = r.get(tbl, path, "fall_from", "infinity")
        if value == "infinity":
            out["fall_from"] = 0.0
        elif isinstance(value, str):
            raise r.error(path + ("fall_from",), f'camera.fall_from must be a radius > 0 or "infinity", got {value!r}')
        else:
            out["fall_from"] = r.real(tbl, path, "fall_from", lo=0.0)
    return out


def wormhole_hint() -> str:
    """``metric.name = 'ellis'`` (or each registered wormhole's name): what a key of the other sheet needs."""
    return "metric.name = " + " or ".join(repr(n) for n in metric_names(sheets=2))


def _sheet(r: _Reader, tbl: dict, path: tuple, *, two_sheets: bool) -> int:
    sheet = r.integer(tbl, path, "sheet", SCHEMA["camera"]["sheet"])  # a shape's default sheet is the same
    if sheet not in (1, -1):
        raise r.error(path + ("sheet",), f"{key_name(path + ('sheet',))} must be 1 or -1, got {sheet}")
    if sheet == -1 and not two_sheets:
        kp = path + ("sheet",)
        why = f"needs a wormhole ({wormhole_hint()}); other spacetimes have one sheet"
        raise r.error(kp, f"{key_name(kp)} = -1 {why}")
    return sheet


#: The options a scene's [render] may set, by name (their ranges: warpviz/options.py), besides the image size.
_RENDER_OPTIONS = {o.name: o for o in RENDER_OPTIONS if o.scene}


def _render_table(r: _Reader, path: tuple, tbl: Any, *, allow_paper: bool) -> dict:
    allowed = ["width", "height", *_RENDER_OPTIONS] + (["paper"] if allow_paper else [])
    r.table(path, tbl, allowed)
    out = {}
    for key in tbl:
        if key == "paper":
            continue
        if key in ("width", "height"):
            out[key] = r.integer(tbl, path, key, lo=1, hi=MAX_IMAGE_SIDE)
            continue
        o = _RENDER_OPTIONS[key]
        if o.kind == "int":
            out[key] = r.integer(tbl, path, key, lo=o.lo, hi=o.hi)
        elif o.kind == "real":
            hi = None if o.hi is None or math.isinf(o.hi) else o.hi
            out[key] = r.real(tbl, path, key, lo=o.lo, hi=hi, lo_open=o.lo_open, hi_open=o.hi_open)
        elif o.kind == "bool":
            out[key] = r.boolean(tbl, path, key)
        else:
            out[key] = r.choice(tbl, path, key, o.choices)
    if "tol" in out:
        # Without a stepper here, the renderer's default (render() checks the one it uses).
        problem = tolerance_problem(out.get("stepper", DEFAULT_OPTIONS["stepper"]), out["tol"])
        if problem:
            raise r.error(path + ("tol",), f"{key_name(path)}.{problem}")
    return out


def _render(r: _Reader, tbl: Any) -> tuple[dict, dict]:
    render = _render_table(r, ("render",), tbl, allow_paper=True)
    paper = _render_table(r, ("render", "paper"), tbl.get("paper", {}), allow_paper=False)
    return render, paper


def _outputs(r: _Reader, tbl: Any) -> dict:
    path = ("outputs",)
    r.table(path, tbl, ("aovs", "file", "tonemap", "exposure"))
    aovs = None
    if "aovs" in tbl:
        aovs = tbl["aovs"]
        if not isinstance(aovs, list) or not all(isinstance(a, str) for a in aovs):
            raise r.error(path + ("aovs",), f"outputs.aovs must be a list of names, got {_describe(aovs)}")
        for i, a in enumerate(aovs):
            if a not in AOV_NAMES:
                known = ", ".join(AOV_NAMES)
                raise r.error(path + ("aovs", i),
                              f"outputs.aovs[{i}]: unknown AOV {a!r}{did_you_mean(a, AOV_NAMES)} (known: {known})")
    file = None
    if "file" in tbl:
        file = r.string(tbl, path, "file")
        if Path(file).suffix.lower() not in (".png", ".exr"):
            raise r.error(path + ("file",), f"outputs.file must end in .png or .exr, got {file!r}")
    # The PNG's look; None: the defaults of warpviz.render.tonemap (the command line's flags override both).
    tonemap = r.choice(tbl, path, "tonemap", list(TONEMAP_NAMES)) if "tonemap" in tbl else None
    exposure = (r.real(tbl, path, "exposure", lo=EXPOSURE_RANGE[0], hi=EXPOSURE_RANGE[1], lo_open=False, hi_open=False)
                if "exposure" in tbl else None)  # fmt: skip
    return {"aovs": aovs, "file": file, "tonemap": tonemap, "exposure": exposure}
