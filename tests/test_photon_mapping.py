"""Caustics by photons (renderer_ext/integrators/photon_tracer.h, photon_map.h): photon passes from the lights
through mirrors and glass, gathered at a camera path's first diffuse vertex, in place of the path tracer's
caustic paths. The image converges to the path tracer's (the statistical test, with the bias falling as the
radius shrinks), in flat space and in Schwarzschild (where the photons' flux takes the proper areas and the
frequency shift between the lamp and the floor), and a pass depends only on (seed, sample index)."""

from __future__ import annotations

import numpy as np
import pytest

import warpviz as wv
from native_scenes import lamp_over_hole, metric
from test_render import _image_means, assert_same_mean


def mirror_lamp(metric_spec=None, *, size=(16, 12), shift=(0.0, 0.0, 0.0)) -> dict:
    """A lamp that shines only upwards (one-sided), into a mirror that sends its light down onto a floor: all
    the floor's light is a caustic (light -> mirror -> diffuse). Black sky, nothing else."""
    sx, sy, sz = shift
    return {
        "metric": metric_spec or metric(),
        "camera": {"position": [sx, sy - 3.2, sz + 1.4], "look_at": [sx, sy, sz], "up": [0, 0, 1], "fov": 60,
                   "width": size[0], "height": size[1]},
        "textures": [{"type": "constant", "color": [0.8, 0.8, 0.8]}, {"type": "constant", "color": [1, 1, 1]}],
        "materials": [
            {"type": "diffuse", "texture": 0},
            {"type": "mirror", "reflectance": [0.9, 0.9, 0.9]},
            {"type": "emissive", "texture": 1, "strength": 6.0},
        ],
        "shapes": [
            {"type": "quad", "corner": [sx - 2, sy - 2, sz], "edge_u": [4, 0, 0], "edge_v": [0, 4, 0], "material": 0},
            {"type": "quad", "corner": [sx - 1.5, sy - 1.5, sz + 2], "edge_u": [0, 3, 0], "edge_v": [3, 0, 0],
             "material": 1},
            {"type": "quad", "corner": [sx - 0.4, sy - 0.4, sz + 1], "edge_u": [0.8, 0, 0], "edge_v": [0, 0.8, 0],
             "material": 2},
        ],
        "environment": {"color": [0, 0, 0]},
    }


def glass_ball(metric_spec=None, *, size=(16, 12)) -> dict:
    """A lamp above and behind a glass ball over a floor: the ball (focal length 0.75 from its centre) focuses
    the lamp into a bright spot on the floor in front of it, near (0, -0.6, 0)."""
    sc = mirror_lamp(metric_spec, size=size)
    sc["materials"][1] = {"type": "glass", "ior": 1.5, "tint": [1, 1, 1]}
    sc["shapes"][1] = {"type": "sphere", "center": [0, 0, 0.9], "radius": 0.5, "material": 1}
    sc["shapes"][2] = {"type": "quad", "corner": [-0.3, 1.3, 2.4], "edge_u": [0.6, 0, 0], "edge_v": [0, -0.6, 0],
                       "material": 2}
    return sc


def test_a_caustic_off_a_mirror_converges_to_the_path_tracers():
    sc = mirror_lamp()
    one = wv.render(sc, spp=2, seed=0, max_depth=4, photons=2000)
    assert one.stats["photon_passes"] == 2 and one.stats["photons_stored"] > 1000
    assert 0 < one.stats["photon_segments"] < one.stats["segments"]
    plain = wv.render(sc, spp=2, seed=0, max_depth=4)
    assert not np.array_equal(one.rgb, plain.rgb)
    # (photon_radius 0.5: a thumbnail's pixel is a fifth of the floor, and the gather disk leaks light off its
    # edges, a bias that shrinks with the radius: -3 % at 2 pixels and 64 samples, -1.3 % at half a pixel)
    photons = _image_means(sc, range(6), spp=16, max_depth=4, photons=4000, photon_radius=0.5)
    traced = _image_means(sc, range(6, 12), spp=64, max_depth=4)
    assert photons.mean() > 0.01
    assert_same_mean(photons, traced, slack=0.02 * traced.mean())
    assert photons.var() < traced.var()  # and far less noise for fewer samples


def test_a_glass_ball_s_caustic_converges_to_the_path_tracers():
    sc = glass_ball()
    photons = _image_means(sc, range(6), spp=16, max_depth=6, photons=4000, photon_radius=1.0)
    traced = _image_means(sc, range(6, 12), spp=64, max_depth=6)
    assert_same_mean(photons, traced, slack=0.02 * traced.mean())


