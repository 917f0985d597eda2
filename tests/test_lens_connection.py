"""The exact lens map of static spherical spacetimes (spacetime/lens_map.h) and the light connection built
on it (integrators/lens_connection.h): every image it finds is confirmed by tracing its geodesic, its area
Jacobian by finite differences of traced rays, and renders with it keep the mean of brute force.

Every registered metric that declares itself static and spherically symmetric is covered without a test
edit (GYOTO style)."""

import math

import numpy as np
import pytest

import warpviz as wv
from warpviz._native import testing
from native_scenes import lamp_over_hole, metric, room
from test_render import _image_means, assert_same_mean

SPHERICAL = [e for e in wv.registered_metrics() if e["static_spherical"]]


def _example(entry):
    m = wv.metric_class(entry["name"]).example()
    return m, [float(m.params[k]) for k in entry["params"]]


def _scale(m):
    """The radius the lens map's rays approach: photon sphere or throat."""
    lm = m.landmarks
    return lm.get("photon_sphere") or lm["throat"]


def test_the_spherical_metrics_declare_their_lens_and_kerr_does_not():
    names = {e["name"] for e in SPHERICAL}
    assert {"schwarzschild", "reissner_nordstrom", "ellis"} <= names
    assert "kerr" not in names and "minkowski" not in names


# (A, B) in units of the inner radius; B farther out than A, so the traced ray stops on B's sphere.
PAIRS = [((7.0, 0.0, 0.0), (-2.0, 9.0, 1.0)), ((7.0, 0.0, 0.0), (-8.0, -1.0, 3.0)), ((4.0, 1.0, 0.0), (3.0, 11.0, -6.0))]


@pytest.mark.parametrize("entry", SPHERICAL, ids=lambda e: e["name"])
@pytest.mark.parametrize("pair", range(len(PAIRS)))
def test_every_image_found_reaches_its_light_point(entry, pair):
    m, params = _example(entry)
    s = _scale(m)
    a, b = (np.asarray(p, dtype=float) * s for p in PAIRS[pair])
    sheets = [1, -1] if entry["sheets"] == 2 else [1]
    for sheet_b in sheets:
        im = testing.lens_images(entry["name"], params, a, 1, -a / np.linalg.norm(a), b, np.array([0.0, 0.0, 1.0]),
                                 sheet_b, 1.0, True, 3)
        assert len(im["directions"]) == 3  # direct, round the far side, one winding
        for order, d in enumerate(im["directions"]):
            rays = wv.trace(m, a, d, tol=1e-12, stepper="dop853", escape_radius=float(np.linalg.norm(b)),
                            sheets=[1] if entry["sheets"] == 2 else None)
            assert rays.status_names[0] == "escaped"
            if entry["sheets"] == 2:
                assert rays.final_sheets[0] == sheet_b
            miss = np.linalg.norm(rays.final_positions[0] - b)
            assert miss < (1e-8 if order < 2 else 1e-7) * max(1.0, s), (order, miss)


@pytest.mark.parametrize("entry", SPHERICAL, ids=lambda e: e["name"])
def test_inward_images_are_the_outward_ones_reversed(entry):
    """Light from far B to near A follows the ray from A to B backwards: same impact parameter, same sweep."""
    m, params = _example(entry)
    s = _scale(m)
    for phi in (0.4, 2.0, 2 * math.pi - 2.0, 2 * math.pi + 0.4):
        out = testing.lens_ray(entry["name"], params, 5.0 * s, 14.0 * s, True, phi)
        back = testing.lens_ray(entry["name"], params, 14.0 * s, 5.0 * s, True, phi)
        assert out is not None and back is not None
        assert back[4] == pytest.approx(out[4], rel=1e-9)  # b
        assert back[1] == pytest.approx(out[1], rel=1e-9)


@pytest.mark.parametrize("entry", SPHERICAL, ids=lambda e: e["name"])
@pytest.mark.parametrize("phi", [0.02, 0.1, 0.3])
def test_inward_rays_steep_enough_to_fall_in_after_b_are_found(entry, phi):
    """An inward ray from far A that meets near B before it would fall into the hole or pass the throat
    (small sweep, impact parameter below the critical one) is an image like any other: the lens map finds
    it, and it is the outward ray from B to A reversed."""
    m, params = _example(entry)
    s = _scale(m)
    out = testing.lens_ray(entry["name"], params, 1.5 * s, 14.0 * s, True, phi)
    back = testing.lens_ray(entry["name"], params, 14.0 * s, 1.5 * s, True, phi)
    assert out is not None and back is not None
    assert back[4] == pytest.approx(out[4], rel=1e-9)  # b
    assert back[1] == pytest.approx(out[1], rel=1e-9)


def _swept(m, r_a, psi, r_b, sheets):
    """Azimuth swept by the equatorial ray leaving (r_a, 0, 0) at angle psi from the radial direction,
    traced to radius r_b, and the sheet it ends on."""
    rays = wv.trace(m, [r_a, 0.0, 0.0], [math.cos(psi), math.sin(psi), 0.0], tol=1e-13, stepper="dop853",
                    escape_radius=r_b, sheets=sheets)
    x, y = rays.final_positions[0][:2]
    return math.atan2(y, x) % (2 * math.pi), rays


