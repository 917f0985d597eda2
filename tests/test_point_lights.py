"""Point and spot lights (scene/scene.h PointLight; the light strategy in path_tracer.h, the photons in
photon_tracer.h): exact irradiance in flat space and along a radius of Schwarzschild, the spot's cone, a
point light focused through a glass ball by photons, bad input refused by name."""

from __future__ import annotations

import numpy as np
import pytest

import warpviz as wv
from native_scenes import metric
from warpviz.scene.camera import pinhole_directions
from warpviz.scene.reader import SceneError


def lamp_over_floor(metric_spec=None, *, light: dict, camera_z: float = 4.0, size=(9, 9), fov: float = 40.0,
                    floor_z: float = 0.0, floor_half: float = 3.0) -> dict:
    """A white floor (albedo 1) at floor_z lit by one point or spot light, seen from straight above."""
    s = floor_half
    return {
        "metric": metric_spec or metric(),
        "camera": {"position": [0, 0, camera_z], "look_at": [0, 0, floor_z], "up": [0, 1, 0], "fov": fov,
                   "width": size[0], "height": size[1]},
        "textures": [{"type": "constant", "color": [1, 1, 1]}],
        "materials": [{"type": "diffuse", "texture": 0}],
        "shapes": [{"type": "quad", "corner": [-s, -s, floor_z], "edge_u": [2 * s, 0, 0], "edge_v": [0, 2 * s, 0],
                    "material": 0}],
        "lights": [light],
        "environment": {"color": [0, 0, 0]},
    }


def _flat_floor_radiance(sc, h, intensity, profile=lambda cos_axis: 1.0, n=12):
    """The pixel means of a flat floor at z = 0 under a point light at height h: (1/pi) I cos / d^2 averaged
    over an n x n grid in each pixel."""
    cam = sc["camera"]
    w, hgt = cam["width"], cam["height"]
    out = np.zeros((hgt, w))
    g = (np.arange(n) + 0.5) / n
    for y in range(hgt):
        for x in range(w):
            pix = np.array([[x + a, y + b] for a in g for b in g])
            d = pinhole_directions(cam, pix, jitter=(0.0, 0.0))
            t = -cam["position"][2] / d[:, 2]
            p = np.asarray(cam["position"]) + d * t[:, None]
            rho2 = p[:, 0] ** 2 + p[:, 1] ** 2
            cos_axis = h / np.sqrt(rho2 + h * h)
            out[y, x] = np.mean(intensity * h / (rho2 + h * h) ** 1.5 * np.vectorize(profile)(cos_axis)) / np.pi
    return out


def test_a_point_light_gives_a_floor_i_cos_over_d_squared():
    sc = lamp_over_floor(light={"type": "point", "position": [0, 0, 1.0], "intensity": 2.0, "color": [1, 0.5, 0.25]})
    img = wv.render(sc, spp=64, seed=0, max_depth=2)
    expect = _flat_floor_radiance(sc, 1.0, 2.0)
    np.testing.assert_allclose(img.rgb[..., 0], expect, rtol=2e-3)
    np.testing.assert_allclose(img.rgb[..., 2], 0.25 * expect, rtol=2e-3)


def test_a_spot_light_lights_its_cone_only():
    cos_o, cos_i = np.cos(np.radians(20.0)), np.cos(np.radians(15.0))

    def profile(c):
        if c >= cos_i:
            return 1.0
        if c <= cos_o:
            return 0.0
        t = (c - cos_o) / (cos_i - cos_o)
        return t * t * (3 - 2 * t)

    sc = lamp_over_floor(light={"type": "spot", "position": [0, 0, 1.0], "intensity": 2.0, "direction": [0, 0, -1],
                                "angle": 20.0, "falloff": 5.0}, size=(15, 15), fov=60)  # fmt: skip
    img = wv.render(sc, spp=64, seed=0, max_depth=2).rgb[..., 0]
    expect = _flat_floor_radiance(sc, 1.0, 2.0, profile)
    assert (expect == 0).sum() > 100 and (img[expect == 0] == 0).all()  # outside the cone: dark
    inside = expect > 0.5 * expect.max()
    np.testing.assert_allclose(img[inside], expect[inside], rtol=5e-3)


