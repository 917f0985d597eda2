// Minkowski spacetime, Cartesian coordinates:  ds^2 = -dt^2 + dx^2 + dy^2 + dz^2.
//
// Flat: rays are straight lines traced analytically (zero integration steps).
#include <cmath>
#include <vector>

#include "engine/register.h"
#include "spacetime/metric.h"

namespace wv {

struct Minkowski : MetricBase<Minkowski> {
  static constexpr const char* kName = "minkowski";
  static constexpr const char* kClassName = "Minkowski";
  static constexpr const char* kSummary = "Flat spacetime: straight rays, traced analytically with zero steps";
  static constexpr bool kFlat = true;
  static constexpr int kNumInvariants = 2;
  static constexpr const char* kInvariantNames[kNumInvariants] = {"H", "E"};

  explicit Minkowski(const std::vector<double>& /*params*/) {}

  template <class T>
  void inverse_metric(const T* /*x*/, T gi[4][4]) const {
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b) gi[a][b] = T(a == b ? (a == 0 ? -1.0 : 1.0) : 0.0);
  }
  void rhs(const double y[8], double dy[8]) const {
    dy[0] = -y[4];
    for (int i = 1; i < 4; ++i) dy[i] = y[4 + i];
    for (int i = 4; i < 8; ++i) dy[i] = 0.0;
  }
  double radius(const double* x) const { return std::sqrt(x[1] * x[1] + x[2] * x[2] + x[3] * x[3]); }
  void conserved(const double y[8], const HamiltonianParts& /*hp*/, double out[], double mag[]) const {
    out[1] = -y[4];
    if (mag) mag[1] = std::fabs(y[4]);
  }
  void invariant_scales(const double* /*y*/, const double inv[], double scale[]) const {
    scale[0] = 1.0;
    scale[1] = std::fabs(inv[1]) > 0.0 ? std::fabs(inv[1]) : 1.0;
  }
};

WARPVIZ_REGISTER_METRIC(Minkowski);

}  // namespace wv
