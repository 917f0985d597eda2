"""A grid texture's marked lines (``mark_u``, ``mark_v``): one line of constant u and one of constant v in
colours of their own, so a class can follow one line's images through the lens (fig11a, fig11b)."""

import numpy as np

import warpviz as wv

RED, GREEN, GREY = [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.2, 0.2, 0.2]


def _wall(**marks):
    """A flat 8 x 8 emissive grid wall (4 x 4 cells) 10 in front of the camera, filling 69 % of a 60 degree view;
    lines 0.6 wide, 3.3 pixels."""
    grid = {"type": "grid", "base": [1.0, 1.0, 1.0], "line_u": GREY, "line_v": GREY, "cells": [4, 4], "width": 0.3}
    grid.update(marks)
    return {
        "metric": {"name": "minkowski", "params": []},
        "camera": {"position": [0, -10, 0], "look_at": [0, 0, 0], "up": [0, 0, 1], "fov": 60, "width": 64, "height": 64},
        "textures": [grid],
        "materials": [{"type": "emissive", "texture": 0, "strength": 1.0, "two_sided": True}],
        "shapes": [{"type": "quad", "corner": [-4, 0, -4], "edge_u": [8, 0, 0], "edge_v": [0, 0, 8], "material": 0}],
        "environment": {"color": [0, 0, 0]},
    }


def test_marked_lines_are_drawn_where_the_line_lies_and_nowhere_else():
    img = wv.render(_wall(mark_u=1, mark_u_color=RED, mark_v=3, mark_v_color=GREEN), spp=4, edge_samples=1).rgb
    red = (img[..., 0] > 0.5) & (img[..., 1] < 0.1)
    green = (img[..., 1] > 0.5) & (img[..., 0] < 0.1)
    # Line u = 1/4 lies at x = -2, line v = 3/4 at z = +2: (0.5 -+ 2 / (2 * 10 tan 30 deg)) * 64 = 20.9 px
    # from the left and from the top.
    half = 10 * np.tan(np.radians(30))
    at = (0.5 - 2 / (2 * half)) * 64
    cols, rows = np.nonzero(red)[1], np.nonzero(green)[0]
    assert red.sum() > 20 and green.sum() > 20
    assert abs(np.median(cols) - at) < 1.0 and np.ptp(cols) <= 3
    assert abs(np.median(rows) - at) < 1.0 and np.ptp(rows) <= 3
    # The other lines keep the grid's own colour.
    plain = wv.render(_wall(), spp=4, edge_samples=1).rgb
    differs = np.any(np.abs(img - plain) > 1e-6, axis=2)
    rows_d, cols_d = np.nonzero(differs)
    assert differs.sum() > 0 and np.all((np.abs(cols_d - at) <= 3) | (np.abs(rows_d - at) <= 3))


def test_unmarked_grid_is_unchanged_by_the_mark_keys():
    a = wv.render(_wall(), spp=2, edge_samples=1).rgb
    b = wv.render(_wall(mark_u=-1, mark_v=-1, mark_u_color=RED, mark_v_color=GREEN), spp=2, edge_samples=1).rgb
    np.testing.assert_array_equal(a, b)


def test_the_shipped_grid_walls_mark_one_red_and_one_green_line():
    for name in ("fig11a", "fig11b"):
        grid = next(t for t in wv.scene.load_scene(name).native()["textures"] if t["type"] == "grid")
        assert grid["mark_u"] == grid["mark_v"] == 9
        assert grid["mark_u_color"][1] > grid["mark_u_color"][0] and grid["mark_v_color"][0] > grid["mark_v_color"][1]
