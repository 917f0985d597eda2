"""tools/make_gallery.py: the qualities' settings, the commands a user types, and a quick gallery built,
interrupted and resumed picture by picture (the classroom gallery itself takes ~50 minutes)."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tools"))

import make_gallery  # noqa: E402
from warpviz.scene import load_scene  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
ROOMS = {"fig03", "fig07", "fig08", "fig10a", "fig10b", "fig10c", "fig10d", "fig10e", "fig12", "fig13"}


@pytest.mark.parametrize("name", ["fig02", "fig04", "fig07", "fig10e", "fig11a", "fig13"])
def test_classroom_quality_is_classroom_sized_with_time_budgets(name):
    scene = load_scene(name)
    assert make_gallery.is_room(scene) == (name in ROOMS)
    s = make_gallery.settings(scene, "classroom")
    assert s["size"][0] >= 640 and s["size"][1] >= 480 and s["spp"] is None
    # rooms at most 4 minutes and denoised (the EXR keeps the unbiased radiance; the stars seen through the
    # wormhole are in the emission AOV, kept out of the denoiser), the rest at most 1
    assert s["seconds"] == (240 if name in ROOMS else 60)
    assert s["denoise"] == (name in ROOMS)
    assert make_gallery.settings(scene, "classroom", spp=8, denoise=False) == {"size": (640, 480), "spp": 8,
                                                                              "seconds": None, "denoise": False}
    ci = make_gallery.settings(scene, "ci")
    assert ci == {"size": None, "spp": None, "seconds": None, "denoise": False}  # each scene's own: what CI renders


def test_commands_are_the_ones_a_user_types():
    s = {"size": (640, 480), "spp": None, "seconds": 240.0, "denoise": True}
    assert (make_gallery.command("scenes/fig07_schwarzschild_cornell.toml", "fig07", s)
            == "warpviz render scenes/fig07_schwarzschild_cornell.toml --size 640x480 --time 4m --denoise -o fig07.png")
    assert (make_gallery.command("scenes/fig02_accretion_disk.toml", "fig02",
                                 {"size": None, "spp": None, "seconds": None, "denoise": False})
            == "warpviz render scenes/fig02_accretion_disk.toml -o fig02.png")  # the ci table, unchanged


def test_a_quick_gallery_is_built_picture_by_picture_and_resumed(tmp_path, monkeypatch):
    out, work, readme = tmp_path / "pictures", tmp_path / "work", tmp_path / "README.md"
    readme.write_text("# x\n\n<!-- gallery -->\nold\n<!-- /gallery -->\n\nafter\n")
    args = ["--quality", "quick", "--out", str(out), "--work", str(work), "--readme", str(readme)]
    assert make_gallery.main([*args, "--only", "fig04", "fig07", "fig06a"]) == 0
    assert sorted(p.name for p in out.iterdir()) == ["fig04.png", "fig06a.png", "fig06a_swatch.png", "fig07.png"]
    text = readme.read_text()
    assert "old" not in text and text.endswith("<!-- /gallery -->\n\nafter\n")
    row = next(line for line in text.splitlines() if "fig07.png" in line and "--time" in line)
    assert "32×24" in row and " spp" in row and "denoised" in row
    assert "not rendered at this quality yet" in next(line for line in text.splitlines() if "fig02" in line)
    assert "fig06a_swatch.png" in text and "the picture alone" in text  # the paper's companion, shown
    meta = make_gallery.png_metadata(out / "fig07.png")
    assert meta["time_limit"] is not None and meta["spp"] >= 1
    assert meta["machine"] == make_gallery._machine()  # the render times' machine, per picture
    assert f"Render times on {meta['machine']}, every core;" in text

    # a picture stopped half-way keeps its passes; the next run continues it with what is left of its budget
    import warpviz as wv

    real = wv.render
    stopped = []

    def stop_after_a_pass(scene, **kw):
        reports = []

        def on_pass(report):
            reports.append(report)
            if len(reports) == 2:
                stopped.append(report.spp)
                raise KeyboardInterrupt

        return real(scene, on_pass=on_pass, **kw)

    monkeypatch.setattr(wv, "render", stop_after_a_pass)
    assert make_gallery.main([*args, "--only", "fig02"]) == 130
    kept = wv.Image.open(work / "fig02.exr")
    assert not kept.completed and kept.metadata["spp"] == stopped[0] and not (out / "fig02.png").exists()
    monkeypatch.setattr(wv, "render", real)
    assert make_gallery.main([*args, "--only", "fig02"]) == 0
    done = wv.Image.open(work / "fig02.exr")
    assert done.completed and done.metadata["spp"] > stopped[0] and (out / "fig02.png").is_file()
    assert done.metadata["seconds"] == pytest.approx(0.5, abs=0.4)  # one budget over both runs

    # a picture that had its budget is kept, not rendered again
    before = (work / "fig04.exr").stat().st_mtime_ns
    assert make_gallery.main([*args, "--only", "fig04"]) == 0
    assert (work / "fig04.exr").stat().st_mtime_ns == before
    np.testing.assert_array_equal(wv.Image.open(work / "fig04.exr").rgb, wv.Image.open(work / "fig04.exr").rgb)


def test_the_render_times_name_each_pictures_machine():
    """A gallery re-rendered in part on another machine says which pictures' times are from which (the most common
    machine first); a picture from before the machine was recorded is said to have none."""
    a, b = {"machine": "A (2 cores)"}, {"machine": "B (2 cores)"}
    metas = {"fig02": a, "fig04": a, "fig07": b, "fig10a": b, "fig05": a, "fig08": {}, "fig09": None}
    assert make_gallery.machines_line(metas) == (
        "Render times on A (2 cores), every core (fig07 and fig10a on B (2 cores); fig08: machine not recorded); each "
        "picture's full-size file is linked.")
    assert make_gallery.machines_line({"fig02": {"machine": "A"}}) == (
        "Render times on A, every core; each picture's full-size file is linked.")


def test_the_companions_mark_what_the_paper_marks(tmp_path):
    """fig05: both images of the marked star found and marked, the primary the farther one; fig08: the
    inset lies inside the picture."""
    import gallery_companions as gc
    from PIL import Image

    import warpviz as wv

    scene = load_scene("fig05")
    img = wv.render(scene, width=160, height=120, spp=4, aovs=[])
    img.save(tmp_path / "fig05.exr")
    img.save(tmp_path / "fig05.png")
    out = gc.make_companion("fig05", scene, tmp_path / "fig05.png", tmp_path / "fig05.exr")
    assert out == tmp_path / "fig05_marked.png" and Image.open(out).size == (2 * 160 + 8, 120)
    found = gc.patches(gc._marked_star(np.asarray(img.rgb), scene.native()["environment"]["spots"][0]["color"]))
    assert len(found) >= 2  # primary and secondary images
    cx, cy = gc.project(scene.native(width=160, height=120)["camera"], [0, 0, 0])
    (x1, y1), (x2, y2) = (p.mean(axis=0) for p in found[:2])
    # on opposite sides of the hole: the secondary image lies across the centre from the primary
    assert (x1 - cx) * (x2 - cx) + (y1 - cy) * (y2 - cy) < 0
    assert gc.companion_path(tmp_path, "fig07") is None


def test_a_kept_picture_of_a_scene_that_has_changed_is_rendered_again(tmp_path):
    # the kept EXR is reused only while the scene is the one it was rendered from (its recorded digest)
    text = (ROOT / "scenes" / "fig04_einstein_ring.toml").read_text()
    path = tmp_path / "ring.toml"
    path.write_text(text)
    out, work, lines = tmp_path / "pictures", tmp_path / "work", []
    out.mkdir()
    work.mkdir()
    s = {"size": (8, 6), "spp": 1, "seconds": None, "denoise": False}
    make_gallery.render_picture(load_scene(path), "ring", s, out=out, work=work, log=lines.append)
    make_gallery.render_picture(load_scene(path), "ring", s, out=out, work=work, log=lines.append)
    assert "done" in lines[-1] and "kept" in lines[-1]  # unchanged: kept
    assert "fov = 40.0" in text
    path.write_text(text.replace("fov = 40.0", "fov = 41.0"))  # a wider view: another scene
    make_gallery.render_picture(load_scene(path), "ring", s, out=out, work=work, log=lines.append)
    assert any("the scene has changed since ring.exr was rendered; starting again" in line for line in lines)
    assert "kept" not in lines[-1]


def test_every_shipped_scene_has_a_picture_name_of_its_own():
    from warpviz.scene.catalog import shipped_scenes

    names = [make_gallery.short_name(p) for p in shipped_scenes()]
    assert len(names) == len(set(names))
    assert "caustics_glass_ball_hole" in names and "fig07" in names and "mitsuba" in names


def test_a_kept_picture_rendered_with_another_default_is_rendered_again(tmp_path, monkeypatch):
    # a picture that had its samples is kept only while today's settings would continue it: a default changed
    # since (here max_depth) makes it render again, as the renderer's own resume check says
    import importlib

    render_module = importlib.import_module("warpviz.render.render")
    out, work, lines = tmp_path / "pictures", tmp_path / "work", []
    out.mkdir()
    work.mkdir()
    s = {"size": (8, 6), "spp": 1, "seconds": None, "denoise": False}
    scene = load_scene("fig04")
    make_gallery.render_picture(scene, "ring", s, out=out, work=work, log=lines.append)
    make_gallery.render_picture(scene, "ring", s, out=out, work=work, log=lines.append)
    assert "kept" in lines[-1]
    depth = render_module.DEFAULT_OPTIONS["max_depth"]
    assert "max_depth" not in load_scene("fig04").native().get("render", {})
    monkeypatch.setitem(render_module.DEFAULT_OPTIONS, "max_depth", depth + 1)
    make_gallery.render_picture(scene, "ring", s, out=out, work=work, log=lines.append)
    assert any("ring.exr is not what today's settings render (" in line and "max_depth" in line for line in lines)
    assert "kept" not in lines[-1]
    assert make_gallery.png_metadata(out / "ring.png")["resume"]["settings"]["max_depth"] == depth + 1
