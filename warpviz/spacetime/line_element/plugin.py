"""Compiling a generated metric file into a plugin and loading it into the core's registry.

A plugin (``renderer_ext/engine/plugin.h``) is the metric file of :func:`~.codegen.metric_source` compiled
with the system C++ compiler against the core's own headers (shipped in the wheel as ``warpviz/include``;
an editable install uses the repository's ``renderer_ext``) and with the core's optimisation flags, so its
rays are traced by the same code as a built-in metric's. It is built in parts that are compiled in parallel
and only when needed:

- ``facts``: the registry entry, landmarks and the three tracers (``trace``);
- ``rk4``, ``dopri5``, ``dop853``: the path tracer with that stepper (``render``).

Each part is one shared library in the cache, named by the hash of everything that decides its bits (the
source, the part, the headers, the compiler and its flags, the core's layout key), written under a
temporary name and renamed into place: the cache is safe to share between processes and users, and a
changed header or compiler gives a new name instead of a stale library. The directory is
``$WARPVIZ_CACHE_DIR/metrics``, else ``$XDG_CACHE_HOME/warpviz/metrics``, else ``~/.cache/warpviz/metrics``.

The plugin is compiled for the instruction set of the batch kernel this machine runs (the core chooses
among AVX-512, AVX2 and baseline at load time and compiles all three; a plugin only needs this machine's,
which makes its build about twice as fast), and that instruction set is part of the hash, so a shared cache
never hands a machine a library its CPU cannot run. Results are bit-identical either way
(``-ffp-contract=off``, no fast math).
"""

from __future__ import annotations

import functools
import hashlib
import os
import shlex
import shutil
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Sequence
from pathlib import Path

from warpviz._native import core

__all__ = ["PARTS", "CompilerNotFoundError", "PluginBuildError", "cache_dir", "build_parts", "load_parts",
           "find_compiler"]  # fmt: skip

#: The parts of a plugin and the WARPVIZ_STEPPERS bits that select them (engine/register.h).
PARTS = {"facts": 1, "rk4": 2, "dopri5": 4, "dop853": 8}

_INSTALL_HINT = ("Install one (Debian/Ubuntu: apt-get install g++; Fedora: dnf install gcc-c++; macOS: "
                 "xcode-select --install; conda: conda install -c conda-forge cxx-compiler) or set CXX "
                 "to its path.")  # fmt: skip


class CompilerNotFoundError(RuntimeError):
    """No C++ compiler to build a metric from its line element (the message says what to install)."""


class PluginBuildError(RuntimeError):
    """A plugin could not be built: the cache folder cannot be written (the message says how to choose
    another), or the compiler refused a generated metric file (a warpviz bug: the message holds its
    diagnostics)."""


def cache_dir() -> Path:
    """Where compiled metric plugins are kept (module docstring)."""
    if os.environ.get("WARPVIZ_CACHE_DIR"):
        return Path(os.environ["WARPVIZ_CACHE_DIR"]) / "metrics"
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "warpviz" / "metrics"


def find_compiler() -> list[str]:
    """The C++ compiler command: ``$CXX`` (which may carry flags), else ``c++``, ``g++`` or ``clang++``.

    Raises
    ------
    CompilerNotFoundError
        None found, saying what to install.
    """
    if os.environ.get("CXX"):
        cmd = shlex.split(os.environ["CXX"])
        if cmd and shutil.which(cmd[0]):
            return cmd
        raise CompilerNotFoundError(f"CXX={os.environ['CXX']!r} is not a command this machine has. {_INSTALL_HINT}")
    for name in ("c++", "g++", "clang++"):
        path = shutil.which(name)
        if path:
            return [path]
    raise CompilerNotFoundError("a metric given by its line element is compiled into a plugin on first use, "
                                f"and no C++ compiler (c++, g++, clang++) was found. {_INSTALL_HINT}")  # fmt: skip


@functools.lru_cache(maxsize=None)
def _compiler_identity(cmd: tuple[str, ...]) -> str:
    try:
        out = subprocess.run([*cmd, "--version"], capture_output=True, text=True, timeout=60)
    except OSError as exc:  # pragma: no cover - a compiler that exists but cannot run
        raise CompilerNotFoundError(f"the C++ compiler {cmd[0]} cannot be run: {exc}. {_INSTALL_HINT}") from exc
    return (out.stdout or out.stderr).splitlines()[0] if (out.stdout or out.stderr) else cmd[0]


def include_dir() -> Path:
    """The core's headers: the wheel's ``warpviz/include``, else the source tree's ``renderer_ext``."""
    package = Path(__file__).resolve().parents[2]
    for candidate in (package / "include", package.parent / "renderer_ext"):
        if (candidate / "engine" / "plugin.h").is_file():
            return candidate
    raise RuntimeError(f"warpviz's C++ headers are missing (looked in {package / 'include'} and "
                       f"{package.parent / 'renderer_ext'}): reinstall warpviz")  # fmt: skip


@functools.lru_cache(maxsize=4)
def _headers_hash(include: Path) -> str:
    h = hashlib.sha256()
    for path in sorted(p for p in include.rglob("*") if p.suffix in (".h", ".cpp") and p.name != "registry.cpp"):
        if path.parent.name in ("metrics", "bindings"):
            continue
        h.update(str(path.relative_to(include)).encode())
        h.update(path.read_bytes())
    return h.hexdigest()


