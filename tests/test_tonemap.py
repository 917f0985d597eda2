"""Tonemapping and exposure of PNG output (warpviz/render/tonemap.py): clip is the old tonemap bit for bit,
filmic keeps the hue of saturated sources, exposure is in stops, bad values are refused everywhere."""

from __future__ import annotations

import colorsys
import json

import numpy as np
import pytest
from typer.testing import CliRunner

import warpviz as wv
from warpviz import cli
from warpviz.limits import EXPOSURE_RANGE, TONEMAP_NAMES
from warpviz.render.image import Image
from warpviz.render.tonemap import (DEFAULT_EXPOSURE, DEFAULT_TONEMAP, FILMIC_KNEE, TONEMAPS, exposed, filmic,
                                    tonemap)
from warpviz.scene import SceneError, scene_from_dict

runner = CliRunner()


def old_tonemap(rgb, *, exposure=1.0, method="clip"):
    """warpviz's PNG tonemap before this module, verbatim (exposure a scale factor): the reference."""
    x = np.nan_to_num(np.asarray(rgb, dtype=np.float64) * exposure, nan=0.0, posinf=1.0, neginf=0.0)
    x = np.maximum(x, 0.0)
    if method == "reinhard":
        x = x / (1.0 + x)
    x = np.minimum(x, 1.0)
    srgb = np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1.0 / 2.4) - 0.055)
    return np.round(srgb * 255.0).astype(np.uint8)


def hostile_rgb(seed=0, shape=(64, 48, 3)):
    """float32 radiance over many decades, with zeros, negatives, NaN and infinities."""
    rng = np.random.default_rng(seed)
    x = (10.0 ** rng.uniform(-5, 3, size=shape)).astype(np.float32)
    x[rng.random(shape) < 0.05] = 0.0
    x[rng.random(shape) < 0.02] *= -1
    flat = x.reshape(-1)
    flat[:6] = [np.nan, np.inf, -np.inf, 1.0, 0.0031308, 1e-30]
    return x


def hue_degrees(rgb):
    h, _, _ = colorsys.rgb_to_hsv(*(float(c) for c in rgb))
    return 360.0 * h


def hue_difference(a, b):
    d = abs(hue_degrees(a) - hue_degrees(b)) % 360.0
    return min(d, 360.0 - d)


def test_clip_is_the_old_tonemap_bit_for_bit():
    rgb = hostile_rgb()
    for method in ("clip", "reinhard"):
        np.testing.assert_array_equal(tonemap(rgb, method=method), old_tonemap(rgb, method=method))
    # exposure in stops: +1 stop is the old scale factor 2, -3 stops 1/8
    np.testing.assert_array_equal(tonemap(rgb, exposure=1.0, method="clip"), old_tonemap(rgb, exposure=2.0))
    np.testing.assert_array_equal(tonemap(rgb, exposure=-3.0, method="clip"), old_tonemap(rgb, exposure=0.125))
    assert tonemap(np.array([[[0.0, 0.5, 2.0]]], dtype=np.float32), method="clip").tolist() == [[[0, 188, 255]]]


def test_image_saves_clip_png_as_before_with_the_look_in_its_metadata(tmp_path):
    from PIL import Image as PILImage

    rgb = hostile_rgb(1, (12, 16, 3))
    img = Image(rgb=rgb, aovs={}, completed=True, stats={}, metadata={"metric": "minkowski"})
    path = img.save(tmp_path / "clip.png", tonemap="clip")
    with PILImage.open(path) as im:
        np.testing.assert_array_equal(np.asarray(im), old_tonemap(rgb))
        meta = json.loads(im.text["warpviz"])
    assert meta["tonemap"] == "clip" and meta["exposure"] == 0.0 and meta["metric"] == "minkowski"
    path = img.save(tmp_path / "default.png")
    with PILImage.open(path) as im:
        meta = json.loads(im.text["warpviz"])
        np.testing.assert_array_equal(np.asarray(im), tonemap(rgb, method=DEFAULT_TONEMAP))
    assert meta["tonemap"] == DEFAULT_TONEMAP and meta["exposure"] == DEFAULT_EXPOSURE
    img.save(tmp_path / "bright.png", exposure=2.5, tonemap="reinhard")
    with PILImage.open(tmp_path / "bright.png") as im:
        meta = json.loads(im.text["warpviz"])
        np.testing.assert_array_equal(np.asarray(im), old_tonemap(rgb, exposure=2.0**2.5, method="reinhard"))
    assert (meta["tonemap"], meta["exposure"]) == ("reinhard", 2.5)


