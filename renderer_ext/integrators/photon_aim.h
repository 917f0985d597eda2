// Where caustic photons are worth sending (o.photon_aim): a projection map of each photon light, learnt from
// the scene before the first photon pass, that says for each part of the light (a cell of its sampling
// square, per side) which emission directions start a photon that can be stored: one whose first segment
// reaches a mirror or glass surface, or, with retro photons, a diffuse one after the hole turned it back
// (photon_tracer.h). Everything else a photon is sent along (the room's walls seen straight, the hole, the
// sky) is traced and lost: in fig07 97 % of the photons, so that the glass ball's caustic, bent round the
// hole onto the floor in front of it, held a third of the image's error at 16 spp.
//
// Directions are drawn in the unit square that the emission's warp maps to the sphere of directions (the
// cosine lobe of an area light, a point light's sky or cone: u1 the polar part, u2 the azimuth): with
// probability kAimShare uniformly within the marked cells of the photon's part of the light, else uniformly in
// the whole square, so every direction keeps a density at least 1 - kAimShare times the unaimed one and the
// photons' flux, divided by the density ratio, is an unbiased estimate whatever the marks (a part the marks
// missed is only noisier). The marks are a function of the scene alone (fixed rays), so every pass, window
// and tile agrees on them.
//
// The marks come from rays traced from the light (the photons' own first segments: closed-form orbits,
// integrated steps): one per coarse cell of the square (kCoarse^2), then the fine cells (kFine^2) of the coarse
// cells that reached something, spread by a flood over the fine cells round each fine cell that did, and the
// marks grown by one fine cell (a cell that reached something at its ray may still be reached at its edge).
// A part of the light where more than kFloodLimit of the coarse cells reach something is marked by whole
// coarse cells grown by one (a mirror wall seen large: aiming there gains little and a flood would cost
// thousands of rays).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace wv {

class PhotonAim {
 public:
  // Parts per side of a light's sampling square (fig07 at 48 x 36: 4 x 4 parts stored 156 photons a pass of 518
  // for 9,650 rays of marks, 2 x 2 parts 117 for 2,560; in Kerr each ray is integrated).
  static constexpr int kPointCells = 2;
  static constexpr int kCoarse = 16;           // direction cells per side, first rays
  static constexpr int kFine = 64;             // ... marked (a multiple of kCoarse)
  static constexpr int kRatio = kFine / kCoarse;
  static constexpr double kAimShare = 0.8;     // the share of photons drawn within the marks
  static constexpr int kFloodLimit = kCoarse * kCoarse / 4;
  static constexpr int kParts = 2 * kPointCells * kPointCells;  // per light: sides x cells
  static constexpr int kMaxParts = 64;  // parts marked in a scene, the most powerful lights' first

  bool active() const { return !marks_.empty(); }
  void resize(size_t lights) { marks_.assign(lights * kParts, {}); }
  size_t lights() const { return marks_.size() / kParts; }

  // As flat arrays (the later ranges of a render are handed the first one's, as path guiding's tree): the
  // marks of light slot l's part p are cells[offsets[l kParts + p] .. offsets[l kParts + p + 1]).
  void to_arrays(std::vector<int64_t>& offsets, std::vector<uint16_t>& cells) const {
    offsets.assign(1, 0);
    cells.clear();
    for (const auto& m : marks_) {
      cells.insert(cells.end(), m.begin(), m.end());
      offsets.push_back(int64_t(cells.size()));
    }
  }
  // From to_arrays' arrays; false where they are not such (the reason in `why`).
  bool from_arrays(const int64_t* offsets, size_t n_offsets, const uint16_t* cells, size_t n_cells, std::string& why) {
    if (n_offsets < 1 || (n_offsets - 1) % kParts != 0 || offsets[0] != 0 || size_t(offsets[n_offsets - 1]) != n_cells) {
      why = "offsets must start at 0, end at the cells' count and hold a multiple of " + std::to_string(kParts) + " + 1";
      return false;
    }
    marks_.assign(n_offsets - 1, {});
    for (size_t u = 0; u + 1 < n_offsets; ++u) {
      if (offsets[u + 1] < offsets[u]) {
        why = "offsets must not decrease";
        return false;
      }
      marks_[u].assign(cells + offsets[u], cells + offsets[u + 1]);
      if (!std::is_sorted(marks_[u].begin(), marks_[u].end()) ||
          (!marks_[u].empty() && marks_[u].back() >= kFine * kFine)) {
        why = "each part's cells must ascend below " + std::to_string(kFine * kFine);
        return false;
      }
    }
    return true;
  }