@pytest.mark.parametrize("entry", SPHERICAL, ids=lambda e: e["name"])
def test_lens_map_derivatives_match_finite_differences_of_traced_rays(entry):
    m, params = _example(entry)
    s = _scale(m)
    sheets = [1] if entry["sheets"] == 2 else None
    r_a, r_b = 6.0 * s, 15.0 * s
    for phi in (0.7, 2.5, 2 * math.pi - 1.0):
        psi, phi_l, dphi_dpsi, dr_dphi, _, _ = testing.lens_ray(entry["name"], params, r_a, r_b, True, phi)
        h = 1e-5
        unwrap = lambda v: phi + (v - phi + math.pi) % (2 * math.pi) - math.pi  # noqa: E731
        p_plus = unwrap(_swept(m, r_a, psi + h, r_b, sheets)[0])
        p_minus = unwrap(_swept(m, r_a, psi - h, r_b, sheets)[0])
        assert unwrap(_swept(m, r_a, psi, r_b, sheets)[0]) == pytest.approx(phi, abs=1e-9)
        assert (p_plus - p_minus) / (2 * h) == pytest.approx(dphi_dpsi, rel=1e-4)
        eps = 1e-4 * r_b
        q_plus = unwrap(_swept(m, r_a, psi, r_b + eps, sheets)[0])
        q_minus = unwrap(_swept(m, r_a, psi, r_b - eps, sheets)[0])
        assert 2 * eps / (q_plus - q_minus) == pytest.approx(dr_dphi, rel=1e-4)


def _sweep_round_periapsis(mass, r_a, r_b, b):
    """int b du / sqrt(P(u)) from 1/r_a and from 1/r_b up to the periapsis u_t, P = 1 - b^2 u^2 (1 - 2M u), by
    mpmath's quadrature in t, u = u_t - t^2, where P(u_t - t^2) / t^2 is a quadratic in t^2 (no endpoint root)."""
    import mpmath as mp  # (sympy's)

    with mp.workdps(30):  # (mpmath's precision is global: set for this reference only)
        b = mp.mpf(b)
        u_t = mp.findroot(lambda u: 1 - b * b * u * u * (1 - 2 * mass * u), (1 / b, mp.mpf(1) / (3 * mass)),
                          solver="anderson")
        d1, d2 = -2 * b * b * u_t + 6 * mass * b * b * u_t**2, -2 * b * b + 12 * mass * b * b * u_t
        d3 = 12 * mass * b * b
        total = mp.mpf(0)
        for r in (r_a, r_b):
            top = mp.sqrt(u_t - 1 / mp.mpf(r))
            if top > 0:  # (nodes graded towards t = 0, where a nearly critical ray's integrand peaks)
                nodes = [0] + [top * mp.mpf(10) ** -k for k in range(8, 0, -1)] + [top]
                total += mp.quad(lambda t: 2 * b / mp.sqrt(-d1 + d2 / 2 * t * t - d3 / 6 * t**4), nodes)
        return float(total)


@pytest.mark.parametrize("mass", [1.0, 2.5])
def test_the_sweep_in_to_the_periapsis_and_out_is_the_quadratures(mass):
    """Schwarzschild's sweep of a ray that leaves A inward, turns at its periapsis u_t and reaches B is one
    Carlson R_F (round the branch point; past the complete integral, twice that minus the R_F): equal to the
    quadratures from u_A and from u_B up to u_t, for rays far from the photon sphere and to 1e-9 of its impact
    parameter, and for A and B on one sphere."""
    rng = np.random.default_rng(3)
    cases = [(r_a, r_b, float(rng.uniform(0.55 * math.pi, 0.999 * math.pi)), 1.0)
             for r_a, r_b in rng.uniform(3.3, 40.0, (40, 2)) * mass]
    cases += [(4.0 * mass, 4.0 * mass, 1.9, 1.0), (4.0 * mass, 30.0 * mass, 1.9, 1.0)]
    b_crit = 3.0 * math.sqrt(3.0) * mass
    for r_a, r_b in ((3.5 * mass, 12.0 * mass), (5.0 * mass, 5.0 * mass)):  # nearly critical: long sweeps
        for gap in (1e-3, 1e-6, 1e-9):
            b = b_crit * (1.0 + gap)
            cases.append((r_a, r_b, math.pi - math.asin(b / r_a * math.sqrt(1.0 - 2.0 * mass / r_a)), gap))
    checked = 0
    for r_a, r_b, psi, gap in cases:
        r_a, r_b = min(r_a, r_b), max(r_a, r_b)  # (the forward evaluation's case: B outside A)
        ray = testing.lens_ray_at_psi("schwarzschild", [mass], r_a, r_b, True, psi)
        if ray is None:  # (b below critical: falls in)
            continue
        checked += 1
        # Within gap of critical the periapsis is nearly a double root of P: its rounding moves u3 - u2 by
        # ~1e-16 / gap relative, and the sweep diverges as its logarithm.
        ref = _sweep_round_periapsis(mass, r_a, r_b, ray[4])
        assert ray[1] == pytest.approx(ref, rel=max(2e-13, 3e-16 / gap)), (r_a, r_b, psi)
    assert checked > 30


