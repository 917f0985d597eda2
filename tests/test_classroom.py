"""The numbers docs/classroom.md asks students to compare with theory, computed as the page says."""

import math

import numpy as np
import pytest

import warpviz as wv
from warpviz.scene.camera import pinhole_directions


@pytest.mark.parametrize("b, exact, weak", [(6.0, 98.173, 38.197), (10.0, 33.775, 22.918), (20.0, 13.512, 11.459)])
def test_bent_rays_deflection_against_4m_over_b(b, exact, weak):
    rays = wv.trace(wv.Schwarzschild(mass=1.0), [-1000.0, b, 0.0], [1.0, 0.0, 0.0], tol=1e-10)
    d = rays.final_directions[0]
    assert math.degrees(math.atan2(-d[1], d[0]) % (2 * math.pi)) == pytest.approx(exact, abs=2e-3)
    assert math.degrees(4.0 / b) == pytest.approx(weak, abs=1e-3)
    assert wv.Schwarzschild(mass=1.0).critical_impact_parameter == pytest.approx(3 * math.sqrt(3))


def test_shadow_size_of_fig07_against_the_closed_form():
    """fig07: M = 2.5 seen from r = 110 (44 M); the shadow's angular radius asin(3 sqrt(3) M sqrt(1 - 2M/r) / r)."""
    closed = math.degrees(wv.Schwarzschild(mass=2.5).shadow_angle(110.0))
    assert closed == pytest.approx(6.625, abs=1e-3)
    img = wv.render("fig07", width=480, height=360, spp=1, aovs=["status"])
    status, cam = img.aovs["status"], img.native_scene["camera"]
    row = int(np.argmax((status == 2).sum(axis=1)))
    cols = np.flatnonzero(status[row] == 2)
    left, right = pinhole_directions(cam, [[cols.min(), row], [cols.max(), row]])
    measured = 0.5 * math.degrees(math.acos(float(left @ right)))  # centres of the outermost shadow pixels
    pixel = 58.0 / 360
    assert closed - pixel <= measured + pixel / 2 and measured <= closed + pixel


def test_frame_dragging_band_of_kerr_and_schwarzschild():
    a = 0.9
    pro, retro = wv.Kerr(mass=1.0, spin=a).photon_orbit_radii
    b = [-(r**3 - 3 * r**2 + a * a * r + a * a) / (a * (r - 1.0)) for r in (pro, retro)]
    assert b == pytest.approx([2.844, -6.832], abs=1e-3)
    assert wv.Schwarzschild(mass=1.0).critical_impact_parameter == pytest.approx(5.196, abs=1e-3)


def _axis_crossing(alpha: float) -> float:
    """Where the ray leaving fig04's camera (0, -40, 0) at angle alpha from the axis crosses the far
    half of the optical axis (inf if it does not)."""
    d = [math.sin(alpha), math.cos(alpha), 0.0]
    rays = wv.trace(wv.Schwarzschild(mass=1.0), [0.0, -40.0, 0.0], [d], record=True, tol=1e-11, escape_radius=400)
    p = rays.points
    hits = [k for k in np.flatnonzero((p[:-1, 0] > 0) & (p[1:, 0] <= 0)) if p[k, 1] > 0]
    if not hits:
        return math.inf
    k = hits[0]
    t = p[k, 0] / (p[k, 0] - p[k + 1, 0])
    return float(p[k, 1] + t * (p[k + 1, 1] - p[k, 1]))


def test_einstein_ring_of_fig04():
    """The ring's angular radius: the camera ray that reaches the source's centre (0, 40, 0) on the axis;
    weak field sqrt(4 M D_ls / (D_l D_s)); the shadow from 40 M; pixel (20, 36) lies on the ring."""
    lo, hi = math.radians(7.5), math.radians(20.0)
    for _ in range(30):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if _axis_crossing(mid) < 40.0 else (lo, mid)
    ring = math.degrees(0.5 * (lo + hi))
    assert ring == pytest.approx(15.02, abs=0.01)
    assert math.degrees(math.sqrt(4 * 40.0 / (40.0 * 80.0))) == pytest.approx(12.81, abs=0.01)
    assert math.degrees(wv.Schwarzschild(mass=1.0).shadow_angle(40.0)) == pytest.approx(7.27, abs=0.01)
    img = wv.render("fig04", spp=8, record_pixels=[[20, 36], [40, 30]])
    cam = img.native_scene["camera"]
    assert math.degrees(math.acos(pinhole_directions(cam, [[20, 36]])[0][1])) == pytest.approx(15.54, abs=0.01)
    x = img.rays.ray_data["pixel_x"]
    assert set(img.rays.status_names[x == 20]) == {"hit"}  # the ring pixel sees the glowing sphere
    assert set(img.rays.status_names[x == 40]) == {"horizon"}  # the README's old example pixel fell in


