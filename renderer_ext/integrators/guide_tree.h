// Path guiding's learned distribution of incident light, in the spirit of Mueller, Gross and Novak, "Practical
// Path Guiding" (2017): a binary tree over space, one per sheet and orientation of the surface (a floor and
// the wall beside it see different halves of the sky), whose leaves each hold a quadtree over the local
// observer's sky, built from training records (where a path's vertex was, which way its next segment
// left in the local frame, how much light came back along it). The directions are the local observer's, so
// the distribution holds every lensed image of every light and bright surface, whatever the metric.
//
// The sky maps onto the unit square by the equal-area cylindrical map, s = (1 + cos theta) / 2 (theta from
// the local z axis), t = phi / 2 pi, so dOmega = 4 pi ds dt; a quadtree cell's density on the square is its
// share of its leaf's energy over its area. A quadrant is divided where it holds more than `rho` of its
// leaf's energy (and at least two records), so bright, narrow images get small cells. A space node is divided
// at the middle of its box's longest side while it holds more than `leaf_records` records.
//
// A tree is built once from one training iteration's records, in their given order (the same records give
// the same tree, bit for bit, however many threads traced them) and does not change while it is sampled.
// Where a leaf saw no light arrive (or no record fell in it) its sky has nothing to say (has_sky() false).
//
// Each leaf also learns how often to choose each light (light_select): the light samples' records (what each
// brought over the probability of choosing its light) give each light's share of the leaf's direct light,
// mixed with an even choice, so a sun on the other sheet of a wormhole that seldom reaches a room is seldom
// chosen there (issue 34).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "core/vec3.h"
#include "scene/shapes.h"

namespace wv {

// One training record: a vertex's user-frame position, sheet and surface normal, the local direction its path
// left along, and what came back: radiance times the cosine at the surface over the pdf that drew the
// direction (an estimate of that product's integral over any cell holding it, >= 0).
struct GuideRecord {
  V3 pos;
  int sheet = 1;
  V3 normal;  // the surface's unit normal (user frame)
  V3 dir;
  double value = 0.0;
  // A light sample's record instead (light >= 0: its index in the scene's light list; dir and value unused):
  // what it brought, MIS-weighted, over the probability of choosing that light (an estimate of the light's
  // share of the vertex's direct light, >= 0).
  int light = -1;
  double light_value = 0.0;
};

// Unit direction (local frame) <-> point of the unit square, equal-area.
inline void sky_to_square(V3 w, double& s, double& t) {
  s = std::clamp(0.5 * (1.0 + w.z), 0.0, 1.0);
  double phi = std::atan2(w.y, w.x) * (0.5 / M_PI);
  if (phi < 0.0) phi += 1.0;
  t = std::min(phi, std::nextafter(1.0, 0.0));
}
inline V3 square_to_sky(double s, double t) {
  const double z = 2.0 * s - 1.0, r = std::sqrt(std::max(0.0, 1.0 - z * z)), phi = 2.0 * M_PI * t;
  return {r * std::cos(phi), r * std::sin(phi), z};
}

class GuideTree {
 public:
  struct Params {
    int leaf_records = 4000;  // a space node with more records is divided
    double rho = 0.01;        // a quadrant with more of its leaf's energy is divided
    int max_depth = 12;       // quadtree levels below the root (cells down to 4^-12 of the sky)
    int lights = 0;           // the scene's lights: each leaf learns how often to choose each one
  };
  // The share of a leaf's light choices spread evenly over the lights, whatever it learnt: a light the
  // training never saw reach a part of space is still chosen there, kEvenLights / (number of lights) of
  // the time.
  static constexpr double kEvenLights = 0.2;

  GuideTree() = default;

