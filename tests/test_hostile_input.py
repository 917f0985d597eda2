"""Hostile input: every bad scene file, command-line option and Python argument is refused with a clear
message (exit code 2 on the command line, no traceback), nothing is written or clobbered, a render too
large for the memory is refused before it allocates, a failed render is not reported as a success (exit
3), and SIGTERM / SIGINT save the partial image.

The tables below are the cases a hostile tester tried (issue 16); a new case is one row.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

import warpviz as wv
from warpviz import cli
from warpviz._native import core
from warpviz.limits import MAX_IMAGE_SIDE, MAX_SPP
from warpviz.render.memory import RenderTooLarge, render_bytes
from warpviz.render.render import OPTIONAL_AOVS
from warpviz.scene import SceneError

from announcing_cli import ANNOUNCING_CLI

runner = CliRunner()

SCENE = """\
version = 1
[metric]
name = "schwarzschild"
mass = 1.0
[camera]
position = [0, -20, 0]
look_at = [0, 0, 0]
fov = 40
[environment]
color = [0.5, 0.5, 0.5]
[render]
width = 16
height = 12
spp = 1
"""


def invoke(*args, env=None):
    return runner.invoke(cli.app, [str(a) for a in args], env=env)


def snapshot(folder: Path) -> dict[str, bytes]:
    """Every file under ``folder`` with its bytes (to show that nothing was written or changed)."""
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def assert_refused(result, code: int, fragment: str):
    assert result.exit_code == code, result.output
    assert fragment in result.output, result.output
    assert "Traceback" not in result.output


# ------------------------------------------------------------------------------------------- scene files
BAD_SCENES = [
    ("tolerance no stepper can meet", SCENE + "tol = 1e-30\n", "render.tol = 1e-30 is outside what dopri5 can meet"),
    ("rk4 tolerance", SCENE + 'stepper = "rk4"\ntol = 1e-14\n', "outside what rk4 can meet"),
    ("path depth beyond the limit", SCENE + "max_depth = 10000000000000\n", "render.max_depth must be in [1, 10000]"),
    ("spp beyond the core's counter", SCENE.replace("spp = 1", "spp = 10000000000000"), "render.spp must be in [1, 2147483647]"),
    ("width beyond the limit", SCENE.replace("width = 16", "width = 70000"), f"render.width must be in [1, {MAX_IMAGE_SIDE}]"),
    ("seed beyond 64 bits", SCENE + "seed = 1180591620717411303424\n", "seed"),
    ("mass that overflows", SCENE.replace("mass = 1.0", "mass = 1e308"), "inside the horizon"),
    ("nesting deeper than Python reads", SCENE + "junk = " + "[" * 5000 + "]" * 5000 + "\n", "nested too deeply"),
    ("not TOML", "\x00\x01\x02 = = =", "TOML syntax error"),
    ("not UTF-8", None, "cannot read the scene file"),
    ("scene file too large", SCENE + "# " + "x" * (17 * 2**20) + "\n", "more than a scene file may be"),
    ("unknown top-level key", SCENE + "[camra]\n", "camra"),
    ("missing version", SCENE.replace("version = 1\n", ""), "version"),
    # metrics from their line element: refused (file:line:column inside the expression) before compiling
    ("line element runs Python", SCENE.replace('name = "schwarzschild"\nmass = 1.0', 'name = "custom"\n'
     'line_element = "-dt**2 + dx**2 + dy**2 + dz**2 + __import__(1)*dx**2"'), "bad.toml:4:50: metric.line_element: unknown function '__import__'"),
    ("line element attribute access", SCENE.replace('name = "schwarzschild"\nmass = 1.0', 'name = "custom"\n'
     'line_element = "-dt**2 + M.__class__*dx**2"\nparameters = { M = 1.0 }'), "bad.toml:4:27: metric.line_element: unexpected character '.'"),
    ("line element huge exponent", SCENE.replace('name = "schwarzschild"\nmass = 1.0', 'name = "custom"\n'
     'line_element = "-dt**2 + dx**2 + dy**2 + dz**2*r**99999"'), "exponent 99999 is larger than 64"),
    ("line element divides by zero", SCENE.replace('name = "schwarzschild"\nmass = 1.0', 'name = "custom"\n'
     'line_element = "-dt**2 + dx**2/(M - M) + dy**2 + dz**2"\nparameters = { M = 1.0 }'), "division by zero"),
    ("landmark of a coordinate", SCENE.replace('name = "schwarzschild"\nmass = 1.0', 'name = "custom"\n'
     'line_element = "-dt**2 + dx**2 + dy**2 + dz**2"\nhorizon_radius = "2*r"'), "metric.horizon_radius: unknown name 'r'"),
    # moving observers (docs/observers.md): impossible ones refused at the key, before any work
    ("camera faster than light", SCENE.replace("fov = 40", "fov = 40\nvelocity = [0.9, 0.9, 0]"), "bad.toml:9:12: camera.velocity has speed 1.27279 c"),
    ("camera velocity of infinity", SCENE.replace("fov = 40", "fov = 40\nvelocity = [inf, 0, 0]"), "camera.velocity"),
    ("static camera in the ergoregion", SCENE.replace('name = "schwarzschild"\nmass = 1.0', 'name = "kerr"\nmass = 1.0\nspin = 0.9')
     .replace("position = [0, -20, 0]", "position = [0, -1.9, 0]\nobserver = \"static\""), "no static observer here"),
    ("orbit inside the photon sphere", SCENE.replace("position = [0, -20, 0]", 'position = [0, -2.9, 0]\nobserver = "orbit"'),
     "faster than light"),
    ("fall from below the camera", SCENE.replace("fov = 40", 'fov = 40\nobserver = "free_fall"\nfall_from = 10.0'), "above it"),
    ("static camera inside the horizon", SCENE.replace("position = [0, -20, 0]", "position = [0, -1.5, 0]"), "inside the horizon"),
    ("wormhole different on its two sheets", SCENE.replace('name = "schwarzschild"\nmass = 1.0', 'name = "custom"\n'
     'coordinates = "wormhole"\nline_element = "-dt**2 + dl**2 + (4 + l**2 + l**3)*dOmega**2"\nthroat_radius = "2"'),
     "the areal radius differs between l and -l"),
    ("custom metric unknown key", SCENE.replace('name = "schwarzschild"\nmass = 1.0', 'name = "custom"\n'
     'line_element = "-dt**2 + dx**2 + dy**2 + dz**2"\nhorizon = "2"'), "did you mean 'horizon_radius'"),
]  # fmt: skip


@pytest.mark.parametrize(("text", "fragment"), [c[1:] for c in BAD_SCENES], ids=[c[0] for c in BAD_SCENES])
def test_bad_scene_files_are_refused_by_validate_and_render(tmp_path, monkeypatch, text, fragment):
    monkeypatch.chdir(tmp_path)
    scene = tmp_path / "bad.toml"
    if text is None:
        scene.write_bytes(b"version = 1\n\xff\xfe\n")
    else:
        scene.write_text(text)
    before = snapshot(tmp_path)
    assert_refused(invoke("validate", scene), 2, fragment)
    assert_refused(invoke("render", scene, "-o", tmp_path / "out.png", "-q"), 2, fragment)
    assert snapshot(tmp_path) == before


def test_a_folder_given_as_the_scene_says_so(tmp_path):
    (tmp_path / "room.toml").mkdir()
    assert_refused(invoke("render", tmp_path / "room.toml"), 2, "is a folder, not a scene file")


# ------------------------------------------------------------------------------------- command-line options
BAD_OPTIONS = [
    ("size zero", ["--size", "0x5"], "WIDTHxHEIGHT"),
    ("size beyond the limit", ["--size", "100000x100000"], f"each in [1, {MAX_IMAGE_SIDE}]"),
    ("size not a size", ["--size", "big"], "WIDTHxHEIGHT"),
    ("spp zero", ["--spp", "0"], "--spp"),
    ("spp beyond the counter", ["--spp", "3000000000"], str(MAX_SPP)),
    ("seed negative", ["--seed", "-1"], "--seed"),
    ("seed beyond 64 bits", ["--seed", "1180591620717411303424"], "--seed"),
    ("crop outside the image", ["--crop", "10,10,16x12"], "crop (10, 10, 16, 12) must be a window"),
    ("crop not a window", ["--crop", "1,2"], "X,Y,WIDTHxHEIGHT"),
    ("error fraction above 1", ["--max-error-fraction", "2"], "--max-error-fraction"),
    ("unknown light connection", ["--light-connection", "magic"], "light_connection must be"),
    ("edge samples 0", ["--edge-samples", "0"], "--edge-samples"),
    ("edge samples above 64", ["--edge-samples", "65"], "--edge-samples"),
]  # fmt: skip


@pytest.mark.parametrize(("args", "fragment"), [c[1:] for c in BAD_OPTIONS], ids=[c[0] for c in BAD_OPTIONS])
def test_bad_render_options_are_refused_before_anything_is_written(tmp_path, args, fragment):
    scene = tmp_path / "ok.toml"
    scene.write_text(SCENE)
    before = snapshot(tmp_path)
    assert_refused(invoke("render", scene, "-o", tmp_path / "out.png", "-q", *args), 2, fragment)
    assert snapshot(tmp_path) == before


def test_output_targets_are_checked_before_rendering(tmp_path, monkeypatch):
    monkeypatch.setattr(cli.common, "_renderer", lambda: pytest.fail("rendered although the output cannot be written"))
    scene = tmp_path / "ok.toml"
    scene.write_text(SCENE)
    (tmp_path / "d.png").mkdir()
    assert_refused(invoke("render", scene, "-o", tmp_path / "d.png"), 2, "is a folder")
    assert_refused(invoke("render", scene, "-o", tmp_path / "nowhere" / "x.png"), 2, "does not exist")
    assert_refused(invoke("render", scene, "-o", tmp_path / "x.jpg"), 2, "must end in .png or .exr")
    assert_refused(invoke("trace", scene, "-p", "1,1", "-o", tmp_path / "d.png"), 2, "must end in .vtp")


def test_a_file_warpviz_did_not_write_is_replaced_only_with_force(tmp_path):
    scene = tmp_path / "ok.toml"
    scene.write_text(SCENE)
    foreign = tmp_path / "holiday.png"
    from PIL import Image

    Image.fromarray(np.full((4, 4, 3), 200, np.uint8)).save(foreign)
    original = foreign.read_bytes()
    assert_refused(invoke("render", scene, "-o", foreign, "-q"), 2, "was not written by warpviz; pass --force")
    assert foreign.read_bytes() == original
    notes = tmp_path / "notes.vtp"
    notes.write_text("my notes")
    assert_refused(invoke("trace", scene, "-p", "1,1", "-o", notes, "-q"), 2, "was not written by warpviz")
    assert notes.read_text() == "my notes"
    # warpviz's own output is replaced without asking, and --force replaces anything
    assert invoke("render", scene, "-o", tmp_path / "mine.png", "-q").exit_code == 0
    assert invoke("render", scene, "-o", tmp_path / "mine.png", "-q").exit_code == 0
    assert invoke("render", scene, "-o", foreign, "-q", "--force").exit_code == 0
    assert foreign.read_bytes() != original


@pytest.mark.parametrize("chosen", ["../escaped.png", "{outside}/escaped.png", "sub/../../escaped.png"])
def test_a_scene_cannot_choose_to_write_outside_its_folder(tmp_path, monkeypatch, chosen):
    folder, outside = tmp_path / "downloads", tmp_path / "elsewhere"
    folder.mkdir()
    outside.mkdir()
    (folder / "sub").mkdir()
    scene = folder / "gift.toml"
    scene.write_text(SCENE + f'[outputs]\nfile = "{chosen.format(outside=outside)}"\n')
    monkeypatch.chdir(folder)
    before = snapshot(tmp_path)
    assert_refused(invoke("render", scene, "-q"), 2, "lies outside the scene's folder and the working directory")
    assert snapshot(tmp_path) == before
    # an explicit -o may go anywhere
    assert invoke("render", scene, "-q", "-o", outside / "chosen_by_me.png").exit_code == 0


def test_scene_chosen_outputs_inside_the_scene_folder_are_written(tmp_path, monkeypatch):
    scene = tmp_path / "room.toml"
    scene.write_text(SCENE + '[outputs]\nfile = "room.exr"\n')
    monkeypatch.chdir(tmp_path)
    assert invoke("render", scene, "-q").exit_code == 0
    assert (tmp_path / "room.exr").is_file()


def test_view_refuses_files_it_cannot_show_without_vtk_noise(tmp_path, monkeypatch):
    import pyvista as pv

    monkeypatch.setenv("PYVISTA_OFF_SCREEN", "true")
    garbage = tmp_path / "random.vtp"
    garbage.write_bytes(np.random.default_rng(1).bytes(3000))
    sphere = tmp_path / "sphere.vtp"
    pv.Sphere().save(sphere)
    for path in (garbage, sphere):
        result = invoke("view", path, "--screenshot", tmp_path / "v.png")
        assert_refused(result, 2, "not a warpviz ray file")
        assert "vtkXMLPolyDataReader" not in result.output and len(result.output.splitlines()) <= 2
    assert not (tmp_path / "v.png").exists()


def test_view_pixels_outside_the_preview_are_bad_input(tmp_path, monkeypatch):
    monkeypatch.setenv("PYVISTA_OFF_SCREEN", "true")
    result = invoke("view", "fig04", "--pixels", "500,500", "--screenshot", tmp_path / "v.png")
    assert_refused(result, 2, "lies outside the")
    assert not (tmp_path / "v.png").exists()


def test_view_without_a_display_says_how_to_get_a_picture(monkeypatch):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    monkeypatch.delenv("PYVISTA_OFF_SCREEN", raising=False)
    if sys.platform in ("win32", "darwin"):
        pytest.skip("a window can open without DISPLAY here")
    assert_refused(invoke("view", "fig04"), 2, "--screenshot")


def test_help_keeps_bracketed_words():
    result = invoke("render", "--help")
    assert result.exit_code == 0 and "[outputs] file" in result.output and "[render.paper]" in result.output


# ------------------------------------------------------------------------------------------------ memory
def test_a_render_too_large_for_the_memory_is_refused_with_the_estimate(tmp_path):
    scene = tmp_path / "ok.toml"
    scene.write_text(SCENE)
    result = invoke("render", scene, "--size", "30000x30000", "-o", tmp_path / "h.png", "-q",
                    env={"WARPVIZ_MEMORY_LIMIT": "4G"})  # fmt: skip
    assert_refused(result, 2, "a 30000x30000 render needs about 93.9 GB (112 bytes per pixel)")
    assert "4.0 GB WARPVIZ_MEMORY_LIMIT allows" in result.output and "--crop" in result.output
    assert not (tmp_path / "h.png").exists()
    # an EXR with every AOV needs more per pixel, and says which AOVs it asked for
    result = invoke("render", scene, "--size", "30000x30000", "-o", tmp_path / "h.exr", "-q",
                    env={"WARPVIZ_MEMORY_LIMIT": "4G"})  # fmt: skip
    assert_refused(result, 2, "(328 bytes per pixel)")
    assert "fewer AOVs" in result.output


def test_the_memory_check_runs_before_any_allocation():
    """The largest image the limits allow (65536 x 65536) is refused on any real machine, and the process
    that refuses it never grows beyond its imports (peak RSS of a fresh interpreter)."""
    code = (
        "import resource, sys\n"
        "from warpviz.cli import main\n"
        "sys.argv = ['warpviz', 'render', 'fig07', '--size', '65536x65536', '-o', 'never.png', '-q']\n"
        "try:\n    main()\n"
        "finally:\n    print('peak', resource.getrusage(resource.RUSAGE_SELF).ru_maxrss, file=sys.stderr)\n"
    )
    env = {k: v for k, v in os.environ.items() if k != "WARPVIZ_MEMORY_LIMIT"}
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=120)
    assert proc.returncode == 2, proc.stderr
    assert ("a 65536x65536 render needs about 646.0 GB (448.0 GB for its 112 bytes per pixel and up to 198.0 GB for a "
            "photon pass of 1288490189 photons)") in proc.stderr  # (fig07: 0.3 photons per pixel)
    peak_kib = int(proc.stderr.split("peak")[-1].split()[0])
    assert peak_kib < 600 * 1024, f"peak RSS {peak_kib / 1024:.0f} MiB: something was allocated"


# Peak resident memory of a child process, sampled from /proc/self/smaps_rollup (which counts the page
# tables, so it is exact at each sample; ru_maxrss misses pages that worker threads faulted in recently).
_MEASURE = """
import sys, threading, time, warpviz as wv