@pytest.mark.parametrize("entry", SPHERICAL, ids=lambda e: e["name"])
def test_a_root_taken_one_newton_step_past_the_last_evaluation_is_the_ray_there(entry):
    """The root skips the evaluation that would only confirm a converged Newton step and moves the last ray
    evaluated on by that step: its sweep, dPhi/dpsi and dR/dphi at B are the forward evaluation's at its
    angle, over rooms of radii and every sweep of images of order 0 to 2, and it takes fewer evaluations
    than a root whose every Newton step is confirmed."""
    m, params = _example(entry)
    s = _scale(m)
    rng = np.random.default_rng(5)
    evals = []
    for _ in range(150):
        r_a, r_b = np.sort(rng.uniform(1.6 * s, 20.0 * s, 2))  # B outside A: the forward evaluation's case
        gamma = float(rng.uniform(0.05, math.pi - 0.05))
        for target in (gamma, 2 * math.pi - gamma, 2 * math.pi + gamma):
            for same in ([True, False] if entry["sheets"] == 2 else [True]):
                ray = testing.lens_ray(entry["name"], params, r_a, r_b, same, target)
                if ray is None:
                    continue
                psi, phi, dphi_dpsi, dr_dphi, b, n = ray
                evals.append(n)
                fwd = testing.lens_ray_at_psi(entry["name"], params, r_a, r_b, same, psi)
                assert fwd is not None
                assert phi == pytest.approx(target, rel=1e-10, abs=1e-10)
                assert fwd[1] == pytest.approx(target, rel=1e-9, abs=1e-9)
                assert fwd[2] == pytest.approx(dphi_dpsi, rel=1e-6)
                assert fwd[3] == pytest.approx(dr_dphi, rel=1e-6, abs=1e-9)
                assert fwd[4] == pytest.approx(b, rel=1e-14)
    assert len(evals) > 300
    # Confirming every root took 5.06-5.22 evaluations on average from this start (the middle of the branch).
    assert np.mean(evals) < 4.6, np.mean(evals)


@pytest.mark.parametrize("entry", [e for e in SPHERICAL if e["sheets"] == 1], ids=lambda e: e["name"])
def test_the_direct_image_started_from_the_bent_line_takes_fewer_evaluations(entry):
    """The order-0 image's root from the straight line aimed short of B by the first-order bending is the same
    ray as from the straight line itself, found in fewer evaluations of Phi (rooms of 2-20 photon-sphere radii)."""
    m, params = _example(entry)
    s = _scale(m)
    rng = np.random.default_rng(11)
    n_flat, n_direct = [], []
    for _ in range(300):
        r_a, r_b = rng.uniform(2.0 * s, 20.0 * s, 2)
        gamma = float(np.arccos(rng.uniform(-0.999, 0.999)))
        flat = testing.lens_ray(entry["name"], params, r_a, r_b, True, gamma, "flat")
        direct = testing.lens_ray(entry["name"], params, r_a, r_b, True, gamma, "direct")
        assert (flat is None) == (direct is None)
        if flat is None:
            continue
        assert direct[0] == pytest.approx(flat[0], rel=1e-9, abs=1e-12)  # psi: the same image
        n_flat.append(flat[5])
        n_direct.append(direct[5])
    assert len(n_flat) > 250
    assert np.mean(n_direct) < np.mean(n_flat) - 0.3, (np.mean(n_direct), np.mean(n_flat))


@pytest.mark.parametrize("entry", SPHERICAL, ids=lambda e: e["name"])
def test_area_jacobian_matches_traced_bundles(entry):
    """|dA/dOmega| of each image against the area that a small square of directions around it covers on
    B's sphere (the light tangent to that sphere, so the plane and sphere areas agree)."""
    m, params = _example(entry)
    s = _scale(m)
    a, b = np.array([7.0, 0.5, 0.0]) * s, np.array([-3.0, 9.0, 4.0]) * s
    r_b = float(np.linalg.norm(b))
    sheets = [1] if entry["sheets"] == 2 else None
    im = testing.lens_images(entry["name"], params, a, 1, -a / np.linalg.norm(a), b, b / r_b, 1, 1.0, True, 2)
    h = 2e-6
    for d, jac in zip(im["directions"], im["jacobians"]):
        e1 = np.cross(d, [0.0, 0.0, 1.0])
        e1 /= np.linalg.norm(e1)
        e2 = np.cross(d, e1)
        dirs = np.array([d + h * e1, d - h * e1, d + h * e2, d - h * e2])
        ends = wv.trace(m, a, dirs, tol=1e-13, stepper="dop853", escape_radius=r_b, sheets=None if sheets is None
                        else [1] * 4).final_positions
        area = np.linalg.norm(np.cross(ends[0] - ends[1], ends[2] - ends[3])) / (2 * h) ** 2
        assert area == pytest.approx(jac, rel=1e-4)


