"""Schwarzschild against exact results: deflection angles, shadow edges, horizon and photon sphere."""

import math

import numpy as np
import pytest
from scipy.integrate import quad

import warpviz as wv

from conftest import deflection, launch_direction

BH = wv.Schwarzschild(mass=1.0)


@pytest.mark.parametrize("case", range(4))
def test_deflection_angle_from_asymptotic_directions(exact, case):
    ref = exact["schwarzschild_deflection"]["cases"][case]
    b = ref["b"]
    alpha = deflection(BH, 1e3, launch_direction(1e3, b), tol=1e-10)
    assert alpha == pytest.approx(ref["alpha"], rel=1e-8)


def tail_azimuth(r: float, b: float) -> float:
    """Exact azimuth swept by a ray of impact parameter b between radius r and infinity (outside r0)."""
    return quad(lambda u: b / math.sqrt(1.0 - b * b * u * u * (1.0 - 2.0 * u)), 0.0, 1.0 / r, epsabs=0, epsrel=1e-13)[0]


def test_deflection_angle_from_swept_azimuth_of_recorded_path(exact):
    """Independent of the asymptotic-direction extrapolation: phi swept along the recorded polyline,
    plus the exact azimuth beyond its two ends, is pi + alpha."""
    ref = exact["schwarzschild_deflection"]["cases"][1]
    b, r0 = ref["b"], 100.0
    rays = wv.trace(BH, [-r0, 0.0, 0.0], launch_direction(r0, b), tol=1e-11, record=True, escape_radius=r0)
    pts = rays.ray_points(0)
    phi = np.unwrap(np.arctan2(pts[:, 1], pts[:, 0]))
    swept = abs(phi[-1] - phi[0])
    r_end = rays.point_data["r"][-1]
    total = swept + tail_azimuth(r0, b) + tail_azimuth(r_end, b)
    assert r_end == pytest.approx(r0, rel=1e-10)  # end point located on the escape sphere
    assert total - math.pi == pytest.approx(ref["alpha"], rel=1e-8)


@pytest.mark.parametrize("case", range(3))
def test_shadow_edge_by_bisection(exact, case):
    """Static camera at r: the boundary between captured and escaping rays is the exact shadow angle."""
    ref = exact["schwarzschild_shadow"]["cases"][case]
    r, theta_ref = ref["r"], math.radians(ref["theta_deg"])

    def captured(theta):
        d = [-math.cos(theta), math.sin(theta), 0.0]  # angle theta from the direction to the hole
        rays = wv.trace(BH, [r, 0.0, 0.0], d, tol=1e-10, escape_radius=200.0)
        return rays.status_names[0] == "horizon"

    lo, hi = theta_ref - 1e-2, theta_ref + 1e-2
    assert captured(lo) and not captured(hi)
    while hi - lo > 2e-7:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if captured(mid) else (lo, mid)
    assert 0.5 * (lo + hi) == pytest.approx(theta_ref, abs=1e-6)


def test_radial_ray_ends_on_the_horizon():
    rays = wv.trace(BH, [0.0, 0.0, 30.0], [0.0, 0.0, -1.0], record=True)
    assert rays.status[0] == wv.RayStatus.HORIZON
    assert np.linalg.norm(rays.final_positions[0]) == pytest.approx(2.0, abs=1e-10)
    assert rays.point_data["r"][-1] == pytest.approx(2.0, abs=1e-10)
    np.testing.assert_allclose(rays.final_directions[0], [0, 0, -1], atol=1e-12)


def test_photon_sphere_orbit_stays_near_r_3_for_windings():
    """A ray launched tangentially at r = 3M circles there: r stays near 3 for over a full turn."""
    rays = wv.trace(BH, [3.0, 0.0, 0.0], [0.0, 1.0, 0.0], tol=1e-12, record=True, max_steps=20000)
    pts = rays.ray_points(0)
    r = rays.point_data["r"]
    phi = np.unwrap(np.arctan2(pts[:, 1], pts[:, 0]))
    near = np.abs(r - 3.0) < 1e-6
    assert phi[near].max() - phi[0] > 2 * math.pi
    assert rays.invariant_drift["L2"][0] < 1e-9


def test_steppers_agree_and_rk4_needs_more_work():
    """All steppers reach the same point of the escape sphere; the seed RK4 takes many more steps."""
    d = launch_direction(50.0, 7.0)
    out = {}
    for stepper, tol in [("dop853", 1e-12), ("dopri5", 1e-10), ("rk4", 1e-10)]:
        rays = wv.trace(BH, [-50.0, 0, 0], d, stepper=stepper, tol=tol, escape_radius=60.0)
        out[stepper] = rays
    ref = out["dop853"].final_positions[0]
    for s in ("dopri5", "rk4"):
        assert np.abs(out[s].final_positions[0] - ref).max() < 1e-6 * 60.0, s
    assert out["rk4"].n_steps[0] > 5 * out["dopri5"].n_steps[0]
