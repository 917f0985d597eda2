"""The reported drifts of conserved quantities against E, Lz and Carter's Q recomputed independently.

E, Lz and Q are recomputed here in Boyer–Lindquist form from the chart states the tracer returns
(Kerr–Schild Cartesian x^i and covariant p_mu): r from x² + y² + z² = r² + a² − a² z² / r², θ from
z = r cos θ, p_θ = ∂x^i/∂θ p_i = cot θ (x p_x + y p_y) − r sin θ p_z (the Kerr–Schild and
Boyer–Lindquist charts differ only in t and φ by functions of r, so p_t, p_φ and p_θ agree), and
Q = p_θ² + cos² θ (Lz² / sin² θ + a² (μ² − E²)) with μ² = −g^{μν} p_μ p_ν.
"""

from __future__ import annotations

import numpy as np
import pytest

import warpviz as wv

M, SPIN = 1.0, 0.9
A = SPIN * M


def bl_invariants(states: np.ndarray) -> dict[str, np.ndarray]:
    """E, Lz and Carter's Q of Kerr chart states, shape (N, 8) -> each (N,), and the size of each one's
    terms (``"<X>_terms"``), which bounds the rounding of X here and in the tracer."""
    x, y, z = states[:, 1], states[:, 2], states[:, 3]
    pt, px, py, pz = states[:, 4], states[:, 5], states[:, 6], states[:, 7]
    rho2 = x * x + y * y + z * z - A * A
    r = np.sqrt(0.5 * (rho2 + np.sqrt(rho2 * rho2 + 4.0 * A * A * z * z)))
    cos = z / r
    sin2 = 1.0 - cos * cos
    sin = np.sqrt(sin2)
    energy = -pt
    lz = x * py - y * px
    p_theta = cos / sin * (x * px + y * py) - r * sin * pz
    # mu^2 = -g^{mu nu} p p with g^{mu nu} = eta - f l l, l^mu = (-1, (r x + a y), (r y - a x)) / (r^2 + a^2), z / r)
    f = 2.0 * M * r**3 / (r**4 + A * A * z * z)
    l_dot_p = -pt + ((r * x + A * y) * px + (r * y - A * x) * py) / (r * r + A * A) + z / r * pz
    mu2 = -(-pt * pt + px * px + py * py + pz * pz - f * l_dot_p**2)
    q = p_theta**2 + cos * cos * (lz * lz / sin2 + A * A * (mu2 - energy * energy))
    q_terms = (np.abs(cos / sin * (x * px + y * py)) + np.abs(r * sin * pz))**2 + cos * cos * (
        lz * lz / sin2 + A * A * (np.abs(mu2) + energy * energy))
    return {"E": energy, "Lz": lz, "Q": q, "E_terms": np.abs(energy), "Lz_terms": np.abs(x * py) + np.abs(y * px),
            "Q_terms": q_terms}


def _rays():
    """A far observer's fan at 60° inclination (Q0 small against its terms) and rays near the hole."""
    far = np.array([0.0, -200.0 * np.sin(np.radians(60)), 200.0 * np.cos(np.radians(60))])
    fwd = -far / np.linalg.norm(far)
    up = np.array([0.0, np.cos(np.radians(60)), np.sin(np.radians(60))])
    right = np.cross(fwd, up)
    s = np.array([-9.0, -4.0, 4.5, 8.0]) / 200.0
    dirs = [fwd + a * right + b * up for a in s for b in s]
    origins = [far] * len(dirs)
    near = np.array([2.0, -12.0, 3.0])
    for d in ([0.1, 1.0, -0.2], [-0.3, 1.0, 0.05], [0.2, 1.0, 0.3]):
        origins.append(near)
        dirs.append(d)
    return np.array(origins), np.array(dirs)


def test_reported_drifts_match_e_lz_q_recomputed_in_boyer_lindquist_form():
    """Step by step (max_steps = 1, 2, ...: each run ends at the next step's state), the reported drift of
    E, Lz, Q is the running maximum of |X − X0| / |X0| recomputed from the states, and the term-scaled
    one is smaller by the size of X's terms over |X0| (10²–10⁴ for Q seen from r = 200)."""
    kerr = wv.Kerr(mass=M, spin=SPIN)
    origins, dirs = _rays()
    running = None
    x0 = None
    for steps in range(1, 25):
        rays = wv.trace(kerr, origins, dirs, stepper="dopri5", tol=1e-4, max_steps=steps, monitor_every=1)
        if x0 is None:
            x0 = bl_invariants(rays.initial_states)
            assert np.all(np.abs(x0["Q"]) > 0.5) and np.all(np.abs(x0["Lz"]) > 0.01)
        x1 = bl_invariants(rays.final_states)
        now = {k: np.abs(x1[k] - x0[k]) / np.abs(x0[k]) for k in ("E", "Lz", "Q")}
        running = now if running is None else {k: np.maximum(running[k], now[k]) for k in now}
        for k in ("E", "Lz", "Q"):
            # equal up to the rounding of X's terms in the two evaluations (a few ulps of them, over |X0|)
            rounding = 1e-14 * np.maximum(x0[k + "_terms"], x1[k + "_terms"]) / np.abs(x0[k])
            assert np.all(np.abs(rays.invariant_drift[k] - running[k]) <= 1e-6 * running[k] + rounding), k
            assert np.all(rays.invariant_drift_scaled[k] <= rays.invariant_drift[k] * (1 + 1e-12))
    assert np.all(running["Q"] > 100 * rounding)  # the steps did drift, so the comparison above had something to compare
    far = slice(0, 16)
    ratio = rays.invariant_drift["Q"][far] / rays.invariant_drift_scaled["Q"][far]
    assert ratio.min() > 30.0, ratio  # the term-scaled Q drift of far rays is far below the relative one
    np.testing.assert_array_equal(rays.invariant_drift["E"], rays.invariant_drift_scaled["E"])


