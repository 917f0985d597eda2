"""VTK export: RayBundle -> .vtp, scene -> .vtm, atomic writes, and the display geometry of each metric."""

import dataclasses
import math
import os

import numpy as np
import pytest

pv = pytest.importorskip("pyvista")

import warpviz as wv  # noqa: E402
import warpviz.io  # noqa: E402

KERR = wv.Kerr(mass=1.0, spin=0.9)
ELLIS = wv.EllisWormhole(throat=1.0)


def kerr_rays(**extra):
    rays = wv.trace(KERR, [-30.0, 0.0, 0.5], [[1, 0, 0], [1, 0.05, 0], [1, 0.3, 0.1]], record=True, escape_radius=60)
    return dataclasses.replace(rays, **extra) if extra else rays


def ellis_rays():
    # head-on rays cross the throat to the other sheet; the last one stays on ours
    return wv.trace(ELLIS, [-20.0, 0.0, 0.0], [[1, 0, 0], [1, 0.02, 0], [1, 0.4, 0]], record=True, escape_radius=40)


def small_scene():
    return {
        "metric": {"name": "kerr", "params": [1.0, 0.9]},
        "camera": {"position": [-20.0, 0, 0], "look_at": [0, 0, 0], "up": [0, 0, 1], "fov": 60.0,
                   "width": 32, "height": 24},
        "materials": [{"type": "diffuse", "texture": 0}, {"type": "mirror", "reflectance": [1, 1, 1]},
                      {"type": "emissive", "texture": 0, "strength": 2.0, "two_sided": False}],
        "shapes": [
            {"type": "sphere", "center": [5.0, 1.0, 0.0], "radius": 2.0, "material": 1, "sheet": 1,
             "pole": [0, 1, 0], "meridian": [1, 0, 0]},
            {"type": "quad", "corner": [0, 0, -5.0], "edge_u": [2.0, 0, 0], "edge_v": [0, 3.0, 0], "material": 0,
             "sheet": 1},
            {"type": "disk", "center": [0, 0, 0], "normal": [0, 0, 1], "inner_radius": 3.0, "outer_radius": 8.0,
             "material": 2, "sheet": 1, "meridian": [1, 0, 0]},
            {"type": "mesh", "vertices": np.array([[0, 0, 9.0], [1, 0, 9], [1, 1, 9], [0, 1, 9]]),
             "faces": np.array([[0, 1, 2], [0, 2, 3]], dtype=np.int32), "uvs": None, "material": 0, "sheet": -1},
        ],
    }  # fmt: skip


def assert_same_array(a, b, name):
    a, b = np.asarray(a), np.asarray(b)
    assert a.dtype == b.dtype, (name, a.dtype, b.dtype)
    assert a.shape == b.shape, (name, a.shape, b.shape)
    assert np.array_equal(a, b), name


# --------------------------------------------------------------------------------------------------
# RayBundle -> PolyData -> .vtp


