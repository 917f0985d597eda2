"""Rendering in passes: time budgets, noise targets, resuming from an EXR, and what an interruption keeps.

The property everything rests on: samples [0, N) split into any passes give the image of one render of N
samples per pixel, bit for bit (the core continues the film's sums in sample order), and a resumed EXR
gives it to float32 rounding (its means were stored as float32).
"""

from __future__ import annotations

import signal
import subprocess
import sys
import time

import numpy as np
import pytest
from typer.testing import CliRunner

import warpviz as wv
from warpviz import cli
from warpviz._native import core
from warpviz.render.passes import PASS_SAMPLES, next_pass, noise_estimate, standard_pass

from announcing_cli import ANNOUNCING_CLI

SMALL = {"width": 24, "height": 18}


def _invoke(*args):
    return CliRunner().invoke(cli.app, [str(a) for a in args])


# ------------------------------------------------------------------------------------------ pass sizes
def test_pass_sizes_double_up_to_the_cap_and_cut_to_the_target():
    sizes, done = [], 0
    while (n := next_pass(done=done, npix=100, spp=40, seconds_left=None, seconds_per_spp=None)) is not None:
        sizes.append(n)
        done += n
    assert sizes == [1, 1, 2, 4, 8, 16, 8] and done == 40
    big = 2000 * 1500
    assert standard_pass(1000, npix=big) == max(1, PASS_SAMPLES // big)
    # a budget shrinks the pass to what fits, and ends the render when not one sample per pixel does
    assert next_pass(done=16, npix=100, spp=None, seconds_left=5.5, seconds_per_spp=0.5) == 11
    assert next_pass(done=16, npix=100, spp=None, seconds_left=0.4, seconds_per_spp=0.5) is None


# ---------------------------------------------------------------------------------------- any split
def test_any_split_into_passes_is_one_render_bit_for_bit():
    whole = wv.render("fig07", **SMALL, spp=12, threads=2, edge_samples=4)
    timed = wv.render("fig07", **SMALL, time_limit=0.6, threads=2, edge_samples=4)
    n = timed.metadata["spp"]
    assert n >= 2 and timed.metadata["stopped_by"] == "time" and timed.completed
    same = wv.render("fig07", **SMALL, spp=n, threads=1, edge_samples=4)
    np.testing.assert_array_equal(timed.rgb, same.rgb)
    for name in timed.aovs:
        np.testing.assert_array_equal(timed.aovs[name], same.aovs[name], err_msg=name)
    # the edge pixels got 4x the samples, in every split
    assert set(np.unique(whole.aovs["samples"])) == {12, 48}


def test_a_time_budget_stops_within_one_pass_and_records_its_samples(tmp_path):
    reports = []
    t0 = time.perf_counter()
    img = wv.render("fig07", width=48, height=36, time_limit=1.5, threads=2, on_pass=reports.append)
    wall = time.perf_counter() - t0
    last_pass = reports[-1].seconds - reports[-2].seconds
    assert wall <= 1.5 + last_pass + 0.3, (wall, last_pass)  # the pass that would not fit was not started
    assert wall >= 0.5 * 1.5  # ... and the budget was used, not abandoned early
    assert [r.spp for r in reports] == sorted(r.spp for r in reports) and reports[-1].spp == img.metadata["spp"]
    assert img.metadata["passes"] == len(reports) and img.metadata["time_limit"] == 1.5
    assert np.all(img.aovs["samples"] >= img.metadata["spp"])
    out = img.save(tmp_path / "t.exr")
    assert wv.Image.open(out).metadata["spp"] == img.metadata["spp"]


def test_spp_and_time_together_whichever_comes_first():
    fast = wv.render("fig04", width=8, height=6, spp=3, time_limit=60, threads=1)
    assert fast.metadata["spp"] == 3 and fast.metadata["stopped_by"] == "spp"


# ------------------------------------------------------------------------------------------- noise
def test_the_core_noise_is_the_documented_estimate():
    img = wv.render("fig07", **SMALL, spp=8, threads=2)
    assert img.metadata["noise"] == pytest.approx(noise_estimate(img.rgb, img.aovs["variance"]), rel=1e-5)
    ones = wv.render("fig07", **SMALL, spp=1, threads=2, edge_samples=1)
    assert ones.metadata["noise"] is None  # one sample per pixel: no variance yet


@pytest.mark.parametrize(("sampler", "lo", "hi"), [("independent", 0.75, 1.2), ("sobol", 0.05, 0.6)])
def test_the_noise_estimate_predicts_the_error_against_a_converged_image(sampler, lo, hi):
    """The flat room with its lamp in view: the variance of the pixel means that the samples estimate
    matches the squared error of independent renders against a reference for independent samples, and
    bounds it from above for the stratified (Sobol) pixel positions, which average the lamp's edge faster."""
    ref = wv.render("fig03", width=16, height=12, spp=2048, seed=100, threads=2, aovs=[], pixel_sampler=sampler)
    err2, est = [], []
    for seed in range(6):
        img = wv.render("fig03", width=16, height=12, spp=32, seed=seed, threads=2, aovs=[], edge_samples=1,
                        pixel_sampler=sampler)  # fmt: skip
        err2.append(np.mean((img.rgb.astype(np.float64) - ref.rgb) ** 2) - np.mean(ref.aovs["variance"]))
        est.append(np.mean(img.aovs["variance"]))
    assert lo < np.mean(err2) / np.mean(est) < hi


def test_a_noise_target_stops_the_render_once_reached():
    img = wv.render("fig03", width=16, height=12, noise_target=0.2, threads=2, aovs=[])
    assert img.metadata["stopped_by"] == "noise" and img.metadata["noise"] <= 0.2
    fewer = wv.render("fig03", width=16, height=12, spp=img.metadata["spp"] // 2, threads=2, aovs=[])
    assert fewer.metadata["noise"] > 0.2  # it stopped at the first pass that reached it


# ------------------------------------------------------------------------------------------ resume
def test_resume_equals_the_direct_render_to_float32_rounding(tmp_path):
    direct = wv.render("fig07", **SMALL, spp=24, threads=2, edge_samples=4)
    part = wv.render("fig07", **SMALL, spp=5, threads=2, edge_samples=4)
    path = part.save(tmp_path / "part.exr")
    resumed = wv.render("fig07", **SMALL, spp=24, threads=2, edge_samples=4, resume=path)
    assert resumed.metadata["spp"] == 24 and resumed.completed
    np.testing.assert_allclose(resumed.rgb, direct.rgb, rtol=1e-6, atol=1e-7)
    np.testing.assert_array_equal(resumed.aovs["samples"], direct.aovs["samples"])
    for name in ("redshift", "status", "depth", "normal", "max_drift", "errors"):
        np.testing.assert_array_equal(resumed.aovs[name], direct.aovs[name], err_msg=name)
    for name in ("n_steps", "albedo", "albedo_normal", "emission"):
        np.testing.assert_allclose(resumed.aovs[name], direct.aovs[name], rtol=1e-6, atol=1e-7, err_msg=name)
    np.testing.assert_allclose(resumed.aovs["variance"], direct.aovs["variance"], rtol=1e-4, atol=1e-9)
    assert resumed.metadata["noise"] == pytest.approx(direct.metadata["noise"], rel=1e-5)
    # an image at its target already: nothing added, the same pixels back
    again = wv.render("fig07", **SMALL, spp=24, threads=2, edge_samples=4, resume=resumed)
    np.testing.assert_array_equal(again.rgb, resumed.rgb)


def test_resume_on_the_command_line_continues_the_exr_in_place(tmp_path):
    out = tmp_path / "r.exr"
    first = _invoke("render", "fig07", "--size", "24x18", "--spp", "4", "-o", out, "-q")
    assert first.exit_code == 0, first.output
    second = _invoke("render", "fig07", "--size", "24x18", "--spp", "10", "--resume", out, "-q")
    assert second.exit_code == 0, second.output
    assert "10 spp" in second.stderr
    img = wv.Image.open(out)
    direct = wv.render("fig07", **SMALL, spp=10)
    assert img.metadata["spp"] == 10
    np.testing.assert_allclose(img.rgb, direct.rgb, rtol=1e-6, atol=1e-7)


@pytest.mark.parametrize(("args", "says"), [
    (["fig04"], "another scene"),
    (["fig07", "--seed", "3"], "seed = 1; this render has seed = 3"),
    (["fig07", "--size", "12x9"], "size = [24, 18]; this render has size = [12, 9]"),
    (["fig07", "--flat"], "metric = \"schwarzschild\"; this render has metric = \"minkowski\""),
    (["fig07", "--edge-samples", "2"], "edge_samples = 8; this render has edge_samples = 2"),
])  # fmt: skip
def test_resume_refuses_another_scene_or_settings_before_any_work(tmp_path, args, says):
    out = tmp_path / "r.exr"
    assert _invoke("render", "fig07", "--size", "24x18", "--spp", "2", "-o", out, "-q").exit_code == 0
    before = out.read_bytes()
    size = [] if "--size" in args else ["--size", "24x18"]
    result = _invoke("render", *args, *size, "--spp", "4", "--resume", out, "-q")
    assert result.exit_code == 2, result.output
    assert says in result.stderr and "Traceback" not in result.output
    assert out.read_bytes() == before  # nothing written


def test_resume_refuses_an_image_from_before_a_fix_that_changes_its_samples():
    """resume.FIXES: a render records the renderer fixes it has (``settings["fixes"]``); an image written before one
    that changes its render (fig12: a sphere lamp, the sun, with the camera's own light samples round the throat)
    cannot be continued, one whose render the fix leaves alone can (fig07: quad lamps, here without the later fixes'
    focus and first winding; fig12 without the camera's light samples)."""
    def from_before_the_fix(img):
        img.metadata["resume"]["settings"].pop("fixes")
        return img

    old = from_before_the_fix(wv.render("fig12", **SMALL, spp=1, threads=2))
    with pytest.raises(ValueError, match="before the camera's own light samples of a sphere lamp were fixed"):
        wv.render("fig12", **SMALL, spp=2, threads=2, resume=old)
    for room, kw in (("fig07", {"lens_focus": False, "lens_images": 2}), ("fig12", {"camera_light_samples": False})):
        img = from_before_the_fix(wv.render(room, **SMALL, spp=1, threads=2, **kw))
        assert wv.render(room, **SMALL, spp=2, threads=2, resume=img, **kw).metadata["spp"] == 2


@pytest.mark.parametrize("tag, says, unaffected", [
    # the lens focus's angles by what the lens magnifies (732f3bc): the wormhole has no mass, so no focus
    ("lens_focus_bins", "before the lens focus drew its angle by what the lens magnifies",
     (("fig07", {"lens_focus": False}), ("fig13", {}))),
    # the first winding's weight without an evaluation of the lens map (LensMap::extrapolated_estimate)
    ("lens_order_extrapolated", "estimated the first winding's weight without evaluating",
     (("fig07", {"lens_images": 2}), ("fig13", {}))),
], ids=["lens_focus_bins", "lens_order_extrapolated"])
def test_resume_refuses_an_image_from_before_a_new_estimator_of_a_curved_room(tag, says, unaffected):
    """A change of estimator in the lens connection changes the samples of a curved room that uses it (fig07, and
    the Kerr room fig10d through its proxies): an image from before it cannot be continued; one rendered without
    what changed, and the wormhole's, can."""
    def from_before(img):
        img.metadata["resume"]["settings"]["fixes"].remove(tag)
        return img

    for room in ("fig07", "fig10d"):
        old = from_before(wv.render(room, **SMALL, spp=1, threads=2))
        with pytest.raises(ValueError, match=says):
            wv.render(room, **SMALL, spp=2, threads=2, resume=old)
    for room, kw in unaffected:
        img = from_before(wv.render(room, **SMALL, spp=1, threads=2, **kw))
        assert wv.render(room, **SMALL, spp=2, threads=2, resume=img, **kw).metadata["spp"] == 2


def test_photon_settings_matter_to_resume_only_where_photons_were_traced():
    """resume.PHOTON_SETTINGS: an image from before ``photon_aim`` existed (implied false) that traced no photons
    continues with today's default aim and another photon radius (they change nothing there); one that traced
    photons is refused, naming the setting, and so is a render that adds photons to one without."""
    def from_before_the_aim(img):
        img.metadata["resume"]["settings"].pop("photon_aim")
        return img

    plain = from_before_the_aim(wv.render("fig07", **SMALL, spp=1, threads=2, photons_per_pixel=0.0))
    resumed = wv.render("fig07", **SMALL, spp=2, threads=2, photons_per_pixel=0.0, photon_radius=3.0, resume=plain)
    assert resumed.metadata["spp"] == 2
    with_photons = from_before_the_aim(wv.render("fig07", **SMALL, spp=1, threads=2, photons_per_pixel=0.3))
    with pytest.raises(ValueError, match="photon_aim = false; this render has photon_aim = true"):
        wv.render("fig07", **SMALL, spp=2, threads=2, photons_per_pixel=0.3, resume=with_photons)
    with pytest.raises(ValueError, match="photons_per_pixel"):
        wv.render("fig07", **SMALL, spp=2, threads=2, photons_per_pixel=0.3, resume=plain)


def test_resume_refuses_a_foreign_or_missing_exr(tmp_path):
    import OpenEXR

    foreign = tmp_path / "foreign.exr"
    with OpenEXR.File({"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage},
                      {"RGB": np.zeros((4, 4, 3), np.float32)}) as f:  # fmt: skip
        f.write(str(foreign))
    result = _invoke("render", "fig07", "--spp", "2", "--resume", foreign, "-o", tmp_path / "x.exr", "-q")
    assert result.exit_code == 2 and "no warpviz header" in result.stderr
    assert not (tmp_path / "x.exr").exists()
    result = _invoke("render", "fig07", "--spp", "2", "--resume", tmp_path / "missing.exr", "-q")
    assert result.exit_code == 2 and "must be an existing .exr file" in result.stderr
    png = wv.render("fig04", width=8, height=6, spp=1).save(tmp_path / "p.png")
    result = _invoke("render", "fig04", "--spp", "2", "--resume", png, "-q")
    assert result.exit_code == 2 and "must be an existing .exr file" in result.stderr


def test_an_interrupted_first_pass_is_kept_but_cannot_be_resumed(tmp_path):
    def stop(done, total):
        raise KeyboardInterrupt

    # 96x72: the first pass (1 spp) outlasts the core's first poll (20 ms)
    img = wv.render("fig07", width=96, height=72, spp=64, threads=1, progress=stop)
    assert not img.completed and img.metadata["stopped_by"] == "interrupted" and img.metadata["spp"] == 0
    assert not img.metadata["resume"]["resumable"]
    path = img.save(tmp_path / "p.exr")
    with pytest.raises(ValueError, match="holds only part of its first pass"):
        wv.render("fig07", width=96, height=72, spp=64, resume=path)


def test_an_interruption_keeps_the_finished_passes_whole():
    calls = []

    def stop_in_the_fourth_pass(done, total):
        calls.append(done)

    reports = []

    def on_pass(report):
        reports.append(report)
        if len(reports) == 3:
            raise KeyboardInterrupt  # as Ctrl-C between passes

    img = wv.render("fig07", **SMALL, spp=64, threads=1, progress=stop_in_the_fourth_pass, on_pass=on_pass)
    assert not img.completed and img.metadata["spp"] == 4 and img.metadata["resume"]["resumable"]
    assert set(np.unique(img.aovs["samples"])) <= {4, 32}
    np.testing.assert_array_equal(img.rgb, wv.render("fig07", **SMALL, spp=4, threads=2).rgb)




def test_sigterm_during_a_resumed_render_keeps_the_earlier_passes(tmp_path):
    out = tmp_path / "r.exr"
    assert _invoke("render", "fig07", "--size", "48x36", "--spp", "6", "-o", out, "-q").exit_code == 0
    cmd = [sys.executable, "-c", ANNOUNCING_CLI, "render", "fig07", "--size", "48x36", "--spp", "100000",
           "--threads", "1", "--resume", str(out), "-q"]  # fmt: skip
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        first = proc.stderr.readline()  # the resumed render's first pass is under way
        assert first.strip() == "rendering", first + proc.stderr.read()
        time.sleep(1.0)  # a few passes
        proc.send_signal(signal.SIGTERM)
        _, stderr = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 143, stderr
    assert "terminated: saved the partial image" in stderr
    img = wv.Image.open(out)
    assert img.metadata["spp"] >= 6 and img.metadata["resume"]["resumable"]
    n = img.metadata["spp"]
    assert set(np.unique(img.aovs["samples"])) <= {n, 8 * n}  # whole passes only
    direct = wv.render("fig07", width=48, height=36, spp=n, threads=2)
    np.testing.assert_allclose(img.rgb, direct.rgb, rtol=1e-6, atol=1e-7)


# ------------------------------------------------------------------------------------- bad options
@pytest.mark.parametrize(("args", "says"), [
    (["--time", "soon"], "--time must be a time such as 90"),
    (["--time", "0"], "--time must be more than 0"),
    (["--noise", "0"], "--noise must be a relative error in (0, 1)"),
    (["--noise", "1.5"], "--noise must be a relative error in (0, 1)"),
])  # fmt: skip
def test_bad_limits_are_exit_2_before_any_work(tmp_path, args, says):
    out = tmp_path / "x.png"
    result = _invoke("render", "fig07", *args, "-o", out, "-q")
    assert result.exit_code == 2 and says in result.stderr, result.output
    assert not out.exists()


def test_bad_limits_in_the_api_name_the_option():
    with pytest.raises(ValueError, match="time_limit must be"):
        wv.render("fig04", width=4, height=3, time_limit=-1)
    with pytest.raises(ValueError, match="noise_target must be"):
        wv.render("fig04", width=4, height=3, noise_target=2)
    with pytest.raises(ValueError, match="on_pass must be"):
        wv.render("fig04", width=4, height=3, on_pass=3)


def test_a_film_of_another_window_is_refused_by_the_core():
    img = core.render  # the binding checks what it is handed, whatever Python does
    native = wv.scene.load_scene("fig04").native(width=4, height=3)
    from warpviz.render.render import DEFAULT_OPTIONS, FILTER_RADII
    from warpviz.options import DETAIL_SAMPLES, EDGE_SAMPLES
    from warpviz.tracing import default_max_drift

    options = dict(DEFAULT_OPTIONS, spp=1, sample_begin=0, threads=1, progress=None, record_pixels=None,
                   crop=[0, 0, 4, 3], aovs=[])  # fmt: skip
    options["max_drift"] = default_max_drift(options["tol"])
    options["filter_radius"] = FILTER_RADII[options["filter"]]
    options["edge_samples"], options["detail_samples"] = EDGE_SAMPLES, DETAIL_SAMPLES
    film = img(native, options)["film"]
    with pytest.raises(ValueError, match="does not cover this window"):
        img(native, dict(options, crop=[0, 0, 2, 3], film=film, sample_begin=1))


def test_segments_by_status_add_up_over_the_passes():
    """Each pass's segments by status are added, as its segments are (they were the last pass's only): flat space
    without photons counts every segment under one status, so over the passes the two agree."""
    from warpviz.render.passes import add_stats

    assert add_stats({"segments": 3, "segments_by_status": {"hit": 2, "escaped": 1}},
                     {"segments": 5, "segments_by_status": {"hit": 4, "escaped": 1}}) == \
        {"segments": 8, "segments_by_status": {"hit": 6, "escaped": 2}}  # fmt: skip
    img = wv.render("fig07", **SMALL, spp=8, threads=2, flat=True, photons_per_pixel=0, edge_samples=1)
    assert img.metadata["passes"] > 1
    assert sum(img.stats["segments_by_status"].values()) == img.stats["segments"]
