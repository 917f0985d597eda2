"""Display meshes of the teaching view: the picture as a grid of pixel cells, pixel outlines, display colours
of a scene's materials, and the bounds the 3-D camera frames. PyVista and VTK are imported on first use.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from warpviz.render import tonemap
from warpviz.scene.native import SCHEMA

_MATERIALS = SCHEMA["materials"]  # the native defaults of keys a hand-built scene may leave out

_MATERIAL_TYPE_COLOR = {"diffuse": (0.75, 0.75, 0.75), "mirror": (0.7, 0.75, 0.85), "glass": (0.6, 0.85, 0.95),
                        "emissive": (1.0, 0.9, 0.4)}  # fmt: skip


def _image_grid(image: np.ndarray):
    """The picture as a W x H grid of unit cells in z = 0 with uint8 cell data ``rgb`` (pixel (x, y) is
    cell ``x + W (H - 1 - y)``, see :mod:`warpviz.viewer.picking`)."""
    import pyvista as pv

    height, width = image.shape[:2]
    grid = pv.ImageData(dimensions=(width + 1, height + 1, 1))
    grid.cell_data["rgb"] = np.ascontiguousarray(image[::-1].reshape(-1, 3))
    return grid


def _pixel_outlines(pixels: np.ndarray, height: int, *, pad: float, z: float):
    """Closed squares around pixels (x, y) of the image grid, as polylines."""
    import pyvista as pv

    pixels = np.asarray(pixels, dtype=np.float64).reshape(-1, 2)
    if not len(pixels):
        return pv.PolyData()
    x0 = pixels[:, 0] - pad
    y0 = height - 1 - pixels[:, 1] - pad
    x1, y1 = x0 + 1 + 2 * pad, y0 + 1 + 2 * pad
    corners = np.stack([np.column_stack([x0, y0]), np.column_stack([x1, y0]), np.column_stack([x1, y1]),
                        np.column_stack([x0, y1])], axis=1)  # fmt: skip
    points = np.concatenate([corners.reshape(-1, 2), np.full((corners.shape[0] * 4, 1), z)], axis=1)
    base = 4 * np.arange(len(pixels))[:, None]
    lines = np.column_stack([np.full(len(pixels), 5), base + np.array([0, 1, 2, 3, 0])[None, :]])
    return pv.PolyData(points, lines=lines.ravel())


def _texture_color(texture: Mapping[str, Any] | None) -> np.ndarray:
    """(3,) typical linear colour of a native scene texture."""
    if not texture:
        return np.full(3, 0.75)
    kind = texture.get("type")
    if kind == "constant":
        return np.asarray(texture["color"], dtype=np.float64)
    if kind == "checker":
        return 0.5 * np.add(np.asarray(texture["color_a"], dtype=np.float64), texture["color_b"])
    if kind == "grid":
        return np.asarray(texture["base"], dtype=np.float64)
    if kind == "image":
        return np.asarray(texture["data"], dtype=np.float64).reshape(-1, 3).mean(axis=0)
    return np.full(3, 0.75)


def _material_colors(native_scene: Mapping[str, Any] | None, material_types) -> np.ndarray:
    """(M, 3) float display colours (linear, about [0, 1]) of a scene's materials."""
    if native_scene is not None:
        materials, textures = native_scene.get("materials") or [], native_scene.get("textures") or []
        out = []
        for m in materials:
            kind = m.get("type")
            tex = textures[m["texture"]] if "texture" in m and 0 <= m["texture"] < len(textures) else None
            if kind == "diffuse":
                out.append(_texture_color(tex))
            elif kind == "emissive":
                c = _texture_color(tex) * float(m.get("strength", _MATERIALS["emissive"]["strength"]))
                out.append(c / max(float(c.max()), 1e-12))
            elif kind == "mirror":
                out.append(0.5 + 0.4 * np.asarray(m.get("reflectance", _MATERIALS["mirror"]["reflectance"]), dtype=np.float64))
            elif kind == "glass":
                tint = m.get("tint", _MATERIALS["glass"]["tint"])
                out.append(0.3 * np.asarray(tint, dtype=np.float64) + np.array([0.4, 0.6, 0.7]))
            else:
                out.append(np.full(3, 0.75))
        return np.array(out, dtype=np.float64).reshape(-1, 3)
    return np.array([_MATERIAL_TYPE_COLOR.get(str(t), (0.75, 0.75, 0.75)) for t in material_types]).reshape(-1, 3)


