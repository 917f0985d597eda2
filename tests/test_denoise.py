"""Denoising with Intel Open Image Denoise (warpviz/render/denoise.py) and its features, the albedo and
albedo_normal AOVs at the first non-specular hit: known feature values, radiance that never changes, a
clear message without the optional binding, lower error against a converged reference."""

from __future__ import annotations

import dataclasses
import importlib.util
import json
import sys

import numpy as np
import pytest

import warpviz as wv
from warpviz.render.denoise import DenoiserMissing, require_denoiser
from warpviz.render.render import OPTIONAL_AOVS

HAS_OIDN = importlib.util.find_spec("pyoidn") is not None
needs_oidn = pytest.mark.skipif(not HAS_OIDN, reason="pyoidn (Intel Open Image Denoise) is not installed: "
                                "pip install 'warpviz[denoise]'")  # fmt: skip


def sphere_scene(*, front="diffuse", width=24, height=18):
    """A unit sphere (albedo 0.6, or a mirror) in front of a wall of albedo (0.2, 0.4, 0.8) at y = 3, a
    white sky: every feature is known."""
    materials = [{"type": "diffuse", "texture": 0}, {"type": "diffuse", "texture": 1}]
    if front == "mirror":
        materials[0] = {"type": "mirror"}
    return {
        "metric": {"name": "minkowski", "params": []},
        "camera": {"position": [0, -6, 0], "look_at": [0, 0, 0], "fov": 40, "width": width, "height": height},
        "textures": [{"type": "constant", "color": [0.6, 0.6, 0.6]}, {"type": "constant", "color": [0.2, 0.4, 0.8]}],
        "materials": materials,
        "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1.0, "material": 0},
                   {"type": "quad", "corner": [-2, 3, -0.6], "edge_u": [4, 0, 0], "edge_v": [0, 0, 1.2],
                    "material": 1}],
        "environment": {"color": [1, 1, 1]},
    }  # fmt: skip


def test_albedo_and_normal_features_have_known_values():
    img = wv.render(sphere_scene(), spp=16, aovs=["albedo", "albedo_normal"], threads=2)
    albedo, normal = img.aovs["albedo"], img.aovs["albedo_normal"]
    assert albedo.shape == normal.shape == (18, 24, 3) and albedo.dtype == np.float32
    # the four pixels round the image's centre see the sphere head on: albedo 0.6, normals that average to
    # the one towards the camera (-y), each ~6 degrees off it (half a pixel of a 40-degree, 18-row view)
    np.testing.assert_allclose(albedo[8:10, 11:13], 0.6, rtol=1e-6)
    centre = normal[8:10, 11:13].reshape(-1, 3)
    np.testing.assert_allclose(centre.mean(axis=0), [0.0, -0.986, 0.0], atol=0.01)
    assert np.all(np.linalg.norm(centre, axis=1) > 0.99)  # a mean of unit normals a few degrees apart
    # a corner pixel sees only the sky: no non-specular hit
    np.testing.assert_array_equal(albedo[0, 0], [0, 0, 0])
    np.testing.assert_array_equal(normal[0, 0], [0, 0, 0])
    # an edge pixel of the sphere averages sphere and sky: between 0 and 0.6, grey
    row = albedo[9, :, 0]
    partial = (row > 0.01) & (row < 0.59)
    assert partial.any()


def test_albedo_is_taken_through_a_mirror():
    """A mirror sphere with a blue wall (0.2, 0.4, 0.8) behind the camera: at the sphere's centre pixel the
    first non-specular hit is that wall, seen in the mirror, so the albedo is the wall's (not the mirror's
    tint); the sphere's normal is not recorded there, the wall's (+y) is."""
    scene = sphere_scene(front="mirror")
    scene["shapes"].append({"type": "quad", "corner": [-10, -8, -10], "edge_u": [0, 0, 20], "edge_v": [20, 0, 0],
                            "material": 1})  # fmt: skip
    img = wv.render(scene, spp=4, aovs=["albedo", "albedo_normal"], threads=2)
    np.testing.assert_allclose(img.aovs["albedo"][9, 12], [0.2, 0.4, 0.8], rtol=1e-6)
    np.testing.assert_allclose(img.aovs["albedo_normal"][9, 12], [0.0, 1.0, 0.0], atol=1e-6)


