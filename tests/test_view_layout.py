"""The teaching view reads from the back of a room: text sized from the window, no two texts overlapping,
the scene framed between the title and the colour bar, round tick values, and the image panel's angle
scale and exact shadow edge."""

import math

import numpy as np
import pytest

pv = pytest.importorskip("pyvista")

import warpviz as wv  # noqa: E402
from warpviz.viewer.decorations import bar_range, round_axes  # noqa: E402
from warpviz.viewer.image_marks import angle_ticks, edge_circle  # noqa: E402
from warpviz.viewer.layout import FONT_PX, font_px, overlapping, text_scale  # noqa: E402
from warpviz.viewer.meshes import _cut_lines_at  # noqa: E402

from view_scenes import lensing_scene  # noqa: E402

#: Font heights (pixels) the view used at 1400x700 before text was sized from the window.
#: (The caption was the scalar bar's title at font size 11, which VTK shrank to fit: about 10 px drawn.)
OLD_FONT_PX = {"title": 9, "status": 9, "label": 10, "label3d": 11, "legend": 7, "axes": 8, "caption": 10, "bar": 10}


def hole_scene(metric=None, width=48, height=32):
    """The viewer tests' hole before a glowing grid wall, at the size these tests use."""
    return lensing_scene(width, height, metric)


def display_point(renderer, point):
    renderer.SetWorldPoint(*point, 1.0)
    renderer.WorldToDisplay()
    return np.asarray(renderer.GetDisplayPoint()[:2])


@pytest.mark.parametrize("size", [(1400, 700), (1920, 1080)])
@pytest.mark.parametrize("scene", ["schwarzschild", "kerr", "fig13"])
def test_no_two_texts_overlap_and_the_scene_sits_between_title_and_bar(scene, size):
    source = {"schwarzschild": hole_scene(), "kerr": hole_scene({"name": "kerr", "params": [1.0, 0.9]}),
              "fig13": "fig13"}[scene]  # fmt: skip
    plotter = wv.view(source, off_screen=True, return_plotter=True, window_size=size, preview_width=48, spp=1,
                      show_flat=True)  # fmt: skip
    try:
        tv = plotter.teaching_view
        tv.select_pixel(*next(iter(tv.pixel_labels)))  # the legend and the status line grow
        plotter.render()
        boxes = tv.text_boxes()
        roles = {role for role, _ in boxes}
        assert {"title", "status", "help", "label", "legend", "caption", "ticks"} <= roles, roles
        assert overlapping(boxes) == []
        width, height = size
        for role, (x0, x1, y0, y1) in boxes:  # inside the window
            assert x0 >= -1 and x1 <= width + 1 and y0 >= -1 and y1 <= height + 1, (role, x0, x1, y0, y1)
        # what the camera frames (the drawn objects, the axes' box) lands between the texts above and the
        # colour bar's caption below
        r = tv._scene_renderer
        corners = np.array([display_point(r, point) for point in tv.fit_points()])
        above = min(y0 for role, (x0, x1, y0, y1) in boxes if role in ("title", "legend") and x0 >= width / 2 - 1)
        below = max(y1 for role, (x0, x1, y0, y1) in boxes if role == "caption")
        assert corners[:, 1].max() < above and corners[:, 1].min() > below
        assert corners[:, 0].min() > width / 2 and corners[:, 0].max() < width
        # and it fills that band: the box spans most of its height or of the panel's width
        span = corners.max(axis=0) - corners.min(axis=0)
        assert span[1] > 0.5 * (above - below) or span[0] > 0.5 * (width / 2)
    finally:
        plotter.close()


def test_text_is_twice_as_large_at_1400_by_700_and_grows_with_the_window():
    scale = text_scale((1400, 700))
    assert scale == 1.0
    for role, old in OLD_FONT_PX.items():  # (the old legend's text was fitted into its box: about 7 px)
        assert font_px(role, scale) >= 2 * old, role
    big = text_scale((1920, 1080))
    assert big == pytest.approx(960 / 700)
    assert all(font_px(role, big) > font_px(role, scale) for role in FONT_PX)
    assert text_scale((1400, 700), panels=1) == 1.0 and text_scale((200, 100)) == 0.5


