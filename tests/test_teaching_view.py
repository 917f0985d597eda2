"""The teaching view explains itself: colourings and their titles, bounces on demand, the flat-space ray,
labels, title and legend, the wormhole's other side, and the ``warpviz view`` flags that reach them."""

import numpy as np
import pytest
from typer.testing import CliRunner

pv = pytest.importorskip("pyvista")

import warpviz as wv  # noqa: E402
from warpviz import cli  # noqa: E402
from warpviz.viewer.annotations import (  # noqa: E402
    COLORINGS,
    LEGEND_STYLE,
    coloring_array,
    coloring_title,
    default_bounces,
    landmark_labels,
    legend_entries,
    length_text,
    length_unit,
    next_coloring,
    view_title,
    visible_ray_ids,
)

WINDOW = (640, 320)

#: The renderer actor each legend key stands for.
ACTOR_OF = {"horizon": "horizon", "ergosphere": "ergosphere", "photon_sphere": "photon_sphere", "throat": "waist",
            "our_sheet": "embedding", "other_sheet": "embedding", "surfaces": "surfaces",
            "other_surfaces": "surfaces", "camera": "camera", "rays": "rays", "highlight": "highlight",
            "picked": "picked", "flat_rays": "flat_rays", "lights": "lights"}  # fmt: skip


def black_hole_scene(metric=None, width=48, height=24):
    """A hole (Schwarzschild by default) in front of a glowing wall with a mirror floor below, camera at
    25 M on the -y axis: camera rays that bounce."""
    return {
        "metric": metric or {"name": "schwarzschild", "params": [1.0]},
        "camera": {"position": [0.0, -25.0, 0.0], "look_at": [0.0, 0.0, 0.0], "up": [0, 0, 1], "fov": 50.0,
                   "width": width, "height": height},
        "textures": [{"type": "grid", "base": [0.02, 0.03, 0.08], "line_u": [1.0, 0.75, 0.3],
                      "line_v": [0.35, 0.7, 1.0], "cells": [16, 8], "width": 0.08},
                     {"type": "constant", "color": [0.8, 0.8, 0.8]}],
        "materials": [{"type": "emissive", "texture": 0, "strength": 1.0, "two_sided": True},
                      {"type": "diffuse", "texture": 1}],
        "shapes": [{"type": "quad", "corner": [-40.0, 15.0, -20.0], "edge_u": [80.0, 0.0, 0.0],
                    "edge_v": [0.0, 0.0, 40.0], "material": 0},
                   {"type": "quad", "corner": [-40.0, -30.0, -6.0], "edge_u": [80.0, 0.0, 0.0],
                    "edge_v": [0.0, 45.0, 0.0], "material": 1}],
        "environment": {"color": [0.05, 0.05, 0.05]},
    }  # fmt: skip


@pytest.fixture(scope="module")
def scene_view():
    """The default view of the bouncing scene (the view chooses the pixels)."""
    plotter = wv.view(black_hole_scene(), off_screen=True, return_plotter=True, window_size=WINDOW,
                      preview_width=32, spp=2)  # fmt: skip
    yield plotter
    plotter.close()


def press_key(plotter, key):
    it = plotter.iren.interactor
    it.SetKeySym(key)
    it.SetKeyCode(key)
    it.InvokeEvent("KeyPressEvent")


# --------------------------------------------------------------------------------------------------
# the words, without rendering


def test_title_names_the_metric_and_its_parameters():
    assert view_title("fig10d", wv.Kerr(mass=2.5, spin=0.9)) == "fig10d: Kerr black hole, mass M = 2.5, spin a/M = 0.9"
    assert view_title("room", wv.Schwarzschild(mass=1.0)) == "room: Schwarzschild black hole, mass M = 1"
    assert view_title("fig13", wv.EllisWormhole(throat=8.0)) == "fig13: Ellis wormhole, throat radius b0 = 8 units"
    assert view_title("schwarzschild", wv.Schwarzschild(mass=3.0)) == "Schwarzschild black hole, mass M = 3"