def lamp_room(metric):
    """A closed diffuse box (no mirror or glass) with a ceiling lamp in view, around a hole or flat."""
    return {
        "metric": metric,
        "camera": {"position": [0, -7, 0], "look_at": [0, 0, 0.5], "fov": 60, "width": 24, "height": 18},
        "textures": [{"type": "constant", "color": [0.7, 0.7, 0.7]}],
        "materials": [{"type": "diffuse", "texture": 0}, {"type": "emissive", "strength": 4.0}],
        "shapes": [{"type": "quad", "corner": c, "edge_u": u, "edge_v": v, "material": 0} for c, u, v in (
                      ([-5, -8, -3], [10, 0, 0], [0, 16, 0]), ([-5, -8, 4], [0, 16, 0], [10, 0, 0]),
                      ([-5, 8, -3], [10, 0, 0], [0, 0, 7]), ([-5, -8, -3], [0, 0, 7], [0, 16, 0]),
                      ([5, -8, -3], [0, 16, 0], [0, 0, 7]), ([-5, -8, -3], [0, 0, 7], [10, 0, 0]))]
                  + [{"type": "quad", "corner": [-1.5, -1, 3.99], "edge_u": [0, 2, 0], "edge_v": [3, 0, 0],
                      "material": 1}],
    }  # fmt: skip


@pytest.mark.parametrize("metric", [{"name": "minkowski", "params": []},
                                    {"name": "schwarzschild", "params": [0.5]}])  # fmt: skip
def test_emission_aov_is_what_the_camera_segment_alone_sees(metric):
    """Without mirrors or glass a path's first hit is its first non-specular one, so the emission AOV is
    the camera segment's own light: exactly the image of max_depth = 1 (same seeds, same first hits); the
    lamp's pixels are nearly all emission (it reflects a little too), the walls' none."""
    scene = lamp_room(metric)
    img = wv.render(scene, spp=4, seed=5, threads=2, aovs=["emission"])
    first = wv.render(scene, spp=4, seed=5, threads=2, aovs=[], max_depth=1)
    np.testing.assert_array_equal(img.aovs["emission"], first.rgb)
    lamp = first.rgb.max(axis=2) > 0
    assert 0 < lamp.sum() < lamp.size
    inside = lamp & (first.rgb.min(axis=2) >= 0.999 * first.rgb.max())  # wholly on the lamp
    assert inside.any()
    assert np.all(img.aovs["emission"][inside] > 0.95 * img.rgb[inside])  # the lamp's light is nearly all of it
    assert np.all(img.aovs["emission"] <= img.rgb + 1e-6)
    assert np.all(img.aovs["emission"][~lamp] == 0) and (img.rgb[~lamp].max(axis=1) > 0).mean() > 0.5


def test_emission_aov_is_taken_through_a_mirror():
    """A mirror sphere in front of the lamp room's back wall reflects the lamp: what it shows of the lamp
    is emission (collected before the first non-specular hit), the walls it shows are not."""
    scene = lamp_room({"name": "minkowski", "params": []})
    scene["materials"].append({"type": "mirror"})
    scene["shapes"].append({"type": "sphere", "center": [0, 0, -0.5], "radius": 2.0, "material": 2})
    img = wv.render(scene, spp=4, seed=5, threads=2, aovs=["emission"])
    first = wv.render(scene, spp=4, seed=5, threads=2, aovs=[], max_depth=1)
    assert (img.aovs["emission"].max(axis=2) > first.rgb.max(axis=2)).any()  # the lamp in the mirror
    assert np.all(img.aovs["emission"] <= img.rgb + 1e-6)


@needs_oidn
def test_denoise_leaves_the_emission_alone():
    """rgb - emission is denoised and the emission added back: the lamp's own pixels keep their radiance."""
    img = wv.render(lamp_room({"name": "minkowski", "params": []}), spp=4, seed=5, threads=2, denoise=True)
    assert img.metadata["denoised"]["kept_sharp"] == "emission"
    emission = img.aovs["emission"]
    inside = np.abs(emission - 4.0).max(axis=2) < 1e-6
    assert inside.any()
    np.testing.assert_allclose(img.denoised[inside], img.rgb[inside], rtol=0.02)
    plain = dataclasses.replace(img, aovs={k: v for k, v in img.aovs.items() if k != "emission"}).denoise()
    assert plain.metadata["denoised"]["kept_sharp"] is None


def test_features_never_change_the_radiance():
    scene = sphere_scene()
    plain = wv.render(scene, spp=4, aovs=[], threads=2)
    every = wv.render(scene, spp=4, aovs=list(OPTIONAL_AOVS), threads=2)
    np.testing.assert_array_equal(plain.rgb, every.rgb)
    assert "albedo" not in plain.aovs and "albedo" in every.aovs
    curved = wv.render("fig07", width=12, height=9, spp=2, threads=2, aovs=[])
    with_features = wv.render("fig07", width=12, height=9, spp=2, threads=2, aovs=["albedo", "albedo_normal"])
    np.testing.assert_array_equal(curved.rgb, with_features.rgb)


def test_missing_binding_named_with_its_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "pyoidn", None)  # import pyoidn now raises ImportError
    with pytest.raises(DenoiserMissing, match=r"pip install 'warpviz\[denoise\]'"):
        require_denoiser()
    calls = []
    monkeypatch.setattr(wv.render.__globals__["core"], "render", lambda *a: calls.append(a))
    with pytest.raises(ImportError, match="pyoidn"):
        wv.render(sphere_scene(), spp=1, denoise=True)
    assert not calls  # refused before rendering
    with pytest.raises(ValueError, match="denoise must be True or False"):
        wv.render(sphere_scene(), spp=1, denoise="yes")


