"""Polygons before they become PyVista polydata, and surfaces of revolution about the z axis.

The mesh helpers shared by the landmark surfaces (:mod:`warpviz.spacetime.landmarks`) and the scene
surfaces (:mod:`warpviz.scene.surfaces`). PyVista is imported only when polydata is made.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # pragma: no cover
    import pyvista as pv


def _join(arrays: list[np.ndarray]) -> np.ndarray:
    return np.concatenate(arrays).astype(np.int64) if arrays else np.zeros(0, dtype=np.int64)


class _Piece:
    """Polygons before they become polydata: points (n, 3), face sizes (F,), point ids (sum sizes,)."""

    def __init__(self, points: np.ndarray, sizes: np.ndarray, conn: np.ndarray):
        self.points = np.asarray(points, dtype=np.float64)
        self.sizes = np.asarray(sizes, dtype=np.int64)
        self.conn = np.asarray(conn, dtype=np.int64)

    def polydata(self, **point_data: np.ndarray) -> pv.PolyData:
        import pyvista as pv

        if not self.points.size:
            mesh = pv.PolyData()
        else:  # VTK's flat layout: each face's size, then its point ids
            starts = np.cumsum(self.sizes) - self.sizes
            mesh = pv.PolyData(self.points, faces=np.insert(self.conn, starts, self.sizes))
        for name, values in point_data.items():
            mesh.point_data[name] = values
        return mesh


def _revolve(rho: np.ndarray, z: np.ndarray, *, n_phi: int, closed: bool = False) -> _Piece:
    """Points and faces of the surface swept by the meridian curve (rho_i, z_i) about z.

    Curve points with rho == 0 lie on the axis and become a single point (their quads become
    triangles). With the curve running from the north pole to the south pole, faces point outward.
    ``closed`` joins the last curve point back to the first.
    """
    rho = np.asarray(rho, dtype=np.float64)
    z = np.asarray(z, dtype=np.float64)
    n = rho.shape[0]
    on_axis = rho == 0.0
    phi = np.linspace(0.0, 2.0 * math.pi, n_phi, endpoint=False)

    per_row = np.where(on_axis, 1, n_phi)
    start = np.concatenate([[0], np.cumsum(per_row)[:-1]])
    index = start[:, None] + np.where(on_axis[:, None], 0, np.arange(n_phi)[None, :])
    x = np.where(on_axis[:, None], 0.0, rho[:, None] * np.cos(phi)[None, :])
    y = np.where(on_axis[:, None], 0.0, rho[:, None] * np.sin(phi)[None, :])
    keep = np.ones((n, n_phi), dtype=bool)
    keep[on_axis, 1:] = False
    points = np.column_stack([x[keep], y[keep], np.broadcast_to(z[:, None], (n, n_phi))[keep]])

    sizes, conn = [], []
    nxt = np.roll(np.arange(n_phi), -1)
    segments = [(i, i + 1) for i in range(n - 1)] + ([(n - 1, 0)] if closed else [])
    for i, k in segments:
        a, b, c, d = index[i], index[k], index[k, nxt], index[i, nxt]
        if on_axis[i] and on_axis[k]:
            continue
        if on_axis[i]:
            cells = np.column_stack([a, b, c])
        elif on_axis[k]:
            cells = np.column_stack([a, b, d])
        else:
            cells = np.column_stack([a, b, c, d])
        sizes.append(np.full(n_phi, cells.shape[1]))
        conn.append(cells.ravel())
    return _Piece(points, _join(sizes), _join(conn))


def _per_point(values: np.ndarray, rho: np.ndarray, n_phi: int) -> np.ndarray:
    """Expand one value per meridian point to one per surface point (as laid out by ``_revolve``)."""
    return np.repeat(np.asarray(values, dtype=np.float64), np.where(rho == 0.0, 1, n_phi))


def _theta(resolution: int) -> np.ndarray:
    return np.linspace(0.0, math.pi, resolution // 2 + 1)


def _check_resolution(resolution: int) -> int:
    if isinstance(resolution, bool) or not isinstance(resolution, (int, np.integer)) or resolution < 3:
        raise ValueError(f"resolution must be an integer >= 3, got {resolution!r}")
    return int(resolution)
