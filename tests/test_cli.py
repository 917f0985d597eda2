"""The ``warpviz`` command line: exit codes, messages and the files it writes."""

from __future__ import annotations

import contextlib
import csv
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

import warpviz as wv
from warpviz import cli
from warpviz.scene import Scene
from warpviz.scene.catalog import shipped_scenes

runner = CliRunner()

BAD_SCENE = """\
version = 1
[metric]
name = "kerr"
spin = 1.2
[camera]
position = [0, -30, 0]
"""


def invoke(*args: str):
    return runner.invoke(cli.app, [str(a) for a in args])


def test_version():
    result = invoke("--version")
    assert result.exit_code == 0 and wv.__version__ in result.stdout


def test_validate_ok_and_failing(tmp_path):
    result = invoke("validate", "fig07", "scenes/fig02_accretion_disk.toml")
    assert result.exit_code == 0, result.output
    assert "fig07_schwarzschild_cornell.toml: Schwarzschild(mass=2.5)" in result.stdout
    assert "fig02_accretion_disk.toml" in result.stdout

    bad = tmp_path / "bad.toml"
    bad.write_text(BAD_SCENE)
    result = invoke("validate", "fig04", bad)
    assert result.exit_code == 2
    assert f"{bad}:4:8: metric.spin must be in (-1, 1), got 1.2" in result.stderr
    assert "Traceback" not in result.output
    assert "fig04_einstein_ring.toml" in result.stdout  # the good one is still reported


def test_validate_every_shipped_scene():
    result = invoke("validate", *shipped_scenes())
    assert result.exit_code == 0, result.output
    assert result.stdout.count("ok ") == len(shipped_scenes())


def test_unknown_scene_name_is_bad_input():
    result = invoke("validate", "fig99")
    assert result.exit_code == 2 and "fig99" in result.stderr


def test_scenes_lists_every_shipped_scene():
    result = invoke("scenes")
    assert result.exit_code == 0
    for path in shipped_scenes():
        assert path.stem in result.stdout
    assert "Einstein ring" in result.stdout
    assert f"{len(shipped_scenes())} scenes" in result.stdout


def test_doctor_quick():
    result = invoke("doctor", "--quick")
    assert result.exit_code == 0, result.output
    for item in ("core flags", "threads", "schwarzschild", "pyvista", "vtk", "display", "skipped (--quick)"):
        assert item in result.stdout


@pytest.mark.slow
def test_doctor_tries_offscreen_rendering():
    result = invoke("doctor")
    assert result.exit_code == 0 and "off-screen 3-D" in result.stdout


def test_render_bad_options_are_exit_2(tmp_path):
    result = invoke("render", "fig04", "--size", "16by12")
    assert result.exit_code == 2 and "WIDTHxHEIGHT" in result.output
    result = invoke("render", "fig04", "-o", tmp_path / "out.jpg")
    assert result.exit_code == 2 and "must end in .png or .exr" in result.stderr
    result = invoke("render", "fig04", "--spp", "0")
    assert result.exit_code == 2
    bad = tmp_path / "bad.toml"
    bad.write_text(BAD_SCENE)
    result = invoke("render", bad, "-o", tmp_path / "x.png")
    assert result.exit_code == 2 and f"{bad}:4:8:" in result.stderr and "Traceback" not in result.output
    assert not (tmp_path / "x.png").exists()


class FakeImage:
    """Stands in for warpviz.render.image.Image in tests of the command's own logic."""

    def __init__(self, width, height, *, completed):
        self.rgb = np.full((height, width, 3), 0.25, dtype=np.float32)
        self.aovs = {"redshift": np.ones((height, width), np.float32), "depth": np.ones((height, width), np.float32)}
        self.completed = completed
        self.saved_aovs = None
        self.saved_look = None

    def save(self, path, *, exposure=None, tonemap=None):
        from PIL import Image

        self.saved_aovs = sorted(self.aovs)
        self.saved_look = {"exposure": exposure, "tonemap": tonemap}
        Image.fromarray(np.zeros((*self.rgb.shape[:2], 3), np.uint8)).save(path, format="PNG")


def test_render_passes_options_and_reports_interruption(tmp_path, monkeypatch):
    calls = []

    def fake_render(scene, **kw):
        calls.append((scene, kw))
        kw["progress"](3, 10)
        return FakeImage(kw["width"] or 96, kw["height"] or 72, completed=False)

    monkeypatch.setattr(cli.common, "_renderer", lambda: fake_render)
    out = tmp_path / "partial.png"
    result = invoke("render", "fig07", "-o", out, "--size", "20x10", "--spp", "3", "--seed", "5", "--threads", "2",
                    "--flat", "--paper", "--no-light-sampling")  # fmt: skip
    assert result.exit_code == 130, result.output
    assert out.is_file() and "partial image" in result.stderr
    scene, kw = calls[0]
    assert isinstance(scene, Scene) and scene.path.name == "fig07_schwarzschild_cornell.toml"
    assert kw == {"spp": 3, "width": 20, "height": 10, "seed": 5, "threads": 2, "flat": True, "light_sampling": False,
                  "paper": True, "progress": kw["progress"], "record_pixels": None,
                  "light_connection": None, "crop": None, "aovs": [],  # a PNG needs no AOVs
                  "on_pass": kw["progress"].on_pass}  # fmt: skip


