// Adaptive step-size control shared by a lone ray (geodesic.h) and a batch of rays in SIMD lanes
// (ray_batch.h): the PI controller's step factors from a trial step's scaled error.
#pragma once

#include "core/fastmath.h"

namespace wv {

// The step controller's transcendental part, from the scaled error e of a trial step and log_prev, the
// log error kept from the last accepted step: log(max(e, 1e-10)) and the factors by which h changes after
// accepting (PI control: Gustafsson; Hairer & Wanner's constants) or rejecting the step, before clamping.
// T is double, or Lanes when a batch computes them for all its rays at once (the same bits either way).
template <class T>
struct StepFactors {
  T log_e, accept, reject;
};

template <class T>
WV_INLINE T step_log_error(T e) {
  return fast_log(max_of(e, T{} + 1e-10));  // (NaN -> 1e-10: such a step is rejected anyway)
}
template <int Order, class T>
WV_INLINE T accept_factor(T log_e, T log_prev) {
  constexpr double beta = 0.04, alpha = 1.0 / Order - 0.75 * beta;
  return 0.9 * fast_exp(beta * log_prev - alpha * log_e);
}
template <int Order, class T>
WV_INLINE T reject_factor(T log_e) {
  return 0.9 * fast_exp(log_e * (-1.0 / Order));
}
// All three at once, for a batch (its lanes need both factors); a lone ray computes only the one it uses.
template <int Order, class T>
WV_INLINE StepFactors<T> step_factors(T e, T log_prev) {
  const T log_e = step_log_error(e);
  return {log_e, accept_factor<Order>(log_e, log_prev), reject_factor<Order>(log_e)};
}

}  // namespace wv