def test_vtp_round_trip_keeps_every_array_exactly(tmp_path):
    n = 3
    extra = {"pixel_x": np.array([4, 5, 6], np.int32), "pixel_y": np.array([7, 8, 9], np.int32),
             "sample": np.array([0, 1, 2], np.int32), "bounce": np.array([0, 0, 1], np.int8)}  # fmt: skip
    rays = kerr_rays(ray_data=extra)
    poly = rays.to_pyvista()
    path = rays.save(tmp_path / "rays.vtp")
    assert path == tmp_path / "rays.vtp"
    back = pv.read(path)

    assert_same_array(back.points, rays.points, "points")
    assert back.points.dtype == np.float64
    assert back.n_cells == n
    for i in range(n):
        assert_same_array(back.get_cell(i).point_ids, np.arange(rays.offsets[i], rays.offsets[i + 1]), f"cell {i}")
    # point data: exactly the bundle's arrays
    assert sorted(back.point_data.keys()) == sorted(rays.point_data)
    assert {"affine_param", "coord_time", "r", "step_size", "hamiltonian_err", "E_drift", "Lz_drift", "Q_drift",
            "E_drift_scaled", "Lz_drift_scaled", "Q_drift_scaled", "log10_error", "log10_error_scaled", "redshift", "sheet"} == set(rays.point_data)  # fmt: skip
    for name, values in rays.point_data.items():
        assert_same_array(back.point_data[name], values, name)
    # cell data
    assert_same_array(back.cell_data["ray_id"], np.arange(n, dtype=np.int64), "ray_id")
    assert_same_array(back.cell_data["status"], rays.status, "status")
    assert_same_array(back.cell_data["n_steps"], rays.n_steps, "n_steps")
    for name, values in rays.invariant_drift.items():
        assert_same_array(back.cell_data[f"max_drift_{name}"], values, name)
    assert_same_array(back.cell_data["max_drift"], rays.max_drift(), "max_drift")
    for name, values in extra.items():
        assert_same_array(back.cell_data[name], values, name)
    # field data
    assert back.field_data["metric"].tolist() == ["kerr"]
    assert_same_array(back.field_data["metric_params"], np.array([1.0, 0.9]), "metric_params")
    assert back.field_data["metric_param_names"].tolist() == ["mass", "spin"]
    assert back.field_data["stepper"].tolist() == ["dopri5"]
    assert_same_array(back.field_data["tol"], np.array([1e-9]), "tol")
    assert back.field_data["warpviz_version"].tolist() == [wv.__version__]
    assert back.field_data["status_legend"].tolist() == ["escaped", "hit", "horizon", "max_steps",
                                                          "invariant_violation", "nan"]  # fmt: skip
    # and the file holds what to_pyvista built
    assert sorted(back.array_names) == sorted(poly.array_names)
    assert rays.status_names.tolist() == ["horizon", "horizon", "escaped"]


def test_vtp_round_trip_of_an_ellis_and_a_flat_bundle(tmp_path):
    rays = ellis_rays()
    back = wv.read_rays(rays.save(tmp_path / "ellis.vtp"))
    assert_same_array(back.point_data["sheet"], rays.point_data["sheet"], "sheet")
    assert set(back.point_data["sheet"].tolist()) == {-1, 1}
    assert_same_array(back.cell_data["max_drift_L2"], rays.invariant_drift["L2"], "L2")

    flat = wv.trace(wv.Minkowski(), [0, 0, 0], [[1, 0, 0], [0, 1, 0]], record=True)
    back = wv.read_rays(flat.save(tmp_path / "flat.vtp"))
    assert back.field_data["metric"].tolist() == ["minkowski"]
    assert back.field_data["metric_params"].shape == (0,)
    assert back.field_data["metric_param_names"].shape == (0,)
    assert_same_array(back.points, flat.points, "points")


def test_rays_with_zero_or_one_point_keep_one_cell_each(tmp_path):
    base = wv.trace(wv.Minkowski(), [0, 0, 0], [[1, 0, 0], [0, 1, 0], [0, 0, 1]])
    points = np.array([[1.0, 2, 3], [4, 5, 6], [7, 8, 9]])
    rays = dataclasses.replace(
        base, points=points, offsets=np.array([0, 0, 1, 3]),
        point_data={"r": np.linalg.norm(points, axis=1), "sheet": np.ones(3, np.int8)},
    )  # fmt: skip
    back = pv.read(rays.save(tmp_path / "short.vtp"))
    assert back.n_cells == 3
    assert [back.get_cell(i).n_points for i in range(3)] == [0, 1, 2]
    assert back.get_cell(2).point_ids == [1, 2]
    assert_same_array(back.cell_data["ray_id"], np.arange(3, dtype=np.int64), "ray_id")


def test_unrecorded_bundle_raises():
    rays = wv.trace(KERR, [-30.0, 0, 0], [1, 0.3, 0], record=False)
    with pytest.raises(ValueError, match="trace with record=True to get paths"):
        rays.to_pyvista()
    with pytest.raises(ValueError, match="record=True"):
        rays.save("never.vtp")
    with pytest.raises(ValueError, match="record=True"):
        wv.scene_multiblock(rays=rays)


