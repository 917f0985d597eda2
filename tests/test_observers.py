"""Moving observers: the camera's 4-velocity and frame (spacetime/observers.h, docs/observers.md), against
special relativity's aberration and Doppler factor, Schwarzschild's free fall and circular orbits, and the
shadow a falling camera sees."""

import math

import numpy as np
import pytest

import warpviz as wv
from warpviz.scene import SceneError, scene_from_dict
from warpviz.spacetime.observers import observer

SCHW = wv.Schwarzschild(mass=1.0)


def _sky_scene(metric: dict, camera: dict, **extra):
    return scene_from_dict({"version": 1, "metric": metric, "camera": camera,
                            "environment": {"color": [1.0, 1.0, 1.0]}, "render": {"width": 41, "height": 31}, **extra},
                           base_dir=".")  # fmt: skip


def test_frame_is_orthonormal_with_the_velocity_for_every_observer():
    kerr = wv.Kerr(mass=1.0, spin=0.9)
    cases = [(SCHW, [9.0, 2.0, 0.0], dict(kind="free_fall")), (SCHW, [0.0, 7.0, 3.0], dict(kind="free_fall", fall_from=20)),
             (SCHW, [8.0, 0.0, 0.0], dict(kind="orbit")), (SCHW, [0.0, 6.0, 6.0], dict(kind="orbit", axis=(1, 0, 0))),
             (kerr, [1.9, 0.3, 0.0], dict(kind="zamo")), (kerr, [6.0, 1.0, 0.0], dict(kind="orbit")),
             (kerr, [3.0, 4.0, 2.0], dict(kind="free_fall")), (kerr, [5.0, 0.0, 1.0], dict(kind="moving", velocity=(0, 0.6, 0.3))),
             (SCHW, [1.2, 0.5, 0.3], dict(kind="free_fall"))]  # fmt: skip
    for metric, pos, spec in cases:
        o = observer(metric, pos, spec.pop("kind"), **spec)
        basis = np.vstack([o.u, o.e])
        gram = basis @ o.g @ basis.T
        np.testing.assert_allclose(gram, np.diag([-1.0, 1, 1, 1]), atol=1e-12, err_msg=f"{metric} {pos}")


def test_circular_orbit_frame_matches_keplers_angular_velocity():
    """Schwarzschild: Omega = sqrt(M / r^3), u^t = 1 / sqrt(1 - 3M/r); Kerr (equator, prograde):
    Omega = 1 / (r^(3/2) + a) at Boyer-Lindquist r (Kerr-Schild x^2 + y^2 = r^2 + a^2)."""
    for r in (4.0, 10.0, 50.0):
        o = observer(SCHW, [r, 0.0, 0.0], "orbit")
        assert o.u[2] / (r * o.u[0]) == pytest.approx(math.sqrt(1.0 / r**3), rel=1e-12)
        assert o.u[0] == pytest.approx(1.0 / math.sqrt(1.0 - 3.0 / r), rel=1e-12)
        assert abs(o.u[1]) < 1e-15 and abs(o.u[3]) < 1e-15
    a, r = 0.9, 7.0
    o = observer(wv.Kerr(mass=1.0, spin=a), [math.sqrt(r * r + a * a), 0.0, 0.0], "orbit")
    omega = (o.u[2] * math.sqrt(r * r + a * a) - o.u[1] * 0.0) / ((r * r + a * a) * o.u[0])
    assert omega == pytest.approx(1.0 / (r**1.5 + a), rel=1e-12)
    retro = observer(wv.Kerr(mass=1.0, spin=a), [math.sqrt(r * r + a * a), 0.0, 0.0], "orbit", axis=(0, 0, -1))
    assert -retro.u[2] / (math.sqrt(r * r + a * a) * retro.u[0]) == pytest.approx(1.0 / (r**1.5 - a), rel=1e-12)


