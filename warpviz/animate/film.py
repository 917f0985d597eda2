"""Rendering a film: one render per camera of a path, frames kept on disk (resumable), then encoded.

Each frame is its own render of the scene with that frame's camera, to ``spp`` samples or a ``time_limit``,
with the seed :func:`frame_seed` (the scene's seed and the frame index): a frame never depends on the
others, on timing or on threads. Frames are written as ``frame_NNNNN.png`` (and ``.exr`` when the film is a
folder) into the frames folder with a ``film.json`` manifest of what they were made from; a rerun renders
only the missing frames, and refuses a folder made from anything else. A ``.mp4`` is encoded with imageio's
ffmpeg plugin (``pip install "warpviz[film]"``), a ``.gif`` with Pillow. See docs/films.md.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
from pathlib import Path
from typing import Callable

import numpy as np

from warpviz.io import atomic_write
from warpviz.limits import MAX_SEED
from warpviz.options import DEFAULT_OPTIONS
from warpviz.render.render import render as render_image
from warpviz.scene import Scene

__all__ = ["FILM_SUFFIXES", "FilmMismatch", "frame_seed", "frames_folder", "render_film"]

#: What a film may be written as: a video, an animated GIF, or (no suffix) a folder of frames.
FILM_SUFFIXES = (".mp4", ".gif")


class FilmMismatch(ValueError):
    """A frames folder that holds frames of another film (scene, path, size or samples differ)."""


def frame_seed(seed: int, index: int) -> int:
    """The seed of frame ``index`` of a film whose scene has ``seed``: both mixed by a SHA-256, so
    neighbouring frames' noise is unrelated, and below :data:`warpviz.limits.MAX_SEED`."""
    digest = hashlib.sha256(f"warpviz-film:{int(seed)}:{int(index)}".encode()).digest()
    return int.from_bytes(digest[:8], "little") % MAX_SEED


def frames_folder(output: Path) -> Path:
    """Where the frames of ``output`` are kept: the folder itself, or ``NAME_frames/`` beside a video."""
    output = Path(output)
    return output.with_name(output.stem + "_frames") if output.suffix.lower() in FILM_SUFFIXES else output


def _camera_scene(scene: Scene, camera: dict) -> Scene:
    cam = {k: v for k, v in camera.items() if k != "tau"}
    return dataclasses.replace(scene, camera=cam)


def _manifest(scene: Scene, cameras: list[dict], settings: dict) -> dict:
    native = scene.native(width=settings["width"], height=settings["height"])
    native.pop("camera")
    blob = json.dumps({"scene": native, "cameras": cameras, "settings": settings}, sort_keys=True, default=str)
    return {"format": 1, "frames": len(cameras), "settings": settings,
            "digest": hashlib.sha256(blob.encode()).hexdigest()}  # fmt: skip


