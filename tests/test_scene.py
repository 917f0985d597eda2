"""Scene files: every shipped scene loads into a well-formed native dict, and bad input is reported at
the right file:line:column with the key path."""

from __future__ import annotations

import re
import textwrap

import numpy as np
import pytest

import warpviz as wv
from warpviz.scene import AOV_NAMES, RENDER_OPTION_KEYS, SceneError, load_scene, scene_from_dict
from warpviz.scene.catalog import resolve_scene, shipped_scenes

SHIPPED = shipped_scenes()

FIGURES = ["fig02", "fig03", "fig04", "fig05", "fig06a", "fig06b", "fig07", "fig08", "fig09", "fig10a", "fig10b",
           "fig10c", "fig10d", "fig10e", "fig11a", "fig11b", "fig12", "fig13"]  # fmt: skip


def test_one_scene_per_paper_figure():
    stems = [p.stem for p in SHIPPED]
    for fig in FIGURES:
        assert sum(s.startswith(fig + "_") for s in stems) == 1, fig
    # besides the figures, the peer-comparison scene (benchmarks/), the library of line-element metrics
    # (docs/line-element.md) and the caustic scenes (benchmarks/bench_caustics.py)
    assert sorted(s for s in stems if not s.startswith(("fig", "line_element_", "caustics_"))) == ["mitsuba_cornell"]
    assert sorted(s for s in stems if s.startswith("caustics_")) == ["caustics_glass_ball", "caustics_glass_ball_hole",
                                                                    "caustics_gravitational_focus"]
    assert len([s for s in stems if s.startswith("line_element_")]) >= 4


def _check_vec(v, n=3):
    assert isinstance(v, list) and len(v) == n and all(isinstance(x, float) and np.isfinite(x) for x in v), v


def check_native(native: dict) -> None:
    """Assert that ``native`` has exactly the structure of docs/native-scene.md, every key written."""
    assert set(native) == {"metric", "camera", "textures", "materials", "shapes", "lights", "environment",
                           "environment_other"}
    for li in native["lights"]:
        assert li["type"] in ("point", "spot") and li["sheet"] in (1, -1) and li["intensity"] >= 0
        _check_vec(li["position"]), _check_vec(li["color"])
        if li["type"] == "spot":
            _check_vec(li["direction"])
            assert 0 < li["angle"] <= 180 and 0 <= li["falloff"] <= li["angle"]
    registry = {m["name"]: m["params"] for m in wv.registered_metrics()}
    metric = native["metric"]
    assert metric["name"] in registry and len(metric["params"]) == len(registry[metric["name"]])
    cam = native["camera"]
    assert set(cam) == {"position", "look_at", "up", "fov", "width", "height", "sheet", "observer", "shift"}
    for k in ("position", "look_at", "up"):
        _check_vec(cam[k])
    assert 0 < cam["fov"] < 180 and cam["sheet"] in (1, -1)
    assert isinstance(cam["width"], int) and isinstance(cam["height"], int) and cam["width"] > 0 and cam["height"] > 0
    for t in native["textures"]:
        if t["type"] == "constant":
            _check_vec(t["color"])
        elif t["type"] == "checker":
            _check_vec(t["color_a"]), _check_vec(t["color_b"]), _check_vec(t["scale"], 2)
        elif t["type"] == "grid":
            for k in ("base", "line_u", "line_v"):
                _check_vec(t[k])
            _check_vec(t["cells"], 2)
            assert all(c >= 1 and c == int(c) for c in t["cells"]) and 0 < t["width"] < 1
        else:
            assert t["type"] == "image"
            data = t["data"]
            assert data.dtype == np.float32 and data.ndim == 3 and data.shape[2] == 3 and np.isfinite(data).all()
            _check_vec(t["repeat"], 2)
    n_tex = len(native["textures"])
    for m in native["materials"]:
        assert m["type"] in ("diffuse", "mirror", "glass", "emissive")
        if m["type"] in ("diffuse", "emissive"):
            assert 0 <= m["texture"] < n_tex
        if m["type"] == "emissive":
            assert m["strength"] >= 0 and all(isinstance(m[k], bool) for k in ("two_sided", "keplerian", "beaming"))
        if m["type"] == "glass":
            assert m["ior"] >= 1
    n_mat = len(native["materials"])
    for s in native["shapes"]:
        assert 0 <= s["material"] < n_mat and s["sheet"] in (1, -1)
        if s["type"] == "sphere":
            _check_vec(s["center"]), _check_vec(s["pole"]), _check_vec(s["meridian"])
            assert s["radius"] > 0
        elif s["type"] == "quad":
            for k in ("corner", "edge_u", "edge_v"):
                _check_vec(s[k])
        elif s["type"] == "disk":
            _check_vec(s["center"]), _check_vec(s["normal"])
            assert 0 <= s["inner_radius"] < s["outer_radius"]
        else:
            assert s["type"] == "mesh"
            v, f, uv = s["vertices"], s["faces"], s["uvs"]
            assert v.dtype == np.float64 and v.ndim == 2 and v.shape[1] == 3
            assert f.dtype == np.int32 and f.ndim == 2 and f.shape[1] == 3 and 0 <= f.min() and f.max() < len(v)
            assert uv is None or (uv.dtype == np.float64 and uv.shape == (len(v), 2))
    for key in ("environment", "environment_other"):
        env = native[key]
        assert set(env) == {"color", "image", "stars", "spots"}
        _check_vec(env["color"])
        assert env["image"] is None or (env["image"].dtype == np.float32 and env["image"].shape[2] == 3)
        assert env["stars"] is None or set(env["stars"]) == {"density", "brightness", "size", "seed"}
        for spot in env["spots"]:
            _check_vec(spot["direction"]), _check_vec(spot["color"])
            assert abs(np.linalg.norm(spot["direction"]) - 1) < 1e-12 and spot["radius"] > 0


