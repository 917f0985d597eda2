#include "scene/bvh.h"

#include <algorithm>

namespace wv {

// A scene of at most this many primitives is one leaf, scanned in order with a box test per primitive: in
// a room (tens of quads) that costs fewer instructions than descending a tree whose boxes all span the
// room (callgrind: fig07 -4.6 % for the whole render, the Mitsuba box -1.6 %).
constexpr int32_t kLinearScene = 32;
static_assert(kLinearScene <= 64, "the single leaf's SIMD masks are 64 bits");

void Bvh::build(const std::vector<Box>& boxes) {
  nodes_.clear();
  prim_boxes_ = boxes;
  order_.resize(boxes.size());
  root_box_ = Box();
  if (boxes.empty()) return;
  std::vector<V3> centroids(boxes.size());
  for (size_t i = 0; i < boxes.size(); ++i) {
    order_[i] = int32_t(i);
    centroids[i] = boxes[i].centroid();
    root_box_.extend(boxes[i]);
  }
  nodes_.reserve(2 * boxes.size());
  build_node(boxes, centroids, 0, int32_t(boxes.size()));
  leaf_soa_.clear();
  const int32_t leaf = nodes_[0].count;
  if (leaf > 2) {  // the single leaf of a small scene: its boxes in blocks of four, in order_
    const Box empty;
    leaf_soa_.assign(size_t(24) * ((leaf + 3) / 4), 0.0);
    for (int32_t k = 0; k < 4 * ((leaf + 3) / 4); ++k) {
      const Box& b = k < leaf ? boxes[order_[k]] : empty;
      double* s = leaf_soa_.data() + 24 * (k / 4) + k % 4;
      for (int a = 0; a < 3; ++a) {
        s[4 * a] = b.lo[a];
        s[12 + 4 * a] = b.hi[a];
      }
    }
  }
}

int32_t Bvh::build_node(const std::vector<Box>& boxes, std::vector<V3>& centroids, int32_t first, int32_t count) {
  const int32_t idx = int32_t(nodes_.size());
  nodes_.emplace_back();
  Box box, cbox;
  for (int32_t k = first; k < first + count; ++k) {
    box.extend(boxes[order_[k]]);
    cbox.extend(centroids[order_[k]]);
  }
  nodes_[idx].box = box;
  if (count <= 2 || (first == 0 && count == int32_t(boxes.size()) && count <= kLinearScene)) {
    nodes_[idx].first = first;
    nodes_[idx].count = count;
    return idx;
  }
  // Binned surface-area heuristic over the widest centroid axis.
  constexpr int kBins = 12;
  const V3 ext = cbox.hi - cbox.lo;
  const int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
  int32_t mid = first + count / 2;
  if (ext[axis] > 0.0) {
    Box bin_box[kBins];
    int bin_count[kBins] = {0};
    auto bin_of = [&](int32_t p) {
      const int b = int(kBins * (centroids[p][axis] - cbox.lo[axis]) / ext[axis]);
      return std::min(kBins - 1, std::max(0, b));
    };
    for (int32_t k = first; k < first + count; ++k) {
      const int b = bin_of(order_[k]);
      bin_box[b].extend(boxes[order_[k]]);
      ++bin_count[b];
    }
    double best = 1e300;
    int best_split = -1;
    for (int s = 1; s < kBins; ++s) {
      Box lb, rb;
      int lc = 0, rc = 0;
      for (int b = 0; b < s; ++b) { if (bin_count[b]) lb.extend(bin_box[b]); lc += bin_count[b]; }
      for (int b = s; b < kBins; ++b) { if (bin_count[b]) rb.extend(bin_box[b]); rc += bin_count[b]; }
      if (lc == 0 || rc == 0) continue;
      const double cost = lb.area() * lc + rb.area() * rc;
      if (cost < best) { best = cost; best_split = s; }
    }
    if (best_split > 0) {
      auto it = std::partition(order_.begin() + first, order_.begin() + first + count,
                               [&](int32_t p) { return bin_of(p) < best_split; });
      mid = int32_t(it - order_.begin());
    } else {
      std::nth_element(order_.begin() + first, order_.begin() + mid, order_.begin() + first + count,
                       [&](int32_t a, int32_t b) { return centroids[a][axis] < centroids[b][axis]; });
    }
  }
  if (mid == first || mid == first + count) mid = first + count / 2;
  const int32_t l = build_node(boxes, centroids, first, mid - first);
  const int32_t r = build_node(boxes, centroids, mid, first + count - mid);
  nodes_[idx].left = l;
  nodes_[idx].right = r;
  return idx;
}

}  // namespace wv
