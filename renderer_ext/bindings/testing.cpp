// Test hooks, bound as warpviz._core._testing (reached from Python as warpviz._native.testing): a
// metric's geometry at one point, and one material's BSDF in a local frame. Not part of the public API.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "bindings/arrays.h"
#include "bindings/scene_dict.h"
#include "engine/registry.h"
#include "core/elliptic.h"
#include "core/trig.h"
#include "core/sobol.h"
#include "film/pixel_filter.h"
#include "integrators/guide_tree.h"
#include "integrators/lens_connection.h"
#include "scene/bvh.h"
#include "scene/material.h"
#include "spacetime/kerr_shadow.h"
#include "spacetime/planar_orbit.h"

namespace nb = nanobind;
using namespace nb::literals;

namespace wv::bindings {

namespace {

// The lens of a registered metric that declares itself static and spherically symmetric (the lens-map hooks).
wv::SphericalLens spherical_lens_of(const std::string& metric, const std::vector<double>& params) {
  wv::SphericalLens lens;
  if (!wv::make_spacetime(metric, params)->spherical_lens(lens))
    throw std::invalid_argument(metric + " is not static and spherically symmetric");
  return lens;
}

// Test hook for the BSDFs: samples material `material` (a complete native material dict, as
// warpviz.scene.native.native_material writes it, without textures: the albedo is given) at
// local normal n for outgoing direction wo with the given uniforms u (N, 3), and evaluates the BSDF at
// the sampled directions and at the given directions `at` (M, 3). Returns wi (N, 3), weight (N, 3),
// pdf (N,), delta (N,), valid (N,), f_eval (N, 3) (= BSDF |cos|, 0 for delta lobes), pdf_eval (N,),
// f_at (M, 3) and pdf_at (M,).
nb::dict bsdf(nb::dict material, std::vector<double> albedo, std::vector<double> n, std::vector<double> wo, F64In u,
              F64In at) {
  if (albedo.size() != 3 || n.size() != 3 || wo.size() != 3) throw std::invalid_argument("albedo, n and wo need 3 components");
  if (u.ndim() != 2 || u.shape(1) != 3) throw std::invalid_argument("u must have shape (N, 3)");
  if (at.ndim() != 2 || at.shape(1) != 3) throw std::invalid_argument("at must have shape (M, 3)");
  const wv::Material m = wv::material_from_dict(material, "material", 0);
  const wv::V3 A(albedo.data()), N = wv::normalize(wv::V3(n.data())), WO = wv::normalize(wv::V3(wo.data()));
  const size_t count = u.shape(0);
  std::vector<double> wi(3 * count), weight(3 * count), pdf(count), fe(3 * count), pe(count);
  std::vector<int8_t> delta(count), valid(count);
  for (size_t i = 0; i < count; ++i) {
    const double* ui = u.data() + 3 * i;
    const wv::BsdfSample b = wv::bsdf_sample(m, A, N, WO, ui[0], ui[1], ui[2]);
    double pev = 0.0;
    const wv::V3 f = wv::bsdf_eval(m, A, N, WO, b.wi, pev);
    for (int c = 0; c < 3; ++c) {
      wi[3 * i + c] = b.wi[c];
      weight[3 * i + c] = b.weight[c];
      fe[3 * i + c] = f[c];
    }
    pdf[i] = b.pdf;
    pe[i] = pev;
    delta[i] = b.delta;
    valid[i] = b.valid;
  }
  const size_t M = at.shape(0);
  std::vector<double> f_at(3 * M), pdf_at(M);
  for (size_t i = 0; i < M; ++i) {
    const wv::V3 f = wv::bsdf_eval(m, A, N, WO, wv::normalize(wv::V3(at.data() + 3 * i)), pdf_at[i]);
    for (int c = 0; c < 3; ++c) f_at[3 * i + c] = f[c];
  }
  nb::dict out;
  out["f_at"] = to_numpy(std::move(f_at), {M, 3});
  out["pdf_at"] = to_numpy(std::move(pdf_at), {M});
  out["wi"] = to_numpy(std::move(wi), {count, 3});
  out["weight"] = to_numpy(std::move(weight), {count, 3});
  out["pdf"] = to_numpy(std::move(pdf), {count});
  out["delta"] = to_numpy(std::move(delta), {count});
  out["valid"] = to_numpy(std::move(valid), {count});
  out["f_eval"] = to_numpy(std::move(fe), {count, 3});
  out["pdf_eval"] = to_numpy(std::move(pe), {count});
  return out;
}

// Test hook for the BVH: one built over boxes (N, 6: lo, hi); for each segment of segs (M, 8: origin,
// direction, tmin, tmax) the primitives its traversal hands to the exact test (an accept that takes none,
// so tmax never shrinks), and for each box of queries (K, 6) those overlapping() visits, as 0/1 arrays
// (M, N) and (K, N) with the order of the visits (1-based) in "segment_order" / "box_order".
nb::dict bvh_candidates(F64In boxes, F64In segs, F64In queries) {
  if (boxes.ndim() != 2 || boxes.shape(1) != 6) throw std::invalid_argument("boxes must have shape (N, 6)");
  if (segs.ndim() != 2 || segs.shape(1) != 8) throw std::invalid_argument("segs must have shape (M, 8)");
  if (queries.ndim() != 2 || queries.shape(1) != 6) throw std::invalid_argument("queries must have shape (K, 6)");
  const size_t n = boxes.shape(0), m = segs.shape(0), k = queries.shape(0);
  auto box_at = [](const double* b) {
    wv::Box x;
    x.lo = wv::V3(b);
    x.hi = wv::V3(b + 3);
    return x;
  };
  std::vector<wv::Box> bs(n);
  for (size_t i = 0; i < n; ++i) bs[i] = box_at(boxes.data() + 6 * i);
  wv::Bvh bvh;
  bvh.build(bs);
  std::vector<int32_t> seg_order(m * n, 0), box_order(k * n, 0);
  for (size_t i = 0; i < m; ++i) {
    const double* s = segs.data() + 8 * i;
    int32_t visits = 0;
    wv::SegmentHit hit;
    bvh.closest(wv::V3(s), wv::V3(s + 3), s[6], s[7], [&](int p, wv::V3, wv::V3, double, double, double&) {
      seg_order[i * n + size_t(p)] = ++visits;
      return false;
    }, hit);
  }
  for (size_t i = 0; i < k; ++i) {
    int32_t visits = 0;
    bvh.overlapping(box_at(queries.data() + 6 * i), [&](int p) { box_order[i * n + size_t(p)] = ++visits; });
  }
  nb::dict out;
  out["segment_order"] = to_numpy(std::move(seg_order), {m, n});
  out["box_order"] = to_numpy(std::move(box_order), {k, n});
  return out;
}

// Test hook for path guiding's tree (integrators/guide_tree.h): built from records (positions (N, 3), sheets
// (N,), local directions (N, 3), values (N,)) over box lo, hi; then, at position `at` on sheet `at_sheet`,
// its leaf (-1: none), the density at directions `eval` (K, 3) and directions drawn from uniforms u (S, 2)
// with their densities. Also the tree's leaf and cell counts.
nb::dict guide_tree(F64In pos, std::vector<int> sheets, F64In dirs, F64In values, std::vector<double> lo,
                    std::vector<double> hi, int leaf_records, double rho, int max_depth, std::vector<double> at,
                    int at_sheet, F64In eval, F64In u) {
  const size_t n = values.shape(0);
  if (pos.ndim() != 2 || pos.shape(1) != 3 || pos.shape(0) != n || dirs.ndim() != 2 || dirs.shape(1) != 3 ||
      dirs.shape(0) != n || sheets.size() != n)
    throw std::invalid_argument("pos and dirs must have shape (N, 3), sheets and values (N,)");
  if (lo.size() != 3 || hi.size() != 3 || at.size() != 3) throw std::invalid_argument("lo, hi, at need 3 components");
  if (eval.ndim() != 2 || eval.shape(1) != 3) throw std::invalid_argument("eval must have shape (K, 3)");
  if (u.ndim() != 2 || u.shape(1) != 2) throw std::invalid_argument("u must have shape (S, 2)");
  std::vector<wv::GuideRecord> recs(n);
  for (size_t i = 0; i < n; ++i) {
    recs[i].pos = wv::V3(pos.data() + 3 * i);
    recs[i].sheet = sheets[i];
    recs[i].normal = wv::V3(0.0, 0.0, 1.0);
    recs[i].dir = wv::normalize(wv::V3(dirs.data() + 3 * i));
    recs[i].value = values.data()[i];
  }
  wv::Box box;
  box.lo = wv::V3(lo.data());
  box.hi = wv::V3(hi.data());
  wv::GuideTree tree;
  tree.build(std::move(recs), box, {leaf_records, rho, max_depth});
  int leaf = tree.leaf(wv::V3(at.data()), at_sheet, wv::V3(0.0, 0.0, 1.0));
  if (leaf >= 0 && !tree.has_sky(leaf)) leaf = -1;
  const size_t k = eval.shape(0), ns = u.shape(0);
  std::vector<double> pe(k, 0.0), ws(3 * ns, 0.0), ps(ns, 0.0);
  if (leaf >= 0) {
    for (size_t i = 0; i < k; ++i) pe[i] = tree.pdf(leaf, wv::normalize(wv::V3(eval.data() + 3 * i)));
    for (size_t i = 0; i < ns; ++i) {
      const wv::V3 w = tree.sample(leaf, u.data()[2 * i], u.data()[2 * i + 1], ps[i]);
      for (int c = 0; c < 3; ++c) ws[3 * i + c] = w[c];
    }
  }
  nb::dict out;
  out["leaf"] = leaf;
  out["leaves"] = tree.leaf_count();
  out["cells"] = tree.cell_count();
  out["pdf_eval"] = to_numpy(std::move(pe), {k});
  out["samples"] = to_numpy(std::move(ws), {ns, 3});
  out["pdf_samples"] = to_numpy(std::move(ps), {ns});
  return out;
}

// The Kerr proposal's proxy masses in Kerr of the given mass and spin a / M (along +z), as Kerr::lens_proxy_spin and
// lens_proxy_mass give them to the proposal.
wv::ProxyMass kerr_proxy_mass(double mass, double spin) {
  const double a = spin * mass;
  return wv::ProxyMass(mass, wv::V3{0.0, 0.0, a}, [&](double c) { return wv::kerr_critical_mass(mass, a, c); });
}

// A planar light: a quad (corner p0, edges p1, p2; r_out 0) or a disk (centre p0, orthonormal axes p1, p2, radii
// r_in, r_out).
wv::PlanarLight planar_light_of(F64In p0, F64In p1, F64In p2, double r_in, double r_out) {
  const auto a = copy1(p0, 3, "p0"), b = copy1(p1, 3, "p1"), c = copy1(p2, 3, "p2");
  wv::PlanarLight L;
  if (r_out > 0.0) {
    L.is_disk = true;
    L.disk.center = {a[0], a[1], a[2]};
    L.disk.axis_u = {b[0], b[1], b[2]};
    L.disk.axis_v = {c[0], c[1], c[2]};
    L.disk.normal = wv::normalize(wv::cross(L.disk.axis_u, L.disk.axis_v));
    L.disk.r_in = r_in;
    L.disk.r_out = r_out;
  } else {
    L.quad = wv::make_quad({a[0], a[1], a[2]}, {b[0], b[1], b[2]}, {c[0], c[1], c[2]});
  }
  return L;
}

}  // namespace

void bind_testing(nb::module_& m) {
  m.def("guide_tree", &guide_tree, "pos"_a, "sheets"_a, "dirs"_a, "values"_a, "lo"_a, "hi"_a, "leaf_records"_a,
        "rho"_a, "max_depth"_a, "at"_a, "at_sheet"_a, "eval"_a, "u"_a,
        "Path guiding's tree built from records: its leaf at a point, densities and samples there.");
  m.def("bvh_candidates", &bvh_candidates, "boxes"_a, "segs"_a, "queries"_a,
        "BVH test hook: the primitives a segment's traversal and a box query hand on, in visit order.");
  m.def("bsdf", &bsdf, "material"_a, "albedo"_a, "n"_a, "wo"_a, "u"_a, "at"_a,
        "Sample and evaluate one material's BSDF in a local frame.");
  m.def(
      "inverse_metric",
      [](const std::string& metric, const std::vector<double>& params, F64In x) {
        auto st = wv::make_spacetime(metric, params);
        const auto xv = copy1(x, 4, "x");
        double gi[4][4];
        st->inverse_metric(xv.data(), gi);
        std::vector<double> out(&gi[0][0], &gi[0][0] + 16);
        return to_numpy(std::move(out), {4, 4});
      },
      "metric"_a, "params"_a, "x"_a);
  m.def(
      "observer_frame",
      [](const std::string& metric, const std::vector<double>& params, F64In x, bool generic) -> nb::object {
        auto st = wv::make_spacetime(metric, params);
        const auto xv = copy1(x, 4, "x");
        wv::ObserverFrame f;
        if (!st->observer_frame(xv.data(), generic, f)) return nb::none();
        return nb::make_tuple(to_numpy(std::vector<double>(&f.g[0][0], &f.g[0][0] + 16), {4, 4}),
                              to_numpy(std::vector<double>(f.u, f.u + 4), {4}),
                              to_numpy(std::vector<double>(&f.e[0][0], &f.e[0][0] + 12), {3, 4}));
      },
      "metric"_a, "params"_a, "x"_a, "generic"_a = false,
      "Test hook: (g_{mu nu}, u^mu, e_j^mu) of the local observer at chart point x, or None.");
  m.def(
      "rhs",
      [](const std::string& metric, const std::vector<double>& params, F64In y, bool autodiff) {
        auto st = wv::make_spacetime(metric, params);
        const auto yv = copy1(y, 8, "y");
        std::vector<double> dy(8);
        if (autodiff) st->rhs_autodiff(yv.data(), dy.data()); else st->rhs(yv.data(), dy.data());
        return to_numpy(std::move(dy), {8});
      },
      "metric"_a, "params"_a, "y"_a, "autodiff"_a = false);
  m.def(
      "invariants",
      [](const std::string& metric, const std::vector<double>& params, F64In y) {
        auto st = wv::make_spacetime(metric, params);
        const auto yv = copy1(y, 8, "y");
        std::vector<double> out(st->invariant_names().size());
        st->invariants(yv.data(), out.data());
        return to_numpy(std::move(out), {out.size()});
      },
      "metric"_a, "params"_a, "y"_a);
  m.def(
      "initial_state",
      [](const std::string& metric, const std::vector<double>& params, F64In pos, F64In dir, int sheet) {
        auto st = wv::make_spacetime(metric, params);
        const auto p = copy1(pos, 3, "pos"), d = copy1(dir, 3, "dir");
        std::vector<double> y(8);
        if (!st->initial_state(p.data(), d.data(), sheet, y.data()))
          throw std::invalid_argument("position " + st->origin_problem(p.data(), sheet));
        return to_numpy(std::move(y), {8});
      },
      "metric"_a, "params"_a, "pos"_a, "dir"_a, "sheet"_a = 1);
  m.def(
      "pixel_samples",
      [](uint64_t seed, uint64_t pixel, int n) {
        std::vector<double> out(2 * size_t(std::max(n, 0)));
        for (int i = 0; i < n; ++i) wv::pixel_sample(seed, pixel, uint64_t(i), out[2 * i], out[2 * i + 1]);
        return to_numpy(std::move(out), {size_t(std::max(n, 0)), 2});
      },
      "seed"_a, "pixel"_a, "n"_a, "Test hook: the first n stratified points (n, 2) of a pixel (core/sobol.h).");
  m.def(
      "padded_samples",
      [](uint64_t seed, uint64_t pixel, uint64_t dim, int n) {
        std::vector<double> out(2 * size_t(std::max(n, 0)));
        for (int i = 0; i < n; ++i) wv::padded_sample(seed, pixel, dim, uint64_t(i), out[2 * i], out[2 * i + 1]);
        return to_numpy(std::move(out), {size_t(std::max(n, 0)), 2});
      },
      "seed"_a, "pixel"_a, "dim"_a, "n"_a,
      "Test hook: the first n points (n, 2) of a pixel's pair of dimensions number dim >= 1 (core/sobol.h).");
  m.def(
      "filter_samples",
      [](int kind, double radius, F64In u) {
        const auto uv = copy1(u, u.ndim() == 1 ? u.shape(0) : 0, "u");
        const wv::PixelFilter f(kind, radius);
        std::vector<double> x(uv.size()), w(uv.size());
        for (size_t i = 0; i < uv.size(); ++i) x[i] = f.sample(uv[i], w[i]);
        return nb::make_tuple(to_numpy(std::move(x), {uv.size()}), to_numpy(std::move(w), {uv.size()}));
      },
      "kind"_a, "radius"_a, "u"_a,
      "Test hook: one axis of pixel filter `kind` (0 box, 1 gaussian, 2 mitchell): offsets and weights of u (n,).");
  m.def(
      "jacobi",
      [](F64In x, double m) {
        const auto xv = copy1(x, x.ndim() == 1 ? x.shape(0) : 0, "x");
        const wv::JacobiFunctions j(m);
        if (!j.valid()) throw std::invalid_argument("parameter m outside (0, 0.9999]");
        std::vector<double> out(3 * xv.size());
        for (size_t i = 0; i < xv.size(); ++i) {
          const wv::JacobiValues v = j(xv[i]);
          out[3 * i] = v.sn;
          out[3 * i + 1] = v.cn;
          out[3 * i + 2] = v.dn;
        }
        return nb::make_tuple(to_numpy(std::move(out), {xv.size(), 3}), j.K());
      },
      "x"_a, "m"_a, "Test hook: sn, cn, dn (n, 3) of x (n,) and K(m) (core/elliptic.h).");
  m.def(
      "elliptic_f",
      [](double phi, double m) {
        return wv::elliptic_f(std::sin(phi), std::cos(phi), m, wv::elliptic_k(m));
      },
      "phi"_a, "m"_a, "Test hook: F(phi | m) for phi in [0, pi] (core/elliptic.h).");
  m.def(
      "carlson_rf",
      [](double x, double y, double z) {
        using D3 = wv::Dual<3>;
        const D3 r = wv::carlson_rf(D3::variable(x, 0), D3::variable(y, 1), D3::variable(z, 2));
        return nb::make_tuple(wv::carlson_rf(x, y, z), r.v, r.d[0], r.d[1], r.d[2]);
      },
      "x"_a, "y"_a, "z"_a,
      "Test hook: R_F(x, y, z) in doubles, then in duals with its gradient (value, dR/dx, dR/dy, dR/dz).");
  m.def(
      "planar_orbit",
      [](double mass, double b, double u0, bool inward, F64In phi, F64In u_targets) -> nb::object {
        const wv::PlanarOrbit o(mass, b, u0, inward);
        if (!o.valid()) return nb::none();
        const auto ph = copy1(phi, phi.ndim() == 1 ? phi.shape(0) : 0, "phi");
        const auto ut = copy1(u_targets, u_targets.ndim() == 1 ? u_targets.shape(0) : 0, "u_targets");
        std::vector<double> u(ph.size()), du(ph.size()), at(2 * ut.size());
        for (size_t i = 0; i < ph.size(); ++i) u[i] = o.u(ph[i], &du[i]);
        for (size_t i = 0; i < ut.size(); ++i) {
          at[2 * i] = o.phi_of(ut[i], false);
          at[2 * i + 1] = o.phi_of(ut[i], true);
        }
        return nb::make_tuple(to_numpy(std::move(u), {ph.size()}), to_numpy(std::move(du), {ph.size()}),
                              to_numpy(std::move(at), {ut.size(), 2}));
      },
      "mass"_a, "b"_a, "u0"_a, "inward"_a, "phi"_a, "u_targets"_a,
      "Test hook: the closed-form orbit (spacetime/planar_orbit.h): u and du/dphi at phi (n,), and the azimuth "
      "(k, 2) at which it reaches each target u on its inward and outward branch (NaN: not ahead); None where "
      "the closed form does not apply.");
  m.def(
      "sin_cos",
      [](F64In x) {
        const auto xv = copy1(x, x.ndim() == 1 ? x.shape(0) : 0, "x");
        std::vector<double> s(xv.size()), c(xv.size());
        for (size_t i = 0; i < xv.size(); ++i) wv::sin_cos(xv[i], s[i], c[i]);
        const size_t n = xv.size();
        return nb::make_tuple(to_numpy(std::move(s), {n}), to_numpy(std::move(c), {n}));
      },
      "x"_a, "Test hook: core/trig.h's sine and cosine of x (n,), as two (n,) arrays.");
  m.def(
      "lens_ray",
      [](const std::string& metric, const std::vector<double>& params, double r_a, double r_b, bool same_sheet,
         double phi, const std::string& start) -> nb::object {
        const wv::SphericalLens lens = spherical_lens_of(metric, params);
        const wv::LensMap map(lens, 1.0 / r_a, 1.0 / r_b, same_sheet);
        double guess = -1.0;
        if (start == "flat") guess = map.flat_guess(phi);
        else if (start == "direct") guess = map.direct_guess(phi);
        else if (start != "middle") throw std::invalid_argument("start must be 'middle', 'flat' or 'direct'");
        const wv::LensRay r = map.solve(phi, guess);
        if (!r.ok) return nb::none();
        return nb::make_tuple(r.psi, r.phi, r.dphi_dpsi, r.dr_dphi, r.b, r.evals);
      },
      "metric"_a, "params"_a, "r_a"_a, "r_b"_a, "same_sheet"_a, "phi"_a, "start"_a = "middle",
      "Test hook: the ray from radius r_a to r_b sweeping azimuth phi, as (psi, phi, dphi/dpsi, dR/dphi at "
      "B, b, evaluations of Phi the root took), or None; the root started from the middle of its branch, the "
      "straight line (`flat`, phi < pi) or the straight line aimed short by the first-order bending (`direct`).");
  m.def(
      "lens_ray_at_psi",
      [](const std::string& metric, const std::vector<double>& params, double r_a, double r_b, bool same_sheet,
         double psi) -> nb::object {
        const wv::SphericalLens lens = spherical_lens_of(metric, params);
        const wv::LensMap map(lens, 1.0 / r_a, 1.0 / r_b, same_sheet);
        const wv::LensRay r = map.at_psi(psi);
        if (!r.ok) return nb::none();
        return nb::make_tuple(r.psi, r.phi, r.dphi_dpsi, r.dr_dphi, r.b);
      },
      "metric"_a, "params"_a, "r_a"_a, "r_b"_a, "same_sheet"_a, "psi"_a,
      "Test hook: the ray from radius r_a (<= r_b, or to the other sheet) leaving at angle psi from the outward "
      "radial direction, evaluated forward, as (psi, phi, dphi/dpsi, dR/dphi at B, b), or None.");
  m.def(
      "lens_images",
      [](const std::string& metric, const std::vector<double>& params, F64In pos_a, int sheet_a, F64In normal_a,
         F64In pos_b, F64In normal_b, int sheet_b, double area, bool two_sided, int orders) {
        const wv::SphericalLens lens = spherical_lens_of(metric, params);
        const auto a = copy1(pos_a, 3, "pos_a"), na = copy1(normal_a, 3, "normal_a");
        const auto b = copy1(pos_b, 3, "pos_b"), nb_ = copy1(normal_b, 3, "normal_b");
        wv::LensVertex v;  // the local frame aligned with the user axes (the static frame's, see trace())
        v.pos = {a[0], a[1], a[2]};
        v.sheet = sheet_a;
        v.radial_local = wv::normalize(v.pos);
        v.normal_local = wv::normalize(wv::V3{na[0], na[1], na[2]});
        wv::LensLight l;
        l.pos = {b[0], b[1], b[2]};
        l.normal = wv::normalize(wv::V3{nb_[0], nb_[1], nb_[2]});
        l.area = area;
        l.sheet = sheet_b;
        l.two_sided = two_sided;
        const wv::LensImages im = wv::lens_images(lens, v, l, orders);
        std::vector<double> dirs, weights, jac;
        for (int i = 0; i < im.n; ++i) {
          dirs.insert(dirs.end(), {im.w[i].x, im.w[i].y, im.w[i].z});
          weights.push_back(im.weight[i]);
          jac.push_back(im.jacobian[i]);
        }
        const size_t n = size_t(im.n);
        nb::dict out;
        out["directions"] = to_numpy(std::move(dirs), {n, 3});
        out["weights"] = to_numpy(std::move(weights), {n});
        out["jacobians"] = to_numpy(std::move(jac), {n});
        // The light strategy's draw: order 0's weight exact, the later ones' estimated, each image solved on demand.
        wv::LensImagePick pick(lens, v, l, orders);
        std::vector<double> pw, pdirs, pjac;
        for (int k = 0; k < pick.n; ++k) {
          pw.push_back(pick.weight[k]);
          wv::V3 w{NAN, NAN, NAN};
          double j = NAN;
          if (!pick.image(k, w, j)) w = {NAN, NAN, NAN}, j = NAN;
          pdirs.insert(pdirs.end(), {w.x, w.y, w.z});
          pjac.push_back(j);
        }
        const size_t np = size_t(pick.n);
        out["pick_weights"] = to_numpy(std::move(pw), {np});
        out["pick_directions"] = to_numpy(std::move(pdirs), {np, 3});
        out["pick_jacobians"] = to_numpy(std::move(pjac), {np});
        return out;
      },
      "metric"_a, "params"_a, "pos_a"_a, "sheet_a"_a, "normal_a"_a, "pos_b"_a, "normal_b"_a, "sheet_b"_a, "area"_a,
      "two_sided"_a, "orders"_a,
      "Test hook: the lensed images of light point B seen from A (directions (n, 3) in the static frame "
      "aligned with the axes, weights cos theta |dOmega/dA| (n,), area Jacobians |dA/dOmega| (n,)), and the light "
      "strategy's draw among them (LensImagePick: pick_weights (m,), order 0's exact and the later orders' "
      "estimated; pick_directions (m, 3) and pick_jacobians (m,) of each image solved, NaN where it brings nothing).");
  m.def(
      "light_crossing",
      [](double mass, F64In pos_a, F64In w_local, F64In corner, F64In edge_u, F64In edge_v, int orders,
         double margin, double spin) -> nb::object {
        const auto a = copy1(pos_a, 3, "pos_a"), w = copy1(w_local, 3, "w_local");
        const auto c = copy1(corner, 3, "corner"), eu = copy1(edge_u, 3, "edge_u"), ev = copy1(edge_v, 3, "edge_v");
        wv::Scene sc;
        sc.quads.push_back(wv::make_quad({c[0], c[1], c[2]}, {eu[0], eu[1], eu[2]}, {ev[0], ev[1], ev[2]}));
        sc.prims.push_back(wv::Prim{wv::PrimKind::kQuad, 0, 0, 0, 1});
        const wv::PlanarLight light = wv::planar_light(sc, 0).grown(margin);
        const wv::V3 pos{a[0], a[1], a[2]};
        const wv::LinearMap identity;  // the local frame aligned with the user axes, as in lens_images
        const wv::ProxyMass pm = kerr_proxy_mass(mass, spin);  // (spin 0: the one mass)
        const wv::LightCrossing x =
            wv::first_light_crossing([&](wv::V3 n) { return pm.at(n); }, pos, wv::normalize(pos), identity,
                                     wv::normalize(wv::V3{w[0], w[1], w[2]}), light, orders);
        if (!x.ok) return nb::none();
        return nb::make_tuple(to_numpy(std::vector<double>{x.pos.x, x.pos.y, x.pos.z}, {3}), x.sweep);
      },
      "mass"_a, "pos_a"_a, "w_local"_a, "corner"_a, "edge_u"_a, "edge_v"_a, "orders"_a, "margin"_a = 0.0,
      "spin"_a = 0.0,
      "Test hook: where the Schwarzschild orbit of the given mass from A along local direction w (the static "
      "frame aligned with the axes) first crosses the quad, grown by margin all round in its plane "
      "(PlanarLight::grown), within swept azimuth orders * pi (integrators/lens_proposal.h), as (point (3,), "
      "sweep), or None. With spin a / M (along +z), the orbit's mass is the Kerr proposal's for its plane and "
      "sense (ProxyMass).");
  m.def(
      "kerr_critical_impact",
      [](double mass, double spin, double c, double cos_theta) {
        return wv::kerr_critical_impact(mass, spin * mass, c, cos_theta);
      },
      "mass"_a, "spin"_a, "c"_a, "cos_theta"_a = 0.0,
      "Test hook: Kerr's critical impact parameter (spacetime/kerr_shadow.h) for light whose angular momentum "
      "makes cosine c with the spin (mass M, spin a / M), seen at polar angle acos(cos_theta) (0: on the "
      "equator, whence the Kerr proposal's proxy mass is it over sqrt(27)).");
  m.def(
      "proxy_mass",
      [](double mass, double spin, F64In normal) {
        const auto n = copy1(normal, 3, "normal");
        return kerr_proxy_mass(mass, spin).at(wv::normalize(wv::V3{n[0], n[1], n[2]}));
      },
      "mass"_a, "spin"_a, "normal"_a,
      "Test hook: the Kerr proposal's proxy mass (integrators/lens_proposal.h, ProxyMass) for the backward ray's "
      "orbit turning about unit normal (3,) by the right hand, in Kerr of the given mass and spin a / M (along +z).");
  m.def(
      "proposal_light_draws",
      [](F64In p0, F64In p1, F64In p2, double r_in, double r_out, double margin, double share, int n) {
        const wv::ProposalLight pl(planar_light_of(p0, p1, p2, r_in, r_out), margin, share);
        std::vector<double> pts, dens, on;
        for (int i = 0; i < n; ++i)
          for (int j = 0; j < n; ++j) {
            const wv::V3 x = pl.point((i + 0.5) / n, (j + 0.5) / n);
            pts.insert(pts.end(), {x.x, x.y, x.z});
            dens.push_back(pl.density(x));
            on.push_back(pl.on_light(x) ? 1.0 : 0.0);
          }
        const size_t k = size_t(n) * size_t(n);
        return nb::make_tuple(to_numpy(std::move(pts), {k, 3}), to_numpy(std::move(dens), {k}),
                              to_numpy(std::move(on), {k}), pl.grown.area(), pl.q);
      },
      "p0"_a, "p1"_a, "p2"_a, "r_in"_a, "r_out"_a, "margin"_a, "share"_a, "n"_a,
      "Test hook: the Kerr proposal's draws from a light and its margin (integrators/lens_proposal.h, "
      "ProposalLight) at the n x n grid of (u1, u2): points (n*n, 3), their density per unit area (n*n,), whether "
      "each is on the light (n*n,), the grown shape's area and the margin's share. A quad: corner p0, edges p1, p2 "
      "(r_out 0); a disk: centre p0, orthonormal axes p1, p2, radii r_in, r_out.");
  m.def(
      "lens_focus_draws",
      [](double mass, F64In pos_a, F64In p0, F64In p1, F64In p2, double r_in, double r_out, int n, F64In at) {
        const auto a = copy1(pos_a, 3, "pos_a");
        const wv::PlanarLight light = planar_light_of(p0, p1, p2, r_in, r_out);
        const wv::LensFocus f(mass, {a[0], a[1], a[2]}, light);
        std::vector<double> pts, dens, drawn, at_dens;
        for (int i = 0; i < n; ++i)
          for (int j = 0; j < n; ++j) {
            wv::V3 x{NAN, NAN, NAN};
            const bool ok = f.active() && f.point((i + 0.5) / n, (j + 0.5) / n, x);
            pts.insert(pts.end(), {x.x, x.y, x.z});
            dens.push_back(ok ? f.density(x) / f.share() : 0.0);
            drawn.push_back(ok ? 1.0 : 0.0);
          }
        const auto q = copy1(at, at.ndim() == 1 ? at.shape(0) : 0, "at");
        for (size_t i = 0; i + 2 < q.size(); i += 3)
          at_dens.push_back(f.active() ? f.density({q[i], q[i + 1], q[i + 2]}) / f.share() : 0.0);
        const size_t k = size_t(n) * size_t(n), m = at_dens.size();
        return nb::make_tuple(to_numpy(std::move(pts), {k, 3}), to_numpy(std::move(dens), {k}),
                              to_numpy(std::move(drawn), {k}), to_numpy(std::move(at_dens), {m}), f.share());
      },
      "mass"_a, "pos_a"_a, "p0"_a, "p1"_a, "p2"_a, "r_in"_a, "r_out"_a, "n"_a, "at"_a,
      "Test hook: the lens focus of a light seen from A (integrators/lens_focus.h) drawn at the n x n grid of (u1, "
      "u2): points (n*n, 3) (NaN where none is drawn), the focus's own density per unit area at each (n*n,), "
      "whether each was drawn (n*n,), its density at the points `at` (m*3,) flattened, (m,), and its share of the "
      "light's draws (0: inactive). The light as proposal_light_draws takes it.");
}

}  // namespace wv::bindings