def render_film(scene: Scene, cameras: list[dict], output: str | Path, *, fps: float = 24.0, spp: int | None = None,
                time_limit: float | None = None, width: int | None = None, height: int | None = None,
                seed: int | None = None, denoise: bool = False, threads: int = 0, exposure: float | None = None,
                tonemap: str | None = None, on_frame: Callable[[int, int, bool], None] | None = None,
                frame_progress=None, client=None, tile: int | None = None) -> Path:  # fmt: skip
    """Render one frame per camera and write the film.

    Parameters
    ----------
    scene : Scene
        What every frame shows; its camera is replaced by each of ``cameras``.
    cameras : list of dict
        Scene cameras, one per frame (:func:`warpviz.animate.camera_path`).
    output : path-like
        ``.mp4`` or ``.gif`` (frames kept in ``NAME_frames/`` beside it), or a folder of ``frame_NNNNN.png`` and
        ``.exr``.
    fps : float
        Frames per second of a video or GIF.
    spp, time_limit : optional
        Each frame's samples per pixel and/or seconds (whichever comes first); default the scene's spp.
    width, height : int, optional
        Frame size (default the scene's); a video needs both even.
    seed : int, optional
        The film's seed (default the scene's); frame k renders with ``frame_seed(seed, k)``.
    denoise : bool
        Denoise each frame (``pip install "warpviz[denoise]"``).
    threads : int
        Render threads; 0 every core.
    exposure, tonemap : optional
        How frames are tonemapped (default the scene's ``[outputs]``, else the defaults).
    on_frame : callable, optional
        ``on_frame(done, total, rendered)`` after each frame (``rendered`` False for a frame already on disk).
    frame_progress : callable, optional
        The renderer's ``progress`` callback for the samples of the frame being rendered.
    client : distributed.Client, optional
        Render each frame's tiles as tasks on this Dask cluster (``warpviz.render``'s ``client``; the frame
        is the local one bit for bit), ``tile`` their side.

    Returns
    -------
    pathlib.Path
        The film written (the folder, for frames).

    Raises
    ------
    FilmMismatch
        The frames folder holds frames of another film.
    ValueError
        Bad arguments (before any frame is rendered).
    """
    output = Path(output)
    suffix = output.suffix.lower()
    if suffix and suffix not in FILM_SUFFIXES:
        raise ValueError(f"a film is written as {', '.join(FILM_SUFFIXES)} or a folder (no suffix), got {output.name!r}")
    if not cameras:
        raise ValueError("a film needs at least one camera")
    if not (isinstance(fps, (int, float)) and not isinstance(fps, bool) and 0 < fps <= 240):
        raise ValueError(f"fps must be in (0, 240], got {fps!r}")
    w, h = scene.size()
    w, h = (width or w), (height or h)
    if suffix == ".mp4" and (w % 2 or h % 2):
        raise ValueError(f"an .mp4 needs an even width and height (H.264's 4:2:0 colour), got {w}x{h}")
    if suffix == ".mp4":
        _video_writer_available()
    base_seed = scene.render_settings().get("seed", DEFAULT_OPTIONS["seed"]) if seed is None else seed
    settings = {"width": w, "height": h, "spp": spp, "time_limit": time_limit, "seed": int(base_seed),
                "denoise": bool(denoise), "exposure": exposure, "tonemap": tonemap}  # fmt: skip
    folder = frames_folder(output)
    manifest = _manifest(scene, cameras, settings)
    _check_folder(folder, manifest)
    folder.mkdir(parents=True, exist_ok=True)
    atomic_write(folder / "film.json", lambda tmp: tmp.write_text(json.dumps(manifest, indent=1, sort_keys=True)))
    look = {k: v for k, v in (("exposure", exposure), ("tonemap", tonemap)) if v is not None}
    look = {**{k: v for k, v in scene.outputs.items() if k in ("exposure", "tonemap") and v is not None}, **look}
    n = len(cameras)
    for k, cam in enumerate(cameras):
        png = folder / f"frame_{k:05d}.png"
        if png.exists():
            if on_frame:
                on_frame(k + 1, n, False)
            continue
        extra = {"time_limit": time_limit} if time_limit is not None else {}
        if client is not None:
            extra.update(client=client, tile=tile)
        img = render_image(_camera_scene(scene, cam), spp=spp, width=w, height=h, seed=frame_seed(base_seed, k),
                           threads=threads, denoise=denoise, progress=frame_progress, **extra)  # fmt: skip
        img.metadata["frame"] = k
        img.metadata["tau"] = cam.get("tau", 0.0)
        if not suffix:
            img.save(folder / f"frame_{k:05d}.exr")
        img.save(png, **look)  # last: a frame counts as done once its PNG exists
        if on_frame:
            on_frame(k + 1, n, True)
    if suffix:
        _encode(folder, n, output, fps)
    return output


def _check_folder(folder: Path, manifest: dict) -> None:
    path = folder / "film.json"
    if not folder.exists():
        return
    if not path.exists():
        if any(folder.glob("frame_*.png")):
            raise FilmMismatch(f"{folder} holds frames but no film.json: not a film warpviz wrote; use another folder")
        return
    try:
        old = json.loads(path.read_text())
    except (OSError, ValueError) as exc:
        raise FilmMismatch(f"{path}: unreadable ({exc})") from None
    if old.get("digest") != manifest["digest"]:
        diff = [k for k in manifest["settings"] if old.get("settings", {}).get(k) != manifest["settings"][k]]
        if old.get("frames") != manifest["frames"]:
            diff.append("frames")
        what = ", ".join(diff) if diff else "the scene or the camera path"
        raise FilmMismatch(f"{folder} holds frames of another film ({what} differ); remove it or write elsewhere")


def _video_writer_available() -> None:
    try:
        import imageio_ffmpeg  # noqa: F401
    except ImportError:
        raise ValueError('writing .mp4 needs imageio-ffmpeg: pip install "warpviz[film]" (or write .gif or a '
                         "folder of frames)") from None  # fmt: skip


def _encode(folder: Path, n: int, output: Path, fps: float) -> None:
    from PIL import Image as PILImage

    frames = [np.asarray(PILImage.open(folder / f"frame_{k:05d}.png").convert("RGB")) for k in range(n)]
    if output.suffix.lower() == ".gif":
        images = [PILImage.fromarray(f) for f in frames]

        def write(tmp: Path) -> None:
            images[0].save(tmp, format="GIF", save_all=True, append_images=images[1:], duration=1000.0 / fps,
                           loop=0)  # fmt: skip

        atomic_write(output, write)
        return
    import imageio.v2 as imageio

    def write_mp4(tmp: Path) -> None:
        writer = imageio.get_writer(str(tmp), format="FFMPEG", mode="I", fps=fps, codec="libx264",
                                    pixelformat="yuv420p", quality=8, macro_block_size=1,
                                    output_params=["-f", "mp4"])  # fmt: skip
        try:
            for f in frames:
                writer.append_data(f)
        finally:
            writer.close()

    atomic_write(output, write_mp4)