def test_landmark_labels_carry_the_radii():
    assert landmark_labels(wv.Schwarzschild(mass=1.0)) == {"horizon": "horizon r = 2 M",
                                                           "photon_sphere": "photon sphere r = 3 M"}  # fmt: skip
    kerr = landmark_labels(wv.Kerr(mass=1.0, spin=0.9))
    # r+ = M + sqrt(M^2 - a^2); the equatorial static limit is 2M; the circular photon orbits
    # r = 2M (1 + cos(2/3 acos(-+a/M))) bound the photon region
    assert kerr["horizon"] == f"horizon r = {1 + np.sqrt(1 - 0.81):.4g} M"
    assert kerr["ergosphere"] == "ergosphere r = 2 M on the equator"
    pro, retro = (2 * (1 + np.cos(2 / 3 * np.arccos(s * 0.9)))for s in (-1, 1))
    assert kerr["photon_sphere"] == f"photon region r = {pro:.4g}-{retro:.4g} M"
    assert "ergosphere" not in landmark_labels(wv.Schwarzschild(mass=1.0))
    assert landmark_labels(wv.EllisWormhole(throat=1.5)) == {"throat": "throat radius b0 = 1.5 units"}
    assert landmark_labels(wv.Minkowski()) == {} and landmark_labels(None) == {}


@pytest.mark.parametrize(("metric", "horizon", "camera"), [
    (wv.Schwarzschild(mass=1.0), "horizon r = 2 M", "45 M"),
    (wv.Schwarzschild(mass=2.5), "horizon r = 2 M (5 units)", "18 M (45 units)"),
    (wv.Kerr(mass=3.482, spin=0.9), "horizon r = 1.436 M (5 units)", "12.92 M (45 units)"),
])  # fmt: skip
def test_lengths_are_shown_in_m_with_the_scene_value_beside_them(metric, horizon, camera):
    """Scene lengths are in M only where M = 1: fig07 (M = 2.5) has its horizon at 5 units = 2 M, fig10d
    (M = 3.482, a/M = 0.9) at 5 units = 1.436 M with its equatorial ergosphere at 6.964 units = 2 M."""
    assert landmark_labels(metric)["horizon"] == horizon
    assert length_text(45.0, metric) == camera
    if "ergosphere" in metric.landmarks:
        assert landmark_labels(metric)["ergosphere"] == "ergosphere r = 2 M (6.964 units) on the equator"
        assert landmark_labels(metric)["photon_sphere"] == "photon region r = 1.558-3.91 M (5.424-13.62 units)"
    assert length_unit(metric) == ("M" if metric.params["mass"] == 1.0 else f"units, M = {metric.params['mass']:g}")
    assert length_text(15.13, wv.EllisWormhole(throat=8.0)) == "1.891 b0 (15.13 units)"
    assert length_text(45.0, wv.Minkowski()) == "45 units" and length_unit(wv.Minkowski()) == "units"


def test_legend_lists_what_is_drawn_once_in_order():
    kerr = wv.Kerr(mass=1.0, spin=0.9)
    entries = legend_entries(["horizon", "ergosphere", "camera", "rays", "camera", "flat_rays"], kerr)
    assert [label for label, _ in entries] == ["horizon", "ergosphere", "camera", "light paths (colour: see the bar)",
                                               "flat-space ray (no gravity)"]  # fmt: skip
    # the radii are in the labels at the landmarks, the legend says what each colour is
    assert [label for label, _ in legend_entries(["photon_sphere"], kerr)] == ["photon region"]
    assert [color for _, color in entries] == [LEGEND_STYLE[k][1] for k in ("horizon", "ergosphere", "camera", "rays",
                                                                           "flat_rays")]  # fmt: skip
    assert legend_entries([], kerr) == []
    with pytest.raises(KeyError, match="'sun'"):
        legend_entries(["sun"], kerr)


