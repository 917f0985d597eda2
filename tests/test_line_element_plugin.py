"""Metrics from their line element as plugins of the core (engine/plugin.h, line_element/plugin.py,
line_element/custom.py): they trace and render like the built-in metric they write out, the compile cache
is keyed by content, and a missing compiler or a foreign library gets a clear error."""

import os
import pickle
import subprocess
import sys

import numpy as np
import pytest

import warpviz as wv
from warpviz._native import core
from warpviz.spacetime.line_element import LineElementError
from warpviz.spacetime.line_element import plugin as plugin_mod
from warpviz.spacetime.line_element.custom import LineElementDefinition
from warpviz.spacetime.line_element.plugin import CompilerNotFoundError

from conftest import EXPRESSION_METRICS, expression_metric
from native_scenes import room
from test_render import _image_means, assert_same_mean

try:
    plugin_mod.find_compiler()
except CompilerNotFoundError as exc:  # pragma: no cover - every machine that built warpviz has one
    pytest.skip(f"no C++ compiler: {exc}", allow_module_level=True)


def _fan(n: int = 600, seed: int = 1):
    """Rays from (0, -20, 1) into the half space towards the hole: some escape, some fall in."""
    rng = np.random.default_rng(seed)
    d = rng.normal(size=(n, 3))
    d[:, 1] = 3.0 * np.abs(d[:, 1])
    return np.array([0.0, -20.0, 1.0]), d / np.linalg.norm(d, axis=1)[:, None]


def test_kerr_schild_schwarzschild_traces_as_the_built_in_metric():
    """The same Hamilton equations in another order of operations: every ray ends the same way after the same
    number of steps, at the same place to 1e-12 of its radius (5e-12 for the few that graze the photon
    sphere, where any rounding grows)."""
    m = expression_metric("ks_schwarzschild")
    assert m.landmarks == {"horizon": 2.0, "capture": 2.5, "photon_sphere": 3.0, "mass": 1.0}
    o, d = _fan()
    for tol in (1e-9, 1e-12):
        a, b = wv.trace(m, o, d, tol=tol), wv.trace(wv.Schwarzschild(mass=1.0), o, d, tol=tol)
        assert (a.status == b.status).all() and (a.n_steps == b.n_steps).all()
        assert {"escaped", "horizon"} == set(b.status_names)
        rel = np.abs(a.final_positions - b.final_positions).max(axis=1) / np.linalg.norm(b.final_positions, axis=1)
        assert np.percentile(rel, 95) < 1e-12 and rel.max() < 5e-12


def test_a_static_chart_absorbs_rays_at_the_capture_radius_and_bends_light_as_the_built_in_metric():
    """Reissner-Nordström in Schwarzschild-like coordinates (g_rr = 1/f diverges at the horizon): rays that fall
    in end at the capture radius (the chart cannot reach the horizon); those that escape leave in the
    built-in Kerr-Schild metric's directions (the two charts differ only in t)."""
    m = expression_metric("static_charged")
    rn = wv.ReissnerNordstrom(mass=1.0, charge=0.8)
    assert {k: m.landmarks[k] for k in rn.landmarks} == pytest.approx(rn.landmarks, rel=1e-14)
    o, d = _fan()
    a, b = wv.trace(m, o, d, tol=1e-12), wv.trace(rn, o, d, tol=1e-12)
    assert (a.status_names == b.status_names).all()
    fell = a.status_names == "horizon"
    assert fell.any() and np.allclose(np.linalg.norm(a.final_positions[fell], axis=1), m.landmarks["capture"], rtol=1e-9)
    out = ~fell
    assert np.abs(a.final_directions[out] - b.final_directions[out]).max() < 1e-9