def test_a_point_light_along_a_radius_of_schwarzschild_is_the_exact_irradiance():
    # Floor A at r_A = 2 facing up, the lamp at r_B = 3.5 straight above, the camera on the same radius: along
    # the radial ray the lens map's bundle gives dA_B / dOmega_A = (r_B - r_A)^2 / (1 - 2M / r_A) (small impact
    # parameters: phi = b (1/r_A - 1/r_B) as in flat space, b = r_A sin(delta) / sqrt(1 - 2M / r_A)), so the
    # floor's radiance under the lamp is (1/pi) I (1 - 2M/r_A) / (r_B - r_A)^2: 0.7 of flat space's at M = 0.3.
    m, ra, rb, intensity = 0.3, 2.0, 3.5, 2.0
    light = {"type": "point", "position": [0, 0, rb], "intensity": intensity}
    sc = lamp_over_floor(metric("schwarzschild", m), light=light, camera_z=6.0, fov=1.0, floor_z=ra, floor_half=1.0)
    centre = wv.render(sc, spp=16, seed=0, max_depth=2).rgb[4, 4, 0]
    assert centre == pytest.approx(intensity * (1 - 2 * m / ra) / (rb - ra) ** 2 / np.pi, rel=2e-4)
    flat = lamp_over_floor(metric("schwarzschild", 1e-12), light=light, camera_z=6.0, fov=1.0, floor_z=ra,
                           floor_half=1.0)  # fmt: skip
    assert wv.render(flat, spp=16, seed=0, max_depth=2).rgb[4, 4, 0] == pytest.approx(
        intensity / (rb - ra) ** 2 / np.pi, rel=2e-4)


def test_a_point_light_through_a_glass_ball_focuses_where_geometric_optics_puts_it():
    # A ball lens (R = 0.5, n = 1.5) has f = n R / (2 (n - 1)) = 0.75 from its centre; a point source u = 3
    # above the centre is imaged (paraxially) v = 1 / (1/f - 1/u) = 1 below it. The ball's spherical aberration
    # focuses its outer rays nearer, so the brightest floor (the circle of least confusion) lies a little
    # nearer the ball: measured 0.9 below the centre (floors 0.7 ... 1.4: peak radiance 2.0, 4.1, 4.9, 3.2,
    # 1.5, 0.6, 0.3 at 81 x 81). Only the photons find it: a point light is never hit by a path.
    def scene(floor_z):
        sc = lamp_over_floor(light={"type": "point", "position": [0, 0, 3.0], "intensity": 1.0}, size=(61, 61),
                             fov=40, floor_z=floor_z, floor_half=2.0)  # fmt: skip
        sc["camera"]["position"] = [0.0, -2.5, 0.2]  # (beside the ball, looking past it at the floor under it)
        sc["materials"].append({"type": "glass", "ior": 1.5})
        sc["shapes"].append({"type": "sphere", "center": [0, 0, 0], "radius": 0.5, "material": 1})
        return sc

    peaks = {}
    for z in (-0.6, -0.9, -1.3):
        sc = scene(z)
        img = wv.render(sc, spp=16, seed=1, max_depth=5, photons=40000, photon_radius=1.0).rgb[..., 0]
        cam = sc["camera"]
        d = pinhole_directions(cam, [[x, y] for y in range(61) for x in range(61)])
        p = np.asarray(cam["position"]) + d * ((z - cam["position"][2]) / d[:, 2])[:, None]
        rho = np.hypot(p[:, 0], p[:, 1]).reshape(61, 61)
        peak = np.unravel_index(np.argmax(img), img.shape)
        assert rho[peak] < 0.1, (z, rho[peak])  # the brightest floor point is on the axis (a pixel: ~0.05)
        peaks[z] = img[peak]
        if z == -0.9:  # the path tracer alone: the ball's shadow there, nothing focused
            assert wv.render(sc, spp=4, seed=1, max_depth=5).rgb[..., 0][peak] < 0.01 * img[peak]
    assert peaks[-0.9] > 2 * max(peaks[-0.6], peaks[-1.3]), peaks


