"""The benchmark scripts' quick modes: they run, write the documented CSV columns, and their error
measurements behave (errors shrink with the tolerance). Timings are reported, never asserted."""

import csv
import importlib.util
import math
import sys
from pathlib import Path

import numpy as np
import pytest

import warpviz as wv

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))

import bench_render  # noqa: E402
import bench_work_precision  # noqa: E402
from _common import pareto_front, time_at_error  # noqa: E402


def read_csv(path: Path) -> list[dict]:
    with path.open() as f:
        return list(csv.DictReader(f))


@pytest.fixture(scope="module")
def work_precision(tmp_path_factory):
    out = tmp_path_factory.mktemp("wp")
    rows = bench_work_precision.main(["--quick", "--no-plots", "--out", str(out)])
    return rows, out


@pytest.fixture(scope="module")
def render(tmp_path_factory):
    out = tmp_path_factory.mktemp("render")
    result = bench_render.main(["--quick", "--no-plots", "--no-mitsuba", "--out", str(out)])
    return result, out


def test_work_precision_csv_has_every_metric_stepper_and_column(work_precision):
    rows, out = work_precision
    table = read_csv(out / "work_precision.csv")
    assert list(table[0]) == bench_work_precision.COLUMNS
    assert len(table) == len(rows)
    assert {r["metric"] for r in table} == {"schwarzschild", "kerr_a0.5", "kerr_a0.9", "kerr_a0.998", "ellis"}
    assert {(r["stepper"], r["variant"]) for r in table} == {
        ("dopri5", "adaptive"), ("dop853", "adaptive"), ("rk4", "seed step 1 M"), ("rk4", "matched step")}
    for r in rows:
        assert r["geodesics_per_s_per_core"] > 0 and r["mean_steps"] > 0
        assert r["status_mismatch"] == 0  # every ray ends as the reference's does
        assert 0 < r["error"] < 0.01, r


def test_dopri5_errors_decrease_with_tolerance(work_precision):
    rows, _ = work_precision
    for metric in {r["metric"] for r in rows}:
        sweep = sorted((r["tol"], r["error"]) for r in rows if r["metric"] == metric and r["stepper"] == "dopri5")
        tols, errors = zip(*sweep)
        assert tols == (1e-10, 1e-8, 1e-6, 1e-4)
        # tighter tolerance, strictly smaller error, and 1e6 in tolerance buys at least 1e4 in error
        assert all(a < b for a, b in zip(errors, errors[1:])), (metric, errors)
        assert errors[0] < 1e-4 * errors[-1], (metric, errors)


def test_conserved_quantities_drift_less_at_tighter_tolerance(work_precision):
    rows, _ = work_precision
    for metric in {r["metric"] for r in rows}:
        drift = {r["tol"]: r["drift_conserved"] for r in rows if r["metric"] == metric and r["stepper"] == "dopri5"}
        assert 0 < drift[1e-10] < 1e-3 * drift[1e-4], (metric, drift)
    for spin in ("0.5", "0.9", "0.998"):
        drift = {r["tol"]: r for r in rows if r["metric"] == f"kerr_a{spin}" and r["stepper"] == "dopri5"}
        assert drift[1e-10]["drift_conserved"] < 1e-3 * drift[1e-4]["drift_conserved"]
        assert drift[1e-10]["drift_Q"] < 1e-8 and drift[1e-10]["drift_Lz"] < 1e-8
        assert drift[1e-10]["drift_E"] == 0.0  # p_t is a state variable and H does not depend on t


def test_rk4_errors_follow_the_halving_rule(work_precision):
    """rk4's step near the mass is tol^(1/4) r: its error falls about as fast as the tolerance."""
    rows, _ = work_precision
    for metric in ("schwarzschild", "ellis"):
        err = {r["tol"]: r["error"] for r in rows if r["metric"] == metric and r["variant"] == "seed step 1 M"}
        assert 1e-3 < err[1e-6] / err[1e-4] < 0.1