def test_a_line_element_metric_renders_as_the_built_in_one():
    """A small curved scene through the expression metric and the built-in: the same picture, pixel for
    pixel, except where a ray's last bits decide which side of an edge it lands."""
    m = expression_metric("ks_schwarzschild")
    scene = {
        "metric": {"name": m.name, "params": m.param_values},
        "camera": {"position": [0.0, -15.0, 2.0], "look_at": [0.0, 0.0, 0.0], "fov": 50, "width": 24, "height": 18},
        "textures": [{"type": "checker", "color_a": [1, 1, 1], "color_b": [0.1, 0.2, 0.8], "scale": [8.0, 4.0]}],
        "materials": [{"type": "diffuse", "texture": 0}],
        "shapes": [{"type": "sphere", "center": [0, 8, 0], "radius": 3, "material": 0}],
        "environment": {"color": [0.6, 0.5, 0.4]},
    }
    a = wv.render(scene, spp=2, seed=3)
    scene["metric"] = {"name": "schwarzschild", "params": [1.0]}
    b = wv.render(scene, spp=2, seed=3)
    diff = np.abs(a.rgb - b.rgb).max(axis=2)
    assert (diff > 1e-5).mean() < 0.02 and np.abs(a.rgb.mean() - b.rgb.mean()) < 1e-3


def test_the_same_definition_gives_the_same_class_and_the_cache_is_keyed_by_content(tmp_path, monkeypatch):
    m = expression_metric("ks_schwarzschild")
    again = wv.Metric.from_line_element(name="ks_schwarzschild", **EXPRESSION_METRICS["ks_schwarzschild"])
    assert type(again) is type(m) and again == m and again.name == m.name
    assert pickle.loads(pickle.dumps(m)) == m  # how a Dask worker gets it
    assert LineElementDefinition(m.definition, parameters={"M": 2.0}).registry_name != m.name  # another default
    assert LineElementDefinition(m.definition).registry_name == m.name
    assert m.to_dict()["line_element"] == EXPRESSION_METRICS["ks_schwarzschild"]["line_element"]

    # another process finds the libraries in the cache and compiles nothing
    code = ("import warpviz as wv, sys; sys.path.insert(0, 'tests'); from conftest import expression_metric; "
            "m = expression_metric('ks_schwarzschild'); print(m.name); "
            "wv.Metric.from_line_element(name='ks_schwarzschild', progress=lambda s: print('COMPILED', s), "
            "**__import__('conftest').EXPRESSION_METRICS['ks_schwarzschild'])")  # fmt: skip
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120,
                         cwd=os.path.dirname(os.path.dirname(__file__)))  # fmt: skip
    assert run.returncode == 0, run.stderr
    assert run.stdout.split() == [m.name]
    libraries = sorted(p.name for p in plugin_mod.cache_dir().glob("*.so"))
    assert any(name.endswith("-facts.so") for name in libraries) and any(n.endswith("-dopri5.so") for n in libraries)


def test_another_stepper_is_compiled_when_a_render_asks_for_it():
    """rk4 and dop853 renderers are compiled on first use only (the tracers of all three are in the facts)."""
    m = expression_metric("ks_schwarzschild")
    assert core.has_stepper(m.name, "dopri5", True) and not core.has_stepper(m.name, "rk4", True)
    assert all(core.has_stepper(m.name, s, False) for s in wv.STEPPERS)
    m.prepare(stepper="rk4")
    assert core.has_stepper(m.name, "rk4", True)


def test_no_compiler_is_a_clear_error_saying_what_to_install(monkeypatch, tmp_path):
    monkeypatch.setenv("WARPVIZ_CACHE_DIR", str(tmp_path))
    monkeypatch.setenv("CXX", str(tmp_path / "no-such-compiler"))
    with pytest.raises(CompilerNotFoundError, match="apt-get install g\\+\\+"):
        wv.Metric.from_line_element("-dt**2 + dx**2 + dy**2 + dz**2 + M*dx**2", parameters={"M": 0.5}, name="nocxx")
    monkeypatch.delenv("CXX")
    monkeypatch.setenv("PATH", str(tmp_path))
    with pytest.raises(CompilerNotFoundError, match="no C\\+\\+ compiler"):
        plugin_mod.find_compiler()


