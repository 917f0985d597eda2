// The photons of one photon pass (photon_tracer.h) and the search for those near a camera path's gather point:
// a balanced kd-tree over their user-frame positions, built deterministically (the same photons give the
// same tree and the same sums, in the same order), and the radius schedule of the passes.
//
// Caustics by progressive photon mapping in its probabilistic form (Knaus and Zwicker 2011): every pass
// is an independent estimate of the caustic light with its own photons and its own radius r_j, the radii
// shrinking as r_j^2 = r_0^2 prod_{i<j} (i + alpha) / (i + 1), so the mean of the passes converges (the bias
// falls as r_j^2, the variance of a pass grows as 1 / r_j^2: alpha = 2/3 balances them). Passes are kept
// independent so that a pass is a function of (seed, pass) alone: any split of a render into ranges, tiles
// or workers gives the same image.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <numeric>
#include <vector>

#include "core/vec3.h"

namespace wv {

// A photon where it was stored: the first diffuse surface after at least one specular vertex.
struct Photon {
  V3 pos;        // user frame
  V3 n_in;       // the surface's user-frame unit normal on the side the photon arrived from
  V3 power;      // flux (already over the photons of its pass), times the shift its frequency took, g^-2
  int sheet = 0;
  int segments = 0;  // geodesic segments from the light to here
};

// The factor r_j^2 / r_0^2 of photon pass j (Knaus and Zwicker's schedule with alpha = 2/3).
inline double photon_radius_factor(int64_t j) {
  constexpr double kAlpha = 2.0 / 3.0;
  double c = 1.0;
  for (int64_t i = 1; i <= j; ++i) c *= (double(i) - 1.0 + kAlpha) / double(i);
  return c;
}

class PhotonMap {
 public:
  PhotonMap() = default;
  // Takes the photons and builds the tree over them (median splits along the widest axis of each node).
  explicit PhotonMap(std::vector<Photon> photons) : photons_(std::move(photons)) {
    nodes_.resize(photons_.size());
    std::vector<uint32_t> idx(photons_.size());
    std::iota(idx.begin(), idx.end(), 0u);
    if (!idx.empty()) build(idx, 0, idx.size());
    // Reorder the photons into the tree's order (node k holds photon k).
    std::vector<Photon> ordered(photons_.size());
    for (size_t k = 0; k < idx.size(); ++k) ordered[k] = photons_[idx[k]];
    photons_.swap(ordered);
  }

  size_t size() const { return photons_.size(); }
  const std::vector<Photon>& photons() const { return photons_; }

  // A gather whose disk widens to hold k photons, in one traversal: r = max(r_min, reach) * scale (scale <= 1),
  // reach the distance from x to the k-th nearest photon on `sheet` that `ok(photon)` accepts (k <=
  // kMaxNeighbours; r_max where fewer than k lie within r_max), and the sum of the powers of the accepted photons
  // within r, added in for_each_near's order: the same sum to the bit as finding reach first and then calling
  // for_each_near with r. Where reach <= r_min the sum is the one of the photons within r_min * scale,
  // gathered on the way; else the photons within r are among the k nearest, kept with the order they were met in.
  static constexpr int kMaxNeighbours = 64;
  template <class Ok>
  V3 flux_near(V3 x, int sheet, int k, double r_min, double r_max, double scale, Ok&& ok, double& r) const {
    Near heap[kMaxNeighbours];  // the k nearest so far, a max-heap in distance once full
    int n = 0;
    k = std::clamp(k, 1, kMaxNeighbours);
    double worst = r_max * r_max;
    const double r_near = r_min * scale, near2 = r_near * r_near;
    V3 flux{0, 0, 0};
    uint32_t met = 0;
    if (!photons_.empty()) nearest(0, photons_.size(), x, sheet, k, ok, heap, n, worst, near2, flux, met);
    const double reach = n < k ? r_max : std::sqrt(heap[0].d2);
    r = std::max(r_min, reach) * scale;
    if (!(reach > r_min)) return flux;  // (r = r_near)
    std::sort(heap, heap + n, [](const Near& a, const Near& b) { return a.met < b.met; });
    const double r2 = r * r;
    flux = {0, 0, 0};
    for (int i = 0; i < n; ++i)
      if (heap[i].d2 <= r2) flux += photons_[heap[i].index].power;
    return flux;
  }

  // Calls f(photon) for every photon on `sheet` within distance r of x (user frame), in the tree's order.
  template <class F>
  void for_each_near(V3 x, int sheet, double r, F&& f) const {
    if (photons_.empty()) return;
    search(0, photons_.size(), x, sheet, r * r, f);
  }

