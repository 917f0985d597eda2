"""The C++ core's layers only include downward (docs/architecture.md).

core < spacetime < scene < film < integrators < engine < metrics, bindings. A file may include files of its
own layer and of lower ones; nothing includes a metric file (they are top-floor plugins). This test reads
every #include "..." under renderer_ext/ and fails on one that points up.
"""

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