def test_speedup_columns_interpolate_rk4_at_dopri5_error(work_precision):
    rows, _ = work_precision
    row = next(r for r in rows if r["metric"] == "schwarzschild" and r["stepper"] == "dopri5" and r["tol"] == 1e-6)
    rk4 = [r for r in rows if r["metric"] == "schwarzschild" and r["stepper"] == "rk4"]
    # (the benchmark's pool: rk4 runs whose statuses all match; with the others the Pareto front, and so the
    # interpolated time, depends on how the timings of a run that disagrees fall on a loaded machine)
    pool = [r for r in rk4 if r["status_mismatch"] == 0]
    expected = time_at_error([r["us_per_geodesic"] for r in pool], [r["error"] for r in pool], row["error"])
    # (NaN, no extrapolation, where the error lies outside rk4's Pareto front: on a loaded machine a noisy timing
    # can drop rk4's least accurate run from the front)
    assert row["speedup_vs_rk4"] == pytest.approx(expected / row["us_per_geodesic"], nan_ok=True)
    assert all(math.isnan(r["speedup_vs_rk4"]) for r in rk4)


def test_time_at_error_interpolates_log_log_on_the_pareto_front():
    times, errors = [1.0, 2.0, 3.0, 4.0, 100.0], [1e-2, 1e-4, 1e-3, 1e-6, 1e-5]  # 3.0 and 100.0 are dominated
    assert pareto_front(times, errors)[0].tolist() == [1.0, 2.0, 4.0]
    assert time_at_error(times, errors, 1e-4) == pytest.approx(2.0)
    assert time_at_error(times, errors, 1e-5) == pytest.approx(2.0 * math.sqrt(2.0))  # halfway in log e
    assert math.isnan(time_at_error(times, errors, 1e-7)) and math.isnan(time_at_error(times, errors, 1e-1))


def test_render_csvs_have_their_columns(render):
    result, out = render
    expected = {
        "render_throughput.csv": ["scene", "light_sampling", "samples_per_s_per_core", "curved_over_flat"],
        "render_light_connection.csv": ["scene", "estimator", "spp", "cpu_s", "rel_rmse", "mse_times_cpu_s"],
        "render_light_connection_summary.csv": ["scene", "brute_force_time_for_equal_error", "rmse_ratio_at_equal_time",
                                                "light_segments_reaching_light"],
        "render_work_precision.csv": ["scene", "stepper", "tol", "cpu_s", "samples_per_s_per_core", "rel_rmse",
                                      "rel_mae"],
        "render_fig07_extrapolation.csv": ["samples_per_s_per_core", "extrapolated_hours_all_cores",
                                           "extrapolated_core_hours"],
    }
    for name, columns in expected.items():
        table = read_csv(out / name)
        assert table and set(columns) <= set(table[0]), name
    assert not (out / "render_mitsuba.csv").exists()
    tp = result["throughput"]
    assert {r["scene"] for r in tp} == {"flat", "schwarzschild", "kerr_a0.9", "ellis"}
    for r in tp:
        assert r["samples_per_s_per_core"] > 0
        assert (r["steps_per_sample"] == 0) == (r["scene"] == "flat")  # flat rays are straight lines
    f7 = result["fig07"][0]
    assert f7["extrapolated_core_hours"] == pytest.approx(f7["target_samples"] / f7["samples_per_s_per_core"] / 3600)


def test_render_error_shrinks_with_tolerance_and_noise_with_spp(render):
    result, _ = render
    wp = {r["tol"]: r["rel_rmse"] for r in result["work_precision"] if r["stepper"] == "dopri5"}
    assert wp[1e-8] < 1e-2 * wp[1e-4]  # same seed and spp: only the geodesics' error is left
    for scene in ("flat", "schwarzschild"):
        for est in ("light connection", "brute force"):
            rmse = {r["spp"]: r["rel_rmse"] for r in result["light_connection"]
                    if r["scene"] == scene and r["estimator"] == est}  # fmt: skip
            assert rmse[8] < rmse[2], (scene, est, rmse)
    flat = next(r for r in result["light_summary"] if r["scene"] == "flat")
    assert flat["brute_force_time_for_equal_error"] > 3  # the light connection pays off in the flat room
    assert flat["light_segments_reaching_light"] == 1.0  # nothing stands between the walls and the lamp
    # the light margin is compared where it acts: in curved rooms (flat proxies are exact)
    assert {r["scene"] for r in result["light_connection"] if r["estimator"] == "no margin"} == {"schwarzschild"}
    curved = next(r for r in result["light_summary"] if r["scene"] == "schwarzschild")
    assert np.isfinite(curved["no_margin_time_for_equal_error"]) and np.isnan(flat["no_margin_time_for_equal_error"])


