"""More samples on the edges of lights, seen directly or in mirrors and glass (``render(edge_samples=)``,
integrators/render_loop.h).

The edge pixels are chosen by probe rays before any sample is drawn, so a pixel's sample count does not
depend on what its samples find. The tests check the two facts that make the estimate unbiased and
deterministic: an edge pixel is exactly the pixel of a render at ``spp x edge_samples`` and every other pixel
exactly that of the plain render (bit for bit), for any window and thread count; and that the probes find
the pixels a lamp's edge crosses.
"""

import importlib.util
import re
from pathlib import Path

import numpy as np
import pytest

import warpviz as wv
from warpviz.options import EDGE_SAMPLES, EDGE_SAMPLES_DENOISED
from native_scenes import metric, room

SCENES = Path(__file__).resolve().parents[1] / "scenes"


def _lit_room(metric_spec, size):
    """The test room with the camera looking up at its ceiling lamp."""
    scene = room(metric_spec, size=size, spheres=False)
    scene["camera"]["look_at"] = [0, 0, 6]
    return scene


CURVED = _lit_room(metric("schwarzschild", 0.4), (20, 15))
FLAT = _lit_room(metric(), (32, 24))


@pytest.mark.parametrize(("scene", "spp", "times"), [(CURVED, 4, 4), (FLAT, 4, 4), (FLAT, 80, 2)],
                         ids=["schwarzschild", "flat", "flat-passes-of-64"])
def test_edge_pixels_are_the_longer_render_and_the_rest_the_plain_one_bit_for_bit(scene, spp, times):
    more = wv.render(scene, spp=spp, seed=5, edge_samples=times)
    plain = wv.render(scene, spp=spp, seed=5, edge_samples=1)
    long = wv.render(scene, spp=spp * times, seed=5, edge_samples=1)
    edge = more.aovs["samples"] == spp * times
    assert 0 < edge.sum() == more.stats["edge_pixels"] < 0.2 * edge.size
    assert np.all(more.aovs["samples"][~edge] == spp)
    extra = spp * (times - 1) * int(edge.sum())
    assert more.stats["samples"] == int(more.aovs["samples"].sum()) == spp * edge.size + extra
    np.testing.assert_array_equal(more.rgb[edge], long.rgb[edge])
    np.testing.assert_array_equal(more.rgb[~edge], plain.rgb[~edge])
    assert plain.stats["edge_pixels"] == 0


def _with_a_sun(scene, strength):
    """The scene with a small emitting ball in view besides its ceiling lamp (strength 12)."""
    scene = {**scene, "materials": scene["materials"] + [{"type": "emissive", "texture": 3, "strength": strength}],
             "shapes": scene["shapes"] + [{"type": "sphere", "center": [-3.0, 0.0, 5.0], "radius": 0.8,
                                           "material": len(scene["materials"])}]}  # fmt: skip
    return scene


def test_the_edges_of_an_emitter_far_brighter_than_the_faintest_get_eight_times_the_edge_samples(tmp_path):
    """A ball at 100x the lamp's radiance: its edge pixels (render_types.h, kBrightEdgePixel) get 8 x edge_samples
    x spp samples, bit for bit those of a render at that many samples; the lamp's edges keep edge_samples x spp,
    the rest spp; every window and thread count agrees on which pixels they are, and a render resumed from its
    file is the render of the total. At 10x the lamp's radiance the ball's edges are ordinary ones."""
    spp, times = 2, 2
    scene = _with_a_sun(CURVED, 1200.0)
    more = wv.render(scene, spp=spp, seed=5, edge_samples=times, threads=1)
    counts = more.aovs["samples"]
    bright, edge = counts == spp * times * 8, counts == spp * times
    assert 0 < bright.sum() == more.stats["bright_edge_pixels"] < more.stats["edge_pixels"]
    assert more.stats["edge_pixels"] == bright.sum() + edge.sum() and np.all(counts[~bright & ~edge] == spp)
    for mask, n in ((bright, spp * times * 8), (edge, spp * times), (~bright & ~edge, spp)):
        np.testing.assert_array_equal(more.rgb[mask], wv.render(scene, spp=n, seed=5, edge_samples=1).rgb[mask])
    tiles = np.zeros_like(more.rgb)
    for x0, y0, w, h in [(0, 0, 7, 15), (7, 0, 13, 8), (7, 8, 13, 7)]:
        tile = wv.render(scene, spp=spp, seed=5, edge_samples=times, threads=2, crop=(x0, y0, w, h))
        tiles[y0:y0 + h, x0:x0 + w] = tile.rgb
        np.testing.assert_array_equal(tile.aovs["samples"], counts[y0:y0 + h, x0:x0 + w])
    np.testing.assert_array_equal(tiles, more.rgb)
    # resumed from its file: the same as one render of the total
    part = wv.render(scene, spp=1, seed=5, edge_samples=times, progress=None).save(tmp_path / "part.exr")
    resumed = wv.render(scene, spp=spp, seed=5, edge_samples=times, resume=part, progress=None)
    np.testing.assert_array_equal(resumed.aovs["samples"], counts)
    np.testing.assert_allclose(resumed.rgb, more.rgb, rtol=1e-6, atol=1e-7)
    dim = wv.render(_with_a_sun(CURVED, 120.0), spp=spp, seed=5, edge_samples=times)
    assert dim.stats["bright_edge_pixels"] == 0 < dim.stats["edge_pixels"]