def test_ray_data_must_be_one_value_per_ray_and_not_shadow_builtin_arrays():
    rays = kerr_rays()
    with pytest.raises(ValueError, match=r"ray_data\['pixel_x'\] must have shape \(3,\)"):
        dataclasses.replace(rays, ray_data={"pixel_x": np.zeros(4)})
    with pytest.raises(ValueError, match="taken by a built-in"):
        dataclasses.replace(rays, ray_data={"status": np.zeros(3)})
    assert kerr_rays().ray_data == {}


def test_wrong_suffixes_and_types_have_clear_errors(tmp_path):
    with pytest.raises(ValueError, match=r"expected a \.vtp file"):
        kerr_rays().save(tmp_path / "rays.vtk")
    with pytest.raises(ValueError, match=r"expected a \.vtm file"):
        wv.write_vtm(pv.MultiBlock(), tmp_path / "scene.vtp")
    with pytest.raises(ValueError, match=r"expected a \.vtp file"):
        wv.read_rays(tmp_path / "rays.csv")
    with pytest.raises(TypeError, match="needs pyvista.PolyData"):
        wv.write_vtp(pv.MultiBlock(), tmp_path / "x.vtp")
    with pytest.raises(FileNotFoundError, match="does not exist"):
        wv.write_vtp(pv.Line(), tmp_path / "missing" / "x.vtp")
    with pytest.raises(FileNotFoundError):
        wv.read_rays(tmp_path / "missing.vtp")
    wv.write_vtp(pv.Sphere(), tmp_path / "sphere.vtp")
    with pytest.raises(ValueError, match="not a warpviz ray file"):
        wv.read_rays(tmp_path / "sphere.vtp")


# --------------------------------------------------------------------------------------------------
# atomic writes


def test_atomic_write_leaves_no_temporary_file(tmp_path):
    target = tmp_path / "out.vtp"
    kerr_rays().save(target)
    assert os.listdir(tmp_path) == ["out.vtp"]
    out = wv.atomic_write(tmp_path / "note.txt", lambda tmp: tmp.write_text("new"))
    assert out.read_text() == "new"
    assert sorted(os.listdir(tmp_path)) == ["note.txt", "out.vtp"]


def test_atomic_write_keeps_the_old_file_when_the_writer_fails(tmp_path):
    target = tmp_path / "rays.vtp"
    kerr_rays().save(target)
    before = target.read_bytes()

    def half_then_crash(tmp):
        tmp.write_bytes(b"<VTKFile truncated")
        raise RuntimeError("crash while writing")

    with pytest.raises(RuntimeError, match="crash while writing"):
        wv.atomic_write(target, half_then_crash)
    with pytest.raises(OSError, match="created no file"):
        wv.atomic_write(target, lambda tmp: None)
    assert target.read_bytes() == before
    assert os.listdir(tmp_path) == ["rays.vtp"]


def test_write_vtm_replaces_an_existing_scene_and_its_pieces(tmp_path):
    path = tmp_path / "scene.vtm"
    wv.save_scene_vtm(path, rays=kerr_rays(), native_scene=small_scene())
    assert len(os.listdir(tmp_path / "scene")) == 6
    wv.save_scene_vtm(path, metric=wv.Schwarzschild(mass=1.0))
    assert sorted(os.listdir(tmp_path)) == ["scene", "scene.vtm"]
    assert len(os.listdir(tmp_path / "scene")) == 2  # the six old pieces are gone
    assert pv.read(path).keys() == ["horizon", "photon_sphere"]


def test_write_vtm_failure_leaves_the_old_scene_untouched(tmp_path, monkeypatch):
    path = tmp_path / "scene.vtm"
    wv.save_scene_vtm(path, metric=KERR)
    before = {p: p.read_bytes() for p in tmp_path.rglob("*") if p.is_file()}

    def fail(writer, data, filename):
        filename.write_text("partial")
        raise OSError("disk full")

    monkeypatch.setattr(warpviz.io, "_run_vtk_writer", fail)
    with pytest.raises(OSError, match="disk full"):
        wv.save_scene_vtm(path, metric=wv.Schwarzschild(mass=1.0))
    assert {p: p.read_bytes() for p in tmp_path.rglob("*") if p.is_file()} == before
    assert sorted(os.listdir(tmp_path)) == ["scene", "scene.vtm"]