  // Builds the tree from `records` (reordered in the process) over box `bounds` (positions outside it fall in
  // its border leaves).
  void build(std::vector<GuideRecord> records, const Box& bounds, const Params& p) {
    *this = GuideTree();
    params_ = p;
    nlights_ = std::max(0, p.lights);
    for (int k = 0; k < kRoots; ++k) {
      auto mid = std::stable_partition(records.begin(), records.end(),
                                       [k](const GuideRecord& r) { return root_index(r.sheet, r.normal) == k; });
      std::vector<GuideRecord> mine(records.begin(), mid);
      records.erase(records.begin(), mid);
      root_[k] = mine.empty() ? -1 : build_space(mine, 0, mine.size(), bounds, 0);
    }
  }

  // The tree as flat arrays (a render's first range trains it; the later ranges, tiles and resumed ranges of
  // the same render are handed it back, bindings/module.cpp): per space node axis, children and leaf
  // (space_index, 4 each) and split; per quadtree node its four sums and children; per leaf its quadtree's
  // root; the two sheets' roots.
  struct Arrays {
    std::vector<int32_t> space_index;  // (N, 4): axis, child 0, child 1, leaf
    std::vector<double> space_split;   // (N,)
    std::vector<double> sky_sum;       // (Q, 4)
    std::vector<int32_t> sky_child;    // (Q, 4)
    std::vector<int32_t> leaf_root;    // (L,)
    std::vector<int32_t> roots;        // (12,)
    std::vector<double> leaf_lights;   // (L, lights): each leaf's light choice, -1 in a row where none
  };
  Arrays arrays() const {
    Arrays a;
    for (const SNode& n : snodes_) {
      a.space_index.insert(a.space_index.end(), {n.axis, n.child[0], n.child[1], n.leaf});
      a.space_split.push_back(n.split);
    }
    for (const QNode& q : qnodes_) {
      a.sky_sum.insert(a.sky_sum.end(), q.sum, q.sum + 4);
      a.sky_child.insert(a.sky_child.end(), q.child, q.child + 4);
    }
    for (const Leaf& l : leaves_) a.leaf_root.push_back(l.root);
    a.roots.assign(root_, root_ + kRoots);
    a.leaf_lights = leaf_lights_;
    return a;
  }
  // The tree from arrays(): an empty string, or what is wrong with them (nothing is kept then). Every index
  // must point forward (children after their parent, as build() lays them out), so no walk can loop or leave
  // the arrays, and every sum must be finite and >= 0 with energy wherever a walk can go.
  std::string load(const Arrays& a) {
    *this = GuideTree();
    const size_t ns = a.space_split.size(), nq = a.sky_sum.size() / 4, nl = a.leaf_root.size();
    if (a.space_index.size() != 4 * ns || a.sky_sum.size() != 4 * nq || a.sky_child.size() != 4 * nq ||
        a.roots.size() != size_t(kRoots))
      return "space_index must be (N, 4) with space_split (N,), sky_sum and sky_child (Q, 4), roots (12,)";
    std::vector<SNode> sn(ns);
    std::vector<char> leaf_used(nl, 0);
    for (size_t i = 0; i < ns; ++i) {
      const int32_t* x = a.space_index.data() + 4 * i;
      SNode& n = sn[i];
      n.axis = x[0];
      n.child[0] = x[1];
      n.child[1] = x[2];
      n.leaf = x[3];
      n.split = a.space_split[i];
      if (n.leaf >= 0) {
        if (size_t(n.leaf) >= nl || leaf_used[size_t(n.leaf)])
          return "a space leaf's index is out of range or repeated";
        leaf_used[size_t(n.leaf)] = 1;
      } else if (n.axis < 0 || n.axis > 2 || !std::isfinite(n.split) || n.child[0] <= int32_t(i) ||
                 n.child[1] <= int32_t(i) || size_t(n.child[0]) >= ns || size_t(n.child[1]) >= ns) {
        return "a space node's axis, split or children are invalid";
      }
    }
    std::vector<QNode> qn(nq);
    for (size_t i = 0; i < nq; ++i) {
      double total = 0.0;
      for (int k = 0; k < 4; ++k) {
        qn[i].sum[k] = a.sky_sum[4 * i + k];
        qn[i].child[k] = a.sky_child[4 * i + k];
        if (!(qn[i].sum[k] >= 0.0) || !std::isfinite(qn[i].sum[k])) return "a sky sum is negative or not finite";
        total += qn[i].sum[k];
        if (qn[i].child[k] != 0 &&
            (qn[i].child[k] <= int32_t(i) || size_t(qn[i].child[k]) >= nq || !(qn[i].sum[k] > 0.0)))
          return "a sky node's child is invalid";
      }
      if (!(total > 0.0) || !std::isfinite(total)) return "a sky node holds no energy";
    }
    std::vector<Leaf> lv(nl);
    for (size_t i = 0; i < nl; ++i) {
      lv[i].root = a.leaf_root[i];
      if (lv[i].root < -1 || (lv[i].root >= 0 && size_t(lv[i].root) >= nq)) return "a leaf's sky root is out of range";
    }
    for (int k = 0; k < kRoots; ++k)
      if (a.roots[k] < -1 || (a.roots[k] >= 0 && size_t(a.roots[k]) >= ns)) return "a root is out of range";
    const size_t nlights = nl > 0 ? a.leaf_lights.size() / nl : 0;
    if (nlights * nl != a.leaf_lights.size()) return "leaf_lights must have a row per leaf";
    for (size_t i = 0; i < nl && nlights > 0; ++i) {
      const double* row = a.leaf_lights.data() + i * nlights;
      if (row[0] < 0.0) {
        for (size_t k = 0; k < nlights; ++k)
          if (row[k] != -1.0) return "a leaf's light choice is partly missing";
        continue;
      }
      double sum = 0.0;
      for (size_t k = 0; k < nlights; ++k) {
        if (!(row[k] > 0.0) || !std::isfinite(row[k])) return "a light's probability is not positive and finite";
        sum += row[k];
      }
      if (!(std::fabs(sum - 1.0) < 1e-9)) return "a leaf's light probabilities do not sum to one";
    }
    snodes_ = std::move(sn);
    qnodes_ = std::move(qn);
    leaves_ = std::move(lv);
    nlights_ = int(nlights);
    leaf_lights_ = a.leaf_lights;
    std::copy(a.roots.begin(), a.roots.end(), root_);
    return "";
  }