def test_colorings_their_arrays_titles_and_cycle():
    assert [coloring_array(n) for n in COLORINGS] == ["log10_error_scaled", "r", "redshift", "affine_param"]
    assert coloring_array("drift", ["log10_error", "r"]) == "log10_error"  # rays saved before the scaled array
    assert coloring_array("step_size") == "step_size"
    drift = coloring_title("drift", wv.Kerr(mass=1.0, spin=0.9))
    assert drift == ("how well each ray keeps energy, angular momentum and Carter's constant\n"
                     "log10 of the error: -10 is ten correct digits; good below -5")  # fmt: skip
    # Lz and L^2 are both angular momentum (about the axis and in all), said once
    assert coloring_title("drift", wv.Schwarzschild()).startswith("how well each ray keeps energy and angular momentum\n")
    assert coloring_title("r", wv.Schwarzschild(mass=1.0)) == "radius r (M)"
    assert coloring_title("r", wv.Schwarzschild(mass=2.5)) == "radius r (units, M = 2.5)"
    assert coloring_title("step_size", None, fallback={"step_size": "step size"}) == "step size"
    cycle = ["drift"]
    for _ in range(4):
        cycle.append(next_coloring(cycle[-1]))
    assert cycle == ["drift", "r", "redshift", "affine", "drift"]
    assert next_coloring("log10_error_scaled") == "r" and next_coloring("step_size") == "drift"
    assert next_coloring("r", ["log10_error", "r", "affine_param"]) == "affine"  # no redshift array: skipped


def test_visible_segments_and_default_bounces():
    bounce = np.array([0, 1, 2, 0, 1, 0])
    assert visible_ray_ids(bounce, 6, 0).tolist() == [0, 3, 5]
    assert visible_ray_ids(bounce, 6, 2).tolist() == [0, 1, 2, 3, 4, 5]
    assert visible_ray_ids(bounce, 6, None).tolist() == visible_ray_ids(None, 6, 0).tolist() == list(range(6))
    with pytest.raises(ValueError, match="bounces must be >= 0"):
        visible_ray_ids(bounce, 6, -1)
    assert default_bounces(True) == 0 and default_bounces(False) is None


# --------------------------------------------------------------------------------------------------
# the view, off-screen


def test_the_default_view_starts_with_the_camera_segments(scene_view):
    tv = scene_view.teaching_view
    assert tv.bounces == 0
    bounce = np.asarray(tv.rays.cell_data["bounce"])
    assert scene_view.renderers[1].actors["rays"].mapper.dataset.n_cells == int(np.sum(bounce == 0))


def test_the_view_draws_the_camera_segments_and_more_bounces_on_demand():
    """Pixels given: one low in the picture, whose camera rays meet the floor and bounce, and one that sees the
    glowing wall past the hole. (The pixels the view chooses here all see the wall directly, round the hole or
    past it: the camera's own light samples show the wall's thin arc round the hole as the brightest lensed
    light, which a noisier first render missed for a pixel whose paths bounced.)"""
    plotter = wv.view(black_hole_scene(), off_screen=True, return_plotter=True, window_size=WINDOW, preview_width=32,
                      spp=2, pixels=[(16, 15), (4, 8)])  # fmt: skip
    try:
        tv = plotter.teaching_view
        scene = plotter.renderers[1]
        bounce = np.asarray(tv.rays.cell_data["bounce"])
        assert bounce.max() >= 1  # the paths do bounce (floor, then wall)
        assert tv.show_bounces(0) == 0  # (given pixels show every bounce at first; the view's own, the camera's)
        drawn = scene.actors["rays"].mapper.dataset
        assert drawn.n_cells == int(np.sum(bounce == 0))
        assert set(np.asarray(bounce[np.asarray(drawn.cell_data["vtkOriginalCellIds"])])) == {0}
        press_key(plotter, "n")
        assert tv.bounces == 1 and scene.actors["rays"].mapper.dataset.n_cells == int(np.sum(bounce <= 1))
        assert tv.show_bounces(None) is None and scene.actors["rays"].mapper.dataset.n_cells == tv.rays.n_cells
        assert tv.show_bounces(0) == 0
        ids = tv.select_pixel(4, 8)  # a selected pixel lights up its drawn segments only
        assert len(ids) and set(bounce[ids]) == {0}
        tv.select_pixels([])
    finally:
        plotter.close()


