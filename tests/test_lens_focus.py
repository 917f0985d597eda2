"""The lens connection's focus (integrators/lens_focus.h): a share of a light's points drawn about the point of its
plane straight behind the hole, as densely as a point lens magnifies them. Its draws follow the density it reports
(which integrates to 1 over the light), the density has the magnification's shape, it applies only where a lens
focuses the light onto the vertex, and renders with it keep the mean of brute force and are less noisy where the
floor under a hole is lit by a lamp's magnified ring."""

import math

import numpy as np
import pytest

import warpviz as wv
from warpviz._native import testing
from native_scenes import metric, room
from test_render import _image_means, assert_same_mean

NONE = np.zeros(0)
# Lights in a ceiling at z = 11.99 facing down (as room()'s lamp): a square, a skew quad, a disk and a ring.
LIGHTS = {
    "square": ((np.array([-3.0, -3.0, 11.99]), np.array([0.0, 6.0, 0.0]), np.array([6.0, 0.0, 0.0]), 0.0, 0.0), 36.0),
    "skew": ((np.array([-3.0, -3.0, 11.99]), np.array([6.0, 0.0, 0.0]), np.array([2.0, 5.0, 0.0]), 0.0, 0.0), 30.0),
    "disk": ((np.array([0.0, 1.0, 11.99]), np.array([1.0, 0.0, 0.0]), np.array([0.0, -1.0, 0.0]), 0.0, 3.0),
             9.0 * math.pi),
    "ring": ((np.array([0.0, 1.0, 11.99]), np.array([1.0, 0.0, 0.0]), np.array([0.0, -1.0, 0.0]), 1.5, 3.0),
             6.75 * math.pi),
}


def _mu(u):
    """The thin point lens's total magnification of a source u Einstein radii off the axis."""
    return (u * u + 2.0) / (u * np.sqrt(u * u + 4.0))


def _on_light(name, p):
    (p0, p1, p2, r_in, r_out), _ = LIGHTS[name]
    if r_out > 0.0:
        rho = np.hypot(*(p[:, :2] - p0[:2]).T)
        return (rho >= r_in - 1e-9) & (rho <= r_out + 1e-9)
    rel = p - p0
    m = np.array([p1[:2], p2[:2]]).T  # in the plane z = const: rel = s p1 + r p2
    s, r = np.linalg.solve(m, rel[:, :2].T)
    return (s >= -1e-9) & (s <= 1 + 1e-9) & (r >= -1e-9) & (r <= 1 + 1e-9)


# Where B* (the line from the vertex through the centre meets the ceiling) lies: on each light (a ring: in its hole),
# and just beside it (within kFocusReach Einstein radii, ~1.5 here).
FOCI = {"square": ((0.0, -1.0), (-0.5, -3.4)), "skew": ((0.0, -1.0), (0.0, -3.4)), "disk": ((0.0, -1.0), (0.8, -2.3)),
        "ring": ((0.2, 1.0), (0.8, -2.3))}


@pytest.mark.parametrize("name", list(LIGHTS))
@pytest.mark.parametrize("where", [0, 1], ids=["on-the-light", "beside-it"])
def test_the_focus_draws_by_its_density_which_integrates_to_one(name, where):
    """Over an n x n grid of (u1, u2) every draw lies on the light, the mean of 1 / density over the grid is the
    light's area (the density integrates to 1 over the points it draws), and the means of x / density and y /
    density are the light's first moments (the draws follow the density, not only its total)."""
    args, area = LIGHTS[name]
    a = -np.array([*FOCI[name][where], 11.99]) * (12.0 / 11.99)  # on the floor, B* where FOCI says
    n = 96
    pts, dens, drawn, _, share = testing.lens_focus_draws(1.0, a, *args, n, NONE)
    assert share == 0.9
    drawn = drawn.astype(bool)
    assert drawn.mean() > 0.97  # (a disk seen from outside: its bounding circle's angles, a few rays miss it)
    p = pts[drawn]
    assert np.allclose(p[:, 2], 11.99) and _on_light(name, p).all()
    assert np.all(dens[drawn] > 0)
    inv = np.zeros(n * n)
    inv[drawn] = 1.0 / dens[drawn]
    assert inv.mean() == pytest.approx(area, rel=0.01)
    # first moments against a fine uniform grid over the light's bounding square
    g = np.linspace(-8.0, 8.0, 801)
    gx, gy = np.meshgrid(g, g)
    q = np.column_stack([gx.ravel(), gy.ravel(), np.full(gx.size, 11.99)])
    inside = _on_light(name, q)
    for k in (0, 1):
        exact = q[inside, k].mean() * area
        est = np.zeros(n * n)
        est[drawn] = p[:, k] / dens[drawn]
        assert est.mean() == pytest.approx(exact, abs=0.01 * area * 3.0)


def test_the_focus_has_the_point_lens_magnification_along_a_ray():
    """Along one ray from B* (where the line from the vertex through the centre meets the light's plane) the density
    goes as mu(rho / rho_E), rho_E = sqrt(4 M D_OB D_AB / D_AO), and is 0 off the light."""
    args, _ = LIGHTS["square"]
    mass, a = 1.0, np.array([0.0, -1.0, -12.0])
    b = a * (1.0 - (a[2] - 11.99) / a[2])  # B*, on the square
    d_ao, d_ob = np.linalg.norm(a), np.linalg.norm(b)
    rho_e = math.sqrt(4.0 * mass * d_ob * (d_ao + d_ob) / d_ao)
    rho = np.array([0.05, 0.3, 1.0, 2.0, 3.5])
    at = b + np.outer(rho, [1.0, 0.0, 0.0])  # towards x = +3 (the edge), then off the light
    dens = testing.lens_focus_draws(mass, a, *args, 1, at.ravel())[3]
    assert dens[-1] == 0.0
    ratio = dens[:-1] / _mu(rho[:-1] / rho_e)
    assert np.allclose(ratio, ratio[0], rtol=1e-12)


