"""Results of :func:`warpviz.trace`: a bundle of null geodesics with their end states and, when
recorded, their polylines and per-point data."""

from __future__ import annotations

import enum
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from warpviz.spacetime import Metric

if TYPE_CHECKING:  # pragma: no cover
    import pyvista as pv


class RayStatus(enum.IntEnum):
    """How a ray ended. ``RayBundle.status`` holds these codes as ``int8``."""

    ESCAPED = 0  #: left the escape sphere moving outward
    HIT = 1  #: hit a scene surface (renderer only)
    HORIZON = 2  #: crossed the event horizon (the path ends on it)
    MAX_STEPS = 3  #: ran out of its step budget
    INVARIANT_VIOLATION = 4  #: a conserved quantity's term-scaled drift exceeded ``max_drift``
    NAN = 5  #: numerical breakdown (non-finite state or step-size underflow)


#: Cell arrays :meth:`RayBundle.to_pyvista` always writes (``max_drift*`` besides).
_CELL_ARRAYS = ("ray_id", "status", "n_steps")


def recorded_point_data(columns: np.ndarray, names) -> dict[str, np.ndarray]:
    """Per-point arrays of recorded paths from the core's (C, P) column block.

    Parameters
    ----------
    columns : numpy.ndarray
        (C, P) float64, one row per name.
    names : sequence of str
        The C column names (``affine_param``, ..., ``<invariant>_drift``, ``redshift``, ``sheet``).

    Returns
    -------
    dict[str, numpy.ndarray]
        Each column as a (P,) array (``sheet`` as int8) plus ``log10_error``, the log10 of the largest of
        ``hamiltonian_err`` and the reported drifts at each point, and ``log10_error_scaled``, the same of
        ``hamiltonian_err`` and the term-scaled drifts: the digits the integration kept, which a quantity
        small against its own terms (Lz or Q of a ray near the axis or the equator) does not inflate.
    """
    point_data = {name: columns[i].astype(np.int8) if name == "sheet" else columns[i] for i, name in enumerate(names)}
    for out, suffix in (("log10_error", "_drift"), ("log10_error_scaled", "_drift_scaled")):
        errors = [point_data["hamiltonian_err"]] + [point_data[n] for n in names if n.endswith(suffix)]
        point_data[out] = np.log10(np.maximum(np.max(np.stack(errors), axis=0), 1e-300))
    return point_data