def test_free_fall_speed_against_the_static_observer():
    """From rest at infinity: v = sqrt(2M / r) inward; from rest at r0: v = sqrt(1 - (1 - 2M/r) / (1 - 2M/r0))."""
    for r in (2.5, 6.0, 30.0):
        fall, rest = observer(SCHW, [0.0, r, 0.0], "free_fall"), observer(SCHW, [0.0, r, 0.0])
        assert fall.speed_relative_to(rest) == pytest.approx(math.sqrt(2.0 / r), rel=1e-12)
        assert fall.u[2] < 0  # inward
        r0 = 2 * r
        fall0 = observer(SCHW, [0.0, r, 0.0], "free_fall", fall_from=r0)
        assert fall0.speed_relative_to(rest) == pytest.approx(math.sqrt(1 - (1 - 2 / r) / (1 - 2 / r0)), rel=1e-10)
    # Painleve-Gullstrand: dr/dtau = -sqrt(2M / r) at every r, through the horizon
    for r in (3.0, 2.0, 1.0, 0.2):
        assert observer(SCHW, [r, 0.0, 0.0], "free_fall").u[1] == pytest.approx(-math.sqrt(2.0 / r), rel=1e-10)


def test_impossible_observers_are_refused_with_the_reason():
    kerr = wv.Kerr(mass=1.0, spin=0.9)
    with pytest.raises(ValueError, match="no static observer here.*ergoregion"):
        observer(kerr, [1.9, 0.0, 0.0], "static")
    with pytest.raises(ValueError, match="not below the speed of light"):
        observer(SCHW, [10.0, 0.0, 0.0], "moving", velocity=(0.6, 0.8, 0.0))
    with pytest.raises(ValueError, match="plane through the centre"):
        observer(SCHW, [10.0, 0.0, 1.0], "orbit")
    with pytest.raises(ValueError, match="faster than light"):
        observer(SCHW, [2.9, 0.0, 0.0], "orbit")  # inside the photon sphere
    with pytest.raises(ValueError, match="above it"):
        observer(SCHW, [10.0, 0.0, 0.0], "free_fall", fall_from=8.0)
    with pytest.raises(ValueError, match="g\\(u, u\\) = -1"):
        observer(SCHW, [10.0, 0.0, 0.0], "given", u=(1.0, 0.0, 0.0, 0.0))


def _flat_moving_render(beta: float, shift: str = "none"):
    camera = {"position": [0.0, 0.0, 0.0], "look_at": [1.0, 0.0, 0.0], "fov": 100.0, "velocity": [beta, 0.0, 0.0],
              "shift": shift}  # fmt: skip
    scene = _sky_scene({"name": "minkowski"}, camera, outputs={"aovs": ["redshift"]})
    pixels = [[x, y] for x in range(0, 41, 4) for y in (3, 15, 28)]
    return wv.render(scene, spp=1, record_pixels=pixels, pixel_sampler="independent", seed=3), pixels


def test_flat_boost_reproduces_aberration_and_doppler_exactly():
    """A camera moving at beta along x sees a source at angle theta from x (rest frame of the sky) at
    cos theta' = (cos theta + beta) / (1 + beta cos theta), shifted by g = 1 / (gamma (1 - beta cos theta'))."""
    beta = 0.6
    img, _ = _flat_moving_render(beta)
    rays = img.rays
    first = np.flatnonzero(rays.ray_data["bounce"] == 0)
    assert first.size > 20
    for k in first:
        pts = rays.points[rays.offsets[k]:rays.offsets[k + 1]]
        lab = pts[-1] - pts[0]
        cos_lab = lab[0] / np.linalg.norm(lab)
        px, py = rays.ray_data["pixel_x"][k], rays.ray_data["pixel_y"][k]
        cos_cam = (cos_lab + beta) / (1 + beta * cos_lab)  # the camera-frame angle of the sample's ray
        g = img.aovs["redshift"][py, px]
        assert g == pytest.approx(math.sqrt(1 - beta**2) / (1 - beta * cos_cam), rel=2e-6)
    # aberration exactly, through the core's camera at a pixel centre: trace the boosted ray
    o = observer(wv.Minkowski(), [0.0, 0.0, 0.0], "moving", velocity=(beta, 0.0, 0.0))
    for theta_cam in np.radians([10.0, 45.0, 90.0, 135.0, 170.0]):
        d = np.array([math.cos(theta_cam), math.sin(theta_cam), 0.0])
        p = o.u - d @ o.e  # light arriving along -d
        look = -p[1:] / p[0]
        cos_lab = look[0] / np.linalg.norm(look)
        assert math.cos(theta_cam) == pytest.approx((cos_lab + beta) / (1 + beta * cos_lab), abs=1e-14)
        assert 1.0 / p[0] == pytest.approx(math.sqrt(1 - beta**2) / (1 - beta * math.cos(theta_cam)), rel=1e-14)


