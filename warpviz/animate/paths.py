"""Camera paths of a film: one camera (position, sheet, look_at, up, fov, observer) per frame.

``orbit`` and ``fall`` move the camera along its observer's worldline, a timelike geodesic integrated by
the core with the same stepper family as light (``_core.worldline``: dop853), the frames evenly spaced in
the observer's proper time, and each frame's camera held by that observer (its 4-velocity from the
integration: aberration and Doppler shift included). ``dolly`` moves a camera held by static observers
along a straight line; a keyframes file interpolates positions, targets and fields of view. See
docs/films.md.
"""

from __future__ import annotations

import copy
import math
import tomllib
from pathlib import Path
from typing import Any

import numpy as np

from warpviz._native import core
from warpviz.scene import Scene, SceneError
from warpviz.scene.native import native_camera

__all__ = ["PATHS", "camera_path"]

#: The built-in camera paths (or a keyframes .toml file).
PATHS = ("orbit", "fall", "dolly")

#: Local error tolerance of the worldlines (dop853): far below anything a frame could show.
WORLDLINE_TOL = 1e-12


def camera_path(scene: Scene, path: str | Path, frames: int, *, duration: float | None = None,
                look: str = "target", to=None, position=None, speed: float | None = None) -> list[dict]:  # fmt: skip
    """One scene camera per frame along ``path``.

    Parameters
    ----------
    scene : Scene
        Its camera is the first frame's (position, target, up, field of view, sheet, observer).
    path : {"orbit", "fall", "dolly"} or path-like
        ``orbit``: a circular geodesic orbit through the camera in the plane of the centre, the camera and the
        horizontal (prograde about the scene's ``up``), one revolution over the film. ``fall``: the camera's own worldline
        as a geodesic: from rest at its position (a static camera), or as its observer moves (``free_fall``,
        ``moving``, an orbit), until ``duration`` of proper time, or by default until half the horizon radius
        (a black hole), the start's radius on the other sheet (a wormhole) or twice the start's radius.
        ``dolly``: static observers along the straight line from the position to ``to`` (default: half-way to
        the target). A ``.toml`` file: keyframes (docs/films.md).
    frames : int
        Number of frames, >= 1.
    duration : float, optional
        ``fall``: proper time (units of M) the film covers.
    look : {"target", "ahead"}
        Where the camera looks: the scene's ``look_at`` throughout, or along its motion.
    to : array_like, shape (3,), optional
        ``dolly``: where the camera ends.
    speed : float, optional
        ``fall``: launch the camera towards its target at this speed (units of c, relative to the local
        observer) instead of from its observer's own motion: a flight, e.g. through a wormhole.
    position : array_like, shape (3,), optional
        Where the path starts, instead of the scene camera's position (its target, up, field of view and
        observer kept).

    Returns
    -------
    list of dict
        Each a scene camera (``position``, ``look_at``, ``up``, ``fov``, ``sheet``, ``observer``, ``shift``) and
        ``tau``, the proper time of the frame (0 for dolly and keyframes).

    Raises
    ------
    ValueError
        Bad arguments, or a path the camera's observer cannot take (the reason).
    """
    if isinstance(frames, bool) or not isinstance(frames, int) or frames < 1:
        raise ValueError(f"frames must be an integer >= 1, got {frames!r}")
    if look not in ("target", "ahead"):
        raise ValueError(f"look must be 'target' or 'ahead', got {look!r}")
    cam = copy.deepcopy(scene.camera)
    if position is not None:
        start = np.asarray(position, dtype=float)
        if start.shape != (3,) or not np.all(np.isfinite(start)):
            raise ValueError(f"position must be 3 finite numbers, got {position!r}")
        if np.allclose(start, cam["look_at"]):
            raise ValueError(f"position {start.tolist()} is the camera's look_at")
        cam["position"] = start.tolist()
    if speed is not None:
        if str(path) != "fall":
            raise ValueError("speed launches a fall (a flight): use it with path 'fall'")
        if not (0.0 <= speed < 1.0):
            raise ValueError(f"speed must be in [0, 1) (units of c), got {speed!r}")
        aim = np.subtract(cam["look_at"], cam["position"])
        cam["observer"] = {"kind": "moving", "velocity": (speed * aim / np.linalg.norm(aim)).tolist()}
    if str(path) == "orbit":
        return _orbit(scene, cam, frames, look)
    if str(path) == "fall":
        return _fall(scene, cam, frames, duration, look)
    if str(path) == "dolly":
        return _dolly(cam, frames, to, look)
    p = Path(path)
    if p.suffix == ".toml":
        return _keyframes(p, cam, frames)
    raise ValueError(f"path must be one of {', '.join(PATHS)} or a keyframes .toml file, got {str(path)!r}")


