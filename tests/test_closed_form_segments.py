"""Closed-form segments (renderer_ext/spacetime/planar_orbit.h, integrators/orbit_segment.h).

A Schwarzschild ray's orbit u(phi) is a Jacobi elliptic function of the azimuth: the functions against
scipy, the orbit against the integrator at tol 1e-12 (far, near the photon sphere, falling in, escaping),
and rendered images against ``segment_method="integrate"``: the same paths, so the same image to the
integrator's tolerance, pixel by pixel, with the statuses and the fallbacks where the closed form does not
apply.
"""

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from scipy.special import elliprd, elliprf, ellipj, ellipk, ellipkinc

import warpviz as wv
from warpviz._native import testing
from warpviz.scene import load_scene


def test_sine_and_cosine_match_libm_to_the_last_bit_or_two():
    """core/trig.h's sine and cosine (the closed-form orbits' two per point) against numpy's, over the
    quadrant boundaries, small and large arguments, and the ones handed on to libm."""
    rng = np.random.default_rng(2)
    quarter = np.pi / 2 * np.arange(-40, 41)
    x = np.concatenate([rng.uniform(-30.0, 30.0, 20000), rng.uniform(-1e4, 1e4, 5000), quarter,
                        np.nextafter(quarter, np.inf), np.nextafter(quarter, -np.inf), [0.0, -0.0, 1e-300, 5e-324],
                        rng.uniform(-1e-8, 1e-8, 100), [1e5, -2e6, 1e300]])
    s, c = testing.sin_cos(x)
    assert np.abs(s - np.sin(x)).max() <= 4.5e-16 and np.abs(c - np.cos(x)).max() <= 4.5e-16
    small = np.abs(x) < 1e-6
    assert np.all(np.abs(s[small] - np.sin(x[small])) <= 1e-16 * np.abs(x[small]) + 1e-300)
    assert np.isnan(testing.sin_cos(np.array([np.nan, np.inf]))[0]).all()


@pytest.mark.parametrize("m", [1e-8, 1e-3, 0.1, 0.3, 0.5, 0.5000001, 0.9, 0.99, 0.999, 0.9999])
def test_jacobi_functions_and_elliptic_integrals_match_scipy(m):
    x = np.linspace(-3.0, 12.0, 301)
    values, K = testing.jacobi(x, m)
    sn, cn, dn, _ = ellipj(x, m)
    assert np.abs(values - np.stack([sn, cn, dn], axis=1)).max() < 5e-14
    assert K == pytest.approx(ellipk(m), rel=1e-14)
    for phi in np.linspace(0.0, np.pi, 13):
        ref = ellipkinc(phi, m) if phi <= np.pi / 2 else 2 * ellipk(m) - ellipkinc(np.pi - phi, m)
        assert testing.elliptic_f(phi, m) == pytest.approx(ref, rel=1e-13, abs=1e-15)


def test_carlson_rf_and_its_gradient_match_scipy():
    """R_F to rounding (the seventh-order series after duplication to 1 % spread), in doubles and in duals;
    its gradient is -R_D / 6 with the differentiated argument last (DLMF 19.18.1)."""
    rng = np.random.default_rng(3)
    triples = [*(tuple(10.0 ** rng.uniform(-6, 3, 3)) for _ in range(200)), (0.0, 1.0, 2.0), (1.0, 0.0, 1e-9),
               (1.0, 1.0, 1.0), (2.0, 2.0, 2.0 + 1e-12), (1e-300, 1.0, 3.0)]  # fmt: skip
    for x, y, z in triples:
        value, dual_value, dx, dy, dz = testing.carlson_rf(x, y, z)
        ref = elliprf(x, y, z)
        assert value == pytest.approx(ref, rel=2e-15) and dual_value == pytest.approx(value, rel=5e-16)
        if min(x, y, z) == 0.0:
            continue  # (a zero argument's square root has no derivative: the duals give NaN, never used so)
        for got, (a, b, c) in ((dx, (y, z, x)), (dy, (z, x, y)), (dz, (x, y, z))):
            if c > 1e-200:
                assert got == pytest.approx(-elliprd(a, b, c) / 6.0, rel=1e-14)