def test_flat_moving_camera_beaming_brightens_ahead_by_g4():
    """A white sky seen by a camera moving towards +x: with shift = "beaming" each pixel is g^4 (its redshift
    AOV to the fourth); with "none" it stays 1."""
    plain, _ = _flat_moving_render(0.5)
    beamed, _ = _flat_moving_render(0.5, shift="beaming")
    g = beamed.aovs["redshift"]
    np.testing.assert_allclose(plain.rgb[..., 0], 1.0, rtol=1e-6)
    # straight ahead the relativistic Doppler factor sqrt((1 + beta) / (1 - beta)); blue up to 74 degrees off
    assert g[15, 20] == pytest.approx(math.sqrt(3.0), rel=2e-3) and g.min() > 1.0
    # one sample per pixel at the AOV's own sample: the pixel is that sample's g^4
    np.testing.assert_allclose(beamed.rgb[..., 1], g**4, rtol=1e-5)


def test_falling_camera_sees_the_shadow_shrink_by_aberration():
    """A camera falling from rest at infinity (v = sqrt(2M/r) inward) sees Schwarzschild's shadow at
    cos a' = (cos a + v) / (1 + v cos a), a the static observer's angle (sin a = 3 sqrt(3) M sqrt(1 - 2M/r) / r,
    a > 90 degrees inside the photon sphere): measured on one image row through the centre. The falling camera's
    view is continuous through the horizon: just inside it the shadow is the formula's limit at r = 2M."""
    for r in (12.0, 4.0, 2.6, 2.0 - 1e-6):
        if r < 2.0:  # just inside the horizon: the limit of the formula at r -> 2M, acos(23 / 31)
            cases = (("free_fall", math.acos(23.0 / 31.0)),)
        else:
            static = math.asin(3 * math.sqrt(3) * math.sqrt(1 - 2 / r) / r)
            if r < 3.0:
                static = math.pi - static
            v = math.sqrt(2 / r)
            cases = (("free_fall", math.acos((math.cos(static) + v) / (1 + v * math.cos(static)))), ("local", static))
        for kind, angle in cases:
            # a shadow wider than a hemisphere is measured as the sky's window behind the camera
            outward = angle > math.radians(80.0)
            cone = math.pi - angle if outward else angle
            half = min(math.radians(85.0), 1.3 * cone)
            width = 801
            fov = 2 * math.degrees(math.atan(math.tan(half) / width))  # one row spanning +-half horizontally
            camera = {"position": [0.0, -r, 0.0], "look_at": [0.0, -2 * r if outward else 0.0, 0.0], "fov": fov,
                      "observer": kind}  # fmt: skip
            scene = scene_from_dict({"version": 1, "metric": {"name": "schwarzschild", "mass": 1.0}, "camera": camera,
                                     "environment": {"color": [1.0, 1.0, 1.0]}, "render": {"width": width, "height": 1},
                                     "outputs": {"aovs": ["status"]}}, base_dir=".")  # fmt: skip
            img = wv.render(scene, spp=1, pixel_sampler="independent", seed=1)
            inside = np.flatnonzero(img.aovs["status"][0] == (0 if outward else 2))  # escaped or horizon
            edge = (inside.max() + 1 - 0.5 * width) / (0.5 * width) * math.tan(half)  # at the last pixel's edge
            pixel = math.tan(half) / (0.5 * width)
            measured = math.atan(edge)
            assert abs(measured - cone) <= 2 * pixel, (r, kind, math.degrees(measured), math.degrees(cone))