def _native(cam: dict) -> dict:
    return native_camera(dict(cam, width=1, height=1))


def _worldline(scene: Scene, cam: dict, taus: np.ndarray, stop_radius: float):
    try:
        return core.worldline(scene.metric.name, list(scene.metric.param_values), _native(cam),
                              np.ascontiguousarray(taus, dtype=np.float64), float(stop_radius), WORLDLINE_TOL)  # fmt: skip
    except ValueError as exc:
        kind = (cam.get("observer") or {}).get("kind", "local")
        raise ValueError(f"the camera's observer ({kind}) cannot be at {cam['position']}: {exc}") from None


def _frames_on(scene: Scene, cam: dict, taus: np.ndarray, stop_radius: float, look: str) -> list[dict]:
    """The cameras at proper times taus along cam's worldline: each held by the observer there (its chart
    4-velocity, observer "given")."""
    pos, sheets, _, u = _worldline(scene, cam, taus, stop_radius)
    if not len(pos):
        raise ValueError("the camera's worldline ends where it starts")
    ahead = []  # a moment later on the same worldline: the direction of motion
    if look == "ahead":
        ahead = _worldline(scene, cam, np.asarray(taus) + 1e-4 * max(1.0, _radius(cam["position"])), stop_radius)[0]
    out = []
    for i in range(len(pos)):
        c = copy.deepcopy(cam)
        c["position"] = [float(v) for v in pos[i]]
        c["sheet"] = int(sheets[i])
        c["observer"] = {"kind": "given", "u": [float(v) for v in u[i]]}
        if i < len(ahead) and np.linalg.norm(ahead[i] - pos[i]) > 0:
            c["look_at"] = [float(v) for v in pos[i] + 10.0 * (ahead[i] - pos[i]) / np.linalg.norm(ahead[i] - pos[i])]
        c["tau"] = float(taus[i])
        out.append(c)
    return out


def _radius(p) -> float:
    return float(np.linalg.norm(p))


def _orbit(scene: Scene, cam: dict, frames: int, look: str) -> list[dict]:
    # the orbit's plane holds the centre, the camera and the horizontal (up x position): its axis is the part
    # of up perpendicular to the position (up itself for a camera in the equatorial plane)
    up, p = np.asarray(cam["up"], dtype=float), np.asarray(cam["position"], dtype=float)
    p_hat = p / np.linalg.norm(p)
    axis = up / np.linalg.norm(up) - p_hat * float(p_hat @ up) / np.linalg.norm(up)
    if not np.linalg.norm(axis) > 1e-9:
        raise ValueError("orbit: the camera's up points at the centre; no orbit plane is horizontal")
    axis /= np.linalg.norm(axis)
    start = dict(cam, observer={"kind": "orbit", "axis": axis.tolist()})
    try:
        x, u, _, _ = core.observer(scene.metric.name, list(scene.metric.param_values), _native(start))
    except ValueError as exc:
        raise ValueError(f"orbit: no circular orbit through the camera at {cam['position']}: {exc}") from None
    r_cyl = float(np.linalg.norm(np.cross(axis, x[1:])))
    speed = float(np.linalg.norm(u[1:]))  # coordinate speed r Omega u^t of the circular motion
    period = 2.0 * math.pi * r_cyl / speed  # proper time of one revolution
    taus = np.arange(frames) * period / frames
    return _frames_on(scene, start, taus, 0.0, look)