  bool empty() const { return leaves_.empty(); }
  int lights() const { return nlights_; }  // the lights its leaves learnt to choose among (0: none)
  size_t leaf_count() const { return leaves_.size(); }
  size_t cell_count() const { return qnodes_.size(); }

  // The leaf holding position pos on `sheet`, on a surface of unit normal `normal`, or -1.
  int leaf(V3 pos, int sheet, V3 normal) const {
    int n = root_[root_index(sheet, normal)];
    if (n < 0) return -1;
    while (snodes_[n].leaf < 0) {
      const SNode& sn = snodes_[n];
      n = pos[sn.axis] < sn.split ? sn.child[0] : sn.child[1];
    }
    return snodes_[n].leaf;
  }
  // Whether leaf l's quadtree can be sampled (it saw light arrive), for pdf() and sample().
  bool has_sky(int l) const { return leaves_[size_t(l)].root >= 0; }
  // Leaf l's probabilities of choosing each light (Params::lights of them), or null where it learnt none.
  const double* light_select(int l) const {
    return nlights_ > 0 && leaf_lights_[size_t(l) * nlights_] >= 0.0 ? &leaf_lights_[size_t(l) * nlights_] : nullptr;
  }

  // Solid-angle density of sample() in leaf l for local unit direction w.
  double pdf(int l, V3 w) const {
    double s, t;
    sky_to_square(w, s, t);
    int n = leaves_[l].root;
    double density = 1.0;  // on the square
    for (;;) {
      const QNode& q = qnodes_[n];
      const int qx = s >= 0.5, qy = t >= 0.5, k = qx + 2 * qy;
      const double total = q.sum[0] + q.sum[1] + q.sum[2] + q.sum[3];
      if (!(q.sum[k] > 0.0)) return 0.0;
      density *= 4.0 * q.sum[k] / total;
      s = 2.0 * s - qx;
      t = 2.0 * t - qy;
      if (q.child[k] == 0) break;
      n = q.child[k];
    }
    return density / (4.0 * M_PI);
  }

