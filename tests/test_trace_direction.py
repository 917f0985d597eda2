"""docs/trace-direction.md: ``trace`` follows emitted light forward, the renderer received light backward;
in Kerr a fan launched from the camera with ``trace`` shows the mirror-image shadow."""

import math

import numpy as np
import pytest

import warpviz as wv
from warpviz.scene.camera import pinhole_directions

W = 401
R0, SPIN = 30.0, 0.9


@pytest.fixture(scope="module")
def row():
    """The worked example of the doc: the rendered shadow of one row of pixels, and the forward fans of
    the same pixel directions as they are, mirrored (y -> -y), and past the hole of opposite spin."""
    camera = {"position": [-R0, 0.0, 0.0], "look_at": [0.0, 0.0, 0.0], "up": [0.0, 0.0, 1.0],
              "fov": 2 * math.degrees(math.atan(math.tan(math.radians(20)) / W)), "width": W, "height": 1}  # fmt: skip
    scene = {"metric": {"name": "kerr", "params": [1.0, SPIN]}, "camera": camera, "textures": [],
             "materials": [], "shapes": [], "environment": {"color": [1.0, 1.0, 1.0]}}  # fmt: skip
    shadow = wv.render(scene, spp=1, aovs=["status"]).aovs["status"][0] == 2
    d = pinhole_directions(camera, np.column_stack([np.arange(W), np.zeros(W, dtype=int)]))
    kerr = wv.Kerr(mass=1.0, spin=SPIN)
    captured = {
        "forward": wv.trace(kerr, camera["position"], d).status_names == "horizon",
        "mirrored": wv.trace(kerr, camera["position"], d * [1, -1, 1]).status_names == "horizon",
        "opposite": wv.trace(wv.Kerr(mass=1.0, spin=-SPIN), camera["position"], d).status_names == "horizon",
    }
    return shadow, d, captured


def edges(inside: np.ndarray, d: np.ndarray) -> tuple[float, float]:
    """Angles (degrees) from the line of sight of the shadow's edges on the +y and the -y side: halfway
    between the last pixel inside and the first outside."""
    cols = np.flatnonzero(inside)
    sy = d[:, 1] / np.linalg.norm(d, axis=1)
    plus = np.arcsin(0.5 * (sy[cols.min()] + sy[cols.min() - 1]))
    minus = np.arcsin(0.5 * (sy[cols.max()] + sy[cols.max() + 1]))
    return math.degrees(plus), -math.degrees(minus)


def impact(alpha_deg: float) -> float:
    """b = r sin(alpha) / sqrt(1 - 2M/r), the impact parameter of a direction seen by the static observer."""
    return R0 * math.sin(math.radians(alpha_deg)) / math.sqrt(1.0 - 2.0 / R0)


def test_forward_trace_shows_the_mirror_image_shadow(row):
    shadow, d, captured = row
    assert shadow.sum() > 150
    assert np.sum(shadow != captured["forward"]) == 141  # the forward fan is the wrong picture
    assert np.sum(shadow != captured["mirrored"]) <= 4  # edge pixels, where the render's sample is off-centre
    np.testing.assert_array_equal(captured["mirrored"], captured["opposite"])  # mirror = opposite spin


def test_shadow_edges_are_the_equatorial_photon_orbits(row):
    """The received light's prograde edge is on the +y side (b ~ 2.84 M), the forward fan's on -y."""
    shadow, d, captured = row
    a = SPIN
    b_orbit = {name: -(r**3 - 3 * r**2 + a * a * r + a * a) / (a * (r - 1.0))
               for name, r in zip(("prograde", "retrograde"), wv.Kerr(mass=1.0, spin=a).photon_orbit_radii)}  # fmt: skip
    assert b_orbit["prograde"] == pytest.approx(2.8444, abs=1e-4)
    assert b_orbit["retrograde"] == pytest.approx(-6.8323, abs=1e-4)
    plus, minus = edges(shadow, d)
    assert plus == pytest.approx(5.44, abs=0.12) and minus == pytest.approx(12.44, abs=0.12)
    # b from the static observer's angle is Schwarzschild's formula: in Kerr at 30 M it is off by ~0.1 M
    assert impact(plus) == pytest.approx(b_orbit["prograde"], abs=0.15)
    assert impact(minus) == pytest.approx(-b_orbit["retrograde"], abs=0.2)
    f_plus, f_minus = edges(captured["forward"], d)  # the mirror image of the mirrored fan's, to a pixel (0.1 deg)
    m_plus, m_minus = edges(captured["mirrored"], d)
    assert f_plus == pytest.approx(m_minus, abs=0.11) and f_minus == pytest.approx(m_plus, abs=0.11)
    assert f_plus == pytest.approx(12.64, abs=0.12) and f_minus == pytest.approx(5.34, abs=0.12)