def test_a_foreign_or_mismatched_library_is_refused_by_name(tmp_path):
    cxx = plugin_mod.find_compiler()
    fake = tmp_path / "fake.cpp"
    fake.write_text('extern "C" const char* warpviz_plugin_abi() { return "warpviz-plugin-0"; }\n'
                    'extern "C" void warpviz_plugin_take(void*) {}\n')  # fmt: skip
    subprocess.run([*cxx, "-shared", "-fPIC", str(fake), "-o", str(tmp_path / "fake.so")], check=True)
    with pytest.raises(RuntimeError, match="built against other warpviz headers"):
        core.load_metric_plugin(str(tmp_path / "fake.so"))
    plain = tmp_path / "plain.cpp"
    plain.write_text("int answer() { return 42; }\n")
    subprocess.run([*cxx, "-shared", "-fPIC", str(plain), "-o", str(tmp_path / "plain.so")], check=True)
    with pytest.raises(RuntimeError, match="is not a warpviz metric plugin"):
        core.load_metric_plugin(str(tmp_path / "plain.so"))
    with pytest.raises(RuntimeError, match="cannot load metric plugin"):
        core.load_metric_plugin(str(tmp_path / "missing.so"))


@pytest.mark.parametrize("kwargs, where", [
    (dict(line_element="-dt**2 + dx**2 + dy**2 + dz**2", parameters={"M": float("nan")}), "parameters.M"),
    (dict(line_element="-dt**2 + dx**2 + dy**2 + dz**2", parameters={"M": 1.0}, horizon_radius="2*r"), "horizon_radius"),
    (dict(line_element="-dt**2 + dx**2 + dy**2 + dz**2", parameters={"M": 1.0}, horizon_radius="-M"), "horizon_radius"),
    (dict(line_element="-dt**2 + dx**2 + dy**2 + dz**2", parameters={"M": 1.0}, event_horizon="M"), "event_horizon"),
    (dict(line_element="-dt**2 + dx**2 + dy**2 + dz**2", name="1st"), "name"),
    (dict(line_element="-dt**2 + dx**2 + dy**2 + dz**2 + __import__('os')"), "line_element"),
    # wormholes: a throat radius to set the chart, the same metric on both sheets, the throat where it says
    (dict(line_element="-dt**2 + dl**2 + (1 + l**2)*dOmega**2", coordinates="wormhole"), "throat_radius"),
    (dict(line_element="-dt**2 + dl**2 + (1 + l**2 + l**3/9)*dOmega**2", coordinates="wormhole",
          throat_radius="1"), "line_element"),
    (dict(line_element="-dt**2 + dl**2 + (4 + l**2)*dOmega**2", coordinates="wormhole", throat_radius="1"),
     "line_element"),
])  # fmt: skip
def test_bad_definitions_are_refused_before_any_compilation(kwargs, where, monkeypatch, tmp_path):
    monkeypatch.setenv("CXX", str(tmp_path / "no-such-compiler"))  # nothing reaches the compiler
    with pytest.raises(LineElementError) as err:
        wv.Metric.from_line_element(**kwargs)
    assert err.value.where == where


SCENE = """\
version = 1
[metric]
name = "custom"
label = "ks_schwarzschild"
line_element = "-dt**2 + dx**2 + dy**2 + dz**2 + 2*M/r*(dt + (x*dx + y*dy + z*dz)/r)**2"
parameters = { M = 1.0 }
horizon_radius = "2*M"
photon_sphere_radius = "3*M"
mass = "M"
[camera]
position = [0, -15, 2]
look_at = [0, 0, 0]
fov = 50
[environment]
color = [0.6, 0.5, 0.4]
[render]
width = 12
height = 9
spp = 1
"""


