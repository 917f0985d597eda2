"""Emitters that also reflect: emission on a diffuse, mirror or glass material is a light (sampled by the
light connection) and reflects like its BSDF, in flat and curved space."""

from __future__ import annotations

import math

import numpy as np
import pytest
from native_scenes import metric, room

import warpviz as wv
from warpviz.scene.reader import SceneError


def _glowing_box(*, albedo: float, emission: float, metric_spec=None, size=(12, 9)) -> dict:
    """A closed cube of six inward-facing quads, each diffuse (albedo) and emitting (radiance `emission`)."""
    s = 5.0
    quads = [  # corner, a, b with a x b pointing out of the box: edge_u = b, edge_v = a
        ([-s, -s, -s], [0, 2 * s, 0], [2 * s, 0, 0]), ([-s, -s, s], [2 * s, 0, 0], [0, 2 * s, 0]),
        ([-s, -s, -s], [2 * s, 0, 0], [0, 0, 2 * s]), ([-s, s, -s], [0, 0, 2 * s], [2 * s, 0, 0]),
        ([-s, -s, -s], [0, 0, 2 * s], [0, 2 * s, 0]), ([s, -s, -s], [0, 2 * s, 0], [0, 0, 2 * s]),
    ]
    return {
        "metric": metric_spec or metric(),
        "camera": {"position": [0.5, -3.0, 0.7], "look_at": [0, 0, 0], "up": [0, 0, 1], "fov": 90,
                   "width": size[0], "height": size[1]},
        "textures": [{"type": "constant", "color": [albedo] * 3}],
        "materials": [{"type": "diffuse", "texture": 0, "emission": [emission] * 3}],
        "shapes": [{"type": "quad", "corner": c, "edge_u": v, "edge_v": u, "material": 0} for c, u, v in quads],
        "environment": {"color": [0, 0, 0]},
    }


@pytest.mark.parametrize("light_sampling", [True, False])
def test_glowing_white_box_is_a_furnace(light_sampling):
    """Every wall emits Le and reflects albedo rho: a path of at most D segments sees Le (1 - rho^D) / (1 - rho)
    everywhere, exactly, whichever strategy found the light."""
    rho, le, depth = 0.5, 1.0, 6
    img = wv.render(_glowing_box(albedo=rho, emission=le), spp=256, max_depth=depth, light_sampling=light_sampling)
    exact = le * (1 - rho**depth) / (1 - rho)
    assert img.aovs["errors"].max() == 0
    px = img.rgb[:, :, 0].astype(np.float64).ravel()
    err = px.std(ddof=1) / math.sqrt(px.size)  # Russian roulette's noise
    assert err < 3e-3 * exact
    assert abs(px.mean() - exact) < 4 * err, (px.mean(), exact, err)


def _image_means(scene, seeds, **kw):
    return np.array([wv.render(scene, seed=s, **kw).rgb.mean() for s in seeds])


def _reflecting_light_room(metric_spec, light: float):
    """The test room with its ceiling light a white diffuse quad that also emits (Mitsuba's Cornell light)."""
    sc = room(metric_spec, size=(16, 12), light=light)
    sc["materials"][3] = {"type": "diffuse", "texture": 0, "emission": [12.0, 10.8, 9.6]}
    return sc


@pytest.mark.parametrize("spec, light", [(metric(), 2.0), (metric("schwarzschild", 1.0), 4.0)])
def test_light_sampling_of_a_reflecting_emitter_is_unbiased(spec, light):
    """Light connection (with MIS) and brute force agree on the image mean within 4 standard errors, in
    flat space and around a Schwarzschild hole; the light connection has less noise, so it did sample
    the reflecting light."""
    sc = _reflecting_light_room(spec, light)
    seeds = range(6)
    nee = _image_means(sc, seeds, spp=8, light_sampling=True, max_depth=4)
    brute = _image_means(sc, seeds, spp=8, light_sampling=False, max_depth=4)
    err = math.sqrt(nee.var(ddof=1) / len(nee) + brute.var(ddof=1) / len(brute))
    assert abs(nee.mean() - brute.mean()) < 4 * err + 1e-3 * nee.mean()
    assert nee.var() < brute.var()


def test_the_emitter_reflects():
    """Compared with a purely emissive light of the same radiance, the reflecting one adds the light it
    reflects: the room is brighter, and the light's own pixels are brighter than its emission."""
    plain = room(metric(), size=(16, 12), light=2.0)
    plain["materials"][3] = {"type": "emissive", "texture": 3, "strength": 12.0}
    glow = room(metric(), size=(16, 12), light=2.0)
    glow["materials"][3] = {"type": "diffuse", "texture": 0, "emission": [12.0, 10.8, 9.6]}
    a = wv.render(plain, spp=32, max_depth=4).rgb.mean()
    b = wv.render(glow, spp=32, max_depth=4).rgb.mean()
    assert b > a * 1.001


def test_emission_table_in_a_scene_file(tmp_path):
    text = """version = 1
[metric]
name = "minkowski"
[camera]
position = [0, -4, 0]
look_at = [0, 0, 0]
[render]
width = 8
height = 6
[materials.glow]
type = "diffuse"
color = [0.5, 0.5, 0.5]
emission = { color = [1.0, 0.5, 0.25], strength = 4.0 }
[[objects]]
shape = "sphere"
center = [0, 0, 0]
radius = 1.0
material = "glow"
"""
    path = tmp_path / "glow.toml"
    path.write_text(text)
    native = wv.load_scene(path).native()
    assert native["materials"][0]["emission"] == [4.0, 2.0, 1.0]
    path.write_text(text.replace("strength = 4.0", "strenght = 4.0"))
    with pytest.raises(SceneError, match=r"glow\.toml:13:40: .*strenght"):
        wv.load_scene(path)