def rss():
    for line in open("/proc/self/smaps_rollup"):
        if line.startswith("Rss:"):
            return int(line.split()[1]) * 1024

peak, running = [0], [True]
def sample():
    while running[0]:
        peak[0] = max(peak[0], rss())
        time.sleep(0.002)

scene = {"metric": {"name": "minkowski", "params": []}, "environment": {"color": [0.5, 0.5, 0.5]},
         "camera": {"position": [0, -5, 0], "look_at": [0, 0, 0], "fov": 30, "width": 2000, "height": 1500},
         "textures": [], "materials": [], "shapes": []}
aovs = sys.argv[2].split(",") if sys.argv[2] else []
tiny = wv.render(dict(scene, camera=dict(scene["camera"], width=4, height=3)), spp=1, threads=1, aovs=aovs)
tiny.save(sys.argv[1])  # loads Pillow or OpenEXR before the baseline
base = rss()
thread = threading.Thread(target=sample)
thread.start()
img = wv.render(scene, spp=2, threads=1, aovs=aovs)  # two passes: the second continues the first's film
img.save(sys.argv[1])
running[0] = False
thread.join()
print(peak[0] - base)
"""


@pytest.mark.skipif(not Path("/proc/self/smaps_rollup").exists(), reason="needs Linux's /proc/self/smaps_rollup")
@pytest.mark.parametrize("suffix", [".png", ".exr"])
@pytest.mark.parametrize("aovs", [(), OPTIONAL_AOVS], ids=["no AOVs", "every AOV"])
def test_the_memory_estimate_matches_what_a_render_uses(tmp_path, suffix, aovs):
    """Peak resident memory added by rendering (in two passes) and saving a 3-megapixel image, against
    render_bytes: never more than the estimate (plus 16 MiB of sampling slack), so a render the check
    lets through fits, and at least 70 % of it (measured: 100-104 % less the slack), so the check refuses
    no render that would fit by much."""
    proc = subprocess.run([sys.executable, "-c", _MEASURE, str(tmp_path / f"m{suffix}"), ",".join(aovs)],
                          capture_output=True, text=True, timeout=300)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    grown = int(proc.stdout.split()[-1])
    estimate = render_bytes(2000, 1500, aovs=aovs)
    assert 0.7 * estimate < grown < estimate + 16 * 2**20, (grown, estimate)


def test_unrequested_aovs_cost_no_memory():
    assert render_bytes(100, 100, aovs=()) == 100 * 100 * 112
    assert render_bytes(100, 100, aovs=("normal",)) == 100 * 100 * 136


def test_the_memory_estimate_counts_the_denoiser_features():
    """albedo and albedo_normal are double sums of 3 channels in the film (24 bytes each per pixel), held
    twice while a pass runs: with both, 2 x (56 + 48) bytes per pixel; with every AOV (the emission the
    denoiser leaves alone another 24) 2 x 164."""
    assert render_bytes(100, 100, aovs=("albedo",)) == 100 * 100 * 160
    assert render_bytes(100, 100, aovs=("albedo", "albedo_normal")) == 100 * 100 * 208
    assert render_bytes(100, 100, aovs=OPTIONAL_AOVS) == 100 * 100 * 328


# ------------------------------------------------------------------------------------------ failed renders
KERR_NEAR_EXTREMAL = """\
version = 1
[metric]
name = "kerr"
mass = 1.0
spin = 0.9999999999
[camera]
position = [0, -20, 0]
look_at = [0, 0, 0]
fov = 40
[render]
width = 32
height = 24
spp = 2
[environment]
color = [1, 1, 1]
"""


def test_a_render_whose_samples_fail_exits_3_and_says_how_many(tmp_path):
    scene = tmp_path / "kerr.toml"
    scene.write_text(KERR_NEAR_EXTREMAL)
    out = tmp_path / "k.exr"
    result = invoke("render", scene, "-o", out, "-q")
    assert result.exit_code == 3, result.output
    assert "samples failed" in result.output and "--max-error-fraction 0.01" in result.output
    import OpenEXR

    with OpenEXR.File(str(out)) as f:  # written, so it can be inspected
        fraction = f.header()["errorFraction"]
        errors = f.channels()["errors"].pixels
    assert 0.01 < fraction < 0.5 and errors.max() > 0
    assert invoke("render", scene, "-o", out, "-q", "--max-error-fraction", "0.5").exit_code == 0


def test_every_render_reports_its_error_fraction():
    img = wv.render("fig04", width=16, height=12, spp=1)
    assert img.error_fraction == 0.0 and img.stats["samples"] == img.aovs["samples"].sum() >= 16 * 12
    bad = wv.render({"metric": {"name": "kerr", "params": [1.0, 0.9999999999]},
                     "camera": {"position": [0, -20, 0], "look_at": [0, 0, 0], "fov": 40, "width": 32, "height": 24},
                     "environment": {"color": [1, 1, 1]}, "textures": [], "materials": [], "shapes": []}, spp=2)  # fmt: skip
    errors = bad.aovs["errors"] * bad.aovs["samples"]
    assert bad.error_fraction == pytest.approx(errors.sum() / bad.aovs["samples"].sum()) and bad.error_fraction > 0.01


# ---------------------------------------------------------------------------------------------- Python API
API_CASES = [
    ("complex direction", lambda: wv.trace(wv.Schwarzschild(mass=1.0), [0, -30, 0], [1 + 1j, 0, 0]), TypeError,
     "imaginary parts would be lost"),
    ("string origin", lambda: wv.trace(wv.Schwarzschild(mass=1.0), ["a", 0, 0], [1, 0, 0]), TypeError, "real numbers"),
    ("tolerance below rounding", lambda: wv.trace(wv.Schwarzschild(mass=1.0), [0, -30, 0], [1, 0, 0], tol=1e-30),
     ValueError, "use [1e-15, 0.1]"),
    ("render of an empty dict", lambda: wv.render({}), SceneError, "scene.metric is missing"),
    ("float record pixels", lambda: wv.render("fig04", width=8, height=6, spp=1, record_pixels=[[1.5, 2]]),
     ValueError, "integer (x, y) pixel coordinates"),
    ("odd record pixels", lambda: wv.render("fig04", width=8, height=6, spp=1, record_pixels=[1, 2, 3]),
     ValueError, "shape (K, 2)"),
    ("unknown AOV", lambda: wv.render("fig04", width=8, height=6, spp=1, aovs=["colour"]), ValueError, "unknown AOV"),
    ("crop outside", lambda: wv.render("fig04", width=8, height=6, spp=1, crop=(4, 0, 8, 6)), ValueError,
     "inside the 8x6 image"),
    ("spp beyond the counter", lambda: wv.render("fig04", width=8, height=6, spp=2**31), ValueError, "spp must be an integer in [1, 2147483647]"),
    ("width beyond the limit", lambda: wv.render("fig04", width=70000, height=6, spp=1), ValueError,
     "width must be an integer in [1, 65536]"),
]  # fmt: skip


@pytest.mark.parametrize(("call", "error", "fragment"), [c[1:] for c in API_CASES], ids=[c[0] for c in API_CASES])
def test_bad_python_arguments_name_the_problem(call, error, fragment):
    with pytest.raises(error) as info:
        call()
    assert fragment in str(info.value)


def test_render_too_large_for_the_memory_is_refused_from_python(monkeypatch):
    monkeypatch.setenv("WARPVIZ_MEMORY_LIMIT", "64M")
    with pytest.raises(RenderTooLarge, match=r"a 4000x3000 render needs about 1\.3 GB \(112 bytes per pixel\)"):
        wv.render("fig04", width=4000, height=3000, spp=1, aovs=[])
    # a window of it fits
    assert wv.render("fig04", width=4000, height=3000, spp=1, crop=(1990, 1490, 20, 20)).shape == (20, 20)


def test_a_photon_pass_too_large_for_the_memory_is_refused_naming_the_photons(monkeypatch):
    """A photon pass is the whole image's, held beside the films: at most 2 x 80 bytes (the stored photons and
    the tree's reordered copy) + 5 per photon (core.photon_pass_bytes), counted before any work."""
    n, most = core.photon_pass_bytes(1000, 0.5, 40, 30)
    assert n == 1000 + 600 and most == n * 165
    assert core.photon_pass_bytes(0, 0.0, 40, 30) == (0, 0)
    monkeypatch.setenv("WARPVIZ_MEMORY_LIMIT", "64M")
    with pytest.raises(RenderTooLarge, match=r"fewer photons a pass \(photons / photons_per_pixel: 1000000 photons a "
                                             r"pass may hold 157\.4 MB\)"):  # fmt: skip
        wv.render("caustics_glass_ball", width=40, height=30, spp=1, photons=10**6, photons_per_pixel=0.0, aovs=[])
    # the same picture with photons a pass that fit is rendered
    assert wv.render("caustics_glass_ball", width=40, height=30, spp=1, photons=1000, aovs=[]).shape == (30, 40)


