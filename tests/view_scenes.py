"""Scenes the viewer tests share (tests/test_viewer.py, tests/test_view_layout.py)."""


def lensing_scene(width=48, height=24, metric=None):
    """A hole (Schwarzschild M = 1 unless ``metric``) in front of a glowing grid, camera 25 M away on the y
    axis looking at it."""
    return {
        "metric": metric or {"name": "schwarzschild", "params": [1.0]},
        "camera": {"position": [0.0, -25.0, 0.0], "look_at": [0.0, 0.0, 0.0], "up": [0, 0, 1], "fov": 50.0,
                   "width": width, "height": height},
        "textures": [{"type": "grid", "base": [0.02, 0.03, 0.08], "line_u": [1.0, 0.75, 0.3],
                      "line_v": [0.35, 0.7, 1.0], "cells": [16, 8], "width": 0.08}],
        "materials": [{"type": "emissive", "texture": 0, "strength": 1.0, "two_sided": True}],
        "shapes": [{"type": "quad", "corner": [-40.0, 15.0, -20.0], "edge_u": [80.0, 0.0, 0.0],
                    "edge_v": [0.0, 0.0, 40.0], "material": 0}],
        "environment": {"color": [0.0, 0.0, 0.0]},
    }  # fmt: skip
