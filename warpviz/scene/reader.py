"""Reading scene tables: type, range and key checks whose failures say where and why.

:class:`_Reader` checks the tables of a parsed scene (keys allowed and required, numbers, vectors,
colours, choices, file references) and turns every problem into a :class:`SceneError` whose message
starts with ``file:line:column:`` (the position of the offending key or value, found by
:class:`~warpviz.scene._toml_positions.TomlPositions`) and names the key path (:func:`key_name`).

Examples
--------
>>> from warpviz.scene.reader import SceneError, key_name
>>> key_name(("objects", 2, "radius")), key_name(("textures", "my tex", "scale"))
('objects[2].radius', 'textures."my tex".scale')
>>> str(SceneError("radius must be > 0", path="room.toml", line=12, column=10, key="objects[2].radius"))
'room.toml:12:10: radius must be > 0'
"""

from __future__ import annotations

import difflib
import math
import numbers
import re
from pathlib import Path
from typing import Any

from warpviz.scene._toml_positions import TomlPositions

__all__ = ["SceneError", "key_name"]

_REQUIRED = object()


class SceneError(ValueError):
    """A scene file or scene dict that cannot be used, with where and why.

    Attributes
    ----------
    reason : str
        The message without the location.
    path : str or None
        The scene file.
    line, column : int or None
        1-based position of the offending key or value in the file.
    key : str or None
        Key path such as ``"metric.spin"`` or ``"objects[2].radius"``.
    """

    def __init__(self, reason: str, *, path: str | None = None, line: int | None = None,
                 column: int | None = None, key: str | None = None):  # fmt: skip
        self.reason, self.path, self.line, self.column, self.key = reason, path, line, column, key
        where = ""
        if path is not None:
            where = f"{path}:{line}:{column}: " if line is not None else f"{path}: "
        super().__init__(where + reason)


def key_name(path: tuple) -> str:
    """Dotted display form of a key path: ``("objects", 2, "radius")`` -> ``"objects[2].radius"``."""
    out = ""
    for part in path:
        if isinstance(part, int):
            out += f"[{part}]"
        else:
            text = part if re.fullmatch(r"[A-Za-z0-9_-]+", part) else f'"{part}"'
            out += f".{text}" if out else text
    return out


# ---------------------------------------------------------------------------------------------- reader
def did_you_mean(name: str, options) -> str:
    """``"; did you mean 'x'?"`` for the option closest to ``name`` (difflib, cutoff 0.6), else ``""``."""
    close = difflib.get_close_matches(name, list(options), n=1, cutoff=0.6)
    return f"; did you mean {close[0]!r}?" if close else ""


