// Small fixed-size vectors shared by the 2D and 3D engines.
//
// Vec<D> is a plain aggregate of D doubles; Spin<D> is the type of an angular velocity or a
// torque: a scalar about the out-of-plane axis in 2D, a vector in 3D. Vec<D, T> holds D of
// some other number type: the contact law also runs on Lanes (core/lanes.hpp), several
// contacts at once, with the same arithmetic. What takes or gives a T by value is always
// inlined: a Lanes value is passed in AVX registers by code compiled for AVX2 and in memory by
// the rest, so it must never cross a call between the two (unoptimised builds included).
#pragma once

#include <array>
#include <cmath>
#include <type_traits>

namespace millsim {

template <int D, class T = double>
struct Vec {
  static_assert(D == 2 || D == 3, "millsim works in two or three dimensions");
  std::array<T, D> c{};

  [[gnu::always_inline]] constexpr T& operator[](int i) { return c[static_cast<std::size_t>(i)]; }
  [[gnu::always_inline]] constexpr T operator[](int i) const {
    return c[static_cast<std::size_t>(i)];
  }

  [[gnu::always_inline]] constexpr Vec& operator+=(const Vec& o) {
    for (int i = 0; i < D; ++i) (*this)[i] += o[i];
    return *this;
  }
  [[gnu::always_inline]] constexpr Vec& operator-=(const Vec& o) {
    for (int i = 0; i < D; ++i) (*this)[i] -= o[i];
    return *this;
  }
  [[gnu::always_inline]] constexpr Vec& operator*=(T s) {
    for (int i = 0; i < D; ++i) (*this)[i] *= s;
    return *this;
  }
  [[gnu::always_inline]] friend constexpr Vec operator+(Vec a, const Vec& b) { return a += b; }
  [[gnu::always_inline]] friend constexpr Vec operator-(Vec a, const Vec& b) { return a -= b; }
  [[gnu::always_inline]] friend constexpr Vec operator*(Vec a, T s) { return a *= s; }
  [[gnu::always_inline]] friend constexpr Vec operator*(T s, Vec a) { return a *= s; }
  [[gnu::always_inline]] friend constexpr Vec operator-(Vec a) {
    for (int i = 0; i < D; ++i) a[i] = -a[i];
    return a;
  }
  friend constexpr bool operator==(const Vec&, const Vec&) = default;
};

using Vec2 = Vec<2>;
using Vec3 = Vec<3>;

template <int D, class T>
[[gnu::always_inline]] constexpr T dot(const Vec<D, T>& a, const Vec<D, T>& b) {
  T s{};
  for (int i = 0; i < D; ++i) s += a[i] * b[i];
  return s;
}
template <int D, class T>
[[gnu::always_inline]] constexpr T norm_squared(const Vec<D, T>& a) {
  return dot(a, a);
}
template <int D>
inline double norm(const Vec<D>& a) {
  return std::sqrt(dot(a, a));
}

/// The integer nearest to t, ties to even, with the sign of t (−0 for t in (−0.5, 0]): the bits of
/// std::nearbyint in the default rounding mode for every t, without its call into the C library
/// (x86-64 has no rounding instruction before SSE4.1; a periodic slab asks once per pair and
/// particle each step). Below 2^52 the sum a + 2^52 keeps no fraction, rounded to even.
[[gnu::always_inline]] inline double nearest_integer(double t) {
  constexpr double two_to_52 = 4503599627370496.0;
  const double a = std::fabs(t);
  const double rounded = a < two_to_52 ? (a + two_to_52) - two_to_52 : a;
  return std::copysign(rounded, t);
}

/// Angular velocity / torque: scalar about +z in 2D, a vector in 3D.
template <int D>
using Spin = std::conditional_t<D == 2, double, Vec3>;
/// The same of some other number type T (double, or Lanes: core/lanes.hpp).
template <int D, class T = double>
using SpinOf = std::conditional_t<D == 2, T, Vec<3, T>>;

/// n × s for a vector n and a spin s. In 2D s is along +z: (n_x, n_y, 0) × (0, 0, s).
template <class T>
[[gnu::always_inline]] constexpr Vec<2, T> cross(const Vec<2, T>& n, T s) {
  return Vec<2, T>{{n[1] * s, -n[0] * s}};
}
/// s × r for a spin s along +z and a vector r in the plane: the velocity of a point at r.
inline constexpr Vec2 cross(double s, const Vec2& r) {
  return Vec2{{-s * r[1], s * r[0]}};
}
/// a × b for two plane vectors: the z component.
template <class T>
[[gnu::always_inline]] constexpr T cross(const Vec<2, T>& a, const Vec<2, T>& b) {
  return a[0] * b[1] - a[1] * b[0];
}

template <class T>
[[gnu::always_inline]] constexpr Vec<3, T> cross(const Vec<3, T>& a, const Vec<3, T>& b) {
  return Vec<3, T>{
      {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]}};
}

inline constexpr double spin_dot(double a, double b) {
  return a * b;
}
inline constexpr double spin_dot(const Vec3& a, const Vec3& b) {
  return dot(a, b);
}

}  // namespace millsim