@dataclass(frozen=True, eq=False)
class RayBundle:
    """N traced rays.

    Attributes
    ----------
    metric : Metric
        The spacetime the rays were traced in.
    stepper : str
        ``"rk4"``, ``"dopri5"`` or ``"dop853"``.
    tol : float
        Local error tolerance used.
    status : numpy.ndarray, shape (N,), int8
        :class:`RayStatus` code of each ray.
    final_positions : numpy.ndarray, shape (N, 3), float64
        End point in the Cartesian frame of its sheet: on the escape sphere for escaped rays, on the
        horizon for captured ones.
    final_directions : numpy.ndarray, shape (N, 3), float64
        Unit vectors: the asymptotic direction of motion for escaped rays (accurate to ``tol``), the
        coordinate direction of motion otherwise.
    final_sheets : numpy.ndarray, shape (N,), int8
        Sheet of the end point (+1 ours, −1 the other side of an Ellis wormhole; always +1 otherwise).
    n_steps : numpy.ndarray, shape (N,), int64
        Accepted integration steps (0 for flat space).
    invariant_drift : dict[str, numpy.ndarray]
        For each conserved quantity X (``"H"``, ``"E"``, ``"Lz"``, ``"Q"``, ``"L2"`` as the metric has
        them) the reported drift: the largest over the monitored points and the end state, shape (N,)
        float64, of the **relative** drift |X − X₀| / |X₀| where X₀ is not negligible against its terms
        (|X₀| ≥ 1e-6 S, S below, as far as the ray has come), and of the term-scaled drift of
        :attr:`invariant_drift_scaled` from where X₀ is negligible on (Q of an equatorial ray, Lz of a ray
        that starts near the axis and leaves it).
        ``"H"`` (0 on an exact null geodesic) is always term-scaled: |2H| over the size of its terms.
    invariant_drift_scaled : dict[str, numpy.ndarray]
        The **term-scaled** drift |X − X₀| / S, shape (N,) float64, S the largest size along the ray of
        the terms X is computed from (e.g. Σ|x p_y| + |y p_x| for Lz; ~r² p⊥² for Carter's Q far out),
        at least a floor of the metric (|E| for E; M |E| for Lz; M² E² for Q and L²). It measures what
        rounding and cancellation let be conserved; ``max_drift`` is checked against it. For a distant
        ray's Q it is smaller than the relative drift by S / |Q₀| (10³–10⁵ on a Kerr image).
        Empty for bundles recorded by the renderer before this was reported.
    points : numpy.ndarray or None, shape (P, 3), float64
        All recorded points (``record=True``), ray after ray, in each point's sheet frame.
    offsets : numpy.ndarray or None, shape (N + 1,), int64
        Ray ``i`` owns ``points[offsets[i]:offsets[i + 1]]``.
    point_data : dict[str, numpy.ndarray]
        Per-point arrays of shape (P,): ``affine_param``, ``coord_time``, ``r`` (areal / Boyer–Lindquist
        radius), ``step_size``, ``hamiltonian_err`` (term-scaled), ``<invariant>_drift`` for each invariant
        but H (the reported drift there, by :attr:`invariant_drift`'s rule), ``<invariant>_drift_scaled``
        (term-scaled), ``log10_error`` (log10 of the largest of ``hamiltonian_err`` and the reported
        drifts), ``log10_error_scaled`` (the same of the term-scaled drifts: the digits kept, what the
        teaching view colours by), ``redshift`` (photon frequency seen by
        the local static observer, or ZAMO, over the one at the ray's start; 0 on a horizon),
        ``sheet`` (int8).
    ray_data : dict[str, numpy.ndarray]
        Extra per-ray arrays of shape (N,), any numeric dtype, e.g. ``pixel_x``, ``pixel_y``,
        ``sample``, ``bounce`` for paths recorded by the renderer. Empty for :func:`warpviz.trace`.
        They become cell data in :meth:`to_pyvista`.
    initial_states, final_states : numpy.ndarray or None, shape (N, 8), float64
        Chart state (t, x, y, z, p_t, p_x, p_y, p_z) with covariant momentum at the start and at the end
        of each ray (:func:`warpviz.trace`; None for the renderer's recorded paths).
    """

    metric: Metric
    stepper: str
    tol: float
    status: np.ndarray
    final_positions: np.ndarray
    final_directions: np.ndarray
    final_sheets: np.ndarray
    n_steps: np.ndarray
    invariant_drift: dict[str, np.ndarray]
    points: np.ndarray | None = None
    offsets: np.ndarray | None = None
    point_data: dict[str, np.ndarray] = field(default_factory=dict)
    ray_data: dict[str, np.ndarray] = field(default_factory=dict)
    invariant_drift_scaled: dict[str, np.ndarray] = field(default_factory=dict)
    initial_states: np.ndarray | None = None
    final_states: np.ndarray | None = None

    def __post_init__(self) -> None:
        n = len(self)
        checked = {}
        for name, values in self.ray_data.items():
            name, values = str(name), np.asarray(values)
            if values.shape != (n,):
                raise ValueError(f"ray_data[{name!r}] must have shape ({n},) (one value per ray), got {values.shape}")
            if name in _CELL_ARRAYS or name.startswith("max_drift"):
                raise ValueError(f"ray_data[{name!r}]: the name is taken by a built-in per-ray array")
            checked[name] = values
        object.__setattr__(self, "ray_data", checked)

    def __len__(self) -> int:
        return int(self.status.shape[0])

    @property
    def recorded(self) -> bool:
        return self.points is not None

    @property
    def status_names(self) -> np.ndarray:
        """Status of each ray as lower-case names, shape (N,), dtype str."""
        names = np.array([s.name.lower() for s in RayStatus])
        return names[self.status]

    def counts(self) -> dict[str, int]:
        """Number of rays per status name (statuses that occur only)."""
        codes, n = np.unique(self.status, return_counts=True)
        return {RayStatus(int(c)).name.lower(): int(k) for c, k in zip(codes, n)}

    def ray_points(self, i: int) -> np.ndarray:
        """Recorded polyline of ray ``i``, shape (n_i, 3) float64 (a view)."""
        if self.points is None:
            raise ValueError("no paths were recorded: trace with record=True")
        return self.points[self.offsets[i] : self.offsets[i + 1]]

    def ray_point_data(self, i: int) -> dict[str, np.ndarray]:
        """Per-point data of ray ``i``, each array of shape (n_i,)."""
        if self.points is None:
            raise ValueError("no paths were recorded: trace with record=True")
        s = slice(self.offsets[i], self.offsets[i + 1])
        return {k: v[s] for k, v in self.point_data.items()}

    def max_drift(self) -> np.ndarray:
        """Largest reported drift (:attr:`invariant_drift`) of any conserved quantity per ray, shape (N,) float64."""
        return np.max(np.stack(list(self.invariant_drift.values())), axis=0)

    def to_pyvista(self) -> pv.PolyData:
        """The recorded paths as VTK polylines with all their data.

        Returns
        -------
        pyvista.PolyData
            ``points`` (P, 3) float64 and one polyline cell per ray, in ray order, so cell ``i`` is
            ray ``i`` (a ray with 0 recorded points is an empty cell, one with 1 point a one-point
            polyline). Attached data:

            * point data: every array of :attr:`point_data`, shape (P,), dtypes kept
              (``affine_param``, ``coord_time``, ``r``, ``step_size``, ``hamiltonian_err``,
              ``<invariant>_drift``, ``log10_error``, ``redshift`` float64; ``sheet`` int8).
            * cell data, shape (N,): ``ray_id`` int64, ``status`` int8 (:class:`RayStatus` codes),
              ``n_steps`` int64, ``max_drift_<invariant>`` float64 for each entry of
              :attr:`invariant_drift` (e.g. ``max_drift_H``, ``max_drift_E``), ``max_drift``
              float64 (largest of those), and every array of :attr:`ray_data`.
            * field data: ``metric`` (str, 1), ``metric_params`` float64 (k,) with
              ``metric_param_names`` str (k,), ``stepper`` (str, 1), ``tol`` float64 (1,),
              ``warpviz_version`` (str, 1), ``status_legend`` str (6,): the status name of each
              code.

        Raises
        ------
        ValueError
            The bundle has no paths: it was traced without ``record=True``.

        Examples
        --------
        >>> import warpviz as wv
        >>> rays = wv.trace(wv.Schwarzschild(mass=1.0), [-50.0, 0, 0], [[1, 0, 0], [1, 0.2, 0]], record=True)
        >>> poly = rays.to_pyvista()
        >>> poly.n_cells, poly.cell_data["status"].tolist(), poly.field_data["metric"].tolist()
        (2, [2, 0], ['schwarzschild'])
        """
        import pyvista as pv

        from warpviz import __version__

        if self.points is None or self.offsets is None:
            raise ValueError("this RayBundle has no recorded paths: trace with record=True to get paths")
        n = len(self)
        points = np.ascontiguousarray(self.points, dtype=np.float64)
        offsets = np.asarray(self.offsets, dtype=np.int64)
        n_points = points.shape[0]
        if offsets.shape != (n + 1,) or offsets[0] != 0 or offsets[-1] != n_points or np.any(np.diff(offsets) < 0):
            raise ValueError(f"offsets must rise from 0 to {n_points} in {n + 1} entries, got {offsets.shape[0]}")

        # VTK's legacy cell layout: for each ray its point count, then its point ids.
        cells = np.empty(n + n_points, dtype=np.int64)
        heads = offsets[:-1] + np.arange(n)
        is_id = np.ones(cells.shape[0], dtype=bool)
        is_id[heads] = False
        cells[heads] = np.diff(offsets)
        cells[is_id] = np.arange(n_points)

        poly = pv.PolyData()
        poly.points = points
        poly.lines = cells
        for name, values in self.point_data.items():
            poly.point_data[name] = np.asarray(values)

        poly.cell_data["ray_id"] = np.arange(n, dtype=np.int64)
        poly.cell_data["status"] = np.asarray(self.status, dtype=np.int8)
        poly.cell_data["n_steps"] = np.asarray(self.n_steps, dtype=np.int64)
        for name, values in self.invariant_drift.items():
            poly.cell_data[f"max_drift_{name}"] = np.asarray(values, dtype=np.float64)
        for name, values in self.invariant_drift_scaled.items():
            poly.cell_data[f"max_drift_scaled_{name}"] = np.asarray(values, dtype=np.float64)
        if self.invariant_drift:
            poly.cell_data["max_drift"] = self.max_drift()
        for name, values in self.ray_data.items():
            poly.cell_data[name] = values

        fields = poly.field_data
        fields["metric"] = [self.metric.name]
        fields["metric_params"] = np.asarray(self.metric.param_values, dtype=np.float64)
        fields["metric_param_names"] = np.asarray(list(self.metric.params), dtype=str)
        fields["stepper"] = [self.stepper]
        fields["tol"] = np.array([self.tol], dtype=np.float64)
        fields["warpviz_version"] = [__version__]
        fields["status_legend"] = [s.name.lower() for s in RayStatus]
        return poly

    def save(self, path: str | os.PathLike) -> Path:
        """Write :meth:`to_pyvista` to a ``.vtp`` file atomically (see :func:`warpviz.write_vtp`).

        Parameters
        ----------
        path : str or os.PathLike
            Destination ending in ``.vtp``; an existing file is replaced.

        Returns
        -------
        pathlib.Path
            ``path``.

        Raises
        ------
        ValueError
            Wrong suffix ("expected a .vtp file"), or no recorded paths (trace with ``record=True``).
        """
        from warpviz.io import write_vtp

        return write_vtp(self.to_pyvista(), path)

    def __repr__(self) -> str:
        counts = ", ".join(f"{k}={v}" for k, v in self.counts().items())
        rec = f", {self.points.shape[0]} points" if self.points is not None else ""
        return f"RayBundle({len(self)} rays in {self.metric!r}, {self.stepper} tol={self.tol:g}: {counts}{rec})"