def test_render_passes_edge_samples_only_when_given(tmp_path, monkeypatch):
    calls = []

    def fake_render(scene, **kw):
        calls.append(kw)
        return FakeImage(kw["width"] or 96, kw["height"] or 72, completed=True)

    monkeypatch.setattr(cli.common, "_renderer", lambda: fake_render)
    for args in ([], ["--edge-samples", "1"]):
        result = invoke("render", "fig07", "-o", tmp_path / "e.png", "--size", "8x6", "-q", "--force", *args)
        assert result.exit_code == 0, result.output
    assert "edge_samples" not in calls[0] and calls[1]["edge_samples"] == 1


def test_render_default_output_and_aov_selection(tmp_path, monkeypatch):
    images = []

    def fake_render(scene, **kw):
        images.append(FakeImage(8, 6, completed=True))
        return images[-1]

    monkeypatch.setattr(cli.common, "_renderer", lambda: fake_render)
    monkeypatch.chdir(tmp_path)
    result = invoke("render", "fig04", "-q")
    assert result.exit_code == 0, result.output
    assert (tmp_path / "fig04_einstein_ring.png").is_file()
    # fig02 keeps only the AOVs its [outputs] lists when writing EXR
    result = invoke("render", "fig02", "-o", "fig02.exr", "-q")
    assert result.exit_code == 0 and images[-1].saved_aovs == ["redshift"]


def test_runtime_errors_are_exit_1(monkeypatch, tmp_path):
    def broken(scene, **kw):
        raise RuntimeError("the core ran out of memory")

    monkeypatch.setattr(cli.common, "_renderer", lambda: broken)
    result = invoke("render", "fig04", "-o", tmp_path / "x.png", "-q")
    assert result.exit_code == 1 and "RuntimeError: the core ran out of memory" in result.stderr
    assert "Traceback" not in result.output


def test_render_writes_png(tmp_path):
    from PIL import Image

    out = tmp_path / "fig04.png"
    result = invoke("render", "fig04", "-o", out, "--size", "16x12", "--spp", "1", "--threads", "2")
    assert result.exit_code == 0, result.output
    with Image.open(out) as im:
        assert im.format == "PNG" and im.size == (16, 12) and im.mode == "RGB"
        pixels = np.asarray(im)
    assert pixels.max() > 0  # the ring is there


def test_render_writes_exr_with_the_scene_aovs(tmp_path):
    import OpenEXR

    out = tmp_path / "fig02.exr"
    result = invoke("render", "fig02", "-o", out, "--size", "16x12", "--spp", "1", "--threads", "2")
    assert result.exit_code == 0, result.output
    with OpenEXR.File(str(out)) as f:
        channels = f.channels()
        names = set(channels)
        rgb = channels["RGB"].pixels if "RGB" in channels else np.stack([channels[c].pixels for c in "RGB"], -1)
    assert rgb.shape == (12, 16, 3) and rgb.dtype == np.float32 and np.isfinite(rgb).all() and rgb.max() > 0
    assert {"redshift", "n_steps", "max_drift", "status"} <= names  # fig02's [outputs] aovs
    assert {"errors", "samples"} <= names  # always: which pixels lost samples, and how many each has
    assert not names & {"depth", "normal.X"}


def test_ctrl_c_saves_the_partial_image(tmp_path, monkeypatch):
    from PIL import Image

    @contextlib.contextmanager
    def interrupting_bar(label, *, enabled):
        def progress(done, total):
            raise KeyboardInterrupt  # what Ctrl-C does inside the render loop

        yield progress

    monkeypatch.setattr(cli.common, "_progress_bar", interrupting_bar)
    out = tmp_path / "partial.png"
    result = invoke("render", "fig07", "-o", out, "--size", "32x24", "--spp", "64", "--threads", "1")
    assert result.exit_code == 130, result.output
    assert "partial image" in result.stderr
    with Image.open(out) as im:
        assert im.size == (32, 24)


def test_trace_writes_recorded_paths(tmp_path):
    import pyvista as pv

    out = tmp_path / "rays.vtp"
    result = invoke("trace", "fig07", "--pixels", "8,6 1,1", "-p", "15,11", "-o", out, "--size", "16x12",
                    "--spp", "2", "--threads", "2", "-q")  # fmt: skip
    assert result.exit_code == 0, result.output
    rays = pv.read(out)
    assert rays.n_cells >= 6  # at least one geodesic per recorded sample
    if "pixel_x" in rays.cell_data:
        assert set(np.unique(rays.cell_data["pixel_x"]).tolist()) == {1, 8, 15}


