"""The native scene dict's one validator and filler (warpviz.scene.native): defaults from SCHEMA, the
messages that name a bad key, types the core converts, and scenes it leaves as they are."""

import re

import numpy as np
import pytest

import warpviz as wv
from warpviz.scene import load_scene, shipped_scenes
from warpviz.scene.native import REQUIRED, SCHEMA, native_material, native_scene
from warpviz.scene.reader import SceneError

SPHERE = {"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": 0}


def base(**changes) -> dict:
    scene = {"metric": {"name": "schwarzschild", "params": [1.0]},
             "camera": {"position": [0, -20, 1], "look_at": [0, 0, 0], "width": 8, "height": 6},
             "textures": [{"type": "constant", "color": [1, 1, 1]}],
             "materials": [{"type": "diffuse", "texture": 0}], "shapes": [dict(SPHERE, center=[0, 5, 0])]}  # fmt: skip
    scene.update(changes)
    return scene


def _equal(a, b) -> bool:
    if isinstance(a, dict):
        return isinstance(b, dict) and a.keys() == b.keys() and all(_equal(a[k], b[k]) for k in a)
    if isinstance(a, list):
        return isinstance(b, list) and len(a) == len(b) and all(map(_equal, a, b))
    if isinstance(a, np.ndarray):
        return isinstance(b, np.ndarray) and a.dtype == b.dtype and np.array_equal(a, b)
    return type(a) is type(b) and a == b


def test_optional_keys_get_the_schemas_defaults():
    full = native_scene(base(
        textures=[{"type": "checker", "color_a": [1, 0, 0], "color_b": [0, 0, 1]},
                  {"type": "grid", "base": [1, 1, 1], "line_u": [0, 0, 0], "line_v": [0, 0, 0]},
                  {"type": "image", "data": np.ones((2, 2, 3), np.float32)}],
        materials=[{"type": "mirror"}, {"type": "glass"}, {"type": "emissive"}],
        shapes=[dict(SPHERE, center=[0, 5, 0]), {"type": "disk", "center": [0, 0, 0], "outer_radius": 9, "material": 2},
                {"type": "quad", "corner": [0, 5, 0], "edge_u": [1, 0, 0], "edge_v": [0, 0, 1], "material": 1},
                {"type": "mesh", "vertices": np.eye(3), "faces": [[0, 1, 2]], "material": 1}],
        environment={"spots": [{"direction": [0, 0, 2]}]}))  # fmt: skip

    def check(table: dict, schema: dict):
        for key, default in schema.items():
            assert key in table, key
            if default is not REQUIRED and key not in ("spots", "environment", "environment_other", "observer"):
                assert _equal(table[key], list(map(float, default)) if isinstance(default, tuple) else default), key

    check(full["camera"], SCHEMA["camera"])
    check(full["camera"]["observer"], SCHEMA["observer"])  # None: the local observer, every key filled in
    for t in full["textures"]:
        check(t, SCHEMA["textures"][t["type"]])
    for m in full["materials"]:
        check(m, SCHEMA["materials"][m["type"]])
    for s in full["shapes"]:
        check(s, SCHEMA["shapes"][s["type"]])
    check(full["environment"], SCHEMA["environment"])
    check(full["environment"]["spots"][0], SCHEMA["spots"])
    assert full["environment_other"] is full["environment"]
    assert set(full) == set(SCHEMA["scene"]) and full["metric"] == {"name": "schwarzschild", "params": [1.0]}


def test_values_take_the_types_the_core_converts():
    full = native_scene(base(
        camera={"position": np.array([0, -20, 1]), "look_at": (0, 0, 0), "width": 8.0, "height": np.int64(6),
                "fov": np.float32(30), "sheet": 1.0},
        textures=[{"type": "image", "data": np.ones((2, 2, 3)), "repeat": (2, 3)}],
        shapes=[{"type": "mesh", "vertices": [[0, 0, 5], [1, 0, 5], [0, 1, 5]], "faces": np.array([[0, 1, 2]]),
                 "material": np.int64(0)}]))  # fmt: skip
    cam = full["camera"]
    assert cam["position"] == [0.0, -20.0, 1.0] and all(type(x) is float for x in cam["position"] + cam["look_at"])
    assert (type(cam["width"]), type(cam["height"]), type(cam["fov"]), type(cam["sheet"])) == (int, int, float, int)
    tex, mesh = full["textures"][0], full["shapes"][0]
    assert tex["data"].dtype == np.float32 and tex["data"].flags.c_contiguous and tex["repeat"] == [2.0, 3.0]
    assert mesh["vertices"].dtype == np.float64 and mesh["faces"].dtype == np.int32 and mesh["uvs"] is None
    assert type(mesh["material"]) is int