@pytest.mark.skipif(importlib.util.find_spec("mitsuba") is None, reason="mitsuba is not installed")
def test_mitsuba_renders_the_same_room(tmp_path):
    cfg = dict(bench_render.QUICK["mitsuba"], spp=16, min_cpu=0.0)
    rows = bench_render.mitsuba_comparison(cfg, threads=1)
    assert [r["renderer"] for r in rows] == ["warpviz", "mitsuba"]
    wv_row, mi_row = rows
    # same scene, same estimator family: mean radiance agrees within Monte Carlo noise; neither image is
    # mirrored (red wall on the left, green on the right)
    assert mi_row["mean_radiance"] == pytest.approx(wv_row["mean_radiance"], rel=0.1)
    for r in rows:
        assert r["left_third_red_minus_green"] > 0.01 and r["right_third_green_minus_red"] > 0.01, r
        assert r["samples_per_s_per_core"] > 0


@pytest.mark.slow
def test_plots_are_written(tmp_path):
    pytest.importorskip("matplotlib")
    bench_work_precision.main(["--quick", "--out", str(tmp_path)])
    bench_render.main(["--quick", "--no-mitsuba", "--out", str(tmp_path)])
    for name in ("work_precision.png", "render_throughput.png", "render_light_connection.png",
                 "render_work_precision.png"):
        assert (tmp_path / name).stat().st_size > 10_000, name


def test_skips_benchmark_reports_every_shortcut(tmp_path):
    import bench_skips

    assert bench_skips.main(["--quick", "--out", str(tmp_path)]) == 0
    rows = read_csv(tmp_path / "skips.csv")
    assert [r["shortcut"].split()[0] for r in rows] == ["flat", "no", "no", "far-field", "Kerr:", "pilots"]
    for r in rows:
        assert float(r["cpu_s_without"]) > 0 and float(r["cpu_s_with"]) > 0
        assert math.isclose(float(r["speedup"]), float(r["cpu_s_without"]) / float(r["cpu_s_with"]), rel_tol=1e-4)


def test_light_connection_benchmark_quick_mode(tmp_path):
    import bench_light_connection

    rows = bench_light_connection.main(["--quick", "--rooms", "fig07,fig07 flat", "--out", str(tmp_path)])
    table = read_csv(tmp_path / "light_connection.csv")
    assert len(table) == len(rows)
    only = bench_light_connection.ONLY_IN
    assert {r["estimator"] for r in rows if r["room"] == "fig07"} == {
        e for e in bench_light_connection.ESTIMATORS if "fig07" in only.get(e, {"fig07"})}
    assert "images" in only and "fig07" not in only["images"]
    for r in rows:
        assert r["cpu_s"] > 0 and r["rel_mse"] > 0 and r["efficiency"] > 0
        assert 0 <= r["unsampled_light_hits"] <= r["light_hits"]
        assert r["room"] != "fig07 flat" or r["unsampled_light_hits"] == 0  # (flat: every direction is drawn)
        if r["room"] == "fig07" and r["max_depth"] == "scene":
            assert r["over_brute"] > 0 and r["over_seed"] > 0 and r["flat_over_this"] > 0


def test_light_connection_benchmark_renders_a_room_from_a_scene_file(tmp_path):
    """--scene ROOM=FILE renders the room (here its flat companion) from that file, and names it in the rows; a
    room it does not know or a file that is not there stops it before any render."""
    import bench_light_connection

    from warpviz.scene.catalog import resolve_scene

    scene = tmp_path / "fig07_then.toml"
    scene.write_text(resolve_scene("fig07").read_text().replace("fov = 58.0", "fov = 60.0"))
    rows = bench_light_connection.main(["--quick", "--rooms", "fig07 flat", "--scene", f"fig07={scene}",
                                        "--out", str(tmp_path)])  # fmt: skip
    assert {r["scene"] for r in rows} == {"fig07_then.toml"} and all(r["rel_mse"] > 0 for r in rows)
    for bad in (f"fig99={scene}", "fig07=" + str(tmp_path / "missing.toml"), str(scene)):
        with pytest.raises(SystemExit, match="--scene"):
            bench_light_connection.main(["--quick", "--rooms", "fig07 flat", "--scene", bad])


def test_mitsuba_cornell_quick(tmp_path):
    """The comparison on Mitsuba's own box runs and writes both measurements (needs pip install mitsuba)."""
    pytest.importorskip("mitsuba")
    import bench_mitsuba_cornell

    rows = bench_mitsuba_cornell.main(["--quick", "--out", str(tmp_path)])
    assert [r["measure"] for r in rows] == ["speed", "speed", "radiance"]
    assert rows[0]["warpviz_over_mitsuba_min"] > 0 and rows[2]["blocks"] == 16
    assert (tmp_path / "mitsuba_cornell.csv").is_file()


