// What a recorded ray leaves behind: its polyline and per-point columns (affine parameter, time, radius,
// step, conserved-quantity drifts, redshift, sheet).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace wv {

// One recorded polyline: xyz (3 per point, user frame) and `columns` values per point:
// affine_param, coord_time, r, step_size, hamiltonian_err, the reported drift of invariants 1..K-1
// (RayResult::drift's rule at that point), their term-scaled drifts, redshift (photon frequency seen by
// the local static observer / ZAMO over the one at the ray's start), sheet.
struct Track {
  std::vector<double> xyz;
  std::vector<double> cols;
};

template <class M>
constexpr int track_columns() {
  return 5 + 2 * (M::kNumInvariants - 1) + 2;
}

// The names of those columns, for a metric whose conserved quantities are `invariants` ([0] = "H").
inline std::vector<std::string> track_column_names(const std::vector<std::string>& invariants) {
  std::vector<std::string> names = {"affine_param", "coord_time", "r", "step_size", "hamiltonian_err"};
  for (std::size_t k = 1; k < invariants.size(); ++k) names.push_back(invariants[k] + "_drift");
  for (std::size_t k = 1; k < invariants.size(); ++k) names.push_back(invariants[k] + "_drift_scaled");
  names.push_back("redshift");
  names.push_back("sheet");
  return names;
}

// Tracks packed into flat arrays: points (P, 3) concatenated, offsets (n + 1) and per-point columns (C, P),
// column-major so each column is one contiguous array. Each track's storage is released once copied.
struct PackedTracks {
  std::vector<double> points;
  std::vector<int64_t> offsets;
  std::vector<double> columns;
};

template <class TrackOf>
PackedTracks pack_tracks(std::size_t n, int num_columns, TrackOf&& track_of) {
  PackedTracks out;
  const std::size_t C = std::size_t(num_columns);
  out.offsets.assign(n + 1, 0);
  for (std::size_t i = 0; i < n; ++i) out.offsets[i + 1] = out.offsets[i] + int64_t(track_of(i).xyz.size() / 3);
  const std::size_t P = std::size_t(out.offsets[n]);
  out.points.reserve(3 * P);
  out.columns.assign(C * P, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    Track& t = track_of(i);
    out.points.insert(out.points.end(), t.xyz.begin(), t.xyz.end());
    const std::size_t base = std::size_t(out.offsets[i]), np = t.xyz.size() / 3;
    for (std::size_t j = 0; j < np; ++j)
      for (std::size_t c = 0; c < C; ++c) out.columns[c * P + base + j] = t.cols[j * C + c];
    Track().xyz.swap(t.xyz);
    Track().cols.swap(t.cols);
  }
  return out;
}

}  // namespace wv
