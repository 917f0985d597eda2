"""Helpers shared by the benchmark scripts: machine description, CPU timing, CSV and plot output, the
equal-error interpolation of work-precision curves, the far observer's image plane (through the
renderer's pinhole camera, :mod:`warpviz.scene.camera`), a converged reference from two halves with its own
noise (:class:`Reference`), and the options that render references on a Dask cluster.

Timings are CPU seconds of this process (``time.process_time``, all threads summed), so a rate is per
core by construction and is not inflated when other processes share the machine. Wall-clock seconds
are recorded beside them.
"""

from __future__ import annotations

import csv
import math
import os
import platform
import subprocess
import time
from collections.abc import Callable, Iterable, Iterator, Sequence
from contextlib import ExitStack, contextmanager
from pathlib import Path
from typing import Any

import numpy as np

from warpviz.scene.camera import pinhole_directions

#: Default output folder of the benchmark scripts.
RESULTS = Path(__file__).resolve().parent / "results"


def cpu_model() -> str:
    """The CPU model name from ``/proc/cpuinfo`` (falls back to :func:`platform.processor`).

    Returns
    -------
    str
        E.g. ``"AMD EPYC"``.
    """
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def machine_line(*, threads: int) -> str:
    """One line describing the machine and the thread count of a run.

    Parameters
    ----------
    threads : int, keyword-only
        Worker threads the benchmark asks for (0 = every core).

    Returns
    -------
    str
        CPU model, logical cores, threads, load average, git version of the checkout.
    """
    try:
        load = "load average {:.1f} {:.1f} {:.1f}".format(*os.getloadavg())
    except OSError:
        load = "load average unknown"
    return f"{cpu_model()}, {os.cpu_count()} logical cores, threads={threads}, {load}, source {source_version()}"


def source_version() -> str:
    """``git describe --always --dirty`` of the checkout the benchmarks live in, or "unknown"."""
    try:
        out = subprocess.run(["git", "describe", "--always", "--dirty"], cwd=Path(__file__).resolve().parent,
                             capture_output=True, text=True, timeout=10, check=True)  # fmt: skip
    except (OSError, subprocess.SubprocessError):
        return "unknown"
    return out.stdout.strip() or "unknown"


def timed(fn: Callable[[], Any]) -> tuple[Any, float, float]:
    """Call ``fn()`` once and time it.

    Parameters
    ----------
    fn : callable
        No arguments.

    Returns
    -------
    result : object
        What ``fn`` returned.
    cpu_seconds : float
        Process CPU time of the call (every thread summed).
    wall_seconds : float
        Wall-clock time of the call.
    """
    c0, w0 = time.process_time(), time.perf_counter()
    result = fn()
    return result, time.process_time() - c0, time.perf_counter() - w0


