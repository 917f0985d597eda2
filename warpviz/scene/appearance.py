"""Compiling what a scene looks like: the skies (``[environment]``, ``[environment_other]``), the
``[textures.NAME]`` and the ``[materials.NAME]`` tables, into native scene entries.

Textures and materials are referred to by name in the file and by index in the native scene; image
files are decoded and procedural pictures (:mod:`warpviz.scene.textures`) generated here, so a scene
that builds renders.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from warpviz.limits import MAX_STRENGTH
from warpviz.scene import textures
from warpviz.scene.native import SCHEMA
from warpviz.scene.reader import _describe, _Reader, key_name

# Defaults of keys that map one to one onto native keys are the native scene's (warpviz.scene.native).
_ENV, _SPOT, _TEX, _MAT = SCHEMA["environment"], SCHEMA["spots"], SCHEMA["textures"], SCHEMA["materials"]


def _environment(r: _Reader, path: tuple, tbl: Any) -> dict:
    r.table(path, tbl, ("color", "image", "stars", "spots"))
    env = {"color": r.color(tbl, path, "color", _ENV["color"]), "image": None, "stars": None, "spots": []}
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
            "seed": r.integer(stars, sp, "seed", 7, lo=0, hi=2**53),
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
            "radius": r.real(spot, sp, "radius", _SPOT["radius"], lo=0.0, hi=math.pi),
            "color": r.color(spot, sp, "color", _SPOT["color"]),
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
    "grid": ("base", "line_u", "line_v", "cells", "width", "mark_u", "mark_v"),
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


def _marked_lines(r: _Reader, tp: tuple, t: dict, cells: list) -> dict:
    """A grid's marked lines: ``mark_u = { line = K, color = [r, g, b] }`` draws line K (0 .. cells[0]) of
    constant u in its own colour, likewise ``mark_v``; as the native keys mark_u(_color), mark_v(_color)."""
    out = {}
    for axis, n in (("u", cells[0]), ("v", cells[1])):
        key = f"mark_{axis}"
        if key not in t:
            continue
        kp = tp + (key,)
        m = r.table(kp, t[key], ("line", "color"), required=("line", "color"))
        out[key] = r.integer(m, kp, "line", lo=0, hi=n)
        out[f"{key}_color"] = r.color(m, kp, "color")
    return out


def _texture(r: _Reader, tp: tuple, kind: str, t: dict) -> dict:
    if kind == "constant":
        return {"type": "constant", "color": r.color(t, tp, "color")}
    if kind == "checker":
        return {
            "type": "checker", "color_a": r.color(t, tp, "color_a", [0.8, 0.8, 0.8]),
            "color_b": r.color(t, tp, "color_b", [0.2, 0.2, 0.2]),
            "scale": r.numbers(t, tp, "scale", 2, _TEX["checker"]["scale"], lo=0.0, lo_open=True),
        }  # fmt: skip
    if kind == "grid":
        cells = r.numbers(t, tp, "cells", 2, _TEX["grid"]["cells"], integer=True, lo=1)
        return {
            "type": "grid", "base": r.color(t, tp, "base", [1.0, 1.0, 1.0]),
            "line_u": r.color(t, tp, "line_u", [0.0, 0.0, 0.0]), "line_v": r.color(t, tp, "line_v", [0.0, 0.0, 0.0]),
            "cells": cells, "width": r.real(t, tp, "width", _TEX["grid"]["width"], lo=0.0, hi=1.0),
            **_marked_lines(r, tp, t, cells),
        }  # fmt: skip
    repeat = r.numbers(t, tp, "repeat", 2, _TEX["image"]["repeat"], lo=0.0, lo_open=True)
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
    "diffuse": ("color", "texture", "emission"),
    "mirror": ("reflectance", "emission"),
    "glass": ("ior", "tint", "emission"),
    "emissive": ("strength", "color", "texture", "two_sided", "keplerian", "beaming", "colour_shift"),
}


#: The defaults of a reflecting material's ``emission = { color, strength }`` table (the native dict has
#: only their product, ``emission``).
EMISSION_DEFAULTS = {"color": [1.0, 1.0, 1.0], "strength": 1.0}


def _emission(r: _Reader, m: dict, mp: tuple) -> list[float]:
    """A diffuse, mirror or glass material's emitted radiance: emission.color * emission.strength (none: 0)."""
    if "emission" not in m:
        return [0.0, 0.0, 0.0]
    ep = mp + ("emission",)
    e = r.table(ep, m["emission"], ("color", "strength"), what="an emission table { color, strength }")
    color = r.color(e, ep, "color", EMISSION_DEFAULTS["color"])
    strength = r.real(e, ep, "strength", EMISSION_DEFAULTS["strength"], lo=0.0, lo_open=False, hi=MAX_STRENGTH,
                      hi_open=False)  # fmt: skip
    return [c * strength for c in color]


def _materials(r: _Reader, tbl: Any, tex_list: list, tex_index: dict) -> tuple[list, dict]:
    path = ("materials",)
    if not isinstance(tbl, dict):
        raise r.error(path, f"materials must be a table of [materials.NAME] tables, got {_describe(tbl)}")
    out, index = [], {}

    def texture_ref(m: dict, mp: tuple, *, albedo: bool, default_color: list) -> int:
        if "texture" in m and "color" in m:
            raise r.error(mp + ("texture",), f"{key_name(mp)}: give either color or texture, not both", at_value=False)
        if "texture" in m:
            return r.reference(m, mp, "texture", tex_index, "texture")
        tex_list.append({"type": "constant", "color": r.color(m, mp, "color", default_color, albedo=albedo)})
        return len(tex_list) - 1

    for name, m in tbl.items():
        mp = path + (name,)
        if not isinstance(m, dict):
            raise r.error(mp, f"{key_name(mp)} must be a table, got {_describe(m)}")
        kind = r.choice(m, mp, "type", list(_MATERIAL_KEYS))
        r.table(mp, m, ("type", *_MATERIAL_KEYS[kind]))
        if kind == "diffuse":
            mat = {"type": "diffuse", "texture": texture_ref(m, mp, albedo=True, default_color=[0.8, 0.8, 0.8]),
                   "emission": _emission(r, m, mp)}  # fmt: skip
        elif kind == "mirror":
            mat = {"type": "mirror", "reflectance": r.color(m, mp, "reflectance", _MAT["mirror"]["reflectance"], albedo=True),
                   "emission": _emission(r, m, mp)}  # fmt: skip
        elif kind == "glass":
            glass = _MAT["glass"]
            mat = {"type": "glass", "ior": r.real(m, mp, "ior", glass["ior"], lo=1.0, hi=4.0, lo_open=False),
                   "tint": r.color(m, mp, "tint", glass["tint"], albedo=True), "emission": _emission(r, m, mp)}  # fmt: skip
        else:
            emissive = _MAT["emissive"]
            mat = {
                "type": "emissive", "texture": texture_ref(m, mp, albedo=False, default_color=[1.0, 1.0, 1.0]),
                "strength": r.real(m, mp, "strength", emissive["strength"], lo=0.0, lo_open=False, hi=MAX_STRENGTH,
                                   hi_open=False),  # fmt: skip
                **{k: r.boolean(m, mp, k, emissive[k]) for k in ("two_sided", "keplerian", "beaming", "colour_shift")},
            }  # fmt: skip
        index[name] = len(out)
        out.append(mat)
    return out, index
