// The film: per-pixel accumulation of radiance and of the arbitrary output variables (AOVs) asked for.
//
// Every pixel is written by exactly one thread at a time (work is split by pixel), and samples are added
// in sample order, so the image does not depend on threads or tiles. A film may cover a window (crop) of
// the camera's image: it is indexed by the image's pixel coordinates, and holds only the window's pixels.
#pragma once

#include <algorithm>
#include <cmath>
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
  bool emission = true;  // the light a path collects before its first non-specular hit (kept from the denoiser)
};

struct Film {
  int x0 = 0, y0 = 0;              // the window's first pixel in the camera's image
  int width = 0, height = 0;       // the window's size
  std::vector<double> rgb_sum;     // (H, W, 3)
  std::vector<double> rgb_sq_sum;  // (H, W, 3) squares of the samples' radiance: the variance of the mean
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
  // Every sample: the radiance its path collected up to and at that hit (lights seen directly or through
  // mirrors and glass, the sky): sharp and not noisy, so the denoiser is given the rest.
  std::vector<double> emission_sum;  // (H, W, 3)

  // Every per-pixel array, once: f(name, array, channels, flag) with `flag` the FilmAovs member that
  // keeps it (null: always kept). resize, has_layout and the bindings' film dict all go through this
  // list, so an array added to the film is added here and nowhere else.
  template <class Self, class F>
  static void for_each_array(Self& film, F&& f) {
    f("rgb_sum", film.rgb_sum, 3, nullptr);
    f("rgb_sq_sum", film.rgb_sq_sum, 3, nullptr);
    f("samples", film.samples, 1, nullptr);
    f("errors", film.errors, 1, nullptr);
    f("steps_sum", film.steps_sum, 1, &FilmAovs::n_steps);
    f("max_drift", film.max_drift, 1, &FilmAovs::max_drift);
    f("redshift", film.redshift, 1, &FilmAovs::redshift);
    f("status", film.status, 1, &FilmAovs::status);
    f("depth", film.depth, 1, &FilmAovs::depth);
    f("normal", film.normal, 3, &FilmAovs::normal);
    f("albedo_sum", film.albedo_sum, 3, &FilmAovs::albedo);
    f("albedo_normal_sum", film.albedo_normal_sum, 3, &FilmAovs::albedo_normal);
    f("emission_sum", film.emission_sum, 3, &FilmAovs::emission);
  }

  void resize(int x, int y, int w, int h, const FilmAovs& a) {
    x0 = x;
    y0 = y;
    width = w;
    height = h;
    const size_t n = size_t(w) * size_t(h);
    for_each_array(*this, [&](const char*, auto& v, size_t c, bool FilmAovs::*flag) {
      v.assign(!flag || a.*flag ? c * n : 0, {});  // zeros
    });
  }

  // Whether this film covers window (x, y, w, h) and keeps exactly the AOVs `a` (the layout resize makes):
  // sums of earlier samples that a render may continue.
  bool has_layout(int x, int y, int w, int h, const FilmAovs& a) const {
    const size_t n = size_t(w) * size_t(h);
    bool same = x0 == x && y0 == y && width == w && height == h;
    for_each_array(*this, [&](const char*, const auto& v, size_t c, bool FilmAovs::*flag) {
      same = same && v.size() == (!flag || a.*flag ? c * n : 0);
    });
    return same;
  }

  // Index of image pixel (px, py), which must lie in the window.
  size_t index(int px, int py) const { return size_t(py - y0) * size_t(width) + size_t(px - x0); }
};

// A film's sums and counts, read in place (the film's own vectors, or the numpy arrays of a film that
// crossed into Python between ranges of samples): what resolve() and noise() read.
struct FilmSums {
  size_t n = 0;                     // pixels
  const double* rgb_sum = nullptr;  // (n, 3)
  const double* rgb_sq_sum = nullptr;
  const int32_t* samples = nullptr;  // (n,)
  const int32_t* errors = nullptr;
  const double* steps_sum = nullptr;  // optional (null: not kept)
  const double* albedo_sum = nullptr;
  const double* albedo_normal_sum = nullptr;
  const double* emission_sum = nullptr;
};

inline FilmSums sums_of(const Film& f) {
  auto opt = [](const std::vector<double>& v) { return v.empty() ? nullptr : v.data(); };
  return {size_t(f.width) * size_t(f.height), f.rgb_sum.data(), f.rgb_sq_sum.data(), f.samples.data(),
          f.errors.data(), opt(f.steps_sum), opt(f.albedo_sum), opt(f.albedo_normal_sum), opt(f.emission_sum)};
}