def test_a_scene_file_names_a_metric_by_its_line_element(tmp_path):
    """The [metric] table of docs/line-element.md: the same metric (and plugin) as from Python, its table
    written back by to_dict, and a render."""
    path = tmp_path / "custom.toml"
    path.write_text(SCENE)
    scene = wv.scene.load_scene(path)
    m = expression_metric("ks_schwarzschild")
    assert type(scene.metric) is type(m) and scene.metric == m
    back = m.to_dict()
    assert back["name"] == "custom" and back["label"] == "ks_schwarzschild" and back["horizon_radius"] == "2*M"
    assert wv.spacetime.metric_from_dict(back) == m
    img = wv.render(path)
    assert img.shape == (9, 12) and np.isfinite(img.rgb).all()


def test_an_expression_error_in_a_scene_file_points_at_its_column(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text(SCENE.replace("2*M/r*(dt", "2*M/q*(dt"))
    with pytest.raises(wv.scene.SceneError) as err:
        wv.scene.load_scene(path)
    line = SCENE.splitlines()[4]
    assert (err.value.line, err.value.column) == (5, line.index("2*M/r") + 1 + 4)
    assert "unknown name 'q'" in str(err.value) and err.value.key == "metric.line_element"


def test_a_spacetime_that_is_not_asymptotically_flat_escapes_at_its_escape_radius():
    """Schwarzschild-de Sitter (the shipped scene's): rays that leave end on the escape sphere inside the
    cosmological horizon with their direction of motion there, rays that fall in end at the capture radius,
    and a camera beyond the escape radius is refused."""
    m = wv.scene.load_scene("line_element_schwarzschild_de_sitter").metric
    lm = m.landmarks
    assert lm["horizon"] == pytest.approx(5.003130874065572, rel=1e-12) and lm["photon_sphere"] == 7.5
    assert lm["escape"] == pytest.approx(0.95 * 197.45149533247064, rel=1e-12)
    o, d = _fan(200)
    rays = wv.trace(m, o * 5.0, d, tol=1e-10)  # from (0, -100, 5)
    out = rays.status_names == "escaped"
    assert out.any() and (rays.status_names[~out] == "horizon").all()
    np.testing.assert_allclose(np.linalg.norm(rays.final_positions[out], axis=1), lm["escape"], rtol=1e-9)
    np.testing.assert_allclose(np.linalg.norm(rays.final_directions[out], axis=1), 1.0, rtol=1e-12)
    with pytest.raises(ValueError, match="beyond the metric's escape radius"):
        wv.trace(m, [0.0, -190.0, 0.0], [0.0, 1.0, 0.0])


def test_a_dask_worker_rebuilds_the_metric_and_renders_it_bit_for_bit(tmp_path):
    """The workers are other processes: the metric travels with each task as its definition, each worker
    loads the plugin from the shared cache (compiling nothing), and the image is the local one."""
    distributed = pytest.importorskip("distributed")
    path = tmp_path / "custom.toml"
    path.write_text(SCENE)
    local = wv.render(path, spp=2, threads=2)
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=":0") as cl, \
            distributed.Client(cl) as client:  # fmt: skip
        remote = wv.render(path, spp=2, client=client, tile=5)
        name = wv.scene.load_scene(path).metric.name
        assert list(client.run(lambda: name in {m["name"] for m in wv.registered_metrics()}).values()) == [True]
    np.testing.assert_array_equal(remote.rgb, local.rgb)


def test_parameters_that_make_a_landmark_unreal_are_refused_by_name():
    """The landmarks are the line element's relation between its parameters (|Q| <= M for a horizon):
    the core refuses other values, naming the landmark, as it refuses |Q| > M for the built-in metric."""
    m = expression_metric("static_charged")
    assert "every landmark" in m.registry_entry["param_relation"]
    with pytest.raises(ValueError, match=r"horizon_radius = M \+ sqrt\(M\*\*2 - Q\*\*2\) is -?nan, not a real radius"):
        type(m)(M=1.0, Q=1.5)
    assert type(m)(M=1.0, Q=0.9).horizon_radius == pytest.approx(1.0 + 0.19**0.5, rel=1e-14)