  // A local unit direction drawn in leaf l from uniforms u1, u2, and its solid-angle density.
  V3 sample(int l, double u1, double u2, double& pdf) const {
    int n = leaves_[l].root;
    double x0 = 0.0, y0 = 0.0, size = 1.0, density = 1.0;
    for (;;) {
      const QNode& q = qnodes_[n];
      const double total = q.sum[0] + q.sum[1] + q.sum[2] + q.sum[3];
      int k = -1, last = 0;
      double acc = 0.0, acc_last = 0.0;
      const double target = u1 * total;
      for (int i = 0; i < 4 && k < 0; ++i) {
        if (!(q.sum[i] > 0.0)) continue;
        if (target < acc + q.sum[i]) k = i;
        else acc += q.sum[i];
        last = i;
        acc_last = acc;
      }
      if (k < 0) {  // (rounding past the last quadrant with energy)
        k = last;
        acc = acc_last - q.sum[last];
      }
      u1 = std::clamp((target - acc) / q.sum[k], 0.0, std::nextafter(1.0, 0.0));
      density *= 4.0 * q.sum[k] / total;
      size *= 0.5;
      x0 += size * (k & 1);
      y0 += size * (k >> 1);
      if (q.child[k] == 0) break;
      n = q.child[k];
    }
    pdf = density / (4.0 * M_PI);
    return square_to_sky(x0 + size * u1, y0 + size * u2);
  }

 private:
  struct SNode {
    int axis = 0;
    double split = 0.0;
    int32_t child[2] = {-1, -1};
    int32_t leaf = -1;  // >= 0: a leaf
  };
  struct QNode {
    double sum[4] = {0, 0, 0, 0};
    int32_t child[4] = {0, 0, 0, 0};  // 0: the quadrant is a cell (node 0 is a root, never a child)
  };
  struct Leaf {
    int32_t root = -1;  // its quadtree's root node, -1 where it saw no light
  };

  // Each sheet's records, and each of six orientations of the surface (the normal's largest component and its
  // sign), have a tree of their own: a floor and the wall beside it see different halves of the sky.
  static constexpr int kRoots = 12;
  static int root_index(int sheet, V3 n) {
    const double ax = std::fabs(n.x), ay = std::fabs(n.y), az = std::fabs(n.z);
    const int axis = ax >= ay && ax >= az ? 0 : (ay >= az ? 1 : 2);
    return 6 * (sheet >= 0 ? 0 : 1) + 2 * axis + (n[axis] < 0.0 ? 1 : 0);
  }

  int32_t build_space(std::vector<GuideRecord>& r, size_t b, size_t e, const Box& box, int depth) {
    const int32_t id = int32_t(snodes_.size());
    snodes_.emplace_back();
    const V3 ext = box.hi - box.lo;
    const int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
    if (e - b <= size_t(params_.leaf_records) || depth >= kMaxSpaceDepth || !(ext[axis] > 0.0)) {
      snodes_[id].leaf = int32_t(leaves_.size());
      leaves_.push_back({build_sky(r, b, e)});
      learn_lights(r, b, e);
      return id;
    }
    const double split = 0.5 * (box.lo[axis] + box.hi[axis]);
    const size_t m = size_t(std::stable_partition(r.begin() + b, r.begin() + e,
                                                  [&](const GuideRecord& g) { return g.pos[axis] < split; }) -
                            r.begin());
    Box lo = box, hi = box;
    lo.hi[axis] = split;
    hi.lo[axis] = split;
    const int32_t c0 = build_space(r, b, m, lo, depth + 1);
    const int32_t c1 = build_space(r, m, e, hi, depth + 1);
    snodes_[id].axis = axis;
    snodes_[id].split = split;
    snodes_[id].child[0] = c0;
    snodes_[id].child[1] = c1;
    return id;
  }

