// The native scene dict -> Scene: conversion only (bindings/scene_dict.h). Every key is read with one of
// the helpers below as helper(table, "key", where); none has a default, so a key that warpviz.scene.native
// did not write fails loudly here instead of silently taking a value of its own.
#include "bindings/scene_dict.h"

#include <nanobind/ndarray.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <cmath>
#include <stdexcept>
#include <string>

namespace nb = nanobind;

namespace wv {
namespace {

[[noreturn]] void missing(const std::string& key, const char* type) {
  throw std::invalid_argument("native scene: '" + key + "' is missing or not " + type +
                              " (warpviz.scene.native.native_scene writes every key)");
}

nb::handle item(const nb::dict& d, const char* key, const std::string& where, const char* type) {
  if (!d.contains(key)) missing(where + "." + key, type);
  return d[key];
}

template <class T>
T typed(const nb::dict& d, const char* key, const std::string& where, const char* type) {
  T v;
  if (!nb::try_cast<T>(item(d, key, where, type), v)) missing(where + "." + key, type);
  return v;
}

double number(const nb::dict& d, const char* key, const std::string& where) {
  return typed<double>(d, key, where, "a number");
}
int integer(const nb::dict& d, const char* key, const std::string& where) {
  return typed<int>(d, key, where, "an integer");
}
bool flag(const nb::dict& d, const char* key, const std::string& where) { return typed<bool>(d, key, where, "a bool"); }
std::string text(const nb::dict& d, const char* key, const std::string& where) {
  return typed<std::string>(d, key, where, "a string");
}
nb::dict table(const nb::dict& d, const char* key, const std::string& where) {
  return typed<nb::dict>(d, key, where, "a dict");
}
nb::list list(const nb::dict& d, const char* key, const std::string& where) {
  return typed<nb::list>(d, key, where, "a list");
}
// A key whose value may be None ("none": no image, no star field, no uvs); false then.
bool given(const nb::dict& d, const char* key, const std::string& where) {
  return !item(d, key, where, "present (None or a value)").is_none();
}

V3 vec3(const nb::dict& d, const char* key, const std::string& where) {
  nb::sequence seq;
  if (!nb::try_cast<nb::sequence>(item(d, key, where, "a list of 3 numbers"), seq) || nb::len(seq) != 3)
    missing(where + "." + key, "a list of 3 numbers");
  V3 v;
  for (int i = 0; i < 3; ++i)
    if (!nb::try_cast<double>(seq[i], v[i])) missing(where + "." + key, "a list of 3 numbers");
  return v;
}

// A pair [u, v] (checker scale, grid cells, image repeats).
void pair(const nb::dict& d, const char* key, const std::string& where, double& u, double& v) {
  nb::sequence seq;
  if (!nb::try_cast<nb::sequence>(item(d, key, where, "a list of 2 numbers"), seq) || nb::len(seq) != 2 ||
      !nb::try_cast<double>(seq[0], u) || !nb::try_cast<double>(seq[1], v))
    missing(where + "." + key, "a list of 2 numbers");
}

// An index into a table of `size` entries, or -1 (range checked: it is used to index).
int index(const nb::dict& d, const char* key, const std::string& where, int size) {
  const int v = integer(d, key, where);
  if (v < -1 || v >= size)
    throw std::invalid_argument("native scene: " + where + "." + key + " index " + std::to_string(v) +
                                " out of range (" + std::to_string(size) + " defined)");
  return v;
}

void image_into(const nb::dict& d, const char* key, const std::string& where, Texture& t) {
  nb::ndarray<const float, nb::c_contig, nb::device::cpu> a;
  if (!nb::try_cast(item(d, key, where, "a float32 array"), a) || a.ndim() != 3 || a.shape(2) != 3 ||
      a.shape(0) < 1 || a.shape(1) < 1)
    missing(where + "." + key, "a C-contiguous float32 array of shape (H, W, 3)");
  t.h = int(a.shape(0));
  t.w = int(a.shape(1));
  t.rgb.assign(a.data(), a.data() + a.size());
}

// The shape's meridian made perpendicular to unit axis n; any perpendicular if parallel.
V3 meridian_axis(const nb::dict& t, const std::string& where, V3 n) {
  V3 mer = vec3(t, "meridian", where);
  mer = mer - n * dot(mer, n);
  if (!(length(mer) > 1e-9)) {
    V3 b;
    basis_around(n, mer, b);
  }
  return normalize(mer);
}

void environment_from(const nb::dict& d, const std::string& w, Environment& env) {
  env.color = vec3(d, "color", w);
  if (given(d, "image", w)) {
    env.has_image = true;
    env.image.kind = TextureKind::kImage;
    image_into(d, "image", w, env.image);
  }
  if (given(d, "stars", w)) {
    const nb::dict s = table(d, "stars", w);
    const std::string ws = w + ".stars";
    env.stars.density = number(s, "density", ws);
    env.stars.brightness = number(s, "brightness", ws);
    env.stars.size = number(s, "size", ws);
    env.stars.seed = typed<uint64_t>(s, "seed", ws, "a non-negative integer");
  }
  const nb::list spots = list(d, "spots", w);
  for (size_t i = 0; i < nb::len(spots); ++i) {
    const std::string ws = w + ".spots[" + std::to_string(i) + "]";
    nb::dict s;
    if (!nb::try_cast<nb::dict>(spots[i], s)) missing(ws, "a dict");
    Spot sp;
    sp.direction = normalize(vec3(s, "direction", ws));
    sp.cos_radius = std::cos(number(s, "radius", ws));
    sp.color = vec3(s, "color", ws);
    env.spots.push_back(sp);
  }
}

// Entry i of a list of tables.
nb::dict entry(const nb::list& l, size_t i, const std::string& where) {
  nb::dict out;
  if (!nb::try_cast<nb::dict>(l[i], out)) missing(where, "a dict");
  return out;
}

}  // namespace

void metric_from_dict(const nb::dict& scene, std::string& name, std::vector<double>& params) {
  const nb::dict md = table(scene, "metric", "scene");
  name = text(md, "name", "metric");
  params = typed<std::vector<double>>(md, "params", "metric", "a list of numbers");
}

void camera_from_dict(const nb::dict& c, Camera& cam, const std::string& w) {
  cam.position = vec3(c, "position", w);
  cam.look_at = vec3(c, "look_at", w);
  cam.up = vec3(c, "up", w);
  cam.fov = number(c, "fov", w);
  cam.width = integer(c, "width", w);
  cam.height = integer(c, "height", w);
  cam.sheet = integer(c, "sheet", w);
  const nb::dict o = table(c, "observer", w);
  const std::string ow = w + ".observer";
  static const char* kinds[] = {"local", "static", "zamo", "orbit", "free_fall", "moving", "given"};
  const std::string kind = text(o, "kind", ow);
  int k = 0;
  while (k < 7 && kind != kinds[k]) ++k;
  if (k == 7) throw std::invalid_argument("native scene: " + ow + ".kind: unknown observer '" + kind + "'");
  cam.observer.kind = ObserverKind(k);
  const V3 v = vec3(o, "velocity", ow), a = vec3(o, "axis", ow);
  for (int i = 0; i < 3; ++i) {
    cam.observer.velocity[i] = v[i];
    cam.observer.axis[i] = a[i];
  }
  cam.observer.fall_from = number(o, "fall_from", ow);
  const auto u = typed<std::vector<double>>(o, "u", ow, "a list of 4 numbers");
  if (u.size() != 4) throw std::invalid_argument("native scene: " + ow + ".u must have 4 numbers");
  for (int i = 0; i < 4; ++i) cam.observer.u[i] = u[i];
  const std::string shift = text(c, "shift", w);
  if (shift == "none") cam.shift = kShiftNone;
  else if (shift == "beaming") cam.shift = kShiftBeaming;
  else if (shift == "colour") cam.shift = kShiftColour;
  else throw std::invalid_argument("native scene: " + w + ".shift: unknown shift '" + shift + "'");
  if (cam.width < 1 || cam.height < 1) throw std::invalid_argument("native scene: " + w + ".width/height must be >= 1");
}

Material material_from_dict(const nb::dict& t, const std::string& w, int ntex) {
  const std::string ty = text(t, "type", w);
  Material m;
  if (ty == "diffuse") {
    m.kind = MaterialKind::kDiffuse;
    m.texture = index(t, "texture", w, ntex);
    m.emission = vec3(t, "emission", w);
  } else if (ty == "mirror") {
    m.kind = MaterialKind::kMirror;
    m.tint = vec3(t, "reflectance", w);
    m.emission = vec3(t, "emission", w);
  } else if (ty == "glass") {
    m.kind = MaterialKind::kGlass;
    m.ior = number(t, "ior", w);
    m.tint = vec3(t, "tint", w);
    m.emission = vec3(t, "emission", w);
  } else if (ty == "emissive") {
    m.kind = MaterialKind::kEmissive;
    m.texture = index(t, "texture", w, ntex);
    m.strength = number(t, "strength", w);
    m.two_sided = flag(t, "two_sided", w);
    m.beaming = flag(t, "beaming", w);
    m.keplerian = flag(t, "keplerian", w);
    m.colour_shift = flag(t, "colour_shift", w);
  } else {
    throw std::invalid_argument("native scene: " + w + ".type: unknown material type '" + ty + "'");
  }
  return m;
}

void scene_from_dict(const nb::dict& d, Scene& sc) {
  camera_from_dict(table(d, "camera", "scene"), sc.camera);
  // Textures
  const nb::list tl = list(d, "textures", "scene");
  for (size_t i = 0; i < nb::len(tl); ++i) {
    const std::string w = "textures[" + std::to_string(i) + "]";
    const nb::dict t = entry(tl, i, w);
    const std::string ty = text(t, "type", w);
    Texture tex;
    if (ty == "constant") {
      tex.a = vec3(t, "color", w);
    } else if (ty == "checker") {
      tex.kind = TextureKind::kChecker;
      tex.a = vec3(t, "color_a", w);
      tex.b = vec3(t, "color_b", w);
      pair(t, "scale", w, tex.su, tex.sv);
    } else if (ty == "grid") {
      tex.kind = TextureKind::kGrid;
      tex.a = vec3(t, "base", w);
      tex.b = vec3(t, "line_u", w);
      tex.c = vec3(t, "line_v", w);
      pair(t, "cells", w, tex.su, tex.sv);
      tex.width = number(t, "width", w);
      tex.mark_u = int(number(t, "mark_u", w));
      tex.mark_v = int(number(t, "mark_v", w));
      tex.mark_u_color = vec3(t, "mark_u_color", w);
      tex.mark_v_color = vec3(t, "mark_v_color", w);
    } else if (ty == "image") {
      tex.kind = TextureKind::kImage;
      image_into(t, "data", w, tex);
      pair(t, "repeat", w, tex.su, tex.sv);
    } else {
      throw std::invalid_argument("native scene: " + w + ".type: unknown texture type '" + ty + "'");
    }
    sc.textures.push_back(std::move(tex));
  }
  const int ntex = int(sc.textures.size());
  // Materials
  const nb::list ml = list(d, "materials", "scene");
  for (size_t i = 0; i < nb::len(ml); ++i) {
    const std::string w = "materials[" + std::to_string(i) + "]";
    sc.materials.push_back(material_from_dict(entry(ml, i, w), w, ntex));
  }
  const int nmat = int(sc.materials.size());
  // Shapes
  const nb::list sl = list(d, "shapes", "scene");
  for (size_t i = 0; i < nb::len(sl); ++i) {
    const std::string w = "shapes[" + std::to_string(i) + "]";
    const nb::dict t = entry(sl, i, w);
    const std::string ty = text(t, "type", w);
    Prim pr;
    pr.material = index(t, "material", w, nmat);
    if (pr.material < 0) throw std::invalid_argument("native scene: " + w + ".material must be a material's index");
    pr.shape = int32_t(i);
    pr.sheet = int8_t(integer(t, "sheet", w));
    if (ty == "sphere") {
      Sphere s;
      s.center = vec3(t, "center", w);
      s.radius = number(t, "radius", w);
      s.pole = normalize(vec3(t, "pole", w));
      s.meridian = meridian_axis(t, w, s.pole);
      s.third = cross(s.pole, s.meridian);
      pr.kind = PrimKind::kSphere;
      pr.index = int32_t(sc.spheres.size());
      sc.spheres.push_back(s);
      sc.prims.push_back(pr);
    } else if (ty == "quad") {
      const V3 corner = vec3(t, "corner", w), eu = vec3(t, "edge_u", w), ev = vec3(t, "edge_v", w);
      const Quad q = make_quad(corner, eu, ev);
      pr.kind = PrimKind::kQuad;
      pr.index = int32_t(sc.quads.size());
      sc.quads.push_back(q);
      sc.prims.push_back(pr);
    } else if (ty == "disk") {
      Disk k;
      k.center = vec3(t, "center", w);
      k.normal = normalize(vec3(t, "normal", w));
      k.r_in = number(t, "inner_radius", w);
      k.r_out = number(t, "outer_radius", w);
      k.axis_u = meridian_axis(t, w, k.normal);
      k.axis_v = cross(k.normal, k.axis_u);
      pr.kind = PrimKind::kDisk;
      pr.index = int32_t(sc.disks.size());
      sc.disks.push_back(k);
      sc.prims.push_back(pr);
    } else if (ty == "mesh") {
      nb::ndarray<const double, nb::c_contig, nb::device::cpu> V, UV;
      nb::ndarray<const int32_t, nb::c_contig, nb::device::cpu> F;
      if (!nb::try_cast(item(t, "vertices", w, "a float64 array"), V) || V.ndim() != 2 || V.shape(1) != 3)
        missing(w + ".vertices", "a C-contiguous float64 array of shape (V, 3)");
      if (!nb::try_cast(item(t, "faces", w, "an int32 array"), F) || F.ndim() != 2 || F.shape(1) != 3)
        missing(w + ".faces", "a C-contiguous int32 array of shape (F, 3)");
      const bool has_uv = given(t, "uvs", w);
      if (has_uv && (!nb::try_cast(item(t, "uvs", w, "a float64 array"), UV) || UV.ndim() != 2 ||
                     UV.shape(0) != V.shape(0) || UV.shape(1) != 2))
        missing(w + ".uvs", "None or a C-contiguous float64 array of shape (V, 2)");
      const size_t nv = V.shape(0);
      const double* v = V.data();
      for (size_t f = 0; f < F.shape(0); ++f) {
        int32_t idx[3];
        for (int c = 0; c < 3; ++c) {
          idx[c] = F.data()[3 * f + c];
          if (idx[c] < 0 || size_t(idx[c]) >= nv)
            throw std::invalid_argument("native scene: " + w + ".faces refers to a vertex out of range");
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
      throw std::invalid_argument("native scene: " + w + ".type: unknown shape type '" + ty + "'");
    }
  }
  // Point and spot lights: no shape, so no ray hits one; the light strategy and the photons reach them.
  const nb::list pll = list(d, "lights", "scene");
  for (size_t i = 0; i < nb::len(pll); ++i) {
    const std::string w = "lights[" + std::to_string(i) + "]";
    const nb::dict t = entry(pll, i, w);
    const std::string ty = text(t, "type", w);
    PointLight pl;
    pl.pos = vec3(t, "position", w);
    pl.sheet = int(integer(t, "sheet", w));
    pl.intensity = vec3(t, "color", w) * number(t, "intensity", w);
    if (ty == "spot") {
      pl.spot = true;
      pl.axis = normalize(vec3(t, "direction", w));
      const double outer = number(t, "angle", w) * M_PI / 180.0, soft = number(t, "falloff", w) * M_PI / 180.0;
      pl.cos_outer = std::cos(outer);
      pl.cos_inner = std::cos(std::max(0.0, outer - soft));
    } else if (ty != "point") {
      throw std::invalid_argument("native scene: " + w + ".type: unknown light type '" + ty + "'");
    }
    sc.point_lights.push_back(pl);
  }
  // The skies of sheet +1 and (a wormhole's) sheet -1; Python writes the same table twice for one sky.
  environment_from(table(d, "environment", "scene"), "environment", sc.environment);
  environment_from(table(d, "environment_other", "scene"), "environment_other", sc.environment_other);
  sc.finalize();
}

}  // namespace wv
