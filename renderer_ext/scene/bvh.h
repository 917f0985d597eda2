// Bounding-volume hierarchy over the scene's primitives (binned SAH build, stack traversal), queried
// with straight segments: whole rays in flat space, chords of integration steps in curved space.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

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
        for (int32_t k = nd.first; k < nd.first + nd.count; ++k) {
          double t;
          // (a small scene's single leaf: each primitive's box first; bvh.cpp, kLinearScene)
          if (nd.count > 2 && !slab(prim_boxes_[order_[k]], o, inv, tmin, tmax)) continue;
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
      if (nd.count > 0) {
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

  std::vector<BvhNode> nodes_;
  std::vector<int32_t> order_;
  std::vector<Box> prim_boxes_;
  Box root_box_;
};

}  // namespace wv
