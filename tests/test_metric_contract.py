"""The Metric contract, checked for every metric compiled into the core (GYOTO/Gradus style)."""

import numpy as np
import pytest

import warpviz as wv
from warpviz._native import testing as core
from warpviz.spacetime.metrics import _CLASSES, LineElementMetric

from conftest import metric_instances

METRICS = metric_instances()
IDS = [m.name for m in METRICS]


def test_every_registered_metric_has_a_python_class_and_is_tested():
    registered = {m["name"] for m in wv.registered_metrics()}
    assert registered == set(_CLASSES) and set(IDS) <= registered
    # every metric file is tested; line elements loaded after collection (shipped scenes, benchmarks) join the
    # registry later in a session, and two of them are tested here (conftest.EXPRESSION_METRICS)
    assert {n for n in registered if not issubclass(_CLASSES[n], LineElementMetric)} <= set(IDS)
    for entry in wv.registered_metrics():
        assert entry["invariants"][0] == "H"
        assert entry["params"] == list(_CLASSES[entry["name"]]._param_names)


def random_states(metric, n, rng):
    """States with positions outside any horizon/throat, near the axis and near the Kerr disk."""
    pos = rng.normal(size=(n, 3)) * 6.0
    pos[: n // 4, :2] *= 1e-3  # near the spin axis
    pos[n // 4 : n // 2, 2] *= 1e-3  # near the equatorial plane
    r = np.linalg.norm(pos, axis=1)
    pos *= (np.maximum(r, 2.5) / r)[:, None]
    ys = np.zeros((n, 8))
    ys[:, 0] = rng.normal(size=n)
    ys[:, 1:4] = pos
    ys[:, 4] = -1.0
    ys[:, 5:] = rng.normal(size=(n, 3))
    return ys


@pytest.mark.parametrize("metric", METRICS, ids=IDS)
def test_hand_written_derivatives_match_dual_numbers(metric):
    """Hand-written Hamilton equations (dg^{mu nu}/dx contracted with p) equal the dual-number ones."""
    rng = np.random.default_rng(7)
    for y in random_states(metric, 400, rng):
        hand = core.rhs(metric.name, metric.param_values, y)
        auto = core.rhs(metric.name, metric.param_values, y, autodiff=True)
        scale = np.max(np.abs(auto))
        np.testing.assert_allclose(hand, auto, rtol=0, atol=1e-12 * scale)


@pytest.mark.parametrize("metric", METRICS, ids=IDS)
def test_inverse_metric_is_symmetric_and_stationary(metric):
    rng = np.random.default_rng(3)
    for y in random_states(metric, 50, rng):
        gi = core.inverse_metric(metric.name, metric.param_values, y[:4])
        np.testing.assert_allclose(gi, gi.T, rtol=1e-15, atol=1e-15)
        dy = core.rhs(metric.name, metric.param_values, y)
        assert dy[4] == 0.0  # p_t conserved: no metric depends on t


@pytest.mark.parametrize("metric", METRICS, ids=IDS)
def test_local_frame_gives_null_momentum_and_round_trips(metric):
    """Initial momenta are null (H = 0 to rounding) and have unit energy for the local observer."""
    rng = np.random.default_rng(11)
    for _ in range(100):
        pos = rng.normal(size=3)
        pos *= rng.uniform(3.0, 40.0) / np.linalg.norm(pos)
        n = rng.normal(size=3)
        n /= np.linalg.norm(n)
        y = core.initial_state(metric.name, metric.param_values, pos, n, 1)
        gi = core.inverse_metric(metric.name, metric.param_values, y[:4])
        p = y[4:]
        h = 0.5 * p @ gi @ p
        assert abs(h) < 1e-13 * (p @ p)
        inv = core.invariants(metric.name, metric.param_values, y)
        assert abs(inv[0] - h) < 1e-14 * (p @ p)


@pytest.mark.parametrize("metric", METRICS[1:], ids=IDS[1:])
def test_conserved_quantities_are_conserved_by_the_flow(metric):
    """d/dlambda of every invariant along Hamilton's equations vanishes (finite differences)."""
    rng = np.random.default_rng(5)
    for y in random_states(metric, 40, rng):
        dy = core.rhs(metric.name, metric.param_values, y)
        eps = 1e-6
        ip = core.invariants(metric.name, metric.param_values, y + eps * dy)
        im = core.invariants(metric.name, metric.param_values, y - eps * dy)
        rate = (ip - im) / (2 * eps)
        scale = np.maximum(np.abs(core.invariants(metric.name, metric.param_values, y)), 1.0)
        assert np.all(np.abs(rate[1:]) < 1e-6 * scale[1:] * np.linalg.norm(dy)), (rate, scale)


@pytest.mark.parametrize("metric", METRICS, ids=IDS)
@pytest.mark.parametrize("stepper", wv.STEPPERS)
def test_every_ray_ends_with_a_defined_status_and_finite_output(metric, stepper):
    rng = np.random.default_rng(2)
    origins = rng.normal(size=(40, 3))
    origins *= (rng.uniform(4.0, 30.0, size=40) / np.linalg.norm(origins, axis=1))[:, None]
    dirs = rng.normal(size=(40, 3))
    rays = wv.trace(metric, origins, dirs, stepper=stepper, tol=1e-8, escape_radius=100.0)
    assert set(rays.status_names) <= {"escaped", "horizon"}
    assert np.isfinite(rays.final_positions).all() and np.isfinite(rays.final_directions).all()
    np.testing.assert_allclose(np.linalg.norm(rays.final_directions, axis=1), 1.0, atol=1e-12)
    assert rays.max_drift().max() < 1e-5


@pytest.mark.parametrize("metric", METRICS, ids=IDS)
def test_observer_frame_is_orthonormal_and_closed_form_matches_generic(metric):
    """The frame the renderer builds at every vertex: u timelike unit, e_j unit and orthogonal to u and
    to each other; where a metric gives it in closed form, it equals the generic Lowdin construction."""
    rng = np.random.default_rng(11)
    for y in random_states(metric, 200, rng):
        x = y[:4]
        fast = core.observer_frame(metric.name, metric.param_values, x)
        slow = core.observer_frame(metric.name, metric.param_values, x, generic=True)
        assert (fast is None) == (slow is None)
        if fast is None:
            continue
        g, u, e = fast
        basis = np.vstack([u, e])
        np.testing.assert_allclose(basis @ g @ basis.T, np.diag([-1.0, 1.0, 1.0, 1.0]), rtol=0, atol=1e-12)
        for a, b in zip(fast, slow):
            np.testing.assert_allclose(a, b, rtol=0, atol=1e-12 * max(1.0, np.max(np.abs(b))))


def test_no_observer_frame_inside_a_horizon():
    for name, params, x in [("schwarzschild", [1.0], [0, 1.5, 0, 0]), ("schwarzschild", [1.0], [0, 0, 0, 2.0])]:
        assert core.observer_frame(name, params, np.array(x, float)) is None
        assert core.observer_frame(name, params, np.array(x, float), generic=True) is None


def test_kerr_frame_in_and_around_the_ergoregion():
    """Kerr a = 0.9 M: the closed-form static frame outside the ergosurface (equatorial r_E = 2 M), the ZAMO
    inside it down to the horizon r+ = 1.436 M, each equal to the generic construction and orthonormal."""
    params = [1.0, 0.9]
    for r_bl in (1.5, 1.9, 1.999, 2.001, 2.5, 10.0):
        for theta in (np.pi / 2, 1.2, 0.3):
            rho = np.sqrt(r_bl**2 + 0.81) * np.sin(theta)  # Kerr-Schild x^2 + y^2 = (r^2 + a^2) sin^2 theta
            x = np.array([0.0, rho * np.cos(0.4), rho * np.sin(0.4), r_bl * np.cos(theta)])
            fast = core.observer_frame("kerr", params, x)
            slow = core.observer_frame("kerr", params, x, generic=True)
            assert fast is not None and slow is not None
            g, u, e = fast
            static = np.allclose(u[1:], 0.0)
            inside = r_bl < 1.0 + np.sqrt(1.0 - 0.81 * np.cos(theta) ** 2)
            assert static != inside  # ZAMO (rotating) exactly inside the ergosurface
            basis = np.vstack([u, e])
            np.testing.assert_allclose(basis @ g @ basis.T, np.diag([-1.0, 1.0, 1.0, 1.0]), rtol=0, atol=1e-11)
            for a, b in zip(fast, slow):
                np.testing.assert_allclose(a, b, rtol=0, atol=1e-11 * max(1.0, np.max(np.abs(b))))


@pytest.mark.parametrize("metric", METRICS, ids=IDS)
def test_registry_facts_are_complete_and_consistent(metric):
    """The registry is the single source of a metric's facts: its Python class is public under the registered
    class name, its defaults and example lie in its parameter ranges, and a metric without a lane-capable
    hand-written right-hand side is reported by build_info (it runs ~6x slower)."""
    entry = metric.registry_entry
    assert type(metric) is wv.metric_class(entry["name"])
    if not isinstance(metric, LineElementMetric):  # a line element's class is not a package name
        assert getattr(wv, entry["class_name"]) is type(metric)
    assert entry["summary"] and entry["sheets"] in (1, 2) and entry["invariants"][0] == "H"
    for spec in entry["param_specs"]:
        assert spec["doc"], spec
        for key in ("default", "example"):
            v = spec[key]
            assert (v > spec["lo"] if spec["lo_open"] else v >= spec["lo"]), (spec, key)
            assert (v < spec["hi"] if spec["hi_open"] else v <= spec["hi"]), (spec, key)
    assert type(metric)() == type(metric)(**{s["name"]: s["default"] for s in entry["param_specs"]})
    slow = wv.build_info()["slow_metrics"]
    assert (metric.name in slow) == (not entry["lane_rhs"] and not entry["flat"])


@pytest.mark.parametrize("metric", METRICS, ids=IDS)
def test_black_holes_capture_camera_rays_between_horizon_and_photon_orbit(metric):
    """Backward camera rays are captured at the capture radius, which must lie strictly between the horizon
    and the innermost photon orbit: at the horizon itself (the default) they never arrive in the ingoing
    Kerr-Schild chart and end as max_steps error pixels (8.9 % of a frame when it was left out)."""
    marks = metric.landmarks
    if "horizon" not in marks:
        assert "capture" not in marks and "photon_sphere" not in marks
        return
    innermost_orbit = marks.get("photon_sphere", marks.get("photon_prograde"))
    assert innermost_orbit is not None, "a black hole has a photon sphere or a photon region"
    assert marks["horizon"] < marks["capture"] < innermost_orbit
    assert marks.get("inner_horizon", 0.0) < marks["horizon"]
    if "photon_retrograde" in marks:
        assert marks["photon_prograde"] < marks["photon_polar"] < marks["photon_retrograde"]
    # a ray aimed straight at the hole falls in
    r = 20.0 * marks["mass"]
    rays = wv.trace(metric, [0.0, -r, 0.0], [0.0, 1.0, 0.0], tol=1e-9)
    assert rays.status_names.tolist() == ["horizon"]


def _kerr_schild_f(metric, r: float) -> float:
    """f(r) of a static, spherically symmetric Kerr-Schild metric g = eta + f l l (l^t = -1): g^tt = -1 - f."""
    gi = core.inverse_metric(metric.name, metric.param_values, np.array([0.0, r, 0.0, 0.0]))
    return -1.0 - gi[0, 0]


def _exact_deflection(metric, b: float) -> float:
    """Deflection of a ray with impact parameter b in ds^2 = -A dt^2 + dr^2 / A + r^2 dOmega^2, A = 1 - f(r):
    alpha = 2 int_0^u0 b du / sqrt(1 - b^2 u^2 A(1/u)) - pi, u0 the turning point, by quadrature with
    u = u0 (1 - t^2), which removes the endpoint's inverse-square-root singularity."""
    from scipy.integrate import quad
    from scipy.optimize import brentq

    def g(u):
        return 1.0 - b * b * u * u * (1.0 - _kerr_schild_f(metric, 1.0 / u))

    u_ph = 1.0 / metric.landmarks["photon_sphere"]
    u0 = brentq(g, 1e-12, u_ph, xtol=1e-16, rtol=1e-15)

    def integrand(t):
        u = u0 * (1.0 - t * t)
        val = g(u)
        return 2.0 * u0 * t * b / np.sqrt(val) if val > 0.0 else 0.0

    return 2.0 * quad(integrand, 0.0, 1.0, epsabs=0.0, epsrel=1e-13, limit=200)[0] - np.pi


# (the Kerr-Schild built-ins: _kerr_schild_f reads f from g^tt)
SPHERICAL = [m for m in METRICS if "photon_sphere" in m.landmarks and m.sheets == 1
             and not isinstance(m, LineElementMetric)]  # fmt: skip


@pytest.mark.parametrize("metric", SPHERICAL, ids=[m.name for m in SPHERICAL])
@pytest.mark.parametrize("b_over_bc", [1.2, 4.0])
def test_deflection_matches_the_exact_integral(metric, b_over_bc):
    """Every static spherically symmetric black hole of the registry (Schwarzschild, Reissner-Nordstrom, ...)
    deflects light by the exact integral of its own f(r), read from its inverse metric."""
    from conftest import deflection

    r_ph = metric.landmarks["photon_sphere"]
    b_c = r_ph / np.sqrt(1.0 - _kerr_schild_f(metric, r_ph))  # critical impact parameter
    b, r0 = b_over_bc * b_c, 1e3 * metric.landmarks["mass"]
    s = b * np.sqrt(1.0 - _kerr_schild_f(metric, r0)) / r0  # sin(angle from radial) seen by the static observer
    alpha = deflection(metric, r0, np.array([np.sqrt(1.0 - s * s), s, 0.0]), tol=1e-10)
    assert alpha == pytest.approx(_exact_deflection(metric, b), rel=1e-8)
