// Bounding-volume hierarchy over the scene's primitives (binned SAH build, stack traversal), queried
// with straight segments: whole rays in flat space, chords of integration steps in curved space.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "core/simd.h"
#include "scene/shapes.h"

namespace wv {

struct BvhNode {
  Box box;
  int32_t left = -1;   // interior: index of the left child (right = left + 1 is not assumed)
  int32_t right = -1;
  int32_t first = 0;   // leaf: range [first, first + count) of Bvh::order
  int32_t count = 0;
};

struct SegmentHit {
  int prim = -1;
  double t = 0.0;
};

// The single leaf's box tests, four boxes per SIMD operation (soa: the leaf's boxes in blocks of four,
// lo.x[4] lo.y[4] lo.z[4] hi.x[4] hi.y[4] hi.z[4]; bit k of the result: box k passes). Inline, so a metric
// plugin, which instantiates the traversal itself, compiles them too (for its own instruction set); the
// core picks its clone at load (WV_LANE_CLONES). The same IEEE operations as Bvh::slab and overlapping()'s
// scalar test, so the same answers (tests/test_bvh.py).
namespace bvh_simd {

typedef double V4 __attribute__((vector_size(32)));
typedef long long M4 __attribute__((vector_size(32)));

// The bits of block blk's boxes that `fail` (all ones) leaves out, below `count`, without a branch per box (the
// branches mispredicted: a third of the leaf's time).
inline uint64_t block_bits(M4 fail, int32_t blk, int32_t count) {
  const uint64_t failed = uint64_t(fail[0] & 1) | uint64_t(fail[1] & 2) | uint64_t(fail[2] & 4) | uint64_t(fail[3] & 8);
  const int32_t left = count - 4 * blk;
  const uint64_t valid = left >= 4 ? 0xF : (uint64_t(1) << left) - 1;
  return (~failed & valid) << (4 * blk);
}

WV_LANE_CLONES inline uint64_t segment_mask(const double* soa, int32_t count, const double* o, const double* inv,
                                            double tmin, double tmax) {
  uint64_t mask = 0;
  for (int32_t blk = 0; 4 * blk < count; ++blk) {
    const double* s = soa + 24 * blk;
    V4 lo = {tmin, tmin, tmin, tmin}, hi = {tmax, tmax, tmax, tmax};
    for (int a = 0; a < 3; ++a) {
      V4 bl, bh;
      __builtin_memcpy(&bl, s + 4 * a, sizeof bl);
      __builtin_memcpy(&bh, s + 12 + 4 * a, sizeof bh);
      const V4 t0 = (bl - o[a]) * inv[a], t1 = (bh - o[a]) * inv[a];
      const M4 swap = t0 > t1;  // (NaN: no swap, no update, as in Bvh::slab)
      const V4 near = swap ? t1 : t0, far = swap ? t0 : t1;
      lo = near > lo ? near : lo;
      hi = far < hi ? far : hi;
    }
    // tmin only grows and tmax only shrinks over the axes, so one test at the end is slab()'s per-axis exit
    mask |= block_bits(lo > hi * (1.0 + 4e-16) + 1e-300, blk, count);
  }
  return mask;
}

WV_LANE_CLONES inline uint64_t box_mask(const double* soa, int32_t count, const double* blo, const double* bhi) {
  uint64_t mask = 0;
  for (int32_t blk = 0; 4 * blk < count; ++blk) {
    const double* s = soa + 24 * blk;
    M4 apart = {0, 0, 0, 0};
    for (int a = 0; a < 3; ++a) {
      V4 pl, ph;
      __builtin_memcpy(&pl, s + 4 * a, sizeof pl);
      __builtin_memcpy(&ph, s + 12 + 4 * a, sizeof ph);
      apart |= (pl > bhi[a]) | (blo[a] > ph);
    }
    mask |= block_bits(apart, blk, count);
  }
  return mask;
}

}  // namespace bvh_simd

class Bvh {
 public:
  // boxes[i] bounds primitive i.
  void build(const std::vector<Box>& boxes);

