"""tools/make_gallery.py's quality settings (nothing is rendered here: the classroom gallery takes hours)."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tools"))

import make_gallery  # noqa: E402
from warpviz.scene import load_scene  # noqa: E402

ROOMS = {"fig03", "fig07", "fig08", "fig10a", "fig10b", "fig10c", "fig10d", "fig10e", "fig12", "fig13"}


@pytest.mark.parametrize("name", ["fig02", "fig04", "fig07", "fig10e", "fig11a", "fig13"])
def test_classroom_quality_is_classroom_sized_with_rooms_at_many_samples(name):
    scene = load_scene(name)
    assert make_gallery.is_room(scene) == (name in ROOMS)
    s = make_gallery.settings(scene, "classroom", spp=None, denoise=None)
    assert s["size"][0] >= 640 and s["size"][1] >= 480
    assert s["spp"] == (1024 if name in ROOMS else 64) and s["denoise"] is False
    assert make_gallery.settings(scene, "classroom", spp=8, denoise=True) == {"size": (640, 480), "spp": 8,
                                                                             "denoise": True}
    ci = make_gallery.settings(scene, "ci", spp=None, denoise=None)
    assert ci == {"size": None, "spp": None, "denoise": False}  # each scene's own: what CI renders


def test_commands_are_the_ones_a_user_types():
    s = {"size": (640, 480), "spp": 1024, "denoise": True}
    assert (make_gallery.command("scenes/fig07_schwarzschild_cornell.toml", "fig07", s)
            == "warpviz render scenes/fig07_schwarzschild_cornell.toml --size 640x480 --spp 1024 --denoise -o fig07.png")
    assert (make_gallery.command("scenes/fig02_accretion_disk.toml", "fig02", {"size": None, "spp": None, "denoise": False})
            == "warpviz render scenes/fig02_accretion_disk.toml -o fig02.png")  # the README's ci table, unchanged
