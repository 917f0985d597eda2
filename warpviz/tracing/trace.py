"""Tracing null geodesics: :func:`trace`."""

from __future__ import annotations

import numbers
from typing import Any

import numpy as np

from warpviz._native import core, registered_metrics
from warpviz.limits import tolerance_problem
from warpviz.options import STEPPER_NAMES
from warpviz.spacetime import Metric, metric_from_dict
from warpviz.tracing.rays import RayBundle, recorded_point_data

STEPPERS = STEPPER_NAMES  # the render options' table names them (warpviz/options.py)


def default_max_drift(tol: float) -> float:
    """Largest term-scaled drift of a conserved quantity (``RayBundle.invariant_drift_scaled``) a ray
    may show at a monitored point before it is marked ``invariant_violation``: 1e3 times the local
    tolerance, but never below 1e-6 (the one place this default lives; ``trace`` and ``render`` use
    it)."""
    return max(1e-6, 1e3 * float(tol))


def _rows(name: str, value: Any) -> np.ndarray:
    raw = np.asarray(value)
    if raw.dtype.kind not in "biuf":
        raise TypeError(f"{name} must be real numbers, got {raw.dtype} values"
                        + (" (the imaginary parts would be lost)" if raw.dtype.kind == "c" else ""))  # fmt: skip
    arr = raw.astype(np.float64)
    if arr.ndim == 1:
        arr = arr[None, :]
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise ValueError(f"{name} must have shape (3,) or (N, 3), got {np.shape(value)}")
    bad = np.flatnonzero(~np.isfinite(arr).all(axis=1))
    if bad.size:
        raise ValueError(f"{name}[{bad[0]}] is not finite: {arr[bad[0]].tolist()}")
    return arr


def _number(name: str, value: Any, *, lo: float, hi: float = np.inf, integer: bool = False) -> float:
    kind = numbers.Integral if integer else numbers.Real
    if isinstance(value, bool) or not isinstance(value, kind):
        raise TypeError(f"{name} must be {'an integer' if integer else 'a real number'}, got {value!r}")
    if not (lo < value < hi) or not np.isfinite(value):
        raise ValueError(f"{name} must be in ({lo:g}, {hi:g}), got {value!r}")
    return value


