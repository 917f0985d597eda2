"""Rendering on a Dask cluster (warpviz/render/distributed.py): the image is the local one, bit for bit, for
any worker count and tile size; a lost worker, Ctrl-C, a time budget and resume behave as locally; the
scene's files stay on the client. The clusters are real (worker processes on this machine)."""

import os
import shutil
import signal
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

import warpviz as wv
from warpviz.cli import app
from warpviz.render.distributed import TileFilms, check_workers, tile_windows

distributed = pytest.importorskip("distributed")

SMALL = {"width": 40, "height": 30, "progress": None}
SCENES = Path(__file__).resolve().parents[1] / "scenes"


@pytest.fixture(scope="module")
def cluster2():
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0") as cl, \
            distributed.Client(cl) as client:  # fmt: skip
        yield cl, client


@pytest.fixture(scope="module")
def local_fig07():
    return wv.render("fig07", **SMALL, spp=6, threads=2)


def assert_same_image(a, b):
    np.testing.assert_array_equal(a.rgb, b.rgb)
    assert set(a.aovs) == set(b.aovs)
    for name in a.aovs:
        np.testing.assert_array_equal(a.aovs[name], b.aovs[name], err_msg=name)
    assert (a.metadata["spp"], a.metadata["passes"]) == (b.metadata["spp"], b.metadata["passes"])


def test_tiles_cover_the_window_once():
    tiles = tile_windows((3, 5, 50, 33), 16)
    cover = np.zeros((40, 60), dtype=int)
    for x, y, w, h in tiles:
        cover[y:y + h, x:x + w] += 1
    assert cover[5:38, 3:53].min() == 1 and cover.sum() == 50 * 33
    with pytest.raises(ValueError, match="tile must be a positive"):
        tile_windows((0, 0, 4, 4), 0)


@pytest.mark.parametrize("tile", [7, 16, 128])
def test_two_workers_give_the_local_image_bit_for_bit(cluster2, local_fig07, tile):
    _, client = cluster2
    img = wv.render("fig07", **SMALL, spp=6, client=client, tile=tile)
    assert_same_image(img, local_fig07)
    assert img.metadata["noise"] == pytest.approx(local_fig07.metadata["noise"], rel=1e-12)


def test_a_guided_render_on_two_workers_is_the_local_one(cluster2):
    """Path guiding's tree is trained once on the client and handed to every tile: the local image."""
    _, client = cluster2
    local = wv.render("fig07", width=24, height=18, progress=None, spp=2, threads=2, guide_training=2)
    img = wv.render("fig07", width=24, height=18, progress=None, spp=2, client=client, tile=8, guide_training=2)
    assert img.stats["guide_segments"] > 0
    assert_same_image(img, local)


def test_a_photon_render_on_two_workers_is_the_local_one(cluster2):
    """Each tile traces the same photon passes (a function of the seed and the sample index): the local image."""
    _, client = cluster2
    scene = "caustics_glass_ball_hole"
    local = wv.render(scene, width=24, height=18, progress=None, spp=2, threads=2, photons=500)
    img = wv.render(scene, width=24, height=18, progress=None, spp=2, client=client, tile=8, photons=500)
    assert img.stats["photon_segments"] > 0
    assert_same_image(img, local)
    # without a tile size, a tile per task slot (here the whole 24 x 18 window, within 128): each pass's photons
    # are traced once, as locally, where 8-pixel tiles traced them 9 times
    once = wv.render(scene, width=24, height=18, progress=None, spp=2, client=client, photons=500)
    assert_same_image(once, local)
    assert once.stats["photon_segments"] == local.stats["photon_segments"] < img.stats["photon_segments"]


def test_one_worker_and_a_curved_wormhole_room_also(local_fig07):
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=":0") as cl, \
            distributed.Client(cl) as client:  # fmt: skip
        assert_same_image(wv.render("fig07", **SMALL, spp=6, client=client, tile=16), local_fig07)
        local = wv.render("fig12", **SMALL, spp=3, threads=1, record_pixels=[[5, 5], [30, 20]])
        remote = wv.render("fig12", **SMALL, spp=3, client=client, tile=16, record_pixels=[[5, 5], [30, 20]])
        assert_same_image(remote, local)
        assert len(remote.rays) == len(local.rays) > 0  # the same paths, grouped by tile
        np.testing.assert_array_equal(np.sort(remote.rays.points, axis=0), np.sort(local.rays.points, axis=0))


def test_a_worker_killed_mid_render_still_gives_the_whole_image(cluster2, local_fig07):
    """After the second pass one worker process is killed (its tiles' films are lost with it): the
    scheduler runs their passes again from the films' lineage, on the other worker or a restarted one."""
    cl, client = cluster2
    killed = []

    def kill_one(report):
        if report.passes == 2 and not killed:
            pid = next(iter(client.run(os.getpid).values()))
            os.kill(pid, signal.SIGKILL)
            killed.append(pid)

    img = wv.render("fig07", **SMALL, spp=6, client=client, tile=8, on_pass=kill_one)
    assert killed and img.completed
    assert_same_image(img, local_fig07)
    client.wait_for_workers(2, timeout=60)