def test_bad_lights_are_refused_by_name():
    base = lamp_over_floor(light={"type": "point", "position": [0, 0, 1.0], "intensity": 1.0})
    for bad, key in (({"type": "laser", "position": [0, 0, 1], "intensity": 1.0}, "lights[0].type"),
                     ({"type": "point", "position": [0, 0, 1], "intensity": -1.0}, "lights[0].intensity"),
                     ({"type": "point", "intensity": 1.0}, "lights[0].position"),
                     ({"type": "spot", "position": [0, 0, 1], "intensity": 1.0, "direction": [0, 0, 0]},
                      "lights[0].direction"),
                     ({"type": "spot", "position": [0, 0, 1], "intensity": 1.0, "direction": [0, 0, -1],
                       "angle": 10.0, "falloff": 20.0}, "lights[0].falloff")):  # fmt: skip
        with pytest.raises(SceneError, match=key.replace("[", r"\[").replace("]", r"\]")):
            wv.render(dict(base, lights=[bad]), spp=1)
    kerr = lamp_over_floor(metric("kerr", 0.1, 0.5), light={"type": "point", "position": [0, 0, 1.0], "intensity": 1.0})
    with pytest.raises(ValueError, match="point and spot lights.*static"):
        wv.render(kerr, spp=1)


def test_a_hole_focuses_a_point_lamp_behind_it_onto_a_wall_as_the_lens_equation_says():
    # The gravitational lens as a burning glass: a lamp 20 behind a hole of M = 0.02, a wall 20 in front of it.
    # A wall point at rho from the axis sees the lamp's two images, together magnified by
    # mu(u) = (u^2 + 2) / (u sqrt(u^2 + 4)), u = rho D_ls / (D_l D_s theta_E), theta_E = sqrt(4 M D_ls / (D_l D_s))
    # (the thin lens: deflection 4M/b <= 0.1 here), so its irradiance is mu times flat space's.
    m, d = 0.02, 20.0
    theta_e = np.sqrt(4 * m * d / (d * 2 * d))
    light = {"type": "point", "position": [0, 0, d], "intensity": 50.0}

    def scene(spec):
        sc = lamp_over_floor(spec, light=light, size=(41, 41), fov=50, floor_z=-d, floor_half=10.0)
        sc["camera"].update(position=[0.0, -4.0, -d + 8.0], look_at=[0.0, 1.0, -d], up=[0, 0, 1])
        return sc

    lensed = wv.render(scene(metric("schwarzschild", m)), spp=16, seed=2, max_depth=2).rgb[..., 0]
    flat = wv.render(scene(metric()), spp=16, seed=2, max_depth=2).rgb[..., 0]
    cam = scene(metric())["camera"]
    dirs = pinhole_directions(cam, [[x, y] for y in range(41) for x in range(41)])
    p = np.asarray(cam["position"]) + dirs * ((-d - cam["position"][2]) / dirs[:, 2])[:, None]
    rho = np.hypot(p[:, 0], p[:, 1]).reshape(41, 41)
    u = rho / (2 * d * theta_e)  # (D_ls / (D_l D_s) = 1 / (2 d))
    mu = (u * u + 2) / (u * np.sqrt(u * u + 4))
    ring = (rho > 0.8) & (rho < 6.0) & (flat > 0)
    assert ring.sum() > 200 and mu[ring].max() > 2.0  # (the wall 2-5x brighter near the axis)
    np.testing.assert_allclose(lensed[ring] / flat[ring], mu[ring], rtol=1e-2)  # (measured: within 0.4 %)
