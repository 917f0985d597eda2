// Materials and their BSDFs, evaluated in the local orthonormal frame of the static observer (or ZAMO)
// at the hit point, where the surface is at rest and flat-space optics hold.
//
// Conventions: n is the unit geometric normal, wo the unit direction back towards the previous vertex
// (towards the camera), wi the sampled unit direction of the next ray. `f` returns BSDF * |cos(wi, n)|.
#pragma once

#include <cmath>

#include "core/rng.h"
#include "core/vec3.h"
#include "scene/texture.h"

namespace wv {

enum class MaterialKind { kDiffuse, kMirror, kGlass, kEmissive };

// The fields of its kind are set from the native scene dict (bindings/scene_dict.cpp); the defaults of
// the optional ones live in Python (warpviz/scene/native.py), not here.
struct Material {
  MaterialKind kind = MaterialKind::kDiffuse;
  int texture = -1;      // diffuse albedo / emitted colour (-1: none)
  V3 tint{0, 0, 0};      // mirror reflectance, glass transmittance
  double ior = 0.0;
  double strength = 0.0;  // emission scale
  bool two_sided = false;
  bool beaming = false;    // emission scaled by g^4 (Doppler + gravitational shift of the emitter)
  bool keplerian = false;  // the emitter orbits prograde about +z (accretion disk) instead of being static
  bool colour_shift = false;  // with beaming: shift the colour too (RGB read as a coarse spectrum)
  V3 emission{0, 0, 0};  // diffuse, mirror, glass: radiance emitted too (one-sided, along the normal)
  // Emits light: emissive, or a reflecting material with emission (a light that also reflects like its BSDF).
  bool emits() const { return kind == MaterialKind::kEmissive || max_component(emission) > 0.0; }
  // How bright it emits, up to its texture: the strength of an emissive one, else emission's largest channel.
  double emission_scale() const { return kind == MaterialKind::kEmissive ? strength : max_component(emission); }
  bool is_delta() const { return kind == MaterialKind::kMirror || kind == MaterialKind::kGlass; }
};

struct BsdfSample {
  V3 wi;
  V3 weight;         // f |cos| / pdf
  double pdf = 0.0;  // solid-angle pdf (0 for delta lobes)
  bool delta = false;
  bool valid = false;
};

inline V3 reflect(V3 wo, V3 n) { return n * (2.0 * dot(wo, n)) - wo; }

// Unpolarised Fresnel reflectance of a dielectric; cos_i > 0 on the incident side, eta = n_t / n_i.
inline double fresnel_dielectric(double cos_i, double eta, double& cos_t) {
  const double sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
  if (sin2_t >= 1.0) {
    cos_t = 0.0;
    return 1.0;  // total internal reflection
  }
  cos_t = std::sqrt(1.0 - sin2_t);
  const double rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  const double rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  return 0.5 * (rs * rs + rp * rp);
}

// Cosine-weighted direction about unit n.
inline V3 cosine_direction(V3 n, double u1, double u2) {
  V3 t, b;
  basis_around(n, t, b);
  const double r = std::sqrt(u1), phi = 6.283185307179586 * u2;
  const double z = std::sqrt(std::max(0.0, 1.0 - u1));
  return t * (r * std::cos(phi)) + b * (r * std::sin(phi)) + n * z;
}

// BSDF * |cos| and solid-angle pdf of sampling wi (non-delta materials only).
inline V3 bsdf_eval(const Material& m, V3 albedo, V3 n, V3 wo, V3 wi, double& pdf) {
  pdf = 0.0;
  if (m.kind != MaterialKind::kDiffuse) return {0, 0, 0};
  const double co = dot(wo, n), ci = dot(wi, n);
  if (co * ci <= 0.0) return {0, 0, 0};  // two-sided Lambert: same side as wo only
  pdf = std::fabs(ci) / M_PI;
  return albedo * (std::fabs(ci) / M_PI);
}

inline BsdfSample bsdf_sample(const Material& m, V3 albedo, V3 n, V3 wo, double u1, double u2, double u3) {
  BsdfSample s;
  const double co = dot(wo, n);
  switch (m.kind) {
    case MaterialKind::kDiffuse: {
      const V3 ns = co >= 0.0 ? n : -n;
      s.wi = cosine_direction(ns, u1, u2);
      const double ci = dot(s.wi, ns);
      if (ci <= 0.0) return s;
      s.pdf = ci / M_PI;
      s.weight = albedo;  // (albedo / pi) cos / (cos / pi)
      s.valid = true;
      return s;
    }
    case MaterialKind::kMirror:
      s.wi = reflect(wo, n);
      s.weight = m.tint;
      s.delta = s.valid = true;
      return s;
    case MaterialKind::kGlass: {
      const bool entering = co > 0.0;
      const double eta = entering ? m.ior : 1.0 / m.ior;
      const V3 ns = entering ? n : -n;
      const double cos_i = std::fabs(co);
      double cos_t;
      const double F = fresnel_dielectric(cos_i, eta, cos_t);
      s.delta = s.valid = true;
      if (u3 < F) {
        s.wi = reflect(wo, ns);
        s.weight = {1, 1, 1};
      } else {
        s.wi = normalize(-wo / eta + ns * (cos_i / eta - cos_t));
        s.weight = m.tint;
      }
      return s;
    }
    case MaterialKind::kEmissive: return s;  // emitters absorb
  }
  return s;
}

}  // namespace wv