def write_csv(path: Path, rows: Sequence[dict]) -> Path:
    """Write ``rows`` (dicts) as CSV; the columns are the union of their keys in first-seen order.

    Parameters
    ----------
    path : pathlib.Path
        Output file; its folder is created.
    rows : sequence of dict
        One dict per row; missing keys are written as empty cells.

    Returns
    -------
    pathlib.Path
        ``path``.
    """
    columns: list[str] = []
    for row in rows:
        columns += [k for k in row if k not in columns]
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open("w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=columns)
        writer.writeheader()
        for row in rows:
            writer.writerow({k: _cell(v) for k, v in row.items()})
    return path


def _cell(value: Any) -> Any:
    if isinstance(value, float):
        return "" if math.isnan(value) else f"{value:.6g}"
    return value


def pareto_front(times: Iterable[float], errors: Iterable[float]) -> tuple[np.ndarray, np.ndarray]:
    """The runs no other run beats in both time and error, sorted by increasing time.

    Parameters
    ----------
    times, errors : iterable of float
        Cost and error of each run (positive).

    Returns
    -------
    times, errors : numpy.ndarray
        The front: times increasing, errors strictly decreasing.
    """
    pts = sorted((t, e) for t, e in zip(times, errors) if t > 0 and e > 0 and math.isfinite(t) and math.isfinite(e))
    front: list[tuple[float, float]] = []
    for t, e in pts:
        if not front or e < front[-1][1]:
            front.append((t, e))
    arr = np.array(front, dtype=float).reshape(-1, 2)
    return arr[:, 0], arr[:, 1]


def time_at_error(times: Iterable[float], errors: Iterable[float], target: float) -> float:
    """Cost at which a method reaches ``target`` error, interpolated log-log on its Pareto front.

    Parameters
    ----------
    times, errors : iterable of float
        The method's runs.
    target : float
        Error to reach.

    Returns
    -------
    float
        Interpolated time, or NaN when ``target`` lies outside the front's error range (no extrapolation).
    """
    t, e = pareto_front(times, errors)
    if len(t) == 0 or not (target > 0) or target > e[0] or target < e[-1]:
        return math.nan
    if len(t) == 1:
        return float(t[0])
    # errors decrease along the front: interpolate log t against -log e (increasing)
    return float(np.exp(np.interp(-np.log(target), -np.log(e), np.log(t))))


def pyplot():
    """matplotlib.pyplot with the non-interactive Agg backend, or None (with a message) if missing."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib is not installed: no plots written (pip install matplotlib)")
        return None
    return plt


def pinhole_grid(position, *, size: int, half_width: float, look_at=(0.0, 0.0, 0.0), up=(0.0, 0.0, 1.0),
                 equal_angles: bool = False) -> np.ndarray:
    """Unit directions of a square grid of rays through the image plane of a pinhole camera.

    The camera is the renderer's (:func:`warpviz.scene.camera.pinhole_directions`: the same basis, the
    same pixel-to-direction map): at ``position``, looking at ``look_at`` with ``up`` towards the top of
    the picture, its vertical field of view ``2 atan(half_width / distance)`` so that the picture spans
    ``+-half_width`` at ``look_at``. The grid has ``size`` points across and up, corners included: the
    pixel corners of a ``(size - 1)``-pixel square image.

    Parameters
    ----------
    position : array_like, shape (3,)
        Where the camera is (the rays' common origin).
    size : int, keyword-only
        Grid points per side, >= 2.
    half_width : float, keyword-only
        Half the side of the picture at ``look_at``.
    look_at, up : array_like, shape (3,), keyword-only
        View target and up hint (default the origin and +z).
    equal_angles : bool, keyword-only
        Space the grid points evenly in angle from the view axis (tangents of evenly spaced angles)
        instead of evenly across the picture.

    Returns
    -------
    numpy.ndarray, shape (size * size, 3), float64
        Ray ``i * size + j`` goes through grid point ``j`` from the left and ``i`` from the bottom.
    """
    if size < 2:
        raise ValueError(f"size must be at least 2, got {size}")
    distance = float(np.linalg.norm(np.subtract(look_at, position)))
    tan_half = half_width / distance
    n = size - 1
    camera = {"position": list(position), "look_at": list(look_at), "up": list(up),
              "fov": math.degrees(2.0 * math.atan(tan_half)), "width": n, "height": n}  # fmt: skip
    t = np.linspace(-1.0, 1.0, size)  # across the picture: -1 at the left (bottom) edge, +1 at the right (top)
    if equal_angles:
        t = np.tan(t * math.atan(tan_half)) / tan_half
    x, y = np.meshgrid(0.5 * n * (1.0 + t), 0.5 * n * (1.0 - t))  # pixel coordinates: x right, y down
    return pinhole_directions(camera, np.column_stack([x.ravel(), y.ravel()]), jitter=(0.0, 0.0))


def seeded_errors(render: Callable[[int], Any], ref: Reference, off, seeds: int) -> dict:
    """A benchmark row's error fields for ``render(seed)`` (an Image) over seeds 1 .. ``seeds`` against ``ref``:
    mean, smallest and largest relative MSE over every pixel, the mean over the ``off`` pixels ((H, W) bool, those
    that see no light directly), the mean wall seconds, and the efficiencies 1 / (MSE x seconds)."""
    errs, offs, secs = [], [], []
    for s in range(seeds):
        t0 = time.perf_counter()
        img = render(1 + s)
        secs.append(time.perf_counter() - t0)
        errs.append(ref.rel_mse(img.rgb)[0])
        offs.append(ref.rel_mse(img.rgb, off)[0])
    mse, mse_off, seconds = float(np.mean(errs)), float(np.mean(offs)), float(np.mean(secs))
    return {"rel_mse_mean": mse, "rel_mse_min": float(np.min(errs)), "rel_mse_max": float(np.max(errs)),
            "rel_mse_off_lights": mse_off, "seconds_mean": seconds, "efficiency": 1.0 / (mse * seconds),
            "efficiency_off_lights": 1.0 / (mse_off * seconds)}  # fmt: skip


def over_baseline(rows: Sequence[dict], base: dict, name: str) -> None:
    """Adds to each of ``rows`` its MSE and efficiency over ``base``'s (a row of :func:`seeded_errors`), over
    every pixel and off the lights: ``mse_over_NAME``, ``efficiency_over_NAME``, ``off_lights_..._over_NAME``."""
    for r in rows:
        r[f"mse_over_{name}"] = r["rel_mse_mean"] / base["rel_mse_mean"]
        r[f"efficiency_over_{name}"] = r["efficiency"] / base["efficiency"]
        r[f"off_lights_mse_over_{name}"] = r["rel_mse_off_lights"] / base["rel_mse_off_lights"]
        r[f"off_lights_efficiency_over_{name}"] = r["efficiency_off_lights"] / base["efficiency_off_lights"]


#: Render options of a converged reference: the path tracer alone. A scene's caustics by photons (the lit rooms
#: ask for 0.3 per pixel) are biased at any finite count, so a reference leaves them out and a photon render's
#: bias counts in its error.
UNBIASED = {"photons": 0, "photons_per_pixel": 0.0}


class Reference:
    """The mean of two independent renders and what their difference says about its own noise.

    Parameters
    ----------
    a, b : numpy.ndarray, shape (H, W, 3)
        The two halves (independent seeds, equal samples).
    spp : int
        Samples per pixel of the smaller half.
    """

    def __init__(self, a: np.ndarray, b: np.ndarray, spp: int):
        a, b = np.asarray(a, np.float64), np.asarray(b, np.float64)
        self.image = 0.5 * (a + b)
        self.scale = float(np.mean(self.image)) ** 2
        # (a - b)^2 / 4 estimates, pixel by pixel, the squared error of the mean (a + b) / 2
        self.noise_map = (a - b) ** 2 / 4.0
        self.noise = float(np.mean(self.noise_map)) / self.scale
        self.spp = spp

    def rel_mse(self, image: np.ndarray, mask: np.ndarray | None = None) -> tuple[float, float]:
        """The relative MSE of ``image`` and its standard error, over every pixel or those of ``mask``.

        The squared error against the reference, less the reference's own squared error estimated from the
        halves, pixel by pixel; summed over pixels and channels and divided by the squared mean of the
        reference. It is unbiased however noisy the reference (the image and the halves are independent);
        the standard error (of the per-pixel terms' mean) says how far the reference's noise still blurs it.

        Parameters
        ----------
        image : numpy.ndarray, shape (H, W, 3)
        mask : numpy.ndarray of bool, shape (H, W), optional
            Only these pixels, and the squared mean of the reference over them.

        Returns
        -------
        (float, float)
            The estimate (slightly below 0 possible when the image is as good as the reference) and its
            standard error.
        """
        d = (np.asarray(image, np.float64) - self.image) ** 2 - self.noise_map
        scale = self.scale
        if mask is not None:
            d, scale = d[mask], float(np.mean(self.image[mask])) ** 2
        d = d / scale
        return float(np.mean(d)), float(np.std(d) / math.sqrt(d.size))


def add_cluster_options(parser, *, what: str = "the converged references") -> None:
    """``--workers N``, ``--cluster ADDRESS`` and ``--tile PX``: render ``what`` on a Dask cluster.

    A benchmark's converged references are its long part (hours at classroom size); on a cluster they are
    the same images bit for bit (each pass's tiles are tasks, :mod:`warpviz.render.distributed`), so the
    results do not depend on where they were rendered. The timed runs stay on this machine unless a script
    says otherwise: they measure it.

    Parameters
    ----------
    parser : argparse.ArgumentParser
    what : str, optional
        What the options send to the cluster, for the help text.
    """
    group = parser.add_argument_group("Dask cluster", f"render {what} on a Dask cluster "
                                      '(pip install "warpviz[dask]"; bit-identical to a local render)')  # fmt: skip
    group.add_argument("--workers", type=int, default=None, metavar="N",
                       help="a local Dask cluster of N single-threaded worker processes")  # fmt: skip
    group.add_argument("--cluster", default=None, metavar="ADDRESS",
                       help="the running Dask scheduler at ADDRESS, e.g. tcp://10.0.0.5:8786")  # fmt: skip
    group.add_argument("--tile", type=int, default=None, metavar="PX",
                       help="with --workers or --cluster: tile side in pixels (default 128)")  # fmt: skip


@contextmanager
def cluster_render_options(args) -> Iterator[dict]:
    """The :func:`warpviz.render` keywords that send a render through the cluster ``args`` names.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed with :func:`add_cluster_options`.

    Yields
    ------
    dict
        ``{}`` without ``--workers`` or ``--cluster`` (render locally, as the script would), else
        ``client``, ``tile`` (where given) and ``threads = 1`` (one thread per task: the workers are the
        cores). Merge it last, ``{"threads": 0, **options}``. The cluster is closed on exit.

    Raises
    ------
    SystemExit
        Both ``--workers`` and ``--cluster``, ``--tile`` without either, or a cluster that cannot be
        started or reached (the message says why).
    """
    if args.workers is None and args.cluster is None:
        if args.tile is not None:
            raise SystemExit("--tile is the tile size on a Dask cluster: give --workers N or --cluster ADDRESS")
        yield {}
        return
    from warpviz.render.distributed import cluster_client

    with ExitStack() as stack:
        try:
            client = stack.enter_context(cluster_client(workers=args.workers, address=args.cluster))
        except (ImportError, ValueError) as exc:
            raise SystemExit(f"cannot use the Dask cluster: {exc}") from None
        print(f"Dask cluster: {len(client.nthreads())} workers, dashboard {client.dashboard_link}", flush=True)
        yield {"client": client, "threads": 1, **({"tile": args.tile} if args.tile is not None else {})}
