"""Facts the core and the Python package share come from one place and agree: the core (statuses, columns,
the camera) or Python (the native scene dict's keys and defaults)."""

import copy
import math
import re
from pathlib import Path

import numpy as np
import pytest

import warpviz as wv
from warpviz._native import core
from warpviz.options import DETAIL_SAMPLES, EDGE_SAMPLES
from warpviz.render.render import DEFAULT_OPTIONS, FILTER_RADII
from warpviz.scene.camera import camera_basis, pinhole_directions
from warpviz.scene.native import native_camera, native_scene, schema_keys
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
        "lights": [{"type": "point", "position": [0, 0, 2], "intensity": 1.0},
                   {"type": "spot", "position": [0, 0, 2], "intensity": 1.0, "direction": [0, 0, -1]}],
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
    options = dict(DEFAULT_OPTIONS, spp=1, sample_begin=0, threads=1, progress=None, record_pixels=None)
    options["max_drift"] = default_max_drift(options["tol"])
    options["filter_radius"] = FILTER_RADII[options["filter"]]
    options["edge_samples"], options["detail_samples"] = EDGE_SAMPLES, DETAIL_SAMPLES
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


def test_python_camera_directions_are_the_renderers():
    cam = {"position": [1.0, -8.0, 2.0], "look_at": [0.0, 0.0, 0.5], "up": [0, 0, 1], "fov": 35.0, "width": 40,
           "height": 30}  # fmt: skip
    pixels = np.array([[0, 0], [39, 29], [20, 15], [7, 22]])
    # pinhole_directions is the core's camera (integrators/camera.h), bit for bit
    _, directions = core.camera_rays("minkowski", [], native_camera(cam), pixels + 0.25)
    np.testing.assert_array_equal(pinhole_directions(cam, pixels, jitter=(0.25, 0.25)), directions)
    # ... and the renderer's flat-space camera rays are its directions at their samples' jitter
    scene = {"metric": {"name": "minkowski"}, "camera": cam, "materials": [], "shapes": []}
    rays = wv.render(scene, spp=4, record_pixels=pixels, progress=None).rays
    forward, right, up = camera_basis(cam)
    tan_half = math.tan(math.radians(cam["fov"]) / 2)
    camera_segments = np.flatnonzero(rays.ray_data["kind"] == 0)
    assert len(camera_segments) == 4 * len(pixels)
    for i in camera_segments:
        pts = rays.ray_points(i)
        d = (pts[-1] - pts[0]) / np.linalg.norm(pts[-1] - pts[0])
        x, y = rays.ray_data["pixel_x"][i], rays.ray_data["pixel_y"][i]
        jitter = ((d @ right / (d @ forward) / (tan_half * 40 / 30) + 1) * 20 - x,
                  (1 - d @ up / (d @ forward) / tan_half) * 15 - y)  # fmt: skip
        assert 0 <= jitter[0] < 1 and 0 <= jitter[1] < 1
        np.testing.assert_allclose(pinhole_directions(cam, [x, y], jitter=jitter)[0], d, rtol=0, atol=1e-12)


def test_python_has_no_camera_arithmetic_of_its_own():
    source = (REPO / "warpviz" / "scene" / "camera.py").read_text()
    code = "\n".join(line for line in source.splitlines() if not line.lstrip().startswith((">>>", "#")))
    code = re.sub(r'"""[\s\S]*?"""', "", code)
    assert "tan(" not in code and "cross(" not in code, "warpviz/scene/camera.py: the pinhole is the core's"


def test_the_cores_camera_in_curved_space():
    cam = native_camera({"position": [0, -30, 1], "look_at": [0, 0, 0], "width": 4, "height": 3})
    frame, d = core.camera_rays("kerr", [1.0, 0.9], cam, np.array([[2.0, 1.5], [0.0, 0.0]]))
    np.testing.assert_allclose(frame @ frame.T, np.eye(3), atol=1e-12)  # orthonormal in the local frame
    np.testing.assert_allclose(d[0], frame[0], rtol=0, atol=1e-15)  # the image centre looks forward
    with pytest.raises(ValueError, match="inside the horizon"):
        core.camera_rays("schwarzschild", [1.0], {**cam, "position": [0.0, 0.5, 0.0]}, np.zeros((0, 2)))