@pytest.mark.skipif(importlib.util.find_spec("pyoidn") is None,
                    reason="pyoidn (Intel Open Image Denoise) is not installed: pip install 'warpviz[denoise]'")
def test_denoise_benchmark_quick_mode(tmp_path):
    import bench_denoise

    rows = bench_denoise.main(["--quick", "--out", str(tmp_path)])
    table = read_csv(tmp_path / "denoise.csv")
    assert [int(r["spp"]) for r in table] == [1, 16] == [r["spp"] for r in rows]
    for r in rows:
        assert r["cpu_s_render"] > 0 and r["cpu_s_denoise"] > 0 and r["noisy_rel_mse"] > 0
        assert r["noisy_rel_mse_equal_time"] < r["noisy_rel_mse"]
        assert r["gain_equal_time"] == pytest.approx(r["noisy_rel_mse_equal_time"] / r["denoised_rel_mse"])
    assert rows[1]["noisy_rel_mse"] < rows[0]["noisy_rel_mse"]  # more samples, less noise


def test_edge_samples_benchmark_quick_mode(tmp_path):
    import bench_edge_samples

    rows = bench_edge_samples.main(["--quick", "--scenes", "fig04", "--out", str(tmp_path)])
    assert [r["edge_samples"] for r in rows] == [1, 2, 4, 8] == [int(r["edge_samples"]) for r in
                                                                  read_csv(tmp_path / "edge_samples.csv")]
    assert rows[0]["edge_pixels"] == 0 < rows[-1]["edge_pixels"] and rows[0]["over_off"] == 1.0
    assert all(r["rel_mse"] > 0 and r["cpu_s"] > 0 for r in rows)


def test_path_guiding_benchmark_quick_mode(tmp_path):
    import bench_path_guiding

    rows = bench_path_guiding.main(["--quick", "--rooms", "mitsuba", "--out", str(tmp_path)])
    assert [r["guide_training"] for r in rows] == [0, 2] == [int(r["guide_training"]) for r in
                                                          read_csv(tmp_path / "path_guiding.csv")]
    assert rows[0]["mse_over_off"] == 1.0 and all(r["rel_mse_mean"] > 0 and r["seconds_mean"] > 0 for r in rows)


def test_caustics_benchmark_quick_mode_builds_its_reference_in_resumable_pieces(tmp_path):
    import bench_caustics

    rows = bench_caustics.main(["--quick", "--rooms", "glass_ball", "--out", str(tmp_path), "--ref-chunk", "16"])
    assert [r["photons"] for r in rows] == [0, 2000] == [int(r["photons"]) for r in read_csv(tmp_path / "caustics.csv")]
    assert rows[0]["mse_over_base"] == 1.0 and all(r["seconds_mean"] > 0 for r in rows)
    ref = tmp_path / "caustics-quick-references" / "caustics-glass_ball-16x12-pt-seed1000.exr"
    assert wv.Image.open(ref).metadata["spp"] == 32  # (two pieces of 16)


@pytest.mark.skipif(importlib.util.find_spec("pyoidn") is None,
                    reason="pyoidn (Intel Open Image Denoise) is not installed: pip install 'warpviz[denoise]'")
def test_time_to_clean_benchmark_quick_mode_builds_its_reference_in_pieces(tmp_path):
    import bench_time_to_clean

    cache = tmp_path / "refs"
    # a target no second of rendering reaches, so each run adds to the reference (at least one pass)
    args = ["--quick", "--scenes", "fig07", "--ref-spp", "100000", "--out", str(tmp_path), "--cache", str(cache)]
    bench_time_to_clean.main(args)
    first = wv_spp(cache)
    summary = bench_time_to_clean.main(args)  # the reference grows by another second per half
    assert wv_spp(cache) > first
    rows = read_csv(tmp_path / "time_to_clean.csv")
    assert {r["method"] for r in rows} == {"noisy", "denoised"} and {int(r["spp"]) for r in rows} == {1, 16}
    noisy = sorted((int(r["spp"]), float(r["rel_mse"])) for r in rows if r["method"] == "noisy")
    # more samples, less error: one seed each, so 16x the samples (at 4x, seed 1's 4 spp holds a firefly as large as
    # its 1 spp's whole error: 0.12 both, against ~0.04 from seeds 2, 4, 5 and 6)
    assert noisy[1][1] < noisy[0][1]
    assert {s["method"] for s in summary} == {"noisy", "denoised"}
    assert all(s["how"] in ("interpolated", "extrapolated", "reached by the first run", "not reached") for s in summary)
    assert all(float(r["rel_mse_se"]) > 0 and float(r["rel_mse_off_lights_se"]) > 0 for r in rows)
    assert all(0 < int(r["light_pixels"]) < 24 * 18 for r in rows)  # fig07's lamp is in view
    assert {(s["method"], s["pixels"]) for s in summary} == {(m, p) for m in ("noisy", "denoised")
                                                              for p in ("all", "off lights")}  # fmt: skip
    before = wv_spp(cache)
    assert bench_time_to_clean.main([*args, "--reference-only"]) == []  # only the references grow
    assert wv_spp(cache) > before