def _focus_at(bstar):
    """The floor vertex whose B* (on the square's plane) is bstar, the square's grid of 40 x 40 points, the focus's
    own density there, its share and the thin lens's mu there."""
    args, area = LIGHTS["square"]
    b = np.array([*bstar, 11.99])
    a = -b * (12.0 / 11.99)
    g = (np.arange(40) + 0.5) / 40 * 6.0 - 3.0
    gx, gy = np.meshgrid(g, g)
    pts = np.column_stack([gx.ravel(), gy.ravel(), np.full(gx.size, 11.99)])
    _, _, _, dens, share = testing.lens_focus_draws(1.0, a, *args, 1, pts.ravel())
    d_ao, d_ob = np.linalg.norm(a), np.linalg.norm(b)
    rho_e = math.sqrt(4.0 * d_ob * (d_ao + d_ob) / d_ao)
    return a, pts, dens, share, _mu(np.linalg.norm(pts - b, axis=1) / rho_e), area


@pytest.mark.parametrize("bstar", [(0.0, 2.4), (1.5, -2.0)], ids=["near-an-edge", "near-a-corner"])
def test_the_focus_density_has_the_magnification_shape_all_round_b_star(bstar):
    """With B* near the light's edge the rays from it to that edge are short: drawn as often as the long ones (the
    angles drawn evenly) the density was ~10x the magnification's shape along them. Drawn as what the point lens
    magnifies along each (the angles' bins), the density over the whole light is mu's shape to within the bins: 90 %
    of the grid within 15 % of the median ratio (measured 0.91-1.08 and 0.92-1.08)."""
    _, _, dens, _, mu, _ = _focus_at(bstar)
    ratio = dens / mu
    lo, hi = np.percentile(ratio, [5, 95]) / np.median(ratio)
    assert 0.85 < lo and hi < 1.15


def test_the_focus_draws_a_light_sample_of_low_variance_from_the_floor():
    """What the light strategy's draws bring from the floor whose B* lies near the lamp's edge, by the lens map's
    exact weights W (the images' cos theta |dOmega / dA|) over the mixture's density: variance 0.015 of its mean
    squared (1.5 by area alone, 0.107 with the angles drawn evenly at share 0.5)."""
    a, pts, dens, share, _, area = _focus_at((0.0, 2.4))
    w = np.array([testing.lens_images("schwarzschild", [1.0], a, 1, np.array([0.0, 0.0, 1.0]), p,
                                      np.array([0.0, 0.0, -1.0]), 1, area, False, 3)["weights"].sum() for p in pts])
    p = (1.0 - share) / area + share * dens
    mean = w.mean() * area
    assert (w * w / p).mean() * area / mean**2 - 1.0 < 0.03
    assert w.var() / w.mean() ** 2 > 1.0  # (by area alone it is far from even)


@pytest.mark.parametrize("case", ["no-mass", "light-on-the-vertex-side", "far-from-the-axis", "beside-the-hole"])
def test_the_focus_applies_only_where_a_lens_focuses_the_light_onto_the_vertex(case):
    args, _ = LIGHTS["square"]
    mass, a = 1.0, np.array([0.0, -1.0, -12.0])
    if case == "no-mass":
        mass = 0.0
    elif case == "light-on-the-vertex-side":  # a vertex above the centre: the line through it meets the plane first
        a = np.array([0.0, -1.0, 6.0])
    elif case == "far-from-the-axis":  # the floor near the wall: B* (12, 12) far from the lamp
        a = np.array([-12.0, -12.0, -12.0])
    else:  # a vertex level with the centre: the line through it never meets the ceiling
        a = np.array([6.0, 0.0, 0.0])
    assert testing.lens_focus_draws(mass, a, *args, 4, NONE)[4] == 0.0


def _floor_room(m):
    """room()'s lamp straight above the hole, and a camera that looks down at the floor under it."""
    sc = room(m, size=(12, 9), light=3.0, spheres=False)
    sc["camera"]["look_at"] = [0.0, 0.0, -12.0]
    return sc


@pytest.mark.parametrize("m", [metric("schwarzschild", 1.0), metric("kerr", 1.0, 0.9)], ids=["schwarzschild", "kerr"])
def test_the_focus_keeps_the_mean_of_brute_force(m):
    sc = _floor_room(m)
    kw = {"spp": 8, "max_depth": 2, "edge_samples": 1}
    focus = _image_means(sc, range(12), **kw)
    brute = _image_means(sc, range(12, 36), light_sampling=False, **kw)
    assert focus.mean() > 0
    assert_same_mean(focus, brute, slack=2e-3 * brute.mean())


def test_the_focus_lowers_the_noise_of_the_floor_under_a_hole():
    """Schwarzschild, the camera looking down at the floor under the hole lit by the lamp above it (the same seeds
    with and without the focus: measured 0.51x the variance; fig07 at 48 x 36: 0.77x the error)."""
    sc = _floor_room(metric("schwarzschild", 1.0))

    def frames(focus):
        return np.stack([wv.render(sc, spp=8, seed=s, max_depth=2, edge_samples=1, lens_focus=focus).rgb
                         for s in range(16)]).astype(np.float64)

    with_focus, without = frames(True), frames(False)
    assert with_focus.var(axis=0).mean() < 0.75 * without.var(axis=0).mean()