  // The light choice of the leaf just made, from the light records among [b, e): each light's share of what
  // they brought, mixed with the even choice (kEvenLights); -1 in the first entry where they brought nothing.
  void learn_lights(const std::vector<GuideRecord>& r, size_t b, size_t e) {
    if (nlights_ <= 0) return;
    std::vector<double> sum(size_t(nlights_), 0.0);
    double total = 0.0;
    for (size_t i = b; i < e; ++i) {
      const GuideRecord& g = r[i];
      if (g.light < 0 || g.light >= nlights_ || !(g.light_value > 0.0) || !std::isfinite(g.light_value)) continue;
      sum[size_t(g.light)] += g.light_value;
      total += g.light_value;
    }
    const size_t at = leaf_lights_.size();
    leaf_lights_.resize(at + size_t(nlights_), -1.0);
    if (!(total > 0.0) || !std::isfinite(total)) return;
    for (int k = 0; k < nlights_; ++k)
      leaf_lights_[at + size_t(k)] = (1.0 - kEvenLights) * sum[size_t(k)] / total + kEvenLights / nlights_;
  }

  // The quadtree of records [b, e) (their square coordinates), or -1 if they carry no energy.
  int32_t build_sky(const std::vector<GuideRecord>& r, size_t b, size_t e) {
    std::vector<Point> pts;
    pts.reserve(e - b);
    double total = 0.0;
    for (size_t i = b; i < e; ++i) {
      if (!(r[i].value > 0.0) || !std::isfinite(r[i].value)) continue;
      Point p;
      sky_to_square(r[i].dir, p.s, p.t);
      p.v = r[i].value;
      pts.push_back(p);
      total += p.v;
    }
    if (pts.empty() || !(total > 0.0)) return -1;
    return build_cell(pts, 0, pts.size(), total, 0);
  }
  struct Point {
    double s, t, v;  // square coordinates relative to the current cell, value
  };
  // The node over points [b, e) (coordinates relative to its square, in [0, 1)).
  int32_t build_cell(std::vector<Point>& p, size_t b, size_t e, double leaf_total, int depth) {
    const int32_t id = int32_t(qnodes_.size());
    qnodes_.emplace_back();
    size_t start[5];
    start[0] = b;
    // Order the points by quadrant (stable), counting and summing each.
    size_t count[4] = {0, 0, 0, 0};
    double sum[4] = {0, 0, 0, 0};
    std::vector<Point> tmp(p.begin() + b, p.begin() + e);
    for (const Point& q : tmp) {
      const int k = (q.s >= 0.5) + 2 * (q.t >= 0.5);
      ++count[k];
      sum[k] += q.v;
    }
    for (int k = 0; k < 4; ++k) start[k + 1] = start[k] + count[k];
    size_t at[4] = {start[0], start[1], start[2], start[3]};
    for (const Point& q : tmp) {
      const int qx = q.s >= 0.5, qy = q.t >= 0.5;
      p[at[qx + 2 * qy]++] = {2.0 * q.s - qx, 2.0 * q.t - qy, q.v};
    }
    for (int k = 0; k < 4; ++k) qnodes_[id].sum[k] = sum[k];
    for (int k = 0; k < 4; ++k) {
      if (depth + 1 < params_.max_depth && count[k] >= 2 && sum[k] > params_.rho * leaf_total) {
        const int32_t c = build_cell(p, start[k], start[k + 1], leaf_total, depth + 1);
        qnodes_[id].child[k] = c;
      }
    }
    return id;
  }

  static constexpr int kMaxSpaceDepth = 24;
  Params params_;
  int32_t root_[kRoots] = {-1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1};
  std::vector<SNode> snodes_;
  std::vector<QNode> qnodes_;
  std::vector<Leaf> leaves_;
  int nlights_ = 0;
  std::vector<double> leaf_lights_;  // (leaves, nlights_): light_select's rows
};

}  // namespace wv