def test_c_cycles_the_colourings_and_the_colour_bar_names_them(scene_view):
    tv = scene_view.teaching_view
    metric = wv.Schwarzschild(mass=1.0)
    assert tv.color_by == "drift" and list(scene_view.scalar_bars.keys()) == [coloring_title("drift", metric)]
    seen = []
    for _ in range(4):
        press_key(scene_view, "c")
        seen.append(tv.color_by)
        mapper = scene_view.renderers[1].actors["rays"].mapper
        assert mapper.array_name == coloring_array(tv.color_by)
        assert list(scene_view.scalar_bars.keys()) == [coloring_title(tv.color_by, metric)]
    assert seen == ["r", "redshift", "affine", "drift"]
    with pytest.raises(ValueError, match="color_by='nope' is not a colouring"):
        tv.cycle_coloring("nope")


def test_legend_is_what_the_panel_draws(scene_view):
    tv = scene_view.teaching_view
    scene = scene_view.renderers[1]

    def check():
        items = tv.drawn_items()
        assert tv.legend == legend_entries(items, tv.metric, tv.legend_colors())
        assert all(ACTOR_OF[key] in scene.actors for key in items)
        # each swatch is the colour its item is drawn in: the paths' is the colour map at their median value
        if "rays" in items:
            actor = scene.actors["rays"]
            mapper = actor.GetMapper()
            drawn = tv.shown_rays.extract_cells(tv._visible)
            values = np.asarray(drawn.point_data[coloring_array(tv.color_by)], dtype=np.float64)
            lut = mapper.GetLookupTable()
            rgb = [0.0, 0.0, 0.0]
            lut.GetColor(float(np.median(values[np.isfinite(values)])), rgb)
            swatch = dict(tv.legend)[next(label for label, _ in tv.legend if label.startswith("light paths"))]
            from matplotlib.colors import to_rgb

            assert np.allclose(to_rgb(swatch), rgb, atol=0.02), (swatch, rgb)
        for key, name in ACTOR_OF.items():  # and nothing drawn is missing from it
            if name in scene.actors and key not in ("other_sheet", "other_surfaces", "our_sheet", "throat"):
                assert key in items, key
        return [label for label, _ in tv.legend]

    labels = check()
    assert labels == ["horizon", "photon sphere", "scene objects", "camera", "light paths (colour: see the bar)"]
    tv.select_pixel(*next(iter(tv.pixel_labels)))
    tv.toggle_flat(True)
    assert check()[-2:] == ["selected pixel's paths", "flat-space ray (no gravity)"]
    tv.toggle_flat(False)
    tv.select_pixels([])
    assert check() == labels
    assert "ergosphere" not in scene.actors


def test_kerr_view_labels_its_ergosphere_and_titles_its_spin():
    scene = black_hole_scene({"name": "kerr", "params": [1.0, 0.9]})
    plotter = wv.view(scene, off_screen=True, return_plotter=True, window_size=WINDOW, preview_width=24, spp=1)
    try:
        tv = plotter.teaching_view
        labels = [label for label, _ in tv.legend]
        assert labels[:3] == ["horizon", "ergosphere", "photon region"]
        assert "Kerr black hole, mass M = 1, spin a/M = 0.9" in tv.title_text.replace("\n", " ")
        texts = [text for text, _ in tv.labels_3d]
        radii = ["horizon r = 1.436 M", "ergosphere r = 2 M on the equator", "photon region r = 1.558-3.91 M"]
        assert texts == ["\n".join(radii), "camera, 25 M from the centre"]
        # the landmarks' label sits on the outermost surface: the retrograde photon orbit's r = 3.91 M at
        # most (Kerr-Schild radius sqrt(r^2 + a^2) on the equator), at least the static limit's 2 M
        anchor = tv.labels_3d[0][1]
        assert 2.0 < np.linalg.norm(anchor) <= np.hypot(3.91, 0.9) + 0.05 and anchor[2] > 1.0
        drawn = [actor.GetInput().strip() for _, actor in tv._text_actors["label3d"]]
        assert drawn == [" \n ".join(text.split("\n")).strip() for text in texts]
        assert "landmark_points" in plotter.renderers[1].actors
    finally:
        plotter.close()