# --------------------------------------------------------------------------------------------------
# .vtm scenes


def test_vtm_round_trip_has_named_blocks_and_their_arrays(tmp_path):
    rays = kerr_rays()
    path = wv.save_scene_vtm(tmp_path / "kerr.vtm", rays=rays, native_scene=small_scene(), resolution=16)
    back = pv.read(path)
    assert back.keys() == ["rays", "surfaces", "horizon", "ergosphere", "photon_sphere", "camera"]
    for name, values in rays.point_data.items():
        assert_same_array(back["rays"].point_data[name], values, name)
    assert_same_array(back["rays"].cell_data["status"], rays.status, "status")
    assert back["rays"].field_data["metric"].tolist() == ["kerr"]
    assert_same_array(back["surfaces"].cell_data["material"], wv.scene_surfaces(small_scene()).cell_data["material"],
                      "material")  # fmt: skip
    assert back["surfaces"].field_data["material_type"].tolist() == ["diffuse", "mirror", "emissive"]
    assert_same_array(back["horizon"].points, wv.horizon_surface(KERR, resolution=16).points, "horizon")
    assert_same_array(wv.read_rays(path).points, rays.points, "read_rays from .vtm")


def test_ellis_scene_has_embedding_and_rays_mapped_onto_it(tmp_path):
    rays = ellis_rays()
    back = pv.read(wv.save_scene_vtm(tmp_path / "ellis.vtm", rays=rays))
    assert back.keys() == ["rays", "throat", "embedding", "embedding_rays"]
    mapped = back["embedding_rays"]
    rho, z = np.hypot(mapped.points[:, 0], mapped.points[:, 1]), mapped.points[:, 2]
    np.testing.assert_allclose(rho, np.cosh(z), rtol=1e-12)  # on the catenoid rho = b0 cosh(z / b0)
    sheet = mapped.point_data["sheet"]
    assert np.all(np.sign(z[np.abs(z) > 1e-9]) == sheet[np.abs(z) > 1e-9])
    assert set(sheet.tolist()) == {-1, 1}
    np.testing.assert_allclose(np.hypot(*mapped.points[:, :2].T), np.linalg.norm(rays.points, axis=1), rtol=1e-12)


def test_read_rays_of_a_scene_without_rays_raises(tmp_path):
    path = wv.save_scene_vtm(tmp_path / "bh.vtm", metric=KERR, resolution=8)
    with pytest.raises(ValueError, match="no 'rays' block"):
        wv.read_rays(path)


def test_scene_multiblock_metric_sources_must_agree():
    blocks = wv.scene_multiblock(native_scene=small_scene(), resolution=8)
    assert blocks.keys() == ["surfaces", "horizon", "ergosphere", "photon_sphere", "camera"]
    assert wv.scene_multiblock(metric={"name": "schwarzschild", "params": [2.0]}).keys() == ["horizon", "photon_sphere"]
    with pytest.raises(ValueError, match="conflicting metrics"):
        wv.scene_multiblock(rays=kerr_rays(), metric=wv.Schwarzschild(mass=1.0))
    assert wv.scene_multiblock(metric=wv.Minkowski()).n_blocks == 0


# --------------------------------------------------------------------------------------------------
# geometry of the metrics


def test_schwarzschild_horizon_and_photon_sphere_radii():
    bh = wv.Schwarzschild(mass=1.5)
    np.testing.assert_allclose(np.linalg.norm(wv.horizon_surface(bh).points, axis=1), 3.0, rtol=1e-14)
    np.testing.assert_allclose(np.linalg.norm(wv.photon_sphere(bh).points, axis=1), 4.5, rtol=1e-14)
    assert list(wv.metric_features(bh)) == ["horizon", "photon_sphere"]


