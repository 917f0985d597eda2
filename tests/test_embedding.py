"""Wormhole embedding diagrams from the lens functions a metric declares (warpviz/spacetime/embedding.py):
exact against the Ellis catenoid and the Morris–Thorne paraboloid, against adaptive quadrature for a
wormhole with a redshift, and drawn for every registered wormhole with no code naming it."""

import math

import numpy as np
import pytest
from scipy import integrate

import warpviz as wv
from warpviz.spacetime import metric_names
from warpviz.spacetime.embedding import WormholeProfile, has_embedding

#: Areal radii from a hair above the throat to far out, in throat radii.
RADII = 1.0 + np.array([1e-12, 1e-8, 1e-4, 0.01, 0.3, 1.0, 2.5, 9.0, 40.0, 1e3, 1e6])


def lens(a, h, throat):
    pad = lambda c: list(c) + [0.0] * (5 - len(c))  # noqa: E731
    return {"a": pad(a), "h": pad(h), "u_inner": 1.0 / throat, "throat": True}


@pytest.mark.parametrize("b0", [0.5, 1.0, 8.0])
def test_ellis_profile_is_the_catenoid(b0):
    """Ellis: l = sqrt(R² − b0²), z = b0 asinh(l / b0), to rounding, also a hair above the throat."""
    profile = WormholeProfile.of(wv.EllisWormhole(throat=b0))
    r = b0 * RADII
    ell = np.sqrt((r - b0) * (r + b0))
    np.testing.assert_allclose(profile.distance(r), ell, rtol=2e-14)
    np.testing.assert_allclose(profile.height(r), b0 * np.arcsinh(ell / b0), rtol=2e-14)
    np.testing.assert_allclose(profile.radius_at(ell), r, rtol=2e-14)
    assert profile.throat == b0 and profile.height(b0) == 0.0 and profile.height(0.5 * b0) == 0.0


def test_morris_thorne_constant_shape_function_is_flamms_paraboloid():
    """ds² = −dt² + dR² / (1 − b0/R) + R² dΩ²: z = 2 sqrt(b0 (R − b0)) and
    l = sqrt(R (R − b0)) + b0 ln((sqrt R + sqrt(R − b0)) / sqrt b0) (Morris & Thorne 1988, their b = b0)."""
    b0 = 2.0
    profile = WormholeProfile(lens([1.0], [1.0, -b0], b0))
    r = b0 * RADII
    np.testing.assert_allclose(profile.height(r), 2.0 * np.sqrt(b0 * (r - b0)), rtol=2e-14)
    exact_l = np.sqrt(r * (r - b0)) + b0 * np.arcsinh(np.sqrt((r - b0) / b0))  # the log, without cancelling
    np.testing.assert_allclose(profile.distance(r), exact_l, rtol=2e-14)
    np.testing.assert_allclose(profile.radius_at(exact_l), r, rtol=1e-13)


def test_a_wormhole_with_redshift_matches_adaptive_quadrature():
    """A = 1 + 0.3 u² − 0.05 u³, h = 1 − u − 0.4 u² + 0.4 u³ (throat at R = 1, where h = 0): l and z against
    QUADPACK with the throat's inverse square root as its weight."""
    a, h = [1.0, 0.0, 0.3, -0.05], [1.0, -1.0, -0.4, 0.4]
    assert abs(np.polynomial.polynomial.polyval(1.0, h)) < 1e-15
    profile = WormholeProfile(lens(a, h, 1.0))
    big_a = lambda x: 1.0 + 0.3 / x**2 - 0.05 / x**3  # noqa: E731
    rest = lambda x: x / (big_a(x) * (1.0 - 0.4 / x**2))  # (R - 1) / F, as h = (1 - u)(1 - 0.4 u²)  # noqa: E731
    for r in (1.0 + 1e-6, 1.3, 4.0, 30.0):
        kw = {"weight": "alg", "wvar": (-0.5, 0.0), "epsabs": 0.0, "epsrel": 1e-13, "limit": 200}
        ell = integrate.quad(lambda x: math.sqrt(rest(x)), 1.0, r, **kw)[0]
        one_minus_f = lambda x: 1.0 - big_a(x) * (1.0 - 1.0 / x) * (1.0 - 0.4 / x**2)  # noqa: E731
        z = integrate.quad(lambda x: math.sqrt(rest(x) * one_minus_f(x)), 1.0, r, **kw)[0]
        assert profile.distance(r) == pytest.approx(ell, rel=1e-12)
        assert profile.height(r) == pytest.approx(z, rel=1e-12)


@pytest.mark.parametrize("name", metric_names())
def test_every_registered_wormhole_gets_its_diagram_and_nothing_else_does(name):
    """The diagram follows from registry facts alone: a static spherical metric with a throat has one (its
    meridian is isometric: dρ² + dz² = dl²), every other metric refuses with a clear error."""
    metric = wv.metric_class(name).example()
    features = wv.metric_features(metric, resolution=8)
    if not has_embedding(metric):
        assert "embedding" not in features
        with pytest.raises(ValueError, match="no embedding diagram"):
            wv.wormhole_embedding(metric)
        return
    assert metric.sheets == 2 and "throat" in metric.landmarks
    emb = wv.wormhole_embedding(metric, resolution=200)
    assert emb is not None and "embedding" in features
    on_meridian = np.abs(emb.points[:, 1]) < 1e-12  # the points at azimuth 0
    on_meridian &= emb.points[:, 0] > 0
    rho, z, ell = emb.points[on_meridian, 0], emb.points[on_meridian, 2], emb.point_data["l"][on_meridian]
    order = np.argsort(ell)
    arc = np.hypot(np.diff(rho[order]), np.diff(z[order]))
    np.testing.assert_allclose(arc, np.diff(ell[order]), rtol=2e-3)  # chords of a curve: second order
    mapped = wv.wormhole_embedding_points(metric, [[0.0, 3.0 * metric.landmarks["throat"], 0.0]], [-1])
    assert mapped[0, 2] < 0 and mapped[0, 1] == pytest.approx(3.0 * metric.landmarks["throat"])


def test_profile_refuses_what_is_not_a_wormhole():
    with pytest.raises(ValueError, match="throat"):
        WormholeProfile({"a": [1, 0, 0, 0, 0], "h": [1, 0, 0, 0, 0], "u_inner": 1 / 3, "throat": False})
    with pytest.raises(ValueError, match="no embedding diagram"):
        WormholeProfile.of(wv.Schwarzschild(mass=1.0))
    profile = WormholeProfile.of(wv.EllisWormhole(throat=1.0))
    with pytest.raises(ValueError, match="finite and >= 0"):
        profile.radius_at(-1.0)
    with pytest.raises(ValueError, match="l_max"):
        wv.wormhole_embedding(wv.EllisWormhole(throat=1.0), l_max=float("nan"))
    assert wv.Schwarzschild(mass=1.0).spherical_lens["throat"] is False
    assert wv.Kerr(mass=1.0, spin=0.5).spherical_lens is None
