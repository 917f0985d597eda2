"""The C++ core's layers only include downward, and the Python package's only import downward
(docs/architecture.md).

C++: core < spacetime < scene < film < integrators < engine < metrics, bindings. A file may include files of
its own layer and of lower ones; nothing includes a metric file (they are top-floor plugins). This test reads
every #include "..." under renderer_ext/ and fails on one that points up.

Python: _native, io, limits, options < spacetime < tracing < scene < render < export < viewer < web < the package root < cli. A
module may import modules of its own layer and of lower ones, at module level or inside a function; the one
exception is reading ``__version__`` from the package root. This test reads every import of warpviz/.
"""

import ast
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1] / "renderer_ext"
LAYERS = ["core", "spacetime", "scene", "film", "integrators", "engine", "metrics", "bindings"]
RANK = {name: i for i, name in enumerate(LAYERS)}
RANK["bindings"] = RANK["metrics"]  # the two top floors, beside each other: neither includes the other
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)


def sources():
    return sorted(p for p in ROOT.rglob("*") if p.suffix in (".h", ".cpp"))


def layer_of(relative: str) -> str:
    return relative.split("/", 1)[0]


def test_every_source_file_is_in_a_known_layer():
    unknown = [str(p.relative_to(ROOT)) for p in sources() if layer_of(str(p.relative_to(ROOT))) not in RANK]
    assert not unknown, f"files outside the layers {LAYERS}: {unknown}"


def upward_includes(relative: str, text: str) -> list[str]:
    """The includes of file `relative` (path under renderer_ext/) with contents `text` that break the rule."""
    here = layer_of(relative)
    bad = []
    for target in INCLUDE.findall(text):
        there = layer_of(target)
        if there not in RANK or there == "metrics" or (there != here and RANK[there] >= RANK[here]):
            bad.append(target)
    return bad


@pytest.mark.parametrize("path", sources(), ids=lambda p: str(p.relative_to(ROOT)))
def test_includes_point_down(path):
    relative = str(path.relative_to(ROOT))
    text = path.read_text()
    for target in INCLUDE.findall(text):
        assert (ROOT / target).exists(), f"{relative} includes missing {target!r}"
    bad = upward_includes(relative, text)
    assert not bad, f"{relative} ({layer_of(relative)}) includes {bad}: upward (layers: {' < '.join(LAYERS)})"


def test_the_checker_refuses_upward_and_sideways_top_floor_includes():
    assert upward_includes("spacetime/x.h", '#include "integrators/path_tracer.h"') == ["integrators/path_tracer.h"]
    assert upward_includes("engine/x.h", '#include "metrics/kerr.cpp"') == ["metrics/kerr.cpp"]
    assert upward_includes("bindings/x.cpp", '#include "metrics/kerr.cpp"') == ["metrics/kerr.cpp"]
    assert upward_includes("core/x.h", '#include "elsewhere/y.h"') == ["elsewhere/y.h"]
    ok = '#include "core/simd.h"\n#include "spacetime/metric.h"\n#include "engine/register.h"\n'
    assert upward_includes("metrics/x.cpp", ok) == []
    assert upward_includes("spacetime/x.h", '#include "spacetime/frame.h"') == []


# ------------------------------------------------------------------------------------------ Python
PACKAGE = Path(__file__).resolve().parents[1] / "warpviz"
PY_LAYERS = ["_native", "spacetime", "tracing", "scene", "render", "animate", "export", "viewer", "web", "__init__", "cli"]
PY_RANK = {name: i for i, name in enumerate(PY_LAYERS)}
# the floor: the core, file formats, limits and the table of render options
PY_RANK["_core"] = PY_RANK["io"] = PY_RANK["limits"] = PY_RANK["options"] = PY_RANK["_native"]


def modules():
    return sorted(PACKAGE.rglob("*.py"))


def py_layer_of(dotted: str) -> str:
    """Layer of a module name such as ``warpviz.scene.loader`` (``warpviz`` alone: the package root)."""
    parts = dotted.split(".")
    return parts[1] if len(parts) > 1 else "__init__"


def module_name(path: Path) -> str:
    parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def upward_imports(name: str, text: str) -> list[str]:
    """The imports of module ``name`` (dotted) with source ``text`` that point to a higher layer."""
    here = "__init__" if name == "warpviz" else py_layer_of(name)
    bad = []
    for node in ast.walk(ast.parse(text)):
        if isinstance(node, ast.Import):
            targets = [(a.name, None) for a in node.names]
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            targets = [(node.module, [a.name for a in node.names])]
        else:
            continue
        if targets[0][0] == "warpviz" and targets[0][1]:  # from warpviz import _core, cli, __version__, ...
            targets = [(f"warpviz.{n}", None) for n in targets[0][1]]
        for target, _ in targets:
            if target.split(".")[0] != "warpviz":
                continue
            if target == "warpviz.__version__":
                continue  # the version string of the package root, read when a file is written
            there = py_layer_of(target)
            if there not in PY_RANK or PY_RANK[there] > PY_RANK[here]:
                bad.append(target)
    return bad


def test_every_python_module_is_in_a_known_layer():
    unknown = [module_name(p) for p in modules() if py_layer_of(module_name(p)) not in PY_RANK]
    assert not unknown, f"modules outside the layers {PY_LAYERS}: {unknown}"


@pytest.mark.parametrize("path", modules(), ids=lambda p: str(p.relative_to(PACKAGE.parent)))
def test_python_imports_point_down(path):
    name = module_name(path)
    bad = upward_imports(name, path.read_text())
    assert not bad, f"{name} imports {bad}: upward (layers: {' < '.join(PY_LAYERS)})"


def test_the_python_checker_refuses_upward_imports():
    assert upward_imports("warpviz.tracing.rays", "from warpviz.export import save_scene_vtm") == ["warpviz.export"]
    assert upward_imports("warpviz.spacetime.x", "def f():\n    import warpviz.viewer.viewer\n") == [
        "warpviz.viewer.viewer"]
    assert upward_imports("warpviz.render.image", "from warpviz import Image") == ["warpviz.Image"]
    assert upward_imports("warpviz.io", "from warpviz.elsewhere import y") == ["warpviz.elsewhere"]
    ok = "from warpviz._native import core\nfrom warpviz.io import atomic_write\nfrom warpviz.scene import textures\n"
    assert upward_imports("warpviz.scene.appearance", ok) == []
    assert upward_imports("warpviz.tracing.rays", "from warpviz import __version__") == []
    assert upward_imports("warpviz", "from warpviz.viewer import view") == []
    assert upward_imports("warpviz.cli", "import warpviz") == []


def test_no_python_module_imports_one_that_imports_it():
    """No cycles between modules, not even through an import inside a function (the scene model once
    imported its loader lazily while the loader imported the model)."""
    graph = {}
    for path in modules():
        name = module_name(path)
        targets = set()
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom) and node.level == 0 and node.module and node.module.startswith("warpviz"):
                for alias in node.names:  # "from warpviz.scene import primitives" imports a module of its own
                    sub = f"{node.module}.{alias.name}"
                    targets.add(sub if (PACKAGE.parent / sub.replace(".", "/")).with_suffix(".py").is_file() else node.module)
            elif isinstance(node, ast.Import):
                targets |= {a.name for a in node.names if a.name.startswith("warpviz")}
        graph[name] = targets - {"warpviz"}  # the package root's __version__ is read by the file writers
    cycles = sorted((a, b) for a, targets in graph.items() for b in targets
                    if b != a and a in graph.get(b, ()) and a < b and a != "warpviz")  # fmt: skip
    assert not cycles, f"modules that import each other: {cycles}"
