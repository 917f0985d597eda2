"""Films: camera paths (:func:`camera_path`: orbit, fall, dolly, keyframes) and rendering them frame by
frame into a video, a GIF or a folder of frames (:func:`render_film`), resumable and deterministic.
See docs/films.md."""

from warpviz.animate.film import FILM_SUFFIXES, FilmMismatch, frame_seed, frames_folder, render_film
from warpviz.animate.paths import PATHS, camera_path

__all__ = ["FILM_SUFFIXES", "PATHS", "FilmMismatch", "camera_path", "frame_seed", "frames_folder", "render_film"]