@pytest.mark.parametrize("path", SHIPPED, ids=[p.stem for p in SHIPPED])
def test_shipped_scene_loads_and_is_well_formed(path):
    text = path.read_text()
    assert text.startswith("# "), "each shipped scene starts with a comment saying what it shows"
    scene = load_scene(path)
    assert scene.path == path and scene.description and "\n" not in scene.description
    native = scene.native()
    check_native(native)
    assert (native["camera"]["width"], native["camera"]["height"]) == scene.size()
    w, h = scene.size()
    assert w * h <= 96 * 72, "default size stays tiny"
    assert set(scene.render_settings()) <= set(RENDER_OPTION_KEYS)
    paper = scene.native(paper=True)["camera"]
    assert paper["width"] >= 800 and scene.render_settings(paper=True)["spp"] >= scene.render_settings().get("spp", 1)
    check_native(scene.native(flat=True))
    assert scene.native(flat=True)["metric"] == {"name": "minkowski", "params": []}
    assert scene.outputs["aovs"] is None or set(scene.outputs["aovs"]) <= set(AOV_NAMES)


@pytest.mark.parametrize("path", SHIPPED, ids=[p.stem for p in SHIPPED])
def test_shipped_scene_renders_tiny(path):
    img = wv.render(load_scene(path), width=16, height=12, spp=1, threads=2)
    assert img.completed
    assert img.rgb.shape == (12, 16, 3) and img.rgb.dtype == np.float32
    assert np.isfinite(img.rgb).all() and (img.rgb >= 0).all()
    assert img.rgb.max() > 0, "something in every figure is lit"


def test_scene_values_reach_the_native_dict():
    scene = load_scene("fig10d")
    assert scene.metric == wv.Kerr(mass=scene.metric.mass, spin=0.9)
    assert scene.metric.horizon_radius == pytest.approx(5.0, rel=1e-12)
    native = scene.native(width=33, height=21)
    assert native["metric"] == {"name": "kerr", "params": [scene.metric.mass, 0.9]}
    assert (native["camera"]["width"], native["camera"]["height"]) == (33, 21)
    assert native["camera"]["position"] == [0.0, -110.0, 0.0]
    assert scene.render_settings() == {"spp": 8, "seed": 1, "max_depth": 6, "photons_per_pixel": 0.3}
    assert scene.render_settings(paper=True) == {"spp": 1024, "seed": 1, "max_depth": 6, "photons_per_pixel": 0.3}
    assert scene.size(paper=True) == (1024, 768)
    # a returned dict is a copy: changing it does not change the scene
    native["camera"]["position"][0] = 99.0
    assert scene.native()["camera"]["position"][0] == 0.0
    with pytest.raises(ValueError, match=r"width must be an integer in \[1, 65536\], got 0"):
        scene.native(width=0)


