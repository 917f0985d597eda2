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

}  // namespace wv
