"""Display meshes: the landmarks of each spacetime and the shapes of a native scene, as PyVista polydata.

Positions are in the frame rays are reported in (see the README): Cartesian Kerr–Schild x, y, z for
Schwarzschild and Kerr (spin along +z), the per-sheet areal-radius frame for the Ellis wormhole.
A Boyer–Lindquist sphere r = const is an oblate spheroid in Kerr–Schild coordinates,

    x² + y² = (r² + a²) sin²θ,    z = r cos θ,

so the Kerr horizon, ergosurface and photon region below are surfaces of revolution about z built
from their Boyer–Lindquist r(θ). All meshes are surfaces of quads and triangles for display (no texture
coordinates); closed ones have their normals pointing out of the volume they enclose.

Examples
--------
>>> import warpviz as wv
>>> sorted(wv.metric_features(wv.Kerr(mass=1.0, spin=0.9)))
['ergosphere', 'horizon', 'photon_sphere']
>>> wv.metric_features(wv.Minkowski())
{}
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from warpviz.metrics import Metric

if TYPE_CHECKING:  # pragma: no cover
    import pyvista as pv

__all__ = [
    "camera_frustum",
    "ellis_embedding",
    "ellis_embedding_points",
    "ergosphere_surface",
    "horizon_surface",
    "metric_features",
    "photon_sphere",
    "scene_surfaces",
    "throat_surface",
]



# --------------------------------------------------------------------------------------------------
# surfaces of revolution


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


def _theta(resolution: int) -> np.ndarray:
    return np.linspace(0.0, math.pi, resolution // 2 + 1)


def _check_resolution(resolution: int) -> int:
    if isinstance(resolution, bool) or not isinstance(resolution, (int, np.integer)) or resolution < 3:
        raise ValueError(f"resolution must be an integer >= 3, got {resolution!r}")
    return int(resolution)


def _kerr_schild_surface(r: np.ndarray, theta: np.ndarray, a: float, resolution: int) -> pv.PolyData:
    """The surface of revolution of the Boyer–Lindquist curve r(θ), θ from 0 to π, in Kerr–Schild
    Cartesian coordinates; point data ``r``."""
    rho = np.sqrt(r * r + a * a) * np.sin(theta)
    rho[[0, -1]] = 0.0  # exactly on the axis at the poles
    z = r * np.cos(theta)
    return _revolve(rho, z, n_phi=resolution).polydata(r=_per_point(r, rho, resolution))


def _per_point(values: np.ndarray, rho: np.ndarray, n_phi: int) -> np.ndarray:
    """Expand one value per meridian point to one per surface point (as laid out by ``_revolve``)."""
    return np.repeat(np.asarray(values, dtype=np.float64), np.where(rho == 0.0, 1, n_phi))


# --------------------------------------------------------------------------------------------------
# spacetime landmarks


def horizon_surface(metric: Metric, *, resolution: int = 64) -> pv.PolyData:
    """The outer event horizon.

    Schwarzschild: the sphere r = 2M. Kerr: r = r₊ = M + √(M² − a²), which in Kerr–Schild Cartesian
    coordinates is the oblate spheroid with semi-axes √(r₊² + a²) (x, y) and r₊ (z).

    Parameters
    ----------
    metric : Schwarzschild or Kerr
    resolution : int, keyword-only
        Points around the equator; the meridian has ``resolution // 2 + 1`` points.

    Returns
    -------
    pyvista.PolyData
        Closed surface, outward normals; point data ``r`` float64 (Boyer–Lindquist radius, = r₊).

    Raises
    ------
    ValueError
        The metric has no horizon.

    Examples
    --------
    >>> import warpviz as wv
    >>> h = horizon_surface(wv.Kerr(mass=1.0, spin=0.6))
    >>> [round(float(v), 12) for v in h.bounds[1::2]]   # x, y semi-axes sqrt(r+^2 + a^2) = sqrt(3.6); z: r+ = 1.8
    [1.897366596101, 1.897366596101, 1.8]
    """
    resolution = _check_resolution(resolution)
    marks = metric.landmarks
    if "horizon" not in marks:
        raise ValueError(f"{metric!r} has no horizon")
    theta = _theta(resolution)
    return _kerr_schild_surface(np.full_like(theta, marks["horizon"]), theta, marks.get("spin", 0.0), resolution)


def ergosphere_surface(metric: Metric, *, resolution: int = 64) -> pv.PolyData:
    """The outer boundary of Kerr's ergoregion (the static limit).

    Boyer–Lindquist r_E(θ) = M + √(M² − a² cos²θ), mapped to Kerr–Schild Cartesian coordinates:
    it touches the horizon at the poles (r_E = r₊) and reaches r_E = 2M on the equator, a
    cylindrical radius of √(4M² + a²).

    Parameters
    ----------
    metric : Kerr
    resolution : int, keyword-only
        Points around the equator; the meridian has ``resolution // 2 + 1`` points.

    Returns
    -------
    pyvista.PolyData
        Closed surface, outward normals; point data ``r`` float64 (Boyer–Lindquist r_E(θ)).

    Raises
    ------
    ValueError
        Not a Kerr metric (a non-rotating hole has no ergoregion: its static limit is the horizon).

    Examples
    --------
    >>> import warpviz as wv
    >>> e = ergosphere_surface(wv.Kerr(mass=1.0, spin=0.6))
    >>> round(float(e.points[:, 2].max()), 12), round(float(e.point_data["r"].max()), 12)
    (1.8, 2.0)
    """
    resolution = _check_resolution(resolution)
    marks = metric.landmarks
    if "ergosphere" not in marks:
        raise ValueError(f"{metric!r} has no ergosphere (only a rotating black hole does)")
    theta = _theta(resolution)
    m, a = marks["mass"], marks["spin"]
    r = m + np.sqrt(np.maximum(m * m - (a * np.cos(theta)) ** 2, 0.0))
    return _kerr_schild_surface(r, theta, a, resolution)


def _kerr_photon_region_cos2(m: float, a: float, r: np.ndarray) -> np.ndarray:
    """cos²θ of the turning points of the spherical photon orbit at Boyer–Lindquist radius r.

    The photon region is (2rΔ − (r − M)Σ)² ≤ 4a²r²Δ sin²θ, with Δ = r² − 2Mr + a² and
    Σ = r² + a²cos²θ. As a quadratic in w = cos²θ, divided by a², it reads αw² + βw + γ ≤ 0, and w
    runs up to its larger root, computed in the cancellation-free form −2γ / (β + √(β² − 4αγ)).
    """
    delta = r * r - 2.0 * m * r + a * a
    a_over = (r * r * (r - 3.0 * m) + 2.0 * a * a * r) / a  # (2rΔ − (r − M) r²) / a
    alpha = ((r - m) * a) ** 2
    beta = 4.0 * r * r * delta - 2.0 * a * a_over * (r - m)
    gamma = a_over**2 - 4.0 * r * r * delta
    w = -2.0 * gamma / (beta + np.sqrt(np.maximum(beta * beta - 4.0 * alpha * gamma, 0.0)))
    return np.clip(w, 0.0, 1.0)


def photon_sphere(metric: Metric, *, resolution: int = 64) -> pv.PolyData:
    """Where light can orbit: the photon sphere, or Kerr's photon region.

    Schwarzschild: the sphere r = 3M. Kerr: the boundary of the *photon region*, the set of
    Boyer–Lindquist (r, θ) through which spherical photon orbits pass. It is a shell between the
    prograde and retrograde equatorial circular orbits (``Kerr.photon_orbit_radii``) on the
    equator that narrows towards the axis, where its inner and outer walls meet at the radius of
    the polar orbit. The wall at Boyer–Lindquist r reaches up to the turning latitude of the
    spherical orbit of that radius. Drawn translucent, the shell shows why the shadow of a spinning
    hole is flattened on one side. For |a| ≤ 1e-12 M the sphere r = 3M is returned.

    Parameters
    ----------
    metric : Schwarzschild or Kerr
    resolution : int, keyword-only
        Points around the equator; each wall's meridian has about ``resolution // 2`` points.

    Returns
    -------
    pyvista.PolyData
        Closed surface (for Kerr, a closed shell of two walls touching on the axis) with normals
        pointing out of the region; point data ``r`` float64 (Boyer–Lindquist radius).

    Raises
    ------
    ValueError
        The metric has no photon orbits.

    Examples
    --------
    >>> import warpviz as wv
    >>> kerr = wv.Kerr(mass=1.0, spin=0.9)
    >>> shell = photon_sphere(kerr)
    >>> r = shell.point_data["r"]
    >>> bool(abs(r.min() - kerr.photon_orbit_radii[0]) < 1e-12), bool(abs(r.max() - kerr.photon_orbit_radii[1]) < 1e-12)
    (True, True)
    """
    resolution = _check_resolution(resolution)
    marks = metric.landmarks
    if "photon_sphere" in marks:
        theta = _theta(resolution)
        return _kerr_schild_surface(np.full_like(theta, marks["photon_sphere"]), theta, marks.get("spin", 0.0),
                                    resolution)  # fmt: skip
    if "photon_prograde" not in marks:
        raise ValueError(f"{metric!r} has no photon sphere")
    m, a = marks["mass"], marks["spin"]
    pro, retro, polar = marks["photon_prograde"], marks["photon_retrograde"], marks["photon_polar"]
    # sin² spacing: the wall leaves the equator like sqrt(r - r_orbit), so this samples it evenly
    t = np.sin(np.linspace(0.0, 0.5 * math.pi, max(resolution // 4, 2) + 1)) ** 2
    r_up = np.concatenate([pro + (polar - pro) * t, polar + (retro - polar) * t[1:]])
    cos2 = _kerr_photon_region_cos2(m, a, r_up)
    cos2[0] = cos2[-1] = 0.0
    cos2[t.shape[0] - 1] = 1.0  # the polar orbit reaches the axis
    # meridian loop: inner wall up from the equator to the north pole, outer wall down to the
    # equator, on to the south pole and back up the inner wall
    r_loop = np.concatenate([r_up, r_up[-2:0:-1]])
    cos_loop = np.concatenate([np.sqrt(cos2), -np.sqrt(cos2[-2:0:-1])])
    rho = np.sqrt((r_loop**2 + a * a) * (1.0 - cos_loop**2))
    rho[np.abs(cos_loop) == 1.0] = 0.0
    z = r_loop * cos_loop
    return _revolve(rho, z, n_phi=resolution, closed=True).polydata(r=_per_point(r_loop, rho, resolution))


def throat_surface(metric: Metric, *, resolution: int = 64) -> pv.PolyData:
    """The throat of an Ellis wormhole: the sphere of areal radius b₀ where the two sheets meet.

    Parameters
    ----------
    metric : EllisWormhole
    resolution : int, keyword-only
        Points around the equator; the meridian has ``resolution // 2 + 1`` points.

    Returns
    -------
    pyvista.PolyData
        Closed sphere of radius b₀, outward normals; point data ``r`` float64 (= b₀).

    Examples
    --------
    >>> import warpviz as wv
    >>> throat_surface(wv.EllisWormhole(throat=2.0)).bounds[1]
    2.0
    """
    resolution = _check_resolution(resolution)
    if "throat" not in metric.landmarks:
        raise ValueError(f"{metric!r} has no throat (only a wormhole does)")
    theta = _theta(resolution)
    return _kerr_schild_surface(np.full_like(theta, metric.landmarks["throat"]), theta, 0.0, resolution)


def ellis_embedding(metric: Metric, *, l_max: float | None = None, resolution: int = 64) -> pv.PolyData:
    """Embedding diagram of the Ellis wormhole's equatorial plane, both sheets.

    The slice t = const, θ = π/2 has dl² + (b₀² + l²) dφ²; it is the surface of revolution with
    ρ = √(b₀² + l²) and z = b₀ asinh(l / b₀) (a catenoid, ρ = b₀ cosh(z / b₀)) in Euclidean space.
    Our sheet (l > 0) is the upper half, the other sheet (l < 0) the lower one, the throat the
    waist at z = 0. Lengths along the meridians are true proper distances l.

    Parameters
    ----------
    metric : EllisWormhole
    l_max : float, optional, keyword-only
        Proper radial distance from the throat drawn on each sheet (default 10 b₀).
    resolution : int, keyword-only
        Points around the circles; ``resolution + 1`` meridian points (evenly spaced in l).

    Returns
    -------
    pyvista.PolyData
        Open surface with point data ``l`` float64 (signed proper distance), ``r`` float64 (areal
        radius ρ) and ``sheet`` int8 (+1 for l ≥ 0, −1 for l < 0).

    Examples
    --------
    >>> import numpy as np, warpviz as wv
    >>> emb = ellis_embedding(wv.EllisWormhole(throat=1.0), l_max=5.0)
    >>> sorted(set(emb.point_data["sheet"].tolist())), bool(np.isclose(emb.bounds[5], np.arcsinh(5.0), rtol=1e-14))
    ([-1, 1], True)
    """
    resolution = _check_resolution(resolution)
    if "throat" not in metric.landmarks:
        raise ValueError(f"{metric!r} is not an Ellis wormhole")
    b0 = metric.landmarks["throat"]
    l_max = 10.0 * b0 if l_max is None else float(l_max)
    if not (l_max > 0.0 and math.isfinite(l_max)):
        raise ValueError(f"l_max must be a positive finite length, got {l_max!r}")
    ell = np.linspace(l_max, -l_max, 2 * (resolution // 2) + 1)  # north (our sheet) to south
    rho = np.hypot(b0, ell)
    z = b0 * np.arcsinh(ell / b0)
    sheet = np.where(ell >= 0.0, 1, -1).astype(np.int8)
    return _revolve(rho, z, n_phi=resolution).polydata(
        l=_per_point(ell, rho, resolution), r=_per_point(rho, rho, resolution), sheet=np.repeat(sheet, resolution)
    )


def ellis_embedding_points(metric: Metric, points: Any, sheet: Any) -> np.ndarray:
    """Map positions on an Ellis wormhole onto its embedding diagram (:func:`ellis_embedding`).

    A point at areal radius R = |x| on sheet s has l = s √(R² − b₀²); it goes to the point of the
    diagram with that l at its azimuth φ = atan2(y, x), which lies exactly on the surface. Rays in
    the plane z = 0 are drawn faithfully; other rays are projected along their latitude (their
    distance from the throat and azimuth are kept). A ray through the throat crosses the waist from
    one sheet to the other.

    Parameters
    ----------
    metric : EllisWormhole
    points : array_like, shape (P, 3), float
        Positions in each point's sheet frame (as in ``RayBundle.points``).
    sheet : array_like, shape (P,), {+1, -1}
        Sheet of each point (``RayBundle.point_data["sheet"]``).

    Returns
    -------
    numpy.ndarray, shape (P, 3), float64
        Positions on the embedding surface.

    Examples
    --------
    >>> import warpviz as wv
    >>> ellis_embedding_points(wv.EllisWormhole(throat=1.0), [[0, 5.0, 0], [5.0, 0, 0]], [1, -1]).round(6).tolist()
    [[0.0, 5.0, 2.292432], [5.0, 0.0, -2.292432]]
    """
    if "throat" not in metric.landmarks:
        raise ValueError(f"{metric!r} is not an Ellis wormhole")
    points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    sheet = np.asarray(sheet).reshape(-1)
    if sheet.shape[0] != points.shape[0]:
        raise ValueError(f"sheet must have one entry per point ({points.shape[0]}), got {sheet.shape[0]}")
    if not np.all((sheet == 1) | (sheet == -1)):
        raise ValueError("sheet entries must be +1 or -1")
    b0 = metric.landmarks["throat"]
    radius = np.maximum(np.linalg.norm(points, axis=1), b0)
    ell = np.where(sheet > 0, 1.0, -1.0) * np.sqrt(radius * radius - b0 * b0)
    phi = np.arctan2(points[:, 1], points[:, 0])
    return np.column_stack([radius * np.cos(phi), radius * np.sin(phi), b0 * np.arcsinh(ell / b0)])


def metric_features(metric: Metric, *, resolution: int = 64) -> dict[str, pv.PolyData]:
    """Every landmark surface the metric has, by block name.

    Schwarzschild: ``horizon``, ``photon_sphere``. Kerr: ``horizon``, ``ergosphere`` (when spinning),
    ``photon_sphere`` (the photon region). Ellis: ``throat``, ``embedding``. Minkowski: none.

    Parameters
    ----------
    metric : Metric
    resolution : int, keyword-only
        Passed to each surface.

    Returns
    -------
    dict[str, pyvista.PolyData]

    Examples
    --------
    >>> import warpviz as wv
    >>> list(metric_features(wv.Schwarzschild(mass=1.0)))
    ['horizon', 'photon_sphere']
    """
    marks = metric.landmarks  # from the core's registry: what this spacetime has
    features = {}
    if "horizon" in marks:
        features["horizon"] = horizon_surface(metric, resolution=resolution)
    if "ergosphere" in marks:
        features["ergosphere"] = ergosphere_surface(metric, resolution=resolution)
    if "photon_sphere" in marks or "photon_prograde" in marks:
        features["photon_sphere"] = photon_sphere(metric, resolution=resolution)
    if "throat" in marks:
        features["throat"] = throat_surface(metric, resolution=resolution)
        features["embedding"] = ellis_embedding(metric, resolution=resolution)
    return features


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
    frame = _frame(_vector(name, "pole", shape.get("pole", (0, 0, 1))),
                   _vector(name, "meridian", shape.get("meridian", (1, 0, 0))))  # fmt: skip
    theta = _theta(resolution)
    rho = radius * np.sin(theta)
    rho[[0, -1]] = 0.0
    piece = _revolve(rho, radius * np.cos(theta), n_phi=resolution)
    return _Piece(center + piece.points @ frame, piece.sizes, piece.conn)


def _disk_piece(name: str, shape: Mapping[str, Any], resolution: int) -> _Piece:
    center = _vector(name, "center", shape["center"])
    r_in, r_out = float(shape.get("inner_radius", 0.0)), float(shape["outer_radius"])
    if not 0.0 <= r_in < r_out:
        raise ValueError(f"{name}: need 0 <= inner_radius < outer_radius, got {r_in!r}, {r_out!r}")
    frame = _frame(_vector(name, "normal", shape["normal"]),
                   _vector(name, "meridian", shape.get("meridian", (1, 0, 0))))  # fmt: skip
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
        sheet.append(np.full(n_faces, shape.get("sheet", 1), dtype=np.int8))
        offset += piece.points.shape[0]

    mesh = _Piece(np.concatenate(points) if points else np.zeros((0, 3)), _join(sizes), _join(conn)).polydata()
    mesh.cell_data["material"] = np.concatenate(material) if material else np.zeros(0, dtype=np.int32)
    mesh.cell_data["shape"] = np.concatenate(index) if index else np.zeros(0, dtype=np.int32)
    mesh.cell_data["sheet"] = np.concatenate(sheet) if sheet else np.zeros(0, dtype=np.int8)
    materials = native_scene.get("materials") or []
    if materials:
        mesh.field_data["material_type"] = [str(m.get("type", "")) for m in materials]
    return mesh


def camera_frustum(camera: Mapping[str, Any], *, length: float | None = None) -> pv.PolyData:
    """Wire-frame pyramid showing a native scene camera: where it is, where it looks, what it sees.

    The apex is the camera position; the base is the image rectangle at distance ``length`` along
    the view direction, ``2 length tan(fov / 2)`` high (``fov`` is vertical) with the image's aspect
    ratio; a small triangle on the top edge marks image-up.

    Parameters
    ----------
    camera : dict
        ``position``, ``look_at``, ``up`` (3-vectors), ``fov`` (degrees, vertical), ``width`` and
        ``height`` (pixels), optional ``sheet`` (see ``docs/native-scene.md``).
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

    position = _vector("camera", "position", camera["position"])
    forward = _vector("camera", "look_at", camera["look_at"]) - position
    distance = float(np.linalg.norm(forward))
    if distance == 0.0:
        raise ValueError("camera: look_at must differ from position")
    forward /= distance
    up = _vector("camera", "up", camera["up"])
    right = np.cross(forward, up)
    if np.linalg.norm(right) < 1e-12 * max(np.linalg.norm(up), 1e-300):
        raise ValueError("camera: up must not be parallel to the view direction")
    right /= np.linalg.norm(right)
    true_up = np.cross(right, forward)
    fov, width, height = float(camera["fov"]), int(camera["width"]), int(camera["height"])
    if not 0.0 < fov < 180.0:
        raise ValueError(f"camera: fov must be in (0, 180) degrees, got {fov!r}")
    if width <= 0 or height <= 0:
        raise ValueError(f"camera: width and height must be positive, got {width} x {height}")
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
    frustum.field_data["sheet"] = np.array([int(camera.get("sheet", 1))])
    return frustum