@pytest.mark.parametrize("entry", SPHERICAL, ids=lambda e: e["name"])
def test_the_light_strategys_draw_solves_the_images_it_picks_and_estimates_the_rest(entry):
    """The light strategy draws an image in proportion to estimated weights (LensImagePick): order 0's exact,
    each later order's from the ray one Newton step on from its start (in Schwarzschild's cubic, order 2's
    extrapolated from order 1's start without an evaluation of its own), solved only when drawn. The images it
    solves are the exact ones (direction and area Jacobian), and the estimated weights are within a few per cent
    of the exact ones (measured in fig07's pairs: 0.99-1.04x; from the start's own ray 0.9-2.6x; here Ellis's
    order 2 to 0.9-1.13x), so it draws about as the exact weights would. Room-like pairs: A on the floor of a
    box around the centre, B on a lamp in its ceiling."""
    m, params = _example(entry)
    s = _scale(m)
    rng = np.random.default_rng(3)
    ratios = []
    for _ in range(60):
        a = rng.uniform(-1.0, 1.0, 3) * 9.0 * s
        a[2] = -9.0 * s  # on the floor, facing up
        if np.linalg.norm(a) < 2.5 * s:
            continue
        b = np.array([*rng.uniform(-3.0, 3.0, 2) * s, 9.0 * s])
        im = testing.lens_images(entry["name"], params, a, 1, np.array([0.0, 0.0, 1.0]), b, np.array([0.0, 0.0, -1.0]),
                                 1, 1.0, False, 3)
        n = len(im["weights"])
        assert len(im["pick_weights"]) == n
        for k in range(n):
            if im["weights"][k] > 0:
                np.testing.assert_allclose(im["pick_directions"][k], im["directions"][k], atol=1e-9)
                assert im["pick_jacobians"][k] == pytest.approx(im["jacobians"][k], rel=1e-6)  # both roots to 1e-10
            else:
                assert np.isnan(im["pick_jacobians"][k])
        if n:
            assert im["pick_weights"][0] == pytest.approx(im["weights"][0], rel=1e-12)
        for k in range(1, n):
            if im["weights"][k] > 0:
                ratios.append(im["pick_weights"][k] / im["weights"][k])
    ratios = np.array(ratios)
    assert len(ratios) > 40
    assert np.median(np.abs(ratios - 1.0)) < 0.03 and np.all(np.abs(ratios - 1.0) < 0.25), (ratios.min(), ratios.max())


def _wormhole_room(light_sheet: int):
    """A room around an Ellis throat whose only light hangs on `light_sheet`."""
    scene = room(metric("ellis", 3.0), size=(12, 9), light=3.0, spheres=False)
    if light_sheet == -1:  # the lamp moves to the other side, where a floor catches its light too
        lamp = scene["shapes"][6]
        lamp["sheet"] = -1
        scene["shapes"].append({"type": "quad", "corner": [-12, -12, -12], "edge_u": [24, 0, 0],
                                "edge_v": [0, 24, 0], "material": 0, "sheet": -1})
    return scene


def _sphere_lamp_room():
    """The room lit by an emissive sphere (sampled on its hemisphere facing each vertex) instead of the quad."""
    scene = room(metric("schwarzschild", 1.0), size=(12, 9), light=3.0, spheres=False)
    scene["shapes"][6] = {"type": "sphere", "center": [3.0, 4.0, 8.0], "radius": 2.0, "material": 3}
    return scene


@pytest.mark.parametrize("scene", [
    pytest.param(_sphere_lamp_room, id="sphere-light"),
    pytest.param(lambda: room(metric("schwarzschild", 1.0), size=(12, 9), light=3.0), id="schwarzschild"),
    pytest.param(lambda: room(metric("reissner_nordstrom", 1.0, 0.7), size=(12, 9), light=3.0), id="rn"),
    pytest.param(lambda: _wormhole_room(1), id="ellis"),
    pytest.param(lambda: _wormhole_room(-1), id="ellis-light-on-the-other-sheet"),
])
def test_lens_connection_keeps_the_mean_of_brute_force_and_of_the_aimed_one(scene):
    sc = scene()
    lens = _image_means(sc, range(8), spp=8, max_depth=3)
    brute = _image_means(sc, range(8, 16), spp=8, max_depth=3, light_sampling=False)
    aimed = _image_means(sc, range(16, 24), spp=8, max_depth=3, light_connection="aimed")
    assert lens.mean() > 0
    assert_same_mean(lens, brute, slack=2e-3 * brute.mean())
    assert_same_mean(lens, aimed, slack=2e-3 * aimed.mean())


def test_lens_connection_lowers_the_noise_of_a_lensed_room():
    """Same time order, far less noise than the aimed proxies (measured ~10x lower variance here)."""
    sc = room(metric("schwarzschild", 1.0), size=(12, 9), light=3.0, spheres=False)

    def frames(lc):
        return np.stack([wv.render(sc, spp=8, seed=s, max_depth=3, light_connection=lc).rgb
                         for s in range(8)]).astype(np.float64)

    lens, aimed = frames("lens"), frames("aimed")
    assert lens.var(axis=0).mean() < 0.3 * aimed.var(axis=0).mean()


def test_flat_space_keeps_its_connection_bit_for_bit():
    sc = room(metric("minkowski"), size=(8, 6))
    a = wv.render(sc, spp=2, seed=3)
    b = wv.render(sc, spp=2, seed=3, light_connection="aimed")
    assert np.array_equal(a.rgb, b.rgb)


@pytest.mark.parametrize("spin", [0.9, 0.99])
def test_kerr_lens_proposal_and_image_proxies_keep_the_mean_and_lower_the_noise(spin):
    """Kerr has no plane reduction. As a proposal ('lens'), the Schwarzschild connection of the same mass
    draws the directions and its density is evaluated where each direction's Schwarzschild orbit first crosses
    the light; the image proxies ('images') are refined on pilot geodesics. Both are densities over directions
    and keep the mean of brute force; both lower the noise of the aimed proxies (measured here at a = 0.9:
    'lens' 0.27x, 'images' 0.21x their variance)."""
    sc = room(metric("kerr", 1.0, spin), size=(12, 9), light=3.0, spheres=False)
    brute = _image_means(sc, range(12, 36), spp=8, max_depth=3, light_sampling=False)
    for lc, seeds in (("lens", range(12)), ("images", range(36, 48))):
        means = _image_means(sc, seeds, spp=8, max_depth=3, light_connection=lc)
        assert_same_mean(means, brute, slack=2e-3 * brute.mean())

    def frames(lc):
        return np.stack([wv.render(sc, spp=8, seed=s, max_depth=3, light_connection=lc).rgb
                         for s in range(6)]).astype(np.float64)

    aimed = frames("aimed").var(axis=0).mean()
    assert frames("lens").var(axis=0).mean() < 0.5 * aimed
    assert frames("images").var(axis=0).mean() < 0.5 * aimed