def test_jacobi_functions_refuse_a_parameter_they_cannot_reach():
    with pytest.raises(ValueError, match="parameter m"):
        testing.jacobi(np.zeros(1), 0.99999)


def traced_orbit(mass, r0, psi):
    """The integrator's orbit from (r0, 0, 0) at angle psi from the outward radial (static frame)."""
    ray = wv.trace(wv.Schwarzschild(mass=mass), [r0, 0.0, 0.0], [np.cos(psi), np.sin(psi), 0.0], tol=1e-13,
                   stepper="dop853", record=True, escape_radius=400.0 * mass)  # fmt: skip
    pts = ray.ray_points(0)
    phi = np.unwrap(np.arctan2(pts[:, 1], pts[:, 0]))
    return phi, np.linalg.norm(pts, axis=1), ray.status_names[0]


@pytest.mark.parametrize(
    "r0, psi",
    [
        (20.0, 2.0),     # inward, b well above critical: round the hole and out
        (20.0, 0.7),     # outward
        (20.0, 2.9),     # inward, b below critical: falls in
        (20.0, 2.87),    # b just above critical (the photon sphere at 3M, a few windings close to it)
        (8.0, 1.2),      # outward from inside the room-sized region
        (400.0, 3.12),   # far away, weak field
    ],
)
def test_the_orbit_is_the_integrators_to_1e9(r0, psi):
    """Against dop853 at tol 1e-13, down to just outside the horizon for the rays that fall in."""
    mass = 1.0
    phi, r, status = traced_orbit(mass, r0, psi)
    b = r0 * np.sin(psi) / np.sqrt(1.0 - 2.0 * mass / r0)
    inward = bool(np.cos(psi) < 0.0)
    keep = r > 2.001 * mass
    got = testing.planar_orbit(mass, float(b), 1.0 / r0, inward, np.ascontiguousarray(phi[keep]), np.array([1.0 / r0]))
    assert got is not None
    u, dudphi, _ = got
    assert np.abs(1.0 / (u * r[keep]) - 1.0).max() < 1e-9
    # du/dphi agrees with the orbit equation (du/dphi)^2 = 1/b^2 - u^2 + 2 M u^3
    assert np.allclose(dudphi**2, 1.0 / b**2 - u**2 + 2.0 * mass * u**3, rtol=1e-8, atol=1e-14)


@pytest.mark.parametrize("b, inward", [(9.0, True), (9.0, False), (4.0, True), (4.0, False), (5.25, True)])
def test_phi_of_inverts_the_orbit(b, inward):
    mass, u0 = 1.0, 1.0 / 10.0
    targets = np.array([0.0, 0.02, 0.05, 0.08, 0.2])
    u_start = testing.planar_orbit(mass, b, u0, inward, np.zeros(1), targets)
    assert u_start is not None
    _, _, at = u_start
    for k, target in enumerate(targets):
        for branch in (0, 1):
            phi = at[k, branch]
            if np.isfinite(phi):
                u, _, _ = testing.planar_orbit(mass, b, u0, inward, np.array([phi]), targets)
                assert u[0] == pytest.approx(target, abs=1e-12)
    # above critical a ray comes back out to u = 0; below it one moving inward never does
    assert np.isfinite(at[0, 1]) == (not inward or b > 3.0 * np.sqrt(3.0))


def render_both(scene, **kw):
    images = {}
    for method in ("integrate", "closed_form"):
        img = wv.render(scene, segment_method=method, progress=None, **kw)
        images[method] = img
    return images["integrate"], images["closed_form"]


