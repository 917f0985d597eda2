"""More samples where a pixel holds more than one surface (``render(detail_samples=)``,
integrators/render_loop.h: ``pixel_classes``).

The detail pixels are found by the probe rays that find the edges of lights, before any sample is drawn:
a pixel whose nine lattice probes disagree on where their branches end (which shape, the sky, the hole).
A pixel's sample count therefore does not depend on what its samples find. The tests check what keeps the
estimate unbiased and deterministic (a detail pixel is bit for bit the pixel of the longer render, every
other pixel that of the plain one, whatever the window and threads), that the probes find an outline,
through a hole's lens too, and the defaults, resume and bad values.
"""

import dataclasses
import importlib.util
import re

import numpy as np
import pytest

import warpviz as wv
from warpviz.options import DETAIL_SAMPLES, DETAIL_SAMPLES_DENOISED
from native_scenes import furnace, metric, room

CURVED = room(metric("schwarzschild", 0.4), size=(20, 15))
FLAT = room(metric(), size=(32, 24))


@pytest.mark.parametrize(("scene", "spp", "times"), [(CURVED, 4, 3), (FLAT, 4, 3), (FLAT, 70, 2)],
                         ids=["schwarzschild", "flat", "flat-passes-of-64"])
def test_detail_pixels_are_the_longer_render_and_the_rest_the_plain_one_bit_for_bit(scene, spp, times):
    more = wv.render(scene, spp=spp, seed=5, edge_samples=1, detail_samples=times)
    plain = wv.render(scene, spp=spp, seed=5, edge_samples=1, detail_samples=1)
    long = wv.render(scene, spp=spp * times, seed=5, edge_samples=1, detail_samples=1)
    detail = more.aovs["samples"] == spp * times
    # (with edge_samples 1 a light's edge gets the detail samples too, so every such pixel counts)
    assert 0 < detail.sum() == more.stats["detail_pixels"] + more.stats["edge_pixels"] < 0.5 * detail.size
    assert np.all(more.aovs["samples"][~detail] == spp)
    np.testing.assert_array_equal(more.rgb[detail], long.rgb[detail])
    np.testing.assert_array_equal(more.rgb[~detail], plain.rgb[~detail])
    assert plain.stats["detail_pixels"] == 0


def test_an_edge_pixel_gets_the_larger_multiple_and_a_detail_pixel_its_own():
    img = wv.render(FLAT, spp=2, seed=1, edge_samples=8, detail_samples=3)
    counts = img.aovs["samples"]
    assert img.stats["edge_pixels"] == (counts == 16).sum() > 0
    assert img.stats["detail_pixels"] == (counts == 6).sum() > 0
    assert set(np.unique(counts)) == {2, 6, 16}
    # edge_samples below detail_samples: the edge pixels get the detail pixels' multiple
    low = wv.render(FLAT, spp=2, seed=1, edge_samples=2, detail_samples=3).aovs["samples"]
    np.testing.assert_array_equal(low > 2, counts > 2)
    assert set(np.unique(low)) == {2, 6}


def test_detail_pixels_do_not_depend_on_the_window_or_the_threads():
    whole = wv.render(CURVED, spp=2, seed=1, threads=1, detail_samples=3)
    tiles = np.zeros_like(whole.rgb)
    counts = np.zeros_like(whole.aovs["samples"])
    for x0, y0, w, h in [(0, 0, 7, 15), (7, 0, 13, 8), (7, 8, 13, 7)]:
        tile = wv.render(CURVED, spp=2, seed=1, threads=2, crop=(x0, y0, w, h), detail_samples=3)
        tiles[y0:y0 + h, x0:x0 + w] = tile.rgb
        counts[y0:y0 + h, x0:x0 + w] = tile.aovs["samples"]
    np.testing.assert_array_equal(tiles, whole.rgb)
    np.testing.assert_array_equal(counts, whole.aovs["samples"])
    assert (counts == 6).sum() == whole.stats["detail_pixels"] > 0


@pytest.mark.parametrize("metric_spec", [metric(), metric("schwarzschild", 0.3)], ids=["flat", "schwarzschild"])
def test_the_probes_find_an_outline(metric_spec):
    """A grey ball under a uniform sky (nothing emits, so there are no edge pixels): a pixel the ball covers
    by a quarter to three quarters always has probes on both sides of its outline (a cut that misses all
    nine probes of a pixel holds at most ~1/8 of it), one it covers fully or not at all is not a detail pixel.
    The ball's coverage is measured with the ball made a lamp and the sky black. Behind a mass the outline
    is where the lens puts it."""
    ball = furnace(albedo=0.5, size=(32, 24), metric_spec=metric_spec)
    img = wv.render(ball, spp=1, detail_samples=2)
    detail = img.aovs["samples"] > 1
    assert img.stats["edge_pixels"] == 0 and img.stats["detail_pixels"] == detail.sum()
    lamp = dict(ball, materials=[{"type": "emissive", "texture": 0, "strength": 2.0}], environment={"color": [0, 0, 0]})
    cover = wv.render(lamp, spp=1024, seed=3, max_depth=1, edge_samples=1).rgb[..., 0]
    half = (cover > 0.25) & (cover < 0.75)
    assert half.sum() >= 8 and np.all(detail[half])
    assert not np.any(detail[(cover == 0.0) | (cover == 1.0)])