def test_trace_rejects_bad_pixels(tmp_path):
    result = invoke("trace", "fig07", "--pixels", "99,1", "--size", "16x12", "-o", tmp_path / "r.vtp")
    assert result.exit_code == 2 and "outside the 16x12 image" in result.stderr
    result = invoke("trace", "fig07", "--pixels", "8;x", "-o", tmp_path / "r.vtp")
    assert result.exit_code == 2 and "expected X,Y" in result.stderr
    result = invoke("trace", "fig07", "--pixels", "1,1", "-o", tmp_path / "r.txt")
    assert result.exit_code == 2 and ".vtp" in result.stderr


def test_view_hands_scenes_and_files_to_the_viewer(monkeypatch, tmp_path):
    seen = []
    monkeypatch.setattr(cli.common, "_viewer", lambda: lambda obj, **kw: seen.append((obj, kw)))
    monkeypatch.setenv("DISPLAY", ":0")  # a window could open (the fake viewer opens none)
    monkeypatch.delenv("PYVISTA_OFF_SCREEN", raising=False)
    assert invoke("view", "fig07").exit_code == 0
    assert isinstance(seen[-1][0], Scene) and seen[-1][0].path.name.startswith("fig07") and seen[-1][1] == {}
    rays = wv.trace(wv.Minkowski(), [0, 0, 0], [1, 0, 0], record=True).save(tmp_path / "rays.vtp")
    shot = tmp_path / "view.png"
    assert invoke("view", rays, "--pixels", "3,4", "--screenshot", shot).exit_code == 0
    obj, kw = seen[-1]
    assert obj == rays and kw["pixels"].tolist() == [[3, 4]] and kw["screenshot"] == shot
    assert invoke("view", tmp_path / "missing.vtp").exit_code == 2
    picture = tmp_path / "image.exr"
    picture.write_text("")
    assert invoke("view", picture).exit_code == 2
    # the image panel's samples, time budget and width
    assert invoke("view", "fig07", "--time", "30s", "--width", "160").exit_code == 0
    assert seen[-1][1] == {"time_limit": 30.0, "spp": None, "preview_width": 160}
    assert invoke("view", "fig07", "--spp", "16").exit_code == 0 and seen[-1][1] == {"spp": 16}
    result = invoke("view", "fig07", "--time", "later")
    assert result.exit_code == 2 and "--time must be a time" in result.stderr


@pytest.mark.slow
def test_view_writes_a_screenshot_headless(tmp_path, monkeypatch):
    monkeypatch.setenv("PYVISTA_OFF_SCREEN", "true")
    shot = tmp_path / "view.png"
    result = invoke("view", "fig04", "--screenshot", shot)
    assert result.exit_code == 0, result.output
    assert shot.is_file() and shot.stat().st_size > 0


def test_bench_runs_the_benchmark_script(tmp_path):
    out = tmp_path / "geodesics.csv"
    result = invoke("bench", "--size", "4", "--rk4-subset", "9", "--out", tmp_path)
    assert result.exit_code == 0, result.output
    with out.open() as f:
        assert {row["stepper"] for row in csv.DictReader(f)} == {"dopri5", "dop853", "rk4"}
    assert invoke("bench", "--no-such-option").exit_code == 2


def test_bench_runs_a_named_suite(tmp_path):
    result = invoke("bench", "skips", "--quick", "--out", tmp_path)
    assert result.exit_code == 0, result.output
    with (tmp_path / "skips.csv").open() as f:
        assert len(list(csv.DictReader(f))) == 6


def test_console_script_is_declared():
    import tomllib

    pyproject = tomllib.loads((Path(__file__).resolve().parents[1] / "pyproject.toml").read_text())
    assert pyproject["project"]["scripts"]["warpviz"] == "warpviz.cli:main"
    assert callable(cli.main)


def test_render_with_photons_and_a_bad_photon_count_refused(tmp_path):
    out = tmp_path / "caustic.png"
    result = invoke("render", "caustics_glass_ball", "--size", "16x12", "--spp", "2", "--photons", "500", "-o", out)
    assert result.exit_code == 0, result.output
    assert out.is_file()
    bad = tmp_path / "bad.png"
    result = invoke("render", "caustics_glass_ball", "--size", "16x12", "--spp", "1", "--photons", "-5", "-o", bad)
    assert result.exit_code == 2 and "photons" in result.output and not bad.exists()


def test_render_with_photons_per_pixel_and_a_bad_density_refused(tmp_path):
    """--photons-per-pixel reaches the render (its EXR's resume settings keep it) and a negative one is exit 2."""
    out = tmp_path / "caustic.exr"
    result = invoke("render", "caustics_glass_ball", "--size", "16x12", "--spp", "2", "--photons", "0",
                    "--photons-per-pixel", "2.5", "-o", out)  # fmt: skip
    assert result.exit_code == 0, result.output
    from warpviz.render.resume import saved_resume

    assert saved_resume(wv.Image.open(out).metadata)["settings"]["photons_per_pixel"] == 2.5
    bad = tmp_path / "bad.png"
    result = invoke("render", "caustics_glass_ball", "--size", "16x12", "--spp", "1", "--photons-per-pixel", "-1",
                    "-o", bad)  # fmt: skip
    assert result.exit_code == 2 and "photons" in result.output and not bad.exists()