@pytest.mark.parametrize("direction", [[1e308, 1e308, 0.0], [5e-324, 0.0, 0.0], [-1e-320, 1e-320, 0.0]])
def test_extreme_direction_lengths_keep_their_direction(direction):
    bh = wv.Schwarzschild(mass=1.0)
    unit = np.asarray(direction) / np.max(np.abs(direction))
    unit /= np.linalg.norm(unit)
    got = wv.trace(bh, [0, -30, 0.5], direction)
    want = wv.trace(bh, [0, -30, 0.5], unit)
    assert got.status_names.tolist() == want.status_names.tolist() != ["invariant_violation"]
    np.testing.assert_allclose(got.final_directions, want.final_directions, rtol=0, atol=1e-14)


def test_crop_windows_tile_the_image_exactly():
    full = wv.render("fig07", width=24, height=18, spp=2)
    for crop in [(0, 0, 24, 18), (0, 0, 7, 5), (7, 5, 17, 13), (23, 17, 1, 1)]:
        x0, y0, w, h = crop
        part = wv.render("fig07", width=24, height=18, spp=2, crop=crop)
        np.testing.assert_array_equal(part.rgb, full.rgb[y0 : y0 + h, x0 : x0 + w])
        for name, arr in full.aovs.items():
            np.testing.assert_array_equal(part.aovs[name], arr[y0 : y0 + h, x0 : x0 + w], err_msg=name)