def test_scene_file_observers_and_their_errors(tmp_path):
    base = 'version = 1\n[metric]\nname = "schwarzschild"\nmass = 1.0\n[camera]\nposition = [0, -10, 0]\n'
    def load(extra):
        p = tmp_path / "s.toml"
        p.write_text(base + extra)
        return wv.scene.load_scene(p)
    assert load('observer = "free_fall"\n').camera["observer"]["kind"] == "free_fall"
    assert load('velocity = [0.3, 0, 0]\n').camera["observer"]["kind"] == "moving"
    assert load('observer = "free_fall"\nfall_from = 20.0\n').camera["observer"]["fall_from"] == 20.0
    assert "observer" not in load("").camera
    cases = {'velocity = [0.8, 0.7, 0]\n': ("s.toml:7", "slower than light"),
             'observer = "orbit"\naxis = [0, 1, 0]\n': ("s.toml:7", "plane through the centre"),
             'observer = "static"\nfall_from = 3.0\n': ("s.toml:8", "belongs to observer = 'free_fall'"),
             'observer = "free_fall"\nfall_from = 5.0\n': ("s.toml:7", "above it"),
             'observer = "flying"\n': ("s.toml:7", "observer"),
             'shift = "blue"\n': ("s.toml:7", "shift")}  # fmt: skip
    for extra, (where, what) in cases.items():
        with pytest.raises(SceneError, match=what) as info:
            load(extra)
        assert where in str(info.value), str(info.value)


def test_rays_traced_back_from_inside_the_horizon_end_cleanly():
    """A camera falling through the horizon: every ray escapes or ends on the horizon (none runs out of steps
    or breaks a conservation law), and the picture is the same just outside and just inside it."""
    fractions = []
    for r in (2.0 + 1e-4, 2.0 - 1e-4, 1.0, 0.3):
        for look in (0.0, -2 * r):
            camera = {"position": [0.0, -r, 0.0], "look_at": [0.0, look, 0.0], "fov": 120.0, "observer": "free_fall"}
            scene = scene_from_dict({"version": 1, "metric": {"name": "schwarzschild", "mass": 1.0}, "camera": camera,
                                     "environment": {"color": [1.0, 1.0, 1.0]}, "render": {"width": 41, "height": 41},
                                     "outputs": {"aovs": ["status"]}}, base_dir=".")  # fmt: skip
            status = wv.render(scene, spp=1).aovs["status"]
            assert set(np.unique(status)) <= {0.0, 2.0}, (r, look, np.unique(status))
            if look == 0.0:
                fractions.append(float((status == 0).mean()))
    assert abs(fractions[0] - fractions[1]) <= 2 / 41**2
    assert fractions[0] > fractions[2] > fractions[3]  # the sky shrinks as the camera falls in


def test_image_panel_shadow_mark_of_a_falling_camera_is_the_aberrated_circle():
    """The teaching view's exact shadow edge (viewer/image_marks.py) for a camera falling from infinity at
    r = 12: cos a' = (cos a + v) / (1 + v cos a), drawn where the render puts it."""
    from warpviz.viewer.image_marks import edge_circle

    r = 12.0
    static = math.asin(3 * math.sqrt(3) * math.sqrt(1 - 2 / r) / r)
    v = math.sqrt(2 / r)
    expect = math.acos((math.cos(static) + v) / (1 + v * math.cos(static)))
    cam = {"position": [0.0, -r, 0.0], "look_at": [0.0, 0.0, 0.0], "fov": 60.0, "width": 100, "height": 100,
           "observer": {"kind": "free_fall"}}  # fmt: skip
    points, label = edge_circle(SCHW, cam, 100, 100)
    assert label == f"shadow radius {math.degrees(expect):.3g}° (exact, aberrated)"
    radius_px = np.linalg.norm(points - 50.0, axis=1)
    t = math.tan(math.radians(30.0))
    np.testing.assert_allclose(radius_px, 50.0 * math.tan(expect) / t, rtol=1e-9)  # centred: radial motion
