"""Ellis wormhole: exact deflection, passage to the other sheet, the regular chart at the throat."""


import numpy as np
import pytest

import warpviz as wv

from conftest import deflection, launch_direction

WH = wv.EllisWormhole(throat=1.0)


@pytest.mark.parametrize("case", range(3))
def test_deflection_angle(exact, case):
    ref = exact["ellis_deflection"]["cases"][case]
    alpha = deflection(WH, 1e3, launch_direction(1e3, ref["b"], mass=0.0), tol=1e-10)
    assert alpha == pytest.approx(ref["alpha"], rel=1e-8)


@pytest.mark.parametrize("b, sheet", [(0.5, -1), (0.99, -1), (1.01, 1), (1.5, 1)])
def test_rays_below_the_throat_radius_pass_to_the_other_sheet(b, sheet):
    rays = wv.trace(WH, [-100.0, 0, 0], launch_direction(100.0, b, mass=0.0), tol=1e-10, record=True)
    assert rays.status_names[0] == "escaped"
    assert rays.final_sheets[0] == sheet
    s = rays.point_data["sheet"]
    assert s[0] == 1 and s[-1] == sheet
    assert np.count_nonzero(np.diff(s)) == (1 if sheet == -1 else 0)  # one crossing, no flicker
    assert rays.point_data["r"].min() >= 1.0 - 1e-12  # areal radius never below the throat


def test_radial_ray_goes_straight_through():
    rays = wv.trace(WH, [-50.0, 0, 0], [1.0, 0, 0], tol=1e-10)
    assert rays.final_sheets[0] == -1
    np.testing.assert_allclose(rays.final_positions[0], [-1000.0, 0, 0], atol=1e-6)
    np.testing.assert_allclose(rays.final_directions[0], [-1.0, 0, 0], atol=1e-12)


def test_rays_start_on_either_sheet_and_the_sheets_are_symmetric():
    d = launch_direction(80.0, 0.7, mass=0.0)
    a = wv.trace(WH, [-80.0, 0, 0], d, sheets=[1], tol=1e-10)
    b = wv.trace(WH, [-80.0, 0, 0], d, sheets=[-1], tol=1e-10)
    assert (a.final_sheets[0], b.final_sheets[0]) == (-1, 1)
    np.testing.assert_allclose(a.final_positions, b.final_positions, atol=1e-9)
    np.testing.assert_allclose(a.final_directions, b.final_directions, atol=1e-12)


def test_angular_invariant_is_conserved_through_the_throat():
    rays = wv.trace(WH, [-60.0, 10.0, 5.0], [[1.0, -0.15, -0.08], [1.0, -0.1, 0.2]], tol=1e-11)
    assert rays.invariant_drift["L2"].max() < 1e-9
    assert rays.invariant_drift["E"].max() == 0.0


def test_origins_inside_the_throat_radius_are_rejected():
    with pytest.raises(ValueError, match=r"origins\[0\] .* inside the wormhole throat"):
        wv.trace(WH, [0.5, 0.0, 0.0], [1.0, 0, 0])
    with pytest.raises(ValueError, match=r"sheets\[1\] must be \+1 or -1"):
        wv.trace(WH, [[5.0, 0, 0], [6.0, 0, 0]], [1.0, 0, 0], sheets=[1, 0])
    # (line-element wormholes loaded as plugins in this process are named too)
    with pytest.raises(ValueError, match=r"only EllisWormhole( and \w+)* ha(s|ve) sheet -1"):
        wv.trace(wv.Schwarzschild(mass=1.0), [5.0, 0, 0], [1.0, 0, 0], sheets=[-1])