def test_recorded_pixels_in_a_crop_window_are_the_same_paths():
    full = wv.render("fig07", width=24, height=18, spp=1, record_pixels=[[10, 8]])
    part = wv.render("fig07", width=24, height=18, spp=1, crop=(8, 6, 4, 4), record_pixels=[[10, 8]])
    np.testing.assert_array_equal(full.rays.points, part.rays.points)
    with pytest.raises(ValueError, match="outside the crop window"):
        wv.render("fig07", width=24, height=18, spp=1, crop=(8, 6, 4, 4), record_pixels=[[0, 0]])


# -------------------------------------------------------------------------------------------- signals
# The real command line in a child process; its progress callback says on stderr when the render loop
# runs, so the signal arrives inside the render (not during the imports).


def _render_until_signalled(tmp_path: Path, sig: int,
                            command: str = "render") -> tuple[subprocess.CompletedProcess, Path]:  # fmt: skip
    out = tmp_path / ("partial.exr" if command == "render" else "partial.vtp")
    extra = ["-p", "24,18"] if command == "trace" else []
    cmd = [sys.executable, "-c", ANNOUNCING_CLI, command, "fig07", "--size", "48x36", "--spp", "100000",
           "--threads", "1", *extra, "-o", str(out)]  # fmt: skip
    # Ctrl-C's default action, as in a terminal: a test run started as a background job of a
    # non-interactive shell has SIGINT ignored, the child would inherit that, and Python then never
    # installs its KeyboardInterrupt handler (this test hung there, not in warpviz).
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    try:
        first = proc.stderr.readline()
        assert first.strip() == "rendering", first + proc.stderr.read()
        time.sleep(0.5)  # a few passes
        proc.send_signal(sig)
        stdout, stderr = proc.communicate(timeout=60)
    except subprocess.TimeoutExpired:
        proc.kill()
        stdout, stderr = proc.communicate()
        pytest.fail(f"the render did not stop within 60 s of signal {sig}; stderr: {stderr}")
    finally:
        if proc.poll() is None:
            proc.kill()
    return subprocess.CompletedProcess(cmd, proc.returncode, stdout, stderr), out


