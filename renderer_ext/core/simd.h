// SIMD lanes: one value per ray for a batch of kLanes rays, so the metric's Hamilton equations and the
// stepper's stage arithmetic run for kLanes rays at once (spacetime/ray_batch.h).
//
// `Lanes` is a GCC/Clang vector of kLanes doubles: + - * / act lane by lane, scalars broadcast, and a
// comparison yields a lane mask usable in `mask ? a : b`. Metric and stepper code templated over the
// scalar type T therefore compiles for T = double and T = Lanes alike. Every operation used is
// correctly rounded IEEE arithmetic (no reassociation, no FMA contraction: the build passes
// -ffp-contract=off), so a ray's result is bit-identical whether it ran alone or in a lane, and on
// any instruction set.
//
// Functions that work on Lanes are WV_INLINE (always inlined) so that they take the instruction set
// of the kernel they are inlined into: the batch kernels are compiled for AVX-512, AVX2 and baseline
// x86-64 and the best one is chosen when the library loads (WV_LANE_CLONES).
#pragma once

#include <cmath>

#include "core/dual.h"  // wv::sqrt(double), so templated code calls sqrt(T) for any T

namespace wv {

constexpr int kLanes = 8;
typedef double Lanes __attribute__((vector_size(8 * kLanes)));

#define WV_INLINE inline __attribute__((always_inline))

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(WARPVIZ_NO_CLONES)
#define WV_LANE_CLONES __attribute__((target_clones("default", "avx2", "arch=x86-64-v4")))
#else
#define WV_LANE_CLONES
#endif

// The instruction set of the batch kernel this CPU runs (the clone WV_LANE_CLONES picks).
inline const char* lane_kernel_isa() {
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(WARPVIZ_NO_CLONES)
  if (__builtin_cpu_supports("x86-64-v4")) return "AVX-512 (x86-64-v4)";
  if (__builtin_cpu_supports("avx2")) return "AVX2";
  return "SSE2 (baseline x86-64)";
#else
  return "compiler default";
#endif
}

// The same choice as a target_clones name ("arch=x86-64-v4", "avx2", "default"): what a metric plugin is
// compiled for (warpviz/spacetime/line_element/plugin.py; built with WARPVIZ_NO_CLONES, it needs only this).
inline const char* lane_kernel_target() {
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(WARPVIZ_NO_CLONES)
  if (__builtin_cpu_supports("x86-64-v4")) return "arch=x86-64-v4";
  if (__builtin_cpu_supports("avx2")) return "avx2";
#endif
  return "default";
}

WV_INLINE Lanes sqrt(Lanes v) {
  Lanes r;
  for (int i = 0; i < kLanes; ++i) r[i] = __builtin_sqrt(v[i]);
  return r;
}

// |x| and max(a, b) for doubles and lanes alike (max returns b when either is NaN).
WV_INLINE double abs_of(double x) { return __builtin_fabs(x); }
WV_INLINE Lanes abs_of(Lanes v) {
  Lanes r;
  for (int i = 0; i < kLanes; ++i) r[i] = __builtin_fabs(v[i]);
  return r;
}
WV_INLINE double max_of(double a, double b) { return a > b ? a : b; }
WV_INLINE Lanes max_of(Lanes a, Lanes b) { return a > b ? a : b; }

}  // namespace wv
