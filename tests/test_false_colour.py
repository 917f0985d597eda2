"""False-colour pictures of physics AOVs (warpviz/render/false_colour.py): known values to known colours,
the colour bar and its labels, the range in the metadata, the command line's --false-colour."""

from __future__ import annotations

import json

import matplotlib
import numpy as np
import pytest
from typer.testing import CliRunner

import warpviz as wv
from warpviz import cli
from warpviz.render.false_colour import FALSE_COLOUR_STYLES, false_colour
from warpviz.render.image import Image

runner = CliRunner()


def rgb8(cmap: str, t: float) -> np.ndarray:
    return np.round(np.asarray(matplotlib.colormaps[cmap](t))[:3] * 255.0).astype(np.uint8)


def aov_pixel(fc, x: int, y: int) -> np.ndarray:
    """The colour of AOV pixel (x, y) in the picture (the centre of its enlarged block)."""
    return fc.pixels[fc.top + fc.zoom * y + fc.zoom // 2, fc.zoom * x + fc.zoom // 2]


def test_redshift_is_diverging_about_one_with_the_horizon_black():
    g = np.array([[0.5, 1.0, 1.5, 0.0], [0.8, 1.2, np.nan, 1.0]], dtype=np.float32)
    fc = false_colour(g, quantity="redshift")
    assert (fc.vmin, fc.vmax, fc.cmap, fc.scale) == (0.5, 1.5, "RdBu", "diverging")
    np.testing.assert_array_equal(aov_pixel(fc, 0, 0), rgb8("RdBu", 0.0))  # g = 0.5: redshifted, red
    np.testing.assert_array_equal(aov_pixel(fc, 1, 0), rgb8("RdBu", 0.5))  # g = 1: the middle
    np.testing.assert_array_equal(aov_pixel(fc, 2, 0), rgb8("RdBu", 1.0))  # g = 1.5: blueshifted, blue
    np.testing.assert_array_equal(aov_pixel(fc, 0, 1), rgb8("RdBu", 0.3))
    np.testing.assert_array_equal(aov_pixel(fc, 3, 0), [0, 0, 0])  # the horizon: no value
    np.testing.assert_array_equal(aov_pixel(fc, 2, 1), [0, 0, 0])  # NaN: no value
    # the range is symmetric about 1 even when the values are not
    fc = false_colour(np.array([[0.9, 1.3]]), quantity="redshift")
    assert (fc.vmin, fc.vmax) == pytest.approx((0.7, 1.3))


def test_log_drift_and_linear_steps_map_to_known_colours():
    drift = np.array([[1e-12, 1e-9, 1e-6, 0.0]])
    fc = false_colour(drift, quantity="max_drift")
    assert fc.scale == "log10" and (fc.vmin, fc.vmax) == pytest.approx((1e-12, 1e-6))
    for x, t in enumerate((0.0, 0.5, 1.0)):
        np.testing.assert_array_equal(aov_pixel(fc, x, 0), rgb8("magma", t))
    np.testing.assert_array_equal(aov_pixel(fc, 3, 0), [0, 0, 0])  # zero drift: no value on a log scale
    steps = np.array([[10.0, 20.0, 30.0, 50.0]])
    fc = false_colour(steps, quantity="n_steps", vmin=10.0, vmax=30.0)
    for x, t in enumerate((0.0, 0.5, 1.0, 1.0)):  # 50 is beyond vmax: drawn at the top end
        np.testing.assert_array_equal(aov_pixel(fc, x, 0), rgb8("viridis", t))


def test_colour_bar_and_labels():
    fc = false_colour(np.linspace(0, 1, 12 * 16).reshape(12, 16), quantity="depth")
    assert fc.zoom == 20  # 12 rows enlarged to at least 240
    H, W = 12 * fc.zoom, 16 * fc.zoom
    assert fc.pixels.shape[0] == fc.top + H and fc.pixels.shape[1] > W + 18 and fc.pixels.dtype == np.uint8
    bar_x = W + 8 + 9  # the bar's middle column
    np.testing.assert_array_equal(fc.pixels[fc.top, bar_x], rgb8("viridis", 1.0))  # high values on top
    np.testing.assert_array_equal(fc.pixels[fc.top + H - 1, bar_x], rgb8("viridis", 0.0))
    assert (fc.pixels[: fc.top, :W] < 128).any()  # the label and the range are written above
    assert (fc.pixels[fc.top:, W + 8 + 18 + 6 :] < 128).any()  # tick values beside the bar


def test_saved_png_names_the_quantity_and_its_range(tmp_path):
    from PIL import Image as PILImage

    fc = false_colour(np.array([[0.5, 1.5]]), quantity="redshift")
    path = fc.save(tmp_path / "g.png", metadata={"metric": "schwarzschild"})
    with PILImage.open(path) as im:
        meta = json.loads(im.text["warpviz"])
        np.testing.assert_array_equal(np.asarray(im), fc.pixels)
    assert meta["metric"] == "schwarzschild"
    assert meta["false_colour"] == {"quantity": "redshift", "vmin": 0.5, "vmax": 1.5, "cmap": "RdBu",
                                    "scale": "diverging"}


def test_bad_false_colour_requests_refused():
    with pytest.raises(ValueError, match="no false colour for 'normal': use one of redshift, n_steps"):
        false_colour(np.zeros((2, 2)), quantity="normal")
    with pytest.raises(ValueError, match=r"needs an \(H, W\) array"):
        false_colour(np.zeros((2, 2, 3)), quantity="depth")
    with pytest.raises(ValueError, match="unknown colormap 'nope'"):
        false_colour(np.zeros((2, 2)), quantity="depth", cmap="nope")
    with pytest.raises(ValueError, match="logarithmic: vmin must be > 0"):
        false_colour(np.ones((2, 2)), quantity="max_drift", vmin=0.0)
    img = Image(rgb=np.zeros((2, 2, 3), np.float32), aovs={"samples": np.ones((2, 2), np.float32)},
                completed=True, stats={})
    with pytest.raises(ValueError, match=r"this image has no 'redshift' AOV \(it has: samples\)"):
        img.false_colour("redshift")
    assert img.false_colour("samples").vmin == 1.0
    assert set(FALSE_COLOUR_STYLES) == {"redshift", "n_steps", "max_drift", "depth", "errors", "samples", "status"}


def test_rendered_disk_redshift_false_colour():
    """fig02's disk: the approaching side is blueshifted (g > 1), the receding one redshifted, the shadow
    black; the picture's colours are the colormap's at each pixel's g."""
    img = wv.render("fig02", width=32, height=24, spp=1, threads=2, aovs=["redshift"])
    g = img.aovs["redshift"]
    fc = img.false_colour("redshift")
    assert fc.vmin < 1.0 < fc.vmax and fc.vmin == pytest.approx(2.0 - fc.vmax)
    assert g.max() > 1.0 and 0.0 < g[g > 0].min() < 1.0  # both sides of the disk
    assert max(g.max() - 1.0, 1.0 - g[g > 0].min()) == pytest.approx(fc.vmax - 1.0)
    for y, x in (np.unravel_index(np.argmax(g), g.shape), np.unravel_index(np.argmin(np.where(g > 0, g, 9)), g.shape)):
        t = (float(g[y, x]) - fc.vmin) / (fc.vmax - fc.vmin)
        np.testing.assert_array_equal(aov_pixel(fc, x, y), rgb8("RdBu", t))
    shadow = np.argwhere(g == 0.0)  # the camera ray fell into the horizon
    assert len(shadow) > 0
    for y, x in shadow:
        np.testing.assert_array_equal(aov_pixel(fc, x, y), [0, 0, 0])


def test_cli_false_colour(tmp_path):
    from PIL import Image as PILImage

    out = tmp_path / "g.png"
    args = ["render", "fig02", "--size", "16x12", "--spp", "1", "--threads", "2", "-q"]
    result = runner.invoke(cli.app, args + ["-o", str(out), "--false-colour", "redshift"])
    assert result.exit_code == 0, result.output
    with PILImage.open(out) as im:
        meta = json.loads(im.text["warpviz"])
        assert im.size[1] >= 240
    assert meta["false_colour"]["quantity"] == "redshift" and meta["metric"] == "schwarzschild"
    assert meta["false_colour"]["vmin"] < 1.0 < meta["false_colour"]["vmax"]
    for bad, message in ((["-o", str(tmp_path / "x.png"), "--false-colour", "colour"], "--false-colour must be one of"),
                         (["-o", str(tmp_path / "x.exr"), "--false-colour", "redshift"], "writes a PNG picture")):
        result = runner.invoke(cli.app, args + bad)
        assert result.exit_code == 2 and message in result.stderr, result.output
    assert not (tmp_path / "x.png").exists() and not (tmp_path / "x.exr").exists()
