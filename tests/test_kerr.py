"""Kerr: conservation of E, Lz and Carter's Q on hard rays; reduction to Schwarzschild; symmetries."""

import math

import numpy as np
import pytest

import warpviz as wv

KERR = wv.Kerr(mass=1.0, spin=0.9)


@pytest.mark.parametrize("inclination_deg", [0.0, 1.0, 2.5, 5.0])
@pytest.mark.parametrize("b", [4.0, 7.0])
def test_polar_rays_conserve_e_lz_q(inclination_deg, b):
    """Rays whose orbital plane contains (or nearly contains) the spin axis cross over the poles."""
    i, psi = math.radians(inclination_deg), math.asin(b / 40.0)
    d = [math.cos(psi), math.sin(psi) * math.sin(i), math.sin(psi) * math.cos(i)]
    rays = wv.trace(KERR, [-40.0, 0.0, 0.0], d, tol=1e-11, record=True)
    assert rays.status_names[0] in ("escaped", "horizon")
    pts = rays.ray_points(0)
    if rays.status_names[0] == "escaped":  # it went over the pole: the cylindrical radius got small
        assert np.hypot(pts[:, 0], pts[:, 1]).min() < 1.0
    for name in ("E", "Lz", "Q"):
        assert rays.invariant_drift[name][0] <= 1e-9, name


@pytest.mark.parametrize("offset", [-1e-4, 0.0, 1e-4])
def test_rays_circling_near_the_prograde_photon_orbit_conserve_e_lz_q(offset, exact):
    r_ph = exact["kerr"]["cases"][0]["photon_orbit_prograde"] * (1.0 + offset)
    x = math.sqrt(r_ph**2 + KERR.a**2)  # Kerr-Schild x of Boyer-Lindquist r on the equator
    rays = wv.trace(KERR, [x, 0.0, 0.0], [0.0, 1.0, 0.0], tol=1e-11, record=True, max_steps=50_000)
    pts = rays.ray_points(0)
    phi = np.unwrap(np.arctan2(pts[:, 1], pts[:, 0]))
    assert phi.max() - phi[0] > 2 * math.pi  # at least one full prograde turn
    for name in ("E", "Lz", "Q"):
        assert rays.invariant_drift[name][0] <= 1e-9, name


def test_spin_zero_equals_schwarzschild():
    rng = np.random.default_rng(4)
    dirs = rng.normal(size=(64, 3))
    origin = [-30.0, 5.0, 3.0]
    k = wv.trace(wv.Kerr(mass=1.0, spin=0.0), origin, dirs, tol=1e-10, escape_radius=100.0)
    s = wv.trace(wv.Schwarzschild(mass=1.0), origin, dirs, tol=1e-10, escape_radius=100.0)
    np.testing.assert_array_equal(k.status, s.status)
    np.testing.assert_allclose(k.final_positions, s.final_positions, rtol=0, atol=1e-10 * 100.0)
    np.testing.assert_allclose(k.final_directions, s.final_directions, rtol=0, atol=1e-10)


def test_negative_spin_is_the_mirror_image():
    rng = np.random.default_rng(8)
    dirs = rng.normal(size=(32, 3))
    o = np.array([-20.0, 3.0, 1.0])
    mirror = np.array([1.0, -1.0, 1.0])
    plus = wv.trace(wv.Kerr(mass=1.0, spin=0.7), o, dirs, tol=1e-10, escape_radius=100.0)
    minus = wv.trace(wv.Kerr(mass=1.0, spin=-0.7), o * mirror, dirs * mirror, tol=1e-10, escape_radius=100.0)
    np.testing.assert_array_equal(plus.status, minus.status)
    np.testing.assert_allclose(plus.final_positions * mirror, minus.final_positions, atol=1e-7)


def test_ergoregion_origins_use_the_zamo_and_horizon_origins_are_rejected():
    x = math.sqrt(1.7**2 + KERR.a**2)  # r = 1.7: inside the ergosphere (r < 2 on the equator), outside r+
    rays = wv.trace(KERR, [x, 0, 0], [[1.0, 0, 0], [0, -1.0, 0]], tol=1e-10)
    assert np.all(rays.status <= wv.RayStatus.HORIZON)
    assert rays.invariant_drift["H"].max() < 1e-7
    with pytest.raises(ValueError, match=r"origins\[1\] = .* inside the horizon"):
        wv.trace(KERR, [[30.0, 0, 0], [1.0, 0, 0.2]], [1.0, 0, 0])


def test_frame_dragging_prograde_rays_get_closer_than_retrograde():
    """At equal impact parameter, a prograde equatorial ray is captured where a retrograde one escapes."""
    b = 4.0  # between the Kerr a=0.9 prograde (~2.9) and retrograde (~6.9) critical impact parameters
    o = np.array([[-1000.0, -b, 0.0], [-1000.0, b, 0.0]])  # y = -b passes with Lz > 0: prograde
    rays = wv.trace(KERR, o, [1.0, 0.0, 0.0], tol=1e-10)
    assert rays.status_names.tolist() == ["escaped", "horizon"]