  // The part of light slot `light` that point (u1, u2) of its sampling square on side `side` (0 or 1) is in.
  static int part(double u1, double u2, int side) {
    const int i = std::clamp(int(u1 * kPointCells), 0, kPointCells - 1);
    const int j = std::clamp(int(u2 * kPointCells), 0, kPointCells - 1);
    return (side * kPointCells + j) * kPointCells + i;
  }
  // A part's cell of the sampling square (i, j) and its side (the rays that mark it start at points spread over the
  // cell: spread()).
  static void part_cell(int part, int& i, int& j, int& side) {
    i = part % kPointCells;
    j = (part / kPointCells) % kPointCells;
    side = part / (kPointCells * kPointCells);
  }
  // A point of the unit square for ray k (a Kronecker sequence: the rays of a part start spread over it).
  static void spread(int k, double& a, double& b) {
    a = std::fmod(0.5 + 0.7548776662466927 * double(k), 1.0);
    b = std::fmod(0.5 + 0.5698402909980532 * double(k), 1.0);
  }

  // Calls f(cell) for fine cell c (i + kFine j) and each fine cell that touches it: the azimuth j wraps round, and
  // the cells of the first ring (i = 0) all meet at the axis.
  template <class F>
  static void around(int c, F&& f) {
    const int i = c % kFine, j = c / kFine;
    for (int dj = -1; dj <= 1; ++dj)
      for (int di = -1; di <= 1; ++di)
        if (i + di >= 0 && i + di < kFine) f(i + di + kFine * ((j + dj + kFine) % kFine));
    if (i == 0)
      for (int jj = 0; jj < kFine; ++jj) f(kFine * jj);
  }

  // The marked fine cells (i + kFine j, ascending) of part p of light slot l.
  std::vector<uint16_t>& marks(size_t l, int p) { return marks_[l * kParts + size_t(p)]; }
  const std::vector<uint16_t>& marks(size_t l, int p) const { return marks_[l * kParts + size_t(p)]; }

  // Draws the emission square's point (v1, v2) for part p of light slot l from uniform (v1, v2), in place;
  // returns its density over the uniform one (divide the photon's flux by it). Without marks it leaves them.
  double draw(size_t l, int p, double& v1, double& v2) const {
    if (!active()) return 1.0;
    const std::vector<uint16_t>& m = marks(l, p);
    if (m.empty()) return 1.0;
    const double boost = kAimShare * double(kFine * kFine) / double(m.size());
    if (v1 < kAimShare) {
      const double x = v1 / kAimShare * double(m.size());
      const size_t k = std::min(m.size() - 1, size_t(x));
      const int c = m[k];
      v1 = (double(c % kFine) + std::min(x - double(k), 1.0 - 1e-16)) / kFine;
      v2 = (double(c / kFine) + v2) / kFine;
      return boost + (1.0 - kAimShare);
    }
    v1 = (v1 - kAimShare) / (1.0 - kAimShare);
    const int i = std::min(kFine - 1, int(v1 * kFine)), j = std::min(kFine - 1, int(v2 * kFine));
    const bool in = std::binary_search(m.begin(), m.end(), uint16_t(i + kFine * j));
    return (in ? boost : 0.0) + (1.0 - kAimShare);
  }

 private:
  std::vector<std::vector<uint16_t>> marks_;  // per light slot and part
};

}  // namespace wv