def test_the_sample_multiples_are_the_renderers_one_rule():
    """resume.sample_multiples is render_types.h's rule through the binding: an edge pixel gets the larger of
    edge_samples and detail_samples, a bright edge pixel 8 x that only where edge_samples is on; and a render's
    pixels hold exactly those multiples of spp."""
    from warpviz.render.resume import sample_multiples

    assert sample_multiples(2, 1) == (1, 2, 1, 16)
    assert sample_multiples(1, 3) == (1, 3, 3, 3)
    assert sample_multiples(4, 6) == (1, 6, 6, 48)
    spp = 2
    img = wv.render(_with_a_sun(CURVED, 1200.0), spp=spp, seed=5, edge_samples=3, threads=2)
    assert set(np.unique(img.aovs["samples"]) // spp) == {1, sample_multiples(3, 1)[1], sample_multiples(3, 1)[3]}


def test_edge_pixels_do_not_depend_on_the_window_or_the_threads():
    whole = wv.render(CURVED, spp=2, seed=1, threads=1)
    tiles = np.zeros_like(whole.rgb)
    counts = np.zeros_like(whole.aovs["samples"])
    for x0, y0, w, h in [(0, 0, 7, 15), (7, 0, 13, 8), (7, 8, 13, 7)]:
        tile = wv.render(CURVED, spp=2, seed=1, threads=2, crop=(x0, y0, w, h))
        tiles[y0:y0 + h, x0:x0 + w] = tile.rgb
        counts[y0:y0 + h, x0:x0 + w] = tile.aovs["samples"]
    np.testing.assert_array_equal(tiles, whole.rgb)
    np.testing.assert_array_equal(counts, whole.aovs["samples"])


def test_the_probes_find_the_pixels_the_lamps_edge_crosses():
    """In the flat room the camera sees the ceiling lamp with straight edges: a pixel it covers by a
    quarter to three quarters always has probes on both sides of the edge (a half-plane cut that misses
    all nine probes of a pixel holds at most ~1/8 of it), and a pixel it covers fully or not at all none."""
    edges = wv.render(FLAT, spp=1, max_depth=1).aovs["samples"] > 1
    cover = wv.render(FLAT, spp=1024, seed=3, max_depth=1, edge_samples=1).rgb[..., 0] / 12.0
    half = (cover > 0.25) & (cover < 0.75)
    assert half.sum() >= 4 and np.all(edges[half])
    assert not np.any(edges[(cover == 0.0) | (cover == 1.0)])
    assert edges.sum() >= 8


def _glass_ball_under_a_lamp() -> dict:
    """A glass ball under a square lamp, the camera looking at the ball from the side: the lamp is out of
    view, seen only reflected in the ball and through it."""
    return {"metric": metric(),
            "camera": {"position": [0, -8, 1], "look_at": [0, 0, 0], "up": [0, 0, 1], "fov": 40, "width": 48,
                       "height": 36},
            "textures": [{"type": "constant", "color": [1, 1, 1]}],
            "materials": [{"type": "emissive", "texture": 0, "strength": 10.0}, {"type": "glass", "ior": 1.5}],
            "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 2.0, "material": 1},
                       {"type": "quad", "corner": [-3, -3, 4], "edge_u": [0, 6, 0], "edge_v": [6, 0, 0], "material": 0}],
            "environment": {"color": [0, 0, 0]}}  # fmt: skip


