"""One definition per render option (warpviz/options.py): the defaults, the checks of render() and of scene
files, the command line's help and the docs table all come from the table, and the core reads every key."""

import math
import re
from pathlib import Path

import pytest

import warpviz as wv
from warpviz._native import core
from warpviz.options import (DEFAULT_OPTIONS, DETAIL_SAMPLES, EDGE_SAMPLES, RENDER_OPTIONS, SCENE_OPTIONS, check_option,
                             options_markdown)
from warpviz.scene import SceneError, load_scene

ROOT = Path(__file__).resolve().parents[1]

SCENE = """version = 1
[metric]
name = "minkowski"
[camera]
position = [0, -5, 0]
look_at = [0, 0, 0]
[environment]
color = [0.5, 0.5, 0.5]
[render]
width = 8
height = 6
"""


def bad_value(o):
    """A value outside option o's range (or of the wrong kind)."""
    if o.kind == "bool":
        return 1
    if o.kind == "choice":
        return "nonsense"
    if o.kind == "int":
        return int(o.hi) + 1
    return -1.0 if o.lo == 0.0 else 2.0 * o.hi


def test_the_docs_table_is_the_options_table():
    page = (ROOT / "docs" / "render-options.md").read_text()
    assert page.endswith(options_markdown()), "regenerate docs/render-options.md from warpviz.options"


def test_render_starts_from_the_tables_defaults():
    assert {k: v for k, v in wv.render.__globals__["DEFAULT_OPTIONS"].items() if k in DEFAULT_OPTIONS} \
        == DEFAULT_OPTIONS  # fmt: skip
    img = wv.render(load_scene_text(SCENE), spp=1, progress=None)
    assert DEFAULT_OPTIONS["edge_samples"] is None  # derived: by denoise, or the resumed image's
    assert img.metadata["edge_samples"] == EDGE_SAMPLES == 8
    assert img.metadata["filter"] == "box" and img.metadata["filter_radius"] == 0.5


def load_scene_text(text, tmp=None):
    import tempfile

    folder = Path(tempfile.mkdtemp())
    (folder / "s.toml").write_text(text)
    return load_scene(folder / "s.toml")


@pytest.mark.parametrize("option", RENDER_OPTIONS, ids=[o.name for o in RENDER_OPTIONS])
def test_every_option_is_checked_alike_by_render_and_by_scene_files(option):
    value = bad_value(option)
    with pytest.raises(ValueError) as by_render:
        check_option(option.name, value)
    assert str(by_render.value).startswith(f"{option.name} must ")
    assert option.range_text() in str(by_render.value) or option.kind == "bool"
    scene = load_scene_text(SCENE)
    with pytest.raises(ValueError, match=re.escape(f"{option.name} must ")):
        wv.render(scene, progress=None, **{"spp": 1, option.name: value})
    if option.scene:
        text = SCENE + f"{option.name} = {value!r}\n".replace("'", '"')
        with pytest.raises(SceneError) as by_file:
            load_scene_text(text)
        assert f"render.{option.name}" in str(by_file.value) and "s.toml:" in str(by_file.value)
    # and a good value is taken from a scene file
    if option.scene and option.default is not None:
        good = option.default
        literal = str(good).lower() if isinstance(good, bool) else repr(good).replace("'", '"')
        assert load_scene_text(SCENE + f"{option.name} = {literal}\n").render_settings()[option.name] == good


def test_a_scene_may_set_the_options_it_could_not_before():
    text = SCENE + 'light_connection = "aimed"\nedge_samples = 2\nfilter = "gaussian"\npixel_sampler = "independent"\n'
    img = wv.render(load_scene_text(text), spp=1, progress=None)
    assert img.metadata["edge_samples"] == 2 and img.metadata["filter"] == "gaussian"
    assert {"light_connection", "edge_samples", "filter", "pixel_sampler"} <= set(SCENE_OPTIONS)


def test_the_core_reads_every_option_and_names_each_one_missing():
    native = load_scene_text(SCENE).native()
    options = {**DEFAULT_OPTIONS, "filter_radius": 0.5, "max_drift": 1e-4, "edge_samples": EDGE_SAMPLES,
               "detail_samples": DETAIL_SAMPLES, "sample_begin": 0, "threads": 1, "aovs": [], "crop": None}  # fmt: skip
    core.render(native, options)  # complete: renders
    for name in DEFAULT_OPTIONS:
        partial = {k: v for k, v in options.items() if k != name}
        with pytest.raises(ValueError, match=f"render option '{name}' is missing"):
            core.render(native, partial)


def test_the_flags_help_comes_from_the_table():
    from typer.testing import CliRunner

    from warpviz import cli

    text = " ".join(CliRunner().invoke(cli.app, ["render", "--help"], env={"COLUMNS": "400"}).output.split())
    assert ("In [1, 64]. Default: 8, or 32 in a denoised render (a resumed render: its image's) (or the scene's "
            "[render] edge_samples).") in text  # fmt: skip
    assert "One of 'lens', 'images', 'aimed'. Default: 'lens'" in text
    assert not math.isnan(DEFAULT_OPTIONS["tol"])


def test_flags_that_render_and_trace_share_are_one_definition():
    """A flag both commands take reads the same: same name, default, range and help (cli/flags.py)."""
    import typer.main

    from warpviz.cli import app

    commands = typer.main.get_command(app).commands
    params = {name: {p.name: p for p in commands[name].params} for name in ("render", "trace")}
    shared = set(params["render"]) & set(params["trace"]) - {"scene", "output", "spp"}  # these differ on purpose
    assert {"size", "threads", "seed", "flat", "paper", "exposure", "tonemap", "force", "quiet"} <= shared
    for name in shared:
        a, b = params["render"][name], params["trace"][name]
        facts = lambda p: (p.opts, p.default, p.help, p.min, p.max)  # noqa: E731
        assert facts(a) == facts(b), name