def test_kerr_horizon_is_the_oblate_spheroid_with_the_right_semi_axes():
    h = wv.horizon_surface(KERR)
    r_plus, a = KERR.horizon_radius, KERR.a
    assert r_plus == pytest.approx(1.0 + math.sqrt(1.0 - 0.81), rel=1e-15)
    xmin, xmax, ymin, ymax, zmin, zmax = h.bounds
    semi = math.sqrt(r_plus**2 + a**2)
    assert (xmax, -xmin, ymax, -ymin) == pytest.approx((semi, semi, semi, semi), rel=1e-14)
    assert (zmax, -zmin) == pytest.approx((r_plus, r_plus), rel=1e-14)
    x, y, z = h.points.T
    np.testing.assert_allclose((x * x + y * y) / semi**2 + z * z / r_plus**2, 1.0, rtol=1e-13)
    assert h.n_open_edges == 0 and h.volume == pytest.approx(4 / 3 * math.pi * semi**2 * r_plus, rel=0.02)


def test_kerr_ergosphere_touches_the_horizon_at_the_poles_and_reaches_2m_on_the_equator():
    for bh in (KERR, wv.Kerr(mass=2.0, spin=-0.5)):
        e = wv.ergosphere_surface(bh, resolution=32)
        x, y, z = e.points.T
        rho = np.hypot(x, y)
        poles = rho == 0.0
        assert poles.sum() == 2
        np.testing.assert_allclose(np.sort(z[poles]), [-bh.horizon_radius, bh.horizon_radius], rtol=1e-14)
        equator = np.abs(z) < 1e-12
        assert equator.sum() == 32
        np.testing.assert_allclose(e.point_data["r"][equator], 2.0 * bh.mass, rtol=1e-14)  # Boyer–Lindquist r
        np.testing.assert_allclose(rho[equator], math.sqrt(4.0 * bh.mass**2 + bh.a**2), rtol=1e-14)
    assert "ergosphere" not in wv.metric_features(wv.Kerr(mass=1.0, spin=0.0))
    with pytest.raises(ValueError, match="no ergosphere"):
        wv.ergosphere_surface(wv.Schwarzschild(mass=1.0))


def test_kerr_photon_region_spans_the_equatorial_orbits_and_meets_at_the_polar_orbit():
    m, a = KERR.mass, KERR.a
    shell = wv.photon_sphere(KERR, resolution=32)
    assert shell.n_open_edges == 0
    x, y, z = shell.points.T
    rho, r = np.hypot(x, y), shell.point_data["r"]
    equator = np.abs(z) < 1e-12
    np.testing.assert_allclose(sorted(set(np.round(r[equator], 12))), KERR.photon_orbit_radii, rtol=1e-12)
    poles = rho == 0.0
    polar = r[poles][0]
    np.testing.assert_allclose(r[poles], polar, rtol=0)
    np.testing.assert_allclose(np.abs(z[poles]), polar, rtol=0)
    assert polar**3 - 3 * m * polar**2 + a * a * polar + a * a * m == pytest.approx(0.0, abs=1e-12)  # L_z = 0 orbit
    # every vertex lies on the boundary (2r Delta - (r - M) Sigma)^2 = 4 a^2 r^2 Delta sin^2(theta)
    cos_t = z / r
    delta, sigma = r * r - 2 * m * r + a * a, r * r + a * a * cos_t**2
    lhs, rhs = (2 * r * delta - (r - m) * sigma) ** 2, 4 * a * a * r * r * delta * (1 - cos_t**2)
    np.testing.assert_allclose(lhs, rhs, rtol=0, atol=1e-9)
    # and it is consistent with the Kerr-Schild oblate mapping x^2 + y^2 = (r^2 + a^2) sin^2(theta)
    np.testing.assert_allclose(rho**2, (r * r + a * a) * (1 - cos_t**2), atol=1e-12)
    # the slow-spin limit is the Schwarzschild photon sphere
    slow = wv.photon_sphere(wv.Kerr(mass=1.0, spin=1e-9), resolution=16)
    np.testing.assert_allclose(slow.point_data["r"], 3.0, rtol=1e-8)