def test_kerr_lens_proposal_keeps_the_mean_with_a_ring_lamp_and_a_lamp_in_a_plane_through_the_hole():
    """The proposal's other shapes and cases: a ring (a disk with a hole) in the ceiling, and a second lamp
    whose plane contains the centre (where the orbit meets the plane's line at a fixed polar angle)."""
    sc = room(metric("kerr", 1.0, 0.9), size=(12, 9), light=3.0, spheres=False)
    sc["shapes"][6] = {"type": "disk", "center": [0.0, 2.0, 11.99], "normal": [0.0, 0.0, -1.0], "inner_radius": 1.5,
                       "outer_radius": 3.5, "material": 3}
    sc["shapes"].append({"type": "quad", "corner": [0.0, 6.0, -3.0], "edge_u": [0.0, 0.0, 6.0],
                         "edge_v": [0.0, 3.0, 0.0], "material": 3})  # in the plane x = 0, facing -x
    lens = _image_means(sc, range(12), spp=8, max_depth=3)
    brute = _image_means(sc, range(12, 36), spp=8, max_depth=3, light_sampling=False)
    assert lens.mean() > 0
    assert_same_mean(lens, brute, slack=2e-3 * brute.mean())


def test_kerr_lens_proposal_at_zero_spin_is_the_exact_connection():
    """At a = 0 Kerr is Schwarzschild and the proposal's samples all reach the light: the same noise as the
    exact lens connection in the same room, and the same mean (without the camera's own light samples, which
    Schwarzschild draws where the lamp's image is small and Kerr does not: camera_connection.h)."""
    kerr = room(metric("kerr", 1.0, 0.0), size=(12, 9), light=3.0, spheres=False)
    schw = room(metric("schwarzschild", 1.0), size=(12, 9), light=3.0, spheres=False)

    def frames(sc, lc, seeds):
        return np.stack([wv.render(sc, spp=8, seed=s, max_depth=2, light_connection=lc, edge_samples=1,
                                   camera_light_samples=False).rgb for s in seeds]).astype(np.float64)

    k, s = frames(kerr, "lens", range(10)), frames(schw, "lens", range(10, 20))
    assert_same_mean(k, s, slack=2e-3 * s.mean())
    ratio = k.var(axis=0).mean() / s.var(axis=0).mean()
    assert 0.8 < ratio < 1.25, ratio


@pytest.mark.parametrize("m", [metric("schwarzschild", 1.0), metric("kerr", 1.0, 0.9)], ids=["schwarzschild", "kerr"])
def test_light_roulette_keeps_the_mean_and_traces_fewer_light_rays(m):
    """Russian roulette on the lens light samples (path_tracer.h, light_roulette): a sample below
    light_roulette x the largest estimate on its path is traced with probability estimate / threshold and
    weighted by the inverse. The default (1) and a harsh one (50: nearly every sample after a path's first
    is a gamble) keep the mean of every sample traced (0), and trace fewer geodesic segments."""
    sc = room(m, size=(12, 9), light=3.0, spheres=False)
    kw = {"spp": 8, "max_depth": 5, "edge_samples": 1}
    every = _image_means(sc, range(12), light_roulette=0.0, **kw)
    for k, seeds in ((1.0, range(12, 24)), (50.0, range(24, 48))):
        assert_same_mean(_image_means(sc, seeds, light_roulette=k, **kw), every, slack=2e-3 * every.mean())

    def segments(k):
        return sum(wv.render(sc, seed=s, light_roulette=k, **kw).stats["segments"] for s in range(2))

    assert segments(1.0) < 0.95 * segments(0.0)
    assert segments(50.0) < segments(1.0)


