"""Flat space: exact straight lines with no integration, and the curved machinery's flat limit."""

import numpy as np

import warpviz as wv


def test_straight_lines_are_exact_and_take_no_steps():
    rng = np.random.default_rng(0)
    origins = rng.uniform(-50, 50, size=(100, 3))
    dirs = rng.normal(size=(100, 3))
    rays = wv.trace(wv.Minkowski(), origins, dirs, escape_radius=500.0, record=True)
    assert np.all(rays.status == wv.RayStatus.ESCAPED)
    assert np.all(rays.n_steps == 0)
    unit = dirs / np.linalg.norm(dirs, axis=1)[:, None]
    np.testing.assert_allclose(rays.final_directions, unit, rtol=0, atol=1e-15)
    np.testing.assert_allclose(np.linalg.norm(rays.final_positions, axis=1), 500.0, rtol=1e-14)
    # the end point lies on the ray: (end - origin) is parallel to the direction, ahead of the origin
    along = rays.final_positions - origins
    np.testing.assert_allclose(np.cross(along, unit), 0.0, atol=1e-11)
    assert np.all(np.einsum("ij,ij->i", along, unit) > 0)
    assert np.all(np.diff(rays.offsets) == 2)  # a line is two points
    np.testing.assert_array_equal(rays.points[0::2], origins)


def test_vanishing_mass_schwarzschild_matches_flat_space():
    rng = np.random.default_rng(1)
    dirs = rng.normal(size=(50, 3))
    flat = wv.trace(wv.Minkowski(), [3.0, -2.0, 1.0], dirs, escape_radius=100.0)
    weak = wv.trace(wv.Schwarzschild(mass=1e-12), [3.0, -2.0, 1.0], dirs, escape_radius=100.0, tol=1e-10)
    np.testing.assert_allclose(weak.final_positions, flat.final_positions, rtol=0, atol=1e-7)
    np.testing.assert_allclose(weak.final_directions, flat.final_directions, rtol=0, atol=1e-9)
    assert np.all(weak.n_steps > 0) and np.all(flat.n_steps == 0)


def test_origin_outside_escape_radius_moving_out_escapes_at_once():
    rays = wv.trace(wv.Minkowski(), [2000.0, 0, 0], [1.0, 1.0, 0])
    np.testing.assert_allclose(rays.final_positions[0], [2000.0, 0, 0])
    np.testing.assert_allclose(rays.final_directions[0], [2**-0.5, 2**-0.5, 0], rtol=1e-15)