@pytest.mark.parametrize(("sig", "code", "word"), [(signal.SIGTERM, 143, "terminated"), (signal.SIGINT, 130, "interrupted")])
def test_a_signal_saves_the_partial_image_with_its_samples(tmp_path, sig, code, word):
    import OpenEXR

    result, out = _render_until_signalled(tmp_path, sig)
    assert result.returncode == code, result.stderr
    assert f"{word}: saved the partial image" in result.stderr and "Traceback" not in result.stderr
    with OpenEXR.File(str(out)) as f:
        channels = f.channels()
        samples = channels["samples"].pixels
        assert "errors" in channels
    assert 1 <= samples.min() and samples.max() < 100000  # every pixel has samples; the render stopped early


def test_sigterm_during_trace_says_the_paths_are_partial(tmp_path):
    result, out = _render_until_signalled(tmp_path, signal.SIGTERM, command="trace")
    assert result.returncode == 143, result.stderr
    assert "terminated: saved the partial paths and image" in result.stderr and str(out) in result.stderr
    assert "wrote" not in result.stderr and "Traceback" not in result.stderr
    assert wv.read_rays(out).n_cells > 0


def test_a_stop_asked_for_during_a_passs_last_chunk_is_kept():
    """An image of one chunk (48 pixels): every poll during a pass comes after its last chunk started,
    so a stop asked for then must still end the render after that pass (it once ran to the end)."""
    calls = []

    def stop_once(done, total):
        calls.append(done)
        if len(calls) == 3:
            raise KeyboardInterrupt

    img = wv.render("fig07", width=8, height=6, spp=4096, threads=1, progress=stop_once)
    assert not img.completed
    assert 1 <= img.aovs["samples"].max() < 4096