def trace(
    metric: Metric | dict,
    origins: Any,
    directions: Any,
    *,
    tol: float = 1e-9,
    stepper: str = "dopri5",
    max_steps: int = 100_000,
    escape_radius: float = 1e3,
    record: bool = False,
    sheets: Any = None,
    max_drift: float | None = None,
    rk4_step: float = 1.0,
    threads: int = 0,
    batch: bool = True,
    monitor_every: int | None = None,
) -> RayBundle:
    """Trace null geodesics (light rays) forward from ``origins`` along ``directions``.

    Rays are integrated from the Hamiltonian H = ½ g^{μν} p_μ p_ν in Cartesian Kerr–Schild
    coordinates (Schwarzschild, Kerr) or the Ellis wormhole's regular chart, until each ray escapes,
    crosses the horizon, runs out of steps or breaks a conservation law. Flat space takes no steps.
    The computation runs in C++ on ``threads`` threads with the GIL released; results do not depend
    on the thread count. Ctrl-C interrupts it.

    Parameters
    ----------
    metric : Metric or dict
        The spacetime, e.g. ``Kerr(mass=1, spin=0.9)`` or ``{"name": "kerr", "mass": 1, "spin": 0.9}``.
    origins : array_like, shape (N, 3) or (3,), float
        Start points (Cartesian, units of M). One origin is shared by all directions.
    directions : array_like, shape (N, 3) or (3,), float
        Directions of the rays as seen by the local static observer at each origin (the
        zero-angular-momentum observer inside Kerr's ergoregion), in the frame closest to the x, y, z
        axes. Normalised here; must be non-zero.
    tol : float, keyword-only
        Local relative + absolute error per step for ``dopri5``/``dop853``. For ``rk4`` it sets how
        far the step is halved near the mass: no step exceeds ``tol ** 0.25`` times the distance to
        the centre. Default 1e-9. Usable: [1e-15, 0.1] for ``dopri5``/``dop853``, [1e-12, 0.1] for
        ``rk4`` (:data:`warpviz.limits.TOLERANCE_RANGES`); outside, a ValueError.
    stepper : {"dopri5", "dop853", "rk4"}, keyword-only
        ``dopri5`` (default, adaptive with dense output), ``dop853`` (high-accuracy reference, with a
        7th-order dense output), ``rk4`` (the seed paper's fixed step with halving: the benchmark baseline).
    max_steps : int, keyword-only
        Step attempts allowed per ray before it ends with status ``max_steps``.
    escape_radius : float, keyword-only
        Rays moving outward beyond this radius have escaped; their end point is on this sphere and
        their direction is extrapolated to infinity.
    record : bool, keyword-only
        Keep every ray's polyline and per-point data (``points``, ``offsets``, ``point_data``).
    sheets : array_like of {+1, -1}, shape (N,), optional, keyword-only
        Ellis wormhole only: the sheet of each origin (default +1, ours).
    max_drift : float, optional, keyword-only
        Largest term-scaled drift |X − X₀| / S of a conserved quantity X (S: the size of the terms X
        is computed from, :attr:`RayBundle.invariant_drift_scaled`) before a step is retried smaller
        and, failing that, the ray is marked ``invariant_violation``; for H, |2H| over the size of its
        terms. A ray's relative drift |X − X₀| / |X₀| may exceed it by S / |X₀| (Carter's Q far out).
        Default ``max(1e-6, 1e3 * tol)``.
    rk4_step : float, keyword-only
        Fixed far-field step of ``rk4`` in units of M, halved in powers of two near the mass
        (default 1.0).
    threads : int, keyword-only
        Worker threads; 0 uses every core.
    batch : bool, keyword-only
        Step rays together in SIMD batches of eight, each with its own step size (about 3x faster,
        every stepper). Each ray's result is bit-identical to tracing it alone (``batch=False``),
        which is kept for comparison and benchmarks.
    monitor_every : int, optional, keyword-only
        Accepted steps between evaluations of the conserved quantities other than H, whose error is
        checked every step at no cost; crossings and ray ends are always checked. Default: every
        step when recording or at ``tol < 1e-8``, otherwise every 4th.

    Returns
    -------
    RayBundle
        Status, end states and conserved-quantity drift of every ray (and paths if recorded).

    Raises
    ------
    ValueError
        Wrong shapes, non-finite or zero directions, origins inside a horizon or throat, bad options;
        the message names the offending row or option.

    Examples
    --------
    >>> import numpy as np, warpviz as wv
    >>> rays = wv.trace(wv.Schwarzschild(mass=1.0), [-1000.0, 0, 0], [[1, 0, 0], [1, 0.01, 0]])
    >>> rays.status_names.tolist()
    ['horizon', 'escaped']
    """
    if isinstance(metric, dict):
        metric = metric_from_dict(metric)
    if not isinstance(metric, Metric):
        raise TypeError(f"metric must be a warpviz Metric (e.g. wv.Kerr(mass=1, spin=0.5)), got {metric!r}")
    if stepper not in STEPPERS:
        raise ValueError(f"unknown stepper {stepper!r}; choose one of {', '.join(STEPPERS)}")
    tol = float(_number("tol", tol, lo=0.0, hi=1.0))
    problem = tolerance_problem(stepper, tol)
    if problem:
        raise ValueError(problem)
    max_steps = int(_number("max_steps", max_steps, lo=0, hi=2**62, integer=True))
    escape_radius = float(_number("escape_radius", escape_radius, lo=0.0))
    threads = int(_number("threads", threads, lo=-1, hi=4096, integer=True))
    max_drift = default_max_drift(tol) if max_drift is None else float(_number("max_drift", max_drift, lo=0.0))
    rk4_step = float(_number("rk4_step", rk4_step, lo=0.0))
    if monitor_every is not None:
        monitor_every = int(_number("monitor_every", monitor_every, lo=0, hi=2**30, integer=True))

    origins = _rows("origins", origins)
    directions = _rows("directions", directions)
    if origins.shape[0] == 1 and directions.shape[0] > 1:
        origins = np.broadcast_to(origins, directions.shape)
    elif directions.shape[0] == 1 and origins.shape[0] > 1:
        directions = np.broadcast_to(directions, origins.shape)
    if origins.shape != directions.shape:
        raise ValueError(f"origins {origins.shape} and directions {directions.shape} must have the same number of rows")
    scale = np.max(np.abs(directions), axis=1)
    bad = np.flatnonzero(~(scale > 0.0))
    if bad.size:
        raise ValueError(f"directions[{bad[0]}] has zero length")
    # Rows whose squared length overflows (1e308) or underflows (5e-324) are first scaled by their largest
    # component, so they keep their direction; the others are divided by their length as they always were.
    with np.errstate(over="ignore", under="ignore"):
        norms = np.linalg.norm(directions, axis=1)
    extreme = ~(np.isfinite(norms) & (norms > 1e-150))
    if extreme.any():
        directions = directions.copy()
        directions[extreme] /= scale[extreme, None]
        norms[extreme] = np.linalg.norm(directions[extreme], axis=1)
    directions = np.ascontiguousarray(directions / norms[:, None])
    origins = np.ascontiguousarray(origins)
    n = origins.shape[0]

    if sheets is None:
        sheets_arr = np.ones(n, dtype=np.int32)
    else:
        sheets_arr = np.asarray(sheets)
        if sheets_arr.ndim == 0:
            sheets_arr = np.full(n, sheets_arr)
        if sheets_arr.shape != (n,):
            raise ValueError(f"sheets must have shape ({n},), got {sheets_arr.shape}")
        bad = np.flatnonzero((sheets_arr != 1) & (sheets_arr != -1))
        if bad.size:
            raise ValueError(f"sheets[{bad[0]}] must be +1 or -1, got {sheets_arr[bad[0]]!r}")
        if metric.sheets < 2 and np.any(sheets_arr == -1):
            many = [e["class_name"] for e in registered_metrics() if e["sheets"] > 1]
            raise ValueError(f"sheets: {type(metric).__name__} has a single sheet; only {' and '.join(many)} "
                             f"{'has' if len(many) == 1 else 'have'} sheet -1")  # fmt: skip
        sheets_arr = np.ascontiguousarray(sheets_arr, dtype=np.int32)

    problem = core.origin_problems(metric.name, metric.param_values, origins, sheets_arr)
    if problem is not None:
        row, why = problem
        raise ValueError(f"origins[{row}] = {origins[row].tolist()} {why}")

    raw = core.trace(
        metric.name, metric.param_values, origins, directions, sheets_arr, tol, stepper, max_steps,
        escape_radius, max_drift, rk4_step, bool(record), threads, bool(batch),
        monitor_every or 0,
    )  # fmt: skip
    drift = {k: np.asarray(v) for k, v in raw["invariant_drift"].items()}
    points = offsets = None
    point_data: dict[str, np.ndarray] = {}
    if record:
        points, offsets, cols = raw["points"], raw["offsets"], raw["columns"]
        point_data = recorded_point_data(cols, raw["column_names"])
    return RayBundle(
        metric=metric,
        stepper=stepper,
        tol=tol,
        status=raw["status"],
        final_positions=raw["final_positions"],
        final_directions=raw["final_directions"],
        final_sheets=raw["final_sheets"].astype(np.int8),
        n_steps=raw["n_steps"],
        invariant_drift=drift,
        invariant_drift_scaled={k: np.asarray(v) for k, v in raw["invariant_drift_scaled"].items()},
        initial_states=raw["initial_states"],
        final_states=raw["final_states"],
        points=points,
        offsets=offsets,
        point_data=point_data,
    )