def test_the_bias_falls_as_the_radius_shrinks():
    # A first radius of 8 pixels blurs the ball's focus (row 13, columns 15-16: 10-50x the floor's brightness)
    # over its neighbours and beyond; the passes' radii shrink, and the light round the focus gathers back
    # towards the path tracer's.
    sc = glass_ball(size=(32, 24))
    window = np.s_[12:16, 12:20]
    # (the path tracer finds the focus by a few rare paths: one 256-spp frame of it ranged over -13 % to +11 % of
    # the mean of 8 seeds; the mean of four has half that spread)
    traced = np.mean([wv.render(sc, spp=256, seed=s, max_depth=6).rgb.mean(axis=2)[window].sum() for s in range(1, 5)])
    one = wv.render(sc, spp=1, seed=1, max_depth=6, photons=20000, photon_radius=8.0).rgb.mean(axis=2)
    many = wv.render(sc, spp=64, seed=1, max_depth=6, photons=20000, photon_radius=8.0).rgb.mean(axis=2)
    assert one[window].sum() < 0.6 * traced  # (the first pass spreads it out of the window)
    assert abs(many[window].sum() - traced) < 0.3 * abs(one[window].sum() - traced)
    assert many[13, 15] > 3 * one[13, 15]


def test_in_schwarzschild_the_photons_flux_takes_proper_areas_and_the_shift():
    # The floor 0.9 above a hole of M = 0.2 (capture radius 0.6), the lamp at 1.9, the mirror at 2.9: the
    # lamp's light reaches the floor's middle blueshifted (g = 1.19, so g^-2 = 0.7 on its flux), areas off
    # the radial direction are stretched, and the hole focuses: the image is 1.6x the flat one's. The photon
    # estimate agrees with the path tracer's only with all of it accounted.
    sc = mirror_lamp(metric("schwarzschild", 0.2), shift=(0.0, 0.0, 0.9))
    photons = _image_means(sc, range(6), spp=16, max_depth=4, photons=3000, photon_radius=0.5)
    traced = _image_means(sc, range(6, 12), spp=128, max_depth=4)
    flat = _image_means(mirror_lamp(shift=(0.0, 0.0, 0.9)), range(2), spp=16, max_depth=4, photons=3000,
                        photon_radius=0.5)  # fmt: skip
    assert photons.mean() > 1.4 * flat.mean()
    assert_same_mean(photons, traced, slack=0.02 * traced.mean())


def _half_means(scene, seeds, **kw):
    """Per seed, the left and right halves' means of the image: (len(seeds), 2)."""
    out = []
    for s in seeds:
        img = wv.render(scene, seed=s, **kw).rgb.mean(axis=2)
        w = img.shape[1] // 2
        out.append((img[:, :w].mean(), img[:, w:].mean()))
    return np.array(out)


def test_in_kerr_photons_go_forward_in_time_and_frame_dragging_turns_them_the_right_way():
    # Kerr (M = 0.25) under the floor, the lamp off the axis: frame dragging turns the mirror's light round the
    # axis, so the image's right half is 9 % brighter at a = +0.9 than at a = -0.9. Photons traced as backward
    # segments (as in a static metric) would be turned the other way; traced forward in time they agree with
    # the path tracer (whose camera rays are backward) in both halves, at both spins.
    right = {}
    for a in (0.9, -0.9):
        sc = mirror_lamp(metric("kerr", 0.25, a), shift=(0.0, 0.0, 0.8))
        sc["shapes"][2]["corner"] = [0.3, -0.4, 1.8]
        traced = _half_means(sc, range(6), spp=128, max_depth=4)
        photons = _half_means(sc, range(6, 12), spp=16, max_depth=4, photons=3000, photon_radius=0.5)
        for k in (0, 1):
            assert_same_mean(photons[:, k], traced[:, k], slack=0.03 * traced[:, k].mean())
        right[a] = traced[:, 1].mean()
    assert right[0.9] > 1.05 * right[-0.9]