def test_time_to_clean_reference_subtracts_its_own_noise_without_bias():
    """A reference as noisy as the image still measures the image's error: the halves' difference takes the
    reference's noise out, pixel by pixel, and the standard error covers what is left."""
    from _common import Reference

    rng = np.random.default_rng(7)
    truth = rng.uniform(0.5, 2.0, size=(120, 160, 3))
    sigma_ref, sigma_img = 0.3 * truth, 0.1 * truth  # heteroscedastic, the reference 9x the image's MSE
    ref = Reference(truth + sigma_ref * rng.standard_normal(truth.shape),
                                        truth + sigma_ref * rng.standard_normal(truth.shape), spp=8)
    image = truth + sigma_img * rng.standard_normal(truth.shape)
    exact = float(np.mean(sigma_img**2)) / float(np.mean(truth)) ** 2
    err, se = ref.rel_mse(image)
    assert abs(err - exact) < 4 * se and se < 0.1 * exact
    assert abs(ref.noise - float(np.mean(sigma_ref**2)) / 2 / float(np.mean(truth)) ** 2) < 0.05 * ref.noise


def wv_spp(cache: Path) -> int:
    import warpviz as wv

    return sum(int(wv.Image.open(p).metadata["spp"]) for p in sorted(cache.glob("*.exr")))


def test_dask_benchmark_quick_mode(tmp_path):
    """The cluster benchmark runs, checks the images are identical and writes every run's wall time."""
    pytest.importorskip("distributed")
    import bench_dask

    assert bench_dask.main(["--quick", "--workers", "2", "--out", str(tmp_path)]) == 0
    rows = read_csv(tmp_path / "dask.csv")
    assert {r["run"] for r in rows} == {"local", "dask", "dask-tiles", "task-cost"}
    assert all(float(r["wall_s"]) > 0 for r in rows)
    assert {int(r["tasks"]) for r in rows if r["run"] == "task-cost"} == {216, 2}


def test_line_element_benchmark_runs_the_generated_and_the_built_in_metric(tmp_path):
    import shutil

    if not (shutil.which("c++") or shutil.which("g++")):
        pytest.skip("no C++ compiler on this machine")
    import bench_line_element

    assert bench_line_element.main(["--metrics", "schwarzschild", "--out", str(tmp_path)]) == 0
    [row] = read_csv(tmp_path / "line_element.csv")
    assert row["metric"] == "schwarzschild" and float(row["ratio_double"]) > 0 and float(row["ratio_lanes"]) > 0


def test_gravity_cost_benchmark_times_every_variant(tmp_path):
    import bench_gravity_cost

    assert bench_gravity_cost.main(["--quick", "--rooms", "fig07", "--out", str(tmp_path)]) == 0
    rows = {r["variant"]: r for r in read_csv(tmp_path / "gravity_cost.csv")}
    assert set(rows) == {"flat", "integrate", "closed_form"}
    assert float(rows["flat"]["steps_per_sample"]) == 0.0
    assert float(rows["closed_form"]["steps_per_sample"]) < 0.1 * float(rows["integrate"]["steps_per_sample"])
    assert float(rows["closed_form"]["median_pixel_rel_diff_vs_integrate"]) < 1e-4


