"""Rendering on a Dask cluster: each pass's tiles are tasks, and the image is the local one, bit for bit.

A pass (:mod:`warpviz.render.passes`) renders samples ``[N, N + n)`` of every pixel. With a
``dask.distributed`` client it is split into tiles (crop windows, ``tile`` pixels square, in rows from the
top left); each tile's pass is one task that continues that tile's film from its previous pass, so a
tile's film stays on the worker that holds it and only small summaries (samples, noise sums, statistics,
recorded paths) come back after each pass. The pass schedule, the time budget, the noise target and
Ctrl-C are :func:`~warpviz.render.passes.run_passes`', exactly as for a local render. At the end the tiles
are gathered and placed into the image's film in tile order.

A pixel's samples depend only on (seed, pixel, sample index) and windows that tile the image hold exactly
its pixels, so the image is bit-identical to the local render of the same samples per pixel for any
worker count, tile size or thread count (``tests/test_distributed.py``). The noise estimate is summed
over tiles (its last bits may differ from the local sum; only a noise-target stop can notice). Recorded
paths are the same segments, grouped by tile within each pass.

The scene travels with the tasks: a native scene holds its meshes and images as arrays (loaded on the
client), so workers read no files; it is sent once to each worker that needs it. A worker that is lost
has its tasks run again elsewhere, from the lineage of the tiles' films (the same samples, the same
bits); Ctrl-C cancels the running pass and keeps the finished ones, like a local render.

Examples
--------
>>> tile_windows((0, 0, 300, 200), 128)
[(0, 0, 128, 128), (128, 0, 128, 128), (256, 0, 44, 128), (0, 128, 128, 72), (128, 128, 128, 72), (256, 128, 44, 72)]
"""

from __future__ import annotations

import math
import time
import uuid
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any

import numpy as np

from warpviz._native import core
from warpviz.render.passes import PASS_SAMPLES, SAMPLE_COUNTS, add_stats, concat_rays

__all__ = ["DEFAULT_TILE", "LOOKAHEAD", "TileFilms", "TiledPasses", "check_workers", "cluster_client", "default_tile",
           "tile_windows"]

#: Tile side in pixels: 128 gives a 640x480 frame 20 tasks a pass and a 1920x1080 one 135.
DEFAULT_TILE = 128

#: Passes queued behind the running one when the passes are known in advance (no time budget or noise target).
LOOKAHEAD = 2


def default_tile(size: tuple[int, int], *, slots: int, photons: bool) -> int:
    """The tile side of a render on a cluster that names none: :data:`DEFAULT_TILE`; with caustics by photons,
    the smallest side that cuts the window into at most one tile per task slot (every tile traces the whole
    image's photon passes, so tiles beyond the slots would only trace them again; at 640 x 480 on two slots the
    128-pixel tiles traced each pass 20 times).

    Parameters
    ----------
    size : tuple of int
        The window's (width, height) in pixels.
    slots : int, keyword-only
        Tasks the cluster runs at once (its workers' threads).
    photons : bool, keyword-only
        Whether the render traces photon passes.

    Examples
    --------
    >>> default_tile((640, 480), slots=2, photons=False), default_tile((640, 480), slots=2, photons=True)
    (128, 480)
    >>> len(tile_windows((0, 0, 1920, 1080), default_tile((1920, 1080), slots=16, photons=True)))
    15
    """
    if not photons:
        return DEFAULT_TILE
    w, h = size
    slots = max(1, int(slots))
    best = max(w, h)
    for cols in range(1, slots + 1):  # a grid of cols x rows <= slots tiles
        rows = slots // cols
        best = min(best, max(math.ceil(w / cols), math.ceil(h / rows)))
    return max(DEFAULT_TILE, best)


def tile_windows(window: tuple[int, int, int, int], tile: int) -> list[tuple[int, int, int, int]]:
    """The tiles of a window, row by row from its top left.

    Parameters
    ----------
    window : tuple of int
        ``(x0, y0, width, height)`` in image pixels.
    tile : int
        Tile side in pixels (the last tile of a row or column is cut to the window).

    Returns
    -------
    list of tuple of int
        ``(x, y, width, height)`` of each tile.
    """
    x0, y0, w, h = (int(v) for v in window)
    if isinstance(tile, bool) or not isinstance(tile, (int, np.integer)) or tile < 1:
        raise ValueError(f"tile must be a positive number of pixels, got {tile!r}")
    tile = int(tile)
    return [(x, y, min(tile, x0 + w - x), min(tile, y0 + h - y))
            for y in range(y0, y0 + h, tile) for x in range(x0, x0 + w, tile)]  # fmt: skip