def test_the_probes_see_the_room_squeezed_round_a_shadow():
    """Round a hole's shadow the room is squeezed into thin rings: the pixels next to the shadow hold many
    surfaces, and the probes find more of them the closer to the rim."""
    img = wv.render(room(metric("schwarzschild", 1.0), size=(48, 36), spheres=False), spp=1, detail_samples=2,
                    edge_samples=1, aovs=["status"])  # fmt: skip
    detail = img.aovs["samples"] > 1
    shadow = img.aovs["status"] == 2  # (sample 0's camera ray crossed the horizon)
    assert shadow.sum() > 20
    rim = np.zeros_like(shadow)
    inner, near = ~shadow[1:-1, 1:-1], shadow[:-2, 1:-1] | shadow[2:, 1:-1] | shadow[1:-1, :-2] | shadow[1:-1, 2:]
    rim[1:-1, 1:-1] = inner & near
    assert rim.sum() > 8 and detail[rim].mean() > 0.9
    assert detail.mean() < 0.5


@pytest.mark.parametrize(("value", "message"), [(0, "detail_samples must be an integer in [1, 64], got 0"),
                                                (65, "detail_samples must be an integer in [1, 64]"),
                                                (1.5, "must be an integer")])
def test_bad_detail_samples_are_named(value, message):
    with pytest.raises(ValueError, match=re.escape(message)):
        wv.render(FLAT, spp=1, detail_samples=value)


def test_spp_times_detail_samples_must_fit_the_sample_index():
    with pytest.raises(ValueError, match="spp x detail_samples"):
        wv.render(FLAT, spp=2**30, edge_samples=1, detail_samples=4)


def test_a_resumed_render_keeps_its_images_detail_samples_and_refuses_another(tmp_path):
    first = wv.render(FLAT, spp=1, seed=3, detail_samples=3, progress=None)
    first.save(tmp_path / "a.exr")
    more = wv.render(FLAT, spp=3, seed=3, resume=tmp_path / "a.exr", progress=None)
    direct = wv.render(FLAT, spp=3, seed=3, detail_samples=3, aovs=[], progress=None)
    assert more.metadata["detail_samples"] == 3
    np.testing.assert_array_equal(more.aovs["samples"], direct.aovs["samples"])
    np.testing.assert_allclose(more.rgb, direct.rgb, rtol=1e-6, atol=1e-7)
    with pytest.raises(ValueError, match="detail_samples = 3; this render has detail_samples = 2"):
        wv.render(FLAT, spp=3, seed=3, resume=tmp_path / "a.exr", detail_samples=2, progress=None)


def test_an_image_from_before_detail_samples_resumes_as_one_without():
    """An image written before the option existed has no detail_samples in its header: it was rendered
    without detail pixels, and resumes so."""
    img = wv.render(FLAT, spp=1, seed=3, progress=None, aovs=[])
    settings = dict(img.metadata["resume"]["settings"])
    assert settings.pop("detail_samples") == 1
    record = {**img.metadata["resume"], "settings": settings}
    old = dataclasses.replace(img, metadata={**img.metadata, "resume": record})
    more = wv.render(FLAT, spp=2, seed=3, resume=old, progress=None)
    direct = wv.render(FLAT, spp=2, seed=3, aovs=[], progress=None)
    assert more.metadata["detail_samples"] == 1
    np.testing.assert_allclose(more.rgb, direct.rgb, rtol=1e-6, atol=1e-7)
    with pytest.raises(ValueError, match="detail_samples = 1; this render has detail_samples = 3"):
        wv.render(FLAT, spp=2, seed=3, resume=old, detail_samples=3, progress=None)


@pytest.mark.skipif(importlib.util.find_spec("pyoidn") is None,
                    reason="pyoidn (Intel Open Image Denoise) is not installed: pip install 'warpviz[denoise]'")
def test_a_denoised_render_gives_the_detail_pixels_more_samples():
    assert (DETAIL_SAMPLES, DETAIL_SAMPLES_DENOISED) == (1, 8)
    den = wv.render(FLAT, spp=1, seed=3, denoise=True, progress=None)
    assert den.metadata["detail_samples"] == 8 and den.stats["detail_pixels"] > 0
    assert np.sum(den.aovs["samples"] == 8) == den.stats["detail_pixels"]
    plain = wv.render(FLAT, spp=1, seed=3, progress=None)
    assert plain.metadata["detail_samples"] == 1 and plain.stats["detail_pixels"] == 0
    assert wv.render(FLAT, spp=1, seed=3, denoise=True, detail_samples=2, progress=None).metadata["detail_samples"] == 2