def test_through_an_ellis_wormhole_s_chart_too():
    # The floor 0.9 from the centre of a throat of radius 0.5 (its chart is not the user frame: the proper areas
    # go through the chart's Jacobian); the throat bends the mirror's light 10 % brighter onto the floor.
    sc = mirror_lamp(metric("ellis", 0.5), shift=(0.0, 0.0, 0.9))
    photons = _image_means(sc, range(6), spp=16, max_depth=4, photons=3000, photon_radius=0.5)
    traced = _image_means(sc, range(6, 12), spp=128, max_depth=4)
    assert_same_mean(photons, traced, slack=0.02 * traced.mean())


def test_a_photon_render_is_the_same_on_any_number_of_threads_and_resumed():
    sc = glass_ball()
    a = wv.render(sc, spp=4, seed=3, threads=1, max_depth=6, photons=1000)
    b = wv.render(sc, spp=4, seed=3, threads=2, max_depth=6, photons=1000)
    np.testing.assert_array_equal(a.rgb, b.rgb)
    half = wv.render(sc, spp=2, seed=3, threads=2, max_depth=6, photons=1000)
    resumed = wv.render(sc, spp=4, seed=3, threads=2, max_depth=6, photons=1000, resume=half)
    np.testing.assert_allclose(resumed.rgb, a.rgb, rtol=1e-6, atol=1e-7)
    with pytest.raises(ValueError, match="photons"):
        wv.render(sc, spp=4, seed=3, max_depth=6, photons=2000, resume=half)  # other photons: another render


def test_a_photon_render_with_a_time_budget_is_a_render_of_the_samples_it_reached():
    sc = glass_ball()
    budget = wv.render(sc, time_limit=0.5, seed=6, max_depth=6, photons=1000)
    spp = int(budget.metadata["spp"])
    assert spp >= 1 and budget.stats["photon_passes"] == spp
    np.testing.assert_array_equal(budget.rgb, wv.render(sc, spp=spp, seed=6, max_depth=6, photons=1000).rgb)


def test_windows_tile_a_photon_render_exactly():
    sc = glass_ball()
    whole = wv.render(sc, spp=2, seed=4, max_depth=6, photons=1000, edge_samples=4, detail_samples=2)
    left = wv.render(sc, spp=2, seed=4, max_depth=6, photons=1000, edge_samples=4, detail_samples=2,
                     crop=(0, 0, 8, 12))
    np.testing.assert_array_equal(whole.rgb[:, :8], left.rgb)


def test_photons_off_is_the_render_before_bit_for_bit():
    sc = glass_ball()
    a = wv.render(sc, spp=2, seed=5, max_depth=6)
    b = wv.render(sc, spp=2, seed=5, max_depth=6, photons=0)
    np.testing.assert_array_equal(a.rgb, b.rgb)
    assert a.stats["photon_segments"] == 0 and a.stats["photon_passes"] == 0


def test_bad_photon_options_are_refused_naming_them():
    with pytest.raises(ValueError, match="photons"):
        wv.render(glass_ball(), spp=1, photons=-1)
    with pytest.raises(ValueError, match="photon_radius"):
        wv.render(glass_ball(), spp=1, photons=10, photon_radius=0.0)


def test_photons_per_pixel_add_the_whole_image_s_count_in_every_window_and_resume_keeps_them():
    """photons_per_pixel adds round(density x width x height) photons to each pass (the same render as that
    count), a window of the image traces the whole image's pass (its pixels are the whole render's), a scene's
    [render] may set it, and a resumed render must keep it."""
    sc = glass_ball()  # 16 x 12: 0.75 per pixel is 144 photons
    per_pixel = wv.render(sc, spp=2, seed=7, max_depth=6, photons=100, photons_per_pixel=0.75)
    assert per_pixel.stats["photon_passes"] == 2 and per_pixel.stats["photons_stored"] > 0
    np.testing.assert_array_equal(per_pixel.rgb, wv.render(sc, spp=2, seed=7, max_depth=6, photons=244).rgb)
    window = wv.render(sc, spp=2, seed=7, max_depth=6, photons=100, photons_per_pixel=0.75, crop=(8, 0, 8, 12))
    np.testing.assert_array_equal(window.rgb, per_pixel.rgb[:, 8:])
    with pytest.raises(ValueError, match="photons_per_pixel"):
        wv.render(sc, spp=4, seed=7, max_depth=6, photons=100, photons_per_pixel=0.5, resume=per_pixel)
    with pytest.raises(ValueError, match="photons_per_pixel"):
        wv.render(sc, spp=1, photons_per_pixel=-0.5)