def test_cli_denoise_without_binding(monkeypatch, tmp_path):
    from typer.testing import CliRunner

    from warpviz import cli

    monkeypatch.setitem(sys.modules, "pyoidn", None)
    out = tmp_path / "d.png"
    result = CliRunner().invoke(cli.app, ["render", "fig03", "--size", "8x6", "--spp", "1", "-q", "--denoise",
                                          "-o", str(out)])  # fmt: skip
    assert result.exit_code == 1 and "warpviz[denoise]" in result.stderr and "Traceback" not in result.output
    assert not out.exists()


@needs_oidn
def test_denoise_keeps_the_exr_radiance_and_adds_a_layer(tmp_path):
    import OpenEXR

    scene = sphere_scene()
    img = wv.render(scene, spp=2, threads=2, aovs=[], denoise=True)
    noisy = wv.render(scene, spp=2, threads=2, aovs=[], edge_samples=img.metadata["edge_samples"],
                      detail_samples=img.metadata["detail_samples"])  # (a denoised render's own sample counts)
    np.testing.assert_array_equal(img.rgb, noisy.rgb)  # the unbiased radiance, bit for bit
    assert img.denoised.shape == img.rgb.shape and img.denoised.dtype == np.float32
    assert not np.array_equal(img.denoised, img.rgb)
    assert img.metadata["denoised"]["features"] == ["albedo", "albedo_normal"]
    assert img.metadata["denoised"]["denoiser"].startswith("pyoidn")
    exr = img.save(tmp_path / "d.exr")
    with OpenEXR.File(str(exr), separate_channels=True) as f:
        ch = f.channels()
        for k, c in enumerate("RGB"):
            np.testing.assert_array_equal(ch[c].pixels, noisy.rgb[..., k])
            np.testing.assert_array_equal(ch[f"denoised.{c}"].pixels, img.denoised[..., k])
        assert json.loads(f.header()["warpviz"])["denoised"]["features"] == ["albedo", "albedo_normal"]
    plain = noisy.save(tmp_path / "n.exr")
    with OpenEXR.File(str(plain), separate_channels=True) as f:
        assert not any(name.startswith("denoised") for name in f.channels())
        assert "denoised" not in json.loads(f.header()["warpviz"])


@needs_oidn
def test_png_of_a_denoised_image_shows_the_denoised_radiance(tmp_path):
    from PIL import Image as PILImage

    from warpviz.render.tonemap import tonemap

    img = wv.render(sphere_scene(), spp=2, threads=2, denoise=True)
    path = img.save(tmp_path / "d.png")
    with PILImage.open(path) as im:
        np.testing.assert_array_equal(np.asarray(im), tonemap(img.denoised))
        assert "denoised" in json.loads(im.text["warpviz"])


@needs_oidn
def test_denoising_lowers_the_error_of_a_noisy_room():
    """The flat Cornell room at 4 spp against 1024 spp: the denoised image's relative MSE is several times
    lower than the noisy one's (measured ~10x at this size)."""
    kw = dict(width=48, height=36, threads=2, progress=None)
    ref = wv.render("fig03", spp=1024, seed=7, aovs=[], **kw).rgb.astype(np.float64)
    img = wv.render("fig03", spp=4, denoise=True, **kw)

    def rel_mse(x):
        return float(np.mean((x - ref) ** 2 / (ref**2 + 1e-2)))

    noisy, denoised = rel_mse(img.rgb), rel_mse(img.denoised)
    assert denoised < 0.5 * noisy, (noisy, denoised)


@needs_oidn
def test_prefiltered_features_lower_the_error_where_they_are_noisy():
    """The flat room's mirror and glass ball make the features noisy at 4 spp (each sample's Fresnel choice
    and the reflected room): denoised on their own first (OIDN's prefiltering, the default), they lower the
    denoised image's error (measured ~25 % at this size; 13 % in fig07 and fig10d at 640 x 480)."""
    from warpviz.render.denoise import denoise_radiance

    kw = dict(width=48, height=36, threads=2, progress=None)
    ref = wv.render("fig03", spp=1024, seed=7, aovs=[], **kw).rgb.astype(np.float64)
    err = {True: 0.0, False: 0.0}
    for seed in range(3):
        img = wv.render("fig03", spp=4, seed=seed, denoise=True, **kw)
        assert img.metadata["denoised"]["features_prefiltered"]
        sharp = img.aovs["emission"]
        for prefilter in err:
            out = denoise_radiance(img.rgb - sharp, albedo=img.aovs["albedo"], normal=img.aovs["albedo_normal"],
                                   prefilter=prefilter) + sharp
            err[prefilter] += float(np.mean((out - ref) ** 2 / (ref**2 + 1e-2)))
    assert err[True] < 0.9 * err[False], err