def test_wormhole_window_of_fig13():
    """From fig13's camera (areal radius R = |(0, -15, 2)|) rays within asin(b0 / R) of the centre pass the
    throat (b < b0) onto the other sheet."""
    ellis = wv.EllisWormhole(throat=8.0)
    position = np.array(wv.scene.load_scene("fig13").native()["camera"]["position"])
    radius = float(np.linalg.norm(position))
    window = math.degrees(math.asin(8.0 / radius))
    assert window == pytest.approx(31.91, abs=0.01)
    inward = -position / radius
    side = np.cross(inward, [0.0, 0.0, 1.0])
    side /= np.linalg.norm(side)
    angles = np.radians([window - 0.2, window + 0.2])
    dirs = np.cos(angles)[:, None] * inward + np.sin(angles)[:, None] * side
    rays = wv.trace(ellis, position, dirs, escape_radius=500)
    assert rays.final_sheets.tolist() == [-1, 1]


def test_window_of_the_fig13_wormhole_against_the_closed_form():
    """fig13: the camera at areal radius |(0, -15, 2)| = 15.13 from an Ellis throat of radius 8 sees the
    other side through a circle of angular radius asin(b0 / r), which the image panel draws and labels."""
    from warpviz.scene import load_scene
    from warpviz.viewer.image_marks import edge_circle

    scene = load_scene("fig13")
    cam = scene.native()["camera"]
    r = float(np.linalg.norm(cam["position"]))
    assert math.degrees(math.asin(8.0 / r)) == pytest.approx(31.91, abs=1e-2)
    _, label = edge_circle(scene.metric, cam, cam["width"], cam["height"])
    assert label == "window radius 31.9° (exact)"


def test_falling_camera_demo_numbers():
    """docs/classroom.md demo 6: at r = 12 M the static camera's shadow is 23.3 degrees, the camera falling from
    infinity (v = sqrt(2M/r) = 0.408) sees 15.2 degrees, and at the horizon acos(23/31) = 42.1 degrees."""
    r = 12.0
    static = math.asin(3 * math.sqrt(3) * math.sqrt(1 - 2 / r) / r)
    v = math.sqrt(2 / r)
    falling = math.acos((math.cos(static) + v) / (1 + v * math.cos(static)))
    assert (round(math.degrees(static), 1), round(v, 3), round(math.degrees(falling), 1)) == (23.3, 0.408, 15.2)
    assert round(math.degrees(math.acos(23 / 31)), 1) == 42.1
    assert math.degrees(wv.Schwarzschild(mass=1.0).shadow_angle(r)) == pytest.approx(math.degrees(static), abs=1e-9)


def test_speckles_come_from_light_turned_back_by_the_hole():
    """docs/classroom.md, "When the picture speckles": the samples that found a lamp by chance where the light
    samples could not have (stats["unsampled_light_hits"] of stats["light_hits"]): none in flat space, none in fig07
    (its exact lens map draws the images of order 1 and 2, which light the ceiling) but a few per thousand when it
    draws order 1 only (lens_images = 2), more than one per hundred in fig10d without photons, whose ceiling they
    light (the lamp hangs below it); with the room's photons, which carry the light the hole turns back, a few per
    thousand."""
    def share(room, **kw):
        hits = unsampled = 0
        for seed in range(4):  # (fig07: ~6 such samples, fig10d ~44 without photons, ~4 with)
            st = wv.render(room, width=48, height=36, spp=16, seed=seed, **kw).stats
            hits, unsampled = hits + st["light_hits"], unsampled + st["unsampled_light_hits"]
        assert hits > 2000
        return unsampled / hits

    assert share("fig07", flat=True) == 0.0
    assert share("fig07") == 0.0
    assert 0.0 < share("fig07", lens_images=2) < 0.007
    assert share("fig10d", photons_per_pixel=0.0) > 0.01
    assert share("fig10d") < 0.004
