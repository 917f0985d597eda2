"""Convenience shapes of scene files built from the native ones: boxes (six quads), cylinders (meshes),
and the scale-rotate-translate transform applied to meshes.

Rotations are given as three angles in degrees about the fixed x, y and z axes, applied in that order
(x first), i.e. the matrix R = Rz · Ry · Rx.

Examples
--------
>>> import numpy as np
>>> from warpviz.scene.primitives import rotation_matrix, cylinder_mesh
>>> np.round(rotation_matrix([0, 0, 90]) @ [1.0, 0, 0], 12).tolist()
[0.0, 1.0, 0.0]
>>> v, f, uv = cylinder_mesh(center=[0, 0, 0], axis=[0, 0, 1], radius=1.0, height=2.0, segments=8)
>>> v.shape[1], f.dtype.name, bool(abs(v[:, 2]).max() == 1.0)
(3, 'int32', True)
"""

from __future__ import annotations

import math

import numpy as np


def rotation_matrix(degrees_xyz) -> np.ndarray:
    """3x3 rotation by angles (degrees) about x, then y, then z (fixed axes): R = Rz · Ry · Rx."""
    ax, ay, az = (math.radians(float(a)) for a in degrees_xyz)
    cx, sx, cy, sy, cz, sz = math.cos(ax), math.sin(ax), math.cos(ay), math.sin(ay), math.cos(az), math.sin(az)
    rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    return rz @ ry @ rx


def transform_points(points: np.ndarray, *, translate=(0.0, 0.0, 0.0), rotate=(0.0, 0.0, 0.0), scale=1.0) -> np.ndarray:
    """Scale (a number or one factor per axis), then rotate (:func:`rotation_matrix`), then translate."""
    p = np.asarray(points, dtype=np.float64) * np.asarray(scale, dtype=np.float64)
    return p @ rotation_matrix(rotate).T + np.asarray(translate, dtype=np.float64)


def box_quads(*, center, size, rotate=(0.0, 0.0, 0.0)) -> list[dict]:
    """The six faces of a box as native quads with outward normals (``edge_u x edge_v`` points out).

    Parameters
    ----------
    center : array_like, shape (3,), keyword-only
        Centre of the box.
    size : array_like, shape (3,), keyword-only
        Edge lengths along the box's own x, y, z axes.
    rotate : array_like, shape (3,), keyword-only
        Rotation of the box about its centre, degrees about x, y, z (:func:`rotation_matrix`).

    Returns
    -------
    list of dict
        ``{"corner", "edge_u", "edge_v"}`` per face (lists of floats), in the order -x, +x, -y, +y, -z, +z.
    """
    c = np.asarray(center, dtype=np.float64)
    h = 0.5 * np.asarray(size, dtype=np.float64)
    rot = rotation_matrix(rotate)
    ex, ey, ez = (rot[:, k] * 2.0 * h[k] for k in range(3))
    lo = c - rot @ h  # the corner at local (-hx, -hy, -hz)
    faces = [
        (lo, ez, ey),  # -x: ez x ey = -x
        (lo + ex, ey, ez),  # +x
        (lo, ex, ez),  # -y: ex x ez = -y
        (lo + ey, ez, ex),  # +y
        (lo, ey, ex),  # -z: ey x ex = -z
        (lo + ez, ex, ey),  # +z
    ]
    return [{"corner": a.tolist(), "edge_u": u.tolist(), "edge_v": v.tolist()} for a, u, v in faces]


def _frame(axis: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    w = axis / np.linalg.norm(axis)
    helper = np.array([1.0, 0.0, 0.0]) if abs(w[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    u = np.cross(helper, w)
    u /= np.linalg.norm(u)
    return u, np.cross(w, u), w


def cylinder_mesh(*, center, axis=(0.0, 0.0, 1.0), radius: float, height: float, segments: int = 48, caps: bool = True):
    """A closed (or open) circular cylinder as a triangle mesh with outward, counter-clockwise faces.

    Parameters
    ----------
    center : array_like, shape (3,), keyword-only
        Midpoint of the axis.
    axis : array_like, shape (3,), keyword-only
        Direction of the axis (normalised here).
    radius, height : float, keyword-only
        Radius and length along the axis.
    segments : int, keyword-only
        Facets around the axis.
    caps : bool, keyword-only
        Close both ends with flat discs.

    Returns
    -------
    vertices : numpy.ndarray, shape (V, 3), float64
    faces : numpy.ndarray, shape (F, 3), int32
    uvs : numpy.ndarray, shape (V, 2), float64
        Side: u = angle / 2 pi, v = position along the axis (0 bottom, 1 top). Caps: a disc mapped into
        the unit square.
    """
    u_dir, v_dir, w = _frame(np.asarray(axis, dtype=np.float64))
    c = np.asarray(center, dtype=np.float64)
    n = int(segments)
    ang = 2.0 * np.pi * np.arange(n + 1) / n  # seam vertex repeated for the texture
    ring = np.cos(ang)[:, None] * u_dir + np.sin(ang)[:, None] * v_dir
    bottom = c - 0.5 * height * w + radius * ring
    top = c + 0.5 * height * w + radius * ring
    verts = [bottom, top]
    u = ang / (2 * np.pi)
    uvs = [np.stack([u, np.zeros(n + 1)], axis=1), np.stack([u, np.ones(n + 1)], axis=1)]
    k = np.arange(n)
    b, t = k, k + (n + 1)
    faces = [np.stack([b, b + 1, t + 1], axis=1), np.stack([b, t + 1, t], axis=1)]
    if caps:
        base = 2 * (n + 1)
        for sign in (-1.0, 1.0):
            centre_idx = base
            rim = c + sign * 0.5 * height * w + radius * ring[:n]
            verts += [(c + sign * 0.5 * height * w)[None, :], rim]
            uvs += [np.array([[0.5, 0.5]]), 0.5 + 0.5 * np.stack([np.cos(ang[:n]), np.sin(ang[:n])], axis=1)]
            r0, r1 = centre_idx + 1 + k, centre_idx + 1 + (k + 1) % n
            first, second = (r0, r1) if sign > 0 else (r1, r0)  # counter-clockwise seen from outside
            tri = np.stack([np.full(n, centre_idx), first, second], axis=1)
            faces.append(tri)
            base += n + 1
    return np.vstack(verts), np.vstack(faces).astype(np.int32), np.vstack(uvs)