# --------------------------------------------------------------------------------------------------
# on the workers


def _tile_pass(native: dict, options: dict, tile: tuple, state: dict | None, extra: dict, metric=None) -> dict:
    """One pass of one tile (runs on a worker): the core continues the tile's film ``state``. ``metric``
    (the scene's, pickled with the task) makes sure the worker's core has it: a metric from its line
    element is rebuilt from its definition there (its plugin from the shared cache, or compiled)."""
    if metric is not None:
        metric.prepare(stepper=options["stepper"])
    x, y, w, h = tile
    opts = {**options, **extra, "crop": [x, y, w, h], "progress": None,
            "film": None if state is None else state["film"],
            "pixel_classes": None if state is None else state["pixel_classes"],
            "photon_aim_marks": None if state is None else state.get("photon_aim")}  # fmt: skip
    record = options.get("record_pixels")
    if record is not None:
        inside = (record[:, 0] >= x) & (record[:, 0] < x + w) & (record[:, 1] >= y) & (record[:, 1] < y + h)
        opts["record_pixels"] = np.ascontiguousarray(record[inside]) if inside.any() else None
    raw = core.render(native, opts)
    return {"film": raw["film"], "pixel_classes": raw["pixel_classes"], "photon_aim": raw.get("photon_aim"),
            "completed": bool(raw["completed"]),
            "stats": raw["stats"], "rays": raw.get("rays"), "noise_parts": tuple(core.film_noise_parts(raw["film"])),
            "samples": int(raw["film"]["samples"].sum())}  # fmt: skip


def _summary(result: dict) -> dict:
    """What the client needs of a tile's pass: all but its film."""
    return {k: v for k, v in result.items() if k not in ("film", "pixel_classes", "photon_aim")}


def _worker_facts() -> dict:
    """This process's warpviz: its installed version and the core's SIMD kernel."""
    from importlib.metadata import version

    from warpviz._native import build_info

    return {"version": version("warpviz"), "simd": build_info()["simd"]}


# --------------------------------------------------------------------------------------------------
# on the client


@dataclass(frozen=True)
class TileFilms:
    """The film of an image whose tiles live on a cluster: one future per tile (None: not rendered).

    Attributes
    ----------
    tiles : tuple of tuple of int
        ``(x, y, width, height)`` of each tile.
    futures : tuple
        A ``distributed.Future`` of each tile's state (its film and edge and detail pixels), or None.
    samples_total : int
        Samples in all the tiles' films.
    window : tuple of int
        ``(x0, y0, width, height)`` the tiles cover.
    """

    tiles: tuple
    futures: tuple
    samples_total: int
    window: tuple

    def gather(self, client) -> dict | None:
        """The whole window's film, the core's dict (tiles not rendered hold zero samples); None if no tile
        was rendered."""
        have = [i for i, f in enumerate(self.futures) if f is not None]
        if not have:
            return None
        films = dict(zip(have, (r["film"] for r in client.gather([self.futures[i] for i in have]))))
        first = films[have[0]]
        x0, y0, w, h = self.window
        out: dict[str, Any] = {"x0": x0, "y0": y0}
        for key, value in first.items():
            if key in ("x0", "y0"):
                continue
            out[key] = None if value is None else np.zeros((h, w, *value.shape[2:]), dtype=value.dtype)
        for i, (x, y, tw, th) in enumerate(self.tiles):
            if i not in films:
                continue
            for key, value in films[i].items():
                if key not in ("x0", "y0") and value is not None:
                    out[key][y - y0:y - y0 + th, x - x0:x - x0 + tw] = value
        return out


def _noise(parts: list[tuple[float, float, int]]) -> float:
    """The noise estimate from the tiles' sums (film/film.h: noise, the one formula)."""
    return float(core.noise_from_parts(sum(p[0] for p in parts), sum(p[1] for p in parts),
                                       sum(int(p[2]) for p in parts)))  # fmt: skip