def _surface_rgb(surfaces, native_scene) -> np.ndarray:
    """(F, 3) uint8 sRGB colour per surface cell, from its material."""
    types = np.asarray(surfaces.field_data["material_type"]).tolist() if "material_type" in surfaces.field_data else []
    colors = _material_colors(native_scene, types)
    material = np.asarray(surfaces.cell_data["material"]) if "material" in surfaces.cell_data else None
    linear = np.full((surfaces.n_cells, 3), 0.75)
    if material is not None and len(colors):
        ok = (material >= 0) & (material < len(colors))
        linear[ok] = colors[material[ok]]
    return tonemap(linear[None, :, :], method="clip")[0]  # albedos in [0, 1]: shown as they are


def _focus_bounds(meshes) -> np.ndarray | None:
    """(6,) union of the bounds of the non-empty meshes."""
    boxes = [np.asarray(m.bounds, dtype=np.float64) for m in meshes if m is not None and m.n_points]
    if not boxes:
        return None
    b = np.stack(boxes)
    return np.array([b[:, 0].min(), b[:, 1].max(), b[:, 2].min(), b[:, 3].max(), b[:, 4].min(), b[:, 5].max()])


def _first_points(poly) -> np.ndarray:
    """(N, 3) first point of each polyline cell of ``poly`` (cells without points skipped)."""
    from vtkmodules.util.numpy_support import vtk_to_numpy

    lines = poly.GetLines()
    offsets = vtk_to_numpy(lines.GetOffsetsArray())
    conn = vtk_to_numpy(lines.GetConnectivityArray())
    starts = offsets[:-1][np.diff(offsets) > 0]
    return np.asarray(poly.points)[conn[starts]] if len(starts) else np.zeros((0, 3))


def _around(bounds: np.ndarray, points: np.ndarray) -> np.ndarray:
    """(6,) bounds centred on the centre of ``bounds``, grown per axis to hold ``points`` (K, 3)."""
    centre = 0.5 * (bounds[0::2] + bounds[1::2])
    half = 0.5 * (bounds[1::2] - bounds[0::2])
    if len(points):
        half = np.maximum(half, np.abs(points - centre).max(axis=0))
    return np.column_stack([centre - half, centre + half]).ravel()


def _cut_lines_at(poly, reach: float):
    """The polylines of ``poly`` each cut after its first point farther than ``reach`` from the z axis
    (one cell per line kept, in order, so cell ids still name the rays; point data kept)."""
    from vtkmodules.util.numpy_support import numpy_to_vtkIdTypeArray, vtk_to_numpy

    out = poly.copy()
    lines = out.GetLines()
    if lines is None or not lines.GetNumberOfCells():
        return out
    offsets = vtk_to_numpy(lines.GetOffsetsArray()).astype(np.int64)
    ids = vtk_to_numpy(lines.GetConnectivityArray()).astype(np.int64)
    far = np.hypot(*np.asarray(out.points, dtype=np.float64)[:, :2].T) > reach
    keep_ids, keep_offsets = [], [0]
    for a, b in zip(offsets[:-1], offsets[1:]):
        cell = ids[a:b]
        beyond = np.flatnonzero(far[cell])
        cell = cell[: max(2, beyond[0] + 1)] if len(beyond) else cell
        keep_ids.append(cell)
        keep_offsets.append(keep_offsets[-1] + len(cell))
    lines.SetData(numpy_to_vtkIdTypeArray(np.asarray(keep_offsets, dtype=np.int64), deep=True),
                  numpy_to_vtkIdTypeArray(np.concatenate(keep_ids).astype(np.int64), deep=True))  # fmt: skip
    out.Modified()
    return out
