"""Where each key and value of a TOML document starts, for error messages with line and column.

:mod:`tomllib` parses a document but forgets positions. :class:`TomlPositions` re-scans the source text
(which tomllib has already accepted, so the scanner may assume it is valid TOML) and records, for every key
path, the line and column of the key and of its value. Key paths are tuples of table keys and array
indices, e.g. ``("metric", "spin")``, ``("objects", 2, "radius")`` or ``("environment", "spots", 0)``;
``[[objects]]`` tables are numbered in order of appearance.

Examples
--------
>>> pos = TomlPositions('version = 1\\n[metric]\\nname = "kerr"\\n  spin = 0.9\\n[[objects]]\\n[[objects]]\\nr = 2\\n')
>>> pos.key(("metric", "spin")), pos.value(("metric", "spin"))
((4, 3), (4, 10))
>>> pos.key(("objects", 1, "r")), pos.key(("objects", 1))
((7, 1), (6, 1))
>>> pos.locate(("objects", 1, "missing"))
(6, 1)
"""

from __future__ import annotations

import bisect

Path = tuple  # a key path: str table keys and int array indices

_BARE = frozenset("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_-")


class TomlPositions:
    """Line/column (both 1-based) of every key and value in a TOML source text.

    Parameters
    ----------
    text : str
        A document that :func:`tomllib.loads` accepts.
    """

    def __init__(self, text: str):
        self._text = text
        self._line_starts = [0] + [i + 1 for i, c in enumerate(text) if c == "\n"]
        self._keys: dict[Path, tuple[int, int]] = {}
        self._values: dict[Path, tuple[int, int]] = {}
        self._aot: dict[Path, int] = {}  # array-of-tables path -> number of tables seen so far
        self._i = 0
        self._scan()

    # ------------------------------------------------------------------ lookup
    def key(self, path: Path) -> tuple[int, int] | None:
        """Position of the key that names ``path`` (a table header for tables), or None."""
        return self._keys.get(tuple(path))

    def value(self, path: Path) -> tuple[int, int] | None:
        """Position of the value stored at ``path`` (key = value, array element), or None."""
        return self._values.get(tuple(path))

    def locate(self, path: Path, *, prefer_value: bool = False) -> tuple[int, int]:
        """Best position for a message about ``path``: the path itself, else its nearest ancestor.

        Parameters
        ----------
        path : tuple
            Key path; it need not exist (a missing key is reported at its table).
        prefer_value : bool, keyword-only
            Point at the value rather than the key when both are known.
        """
        path = tuple(path)
        while path:
            first, second = (self._values, self._keys) if prefer_value else (self._keys, self._values)
            for table in (first, second):
                if path in table:
                    return table[path]
            path = path[:-1]
        return (1, 1)

    # ---------------------------------------------------------------- scanning
    def _pos(self, index: int) -> tuple[int, int]:
        line = bisect.bisect_right(self._line_starts, index) - 1
        return line + 1, index - self._line_starts[line] + 1

    def _peek(self, n: int = 1) -> str:
        return self._text[self._i : self._i + n]

    def _skip_space(self, *, newlines: bool) -> None:
        text, n = self._text, len(self._text)
        while self._i < n:
            c = text[self._i]
            if c in " \t\r" or (newlines and c == "\n"):
                self._i += 1
            elif c == "#" and newlines:
                while self._i < n and text[self._i] != "\n":
                    self._i += 1
            else:
                return

    def _skip_line(self) -> None:
        end = self._text.find("\n", self._i)
        self._i = len(self._text) if end < 0 else end + 1

    def _scan(self) -> None:
        table: Path = ()
        n = len(self._text)
        while True:
            self._skip_space(newlines=True)
            if self._i >= n:
                return
            start = self._i
            if self._peek(2) == "[[":
                self._i += 2
                segments = self._key()
                table = self._resolve(segments, array=True)
                self._keys.setdefault(table[:-1], self._pos(start))
                self._keys[table] = self._pos(start)
                self._skip_line()
            elif self._peek() == "[":
                self._i += 1
                segments = self._key()
                table = self._resolve(segments, array=False)
                self._keys[table] = self._pos(start)
                self._skip_line()
            else:
                self._key_value(table)

    def _resolve(self, segments: list[tuple[str, int]], *, array: bool) -> Path:
        path: Path = ()
        for k, (name, _) in enumerate(segments):
            path += (name,)
            last = k == len(segments) - 1
            if last and array:
                self._aot[path] = self._aot.get(path, 0) + 1
                path += (self._aot[path] - 1,)
            elif path in self._aot:
                path += (self._aot[path] - 1,)
        return path

    def _key(self) -> list[tuple[str, int]]:
        """Parse a (dotted) key at the cursor: [(segment, start index), ...]."""
        segments = []
        while True:
            self._skip_space(newlines=False)
            start = self._i
            c = self._peek()
            if c == '"':
                name = self._basic_string()
            elif c == "'":
                end = self._text.index("'", self._i + 1)
                name = self._text[self._i + 1 : end]
                self._i = end + 1
            else:
                j = self._i
                while j < len(self._text) and self._text[j] in _BARE:
                    j += 1
                name = self._text[self._i : j]
                self._i = j
            segments.append((name, start))
            self._skip_space(newlines=False)
            if self._peek() != ".":
                return segments
            self._i += 1

    def _key_value(self, prefix: Path) -> None:
        segments = self._key()
        path = prefix
        for name, start in segments:
            path += (name,)
            self._keys.setdefault(path, self._pos(start))
        self._skip_space(newlines=False)
        self._i += 1  # "="
        self._value(path)

    def _value(self, path: Path) -> None:
        self._skip_space(newlines=False)
        self._values[path] = self._pos(self._i)
        c = self._peek()
        if c == '"':
            if self._peek(3) == '"""':
                self._multiline('"""')
            else:
                self._basic_string()
        elif c == "'":
            if self._peek(3) == "'''":
                self._multiline("'''")
            else:
                self._i = self._text.index("'", self._i + 1) + 1
        elif c == "[":
            self._i += 1
            index = 0
            while True:
                self._skip_space(newlines=True)
                if self._peek() == "]":
                    self._i += 1
                    return
                self._value(path + (index,))
                index += 1
                self._skip_space(newlines=True)
                if self._peek() == ",":
                    self._i += 1
        elif c == "{":
            self._i += 1
            while True:
                self._skip_space(newlines=False)
                if self._peek() == "}":
                    self._i += 1
                    return
                self._key_value(path)
                self._skip_space(newlines=False)
                if self._peek() == ",":
                    self._i += 1
        else:  # number, bool, date-time: up to the next delimiter
            n = len(self._text)
            while self._i < n and self._text[self._i] not in ",]}\n#":
                self._i += 1

    def _basic_string(self) -> str:
        text = self._text
        j = self._i + 1
        out = []
        while text[j] != '"':
            if text[j] == "\\":
                out.append(text[j : j + 2])
                j += 2
            else:
                out.append(text[j])
                j += 1
        self._i = j + 1
        raw = "".join(out)
        if "\\" in raw:
            try:
                raw = raw.encode("latin-1", "backslashreplace").decode("unicode_escape")
            except UnicodeDecodeError:  # pragma: no cover - keys with exotic escapes
                pass
        return raw

    def _multiline(self, quote: str) -> None:
        text = self._text
        j = self._i + 3
        while True:
            if quote == '"""' and text[j] == "\\":
                j += 2
                continue
            if text.startswith(quote, j):
                j += 3
                while j < len(text) and text[j] == quote[0]:  # up to two quotes may end the content
                    j += 1
                self._i = j
                return
            j += 1