def test_the_texts_are_drawn_at_the_window_sizes_height():
    plotter = wv.view(hole_scene(), off_screen=True, return_plotter=True, window_size=(1400, 700),
                      preview_width=32, spp=1)  # fmt: skip
    try:
        tv = plotter.teaching_view
        plotter.render()
        heights = {}
        for role, (x0, x1, y0, y1) in tv.text_boxes():
            heights.setdefault(role, []).append(y1 - y0)
        # one line of text is drawn about its font's height
        for role in ("title", "status", "label", "legend", "caption"):
            assert min(heights[role]) >= 0.85 * 2 * OLD_FONT_PX[role], (role, heights[role])
    finally:
        plotter.close()


def test_round_axis_values_and_colour_bar_ticks():
    bounds, counts = round_axes([-40.3, 43.1, -110.0, 50.0, -61.0, 85.4])
    assert bounds == [-40.0, 40.0, -100.0, 50.0, -50.0, 50.0] and counts == [5, 4, 3]
    for lo, hi, n in zip(bounds[0::2], bounds[1::2], counts):
        ticks = np.linspace(lo, hi, n)
        assert np.allclose(ticks, np.round(ticks))  # every label a whole number here
    lo, hi, n = bar_range(-15.2, -6.7, include=[-5.0])
    assert (lo, hi, n) == (-16.0, -4.0, 7) and lo <= -15.2 and hi >= -5.0
    lo, hi, n = bar_range(0.93, 1.07)
    ticks = np.linspace(lo, hi, n)
    assert lo <= 0.93 and hi >= 1.07 and 3 <= n <= 7
    assert np.allclose(ticks * 100, np.round(ticks * 100))


def test_the_drawn_axes_and_colour_bar_show_round_values():
    plotter = wv.view(hole_scene(), off_screen=True, return_plotter=True, window_size=(1400, 700),
                      preview_width=32, spp=1)  # fmt: skip
    try:
        axes = plotter.renderers[1].cube_axes_actor
        b = axes.GetBounds()
        step = [(b[1] - b[0]), (b[3] - b[2]), (b[5] - b[4])]
        labels = [axes.n_xlabels, axes.n_ylabels, axes.n_zlabels]
        for lo, span, n in zip(b[0::2], step, labels):
            values = lo + np.arange(n) * span / (n - 1)
            assert np.allclose(values, np.round(values, 6)) and all(
                abs(v / 10 ** math.floor(math.log10(abs(span / (n - 1))))) % 1 < 1e-9 or v == 0 for v in values
            )
        bar = next(iter(plotter.scalar_bars.values()))
        lo, hi = bar.GetLookupTable().GetRange()
        ticks = np.linspace(lo, hi, bar.GetNumberOfLabels())
        assert np.allclose(ticks, np.round(ticks))  # the drift bar: whole powers of ten
        assert lo <= -5.0 <= hi  # the good line is on it, marked where -5 is
        from warpviz.viewer.layout import BAR_BOX

        mark = plotter.teaching_view._good_mark.GetMapper().GetInput().GetPoints()
        assert mark.GetPoint(0)[0] == pytest.approx(BAR_BOX[0] + BAR_BOX[2] * (-5.0 - lo) / (hi - lo))
        plotter.teaching_view.cycle_coloring("r")  # no good line for the radius
        assert plotter.teaching_view._good_mark is None
    finally:
        plotter.close()


def test_angle_scale_marks_the_pinhole_angles():
    cam = {"fov": 60.0}
    ticks = angle_ticks(cam, 160, 120)
    t = math.tan(math.radians(30.0))
    for x, label in ticks["x"]:
        angle = math.radians(float(label.rstrip("°")))
        assert x == pytest.approx((math.tan(angle) / (t * 160 / 120) + 1) * 80)
    assert [label for _, label in ticks["y"]] == ["-20°", "-10°", "0°", "10°", "20°"]
    assert ticks["y"][2][0] == pytest.approx(60.0)


