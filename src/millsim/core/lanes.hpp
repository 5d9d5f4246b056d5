// Lanes: several doubles worked on at once, one contact per lane, by the same arithmetic as
// one double. The contact law is written once for a number type T (double, or Lanes) with the
// helpers below, so that a lane's result is bit for bit the one a double would give: every lane
// does the same IEEE operations in the same order (no fused multiply–add: the kernels that use
// wider instructions are compiled for AVX2 without FMA).
#pragma once

#include <cstddef>
#include <cstring>
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
  // Halves folded in the vector unit (a loop over the lanes compiled to an extraction each).
  static_assert(lane_count == 4);
  const M folded = mask | __builtin_shufflevector(mask, mask, 2, 3, 0, 1);
  return (folded[0] | folded[1]) != 0;
}

/// Whether the mask holds in every lane (for bool, the mask itself).
[[gnu::always_inline]] inline bool all(bool mask) {
  return mask;
}
template <class M>
[[gnu::always_inline]] inline bool all(M mask) {
  static_assert(lane_count == 4);
  const M folded = mask & __builtin_shufflevector(mask, mask, 2, 3, 0, 1);
  return (folded[0] & folded[1]) != 0;
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

/// The magnitude of the first with the sign of the second, in every lane as std::copysign.
[[gnu::always_inline]] inline double lane_copysign(double magnitude, double sign) {
  return __builtin_copysign(magnitude, sign);
}
[[gnu::always_inline]] inline Lanes lane_copysign(Lanes magnitude, Lanes sign) {
  Lanes r;
  for (int l = 0; l < lane_count; ++l) r[l] = __builtin_copysign(magnitude[l], sign[l]);
  return r;
}

/// core/vec.hpp's nearest_integer in every lane, by the same operations.
[[gnu::always_inline]] inline Lanes lane_nearest_integer(Lanes t) {
  Lanes two_to_52;
  for (int l = 0; l < lane_count; ++l) two_to_52[l] = 4503599627370496.0;
  const Lanes magnitude = lane_abs(t);
  return lane_copysign(magnitude < two_to_52 ? (magnitude + two_to_52) - two_to_52 : magnitude, t);
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

/// A 2D vector's two components in one register (SSE2), for the pair kernel's gathers and sums
/// in 2D: the same operations on each component as on a Vec<2>.
using Pair2 = double __attribute__((vector_size(sizeof(double) * 2)));

[[gnu::always_inline]] inline Pair2 pair_of(const Vec<2>& a) {
  Pair2 r;
  std::memcpy(&r, a.c.data(), sizeof r);
  return r;
}
[[gnu::always_inline]] inline Pair2 pair_of(Pair2 a) {
  return a;
}
/// A 3D vector's first two components in one register.
[[gnu::always_inline]] inline Pair2 planar_pair_of(const Vec<3>& a) {
  Pair2 r;
  std::memcpy(&r, a.c.data(), sizeof r);
  return r;
}
/// a += b and a −= b, both components at once.
[[gnu::always_inline]] inline void add_to(Vec<2>& a, Pair2 b) {
  const Pair2 sum = pair_of(a) + b;
  std::memcpy(a.c.data(), &sum, sizeof sum);
}
[[gnu::always_inline]] inline void subtract_from(Vec<2>& a, Pair2 b) {
  const Pair2 difference = pair_of(a) - b;
  std::memcpy(a.c.data(), &difference, sizeof difference);
}

/// Lanes of 2D vectors: f(l) (a Vec<2> or a Pair2) in lane l.
template <class F>
[[gnu::always_inline]] inline Vec<2, Lanes> lanes_of(F&& f) {
  static_assert(lane_count == 4);
  const Pair2 p0 = pair_of(f(0)), p1 = pair_of(f(1)), p2 = pair_of(f(2)), p3 = pair_of(f(3));
  const Lanes a = {p0[0], p0[1], p2[0], p2[1]};
  const Lanes b = {p1[0], p1[1], p3[0], p3[1]};
  return {{__builtin_shufflevector(a, b, 0, 4, 2, 6), __builtin_shufflevector(a, b, 1, 5, 3, 7)}};
}

/// The 2D vector of each lane: the inverse of lanes_of.
[[gnu::always_inline]] inline std::array<Pair2, lane_count> pairs_of(const Vec<2, Lanes>& v) {
  const Lanes low = __builtin_shufflevector(v[0], v[1], 0, 4, 2, 6);   // x0 y0 x2 y2
  const Lanes high = __builtin_shufflevector(v[0], v[1], 1, 5, 3, 7);  // x1 y1 x3 y3
  return {Pair2{low[0], low[1]}, Pair2{high[0], high[1]}, Pair2{low[2], low[3]},
          Pair2{high[2], high[3]}};
}

}  // namespace millsim
