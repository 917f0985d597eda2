"""Python metric classes: validation, landmarks, dict round trip."""

import math

import pytest

import warpviz as wv


@pytest.mark.parametrize(
    "make, message",
    [
        (lambda: wv.Schwarzschild(mass=0.0), "mass must be > 0"),
        (lambda: wv.Schwarzschild(mass=-1.0), "mass must be > 0"),
        (lambda: wv.Schwarzschild(mass=float("nan")), "mass must be finite"),
        (lambda: wv.Kerr(mass=1.0, spin=1.0), r"\|spin\| < 1"),
        (lambda: wv.Kerr(mass=1.0, spin=-1.5), r"\|spin\| < 1"),
        (lambda: wv.Kerr(mass=1.0, spin=float("inf")), "spin must be finite"),
        (lambda: wv.EllisWormhole(throat=0.0), "throat must be > 0"),
    ],
)
def test_bad_parameters_raise_value_error_naming_them(make, message):
    with pytest.raises(ValueError, match=message):
        make()


def test_wrong_types_and_positional_use_are_rejected():
    with pytest.raises(TypeError, match="mass must be a real number"):
        wv.Schwarzschild(mass="1")
    with pytest.raises(TypeError, match="spin must be a real number"):
        wv.Kerr(mass=1.0, spin=True)
    with pytest.raises(TypeError):
        wv.Kerr(1.0, 0.5)  # keyword-only


def test_metrics_are_immutable_values():
    k = wv.Kerr(mass=2.0, spin=0.5)
    with pytest.raises(AttributeError):
        k.spin = 0.1
    assert k == wv.Kerr(mass=2.0, spin=0.5) and k != wv.Kerr(mass=2.0, spin=0.4)
    assert len({k, wv.Kerr(mass=2.0, spin=0.5)}) == 1
    assert repr(k) == "Kerr(mass=2.0, spin=0.5)"


@pytest.mark.parametrize(
    "metric", [wv.Minkowski(), wv.Schwarzschild(mass=3.0), wv.Kerr(mass=1.0, spin=-0.3), wv.EllisWormhole(throat=2.0)]
)
def test_dict_round_trip(metric):
    assert wv.metric_from_dict(metric.to_dict()) == metric


def test_metric_from_dict_errors_name_the_problem():
    with pytest.raises(ValueError, match="unknown metric 'kerrr'.*kerr"):
        wv.metric_from_dict({"name": "kerrr"})
    with pytest.raises(ValueError, match=r"unknown parameter\(s\) \['spn'\]"):
        wv.metric_from_dict({"name": "kerr", "spn": 0.5})


def test_kerr_landmarks_match_exact_values(exact):
    case = exact["kerr"]["cases"][0]
    k = wv.Kerr(mass=1.0, spin=case["a"])
    assert k.horizon_radius == pytest.approx(case["r_plus"], rel=1e-13)
    pro, retro = k.photon_orbit_radii
    assert pro == pytest.approx(case["photon_orbit_prograde"], rel=1e-12)
    assert retro == pytest.approx(case["photon_orbit_retrograde"], rel=1e-12)
    assert k.ergosphere_radius(math.pi / 2) == pytest.approx(2.0)


def test_schwarzschild_landmarks(exact):
    s = wv.Schwarzschild(mass=1.0)
    assert s.critical_impact_parameter == pytest.approx(exact["schwarzschild_deflection"]["critical_impact_parameter"])
    for case in exact["schwarzschild_shadow"]["cases"]:
        assert math.degrees(s.shadow_angle(case["r"])) == pytest.approx(case["theta_deg"], rel=1e-12)