@pytest.mark.parametrize("name", ["fig07_schwarzschild_cornell", "fig08_glass_ball_black_hole"])
def test_a_room_renders_the_same_image_in_closed_form(name):
    """Same seeds, so the same paths: pixel by pixel, equal to the integrator's tolerance. (Without the rooms'
    photons: a gather's radius reaches to its 16th nearest photon, so photons moved by the tolerance move it, and
    the photons' own test is tests/test_photon_mapping.py; without the camera's own light samples, whose rays
    follow the lamp's images of order 2 and 3, where the integrator's error grows e^(2 pi) a winding and one
    such ray in a lamp pixel may land on the lamp in closed form and beside it integrated.)"""
    scene = load_scene(f"scenes/{name}.toml")
    a, b = render_both(scene, width=40, height=30, spp=4, edge_samples=1, threads=2, photons=0,
                       photons_per_pixel=0.0, camera_light_samples=False)
    assert a.stats["photon_passes"] == 0 and b.stats["photon_passes"] == 0  # (the scenes' own density off too)
    assert b.stats["steps"] < 0.01 * a.stats["steps"]  # (a few segments start below the capture radius)
    rel = np.abs(a.rgb - b.rgb).sum(-1) / (np.abs(a.rgb).sum(-1) + 1e-9)
    assert np.median(rel) < 1e-5
    assert np.mean(rel > 1e-3) < 0.02  # a path that grazes an edge may take the other side
    assert b.rgb.mean() == pytest.approx(a.rgb.mean(), rel=2e-3)
    ca, cb = a.stats["segments_by_status"], b.stats["segments_by_status"]
    for status in ("hit", "escaped", "horizon"):
        assert cb[status] == pytest.approx(ca[status], rel=0.01, abs=3)


@pytest.mark.parametrize("name", ["fig07_schwarzschild_cornell", "fig08_glass_ball_black_hole"])
def test_direct_light_in_closed_form_is_the_integrators_at_1e10(name):
    """Direct light alone (max_depth 2): every light sample's segment is aimed at its light point, and in closed
    form it is searched for what is in the way only up to that point and ends on the light's plane there
    (orbit_segment.h, aimed()); the integrator at 1e-10 traces the whole ray. Same seeds, same paths: pixel by
    pixel equal to 1e-6 (measured: 2e-8), and the same segments by status (the shadows of the boxes and balls,
    the lamp's images round the hole)."""
    scene = load_scene(f"scenes/{name}.toml")
    kw = dict(width=40, height=30, spp=4, edge_samples=1, threads=2, photons=0, camera_light_samples=False, max_depth=2)
    a = wv.render(scene, segment_method="integrate", stepper="dop853", tol=1e-10, **kw)
    b = wv.render(scene, **kw)
    assert b.stats["steps"] < 0.01 * a.stats["steps"]
    rel = np.abs(a.rgb - b.rgb).sum(-1) / (np.abs(a.rgb).sum(-1) + 1e-9)
    assert rel.max() < 1e-6, rel.max()
    assert a.stats["segments_by_status"] == b.stats["segments_by_status"]


@pytest.mark.parametrize("name", ["fig04_einstein_ring", "fig02_accretion_disk"])
def test_escaped_rays_see_the_same_sky_and_disks(name):
    """The sky direction at infinity comes from the orbit's asymptote (no Born tail). Pixel by pixel without the
    camera's own star samples, which see a star's images of order 2 and 3 at the shadow's rim in every sample, where
    the integrator's error is amplified e^(2 pi) a winding (there the two methods differ in the stars' profiles
    by far more than 1e-3); with them, the same mean."""
    scene = load_scene(f"scenes/{name}.toml")
    a, b = render_both(scene, width=48, height=36, spp=2, edge_samples=1, threads=2, camera_light_samples=False)
    rel = np.abs(a.rgb - b.rgb).sum(-1) / (np.abs(a.rgb).sum(-1) + 1e-9)
    assert np.median(rel) < 1e-5
    assert np.mean(rel > 1e-3) < 0.02
    assert b.rgb.mean() == pytest.approx(a.rgb.mean(), rel=2e-3)
    a, b = render_both(scene, width=48, height=36, spp=2, edge_samples=1, threads=2)
    assert b.rgb.mean() == pytest.approx(a.rgb.mean(), rel=2e-3)