# ------------------------------------------------------------------------------------------------ bench
def test_bench_writes_only_into_the_folder_given(tmp_path, monkeypatch):
    repo = Path(__file__).resolve().parents[1]
    results = repo / "benchmarks" / "results"
    before = {p.name: p.stat().st_mtime_ns for p in results.iterdir()}
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    result = invoke("bench", "--size", "4", "--rk4-subset", "9")
    assert result.exit_code == 0, result.output
    assert sorted(p.name for p in work.iterdir()) == ["geodesics.csv"]
    chosen = tmp_path / "chosen"
    assert invoke("bench", "skips", "--quick", "--out", chosen).exit_code == 0
    assert (chosen / "skips.csv").is_file() and sorted(p.name for p in work.iterdir()) == ["geodesics.csv"]
    assert {p.name: p.stat().st_mtime_ns for p in results.iterdir()} == before


# ------------------------------------------------------------------------------------- round two (issue 38)
LAMP = SCENE + """
[materials.lamp]
type = "emissive"
color = [1, 1, 1]
strength = {strength}

[[objects]]
shape = "sphere"
center = [0, 0, 3]
radius = 1
material = "lamp"
"""

MESH = SCENE + """
[materials.grey]
type = "diffuse"
color = [0.5, 0.5, 0.5]

[[objects]]
shape = "mesh"
file = "{file}"
material = "grey"
"""