def test_the_probes_follow_mirrors_and_glass():
    """A lamp seen only in a glass ball: the pixels whose samples see it part of the time (its image's edge
    crosses them, or each sample's Fresnel choice reflects or refracts it) get the edge samples. Such a
    pixel's emission differs between two renders of independent seeds; every pixel where it differs by
    more than 2 % of the lamp's radiance (256 spp each) is an edge pixel. The probes of directly seen
    lights alone found none here."""
    scene = _glass_ball_under_a_lamp()
    assert wv.render(scene, spp=4, max_depth=1).rgb.max() == 0.0  # the lamp is out of view
    edges = wv.render(scene, spp=1, max_depth=8).aovs["samples"] > 1
    a, b = (wv.render(scene, spp=256, seed=s, max_depth=8, edge_samples=1, aovs=["emission"]).aovs["emission"][..., 0]
            for s in (3, 4))  # fmt: skip
    noisy = np.abs(a - b) / 10.0 > 0.02
    assert noisy.sum() >= 20 and np.all(edges[noisy])
    assert edges.sum() < 0.15 * edges.size


def test_a_scene_without_emitters_gets_no_edge_samples():
    materials = [{"type": "diffuse", "texture": 3} if m["type"] == "emissive" else m for m in FLAT["materials"]]
    scene = dict(FLAT, materials=materials, environment={"color": [1, 1, 1]})
    img = wv.render(scene, spp=2)
    assert img.stats["edge_pixels"] == 0 and np.all(img.aovs["samples"] == 2)


@pytest.mark.parametrize(("value", "message"), [(0, "edge_samples must be an integer in [1, 64], got 0"),
                                                (65, "edge_samples must be an integer in [1, 64]"),
                                                (2.0, "must be an integer"), (True, "must be an integer")])
def test_bad_edge_samples_are_named(value, message):
    with pytest.raises(ValueError, match=re.escape(message)):
        wv.render(FLAT, spp=1, edge_samples=value)


def test_spp_times_edge_samples_must_fit_the_sample_index():
    with pytest.raises(ValueError, match="spp x edge_samples"):
        wv.render(FLAT, spp=2**30, edge_samples=4)


@pytest.mark.skipif(importlib.util.find_spec("pyoidn") is None,
                    reason="pyoidn (Intel Open Image Denoise) is not installed: pip install 'warpviz[denoise]'")
def test_a_denoised_render_gives_the_edges_more_samples_and_a_resumed_one_keeps_its_images(tmp_path):
    # The denoiser cleans all but the emission it keeps out, so a denoised render's default is x32 (x8 not
    # denoised); a call's or a scene's value wins; resuming an image (denoised or not) keeps the image's.
    assert (EDGE_SAMPLES, EDGE_SAMPLES_DENOISED) == (8, 32)
    den = wv.render(FLAT, spp=1, seed=3, denoise=True, progress=None)
    edge = den.aovs["samples"] > den.metadata["detail_samples"]  # (the detail pixels get their own multiple)
    assert den.metadata["edge_samples"] == 32 and edge.sum() == den.stats["edge_pixels"] > 0
    assert np.all(den.aovs["samples"][edge] == 32)
    assert wv.render(FLAT, spp=1, seed=3, progress=None).metadata["edge_samples"] == 8
    assert wv.render(FLAT, spp=1, seed=3, denoise=True, edge_samples=4, progress=None).metadata["edge_samples"] == 4
    den.save(tmp_path / "den.exr")
    more = wv.render(FLAT, spp=2, seed=3, resume=tmp_path / "den.exr", progress=None)  # not denoised: still x32
    kept = [a for a in den.aovs if a not in ("errors", "samples", "variance")]
    direct = wv.render(FLAT, spp=2, seed=3, edge_samples=32, detail_samples=8, aovs=kept, progress=None)
    assert more.metadata["edge_samples"] == 32
    np.testing.assert_allclose(more.rgb, direct.rgb, rtol=1e-6, atol=1e-7)


def _lamp_behind_a_hole(metric_spec) -> dict:
    """A small bright ball behind a hole (Schwarzschild M = 0.1 or an Ellis throat b0 = 0.4), a little off the axis:
    seen from the front its light comes round both sides of the hole in thin arcs, narrower than the probes'
    lattice (the direct image 1.7 pixels across, the one round the far side a sliver below the shadow)."""
    return {"metric": metric_spec,
            "camera": {"position": [0, -20, 0], "look_at": [0, 0, 0], "up": [0, 0, 1], "fov": 30, "width": 40,
                       "height": 30},
            "textures": [{"type": "constant", "color": [1, 1, 1]}],
            "materials": [{"type": "emissive", "texture": 0, "strength": 100.0}],
            "shapes": [{"type": "sphere", "center": [0.0, 20.0, 1.0], "radius": 0.6, "material": 0}],
            "environment": {"color": [0, 0, 0]}}  # fmt: skip


