// The film: per-pixel accumulation of radiance and of the arbitrary output variables (AOVs) asked for.
//
// Every pixel is written by exactly one thread at a time (work is split by pixel), and samples are added
// in sample order, so the image does not depend on threads or tiles. A film may cover a window (crop) of
// the camera's image: it is indexed by the image's pixel coordinates, and holds only the window's pixels.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace wv {

// The AOVs a film keeps beside radiance, samples and errors (which it always keeps). Each one that is not
// asked for costs no memory and no work.
struct FilmAovs {
  bool n_steps = true, max_drift = true, redshift = true, status = true, depth = true, normal = true;
  bool albedo = true, albedo_normal = true;  // the denoiser's features, at the first non-specular hit
};

struct Film {
  int x0 = 0, y0 = 0;              // the window's first pixel in the camera's image
  int width = 0, height = 0;       // the window's size
  std::vector<double> rgb_sum;     // (H, W, 3)
  std::vector<int32_t> samples;    // (H, W) samples accumulated
  std::vector<int32_t> errors;     // (H, W) samples whose path had an erroneous geodesic
  // Optional (empty unless asked for):
  std::vector<double> steps_sum;   // (H, W) integration steps of all geodesics of the pixel's paths
  std::vector<float> max_drift;    // (H, W) largest relative drift of any conserved quantity
  // First camera ray of sample 0 (no blending across edges):
  std::vector<float> redshift;     // (H, W) g = nu_camera / nu_emitted at the first hit or the sky; 0: horizon
  std::vector<float> status;       // (H, W) RayStatus of the camera geodesic
  std::vector<float> depth;        // (H, W) user-frame distance camera -> first hit (inf: none)
  std::vector<float> normal;       // (H, W, 3) user-frame geometric normal at the first hit
  // Every sample, at its path's first non-specular hit (through mirrors and glass; zero where the path
  // meets none): the features a denoiser is fed with.
  std::vector<double> albedo_sum;         // (H, W, 3) albedo in [0, 1] (an emitter: its colour)
  std::vector<double> albedo_normal_sum;  // (H, W, 3) user-frame normal there

  void resize(int x, int y, int w, int h, const FilmAovs& a) {
    x0 = x;
    y0 = y;
    width = w;
    height = h;
    const size_t n = size_t(w) * size_t(h);
    rgb_sum.assign(3 * n, 0.0);
    samples.assign(n, 0);
    errors.assign(n, 0);
    steps_sum.assign(a.n_steps ? n : 0, 0.0);
    max_drift.assign(a.max_drift ? n : 0, 0.0f);
    redshift.assign(a.redshift ? n : 0, 0.0f);
    status.assign(a.status ? n : 0, 0.0f);
    depth.assign(a.depth ? n : 0, 0.0f);
    normal.assign(a.normal ? 3 * n : 0, 0.0f);
    albedo_sum.assign(a.albedo ? 3 * n : 0, 0.0);
    albedo_normal_sum.assign(a.albedo_normal ? 3 * n : 0, 0.0);
  }

  // Index of image pixel (px, py), which must lie in the window.
  size_t index(int px, int py) const { return size_t(py - y0) * size_t(width) + size_t(px - x0); }
};

// The film resolved to per-pixel means, float32 as the image and its AOVs are stored: rgb (H, W, 3) mean
// radiance, n_steps (if kept) and errors (H, W) means per sample, samples (H, W) counts, albedo and
// albedo_normal (if kept) (H, W, 3) means per sample; and the window's totals of samples and of samples
// with errors.
struct ResolvedFilm {
  std::vector<float> rgb, n_steps, errors, samples, albedo, albedo_normal;
  int64_t samples_total = 0, errors_total = 0;
};

// Resolves the film, releasing each of its sums as soon as it is converted (so a large image needs the
// film plus one float32 copy of the radiance at most). The first-hit AOVs are already per pixel and stay
// in the film.
inline ResolvedFilm resolve(Film& f) {
  const size_t n = size_t(f.width) * size_t(f.height);
  ResolvedFilm out;
  out.rgb.resize(3 * n);
  auto per_sample = [&f](size_t i) { return f.samples[i] > 0 ? 1.0 / f.samples[i] : 0.0; };
  for (size_t i = 0; i < n; ++i) {
    const double c = per_sample(i);
    for (int k = 0; k < 3; ++k) out.rgb[3 * i + k] = float(f.rgb_sum[3 * i + k] * c);
  }
  std::vector<double>().swap(f.rgb_sum);
  if (!f.steps_sum.empty()) {
    out.n_steps.resize(n);
    for (size_t i = 0; i < n; ++i) out.n_steps[i] = float(f.steps_sum[i] * per_sample(i));
    std::vector<double>().swap(f.steps_sum);
  }
  auto mean3 = [&](std::vector<double>& sum, std::vector<float>& mean) {
    if (sum.empty()) return;
    mean.resize(3 * n);
    for (size_t i = 0; i < n; ++i)
      for (int k = 0; k < 3; ++k) mean[3 * i + k] = float(sum[3 * i + k] * per_sample(i));
    std::vector<double>().swap(sum);
  };
  mean3(f.albedo_sum, out.albedo);
  mean3(f.albedo_normal_sum, out.albedo_normal);
  out.errors.resize(n);
  for (size_t i = 0; i < n; ++i) {
    out.errors[i] = float(f.errors[i] * per_sample(i));
    out.errors_total += f.errors[i];
    out.samples_total += f.samples[i];
  }
  std::vector<int32_t>().swap(f.errors);
  out.samples.resize(n);
  for (size_t i = 0; i < n; ++i) out.samples[i] = float(f.samples[i]);
  std::vector<int32_t>().swap(f.samples);
  return out;
}

}  // namespace wv
