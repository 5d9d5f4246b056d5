// Lanes: several doubles worked on at once, one contact per lane, by the same arithmetic as
// one double. The contact law is written once for a number type T (double, or Lanes) with the
// helpers below, so that a lane's result is bit for bit the one a double would give: every lane
// does the same IEEE operations in the same order (no fused multiply–add: the kernels that use
// wider instructions are compiled for AVX2 without FMA).
#pragma once

#include <cstddef>
#include <utility>

#include "millsim/core/vec.hpp"

namespace millsim {

/// Contacts evaluated at once by the pair stage: four doubles, one AVX register (two SSE2
/// registers where the processor has no AVX2).
inline constexpr int lane_count = 4;

using Lanes = double __attribute__((vector_size(sizeof(double) * lane_count)));

/// What comparing two T gives: bool for double, a lane mask (all bits set where true) for Lanes.
template <class T>
using Mask = decltype(T{} < T{});

/// a where the mask holds, else b, in each lane (for double, a plain choice).
template <class M, class T>
[[gnu::always_inline]] inline T select(M mask, T a, T b) {
  return mask ? a : b;
}

/// The same for each component of a vector.
template <class M, int D, class T>
[[gnu::always_inline]] inline Vec<D, T> select(M mask, const Vec<D, T>& a, const Vec<D, T>& b) {
  Vec<D, T> r;
  for (int i = 0; i < D; ++i) r[i] = select(mask, a[i], b[i]);
  return r;
}

/// Whether the mask holds in any lane (for bool, the mask itself).
[[gnu::always_inline]] inline bool any(bool mask) {
  return mask;
}
template <class M>
[[gnu::always_inline]] inline bool any(M mask) {
  auto bits = mask[0];
  for (int l = 1; l < lane_count; ++l) bits |= mask[l];
  return bits != 0;
}

/// Square root and absolute value, exact in every lane as std::sqrt and std::abs are.
[[gnu::always_inline]] inline double lane_sqrt(double x) {
  return __builtin_sqrt(x);
}
[[gnu::always_inline]] inline double lane_abs(double x) {
  return __builtin_fabs(x);
}
[[gnu::always_inline]] inline Lanes lane_sqrt(Lanes x) {
  Lanes r;
  for (int l = 0; l < lane_count; ++l) r[l] = __builtin_sqrt(x[l]);
  return r;
}
[[gnu::always_inline]] inline Lanes lane_abs(Lanes x) {
  Lanes r;
  for (int l = 0; l < lane_count; ++l) r[l] = __builtin_fabs(x[l]);
  return r;
}

/// Lanes holding f(l) in lane l, for l = 0 … lane_count − 1 (f gives one double per lane).
template <class F>
[[gnu::always_inline]] inline Lanes gather_lanes(F&& f) {
  return [&]<std::size_t... L>(std::index_sequence<L...>) __attribute__((always_inline)) {
    return Lanes{f(L)...};
  }
  (std::make_index_sequence<static_cast<std::size_t>(lane_count)>{});
}

/// Lanes of one spin per lane (Spin<D>: a number in 2D, a vector in 3D): f(l) in lane l.
template <int D, class F>
[[gnu::always_inline]] inline auto gather_spin_lanes(F&& f) {
  if constexpr (D == 2) {
    return gather_lanes(f);
  } else {
    Vec<3, Lanes> r;
    for (int d = 0; d < 3; ++d) r[d] = gather_lanes([&](std::size_t l) { return f(l)[d]; });
    return r;
  }
}

/// The same value in every lane.
template <class T>
[[gnu::always_inline]] inline T splat(double x) {
  if constexpr (sizeof(T) == sizeof(double)) {
    return x;
  } else {
    T r;
    for (int l = 0; l < lane_count; ++l) r[l] = x;
    return r;
  }
}

}  // namespace millsim