def test_wormhole_flat_keeps_the_camera_sheet():
    room_side, space_side = load_scene("fig13"), load_scene("fig12")
    both = room_side.native()
    assert {s["sheet"] for s in both["shapes"]} == {1, -1} and "environment_other" in both
    flat = room_side.native(flat=True)
    assert len(flat["shapes"]) == sum(s["sheet"] == 1 for s in both["shapes"])
    assert flat["environment_other"] is flat["environment"]  # flat space: one sheet, one sky
    flat_space = space_side.native(flat=True)
    assert flat_space["camera"]["sheet"] == 1 and all(s["sheet"] == 1 for s in flat_space["shapes"])
    assert len(flat_space["shapes"]) == sum(s["sheet"] == -1 for s in space_side.native()["shapes"])
    assert flat_space["environment"]["stars"] == space_side.native()["environment_other"]["stars"]


def test_shipped_scenes_by_name():
    assert resolve_scene("fig07").name == "fig07_schwarzschild_cornell.toml"
    assert resolve_scene("fig10c_kerr_cornell_a06").name == "fig10c_kerr_cornell_a06.toml"
    assert load_scene("fig06b").metric == wv.Kerr(mass=1.0, spin=0.9)
    with pytest.raises(SceneError, match="ambiguous: fig10a_kerr_cornell_a0, fig10b"):
        load_scene("fig10")
    with pytest.raises(SceneError, match="did you mean fig03_cornell_flat"):
        load_scene("fig03_cornell_flt")
    with pytest.raises(SceneError, match="no such scene file"):
        load_scene("missing/dir/scene.toml")


# ------------------------------------------------------------------------------------------ bad input
GOOD = """\
version = 1
description = "a test scene"

[metric]
name = "kerr"
mass = 1.0
spin = 0.5

[camera]
position = [0.0, -30.0, 0.0]
fov = 40.0

[environment]
stars = { density = 100.0, seed = 3 }
spots = [
  { direction = [0, 1, 0], radius = 0.05 },
  { direction = [1, 1, 0], radius = 0.02 },
]

[textures.tiles]
type = "grid"
cells = [4, 4]

[materials.white]
type = "diffuse"
texture = "tiles"

[materials.lamp]
type = "emissive"
strength = 2.0

[[objects]]
shape = "sphere"
center = [0.0, 10.0, 0.0]
radius = 2.0
material = "white"

[[objects]]
shape = "quad"
corner = [-1.0, 12.0, 5.0]
edge_u = [2.0, 0.0, 0.0]
edge_v = [0.0, 2.0, 0.0]
material = "lamp"
"""