def test_a_metric_from_its_line_element_traces_its_photons_forward_in_time():
    """A line element (Schwarzschild in Kerr-Schild form, compiled as a plugin) is not declared static, so its
    photons are integrated forward in time, as Kerr's: the same scene as the Schwarzschild test above (the
    blueshifted, focused caustic under a hole of M = 0.2), photons against the path tracer in that metric."""
    from warpviz.spacetime.line_element.plugin import CompilerNotFoundError

    from conftest import expression_metric

    try:
        m = expression_metric("ks_schwarzschild")
    except CompilerNotFoundError as exc:  # pragma: no cover - every machine that built warpviz has one
        pytest.skip(f"no C++ compiler: {exc}")
    sc = mirror_lamp({"name": m.name, "params": [0.2]}, shift=(0.0, 0.0, 0.9))
    photons = _image_means(sc, range(6), spp=16, max_depth=4, photons=3000, photon_radius=0.5)
    traced = _image_means(sc, range(6, 12), spp=128, max_depth=4)
    assert photons.mean() > 0.01
    assert_same_mean(photons, traced, slack=0.02 * traced.mean())


@pytest.mark.parametrize("spec, connection",
                         [(metric("schwarzschild", 1.0), "aimed"), (metric("kerr", 1.0, 0.9), "lens")],
                         ids=["schwarzschild-aimed", "kerr"])
def test_light_the_hole_turns_back_is_the_photons_and_converges_to_the_path_tracers(spec, connection):
    # Direct light only (max_depth 2): the ceiling's light is the lamp's, turned back by the hole. Round Kerr (and
    # with the aimed connection anywhere) the path tracer finds it by BSDF samples alone (fireflies); with
    # retro_photons the photons carry it (traced backward in a static metric, integrated forward in time in Kerr)
    # and the path tracer leaves it out in both strategies: the same mean, without those full-weight samples (a
    # pass's photons are shared by the whole image, so the image means' spread is not the pixels' noise).
    sc = lamp_over_hole(spec)
    kw = {"max_depth": 2, "photons": 3000, "light_connection": connection}
    on = [wv.render(sc, spp=16, seed=s, **kw).stats for s in range(5)]
    off = [wv.render(sc, spp=16, seed=s, retro_photons=False, **kw).stats for s in range(5)]
    assert min(st["photons_stored"] for st in on) > 100 and max(st["photons_stored"] for st in off) == 0
    unsampled_on, unsampled_off = (sum(st["unsampled_light_hits"] for st in sts) for sts in (on, off))
    assert unsampled_off >= 10 and unsampled_on <= 0.3 * unsampled_off  # (Kerr: 4 of 16, turned by under 120 deg)
    lamp = _image_means(sc, range(4), spp=16, max_depth=1)  # the lamp seen directly
    photons = _image_means(sc, range(6), spp=16, **kw)
    traced = _image_means(sc, range(6, 14), spp=64, max_depth=2, light_connection=connection)
    assert photons.mean() - lamp.mean() > 0.1 * (traced.mean() - lamp.mean()) > 0.0
    assert_same_mean(photons, traced, slack=0.02 * traced.mean())


def test_retro_photons_change_nothing_in_flat_space_nor_where_the_lens_map_is_exact():
    # A straight segment never turns: in flat space the option changes no bit. Round Schwarzschild the light
    # connection's exact lens map draws the turned-back light itself (with less noise than a gather), so there
    # the path tracer keeps it and no photon carries it: with either connection that uses the map ("lens", and
    # "images", which differs from it only round Kerr).
    for spec, connection in ((metric(), "lens"), (metric("schwarzschild", 1.0), "lens"),
                             (metric("schwarzschild", 1.0), "images")):
        sc = lamp_over_hole(spec, size=(12, 9))
        kw = {"spp": 4, "seed": 3, "max_depth": 3, "photons": 500, "light_connection": connection}
        a = wv.render(sc, **kw)
        b = wv.render(sc, retro_photons=False, **kw)
        np.testing.assert_array_equal(a.rgb, b.rgb)
        assert a.stats["photons_stored"] == 0
    aimed = wv.render(sc, spp=4, seed=3, max_depth=3, photons=500, light_connection="aimed")
    assert aimed.stats["photons_stored"] > 0