def test_a_worker_killed_mid_resume_still_gives_the_whole_image(cluster2, tmp_path):
    """A resumed render's tiles start from the saved film: after its first pass one worker is killed, and the
    lost tiles' passes run again from the films the scheduler keeps in their first tasks (scattered to one worker
    each, they were lost with it)."""
    cl, client = cluster2
    killed = []

    def kill_one(report):  # (after the resumed render's first pass, whatever its count of passes)
        if not killed:
            pid = next(iter(client.run(os.getpid).values()))
            os.kill(pid, signal.SIGKILL)
            killed.append(pid)

    part = wv.render("fig07", **SMALL, spp=2, threads=2).save(tmp_path / "part.exr")
    resumed = wv.render("fig07", **SMALL, spp=6, client=client, tile=8, resume=part, on_pass=kill_one)
    assert killed and resumed.completed and resumed.metadata["spp"] == 6
    local = wv.render("fig07", **SMALL, spp=6, threads=2, resume=part)
    np.testing.assert_array_equal(resumed.rgb, local.rgb)
    client.wait_for_workers(2, timeout=60)


def test_ctrl_c_keeps_the_finished_passes(cluster2):
    _, client = cluster2
    calls = []

    def progress(done, total):  # called as each of the 6 tiles finishes its pass
        calls.append(done)
        if len(calls) == stop_at:
            raise KeyboardInterrupt

    stop_at = 15  # inside the third pass
    img = wv.render("fig07", width=40, height=30, spp=64, client=client, tile=16, progress=progress)
    assert not img.completed and img.metadata["stopped_by"] == "interrupted"
    assert img.metadata["spp"] == 2 and img.metadata["passes"] == 2
    assert_same_image(img, wv.render("fig07", **SMALL, spp=2, threads=2))
    calls.clear()
    stop_at = 3  # inside the first pass: the finished tiles are kept, the others are empty
    first = wv.render("fig07", width=40, height=30, spp=64, client=client, tile=16, progress=progress)
    assert not first.completed and first.metadata["spp"] == 0
    assert 0 < np.count_nonzero(first.aovs["samples"]) < 40 * 30


def test_a_time_budget_a_noise_target_and_resume_work_on_a_cluster(cluster2, tmp_path):
    _, client = cluster2
    timed = wv.render("fig07", **SMALL, time_limit=1.5, client=client, tile=16)
    assert timed.metadata["stopped_by"] == "time" and timed.metadata["spp"] >= 1
    np.testing.assert_array_equal(timed.rgb, wv.render("fig07", **SMALL, spp=timed.metadata["spp"], threads=2).rgb)
    noisy = wv.render("fig03", **SMALL, noise_target=0.2, client=client, tile=16, aovs=[])
    alone = wv.render("fig03", **SMALL, noise_target=0.2, threads=2, aovs=[])
    assert noisy.metadata["stopped_by"] == "noise" and noisy.metadata["spp"] == alone.metadata["spp"]
    np.testing.assert_array_equal(noisy.rgb, alone.rgb)
    part = wv.render("fig07", **SMALL, spp=3, threads=2).save(tmp_path / "part.exr")
    resumed = wv.render("fig07", **SMALL, spp=9, client=client, tile=16, resume=part)
    direct = wv.render("fig07", **SMALL, spp=9, threads=2)
    assert resumed.metadata["spp"] == 9
    np.testing.assert_allclose(resumed.rgb, direct.rgb, rtol=1e-6, atol=1e-7)  # as a local resume: float32
    np.testing.assert_array_equal(resumed.aovs["samples"], direct.aovs["samples"])
    again = wv.render("fig07", **SMALL, spp=9, client=client, tile=16, resume=resumed)  # at its target already
    np.testing.assert_array_equal(again.rgb, resumed.rgb)


def test_the_scene_files_stay_on_the_client(cluster2, tmp_path):
    """The textures of a loaded scene travel inside it: with the files deleted, the cluster renders it."""
    _, client = cluster2
    shutil.copy(SCENES / "fig02_accretion_disk.toml", tmp_path / "disk.toml")
    shutil.copytree(SCENES / "textures", tmp_path / "textures")
    scene = wv.load_scene(tmp_path / "disk.toml")
    shutil.rmtree(tmp_path / "textures")
    local = wv.render(scene, **SMALL, spp=2, threads=2)
    assert_same_image(wv.render(scene, **SMALL, spp=2, client=client, tile=16), local)


def test_bad_cluster_arguments_are_named_before_any_work(cluster2):
    _, client = cluster2
    with pytest.raises(ValueError, match="needs client="):
        wv.render("fig07", **SMALL, spp=1, tile=16)
    with pytest.raises(ValueError, match="tile must be a positive"):
        wv.render("fig07", **SMALL, spp=1, client=client, tile=0)
    with pytest.raises(ValueError, match="dask.distributed.Client"):
        wv.render("fig07", **SMALL, spp=1, client="tcp://somewhere:8786")