def test_gravity_cost_benchmark_measures_the_efficiency_cost(tmp_path):
    import bench_gravity_cost

    assert bench_gravity_cost.main(["--efficiency", "--quick", "--rooms", "fig07", "--out", str(tmp_path)]) == 0
    rows = {r["variant"]: r for r in read_csv(tmp_path / "gravity_efficiency.csv")}
    assert set(rows) == {"flat", "curved"}
    for r in rows.values():
        assert r["reference"] == "unbiased"  # path traced without photons: a photon map's blur counts as error
        assert float(r["rel_mse"]) > 0 and float(r["cpu_s"]) > 0
        assert float(r["efficiency"]) == pytest.approx(1.0 / (float(r["rel_mse"]) * float(r["cpu_s"])), rel=1e-4)  # (the CSV keeps 6 digits)
    assert float(rows["flat"]["flat_over_this"]) == 1.0
    assert float(rows["curved"]["flat_over_this"]) > 1.0  # curved space costs more per sample


def test_benchmark_references_on_a_dask_cluster_are_the_local_ones_bit_for_bit(tmp_path):
    """--workers sends a sweep's references (and time-to-clean's timed renders) through the cluster: the
    same images, so the same results, as on this machine."""
    pytest.importorskip("distributed")
    import argparse

    import bench_light_connection
    import bench_time_to_clean
    from _common import add_cluster_options, cluster_render_options

    import warpviz as wv

    refs = {}
    for where, extra in (("local", []), ("dask", ["--workers", "2", "--tile", "8"])):
        cache = tmp_path / where
        # spp, not the time budget, decides when a half is done, so the passes are the same everywhere
        args = ["--quick", "--scenes", "fig07", "--ref-spp", "4", "--ref-time", "600", "--reference-only",
                "--cache", str(cache), "--out", str(tmp_path), *extra]  # fmt: skip
        assert bench_time_to_clean.main(args) == []
        refs[where] = [wv.Image.open(p) for p in sorted(cache.glob("*.exr"))]
    assert len(refs["local"]) == len(refs["dask"]) == 2
    for a, b in zip(refs["local"], refs["dask"]):
        np.testing.assert_array_equal(a.rgb, b.rgb)
        assert a.metadata["spp"] == b.metadata["spp"] == 4

    parser = argparse.ArgumentParser()
    add_cluster_options(parser)
    cfg = {"size": (12, 9), "ref_spp": 8}
    local = bench_light_connection.reference("fig07", cfg)
    with cluster_render_options(parser.parse_args(["--workers", "1"])) as via:
        assert set(via) == {"client", "threads"}
        remote = bench_light_connection.reference("fig07", cfg, via=via)
    for x, y in zip(local, remote):
        np.testing.assert_array_equal(x, y)
    with pytest.raises(SystemExit, match="--tile is the tile size"), \
            cluster_render_options(parser.parse_args(["--tile", "16"])):  # fmt: skip
        pass
    with pytest.raises(SystemExit, match="cannot use the Dask cluster"), \
            cluster_render_options(parser.parse_args(["--workers", "1", "--cluster", "tcp://127.0.0.1:1"])):  # fmt: skip
        pass


def test_builds_benchmark_quick_mode_compares_a_build_with_itself(tmp_path):
    import bench_builds

    rows = bench_builds.main(["--quick", "--out", str(tmp_path)])
    assert [r["scene"] for r in rows] == ["fig03", "fig07", "far-kerr"]
    assert all(r["identical"] and r["a_over_b_min"] > 0 for r in rows)  # the same build: the same images
    assert rows[2]["rays"] == 64 and rows[2]["a_rays_per_s_best"] > 0 and rows[0]["rays"] == 0  # geodesics/s
    assert len(read_csv(tmp_path / "builds.csv")) == 3
    # B run with a source tree's own package (here this one's): the child imports it, not the installed one
    tree = str(Path(bench_builds.__file__).resolve().parents[1])
    rows = bench_builds.main(["--package-b", tree, "--renders", "fig03:8x6:1", "--repeat", "1", "--out", str(tmp_path)])
    assert rows[0]["identical"]
    with pytest.raises(SystemExit, match="no compiled core"):
        bench_builds.main([str(tmp_path / "missing.so"), "--quick", "--out", str(tmp_path)])
    # at equal error: the same build on the same seeds (B from the scene's own file) has the same error
    scene_file = str(Path(tree) / "scenes" / "fig03_cornell_flat.toml")
    rows = bench_builds.main(["--renders", "fig03:8x6:2", "--repeat", "1", "--error", "--seeds", "2", "--ref-spp", "8",
                              "--scene-b", scene_file, "--out", str(tmp_path)])
    r = rows[0]
    assert r["identical"] and r["a_rel_mse"] == r["b_rel_mse"] > 0
    assert r["efficiency_b_over_a_min"] == pytest.approx(r["a_cpu_s_min"] / r["b_cpu_s_min"])
