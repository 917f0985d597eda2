// What a recorded ray leaves behind: its polyline and per-point columns (affine parameter, time, radius,
// step, conserved-quantity drifts, redshift, sheet).
#pragma once

#include <vector>

namespace wv {

// One recorded polyline: xyz (3 per point, user frame) and `columns` values per point:
// affine_param, coord_time, r, step_size, hamiltonian_err, drift of invariants 1..K-1, redshift
// (photon frequency seen by the local static observer / ZAMO over the one at the ray's start), sheet.
struct Track {
  std::vector<double> xyz;
  std::vector<double> cols;
};

template <class M>
constexpr int track_columns() {
  return 5 + (M::kNumInvariants - 1) + 2;
}

}  // namespace wv