def _isa_flags() -> list[str]:
    """Flags for this machine's batch-kernel instruction set (the target the core's clones chose)."""
    target = core.build_info()["lane_target"]
    if target.startswith("arch="):
        return [f"-march={target[5:]}", "-DWARPVIZ_NO_CLONES"]
    if target == "default":
        return ["-DWARPVIZ_NO_CLONES"]
    return [f"-m{target}", "-DWARPVIZ_NO_CLONES"]


def _command(cxx: list[str], include: Path, source: Path, mask: int, output: Path) -> list[str]:
    flags = shlex.split(core.build_info()["flags"])  # the core's optimisation flags, one definition (CMake)
    return [*cxx, "-std=c++20", *flags, *_isa_flags(), "-fPIC", "-shared", "-pthread", "-fvisibility=hidden",
            "-fvisibility-inlines-hidden", "-Wno-psabi", f"-DWARPVIZ_STEPPERS={mask}", f"-I{include}",
            str(source), str(include / "engine" / "plugin_entry.cpp"), "-o", str(output)]  # fmt: skip


def _part_key(source: str, part: str, cxx: list[str], include: Path) -> str:
    h = hashlib.sha256()
    for piece in (source, part, _compiler_identity(tuple(cxx)), " ".join(cxx), core.build_info()["flags"],
                  " ".join(_isa_flags()), _headers_hash(include), core.plugin_abi_key()):  # fmt: skip
        h.update(piece.encode())
        h.update(b"\0")
    return h.hexdigest()[:24]


def build_parts(source: str, parts: Sequence[str], *,
                progress: Callable[[str], None] | None = None) -> dict[str, Path]:  # fmt: skip
    """The compiled plugin libraries of ``source`` for ``parts``, compiling those not in the cache in parallel.

    Parameters
    ----------
    source : str
        A metric file (:func:`~.codegen.metric_source` with ``register=True``).
    parts : sequence of str
        Keys of :data:`PARTS`.
    progress : callable, optional
        Called with one line before a compilation starts (how many parts, why it takes a while) and one
        after; by default those lines go to standard error when it is a terminal.

    Returns
    -------
    dict of str to Path
        Each part's shared library.

    Raises
    ------
    CompilerNotFoundError, PluginBuildError
    """
    unknown = [p for p in parts if p not in PARTS]
    if unknown:
        raise ValueError(f"unknown plugin part(s) {unknown}; parts are {list(PARTS)}")
    cxx = find_compiler()
    include = include_dir()
    folder = cache_dir()
    out = {p: folder / f"{_part_key(source, p, cxx, include)}-{p}.so" for p in parts}
    todo = [p for p in parts if not out[p].is_file()]
    if not todo:
        return out
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise PluginBuildError(f"cannot create the metric cache {folder}: {exc.strerror or exc}; set "
                               "WARPVIZ_CACHE_DIR to a folder you can write") from None  # fmt: skip
    if progress is None and sys.stderr is not None and sys.stderr.isatty():
        progress = lambda line: print(f"warpviz: {line}", file=sys.stderr, flush=True)  # noqa: E731
    if progress:
        progress(f"compiling the metric's {', '.join(todo)} part{'s' if len(todo) > 1 else ''} with {cxx[0]} "
                 f"(first use only, about 20 s; cached in {folder})")  # fmt: skip
    start = time.perf_counter()
    with tempfile.TemporaryDirectory(dir=folder, prefix=".build-") as tmp:
        src = Path(tmp) / "metric.cpp"
        src.write_text(source)
        jobs = {}
        for p in todo:
            target = Path(tmp) / out[p].name
            cmd = _command(cxx, include, src, PARTS[p], target)
            jobs[p] = (subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True), target)
        failed = []
        for p, (proc, target) in jobs.items():
            log, _ = proc.communicate()
            if proc.returncode != 0:
                failed.append(f"part {p}: exit {proc.returncode}\n{log[-4000:]}")
            else:
                os.replace(target, out[p])  # atomic: another process sees the whole library or none
        if failed:
            (folder / "last-failure.cpp").write_text(source)
            raise PluginBuildError("the C++ compiler refused a generated metric file (a warpviz bug; the source is "
                                   f"in {folder / 'last-failure.cpp'}):\n" + "\n".join(failed))  # fmt: skip
    if progress:
        progress(f"compiled in {time.perf_counter() - start:.1f} s")
    return out


def load_parts(source: str, parts: Sequence[str], *, progress: Callable[[str], None] | None = None) -> list[str]:
    """Builds (or finds in the cache) and loads ``parts`` of the plugin of ``source``, facts first.

    Returns
    -------
    list of str
        The registry names the loaded parts added (the metric's name when ``facts`` was loaded now).
    """
    ordered = sorted(parts, key=list(PARTS).index)
    libraries = build_parts(source, ordered, progress=progress)
    names: list[str] = []
    for p in ordered:
        names += core.load_metric_plugin(str(libraries[p]))
    return names