@pytest.mark.parametrize("source", [(1.0, 0.4, 0.1), (1.0, 0.05, 0.05), (0.2, 0.5, 1.0), (0.9, 0.8, 0.05)])
def test_filmic_keeps_the_hue_of_a_saturated_source(source):
    """An orange (red, blue, yellow) light at 1x-1000x the clip level keeps, in the 8-bit picture under
    filmic, the hue and saturation it has when shown unclipped (at 1x under clip), within 2 degrees; clip
    turns the bright ones white (orange at 8x: saturation 0.2)."""
    source = np.array(source)
    shown = tonemap(source[None, None, :], method="clip")[0, 0] / 255.0  # the colour itself, not clipped
    for brightness in (1.0, 2.0, 8.0, 100.0, 1000.0):
        rgb = (source * brightness)[None, None, :]
        pic = tonemap(rgb, method="filmic")[0, 0] / 255.0
        assert hue_difference(pic, shown) < 2.0, (source, brightness, pic)
        s_src, s_pic = colorsys.rgb_to_hsv(*shown)[1], colorsys.rgb_to_hsv(*pic)[1]
        assert s_pic > 0.75 * s_src  # still saturated: not bleached to white
    if source[1] == 0.4:  # the orange ring source: under clip at 8x it is (1, 1, 0.8), nearly white
        clipped = tonemap((source * 8.0)[None, None, :], method="clip")[0, 0] / 255.0
        assert colorsys.rgb_to_hsv(*clipped)[1] < 0.25


def test_filmic_curve_is_monotone_continuous_and_the_identity_below_its_knee():
    m = np.concatenate([np.linspace(0.0, 4.0, 4001), np.geomspace(4.0, 1e6, 500)[1:]])
    grey = np.repeat(m[:, None], 3, axis=1)
    out = filmic(grey)[:, 0]
    assert np.all(np.diff(out) >= 0.0) and np.all(np.diff(out[m <= 1e3]) > 0.0)  # strictly rising to 1e3
    assert out.max() < 1.0
    below = m <= FILMIC_KNEE
    np.testing.assert_array_equal(out[below], m[below])  # the identity: mid-tones as clip shows them
    # slope 1 at the knee (no seam): a small step above it moves the output by the same amount
    eps = 1e-6
    up = filmic(np.full((1, 3), FILMIC_KNEE + eps))[0, 0]
    assert abs((up - FILMIC_KNEE) / eps - 1.0) < 1e-5
    # known values: m = 1 -> 0.75, m = 10 -> 0.5 + 0.5 * 19 / 20 = 0.975
    np.testing.assert_allclose(filmic(np.array([[1.0, 0.5, 0.0], [10.0, 1.0, 0.0]]))[:, 0], [0.75, 0.975])
    np.testing.assert_allclose(filmic(np.array([[10.0, 1.0, 0.0]]))[0, 1], 0.0975)  # the same factor on G
    # pixels whose channels all lie below the knee are bit-identical to clip in the 8-bit picture
    rgb = hostile_rgb(2) * 1e-3
    dim = np.max(np.nan_to_num(rgb, nan=0, posinf=1), axis=-1) <= FILMIC_KNEE
    np.testing.assert_array_equal(tonemap(rgb, method="filmic")[dim], tonemap(rgb, method="clip")[dim])