def test_flat_ray_of_each_chosen_pixel_without_a_selection(scene_view):
    tv = scene_view.teaching_view
    tv.select_pixels([])
    tv.toggle_flat(True)
    try:
        chosen = list(tv.pixel_labels)
        segments = tv.flat_rays()
        assert len(segments) == len(chosen) >= 2
        cam = dict(black_hole_scene()["camera"], width=tv.image.shape[1], height=tv.image.shape[0])
        for (x, y), (start, end) in zip(chosen, segments):
            np.testing.assert_allclose(start, cam["position"])
            want = wv.scene.camera.pinhole_directions(cam, [[x, y]])[0]
            np.testing.assert_allclose((end - start) / np.linalg.norm(end - start), want, atol=1e-12)
        assert scene_view.renderers[1].actors["flat_rays"].mapper.dataset.n_cells == len(chosen)
    finally:
        tv.toggle_flat(False)


def test_wormhole_view_draws_the_objects_on_the_other_side():
    metric = {"name": "ellis", "params": [1.0]}
    scene = {
        "metric": metric,
        "camera": {"position": [0.0, -12.0, 0.0], "look_at": [0.0, 0.0, 0.0], "up": [0, 0, 1], "fov": 60.0,
                   "width": 32, "height": 16, "sheet": 1},
        "textures": [{"type": "constant", "color": [1.0, 0.8, 0.3]}, {"type": "constant", "color": [0.3, 0.6, 1.0]}],
        "materials": [{"type": "emissive", "texture": 0, "strength": 1.0}, {"type": "diffuse", "texture": 1}],
        "shapes": [{"type": "sphere", "center": [0.0, 10.0, 0.0], "radius": 2.0, "material": 0, "sheet": -1},
                   {"type": "sphere", "center": [8.0, -4.0, 0.0], "radius": 1.0, "material": 1, "sheet": 1}],
        "environment": {"color": [0.0, 0.0, 0.0]},
    }  # fmt: skip
    plotter = wv.view(scene, off_screen=True, return_plotter=True, window_size=WINDOW, preview_width=32, spp=1)
    try:
        tv = plotter.teaching_view
        r = plotter.renderers[1]
        assert {"embedding", "waist", "surfaces", "camera"} <= set(r.actors)
        shown = r.actors["surfaces"].mapper.dataset
        z = np.asarray(shown.points)[:, 2]
        # the far sphere sits on the lower (other) sheet of the diagram, the near one on ours
        assert z.min() < -1.0 and z.max() > 1.0
        expected = wv.wormhole_embedding_points(wv.EllisWormhole(throat=1.0), [[0.0, 10.0, 0.0]], [-1])[0, 2]
        assert abs(z.min() - expected) < 1.0
        labels = [label for label, _ in tv.legend]
        assert labels[:3] == ["our sheet", "other sheet", "throat"]
        assert "objects on the other side" in labels and "scene objects" in labels
    finally:
        plotter.close()


# --------------------------------------------------------------------------------------------------
# the command line


def invoke(*args):
    return CliRunner().invoke(cli.app, [str(a) for a in args])