class _Reader:
    """Validation helpers that turn problems into SceneErrors at the right file position."""

    def __init__(self, *, label: str | None, positions: TomlPositions | None, base_dir: Path):
        self.label, self.positions, self.base_dir = label, positions, base_dir

    def error(self, path: tuple, reason: str, *, at_value: bool = True, inside: int | None = None) -> SceneError:
        """A SceneError at ``path``'s value (or key); ``inside``: the 1-based column within a one-line string
        value where the problem is (an expression's), added to the string's position past its quote."""
        line = column = None
        if self.positions is not None:
            line, column = self.positions.locate(path, prefer_value=at_value)
            if inside is not None and column is not None and self.positions.value(path) is not None:
                column += inside
        return SceneError(reason, path=self.label, line=line, column=column, key=key_name(path) or None)

    def table(self, path: tuple, value: Any, allowed, *, required=(), what: str | None = None) -> dict:
        """Check ``value`` is a table with only ``allowed`` keys and every ``required`` one."""
        where = what or (f"[{key_name(path)}]" if path else "the top level")
        if not isinstance(value, dict):
            raise self.error(path, f"{key_name(path) or 'the scene'} must be a table, got {_describe(value)}")
        for k in value:
            if k not in allowed:
                known = ", ".join(sorted(allowed))
                raise self.error(path + (k,), f"unknown key {k!r} in {where}{did_you_mean(k, allowed)} (allowed: {known})",
                                 at_value=False)
        for k in required:
            if k not in value:
                raise self.error(path, f"{where} is missing the required key {k!r}", at_value=False)
        return value

    def get(self, tbl: dict, path: tuple, name: str, default: Any = _REQUIRED) -> Any:
        if name in tbl:
            return tbl[name]
        if default is _REQUIRED:
            where = key_name(path) or "the scene"
            raise self.error(path, f"{where} is missing the required key {name!r}", at_value=False)
        return default

    def real(self, tbl, path, name, default=_REQUIRED, *, lo=None, hi=None, lo_open=True, hi_open=True) -> float:
        value = self.get(tbl, path, name, default)
        kp = path + (name,)
        if isinstance(value, bool) or not isinstance(value, numbers.Real):
            raise self.error(kp, f"{key_name(kp)} must be a number, got {_describe(value)}")
        value = float(value)
        if not math.isfinite(value):
            raise self.error(kp, f"{key_name(kp)} must be finite, got {value}")
        _check_range(self, kp, value, lo, hi, lo_open, hi_open)
        return value

    def integer(self, tbl, path, name, default=_REQUIRED, *, lo=None, hi=None) -> int:
        value = self.get(tbl, path, name, default)
        kp = path + (name,)
        if isinstance(value, bool) or not isinstance(value, numbers.Integral):
            raise self.error(kp, f"{key_name(kp)} must be an integer, got {_describe(value)}")
        _check_range(self, kp, int(value), lo, hi, False, False)
        return int(value)

    def boolean(self, tbl, path, name, default=_REQUIRED) -> bool:
        value = self.get(tbl, path, name, default)
        if not isinstance(value, bool):
            kp = path + (name,)
            raise self.error(kp, f"{key_name(kp)} must be true or false, got {_describe(value)}")
        return value

    def string(self, tbl, path, name, default=_REQUIRED) -> str:
        value = self.get(tbl, path, name, default)
        if not isinstance(value, str):
            raise self.error(path + (name,), f"{key_name(path + (name,))} must be a string, got {_describe(value)}")
        return value

    def choice(self, tbl, path, name, options, default=_REQUIRED) -> str:
        value = self.string(tbl, path, name, default)
        if value not in options:
            raise self.error(path + (name,), f"{key_name(path + (name,))} = {value!r} is not one of "
                             f"{', '.join(options)}{did_you_mean(value, options)}")
        return value

    def reference(self, tbl, path, name, index: dict, what: str) -> int:
        """The index of the named ``what`` (texture, material) that ``tbl[name]`` refers to, else an error
        listing the defined ones."""
        value = self.string(tbl, path, name)
        if value not in index:
            kp = path + (name,)
            defined = ", ".join(index) or "none"
            raise self.error(kp, f"{key_name(kp)}: unknown {what} {value!r}{did_you_mean(value, index)} (defined: {defined})")
        return index[value]

    def numbers(self, tbl, path, name, n, default=_REQUIRED, *, integer=False, lo=None, hi=None, lo_open=False) -> list:
        value = self.get(tbl, path, name, default)
        kp = path + (name,)
        kind = "integers" if integer else "numbers"
        kind_type = numbers.Integral if integer else numbers.Real
        ok = isinstance(value, (list, tuple)) and len(value) == n
        ok = ok and all(not isinstance(x, bool) and isinstance(x, kind_type) for x in value)
        if not ok:
            raise self.error(kp, f"{key_name(kp)} must be a list of {n} {kind}, got {_describe(value)}")
        out = [int(x) if integer else float(x) for x in value]
        for i, x in enumerate(out):
            if not math.isfinite(x):
                raise self.error(kp + (i,), f"{key_name(kp)}[{i}] must be finite, got {x}")
            _check_range(self, kp + (i,), x, lo, hi, lo_open, False, label=f"{key_name(kp)}[{i}]")
        return out

    def vec3(self, tbl, path, name, default=_REQUIRED, *, nonzero=False) -> list[float]:
        v = self.numbers(tbl, path, name, 3, default)
        if nonzero and not any(v):
            raise self.error(path + (name,), f"{key_name(path + (name,))} must not be the zero vector")
        return v

    def color(self, tbl, path, name, default=_REQUIRED, *, albedo=False) -> list[float]:
        """Linear RGB: three numbers >= 0, and <= 1 for reflectances (``albedo``)."""
        return self.numbers(tbl, path, name, 3, default, lo=0.0, hi=1.0 if albedo else None)

    def file(self, tbl, path, name, *, kind: str, suffixes=None) -> Path:
        rel = self.string(tbl, path, name)
        kp = path + (name,)
        p = Path(rel)
        full = p if p.is_absolute() else self.base_dir / p
        if suffixes is not None and p.suffix.lower() not in suffixes:
            raise self.error(kp, f"{key_name(kp)} = {rel!r}: unsupported {kind} format (use {', '.join(suffixes)})")
        if full.is_dir():
            raise self.error(kp, f"{key_name(kp)}: {kind} file {rel!r} is a folder, not a file")
        if not full.is_file():
            raise self.error(
                kp, f"{key_name(kp)}: {kind} file {rel!r} not found (paths are relative to the scene file's folder)"
            )
        return full


def _check_range(r: _Reader, kp, value, lo, hi, lo_open, hi_open, *, label=None) -> None:
    label = label or key_name(kp)
    bad_lo = lo is not None and (value <= lo if lo_open else value < lo)
    bad_hi = hi is not None and (value >= hi if hi_open else value > hi)
    if not (bad_lo or bad_hi):
        return
    if lo is not None and hi is not None and math.isfinite(hi):
        left, right = ("(" if lo_open else "["), (")" if hi_open else "]")
        raise r.error(kp, f"{label} must be in {left}{_num(lo)}, {_num(hi)}{right}, got {_num(value)}")
    if bad_lo:
        raise r.error(kp, f"{label} must be {'>' if lo_open else '>='} {_num(lo)}, got {_num(value)}")
    raise r.error(kp, f"{label} must be {'<' if hi_open else '<='} {_num(hi)}, got {_num(value)}")


def _num(x) -> str:
    return f"{x:g}" if isinstance(x, float) else str(x)


def _describe(value: Any) -> str:
    if isinstance(value, dict):
        return "a table"
    if isinstance(value, list):
        return f"a list of {len(value)}" if len(value) != 1 else "a list of 1"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return f"the string {value!r}"
    return repr(value)
