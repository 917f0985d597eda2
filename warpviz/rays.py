"""Results of :func:`warpviz.trace`: a bundle of null geodesics with their end states and, when
recorded, their polylines and per-point data."""

from __future__ import annotations

import enum
from dataclasses import dataclass, field

import numpy as np

from warpviz.metrics import Metric


class RayStatus(enum.IntEnum):
    """How a ray ended. ``RayBundle.status`` holds these codes as ``int8``."""

    ESCAPED = 0  #: left the escape sphere moving outward
    HIT = 1  #: hit a scene surface (renderer only)
    HORIZON = 2  #: crossed the event horizon (the path ends on it)
    MAX_STEPS = 3  #: ran out of its step budget
    INVARIANT_VIOLATION = 4  #: a conserved quantity drifted beyond ``max_drift``
    NAN = 5  #: numerical breakdown (non-finite state or step-size underflow)


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
        For each conserved quantity (``"H"``, ``"E"``, ``"Lz"``, ``"Q"``, ``"L2"`` as the metric has
        them) the largest relative drift along each ray, shape (N,) float64. ``"H"`` is the relative
        size of the Hamiltonian, which is 0 for an exact null geodesic.
    points : numpy.ndarray or None, shape (P, 3), float64
        All recorded points (``record=True``), ray after ray, in each point's sheet frame.
    offsets : numpy.ndarray or None, shape (N + 1,), int64
        Ray ``i`` owns ``points[offsets[i]:offsets[i + 1]]``.
    point_data : dict[str, numpy.ndarray]
        Per-point arrays of shape (P,): ``affine_param``, ``coord_time``, ``r`` (areal / Boyer–Lindquist
        radius), ``step_size``, ``hamiltonian_err``, ``<invariant>_drift`` for each invariant but H,
        ``log10_error`` (log10 of the largest of those errors), ``sheet`` (int8).
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
        """Largest relative drift of any conserved quantity per ray, shape (N,) float64."""
        return np.max(np.stack(list(self.invariant_drift.values())), axis=0)

    def __repr__(self) -> str:
        counts = ", ".join(f"{k}={v}" for k, v in self.counts().items())
        rec = f", {self.points.shape[0]} points" if self.points is not None else ""
        return f"RayBundle({len(self)} rays in {self.metric!r}, {self.stepper} tol={self.tol:g}: {counts}{rec})"
