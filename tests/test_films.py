"""Films (warpviz.animate, `warpviz animate`): camera paths on geodesics against closed forms, and frames
that are deterministic, resumable and encoded."""

import dataclasses
import json
import math

import numpy as np
import pytest
from PIL import Image as PILImage
from scipy.optimize import brentq
from typer.testing import CliRunner

import warpviz as wv
from warpviz.animate import FilmMismatch, camera_path, frame_seed, render_film
from warpviz.cli import app
from warpviz.scene import scene_from_dict


def _scene(camera: dict, metric=None, **render) -> object:
    data = {"version": 1, "metric": metric or {"name": "schwarzschild", "mass": 1.0}, "camera": camera,
            "environment": {"color": [0.2, 0.3, 0.5], "spots": [{"direction": [1, 0, 0], "radius": 0.3}]},
            "render": {"width": 16, "height": 12, "spp": 2, **render}}  # fmt: skip
    return scene_from_dict(data, base_dir=".")


def test_fall_path_follows_the_cycloid_of_radial_free_fall():
    """From rest at r0: r = r0 (1 + cos eta) / 2, tau = sqrt(r0^3 / 8M) (eta + sin eta), through the horizon;
    each frame's camera is held by the falling observer (its 4-velocity: dr/dtau of the cycloid)."""
    r0 = 10.0
    cams = camera_path(_scene({"position": [0.0, -r0, 0.0]}), "fall", 12)
    assert 8 <= len(cams) <= 12
    for c in cams:
        eta = brentq(lambda e: math.sqrt(r0**3 / 8) * (e + math.sin(e)) - c["tau"], 0.0, math.pi)
        r = np.linalg.norm(c["position"])
        assert r == pytest.approx(r0 * (1 + math.cos(eta)) / 2, rel=1e-9, abs=1e-9)
        assert c["observer"]["kind"] == "given"
    assert np.linalg.norm(cams[-1]["position"]) < 2.0  # inside the horizon at the end
    # the observer is exactly the free fall from rest at r0 at each frame
    from warpviz.spacetime.observers import observer

    for c in cams[1:4]:
        fall = observer(wv.Schwarzschild(mass=1.0), c["position"], "free_fall", fall_from=r0)
        np.testing.assert_allclose(c["observer"]["u"], fall.u, rtol=1e-8, atol=1e-9)


def test_orbit_path_is_one_revolution_at_keplers_rate():
    r = 8.0
    cams = camera_path(_scene({"position": [r, 0.0, 0.0], "look_at": [0, 0, 0]}), "orbit", 8)
    assert len(cams) == 8
    angles = [math.atan2(c["position"][1], c["position"][0]) for c in cams]
    np.testing.assert_allclose(np.unwrap(angles), np.arange(8) * 2 * math.pi / 8, atol=1e-8)
    for c in cams:
        assert np.linalg.norm(c["position"]) == pytest.approx(r, rel=1e-9)
    # proper period 2 pi / (Omega u^t), Omega = sqrt(M / r^3), u^t = 1 / sqrt(1 - 3M/r)
    period = 2 * math.pi * math.sqrt(r**3) * math.sqrt(1 - 3 / r)
    assert cams[1]["tau"] * 8 == pytest.approx(period, rel=1e-12)


def test_wormhole_flight_comes_out_on_the_other_sheet():
    cam = {"position": [0.0, -6.0, 0.0], "velocity": [0.0, 0.5, 0.0]}
    cams = camera_path(_scene(cam, metric={"name": "ellis", "throat": 2.0}), "fall", 10, look="ahead")
    assert cams[0]["sheet"] == 1 and cams[-1]["sheet"] == -1
    assert np.linalg.norm(cams[-1]["position"]) == pytest.approx(6.0, rel=0.02)
    # looking ahead: towards the throat at first, away from it on the far side
    assert cams[0]["look_at"][1] > cams[0]["position"][1] and cams[-1]["look_at"][1] < cams[-1]["position"][1]


def test_speed_launches_a_flight_and_position_moves_the_start():
    sc = _scene({"position": [0.0, -6.0, 0.0], "look_at": [0, 0, 0]}, metric={"name": "ellis", "throat": 2.0})
    cams = camera_path(sc, "fall", 5, speed=0.5, position=[0.0, -8.0, 0.0])
    assert cams[0]["position"] == [0.0, -8.0, 0.0] and cams[-1]["sheet"] == -1
    # no gravity in the massless Ellis wormhole: the speed relative to the static observers stays 0.5
    from warpviz.spacetime.observers import observer

    ellis = wv.EllisWormhole(throat=2.0)
    for c in cams[1:]:
        moving = observer(ellis, c["position"], "given", u=c["observer"]["u"], sheet=c["sheet"])
        assert moving.speed_relative_to(observer(ellis, c["position"], sheet=c["sheet"])) == pytest.approx(0.5, rel=1e-9)
    with pytest.raises(ValueError, match="use it with path 'fall'"):
        camera_path(sc, "orbit", 3, speed=0.5)


