"""tools/make_screenshots.py writes the docs' teaching-view screenshots off-screen."""

import importlib.util
from pathlib import Path

import pytest

pv = pytest.importorskip("pyvista")

ROOT = Path(__file__).resolve().parents[1]


def load_tool():
    spec = importlib.util.spec_from_file_location("make_screenshots", ROOT / "tools" / "make_screenshots.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_make_screenshots_writes_the_asked_shot(tmp_path, capsys):
    tool = load_tool()
    assert set(tool.SHOTS) == {"fig04", "fig07", "fig10d", "wormhole"}
    assert tool.main(["--only", "fig04", "--out", str(tmp_path), "--size", "400x200", "--spp", "1"]) == 0
    written = sorted(p.name for p in tmp_path.iterdir())
    assert written == ["view_fig04.png"]
    assert pv.read(tmp_path / "view_fig04.png").dimensions[:2] == (400, 200)
    assert "warpviz view fig04 --pixels 20,36 --flat-ray" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        tool.main(["--spp", "0", "--out", str(tmp_path)])


def test_the_docs_show_every_screenshot():
    tool = load_tool()
    docs = (ROOT / "docs" / "classroom.md").read_text() + (ROOT / "README.md").read_text()
    for name in tool.SHOTS:
        image = ROOT / "docs" / "images" / f"view_{name}.png"
        assert image.is_file(), image
        assert f"images/view_{name}.png" in docs, name
