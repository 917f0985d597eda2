"""Loading a scene file: read the TOML, validate every table and build the :class:`~warpviz.scene.model.Scene`.

:func:`load_scene` takes a path or a shipped scene's name (:mod:`warpviz.scene.catalog`); a TOML syntax
error becomes a :class:`~warpviz.scene.reader.SceneError` at its line and column. The tables are
compiled to native scene entries by :mod:`~warpviz.scene.settings` (``[metric]``, ``[camera]``,
``[render]``, ``[outputs]``), :mod:`~warpviz.scene.appearance` (skies, textures, materials) and
:mod:`~warpviz.scene.objects` (``[[objects]]``).

Examples
--------
>>> from warpviz.scene.loader import load_scene
>>> load_scene("fig07")
Scene('fig07_schwarzschild_cornell.toml', Schwarzschild(mass=2.5))
"""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

from warpviz.scene._toml_positions import TomlPositions
from warpviz.scene.appearance import _environment, _materials, _textures
from warpviz.scene.catalog import resolve_scene
from warpviz.scene.model import Scene
from warpviz.scene.lights import _lights
from warpviz.scene.objects import _objects
from warpviz.scene.reader import SceneError, _describe, _Reader
from warpviz.scene.settings import _camera, _metric, _outputs, _render, wormhole_hint

__all__ = ["FORMAT_VERSION", "load_scene", "scene_from_dict"]

FORMAT_VERSION = 1

#: Largest scene file read, in bytes (a scene is a few kilobytes; meshes and images are files of their own).
MAX_SCENE_BYTES = 16 * 2**20


def scene_from_dict(data: dict, *, base_dir: str | Path) -> Scene:
    """Validate a parsed scene (the structure of a scene file) and load what it refers to.

    Parameters
    ----------
    data : dict
        As :func:`tomllib.loads` returns for a scene file (tuples may stand for lists).
    base_dir : str or Path, keyword-only
        Folder that relative mesh and image paths start from.

    Returns
    -------
    Scene

    Raises
    ------
    SceneError
        The first problem found; the message names the key path (there are no line numbers).
    """
    return _build(_Reader(label=None, positions=None, base_dir=Path(base_dir)), data, path=None)


def load_scene(path: str | Path) -> Scene:
    """Read, validate and load a scene file.

    Parameters
    ----------
    path : str or Path
        A TOML scene file, or the name of a shipped scene (``"fig07"``; see :mod:`warpviz.scene.catalog`).

    Returns
    -------
    Scene

    Raises
    ------
    SceneError
        Unreadable file, TOML syntax error, or invalid content; the message starts with
        ``file:line:column:``.
    """
    try:
        file = resolve_scene(path)
    except (FileNotFoundError, LookupError) as exc:
        raise SceneError(str(exc.args[0] if exc.args else exc)) from None
    label = str(path) if Path(path).is_file() else str(file)
    try:
        size = file.stat().st_size
        if size > MAX_SCENE_BYTES:
            raise SceneError(f"the scene file is {size} bytes, more than a scene file may be ({MAX_SCENE_BYTES}; "
                             "meshes and textures go in files of their own)", path=label)  # fmt: skip
        text = file.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise SceneError(f"cannot read the scene file: {exc}", path=label) from None
    try:
        data = tomllib.loads(text)
        reader = _Reader(label=label, positions=TomlPositions(text), base_dir=file.parent)
        return _build(reader, data, path=file)
    except tomllib.TOMLDecodeError as exc:
        line, column, reason = _toml_error_position(str(exc), text)
        raise SceneError(f"TOML syntax error: {reason}", path=label, line=line, column=column) from None
    except RecursionError:
        raise SceneError("arrays or tables are nested too deeply to read (a scene needs a few levels)",
                         path=label) from None  # fmt: skip


def _toml_error_position(message: str, text: str) -> tuple[int, int, str]:
    m = re.search(r"\s*\(at line (\d+), column (\d+)\)\s*$", message)
    if m:
        return int(m.group(1)), int(m.group(2)), message[: m.start()]
    m = re.search(r"\s*\(at end of document\)\s*$", message)
    if m:
        lines = text.split("\n")
        return len(lines), len(lines[-1]) + 1, message[: m.start()] + " (at end of file)"
    return 1, 1, message


# ---------------------------------------------------------------------------------------------- building
_TOP_KEYS = ("version", "description", "metric", "camera", "render", "environment", "environment_other",
             "textures", "materials", "objects", "lights", "outputs")  # fmt: skip


def _build(r: _Reader, data: dict, *, path: Path | None) -> Scene:
    r.table((), data, _TOP_KEYS, what="the scene file")
    version = r.get(data, (), "version")
    if isinstance(version, bool) or not isinstance(version, int) or version != FORMAT_VERSION:
        why = f"version must be {FORMAT_VERSION} (the scene format this warpviz reads), got {_describe(version)}"
        raise r.error(("version",), why)
    description = r.string(data, (), "description", "")
    metric = _metric(r, r.get(data, (), "metric"))
    two_sheets = metric.sheets == 2  # a wormhole: objects, camera and sky may be on its other sheet
    camera = _camera(r, r.get(data, (), "camera"), metric)
    render, paper = _render(r, data.get("render", {}))
    environment = _environment(r, ("environment",), data.get("environment", {}))
    environment_other = None
    if "environment_other" in data:
        if not two_sheets:
            raise r.error(("environment_other",), "[environment_other] is the sky of a wormhole's other sheet; "
                          f"it needs {wormhole_hint()}, not {metric.name!r}", at_value=False)  # fmt: skip
        environment_other = _environment(r, ("environment_other",), data["environment_other"])
    tex_list, tex_index = _textures(r, data.get("textures", {}))
    mat_list, mat_index = _materials(r, data.get("materials", {}), tex_list, tex_index)
    shapes = _objects(r, data.get("objects", []), mat_index, two_sheets=two_sheets)
    lights = _lights(r, data.get("lights", []), two_sheets=two_sheets)
    outputs = _outputs(r, data.get("outputs", {}))
    return Scene(
        path=path, description=description.strip(), metric=metric, camera=camera, outputs=outputs,
        _render=render, _paper=paper, _textures=tex_list, _materials=mat_list, _shapes=shapes, _lights=lights,
        _environment=environment, _environment_other=environment_other,
    )  # fmt: skip