def test_the_flat_limit_traces_straight_lines():
    """M = 0 makes the Kerr-Schild line element Minkowski's: every ray escapes in its starting direction."""
    m = expression_metric("ks_schwarzschild")
    flat = type(m)(M=0.0)
    o, d = _fan(100)
    rays = wv.trace(flat, o, d, tol=1e-10)
    assert set(rays.status_names) == {"escaped"}
    np.testing.assert_allclose(rays.final_directions, d, rtol=0, atol=1e-12)


def test_kerr_written_in_kerr_schild_form_traces_as_the_built_in_metric():
    """Kerr a = 0.9 from its line element: the rays that escape from the built-in leave in the same directions
    to 1e-9 (falling rays end a little deeper here: at |x| = r+ rather than Boyer-Lindquist r = r+)."""
    from test_line_element import KERR_DEFINITIONS

    m = wv.Metric.from_line_element("-dt**2 + dx**2 + dy**2 + dz**2 + f*l**2", parameters={"M": 1.0, "spin": 0.9},
                                    definitions=KERR_DEFINITIONS, horizon_radius="M + sqrt(M**2 - (spin*M)**2)",
                                    mass="M", name="kerr_ks")  # fmt: skip
    assert m.invariant_names == ["H", "E", "Lz"]
    o, d = _fan(400)
    a, b = wv.trace(m, o, d, tol=1e-12), wv.trace(wv.Kerr(mass=1.0, spin=0.9), o, d, tol=1e-12)
    out = b.status_names == "escaped"
    assert out.sum() > 100 and (a.status_names == b.status_names).mean() > 0.99
    both = out & (a.status_names == "escaped")
    assert np.abs(a.final_directions[both] - b.final_directions[both]).max() < 1e-9


def test_a_cache_folder_that_cannot_be_written_says_how_to_choose_another(tmp_path, monkeypatch):
    blocker = tmp_path / "not-a-folder"
    blocker.write_text("")
    monkeypatch.setenv("WARPVIZ_CACHE_DIR", str(blocker))
    with pytest.raises(plugin_mod.PluginBuildError, match="set WARPVIZ_CACHE_DIR to a folder you can write"):
        plugin_mod.build_parts("// nothing\n", ["facts"])


def test_the_ellis_wormhole_from_its_line_element_traces_as_the_built_in_one_on_both_sheets():
    """coordinates = "wormhole": ds^2 = -dt^2 + dl^2 + (b^2 + l^2) dOmega^2 in the same chart as the Ellis file
    (l = (rho - b^2/rho)/2, the inversion between the sheets): the same rays, through the throat and past it."""
    m = expression_metric("ellis_expr")
    assert m.sheets == 2 and m.landmarks["throat"] == 1.5
    ellis = wv.EllisWormhole(throat=1.5)
    dirs = np.array([[1.0, 0.03 * k, 0.01] for k in range(-25, 26)])
    for sheet in (1, -1):
        a = wv.trace(m, [-8.0, 0.5, 0.0], dirs, tol=1e-12, stepper="dop853", sheets=[sheet] * len(dirs))
        b = wv.trace(ellis, [-8.0, 0.5, 0.0], dirs, tol=1e-12, stepper="dop853", sheets=[sheet] * len(dirs))
        assert set(a.final_sheets) == {1, -1}  # some rays pass the throat, some do not
        np.testing.assert_array_equal(a.final_sheets, b.final_sheets)
        np.testing.assert_allclose(a.final_directions, b.final_directions, atol=1e-11)
        np.testing.assert_allclose(a.final_positions, b.final_positions, rtol=1e-11)
    with pytest.raises(ValueError, match="inside the wormhole throat"):
        wv.trace(m, [0.5, 0.0, 0.0], [1.0, 0.0, 0.0])