def test_the_proposal_grows_the_light_by_its_margin():
    """PlanarLight::grown (lens_proposal.h), the light the Kerr proposal draws from: a quad grown by a margin has
    each edge that much further out in its plane (a skew quad too). The direct image of a point in the margin
    crosses the grown quad there and not the quad; any proxy orbit's first crossing with the grown quad lies
    within the margin of the quad, is the quad's own first crossing wherever it lies inside the quad, and comes no
    later than that."""
    mass, margin = 1.0, 0.9
    corner, eu, ev = np.array([-3.0, -3.0, 8.0]), np.array([6.0, 0.0, 0.0]), np.array([2.0, 5.0, 0.0])
    a = np.array([2.0, -7.0, -6.0])
    normal = np.cross(eu, ev) / np.linalg.norm(np.cross(eu, ev))
    nu, nv = np.cross(ev, normal), np.cross(normal, eu)  # in-plane normals of the edges along ev and along eu
    nu, nv = nu / np.linalg.norm(nu), nv / np.linalg.norm(nv)
    nu, nv = nu * np.sign(nu @ eu), nv * np.sign(nv @ ev)  # pointing inward from the edges at the corner

    def outside(p):  # how far p lies past the quad's furthest edge line, in the plane (<= 0: inside)
        d = p - corner
        return max(-(d @ nu), (d - eu) @ nu, -(d @ nv), (d - ev) @ nv)

    rng = np.random.default_rng(11)
    in_margin = 0
    for _ in range(20):  # the direct image of a point in the margin crosses the grown quad there, not the quad
        b = corner + rng.uniform(-0.1, 1.1) * eu + rng.uniform(-0.1, 1.1) * ev
        if not 0.0 < outside(b) < margin:
            continue
        im = testing.lens_images("schwarzschild", [mass], a, 1, np.array([0.0, 0.0, 1.0]), b, -normal, 1, 36.0,
                                 True, 1)
        grown = testing.light_crossing(mass, a, im["directions"][0], corner, eu, ev, 2, margin)
        assert grown is not None and np.linalg.norm(grown[0] - b) < 1e-7 and grown[1] < math.pi
        assert testing.light_crossing(mass, a, im["directions"][0], corner, eu, ev, 1) is None
        in_margin += 1
    assert in_margin > 5
    for _ in range(300):
        w = corner + rng.uniform(-0.4, 1.4) * eu + rng.uniform(-0.4, 1.4) * ev - a
        w /= np.linalg.norm(w)
        plain = testing.light_crossing(mass, a, w, corner, eu, ev, 2)
        grown = testing.light_crossing(mass, a, w, corner, eu, ev, 2, margin)
        if plain is not None:
            assert grown is not None and grown[1] <= plain[1] + 1e-12
        if grown is None:
            continue
        pos, sweep = grown
        assert abs((pos - corner) @ normal) < 1e-9 and outside(pos) <= margin + 1e-9
        if outside(pos) <= 0.0:
            assert plain is not None and np.linalg.norm(plain[0] - pos) < 1e-9 and plain[1] == pytest.approx(sweep)
    # margin 0 is the quad itself
    b = corner + 0.3 * eu + 0.6 * ev
    w = testing.lens_images("schwarzschild", [mass], a, 1, np.array([0.0, 0.0, 1.0]), b, -normal, 1, 36.0, True,
                            1)["directions"][0]
    x0 = testing.light_crossing(mass, a, w, corner, eu, ev, 2)
    x1 = testing.light_crossing(mass, a, w, corner, eu, ev, 2, 0.0)
    assert np.linalg.norm(x0[0] - b) < 1e-7 and np.array_equal(x0[0], x1[0]) and x0[1] == x1[1]


@pytest.mark.parametrize("shape", ["quad", "disk", "ring"])
def test_the_proposal_draws_the_margin_with_its_share_and_knows_its_density(shape):
    """ProposalLight (lens_proposal.h): the proposal draws B on the light with probability 1 - q and in the margin
    round it with probability q, each uniformly by area, and its density is a function of the point alone: over a
    grid of (u1, u2) the share of points on the light is 1 - q, the mean of 1 / density is the grown shape's area
    (the density integrates to 1), and each part has one density."""
    margin, share, n = 0.9, 0.15, 64
    if shape == "quad":  # a skew quad, its edges 6 and ~5.4 long
        args, area = ([-3.0, -3.0, 8.0], [6.0, 0.0, 0.0], [2.0, 5.0, 0.0], 0.0, 0.0), 30.0
    else:  # a disk of radius 3 (a ring: with a hole of radius 1.5, which the margin shrinks)
        r_in = 1.5 if shape == "ring" else 0.0
        args, area = ([0.0, 1.0, 8.0], [1.0, 0.0, 0.0], [0.0, -1.0, 0.0], r_in, 3.0), math.pi * (9.0 - r_in**2)
    args = (*(np.array(v) for v in args[:3]), *args[3:])
    pts, dens, on, grown_area, q = testing.proposal_light_draws(*args, margin, share, n)
    assert q == share and grown_area > area
    on = on.astype(bool)
    assert on.mean() == pytest.approx(1 - share, abs=2.0 / n)
    assert np.allclose(dens[on], (1 - share) / area) and np.allclose(dens[~on], share / (grown_area - area))
    assert np.mean(1.0 / dens) == pytest.approx(grown_area, rel=0.02)
    assert np.allclose(pts[:, 2], 8.0)  # in the light's plane
    # no margin: the light alone, every draw on it
    pts, dens, on, grown_area, q = testing.proposal_light_draws(*args, 0.0, share, 8)
    assert q == 0.0 and on.all() and np.allclose(dens, 1.0 / area) and grown_area == pytest.approx(area)


def test_kerr_proposal_margin_keeps_the_mean_and_lowers_the_noise():
    """The Kerr proposal draws from each light grown by twice the spin length a (Kerr::lens_proxy_margin): directions by
    which the light arrives in Kerr but whose Schwarzschild orbit misses the light itself were BSDF sampling's alone,
    rare samples at full weight. With the margin (light_margin, the default) the mean stays brute force's and the
    noise is lower than without it (here 0.57x; in a room of 12 M with a lamp of 6 M, where the proxy's masses by
    plane leave less for the margin, 0.98x)."""
    sc = room(metric("kerr", 1.0, 0.9), size=(12, 9), half=14.0, light=4.0, spheres=False)
    kw = {"spp": 8, "max_depth": 2, "edge_samples": 1}
    brute = _image_means(sc, range(100, 124), light_sampling=False, **kw)

    def frames(margin, seeds):
        return np.stack([wv.render(sc, seed=s, light_margin=margin, **kw).rgb for s in seeds]).astype(np.float64)

    with_margin, without = frames(True, range(12)), frames(False, range(12, 24))
    assert_same_mean(with_margin.mean(axis=(1, 2, 3)), brute, slack=2e-3 * brute.mean())
    assert_same_mean(without.mean(axis=(1, 2, 3)), brute, slack=2e-3 * brute.mean())
    assert with_margin.var(axis=0).mean() < 0.9 * without.var(axis=0).mean()


