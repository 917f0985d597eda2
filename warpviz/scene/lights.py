"""Compiling the ``[[lights]]`` of a scene into native point and spot lights.

A point light sends ``intensity`` x ``color`` per steradian of the local sky at ``position`` in every
direction; a spot light only within ``angle`` degrees of ``direction`` (or of the way to ``look_at``), its
edge softened over the last ``falloff`` degrees. No ray ever hits one, so neither is seen directly; the light
strategy reaches them (exactly, through the lens map, in static spacetimes) and the photons carry their
caustics (``photons``).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from warpviz.limits import MAX_STRENGTH
from warpviz.scene.native import SCHEMA
from warpviz.scene.reader import _describe, _Reader, key_name
from warpviz.scene.settings import _sheet

_LIGHT_KEYS = {"point": ("position", "color", "intensity"),
               "spot": ("position", "color", "intensity", "direction", "look_at", "angle", "falloff")}  # fmt: skip
_COMMON_LIGHT_KEYS = ("type", "sheet", "name")


def _lights(r: _Reader, lights: Any, *, two_sheets: bool) -> list[dict]:
    if not isinstance(lights, list):
        raise r.error(("lights",), f"lights must be an array of [[lights]] tables, got {_describe(lights)}")
    out = []
    for i, t in enumerate(lights):
        lp = ("lights", i)
        if not isinstance(t, dict):
            raise r.error(lp, f"{key_name(lp)} must be a table, got {_describe(t)}")
        kind = r.choice(t, lp, "type", list(_LIGHT_KEYS))
        r.table(lp, t, (*_COMMON_LIGHT_KEYS, *_LIGHT_KEYS[kind]), required=("position", "intensity"),
                what=f"{key_name(lp)} ({kind})")  # fmt: skip
        if "name" in t:
            r.string(t, lp, "name")
        native = SCHEMA["lights"][kind]
        light = {"type": kind, "position": r.vec3(t, lp, "position"), "sheet": _sheet(r, t, lp, two_sheets=two_sheets),
                 "color": r.color(t, lp, "color", list(native["color"])),
                 "intensity": r.real(t, lp, "intensity", lo=0.0, hi=MAX_STRENGTH, lo_open=False, hi_open=False)}  # fmt: skip
        if kind == "spot":
            if ("direction" in t) == ("look_at" in t):
                raise r.error(lp, f"{key_name(lp)} (spot) needs one of direction or look_at", at_value=False)
            if "direction" in t:
                direction = r.vec3(t, lp, "direction", nonzero=True)
            else:
                direction = list(np.asarray(r.vec3(t, lp, "look_at"), float) - np.asarray(light["position"], float))
                if not np.linalg.norm(direction) > 0:
                    raise r.error(lp + ("look_at",), f"{key_name(lp + ('look_at',))} must differ from the position")
            angle = r.real(t, lp, "angle", native["angle"], lo=0.0, hi=180.0, hi_open=False)
            falloff = r.real(t, lp, "falloff", min(native["falloff"], angle), lo=0.0, hi=angle, lo_open=False,
                             hi_open=False)  # fmt: skip
            light.update(direction=[float(v) for v in direction], angle=angle, falloff=falloff)
        out.append(light)
    return out
