"""Numerical stress: near-critical windings, extreme spins, rays along and through the axis, the Ellis
throat's photon orbit, huge inputs and extreme tolerances. Every ray must end with a defined status,
finite output and its drift within tolerance."""

import math

import numpy as np
import pytest

import warpviz as wv

from conftest import launch_direction

B_CRIT = 3.0 * math.sqrt(3.0)


def assert_sane(rays, drift=1e-8):
    assert np.isin(rays.status, [s.value for s in wv.RayStatus]).all()
    assert np.isfinite(rays.final_positions).all() and np.isfinite(rays.final_directions).all()
    for name, v in rays.invariant_drift.items():
        assert v.max() < drift, name


@pytest.mark.parametrize("eps", [1e-2, 1e-4, 1e-6, 1e-8])
def test_near_critical_impact_parameters_wind_and_split_correctly(eps):
    d = [launch_direction(1e3, B_CRIT * (1 + eps)), launch_direction(1e3, B_CRIT * (1 - eps))]
    rays = wv.trace(wv.Schwarzschild(mass=1.0), [-1e3, 0, 0], d, tol=1e-10)
    assert rays.status_names.tolist() == ["escaped", "horizon"]
    assert_sane(rays)


@pytest.mark.parametrize("spin", [0.0, 0.999999, -0.9])
def test_rays_along_the_spin_axis_and_over_the_poles(spin):
    k = wv.Kerr(mass=1.0, spin=spin)
    axis = wv.trace(k, [0, 0, 50.0], [[0, 0, -1.0], [0, 0, 1.0]], tol=1e-10)
    assert axis.status_names.tolist() == ["horizon", "escaped"]
    np.testing.assert_allclose(axis.final_positions[0], [0, 0, k.horizon_radius], atol=1e-9)
    assert_sane(axis)
    pole = wv.trace(k, [-40.0, 0, 0], [math.cos(0.2), 0, math.sin(0.2)], tol=1e-10)
    assert_sane(pole, drift=1e-9)


@pytest.mark.parametrize("b", [1 - 1e-9, 1.0, 1 + 1e-9])
def test_ellis_rays_at_the_throat_radius(b):
    rays = wv.trace(wv.EllisWormhole(throat=1.0), [-100.0, 0, 0], launch_direction(100.0, b, mass=0.0), tol=1e-10)
    assert rays.status_names[0] == "escaped"
    assert_sane(rays)


def test_the_throat_photon_orbit_ends_on_its_step_budget():
    rays = wv.trace(wv.EllisWormhole(throat=1.0), [1.0, 0, 0], [0, 1.0, 0], tol=1e-10, max_steps=20_000)
    assert rays.status_names[0] == "max_steps"
    assert_sane(rays, drift=1e-6)


def test_huge_origins_and_extreme_tolerances():
    bh = wv.Schwarzschild(mass=1.0)
    assert_sane(wv.trace(bh, [1e12, 0, 0], [[-1.0, 0, 0], [-1.0, 1e-11, 0]], tol=1e-9), drift=1e-8)
    tight = wv.trace(bh, [-50.0, 0, 0], [1.0, 0.1, 0], tol=1e-15)
    assert_sane(tight, drift=1e-13)
    loose = wv.trace(bh, [-50.0, 0, 0], [[1.0, 0.1, 0], [1, 0.15, 0]], tol=1e-3)
    assert loose.status_names.tolist() == ["horizon", "escaped"]


@pytest.mark.parametrize("eps", [1e-3, 1e-6])
@pytest.mark.parametrize("metric", [wv.Schwarzschild(mass=1.0), wv.Kerr(mass=1.0, spin=0.9)],
                         ids=["schwarzschild", "kerr"])
def test_outgoing_rays_from_just_outside_the_horizon_escape(metric, eps):
    """Radially outgoing light from r = r+ (1 + eps), on the pole and in the equatorial plane, escapes
    along its initial direction. Its coordinate momentum starts at ~1/eps and falls to ~1 on the way
    out; the null-condition error is measured against the largest size it had, so the rounding
    committed near the horizon does not mark the ray as violating."""
    r0 = metric.horizon_radius * (1 + eps)
    origins = [[0, 0, r0], [0, 0, -r0]]
    directions = [[0, 0, 1], [0, 0, -1]]
    if isinstance(metric, wv.Schwarzschild):
        origins.append([r0, 0, 0])
        directions.append([1, 0, 0])
    rays = wv.trace(metric, origins, directions, tol=1e-9)
    assert set(rays.status_names) == {"escaped"}
    np.testing.assert_allclose(rays.final_directions, directions, atol=1e-9)
    assert rays.invariant_drift["H"].max() < 1e-8


def test_radial_ray_from_the_ellis_throat_crosses_to_the_other_sheet():
    """A ray starting on the throat (l = 0) and sent inward goes to the other universe, where it moves
    radially outward along the same direction from the centre (+x); sent outward it stays on ours."""
    rays = wv.trace(wv.EllisWormhole(throat=1.0), [1.0, 0, 0], [[-1.0, 0, 0], [1.0, 0, 0]], tol=1e-10)
    assert rays.status_names.tolist() == ["escaped", "escaped"]
    assert rays.final_sheets.tolist() == [-1, 1]
    np.testing.assert_allclose(rays.final_directions, [[1, 0, 0], [1, 0, 0]], atol=1e-12)
    assert_sane(rays)


def test_a_million_steps_on_the_photon_sphere_stay_bounded():
    """The seed's RK4 with a small fixed step along Schwarzschild's unstable circular photon orbit: a
    1e6-step path ends on its step budget or leaves the orbit, with finite output and bounded drift."""
    bh = wv.Schwarzschild(mass=1.0)
    rays = wv.trace(bh, [3.0, 0, 0], [0, 1.0, 0], stepper="rk4", rk4_step=1e-4, tol=1e-12,
                    max_steps=1_000_000, max_drift=1e-6)
    assert rays.status_names[0] in {"max_steps", "escaped", "horizon"}
    assert rays.n_steps[0] > 500_000
    assert_sane(rays, drift=1e-6)


@pytest.mark.parametrize("spin", [0.999, -0.999])
def test_render_from_inside_the_ergosphere_is_finite(spin):
    """A camera inside Kerr's ergosphere has no static observer: it is a ZAMO; the image is finite and
    shows the horizon below and the sky above."""
    scene = {
        "metric": {"name": "kerr", "params": [1.0, spin]},
        "camera": {"position": [1.6, 0, 0.1], "look_at": [10, 0, 0.1], "up": [0, 0, 1], "fov": 120,
                   "width": 16, "height": 12},
        "materials": [], "shapes": [], "environment": {"color": [1, 1, 1]},
    }
    img = wv.render(scene, spp=1)
    assert np.isfinite(img.rgb).all() and img.aovs["errors"].max() == 0
    status = img.aovs["status"]
    assert (status == wv.RayStatus.ESCAPED).any() and (status == wv.RayStatus.HORIZON).any()