def test_arrays_already_in_the_cores_types_are_shared_not_copied():
    image = np.ones((3, 4, 3), np.float32)
    vertices, faces = np.eye(3), np.array([[0, 1, 2]], np.int32)
    full = native_scene(base(textures=[{"type": "image", "data": image}], environment={"image": image},
                             shapes=[{"type": "mesh", "vertices": vertices, "faces": faces, "material": 0}]))
    assert full["textures"][0]["data"] is image and full["environment"]["image"] is image
    assert full["shapes"][0]["vertices"] is vertices and full["shapes"][0]["faces"] is faces


def test_a_complete_scene_comes_back_the_same():
    for name in shipped_scenes():
        native = load_scene(name).native()
        assert _equal(native_scene(native), native), name
    full = native_scene(base())
    again = native_scene(full)
    assert again is not full and _equal(again, full)


def test_keys_the_core_does_not_read_are_left_out():
    full = native_scene(base(shapes=[dict(SPHERE, center=[0, 5, 0], name="ball", colour=[1, 0, 0])], extra=1))
    assert set(full["shapes"][0]) == set(SCHEMA["shapes"]["sphere"]) | {"type"} and "extra" not in full


@pytest.mark.parametrize("change, message", [
    (lambda s: s.pop("metric"), "scene.metric is missing"),
    (lambda s: s["metric"].update(name="kerrr"), "unknown metric 'kerrr'"),
    (lambda s: s["metric"].update(params=[-1.0]), "mass"),
    (lambda s: s["camera"].pop("width"), "camera.width is missing"),
    (lambda s: s["camera"].update(width=0), r"camera.width must be an integer in \[1, 65536\], got 0"),
    (lambda s: s["camera"].update(height=2.5), r"camera.height must be an integer in \[1, 65536\], got 2.5"),
    (lambda s: s["camera"].update(fov=180), r"camera.fov must be in \(0, 180\) degrees"),
    (lambda s: s["camera"].update(up=[0, 1]), "camera.up must be a list of 3 numbers"),
    (lambda s: s["camera"].update(position=[0, "a", 0]), "camera.position must be a list of 3 finite numbers"),
    (lambda s: s["camera"].update(sheet=2), r"camera.sheet must be \+1 or -1"),
    (lambda s: s["camera"].update(look_at=[0, -20, 1]), "camera.look_at must differ from camera.position"),
    (lambda s: s["camera"].update(position=[0, 0, 1.5]), "camera.position lies inside the horizon"),
    (lambda s: s.update(textures={}), "textures must be a list"),
    (lambda s: s["textures"].append({"type": "noise"}), r"textures\[1\].type unknown texture type 'noise'"),
    (lambda s: s["textures"].append({"type": "checker", "color_a": [1, 1, 1], "color_b": [0, 0, 0], "scale": [0, 1]}),
     r"textures\[1\].scale must be a list of 2 positive numbers"),
    (lambda s: s["textures"].append({"type": "image", "data": np.ones((2, 2))}),
     r"textures\[1\].data must be a float32 array of shape \(H, W, 3\)"),
    (lambda s: s["materials"].append({"type": "velvet"}), r"materials\[1\].type unknown material type 'velvet'"),
    (lambda s: s["materials"].append({"type": "glass", "ior": 0.5}), r"materials\[1\].ior must be >= 1"),
    (lambda s: s["materials"].append({"type": "emissive", "strength": -1}), r"materials\[1\].strength must be in \[0, 1e\+12\]"),
    (lambda s: s["materials"].append({"type": "emissive", "strength": 1e308}), r"materials\[1\].strength must be in"),
    (lambda s: s["materials"].append({"type": "emissive", "beaming": 1}), r"materials\[1\].beaming must be True or False"),
    (lambda s: s["materials"][0].update(texture=3), r"materials\[0\].texture index 3 out of range \(1 defined\)"),
    (lambda s: s["materials"][0].pop("texture"), r"materials\[0\].texture is missing"),
    (lambda s: s["shapes"][0].update(material=-1), r"shapes\[0\].material is required"),
    (lambda s: s["shapes"][0].update(material=1.0), r"shapes\[0\].material must be an integer"),
    (lambda s: s["shapes"][0].update(radius=0), r"shapes\[0\].radius must be > 0"),
    (lambda s: s["shapes"][0].update(pole=[0, 0, 0]), r"shapes\[0\].pole must be non-zero"),
    (lambda s: s["shapes"][0].update(sheet=0), r"shapes\[0\].sheet must be \+1 or -1"),
    (lambda s: s["shapes"].append({"type": "cone", "material": 0}), r"shapes\[1\].type unknown shape type 'cone'"),
    (lambda s: s["shapes"].append({"type": "quad", "corner": [0, 0, 0], "edge_u": [1, 0, 0], "edge_v": [2, 0, 0],
                                   "material": 0}), r"shapes\[1\] edge_u and edge_v must span a parallelogram"),
    (lambda s: s["shapes"].append({"type": "disk", "center": [0, 0, 0], "inner_radius": 3, "outer_radius": 2,
                                   "material": 0}), r"shapes\[1\] needs 0 <= inner_radius < outer_radius"),
    (lambda s: s["shapes"].append({"type": "disk", "center": [0, 0, 0], "normal": [0, 0, 0], "outer_radius": 2,
                                   "material": 0}), r"shapes\[1\].normal must be non-zero"),
    (lambda s: s["shapes"].append({"type": "mesh", "vertices": np.eye(3), "faces": [[0, 1, 3]], "material": 0}),
     r"shapes\[1\].faces refers to a vertex out of range"),
    (lambda s: s["shapes"].append({"type": "mesh", "vertices": np.eye(3), "faces": [[0.0, 1.0, 2.0]], "material": 0}),
     r"shapes\[1\].faces must be an int32 array of shape \(F, 3\)"),
    (lambda s: s["shapes"].append({"type": "mesh", "vertices": np.eye(3), "faces": [[0, 1, 2]], "uvs": np.zeros((2, 2)),
                                   "material": 0}), r"shapes\[1\].uvs must be a float64 array of shape \(V, 2\)"),
    (lambda s: s.update(environment=[]), r"environment must be a table \(dict\)"),
    (lambda s: s.update(environment={"stars": {"density": 1.0}}), "environment.stars.brightness is missing"),
    (lambda s: s.update(environment={"stars": {"density": -1.0, "brightness": 1, "size": 0.1, "seed": 0}}),
     "environment.stars needs density >= 0 and size > 0"),
    (lambda s: s.update(environment={"stars": {"density": 1.0, "brightness": 1, "size": 0.1, "seed": 2**60}}),
     r"environment.stars.seed must be in \[0, 2\*\*53\]"),
    (lambda s: s.update(environment={"spots": [{"direction": [0, 0, 0]}]}), r"environment.spots\[0\].direction must be non-zero"),
    (lambda s: s.update(environment_other={"spots": [{"direction": [0, 0, 1], "radius": 4}]}),
     r"environment_other.spots\[0\].radius must be in \(0, pi\)"),
])  # fmt: skip
def test_bad_native_scenes_name_the_key(change, message):
    scene = base()
    change(scene)
    with pytest.raises(SceneError, match=message):
        native_scene(scene)
    with pytest.raises(ValueError, match=message):  # what render() says: the same check, before the core
        wv.render(scene, spp=1, progress=None)


def test_one_material_for_the_bsdf_hook():
    assert native_material({"type": "emissive"}) == {"type": "emissive", "texture": -1, "strength": 1.0, "two_sided": False,
                                                     "keplerian": False, "beaming": False, "colour_shift": False}  # fmt: skip
    with pytest.raises(SceneError, match=re.escape("material.texture index 0 out of range (0 defined)")):
        native_material({"type": "diffuse", "texture": 0})