def test_ellis_throat_and_embedding_have_both_sheets():
    wh = wv.EllisWormhole(throat=2.0)
    np.testing.assert_allclose(np.linalg.norm(wv.throat_surface(wh).points, axis=1), 2.0, rtol=1e-14)
    emb = wv.wormhole_embedding(wh, l_max=6.0, resolution=16)
    x, y, z = emb.points.T
    np.testing.assert_allclose(np.hypot(x, y), 2.0 * np.cosh(z / 2.0), rtol=1e-13)
    sheet, ell = emb.point_data["sheet"], emb.point_data["l"]
    assert set(sheet.tolist()) == {-1, 1}
    assert np.all(sheet[z > 0] == 1) and np.all(sheet[z < 0] == -1)
    assert (ell.min(), ell.max()) == (-6.0, 6.0)
    assert emb.bounds[5] == pytest.approx(2.0 * math.asinh(3.0), rel=1e-14)
    assert emb.bounds[4] == pytest.approx(-2.0 * math.asinh(3.0), rel=1e-14)
    assert list(wv.metric_features(wh)) == ["throat", "embedding"]
    assert wv.metric_features(wv.Minkowski()) == {}
    with pytest.raises(ValueError, match="has no horizon"):
        wv.horizon_surface(wh)


def test_wormhole_embedding_points_keep_distance_and_sheet():
    out = wv.wormhole_embedding_points(ELLIS, [[3.0, 4.0, 0.0], [0.0, 0.0, 1.0], [0.0, 2.0, 0.0]], [-1, 1, 1])
    np.testing.assert_allclose(out[0], [3.0, 4.0, -math.asinh(math.sqrt(24.0))], rtol=1e-14)
    np.testing.assert_allclose(out[1], [1.0, 0.0, 0.0], atol=1e-15)  # on the throat, azimuth 0 on the axis
    np.testing.assert_allclose(out[2], [0.0, 2.0, math.asinh(math.sqrt(3.0))], atol=1e-15)
    with pytest.raises(ValueError, match="one entry per point"):
        wv.wormhole_embedding_points(ELLIS, [[1.0, 0, 0]], [1, 1])


# --------------------------------------------------------------------------------------------------
# scene shapes and camera


def test_scene_surfaces_of_a_small_native_scene():
    scene = small_scene()
    s = wv.scene_surfaces(scene, resolution=8)
    # sphere: 5 meridian points -> 2 x 8 triangles + 2 x 8 quads; quad: 1; disk: 5 rings -> 4 x 8 quads; mesh: 2
    counts = {0: 32, 1: 1, 2: 32, 3: 2}
    assert s.n_cells == sum(counts.values())
    assert_same_array(s.cell_data["shape"], np.repeat(np.arange(4, dtype=np.int32), list(counts.values())), "shape")
    assert_same_array(s.cell_data["material"], np.repeat(np.array([1, 0, 2, 0], np.int32), list(counts.values())),
                      "material")  # fmt: skip
    assert_same_array(s.cell_data["sheet"], np.repeat(np.array([1, 1, 1, -1], np.int8), list(counts.values())), "sheet")

    normals = s.compute_normals(cell_normals=True, point_normals=False, auto_orient_normals=False,
                                consistent_normals=False, split_vertices=False).cell_data["Normals"]  # fmt: skip
    shape = s.cell_data["shape"]
    np.testing.assert_allclose(normals[shape == 1], [[0, 0, 1]], atol=1e-12)  # edge_u x edge_v
    np.testing.assert_allclose(normals[shape == 2], np.tile([0, 0, 1], (32, 1)), atol=1e-12)  # disk normal
    sphere = s.extract_cells(np.flatnonzero(shape == 0))
    np.testing.assert_allclose(np.linalg.norm(sphere.points - [5.0, 1.0, 0.0], axis=1), 2.0, rtol=1e-14)
    centres = sphere.cell_centers().points - [5.0, 1.0, 0.0]
    assert np.all(np.einsum("ij,ij->i", normals[shape == 0], centres) > 0)  # outward
    assert sphere.bounds[3] == pytest.approx(3.0, rel=1e-14)  # the pole points along +y
    disk = s.extract_cells(np.flatnonzero(shape == 2))
    np.testing.assert_allclose(sorted({round(float(v), 12) for v in np.hypot(*disk.points[:, :2].T)}),
                               [3.0, 4.25, 5.5, 6.75, 8.0])  # fmt: skip
    assert wv.scene_surfaces({"shapes": []}).n_cells == 0
    with pytest.raises(ValueError, match=r"shapes\[0\]: unknown shape type 'cone'"):
        wv.scene_surfaces({"shapes": [{"type": "cone"}]})
    with pytest.raises(ValueError, match=r"shapes\[0\] \(sphere\): missing key 'radius'"):
        wv.scene_surfaces({"shapes": [{"type": "sphere", "center": [0, 0, 0], "material": 0}]})