def test_view_flags_reach_the_viewer(monkeypatch):
    seen = []
    monkeypatch.setattr(cli.common, "_viewer", lambda: lambda obj, **kw: seen.append(kw))
    monkeypatch.setenv("DISPLAY", ":0")
    monkeypatch.delenv("PYVISTA_OFF_SCREEN", raising=False)
    assert invoke("view", "fig07", "--bounces", "2", "--flat-ray", "--color-by", "redshift").exit_code == 0
    assert seen[-1] == {"bounces": 2, "show_flat": True, "color_by": "redshift"}
    assert invoke("view", "fig07").exit_code == 0 and seen[-1] == {}
    for args, message in ((("--bounces", "-1"), "--bounces must be 0"), (("--color-by", "speed"), "--color-by must be one of drift, r, redshift, affine"),
                          (("--bounces", "two"), "Invalid value for '--bounces'")):  # fmt: skip
        result = invoke("view", "fig07", *args)
        assert result.exit_code == 2, result.output
        assert message in result.output
    assert len(seen) == 2


def test_view_flags_headless_screenshot(tmp_path, monkeypatch):
    """``--flat-ray --color-by r --bounces 1`` through to the picture: the flat rays' lime is in it."""
    monkeypatch.setenv("PYVISTA_OFF_SCREEN", "true")
    lime = []
    for i, flags in enumerate([(), ("--flat-ray", "--color-by", "r", "--bounces", "1")]):
        shot = tmp_path / f"view{i}.png"
        result = invoke("view", "fig04", "--screenshot", shot, *flags)
        assert result.exit_code == 0, result.output
        rgb = np.asarray(pv.read(shot).point_data["PNGImage"])[:, :3].astype(int)
        lime.append(int(np.sum(np.all(np.abs(rgb - (0, 255, 0)) <= 40, axis=-1))))
    assert lime[1] > lime[0] + 200


# --------------------------------------------------------------------------------------------------
# the progressive image


def test_progressive_preview_doubles_its_samples_and_converges():
    """Each step averages a pass with as many new samples as so far; the mean approaches a 256-spp render."""
    from warpviz.viewer.progressive import ProgressivePreview

    scene = black_hole_scene(width=24, height=12)
    reference = np.asarray(wv.render(scene, spp=256, seed=99, aovs=[]).rgb, dtype=np.float64)
    first = wv.render(scene, spp=2, seed=5, aovs=[])
    preview = ProgressivePreview(scene, width=24, height=12, spp=2, seed=5, max_spp=64, first=first.rgb)
    np.testing.assert_array_equal(preview.image(), first.to_uint8())
    samples, errors = [preview.samples], [float(np.sqrt(np.mean((preview.rgb - reference) ** 2)))]
    while (image := preview.step()) is not None:
        assert image.shape == (12, 24, 3) and image.dtype == np.uint8
        samples.append(preview.samples)
        errors.append(float(np.sqrt(np.mean((preview.rgb - reference) ** 2))))
    assert samples == [2, 4, 8, 16, 32, 64] and preview.done and preview.passes == 6
    # noise falls as 1/sqrt(spp): 32x the samples, about 1/5.7 of the error (the reference's own noise aside)
    assert errors[-1] < 0.3 * errors[0]
    assert all(b < a * 1.15 for a, b in zip(errors, errors[1:]))  # never noticeably worse
    # the passes are independent: a second pass's seed differs from the first's
    again = ProgressivePreview(scene, width=24, height=12, spp=2, seed=5, max_spp=4)
    again.step()
    np.testing.assert_array_equal(again.rgb, first.rgb)
    one = again.rgb.copy()
    again.step()
    assert not np.array_equal(again.rgb, one)
    with pytest.raises(ValueError, match="spp <= max_spp"):
        ProgressivePreview(scene, width=24, height=12, spp=8, max_spp=4)
    with pytest.raises(ValueError, match=r"first must have shape \(12, 24, 3\)"):
        ProgressivePreview(scene, width=24, height=12, first=np.zeros((3, 3, 3)))