def _fall(scene: Scene, cam: dict, frames: int, duration: float | None, look: str) -> list[dict]:
    lm = core.landmarks(scene.metric.name, list(scene.metric.param_values))
    r0 = _radius(cam["position"])
    start = cam  # a static camera is at rest at the first frame and falls from there
    horizon = lm["horizon"]
    stop = 0.5 * horizon if horizon > 0 else 0.0
    if duration is not None:
        if not (duration > 0 and math.isfinite(duration)):
            raise ValueError(f"duration must be a positive proper time, got {duration!r}")
        taus = np.linspace(0.0, duration, frames)
        return _frames_on(scene, start, taus, stop, look)
    mass = max(lm["mass"], 1e-3 * r0)
    t_max = 1.5 * max(math.pi * math.sqrt(r0**3 / (2 * mass)), 40.0 * r0)
    grid = np.linspace(0.0, t_max, 4001)
    pos, sheets, _, _ = _worldline(scene, start, grid, stop)
    radii = np.linalg.norm(pos, axis=1)
    end = len(pos) - 1
    if horizon <= 0:
        other = (sheets != sheets[0]) & (radii >= r0)
        far = radii >= 2 * r0
        hits = np.flatnonzero(other | far)
        end = int(hits[0]) if hits.size else end
    if end < 1 or np.max(np.linalg.norm(pos[: end + 1] - pos[0], axis=1)) < 1e-6 * max(1.0, r0):
        raise ValueError(f"fall: the camera at {cam['position']} does not move: nothing pulls it (give it a "
                         "velocity, or observer = 'moving')")  # fmt: skip
    return _frames_on(scene, start, np.linspace(0.0, grid[end], frames), stop, look)


def _dolly(cam: dict, frames: int, to, look: str) -> list[dict]:
    a = np.asarray(cam["position"], dtype=float)
    b = (a + np.asarray(cam["look_at"], dtype=float)) / 2 if to is None else np.asarray(to, dtype=float)
    if b.shape != (3,) or not np.all(np.isfinite(b)):
        raise ValueError(f"to must be 3 finite numbers, got {to!r}")
    out = []
    for i in range(frames):
        s = i / max(1, frames - 1)
        c = copy.deepcopy(cam)
        c["position"] = [float(v) for v in (1 - s) * a + s * b]
        if look == "ahead" and np.linalg.norm(b - a) > 0:
            c["look_at"] = [float(v) for v in np.asarray(c["position"]) + (b - a)]
        c["tau"] = 0.0
        out.append(c)
    return out


def _keyframes(path: Path, cam: dict, frames: int) -> list[dict]:
    """Keyframes: ``[[key]]`` tables with ``time`` (seconds, increasing) and any of ``position``,
    ``look_at``, ``up``, ``fov`` (a key a table leaves out keeps the previous key's, the first the scene's);
    linear between keys, frames evenly spaced from the first time to the last."""
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except (OSError, tomllib.TOMLDecodeError) as exc:
        raise SceneError(f"{path}: {exc}") from None
    keys = data.get("key")
    if not isinstance(keys, list) or len(keys) < 1:
        raise SceneError(f"{path}: needs at least one [[key]] table with a time")
    rows: list[dict[str, Any]] = []
    prev = {k: cam[k] for k in ("position", "look_at", "up", "fov")}
    for i, k in enumerate(keys):
        where = f"{path}: key[{i}]"
        extra = set(k) - {"time", "position", "look_at", "up", "fov"}
        if extra:
            raise SceneError(f"{where}: unknown key {sorted(extra)[0]!r} (keys: time, position, look_at, up, fov)")
        t = k.get("time")
        if isinstance(t, bool) or not isinstance(t, (int, float)) or (rows and not t > rows[-1]["time"]):
            raise SceneError(f"{where}.time must be a number greater than the previous key's, got {t!r}")
        row = {"time": float(t)}
        for name in ("position", "look_at", "up"):
            v = k.get(name, prev[name])
            if not (isinstance(v, list) and len(v) == 3 and all(isinstance(c, (int, float)) for c in v)):
                raise SceneError(f"{where}.{name} must be a list of 3 numbers, got {v!r}")
            row[name] = [float(c) for c in v]
        fov = k.get("fov", prev["fov"])
        if isinstance(fov, bool) or not isinstance(fov, (int, float)) or not 0 < fov < 180:
            raise SceneError(f"{where}.fov must be in (0, 180) degrees, got {fov!r}")
        row["fov"] = float(fov)
        prev = row
        rows.append(row)
    times = np.array([r["time"] for r in rows])
    out = []
    for i in range(frames):
        t = times[0] + (times[-1] - times[0]) * (i / max(1, frames - 1))
        j = int(np.clip(np.searchsorted(times, t, side="right") - 1, 0, len(rows) - 1))
        k = min(j + 1, len(rows) - 1)
        s = 0.0 if k == j else (t - times[j]) / (times[k] - times[j])
        c = copy.deepcopy(cam)
        for name in ("position", "look_at", "up"):
            c[name] = [float(v) for v in (1 - s) * np.asarray(rows[j][name]) + s * np.asarray(rows[k][name])]
        c["fov"] = float((1 - s) * rows[j]["fov"] + s * rows[k]["fov"])
        c["tau"] = 0.0
        out.append(c)
    return out