def test_aimed_photons_are_mostly_stored_and_converge_to_the_path_tracers():
    """photon_aim (photon_aim.h): the lamp's projection map sends four in five photons towards the glass ball, the
    rest by the cosine; nearly all that leave within the marks are stored, so a pass stores several times as many,
    and their flux, divided by the density ratio, converges to the path tracer's caustic with a quarter of the
    photons the unaimed test above takes."""
    sc = glass_ball()
    kw = dict(spp=4, max_depth=6, photons=1000, photon_radius=1.0)
    aimed = wv.render(sc, seed=1, **kw)
    plain = wv.render(sc, seed=1, photon_aim=False, **kw)
    assert aimed.stats["photons_stored"] > 4 * plain.stats["photons_stored"] > 0
    assert not np.array_equal(aimed.rgb, plain.rgb)
    # The marks are learnt once per render (its first range) and handed to the later passes (1, 1, 2 samples): a
    # four-pass render traces them once, so its photon segments are well under four times a one-pass render's.
    one = wv.render(sc, seed=1, **{**kw, "spp": 1})
    assert aimed.stats["photon_passes"] == 4 and aimed.stats["photon_segments"] < 3 * one.stats["photon_segments"]
    photons = _image_means(sc, range(6), **{**kw, "spp": 16})
    traced = _image_means(sc, range(6, 12), spp=64, max_depth=6)
    assert_same_mean(photons, traced, slack=0.02 * traced.mean())


def test_photon_aim_off_is_the_unaimed_render_and_bad_marks_are_refused():
    sc = glass_ball()
    off = wv.render(sc, spp=2, seed=5, max_depth=6, photons=500, photon_aim=False)
    on = wv.render(sc, spp=2, seed=5, max_depth=6, photons=500)
    assert off.stats["photon_segments"] < on.stats["photon_segments"]  # (the marks' rays)
    with pytest.raises(ValueError, match="photon_aim"):
        wv.render(sc, spp=1, photons=10, photon_aim="yes")
    # The marks a render hands its later ranges (the core's "photon_aim") are checked where they come back in.
    from warpviz._native import core
    from warpviz.options import DEFAULT_OPTIONS, DETAIL_SAMPLES, EDGE_SAMPLES
    from warpviz.scene.native import native_scene

    options = {**DEFAULT_OPTIONS, "filter_radius": 0.5, "max_drift": 1e-4, "edge_samples": EDGE_SAMPLES,
               "detail_samples": DETAIL_SAMPLES, "sample_begin": 0, "threads": 1, "aovs": [], "crop": None,
               "spp": 1, "photons": 200, "max_depth": 6}  # fmt: skip
    sc = native_scene(sc)
    raw = core.render(sc, options)
    marks = raw["photon_aim"]
    assert marks["offsets"].dtype == np.int64 and marks["cells"].dtype == np.uint16 and len(marks["cells"]) > 0
    again = core.render(sc, {**options, "photon_aim_marks": marks})
    np.testing.assert_array_equal(again["film"]["rgb_sum"], raw["film"]["rgb_sum"])
    assert again["stats"]["photon_segments"] < raw["stats"]["photon_segments"]  # (not learnt again)
    bad = {"offsets": marks["offsets"][:-1], "cells": marks["cells"]}
    with pytest.raises(ValueError, match="photon_aim_marks"):
        core.render(sc, {**options, "photon_aim_marks": bad})
    with pytest.raises(ValueError, match="photon_aim_marks"):
        core.render(sc, {**options, "photon_aim_marks": {"offsets": marks["offsets"], "cells": marks["cells"][::-1]
                                                          .copy()}})  # fmt: skip


def test_a_lamp_of_many_pieces_marks_only_its_most_powerful_ones():
    """The marks cost ~1,000 rays a part of a light; a lamp of 100 quads (an emissive mesh is one light a triangle)
    gets them for its most powerful pieces, 64 parts in all (photon_aim.h: kMaxParts), the rest unaimed."""
    sc = glass_ball()
    lamp = sc["shapes"].pop(2)
    for i in range(10):
        for j in range(10):
            sc["shapes"].append({**lamp, "corner": [-0.3 + 0.06 * i, 1.3 - 0.06 * j, 2.4], "edge_u": [0.06, 0, 0],
                                 "edge_v": [0, -0.06, 0]})  # fmt: skip
    aimed = wv.render(sc, spp=1, seed=1, max_depth=6, photons=200)
    plain = wv.render(sc, spp=1, seed=1, max_depth=6, photons=200, photon_aim=False)
    assert aimed.stats["photons_stored"] > plain.stats["photons_stored"]
    assert aimed.stats["photon_segments"] < 64 * 1024  # (all 400 parts: over 100,000 rays)