def test_a_worker_with_another_warpviz_is_named():
    class FakeClient:
        scheduler = type("S", (), {"address": "tcp://sched:8786"})()

        def nthreads(self):
            return {"tcp://w1:1": 1}

        def run(self, fn):
            return {"tcp://w1:1": {"version": "0.0.1", "simd": wv.build_info()["simd"]}}

    with pytest.raises(ValueError, match=r"worker tcp://w1:1 runs warpviz 0\.0\.1"):
        check_workers(FakeClient())


def test_tile_films_gather_places_tiles_and_leaves_missing_ones_empty(cluster2):
    _, client = cluster2
    film = {"x0": 0, "y0": 0, "samples": np.ones((2, 2), np.int32), "rgb_sum": np.ones((2, 2, 3)), "depth": None}
    [fut] = client.scatter([{"film": film}])
    tiles = TileFilms(tiles=((0, 0, 2, 2), (2, 0, 2, 2)), futures=(fut, None), samples_total=4, window=(0, 0, 4, 2))
    out = tiles.gather(client)
    assert out["samples"].tolist() == [[1, 1, 0, 0], [1, 1, 0, 0]] and out["depth"] is None
    assert TileFilms(tiles=tiles.tiles, futures=(None, None), samples_total=0, window=(0, 0, 4, 2)).gather(client) is None


# ------------------------------------------------------------------------------------------ command line
def test_the_command_line_renders_on_local_workers(tmp_path):
    runner = CliRunner()
    out, ref = tmp_path / "w.exr", tmp_path / "l.exr"
    args = ["render", "fig07", "--size", "40x30", "--spp", "4", "-q"]
    res = runner.invoke(app, [*args, "--workers", "2", "--tile", "16", "-o", str(out)])
    assert res.exit_code == 0, res.output
    assert "Dask: 2 local workers, dashboard http" in res.output
    assert runner.invoke(app, [*args, "-o", str(ref)]).exit_code == 0
    np.testing.assert_array_equal(wv.Image.open(out).rgb, wv.Image.open(ref).rgb)


@pytest.mark.parametrize("extra, says", [
    (["--tile", "16"], "--tile is the tile size of a render on a Dask cluster"),
    (["--workers", "2", "--cluster", "tcp://127.0.0.1:1"], "not both"),
    (["--cluster", "tcp://127.0.0.1:1"], "cannot reach the Dask scheduler"),
])  # fmt: skip
def test_the_command_line_refuses_bad_cluster_flags(tmp_path, extra, says):
    res = CliRunner().invoke(app, ["render", "fig07", "--size", "8x6", "--spp", "1", "-o", str(tmp_path / "x.png"),
                                   *extra])  # fmt: skip
    assert res.exit_code == 2, res.output
    assert says in " ".join(res.output.split())
    assert not (tmp_path / "x.png").exists()


def test_a_film_on_the_cluster_is_the_local_film(cluster2, tmp_path):
    """warpviz animate --workers: each frame's tiles are tasks; a falling camera's frames (a moving observer's
    4-velocity in the scene) are the local ones bit for bit."""
    from warpviz.animate import camera_path, render_film

    sc = wv.scene.load_scene("fig07")
    cams = camera_path(sc, "fall", 2, position=[0.0, -45.0, 0.0], duration=20.0)
    _, client = cluster2
    render_film(sc, cams, tmp_path / "local", spp=2, width=24, height=18, threads=2)
    render_film(sc, cams, tmp_path / "dask", spp=2, width=24, height=18, client=client, tile=8)
    for k in range(2):
        a, b = (wv.Image.open(tmp_path / d / f"frame_{k:05d}.exr") for d in ("local", "dask"))
        np.testing.assert_array_equal(a.rgb, b.rgb)


def test_each_render_scatters_its_scene_under_a_key_of_its_own_and_hands_films_to_its_tasks(cluster2):
    """Scattered under the content's hash, two renders of one scene would share the scene's key, and a first
    render's future released as the second scatters makes the scheduler forget the data the second's tasks
    need: they fail with "lost dependencies" (dask/distributed#8576; a scatter, submit and release of the same
    scene in a loop fails so nearly every time). So each render scatters its scene under a key of its own. A
    resumed film's tiles are not scattered at all: they go to the first pass's tasks as their arguments, which the
    scheduler keeps (scattered to one worker each, a killed worker lost them for good)."""
    from warpviz.render.distributed import TiledPasses

    _, client = cluster2
    native = wv.scene.load_scene("fig03").native(width=8, height=6)
    options = {"crop": (0, 0, 8, 6), "threads": 1}
    a, b = (TiledPasses(client, native, options, tile=4) for _ in range(2))
    assert a.native.key != b.native.key
    film = wv.render("fig03", width=8, height=6, spp=1, aovs=[], progress=None)
    from warpviz.render.resume import film_from_image

    part = film_from_image(film, [])
    states = a._start(part)
    assert all(isinstance(t, dict) for t in states) and len(states) == len(a.tiles) == 4
    assert sum(int(t["film"]["samples"].sum()) for t in states) == int(part["samples"].sum()) >= 8 * 6
