"""Build warpviz's wheel and check that it works on its own: the shipped scenes (with their meshes and
textures) inside it, the README's main job (``warpviz render fig02``) run from the installed files alone.

Usage: ``python tools/check_wheel.py [--keep FOLDER]``. ``.ci/run`` runs it after the tests.

The wheel is built by pip (an isolated build, as ``pip install .`` does) and unpacked into a folder of its
own; the checks run in a Python started with ``-S`` and that folder first on its path, so neither the
editable install of the checkout nor the repository's ``scenes/`` folder can stand in for what the wheel
carries (the dependencies, numpy, VTK and the rest, come from this environment's site-packages).
Exit 0 when every check passes; 1 with what failed.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import sysconfig
import tempfile
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

#: What the unpacked wheel must contain, relative to its root.
MUST_CONTAIN = ["warpviz/scenes/fig02_accretion_disk.toml", "warpviz/scenes/fig13_wormhole_room_side.toml",
                "warpviz/scenes/meshes/satellite_panels.obj", "warpviz/scenes/textures/accretion_disk.png",
                "warpviz/include/engine/plugin.h", "warpviz/include/engine/plugin_entry.cpp",
                "warpviz/include/integrators/path_tracer.h"]  # fmt: skip

#: Run in the unpacked wheel: where warpviz and its scenes come from, then the README's main job.
PROBE = """
import sys
import warpviz
from warpviz.scene.catalog import resolve_scene, shipped_scenes
print("package", warpviz.__file__)
print("scene", resolve_scene("fig02"))
print("scenes", len(shipped_scenes()))
from warpviz.spacetime.line_element.plugin import include_dir
print("headers", include_dir())  # a line element's plugin is built against the wheel's own headers
from warpviz.cli import main
sys.argv = ["warpviz", "render", "fig02", "-o", sys.argv[1], "--size", "64x48", "--spp", "1", "-q"]
main()
"""


def _run(cmd: list[str], **kw) -> subprocess.CompletedProcess:
    print("$", " ".join(cmd), flush=True)
    return subprocess.run(cmd, text=True, capture_output=True, **kw)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--keep", type=Path, default=None, help="build and unpack into this folder and keep it")
    args = parser.parse_args(argv)
    work = args.keep or Path(tempfile.mkdtemp(prefix="warpviz-wheel-"))
    work.mkdir(parents=True, exist_ok=True)
    built = _run([sys.executable, "-m", "pip", "wheel", "--no-deps", "-w", str(work / "dist"), str(ROOT)])
    wheels = sorted((work / "dist").glob("warpviz-*.whl"))
    if built.returncode != 0 or not wheels:
        print(built.stdout[-4000:], built.stderr[-4000:], sep="\n", file=sys.stderr)
        print("FAILED: the wheel did not build", file=sys.stderr)
        return 1
    site = work / "site"
    with zipfile.ZipFile(wheels[-1]) as wheel:
        names = set(wheel.namelist())
        missing = [name for name in MUST_CONTAIN if name not in names]
        wheel.extractall(site)
    print(f"{wheels[-1].name}: {len(names)} files")
    if missing:
        print(f"FAILED: the wheel lacks {', '.join(missing)}", file=sys.stderr)
        return 1
    out = work / "fig02.png"
    deps = sysconfig.get_paths()["purelib"], sysconfig.get_paths()["platlib"]
    env = {"PYTHONPATH": ":".join([str(site), *dict.fromkeys(deps)]), "PATH": "/usr/bin:/bin",
           "PYVISTA_OFF_SCREEN": "true", "HOME": str(work)}  # fmt: skip
    probe = _run([sys.executable, "-S", "-c", PROBE, str(out)], cwd=work, env=env)
    print(probe.stdout, probe.stderr, sep="\n")
    lines = dict(line.split(" ", 1) for line in probe.stdout.splitlines() if " " in line)
    problems = []
    if probe.returncode != 0:
        problems.append(f"the main job exited with {probe.returncode}")
    if not lines.get("package", "").startswith(str(site)):
        problems.append(f"warpviz was imported from {lines.get('package')!r}, not from the unpacked wheel")
    if not lines.get("scene", "").startswith(str(site)):
        problems.append(f"fig02 was found at {lines.get('scene')!r}, not in the wheel")
    if not lines.get("headers", "").startswith(str(site)):
        problems.append(f"the C++ headers for line-element plugins are {lines.get('headers')!r}, not the wheel's")
    if not out.is_file():
        problems.append("no fig02.png was written")
    if problems:
        print("FAILED: " + "; ".join(problems), file=sys.stderr)
        return 1
    print(f"the wheel works on its own: {lines['scenes']} shipped scenes, fig02 rendered to {out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