def test_the_interstellar_wormhole_scene_has_the_window_its_comment_states():
    """line_element_interstellar_wormhole: with g_tt = -1 every ray below the throat radius passes, so from the
    camera at areal radius 15.13 the window is asin(8 / 15.13) = 31.9 degrees whatever R(l) (the scene's
    header comment); just inside it a ray reaches the other sheet, just outside it does not."""
    sc = wv.scene.load_scene("line_element_interstellar_wormhole")
    assert sc.metric.sheets == 2 and sc.metric.landmarks["throat"] == 8.0
    position = np.array(sc.camera["position"])
    radius = float(np.linalg.norm(position))
    window = np.arcsin(8.0 / radius)
    assert np.degrees(window) == pytest.approx(31.91, abs=0.01)
    inward = -position / radius
    side = np.cross(inward, [0.0, 0.0, 1.0])
    side /= np.linalg.norm(side)
    angles = window + np.radians([-0.2, 0.2])
    dirs = np.cos(angles)[:, None] * inward + np.sin(angles)[:, None] * side
    rays = wv.trace(sc.metric, position, dirs, escape_radius=500)
    assert rays.final_sheets.tolist() == [-1, 1]


@pytest.mark.parametrize("key", ["ks_schwarzschild", "static_charged"])
def test_a_line_element_with_a_mass_draws_light_samples_from_the_schwarzschild_lens_map(key):
    """A metric from its line element that gives a mass, asymptotically flat and without a throat, offers the
    Schwarzschild lens map of that mass as the light connection's proposal, as Kerr does
    (integrators/lens_proposal.h): the mean of brute force (in Reissner-Nordström with Q = 0.8 M too, whose orbits
    are not the proxy's), far less noise than the aimed proxies (measured: 0.06x in ks_schwarzschild, where every
    proposed sample reaches the light, 0.4x in static_charged)."""
    m = expression_metric(key)
    sc = room({"name": m.name, "params": m.param_values}, size=(12, 9), light=3.0, spheres=False)
    lens = _image_means(sc, range(12), spp=8, max_depth=3)
    brute = _image_means(sc, range(12, 36), spp=8, max_depth=3, light_sampling=False)
    assert lens.mean() > 0
    assert_same_mean(lens, brute, slack=2e-3 * brute.mean())

    def variance(**kw):
        return np.stack([wv.render(sc, spp=8, seed=s, max_depth=3, **kw).rgb
                         for s in range(6)]).astype(np.float64).var(axis=0).mean()

    assert variance() < 0.6 * variance(light_connection="aimed")


def test_only_an_asymptotically_flat_line_element_with_a_mass_and_no_throat_offers_the_proxy():
    """The proxy is Schwarzschild's: a wormhole (its throat's scale is no mass), a spacetime that is not
    asymptotically flat (an escape radius) or one without a mass does not offer it."""
    from warpviz.spacetime.line_element.codegen import metric_source
    from warpviz.spacetime.line_element.tensor import LineElement

    le = LineElement("-dt**2 + dx**2 + dy**2 + dz**2 + 2*M/r*(dt + (x*dx + y*dy + z*dz)/r)**2", parameters=["M"])
    M = le.params[0]
    offers = {}
    for label, landmarks in (("mass", {"mass": M}), ("none", {}), ("escape", {"mass": M, "escape_radius": 50 * M})):
        source = metric_source(le, name="probe", values={"M": 1.0}, landmarks=landmarks, register=False)
        offers[label] = "kLensProxy = true" in source
    wormhole = LineElement("-dt**2 + dl**2 + (b**2 + l**2)*dOmega**2", coordinates="wormhole", parameters=["b"],
                           throat="b")
    source = metric_source(wormhole, name="probe", values={"b": 1.0}, landmarks={"throat_radius": wormhole.params[0]},
                           register=False)
    offers["wormhole"] = "kLensProxy = true" in source
    assert offers == {"mass": True, "none": False, "escape": False, "wormhole": False}