// The variance of pixel i's mean in channel k: (sum of squares - n mean^2) / (n - 1) / n, never below 0
// (rounding); NaN below 2 samples.
inline double mean_variance(const FilmSums& f, size_t i, int k) {
  const double m = double(f.samples[i]);
  if (m < 2) return NAN;
  const double sum = f.rgb_sum[3 * i + k];
  return std::max(0.0, f.rgb_sq_sum[3 * i + k] - sum * sum / m) / ((m - 1) * m);
}

// The relative noise of the image (warpviz/render/passes.py: noise_estimate): the root mean variance of the
// pixel means over their mean radiance, both over the lit pixels (a channel's mean above 0) and channels;
// 0 where no pixel is lit, NaN while a lit pixel has fewer than 2 samples. The samples' variance / n is
// right for independent samples and an upper bound for the stratified pixel positions (Sobol), whose
// mean converges faster where an edge crosses the pixel. (Splitting the samples by index parity instead
// does not work for Sobol points: the even and odd ones lie in opposite halves of the pixel.)
// Its sums over the lit pixels, which add over the tiles of an image (warpviz/render/distributed.py).
struct NoiseParts {
  double var = 0.0, level = 0.0;  // sums over lit pixels and channels of the mean's variance and of the mean
  size_t lit = 0;                 // lit pixels
};

inline NoiseParts noise_parts(const FilmSums& f) {
  NoiseParts p;
  for (size_t i = 0; i < f.n; ++i) {
    const double m = double(f.samples[i]);
    if (m <= 0 || !(f.rgb_sum[3 * i] > 0 || f.rgb_sum[3 * i + 1] > 0 || f.rgb_sum[3 * i + 2] > 0)) continue;
    ++p.lit;
    for (int k = 0; k < 3; ++k) {
      p.var += mean_variance(f, i, k);  // NaN (fewer than 2 samples) makes the estimate NaN
      p.level += f.rgb_sum[3 * i + k] / m;
    }
  }
  return p;
}

inline double noise(const NoiseParts& p) {
  if (p.lit == 0) return 0.0;
  return p.level > 0 ? std::sqrt(p.var / double(3 * p.lit)) / (p.level / double(3 * p.lit)) : INFINITY;
}

inline double noise(const FilmSums& f) { return noise(noise_parts(f)); }

// The film resolved to per-pixel means, float32 as the image and its AOVs are stored: rgb (H, W, 3) mean
// radiance, variance (H, W, 3) the variance of that mean estimated from the pixel's samples (sample
// variance / n; NaN below 2 samples), n_steps (if kept) and errors (H, W) means per sample, samples (H, W)
// counts, albedo, albedo_normal and emission (if kept) (H, W, 3) means per sample; and the totals of samples and of
// samples with errors. The first-hit AOVs and max_drift are per pixel already and stay in the film.
struct ResolvedFilm {
  std::vector<float> rgb, variance, n_steps, errors, samples, albedo, albedo_normal, emission;
  int64_t samples_total = 0, errors_total = 0;
};

inline ResolvedFilm resolve(const FilmSums& f) {
  const size_t n = f.n;
  ResolvedFilm out;
  auto per_sample = [&f](size_t i) { return f.samples[i] > 0 ? 1.0 / f.samples[i] : 0.0; };
  out.rgb.resize(3 * n);
  out.variance.resize(3 * n);
  for (size_t i = 0; i < n; ++i) {
    const double c = per_sample(i);
    for (int k = 0; k < 3; ++k) {
      out.rgb[3 * i + k] = float(f.rgb_sum[3 * i + k] * c);
      out.variance[3 * i + k] = float(mean_variance(f, i, k));
    }
  }
  if (f.steps_sum) {
    out.n_steps.resize(n);
    for (size_t i = 0; i < n; ++i) out.n_steps[i] = float(f.steps_sum[i] * per_sample(i));
  }
  auto mean3 = [&](const double* sum, std::vector<float>& mean) {
    if (!sum) return;
    mean.resize(3 * n);
    for (size_t i = 0; i < n; ++i)
      for (int k = 0; k < 3; ++k) mean[3 * i + k] = float(sum[3 * i + k] * per_sample(i));
  };
  mean3(f.albedo_sum, out.albedo);
  mean3(f.albedo_normal_sum, out.albedo_normal);
  mean3(f.emission_sum, out.emission);
  out.errors.resize(n);
  out.samples.resize(n);
  for (size_t i = 0; i < n; ++i) {
    out.errors[i] = float(f.errors[i] * per_sample(i));
    out.samples[i] = float(f.samples[i]);
    out.errors_total += f.errors[i];
    out.samples_total += f.samples[i];
  }
  return out;
}

}  // namespace wv
