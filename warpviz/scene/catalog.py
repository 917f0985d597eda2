"""The shipped figure scenes: where they live and how a bare name such as ``fig07`` finds its file.

Shipped scenes are the ``scenes/*.toml`` files of the repository. A built package (a wheel) carries
them, with their meshes and textures, inside the package as ``warpviz/scenes`` (:data:`PACKAGE_SCENES`);
an editable install finds the repository's folder next to the package directory
(:data:`REPOSITORY_SCENES`). The environment variable ``WARPVIZ_SCENES`` (folders separated by
``os.pathsep``) is searched first, for scenes kept elsewhere; an entry that is not a folder is warned
about and ignored.

Examples
--------
>>> from warpviz.scene.catalog import resolve_scene, shipped_scenes
>>> resolve_scene("fig07").name
'fig07_schwarzschild_cornell.toml'
>>> len(shipped_scenes()) >= 17
True
"""

from __future__ import annotations

import difflib
import os
import tomllib
import warnings
from pathlib import Path

__all__ = ["PACKAGE_SCENES", "REPOSITORY_SCENES", "looks_like_path", "resolve_scene", "scene_description",
           "scene_dirs", "shipped_scenes"]

#: Where an installed package keeps its scenes (with their meshes and textures): CMake installs the
#: repository's ``scenes/`` there when a wheel is built.
PACKAGE_SCENES = Path(__file__).resolve().parents[1] / "scenes"

#: The repository's ``scenes/`` folder, beside the package directory (an editable install).
REPOSITORY_SCENES = Path(__file__).resolve().parents[2] / "scenes"


def scene_dirs() -> list[Path]:
    """Folders searched for shipped scenes, in order: ``$WARPVIZ_SCENES`` entries, then ``<repo>/scenes``."""
    dirs = [Path(p) for p in os.environ.get("WARPVIZ_SCENES", "").split(os.pathsep) if p]
    for d in dirs:
        if not d.is_dir():
            what = "a file" if d.is_file() else "not there"
            warnings.warn(f"WARPVIZ_SCENES names {str(d)!r}, which is {what}, not a folder of scenes; it is ignored",
                          stacklevel=2)  # fmt: skip
    dirs += [PACKAGE_SCENES, REPOSITORY_SCENES]
    return list(dict.fromkeys(d for d in dirs if d.is_dir()))


def shipped_scenes() -> list[Path]:
    """Every shipped scene file, sorted by name (a name found in an earlier folder hides later ones)."""
    seen: dict[str, Path] = {}
    for d in scene_dirs():
        for p in sorted(d.glob("*.toml")):
            seen.setdefault(p.name, p)
    return [seen[k] for k in sorted(seen)]


def scene_description(path: str | Path) -> str:
    """First line of a scene file's ``description`` ('' if it has none or cannot be read)."""
    try:
        data = tomllib.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, tomllib.TOMLDecodeError, UnicodeDecodeError):
        return ""
    text = data.get("description", "")
    return text.strip().splitlines()[0] if isinstance(text, str) and text.strip() else ""


def looks_like_path(spec: str | Path) -> bool:
    """Whether ``spec`` names a file (has a folder part or a suffix) rather than a shipped scene name."""
    s = str(spec)
    return isinstance(spec, Path) or os.sep in s or "/" in s or Path(s).suffix != ""


def resolve_scene(spec: str | Path) -> Path:
    """The scene file for ``spec``: an existing path, or the name of a shipped scene.

    A name matches a shipped scene whose file stem equals it, or starts with it followed by ``_``
    (``fig07`` → ``fig07_schwarzschild_cornell.toml``), or, failing those, starts with it when only one
    does (``fig02`` → ``fig02_...``; ``fig10`` is ambiguous between ``fig10a`` … ``fig10e``).

    Parameters
    ----------
    spec : str or Path
        Path of a TOML file, or a shipped scene's name.

    Returns
    -------
    Path
        An existing file.

    Raises
    ------
    FileNotFoundError
        Nothing matches; the message suggests close names.
    LookupError
        The name matches several shipped scenes; the message lists them.
    """
    p = Path(spec)
    if p.is_file():
        return p
    if p.is_dir():
        raise FileNotFoundError(f"{spec}: is a folder, not a scene file (give a .toml file in it)")
    if looks_like_path(spec):
        raise FileNotFoundError(f"{spec}: no such scene file")
    name = str(spec)
    scenes = shipped_scenes()
    stems = [s.stem for s in scenes]
    for test in (lambda s: s == name, lambda s: s.startswith(name + "_"), lambda s: s.startswith(name)):
        found = [scenes[i] for i, s in enumerate(stems) if test(s)]
        if len(found) == 1:
            return found[0]
        if len(found) > 1:
            raise LookupError(f"scene name {name!r} is ambiguous: {', '.join(f.stem for f in found)}")
    close = difflib.get_close_matches(name, stems, n=3, cutoff=0.5)
    hint = f"; did you mean {' or '.join(close)}?" if close else "; `warpviz scenes` lists the shipped scenes"
    raise FileNotFoundError(f"{name}: no such scene file or shipped scene{hint}")