 private:
  // Node k of a range [lo, hi) is its median m = (lo + hi) / 2; its axis is nodes_[m].
  void build(std::vector<uint32_t>& idx, size_t lo, size_t hi) {
    if (hi <= lo) return;
    V3 a = photons_[idx[lo]].pos, b = a;
    for (size_t k = lo; k < hi; ++k) {
      const V3 p = photons_[idx[k]].pos;
      a = {std::min(a.x, p.x), std::min(a.y, p.y), std::min(a.z, p.z)};
      b = {std::max(b.x, p.x), std::max(b.y, p.y), std::max(b.z, p.z)};
    }
    const V3 ext = b - a;
    const int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : ext.y >= ext.z ? 1 : 2;
    const size_t m = (lo + hi) / 2;
    // (Ties broken by index: the same photons give the same tree with any standard library.)
    std::nth_element(idx.begin() + lo, idx.begin() + m, idx.begin() + hi, [&](uint32_t i, uint32_t j) {
      const double pi = photons_[i].pos[axis], pj = photons_[j].pos[axis];
      return pi < pj || (pi == pj && i < j);
    });
    nodes_[m] = int8_t(axis);
    build(idx, lo, m);
    build(idx, m + 1, hi);
  }

  struct Near {
    double d2;
    uint32_t met, index;  // the order the traversal met it in; the photon
  };
  // flux_near's traversal: the k nearest accepted photons within sqrt(worst) into heap (n of them), and the
  // powers of those within sqrt(near2) into flux, in search's order (the same node order; a side is skipped
  // only where neither reaches it).
  template <class Ok>
  void nearest(size_t lo, size_t hi, V3 x, int sheet, int k, Ok& ok, Near* heap, int& n, double& worst, double near2,
               V3& flux, uint32_t& met) const {
    auto farther = [](const Near& a, const Near& b) { return a.d2 < b.d2; };
    while (hi > lo) {
      const size_t m = (lo + hi) / 2;
      const Photon& p = photons_[m];
      const V3 d = p.pos - x;
      const double d2 = dot(d, d);
      if ((d2 < worst || d2 <= near2) && p.sheet == sheet && ok(p)) {
        if (d2 <= near2) flux += p.power;
        const Near e{d2, met++, uint32_t(m)};
        if (d2 < worst) {
          if (n < k) {
            heap[n++] = e;
            std::push_heap(heap, heap + n, farther);
            if (n == k) worst = std::min(worst, heap[0].d2);
          } else {
            std::pop_heap(heap, heap + n, farther);
            heap[n - 1] = e;
            std::push_heap(heap, heap + n, farther);
            worst = heap[0].d2;
          }
        }
      }
      const int axis = nodes_[m];
      const double delta = x[axis] - p.pos[axis], delta2 = delta * delta;
      if (delta <= 0.0) {
        nearest(lo, m, x, sheet, k, ok, heap, n, worst, near2, flux, met);
        if (delta2 >= worst && delta2 > near2) return;
        lo = m + 1;
      } else {
        nearest(m + 1, hi, x, sheet, k, ok, heap, n, worst, near2, flux, met);
        if (delta2 >= worst && delta2 > near2) return;
        hi = m;
      }
    }
  }

  template <class F>
  void search(size_t lo, size_t hi, V3 x, int sheet, double r2, F& f) const {
    while (hi > lo) {
      const size_t m = (lo + hi) / 2;
      const Photon& p = photons_[m];
      const V3 d = p.pos - x;
      if (p.sheet == sheet && dot(d, d) <= r2) f(p);
      const int axis = nodes_[m];
      const double delta = x[axis] - p.pos[axis];
      // The near side first (by recursion), then the far one if the sphere reaches it (by the loop).
      if (delta <= 0.0) {
        search(lo, m, x, sheet, r2, f);
        if (delta * delta > r2) return;
        lo = m + 1;
      } else {
        search(m + 1, hi, x, sheet, r2, f);
        if (delta * delta > r2) return;
        hi = m;
      }
    }
  }

  std::vector<Photon> photons_;
  std::vector<int8_t> nodes_;  // the split axis of each node
};

// The photon pass the camera samples of a render loop's sub-pass gather from: its map and r_j^2 / r_0^2.
struct PhotonPass {
  PhotonMap map;
  double r2_factor = 1.0;
};

}  // namespace wv