def write(tmp_path, text, name="scene.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def expected_position(text: str, marker: str, occurrence: int = 1) -> tuple[int, int]:
    """1-based line and column of the ``occurrence``-th ``marker`` in ``text``, found independently; a
    ``^`` in the marker points at the character after it instead of the marker's start."""
    offset = marker.find("^")
    if offset >= 0:
        marker = marker.replace("^", "", 1)
    index = -1
    for _ in range(occurrence):
        index = text.index(marker, index + 1)
    index += max(offset, 0)
    line = text.count("\n", 0, index) + 1
    column = index - (text.rfind("\n", 0, index) + 1) + 1
    return line, column


def test_good_scene_loads(tmp_path):
    scene = load_scene(write(tmp_path, GOOD))
    native = scene.native()
    check_native(native)
    assert [t["type"] for t in native["textures"]] == ["grid", "constant"]  # the lamp's colour becomes a texture
    assert native["materials"][1] == {"type": "emissive", "texture": 1, "strength": 2.0, "two_sided": False,
                                      "keplerian": False, "beaming": False, "colour_shift": False}  # fmt: skip
    assert native["environment"]["stars"] == {"density": 100.0, "brightness": 20.0, "size": 0.002, "seed": 3}
    np.testing.assert_allclose(native["environment"]["spots"][1]["direction"], [2**-0.5, 2**-0.5, 0.0])


# (description, replace this, by that, text marking where the error is, its occurrence, message pattern)
BAD = [
    ("syntax error", "spin = 0.5", "spin = = 0.5", "= 0.5", 1, r"TOML syntax error: Invalid value"),
    ("unknown key with did-you-mean", "spin = 0.5", "spn = 0.5", "spn", 1,
     r"unknown key 'spn' in \[metric\] \(kerr\); did you mean 'spin'\?"),
    ("spin >= 1", "spin = 0.5", "spin = 1.2", "1.2", 1, r"metric\.spin must be in \(-1, 1\), got 1\.2"),
    ("spin exactly 1", "spin = 0.5", "spin = 1", "spin = ^1", 1, r"metric\.spin must be in \(-1, 1\), got 1"),
    ("negative radius", "radius = 2.0", "radius = -2.0", "-2.0", 1, r"objects\[0\]\.radius must be > 0, got -2"),
    ("missing mesh file", 'shape = "sphere"\ncenter = [0.0, 10.0, 0.0]\nradius = 2.0',
     'shape = "mesh"\nfile = "meshes/nothere.obj"', '"meshes/nothere.obj"', 1,
     r"objects\[0\]\.file: mesh file 'meshes/nothere.obj' not found"),
    ("unknown material", 'material = "lamp"', 'material = "lamb"', '"lamb"', 1,
     r"objects\[1\]\.material: unknown material 'lamb'; did you mean 'lamp'\? \(defined: white, lamp\)"),
    ("wrong version", "version = 1", "version = 2", "version = ^2", 1, r"version must be 1 .*got 2"),
    ("missing version", 'version = 1\n', '', "description", 1, r"missing the required key 'version'"),
    ("unknown table", "[environment]", "[enviroment]", "[enviroment]", 1,
     r"unknown key 'enviroment' in the scene file; did you mean 'environment'\?"),
    ("unknown key in an inline table", "density = 100.0", "dnsity = 100.0", "dnsity", 1,
     r"unknown key 'dnsity' in \[environment\.stars\]; did you mean 'density'\?"),
    ("bad value in an array of inline tables", "radius = 0.02 }", "radius = -0.02 }", "-0.02", 1,
     r"environment\.spots\[1\]\.radius must be in \(0, 3\.14159\), got -0\.02"),
    ("unknown texture", 'texture = "tiles"', 'texture = "tile"', '"tile"', 1,
     r"materials\.white\.texture: unknown texture 'tile'; did you mean 'tiles'\?"),
    ("wrong type", "fov = 40.0", 'fov = "wide"', '"wide"', 1, r"camera\.fov must be a number, got the string 'wide'"),
    ("fov out of range", "fov = 40.0", "fov = 180", "180", 1, r"camera\.fov must be in \(0, 180\), got 180"),
    ("camera inside the horizon", "position = [0.0, -30.0, 0.0]", "position = [0.0, -1.0, 0.0]", "[0.0, -1.0", 1,
     r"camera\.position \[0\.0, -1\.0, 0\.0\] lies inside the horizon"),
    ("other sheet without a wormhole", 'material = "lamp"', 'material = "lamp"\nsheet = -1', "sheet = ^-1", 1,
     r"objects\[1\]\.sheet = -1 needs a wormhole"),
    ("unknown shape", 'shape = "quad"', 'shape = "quadd"', '"quadd"', 1,
     r"objects\[1\]\.shape = 'quadd' is not one of .*; did you mean 'quad'\?"),
    ("key of another shape", "radius = 2.0", "radius = 2.0\nedge_u = [1, 0, 0]", "edge_u", 1,
     r"unknown key 'edge_u' in objects\[0\] \(sphere\)"),
    ("missing material", 'material = "white"\n', "", "[[objects]]", 1,
     r"objects\[0\] \(sphere\) is missing the required key 'material'"),
    ("vector of the wrong length", "edge_v = [0.0, 2.0, 0.0]", "edge_v = [0.0, 2.0]", "[0.0, 2.0]", 1,
     r"objects\[1\]\.edge_v must be a list of 3 numbers, got a list of 2"),
    ("albedo above one", 'texture = "tiles"', "color = [1.2, 0.5, 0.5]", "1.2", 1,
     r"materials\.white\.color\[0\] must be in \[0, 1\], got 1\.2"),
    ("parameter of another metric", "spin = 0.5", "spin = 0.5\nthroat = 2.0", "throat", 1,
     r"unknown key 'throat' in \[metric\] \(kerr\) \(allowed: mass, name, spin\)"),
    ("bad paper setting", "[textures.tiles]", "[render.paper]\nspp = 0\n\n[textures.tiles]", "spp = ^0", 1,
     r"render\.paper\.spp must be in \[1, 2147483647\], got 0"),
    ("sky of the other sheet without a wormhole", "[textures.tiles]", "[environment_other]\n\n[textures.tiles]",
     "[environment_other]", 1, r"\[environment_other\] is the sky of a wormhole's other sheet"),
    ("marked grid line beyond the last", "cells = [4, 4]", "cells = [4, 4]\nmark_u = { line = 5, color = [1, 0, 0] }",
     "5,", 1, r"textures\.tiles\.mark_u\.line must be in \[0, 4\], got 5"),
    ("marked grid line without a colour", "cells = [4, 4]", "cells = [4, 4]\nmark_v = { line = 2 }",
     "mark_v", 1, r"missing the required key 'color'"),
]  # fmt: skip


@pytest.mark.parametrize(("what", "old", "new", "marker", "occurrence", "pattern"), BAD, ids=[b[0] for b in BAD])
def test_bad_input_names_file_line_column(tmp_path, what, old, new, marker, occurrence, pattern):
    assert old in GOOD, "the test replaces existing text"
    text = GOOD.replace(old, new, 1)
    path = write(tmp_path, text)
    with pytest.raises(SceneError) as info:
        load_scene(path)
    err = info.value
    assert isinstance(err, ValueError)
    line, column = expected_position(text, marker, occurrence)
    assert str(err).startswith(f"{path}:{line}:{column}: "), (str(err), line, column)
    assert (err.line, err.column, err.path) == (line, column, str(path))
    assert re.search(pattern, str(err)), str(err)


def test_syntax_error_at_end_of_file(tmp_path):
    path = write(tmp_path, GOOD + "spots = [1, 2,\n")
    with pytest.raises(SceneError, match=r"scene\.toml:\d+:\d+: TOML syntax error"):
        load_scene(path)


def test_from_dict_names_the_key_without_a_line(tmp_path):
    data = {
        "version": 1,
        "metric": {"name": "schwarzschild", "mass": 2.0},
        "camera": {"position": (0.0, -40.0, 0.0)},  # tuples are fine
        "materials": {"m": {"type": "mirror"}},
        "objects": [
            {"shape": "disk", "center": [0, 0, 0], "outer_radius": 10.0, "inner_radius": 12.0, "material": "m"}
        ],
    }
    with pytest.raises(SceneError) as info:
        scene_from_dict(data, base_dir=tmp_path)
    assert str(info.value) == "objects[0].outer_radius must be > 12, got 10"
    assert info.value.key == "objects[0].outer_radius" and info.value.line is None
    data["objects"][0]["inner_radius"] = 6.0
    scene = scene_from_dict(data, base_dir=tmp_path)
    assert scene.path is None and scene.metric == wv.Schwarzschild(mass=2.0)
    disk = scene.native()["shapes"][0]
    assert disk == {"type": "disk", "center": [0.0, 0.0, 0.0], "normal": [0.0, 0.0, 1.0], "inner_radius": 6.0,
                    "outer_radius": 10.0, "meridian": [1.0, 0.0, 0.0], "material": 0, "sheet": 1}  # fmt: skip


# ------------------------------------------------------------------------------------------ shapes and files
def scene_with_objects(objects: str, extra: str = "") -> str:
    return textwrap.dedent(
        """\
        version = 1
        [metric]
        name = "minkowski"
        [camera]
        position = [0.0, -30.0, 0.0]
        [materials.grey]
        type = "diffuse"
        """
    ) + extra + objects


def test_mesh_files_are_loaded_and_transformed(tmp_path):
    import trimesh

    (tmp_path / "meshes").mkdir()
    box = trimesh.creation.box(extents=[1.0, 2.0, 3.0])
    box.export(tmp_path / "meshes" / "box.ply")
    box.export(tmp_path / "meshes" / "box.stl")
    objs = """
[[objects]]
shape = "mesh"
file = "meshes/box.ply"
scale = 2.0
rotate = [0, 0, 90]
translate = [10.0, 0.0, 0.0]
material = "grey"

[[objects]]
shape = "mesh"
file = "meshes/box.stl"
material = "grey"
"""
    native = load_scene(write(tmp_path, scene_with_objects(objs))).native()
    check_native(native)
    ply, stl = native["shapes"]
    expected = np.asarray(box.vertices) * 2.0
    expected = np.stack([-expected[:, 1], expected[:, 0], expected[:, 2]], axis=1) + [10.0, 0.0, 0.0]
    np.testing.assert_allclose(ply["vertices"], expected, atol=1e-12)
    np.testing.assert_array_equal(ply["faces"], box.faces)
    assert len(stl["faces"]) == 12
    assert np.ptp(ply["vertices"], axis=0) == pytest.approx([4.0, 2.0, 6.0])


def test_obj_uvs_are_kept(tmp_path):
    obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n"
    (tmp_path / "tri.obj").write_text(obj)
    objs = '[[objects]]\nshape = "mesh"\nfile = "tri.obj"\nmaterial = "grey"\n'
    shape = load_scene(write(tmp_path, scene_with_objects(objs))).native()["shapes"][0]
    assert shape["uvs"] is not None and shape["uvs"].shape == (3, 2)
    assert sorted(map(tuple, shape["uvs"].tolist())) == [(0.0, 0.0), (0.0, 1.0), (1.0, 0.0)]


def test_unreadable_mesh_is_an_error_at_its_key(tmp_path):
    (tmp_path / "junk.obj").write_text("this is not a mesh\n")
    objs = '[[objects]]\nshape = "mesh"\nfile = "junk.obj"\nmaterial = "grey"\n'
    text = scene_with_objects(objs)
    with pytest.raises(SceneError) as info:
        load_scene(write(tmp_path, text))
    line, column = expected_position(text, '"junk.obj"')
    assert (info.value.line, info.value.column) == (line, column)
    assert "objects[0].file" in str(info.value)


def test_box_and_cylinder_conveniences(tmp_path):
    objs = """
[[objects]]
shape = "box"
center = [1.0, 2.0, 3.0]
size = [2.0, 4.0, 6.0]
rotate = [0, 0, 30]
material = "grey"

[[objects]]
shape = "cylinder"
center = [0.0, 0.0, 0.0]
axis = [1.0, 0.0, 0.0]
radius = 1.5
height = 4.0
segments = 24
material = "grey"
"""
    shapes = load_scene(write(tmp_path, scene_with_objects(objs))).native()["shapes"]
    quads, cylinder = shapes[:6], shapes[6]
    assert [s["type"] for s in quads] == ["quad"] * 6 and cylinder["type"] == "mesh"
    centre = np.array([1.0, 2.0, 3.0])
    areas = []
    for q in quads:  # outward normals, face centres at the right distances
        c, u, v = (np.asarray(q[k]) for k in ("corner", "edge_u", "edge_v"))
        n = np.cross(u, v)
        mid = c + 0.5 * (u + v) - centre
        assert n @ mid > 0
        areas.append(np.linalg.norm(n))
    assert sorted(areas) == pytest.approx([8, 8, 12, 12, 24, 24])
    v = cylinder["vertices"]
    assert np.ptp(v[:, 0]) == pytest.approx(4.0) and np.hypot(v[:, 1], v[:, 2]).max() == pytest.approx(1.5)


def test_image_and_procedural_textures(tmp_path):
    from PIL import Image

    pixels = np.zeros((2, 4, 3), dtype=np.uint8)
    pixels[0, :, 0] = 255  # top row red
    pixels[1, :, 1] = 128  # bottom row half green (sRGB)
    Image.fromarray(pixels).save(tmp_path / "tex.png")
    extra = """
[textures.picture]
type = "image"
file = "tex.png"
repeat = [2, 1]

[textures.chart]
type = "swatch"
cells = [3, 5]
cell_px = 4

[textures.planet]
type = "earth-like"
resolution = [32, 16]

[materials.a]
type = "diffuse"
texture = "picture"
"""
    native = load_scene(write(tmp_path, scene_with_objects("", extra))).native()
    picture, chart, planet = native["textures"][:3]
    assert picture["repeat"] == [2.0, 1.0]
    np.testing.assert_allclose(picture["data"][0, 0], [1.0, 0.0, 0.0])
    srgb_128 = ((128 / 255 + 0.055) / 1.055) ** 2.4  # sRGB 128 decoded to linear
    assert picture["data"][1, 0, 1] == pytest.approx(srgb_128, rel=1e-6)
    assert chart["data"].shape == (20, 12, 3) and len({tuple(c) for c in chart["data"].reshape(-1, 3).round(4)}) >= 16
    assert planet["data"].shape == (16, 32, 3) and 0.0 <= planet["data"].min() and planet["data"].max() <= 1.0


def test_missing_image_file(tmp_path):
    extra = '[environment]\nimage = "sky.exr"\n'
    text = scene_with_objects("", extra)
    with pytest.raises(SceneError) as info:
        load_scene(write(tmp_path, text))
    assert (info.value.line, info.value.column) == expected_position(text, '"sky.exr"')
    assert "environment.image: image file 'sky.exr' not found" in str(info.value)


def test_scene_is_immutable():
    scene = load_scene("fig04")
    with pytest.raises(AttributeError):
        scene.metric = wv.Minkowski()


def test_scene_aov_names_are_the_renderers():
    from warpviz.render.render import OPTIONAL_AOVS

    assert set(AOV_NAMES) == set(OPTIONAL_AOVS) | {"errors", "samples"}
