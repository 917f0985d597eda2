"""Path guiding's learned distribution (renderer_ext/integrators/guide_tree.h): a tree over space whose leaves
hold quadtrees over the local sky, built from training records. Its density integrates to one, its samples
follow it, it puts its mass where the records saw light, and the same records give the same tree."""

from __future__ import annotations

import numpy as np
import pytest

from warpviz._native import testing

LO, HI = [-1.0, -1.0, -1.0], [1.0, 1.0, 1.0]


def _sky(s, t):
    """The equal-area map of the tree: square point (s, t) -> unit direction."""
    z = 2.0 * s - 1.0
    r = np.sqrt(np.maximum(0.0, 1.0 - z * z))
    return np.stack([r * np.cos(2 * np.pi * t), r * np.sin(2 * np.pi * t), z], axis=-1)


def _records(rng, n, *, lobe=(0.3, -0.5, 0.8), share=0.7, spread=0.05):
    """Records in the unit box: a bright lobe around `lobe` (a lamp's image) over a dim uniform sky."""
    pos = rng.uniform(-1, 1, (n, 3))
    d = rng.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    bright = rng.uniform(size=n) < share
    axis = np.asarray(lobe) / np.linalg.norm(lobe)
    d[bright] = axis + spread * rng.normal(size=(int(bright.sum()), 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    values = np.where(bright, 10.0, 0.1)
    return pos, d, values, axis


def _tree(pos, d, values, *, sheets=None, leaf_records=500, rho=0.01, max_depth=6, at=(0.1, 0.2, 0.3), at_sheet=1,
          evaluate=None, u=None):
    sheets = [1] * len(values) if sheets is None else list(sheets)
    evaluate = np.zeros((0, 3)) if evaluate is None else evaluate
    u = np.zeros((0, 2)) if u is None else u
    return testing.guide_tree(pos, sheets, d, values, LO, HI, leaf_records, rho, max_depth, list(at), at_sheet,
                              evaluate, u)  # fmt: skip


def test_density_integrates_to_one():
    # The density is constant on square cells of side 2^-max_depth at the finest, so the midpoint rule on
    # that grid integrates it exactly.
    pos, d, values, _ = _records(np.random.default_rng(1), 20_000)
    depth = 6
    g = (np.arange(2**depth) + 0.5) / 2**depth
    s, t = np.meshgrid(g, g, indexing="ij")
    dirs = _sky(s.ravel(), t.ravel())
    out = _tree(pos, d, values, max_depth=depth, evaluate=dirs)
    assert out["leaf"] >= 0 and out["leaves"] > 1 and out["cells"] > 10
    integral = out["pdf_eval"].sum() * 4 * np.pi / len(dirs)
    assert integral == pytest.approx(1.0, abs=1e-12)


def test_samples_follow_the_density():
    rng = np.random.default_rng(2)
    pos, d, values, axis = _records(rng, 20_000)
    u = rng.uniform(size=(100_000, 2))
    depth = 5
    g = (np.arange(2**depth) + 0.5) / 2**depth
    s, t = np.meshgrid(g, g, indexing="ij")
    out = _tree(pos, d, values, max_depth=depth, evaluate=_sky(s.ravel(), t.ravel()), u=u)
    w, p = out["samples"], out["pdf_samples"]
    assert np.allclose(np.linalg.norm(w, axis=1), 1.0)
    # each sample's density is the tree's density in its direction
    again = _tree(pos, d, values, max_depth=depth, evaluate=w)["pdf_eval"]
    np.testing.assert_allclose(p, again, rtol=1e-12)
    # chi-square of the samples' cells on the finest grid against the cells' probabilities
    ss = np.clip(0.5 * (1 + w[:, 2]), 0, 1 - 1e-16)
    tt = (np.arctan2(w[:, 1], w[:, 0]) / (2 * np.pi)) % 1.0
    cells = np.floor(ss * 2**depth).astype(int) * 2**depth + np.floor(tt * 2**depth).astype(int)
    counts = np.bincount(cells, minlength=4**depth)
    expected = out["pdf_eval"] * 4 * np.pi / 4**depth * len(w)
    keep = expected > 5
    assert counts[~keep].sum() < 0.01 * len(w)
    chi2 = (((counts - expected) ** 2)[keep] / expected[keep]).sum()
    dof = int(keep.sum()) - 1
    assert chi2 < dof + 5 * np.sqrt(2 * dof), (chi2, dof)
    # the lamp's lobe holds most of the samples, as it holds most of the records' energy
    assert (w @ axis > np.cos(0.2)).mean() > 0.9


def test_mass_where_the_light_was():
    rng = np.random.default_rng(3)
    pos, d, values, axis = _records(rng, 20_000)
    away = -axis
    out = _tree(pos, d, values, evaluate=np.stack([axis, away]), max_depth=10)
    p_lobe, p_away = out["pdf_eval"]
    assert p_lobe > 50 / (4 * np.pi) and p_lobe > 1000 * p_away
    # records only in the lower half of the box: the upper half's leaves saw nothing
    low = pos[:, 2] < 0
    high_leaf = _tree(pos[low], d[low], values[low], at=(0.0, 0.0, 0.9))["leaf"]
    low_leaf = _tree(pos[low], d[low], values[low], at=(0.0, 0.0, -0.9))["leaf"]
    assert high_leaf == -1 and low_leaf >= 0
    # and one sheet's records say nothing about the other sheet
    assert _tree(pos, d, values, at_sheet=-1)["leaf"] == -1


def test_same_records_same_tree():
    rng = np.random.default_rng(4)
    pos, d, values, _ = _records(rng, 5_000)
    u = rng.uniform(size=(1000, 2))
    a = _tree(pos, d, values, u=u, evaluate=d[:100])
    b = _tree(pos, d, values, u=u, evaluate=d[:100])
    assert a["cells"] == b["cells"] and a["leaves"] == b["leaves"]
    np.testing.assert_array_equal(a["samples"], b["samples"])
    np.testing.assert_array_equal(a["pdf_eval"], b["pdf_eval"])


def test_zero_and_invalid_values_are_ignored():
    rng = np.random.default_rng(5)
    pos, d, values, _ = _records(rng, 2_000)
    assert _tree(pos, d, np.zeros_like(values))["leaf"] == -1
    bad = values.copy()
    bad[::2] = np.nan
    out = _tree(pos, d, bad, evaluate=d[:10])
    assert out["leaf"] >= 0 and np.isfinite(out["pdf_eval"]).all()


# --- guided renders ------------------------------------------------------------------------------------------

import warpviz as wv  # noqa: E402
from native_scenes import metric, room  # noqa: E402
from test_lens_connection import _wormhole_room  # noqa: E402
from test_render import _image_means, assert_same_mean  # noqa: E402


def _lamps_on_both_sheets():
    """The wormhole room with a second lamp on the other sheet, over a floor there: two lights, each of which
    reaches its own sheet easily and the other only through the throat."""
    scene = _wormhole_room(1)
    scene["shapes"].append(dict(scene["shapes"][6], sheet=-1))
    scene["shapes"].append({"type": "quad", "corner": [-12, -12, -12], "edge_u": [24, 0, 0], "edge_v": [0, 24, 0],
                            "material": 0, "sheet": -1})  # fmt: skip
    return scene


@pytest.mark.parametrize("scene", [
    pytest.param(lambda: room(metric("minkowski"), size=(12, 9), light=3.0), id="flat"),
    pytest.param(_lamps_on_both_sheets, id="ellis-two-lamps"),
    pytest.param(lambda: room(metric("schwarzschild", 1.0), size=(12, 9), light=3.0), id="schwarzschild"),
    pytest.param(lambda: room(metric("kerr", 1.0, 0.9), size=(12, 9), light=3.0, spheres=False), id="kerr-0.9"),
    pytest.param(lambda: _wormhole_room(1), id="ellis"),
    pytest.param(lambda: _wormhole_room(-1), id="ellis-light-on-the-other-sheet"),
])  # fmt: skip
def test_guided_renders_keep_the_mean_of_unguided_ones(scene):
    sc = scene()
    one = wv.render(sc, spp=2, seed=0, max_depth=3, guide_training=4)
    assert 0 < one.stats["guide_segments"] < one.stats["segments"]  # it trained (counted with the render's)
    assert not np.array_equal(one.rgb, wv.render(sc, spp=2, seed=0, max_depth=3).rgb)  # and guided something
    guided = _image_means(sc, range(8), spp=8, max_depth=3, guide_training=4)
    plain = _image_means(sc, range(8, 16), spp=8, max_depth=3)
    assert guided.mean() > 0
    assert_same_mean(guided, plain, slack=2e-3 * plain.mean())


def test_guided_renders_are_the_same_on_any_number_of_threads_and_resumed():
    sc = room(metric("schwarzschild", 1.0), size=(12, 9), light=3.0)
    a = wv.render(sc, spp=4, seed=2, threads=1, guide_training=8)
    b = wv.render(sc, spp=4, seed=2, threads=2, guide_training=8)
    np.testing.assert_array_equal(a.rgb, b.rgb)
    half = wv.render(sc, spp=2, seed=2, threads=2, guide_training=8)
    resumed = wv.render(sc, spp=4, seed=2, threads=2, guide_training=8, resume=half)  # (trains the same tree again)
    np.testing.assert_allclose(resumed.rgb, a.rgb, rtol=1e-6, atol=1e-7)  # (as any resume: float32 sums)
    with pytest.raises(ValueError, match="guide_training"):
        wv.render(sc, spp=4, seed=2, guide_training=4, resume=half)  # trained otherwise: not the same render
    again = wv.render(sc, spp=4, seed=2, threads=2, guide_training=8, resume=resumed)  # its own samples: no pass
    assert again.stats["guide_segments"] == 0 and resumed.stats["guide_segments"] > 0  # so nothing trained
    np.testing.assert_array_equal(again.rgb, resumed.rgb)


def test_guiding_off_is_the_render_before_bit_for_bit():
    sc = room(metric("schwarzschild", 1.0), size=(12, 9), light=3.0)
    a = wv.render(sc, spp=2, seed=5)
    b = wv.render(sc, spp=2, seed=5, guide_training=0)
    np.testing.assert_array_equal(a.rgb, b.rgb)
    assert a.stats["guide_segments"] == 0


def test_a_bad_guide_or_training_option_is_refused_naming_it(monkeypatch):
    import importlib

    from warpviz.options import DEFAULT_OPTIONS

    rr = importlib.import_module("warpviz.render.render")

    sc = room(metric("schwarzschild", 1.0), size=(6, 4), light=3.0)
    assert DEFAULT_OPTIONS["guide_training"] == 0
    with pytest.raises(ValueError, match="guide_training"):
        wv.render(sc, spp=1, guide_training=-1)
    with pytest.raises(ValueError, match="guide_training"):
        wv.render(sc, spp=1, guide_training=1000)
    # the tree a render trains and hands to its ranges, and what the core says of broken ones
    calls = []
    real = rr.core.render
    monkeypatch.setattr(rr.core, "render", lambda native, options: calls.append((native, options)) or real(native, options))
    wv.render(sc, spp=1, guide_training=2)
    native, options = calls[-1]
    good = options["guide"]
    assert good is not None and good["roots"].shape == (12,) and good["sky_sum"].shape[1] == 4
    for key, bad in (("sky_child", lambda a: np.full_like(a, 10**6)), ("sky_sum", lambda a: -a),
                     ("space_index", lambda a: np.zeros_like(a) - 7), ("roots", lambda a: a[:2]),
                     ("leaf_root", lambda a: a + 10**6), ("leaf_lights", lambda a: np.full_like(a, 0.7))):  # fmt: skip
        broken = dict(good, **{key: np.ascontiguousarray(bad(good[key]))})
        with pytest.raises(ValueError, match="render option 'guide'"):
            real(native, dict(options, guide=broken))
    with pytest.raises(ValueError, match="render option 'guide'"):
        real(native, dict(options, guide={"roots": good["roots"]}))
    # a tree learnt for another scene's lights
    calls.clear()
    wv.render(_lamps_on_both_sheets(), spp=1, guide_training=2)
    two = calls[-1][1]["guide"]
    assert two["leaf_lights"].shape[1] == 2
    with pytest.raises(ValueError, match="render option 'guide' chooses among 2 lights, the scene has 1"):
        real(native, dict(options, guide=two))


def test_each_part_of_space_learns_which_light_to_choose(monkeypatch):
    """With a lamp on each sheet of a wormhole, the leaves learn to choose mostly their own sheet's lamp (the
    other is still chosen at least kEvenLights / 2 of the time), and the learnt choice keeps the mean."""
    import importlib

    rr = importlib.import_module("warpviz.render.render")
    sc = _lamps_on_both_sheets()
    calls = []
    real = rr.core.render
    monkeypatch.setattr(rr.core, "render", lambda native, options: calls.append(options) or real(native, options))
    wv.render(sc, spp=1, guide_training=8)
    rows = calls[-1]["guide"]["leaf_lights"]
    learnt = rows[rows[:, 0] >= 0]
    assert rows.shape[1] == 2 and len(learnt) > 0
    np.testing.assert_allclose(learnt.sum(axis=1), 1.0, rtol=1e-12)
    assert learnt.min() >= 0.1 - 1e-12 and learnt.max() > 0.8  # (the even share: 0.2 / 2 lights)
