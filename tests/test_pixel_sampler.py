"""The stratified pixel sampler (core/sobol.h): every prefix of 2^k points of a pixel is a (0, k, 2)-net
(one point in each of the 2^k boxes of every elementary shape), pixels are scrambled independently, and
renders with it keep the mean of uniform jitter while edges inside pixels average out faster."""

import numpy as np
import pytest

import warpviz as wv
from warpviz._native import testing
from native_scenes import metric, room
from test_render import _image_means, assert_same_mean


@pytest.mark.parametrize("k", [2, 4, 6, 8])
def test_every_power_of_two_prefix_is_a_net(k):
    n = 2**k
    for pixel in (0, 17, 123456):
        pts = testing.pixel_samples(5, pixel, n)
        assert pts.shape == (n, 2) and (pts >= 0).all() and (pts < 1).all()
        for j in range(k + 1):  # boxes of 2^j x 2^(k - j)
            cells = np.floor(pts[:, 0] * 2**j).astype(int) * 2 ** (k - j) + np.floor(pts[:, 1] * 2 ** (k - j)).astype(int)
            assert np.bincount(cells, minlength=n).tolist() == [1] * n


def test_pixels_and_seeds_are_scrambled_apart():
    a, b, c = (testing.pixel_samples(s, p, 64) for s, p in ((1, 0), (1, 1), (2, 0)))
    assert not np.allclose(a, b) and not np.allclose(a, c)
    # independent scrambles: the first points of many pixels are uniform
    first = np.array([testing.pixel_samples(3, p, 1)[0] for p in range(4000)])
    hist = np.histogram2d(first[:, 0], first[:, 1], bins=4, range=[[0, 1], [0, 1]])[0]
    assert hist.min() > 180 and hist.max() < 320


def test_stratified_pixels_keep_the_mean_and_lower_edge_noise():
    scene = room(metric("schwarzschild", 1.0), size=(12, 9), light=3.0)
    sobol = _image_means(scene, range(8), spp=8, max_depth=2)
    independent = _image_means(scene, range(8, 16), spp=8, max_depth=2, pixel_sampler="independent")
    assert_same_mean(sobol, independent, slack=2e-3 * independent.mean())

    def frames(ps):
        return np.stack([wv.render(scene, spp=16, seed=s, max_depth=1, pixel_sampler=ps, edge_samples=1,
                                   camera_light_samples=False).rgb
                         for s in range(10)]).astype(np.float64)  # (the same samples in every pixel)

    # the camera segment alone (the lamp seen through the lens): what varies is only where in its pixel a
    # sample looks (measured: 0.5x the variance at 16 spp; the camera's own light samples, off here, take
    # 12x off the variance of the lamp's pixels in either case)
    assert frames("sobol").var(axis=0).mean() < 0.75 * frames("independent").var(axis=0).mean()


def test_pixel_sampler_is_validated():
    with pytest.raises(ValueError, match="pixel_sampler must be one of 'sobol', 'independent', got 'halton'"):
        wv.render(room(metric("minkowski"), size=(4, 3)), spp=1, pixel_sampler="halton")
