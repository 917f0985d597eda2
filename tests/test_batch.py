"""SIMD ray batches (renderer_ext/spacetime/ray_batch.h): every ray's result is bit-identical to tracing
it alone, whatever else shares its batch, for every ending a ray can have; a render whose samples'
geodesics share the lanes is bit-identical to one that integrates each geodesic on its own."""

import numpy as np
import pytest

import warpviz as wv

from conftest import metric_instances

RNG = np.random.default_rng(20261201)


def mixed_rays(metric, n=301):
    """n rays (not a multiple of the 8 lanes, more than one 256-ray block) that escape, fall in, wind
    near the photon orbit, start beyond the escape radius or (Ellis) pass the throat."""
    r0 = 40.0 if metric.sheets == 1 else 12.0
    u = RNG.normal(size=(n, 3))
    origins = r0 * u / np.linalg.norm(u, axis=1)[:, None]
    inward = -origins / r0
    tangent = np.cross(inward, RNG.normal(size=(n, 3)))
    tangent /= np.linalg.norm(tangent, axis=1)[:, None]
    angle = RNG.uniform(0.0, 0.25, size=n)  # up to ~10 M impact parameter: captured, winding, escaping
    dirs = np.cos(angle)[:, None] * inward + np.sin(angle)[:, None] * tangent
    origins[:5] = [[1500.0, 0.0, 0.0]] * 5  # beyond the escape radius
    dirs[:5] = [[1.0, 0.0, 0.0], [0.9, 0.1, 0.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.6, 0.0, 0.8]]
    return origins, dirs


# Every curved metric of the registry (its example parameters), plus a retrograde Kerr hole.
METRICS = [m for m in metric_instances() if not m.is_flat] + [wv.Kerr(mass=1.0, spin=-0.5)]


def assert_bundles_identical(a: wv.RayBundle, b: wv.RayBundle):
    for name in ("status", "final_positions", "final_directions", "final_sheets", "n_steps"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)
    assert a.invariant_drift.keys() == b.invariant_drift.keys()
    for k in a.invariant_drift:
        np.testing.assert_array_equal(a.invariant_drift[k], b.invariant_drift[k], err_msg=k)
    if a.points is not None:
        np.testing.assert_array_equal(a.offsets, b.offsets)
        np.testing.assert_array_equal(a.points, b.points)
        assert a.point_data.keys() == b.point_data.keys()
        for k in a.point_data:
            np.testing.assert_array_equal(a.point_data[k], b.point_data[k], err_msg=k)


@pytest.mark.parametrize("metric", METRICS, ids=repr)
@pytest.mark.parametrize("record", [False, True])
def test_batch_equals_one_ray_at_a_time(metric, record):
    origins, dirs = mixed_rays(metric)
    kw = dict(tol=1e-9, record=record, threads=1)
    batched = wv.trace(metric, origins, dirs, batch=True, **kw)
    single = wv.trace(metric, origins, dirs, batch=False, **kw)
    assert_bundles_identical(batched, single)
    counts = batched.counts()
    assert counts.get("escaped", 0) > 0
    if metric.sheets == 1:
        assert counts.get("horizon", 0) > 0
    else:
        assert np.any(batched.final_sheets == -1)


@pytest.mark.parametrize("metric", METRICS[:2], ids=repr)
def test_batch_step_budget_and_thread_count(metric):
    """Rays that run out of steps mid-batch end like lone rays; threads do not change anything."""
    origins, dirs = mixed_rays(metric, n=64)
    one = wv.trace(metric, origins, dirs, max_steps=40, threads=1)
    assert one.counts().get("max_steps", 0) > 0
    assert_bundles_identical(one, wv.trace(metric, origins, dirs, max_steps=40, batch=False, threads=1))
    assert_bundles_identical(one, wv.trace(metric, origins, dirs, max_steps=40, threads=2))


def test_batch_of_one_ray_and_loose_tolerance():
    metric = wv.Kerr(mass=1.0, spin=0.99)
    for tol in (1e-4, 1e-12):
        a = wv.trace(metric, [30.0, 1.0, 2.0], [-1.0, 0.1, 0.05], tol=tol)
        b = wv.trace(metric, [30.0, 1.0, 2.0], [-1.0, 0.1, 0.05], tol=tol, batch=False)
        assert_bundles_identical(a, b)


@pytest.mark.parametrize("stepper", ["rk4", "dop853"])
def test_other_steppers_in_lanes_equal_lone_rays(stepper):
    metric = wv.Kerr(mass=1.0, spin=0.7)
    origins, dirs = mixed_rays(metric, n=45)
    kw = dict(stepper=stepper, tol=1e-8, record=True, threads=1)
    assert_bundles_identical(wv.trace(metric, origins, dirs, **kw), wv.trace(metric, origins, dirs, batch=False, **kw))


# --- the renderer: many samples' geodesics step together in the lanes --------------------------------

from native_scenes import metric as native_metric  # noqa: E402
from native_scenes import room  # noqa: E402


def _counts(stats: dict) -> dict:
    return {k: v for k, v in stats.items() if k not in ("seconds", "threads")}


def assert_images_identical(a: wv.Image, b: wv.Image):
    np.testing.assert_array_equal(a.rgb, b.rgb)
    assert a.aovs.keys() == b.aovs.keys()
    for k in a.aovs:
        np.testing.assert_array_equal(a.aovs[k], b.aovs[k], err_msg=k)
    assert _counts(a.stats) == _counts(b.stats)


@pytest.mark.parametrize(
    "spec", [("schwarzschild", 2.5), ("kerr", 2.5, 0.9), ("ellis", 5.0)], ids=lambda s: s[0]
)
def test_render_in_lanes_equals_render_one_geodesic_at_a_time(spec):
    """Light connection, pilots, bounces and recorded paths: the same image, AOVs, statistics and paths."""
    scene = room(native_metric(*spec), size=(12, 9), spheres=True)
    pixels = [[3, 4], [6, 2], [11, 8]]
    lanes = wv.render(scene, spp=3, threads=1, record_pixels=pixels)
    single = wv.render(scene, spp=3, threads=1, batch=False, record_pixels=pixels)
    assert_images_identical(lanes, single)
    assert_bundles_identical(lanes.rays, single.rays)
    assert lanes.stats["steps"] > 0
    assert_images_identical(lanes, wv.render(scene, spp=3, threads=2, record_pixels=pixels))


def test_render_in_lanes_with_brute_force_and_without_aiming():
    scene = room(native_metric("schwarzschild", 2.5), size=(10, 8))
    for kw in ({"light_sampling": False}, {"aim_lights": False, "light_connection": "aimed"}):
        assert_images_identical(wv.render(scene, spp=2, **kw), wv.render(scene, spp=2, batch=False, **kw))


@pytest.mark.parametrize("stepper", ["rk4", "dop853"])
def test_render_with_other_steppers_in_lanes_equals_one_geodesic_at_a_time(stepper):
    scene = room(native_metric("kerr", 2.5, 0.6), size=(8, 6))
    assert_images_identical(wv.render(scene, spp=1, stepper=stepper, tol=1e-6),
                            wv.render(scene, spp=1, stepper=stepper, tol=1e-6, batch=False))


def test_pilot_tolerance_is_validated_and_reported_kernel_is_named():
    scene = room(native_metric("schwarzschild", 2.5), size=(4, 3))
    with pytest.raises(ValueError, match="pilot_tol"):
        wv.render(scene, spp=1, pilot_tol=0.0)
    info = wv.build_info()
    assert "8-ray batches" in info["simd"]
    assert "-ffp-contract=off" in info["flags"]
