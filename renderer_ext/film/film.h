// The film: per-pixel accumulation of radiance and the arbitrary output variables (AOVs).
//
// Every pixel is written by exactly one thread at a time (work is split by pixel), and samples are added
// in sample order, so the image does not depend on threads or tiles.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace wv {

struct Film {
  int width = 0, height = 0;
  std::vector<double> rgb_sum;     // (H, W, 3)
  std::vector<int32_t> samples;    // (H, W) samples accumulated
  std::vector<double> steps_sum;   // (H, W) integration steps of all geodesics of the pixel's paths
  std::vector<float> max_drift;    // (H, W) largest relative drift of any conserved quantity
  std::vector<int32_t> errors;     // (H, W) samples whose path had an erroneous geodesic
  // First camera ray of sample 0 (no blending across edges):
  std::vector<float> redshift;     // (H, W) g = nu_camera / nu_emitted at the first hit or the sky; 0: horizon
  std::vector<float> status;       // (H, W) RayStatus of the camera geodesic
  std::vector<float> depth;        // (H, W) user-frame distance camera -> first hit (inf: none)
  std::vector<float> normal;       // (H, W, 3) user-frame geometric normal at the first hit

  void resize(int w, int h) {
    width = w;
    height = h;
    const size_t n = size_t(w) * size_t(h);
    rgb_sum.assign(3 * n, 0.0);
    samples.assign(n, 0);
    steps_sum.assign(n, 0.0);
    max_drift.assign(n, 0.0f);
    errors.assign(n, 0);
    redshift.assign(n, 0.0f);
    status.assign(n, 0.0f);
    depth.assign(n, 0.0f);
    normal.assign(3 * n, 0.0f);
  }
};

// The film resolved to per-pixel means, float32 as the image and its AOVs are stored: rgb (H, W, 3) mean
// radiance, n_steps and errors (H, W) means per sample, samples (H, W) counts. The first-hit AOVs of the
// film are already per pixel and are used as they are.
struct ResolvedFilm {
  std::vector<float> rgb, n_steps, errors, samples;
};

inline ResolvedFilm resolve(const Film& f) {
  const size_t n = size_t(f.width) * size_t(f.height);
  ResolvedFilm out;
  out.rgb.resize(3 * n);
  out.n_steps.resize(n);
  out.errors.resize(n);
  out.samples.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const double c = f.samples[i] > 0 ? 1.0 / f.samples[i] : 0.0;
    for (int k = 0; k < 3; ++k) out.rgb[3 * i + k] = float(f.rgb_sum[3 * i + k] * c);
    out.n_steps[i] = float(f.steps_sum[i] * c);
    out.errors[i] = float(f.errors[i] * c);
    out.samples[i] = float(f.samples[i]);
  }
  return out;
}

}  // namespace wv