class TiledPasses:
    """``render_range`` for :func:`~warpviz.render.passes.run_passes` on a Dask cluster.

    Parameters
    ----------
    client : distributed.Client
    native : dict
        The complete native scene (sent once to each worker that needs it).
    options : dict
        The core's options for the whole window (``crop``; ``threads``: threads per task).
    tile : int
        Tile side in pixels.
    metric : Metric, optional
        The scene's metric, sent with each task so that a worker can load one given by its line element.
    """

    def __init__(self, client, native: dict, options: dict, *, tile: int, metric=None):
        self.client = client
        self.metric = metric
        self.window = tuple(options["crop"])
        self.tiles = tuple(tile_windows(self.window, tile))
        self.options = {k: v for k, v in options.items() if k not in ("progress", "film", "pixel_classes")}
        # Scattered under a key of this render's own (hash=False): under the content's hash a second render of
        # the same scene reuses the key of the first, and when the first render's future is released as the
        # second scatters, the scheduler can forget the data the second's tasks need ("lost dependencies",
        # dask/distributed#8576: seen here as a rare failure of consecutive renders of one scene). On every worker
        # (broadcast): scattered to one, the scene died with it when that worker was killed and the tasks that
        # needed it were forgotten ("lost scattered data, which can't be recovered": a rare failure of the test
        # that kills a worker mid-render); a copy on each survives the loss of any of them.
        [self.native] = client.scatter([native], hash=False, broadcast=True)
        self.threads = sum(client.nthreads().values()) * max(1, int(options["threads"]))
        self._run = uuid.uuid4().hex[:8]
        self._pass = 0
        self._samples: dict[int, int] = {}  # each tile's samples after the last finished pass
        self._plan: list[tuple[int, int]] = []  # (sample_begin, spp) of the passes to come, if known
        self._ahead: dict[tuple[int, int], tuple[list, list]] = {}  # passes queued behind the running one
        #: The largest pass in samples over the image: PASS_SAMPLES per two threads (what a pass is locally).
        self.pass_samples = PASS_SAMPLES * max(1, self.threads // 2)

    def _start(self, film) -> tuple:
        """Each tile's state before the first pass here: none, or a resumed film split into tiles."""
        if film is None:
            return (None,) * len(self.tiles)
        if isinstance(film, TileFilms):
            return film.futures
        x0, y0 = self.window[:2]
        states = []
        for x, y, w, h in self.tiles:
            part = {k: (v if k in ("x0", "y0") or v is None else np.ascontiguousarray(v[y - y0:y - y0 + h, x - x0:x - x0 + w]))
                    for k, v in film.items()}  # fmt: skip
            part["x0"], part["y0"] = x, y
            self._samples[len(states)] = int(part["samples"].sum())
            states.append({"film": part, "pixel_classes": None})
        # Handed to the first pass's tasks as their arguments, not scattered: scattered, each tile's film lived on
        # one worker only, and a worker killed while its tiles' later passes still needed them lost them for good
        # ("lost scattered data"); in the tasks, the scheduler keeps them and can run a lost pass again from them.
        return tuple(states)

    def expect(self, begin: int, sizes: list[int]) -> None:
        """The passes :func:`~warpviz.render.passes.run_passes` will ask for from sample ``begin`` (a render
        without a time budget or noise target: :func:`~warpviz.render.passes.pass_plan`): the next
        :data:`LOOKAHEAD` of them are queued behind each pass, so no worker waits for a pass's last tile."""
        self._plan = []
        for n in sizes:
            self._plan.append((begin, int(n)))
            begin += int(n)

    def _submit(self, states, begin: int, n: int) -> tuple[list, list]:
        """One pass of every tile, continuing ``states``: the tiles' result and summary futures."""
        small = {"spp": n, "sample_begin": begin}
        self._pass += 1
        keys = [f"warpviz-{self._run}-pass{self._pass}-tile{i}" for i in range(len(self.tiles))]
        results = [self.client.submit(_tile_pass, self.native, self.options, t, s, small, metric=self.metric, key=k,
                                      pure=False)
                   for t, s, k in zip(self.tiles, states, keys)]  # fmt: skip
        summaries = [self.client.submit(_summary, r, key=k + "-summary", pure=False) for r, k in zip(results, keys)]
        return results, summaries

    def _queue_ahead(self, begin: int, n: int, results: list) -> None:
        if (begin, n) not in self._plan:
            return
        at = self._plan.index((begin, n))
        for nxt in self._plan[at + 1:at + 1 + LOOKAHEAD]:
            if nxt not in self._ahead:
                self._ahead[nxt] = self._submit(results, *nxt)
            results = self._ahead[nxt][0]

    def _drop_ahead(self) -> None:
        for results, summaries in self._ahead.values():
            self.client.cancel(results + summaries)
        self._ahead.clear()

    def __call__(self, extra: dict) -> dict:
        from distributed import as_completed

        progress = extra.get("progress")
        begin, n = int(extra["sample_begin"]), int(extra["spp"])
        if (begin, n) in self._ahead:  # queued behind the last pass, maybe running already
            results, summaries = self._ahead.pop((begin, n))
        else:
            self._drop_ahead()
            results, summaries = self._submit(self._start(extra.get("film")), begin, n)
        self._queue_ahead(begin, n, results)
        index = {s.key: i for i, s in enumerate(summaries)}
        got: dict[int, dict] = {}
        expected = n * self.window[2] * self.window[3]  # (edge and detail pixels add a few)
        t0 = time.perf_counter()
        try:
            for fut in as_completed(summaries):
                got[index[fut.key]] = fut.result()
                if progress is not None:
                    done = sum(r["samples"] for r in got.values())
                    added = done - sum(self._samples.get(i, 0) for i in got)
                    progress(added, max(added, expected))
        except KeyboardInterrupt:
            self._drop_ahead()
            self.client.cancel([r for i, r in enumerate(results) if i not in got] + summaries)
            partial = TileFilms(self.tiles, tuple(r if i in got else None for i, r in enumerate(results)),
                                sum(r["samples"] for r in got.values()), self.window)  # fmt: skip
            return {"completed": False, "film": partial if got else None, "stats": {}, "noise": math.nan}
        except BaseException:  # a task failed (its error is the render's): nothing of this render keeps running
            self._drop_ahead()
            self.client.cancel(results + summaries)
            raise
        ordered = [got[i] for i in range(len(self.tiles))]
        self._samples = {i: r["samples"] for i, r in enumerate(ordered)}
        stats: dict = {}
        for r in ordered:
            stats = add_stats(stats, r["stats"],
                              summed=(*SAMPLE_COUNTS, "edge_pixels", "bright_edge_pixels", "detail_pixels"))
        stats["seconds"] = time.perf_counter() - t0
        stats["threads"] = self.threads
        raw = {"completed": all(r["completed"] for r in ordered), "pixel_classes": None, "stats": stats,
               "film": TileFilms(self.tiles, tuple(results), sum(r["samples"] for r in ordered), self.window),
               "noise": _noise([r["noise_parts"] for r in ordered])}  # fmt: skip
        rays = [r["rays"] for r in ordered if r["rays"] is not None and len(r["rays"]["offsets"]) > 1]
        if self.options.get("record_pixels") is not None:
            raw["rays"] = concat_rays(rays) if rays else next(r["rays"] for r in ordered if r["rays"] is not None)
        return raw


def check_workers(client) -> None:
    """Every worker runs this warpviz (same version and SIMD kernel), else a ValueError naming the worker.

    Raises
    ------
    ValueError
        No workers, a worker without warpviz, or one whose warpviz differs.
    """
    mine = _worker_facts()
    if not client.nthreads():
        raise ValueError(f"the Dask cluster at {client.scheduler.address} has no workers")
    try:
        facts = client.run(_worker_facts)
    except ImportError as exc:  # pragma: no cover - a worker without warpviz
        raise ValueError(f"a Dask worker cannot import warpviz ({exc}); install the same warpviz on every worker") from None
    for worker, theirs in facts.items():
        if theirs != mine:
            raise ValueError(f"Dask worker {worker} runs warpviz {theirs['version']} ({theirs['simd']}), this client "
                             f"{mine['version']} ({mine['simd']}): install the same build on every worker")  # fmt: skip


@contextmanager
def cluster_client(*, workers: int | None = None, address: str | None = None):
    """A Dask client: a local cluster of ``workers`` processes (one thread each), or the scheduler at
    ``address``; closed (and the local cluster shut down) on exit.

    Raises
    ------
    ImportError
        ``dask.distributed`` is not installed (``pip install "warpviz[dask]"``).
    ValueError
        Both or neither of ``workers`` and ``address``, or a scheduler that cannot be reached.
    """
    if (workers is None) == (address is None):
        raise ValueError("give either workers (a local Dask cluster) or address (an existing scheduler)")
    try:
        from distributed import Client, LocalCluster
    except ImportError:
        raise ImportError('rendering on a Dask cluster needs dask.distributed: pip install "warpviz[dask]"') from None
    if workers is not None:
        if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
            raise ValueError(f"workers must be a positive integer, got {workers!r}")
        import logging

        # the workers' own warnings (a cancelled task after Ctrl-C) are not the user's business
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=":0",
                               silence_logs=logging.ERROR)  # fmt: skip
        client = Client(cluster)
    else:
        cluster = None
        try:
            client = Client(address, timeout="10s")
        except (OSError, TimeoutError) as exc:
            raise ValueError(f"cannot reach the Dask scheduler at {address!r}: {exc}") from None
    try:
        yield client
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