def test_camera_frustum_corners():
    cam = {"position": [1.0, 2.0, 3.0], "look_at": [1.0, 12.0, 3.0], "up": [0, 0, 1], "fov": 60.0,
           "width": 40, "height": 20}  # fmt: skip
    f = wv.camera_frustum(cam, length=5.0)
    half_h = 5.0 * math.tan(math.radians(30.0))
    np.testing.assert_allclose(f.points[0], [1.0, 2.0, 3.0])
    # looking along +y with z up, the camera's right is +x
    expected = [[1 - 2 * half_h, 7.0, 3 - half_h], [1 + 2 * half_h, 7.0, 3 - half_h],
                [1 + 2 * half_h, 7.0, 3 + half_h], [1 - 2 * half_h, 7.0, 3 + half_h]]  # fmt: skip
    np.testing.assert_allclose(f.points[1:5], expected, rtol=1e-14)
    assert f.points[5][2] > 3 + half_h
    assert f.n_lines == 6
    assert wv.camera_frustum(cam).points[1][1] == pytest.approx(12.0)  # default length: distance to look_at
    with pytest.raises(ValueError, match="parallel"):
        wv.camera_frustum({**cam, "up": [0, 1, 0]})


def test_point_and_spot_lights_are_a_block_of_points(tmp_path):
    """Point and spot lights are never hit, so no surface shows them: the multiblock holds them as points (position,
    colour, intensity, a spot's unit axis and half-angle, sheet), after the surfaces, and the .vtm keeps them."""
    scene = small_scene()
    scene["lights"] = [{"type": "point", "position": [1.0, 2.0, 3.0], "intensity": 5.0, "color": [1.0, 0.5, 0.25]},
                       {"type": "spot", "position": [0.0, 0.0, 4.0], "intensity": 2.0, "direction": [0.0, 0.0, -3.0],
                        "angle": 20.0, "sheet": 1}]  # fmt: skip
    blocks = wv.scene_multiblock(native_scene=scene, resolution=8)
    assert blocks.keys()[:2] == ["surfaces", "lights"]
    lights = blocks["lights"]
    np.testing.assert_array_equal(lights.points, [[1.0, 2.0, 3.0], [0.0, 0.0, 4.0]])
    assert lights.n_cells == 2  # one vertex each
    assert lights.point_data["spot"].tolist() == [0, 1] and lights.point_data["intensity"].tolist() == [5.0, 2.0]
    assert lights.point_data["direction"].tolist() == [[0.0, 0.0, 0.0], [0.0, 0.0, -1.0]]
    assert lights.point_data["angle"].tolist() == [180.0, 20.0]
    assert lights.point_data["color"][0].tolist() == [1.0, 0.5, 0.25]
    back = pv.read(wv.save_scene_vtm(tmp_path / "lit.vtm", native_scene=scene, resolution=8))
    assert back["lights"].point_data["angle"].tolist() == [180.0, 20.0]
    assert "lights" not in wv.scene_multiblock(native_scene=small_scene(), resolution=8).keys()