def test_path_errors_name_the_reason(tmp_path):
    with pytest.raises(ValueError, match="no circular orbit"):
        camera_path(_scene({"position": [2.5, 0.0, 0.0]}), "orbit", 4)  # inside the photon sphere
    with pytest.raises(ValueError, match="does not move"):
        camera_path(_scene({"position": [0, -6.0, 0]}, metric={"name": "ellis", "throat": 2.0}), "fall", 4)
    with pytest.raises(ValueError, match="orbit, fall, dolly"):
        camera_path(_scene({"position": [0, -6.0, 0]}), "spiral", 4)
    keys = tmp_path / "k.toml"
    keys.write_text("[[key]]\ntime = 0\n[[key]]\ntime = 0\n")
    with pytest.raises(wv.scene.SceneError, match=r"key\[1\].time"):
        camera_path(_scene({"position": [0, -6.0, 0]}), keys, 4)


def test_keyframes_interpolate_linearly(tmp_path):
    keys = tmp_path / "k.toml"
    keys.write_text("[[key]]\ntime = 0\nposition = [0, -20, 0]\n[[key]]\ntime = 2\nposition = [0, -10, 4]\nfov = 60\n")
    cams = camera_path(_scene({"position": [0, -30.0, 0]}), keys, 5)
    np.testing.assert_allclose(cams[2]["position"], [0, -15, 2])
    assert cams[2]["fov"] == pytest.approx(50.0)


def test_frames_are_deterministic_resumable_and_refuse_another_film(tmp_path):
    sc = _scene({"position": [0.0, -10.0, 0.0], "look_at": [0, 0, 0]})
    cams = camera_path(sc, "orbit", 3)
    out = tmp_path / "film"
    calls = []
    render_film(sc, cams, out, spp=2, on_frame=lambda k, n, rendered: calls.append(rendered))
    assert calls == [True, True, True]
    first = np.asarray(PILImage.open(out / "frame_00001.png"))
    # a frame equals a render of its own camera with the frame's seed
    own = wv.render(dataclasses.replace(sc, camera={k: v for k, v in cams[1].items() if k != "tau"}), spp=2,
                    seed=frame_seed(0, 1))
    exr = wv.Image.open(out / "frame_00001.exr")
    np.testing.assert_array_equal(exr.rgb, own.rgb)
    # resume: a deleted frame is rendered again, the others kept, bit for bit
    (out / "frame_00001.png").unlink()
    calls.clear()
    render_film(sc, cams, out, spp=2, on_frame=lambda k, n, rendered: calls.append(rendered))
    assert calls == [False, True, False]
    np.testing.assert_array_equal(np.asarray(PILImage.open(out / "frame_00001.png")), first)  # pixels, not timings
    with pytest.raises(FilmMismatch, match="spp"):
        render_film(sc, cams, out, spp=3)
    assert json.loads((out / "film.json").read_text())["settings"]["spp"] == 2


def test_animate_cli_writes_a_gif_and_an_mp4(tmp_path):
    pytest.importorskip("imageio_ffmpeg", reason="mp4 needs warpviz[film]")
    scene = tmp_path / "s.toml"
    scene.write_text('version = 1\n[metric]\nname = "schwarzschild"\nmass = 1.0\n[camera]\nposition = [0, -12, 0]\n'
                     '[environment]\ncolor = [0.3, 0.3, 0.4]\n[render]\nwidth = 16\nheight = 12\nspp = 1\n')  # fmt: skip
    runner = CliRunner()
    for name in ("f.gif", "f.mp4"):
        res = runner.invoke(app, ["animate", str(scene), "--path", "fall", "--frames", "3", "-o", str(tmp_path / name),
                                  "--quiet"])  # fmt: skip
        assert res.exit_code == 0, res.output
        assert (tmp_path / name).stat().st_size > 100
    import imageio.v3 as iio

    assert iio.imread(tmp_path / "f.gif", index=None).shape[:3] == (3, 12, 16)
    # an odd size cannot be an mp4; a bad path is exit 2 before any frame
    res = runner.invoke(app, ["animate", str(scene), "--size", "15x12", "-o", str(tmp_path / "g.mp4"), "-q"])
    assert res.exit_code == 2 and "even width" in res.output
    res = runner.invoke(app, ["animate", str(scene), "--path", "spiral", "-o", str(tmp_path / "h.gif"), "-q"])
    assert res.exit_code == 2 and not (tmp_path / "h_frames").exists()
    # a file warpviz did not write is not replaced without --force; its own film is (resumed: nothing to render)
    (tmp_path / "mine.gif").write_bytes(b"precious")
    res = runner.invoke(app, ["animate", str(scene), "-o", str(tmp_path / "mine.gif"), "-q"])
    assert res.exit_code == 2 and "--force" in res.output and (tmp_path / "mine.gif").read_bytes() == b"precious"
    res = runner.invoke(app, ["animate", str(scene), "--path", "fall", "--frames", "3", "-o", str(tmp_path / "f.gif")])
    assert res.exit_code == 0 and "3 already on disk" in res.output
