"""Facts the core and the Python package share come from one place (the core) and agree."""

import warpviz as wv
from warpviz._native import core


def test_ray_status_codes_are_the_cores():
    assert [s.name.lower() for s in wv.RayStatus] == list(core.status_names())
    assert [int(s) for s in wv.RayStatus] == list(range(len(core.status_names())))


def test_render_statistics_name_every_status():
    img = wv.render({"metric": {"name": "minkowski", "params": []},
                     "camera": {"position": [0, -5, 0], "look_at": [0, 0, 0], "width": 2, "height": 2},
                     "materials": [], "shapes": [], "environment": {"color": [0.1, 0.1, 0.1]}},
                    spp=1, progress=None)  # fmt: skip
    assert list(img.stats["segments_by_status"]) == list(core.status_names())


def test_recorded_columns_follow_the_metrics_invariants():
    for metric in (wv.Kerr(mass=1.0, spin=0.5), wv.EllisWormhole()):
        rays = wv.trace(metric, [0.0, -30.0, 0.0], [0.0, 1.0, 0.1], record=True)
        drift_columns = {k[: -len("_drift")] for k in rays.point_data if k.endswith("_drift")}
        assert drift_columns == set(metric.invariant_names[1:])