TRIANGLE = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"


@pytest.mark.parametrize("name", ["/proc/x.png", "{folder}/" + "a" * 300 + ".png"], ids=["unwritable", "too long"])
def test_an_output_that_cannot_be_written_is_refused_before_rendering(tmp_path, monkeypatch, name):
    monkeypatch.setattr(cli.common, "_renderer", lambda: pytest.fail("rendered although the output cannot be written"))
    scene = tmp_path / "ok.toml"
    scene.write_text(SCENE)
    before = snapshot(tmp_path)
    target = name.format(folder=tmp_path)
    result = invoke("render", scene, "-o", target, "-q")
    assert_refused(result, 2, "cannot write output")
    assert ("file name too long" in result.output) == ("a" * 300 in target)
    assert_refused(invoke("trace", scene, "-p", "1,1", "-o", target.replace(".png", ".vtp"), "-q"), 2, "cannot write")
    assert snapshot(tmp_path) == before


def test_a_file_name_near_the_limit_is_written(tmp_path):
    """A 250-character name fits the file system; its staging folder's name must fit too (it once did not,
    and the finished render was lost)."""
    scene = tmp_path / "ok.toml"
    scene.write_text(SCENE)
    target = tmp_path / ("b" * 246 + ".png")
    assert invoke("render", scene, "-o", target, "-q").exit_code == 0
    assert target.is_file() and [p.name for p in tmp_path.iterdir() if p.name.startswith(".")] == []


def test_an_absurd_emission_strength_is_refused_and_infinite_radiance_is_a_failed_sample(tmp_path):
    scene = tmp_path / "sun.toml"
    scene.write_text(LAMP.format(strength="1e308"))
    result = invoke("render", scene, "-o", tmp_path / "x.exr", "-q")
    assert_refused(result, 2, "sun.toml:")
    assert "materials.lamp.strength must be in [0, 1e+12]" in result.output
    # whatever makes a sample's radiance overflow (here a texture of 1e29 at the highest strength: 1e41) fails
    # that sample instead of writing an infinite pixel
    native = wv.scene.load_scene(_write(tmp_path / "ok.toml", LAMP.format(strength="1e12"))).native()
    lamp = next(i for i, m in enumerate(native["materials"]) if m["type"] == "emissive")
    native["textures"].append({"type": "constant", "color": [1e29, 1e29, 1e29]})
    native["materials"][lamp]["texture"] = len(native["textures"]) - 1
    img = wv.render(native, width=16, height=12, spp=2, progress=None)
    assert np.isfinite(img.rgb).all()
    failed = img.aovs["errors"] > 0
    assert 0 < failed.sum() < failed.size  # the pixels that see the lamp


