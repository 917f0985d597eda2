"""Display meshes of a native scene: its shapes as one surface, its point and spot lights as points and its camera
as a frustum (PyVista polydata).

Examples
--------
>>> cam = {"position": [0, 0, 0], "look_at": [0, 0, 5], "up": [0, 1, 0], "fov": 60.0, "width": 4, "height": 3}
>>> frustum = camera_frustum(cam)
>>> frustum.n_points, frustum.field_data["width"].tolist()
(6, [4])
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from warpviz.scene.camera import camera_basis
from warpviz.scene.native import SCHEMA, native_camera
from warpviz.spacetime._meshes import _check_resolution, _join, _Piece, _revolve, _theta

if TYPE_CHECKING:  # pragma: no cover
    import pyvista as pv

__all__ = ["camera_frustum", "scene_lights", "scene_surfaces"]


# --------------------------------------------------------------------------------------------------
# scene shapes


def _vector(shape_name: str, key: str, value: Any) -> np.ndarray:
    vec = np.asarray(value, dtype=np.float64)
    if vec.shape != (3,) or not np.all(np.isfinite(vec)):
        raise ValueError(f"{shape_name}: {key} must be 3 finite numbers, got {value!r}")
    return vec


def _frame(axis: np.ndarray, meridian: np.ndarray | None) -> np.ndarray:
    """Right-handed orthonormal rows (e1, e2, e3): e3 along ``axis``, e1 towards ``meridian``."""
    e3 = axis / np.linalg.norm(axis)
    candidates = [] if meridian is None else [meridian]
    candidates += [np.eye(3)[i] for i in np.argsort(np.abs(e3))]
    for m in candidates:
        e1 = m - (m @ e3) * e3
        if np.linalg.norm(e1) > 1e-9 * max(np.linalg.norm(m), 1.0):
            e1 = e1 / np.linalg.norm(e1)
            return np.stack([e1, np.cross(e3, e1), e3])
    raise AssertionError("unreachable: some axis is perpendicular enough")  # pragma: no cover


def _sphere_piece(name: str, shape: Mapping[str, Any], resolution: int) -> _Piece:
    center = _vector(name, "center", shape["center"])
    radius = float(shape["radius"])
    if not radius > 0.0:
        raise ValueError(f"{name}: radius must be > 0, got {radius!r}")
    defaults = SCHEMA["shapes"]["sphere"]
    frame = _frame(_vector(name, "pole", shape.get("pole", defaults["pole"])),
                   _vector(name, "meridian", shape.get("meridian", defaults["meridian"])))  # fmt: skip
    theta = _theta(resolution)
    rho = radius * np.sin(theta)
    rho[[0, -1]] = 0.0
    piece = _revolve(rho, radius * np.cos(theta), n_phi=resolution)
    return _Piece(center + piece.points @ frame, piece.sizes, piece.conn)


def _disk_piece(name: str, shape: Mapping[str, Any], resolution: int) -> _Piece:
    center = _vector(name, "center", shape["center"])
    defaults = SCHEMA["shapes"]["disk"]
    r_in, r_out = float(shape.get("inner_radius", defaults["inner_radius"])), float(shape["outer_radius"])
    if not 0.0 <= r_in < r_out:
        raise ValueError(f"{name}: need 0 <= inner_radius < outer_radius, got {r_in!r}, {r_out!r}")
    frame = _frame(_vector(name, "normal", shape.get("normal", defaults["normal"])),
                   _vector(name, "meridian", shape.get("meridian", defaults["meridian"])))  # fmt: skip
    rho = np.linspace(r_in, r_out, 5)
    piece = _revolve(rho, np.zeros_like(rho), n_phi=resolution)
    return _Piece(center + piece.points @ frame, piece.sizes, piece.conn)


def _quad_piece(name: str, shape: Mapping[str, Any], resolution: int) -> _Piece:
    corner = _vector(name, "corner", shape["corner"])
    eu, ev = _vector(name, "edge_u", shape["edge_u"]), _vector(name, "edge_v", shape["edge_v"])
    points = np.stack([corner, corner + eu, corner + eu + ev, corner + ev])  # counter-clockwise about eu x ev
    return _Piece(points, [4], [0, 1, 2, 3])


def _mesh_piece(name: str, shape: Mapping[str, Any], resolution: int) -> _Piece:
    vertices = np.asarray(shape["vertices"], dtype=np.float64)
    faces = np.asarray(shape["faces"], dtype=np.int64)
    if vertices.ndim != 2 or vertices.shape[1] != 3:
        raise ValueError(f"{name}: vertices must have shape (V, 3), got {vertices.shape}")
    if faces.ndim != 2 or faces.shape[1] != 3:
        raise ValueError(f"{name}: faces must have shape (F, 3), got {faces.shape}")
    if faces.size and (faces.min() < 0 or faces.max() >= vertices.shape[0]):
        raise ValueError(f"{name}: face indices must be in [0, {vertices.shape[0]})")
    return _Piece(vertices, np.full(faces.shape[0], 3), faces.ravel())


_PIECES = {"sphere": _sphere_piece, "disk": _disk_piece, "quad": _quad_piece, "mesh": _mesh_piece}


def scene_surfaces(native_scene: Mapping[str, Any], *, resolution: int = 48) -> pv.PolyData:
    """The shapes of a native scene dictionary as one mesh, for display.

    Spheres and annular disks are tessellated (``resolution`` points around), quads are one quad,
    meshes are copied. Faces keep the front side of the renderer: outward on spheres, along
    ``normal`` on disks, along ``edge_u × edge_v`` on quads, counter-clockwise on meshes.

    Parameters
    ----------
    native_scene : dict
        A scene as described in ``docs/native-scene.md``; only ``shapes`` (and the material
        ``type`` names of ``materials``) are used.
    resolution : int, keyword-only
        Points around spheres and disks.

    Returns
    -------
    pyvista.PolyData
        All shapes, with cell data ``material`` int32 (material index), ``shape`` int32 (index into
        ``shapes``) and ``sheet`` int8 (+1 / −1); field data ``material_type`` (str, one per material)
        when the scene lists materials. Empty when there are no shapes.

    Raises
    ------
    ValueError
        An unknown shape type or bad shape geometry, naming the shape.

    Examples
    --------
    >>> scene = {"shapes": [
    ...     {"type": "quad", "corner": [0, 0, 0], "edge_u": [1, 0, 0], "edge_v": [0, 1, 0], "material": 1},
    ...     {"type": "mesh", "vertices": [[0, 0, 1], [1, 0, 1], [0, 1, 1]], "faces": [[0, 1, 2]], "material": 0},
    ... ]}
    >>> s = scene_surfaces(scene)
    >>> s.n_cells, s.cell_data["material"].tolist(), s.cell_data["shape"].tolist()
    (2, [1, 0], [0, 1])
    """
    resolution = _check_resolution(resolution)
    shapes: Sequence[Mapping[str, Any]] = native_scene.get("shapes", []) or []
    points, sizes, conn, material, index, sheet = [], [], [], [], [], []
    offset = 0
    for i, shape in enumerate(shapes):
        kind = shape.get("type")
        name = f"shapes[{i}] ({kind})"
        if kind not in _PIECES:
            raise ValueError(f"shapes[{i}]: unknown shape type {kind!r}; known: {', '.join(sorted(_PIECES))}")
        try:
            piece = _PIECES[kind](name, shape, resolution)
        except KeyError as exc:
            raise ValueError(f"{name}: missing key {exc.args[0]!r}") from None
        n_faces = piece.sizes.shape[0]
        points.append(piece.points)
        sizes.append(piece.sizes)
        conn.append(piece.conn + offset)
        material.append(np.full(n_faces, shape.get("material", -1), dtype=np.int32))
        index.append(np.full(n_faces, i, dtype=np.int32))
        sheet.append(np.full(n_faces, shape.get("sheet", SCHEMA["shapes"][kind]["sheet"]), dtype=np.int8))
        offset += piece.points.shape[0]

    mesh = _Piece(np.concatenate(points) if points else np.zeros((0, 3)), _join(sizes), _join(conn)).polydata()
    mesh.cell_data["material"] = np.concatenate(material) if material else np.zeros(0, dtype=np.int32)
    mesh.cell_data["shape"] = np.concatenate(index) if index else np.zeros(0, dtype=np.int32)
    mesh.cell_data["sheet"] = np.concatenate(sheet) if sheet else np.zeros(0, dtype=np.int8)
    materials = native_scene.get("materials") or []
    if materials:
        mesh.field_data["material_type"] = [str(m.get("type", "")) for m in materials]
    return mesh


def scene_lights(native_scene: Mapping[str, Any]) -> pv.PolyData | None:
    """The point and spot lights of a native scene (``lights``) as points: they are never hit, so no surface
    shows them.

    Parameters
    ----------
    native_scene : dict
        A native scene (``docs/native-scene.md``).

    Returns
    -------
    pyvista.PolyData or None
        None without lights; else one vertex per light at its position, (N, 3) float64, with point arrays
        ``color`` (N, 3) and ``intensity`` (N,) (radiant intensity = intensity x color per steradian),
        ``spot`` (N,) uint8 (1: a spot light), ``direction`` (N, 3) (a spot's unit axis, zeros for a point
        light), ``angle`` (N,) (a spot's half-angle in degrees, 180 for a point light) and ``sheet`` (N,) int8.

    Examples
    --------
    >>> lights = scene_lights({"lights": [{"type": "spot", "position": [0, 0, 5], "direction": [0, 0, -2],
    ...                                     "intensity": 3.0, "angle": 30.0}]})
    >>> lights.n_points, lights.point_data["direction"].tolist(), lights.point_data["angle"].tolist()
    (1, [[0.0, 0.0, -1.0]], [30.0])
    """
    import pyvista as pv

    lights = list(native_scene.get("lights") or [])
    if not lights:
        return None
    n = len(lights)
    points = np.array([light["position"] for light in lights], dtype=np.float64).reshape(n, 3)
    mesh = pv.PolyData(points)  # (one vertex cell per point)
    mesh.point_data["color"] = np.array([light.get("color", [1.0, 1.0, 1.0]) for light in lights], dtype=np.float64)
    mesh.point_data["intensity"] = np.array([float(light["intensity"]) for light in lights])
    spot = np.array([light.get("type") == "spot" for light in lights])
    mesh.point_data["spot"] = spot.astype(np.uint8)
    axis = np.zeros((n, 3))
    for i, light in enumerate(lights):
        if spot[i]:
            d = np.asarray(light["direction"], dtype=np.float64)
            axis[i] = d / np.linalg.norm(d)
    mesh.point_data["direction"] = axis
    spot_angle = float(SCHEMA["lights"]["spot"]["angle"])  # (the native default)
    mesh.point_data["angle"] = np.array([float(light.get("angle", spot_angle)) if is_spot else 180.0
                                         for light, is_spot in zip(lights, spot)])  # fmt: skip
    mesh.point_data["sheet"] = np.array([int(light.get("sheet", 1)) for light in lights], dtype=np.int8)
    return mesh


def camera_frustum(camera: Mapping[str, Any], *, length: float | None = None) -> pv.PolyData:
    """Wire-frame pyramid showing a native scene camera: where it is, where it looks, what it sees.

    The apex is the camera position; the base is the image rectangle at distance ``length`` along
    the view direction, ``2 length tan(fov / 2)`` high (``fov`` is vertical) with the image's aspect
    ratio; a small triangle on the top edge marks image-up.

    Parameters
    ----------
    camera : dict
        A native scene camera (``docs/native-scene.md``): ``position``, ``look_at`` (3-vectors), ``width``
        and ``height`` (pixels), optional ``up``, ``fov`` (degrees, vertical) and ``sheet``.
    length : float, optional, keyword-only
        Distance from the apex to the base; default the distance to ``look_at``.

    Returns
    -------
    pyvista.PolyData
        Points: apex, the base corners (bottom-left, bottom-right, top-right, top-left as seen by
        the camera) and the tip of the up marker, float64 (6, 3). Lines: the 4 edges from the apex,
        the closed base, the up marker. Field data ``fov``, ``width``, ``height``, ``sheet``.

    Examples
    --------
    >>> cam = {"position": [0, 0, 0], "look_at": [10, 0, 0], "up": [0, 0, 1], "fov": 90.0, "width": 200, "height": 100}
    >>> camera_frustum(cam).points[1:5].round(12).tolist()
    [[10.0, 20.0, -10.0], [10.0, -20.0, -10.0], [10.0, -20.0, 10.0], [10.0, 20.0, 10.0]]
    """
    import pyvista as pv

    camera = native_camera(camera)
    forward, right, true_up = camera_basis(camera)  # the renderer's (and checks up against the view)
    position = np.asarray(camera["position"], dtype=np.float64)
    distance = float(np.linalg.norm(np.subtract(camera["look_at"], position)))
    fov, width, height = camera["fov"], camera["width"], camera["height"]
    length = distance if length is None else float(length)
    if not (length > 0.0 and math.isfinite(length)):
        raise ValueError(f"length must be a positive finite distance, got {length!r}")

    half_h = length * math.tan(math.radians(fov) / 2.0)
    half_w = half_h * width / height
    centre = position + length * forward
    corners = [centre + sx * half_w * right + sy * half_h * true_up for sx, sy in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
    tip = centre + 1.4 * half_h * true_up
    points = np.stack([position, *corners, tip])
    lines = [2, 0, 1, 2, 0, 2, 2, 0, 3, 2, 0, 4, 5, 1, 2, 3, 4, 1, 3, 3, 5, 4]
    frustum = pv.PolyData(points, lines=np.asarray(lines, dtype=np.int64))
    frustum.field_data["fov"] = np.array([fov])
    frustum.field_data["width"] = np.array([width])
    frustum.field_data["height"] = np.array([height])
    frustum.field_data["sheet"] = np.array([camera["sheet"]])
    return frustum