def test_other_metrics_integrate_bit_for_bit():
    """Kerr has no closed-form orbit: both settings are the same render."""
    scene = load_scene("scenes/fig10d_kerr_cornell_a09.toml")
    a, b = render_both(scene, width=16, height=12, spp=2, edge_samples=1, threads=2)
    assert np.array_equal(a.rgb, b.rgb)
    assert a.stats["steps"] == b.stats["steps"] > 0


def test_reissner_nordstrom_without_charge_is_schwarzschild_in_closed_form():
    """The closed form is chosen from the lens polynomial a metric declares, not from its name."""
    scene = load_scene("scenes/fig07_schwarzschild_cornell.toml")
    rn = dataclasses.replace(scene, metric=wv.ReissnerNordstrom(mass=scene.metric.mass, charge=0.0))
    a = wv.render(scene, width=16, height=12, spp=2, edge_samples=1, threads=2, progress=None)
    b = wv.render(rn, width=16, height=12, spp=2, edge_samples=1, threads=2, progress=None)
    assert b.stats["steps"] == a.stats["steps"] < 1000
    assert np.allclose(a.rgb, b.rgb, rtol=1e-6, atol=1e-7)


def test_a_mesh_in_the_room_renders_the_same_in_closed_form(tmp_path):
    """Triangles (planes with edges) and, where a piece meets more of them than its lists hold, the whole
    BVH per chord; a big mesh close to the camera covers many pixels."""
    root = Path(__file__).resolve().parents[1] / "scenes"
    text = (root / "fig07_schwarzschild_cornell.toml").read_text()
    text += f"""
[[objects]]
name = "panels"
shape = "mesh"
file = "{(root / 'meshes' / 'satellite_panels.obj').as_posix()}"
translate = [18.0, -40.0, -8.0]
scale = 9.0
rotate = [20.0, 10.0, 30.0]
material = "red"
"""
    path = tmp_path / "room_with_mesh.toml"
    path.write_text(text)
    scene = load_scene(path)
    # (without the camera's own light samples, as in the room's test above)
    a, b = render_both(scene, width=40, height=30, spp=4, edge_samples=1, threads=2, camera_light_samples=False)
    assert b.stats["steps"] < 0.01 * a.stats["steps"]
    rel = np.abs(a.rgb - b.rgb).sum(-1) / (np.abs(a.rgb).sum(-1) + 1e-9)
    assert np.median(rel) < 1e-5
    assert np.mean(rel > 1e-3) < 0.02
    assert b.rgb.mean() == pytest.approx(a.rgb.mean(), rel=2e-3)


@pytest.mark.parametrize("segment_method", ["closed_form", "integrate"])
def test_a_small_ball_behind_a_hole_is_hit_whatever_its_size(segment_method):
    """A ball behind a hole (M = 0.1) seen in its two lensed images, its radius 0.6, 0.2 or 0.1 with the same light
    (strength 100 (0.6 / r)^2): the light that reaches the camera is nearly the same (a bigger ball spans a little
    more magnification). A long chord far from the hole passes through a small ball with both ends outside it; the
    crossing on the curve was searched only near the chord's entry and at 32 points along the piece, so a ball
    shorter than those steps was missed: at 1024 camera rays a pixel, the ball of radius 0.1 gave no light at all in
    closed form (0.3: 8 % of it) and 77 % by the integrator. Both methods see the same image."""
    from test_camera_connection import _lamp_behind_a_hole

    def seen(r):
        scene = _lamp_behind_a_hole({"name": "schwarzschild", "params": [0.1]}, radius=r)
        return wv.render(scene, spp=256, max_depth=1, edge_samples=1, light_sampling=False,
                         segment_method=segment_method).rgb[..., 0].sum()  # fmt: skip
    big, mid, small = seen(0.6), seen(0.2), seen(0.1)
    assert abs(mid / big - 1.0) < 0.08 and abs(small / big - 1.0) < 0.08, (big, mid, small)
