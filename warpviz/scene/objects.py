"""Compiling the ``[[objects]]`` of a scene into native shapes.

Spheres, quads and disks map one to one; boxes become six quads and cylinders triangle meshes
(:mod:`warpviz.scene.primitives`); mesh files are read with trimesh and transformed. Every shape
carries its material index and sheet.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from warpviz.limits import MESH_LIMIT_VARIABLE, mesh_limit_bytes
from warpviz.scene import primitives
from warpviz.scene.native import SCHEMA
from warpviz.scene.reader import _describe, _Reader, key_name
from warpviz.scene.settings import _sheet

__all__ = ["MESH_SUFFIXES"]

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


def _objects(r: _Reader, objs: Any, mat_index: dict, *, two_sheets: bool) -> list[dict]:
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
        material = r.reference(o, op, "material", mat_index, "material")
        if "name" in o:
            r.string(o, op, "name")
        common = {"material": material, "sheet": _sheet(r, o, op, two_sheets=two_sheets)}
        for shape in _shape(r, op, kind, o):
            shapes.append({**shape, **common})
    return shapes


def _not_parallel(r: _Reader, kp: tuple, a, b, what: str) -> None:
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    if np.linalg.norm(np.cross(a / np.linalg.norm(a), b / np.linalg.norm(b))) < 1e-9:
        raise r.error(kp, f"{key_name(kp)} must not be parallel to {what}")


def _shape(r: _Reader, op: tuple, kind: str, o: dict) -> list[dict]:
    native = SCHEMA["shapes"].get(kind, {})  # the defaults of keys that native shapes have
    if kind == "sphere":
        pole = r.vec3(o, op, "pole", native["pole"], nonzero=True)
        meridian = r.vec3(o, op, "meridian", native["meridian"], nonzero=True)
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
        normal = r.vec3(o, op, "normal", native["normal"], nonzero=True)
        meridian = r.vec3(o, op, "meridian", native["meridian"], nonzero=True)
        _not_parallel(r, op + ("meridian",), meridian, normal, "the normal")
        inner = r.real(o, op, "inner_radius", native["inner_radius"], lo=0.0, lo_open=False)
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
    import warnings

    import trimesh

    try:
        limit = mesh_limit_bytes()
    except ValueError as exc:
        raise r.error(kp, f"{key_name(kp)}: {exc}") from None
    size = file.stat().st_size
    if size > limit:
        raise r.error(kp, f"{key_name(kp)}: mesh {file.name!r} is {size / 2**20:.0f} MB, more than the "
                          f"{limit / 2**20:.0f} MB a mesh file may be (set {MESH_LIMIT_VARIABLE} to a larger number "
                          "of MB to read it)")  # fmt: skip
    try:
        with warnings.catch_warnings():  # the loaders' own warnings (NaN arithmetic) say less than the checks below
            warnings.simplefilter("ignore")
            mesh = trimesh.load(str(file), force="mesh", process=False)
    except Exception as exc:  # noqa: BLE001 - any loader failure is the file's fault
        raise r.error(kp, f"{key_name(kp)}: cannot read mesh {file.name!r}: {exc}") from None
    vertices = np.asarray(getattr(mesh, "vertices", np.empty((0, 3))), dtype=np.float64)
    faces = np.asarray(getattr(mesh, "faces", np.empty((0, 3))), dtype=np.int32)
    if vertices.ndim != 2 or len(vertices) == 0 or faces.ndim != 2 or len(faces) == 0:
        raise r.error(kp, f"{key_name(kp)}: mesh {file.name!r} has no triangles")
    bad = int(np.count_nonzero(~np.isfinite(vertices).all(axis=1)))
    if bad:
        raise r.error(kp, f"{key_name(kp)}: mesh {file.name!r} has {bad} vertices whose coordinates are not "
                          "finite numbers (NaN or infinity)")  # fmt: skip
    uv = getattr(getattr(mesh, "visual", None), "uv", None)
    uvs = None
    if uv is not None and np.shape(uv) == (len(vertices), 2):
        uvs = np.ascontiguousarray(uv, dtype=np.float64)
    return np.ascontiguousarray(vertices), np.ascontiguousarray(faces), uvs