@pytest.mark.parametrize("mass, distance", [(1.0, 25.0), (2.5, 110.0)])
def test_the_shadow_edge_is_the_exact_circle(mass, distance):
    metric = wv.Schwarzschild(mass=mass)
    cam = {"position": [0.0, -distance, 0.0], "look_at": [0.0, 0.0, 0.0], "up": [0, 0, 1], "fov": 50.0,
           "width": 96, "height": 72}  # fmt: skip
    points, label = edge_circle(metric, cam, 96, 72)
    alpha = metric.shadow_angle(distance)
    want = math.tan(alpha) / math.tan(math.radians(25.0)) * 36.0  # pixels from the centre
    radius = np.hypot(points[:, 0] - 48.0, points[:, 1] - 36.0)
    np.testing.assert_allclose(radius, want, rtol=1e-9)
    assert label == f"shadow radius {math.degrees(alpha):.3g}° (exact)"
    # the camera looking past the hole: the circle moves off centre, its angular radius stays
    off = dict(cam, look_at=[10.0, 0.0, 5.0])
    moved, _ = edge_circle(metric, off, 96, 72)
    assert moved[:, 0].mean() < 48.0 and moved[:, 1].mean() > 36.0  # the hole is left of and below the centre


def test_the_wormhole_window_and_no_edge_where_none_is_exact():
    cam = {"position": [0.0, -15.0, 0.0], "look_at": [0.0, 0.0, 0.0], "up": [0, 0, 1], "fov": 90.0,
           "width": 64, "height": 64}  # fmt: skip
    points, label = edge_circle(wv.EllisWormhole(throat=8.0), cam, 64, 64)
    alpha = math.asin(8.0 / 15.0)
    np.testing.assert_allclose(np.hypot(points[:, 0] - 32, points[:, 1] - 32), math.tan(alpha) * 32, rtol=1e-9)
    assert label.startswith("window radius 32.2°")
    assert edge_circle(wv.Kerr(mass=1.0, spin=0.9), cam, 64, 64) is None
    assert edge_circle(wv.Minkowski(), cam, 64, 64) is None and edge_circle(None, cam, 64, 64) is None


def test_the_view_marks_the_shadow_and_labels_it():
    plotter = wv.view(hole_scene(), off_screen=True, return_plotter=True, window_size=(1400, 700),
                      preview_width=48, spp=1)  # fmt: skip
    try:
        tv = plotter.teaching_view
        alpha = wv.Schwarzschild(mass=1.0).shadow_angle(25.0)
        assert tv.image_edge_label == f"shadow radius {math.degrees(alpha):.3g}° (exact)"
        assert "edge_circle" in tv._named_actors and "angle_ticks" in tv._named_actors
    finally:
        plotter.close()


def test_rays_leaving_the_diagram_are_cut_at_its_rim_one_cell_each():
    points = np.array([[0.0, 0, 0], [5.0, 0, 0], [20.0, 0, 0], [40.0, 0, 0], [0.0, 1, 0], [3.0, 1, 0], [2.0, 1, 0]])
    poly = pv.PolyData(points, lines=[4, 0, 1, 2, 3, 3, 4, 5, 6])
    poly.cell_data["bounce"] = np.array([0, 1])
    cut = _cut_lines_at(poly, 10.0)
    assert cut.n_cells == 2 and list(cut.cell_data["bounce"]) == [0, 1]
    first = np.asarray(cut.get_cell(0).points)
    assert len(first) == 3 and first[-1, 0] == 20.0  # up to the first point past the rim
    assert len(cut.get_cell(1).points) == 3


def test_the_3d_labels_find_new_places_after_the_scene_is_turned():
    plotter = wv.view("fig13", off_screen=True, return_plotter=True, window_size=(1400, 700), preview_width=32,
                      spp=1)  # fmt: skip
    try:
        tv = plotter.teaching_view
        r = tv._scene_renderer
        x0 = r.GetViewport()[0] * 1400
        for azimuth in (35.0, 80.0, 150.0):
            r.GetActiveCamera().Azimuth(azimuth)
            r.ResetCameraClippingRange()
            tv._press = (int(x0 + 300), 350)  # a drag in the 3-D panel ends
            tv._event_position = lambda: (int(x0 + 340), 360)
            tv._on_release()
            plotter.render()
            labels = [(role, box) for role, box in tv.text_boxes() if role == "label3d"]
            assert len(labels) >= 3 and overlapping(labels) == [], (azimuth, labels)
            for _, (lo, hi, _, _) in labels:
                assert lo >= x0 - 1 and hi <= 1401
    finally:
        plotter.close()
