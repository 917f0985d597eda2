"""Facts the core and the Python package share come from one place and agree: the core (statuses, columns)
or Python (the native scene dict's keys and defaults)."""

import copy
import re
from pathlib import Path

import numpy as np
import pytest

import warpviz as wv
from warpviz._native import core
from warpviz.render.render import DEFAULT_OPTIONS
from warpviz.scene.native import native_scene, schema_keys
from warpviz.scene.reader import key_name
from warpviz.tracing import default_max_drift


def test_ray_status_codes_are_the_cores():
    assert [s.name.lower() for s in wv.RayStatus] == list(core.status_names())
    assert [int(s) for s in wv.RayStatus] == list(range(len(core.status_names())))


def test_render_statistics_name_every_status():
    img = wv.render({"metric": {"name": "minkowski", "params": []},
                     "camera": {"position": [0, -5, 0], "look_at": [0, 0, 0], "width": 2, "height": 2},
                     "materials": [], "shapes": [], "environment": {"color": [0.1, 0.1, 0.1]}},
                    spp=1, progress=None)  # fmt: skip
    assert list(img.stats["segments_by_status"]) == list(core.status_names())


def test_recorded_columns_follow_the_metrics_invariants():
    for metric in (wv.Kerr(mass=1.0, spin=0.5), wv.EllisWormhole()):
        rays = wv.trace(metric, [0.0, -30.0, 0.0], [0.0, 1.0, 0.1], record=True)
        drift_columns = {k[: -len("_drift")] for k in rays.point_data if k.endswith("_drift")}
        assert drift_columns == set(metric.invariant_names[1:])


# ------------------------------------------------------------------------------ the native scene dict
# Its defaults live in Python (warpviz/scene/native.py, SCHEMA); the core's converter
# (renderer_ext/bindings/scene_dict.cpp) reads every key with a helper(table, "key", where) that has no
# default, so a key Python did not write fails there instead of silently taking a value of the core's.

REPO = Path(__file__).resolve().parents[1]
SCENE_DICT = REPO / "renderer_ext" / "bindings" / "scene_dict.cpp"
KEY_READ = re.compile(r'[\w:<>]+\(\s*[a-z]\w*\s*,\s*"([a-z_]+)"')  # helper(table, "key", ...), typed<T>(...)


def _code(path: Path) -> str:
    """C++ source without comments."""
    return re.sub(r"//[^\n]*", "", path.read_text())


def test_the_core_reads_exactly_the_native_scene_keys_python_writes():
    read = set(KEY_READ.findall(_code(SCENE_DICT)))
    assert read, "no key reads found in scene_dict.cpp: has the helper(table, \"key\", where) form changed?"
    assert read - schema_keys() == set(), "keys the core reads that warpviz.scene.native.SCHEMA does not write"
    assert schema_keys() - read == set(), "keys in warpviz.scene.native.SCHEMA that the core never reads"


def test_the_core_reads_scene_keys_only_through_its_helpers():
    code = _code(SCENE_DICT)
    assert code.count(".contains(") == 1, "the one presence check is in item(), which fails on a missing key"
    assert not re.findall(r'\w\["[a-z_]+"\]', code), "a key read by subscript, past the helpers"
    module = _code(REPO / "renderer_ext" / "bindings" / "module.cpp")
    assert not re.findall(r'\bscene(?:\.contains\(|\[")', module), "render() reads scene keys: scene_dict.cpp does"


def _scene_of_every_kind() -> dict:
    image = np.full((2, 3, 3), 0.5, dtype=np.float32)
    spot = {"direction": [0, 1, 0]}
    return native_scene({
        "metric": {"name": "minkowski", "params": []},
        "camera": {"position": [0, -6, 0], "look_at": [0, 0, 0], "width": 2, "height": 2},
        "textures": [{"type": "constant", "color": [1, 1, 1]}, {"type": "checker", "color_a": [1, 0, 0], "color_b": [0, 0, 1]},
                     {"type": "grid", "base": [1, 1, 1], "line_u": [1, 0, 0], "line_v": [0, 1, 0]},
                     {"type": "image", "data": image}],
        "materials": [{"type": "diffuse", "texture": 0}, {"type": "mirror"}, {"type": "glass"},
                      {"type": "emissive", "texture": 3}],
        "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": 0},
                   {"type": "quad", "corner": [-2, 2, -2], "edge_u": [4, 0, 0], "edge_v": [0, 0, 4], "material": 1},
                   {"type": "disk", "center": [0, 0, -1], "outer_radius": 3, "material": 3},
                   {"type": "mesh", "vertices": np.eye(3), "faces": np.array([[0, 1, 2]], dtype=np.int32),
                    "uvs": np.zeros((3, 2)), "material": 2}],
        "environment": {"image": image, "spots": [spot],
                        "stars": {"density": 10.0, "brightness": 1.0, "size": 0.01, "seed": 1}},
        "environment_other": {"spots": [spot]},
    })  # fmt: skip


def _key_paths(node, path=()):
    """Every key path of a native dict (through tables and lists, not into arrays)."""
    if isinstance(node, dict):
        for key, value in node.items():
            yield path + (key,)
            yield from _key_paths(value, path + (key,))
    elif isinstance(node, list):
        for i, value in enumerate(node):
            yield from _key_paths(value, path + (i,))


def _render_options() -> dict:
    options = dict(DEFAULT_OPTIONS, spp=1, threads=1, progress=None, record_pixels=None)
    options["max_drift"] = default_max_drift(options["tol"])
    return options


def test_the_core_has_no_default_for_any_native_scene_key():
    full = _scene_of_every_kind()
    core.render(full, _render_options())  # complete: renders
    paths = list(_key_paths(full))
    assert {p[-1] for p in paths if isinstance(p[-1], str)} == schema_keys()  # the scene has every key
    for path in paths:
        scene = copy.deepcopy(full)
        node = scene
        for part in path[:-1]:
            node = node[part]
        del node[path[-1]]
        name = f"scene.{path[0]}" if len(path) == 1 else key_name(path)
        with pytest.raises(ValueError, match=re.escape(f"'{name}' is missing")):
            core.render(scene, _render_options())
