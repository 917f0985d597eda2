// Pixel reconstruction filters by filter importance sampling: a camera sample's offset from its pixel's
// centre is drawn from the filter (one offset per axis, from the sample's two pixel numbers in [0, 1)),
// and the sample's radiance is weighted by f / p, so the pixel's mean of weighted samples is the
// filter-weighted image, sum f(x - c) L(x) / sum f, without splatting into neighbours: a pixel still
// depends only on its own samples (seed, pixel, sample), for any thread count or tile.
//
// Filters are separable, f(x, y) = f1(x) f1(y), with f1 of support [-r, r] (r: radius in pixels):
//   box       f1 = 1                                       (r = 0.5 is the pixel: the offset is u - 1/2)
//   gaussian  f1 = exp(-x^2 / (2 sigma^2)), sigma = r / 3, truncated at r (r = 1.5: sigma = 0.5 px)
//   mitchell  Mitchell-Netravali with B = C = 1/3 on t = 2 |x| / r in [0, 2] (negative lobes: the
//             weight is negative where f1 is)
// Box and gaussian are sampled exactly (weight 1); mitchell's |f1| from a piecewise-constant table of
// kBins bins whose density p is what is sampled, so the weight f1 / (p F), F = the integral of f1, makes
// the estimate exactly unbiased for the filter itself.
#pragma once

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace wv {

enum PixelFilterKind : int { kBoxFilter = 0, kGaussianFilter = 1, kMitchellFilter = 2 };

class PixelFilter {
 public:
  static constexpr int kBins = 1024;

  PixelFilter() = default;
  PixelFilter(int kind, double radius) : kind_(kind), r_(radius) {
    if (!(radius > 0.0 && std::isfinite(radius))) throw std::invalid_argument("filter_radius must be > 0");
    if (kind == kGaussianFilter) {
      sigma_ = r_ / 3.0;
      const double s = sigma_ * std::sqrt(2.0);
      erf_r_ = std::erf(r_ / s);
    } else if (kind == kMitchellFilter) {
      // Table of |f1| over [-r, r]: each bin's mass from the largest |f1| at its ends and middle, so no bin
      // where f1 is not identically 0 has zero probability.
      cdf_.assign(kBins + 1, 0.0);
      const double dx = 2.0 * r_ / kBins;
      for (int j = 0; j < kBins; ++j) {
        const double a = -r_ + j * dx;
        const double m = std::max({std::fabs(f1(a)), std::fabs(f1(a + 0.5 * dx)), std::fabs(f1(a + dx))});
        cdf_[j + 1] = cdf_[j] + m * dx;
      }
      integral_ = 0.5 * r_;  // the Mitchell-Netravali kernel integrates to 1 over t in [-2, 2]
    } else if (kind != kBoxFilter) {
      throw std::invalid_argument("unknown pixel filter");
    }
  }

  int kind() const { return kind_; }
  double radius() const { return r_; }

  // The filter's 1-D profile at offset x (pixels), unnormalised (f1(0) = 1 for box and gaussian).
  double f1(double x) const {
    const double ax = std::fabs(x);
    if (ax > r_) return 0.0;
    if (kind_ == kBoxFilter) return 1.0;
    if (kind_ == kGaussianFilter) return std::exp(-x * x / (2.0 * sigma_ * sigma_));
    const double t = 2.0 * ax / r_, B = 1.0 / 3.0, C = 1.0 / 3.0;
    if (t < 1.0)
      return ((12.0 - 9.0 * B - 6.0 * C) * t * t * t + (-18.0 + 12.0 * B + 6.0 * C) * t * t + (6.0 - 2.0 * B)) / 6.0;
    return ((-B - 6.0 * C) * t * t * t + (6.0 * B + 30.0 * C) * t * t + (-12.0 * B - 48.0 * C) * t + (8.0 * B + 24.0 * C)) /
           6.0;
  }

  // One axis: the offset from the pixel centre for the number u in [0, 1), and its weight (f1 / (p F)).
  double sample(double u, double& weight) const {
    weight = 1.0;
    if (kind_ == kBoxFilter) return (2.0 * u - 1.0) * r_;
    if (kind_ == kGaussianFilter) return gaussian_inverse(u);
    // mitchell: the bin by bisection of the table, then uniformly inside it
    const double target = u * cdf_[kBins];
    int lo = 0, hi = kBins;
    while (hi - lo > 1) {
      const int mid = (lo + hi) / 2;
      if (cdf_[mid] <= target) lo = mid;
      else hi = mid;
    }
    const double mass = cdf_[lo + 1] - cdf_[lo], dx = 2.0 * r_ / kBins;
    const double frac = mass > 0.0 ? std::min(1.0, std::max(0.0, (target - cdf_[lo]) / mass)) : 0.5;
    const double x = -r_ + (lo + frac) * dx;
    const double p = mass / (cdf_[kBins] * dx);  // the density sampled, on [-r, r]
    weight = f1(x) / (p * integral_);
    return x;
  }

 private:
  // Inverse CDF of the gaussian truncated at +-r: erf(x / (sigma sqrt 2)) = (2u - 1) erf(r / (sigma sqrt 2)),
  // by Newton's method safeguarded by bisection (converged to 1e-14 px).
  double gaussian_inverse(double u) const {
    const double s = sigma_ * std::sqrt(2.0), target = (2.0 * u - 1.0) * erf_r_;
    double lo = -r_, hi = r_, x = 0.0;
    for (int it = 0; it < 100; ++it) {
      const double g = std::erf(x / s) - target;
      if (g > 0.0) hi = x;
      else lo = x;
      const double dg = 2.0 / std::sqrt(M_PI) / s * std::exp(-(x / s) * (x / s));
      double xn = x - g / dg;
      if (!(xn > lo && xn < hi)) xn = 0.5 * (lo + hi);
      if (std::fabs(xn - x) < 1e-14 || hi - lo < 1e-14) return xn;
      x = xn;
    }
    return x;
  }

  int kind_ = kBoxFilter;
  double r_ = 0.5, sigma_ = 0.0, erf_r_ = 1.0, integral_ = 1.0;
  std::vector<double> cdf_;
};

}  // namespace wv