def test_view_refines_its_image_in_the_background():
    import time

    plotter = wv.view(black_hole_scene(), off_screen=True, return_plotter=True, window_size=WINDOW,
                      preview_width=24, spp=1)  # fmt: skip
    try:
        tv = plotter.teaching_view
        before = plotter.renderers[0].actors["image"].mapper.dataset.cell_data["rgb"].copy()
        assert tv.image_samples == 1 and tv.status().endswith("image: 1 samples per pixel")
        refiner = tv.start_refining(max_spp=16, refresh_ms=50)
        assert refiner is not None and tv.start_refining() is None  # once
        seen = [tv.image_samples]
        deadline = time.monotonic() + 60
        while tv.image_samples < 16 and time.monotonic() < deadline:
            time.sleep(0.02)
            if tv._on_timer():  # what the VTK timer calls in a window
                seen.append(tv.image_samples)
        # the newest image each time (a pass finished between two looks is skipped), the count doubling
        assert seen[-1] == 16 and set(seen) <= {1, 2, 4, 8, 16} and seen == sorted(set(seen))
        assert refiner.error is None
        refiner._thread.join(5)
        assert not refiner.running
        shown = plotter.renderers[0].actors["image"].mapper.dataset.cell_data["rgb"]
        assert not np.array_equal(shown, before)
        np.testing.assert_array_equal(shown, np.ascontiguousarray(tv.image[::-1].reshape(-1, 3)))
        np.testing.assert_array_equal(tv.image, refiner.preview.image())
        assert "image: 16 samples per pixel" in tv.status()
    finally:
        plotter.teaching_view.stop_refining()
        plotter.close()


def test_stopping_the_refiner_ends_the_pass_under_way():
    import time

    from warpviz.viewer.progressive import BackgroundRefiner, ProgressivePreview

    preview = ProgressivePreview(black_hole_scene(width=160, height=80), width=160, height=80, spp=64, max_spp=4096)
    refiner = BackgroundRefiner(preview).start()
    time.sleep(0.2)
    t0 = time.monotonic()
    refiner.stop()
    assert not refiner.running and time.monotonic() - t0 < 2.0 and refiner.error is None
    assert preview.samples < 4096


@pytest.mark.parametrize("scene", ["fig04", "fig07", "fig09", "fig10d", "fig13"])
def test_the_shipped_views_show_no_ray_above_the_good_line(scene):
    """The rays a view records (the pixels it chooses, at the screenshots' 32 spp) keep their conserved
    quantities to better than GOOD_DRIFT against the size of their terms at the renderer's tolerance, so
    the colour bar's "good below -5" holds for all of them. (Their relative drift did not: Lz and Q of
    fig10d's 'light bent round the hole' are small against their terms, and |X - X0| / |X0| read 4e-5.)"""
    from warpviz.viewer.annotations import GOOD_DRIFT
    from warpviz.viewer.view_content import view_content

    content = view_content(scene, spp=32)
    worst = float(np.nanmax(np.asarray(content.rays.point_data["log10_error_scaled"])))
    assert worst < np.log10(GOOD_DRIFT), (scene, worst)


def test_point_and_spot_lights_are_drawn_with_a_spot_s_axis():
    """Point and spot lights are never hit, so no surface shows them: the 3-D panel draws them as balls, a spot
    with an arrow along its axis, and the legend says what they are."""
    scene = black_hole_scene()
    scene["lights"] = [{"type": "point", "position": [-10.0, -10.0, 10.0], "intensity": 50.0},
                       {"type": "spot", "position": [10.0, -10.0, 10.0], "intensity": 50.0,
                        "direction": [0.0, 0.0, -1.0], "angle": 25.0}]  # fmt: skip
    plotter = wv.view(scene, off_screen=True, return_plotter=True, window_size=WINDOW, preview_width=16, spp=1)
    try:
        tv = plotter.teaching_view
        actors = plotter.renderers[1].actors
        assert "lights" in tv.drawn_items() and "lights" in actors and "light_axes" in actors
        assert any(label.startswith("point and spot lights") for label, _ in tv.legend)
        balls = actors["lights"].GetMapper().GetInput()
        np.testing.assert_array_equal(np.asarray(balls.GetPoints().GetData()), [[-10.0, -10.0, 10.0], [10.0, -10.0, 10.0]])
    finally:
        plotter.close()