def test_exposure_doubles_the_linear_values_per_stop():
    rgb = np.abs(hostile_rgb(3)) * 1e-3
    rgb = np.nan_to_num(rgb, posinf=1.0)
    base = exposed(rgb, 0.0)
    np.testing.assert_array_equal(exposed(rgb, 1.0), 2.0 * base)
    np.testing.assert_array_equal(exposed(rgb, 3.0), 8.0 * base)
    np.testing.assert_array_equal(exposed(rgb, -2.0), 0.25 * base)
    np.testing.assert_allclose(exposed(rgb, 0.5), np.sqrt(2.0) * base, rtol=1e-15)
    for method in TONEMAPS:
        np.testing.assert_array_equal(tonemap(rgb, exposure=1.0, method=method), tonemap(2.0 * rgb, method=method))


@pytest.mark.parametrize("bad", [EXPOSURE_RANGE[1] + 1, EXPOSURE_RANGE[0] - 0.5, float("nan"), float("inf"), "2", True])
def test_bad_exposure_refused(bad):
    rgb = np.ones((1, 1, 3))
    with pytest.raises(ValueError, match=r"exposure must be a number of stops in \[-20, 20\]"):
        tonemap(rgb, exposure=bad)
    img = Image(rgb=rgb.astype(np.float32), aovs={}, completed=True, stats={})
    with pytest.raises(ValueError, match="exposure must be"):
        img.to_uint8(exposure=bad)


def test_bad_tonemap_refused(tmp_path):
    rgb = np.ones((1, 1, 3), dtype=np.float32)
    with pytest.raises(ValueError, match=r"unknown tonemap 'aces' \(known: filmic, clip, reinhard\)"):
        tonemap(rgb, method="aces")
    img = Image(rgb=rgb, aovs={}, completed=True, stats={})
    with pytest.raises(ValueError, match="unknown tonemap"):
        img.save(tmp_path / "x.png", tonemap="aces")
    assert not (tmp_path / "x.png").exists()
    assert tuple(TONEMAPS) == TONEMAP_NAMES


def scene_with_outputs(outputs: dict) -> dict:
    return {"version": 1, "metric": {"name": "minkowski"}, "camera": {"position": [0, -5, 0]},
            "render": {"width": 8, "height": 6, "spp": 1}, "outputs": outputs}  # fmt: skip


def test_scene_outputs_tonemap_and_exposure_checked():
    sc = scene_from_dict(scene_with_outputs({"tonemap": "clip", "exposure": -1.5}), base_dir=".")
    assert sc.outputs["tonemap"] == "clip" and sc.outputs["exposure"] == -1.5
    sc = scene_from_dict(scene_with_outputs({}), base_dir=".")
    assert sc.outputs["tonemap"] is None and sc.outputs["exposure"] is None
    with pytest.raises(SceneError, match=r"outputs.exposure must be in \[-20, 20\]"):
        scene_from_dict(scene_with_outputs({"exposure": 25}), base_dir=".")
    with pytest.raises(SceneError, match="outputs.tonemap = 'film' is not one of filmic, clip, reinhard"):
        scene_from_dict(scene_with_outputs({"tonemap": "film"}), base_dir=".")


def test_cli_exposure_and_tonemap(tmp_path):
    from PIL import Image as PILImage

    out = tmp_path / "fig04.png"
    args = ["render", "fig04", "--size", "16x12", "--spp", "1", "--threads", "2", "-q"]
    result = runner.invoke(cli.app, args + ["-o", str(out), "--tonemap", "clip", "--exposure", "-1"])
    assert result.exit_code == 0, result.output
    with PILImage.open(out) as im:
        meta = json.loads(im.text["warpviz"])
        clipped = np.asarray(im)
    assert (meta["tonemap"], meta["exposure"]) == ("clip", -1.0)
    img = wv.render("fig04", width=16, height=12, spp=1, threads=2)
    np.testing.assert_array_equal(clipped, old_tonemap(img.rgb, exposure=0.5))
    for bad, message in ((["--exposure", "30"], "--exposure must be a number of stops in [-20, 20], got 30.0"),
                         (["--tonemap", "aces"], "--tonemap must be one of filmic, clip, reinhard, got 'aces'")):
        result = runner.invoke(cli.app, args + ["-o", str(tmp_path / "bad.png"), *bad])
        assert result.exit_code == 2, result.output
        assert message in result.stderr and "Traceback" not in result.output
        assert not (tmp_path / "bad.png").exists()