  // Closest primitive hit by o + t d with t in (tmin, tmax) that `accept(prim, o, d, tmin, tmax, t)`
  // confirms (the exact intersection test, filtered by sheet etc.).
  template <class Accept>
  bool closest(V3 o, V3 d, double tmin, double tmax, const Accept& accept, SegmentHit& hit) const {
    if (nodes_.empty()) return false;
    const V3 inv{1.0 / d.x, 1.0 / d.y, 1.0 / d.z};
    int32_t stack[64];
    int sp = 0;
    stack[sp++] = 0;
    bool found = false;
    while (sp > 0) {
      const BvhNode& nd = nodes_[stack[--sp]];
      if (!slab(nd.box, o, inv, tmin, tmax)) continue;
      if (nd.count > 0) {
        if (nd.count > 2) {  // a small scene's single leaf (bvh.cpp, kLinearScene): its boxes in SIMD first
          // (a box the segment meets up to the first tmax, in order; accept() then holds each to the
          // current tmax, so the closest hit is the one the one-box-at-a-time scan found)
          for (uint64_t m = leaf_segment_mask(nd.count, o, inv, tmin, tmax); m != 0; m &= m - 1) {
            const int32_t p = order_[nd.first + __builtin_ctzll(m)];
            double t;
            if (accept(p, o, d, tmin, tmax, t)) {
              tmax = t;
              hit.prim = p;
              hit.t = t;
              found = true;
            }
          }
          continue;
        }
        for (int32_t k = nd.first; k < nd.first + nd.count; ++k) {
          double t;
          if (accept(order_[k], o, d, tmin, tmax, t)) {
            tmax = t;
            hit.prim = order_[k];
            hit.t = t;
            found = true;
          }
        }
      } else if (sp + 2 <= 64) {
        stack[sp++] = nd.left;
        stack[sp++] = nd.right;
      }
    }
    return found;
  }

  // Calls visit(prim) for every primitive whose box overlaps box b.
  template <class Visit>
  void overlapping(const Box& b, const Visit& visit) const {
    if (nodes_.empty()) return;
    int32_t stack[64];
    int sp = 0;
    stack[sp++] = 0;
    while (sp > 0) {
      const BvhNode& nd = nodes_[stack[--sp]];
      const Box& a = nd.box;
      if (a.lo.x > b.hi.x || b.lo.x > a.hi.x || a.lo.y > b.hi.y || b.lo.y > a.hi.y || a.lo.z > b.hi.z ||
          b.lo.z > a.hi.z)
        continue;
      if (nd.count > 2) {  // the small scene's single leaf: its boxes in SIMD
        for (uint64_t m = leaf_box_mask(nd.count, b); m != 0; m &= m - 1) visit(order_[nd.first + __builtin_ctzll(m)]);
      } else if (nd.count > 0) {
        for (int32_t k = nd.first; k < nd.first + nd.count; ++k) {
          const Box& pb = prim_boxes_[order_[k]];
          if (pb.lo.x > b.hi.x || b.lo.x > pb.hi.x || pb.lo.y > b.hi.y || b.lo.y > pb.hi.y || pb.lo.z > b.hi.z ||
              b.lo.z > pb.hi.z)
            continue;
          visit(order_[k]);
        }
      } else if (sp + 2 <= 64) {
        stack[sp++] = nd.left;
        stack[sp++] = nd.right;
      }
    }
  }

  const Box& bounds() const { return root_box_; }
  bool empty() const { return nodes_.empty(); }

 private:
  static bool slab(const Box& b, V3 o, V3 inv, double tmin, double tmax) {
    for (int a = 0; a < 3; ++a) {
      double t0 = (b.lo[a] - o[a]) * inv[a], t1 = (b.hi[a] - o[a]) * inv[a];
      if (t0 > t1) std::swap(t0, t1);
      // NaN from 0 * inf (origin on a slab plane, axis-parallel ray) must not cull
      if (t0 > tmin) tmin = t0;
      if (t1 < tmax) tmax = t1;
      if (tmin > tmax * (1.0 + 4e-16) + 1e-300) return false;
    }
    return true;
  }
  int32_t build_node(const std::vector<Box>& boxes, std::vector<V3>& centroids, int32_t first, int32_t count);
  // The single leaf of a small scene (the root, a leaf of `count` > 2 primitives, at most bvh.cpp's
  // kLinearScene): bit k set where the box of order_[k] passes slab() for the segment / overlaps box b.
  uint64_t leaf_segment_mask(int32_t count, V3 o, V3 inv, double tmin, double tmax) const {
    const double oo[3] = {o.x, o.y, o.z}, ii[3] = {inv.x, inv.y, inv.z};
    return bvh_simd::segment_mask(leaf_soa_.data(), count, oo, ii, tmin, tmax);
  }
  uint64_t leaf_box_mask(int32_t count, const Box& b) const {
    const double lo[3] = {b.lo.x, b.lo.y, b.lo.z}, hi[3] = {b.hi.x, b.hi.y, b.hi.z};
    return bvh_simd::box_mask(leaf_soa_.data(), count, lo, hi);
  }

  std::vector<BvhNode> nodes_;
  std::vector<int32_t> order_;
  std::vector<Box> prim_boxes_;
  // The single leaf's boxes in blocks of four: lo.x[4] lo.y[4] lo.z[4] hi.x[4] hi.y[4] hi.z[4] per block.
  std::vector<double> leaf_soa_;
  Box root_box_;
};

}  // namespace wv
