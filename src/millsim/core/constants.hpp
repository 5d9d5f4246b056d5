#pragma once

#include <numbers>

namespace millsim {

inline constexpr double pi = std::numbers::pi;
/// Standard gravity, m/s^2.
inline constexpr double standard_gravity = 9.81;

}  // namespace millsim