def _assert_edges_hold_the_lamp(edges, cover):
    """Every pixel that sees the lamp over 2 % to 98 % of its area (cover: the fraction, per pixel) is an edge pixel,
    and none farther than two pixels from where it is seen at all."""
    partial = (cover > 0.02) & (cover < 0.98)
    assert partial.sum() >= 10 and np.all(edges[partial])
    lit = cover > 0.0
    near = lit.copy()
    for dy in range(-2, 3):
        for dx in range(-2, 3):
            near |= np.roll(np.roll(lit, dy, axis=0), dx, axis=1)
    assert not np.any(edges & ~near)


@pytest.mark.parametrize("metric_spec", [metric("schwarzschild", 0.1), metric("ellis", 0.4)],
                         ids=["schwarzschild", "ellis"])
def test_the_lens_map_finds_a_lamps_thin_lensed_arcs(metric_spec):
    """In a static spherical metric the lamp's images are also found through the exact lens map from the camera
    (path_tracer.h, light_image_marks): a pixel that a thin arc of the lamp crosses, which none of its nine probes
    sees, is an edge pixel. Every pixel that sees the lamp over 2 % to 98 % of its area (a 4096-sample
    camera-segment render) gets the edge samples; none farther than two pixels from where that render saw the lamp
    does (an arc's tips thin out below a 4096th of a pixel)."""
    scene = _lamp_behind_a_hole(metric_spec)
    edges = wv.render(scene, spp=1, max_depth=1).aovs["samples"] > 1
    cover = wv.render(scene, spp=4096, seed=3, max_depth=1, edge_samples=1).rgb[..., 0] / 100.0
    _assert_edges_hold_the_lamp(edges, cover)


def test_the_shadow_rim_probes_find_a_lamps_thin_arcs_in_kerr():
    """Kerr has no exact lens map, so the lamp's thin images round the hole are found by the probes alone: a pixel on
    the shadow's edge (some of its nine lattice probes fall in, some do not) that none of them sees a light in gets
    8 x 8 probes more (render_loop.h, pixel_classes), and so is an edge pixel where any of them sees the lamp.
    The ball behind the hole (M = 0.1, a = 0.9 M): every pixel that sees it over 2 % to 98 % of its area (a
    4096-sample camera-segment render of the middle 16 x 20 pixels, which hold all of its images) gets the edge
    samples, and none farther than two pixels from where that render saw it does."""
    scene = _lamp_behind_a_hole(metric("kerr", 0.1, 0.9))
    edges = wv.render(scene, spp=1, max_depth=1).aovs["samples"] > 1
    cover = np.zeros(edges.shape)  # (the sky is black: the lamp is seen only round the hole)
    cover[4:24, 12:28] = wv.render(scene, spp=4096, seed=3, max_depth=1, edge_samples=1,
                                   crop=(12, 4, 16, 20)).rgb[..., 0] / 100.0
    assert cover[4:24, 12:28][[0, -1]].max() == 0.0 and cover[4:24, 12:28][:, [0, -1]].max() == 0.0
    _assert_edges_hold_the_lamp(edges, cover)


def test_the_shadow_rim_probes_find_the_lamps_arcs_in_the_kerr_room():
    """fig10d at 48 x 36 (a = 0.9 M): the ceiling lamp's images round the hole (order 1 below the shadow, order 2
    above it) cross pixels none of whose nine lattice probes sees them; before the rim's probes three of them,
    seeing the lamp over 1.8 %, 2.3 % and 18 % of their area, got no edge samples (the one of 18 % held 7 % of the
    room's error at 16 spp). Every pixel round the hole that sees the lamp over 1.5 % to 98 % of its area (a
    2048-sample camera-segment render, the lamp's radiance 15) is now an edge pixel."""
    scene = wv.load_scene(SCENES / "fig10d_kerr_cornell_a09.toml")
    edges = wv.render(scene, spp=1, width=48, height=36, max_depth=1).aovs["samples"][10:26, 18:32] > 1
    cover = wv.render(scene, spp=2048, seed=3, width=48, height=36, max_depth=1, edge_samples=1,
                      crop=(18, 10, 14, 16)).rgb[..., 0] / 15.0
    partial = (cover > 0.015) & (cover < 0.98)
    assert partial.sum() >= 5 and np.all(edges[partial])
