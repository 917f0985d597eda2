"""BSDF sampling against evaluation for every material: the sampled directions follow the evaluated pdf
(chi-square over solid-angle bins), sample weights equal f |cos| / pdf, the BSDF integrates to the
albedo, and the dielectric reflects exactly the Fresnel fraction with Snell's-law refraction."""

import math

import numpy as np
import pytest
from scipy import stats

from warpviz._native import testing as core
from warpviz.scene.native import native_material

N_Z = np.array([0.0, 0.0, 1.0])
WO = np.array([0.6, 0.0, 0.8])  # 36.87 degrees from the normal


def sample(material, *, n=N_Z, wo=WO, albedo=(0.8, 0.5, 0.2), count=200_000, seed=1, at=None):
    u = np.random.default_rng(seed).random((count, 3))
    at = np.zeros((0, 3)) if at is None else np.ascontiguousarray(at, dtype=np.float64)
    material = native_material(material)  # the optional keys' defaults, as for a scene
    return core.bsdf(material, list(albedo), list(n), list(wo), np.ascontiguousarray(u), at)


def fresnel(cos_i, eta):
    sin2_t = (1 - cos_i**2) / eta**2
    if sin2_t >= 1:
        return 1.0, 0.0
    cos_t = math.sqrt(1 - sin2_t)
    rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t)
    rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t)
    return 0.5 * (rs**2 + rp**2), cos_t


DIFFUSE = {"type": "diffuse", "texture": -1}


@pytest.mark.parametrize("wo", [WO, np.array([0.0, 0.6, -0.8])], ids=["front", "back"])
def test_diffuse_samples_follow_the_evaluated_pdf(wo):
    s = sample(DIFFUSE, wo=wo)
    assert s["valid"].all() and not s["delta"].any()
    wi = s["wi"]
    side = np.sign(wo @ N_Z)
    assert np.all(wi @ N_Z * side > 0)  # same side as wo (two-sided Lambert)
    np.testing.assert_allclose(s["pdf"], s["pdf_eval"], rtol=1e-12)
    np.testing.assert_allclose(s["weight"], s["f_eval"] / s["pdf_eval"][:, None], rtol=1e-12)
    np.testing.assert_allclose(s["weight"], np.broadcast_to([0.8, 0.5, 0.2], wi.shape), rtol=1e-12)
    # chi-square over 8 x 8 bins equal in solid angle measure of the cosine pdf:
    # u1 = 1 - cos^2(theta) is uniform, phi / 2pi is uniform
    cos_t = np.abs(wi[:, 2])
    a = np.clip((1 - cos_t**2) * 8, 0, 7.999).astype(int)
    b = np.clip((np.arctan2(wi[:, 1], wi[:, 0]) % (2 * np.pi)) / (2 * np.pi) * 8, 0, 7.999).astype(int)
    counts = np.bincount(a * 8 + b, minlength=64)
    p = stats.chisquare(counts).pvalue
    assert p > 1e-4, p


def test_diffuse_bsdf_and_pdf_integrate_to_albedo_and_one():
    """Over uniformly distributed directions: the integral of f |cos| is the albedo and that of the pdf
    is 1 (both evaluated by the renderer's own bsdf_eval)."""
    rng = np.random.default_rng(2)
    v = rng.normal(size=(400_000, 3))
    v /= np.linalg.norm(v, axis=1)[:, None]
    s = sample(DIFFUSE, count=1, at=v)
    np.testing.assert_allclose(s["f_at"].mean(axis=0) * 4 * np.pi, [0.8, 0.5, 0.2], rtol=1e-2)
    assert s["pdf_at"].mean() * 4 * np.pi == pytest.approx(1.0, rel=1e-2)
    assert np.all(s["f_at"][(v @ N_Z) * (WO @ N_Z) < 0] == 0)  # nothing on the far side


def test_mirror_reflects_specularly():
    s = sample({"type": "mirror", "reflectance": [0.9, 0.8, 0.7]}, count=100)
    assert s["delta"].all() and s["valid"].all()
    np.testing.assert_allclose(s["wi"], np.broadcast_to([-0.6, 0.0, 0.8], (100, 3)), atol=1e-15)
    np.testing.assert_allclose(s["weight"], np.broadcast_to([0.9, 0.8, 0.7], (100, 3)))
    assert np.all(s["f_eval"] == 0) and np.all(s["pdf_eval"] == 0)  # delta lobes are never evaluated


@pytest.mark.parametrize("inside", [False, True], ids=["entering", "leaving"])
def test_glass_reflects_the_fresnel_fraction_and_refracts_by_snell(inside):
    ior = 1.5
    wo = np.array([0.6, 0.0, 0.8]) if not inside else np.array([0.4, 0.0, -math.sqrt(1 - 0.16)])
    s = sample({"type": "glass", "ior": ior, "tint": [1.0, 0.9, 0.8]}, wo=wo, count=100_000)
    assert s["delta"].all() and s["valid"].all()
    cos_i = abs(wo[2])
    eta = ior if not inside else 1 / ior
    F, cos_t = fresnel(cos_i, eta)
    reflected = np.sign(s["wi"][:, 2]) == np.sign(wo[2])
    frac = reflected.mean()
    assert abs(frac - F) < 4 * math.sqrt(F * (1 - F) / 100_000) + 1e-9
    np.testing.assert_allclose(s["wi"][reflected], np.broadcast_to([-wo[0], 0, wo[2]], (reflected.sum(), 3)),
                               atol=1e-12)
    if F < 1:
        t = s["wi"][~reflected]
        # Snell: sin_t = sin_i / eta, in the plane of incidence, on the other side
        np.testing.assert_allclose(np.hypot(t[:, 0], t[:, 1]), math.sqrt(1 - cos_i**2) / eta, rtol=1e-12)
        np.testing.assert_allclose(np.abs(t[:, 2]), cos_t, rtol=1e-12)
        assert np.all(t[:, 0] * wo[0] < 0) and np.all(t[:, 1] == 0)
        np.testing.assert_allclose(s["weight"][~reflected], np.broadcast_to([1.0, 0.9, 0.8], t.shape))


def test_glass_total_internal_reflection():
    wo = np.array([0.9, 0.0, -math.sqrt(1 - 0.81)])  # inside, beyond the critical angle of 41.8 degrees
    s = sample({"type": "glass", "ior": 1.5}, wo=wo, count=1000)
    assert np.all(np.sign(s["wi"][:, 2]) == np.sign(wo[2]))


def test_emitters_do_not_scatter():
    s = sample({"type": "emissive", "strength": 3.0}, count=10)
    assert not s["valid"].any()