def test_light_crossing_finds_the_point_whose_image_a_direction_is():
    """B_S(w) of the Kerr proposal (integrators/lens_proposal.h): the images of a point on the lamp lead back
    to it (the direct one, and the one round the far side where no earlier crossing is in the way), and any
    direction whose orbit crosses the lamp is an image of the crossing point, of the order its sweep says."""
    mass = 1.0
    corner, eu, ev = np.array([-3.0, -3.0, 8.0]), np.array([0.0, 6.0, 0.0]), np.array([6.0, 0.0, 0.0])
    rng = np.random.default_rng(5)
    a = np.array([2.0, -7.0, -6.0])
    normal_a = np.array([0.0, 0.0, 1.0])
    for _ in range(20):
        b = corner + rng.uniform() * eu + rng.uniform() * ev
        im = testing.lens_images("schwarzschild", [mass], a, 1, normal_a, b, np.array([0.0, 0.0, -1.0]), 1, 36.0,
                                 True, 2)
        x = testing.light_crossing(mass, a, im["directions"][0], corner, eu, ev, 2)
        assert x is not None and np.linalg.norm(x[0] - b) < 1e-7 and x[1] < math.pi
        x = testing.light_crossing(mass, a, im["directions"][1], corner, eu, ev, 2)
        assert x is not None and np.linalg.norm(x[0] - b) < 1e-7 and math.pi < x[1] < 2 * math.pi
        assert testing.light_crossing(mass, a, im["directions"][1], corner, eu, ev, 1) is None
    hits = 0
    for _ in range(200):  # towards the lamp and around it (lensing moves it), some through the hole
        w = corner + rng.uniform(-1, 2) * eu + rng.uniform(-1, 2) * ev - a
        w /= np.linalg.norm(w)
        x = testing.light_crossing(mass, a, w, corner, eu, ev, 2)
        if x is None:
            continue
        hits += 1
        pos, sweep = x
        rel = np.linalg.solve(np.stack([eu, ev, np.cross(eu, ev)], axis=1), pos - corner)
        assert -1e-9 <= rel[0] <= 1 + 1e-9 and -1e-9 <= rel[1] <= 1 + 1e-9 and abs(rel[2]) < 1e-9
        im = testing.lens_images("schwarzschild", [mass], a, 1, normal_a, pos, np.array([0.0, 0.0, -1.0]), 1,
                                 36.0, True, 2)
        order = int(sweep // math.pi)
        assert np.dot(im["directions"][order], w) > 1 - 1e-10, (order, sweep)
    assert hits > 10


def test_kerr_critical_impact_parameter_by_inclination():
    """spacetime/kerr_shadow.h: on the equator (c = +-1) the closed forms of the prograde and retrograde circular
    photon orbits, b = 6 M cos(arccos(-+a) / 3) -+ a; 3 sqrt(3) M without spin; between them it falls steadily
    from the retrograde value to the prograde one. (Over the poles, c = 0: test_render.py, the shadow seen from the
    axis.)"""
    b_c = testing.kerr_critical_impact
    for a in (0.3, 0.9, 0.99):
        assert b_c(1.0, a, 1.0) == pytest.approx(6 * math.cos(math.acos(-a) / 3) - a, rel=1e-12)
        assert b_c(1.0, a, -1.0) == pytest.approx(6 * math.cos(math.acos(a) / 3) + a, rel=1e-12)
        b = [b_c(1.0, a, c) for c in np.linspace(-1.0, 1.0, 41)]
        assert np.all(np.diff(b) < 0)
    assert b_c(2.0, 0.0, 0.3) == pytest.approx(2.0 * math.sqrt(27.0), rel=1e-15)
    assert b_c(2.0, 0.9, 0.5) == pytest.approx(2.0 * b_c(1.0, 0.9, 0.5), rel=1e-12)  # lengths scale with M


def test_the_proxy_mass_follows_the_plane_and_keeps_the_area_jacobian():
    """ProxyMass (lens_proposal.h): a backward ray turning about -z is light turning with the hole (spin along +z),
    whose proxy is lighter, halfway (kProxyMassBlend) to the mass whose critical impact parameter is Kerr's there;
    about +z, heavier. Because the mass changes only from one orbit plane to another, the map from a direction to
    where its orbit crosses the lamp keeps the area Jacobian of the Schwarzschild map of its plane's mass: finite
    differences of the crossing point against the exact Jacobian at that mass (the plane turning with the direction
    adds nothing to it)."""
    mass, spin = 1.0, 0.9
    blend = 0.5
    pro = 1.0 + blend * (testing.kerr_critical_impact(1.0, spin, 1.0) / math.sqrt(27.0) - 1.0)
    retro = 1.0 + blend * (testing.kerr_critical_impact(1.0, spin, -1.0) / math.sqrt(27.0) - 1.0)
    assert testing.proxy_mass(mass, spin, np.array([0.0, 0.0, -1.0])) == pytest.approx(pro, rel=1e-12)
    assert testing.proxy_mass(mass, spin, np.array([0.0, 0.0, 1.0])) == pytest.approx(retro, rel=1e-12)
    assert pro < 0.8 and retro > 1.15
    assert testing.proxy_mass(mass, 0.0, np.array([0.0, 0.0, 1.0])) == mass

    corner, eu, ev = np.array([-3.0, -3.0, 8.0]), np.array([0.0, 6.0, 0.0]), np.array([6.0, 0.0, 0.0])
    normal_b = np.array([0.0, 0.0, -1.0])
    a = np.array([2.0, -7.0, -6.0])
    rng = np.random.default_rng(11)
    checked, eps, masses = 0, 1e-6, set()
    for i in range(40):  # directions of the images of lamp points, each at its own plane's mass
        b = corner + rng.uniform(0.1, 0.9) * eu + rng.uniform(0.1, 0.9) * ev
        order = i % 2  # the direct image, or the one round the far side (turning the other way)
        n = np.cross(a, b) * (1 if order == 0 else -1)
        m = testing.proxy_mass(mass, spin, n / np.linalg.norm(n))
        im = testing.lens_images("schwarzschild", [m], a, 1, np.array([0.0, 0.0, 1.0]), b, normal_b, 1, 36.0, True, 2)
        w = im["directions"][order]
        x = testing.light_crossing(mass, a, w, corner, eu, ev, 2, 0.0, spin)
        if x is None:  # (an earlier crossing of the lamp is in the way)
            continue
        assert np.linalg.norm(x[0] - b) < 1e-7 and int(x[1] // math.pi) == order
        e1 = np.cross(w, [0.3, 0.5, 0.8])
        e1 /= np.linalg.norm(e1)
        e2 = np.cross(w, e1)
        pts = []
        for d in (e1, -e1, e2, -e2):
            y = testing.light_crossing(mass, a, (w + eps * d) / np.linalg.norm(w + eps * d), corner, eu, ev, 2, 1.0,
                                       spin)
            pts.append(None if y is None else y[0])
        if any(p is None for p in pts):
            continue
        fd = np.linalg.norm(np.cross((pts[0] - pts[1]) / (2 * eps), (pts[2] - pts[3]) / (2 * eps)))
        assert fd == pytest.approx(im["jacobians"][order], rel=1e-4)
        checked += 1
        masses.add(round(m, 3))
    assert checked > 20 and min(masses) < 0.95 and max(masses) > 1.0  # lighter and heavier than the metric


def test_bsdf_samples_that_the_light_strategy_cannot_draw_are_counted():
    """The render's stats (render_types.h, RenderStats): `light_hits` counts the BSDF samples at diffuse vertices that
    reach a lamp's lit side where a light sample was drawn too, `unsampled_light_hits` those of them whose direction the
    light strategy could not have drawn (its pdf 0: each comes at full weight, the fireflies MIS cannot tame). In flat
    space it draws every direction that reaches the lamp: none. Round a Schwarzschild hole the ceiling beside the lamp
    (hung just below it) sees the lamp's lit face only round the hole: with the direct image alone (lens_images = 1)
    those BSDF samples are unsampled, with orders 0 and 1 (the default) nearly none, with orders 0-3 fewer still."""
    flat = wv.render(room(metric()), spp=64, seed=1, max_depth=2).stats
    assert flat["light_hits"] > 200 and flat["unsampled_light_hits"] == 0
    sc = room(metric("schwarzschild", 1.0))
    one, two, four = (wv.render(sc, spp=64, seed=1, max_depth=2, lens_images=k).stats for k in (1, 2, 4))
    assert min(one["light_hits"], two["light_hits"], four["light_hits"]) > 150
    assert one["unsampled_light_hits"] >= 10
    assert four["unsampled_light_hits"] <= two["unsampled_light_hits"] <= 0.2 * one["unsampled_light_hits"]


def test_light_connection_options_are_validated():
    sc = room(metric("schwarzschild", 1.0), size=(4, 3))
    with pytest.raises(ValueError, match="light_connection must be one of 'lens', 'images', 'aimed', got 'exact'"):
        wv.render(sc, spp=1, light_connection="exact")
    with pytest.raises(ValueError, match=r"lens_images must be an integer in \[1, 4\], got 5"):
        wv.render(sc, spp=1, lens_images=5)
    with pytest.raises(ValueError, match="lens_images"):
        wv.render(sc, spp=1, lens_images=0)


def test_a_surface_lit_from_behind_its_normal_is_sampled_as_from_the_front():
    # A diffuse surface reflects on both sides, so the lens connection's vertex takes its normal on the side the
    # path arrives from. The ceiling over a lamp that shines down, lit only by the lamp's images of order 1 and 2
    # (round the hole), gets the same light samples whichever way its normal points; with the geometric normal,
    # a ceiling whose normal points up (away from the room) drew none, and each BSDF sample that found the lamp
    # counted as unsampled at full weight.
    means, counts = {}, {}
    for up in (False, True):
        sc = lamp_over_hole(metric("schwarzschild", 1.0), normal_up=up)
        imgs = [wv.render(sc, spp=16, seed=s, max_depth=2, lens_images=3) for s in range(6)]
        means[up] = np.array([img.rgb.mean() for img in imgs])
        counts[up] = [sum(img.stats[k] for img in imgs) for k in ("light_hits", "unsampled_light_hits")]
    for up in (False, True):
        assert counts[up][0] >= 10 and counts[up][1] == 0
    assert_same_mean(means[True], means[False])
    assert means[True].var() < 4 * means[False].var()
