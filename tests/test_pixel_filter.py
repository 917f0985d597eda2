"""Pixel reconstruction filters (film/pixel_filter.h): the sampled offsets follow the filter, a filtered
edge is the analytic convolution, and filtered images stay bit-identical for any thread count."""

from __future__ import annotations

import math

import numpy as np
import pytest

import warpviz as wv
from warpviz._native import testing
from warpviz.render.render import FILTER_RADII

KINDS = {"box": 0, "gaussian": 1, "mitchell": 2}


def profile(name: str, radius: float, x: np.ndarray) -> np.ndarray:
    """The 1-D filter profiles by their textbook definitions (unnormalised)."""
    ax = np.abs(x)
    if name == "box":
        f = np.ones_like(x)
    elif name == "gaussian":
        sigma = radius / 3.0
        f = np.exp(-x * x / (2 * sigma * sigma))
    else:  # Mitchell-Netravali, B = C = 1/3, t in [0, 2] over the support
        b = c = 1.0 / 3.0
        t = 2.0 * ax / radius
        inner = ((12 - 9 * b - 6 * c) * t**3 + (-18 + 12 * b + 6 * c) * t**2 + (6 - 2 * b)) / 6
        outer = ((-b - 6 * c) * t**3 + (6 * b + 30 * c) * t**2 + (-12 * b - 48 * c) * t + (8 * b + 24 * c)) / 6
        f = np.where(t < 1, inner, outer)
    return np.where(ax <= radius, f, 0.0)


def filter_cdf(name: str, radius: float, x: np.ndarray) -> np.ndarray:
    """Signed cumulative integral of the normalised profile up to x, by fine quadrature."""
    grid = np.linspace(-radius, radius, 400_001)
    f = profile(name, radius, grid)
    cum = np.concatenate([[0.0], np.cumsum(0.5 * (f[1:] + f[:-1]) * np.diff(grid))])
    return np.interp(x, grid, cum / cum[-1])


@pytest.mark.parametrize("name", ["box", "gaussian", "mitchell"])
@pytest.mark.parametrize("scale", [1.0, 1.7])
def test_sampled_offsets_follow_the_filter(name, scale):
    """Weighted histogram of 400k offsets against the filter's mass per bin (z-scores), and weighted
    moments against the filter's; gaussian and box need no weights (exact inverse CDFs)."""
    radius = FILTER_RADII[name] * scale
    rng = np.random.default_rng(11)
    u = rng.random(400_000)
    x, w = testing.filter_samples(KINDS[name], radius, u)
    assert np.all(np.abs(x) <= radius)
    if name != "mitchell":
        np.testing.assert_array_equal(w, 1.0)
    else:
        assert (w < 0).mean() > 0.01  # the negative lobes are sampled, with negative weights
    edges = np.linspace(-radius, radius, 41)
    expected = np.diff(filter_cdf(name, radius, edges))
    which = np.clip(np.digitize(x, edges) - 1, 0, 39)
    for j in range(40):
        contrib = np.where(which == j, w, 0.0)
        z = (contrib.mean() - expected[j]) / (contrib.std() / math.sqrt(len(u)) + 1e-12)
        assert abs(z) < 4.5, (j, contrib.mean(), expected[j], z)
    grid = np.linspace(-radius, radius, 400_001)
    f = profile(name, radius, grid)
    for k in (0, 2, 4):
        exact = np.trapezoid(f * grid**k, grid) / np.trapezoid(f, grid)
        est = np.mean(w * x**k)
        sd = np.std(w * x**k) / math.sqrt(len(u))
        assert abs(est - exact) < 4.5 * sd + 1e-12, (k, est, exact)


def test_box_of_the_pixel_is_the_plain_jitter():
    u = np.linspace(0.0, 1.0, 101)[:-1]
    x, w = testing.filter_samples(0, 0.5, u)
    np.testing.assert_allclose(x, u - 0.5, rtol=0, atol=1e-16)
    np.testing.assert_array_equal(w, 1.0)


def _edge_scene(width: int, edge_px: float, distance: float = 10.0, fov: float = 10.0, height: int = 2) -> dict:
    """Flat space: an emissive quad (radiance 1) covering x >= X_e of the plane y = 0 before a black sky,
    placed so its edge falls at pixel coordinate edge_px."""
    tan_half = math.tan(math.radians(fov) / 2)
    x_edge = (2 * edge_px / width - 1) * tan_half * width / height * distance
    big = 100.0
    return {
        "metric": {"name": "minkowski", "params": []},
        "camera": {"position": [0, -distance, 0], "look_at": [0, 0, 0], "up": [0, 0, 1], "fov": fov,
                   "width": width, "height": height},
        "materials": [{"type": "emissive", "strength": 1.0}],
        "shapes": [{"type": "quad", "corner": [x_edge, 0, -big], "edge_u": [big, 0, 0], "edge_v": [0, 0, 2 * big],
                    "material": 0}],
        "environment": {"color": [0, 0, 0]},
    }


@pytest.mark.parametrize("name", ["gaussian", "mitchell"])
def test_filtered_edge_is_the_analytic_convolution(name):
    """A step edge at pixel coordinate 16.3: pixel px sees 1 - F(16.3 - (px + 1/2)), F the filter's CDF."""
    width, edge, spp = 32, 16.3, 1024
    img = wv.render(_edge_scene(width, edge), spp=spp, filter=name, threads=2)
    got = img.rgb[:, :, 0].astype(np.float64).mean(axis=0)
    centres = np.arange(width) + 0.5
    exact = 1.0 - filter_cdf(name, FILTER_RADII[name], edge - centres)
    transition = np.abs(edge - centres) < FILTER_RADII[name]
    assert transition.sum() >= 3
    tol = 4.0 * np.sqrt(np.maximum(exact * (1 - exact), 0.02) / (2 * spp)) + 2e-3
    np.testing.assert_array_less(np.abs(got - exact), tol)
    box = wv.render(_edge_scene(width, edge), spp=spp, threads=2).rgb[:, :, 0].astype(np.float64).mean(axis=0)
    assert abs(box[16] - 0.7) < 0.01  # the box of the pixel: the covered fraction of pixel 16
    assert np.abs(got - box)[transition].max() > 0.02  # the filter changed the image where it should


@pytest.mark.parametrize("name", ["gaussian", "mitchell"])
def test_filtered_renders_are_bit_identical_for_any_thread_count(name):
    kw = {"width": 12, "height": 9, "spp": 4, "progress": None, "filter": name}
    for flat in (True, False):
        one = wv.render("fig07", threads=1, flat=flat, **kw).rgb
        two = wv.render("fig07", threads=2, flat=flat, **kw).rgb
        lone = wv.render("fig07", threads=2, flat=flat, batch=False, **kw).rgb
        np.testing.assert_array_equal(one, two)
        np.testing.assert_array_equal(one, lone)
    assert not np.array_equal(one, wv.render("fig07", threads=2, **{**kw, "filter": "box"}).rgb)


def test_filter_options_are_checked():
    with pytest.raises(ValueError, match="filter must be one of"):
        wv.render("fig07", width=4, height=3, spp=1, filter="lanczos")
    with pytest.raises(ValueError, match="filter_radius must be"):
        wv.render("fig07", width=4, height=3, spp=1, filter="gaussian", filter_radius=0.0)