def test_end_state_counts_in_the_reported_drift():
    """A whole trace: the reported drift is at least the relative drift of the end state (escaped rays
    end beyond the escape sphere, where the step monitor does not look every step)."""
    origins, dirs = _rays()
    rays = wv.trace(wv.Kerr(mass=M, spin=SPIN), origins, dirs, tol=1e-6)
    assert {"escaped", "horizon"} <= set(rays.counts())
    x0, x1 = bl_invariants(rays.initial_states), bl_invariants(rays.final_states)
    for k in ("Lz", "Q"):
        end = np.abs(x1[k] - x0[k]) / np.abs(x0[k])
        assert np.all(rays.invariant_drift[k] >= end * (1 - 1e-6) - 1e-14), k


def test_negligible_q_is_reported_term_scaled():
    """Q of an equatorial ray is 0: its reported drift is the term-scaled one, as is H's always."""
    rays = wv.trace(wv.Kerr(mass=M, spin=SPIN), [[0.0, -30.0, 0.0]], [[0.2, 1.0, 0.0], [-0.1, 1.0, 0.0]],
                    tol=1e-6, monitor_every=1)
    assert np.all(bl_invariants(rays.initial_states)["Q"] == 0.0)
    for k in ("H", "Q"):
        np.testing.assert_array_equal(rays.invariant_drift[k], rays.invariant_drift_scaled[k])


def test_lz_of_a_ray_leaving_the_axis_becomes_term_scaled():
    """A ray that starts 1.4e-6 M off the axis has Lz ~1e-6 of the size its terms reach as it leaves
    the axis; the integration error grows with those terms, so from there on the term-scaled drift is
    reported (the relative one would read ~1e-6 at tol 1e-10; hypothesis found this ray)."""
    theta, r0 = 6e-8, 23.0
    origin = r0 * np.array([np.sin(theta), 0.0, np.cos(theta)])
    rays = wv.trace(wv.Kerr(mass=1.0, spin=0.0), origin, [1.0, 1.0, 0.0], tol=1e-10, escape_radius=200.0,
                    record=True)
    lz0 = np.abs(bl_invariants(rays.initial_states)["Lz"][0])
    assert 0.0 < lz0 < 1e-5
    np.testing.assert_array_equal(rays.invariant_drift["Lz"], rays.invariant_drift_scaled["Lz"])
    assert rays.invariant_drift["Lz"][0] < 1e-12
    pd = rays.ray_point_data(0)
    assert pd["Lz_drift"][-1] == pd["Lz_drift_scaled"][-1]


@pytest.mark.parametrize("metric", [wv.Schwarzschild(), wv.Kerr(spin=0.9)])
def test_point_drift_columns(metric):
    """Per point: `<X>_drift` follows the per-ray rule and its maximum is the ray's reported drift."""
    origins, dirs = _rays()
    rays = wv.trace(metric, origins, dirs, tol=1e-6, record=True)
    for name in rays.invariant_drift:
        if name == "H":
            continue
        for i in range(len(rays)):
            pd = rays.ray_point_data(i)
            assert pd[f"{name}_drift"].max() <= rays.invariant_drift[name][i]
            assert pd[f"{name}_drift_scaled"].max() <= rays.invariant_drift_scaled[name][i]
            assert np.all(pd[f"{name}_drift_scaled"] <= pd[f"{name}_drift"] * (1 + 1e-12) + 1e-300)


def test_flat_space_records_zero_drift_columns():
    """Straight rays conserve everything exactly: every drift column of a recorded Minkowski ray is 0."""
    rays = wv.trace(wv.Minkowski(), [0.0, 0.0, 0.0], [[1.0, 0.2, 0.0], [0.0, 1.0, 0.3]], record=True)
    drift_columns = [k for k in rays.point_data if "drift" in k]
    assert len(drift_columns) == 2 * (len(rays.invariant_drift) - 1)
    for k in drift_columns:
        np.testing.assert_array_equal(rays.point_data[k], 0.0, err_msg=k)
