"""The teaching view's image gets better while you look: successive renders of the preview, averaged.

:class:`ProgressivePreview` is the logic (no threads, no VTK): each :meth:`~ProgressivePreview.step`
renders one more pass of the scene at the preview size with a fresh seed, as many samples per pixel as
it has so far (so the count doubles), and returns the running mean tonemapped. Passes with different
seeds are independent estimates of the same image, so their sample-weighted mean is an estimate with
all their samples: its noise falls as 1 / sqrt(samples).

:class:`BackgroundRefiner` runs the passes on a worker thread (the renderer releases the GIL, so the
window stays responsive) and hands the newest image to whoever asks (:meth:`~BackgroundRefiner.take`,
which the window calls from a VTK timer); :meth:`~BackgroundRefiner.stop` ends the pass under way within
its next progress poll (about 20 ms).

Examples
--------
>>> import warpviz as wv
>>> from warpviz.viewer.progressive import ProgressivePreview
>>> scene = {"metric": {"name": "schwarzschild", "params": [1.0]},
...          "camera": {"position": [0.0, -20.0, 0.0], "look_at": [0.0, 0.0, 0.0], "fov": 40.0,
...                     "width": 8, "height": 6},
...          "textures": [], "materials": [], "shapes": [], "environment": {"color": [1.0, 1.0, 1.0]}}
>>> preview = ProgressivePreview(scene, width=8, height=6, spp=1, max_spp=4)
>>> preview.step().shape, preview.samples
((6, 8, 3), 1)
>>> [(preview.step() is not None, preview.samples) for _ in range(3)]
[(True, 2), (True, 4), (False, 4)]
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import Any

import numpy as np

from warpviz.limits import MAX_SEED
from warpviz.render import tonemap

__all__ = ["DEFAULT_MAX_SPP", "DEFAULT_REFRESH_MS", "BackgroundRefiner", "ProgressivePreview"]

#: Samples per pixel at which the view's image stops refining (a 96-pixel preview reaches it in
#: seconds to a minute; the noise is then 1/8 of a 4-spp preview's).
DEFAULT_MAX_SPP = 256

#: How often (milliseconds) the window looks for a better image.
DEFAULT_REFRESH_MS = 250


class ProgressivePreview:
    """Successive passes of a scene at one size, averaged into a better and better image.

    Parameters
    ----------
    scene : str, os.PathLike, warpviz.scene.Scene or dict
        What :func:`warpviz.render` accepts.
    width, height : int, keyword-only
        The image size (the view's preview size).
    spp : int, keyword-only
        Samples per pixel of the first pass (or of ``first``).
    seed : int, keyword-only
        Seed of the first pass; pass ``k`` uses ``seed + k`` (modulo the seed limit).
    max_spp : int, keyword-only
        Total samples per pixel after which :meth:`step` returns None.
    first : numpy.ndarray, optional, keyword-only
        (height, width, 3) float linear radiance of a render already made with ``spp`` samples and
        ``seed`` (the view's preview): it becomes the first pass.
    threads : int, optional, keyword-only
        Passed to :func:`warpviz.render`.

    Attributes
    ----------
    samples : int
        Samples per pixel averaged so far.
    passes : int
        Renders averaged so far.
    rgb : numpy.ndarray or None
        (height, width, 3) float64 running mean of the linear radiance, None before the first pass.
    """

    def __init__(self, scene, *, width: int, height: int, spp: int = 4, seed: int = 0,
                 max_spp: int = DEFAULT_MAX_SPP, first: np.ndarray | None = None, threads: int | None = None):  # fmt: skip
        width, height, spp, max_spp = int(width), int(height), int(spp), int(max_spp)
        if min(width, height) < 1:
            raise ValueError(f"ProgressivePreview: width and height must be >= 1, got {width}x{height}")
        if spp < 1 or max_spp < spp:
            raise ValueError(f"ProgressivePreview: need 1 <= spp <= max_spp, got spp={spp}, max_spp={max_spp}")
        self.scene = scene
        self.width, self.height = width, height
        self.first_spp, self.max_spp = spp, max_spp
        self.seed = int(seed)
        self.threads = threads
        self.samples = 0
        self.passes = 0
        self.rgb: np.ndarray | None = None
        if first is not None:
            first = np.asarray(first, dtype=np.float64)
            if first.shape != (height, width, 3):
                raise ValueError(f"ProgressivePreview: first must have shape ({height}, {width}, 3), got {first.shape}")
            self._absorb(first, spp)

    @property
    def done(self) -> bool:
        """Whether :attr:`max_spp` samples are averaged."""
        return self.samples >= self.max_spp

    def _absorb(self, rgb: np.ndarray, spp: int) -> None:
        total = self.samples + spp
        self.rgb = rgb.astype(np.float64) if self.rgb is None else self.rgb + (rgb - self.rgb) * (spp / total)
        self.samples = total
        self.passes += 1

    def next_spp(self) -> int:
        """Samples per pixel of the next pass: as many as so far (the first pass: ``spp``), at most what is
        left to :attr:`max_spp`; 0 when done."""
        return max(0, min(self.samples or self.first_spp, self.max_spp - self.samples))

    def image(self) -> np.ndarray | None:
        """The running mean tonemapped: (height, width, 3) uint8 sRGB, or None before the first pass."""
        return None if self.rgb is None else tonemap(self.rgb)

    def step(self, *, progress: Callable[[int, int], Any] | None = None) -> np.ndarray | None:
        """Render the next pass and average it in.

        Parameters
        ----------
        progress : callable, optional, keyword-only
            Passed to :func:`warpviz.render` (raising ``KeyboardInterrupt`` in it abandons the pass).

        Returns
        -------
        numpy.ndarray or None
            The better image, (height, width, 3) uint8; None when done or when the pass was stopped (it
            is then not averaged in).
        """
        from warpviz.render import render

        n = self.next_spp()
        if n == 0:
            return None
        seed = (self.seed + self.passes) % MAX_SEED
        extra = {} if self.threads is None else {"threads": self.threads}
        img = render(self.scene, width=self.width, height=self.height, spp=n, seed=seed, aovs=[],
                     progress=progress, **extra)  # fmt: skip
        if not img.completed:
            return None
        self._absorb(np.asarray(img.rgb), n)
        return self.image()


class BackgroundRefiner:
    """Runs a :class:`ProgressivePreview`'s passes on a daemon thread, keeping the newest image.

    Parameters
    ----------
    preview : ProgressivePreview

    Attributes
    ----------
    error : BaseException or None
        What stopped the worker, if it failed (the window then keeps its last image).
    """

    def __init__(self, preview: ProgressivePreview):
        self.preview = preview
        self.error: BaseException | None = None
        self._lock = threading.Lock()
        self._latest: tuple[int, np.ndarray] | None = None
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="warpviz-progressive-preview", daemon=True)

    def start(self) -> BackgroundRefiner:
        """Start the worker (once); returns self."""
        if not self._thread.is_alive() and not self._stop.is_set():
            self._thread.start()
        return self

    def _poll(self, done: int, total: int) -> None:
        if self._stop.is_set():
            raise KeyboardInterrupt

    def _run(self) -> None:
        try:
            while not self._stop.is_set():
                image = self.preview.step(progress=self._poll)
                if image is None:
                    break
                with self._lock:
                    self._latest = (self.preview.samples, image)
        except BaseException as exc:  # noqa: BLE001 - reported through .error, the window keeps going
            self.error = exc

    def take(self) -> tuple[int, np.ndarray] | None:
        """The newest image not yet taken, as (samples per pixel, (H, W, 3) uint8), or None."""
        with self._lock:
            latest, self._latest = self._latest, None
        return latest

    @property
    def running(self) -> bool:
        """Whether the worker is still rendering."""
        return self._thread.is_alive()

    def stop(self, timeout: float = 5.0) -> None:
        """Ask the worker to stop and wait for it (at most ``timeout`` seconds)."""
        self._stop.set()
        if self._thread.is_alive():
            self._thread.join(timeout)
