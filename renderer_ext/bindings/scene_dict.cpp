#include "bindings/scene_dict.h"

#include <nanobind/ndarray.h>
#include <nanobind/stl/string.h>

#include <cmath>
#include <stdexcept>
#include <string>

namespace nb = nanobind;

namespace wv {
namespace {

[[noreturn]] void fail(const std::string& where, const std::string& what) {
  throw std::invalid_argument(where + " " + what);
}

nb::handle get(const nb::dict& d, const char* key, const std::string& where, bool required = true) {
  if (d.contains(key)) return d[key];
  if (required) fail(where + "." + key, "is missing");
  return nb::handle();
}

double number(const nb::dict& d, const char* key, const std::string& where, double dflt = NAN, bool required = false) {
  nb::handle h = get(d, key, where, required && std::isnan(dflt));
  if (!h.is_valid() || h.is_none()) return dflt;
  double v;
  if (!nb::try_cast<double>(h, v)) fail(where + "." + key, "must be a number");
  if (!std::isfinite(v)) fail(where + "." + key, "must be finite");
  return v;
}

V3 vec3(const nb::dict& d, const char* key, const std::string& where, V3 dflt, bool required = false) {
  nb::handle h = get(d, key, where, required);
  if (!h.is_valid() || h.is_none()) return dflt;
  const std::string w = where + "." + key;
  nb::sequence seq;
  if (!nb::try_cast<nb::sequence>(h, seq) || nb::len(seq) != 3) fail(w, "must be a list of 3 numbers");
  V3 v;
  for (int i = 0; i < 3; ++i) {
    if (!nb::try_cast<double>(seq[i], v[i]) || !std::isfinite(v[i])) fail(w, "must be a list of 3 finite numbers");
  }
  return v;
}

// A pair of positive numbers [u, v] (checker scale, grid cells, image repeats).
void pair(const nb::dict& d, const char* key, const std::string& where, double dflt, double& u, double& v) {
  u = v = dflt;
  nb::handle h = get(d, key, where, false);
  if (!h.is_valid() || h.is_none()) return;
  const std::string w = where + "." + key;
  nb::sequence seq;
  if (!nb::try_cast<nb::sequence>(h, seq) || nb::len(seq) != 2 || !nb::try_cast<double>(seq[0], u) ||
      !nb::try_cast<double>(seq[1], v) || !(u > 0 && v > 0 && std::isfinite(u) && std::isfinite(v)))
    fail(w, "must be a list of 2 positive numbers");
}

nb::dict sub(nb::handle h, const std::string& where) {
  nb::dict out;
  if (!nb::try_cast<nb::dict>(h, out)) fail(where, "must be a table (dict)");
  return out;
}

int index(const nb::dict& d, const char* key, const std::string& where, int size, int dflt = -2) {
  nb::handle h = get(d, key, where, dflt == -2);
  if (!h.is_valid() || h.is_none()) return dflt;
  int v;
  if (!nb::try_cast<int>(h, v)) fail(where + "." + key, "must be an integer");
  if (v < -1 || v >= size) fail(where + "." + key, "index " + std::to_string(v) + " out of range (" + std::to_string(size) + " defined)");
  return v;
}

int sheet_of(const nb::dict& d, const std::string& where) {
  const double s = number(d, "sheet", where, 1.0);
  if (s != 1.0 && s != -1.0) fail(where + ".sheet", "must be +1 or -1");
  return int(s);
}

void image_into(nb::handle h, const std::string& where, Texture& t) {
  nb::ndarray<const float, nb::c_contig, nb::device::cpu> a;
  if (!nb::try_cast(h, a) || a.ndim() != 3 || a.shape(2) != 3 || a.shape(0) < 1 || a.shape(1) < 1)
    fail(where, "must be a C-contiguous float32 array of shape (H, W, 3)");
  t.h = int(a.shape(0));
  t.w = int(a.shape(1));
  t.rgb.assign(a.data(), a.data() + a.size());
}

// The shape's "meridian" (default +x) made perpendicular to unit axis n; any perpendicular if parallel.
V3 meridian_axis(const nb::dict& t, const std::string& where, V3 n) {
  V3 mer = vec3(t, "meridian", where, {1, 0, 0});
  mer = mer - n * dot(mer, n);
  if (!(length(mer) > 1e-9)) {
    V3 b;
    basis_around(n, mer, b);
  }
  return normalize(mer);
}

std::string type_of(const nb::dict& d, const std::string& where) {
  nb::handle h = get(d, "type", where);
  std::string s;
  if (!nb::try_cast<std::string>(h, s)) fail(where + ".type", "must be a string");
  return s;
}

void environment_from(const nb::dict& d, const std::string& w, Environment& env) {
  env.color = vec3(d, "color", w, {0, 0, 0});
  if (d.contains("image") && !d["image"].is_none()) {
    env.has_image = true;
    env.image.kind = TextureKind::kImage;
    image_into(d["image"], w + ".image", env.image);
  }
  if (d.contains("stars") && !d["stars"].is_none()) {
    const nb::dict s = sub(d["stars"], w + ".stars");
    // No defaults here: the scene compiler (warpviz's TOML reader) owns them and writes every key.
    env.stars.density = number(s, "density", w + ".stars", NAN, true);
    env.stars.brightness = number(s, "brightness", w + ".stars", NAN, true);
    env.stars.size = number(s, "size", w + ".stars", NAN, true);
    env.stars.seed = uint64_t(number(s, "seed", w + ".stars", NAN, true));
    if (env.stars.density < 0 || env.stars.size <= 0) fail(w + ".stars", "needs density >= 0 and size > 0");
  }
  if (d.contains("spots") && !d["spots"].is_none()) {
    nb::list spots;
    if (!nb::try_cast<nb::list>(d["spots"], spots)) fail(w + ".spots", "must be a list");
    for (size_t i = 0; i < nb::len(spots); ++i) {
      const std::string ws = w + ".spots[" + std::to_string(i) + "]";
      const nb::dict s = sub(spots[i], ws);
      Spot sp;
      sp.direction = normalize(vec3(s, "direction", ws, {}, true));
      if (!(length(sp.direction) > 0)) fail(ws + ".direction", "must be non-zero");
      const double r = number(s, "radius", ws, 0.01);
      if (!(r > 0 && r < M_PI)) fail(ws + ".radius", "must be in (0, pi)");
      sp.cos_radius = std::cos(r);
      sp.color = vec3(s, "color", ws, {1, 1, 1});
      env.spots.push_back(sp);
    }
  }
}

}  // namespace

void scene_from_dict(const nb::dict& d, Scene& sc) {
  // Camera
  {
    const std::string w = "camera";
    const nb::dict c = sub(get(d, "camera", "scene"), w);
    Camera& cam = sc.camera;
    cam.position = vec3(c, "position", w, {}, true);
    cam.look_at = vec3(c, "look_at", w, {}, true);
    cam.up = vec3(c, "up", w, {0, 0, 1});
    cam.fov = number(c, "fov", w, 40.0);
    if (!(cam.fov > 0 && cam.fov < 180)) fail(w + ".fov", "must be in (0, 180) degrees");
    const double W = number(c, "width", w, 64), H = number(c, "height", w, 48);
    if (!(W >= 1 && H >= 1 && W <= 65536 && H <= 65536) || W != std::floor(W) || H != std::floor(H))
      fail(w + ".width/height", "must be positive integers");
    cam.width = int(W);
    cam.height = int(H);
    cam.sheet = sheet_of(c, w);
    if (!(length(cam.look_at - cam.position) > 0)) fail(w + ".look_at", "must differ from camera.position");
  }
  // Textures
  if (d.contains("textures")) {
    nb::list tl = nb::cast<nb::list>(d["textures"]);
    for (size_t i = 0; i < nb::len(tl); ++i) {
      const std::string w = "textures[" + std::to_string(i) + "]";
      const nb::dict t = sub(tl[i], w);
      const std::string ty = type_of(t, w);
      Texture tex;
      if (ty == "constant") {
        tex.a = vec3(t, "color", w, {}, true);
      } else if (ty == "checker") {
        tex.kind = TextureKind::kChecker;
        tex.a = vec3(t, "color_a", w, {}, true);
        tex.b = vec3(t, "color_b", w, {}, true);
        pair(t, "scale", w, 8.0, tex.su, tex.sv);
      } else if (ty == "grid") {
        tex.kind = TextureKind::kGrid;
        tex.a = vec3(t, "base", w, {}, true);
        tex.b = vec3(t, "line_u", w, {}, true);
        tex.c = vec3(t, "line_v", w, {}, true);
        pair(t, "cells", w, 10.0, tex.su, tex.sv);
        tex.width = number(t, "width", w, 0.05);
      } else if (ty == "image") {
        tex.kind = TextureKind::kImage;
        image_into(get(t, "data", w), w + ".data", tex);
        pair(t, "repeat", w, 1.0, tex.su, tex.sv);
      } else {
        fail(w + ".type", "unknown texture type '" + ty + "' (known: constant, checker, grid, image)");
      }
      sc.textures.push_back(std::move(tex));
    }
  }
  const int ntex = int(sc.textures.size());
  // Materials
  nb::list ml = nb::cast<nb::list>(get(d, "materials", "scene"));
  for (size_t i = 0; i < nb::len(ml); ++i) {
    const std::string w = "materials[" + std::to_string(i) + "]";
    const nb::dict t = sub(ml[i], w);
    const std::string ty = type_of(t, w);
    Material m;
    if (ty == "diffuse") {
      m.kind = MaterialKind::kDiffuse;
      m.texture = index(t, "texture", w, ntex);
    } else if (ty == "mirror") {
      m.kind = MaterialKind::kMirror;
      m.tint = vec3(t, "reflectance", w, {1, 1, 1});
    } else if (ty == "glass") {
      m.kind = MaterialKind::kGlass;
      m.ior = number(t, "ior", w, 1.5);
      if (!(m.ior >= 1.0)) fail(w + ".ior", "must be >= 1");
      m.tint = vec3(t, "tint", w, {1, 1, 1});
    } else if (ty == "emissive") {
      m.kind = MaterialKind::kEmissive;
      m.texture = index(t, "texture", w, ntex, -1);
      m.strength = number(t, "strength", w, 1.0);
      if (!(m.strength >= 0)) fail(w + ".strength", "must be >= 0");
      m.two_sided = t.contains("two_sided") && nb::cast<bool>(t["two_sided"]);
      m.beaming = t.contains("beaming") && nb::cast<bool>(t["beaming"]);
      m.keplerian = t.contains("keplerian") && nb::cast<bool>(t["keplerian"]);
      m.colour_shift = t.contains("colour_shift") && nb::cast<bool>(t["colour_shift"]);
    } else {
      fail(w + ".type", "unknown material type '" + ty + "' (known: diffuse, mirror, glass, emissive)");
    }
    sc.materials.push_back(m);
  }
  const int nmat = int(sc.materials.size());
  // Shapes
  nb::list sl = nb::cast<nb::list>(get(d, "shapes", "scene"));
  for (size_t i = 0; i < nb::len(sl); ++i) {
    const std::string w = "shapes[" + std::to_string(i) + "]";
    const nb::dict t = sub(sl[i], w);
    const std::string ty = type_of(t, w);
    Prim pr;
    pr.material = index(t, "material", w, nmat);
    if (pr.material < 0) fail(w + ".material", "is required");
    pr.shape = int32_t(i);
    pr.sheet = int8_t(sheet_of(t, w));
    if (ty == "sphere") {
      Sphere s;
      s.center = vec3(t, "center", w, {}, true);
      s.radius = number(t, "radius", w, NAN, true);
      if (!(s.radius > 0)) fail(w + ".radius", "must be > 0");
      s.pole = normalize(vec3(t, "pole", w, {0, 0, 1}));
      s.meridian = meridian_axis(t, w, s.pole);
      s.third = cross(s.pole, s.meridian);
      pr.kind = PrimKind::kSphere;
      pr.index = int32_t(sc.spheres.size());
      sc.spheres.push_back(s);
      sc.prims.push_back(pr);
    } else if (ty == "quad") {
      Quad q;
      q.corner = vec3(t, "corner", w, {}, true);
      q.eu = vec3(t, "edge_u", w, {}, true);
      q.ev = vec3(t, "edge_v", w, {}, true);
      const V3 c = cross(q.eu, q.ev);
      q.area = length(c);
      if (!(q.area > 0)) fail(w, "edge_u and edge_v must span a parallelogram (non-zero, not parallel)");
      q.normal = c / q.area;
      pr.kind = PrimKind::kQuad;
      pr.index = int32_t(sc.quads.size());
      sc.quads.push_back(q);
      sc.prims.push_back(pr);
    } else if (ty == "disk") {
      Disk k;
      k.center = vec3(t, "center", w, {}, true);
      k.normal = normalize(vec3(t, "normal", w, {0, 0, 1}));
      if (!(length(k.normal) > 0)) fail(w + ".normal", "must be non-zero");
      k.r_in = number(t, "inner_radius", w, 0.0);
      k.r_out = number(t, "outer_radius", w, NAN, true);
      if (!(k.r_in >= 0 && k.r_out > k.r_in)) fail(w, "needs 0 <= inner_radius < outer_radius");
      k.axis_u = meridian_axis(t, w, k.normal);
      k.axis_v = cross(k.normal, k.axis_u);
      pr.kind = PrimKind::kDisk;
      pr.index = int32_t(sc.disks.size());
      sc.disks.push_back(k);
      sc.prims.push_back(pr);
    } else if (ty == "mesh") {
      nb::ndarray<const double, nb::c_contig, nb::device::cpu> V, UV;
      nb::ndarray<const int32_t, nb::c_contig, nb::device::cpu> F;
      if (!nb::try_cast(get(t, "vertices", w), V) || V.ndim() != 2 || V.shape(1) != 3)
        fail(w + ".vertices", "must be a C-contiguous float64 array of shape (V, 3)");
      if (!nb::try_cast(get(t, "faces", w), F) || F.ndim() != 2 || F.shape(1) != 3)
        fail(w + ".faces", "must be a C-contiguous int32 array of shape (F, 3)");
      const bool has_uv = t.contains("uvs") && !t["uvs"].is_none();
      if (has_uv && (!nb::try_cast(t["uvs"], UV) || UV.ndim() != 2 || UV.shape(0) != V.shape(0) || UV.shape(1) != 2))
        fail(w + ".uvs", "must be a C-contiguous float64 array of shape (V, 2)");
      const size_t nv = V.shape(0);
      const double* v = V.data();
      for (size_t f = 0; f < F.shape(0); ++f) {
        int32_t idx[3];
        for (int c = 0; c < 3; ++c) {
          idx[c] = F.data()[3 * f + c];
          if (idx[c] < 0 || size_t(idx[c]) >= nv) fail(w + ".faces", "refers to a vertex out of range");
        }
        Triangle tr;
        tr.a = V3(v + 3 * idx[0]);
        tr.e1 = V3(v + 3 * idx[1]) - tr.a;
        tr.e2 = V3(v + 3 * idx[2]) - tr.a;
        const V3 c = cross(tr.e1, tr.e2);
        if (!(length(c) > 0)) continue;  // degenerate triangle: nothing to hit
        tr.normal = normalize(c);
        for (int c2 = 0; c2 < 3; ++c2) {
          tr.uv[c2][0] = has_uv ? UV.data()[2 * idx[c2]] : 0.0;
          tr.uv[c2][1] = has_uv ? UV.data()[2 * idx[c2] + 1] : 0.0;
        }
        Prim p2 = pr;
        p2.kind = PrimKind::kTriangle;
        p2.index = int32_t(sc.triangles.size());
        sc.triangles.push_back(tr);
        sc.prims.push_back(p2);
      }
    } else {
      fail(w + ".type", "unknown shape type '" + ty + "' (known: sphere, quad, disk, mesh)");
    }
  }
  // Environment(s)
  if (d.contains("environment") && !d["environment"].is_none())
    environment_from(sub(d["environment"], "environment"), "environment", sc.environment);
  if (d.contains("environment_other") && !d["environment_other"].is_none())
    environment_from(sub(d["environment_other"], "environment_other"), "environment_other", sc.environment_other);
  else
    sc.environment_other = sc.environment;
  sc.finalize();
}

}  // namespace wv