def _write(path: Path, text: str) -> Path:
    path.write_text(text)
    return path


def test_mesh_files_that_are_folders_not_finite_or_too_large(tmp_path, monkeypatch):
    (tmp_path / "box.obj").mkdir()
    result = invoke("validate", _write(tmp_path / "a.toml", MESH.format(file="box.obj")))
    assert_refused(result, 2, "a.toml:")
    assert "'box.obj' is a folder, not a file" in result.output
    (tmp_path / "nan.obj").write_text(TRIANGLE.replace("v 1 0 0", "v nan 0 0"))
    result = subprocess.run([sys.executable, "-W", "error::RuntimeWarning", "-c",
                             "from warpviz.cli import main; main()", "validate", str(_write(tmp_path / "b.toml", MESH.format(file="nan.obj")))],
                            capture_output=True, text=True)  # fmt: skip
    assert result.returncode == 2 and "b.toml:" in result.stderr, result.stderr
    assert "has 1 vertices whose coordinates are not finite" in result.stderr and "Warning" not in result.stderr
    # a huge (sparse) file is refused by its size, before it is read
    huge = tmp_path / "huge.obj"
    with open(huge, "wb") as f:
        f.truncate(300 * 2**20)
    t0 = time.perf_counter()
    result = invoke("validate", _write(tmp_path / "c.toml", MESH.format(file="huge.obj")))
    assert_refused(result, 2, "is 300 MB, more than the 256 MB a mesh file may be (set WARPVIZ_MAX_MESH_MB")
    assert time.perf_counter() - t0 < 5.0
    # the limit is the environment's where it is set
    (tmp_path / "tri.obj").write_text(TRIANGLE)
    small = _write(tmp_path / "d.toml", MESH.format(file="tri.obj"))
    assert invoke("validate", small).exit_code == 0
    monkeypatch.setenv("WARPVIZ_MAX_MESH_MB", "0.00001")
    assert_refused(invoke("validate", small), 2, "more than the 0 MB a mesh file may be")
    monkeypatch.setenv("WARPVIZ_MAX_MESH_MB", "lots")
    assert_refused(invoke("validate", small), 2, "WARPVIZ_MAX_MESH_MB='lots' must be a positive number of MB")


def test_serve_on_a_port_in_use_is_refused_before_the_preview(tmp_path):
    import socket

    with socket.socket() as busy:
        busy.bind(("127.0.0.1", 0))
        busy.listen()
        port = busy.getsockname()[1]
        result = subprocess.run([sys.executable, "-c", "from warpviz.cli import main; main()", "serve", "fig09",
                                 "--port", str(port), "--no-browser"],
                                capture_output=True, text=True, timeout=60)  # fmt: skip
    assert result.returncode == 2, result.stderr
    assert f"port {port} on 127.0.0.1 is in use" in result.stderr and "rendering the preview" not in result.stderr


def test_paper_without_a_paper_table_warpviz_scenes_on_a_file_and_a_dark_room(tmp_path, monkeypatch):
    scene = _write(tmp_path / "ok.toml", SCENE)
    before = snapshot(tmp_path)
    assert_refused(invoke("render", scene, "--paper", "-o", tmp_path / "p.png", "-q"), 2, "has no [render.paper]")
    assert_refused(invoke("trace", scene, "--paper", "-p", "1,1", "-o", tmp_path / "p.vtp", "-q"), 2, "--paper")
    assert snapshot(tmp_path) == before
    result = invoke("scenes", env={"WARPVIZ_SCENES": str(scene)})
    assert result.exit_code == 0 and f"WARPVIZ_SCENES names {str(scene)!r}, which is a file" in result.output
    dark = _write(tmp_path / "dark.toml", SCENE.replace("color = [0.5, 0.5, 0.5]", "color = [0, 0, 0]"))
    result = invoke("render", dark, "-o", tmp_path / "dark.png", "-q")
    assert result.exit_code == 0 and "warning: nothing in the scene 'dark.toml' gives off light" in result.output
    assert "Traceback" not in result.output and "UserWarning" not in result.output
    lit = invoke("render", _write(tmp_path / "lit.toml", LAMP.format(strength="3").replace(
        "color = [0.5, 0.5, 0.5]", "color = [0, 0, 0]")), "-o", tmp_path / "lit.png", "-q")  # fmt: skip
    assert lit.exit_code == 0 and "gives off light" not in lit.output


def test_bench_with_an_unknown_suite_lists_the_suites():
    result = invoke("bench", "nonsense")
    assert_refused(result, 2, "no benchmark suite 'nonsense'; the suites are: geodesics, work-precision")
    assert "time-to-clean" in result.output
